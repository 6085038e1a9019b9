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

from ..core import colors, compositing, passes, schema, shaders, silhouettes
from ..core.ids import ENGINE_ID
from ..core.log import one_line, warn_once
from ..core.view import DrawStats, View
from . import density, gather, runtime, setting_repair, strands
from .gpu_context import ensure_gpu, is_init_scene
from .views import NoCameraError, camera_view, render_size


def world_color(scene) -> tuple[float, float, float]:
    world = scene.world
    if world is None:
        return (0.0, 0.0, 0.0)
    return tuple(world.color)


def composite_film(rgba: np.ndarray, scene) -> np.ndarray:
    """Premultiplied image over the film (transparent, or the world colour),
    in place: ``rgba`` is the frame just read back, which nobody else holds."""
    if not scene.render.film_transparent:
        compositing.over_film(rgba, world_color(scene))
    return rgba


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


# Frames of more than this many pixels are drawn and handed to Blender tile
# by tile (RenderEngine.begin_result on a sub-rectangle), so SolidWire's own
# float targets and readback stay at one tile (~0.3 GiB at this size) however
# big the frame: peak memory is Blender's result plus one tile. A 4K UHD
# frame (3840 x 2160, 8.3 Mpx) is one piece: every tile draws every mesh
# again, and on a dense mesh that per-triangle work is most of a frame.
TILE_PIXELS = 2 * 2048 * 2048
TILE_SIDE = 8192  # and no tile side longer than this (GPU texture limits)


def tiles_of(region, tile_pixels: int | None = None):
    """(x0, y0, w, h) tiles covering ``region`` (frame pixels), rows from the
    bottom: the fewest columns and rows whose tiles hold at most
    ``tile_pixels`` (default TILE_PIXELS), all of one size but the last
    column and row, so consecutive tiles reuse one set of targets."""
    x0, y0, w, h = region
    budget = max(int(tile_pixels or TILE_PIXELS), 1)
    columns, rows = -(-w // TILE_SIDE), -(-h // TILE_SIDE)
    while -(-w // columns) * -(-h // rows) > budget:
        # Split the longer side of the tile: tiles stay near square.
        if -(-w // columns) >= -(-h // rows):
            columns += 1
        else:
            rows += 1
    tile_w, tile_h = -(-w // columns), -(-h // rows)
    for ty in range(y0, y0 + h, tile_h):
        for tx in range(x0, x0 + w, tile_w):
            yield tx, ty, min(tile_w, x0 + w - tx), min(tile_h, y0 + h - ty)


class PreparedFrame:
    """What every tile of one frame shares: the full-frame view, the settings
    snapshot and the gathered draw items (extracted and uploaded once).
    ``extra_passes`` (core.schema.EXTRA_PASSES) are drawn with each tile."""

    def __init__(self, depsgraph, size, *, should_stop=None, extra_passes=(), options=None):
        ensure_gpu()  # uploads start in gather(), before anything is drawn
        # Read once per frame: every tile draws with the same options.
        self.options = runtime.options if options is None else options
        self.scene = depsgraph.scene
        self.view = camera_view(self.scene, depsgraph, size)
        # A stored NaN is drawn as its default and put right in the scene
        # itself (the original: self.scene is the depsgraph's copy); the
        # messages go to the engine's report (``messages``).
        self.settings, self.messages = setting_repair.checked_snapshot(self.scene, self.scene.original.solidwire)
        # Reuse: unchanged meshes are recognised by their content fingerprint
        # (runtime.py says why), so a multi-frame render re-extracts only what
        # changed on each frame.
        self.frame = runtime.begin_frame(reuse=self.options.reuse_meshes)
        # The view lets gather skip extracting meshes that are wholly off-screen.
        self.extra_passes = tuple(extra_passes)
        object_settings = gather.ObjectSettings(
            gather.SHOW_IN_RENDER, bpy.data.objects, pass_index=passes.OBJECT_INDEX_PASS in self.extra_passes
        )
        self.items, self.seen, self.ms_extract = gather.gather(
            depsgraph,
            runtime.mesh_cache,
            view=self.view,
            view_reach=silhouettes.outer_reach(self.settings, self.view),
            should_stop=should_stop,
            object_settings=object_settings,
            materials=passes.MATERIAL_INDEX_PASS in self.extra_passes,
            edge_lengths=density.needs_lengths(self.settings),
            tessellation=bool(self.settings.show_tessellation),
            reposition=self.options.reposition_meshes,
            **gather.gather_options(self.settings),
        )
        self.messages += object_settings.messages
        # Measured on the whole frame's view, so every tile fades alike.
        density.fade_dense_items(self.items, self.view, self.settings)
        # Hair and point clouds (blender/strands.py), drawn by the same passes.
        self.strands = strands.gather_strands(
            depsgraph,
            object_settings=gather.ObjectSettings(gather.SHOW_IN_RENDER, bpy.data.objects),
            colors=colors.needs_item_colors(self.settings),
        )
        self.draw_stats = None
        self.ms_draw = 0.0

    def draw(self, region, *, keep_readback: bool = False, read_depth: bool = True):
        """(rgba premultiplied over the film, view depth, {extra pass: values})
        of ``region`` (x0, y0, w, h in frame pixels), pixel for pixel as in
        the whole frame; the view depth is None with ``read_depth`` False
        (a frame without a Depth pass). ``keep_readback``: rgba and depth are views of
        buffers reused by the next draw (core.targets.Targets.read), for a
        caller that hands them on at once."""
        width, height = self.view.width, self.view.height
        view = self.view if tuple(region) == (0, 0, width, height) else sub_view(self.view, region)
        start = time.perf_counter()
        rgba, depth, stats, extra = passes.render_passes(
            self.items,
            view,
            self.settings,
            extra_passes=self.extra_passes,
            keep_readback=keep_readback,
            read_depth=read_depth,
            strands=self.strands,
            options=self.options,
        )
        self.ms_draw += (time.perf_counter() - start) * 1000.0
        if self.draw_stats is None:
            self.draw_stats = stats
        return composite_film(rgba, self.scene), depth, extra

    def finish(self) -> None:
        runtime.end_frame(self.frame, self.draw_stats or DrawStats(), self.ms_extract, self.ms_draw, self.seen)


def render_scene(
    depsgraph, size=None, *, region=None, should_stop=None, report=None, extra_passes=(), extra_out=None, options=None
):
    """Render ``depsgraph``'s scene from its camera in one piece: (rgba
    premultiplied over the film, view depth), or None when ``should_stop()``
    said so. ``region`` (x0, y0, w, h) in pixels of the full frame draws that
    window only. ``report(text, fraction)`` hears about the stages. The render
    passes named in ``extra_passes`` (core.schema.EXTRA_PASSES) go into the
    dict ``extra_out``. ``options`` (core.options.DrawOptions): how to draw,
    by default runtime.options."""
    report = report or (lambda _text, _fraction: None)
    report("extracting meshes", 0.0)
    frame = PreparedFrame(depsgraph, size, should_stop=should_stop, extra_passes=extra_passes, options=options)
    for line in frame.messages:
        warn_once(("repaired", line), line)
    if should_stop is not None and should_stop():
        return None
    report(f"drawing {len(frame.items)} objects", 0.5)
    rgba, depth, extra = frame.draw(region or (0, 0, frame.view.width, frame.view.height))
    if extra_out is not None:
        extra_out.update(extra)
    frame.finish()
    report("writing the result", 0.9)
    return rgba, depth


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


def passes_of(view_layer) -> tuple:
    """The render passes beyond Combined that ``view_layer`` asks for, in
    core.schema.RENDER_PASSES order: Blender's own switches and SolidWire's
    (``view_layer.solidwire``)."""
    props = getattr(view_layer, "solidwire", None)
    return tuple(
        p.name
        for p in schema.RENDER_PASSES
        if (props is not None or not p.own) and getattr(props if p.own else view_layer, p.switch)
    )


def extra_passes_of(view_layer) -> tuple:
    """:func:`passes_of` less Depth, which a frame reads back on its own
    (``read_depth``) rather than drawing it as an extra pass."""
    return tuple(name for name in passes_of(view_layer) if name != schema.DEPTH_PASS)


# (channels, channel ids, type) of each pass as Blender registers it.
PASS_LAYOUT = {p.name: (p.channels, p.channel_ids, p.kind) for p in schema.RENDER_PASSES}


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
        stop = runtime.render_stop_reason() if runtime.render_stop_reason is not None else None
        if stop:
            self.report({"ERROR"}, stop)  # ends Blender's animation render before this frame
            return
        width, height = render_size(scene)
        region = region_of(scene, width, height)
        layer_name = depsgraph.view_layer.name
        try:
            with shaders.gl_context(shaders.RENDER_ENGINE_CONTEXT):
                self._render_frame(depsgraph, (width, height), region, layer_name)
        except NoCameraError as exc:
            self.report({"ERROR"}, f"SolidWire: {exc}")
        except Exception as exc:  # noqa: BLE001  (never take the render, or Blender, down)
            self.report({"ERROR"}, f"SolidWire render failed: {type(exc).__name__}: {one_line(exc)}")
        else:
            self.update_progress(1.0)

    def _render_frame(self, depsgraph, size, region, layer_name) -> None:
        """Extract once, then draw and hand over the region tile by tile."""
        self.update_stats("SolidWire", f"{layer_name} | extracting meshes")
        frame = PreparedFrame(
            depsgraph, size, should_stop=self.test_break, extra_passes=extra_passes_of(depsgraph.view_layer)
        )
        for line in frame.messages:
            self.report({"WARNING"}, line)
        tiles = list(tiles_of(region))
        for number, tile in enumerate(tiles, start=1):
            if self.test_break():
                return  # cancelled (Esc): Blender keeps what it had
            self.update_stats(
                "SolidWire",
                f"{layer_name} | drawing {len(frame.items)} objects"
                + (f", tile {number} of {len(tiles)}" if len(tiles) > 1 else ""),
            )
            self.update_progress(0.1 + 0.9 * (number - 1) / len(tiles))
            # The tile goes into Blender's result before the next is drawn,
            # so its readback can live in buffers that are reused.
            rgba, depth, extra = frame.draw(tile, keep_readback=True, read_depth=depsgraph.view_layer.use_pass_z)
            self._write(tile, region, layer_name, rgba, depth, extra)
        frame.finish()

    def _write(self, tile, region, layer_name, rgba, depth, extra) -> None:
        """One tile into this view layer's result layer. Result coordinates
        are relative to the region (Blender places the region in the frame,
        with or without Crop to Render Region). The result is ended whatever
        happens."""
        x0, y0, w, h = tile
        result = self.begin_result(x0 - region[0], y0 - region[1], w, h, layer=layer_name)
        cancel = True
        try:
            layer = result.layers[0]
            write_pass(layer.passes["Combined"], rgba)
            depth_pass = layer.passes.find(schema.DEPTH_PASS)
            if depth_pass != -1 and depth is not None:
                write_pass(layer.passes[depth_pass], depth)
            for name, values in extra.items():
                index = layer.passes.find(name)
                if index != -1:
                    write_pass(layer.passes[index], values)
            cancel = False
        except Exception as exc:  # noqa: BLE001  (any failure to fill the result is one render error)
            raise RuntimeError(f"could not write the result: {type(exc).__name__}: {one_line(exc)}") from None
        finally:
            self.end_result(result, cancel=cancel)

    def update_render_passes(self, scene=None, renderlayer=None):
        self.register_pass(scene, renderlayer, "Combined", 4, "RGBA", "COLOR")
        for name in passes_of(renderlayer):
            channels, channel_ids, kind = PASS_LAYOUT[name]
            self.register_pass(scene, renderlayer, name, channels, channel_ids, kind)


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
