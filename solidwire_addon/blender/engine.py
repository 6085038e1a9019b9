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


def render_scene(depsgraph, size=None):
    """Render ``depsgraph``'s scene from its camera: (rgba premultiplied over
    the film, view depth, stats dict). Shared by the engine and the CLI."""
    ensure_gpu()  # uploads start in gather(), before anything is drawn
    scene = depsgraph.scene
    view = camera_view(scene, depsgraph, size)
    settings = scene.solidwire.snapshot()
    # Reuse: unchanged meshes are recognised by their content fingerprint
    # (runtime.py says why), so a multi-frame render re-extracts only what
    # changed on each frame.
    frame = runtime.begin_frame(reuse=True)
    # The view lets gather skip extracting meshes that are wholly off-screen.
    items, seen, ms_extract = gather.gather(depsgraph, runtime.mesh_cache, view=view)
    start = time.perf_counter()
    rgba, depth, draw_stats = passes.render(items, view, settings)
    runtime.end_frame(frame, draw_stats, ms_extract, (time.perf_counter() - start) * 1000.0, seen)
    return composite_film(rgba, scene), depth


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
        try:
            rgba, depth = render_scene(depsgraph, (width, height))
        except NoCameraError as exc:
            self.report({"ERROR"}, f"SolidWire: {exc}")
            return
        except Exception as exc:  # never take the render (or Blender) down
            self.report({"ERROR"}, f"SolidWire render failed: {type(exc).__name__}: {exc}")
            return
        result = self.begin_result(0, 0, width, height)
        layer = result.layers[0]
        write_pass(layer.passes["Combined"], rgba)
        depth_pass = layer.passes.find("Depth")
        if depth_pass != -1:
            write_pass(layer.passes[depth_pass], depth)
        self.end_result(result)

    def update_render_passes(self, scene=None, renderlayer=None):
        self.register_pass(scene, renderlayer, "Combined", 4, "RGBA", "COLOR")
        if renderlayer.use_pass_z:
            self.register_pass(scene, renderlayer, "Depth", 1, "Z", "VALUE")


# Blender's own panels that apply to any engine (output, format, dimensions,
# colour management, film) show for SOLIDWIRE too.
_COMPAT_PANELS = (
    "RENDER_PT_format",
    "RENDER_PT_frame_range",
    "RENDER_PT_time_stretching",
    "RENDER_PT_output",
    "RENDER_PT_color_management",
    "RENDER_PT_color_management_display_settings",
    "RENDER_PT_color_management_curves",
    "RENDER_PT_stamp",
    "RENDER_PT_post_processing",
    "VIEWLAYER_PT_layer",
    "VIEWLAYER_PT_layer_passes",
    "VIEWLAYER_PT_layer_passes_data",
    "CYCLES_RENDER_PT_film_transparency",
    "RENDER_PT_eevee_film",
)


def _compat_panels():
    for name in _COMPAT_PANELS:
        panel = getattr(bpy.types, name, None)
        # Only a panel's own set: an inherited one is shared by its siblings
        # (CYCLES_RENDER_PT_film_transparency shares CyclesButtonsPanel's with
        # 84 Cycles panels, which would all show for SolidWire).
        if panel is not None and isinstance(panel.__dict__.get("COMPAT_ENGINES"), set):
            yield panel


def register_compat() -> None:
    for panel in _compat_panels():
        panel.COMPAT_ENGINES.add(SolidWireRenderEngine.bl_idname)


def unregister_compat() -> None:
    for panel in _compat_panels():
        panel.COMPAT_ENGINES.discard(SolidWireRenderEngine.bl_idname)


classes = (SolidWireRenderEngine,)
