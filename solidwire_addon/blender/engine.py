"""Render target: the SOLIDWIRE render engine.

``blender -b scene.blend -E SOLIDWIRE -f 1`` and
``bpy.ops.render.render(write_still=True)`` both come through here. The scene
camera's view is drawn at the final resolution into the Combined pass
(premultiplied RGBA; transparent film or world colour behind it) and, when
enabled on the view layer, the Depth pass (view depth, 1e10 where empty).
"""

from __future__ import annotations

import time

import bpy
import numpy as np

from ..core import passes
from ..core.ids import ENGINE_ID
from . import gather, runtime
from .gpu_context import ensure_gpu, is_init_scene
from ..core.view import View
from .views import NoCameraError, camera_view, render_size


def world_color(scene) -> tuple[float, float, float]:
    world = scene.world
    if world is None:
        return (0.0, 0.0, 0.0)
    return tuple(world.color)


def composite_film(rgba: np.ndarray, scene) -> np.ndarray:
    """Premultiplied image over the film: transparent, or the world colour."""
    if scene.render.film_transparent:
        return rgba
    out = rgba.copy()
    background = np.asarray(world_color(scene), dtype=np.float32)
    out[..., :3] += (1.0 - rgba[..., 3:4]) * background
    out[..., 3] = 1.0
    return out


def region_of(scene, width: int, height: int) -> tuple[int, int, int, int]:
    """(x0, y0, w, h) in pixels of what a render draws: the render region
    (border) when it is on, as Blender truncates it, else the whole frame."""
    r = scene.render
    if not r.use_border:
        return 0, 0, width, height
    x0, x1 = int(r.border_min_x * width), int(r.border_max_x * width)
    y0, y1 = int(r.border_min_y * height), int(r.border_max_y * height)
    if x1 <= x0 or y1 <= y0:
        return 0, 0, width, height  # an empty region: Blender renders the frame
    return x0, y0, x1 - x0, y1 - y0


def render_scene(depsgraph, size=None, *, region=None, should_stop=None, report=None):
    """Render ``depsgraph``'s scene from its camera: (rgba premultiplied over
    the film, view depth), or None when ``should_stop()`` said so. Shared by
    the engine and the command line.

    ``region`` (x0, y0, w, h) in pixels of the full frame draws that window
    only, pixel for pixel as in the full render. ``report(text, fraction)``
    hears about the stages."""
    ensure_gpu()  # uploads start in gather(), before anything is drawn
    scene = depsgraph.scene
    view = camera_view(scene, depsgraph, size)
    if region is not None:
        view = sub_view(view, region)
    settings = scene.solidwire.snapshot()
    report = report or (lambda _text, _fraction: None)
    report("extracting meshes", 0.0)
    # Reuse: unchanged meshes are recognised by their content fingerprint
    # (runtime.py says why), so a multi-frame render re-extracts only what
    # changed on each frame.
    frame = runtime.begin_frame(reuse=True)
    # The view lets gather skip extracting meshes that are wholly off-screen.
    items, seen, ms_extract = gather.gather(depsgraph, runtime.mesh_cache, view=view, should_stop=should_stop,
                                            **passes.gather_options(settings))
    if should_stop is not None and should_stop():
        return None
    report(f"drawing {len(items)} objects", 0.5)
    start = time.perf_counter()
    rgba, depth, draw_stats = passes.render(items, view, settings)
    runtime.end_frame(frame, draw_stats, ms_extract, (time.perf_counter() - start) * 1000.0, seen)
    report("writing the result", 0.9)
    return composite_film(rgba, scene), depth


def sub_view(view, region):
    """The part (x0, y0, w, h) of ``view``'s window as a view of its own: the
    projection is followed by the window-space scale and shift that maps the
    region onto the whole target, so every pixel keeps its size and place."""
    x0, y0, w, h = region
    width, height = view.width, view.height
    window = np.eye(4)
    window[0, 0], window[0, 3] = width / w, (width - 2.0 * x0 - w) / w
    window[1, 1], window[1, 3] = height / h, (height - 2.0 * y0 - h) / h
    return View(view.view_matrix, window @ view.projection, (0, 0, w, h))


def write_pass(render_pass, array: np.ndarray) -> None:
    """Copy ``array`` ((H*W, channels) or any shape of that size) into
    ``render_pass``. ``bpy_prop_array.foreach_set`` takes a contiguous float32
    buffer in one copy; assigning to ``RenderPass.rect`` instead walks every
    pixel through Python's sequence protocol (about 0.5 s at 1280x720)."""
    render_pass.rect.foreach_set(np.ascontiguousarray(array, dtype=np.float32).reshape(-1))


class SolidWireRenderEngine(bpy.types.RenderEngine):
    bl_idname = ENGINE_ID
    bl_label = "SolidWire"
    bl_use_gpu_context = True
    bl_use_preview = False

    def render(self, depsgraph):
        scene = depsgraph.scene
        if is_init_scene(scene):
            return  # gpu_context.ensure_gpu(): the GPU is now initialised
        width, height = render_size(scene)
        region = region_of(scene, width, height)
        layer_name = depsgraph.view_layer.name

        def report(text, fraction):
            self.update_stats("SolidWire", f"{layer_name} | {text}")
            self.update_progress(fraction)

        try:
            rendered = render_scene(depsgraph, (width, height), region=region, should_stop=self.test_break,
                                    report=report)
        except NoCameraError as exc:
            self.report({"ERROR"}, f"SolidWire: {exc}")
            return
        except Exception as exc:  # never take the render (or Blender) down
            self.report({"ERROR"}, f"SolidWire render failed: {type(exc).__name__}: {exc}")
            return
        if rendered is None:
            return  # cancelled (Esc): Blender keeps what it had
        rgba, depth = rendered
        # Each view layer into its own result layer; the region's size (with
        # or without Crop to Render Region, Blender places it in the frame).
        result = self.begin_result(0, 0, region[2], region[3], layer=layer_name)
        cancel = True
        try:
            layer = result.layers[0]
            write_pass(layer.passes["Combined"], rgba)
            depth_pass = layer.passes.find("Depth")
            if depth_pass != -1:
                write_pass(layer.passes[depth_pass], depth)
            cancel = False
        except Exception as exc:  # the result must be ended whatever happens
            self.report({"ERROR"}, f"SolidWire could not write the result: {type(exc).__name__}: {exc}")
        finally:
            self.end_result(result, cancel=cancel)
        self.update_progress(1.0)

    def update_render_passes(self, scene=None, renderlayer=None):
        self.register_pass(scene, renderlayer, "Combined", 4, "RGBA", "COLOR")
        if renderlayer.use_pass_z:
            self.register_pass(scene, renderlayer, "Depth", 1, "Z", "VALUE")


# Blender's own panels marked for any engine carry the pseudo-engine
# "BLENDER_RENDER" in their COMPAT_ENGINES (camera lens, mesh data, object
# visibility, world, output, colour management, ...): SolidWire joins every
# one of them, the way third-party engines do, so no hand list goes stale.
GENERIC_ENGINE = "BLENDER_RENDER"
# Panels that apply to SolidWire but are not marked generic.
_EXTRA_PANELS = ("CYCLES_RENDER_PT_film_transparency", "RENDER_PT_eevee_film")
# Generic panels whose settings SolidWire does not use.
_EXCLUDED_PANELS = ("RENDER_PT_simplify",)


def _compat_panels():
    for panel in bpy.types.Panel.__subclasses__():
        engines = getattr(panel, "COMPAT_ENGINES", None)
        if not isinstance(engines, set) or panel.__name__ in _EXCLUDED_PANELS:
            continue
        if GENERIC_ENGINE in engines:
            yield panel
        elif panel.__name__ in _EXTRA_PANELS and isinstance(panel.__dict__.get("COMPAT_ENGINES"), set):
            # Only a panel's own set: an inherited one is shared by its
            # siblings (CYCLES_RENDER_PT_film_transparency shares
            # CyclesButtonsPanel's with 84 Cycles panels).
            yield panel


def register_compat() -> None:
    for panel in _compat_panels():
        panel.COMPAT_ENGINES.add(SolidWireRenderEngine.bl_idname)


def unregister_compat() -> None:
    for panel in _compat_panels():
        panel.COMPAT_ENGINES.discard(SolidWireRenderEngine.bl_idname)


classes = (SolidWireRenderEngine,)
