"""The pass plan: which passes draw a frame, in which order, with which
settings. Each pass is a unit that owns its settings, its framebuffers and
the state it leaves for the passes after it (in :class:`Frame`), and runs
either way, as Blender's overlay engine gives each overlay a class with its
sync and draw steps:

    RegionLinesPass   the lines of multi-face regions as an image the surface
                      and wire passes read (docs/image_model.md §2.6)
    SurfacePass       every drawn face: depth, the fill colour and the
                      visible wire, in one pass (with hidden lines offscreen
                      the wire into a layer of its own)
    HiddenLinesPass   hidden lines, behind the surface depth, blended "over"
    WirePass          the visible wire over the hidden lines (only with
                      hidden lines: that layer, or over the viewport the
                      wire drawn again)
    OutputsPass       the read-back image and the render passes (offscreen)
    SilhouettePass    the outer half of silhouette edges (image model §5.5)
    StrandsPass       hair and point clouds (core/strands.py)

* :meth:`render` of each unit (render engine, command line, tests): float
  offscreen targets, read back as premultiplied RGBA plus view depth; the
  executor is :func:`render_passes`.
* :meth:`over_viewport` (viewport overlay): into a bound framebuffer that
  already holds the scene's colour and depth, through the scene's colour
  management (a display LUT, docs/image_model.md §9); the executor is
  :func:`draw_over_viewport`. Its sync step first records the meshes dense
  on screen into the overlay's own targets (a deferred surface kept between
  redraws), which the surface pass composites against the scene's depth.

How a frame is drawn apart from what it shows (deferred surface or not,
say) comes in one options.DrawOptions value, handed down from the caller.
"""

from __future__ import annotations

from contextlib import contextmanager
from dataclasses import dataclass, field, replace

import gpu
import numpy as np

from . import compositing, schema, shaders, silhouettes
from . import draw as draw_mod
from . import strands as strands_mod
from .draw import DrawTarget
from .edge_select import WALK_LIMIT
from .log import warn_once
from .options import DEFAULT as DEFAULT_OPTIONS
from .options import DrawOptions

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
from .settings import clip_end_of, depth_rows, pack_params
from .targets import BACKGROUND_DEPTH, overlay_targets_for, read_texture, release_kept_images, targets_for
from .view import NO_DEPTH_ALLOWANCE, OVERLAY_DEPTH_BIAS, DrawStats, View, blender_depth_allowance, window_boxes

# Written by the surface pass's extra outputs (the rest has its own pass).
_SURFACE_AOVS = frozenset((WIRE_PASS, EDGE_DISTANCE_PASS, NORMAL_PASS, OBJECT_INDEX_PASS, MATERIAL_INDEX_PASS))

# The overlay defers a mesh from this many triangles per pixel of its
# window box on (draw.split_deferred). Higher than the render's threshold:
# the overlay's direct pass shades only what Blender's depth lets through.
# Both keep their image between redraws, so a redraw that changes nothing
# only composites either way. Measured on llvmpipe at 1280 x 720 (every
# edge of Suzanne filling the viewport; docs/dev/benchmarks.md, "Deferred
# or direct"): an edit redraws about twice as fast deferred at every
# density from 0.017 triangles per pixel up (15 against 30 ms there, 23
# against 45 at 0.07), while a whole redraw (the view or the object moved)
# costs 1.5x deferred at 0.017, the same at 0.07 and 0.7x at 0.27.
OVERLAY_DEFERRED_MIN_DENSITY = 0.05


@dataclass
class Frame:
    """What the passes of one frame share: their inputs, and what each
    leaves for the passes after it.

    ``base`` is what every draw of the frame has in common (draw.DrawTarget):
    offscreen the render's linear depth, over the viewport the depth bias,
    the clipping region and the display transform. Offscreen, ``targets``
    are the float targets the passes draw into and ``rgba``, ``depth`` and
    ``extra`` what OutputsPass read back; over the viewport,
    ``region_lines`` is the image RegionLinesPass drew."""

    items: list
    view: View
    settings: object
    base: DrawTarget
    options: DrawOptions = DEFAULT_OPTIONS
    cull: bool = True
    strands: tuple = ()
    stats: DrawStats | None = None
    # Offscreen
    targets: object = None
    extra_passes: frozenset = frozenset()
    keep_readback: bool = False
    read_depth: bool = True
    rgba: np.ndarray | None = None
    depth: np.ndarray | None = None
    extra: dict = field(default_factory=dict)
    # Over the viewport
    scene_depth: bool = True
    scene_surfaces: bool = False
    region_lines: object = None
    line_stats: DrawStats = field(default_factory=DrawStats)
    # The sync step's split (_sync_overlay_surface): items drawn directly,
    # and the deferred ones' OverlaySurface.
    direct: list | None = None
    overlay_surface: OverlaySurface | None = None
    # The surface pass composited the kept frame (_overlay_kept_frame), so
    # the hidden-line and wire passes draw nothing.
    frame_kept: bool = False

    def overlay_stats(self) -> DrawStats:
        """The surface pass's DrawStats over the viewport, with what the
        region lines counted (the deferred surface's record and lines are
        already in them: SurfacePass added them)."""
        stats = self.stats if self.stats is not None else DrawStats()
        if self.overlay_surface is None:
            stats.extra.update(self.line_stats.extra)
        return stats

    @property
    def aovs(self) -> bool:
        """The surface pass writes the render passes' outputs."""
        return bool(self.extra_passes & _SURFACE_AOVS)


class RenderPass:
    """One pass of the plan. ``render`` draws it into the frame's offscreen
    targets, ``over_viewport`` into the bound viewport framebuffer; a pass
    that has nothing to do in one of the two leaves it as it is."""

    def __init__(self, settings):
        self.settings = settings  # the DrawSettings this pass draws with

    def render(self, frame: Frame) -> None:
        pass

    def over_viewport(self, frame: Frame) -> None:
        pass


class RegionLinesPass(RenderPass):
    """The lines of multi-face regions (docs/image_model.md §2.6). Over the
    viewport: an image of its own, drawn first, which the surface and wire
    passes read. Offscreen the surface pass draws them between its two
    deferred stages, over its own visibility record."""

    def over_viewport(self, frame: Frame) -> None:
        if not _has_region_lines(frame.direct):
            return
        saved_viewport = gpu.state.viewport_get()
        try:
            frame.region_lines = _overlay_region_lines(
                frame.direct, frame.view, self.settings, frame.line_stats, frame.options, frame.base.clip_planes
            )
        finally:
            gpu.state.viewport_set(*saved_viewport)


class SurfacePass(RenderPass):
    """Every drawn face: depth, the fill and, with ``wire``, the visible
    wire. ``wire`` False (under hidden lines) shows no wire whatever an
    object's override says: offscreen the pass draws the wire into a layer
    of its own instead (targets.wire_layer), which WirePass blends over the
    hidden lines; over the viewport WirePass draws it again."""

    def __init__(self, settings, *, wire: bool = True):
        super().__init__(settings)
        self.wire = wire

    def render(self, frame: Frame) -> None:
        frame.stats = draw_surface(
            frame.targets,
            frame.items,
            frame.view,
            self.settings,
            wire=True,
            wire_layer=not self.wire,
            aovs=frame.aovs,
            cull=frame.cull,
            options=frame.options,
        )

    def over_viewport(self, frame: Frame) -> None:
        """Unless the scene's depth holds every item's surface (Solid
        shading without X-ray: not for an object drawn as wire or in front,
        item.in_scene_depth), a depth-only pre-pass comes first, so only the
        nearest of our own surfaces passes the colour passes (no back edges
        show through where the scene depth is empty). Where it does, the
        scene's depth already is that surface (our surfaces win the tie by
        the depth bias) and the pre-pass would only cost a second pass over
        every triangle; a deferred surface needs none either (its composite
        writes the record's depth). Without scene depth (X-ray: Blender's
        depth is no surface there) the bound depth is cleared first, so only
        our own surfaces occlude."""
        items, view, settings = frame.items, frame.view, frame.settings
        # The pre-pass gets the clipping planes and the LUT too: with the LUT
        # its variant, and so its compiled program, is the surface pass's.
        base = replace(frame.base, region_lines=frame.region_lines)
        if not frame.scene_depth:
            gpu.state.depth_mask_set(True)
            gpu.state.active_framebuffer_get().clear(depth=1.0)
        if frame.overlay_surface is not None:
            # (The deferred surface keeps an image of its own.)
            release_kept_images(view.width, view.height)
        elif _overlay_kept_frame(frame, self.settings, hidden=not self.wire):
            return  # (its composite writes our depth where the pre-pass would)
        if frame.overlay_surface is None and not (
            frame.scene_depth and frame.scene_surfaces and all(item.in_scene_depth for item in items)
        ):
            gpu.state.blend_set("NONE")
            gpu.state.color_mask_set(False, False, False, False)
            draw_mod.draw(items, view, settings, target=replace(base, depth_only=True))
            gpu.state.color_mask_set(True, True, True, True)
        gpu.state.blend_set("ALPHA_PREMULT")
        # Without the wire and the fill the pass would draw nothing the
        # pre-pass did not.
        if not self.wire and not self.settings.use_fill:
            return
        frame.stats = draw_mod.draw(frame.direct, view, self.settings, target=_with_lines(base, self.wire))
        if frame.overlay_surface is not None:
            _draw_overlay_surface(frame, _with_lines(base, self.wire))
            frame.stats.add(frame.line_stats)


class HiddenLinesPass(RenderPass):
    """Hidden lines (image model §5.4), behind the surface depth, blended
    "over" (draw.DrawTarget.hidden): first the layers of multi-face
    regions, peeled one at a time (_peel_hidden_regions), then every other
    triangle's directly."""

    def render(self, frame: Frame) -> None:
        targets = frame.targets
        if HIDDEN_WIRE_PASS in frame.extra_passes:
            # The Hidden Wire pass is these layers on their own: drawn once
            # into its target and blended over the image from there ("over"
            # is associative), not drawn twice.
            frame.extra[HIDDEN_WIRE_PASS] = _hidden_wire(frame, self.settings)
            _blend_layer(targets.color, targets.depth, targets.own_layer, frame.view)
            return
        peeled = _peel_hidden_regions(
            frame,
            self.settings,
            targets,
            into=((targets.color_framebuffer, "GREATER"),),
            behind=targets.depth,
            stats=frame.stats,
        )
        _blended(
            frame,
            lambda: _draw_hidden(frame.items, peeled, frame.view, self.settings, frame.base, frame.cull, frame.stats),
        )

    def over_viewport(self, frame: Frame) -> None:
        if frame.frame_kept:
            return
        # The overlay's own targets; Blender's depth cannot be read, so the
        # layers are peeled from the front and Blender's depth test keeps
        # those behind its surface when they are composited.
        view = frame.view
        targets = overlay_targets_for(view.width, view.height)
        saved_viewport = gpu.state.viewport_get()
        try:
            peeled = _peel_hidden_regions(
                frame,
                self.settings,
                targets,
                into=((None, "GREATER"),),
                stats=frame.line_stats,
                restore_viewport=saved_viewport,
            )
        finally:
            gpu.state.viewport_set(*saved_viewport)
        if peeled:
            targets.surface_key = None  # its record was drawn over: the next redraw records it whole
        _draw_hidden(frame.items, peeled, view, self.settings, frame.base, frame.cull, frame.line_stats)


def _draw_hidden(
    items, peeled, view: View, settings, base: DrawTarget, cull: bool, stats: DrawStats | None, test: str = "GREATER"
) -> None:
    """The direct hidden-line pass into the bound framebuffer: every
    triangle of ``items`` walks its region, except those whose layers
    _peel_hidden_regions drew (the region triangles of ``peeled``; a peeled
    mesh with no other triangle is not drawn at all); ``test``: its depth
    test (ALWAYS: every fragment, whatever lies in front). The triangles
    it left out for showing no line (DrawTarget.drop_lineless), and those
    it drew measuring their walk's picks alone, go into ``stats``'s extra
    counts; what it drew is the surface pass's to count."""
    peeled_ids = {id(item) for item in peeled}
    walked = [item for item in items if id(item) not in peeled_ids]
    rest = [item for item in peeled if item.mesh.region_sizes()[2]]
    drawn = [draw_mod.draw(walked, view, settings, target=replace(base.hidden(), depth_test=test), cull=cull)]
    peeled_target = replace(base.hidden(region_layers_peeled=True), depth_test=test)
    drawn.append(draw_mod.draw(rest, view, settings, target=peeled_target, cull=cull))
    for counts in drawn if stats is not None else ():
        for name in (draw_mod.LINELESS_LEFT_OUT, draw_mod.WALK_PICKS_DRAWN):
            if name in counts.extra:
                stats.add(DrawStats(extra={name: counts.extra[name]}))


def _overlay_kept_frame(frame: Frame, settings, hidden: bool) -> bool:
    """A frame the overlay draws directly (nothing deferred: under hidden
    lines, in X-ray or Wireframe shading, inside a clipping region, sparse
    meshes), kept as one or two images once a redraw repeats the key of
    the one before (_keeping), and composited from then on; False where it
    is drawn directly (a new key: an orbit, a drag, which pays nothing for
    the keeping). ``settings``: the surface pass's; ``hidden``: hidden
    lines are on.

    Blender's depth at a pixel is either our nearest surface (less the
    bias: ours, or Blender's own drawing of it) or something Blender drew
    in front of it, so the passes drawn directly leave one of two images
    there: the first, as if Blender's depth held our own surfaces alone
    (the surface; under hidden lines the fill, the hidden lines behind our
    nearest surface and the wire), or the second, as if something hid every
    one of our surfaces (every hidden line of every layer, nothing else;
    without hidden lines, nothing). _draw_kept_frame draws them; the first
    is composited at our nearest surface's depth, tested LESS_EQUAL against
    Blender's and written, the second at the same depth tested GREATER, so
    each pixel takes the one its depth picks."""
    if not frame.items:
        return False  # (strands alone: nothing of ours to keep)
    view = frame.view
    targets = overlay_targets_for(view.width, view.height)
    key = _overlay_image_key("frame", frame.items, view, settings, frame.base.display, frame.base.clip_planes)
    edited, rect = _kept_frame_rect(targets, key, frame, settings, hidden)
    if edited:
        # An edit: drawn into the kept images (inside ``rect`` where known),
        # so that the next edit of a drag can redraw only what it changes.
        targets.drawn_keys["frame"] = key
        composite = _composite_shader()
    else:
        composite = _keeping(targets, "frame", key)
    if composite is None:
        return False
    visible = targets.kept_image("frame")
    occluded = targets.kept_image("frame, occluded") if hidden else None
    if not hidden:
        targets.kept.pop("frame, occluded", None)
    if visible.key == key or rect == ():
        frame.line_stats.extra["frame_reused"] = 1
    else:
        visible.key = None
        saved_viewport = gpu.state.viewport_get()
        try:
            with _state_kept():
                counts = _draw_kept_frame(frame, settings, targets, visible, occluded, rect)
        finally:
            gpu.state.viewport_set(*saved_viewport)
        if rect is None:
            visible.counts = counts
            _ready_for_partial_redraws(frame.items)
        else:
            frame.line_stats.extra["frame_partial"] = 1
        if edited and rect is None:
            frame.line_stats.extra["frame_edited"] = 1
        visible.box = _window_box_px(frame.items, view)
    visible.key = key
    drawn, culled, triangles, layers = visible.counts
    frame.stats = DrawStats(drawn, culled, triangles)
    if layers:
        frame.line_stats.extra["hidden_region_layers"] = layers
    if visible.box is not None:
        with _state_kept():
            _composite_kept(
                composite, visible.depth, visible.colour, visible.box, view, None, test="LESS_EQUAL", write_depth=True
            )
            if occluded is not None:
                _composite_kept(composite, visible.depth, occluded.colour, visible.box, view, None)
    frame.frame_kept = True
    return True


def _kept_frame_rect(targets, key, frame: Frame, settings, hidden: bool):
    """(edited, rect): whether the kept frame (_overlay_kept_frame) was
    drawn for a key that differs from ``key`` only by meshes that moved
    some vertices (an edit, a drag: _moved_items), and then the window
    rectangle the moves changed (_redraw_rect; () where they changed
    nothing; None where that is not known), all of the kept images that
    needs drawing again.

    An edit of what the last redraw drew directly (a drag whose first step
    extracted the mesh again, a quad now split the other way; an edit
    right after an orbit) is an edit too, with the whole of the kept
    images to draw: the next step of the drag then redraws only what it
    changes, where drawing this one directly would leave every later step
    to draw directly too."""
    visible = targets.kept.get("frame")
    if visible is not None and visible.key is not None and not (hidden and "frame, occluded" not in targets.kept):
        moved = _moved_items(visible.key, key, frame.items)
        if moved is not None:
            return True, _redraw_rect(moved, frame.view, settings, frame.items)
    drawn = targets.drawn_keys.get("frame")
    if drawn != key and _moved_items(drawn, key, frame.items) is not None:
        return True, None
    return False, None


def _composite_shader():
    """The kept images' composite shader, or None where the backend refuses it."""
    try:
        return shaders.get_overlay_composite(0.0)
    except shaders.DeferredUnavailable:
        return None


def _draw_kept_frame(frame: Frame, settings, targets, visible, occluded, rect=None) -> tuple:
    """The images of _overlay_kept_frame, drawn as the passes draw over the
    viewport: into ``visible`` over our own depth (a depth-only pass of our
    surfaces first, as Blender's depth holds them), and with hidden lines
    (``occluded`` not None) the hidden lines alone, untested, into
    ``occluded``; with ``rect`` (x, y, width, height) inside that window
    rectangle alone, the rest of both images kept (each pixel depends only
    on the triangles that cover it, and on a software rasteriser only the
    triangle blocks that can reach the rectangle are drawn). Returns
    (objects drawn, culled, triangles drawn, hidden layers peeled)."""
    view, base, cull = frame.view, frame.base, frame.cull
    if rect is not None and shaders.software_rasteriser():
        base = replace(base, scissor_window=(*rect, 1.0))  # (a triangle draws only where it covers)
    items = frame.items
    width, height = view.width, view.height
    lines_base = replace(base, region_lines=frame.region_lines)
    # (A framebuffer brings its own scissor when bound: set after each bind.)
    front = visible.framebuffer()
    with front.bind(), _scissored(rect):
        _clear(front, width, height)
        gpu.state.color_mask_set(False, False, False, False)
        draw_mod.draw(items, view, settings, target=replace(lines_base, depth_only=True), cull=cull)
        gpu.state.color_mask_set(True, True, True, True)
        gpu.state.blend_set("ALPHA_PREMULT")
        if occluded is None:
            stats = draw_mod.draw(items, view, settings, target=lines_base, cull=cull)
            return stats.objects_drawn, stats.objects_culled, stats.triangles_drawn, 0
        if settings.use_fill:
            draw_mod.draw(items, view, settings, target=_with_lines(lines_base, False), cull=cull)
    wire_only = replace(settings, use_fill=False)  # (as plan() gives the hidden-line and wire passes)
    # The hidden lines go into both images: one walk of each mesh for both.
    base = replace(base, walk_scope=object())
    behind = occluded.framebuffer(visible.depth)  # (never written: only the visible image's depth is)
    with behind.bind(), _scissored(rect):
        _clear(behind, width, height, depth=False)
    into = ((visible.framebuffer, "GREATER"), (lambda: occluded.framebuffer(visible.depth), "ALWAYS"))
    peeled = _peel_hidden_regions(frame, wire_only, targets, into=into, stats=frame.line_stats, box=rect)
    if peeled:
        targets.surface_key = None  # its record was drawn over: the next redraw records it whole
    for framebuffer_of, test in into:
        framebuffer = framebuffer_of()
        with framebuffer.bind(), _scissored(rect):
            _no_clear(width, height)
            gpu.state.blend_set("ALPHA_PREMULT")
            _draw_hidden(items, peeled, view, wire_only, base, cull, frame.line_stats, test=test)
    with front.bind(), _scissored(rect):
        _no_clear(width, height)
        gpu.state.blend_set("ALPHA_PREMULT")
        stats = draw_mod.draw(items, view, wire_only, target=lines_base, cull=cull)
    layers = frame.line_stats.extra.get("hidden_region_layers", 0) if peeled else 0
    return stats.objects_drawn, stats.objects_culled, stats.triangles_drawn, layers


def _window_box_px(items, view: View):
    """The pixels (x, y, width, height) the items' window boxes cover
    (draw.window_union), or None where they cover none."""
    x0, y0, x1, y1 = draw_mod.window_union(items, view)
    left = max(int(np.floor((x0 + 1.0) * 0.5 * view.width)), 0)
    bottom = max(int(np.floor((y0 + 1.0) * 0.5 * view.height)), 0)
    right = min(int(np.ceil((x1 + 1.0) * 0.5 * view.width)), view.width)
    top = min(int(np.ceil((y1 + 1.0) * 0.5 * view.height)), view.height)
    if right <= left or top <= bottom:
        return None
    return left, bottom, right - left, top - bottom


def _keeping(targets, name: str, key):
    """Whether the overlay composites its kept image ``name`` (drawn for
    ``key``: kept now, or already) instead of drawing directly: the
    composite shader where the image has that key or the redraw before
    drew that key (a redraw that changes nothing; the caller then draws
    the image first), else None, the key remembered. A redraw with a new
    key (an orbit, a drag) draws directly, which costs one pass, where
    keeping costs a pass into the image and a composite."""
    kept = targets.kept_image(name)
    drawn, targets.drawn_keys[name] = targets.drawn_keys.get(name), key
    if key is None or (kept.key != key and drawn != key):
        return None
    return _composite_shader()


@contextmanager
def _state_kept():
    """Blending, depth test and depth writes as they were on entry, on exit."""
    saved = gpu.state.blend_get(), gpu.state.depth_test_get(), gpu.state.depth_mask_get()
    try:
        yield
    finally:
        gpu.state.blend_set(saved[0])
        gpu.state.depth_test_set(saved[1])
        gpu.state.depth_mask_set(saved[2])


class WirePass(RenderPass):
    """The visible wire on its own, over the hidden lines; leaves the
    surface's depth and view depth alone."""

    def render(self, frame: Frame) -> None:
        # The surface pass drew the wire into a layer of its own, unblended
        # (SurfacePass): where two triangles lie at the surface's very depth
        # (a flat n-gon whose outline crosses itself has triangles on one
        # another) the last one stays, as in the surface pass without hidden
        # lines, where blended straight over the hidden lines the line would
        # count twice (1 - (1 - I)^2). That layer goes "over" the image now.
        targets = frame.targets
        _blend_layer(targets.color, targets.depth, targets.wire_layer, frame.view)

    def over_viewport(self, frame: Frame) -> None:
        if not frame.frame_kept:
            frame.stats = _draw(frame, self.settings, replace(frame.base, region_lines=frame.region_lines))


class OutputsPass(RenderPass):
    """Offscreen only: the Hidden Wire pass when asked for, then the image
    and view depth read back, and the surface pass's extra outputs."""

    def render(self, frame: Frame) -> None:
        targets = frame.targets
        if HIDDEN_WIRE_PASS in frame.extra_passes and HIDDEN_WIRE_PASS not in frame.extra:
            frame.extra[HIDDEN_WIRE_PASS] = _hidden_wire(frame, self.settings)
        # The surface passes' outputs need the coverage that the view depth holds.
        aovs = frame.aovs
        frame.rgba, frame.depth = targets.read(keep=frame.keep_readback, depth=frame.read_depth or aovs)
        if aovs:
            covered = frame.depth < BACKGROUND_DEPTH
            aov = read_texture(targets.aov, 4)
            frame.extra[WIRE_PASS] = aov[..., 1:2]
            frame.extra[EDGE_DISTANCE_PASS] = np.where(covered, aov[..., 0], BACKGROUND_DEPTH)[..., None]
            frame.extra[OBJECT_INDEX_PASS] = aov[..., 2:3]
            frame.extra[MATERIAL_INDEX_PASS] = aov[..., 3:4]
            frame.extra[NORMAL_PASS] = read_texture(targets.normal, 4)[..., :3]


class SilhouettePass(RenderPass):
    """The outer halves of silhouette edges (image model §5.5): offscreen
    into a target of their own, composited over the read-back image; over
    the viewport straight into it."""

    def render(self, frame: Frame) -> None:
        frame.rgba = _composite_silhouettes(frame.rgba, frame.targets, frame.items, frame.view, self.settings)

    def over_viewport(self, frame: Frame) -> None:
        silhouettes.draw_silhouettes(frame.items, frame.view, self.settings, frame.base)


class StrandsPass(RenderPass):
    """Hair and point clouds (core/strands.py), over everything above."""

    def render(self, frame: Frame) -> None:
        frame.rgba, frame.depth = strands_mod.composite_render(
            frame.rgba, frame.depth, frame.targets, frame.view, self.settings, frame.strands
        )

    def over_viewport(self, frame: Frame) -> None:
        strands_mod.draw_over_viewport(frame.strands, frame.view, self.settings, frame.base)


def plan(settings, *, strands: bool = False) -> tuple[RenderPass, ...]:
    """The passes ``settings`` need, in drawing order (an option that is off
    adds no pass). Over the viewport OutputsPass does nothing; offscreen
    RegionLinesPass does nothing (the surface pass draws the lines)."""
    passes: list[RenderPass] = [RegionLinesPass(settings)]
    if settings.use_hidden_lines:
        # Hidden lines sit under the visible wire and over the fill: the
        # surface pass shows the fill alone (offscreen its wire goes into a
        # layer of its own), then hidden lines, then the wire.
        wire_only = replace(settings, use_fill=False)
        passes += [SurfacePass(settings, wire=False), HiddenLinesPass(wire_only), WirePass(wire_only)]
    else:
        passes.append(SurfacePass(settings))
    passes.append(OutputsPass(settings))
    if settings.use_silhouettes:
        passes.append(SilhouettePass(settings))
    if strands:
        passes.append(StrandsPass(settings))
    return tuple(passes)


def _with_lines(target: DrawTarget, wire: bool) -> DrawTarget:
    return target if wire else replace(target, lines=draw_mod.NO_LINES)


def _draw(frame: Frame, settings, target: DrawTarget):
    return draw_mod.draw(frame.items, frame.view, settings, target=target, cull=frame.cull)


def _blended(frame: Frame, draw_pass) -> None:
    """A pass blended "over" the offscreen colour: a framebuffer without the
    view-depth target, which must keep the surface's view depth."""
    with frame.targets.color_framebuffer().bind():
        gpu.state.viewport_set(0, 0, frame.view.width, frame.view.height)
        gpu.state.blend_set("ALPHA_PREMULT")
        try:
            draw_pass()
        finally:
            gpu.state.blend_set("NONE")
            gpu.state.depth_test_set("NONE")


def render(items, view: View, settings, *, cull: bool = True, options: DrawOptions = DEFAULT_OPTIONS):
    """Draw ``items`` offscreen; return (rgba, view_depth, stats).

    ``rgba`` is (H, W, 4) float32, premultiplied, bottom row first, over a
    transparent background; ``view_depth`` is (H, W) with BACKGROUND_DEPTH
    where nothing was drawn. The caller makes sure the GPU is usable."""
    rgba, depth, stats, _extra = render_passes(items, view, settings, cull=cull, options=options)
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
    options: DrawOptions = DEFAULT_OPTIONS,
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
    frame = Frame(
        items,
        view,
        settings,
        DrawTarget(linear_depth=True, drop_lineless=_drop_lineless(options)),
        options=options,
        cull=cull,
        strands=tuple(strands),
        targets=targets_for(view.width, view.height),
        extra_passes=extra_passes,
        keep_readback=keep_readback,
        read_depth=read_depth,
    )
    for unit in plan(settings, strands=bool(strands)):
        unit.render(frame)
    extra = {name: value for name, value in frame.extra.items() if name in extra_passes}
    return frame.rgba, frame.depth, frame.stats, extra


def _clear(framebuffer, width: int, height: int, depth: bool = True, color: bool = True) -> None:
    # A clear honours the depth write mask, and GPU state lives per GL
    # context: a previous frame drawn in this context may have left depth
    # writes off, which left the old depth in place (wrong occlusion in the
    # next render drawn in that context).
    gpu.state.depth_mask_set(depth)
    gpu.state.color_mask_set(True, True, True, True)
    gpu.state.blend_set("NONE")
    if not color:
        framebuffer.clear(depth=1.0)
    elif depth:
        framebuffer.clear(color=(0.0, 0.0, 0.0, 0.0), depth=1.0)
    else:
        framebuffer.clear(color=(0.0, 0.0, 0.0, 0.0))
    gpu.state.viewport_set(0, 0, width, height)


def _no_clear(width: int, height: int) -> None:
    """The state _clear leaves, without clearing anything."""
    gpu.state.depth_mask_set(False)
    gpu.state.color_mask_set(True, True, True, True)
    gpu.state.blend_set("NONE")
    gpu.state.viewport_set(0, 0, width, height)


def draw_surface(
    targets,
    items,
    view: View,
    settings,
    *,
    wire: bool = True,
    wire_layer: bool = False,
    aovs: bool = False,
    cull: bool = True,
    options: DrawOptions = DEFAULT_OPTIONS,
):
    """The surface pass into ``targets`` (cleared first): depth, the fill
    and the visible wire (none with ``wire`` False; into
    ``targets.wire_layer`` instead of the colour with ``wire_layer``), and
    the render passes' outputs with ``aovs``. Meshes dense on screen are drawn deferred
    (docs/image_model.md §2.5, draw.split_deferred) unless ``options`` say
    otherwise, the rest directly, into the same depth buffer; the same image
    either way. Returns the DrawStats."""
    width, height = view.width, view.height
    target = DrawTarget(
        linear_depth=True,
        aovs=aovs,
        lines=draw_mod.WIRE_LINES if wire else draw_mod.NO_LINES,
        wire_layer=wire and wire_layer,
    )
    deferred, direct = ([], list(items))
    if options.deferred_surface and shaders.deferred_available():
        no_lines = None if wire else draw_mod.DEFERRED_MIN_DENSITY_NO_LINES
        deferred, direct = draw_mod.split_deferred(items, view, no_lines)
    # A mesh drawn directly takes its regions' lines from the region-lines
    # pass too (docs/image_model.md §2.6), over a record of its own, as the
    # viewport overlay's direct meshes do: no pixel walks a region's edges.
    line_stats = DrawStats()
    direct_lines = _direct_region_lines(targets, direct, view, settings, target, cull, options, line_stats)
    framebuffer = targets.framebuffer(aovs=aovs, wire_layer=target.wire_layer)
    with framebuffer.bind():
        _clear(framebuffer, width, height)
        targets.clear_view_depth()
        stats = draw_mod.draw(
            direct, view, settings, target=replace(target, view_depth=True, **direct_lines), cull=cull
        )
        gpu.state.depth_test_set("NONE")
        gpu.state.depth_mask_set(False)
    stats.extra.update(line_stats.extra)
    if deferred:
        try:
            stats.add(
                _deferred_surface(targets, deferred, view, settings, target, cull, options, after_direct=bool(direct))
            )
        except shaders.DeferredUnavailable as exc:
            _refused(exc)
            return draw_surface(
                targets, items, view, settings, wire=wire, wire_layer=wire_layer, aovs=aovs, cull=cull, options=options
            )
    return stats


def _deferred_surface(
    targets,
    items,
    view: View,
    settings,
    target: DrawTarget,
    cull: bool,
    options: DrawOptions,
    *,
    after_direct: bool = True,
):
    """The surface pass of ``items`` in two stages over the depth the direct
    draws left: which triangle each pixel shows (depth test, no shading),
    then the exact fragment stage once per pixel shown. Same depth, same
    image as the direct pass; the edge set-up runs once per visible pixel
    instead of at every corner of every triangle.

    The resolve is depth-tested against the record, so it reads the record
    only where a surface is; where nothing was drawn directly first
    (``after_direct`` False) every such pixel gets its record from this
    pass, and the record needs no clear. (The region-lines pass may read a
    stale record beside the surface, and write lines there that no resolve
    reads.)"""
    width, height = view.width, view.height
    # (keep_depth: the direct draws' depth stays)
    stats = _record_visibility(
        targets, items, view, settings, target, options, cull=cull, keep_depth=True, clear_record=after_direct
    )
    # The lines of multi-face regions as quads over the record, so that no
    # pixel walks a region's edges (docs/image_model.md §2.6).
    images = _region_line_images(targets, items, view, settings, target, cull, stats)
    with targets.resolve_framebuffer(aovs=target.aovs, wire_layer=target.wire_layer).bind():
        gpu.state.viewport_set(0, 0, width, height)
        resolve = replace(target, stage=draw_mod.RESOLVE, visibility=targets.visible, view_depth=True, **images)
        draw_mod.draw(items, view, settings, target=resolve, cull=cull)
    return stats


def _region_line_images(targets, items, view: View, settings, target: DrawTarget, cull: bool, stats) -> dict:
    """The region-lines images of ``items`` over their visibility record in
    ``targets.visible``, as DrawTarget fields for the pass that reads them
    (both None without multi-face regions). A pass with the wire switched
    off needs no lines, unless it writes the render passes (the Wire pass
    is the visible lines' intensity whether or not the image shows them:
    the fill under hidden lines). The Edge Distance pass needs d itself:
    with the render passes' outputs a second run keeps each pixel's nearest
    line distance, which the reader takes in place of a walk. The lines
    pass keeps ``aovs``: with it draw() groups and numbers the draws as the
    record and the reader do; it writes no output of them."""
    lines = distances = None
    if _has_region_lines(items):
        if target.lines != draw_mod.NO_LINES or target.aovs:
            lines = _draw_region_lines(targets, items, view, settings, target, cull, stats)
        if target.aovs:
            distances = _draw_region_lines(
                targets, items, view, settings, replace(target, line_distance=True), cull, stats
            )
    return {"region_lines": lines, "region_distance": distances}


def _direct_region_lines(targets, direct, view: View, settings, target: DrawTarget, cull, options, stats) -> dict:
    """_region_line_images for the meshes the surface pass draws directly
    (with the deferred surface switched off, DrawOptions.deferred_surface):
    a record of those that read the image alone (_line_image_readers),
    then their lines over it. The direct pass's depth test lets only the
    nearest surface through, and where that is a reader's triangle the
    record holds it too, so the record needs no other mesh (as the viewport
    overlay's, _overlay_region_lines). Nothing where the record cannot
    number them all exactly (draw.DEFERRED_MAX) or its stages do not
    compile here: those pixels walk their regions."""
    items = _line_image_readers(direct)
    numbered = len(items) < draw_mod.DEFERRED_MAX and all(
        item.mesh.triangle_count < draw_mod.DEFERRED_MAX for item in items
    )
    if not (_has_region_lines(items) and numbered and shaders.deferred_available()):
        return {}
    try:
        _record_visibility(targets, items, view, settings, target, options, cull=cull)
        return _region_line_images(targets, items, view, settings, target, cull, stats)
    except shaders.DeferredUnavailable as exc:
        _refused(exc)
        return {}


def _record_visibility(
    targets,
    items,
    view: View,
    settings,
    target: DrawTarget,
    options: DrawOptions,
    *,
    cull=True,
    keep_depth=False,
    scissor=None,
    clear_record=True,
    framebuffer=None,
):
    """The visibility record of ``items`` into ``targets.visible`` (which
    triangle each pixel shows; depth test, no shading), drawn as ``target``
    says apart from its stage; ``keep_depth`` keeps the depth already in the
    targets; ``scissor`` (x, y, width, height) records that rectangle alone;
    ``clear_record`` False leaves the last record where nothing is drawn
    now (for a reader that tests depth first); ``framebuffer`` another
    framebuffer over that texture (a hidden region layer's). Returns the
    DrawStats."""
    framebuffer = framebuffer or targets.visibility_framebuffer()
    # Inside a scissor a software rasteriser records only the blocks of
    # triangles that can cover it (as the region lines' runs below): it
    # would transform and set up every triangle before the scissor drops
    # it. The reach is a pixel of rounding to spare.
    window = None if scissor is None or not shaders.software_rasteriser() else (*scissor, 1.0)
    with framebuffer.bind(), _scissored(scissor):
        if clear_record or not keep_depth:
            _clear(framebuffer, view.width, view.height, depth=not keep_depth)
        else:
            _no_clear(view.width, view.height)
        record = replace(
            target,
            stage=draw_mod.VISIBILITY,
            triangle_ids_by_vertex=_triangle_ids_by_vertex(options),
            scissor_window=window,
        )
        stats = draw_mod.draw(items, view, settings, target=record, cull=cull)
        gpu.state.depth_test_set("NONE")
        gpu.state.depth_mask_set(False)
    return stats


# The scissor _scissored set, innermost last (gpu.state has no getter for
# the scissor test, so the nesting is kept here).
_scissors: list = []


@contextmanager
def _scissored(scissor):
    """Clears and draws inside the bound framebuffer limited to ``scissor``
    (x, y, width, height; None: no further limit), inside the scissor of
    an enclosing _scissored, which holds again on exit."""
    if scissor is None:
        yield
        return
    if _scissors:
        scissor = _intersection(_scissors[-1], scissor)
    _scissors.append(scissor)
    gpu.state.scissor_test_set(True)
    gpu.state.scissor_set(*scissor)
    try:
        yield
    finally:
        _scissors.pop()
        if _scissors:
            gpu.state.scissor_set(*_scissors[-1])
        else:
            gpu.state.scissor_test_set(False)


def _intersection(a, b) -> tuple:
    """The rectangle (x, y, width, height) two rectangles share (width or
    height 0 where they share none)."""
    x0, y0 = max(a[0], b[0]), max(a[1], b[1])
    x1, y1 = min(a[0] + a[2], b[0] + b[2]), min(a[1] + a[3], b[1] + b[3])
    return x0, y0, max(x1 - x0, 0), max(y1 - y0, 0)


def _triangle_ids_by_vertex(options: DrawOptions) -> bool:
    if options.triangle_ids_by_vertex is not None:
        return options.triangle_ids_by_vertex
    return shaders.triangle_ids_by_vertex()


def _drop_lineless(options: DrawOptions) -> bool:
    if options.drop_lineless_triangles is not None:
        return options.drop_lineless_triangles
    return shaders.software_rasteriser()


def _has_region_lines(items) -> bool:
    return any(item.mesh.region_line_count for item in items)


def _line_image_readers(items) -> list:
    """The items whose triangles read the region-lines image: those with
    multi-face regions, whether or not a region has a line
    (cache.GPUMesh.reads_region_line_image). A record for that image holds
    them all: where such a triangle is the nearest surface, the record then
    shows it, and no line of a region it hides is kept there."""
    return [item for item in items if item.mesh.region_line_count or item.mesh.reads_region_line_image]


def _draw_region_lines(targets, items, view: View, settings, target: DrawTarget, cull: bool, stats, scissor=None):
    """The region-lines pass over ``targets.visible`` (the visibility
    record of ``items``, numbered as draw() numbers them): the strongest
    line per pixel into ``targets.lines``, which it returns (with
    ``target.line_distance`` the nearest line's distance into
    ``targets.line_distances``; with HIDDEN_LINES a hidden layer's lines
    into ``targets.hidden_lines``); ``scissor`` as _record_visibility's."""
    hidden = target.lines == draw_mod.HIDDEN_LINES
    if hidden:
        framebuffer = targets.hidden_lines_framebuffer()
    elif target.line_distance:
        framebuffer = targets.line_distance_framebuffer()
    else:
        framebuffer = targets.region_lines_framebuffer()
    # Inside a scissor a software rasteriser draws only the runs whose
    # lines reach it (the scissor comes from _redraw_rect, which measures the
    # lines' reach): it would set up every run's quad before the scissor
    # drops it, where a GPU drops them for less than picking them costs.
    reach = None if scissor is None or not shaders.software_rasteriser() else _line_reach_px(settings, items)
    with framebuffer.bind(), _scissored(scissor):
        # The lines are the depth alone, or (a hidden layer's) depth and colour.
        _clear(framebuffer, view.width, view.height, color=hidden)
        lines = replace(
            target,
            stage=draw_mod.LINES,
            visibility=targets.visible,
            scissor_window=None if reach is None else (*scissor, reach),
        )
        left_out = 0
        for runs in _line_run_draws(items, settings, target):
            drawn = draw_mod.draw(items, view, settings, target=replace(lines, line_runs=runs), cull=cull)
            left_out += drawn.extra.get("region_runs_left_out", 0)
        gpu.state.depth_test_set("NONE")
        gpu.state.depth_mask_set(False)
    stats.extra["region_line_entries"] = sum(item.mesh.region_line_count for item in items)
    if left_out:
        stats.extra["region_runs_left_out"] = left_out
    if hidden:
        return targets.hidden_lines
    return targets.line_distances if target.line_distance else targets.lines


def _line_run_draws(items, settings, target: DrawTarget) -> tuple:
    """The LINES draws of the strongest visible line (draw.ALL_RUNS...):
    with edge classes on, the wire's runs apart from the classes', so that
    most runs take the shader without per-style code; each draw keeps the
    strongest line per pixel by the same depth test, so the image is the
    one draw's. The nearest line's distance and a hidden layer's lines
    take no class code anyway."""
    if target.line_distance or target.lines == draw_mod.HIDDEN_LINES or not draw_mod.edge_classes_of(settings):
        return (draw_mod.ALL_RUNS,)
    draws = ()
    if any(item.mesh.region_wire_runs for item in items):
        draws += (draw_mod.WIRE_RUNS,)
    if any(item.mesh.region_wire_runs < item.mesh.region_run_count for item in items):
        draws += (draw_mod.CLASS_RUNS,)
    return draws


def _overlay_region_lines(items, view: View, settings, stats, options: DrawOptions = DEFAULT_OPTIONS, clip_planes=None):
    """The viewport overlay's region lines: a visibility record of the
    meshes with multi-face regions at the region's size (own depth:
    Blender's depth buffer cannot be read back here; inside the viewport's
    clipping region ``clip_planes``, which cuts the record as it cuts the
    surface), then the region-lines pass over it. The overlay's surface
    pass reads the result where its depth test lets a region's triangle
    through: the depth it tests against
    (Blender's, or our own pre-pass of every mesh) lets only the nearest
    surface pass, and where that is a region's triangle, the record holds it
    too. So the record needs no other mesh.

    A redraw that changes nothing the lines depend on (the view, the
    settings, which meshes in which shape where) reuses the last image of
    that viewport size: a viewport redraws far more often than its scene
    changes."""
    items = _line_image_readers(items)
    targets = overlay_targets_for(view.width, view.height)
    key = _overlay_lines_key(items, view, settings, clip_planes)
    if key is not None and targets.lines_key == key and targets.lines is not None:
        stats.extra["region_line_entries"] = sum(item.mesh.region_line_count for item in items)
        stats.extra["region_lines_reused"] = 1
        return targets.lines
    # Only vertices moved since the last image: record and draw the lines
    # again inside the rectangle the moves changed (as _overlay_surface).
    moved = _moved_in_lines(targets.lines_key, key, items) if targets.lines is not None else None
    scissor = None if moved is None else _redraw_rect(moved, view, settings, items)
    targets.lines_key = None
    record = DrawTarget(linear_depth=True, clip_planes=clip_planes)
    if scissor is not None:
        stats.extra["region_lines_partial"] = 1
        lines = targets.lines
        if scissor:
            _record_visibility(targets, items, view, settings, record, options, scissor=scissor)
            lines = _draw_region_lines(
                targets, items, view, settings, DrawTarget(linear_depth=True), True, stats, scissor
            )
    else:
        _record_visibility(targets, items, view, settings, record, options)
        _ready_for_partial_redraws(items)
        lines = _draw_region_lines(targets, items, view, settings, DrawTarget(linear_depth=True), True, stats)
    targets.lines_key = key
    return lines


def _overlay_lines_key(items, view: View, settings, clip_planes=None):
    """What the overlay's region lines depend on, or None when that cannot
    be told (a setting that does not hash): each mesh by its serial and
    shape version (cache.GPUMesh), its matrix and style, the view, the
    settings and the clipping region."""
    try:
        return (
            view.view_matrix.tobytes(),
            view.projection.tobytes(),
            tuple(view.viewport),
            hash(settings),
            tuple((item.mesh.serial, item.mesh.version, item.matrix.tobytes(), item.style) for item in items),
            None if clip_planes is None else np.asarray(clip_planes, dtype=np.float64).tobytes(),
        )
    except (TypeError, AttributeError):
        return None


def _overlay_image_key(kind: str, items, view: View, settings, display, clip_planes=None):
    """What an image the overlay keeps depends on (the region lines' key,
    _overlay_lines_key, with the display transform and each mesh's colour
    source), or None when that cannot be told."""
    key = _overlay_lines_key(items, view, settings, clip_planes)
    if key is None:
        return None
    key = (kind, key, None if display is None else display.key, tuple(item.source for item in items))
    try:
        hash(key)
    except TypeError:
        return None
    return key


def _sync_overlay_surface(frame: Frame) -> None:
    """The overlay's sync step: where the frame is the surface pass alone
    (silhouettes may follow), the meshes dense on screen
    (OVERLAY_DEFERRED_MIN_DENSITY, and every mesh with multi-face regions)
    are recorded into the overlay's own targets (_overlay_surface) for the
    surface pass to draw (_draw_overlay_surface); the rest stays in
    ``frame.direct``. The record knows which of our own triangles is
    nearest at each pixel, and its composite writes that depth, so Blender's
    depth need not hold our surfaces (X-ray, Wireframe shading) where every
    mesh is deferred. A deferred stage the backend refuses falls back to
    drawing directly, said once."""
    frame.direct = list(frame.items)
    if not _overlay_defers(frame):
        return
    deferred, direct = draw_mod.split_deferred(frame.items, frame.view, OVERLAY_DEFERRED_MIN_DENSITY)
    if not deferred or (direct and not frame.scene_surfaces):
        # (Without Blender's depth of our surfaces a mesh drawn directly
        # would need the deferred ones' depth before its colour, and they
        # its depth before theirs: such a frame is drawn directly.)
        return
    saved_viewport = gpu.state.viewport_get()
    try:
        shaders.get_overlay_composite(frame.base.depth_bias)  # compiled before anything is drawn: a refusal falls back
        frame.overlay_surface = _overlay_surface(deferred, frame.view, frame.settings, frame.base.display, frame)
        frame.direct = direct
    except shaders.DeferredUnavailable as exc:
        _refused(exc)
    finally:
        gpu.state.viewport_set(*saved_viewport)


def _refused(exc: Exception) -> None:
    shaders.disable_deferred()
    warn_once(
        ("deferred",),
        f"SolidWire: the deferred surface pass is not available here ({exc}); drawing directly "
        f"(a region of more than {WALK_LIMIT} drawn edges is measured face by face)",
    )


def _overlay_defers(frame: Frame) -> bool:
    """Whether the overlay's surface may be deferred: the frame's passes are
    the surface pass alone (silhouettes may follow), no clipping region, and
    the deferred stages are in use, and every item is drawn as a surface
    Blender's depth test can meet (item.in_scene_depth: not as wire, not in
    front)."""
    units = plan(frame.settings)
    drawing = [unit for unit in units if not isinstance(unit, (RegionLinesPass, OutputsPass, SilhouettePass))]
    return (
        frame.base.clip_planes is None
        and frame.options.deferred_surface
        and shaders.deferred_available()
        and len(drawing) == 1
        and isinstance(drawing[0], SurfacePass)
        and drawing[0].wire
        and all(item.in_scene_depth for item in frame.items)
    )


@dataclass
class OverlaySurface:
    """The deferred overlay's surface of one frame (_overlay_surface): the
    deferred ``items``, the overlay's ``targets`` holding their record,
    their region-lines image ``lines`` (None without multi-face regions),
    and whether ``targets.surface`` holds their resolved image (``kept``:
    the surface pass composites it) or not (the surface pass resolves the
    record straight into Blender's buffer)."""

    targets: object
    items: list
    lines: object
    kept: bool


def _overlay_surface(items, view: View, settings, display, frame: Frame) -> OverlaySurface:
    """The deferred overlay's surface, in the overlay's own targets at the
    viewport's size: the visibility record of ``items`` over a depth buffer
    of its own (window depth, as Blender's), and the region lines over it
    when a mesh has multi-face regions (docs/image_model.md §2.5, §2.6);
    ``frame.line_stats`` gets the draws' counts.

    Nothing here reads Blender's buffers, so what it draws depends only on
    its key (the view, the settings, which meshes in which shape where,
    their styles and colour sources, the display transform;
    _overlay_lines_key), and what was drawn for the last key is kept:

    * the resolved image of this key: the surface pass only composites it
      (a static redraw);
    * the record and lines of this key (the redraw before had the same
      key): they are resolved into ``targets.surface`` now and kept, so
      from the next redraw on a static redraw only composites;
    * the image of a key that differs only by meshes that moved some
      vertices (an edit, a drag; _moved_items): record, lines and resolve
      again only inside the window rectangle the moves changed
      (_redraw_rect), then composite;
    * an edit that is not known so well, or changed too much: record and
      lines again, resolved into ``targets.surface`` and kept, so that the
      next edit of a drag can be the one above;
    * none of these (a moved object, another view, other settings): record and lines again, and
      the surface pass resolves them straight into Blender's buffer. That
      costs what a resolve into our own target costs and saves the
      composite, while an image kept for a key that changes at every
      redraw (a drag, an orbit) is never used."""
    targets = overlay_targets_for(view.width, view.height)
    key = _overlay_image_key("surface", items, view, settings, display)
    line_count = sum(item.mesh.region_line_count for item in items)
    record_stats = DrawStats()
    if key is not None and targets.surface_key == key and targets.lines_key == key:
        record_stats.objects_drawn, record_stats.objects_culled, record_stats.triangles_drawn = targets.surface_counts
        if line_count:
            record_stats.extra.update(region_line_entries=line_count, region_lines_reused=1)
        record_stats.extra["surface_reused"] = 1
        frame.line_stats.add(record_stats)
        return OverlaySurface(targets, items, targets.lines if line_count else None, kept=True)
    lines = targets.lines if line_count else None
    kept_key = targets.surface_key if targets.lines_key == targets.surface_key else None
    moved = _moved_items(kept_key, key, items)
    scissor = None if moved is None else _redraw_rect(moved, view, settings, items)
    # An edit that moved vertices of the meshes recorded last: the next
    # redraw is likely another (a drag), which redraws only what it
    # changes if this one keeps its image.
    edited = scissor is None and _moved_items(targets.lines_key, key, items) is not None
    if scissor is not None:
        # Only vertices moved since the kept image: record, lines and
        # resolve again inside the rectangle they changed, into the kept
        # targets (the same pixels as a whole record there: each pixel's
        # record, lines and colour depend on what covers it alone).
        record_stats.extra["surface_partial"] = 1
        if scissor:
            recorded = _record_visibility(targets, items, view, settings, DrawTarget(), frame.options, scissor=scissor)
            if "record_triangles_left_out" in recorded.extra:
                record_stats.extra["record_triangles_left_out"] = recorded.extra["record_triangles_left_out"]
            if line_count:
                _draw_region_lines(targets, items, view, settings, DrawTarget(), True, record_stats, scissor=scissor)
        elif line_count:
            record_stats.extra.update(region_line_entries=line_count, region_lines_reused=1)
        targets.lines_key = key
    elif key is not None and targets.lines_key == key:
        if line_count:
            record_stats.extra.update(region_line_entries=line_count, region_lines_reused=1)
        record_stats.extra["record_reused"] = 1
    elif edited:
        targets.lines_key = targets.surface_key = None
        _record_visibility(targets, items, view, settings, DrawTarget(), frame.options)
        _ready_for_partial_redraws(items)
        if line_count:
            lines = _draw_region_lines(targets, items, view, settings, DrawTarget(), True, record_stats)
        targets.lines_key = key
        record_stats.extra["surface_edited"] = 1
    else:
        targets.lines_key = targets.surface_key = None
        _record_visibility(targets, items, view, settings, DrawTarget(), frame.options)
        _ready_for_partial_redraws(items)
        if line_count:
            lines = _draw_region_lines(targets, items, view, settings, DrawTarget(), True, record_stats)
        # (One key for the record, its lines and the resolved image: the
        # direct path's own region lines (_overlay_region_lines) never
        # match it.)
        targets.lines_key = key
        frame.line_stats.add(record_stats)
        return OverlaySurface(targets, items, lines, kept=False)
    if scissor != ():
        with targets.surface_framebuffer().bind(), _scissored(scissor):
            gpu.state.viewport_set(0, 0, view.width, view.height)
            gpu.state.blend_set("NONE")
            resolve = DrawTarget(
                stage=draw_mod.RESOLVE, visibility=targets.visible, region_lines=lines, display=display
            )
            record_stats.add(draw_mod.draw(items, view, settings, target=resolve))
    else:
        record_stats.objects_drawn, record_stats.objects_culled, record_stats.triangles_drawn = targets.surface_counts
    targets.surface_key = key
    targets.surface_rect = draw_mod.window_union(items, view)
    targets.surface_counts = (record_stats.objects_drawn, record_stats.objects_culled, record_stats.triangles_drawn)
    frame.line_stats.add(record_stats)
    return OverlaySurface(targets, items, lines, kept=True)


def _ready_for_partial_redraws(items) -> None:
    """After a whole record on a software rasteriser: make what a partial
    redraw reads to leave out the triangle blocks and region-lines runs
    that cannot reach its rectangle (cache.GPUMesh.prepare_partial_redraws)
    now, with the whole record's cost, so that an edit, the redraw that has
    to be quick, measures only the blocks it moved. Kept with each mesh: a
    view change, which records whole again, makes nothing."""
    if shaders.software_rasteriser():
        for item in items:
            item.mesh.prepare_partial_redraws()


def _moved_items(before_key, key, items):
    """[(item, the move)] for the items whose mesh moved vertices since
    ``before_key`` was drawn, when that is all that changed: every other
    part of the two keys (_overlay_surface) alike; the move is the
    mesh-space box it changed, or None where nothing (_redraw_rect), and
    ``UNKNOWN_MOVE`` where that is not known (not one move further on, or
    cache.GPUMesh.last_move cannot tell). Else None."""
    if before_key is None or key is None or before_key[0] != key[0] or before_key[2:] != key[2:]:
        return None
    return _moved_in_lines(before_key[1], key[1], items)


def _moved_in_lines(before_lines, now_lines, items):
    """_moved_items for two region-lines keys (_overlay_lines_key)."""
    if before_lines is None or now_lines is None:
        return None
    if (
        before_lines[:4] != now_lines[:4]
        or before_lines[5:] != now_lines[5:]
        or len(before_lines[4]) != len(now_lines[4])
    ):
        return None
    moved = []
    for item, before, now in zip(items, before_lines[4], now_lines[4]):
        if before == now:
            continue
        serial, version, matrix, style = now
        if (before[0], before[2], before[3]) != (serial, matrix, style):
            return None
        move = item.mesh.last_move() if version == before[1] + 1 else None
        moved.append((item, UNKNOWN_MOVE if move is None or move[0] != version else move[1]))
    return moved


UNKNOWN_MOVE = "unknown"


def _redraw_rect(moved, view: View, settings, items):
    """The window rectangle (x, y, width, height) that the moves ``moved``
    (_moved_items) changed: each box's window box widened by the reach of
    the widest line (docs/image_model.md §3.1: nothing farther than h + 2s
    from a line sees it); () where nothing changed; None where that cannot
    be told (a move not known, widths not in pixels, the density fade,
    whose lines fade by the length of whole chains). (However big, it costs
    no more than recording and resolving everything again.)"""
    reach = _line_reach_px(settings, items)
    if reach is None or any(box is UNKNOWN_MOVE for _item, box in moved):
        return None
    to_clip = view.projection @ view.view_matrix
    boxes = [window_boxes((to_clip @ item.matrix)[None], *box) for item, box in moved if box is not None]
    if not boxes:
        return ()
    ndc = np.concatenate(boxes)
    width, height = view.width, view.height
    x0 = max(int(np.floor((ndc[:, 0].min() + 1.0) * 0.5 * width - reach)), 0)
    y0 = max(int(np.floor((ndc[:, 1].min() + 1.0) * 0.5 * height - reach)), 0)
    x1 = min(int(np.ceil((ndc[:, 2].max() + 1.0) * 0.5 * width + reach)), width)
    y1 = min(int(np.ceil((ndc[:, 3].max() + 1.0) * 0.5 * height + reach)), height)
    if x1 <= x0 or y1 <= y0:
        return ()
    return (x0, y0, x1 - x0, y1 - y0)


def _param_slots(names) -> list:
    """Float offsets of the parameter block's members ``names``."""
    slots, offset = {}, 0
    for member in schema.PARAM_BLOCK:
        slots[member.glsl] = offset
        offset += 4 if member.glsl_type == "vec4" else 1
    return [slots[name] for name in names]


_WIRE_HALF_SLOTS = _param_slots(["half_thickness", "half_thickness_far"])
_CLASS_HALF_SLOTS = _param_slots([f"{name}_half_thickness" for name in draw_mod.EDGE_CLASSES])
(_SOFTNESS_SLOT, _CLASS_SCALE_SLOT) = _param_slots(["softness", "class_width_scale"])


def _line_reach_px(settings, items) -> float | None:
    """The widest reach in pixels of any line ``items`` draw with
    ``settings`` (the widest half width of every style, class widths
    included, plus 2s, and 2 px to spare), or None where it is not a
    fixed number of pixels."""
    if settings.thickness_mode != "PIXELS" or draw_mod.density_fade_of(settings):
        return None
    reach = 0.0
    for style in {item.style for item in items} | {None}:
        styled = draw_mod.styled(settings, style)
        block = pack_params(styled, (0.0, 0.0, 1.0, 1.0), class_reference=settings.thickness)
        values = np.frombuffer(block, np.float32)
        wire = float(values[_WIRE_HALF_SLOTS].max())
        # A class's half width as shaders/edge_styles.glsl scales it.
        scale = float(values[_CLASS_SCALE_SLOT])
        classes = float(values[_CLASS_HALF_SLOTS].max()) * (wire * scale if scale > 0.0 else 1.0)
        reach = max(reach, max(wire, classes) + 2.0 * float(values[_SOFTNESS_SLOT]))
    return reach + 2.0


def _draw_overlay_surface(frame: Frame, target: DrawTarget) -> None:
    """The deferred meshes (``frame.overlay_surface``) into the bound
    framebuffer (Blender's), each pixel at the record's depth less the
    bias, depth test LESS_EQUAL and write, blended as the caller set
    (premultiplied "over"): the kept image composited, or the record
    resolved straight. The two give the same image: the kept image is
    float32, resolved by the same fragment code. A backend that refuses the
    straight resolve draws these meshes directly (``target``, walking their
    regions), said once."""
    surface = frame.overlay_surface
    targets = surface.targets
    if surface.kept:
        _composite_overlay_surface(targets, frame.base.depth_bias, frame.view)
        return
    resolve = DrawTarget(
        stage=draw_mod.RESOLVE,
        visibility=targets.visible,
        region_lines=surface.lines,
        display=frame.base.display,
        depth_bias=frame.base.depth_bias,
        record_depth=targets.depth,
    )
    try:
        stats = draw_mod.draw(surface.items, frame.view, frame.settings, target=resolve)
        stats.extra["surface_straight"] = 1
    except shaders.DeferredUnavailable as exc:
        _refused(exc)
        stats = draw_mod.draw(surface.items, frame.view, frame.settings, target=replace(target, region_lines=None))
    frame.line_stats.add(stats)


def _composite_overlay_surface(targets, depth_bias: float, view: View) -> None:
    """Blend ``targets.surface`` into the bound framebuffer (Blender's)
    over the items' window boxes, each pixel at the record's depth less the
    bias and Blender's allowance, with depth test LESS_EQUAL and write,
    blending as the caller set (premultiplied "over")."""
    shader = shaders.get_overlay_composite(depth_bias)
    shader.bind()
    _bind_depth_allowance(shader, view, blender_depth_allowance(view))
    shader.uniform_sampler("record_depth", targets.depth)
    shader.uniform_sampler("surface_image", targets.surface)
    gpu.state.depth_test_set("LESS_EQUAL")
    gpu.state.depth_mask_set(True)
    draw_mod.draw_rectangle(shader, targets.surface_rect)


def _peel_hidden_regions(
    frame: Frame, settings, targets, *, into, behind=None, stats=None, restore_viewport=None, box=None
) -> list:
    """The hidden layers (image model §5.4) of the triangles whose lines come
    from the region-lines pass, without walking a region's edges (§2.6):
    peeled one layer at a time. Each layer is a visibility record of those
    triangles (the nearest strictly behind the layer before, or behind
    ``behind``, the surface depth, for the first), the region-lines pass
    over it keeping each pixel's nearest line and the layer's colour there,
    and that colour blended "over" at the layer's depth into each of
    ``into``: (a function giving a framebuffer, None for the one bound (the
    viewport's, whose viewport ``restore_viewport`` is), and its depth
    test: GREATER against the depth there, as the direct hidden-line pass
    is, or ALWAYS). Each layer's depth
    is read back (about 2 ms at 1280 x 720 on llvmpipe): the next layer can only lie
    where this one does, so it is drawn inside their box, and the peeling
    stops at the first empty layer. ``box`` (x, y, width, height): the
    pixels to peel, all of them where None.

    Only the meshes that _peeled_items picks are peeled; returns them (the
    direct hidden-line pass leaves their region triangles out, and walks
    the rest: _draw_hidden); none where the record's stages do not compile
    here. (A mesh drawn directly is peeled too: the layers are records of
    their own, whichever way the surface was drawn.)"""
    items = _peeled_items(frame.items, images=len(into))
    if not items or not shaders.deferred_available():
        return []
    view, base, options, cull = frame.view, frame.base, frame.options, frame.cull
    stats = stats if stats is not None else DrawStats()
    # The layers are recorded in linear depth, as the render's surface: which
    # of two layers is nearer never depends on the clip range (float window
    # depth near 1 cannot tell a face from one just behind it). Over the
    # viewport the composite turns it into window depth for Blender's test.
    record = DrawTarget(linear_depth=True, clip_planes=base.clip_planes, region_layers=True)
    lines = DrawTarget(linear_depth=True, lines=draw_mod.HIDDEN_LINES, display=base.display)
    # The state the caller's own passes draw with stays (over the viewport
    # they blend as the composite does).
    saved = gpu.state.blend_get(), gpu.state.depth_test_get(), gpu.state.depth_mask_get()
    try:
        # (Compiled before anything is drawn.) Over the viewport the layer
        # moves towards the camera by twice the overlay's bias: half meets
        # the bias our own surface was drawn with, the other half keeps the
        # surface's own layer (peeled too, from the front) from passing
        # GREATER by a rounding of Blender's depth. The render's depth has
        # no bias and its first layer lies behind the surface already.
        over_viewport = not base.linear_depth
        composite = shaders.get_overlay_composite(2.0 * base.depth_bias, linear_record=over_viewport)
        rows = _window_depth_rows(view.projection) if over_viewport else None
        # (Twice Blender's allowance too, for the same reason.)
        allowance = tuple(2.0 * a for a in blender_depth_allowance(view)) if over_viewport else NO_DEPTH_ALLOWANCE
        box, layers = box or (0, 0, view.width, view.height), 0
        behind_tiles = None  # (the first layer lies behind ``behind``, or in front of everything)
        left_out = 0  # triangles the records left out (behind_tiles, and outside the box)
        for layer in range(1, PEEL_MOST_LAYERS + 1):
            previous = behind if layer == 1 else targets.peel_depths[(layer - 1) % 2]
            recorded = _record_visibility(
                targets,
                items,
                view,
                settings,
                replace(record, peel_depth=previous, behind_tiles=behind_tiles),
                options,
                cull=cull,
                scissor=box,
                framebuffer=targets.peel_framebuffer(layer),
            )
            left_out += recorded.extra.get("record_triangles_left_out", 0)
            extent = _layer_extent(targets.peel_depths[layer % 2], box, view)
            if extent is None:
                break
            box, behind_tiles = extent
            _draw_region_lines(targets, items, view, settings, lines, cull, stats, box)
            if restore_viewport is not None:
                gpu.state.viewport_set(*restore_viewport)
            for framebuffer_of, test in into:
                _composite_kept(
                    composite,
                    targets.peel_depths[layer % 2],
                    targets.hidden_lines,
                    box,
                    view,
                    framebuffer_of,
                    test=test,
                    window_depth_rows=rows,
                    allowance=allowance,
                )
            layers = layer
        else:
            warn_once(("peel",), f"SolidWire: hidden lines stop after {layers} layers behind the surface")
        stats.extra["hidden_region_layers"] = layers
        stats.extra["peel_triangles_left_out"] = left_out
    except shaders.DeferredUnavailable as exc:
        # (Only the first layer's draws compile anything: nothing was
        # composited yet.)
        _refused(exc)
        return []
    finally:
        gpu.state.blend_set(saved[0])
        gpu.state.depth_test_set(saved[1])
        gpu.state.depth_mask_set(saved[2])
    return items


# Under hidden lines the direct pass walks each region triangle's region
# lines (solidwire_vert.glsl select_segments), a cost that grows with the
# region; peeling the layers costs a record and a lines pass per layer
# instead, whatever the regions' size. A region past the walk's limit
# (edge_select.WALK_LIMIT) is walked face by face, where a line can stop
# short: a mesh with one is always peeled. Otherwise a mesh is peeled where
# its triangles' regions hold this many lines or more on average. Measured
# (2-core VM, llvmpipe, 1280 x 720, Suzanne with cage edges, F12 walked /
# peeled, medians of four alternating in one process), since the walk
# tests groups of segments by their window boxes and its draw leaves out
# the triangles with no line near (draw._run_walk_table): level 4 (64
# lines a region) 469 / 589 ms, level 5 (128) 1,809 / 982 ms.
PEEL_MIN_REGION_LINES = 96
# The same where the hidden lines are drawn into two images at once (the
# overlay's kept frame: the visible image and the occluded one): the walk
# sets its picks up again for each, while the peeling records each layer
# once for both. An edit redraw of the cage look at level 4 cost 331 ms
# peeled and 465 walked (medians of five, two processes each).
PEEL_MIN_REGION_LINES_TWICE = 48
# Each peeled layer lies strictly behind the one before at every pixel, so
# the peeling ends; this only guards against a driver that breaks that
# (a NaN depth passes every test) turning the frame into an endless loop.
PEEL_MOST_LAYERS = 4096


def _peeled_items(items, images: int = 1) -> list:
    """The items whose hidden region layers are peeled where the hidden
    lines go into ``images`` images (see PEEL_MIN_REGION_LINES)."""
    # (Never above the one-image threshold, whatever that is set to.)
    least = PEEL_MIN_REGION_LINES if images == 1 else min(PEEL_MIN_REGION_LINES_TWICE, PEEL_MIN_REGION_LINES)
    peeled = []
    for item in items:
        if item.mesh.region_line_count:
            most, mean, _outside = item.mesh.region_sizes()
            if most > WALK_LIMIT or mean >= least:
                peeled.append(item)
    return peeled


def _layer_extent(depth_image, scissor, view: View):
    """(the box (x, y, width, height) around the pixels inside ``scissor``
    where a layer was recorded into ``depth_image`` (cleared to 1.0 there),
    that depth by tiles (draw.DepthTiles) or None), or None where no pixel
    was recorded. The next layer can only lie inside the box, and only
    behind the tiles: a software rasteriser's record leaves out the blocks
    of triangles that lie wholly in front of them (it would set up every
    triangle of a block before the depth test drops its pixels; a GPU drops
    them for less than picking them costs)."""
    x, y, w, h = scissor
    depth = read_texture(depth_image, 1)[y : y + h, x : x + w, 0]
    recorded = depth < 1.0
    columns, rows = recorded.any(axis=0), recorded.any(axis=1)
    if not columns.any():
        return None
    xs, ys = np.flatnonzero(columns), np.flatnonzero(rows)
    box = x + int(xs[0]), y + int(ys[0]), int(xs[-1] - xs[0] + 1), int(ys[-1] - ys[0] + 1)
    tiles = None
    if shaders.software_rasteriser():
        x0, y0, bw, bh = box
        inside = depth[y0 - y : y0 - y + bh, x0 - x : x0 - x + bw]
        tiles = draw_mod.DepthTiles(inside, (x0, y0), inv_clip_end=1.0 / clip_end_of(view.projection))
    return box, tiles


def _composite_kept(
    shader,
    depth,
    colour,
    scissor,
    view: View,
    into,
    *,
    test: str = "GREATER",
    write_depth: bool = False,
    window_depth_rows=None,
    allowance=NO_DEPTH_ALLOWANCE,
) -> None:
    """Blend an image (``colour``, premultiplied, at the depth image
    ``depth``: a hidden layer's lines, a kept image) "over" into
    ``into()`` (None: the bound framebuffer) inside ``scissor``, each pixel
    at its depth less the bias ``shader`` moves it by
    (shaders.get_overlay_composite), tested ``test`` against the depth
    there (GREATER: a hidden layer, behind the surface) and written with
    ``write_depth``; ``window_depth_rows`` (_window_depth_rows) for a
    composite of a linear record; ``allowance``: Blender's depth allowance
    (view.blender_depth_allowance) it moves the pixels by too, where the
    depth image has none of it yet."""
    x, y, w, h = scissor
    rect = (
        2.0 * x / view.width - 1.0,
        2.0 * y / view.height - 1.0,
        2.0 * (x + w) / view.width - 1.0,
        2.0 * (y + h) / view.height - 1.0,
    )

    def draw():
        gpu.state.blend_set("ALPHA_PREMULT")
        gpu.state.depth_test_set(test)
        gpu.state.depth_mask_set(write_depth)
        shader.bind()
        shader.uniform_sampler("record_depth", depth)
        shader.uniform_sampler("surface_image", colour)
        _bind_depth_allowance(shader, view, allowance)
        if window_depth_rows is not None:
            shader.uniform_float("window_depth_rows", window_depth_rows)
        draw_mod.draw_rectangle(shader, rect)

    if into is None:
        draw()
        return
    with into().bind():
        gpu.state.viewport_set(0, 0, view.width, view.height)
        draw()


def _bind_depth_allowance(shader, view: View, allowance) -> None:
    """The push constants of a bound composite shader
    (shaders.get_overlay_composite) that move its pixels by Blender's depth
    ``allowance`` (NO_DEPTH_ALLOWANCE: not at all)."""
    shader.uniform_float("depth_rows", depth_rows(view.projection))
    shader.uniform_float("blender_depth_allowance", allowance)


def _window_depth_rows(projection) -> tuple:
    """The projection's depth rows for the composite of a linear record
    (shaders.get_overlay_composite): clip z and w of the point at view
    depth ``r * clip_end`` are ``y - x r`` and ``w - z r`` (Blender's
    projections, perspective or orthographic, give z and w from view z
    alone)."""
    clip_end = clip_end_of(projection)
    p22, p23, p32, p33 = depth_rows(projection)
    return (p22 * clip_end, p23, p32 * clip_end, p33)


def _hidden_wire(frame: Frame, settings) -> np.ndarray:
    """The Hidden Wire pass: H of image model §5.4 (coverage of the hidden
    layers, wire alpha included), whether or not Hidden Lines is on in the
    image. The hidden-line pass again, into a target of its own over the
    surface depth: "over" blending of the a_k on 0 leaves 1 - prod(1 - a_k)
    in alpha."""
    targets, view = frame.targets, frame.view
    framebuffer = targets.own_layer_framebuffer()
    with framebuffer.bind():
        _clear(framebuffer, view.width, view.height, depth=False)  # the surface depth stays
    settings = replace(settings, use_fill=False)
    peeled = _peel_hidden_regions(
        frame,
        settings,
        targets,
        into=((targets.own_layer_framebuffer, "GREATER"),),
        behind=targets.depth,
        stats=frame.stats,
    )
    with framebuffer.bind():
        gpu.state.viewport_set(0, 0, view.width, view.height)
        gpu.state.blend_set("ALPHA_PREMULT")
        try:
            _draw_hidden(frame.items, peeled, view, settings, frame.base, frame.cull, frame.stats)
        finally:
            gpu.state.blend_set("NONE")
            gpu.state.depth_test_set("NONE")
    return read_texture(targets.own_layer, 4)[..., 3:4]


def _blend_layer(colour, depth, layer, view: View) -> None:
    """``layer`` (premultiplied colour on nothing: targets.own_layer or
    targets.wire_layer) blended "over" the colour texture ``colour`` where
    the depth image ``depth`` holds a surface (no line lies over the
    background). Drawn into the colour alone: the depth is read, not
    attached, so no texture is read and attached at once."""
    shader = shaders.get_overlay_composite(0.0)
    framebuffer = gpu.types.GPUFrameBuffer(color_slots=(colour,))
    with framebuffer.bind():
        gpu.state.viewport_set(0, 0, view.width, view.height)
        gpu.state.blend_set("ALPHA_PREMULT")
        gpu.state.depth_test_set("NONE")
        gpu.state.depth_mask_set(False)
        shader.bind()
        shader.uniform_float("depth_rows", (0.0,) * 4)  # (no allowance: its depth is never written)
        shader.uniform_float("blender_depth_allowance", NO_DEPTH_ALLOWANCE)
        shader.uniform_sampler("record_depth", depth)
        shader.uniform_sampler("surface_image", layer)
        try:
            draw_mod.draw_rectangle(shader, (-1.0, -1.0, 1.0, 1.0))
        finally:
            gpu.state.blend_set("NONE")


def _composite_silhouettes(rgba, targets, items, view, settings):
    """Draw the outer halves of silhouette edges (max intensity per pixel,
    occluded by the surface pass's depth) and composite them over ``rgba``
    with the wire colour ("over", premultiplied)."""
    framebuffer = targets.silhouette_framebuffer()
    with framebuffer.bind():
        _clear(framebuffer, view.width, view.height)
        silhouettes.draw_silhouettes(items, view, settings, DrawTarget(linear_depth=True), targets.depth)
        gpu.state.depth_test_set("NONE")
        gpu.state.depth_mask_set(False)
    compositing.color_over(rgba, settings.wire_color, read_texture(targets.outer, 1)[..., 0])
    return rgba


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
    options: DrawOptions = DEFAULT_OPTIONS,
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
    # Every pass gets the clipping planes and the LUT.
    frame = Frame(
        items,
        view,
        settings,
        DrawTarget(
            depth_bias=depth_bias, clip_planes=clip_planes, display=display, drop_lineless=_drop_lineless(options)
        ),
        options=options,
        strands=tuple(strands),
        scene_depth=scene_depth,
        scene_surfaces=scene_surfaces,
    )
    try:
        _sync_overlay_surface(frame)
        for unit in plan(settings, strands=bool(strands)):
            unit.over_viewport(frame)
    finally:
        gpu.state.color_mask_set(True, True, True, True)
        gpu.state.blend_set(saved_blend)
        gpu.state.depth_test_set(saved_depth_test)
        gpu.state.depth_mask_set(saved_depth_mask)
    return frame.overlay_stats()
