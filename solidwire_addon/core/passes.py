"""The pass plan: which passes draw a frame, in which order, with which
settings. One plan serves every target; the two executors below differ only
in where the passes land.

    surface      every drawn face: depth, the fill colour and (unless hidden
                 lines are on) the visible wire, in one pass
    hidden       hidden lines, behind the surface depth, blended "over"
    wire         the visible wire over the hidden lines (only with hidden lines)
    silhouettes  the outer half of silhouette edges (image model §5.5)

* :func:`render` (render engine, command line, tests): float offscreen
  targets, read back as premultiplied RGBA plus view depth.
* :func:`draw_over_viewport` (viewport overlay): into a bound framebuffer
  that already holds the scene's colour and depth, through the scene's
  colour management (a display LUT, docs/image_model.md §9); meshes dense
  on screen through a deferred surface in the overlay's own targets, kept
  between redraws and composited against the scene's depth.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import gpu
import numpy as np

from . import colors, compositing, edge_select, shaders, silhouettes
from . import draw as draw_mod
from . import strands as strands_mod
from .log import warn_once

# Render passes beyond Combined and Depth (docs/image_model.md §6), by the
# name they have in Blender's render result: the schema's one table.
from .schema import (
    EDGE_DISTANCE_PASS,
    HIDDEN_WIRE_PASS,
    MATERIAL_INDEX_PASS,
    NORMAL_PASS,
    OBJECT_INDEX_PASS,
    WIRE_PASS,
)
from .targets import BACKGROUND_DEPTH, overlay_targets_for, read_texture, targets_for
from .view import View, translation, window_boxes

SURFACE, HIDDEN, WIRE, SILHOUETTES = "surface", "hidden", "wire", "silhouettes"

# Written by the surface pass's extra outputs (the rest has its own pass).
_SURFACE_AOVS = frozenset((WIRE_PASS, EDGE_DISTANCE_PASS, NORMAL_PASS, OBJECT_INDEX_PASS, MATERIAL_INDEX_PASS))


@dataclass(frozen=True)
class Pass:
    kind: str
    settings: object  # the DrawSettings this pass draws with
    show_wire: bool = True  # False: the pass draws no wire, whatever an object's override says


def plan(settings) -> tuple[Pass, ...]:
    """The passes ``settings`` need, in drawing order (an option that is off
    adds no pass)."""
    if settings.use_hidden_lines:
        # Hidden lines sit under the visible wire and over the fill: the
        # surface pass draws the fill (wire switched off), then hidden lines,
        # then the wire on its own.
        wire_only = replace(settings, use_fill=False)
        passes = [
            Pass(SURFACE, replace(settings, wire_color=(*settings.wire_color[:3], 0.0)), show_wire=False),
            Pass(HIDDEN, wire_only),
            Pass(WIRE, wire_only),
        ]
    else:
        passes = [Pass(SURFACE, settings)]
    if settings.use_silhouettes:
        passes.append(Pass(SILHOUETTES, settings))
    return tuple(passes)


def gather_options(settings) -> dict:
    """What the draw items of a frame with ``settings`` must carry (keyword
    arguments of blender/gather.gather): corner tables for a shaded fill or
    material colours, colour-source inputs for per-object colours."""
    return {
        "corners": draw_mod.needs_corners(settings),
        "colors": colors.needs_item_colors(settings),
        "attribute_colors": colors.needs_attribute_colors(settings),
        "edges": edge_select.Selection(
            float(settings.edge_angle), draw_mod.edge_classes_of(settings), bool(settings.use_cage_edges)
        ),
    }


def render(items, view: View, settings, *, cull: bool = True):
    """Draw ``items`` offscreen; return (rgba, view_depth, stats).

    ``rgba`` is (H, W, 4) float32, premultiplied, bottom row first, over a
    transparent background; ``view_depth`` is (H, W) with BACKGROUND_DEPTH
    where nothing was drawn. The caller makes sure the GPU is usable."""
    rgba, depth, stats, _extra = render_passes(items, view, settings, cull=cull)
    return rgba, depth, stats


def render_passes(
    items,
    view: View,
    settings,
    *,
    cull: bool = True,
    extra_passes=(),
    keep_readback: bool = False,
    read_depth: bool = True,
    strands=(),
):
    """:func:`render` plus the render passes named in ``extra_passes`` (of
    schema.EXTRA_PASSES): (rgba, view_depth, stats, {name: (H, W, channels)}).
    A pass that is not asked for costs nothing: the surface pass gets its
    extra outputs only when one of them is wanted, Hidden Wire its own pass
    only when asked for, and with ``read_depth`` False (no Depth pass) the
    view depth is not read back (None). ``keep_readback``: rgba and
    view_depth are views of buffers the targets keep, valid until the next
    such frame (:meth:`Targets.read`)."""
    extra_passes = frozenset(extra_passes)
    aovs = bool(extra_passes & _SURFACE_AOVS)
    width, height = view.width, view.height
    targets = targets_for(width, height)
    steps = plan(settings)
    surface = steps[0]
    stats = draw_surface(targets, items, view, surface.settings, show_wire=surface.show_wire, aovs=aovs, cull=cull)
    blended = [step for step in steps[1:] if step.kind in (HIDDEN, WIRE)]
    if blended:
        # A framebuffer without the view-depth target: blended passes must
        # leave the surface's view depth alone.
        with targets.color_framebuffer().bind():
            gpu.state.viewport_set(0, 0, width, height)
            gpu.state.blend_set("ALPHA_PREMULT")
            try:
                for step in blended:
                    if step.kind == HIDDEN:
                        draw_mod.draw_hidden_lines(items, view, step.settings, cull=cull, linear_depth=True)
                    else:
                        draw_mod.draw(items, view, step.settings, depth_write=False, cull=cull, linear_depth=True)
            finally:
                gpu.state.blend_set("NONE")
                gpu.state.depth_test_set("NONE")
    extra = {}
    if HIDDEN_WIRE_PASS in extra_passes:
        extra[HIDDEN_WIRE_PASS] = _hidden_wire(targets, items, view, settings, cull)
    # The surface passes' outputs need the coverage that the view depth holds.
    rgba, depth = targets.read(keep=keep_readback, depth=read_depth or aovs)
    if aovs:
        covered = depth < BACKGROUND_DEPTH
        aov = read_texture(targets.aov, 4)
        extra[WIRE_PASS] = aov[..., 1:2]
        extra[EDGE_DISTANCE_PASS] = np.where(covered, aov[..., 0], BACKGROUND_DEPTH)[..., None]
        extra[OBJECT_INDEX_PASS] = aov[..., 2:3]
        extra[MATERIAL_INDEX_PASS] = aov[..., 3:4]
        extra[NORMAL_PASS] = read_texture(targets.normal, 4)[..., :3]
    if any(step.kind == SILHOUETTES for step in steps):
        rgba = _composite_silhouettes(rgba, targets, items, view, settings)
    if strands:  # hair and point clouds (core/strands.py), over everything above
        rgba, depth = strands_mod.composite_render(rgba, depth, targets, view, settings, strands)
    return rgba, depth, stats, {name: value for name, value in extra.items() if name in extra_passes}


def _clear(framebuffer, width: int, height: int, depth: bool = True) -> None:
    # A clear honours the depth write mask, and GPU state lives per GL
    # context: a previous frame drawn in this context may have left depth
    # writes off, which left the old depth in place (wrong occlusion in the
    # next render drawn in that context).
    gpu.state.depth_mask_set(depth)
    gpu.state.color_mask_set(True, True, True, True)
    gpu.state.blend_set("NONE")
    if depth:
        framebuffer.clear(color=(0.0, 0.0, 0.0, 0.0), depth=1.0)
    else:
        framebuffer.clear(color=(0.0, 0.0, 0.0, 0.0))
    gpu.state.viewport_set(0, 0, width, height)


# Off only to measure the direct surface pass against it (scripts/bench).
use_deferred_surface = True


def draw_surface(
    targets, items, view: View, settings, *, show_wire: bool = True, aovs: bool = False, cull: bool = True
):
    """The surface pass into ``targets`` (cleared first): depth, the fill
    and the visible wire, and the render passes' outputs with ``aovs``.
    Meshes dense on screen are drawn deferred (docs/image_model.md §2.5,
    draw.split_deferred), the rest directly, into the same depth buffer; the
    same image either way. Returns the DrawStats."""
    width, height = view.width, view.height
    surface_args = {"cull": cull, "show_wire": show_wire, "write_aovs": aovs, "linear_depth": True}
    deferred, direct = ([], list(items))
    if use_deferred_surface and shaders.deferred_available():
        deferred, direct = draw_mod.split_deferred(items, view)
    framebuffer = targets.framebuffer(aovs=aovs)
    with framebuffer.bind():
        _clear(framebuffer, width, height)
        targets.clear_view_depth()
        stats = draw_mod.draw(direct, view, settings, write_view_depth=True, **surface_args)
        gpu.state.depth_test_set("NONE")
        gpu.state.depth_mask_set(False)
    if deferred:
        try:
            stats.add(_deferred_surface(targets, deferred, view, settings, aovs, surface_args))
        except shaders.DeferredUnavailable as exc:
            shaders.disable_deferred()
            warn_once(
                ("deferred",), f"SolidWire: the deferred surface pass is not available here ({exc}); drawing directly"
            )
            return draw_surface(targets, items, view, settings, show_wire=show_wire, aovs=aovs, cull=cull)
    return stats


def _deferred_surface(targets, items, view: View, settings, aovs: bool, surface_args: dict):
    """The surface pass of ``items`` in two stages over the depth the direct
    draws left: which triangle each pixel shows (depth test, no shading),
    then the exact fragment stage once per pixel shown. Same depth, same
    image as the direct pass; the edge set-up runs once per visible pixel
    instead of at every corner of every triangle."""
    width, height = view.width, view.height
    framebuffer = targets.visibility_framebuffer()
    with framebuffer.bind():
        _clear(framebuffer, width, height, depth=False)  # keep the direct draws' depth
        stats = draw_mod.draw(items, view, settings, stage=draw_mod.VISIBILITY, **surface_args)
        gpu.state.depth_test_set("NONE")
        gpu.state.depth_mask_set(False)
    # The lines of multi-face regions as quads over the record, so that no
    # pixel walks a region's edges (docs/image_model.md §2.6). The Edge
    # Distance pass needs d itself, so with the render passes' outputs the
    # resolve walks the regions instead; a pass with the wire switched off
    # needs no lines.
    lines = None
    if not aovs and surface_args["show_wire"] and _has_region_lines(items):
        lines = _draw_region_lines(targets, items, view, settings, surface_args, stats)
    with targets.resolve_framebuffer(aovs=aovs).bind():
        gpu.state.viewport_set(0, 0, width, height)
        draw_mod.draw(
            items,
            view,
            settings,
            stage=draw_mod.RESOLVE,
            visibility=targets.visible,
            write_view_depth=True,
            region_lines=lines,
            **surface_args,
        )
    return stats


def _has_region_lines(items) -> bool:
    return any(item.mesh.region_line_count for item in items)


def _draw_region_lines(targets, items, view: View, settings, draw_args: dict, stats):
    """The region-lines pass over ``targets.visible`` (the visibility
    record of ``items``, numbered as draw() numbers them): the strongest
    line per pixel into ``targets.lines``, which it returns."""
    framebuffer = targets.region_lines_framebuffer()
    with framebuffer.bind():
        _clear(framebuffer, view.width, view.height)
        draw_mod.draw(items, view, settings, stage=draw_mod.LINES, visibility=targets.visible, **draw_args)
        gpu.state.depth_test_set("NONE")
        gpu.state.depth_mask_set(False)
    stats.extra["region_line_entries"] = sum(item.mesh.region_line_count for item in items)
    return targets.lines


def _overlay_region_lines(items, view: View, settings, stats):
    """The viewport overlay's region lines: a visibility record of the
    meshes with multi-face regions at the region's size (own depth:
    Blender's depth buffer cannot be read back here), then the region-lines
    pass over it. The overlay's surface pass reads the result where its
    depth test lets a region's triangle through: the depth it tests against
    (Blender's, or our own pre-pass of every mesh) lets only the nearest
    surface pass, and where that is a region's triangle, the record holds it
    too. So the record needs no other mesh.

    A redraw that changes nothing the lines depend on (the view, the
    settings, which meshes in which shape where) reuses the last image of
    that viewport size: a viewport redraws far more often than its scene
    changes."""
    items = [item for item in items if item.mesh.region_line_count]
    targets = overlay_targets_for(view.width, view.height)
    key = _overlay_lines_key(items, view, settings)
    if key is not None and targets.lines_key == key and targets.lines is not None:
        stats.extra["region_line_entries"] = sum(item.mesh.region_line_count for item in items)
        stats.extra["region_lines_reused"] = 1
        return targets.lines
    targets.lines_key = None
    framebuffer = targets.visibility_framebuffer()
    with framebuffer.bind():
        _clear(framebuffer, view.width, view.height)
        draw_mod.draw(items, view, settings, stage=draw_mod.VISIBILITY, linear_depth=True)
        gpu.state.depth_test_set("NONE")
        gpu.state.depth_mask_set(False)
    lines = _draw_region_lines(targets, items, view, settings, {"linear_depth": True}, stats)
    targets.lines_key = key
    return lines


def _overlay_defers(items, settings, clip_planes) -> bool:
    """Whether the overlay's surface may be deferred: the frame's passes are
    the surface pass alone (silhouettes may follow), no clipping region, and
    the deferred stages are in use. (The caller also asks that Blender's
    depth hold every surface: the record then only has to know which of our
    own triangles is nearest, and Blender's depth test does the rest.)"""
    steps = plan(settings)
    return (
        clip_planes is None
        and use_deferred_surface
        and shaders.deferred_available()
        and steps[0].kind == SURFACE
        and all(step.kind in (SURFACE, SILHOUETTES) for step in steps)
        and all(item.in_scene_depth for item in items)
    )


def _overlay_surface(items, view: View, settings, display, stats):
    """The deferred overlay's surface, into the overlay's own targets at
    the viewport's size: the visibility record of ``items`` over a depth
    buffer of its own (window depth, as Blender's), the region lines over
    it when a mesh has multi-face regions (docs/image_model.md §2.5, §2.6),
    then the resolve into ``targets.surface``. Returns the targets, for
    _composite_overlay_surface; ``stats`` gets the draws' counts.

    Nothing here reads Blender's buffers, so a redraw that changes nothing
    the image depends on (the view, the settings, which meshes in which
    shape where, their styles and colour sources, the display transform;
    _overlay_lines_key) reuses it whole: a static redraw only composites."""
    targets = overlay_targets_for(view.width, view.height)
    key = _overlay_lines_key(items, view, settings)
    if key is not None:
        key = ("surface", key, None if display is None else display.key, tuple(item.source for item in items))
        try:
            hash(key)
        except TypeError:
            key = None
    line_count = sum(item.mesh.region_line_count for item in items)
    record_stats = draw_mod.DrawStats()
    if key is not None and targets.surface_key == key and targets.lines_key == key:
        record_stats.objects_drawn, record_stats.objects_culled, record_stats.triangles_drawn = targets.surface_counts
        if line_count:
            record_stats.extra.update(region_line_entries=line_count, region_lines_reused=1)
        record_stats.extra["surface_reused"] = 1
        stats.add(record_stats)
        return targets
    targets.lines_key = targets.surface_key = None
    width, height = view.width, view.height
    framebuffer = targets.visibility_framebuffer()
    with framebuffer.bind():
        _clear(framebuffer, width, height)
        draw_mod.draw(items, view, settings, stage=draw_mod.VISIBILITY)
        gpu.state.depth_test_set("NONE")
        gpu.state.depth_mask_set(False)
    lines = _draw_region_lines(targets, items, view, settings, {}, record_stats) if line_count else None
    with targets.surface_framebuffer().bind():
        gpu.state.viewport_set(0, 0, width, height)
        gpu.state.blend_set("NONE")
        record_stats.add(
            draw_mod.draw(
                items,
                view,
                settings,
                stage=draw_mod.RESOLVE,
                visibility=targets.visible,
                region_lines=lines,
                display=display,
            )
        )
    # (One key for the record, its lines and the resolved image: the
    # direct path's own region lines (_overlay_region_lines) never match it.)
    targets.lines_key = targets.surface_key = key
    targets.surface_rect = _window_union(items, view)
    targets.surface_counts = (record_stats.objects_drawn, record_stats.objects_culled, record_stats.triangles_drawn)
    stats.add(record_stats)
    return targets


def _window_union(items, view: View) -> tuple:
    """The NDC rectangle over every item's window box (view.window_boxes),
    vectorised per mesh."""
    by_mesh: dict = {}
    for item in items:
        by_mesh.setdefault(id(item.mesh), []).append(item)
    boxes = []
    for group in by_mesh.values():
        mesh = group[0].mesh
        to_clip = (
            view.projection @ view.view_matrix @ np.stack([item.matrix for item in group]) @ translation(mesh.centre)
        )
        boxes.append(window_boxes(to_clip, mesh.bounds_min, mesh.bounds_max))
    boxes = np.concatenate(boxes)
    return (float(boxes[:, 0].min()), float(boxes[:, 1].min()), float(boxes[:, 2].max()), float(boxes[:, 3].max()))


def _composite_overlay_surface(targets, depth_bias: float) -> None:
    """Blend ``targets.surface`` into the bound framebuffer (Blender's)
    over the items' window boxes, each pixel at the record's depth less the
    bias, with depth test LESS_EQUAL and write, blending as the caller set
    (premultiplied "over")."""
    shader = shaders.get_overlay_composite(depth_bias)
    shader.bind()
    shader.uniform_sampler("record_depth", targets.depth)
    shader.uniform_sampler("surface_image", targets.surface)
    gpu.state.depth_test_set("LESS_EQUAL")
    gpu.state.depth_mask_set(True)
    draw_mod.draw_rectangle(shader, targets.surface_rect)


def _overlay_lines_key(items, view: View, settings):
    """What the overlay's region lines depend on, or None when that cannot
    be told (a setting that does not hash): each mesh by its serial and
    shape version (cache.GPUMesh), its matrix and style, the view and the
    settings."""
    try:
        return (
            view.view_matrix.tobytes(),
            view.projection.tobytes(),
            tuple(view.viewport),
            hash(settings),
            tuple((item.mesh.serial, item.mesh.version, item.matrix.tobytes(), item.style) for item in items),
        )
    except (TypeError, AttributeError):
        return None


def _hidden_wire(targets, items, view, settings, cull: bool) -> np.ndarray:
    """The Hidden Wire pass: H of image model §5.4 (coverage of the hidden
    layers, wire alpha included), whether or not Hidden Lines is on in the
    image. The hidden-line pass again, into a target of its own over the
    surface depth: "over" blending of the a_k on 0 leaves 1 - prod(1 - a_k)
    in alpha."""
    framebuffer = targets.hidden_framebuffer()
    with framebuffer.bind():
        _clear(framebuffer, view.width, view.height, depth=False)  # the surface depth stays
        gpu.state.blend_set("ALPHA_PREMULT")
        try:
            draw_mod.draw_hidden_lines(items, view, replace(settings, use_fill=False), cull=cull, linear_depth=True)
        finally:
            gpu.state.blend_set("NONE")
            gpu.state.depth_test_set("NONE")
    return read_texture(targets.hidden, 4)[..., 3:4]


def _composite_silhouettes(rgba, targets, items, view, settings):
    """Draw the outer halves of silhouette edges (max intensity per pixel,
    occluded by the surface pass's depth) and composite them over ``rgba``
    with the wire colour ("over", premultiplied)."""
    framebuffer = targets.silhouette_framebuffer()
    with framebuffer.bind():
        _clear(framebuffer, view.width, view.height)
        silhouettes.draw_silhouettes(items, view, settings, targets.depth, linear_depth=True)
        gpu.state.depth_test_set("NONE")
        gpu.state.depth_mask_set(False)
    compositing.color_over(rgba, settings.wire_color, read_texture(targets.outer, 1)[..., 0])
    return rgba


# NDC depth bias of the viewport overlay (2^-18: 32 steps of a 24-bit depth
# buffer, about 4 float32 ULPs of z/w near 1). Enough to win the tie with
# Blender's own depth of the same surface (a few ULPs off, computed from other
# float32 matrices); small enough that a surface more than a hair behind
# another stays hidden. See DEPTH_BIAS in shaders/solidwire_vert.glsl.
OVERLAY_DEPTH_BIAS = 2.0**-18


# The overlay defers a mesh from this many triangles per pixel of its
# window box on (draw.split_deferred). Lower than the render's threshold:
# the overlay's direct pass shades only what Blender's depth lets through,
# but its image is kept between redraws, so a redraw that changes nothing
# only composites. Measured on llvmpipe at 1280 x 720 (docs/dev/viewport-
# benchmark.md): Suzanne at 0.1 triangles per pixel redraws an edit faster
# directly (by ~8 ms of ~35), at 0.4 and above deferred (by ~15 ms of ~75).
OVERLAY_DEFERRED_MIN_DENSITY = 0.2


def draw_over_viewport(
    items,
    view: View,
    settings,
    *,
    depth_bias: float = OVERLAY_DEPTH_BIAS,
    scene_depth: bool = True,
    scene_surfaces: bool = False,
    clip_planes=None,
    display=None,
    strands=(),
):
    """Draw ``items`` over a bound framebuffer that already holds the scene's
    colour and depth (a 3D viewport after its own drawing). Returns the
    DrawStats of the surface pass.

    ``scene_depth`` False (X-ray: Blender's depth is no surface there) clears
    the bound depth first, so only our own surfaces occlude. ``clip_planes``
    ((6, 4) world-space planes, the viewport's clipping region) discards
    everything outside them in every pass (docs/image_model.md §5.6).
    ``display`` (a display_transform.DisplayLUT of the scene's colour
    management) makes every colour pass write what the F12 render shows
    (docs/image_model.md §9); None writes the scene-linear colour.

    Unless ``scene_surfaces`` says the scene's depth holds every item's
    surface (Solid shading without X-ray: not for an object drawn as wire
    or in front, item.in_scene_depth), a depth-only
    pre-pass comes first, so only the nearest of our own surfaces passes the
    colour passes (no back edges show through where the scene depth is
    empty). Where it does, the scene's depth already is that surface (our
    surfaces win the tie by ``depth_bias``) and the pre-pass would only
    cost a second pass over every triangle. The scene's depth hides wires
    behind other geometry. Then the plan's passes, blended with
    premultiplied alpha at depth test LESS_EQUAL. GPU state is restored."""
    saved_blend = gpu.state.blend_get()
    saved_depth_test = gpu.state.depth_test_get()
    saved_depth_mask = gpu.state.depth_mask_get()
    stats = None
    # Every pass gets the clipping planes and the LUT (the depth pre-pass
    # too: with the LUT its variant, and so its compiled program, is the
    # surface pass's).
    options = {"display": display} if clip_planes is None else {"clip_planes": clip_planes, "display": display}
    line_stats = draw_mod.DrawStats()
    # Where Blender's depth holds every surface, the dense meshes' surface
    # is deferred: recorded and resolved in the overlay's own targets
    # (_overlay_surface), then composited into Blender's buffer.
    deferred, direct = [], list(items)
    if scene_depth and scene_surfaces and _overlay_defers(items, settings, clip_planes):
        deferred, direct = draw_mod.split_deferred(items, view, OVERLAY_DEFERRED_MIN_DENSITY)
    record = None
    if deferred:
        saved_viewport = gpu.state.viewport_get()
        try:
            shaders.get_overlay_composite(depth_bias)  # compiled before anything is drawn: a refusal falls back
            record = _overlay_surface(deferred, view, settings, display, line_stats)
        except shaders.DeferredUnavailable as exc:
            shaders.disable_deferred()
            warn_once(
                ("deferred",), f"SolidWire: the deferred surface pass is not available here ({exc}); drawing directly"
            )
            deferred, direct = [], list(items)
        finally:
            gpu.state.viewport_set(*saved_viewport)
    if clip_planes is None and not deferred and _has_region_lines(items):
        # (Inside a clipping region the record would keep clipped-away
        # surfaces: there the regions are walked.)
        saved_viewport = gpu.state.viewport_get()
        try:
            options["region_lines"] = _overlay_region_lines(items, view, settings, line_stats)
        finally:
            gpu.state.viewport_set(*saved_viewport)
    try:
        if not scene_depth:
            gpu.state.depth_mask_set(True)
            gpu.state.active_framebuffer_get().clear(depth=1.0)
        if not (scene_depth and scene_surfaces and all(item.in_scene_depth for item in items)):
            gpu.state.blend_set("NONE")
            gpu.state.color_mask_set(False, False, False, False)
            draw_mod.draw(items, view, settings, depth_bias=depth_bias, **options)
            gpu.state.color_mask_set(True, True, True, True)
        gpu.state.blend_set("ALPHA_PREMULT")
        for step in plan(settings):
            if step.kind == SURFACE:
                # With hidden lines the surface pass only carries the fill.
                if settings.use_hidden_lines and not settings.use_fill:
                    continue
                surface_stats = draw_mod.draw(
                    direct, view, step.settings, depth_bias=depth_bias, show_wire=step.show_wire, **options
                )
                if record is not None:
                    _composite_overlay_surface(record, depth_bias)
                    surface_stats.add(line_stats)
                stats = stats or surface_stats
            elif step.kind == HIDDEN:
                walk = {name: value for name, value in options.items() if name != "region_lines"}
                draw_mod.draw_hidden_lines(items, view, step.settings, depth_bias=depth_bias, **walk)
            elif step.kind == WIRE:
                stats = draw_mod.draw(items, view, step.settings, depth_bias=depth_bias, **options)
            elif step.kind == SILHOUETTES:
                silhouettes.draw_silhouettes(items, view, step.settings, overlay_bias=depth_bias, display=display)
        if strands:  # hair and point clouds (core/strands.py)
            strands_mod.draw_over_viewport(strands, view, settings, depth_bias, display, clip_planes)
    finally:
        gpu.state.color_mask_set(True, True, True, True)
        gpu.state.blend_set(saved_blend)
        gpu.state.depth_test_set(saved_depth_test)
        gpu.state.depth_mask_set(saved_depth_mask)
    stats = stats if stats is not None else draw_mod.DrawStats()
    if record is None:
        stats.extra.update(line_stats.extra)
    return stats
