"""One pass of the solid wireframe: a shader variant, the parameter block
and the batches of the drawn meshes, into the bound framebuffer.

Input is plain data (``core/view.py``): draw items with float64 object
matrices, a view and a settings snapshot (``core/settings.py``). Which passes
run, in which order and with which blending is the pass plan's business
(``core/passes.py``); nothing here reads ``bpy.context``.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import gpu
import numpy as np

from . import colors, matcaps, shaders
from .cache import RECORD_BLOCK_TRIANGLES, table_texture, texture_bytes
from .edge_select import EDGE_CLASSES
from .log import warn_once
from .settings import pack_params
from .view import (
    NO_DEPTH_ALLOWANCE,
    DrawStats,
    View,
    blender_depth_allowance,
    box_pixels,
    determinant3,
    inverse_transpose3,
    outside_frustum_many,
    translation,
    wholly_in_front,
    window_boxes,
    window_rect,
)

# Which lines a draw shows (DrawTarget.lines): the visible wire with the
# fill, none (the fill and depth only: the surface under hidden lines), or
# the hidden-line layer (image model §5.4: real edges behind the surface,
# dimmed and dashed, no fill).
WIRE_LINES, NO_LINES, HIDDEN_LINES = "wire", "none", "hidden"

# Which runs of a mesh's region-lines table a LINES draw draws
# (DrawTarget.line_runs): all of them, or the wire's (style 0) apart from
# the edge classes'. The table holds its entries by style, so the wire's
# runs come first (cache.GPUMesh.region_wire_runs). Drawn apart, the
# wire's runs take a shader without the per-style code: on a software
# rasteriser that code costs every fragment of every run, although most
# lines are the wire's (passes._draw_region_lines).
ALL_RUNS, WIRE_RUNS, CLASS_RUNS = "all", "wire", "classes"

# The two stages of the deferred surface (docs/image_model.md §2.5; see
# passes.SurfacePass): VISIBILITY records which triangle of which draw
# each pixel shows, RESOLVE runs the exact fragment stage once per pixel of
# that record. ``stage=None`` draws directly (one pass, every fragment).
VISIBILITY, RESOLVE = "visibility", "resolve"
# Between the two: the lines of multi-face regions drawn over the
# visibility record (passes._draw_region_lines, docs/image_model.md §2.6).
LINES = "lines"


@dataclass(frozen=True, eq=False)
class DrawTarget:
    """Where one draw lands and how: the one description of a draw's
    target, from which its shader variant follows (:func:`shader_variant`).

    Depth: the test and whether the draw writes depth, an NDC bias towards
    the camera (the viewport overlay, view.OVERLAY_DEPTH_BIAS) and whether
    the depth written is view depth / clip end (the render's own targets,
    LINEAR_DEPTH in solidwire_frag.glsl). ``clip_planes`` ((6, 4)
    world-space planes of a viewport's clipping region): fragments outside
    them are discarded. ``display`` (a display_transform.DisplayLUT,
    viewport overlay only): the colour leaves through the scene's colour
    management (image model §9). ``stage``: None draws directly, VISIBILITY
    or RESOLVE one half of the deferred surface (RESOLVE reads the record
    in ``visibility``), LINES the lines of multi-face regions over that
    record into the bound region-lines target; ``region_lines`` is that
    target's image, which a surface draw then reads. ``line_distance``
    (LINES): each pixel's nearest line distance instead of its strongest
    line, whose image ``region_distance`` a RESOLVE with ``aovs`` reads for
    the Edge Distance pass. ``record_depth`` (the
    viewport overlay's record depth, RESOLVE only): the resolve writes that
    window depth less ``depth_bias`` and meets the bound depth with
    ``depth_test``, as the overlay's composite would, so it can resolve
    straight into Blender's buffer. Outputs: the view
    depth in a second colour target, the render passes' targets (``aovs``),
    and which ``lines`` the colour shows (WIRE_LINES, NO_LINES,
    HIDDEN_LINES); ``wire_layer`` (WIRE_LINES, the render under hidden
    lines): the colour shows the fill alone and the visible wire goes,
    premultiplied and unblended, into a colour target of its own (after
    the render passes' two), so that the hidden lines can go between the
    two (passes.WirePass). ``triangle_ids_by_vertex``: how the VISIBILITY stage
    numbers triangles (options.DrawOptions). ``scissor_window`` (x, y,
    width, height, reach; LINES and VISIBILITY): the caller draws inside
    that window rectangle alone (a scissor) and nothing drawn reaches
    farther than ``reach`` px from its geometry's window box, so what
    cannot reach the rectangle is left out of the draw (a partial redraw
    on a software rasteriser): the runs of LINES whose lines cannot reach
    it, the blocks of triangles of VISIBILITY that lie outside it (numbered
    by vertex only: gl_PrimitiveID would start again at each range).
    ``line_runs`` (LINES): which runs of each mesh's region-lines table it
    draws (ALL_RUNS, WIRE_RUNS: then without the edge classes' code,
    CLASS_RUNS). ``depth_only``: the caller masks the colour (a depth
    pre-pass drawn with the surface's own program, so that the depths
    agree): nothing but the depth matters, and the walk-table pre-pass
    (_run_walk_table), whose picks only colour reads, is left out.

    The hidden layers of multi-face regions (passes._peel_hidden_regions):
    ``region_layers`` (VISIBILITY) records only the triangles whose lines
    come from the region-lines pass, with ``peel_depth`` (a depth image)
    only those strictly behind it; LINES with HIDDEN_LINES draws such a
    layer's lines (the nearest line per pixel and its colour); a direct
    HIDDEN_LINES draw with ``region_layers_peeled`` leaves those triangles
    out. ``behind_tiles`` (VISIBILITY with ``peel_depth``, numbered by
    vertex): that depth image by tiles (DepthTiles), so that the blocks of
    triangles that lie wholly in front of it are left out of the draw.
    ``drop_lineless`` (a direct HIDDEN_LINES draw, options.DrawOptions):
    the region triangles that the walk-table pre-pass found no line near
    are left out (they would draw nothing). ``walk_scope`` (a direct draw
    that walks its regions with the walk-table pre-pass): draws given the
    same scope object keep one walk of a mesh while nothing the walk
    depends on changes (_walk_key): the overlay's kept images draw the
    hidden lines twice, once into each image. None: every draw() call walks
    (its own two draws of a mesh, _splits_walked_triangles, share one walk)."""

    depth_test: str = "LESS_EQUAL"
    depth_write: bool = True
    depth_bias: float = 0.0
    linear_depth: bool = False
    clip_planes: object = None
    display: object = None
    stage: str | None = None
    visibility: object = None
    region_lines: object = None
    line_distance: bool = False
    region_distance: object = None
    record_depth: object = None
    view_depth: bool = False
    aovs: bool = False
    lines: str = WIRE_LINES
    triangle_ids_by_vertex: bool = False
    scissor_window: tuple | None = None
    region_layers: bool = False
    peel_depth: object = None
    behind_tiles: object = None
    region_layers_peeled: bool = False
    line_runs: str = ALL_RUNS
    depth_only: bool = False
    drop_lineless: bool = False
    walk_scope: object = None
    wire_layer: bool = False

    def hidden(self, region_layers_peeled: bool = False) -> DrawTarget:
        """The hidden-line layer over this target (image model §5.4): every
        face behind the depth already in the framebuffer draws its real
        edges dimmed and dashed, blended "over" (the caller sets the blend
        mode). Strictly GREATER, so the visible surface itself never
        passes: the same shader wrote that depth, so there is no z-fight.
        With one wire colour "over" is commutative (alpha = 1 - prod(1 -
        a_k)), so draw order does not matter. No region-lines image: the
        layer walks every region itself, unless ``region_layers_peeled``
        says those layers were drawn already (passes._peel_hidden_regions)."""
        return replace(
            self,
            depth_test="GREATER",
            depth_write=False,
            lines=HIDDEN_LINES,
            region_lines=None,
            view_depth=False,
            wire_layer=False,
            region_layers_peeled=region_layers_peeled,
        )


def shader_variant(settings, target: DrawTarget | None = None) -> shaders.ShaderVariant:
    """The compiled-code features of a draw of ``settings`` into ``target``
    (per-mesh parts and missing resources refine it in :func:`draw`)."""
    target = target or DrawTarget()
    diagonals = {
        "HIDDEN": shaders.DIAGONALS_HIDDEN,
        "SOLID": shaders.DIAGONALS_SOLID,
    }.get(settings.diagonal_mode, shaders.DIAGONALS_PATTERN)
    variant = shaders.ShaderVariant(
        diagonals=diagonals,
        use_fill=bool(settings.use_fill),
        use_fade=bool(settings.use_fade),
        write_view_depth=target.view_depth,
        depth_bias=target.depth_bias,
        linear_depth=target.linear_depth,
        thickness_mode={"WORLD": shaders.THICKNESS_WORLD, "DEPTH": shaders.THICKNESS_DEPTH}.get(
            settings.thickness_mode, shaders.THICKNESS_PIXELS
        ),
        shading=fill_shading(settings),
        item_colors=colors.needs_item_colors(settings),
        material_colors=colors.needs_material_colors(settings),
        attribute_colors=colors.needs_attribute_colors(settings),
        edge_classes=bool(edge_classes_of(settings)),
        density_fade=density_fade_of(settings),
    )
    if target.lines == HIDDEN_LINES:
        variant = replace(
            variant,
            hidden_pass=True,
            write_view_depth=False,
            shading=shaders.SHADING_FLAT,
            material_colors=False,
            attribute_colors=False,
        )
    if target.wire_layer and target.stage in (None, RESOLVE):
        # (The record and lines stages of such a surface write no colour.)
        if target.lines != WIRE_LINES:
            raise ValueError("only a surface draw of the visible wire puts that wire in a layer of its own")
        variant = replace(variant, wire_layer=True)
    if target.aovs:
        variant = replace(variant, write_aovs=True)
    elif target.lines == NO_LINES and target.stage in (None, RESOLVE):
        # The fill alone (under hidden lines): no line to measure.
        variant = replace(
            variant, no_lines=True, diagonals=shaders.DIAGONALS_HIDDEN, edge_classes=False, density_fade=False
        )
    if target.region_layers_peeled and target.stage is None:
        variant = replace(variant, region_layers_peeled=True)
    if target.stage == RESOLVE:
        variant = replace(variant, resolve=True, linear_depth=False, record_depth=target.record_depth is not None)
    elif target.stage == VISIBILITY:
        variant = shaders.ShaderVariant(
            visibility=True,
            linear_depth=target.linear_depth,
            triangle_ids_by_vertex=target.triangle_ids_by_vertex,
            region_layers=target.region_layers,
            peel_layer=target.peel_depth is not None,
        )
    elif target.stage == LINES and target.lines == HIDDEN_LINES:
        # A hidden layer's lines: the wire's style alone (image model §5.4).
        variant = shaders.ShaderVariant(
            region_lines_pass=True,
            hidden_pass=True,
            thickness_mode=variant.thickness_mode,
            use_fade=variant.use_fade,
            item_colors=variant.item_colors,
        )
    elif target.stage == LINES:
        variant = shaders.ShaderVariant(
            region_lines_pass=True,
            thickness_mode=variant.thickness_mode,
            edge_classes=variant.edge_classes and target.line_runs != WIRE_RUNS,
            density_fade=variant.density_fade,
            line_distance=target.line_distance,
        )
    if target.clip_planes is not None and target.stage != LINES:
        # (The region-lines pass keeps a line only where the record's
        # triangle is: a record inside the clipping region clips it.)
        variant = replace(variant, clip_planes=True)
    if target.region_lines is not None:
        variant = replace(variant, region_lines=True)
    if target.region_distance is not None:
        variant = replace(variant, region_distance=True)
    if target.display is not None:
        variant = replace(variant, display_transform=True)
    return variant


def edge_classes_of(settings) -> tuple:
    """The edge classes switched on (image model §3.6), in style order."""
    return tuple(name for name in EDGE_CLASSES if getattr(settings, f"use_{name}_edges"))


def density_fade_of(settings) -> bool:
    """Whether each line fades with its chain's length (image model §3.7):
    on, with a length to fade below. A length of 0 fades nothing, and the
    image is then the one the fade switched off gives (each style the
    nearest line's, not the strongest faded one's: the two differ where
    patterned lines meet)."""
    return bool(settings.use_density_fade) and float(settings.density_fade_length) > 0.0


def fill_shading(settings) -> int:
    """The shading the fill asks for (none without a fill)."""
    if not settings.use_fill:
        return shaders.SHADING_FLAT
    return {"STUDIO": shaders.SHADING_STUDIO, "MATCAP": shaders.SHADING_MATCAP}.get(
        settings.fill_shading, shaders.SHADING_FLAT
    )


def needs_corners(settings) -> bool:
    """Whether meshes must carry their corner table (normals, material
    indices): extracted and uploaded only then (see gather)."""
    return fill_shading(settings) != shaders.SHADING_FLAT or colors.needs_material_colors(settings)


class ExactProgram:
    """How the add-on draws a mesh: the exact edge-distance shaders over the
    mesh's triangle batch. The benchmark (scripts/bench/methods.py) passes
    its own program with the same two methods to draw a published method
    through this same pass."""

    supports_ngons = True
    supports_instancing = True
    supports_setup_table = True
    supports_walk_table = True

    def shader(self, variant):
        return shaders.get(variant)

    def batch(self, mesh):
        return mesh.batch


EXACT = ExactProgram()


# The DrawStats count of the triangles a hidden-line draw left out for
# showing no line there (DrawTarget.drop_lineless), and of those it drew
# with the variant that measures the walk's picks alone
# (ShaderVariant.walk_picks_only).
LINELESS_LEFT_OUT = "lineless_triangles_left_out"
WALK_PICKS_DRAWN = "walk_picked_triangles"

# A mesh drawn by at least this many visible instances is drawn with one
# draw_instanced call (matrices from a float texture) instead of one draw per
# instance; scripts/bench_scale.py measures both.
INSTANCING_MIN = 16

# A mesh of at least this many triangles, drawn object by object without
# n-gons, gets its edge set-up from the set-up pre-pass (one compute
# invocation per triangle, shaders/setup_comp.glsl) instead of from every
# corner of the vertex stage; below it the dispatch costs more than it saves.
SETUP_TABLE_MIN = 50_000

# A mesh whose triangles' regions hold at least this many lines on average
# (cache.GPUMesh.region_sizes), drawn object by object in a direct draw that
# walks them (under hidden lines: the meshes below passes.PEEL_MIN_REGION_LINES), picks
# each triangle's segments in the walk-table pre-pass (_run_walk_table)
# instead of at its provoking corner. On a CPU rasteriser a corner's loop
# over the block holds up the other corners shaded beside it, so choosing
# at one corner of three costs as much as choosing at all three (measured:
# Suzanne with cage edges at level 3 under hidden lines, F12 1280 x 720 on
# llvmpipe, the hidden-line pass 247 ms choosing at one corner, 245 at all
# three, 197 with the pre-pass; docs/dev/regions-log.md). Below eight lines
# a block is too short for the pre-pass's draw to pay.
WALK_TABLE_MIN_LINES = 8

# Triangle numbers, instances and draw numbers travel as float32 whole
# numbers in the visibility record: exact below 2^24.
DEFERRED_MAX = 1 << 24
# The deferred surface pays for a mesh with at least this many triangles
# per pixel of its window boxes. Measured on llvmpipe (every edge of
# Suzanne filling the frame, F12; docs/dev/benchmarks.md, "Deferred or
# direct"): the break-even lies at 0.015-0.02 at 640 x 360, 1280 x 720,
# 1920 x 1080 and 3840 x 2160 alike; from 0.03 on the deferred surface is
# 1.1-2x faster (a direct draw sets every triangle up at three corners and
# shades every fragment, hidden ones too; the resolve sets one triangle up
# per visible pixel), below 0.008 the direct draw by about 1.1x.
# A mesh whose triangles walk segment blocks (n-gons, regions, classes) has
# a set-up several times dearer and counts DEFERRED_BLOCK_WEIGHT times.
DEFERRED_MIN_DENSITY = 0.02
# A surface that shows no line (the fill under hidden lines) sets no edge
# up in its direct draw, so that draw stays the cheaper one far longer
# (Suzanne at 0.07 triangles per pixel: 109 against 116 ms deferred).
DEFERRED_MIN_DENSITY_NO_LINES = 0.4
DEFERRED_BLOCK_WEIGHT = 8.0


def _items_by_mesh(items) -> list[list]:
    """``items`` grouped by their mesh, in first-seen order."""
    by_mesh: dict = {}
    for item in items:
        by_mesh.setdefault(id(item.mesh), []).append(item)
    return list(by_mesh.values())


def mesh_window_boxes(group, view: View) -> np.ndarray:
    """(N, 4) NDC window boxes (view.window_boxes) of the items of
    ``group``, which share one mesh: one vectorised product for them all."""
    mesh = group[0].mesh
    to_clip = view.projection @ view.view_matrix @ np.stack([item.matrix for item in group]) @ translation(mesh.centre)
    return window_boxes(to_clip, mesh.bounds_min, mesh.bounds_max)


def window_union(items, view: View) -> tuple:
    """The NDC rectangle (x0, y0, x1, y1) over every item's window box."""
    boxes = np.concatenate([mesh_window_boxes(group, view) for group in _items_by_mesh(items)])
    return (float(boxes[:, 0].min()), float(boxes[:, 1].min()), float(boxes[:, 2].max()), float(boxes[:, 3].max()))


def split_deferred(items, view: View, min_density: float | None = None) -> tuple[list, list]:
    """(items to draw deferred, items to draw directly): a mesh is deferred
    when its triangles are dense on screen (``min_density`` triangles per
    pixel of its window boxes, by default DEFERRED_MIN_DENSITY; a surface
    without lines passes DEFERRED_MIN_DENSITY_NO_LINES), counted
    over all its items at once; numbers the visibility record cannot hold
    exactly (DEFERRED_MAX) keep the direct draw."""
    if min_density is None:
        min_density = DEFERRED_MIN_DENSITY
    by_mesh = _items_by_mesh(items)
    if len(by_mesh) >= DEFERRED_MAX or len(items) >= DEFERRED_MAX:
        return [], list(items)
    deferred, direct = [], []
    for group in by_mesh:
        mesh = group[0].mesh
        pixels = float(box_pixels(mesh_window_boxes(group, view), view).sum())
        weight = DEFERRED_BLOCK_WEIGHT if mesh.has_ngons else 1.0
        # Multi-face regions draw their lines over the visibility record
        # (docs/image_model.md §2.6), so such a mesh is always deferred.
        dense = weight * mesh.triangle_count * len(group) >= min_density * pixels or mesh.region_line_count > 0
        (deferred if dense and 0 < mesh.triangle_count < DEFERRED_MAX else direct).extend(group)
    return deferred, direct


def styled(settings, style, show_wire: bool = True):
    """``settings`` with an object's style override applied
    (docs/image_model.md §5.9); ``show_wire=False`` keeps the wire out of the
    pass whatever the override's colour (the fill-only surface pass under
    hidden lines)."""
    if style is not None:
        # (Class widths follow the wire's through the parameter block's
        # class_width_scale, which keeps the scene's Thickness: params_block.)
        settings = replace(
            settings, wire_color=style.wire_color, thickness=style.thickness, fill_color=style.fill_color
        )
    if not show_wire and settings.wire_color[3] != 0.0:
        settings = replace(settings, wire_color=(*settings.wire_color[:3], 0.0))
    return settings


@dataclass
class DrawGroup:
    """The visible instances of one GPU mesh with one style: their
    float64-composed matrices, stacked (N, 4, 4)."""

    mesh: object  # core.cache.GPUMesh
    style: object  # view.Style or None
    world: np.ndarray
    object_to_view: np.ndarray
    object_to_clip: np.ndarray
    indices: np.ndarray  # (N,) the items' indices in the draw's list
    pass_index: np.ndarray | None = None  # (N,) IndexOB values (render passes only)
    materials: list | None = None  # per instance, DrawItem.materials (render passes only)


@dataclass
class SingleDraw:
    """One object drawn on its own (one draw call)."""

    mesh: object
    style: object
    world: np.ndarray  # (4, 4)
    object_to_view: np.ndarray
    object_to_clip: np.ndarray
    info: np.ndarray  # (4,) item info: colour-table base, mirrored
    mirrored: bool
    pass_index: float | None
    materials: tuple | None


@dataclass
class InstancedDraw:
    """Instances of one mesh, style and facing in one draw_instanced call."""

    mesh: object
    style: object
    object_to_view: np.ndarray  # (N, 4, 4)
    object_to_clip: np.ndarray
    info: np.ndarray  # (N, 4)
    mirrored: bool


def _groups(items, view: View, cull: bool, stats: DrawStats, pass_indices: bool = False):
    """Items grouped by GPU mesh and style with their float64-composed
    matrices, culled (vectorised over each group): DrawGroups holding only
    the visible instances."""
    by_mesh: dict = {}
    for index, item in enumerate(items):
        # Plain items key by mesh alone: no tuple per item on the common path.
        key = id(item.mesh) if item.style is None else (id(item.mesh), item.style)
        by_mesh.setdefault(key, []).append(index)
    for group in by_mesh.values():
        mesh, style = items[group[0]].mesh, items[group[0]].style
        indices = np.asarray(group, dtype=np.int64)
        world = np.stack([items[i].matrix for i in group]) if len(group) > 1 else items[group[0]].matrix[None]
        # float64 all the way to here: the mesh centre and any large world
        # translation cancel against the view before rounding to float32.
        object_to_view = view.view_matrix @ world @ translation(mesh.centre)
        object_to_clip = view.projection @ object_to_view
        pass_index = np.array([items[i].pass_index for i in group], dtype=np.float64) if pass_indices else None
        materials = [items[i].materials for i in group] if pass_indices else None
        if cull:
            outside = outside_frustum_many(object_to_clip, mesh.bounds_min, mesh.bounds_max)
            if outside.any():
                stats.objects_culled += int(outside.sum())
                keep = ~outside
                world, object_to_view, object_to_clip = world[keep], object_to_view[keep], object_to_clip[keep]
                indices = indices[keep]
                if pass_index is not None:
                    pass_index = pass_index[keep]
                    materials = [m for m, k in zip(materials, keep) if k]
        if len(world):
            yield DrawGroup(mesh, style, world, object_to_view, object_to_clip, indices, pass_index, materials)


def normal_to_view(object_to_view: np.ndarray) -> np.ndarray:
    """(..., 4, 4): the inverse transpose of the 3x3 part (normals to view
    space), as a 4x4 with zeros elsewhere; non-invertible -> zeros."""
    linear = object_to_view[..., :3, :3]
    out = np.zeros(linear.shape[:-2] + (4, 4))
    inverse_t, det = inverse_transpose3(linear)
    ok = np.abs(det) > 1e-300
    out[..., :3, :3] = np.where(ok[..., None, None], inverse_t, 0.0)
    return out


def _instance_rows(object_to_view, object_to_clip, info) -> np.ndarray:
    """(N * INSTANCE_TEXELS, 4) float32: per instance the 4 columns of
    object_to_clip, the view-z row, the 3 columns of the normal matrix and
    the item info (colour-table base, mirrored) (shaders/instancing.glsl)."""
    rows = np.zeros((len(object_to_clip), shaders.INSTANCE_TEXELS, 4), dtype=np.float32)
    rows[:, :4, :] = np.swapaxes(object_to_clip, 1, 2)
    rows[:, 4, :] = object_to_view[:, 2, :]
    rows[:, 5:8, :] = np.swapaxes(normal_to_view(object_to_view), 1, 2)[:, :3, :]
    rows[:, 8, :] = info
    return rows.reshape(-1, 4)


def draw(
    items, view: View, settings, *, target: DrawTarget | None = None, cull: bool = True, program=EXACT
) -> DrawStats:
    """Draw ``items`` into the bound framebuffer as ``target`` describes
    (by default: depth test LESS_EQUAL and write, the visible wire).

    Every fragment of a face writes depth (nothing is discarded), so a wire is
    only ever seen on the face that is the visible surface there. Items with
    a style override draw with their own parameter block (one per distinct
    style); the variant does not depend on the style. The two halves of
    the deferred surface (target stages VISIBILITY and RESOLVE, and LINES
    between them) must be called with the same items, view and settings so
    that they number the draws alike. ``program`` draws another method
    through this same pass (the benchmark's, scripts/bench/methods.py)."""
    target = target or DrawTarget()
    stats = DrawStats()
    if not items:
        return stats
    show_wire = target.lines != NO_LINES
    settings = styled(settings, None, show_wire)
    variant = shader_variant(settings, target)
    stage = target.stage
    extras = {}
    if target.region_lines is not None:
        extras["region_line_image"] = target.region_lines
    if target.region_distance is not None:
        extras["region_distance_image"] = target.region_distance
    if target.display is not None:
        extras["display"] = target.display
    if target.visibility is not None:
        extras["visibility"] = target.visibility
    if target.record_depth is not None:
        extras["record_depth"] = target.record_depth
    if target.peel_depth is not None:
        extras["peel_depth"] = target.peel_depth
    if target.clip_planes is not None:
        clip_rows = clip_space_planes(target.clip_planes, view)
        extras["clip_block"] = gpu.types.GPUUniformBuf(np.asarray(clip_rows, dtype=np.float32).tobytes())
    variant = _available(variant, settings, items, extras)
    # Two per-object mechanisms side by side:
    # an object's style override (wire colour, thickness, fill colour) is a
    # parameter block per distinct style (``ubo(style)``), since thickness
    # and the wire's alpha live there; per-item colours of the colour sources
    # and the fill shading's normal matrix come from the frame's item table
    # (colors.color_table, item_table.glsl), whose colours are computed from
    # each item's styled settings, so an override also holds for the colour
    # sources' SINGLE values. The render passes' world normal and pass index
    # keep their own object block (_set_object_block).
    bases = np.zeros(len(items), dtype=np.int64)
    if variant.item_colors:
        table, bases = colors.color_table(items, settings, lambda style: styled(settings, style, show_wire))
        extras["item_colors"] = table_texture(table)
    # Each style's block, and its bytes (what a pre-pass's output depends on).
    packed = {None: params_block(settings, view, target)}
    blocks = {None: gpu.types.GPUUniformBuf(packed[None])}

    def ubo(style):
        block = blocks.get(style)
        if block is None:
            packed[style] = params_block(
                styled(settings, style, show_wire), view, target, class_reference=settings.thickness
            )
            block = blocks[style] = gpu.types.GPUUniformBuf(packed[style])
        return block

    # A resolve writes no depth (the record did) unless it writes the
    # record's depth into another buffer (``record_depth``). The render's
    # resolve draws over the record's depth, its rectangle at the far end of
    # the depth range: it passes only where a surface was recorded
    # (shaders/resolve_vert.glsl). The overlay's kept image has no depth.
    if stage != RESOLVE or target.record_depth is not None:
        depth_test, depth_write = target.depth_test, target.depth_write
    else:
        depth_test, depth_write = ("GREATER" if target.linear_depth else "NONE"), False
    gpu.state.depth_test_set(depth_test)
    gpu.state.depth_mask_set(depth_write)
    # Window-space winding flips with a mirroring view or a projection that
    # mirrors x or y (the z flip of a GL projection does not change winding).
    flip = determinant3(view.view_matrix[:3, :3]) * view.projection[0, 0] * view.projection[1, 1] < 0.0
    groups = list(_groups(items, view, cull, stats, pass_indices=target.aovs))
    try:
        call = _DrawCall(
            ubo=ubo,
            packed=packed,
            settings=settings,
            program=program,
            flip=flip,
            stats=stats,
            extras=extras,
            bases=bases,
            # Both deferred stages must split and number the draws alike:
            # instancing does not depend on the stage's variant.
            instancing=program.supports_instancing and not target.aovs,
            depth_only=target.depth_only,
            # (Only a draw of lines alone: no fill, no depth, so a triangle
            # that shows no line changes nothing.)
            drop_lineless=target.drop_lineless
            and target.lines == HIDDEN_LINES
            and stage is None
            and not target.depth_write,
            # (A scope of this draw's own where none is given: its two draws
            # of a walked mesh, _splits_walked_triangles, share one walk.)
            walk_scope=object() if target.walk_scope is None else target.walk_scope,
            numbering=_DrawNumbers(
                stage,
                extras,
                by_vertex=variant.triangle_ids_by_vertex,
                view=view,
                window=target.scissor_window,
                behind=target.behind_tiles,
                runs=target.line_runs,
            ),
        )
        # (Diagonals from the settings, not the variant: every stage must part alike.)
        parts = _parts(
            groups, program, stage, view, settings.diagonal_mode != "HIDDEN", bool(settings.use_hidden_lines)
        )
        # One variant per part; parts in a fixed order (both deferred stages
        # must draw, and so number, alike).
        for part in sorted(parts):
            part_variant = part.variant(variant)
            _draw_groups(parts[part], part_variant, call)
            if _splits_walked_triangles(part_variant, call):
                # Its picked triangles, with the variant made for them (the
                # same walk: call.walk_scope).
                _draw_groups(parts[part], replace(part_variant, walk_picks_only=True), call)
        if call.numbering.runs_left_out:
            stats.extra["region_runs_left_out"] = call.numbering.runs_left_out
        if call.numbering.triangles_left_out:
            stats.extra["record_triangles_left_out"] = call.numbering.triangles_left_out
    finally:
        gpu.state.face_culling_set("NONE")
    return stats


def _splits_walked_triangles(variant, call: _DrawCall) -> bool:
    """Whether a part's draw of ``variant`` reads back its walk's picks
    (DrawTarget.drop_lineless), and so draws the triangles that the picks
    give every line (cache.GPUMesh.walked_triangles) in a second draw with
    the variant that measures them alone (ShaderVariant.walk_picks_only):
    the same image."""
    return variant.walk_table and call.drop_lineless and not call.depth_only and not variant.walk_picks_only


def _available(variant, settings, items, extras: dict):
    """``variant`` without what this frame cannot draw: a matcap that did
    not load, corner tables the items were gathered without."""
    if variant.shading == shaders.SHADING_MATCAP:
        extras["matcap_image"] = matcaps.texture(settings.matcap)
        if extras["matcap_image"] is None:
            variant = replace(variant, shading=shaders.SHADING_FLAT)
    if (variant.shading != shaders.SHADING_FLAT or variant.material_colors) and any(
        item.mesh.corners is None for item in items
    ):
        # Meshes gathered without their corner table (a caller that did not
        # ask for it): draw flat rather than read a missing table.
        warn_once(("corners",), "SolidWire: meshes were gathered without normals; drawing a flat fill")
        variant = replace(variant, shading=shaders.SHADING_FLAT, material_colors=False)
    return variant


@dataclass(frozen=True, order=True)
class _Part:
    """The draw groups of one draw that share the per-mesh features of
    their variant. Part of every stage's key alike, so that both deferred
    stages part (and number) the draws alike."""

    ngons: bool  # the mesh has n-gons or regions: the fragment stage walks blocks
    lines_only: bool  # ... whose blocks hold only region lines
    colored: bool  # the mesh has a colour attribute
    setup_table: bool  # the edge set-up comes from the pre-pass
    in_front: bool  # every triangle lies in front of the near plane
    run_segments: int = 1  # the region-lines pass's segments per quad
    lines_from_image_only: bool = False  # every triangle's lines come from the region-lines pass
    ngon_diagonals: bool = False  # blocks hold listed n-gons' diagonals (walked where they show, see variant)
    flat_ngons_alone: bool = False  # every n-gon is a region of its own and flat (asked where diagonals show)
    ngons_may_fold: bool = False  # an n-gon may not be flat: its triangles can overlap on screen
    own_edges: bool = False  # some listed faces measure their own edges (edge_select.OWN_EDGES_MEASURED)
    walk_table: bool = False  # a direct draw's walk picks its segments in the walk-table pre-pass

    def variant(self, variant):
        """``variant`` for this part. The visibility and region-lines passes
        read neither n-gon outlines nor the set-up table; a draw that reads
        the region lines needs no block code for a mesh whose blocks only
        hold them (and n-gon diagonals, where no diagonal shows or each
        triangle's own give them)."""
        plain_stage = variant.visibility or variant.region_lines_pass
        # Where every n-gon is a region of its own (all its edges lines) and
        # flat (its triangles' windows never overlap), the nearest of its
        # diagonals that is not one of the pixel's own triangle lies beyond
        # an edge of that triangle: a diagonal, nearer, or a line, nearer
        # and as wide, so brighter than it could be. The triangle's own
        # diagonals then give max(P(d_real), m P(d_diag)) exactly (image
        # model §2.6, §4.4), in every diagonal mode. Not where each line
        # keeps a maximum of its own (density fade, edge classes of their
        # own widths, §3.6-§3.7): then the n-gon's are walked.
        own_diagonals_do = self.flat_ngons_alone and not (variant.density_fade or variant.edge_classes)
        diagonals_walked = (
            self.ngon_diagonals and variant.diagonals != shaders.DIAGONALS_HIDDEN and not own_diagonals_do
        )
        lines_elsewhere = self.lines_only and variant.region_lines and not diagonals_walked
        part_variant = replace(
            variant,
            ngons=self.ngons and not plain_stage and not lines_elsewhere,
            setup_table=self.setup_table and not plain_stage,
            in_front=self.in_front and not variant.visibility,
            attribute_colors=variant.attribute_colors and self.colored and not plain_stage,
            run_segments=self.run_segments if variant.region_lines_pass else 1,
            own_edges=self.own_edges and not plain_stage,
            # A hidden layer is never the visible face itself: a triangle
            # of a folded n-gon tests its face's other triangles
            # (quad_partner.glsl, NGON_SIBLINGS) in the direct hidden-line
            # pass and in the peeled layers' record.
            ngon_siblings=self.ngons_may_fold
            and (
                (variant.hidden_pass and not (variant.resolve or variant.region_lines_pass or variant.no_lines))
                or (variant.visibility and variant.region_layers)
            ),
        )
        if (
            self.lines_from_image_only
            and variant.resolve
            and variant.region_lines
            and variant.diagonals == shaders.DIAGONALS_HIDDEN
            and not (part_variant.ngons or part_variant.setup_table)
        ):
            # Every triangle's lines come from the region-lines image and
            # no diagonal is drawn: no triangle edge to set up per pixel.
            part_variant = replace(part_variant, no_edge_setup=True)
        if lines_elsewhere and variant.edge_classes:
            part_variant = replace(part_variant, edge_classes=False, style_colors=True)
        if variant.no_lines:
            part_variant = replace(part_variant, ngons=False, setup_table=False, no_edge_setup=True, own_edges=False)
        if (
            self.walk_table
            and part_variant.ngons
            # (A peeled mesh's region triangles are dropped before any walk.)
            and not (
                part_variant.resolve
                or part_variant.region_lines
                or part_variant.instanced
                or part_variant.region_layers_peeled
            )
        ):
            part_variant = replace(part_variant, walk_table=True)
        return part_variant


def _parts(groups, program, stage, view: View, diagonals_shown: bool = False, hidden_lines: bool = False) -> dict:
    """DrawGroups by _Part.

    Meshes with n-gons need the fragment stage's outline walk; the rest use
    a variant without it (llvmpipe pays for a loop even when it runs zero
    times), so tri/quad meshes never pay for n-gons. Big tri/quad meshes
    take their edge set-up from the pre-pass: only a mesh drawn once in
    this pass, whose table is then written before its one draw and never
    rewritten while a draw may still read it (objects sharing a mesh keep
    the per-corner set-up); see _setup_size for the deferred stages."""
    setup_ok = getattr(program, "supports_setup_table", False) and _setup_ready()
    draws_of: dict = {}
    for g in groups:
        draws_of[id(g.mesh)] = draws_of.get(id(g.mesh), 0) + len(g.world)
    parts: dict = {}
    for g in groups:
        mesh = g.mesh
        ngons = program.supports_ngons and mesh.has_ngons
        table = setup_ok and not ngons and draws_of[id(mesh)] == 1 and _setup_size(mesh, stage, g.object_to_clip, view)
        walk_table = (
            ngons
            and stage is None
            and draws_of[id(mesh)] == 1
            and getattr(program, "supports_walk_table", False)
            and mesh.region_line_count > 0
            and mesh.region_sizes()[1] >= WALK_TABLE_MIN_LINES
        )
        part = _Part(
            ngons=ngons,
            lines_only=ngons and getattr(mesh, "blocks_only_for_region_lines", False),
            colored=getattr(mesh, "attribute_colors", None) is not None,
            setup_table=table,
            walk_table=bool(walk_table),
            in_front=wholly_in_front(g.object_to_clip, mesh.bounds_min, mesh.bounds_max),
            run_segments=getattr(mesh, "region_run_segments", 1),
            lines_from_image_only=getattr(mesh, "lines_only_from_region_pass", False),
            ngon_diagonals=getattr(mesh, "blocks_hold_ngon_diagonals", False),
            # (Flat alone is not enough: a flat outline that crosses itself
            # has triangles lying on one another, as a folded one has.)
            flat_ngons_alone=diagonals_shown
            and getattr(mesh, "ngons_alone", False)
            and mesh.ngons_flat()
            and not mesh.ngons_may_fold(),
            # (Asked only where hidden lines read it: an edit re-asks.)
            ngons_may_fold=hidden_lines and mesh.has_ngons and mesh.ngons_may_fold(),
            own_edges=getattr(mesh, "own_edges_measured", False),
        )
        parts.setdefault(part, []).append(g)
    return parts


@dataclass
class _DrawCall:
    """What every part of one draw() shares: ``ubo(style)`` the parameter
    block of a style (``packed[style]`` its bytes, once ubo made it), the
    winding flip, the frame's extras (textures and blocks bound once) and
    colour-table bases, whether many instances of a mesh draw instanced,
    and the deferred stages' draw numbering."""

    ubo: object
    packed: dict
    settings: object
    program: object
    flip: bool
    stats: DrawStats
    extras: dict
    bases: np.ndarray
    instancing: bool
    numbering: _DrawNumbers
    depth_only: bool = False
    drop_lineless: bool = False  # DrawTarget.drop_lineless, where the draw shows lines alone
    walk_scope: object = None  # DrawTarget.walk_scope, or one of this draw() call's own


def clip_space_planes(planes, view: View) -> list:
    """World-space planes (kept where dot(plane, (x, 1)) >= 0, Blender's
    convention) as clip-space planes, flattened for the shader: with
    clip = P V world, dot(plane, world) = dot(plane P V^-1, clip), the same
    for every object, and linear in clip space, so the interpolated distance
    is exact across a triangle."""
    world = np.asarray(planes, dtype=np.float64).reshape(-1, 4)
    rows = np.zeros((shaders.CLIP_PLANES, 4))
    rows[: len(world)] = world[: shaders.CLIP_PLANES] @ np.linalg.inv(view.projection @ view.view_matrix)
    # Scale each plane so float32 keeps its precision (the sign is what counts).
    norms = np.abs(rows).max(axis=1, keepdims=True)
    rows = np.where(norms > 0.0, rows / np.where(norms > 0.0, norms, 1.0), 0.0)
    return rows.astype(np.float32).ravel().tolist()


def _set_clip_planes(shader, block) -> None:
    # A uniform block (shaders.CLIP_BLOCK_GLSL), not push constants: those
    # stay within 128 bytes.
    shader.uniform_block("clip_params", block)


def _bind_extras(shader, variant, extras) -> None:
    """Samplers of the shaded fill and the colour sources, and the clipping
    region's block."""
    if variant.shading == shaders.SHADING_MATCAP:
        shader.uniform_sampler("matcap_image", extras["matcap_image"])
    if variant.item_colors:
        shader.uniform_sampler("item_colors", extras["item_colors"])
    if variant.clip_planes:
        _set_clip_planes(shader, extras["clip_block"])
    if variant.display_transform:
        bind_display_transform(shader, extras["display"])
    if variant.region_lines:
        shader.uniform_sampler("region_line_image", extras["region_line_image"])
    if variant.region_distance:
        shader.uniform_sampler("region_distance_image", extras["region_distance_image"])
    if variant.record_depth:
        shader.uniform_sampler("record_depth", extras["record_depth"])
    if variant.peel_layer:
        shader.uniform_sampler("peel_depth", extras["peel_depth"])


def params_block(settings, view: View, target: DrawTarget, class_reference: float | None = None) -> bytes:
    """The parameter block of a draw of ``target`` in ``view``
    (settings.pack_params; ``class_reference``: the scene's Thickness where
    ``settings`` are an object's, styled): a viewport overlay's
    (``target.depth_bias``) moves its surfaces towards the camera by
    Blender's depth allowance (view.blender_depth_allowance)."""
    allowance = blender_depth_allowance(view) if target.depth_bias else NO_DEPTH_ALLOWANCE
    return pack_params(settings, view.viewport, view.projection, allowance, class_reference)


def bind_display_transform(shader, display) -> None:
    """The display LUT and its shaper constants (shaders.add_display_transform)."""
    shader.uniform_sampler("display_lut", display.texture())
    shader.uniform_float("display_shaper", display.shaper)


def _bind_mesh(shader, variant, mesh) -> None:
    shader.uniform_sampler("vertex_positions", mesh.positions)
    if variant.region_lines_pass and variant.thickness_mode == shaders.THICKNESS_WORLD and mesh.region_run_count:
        shader.uniform_sampler("run_bounds", mesh.run_bounds_table())  # (a mesh with no run draws no quad)
    if variant.visibility:
        if variant.region_layers:
            shader.uniform_sampler("triangle_regions", mesh.region_tables()[1])
            shader.uniform_sampler("triangle_vertices", mesh.triangles)
            shader.uniform_sampler("triangle_flag_table", mesh.flag_table())
            if variant.ngon_siblings:
                shader.uniform_sampler("triangle_faces", mesh.face_table())
        return  # its batch holds the rest (cache.GPUMesh.visibility_batch)
    shader.uniform_sampler("triangle_vertices", mesh.triangles)
    if variant.resolve and not variant.no_edge_setup:
        # (A resolve whose lines all come from the region-lines image reads
        # no edge flags: the table is never made for it.)
        shader.uniform_sampler("triangle_flag_table", mesh.flag_table())
    if variant.ngon_siblings:
        shader.uniform_sampler("triangle_faces", mesh.face_table())
    if variant.ngons or variant.own_edges:  # (OWN_EDGES: a quad's 4th corner is in its block)
        shader.uniform_sampler("ngon_corners", mesh.ngon_corners)
    if variant.uses_corners:
        shader.uniform_sampler("corner_table", mesh.corners)
        shader.uniform_int("normal_domain", mesh.normal_domain)
    if variant.attribute_colors:
        shader.uniform_sampler("attribute_colors", mesh.attribute_colors)
        shader.uniform_int("attribute_domain", mesh.attribute_domain)


class _DrawNumbers:
    """Numbers the draw calls of a deferred stage (1, 2, ...; 0 is "nothing
    drawn here" in the visibility record) and makes each call: the
    visibility stage draws the mesh's triangles, the resolve stage a
    rectangle over the draw's window box. A direct draw (stage None) just
    draws the batch."""

    def __init__(
        self,
        stage,
        extras,
        by_vertex: bool = False,
        view: View | None = None,
        window=None,
        behind=None,
        runs: str = ALL_RUNS,
    ):
        self.stage, self.extras, self.count = stage, extras, 0
        self.runs = runs  # DrawTarget.line_runs
        self.by_vertex = by_vertex  # the visibility batch's numbering (ShaderVariant.triangle_ids_by_vertex)
        self.view = view
        self.window = window  # DrawTarget.scissor_window
        self.behind = behind  # DrawTarget.behind_tiles
        self.runs_left_out = 0  # region-lines runs that the window left out
        self.triangles_left_out = 0  # recorded triangles that the window left out

    @property
    def viewport(self):
        """The draw's viewport (x, y, width, height), or None."""
        return None if self.view is None else self.view.viewport

    @property
    def draws_over_record(self) -> bool:
        """A stage that draws over the visibility record: no face culling
        (its triangles are not the mesh's)."""
        return self.stage in (RESOLVE, LINES)

    def bind(self, shader) -> None:
        if self.stage in (RESOLVE, LINES):
            shader.uniform_sampler("visibility", self.extras["visibility"])
        if self.stage == LINES and shaders.uses_uniform(shader, "clip_w_of_depth"):
            # (Read only for widths in scene units.) Clip w at a view depth z: w = -P[3][2] z + P[3][3] (z for a
            # perspective camera, 1 for an orthographic one).
            row = self.view.projection[3]
            shader.uniform_float("clip_w_of_depth", (float(-row[2]), float(row[3])))

    def _draw_ranges(self, shader, batch, mesh, ranges) -> None:
        """``batch`` (three elements a triangle, in table order) for the
        triangle ranges ``ranges`` (triangle_ranges_reaching) alone."""
        first, count = ranges
        for start, size in zip((3 * first).tolist(), (3 * count).tolist()):
            batch.draw_range(shader, elem_start=start, elem_count=size)  # (size > 0: 0 would draw to the end)
        self.triangles_left_out += mesh.triangle_count - int(count.sum())

    def _draw_runs(self, shader, mesh, object_to_clip, instance_count: int) -> None:
        """The LINES draw of ``mesh``: its runs ``self.runs`` asks for (the
        quads first to end - 1 of its batch), those that can reach the
        window alone where there is one."""
        count = mesh.region_run_count
        first, end = {
            ALL_RUNS: (0, count),
            WIRE_RUNS: (0, mesh.region_wire_runs),
            CLASS_RUNS: (mesh.region_wire_runs, count),
        }[self.runs]
        picked = None
        if end > first and self.window is not None and not instance_count:
            picked = runs_reaching(mesh, object_to_clip, self.view.viewport, self.window)
            if picked is not None:
                picked = picked[(picked >= first) & (picked < end)]
            self.runs_left_out += end - first - (end - first if picked is None else len(picked))
        if end <= first or (picked is not None and not len(picked)):
            return
        shader.uniform_int("draw_number", self.count)
        lines, regions = mesh.region_tables()
        shader.uniform_sampler("region_lines", lines)
        shader.uniform_sampler("triangle_regions", regions)
        shader.uniform_int("line_first", first)
        shader.uniform_int("line_count", end)
        if instance_count:
            # (Every run of the batch for each instance: line_first and
            # line_count collapse the others.)
            indexed_quad_batch(count).draw_instanced(shader, instance_start=0, instance_count=instance_count)
        elif picked is None:
            indexed_quad_batch(count).draw_range(shader, elem_start=6 * first, elem_count=6 * (end - first))
        else:
            picked_quad_batch(picked, count).draw(shader)

    def direct_ranges(self, mesh, object_to_clip):
        """The triangle ranges (triangle_ranges_reaching) a direct,
        non-instanced draw of ``mesh`` draws, or None for all of them."""
        if self.window is None:
            return None
        return triangle_ranges_reaching(mesh, object_to_clip, self.view.viewport, self.window)

    def draw(self, shader, mesh, batch_of, object_to_clip, instance_count: int = 0, object_to_view_z=None) -> None:
        """One draw call of ``mesh``; ``batch_of()`` gives the direct draw's
        batch (asked for only when drawing directly). ``object_to_view_z``:
        the row of the object-to-view matrix giving view z (for
        ``behind``)."""
        if self.stage is None:
            batch = batch_of()
            # (A triangle list in table order: triangle t is corners 3t..3t+2.)
            ranges = None if instance_count else self.direct_ranges(mesh, object_to_clip)
            if instance_count:
                batch.draw_instanced(shader, instance_start=0, instance_count=instance_count)
            elif ranges is None:
                batch.draw(shader)
            else:
                self._draw_ranges(shader, batch, mesh, ranges)
            return
        self.count += 1
        if self.stage == LINES:
            self._draw_runs(shader, mesh, object_to_clip, instance_count)
            return
        shader.uniform_int("draw_number", self.count)
        if self.stage == VISIBILITY:
            batch = mesh.visibility_batch(by_vertex=self.by_vertex)
            ranges = None
            behind = self.behind if object_to_view_z is not None else None
            if (self.window is not None or behind is not None) and self.by_vertex and not instance_count:
                ranges = triangle_ranges_reaching(
                    mesh, object_to_clip, self.view.viewport, self.window, behind, object_to_view_z
                )
            if instance_count:
                batch.draw_instanced(shader, instance_start=0, instance_count=instance_count)
            elif ranges is None:
                batch.draw(shader)
            else:
                self._draw_ranges(shader, batch, mesh, ranges)
            return
        shader.uniform_float("resolve_rect", window_rect(object_to_clip, mesh.bounds_min, mesh.bounds_max))
        _rectangle().draw(shader)


_quad_batches: dict[int, object] = {}  # quads: batch
_quad_corner_buffers: dict[int, object] = {}  # quads: their vertex buffer


def indexed_quad_batch(count: int):
    """Four corners (``quad_corner`` 0..3) and six indices (two triangles)
    for each of at least ``count`` screen-space quads whose shader pulls
    everything else (gl_VertexID / 4 is the quad): the region lines' runs,
    the silhouette fins, hair segments and points. Indexed, because a
    software rasteriser shades the vertices of an indexed draw once (4
    invocations per quad, not 6) and these vertex stages are dear: a
    region-lines run sets up every segment at each corner, and most
    silhouette fins are set up only to collapse. Shared by every draw of
    the same size class (the next power of two)."""
    size = _size_class(count)
    batch = _quad_batches.get(size)
    if batch is None:
        indices = _quad_indices(np.arange(size, dtype=np.int32))
        batch = _quad_batches[size] = gpu.types.GPUBatch(type="TRIS", buf=_quad_corners(size), elem=indices)
    return batch


def _size_class(count: int) -> int:
    """The quads a shared batch for ``count`` holds: the next power of two
    (at least 64)."""
    return 1 << max(int(count - 1).bit_length(), 6)


def picked_quad_batch(picked: np.ndarray, count: int):
    """indexed_quad_batch(count)'s corners with the triangles of the quads
    ``picked`` alone: a draw of some of ``count`` quads in which
    gl_VertexID / 4 is still each quad's number. Made per draw (its index
    buffer is as long as the pick)."""
    return gpu.types.GPUBatch(type="TRIS", buf=_quad_corners(_size_class(count)), elem=_quad_indices(picked))


def runs_reaching(mesh, object_to_clip: np.ndarray, viewport, window) -> np.ndarray | None:
    """The runs of ``mesh``'s region lines (cache.GPUMesh.run_points)
    whose lines can reach the window rectangle of ``window`` (x, y, width,
    height, reach: DrawTarget.scissor_window), in order; None where that is
    every run. A run's segments lie in the window box of their ends where
    every end is in front of the camera (a segment there projects to the
    segment between its ends' projections; the near plane only shortens
    it), and its lines within ``reach`` px of them. This rounds in float32
    as the drawing does, not in the same order: the reach has pixels to
    spare (passes._line_reach_px)."""
    points, corners = mesh.run_points()
    x, y, ahead = _window_points(points, object_to_clip, viewport)
    # (corners is (2 L, R): each reduction runs along whole rows.)
    picked = np.flatnonzero(_boxes_reaching(x[corners], y[corners], ahead[corners], window))
    return None if len(picked) == corners.shape[1] else picked


def triangle_ranges_reaching(mesh, object_to_clip: np.ndarray, viewport, window, behind=None, object_to_view_z=None):
    """(first triangle, triangle count) (int64 arrays) of each range of
    consecutive triangles of ``mesh`` that may cover a pixel of the window
    rectangle of ``window`` (DrawTarget.scissor_window; None: anywhere),
    and with ``behind`` (DepthTiles; ``object_to_view_z`` the object's view
    z row) lie behind its depth there, in order, or None where that is
    every triangle: the blocks of cache.GPUMesh.triangle_block_corners
    whose box projects within ``reach`` px of the rectangle (and reaches
    behind the tiles it projects onto), neighbours joined. A box wholly in
    front of the camera projects inside the window box of its corners, so
    every triangle it holds does, and no point of it lies deeper than its
    deepest corner."""
    points = mesh.triangle_block_corners()
    x, y, ahead = _window_points(points, object_to_clip, viewport)
    x, y, ahead = x.reshape(8, -1), y.reshape(8, -1), ahead.reshape(8, -1)
    kept = np.ones(x.shape[1], bool) if window is None else _boxes_reaching(x, y, ahead, window)
    if behind is not None:
        deepest = behind.record_depth(points, object_to_view_z).reshape(8, -1).max(axis=0)
        kept &= behind.reached(x.min(axis=0), x.max(axis=0), y.min(axis=0), y.max(axis=0), deepest)
        kept |= ~ahead.all(axis=0)
    if kept.all():
        return None
    # Where kept blocks start and stop: the rises and falls of the padded mask.
    steps = np.diff(np.concatenate(([0], kept.view(np.int8), [0])))
    first = np.flatnonzero(steps == 1) * RECORD_BLOCK_TRIANGLES
    end = np.minimum(np.flatnonzero(steps == -1) * RECORD_BLOCK_TRIANGLES, mesh.triangle_count)
    return first, end - first


def _window_points(points: np.ndarray, object_to_clip: np.ndarray, viewport):
    """(x, y, ahead): the window position of mesh-space ``points`` ((N, 4),
    w 0: the matrix's last column is added apart) under ``object_to_clip``
    in ``viewport`` (x, y, width, height), and whether each lies in front
    of the camera plane (where not, its x and y mean nothing)."""
    to_clip = object_to_clip.astype(np.float32)
    x, y, z, w = to_clip @ points.T + to_clip[:, 3:]
    ahead = w > 1e-6 * (np.abs(x) + np.abs(y) + np.abs(z) + 1.0)
    safe_w = np.where(ahead, w, np.float32(1.0))
    left, bottom, width, height = viewport
    return left + (x / safe_w + 1.0) * (0.5 * width), bottom + (y / safe_w + 1.0) * (0.5 * height), ahead


def _boxes_reaching(x: np.ndarray, y: np.ndarray, ahead: np.ndarray, window) -> np.ndarray:
    """(K,) bool: whether the window box of each column of points ((P, K)
    window ``x``, ``y`` and ``ahead`` of _window_points) comes within the
    reach of ``window`` (DrawTarget.scissor_window). A column with a point
    at or behind the camera plane is kept."""
    rect_x, rect_y, rect_width, rect_height, reach = window
    return (
        (x.min(axis=0) < rect_x + rect_width + reach)
        & (x.max(axis=0) > rect_x - reach)
        & (y.min(axis=0) < rect_y + rect_height + reach)
        & (y.max(axis=0) > rect_y - reach)
    ) | ~ahead.all(axis=0)


class DepthTiles:
    """A depth image (a hidden layer's, passes._peel_hidden_regions) by
    tiles of TILE px: each tile's least depth where the image holds one,
    and coarser levels of 2 x 2 tiles each up to one tile, so that what a
    box of triangles could find behind it is looked up in at most four
    tiles. A pixel where the image holds nothing counts as infinitely deep:
    a peeled layer can only lie where the layer before it does.

    The depth is view depth / clip end (``inv_clip_end``), as every layer's
    record holds it."""

    TILE = 8

    def __init__(self, depth: np.ndarray, origin, *, inv_clip_end: float):
        tile = self.TILE
        height, width = depth.shape
        padded = np.full((-(-height // tile) * tile, -(-width // tile) * tile), np.inf, np.float32)
        padded[:height, :width] = np.where(depth < 1.0, depth, np.inf)
        level = padded.reshape(padded.shape[0] // tile, tile, -1, tile).min(axis=(1, 3))
        self.levels = [level]
        while max(level.shape) > 1:
            rows, columns = -(-level.shape[0] // 2), -(-level.shape[1] // 2)
            even = np.full((2 * rows, 2 * columns), np.inf, np.float32)
            even[: level.shape[0], : level.shape[1]] = level
            level = even.reshape(rows, 2, columns, 2).min(axis=(1, 3))
            self.levels.append(level)
        self.origin = origin
        self.inv_clip_end = inv_clip_end

    def record_depth(self, points: np.ndarray, object_to_view_z) -> np.ndarray:
        """The depth the record writes at mesh-space ``points`` ((N, 4), w 0
        as _window_points'), in float64 (where a point is at or behind the
        camera plane the value means nothing: the caller keeps its box)."""
        row = np.asarray(object_to_view_z, np.float64)
        return -(points[:, :3] @ row[:3] + row[3]) * self.inv_clip_end

    def reached(self, x_low, x_high, y_low, y_high, deepest) -> np.ndarray:
        """Whether a box whose window extent is ``x_low``..``y_high`` (one
        pixel to spare is added) and whose deepest point is ``deepest`` may
        reach behind the image: some tile it covers holds a depth in front
        of that point (with a margin for the GPU's float32 rounding)."""
        ox, oy = self.origin
        finest = self.levels[0]
        rows, columns = finest.shape
        tx0 = np.clip(np.floor((x_low - 1.0 - ox) / self.TILE), 0, columns - 1).astype(np.int64)
        tx1 = np.clip(np.floor((x_high + 1.0 - ox) / self.TILE), 0, columns - 1).astype(np.int64)
        ty0 = np.clip(np.floor((y_low - 1.0 - oy) / self.TILE), 0, rows - 1).astype(np.int64)
        ty1 = np.clip(np.floor((y_high + 1.0 - oy) / self.TILE), 0, rows - 1).astype(np.int64)
        # The level at which the box spans at most two tiles each way: the
        # first whose tiles are as wide as its span (bit length of span - 1).
        span = np.maximum(tx1 - tx0, ty1 - ty0)
        level_of = np.frexp(np.maximum(span - 1, 0).astype(np.float64))[1]
        least = np.full(len(tx0), np.inf)
        for number in np.unique(level_of).tolist():
            at = np.flatnonzero(level_of == number)
            level = self.levels[min(number, len(self.levels) - 1)]
            shift = min(number, len(self.levels) - 1)
            for tx in (tx0, tx1):
                for ty in (ty0, ty1):
                    least[at] = np.minimum(least[at], level[ty[at] >> shift, tx[at] >> shift])
        margin = 1e-6 + 1e-5 * np.abs(deepest)
        return deepest + margin > least


# Each quad's two triangles over its four corners.
_QUAD_TRIANGLES = np.array([0, 1, 2, 0, 2, 3], dtype=np.int32)


def _quad_indices(quads: np.ndarray):
    return gpu.types.GPUIndexBuf(
        type="TRIS", seq=(4 * quads.astype(np.int32)[:, None] + _QUAD_TRIANGLES).reshape(-1, 3)
    )


def _quad_corners(size: int):
    """The vertex buffer of ``size`` quads' corners (``quad_corner`` 0 to 3
    each), shared as indexed_quad_batch's batches are."""
    vbo = _quad_corner_buffers.get(size)
    if vbo is None:
        fmt = gpu.types.GPUVertFormat()
        fmt.attr_add(id="quad_corner", comp_type="I32", len=1, fetch_mode="INT")
        vbo = gpu.types.GPUVertBuf(fmt, 4 * size)
        vbo.attr_fill("quad_corner", np.tile(np.arange(4, dtype=np.int32), size))
        _quad_corner_buffers[size] = vbo
    return vbo


_rectangles: list = []


def _rectangle():
    """Two triangles over a rectangle (corner bits: x = 1, y = 2); see
    resolve_vert.glsl. Made once."""
    if not _rectangles:
        fmt = gpu.types.GPUVertFormat()
        fmt.attr_add(id="rect_corner", comp_type="I32", len=1, fetch_mode="INT")
        vbo = gpu.types.GPUVertBuf(fmt, 6)
        vbo.attr_fill("rect_corner", [0, 1, 3, 0, 3, 2])
        _rectangles.append(gpu.types.GPUBatch(type="TRIS", buf=vbo))
    return _rectangles[0]


def draw_rectangle(shader, rect) -> None:
    """Draw ``shader`` (resolve_vert.glsl's vertex stage) over the NDC
    rectangle ``rect`` (x0, y0, x1, y1)."""
    shader.uniform_float("resolve_rect", rect)
    _rectangle().draw(shader)


def release_rectangle() -> None:
    """Drop the resolve pass's rectangle and the quad batches (add-on
    unregister frees every GPU object)."""
    _rectangles.clear()
    _quad_batches.clear()
    _quad_corner_buffers.clear()


def _draw_groups(groups, variant, call: _DrawCall) -> None:
    """Draw DrawGroups with one shader variant: per object (SingleDraw), or
    instanced for meshes with many instances (InstancedDraw)."""
    ubo, settings, program, stats = call.ubo, call.settings, call.program, call.stats
    extras, bases, numbering = call.extras, call.bases, call.numbering
    resolving = numbering.draws_over_record
    shader = program.shader(variant)
    uses_view_depth = shaders.uses_uniform(shader, "object_to_view_z")
    # (A resolve that reads the set-up table and needs no barycentrics
    # never transforms a vertex.)
    uses_matrix = shaders.uses_uniform(shader, "object_to_clip")
    shader.bind()
    bound = None
    shader.uniform_block("params", ubo(bound))
    _bind_extras(shader, variant, extras)
    numbering.bind(shader)
    instanced: list[InstancedDraw] = []
    single: list[SingleDraw] = []
    for group in groups:
        mirrored_all = (determinant3(group.world[:, :3, :3]) < 0.0) != call.flip
        info_all = np.zeros((len(group.world), 4))
        if bases is not None and len(bases):
            info_all[:, 0] = bases[group.indices]
        info_all[:, 1] = mirrored_all
        # (The instanced variant has no per-object pass values: with passes
        # every object is drawn on its own.)
        if call.instancing and len(group.world) >= INSTANCING_MIN:
            sides = (
                (False, True)
                if settings.use_backface_culling and 0 < mirrored_all.sum() < len(mirrored_all)
                else (None,)
            )
            for side in sides:
                pick = slice(None) if side is None else mirrored_all == side
                facing = bool(mirrored_all[0]) if side is None else side
                instanced.append(
                    InstancedDraw(
                        group.mesh,
                        group.style,
                        group.object_to_view[pick],
                        group.object_to_clip[pick],
                        info_all[pick],
                        facing,
                    )
                )
            continue
        for k in range(len(group.world)):
            single.append(
                SingleDraw(
                    group.mesh,
                    group.style,
                    group.world[k],
                    group.object_to_view[k],
                    group.object_to_clip[k],
                    info_all[k],
                    bool(mirrored_all[k]),
                    None if group.pass_index is None else float(group.pass_index[k]),
                    None if group.materials is None else group.materials[k],
                )
            )
    if single and variant.per_item:
        # Normal matrices and item info of every object in one texture
        # (item_table.glsl); each draw says its slot.
        rows = np.zeros((len(single), shaders.ITEM_TEXELS, 4), dtype=np.float32)
        rows[:, :3, :] = np.swapaxes(normal_to_view(np.stack([d.object_to_view for d in single])), 1, 2)[:, :3, :]
        rows[:, 3, :] = np.stack([d.info for d in single])
        item_table = table_texture(rows.reshape(-1, 4))  # kept alive until the draws are done
        shader.uniform_sampler("item_table", item_table)
    object_block = None  # the render passes' per-object block (write_aovs only)
    material_tables: dict = {}  # (mesh, materials) -> triangle -> material pass index texture
    if single:
        for slot, one in enumerate(single):
            mesh, style, mirrored, object_to_clip = one.mesh, one.style, one.mirrored, one.object_to_clip
            if variant.setup_table:
                # (Before each draw: so a mesh is set up for the matrix of
                # the one object drawing it.)
                _run_setup(mesh, object_to_clip, ubo(style), variant.in_front, numbering.viewport)
                shader.bind()
                bound = _UNBOUND  # the pre-pass bound its own block
                shader.uniform_sampler("setup_table", mesh.setup_table)
            triangles = None  # every triangle (of the ranges the draw reaches)
            picked = ()  # those a second draw measures the picks of alone (_splits_walked_triangles)
            if variant.walk_table and call.depth_only:
                # (The same program, for the same depths; its picks are
                # never read. Bound all the same: the program samples it.)
                shader.uniform_sampler("walk_table", mesh.walk_table())
            elif variant.walk_table:
                # (Before each draw, as the set-up pre-pass: the picks are
                # for this object's matrix.)
                ranges = numbering.direct_ranges(mesh, object_to_clip)
                block = ubo(style)
                walk_table = _run_walk_table(
                    mesh,
                    variant,
                    object_to_clip,
                    one.object_to_view,
                    block,
                    ranges,
                    call.walk_scope,
                    call.packed[style],
                )
                shader.bind()
                bound = _UNBOUND  # the pre-pass bound its own block
                _bind_extras(shader, variant, extras)
                numbering.bind(shader)
                shader.uniform_sampler("walk_table", walk_table)
                if call.drop_lineless:
                    others, picked = mesh.walked_triangles(ranges)
                    triangles = picked if variant.walk_picks_only else others
            if style is not bound:
                bound = style
                shader.uniform_block("params", ubo(style))
            if settings.use_backface_culling and not resolving:
                gpu.state.face_culling_set("FRONT" if mirrored else "BACK")
            if variant.write_aovs:
                object_block = _set_object_block(shader, object_block, one.world, mirrored, one.pass_index)
                shader.uniform_sampler("triangle_material", _material_table(mesh, one.materials, material_tables))
            if uses_matrix:
                shader.uniform_float("object_to_clip", object_to_clip.T.astype(np.float32).ravel().tolist())
            if uses_view_depth:
                shader.uniform_float("object_to_view_z", one.object_to_view[2].astype(np.float32).tolist())
            if variant.per_item:
                shader.uniform_int("item_slot", slot)
            _bind_mesh(shader, variant, mesh)
            if triangles is None:
                numbering.draw(
                    shader,
                    mesh,
                    lambda mesh=mesh: program.batch(mesh),
                    object_to_clip,
                    object_to_view_z=one.object_to_view[2],
                )
            elif len(triangles):
                mesh.batch_of_triangles(triangles).draw(shader)
            if variant.walk_picks_only:
                # (The object, and what it left out, counted by its other draw.)
                stats.add(DrawStats(extra={WALK_PICKS_DRAWN: len(triangles)}))
                continue
            stats.objects_drawn += 1
            stats.triangles_drawn += mesh.triangle_count
            if triangles is not None:
                left_out = mesh.triangle_count - len(triangles) - len(picked)
                stats.add(DrawStats(extra={LINELESS_LEFT_OUT: left_out}))
    if instanced:
        _draw_instanced(instanced, variant, call)


_UNBOUND = object()


def _setup_ready() -> bool:
    """Compute shaders run here and the pre-pass compiles; a backend that
    refuses it keeps the per-corner set-up (said once), never a failed draw;
    so does a context where it may not dispatch (shaders.setup_dispatch_allowed)."""
    if not shaders.setup_dispatch_allowed():
        return False
    try:
        shaders.get_setup()
    except Exception as exc:  # noqa: BLE001 - any compile/link failure means: no pre-pass
        shaders.disable_setup()
        warn_once(("setup",), f"SolidWire: the set-up pre-pass is not available here ({exc}); drawing without it")
        return False
    return True


def _setup_size(mesh, stage, object_to_clip, view: View) -> bool:
    """Whether a draw of ``mesh`` gains from the set-up pre-pass (and its
    table fits in a texture). A direct draw sets a triangle up at each of
    its corners: the pre-pass pays from SETUP_TABLE_MIN triangles on.

    The deferred stages never use it: the resolve sets a triangle up once
    per pixel it shows instead. (The pre-pass would pay there where a draw's
    window box holds more pixels than the mesh has triangles, but a compute
    dispatch between the resolve's draws crashed llvmpipe inside the
    dispatch, reproducibly after a long run of renders in one process; the
    direct draws' pre-pass runs outside any deferred stage.)"""
    if mesh.triangle_count > shaders.SETUP_MAX_TRIANGLES:
        return False
    return stage is None and mesh.triangle_count >= SETUP_TABLE_MIN


def _setup_key(mesh, object_to_clip, in_front: bool, viewport) -> tuple | None:
    """Everything a mesh's set-up table depends on: its triangles and
    positions (serial and shape version, cache.GPUMesh), the matrix as the
    pre-pass gets it, the viewport (the only parameter the edge set-up
    reads, edge_geometry.glsl), the variant and the GL context that wrote
    it (a compute barrier orders the writes for its own context only); None
    when the viewport is not known."""
    if viewport is None:
        return None
    matrix = np.asarray(object_to_clip, dtype=np.float32).tobytes()
    viewport = tuple(float(v) for v in viewport)
    return (mesh.serial, mesh.version, matrix, bool(in_front), viewport, shaders.current_gl_context())


def _run_setup(mesh, object_to_clip, block, in_front: bool = False, viewport=None) -> None:
    """The set-up pre-pass of one draw: every triangle's edge set-up into
    ``mesh.setup_table`` (allocated on first use; gpu.compute.dispatch ends
    with the barrier that makes the writes visible to the draw's texture
    fetches). ``in_front``: the draw lies wholly in front of the near plane
    (view.wholly_in_front), so the pre-pass runs without its clipping code.
    With the ``viewport`` known, a table already set up for the same mesh,
    matrix and viewport (_setup_key) is kept: a redraw that changes none of
    them, or a second pass over the mesh in the same frame, dispatches
    nothing."""
    count = mesh.triangle_count
    key = _setup_key(mesh, object_to_clip, in_front, viewport)
    if key is not None and getattr(mesh, "setup_table", None) is not None and getattr(mesh, "setup_key", None) == key:
        return
    mesh.setup_key = None
    if getattr(mesh, "setup_table", None) is None:
        rows = -(-count // shaders.SETUP_ROW_TRIANGLES)
        mesh.setup_table = gpu.types.GPUTexture(
            (shaders.SETUP_ROW_TRIANGLES * shaders.SETUP_TEXELS, rows), format="RGBA32F"
        )
        mesh.gpu_bytes += texture_bytes(mesh.setup_table)
    setup = shaders.get_setup(in_front)
    setup.bind()
    setup.uniform_block("params", block)
    setup.uniform_float("object_to_clip", object_to_clip.T.astype(np.float32).ravel().tolist())
    setup.uniform_int("triangle_count", count)
    setup.uniform_sampler("vertex_positions", mesh.positions)
    setup.uniform_sampler("triangle_vertices", mesh.triangles)
    setup.image("setup_table", mesh.setup_table)
    groups = -(-count // shaders.SETUP_GROUP_SIZE)
    groups_x = min(groups, 65535)
    gpu.compute.dispatch(setup, groups_x, -(-groups // groups_x), 1)
    mesh.setup_key = key


def _walk_key(scope, mesh, pass_variant, object_to_clip, object_to_view, packed: bytes, ranges) -> tuple:
    """Everything the walk table of ``mesh`` depends on within ``scope``
    (DrawTarget.walk_scope, held here: no other object takes its place):
    its triangles and positions (serial and shape version,
    cache.GPUMesh), the pre-pass's variant, the matrices and the parameter
    block as it gets them (the reach, the viewport), the triangle ranges it
    writes, and the GL context that wrote it (as _setup_key)."""
    return (
        scope,
        mesh.serial,
        mesh.version,
        pass_variant,
        np.asarray(object_to_clip, dtype=np.float32).tobytes(),
        np.asarray(object_to_view[2], dtype=np.float32).tobytes(),
        bytes(packed),
        None if ranges is None else (ranges[0].tobytes(), ranges[1].tobytes()),
        shaders.current_gl_context(),
    )


def _run_walk_table(mesh, variant, object_to_clip, object_to_view, block, ranges=None, scope=None, packed=b""):
    """The walk-table pre-pass of one draw (shaders/walk_table_frag.glsl):
    a fragment per triangle of ``mesh`` writes which segments of its block
    lie within reach of it, into the mesh's table (cache.GPUMesh.walk_table),
    which it returns for the draw to read; ``ranges``: only the triangle
    ranges the draw draws (_DrawNumbers.direct_ranges: an edit's partial
    redraw; the table's rows that hold them), None for all. Draws into the
    table's own framebuffer and puts back the bound one, its viewport and
    the blend and depth state. With a ``scope`` (DrawTarget.walk_scope;
    ``packed`` the bytes of ``block``) a table already walked in that scope
    for the same key (_walk_key) is kept instead."""
    table = mesh.walk_table()
    pass_variant = replace(variant, walk_table=False, walk_picks_only=False, walk_table_pass=True, clip_planes=False)
    key = None
    if scope is not None:
        key = _walk_key(scope, mesh, pass_variant, object_to_clip, object_to_view, packed, ranges)
    if key is not None and mesh.walk_key == key:
        return table
    mesh.walk_key = None
    group_batch, group_boxes = mesh.walk_groups()
    # (Made for each run, as the pass targets' are: a framebuffer belongs to
    # the GL context that made it, and a mesh is drawn in two.)
    framebuffer = gpu.types.GPUFrameBuffer(color_slots=(table,))
    shader = shaders.get(pass_variant)
    saved_viewport = gpu.state.viewport_get()
    saved = gpu.state.blend_get(), gpu.state.depth_test_get(), gpu.state.depth_mask_get()
    try:
        if group_batch is not None:
            # First the window box of each group of the blocks' segments,
            # which the pass tests before setting any of them up.
            with gpu.types.GPUFrameBuffer(color_slots=(group_boxes,)).bind():
                _point_texels_state(group_boxes)
                groups = shaders.get_walk_groups(variant.in_front)
                groups.bind()
                groups.uniform_block("params", block)
                groups.uniform_float("object_to_clip", object_to_clip.T.astype(np.float32).ravel().tolist())
                groups.uniform_int("group_table_size", (group_boxes.width, group_boxes.height))
                groups.uniform_sampler("vertex_positions", mesh.positions)
                groups.uniform_sampler("ngon_corners", mesh.ngon_corners)
                group_batch.draw(groups)
        with framebuffer.bind():
            _point_texels_state(table)
            shader.bind()
            shader.uniform_block("params", block)
            if shaders.uses_uniform(shader, "object_to_clip"):
                shader.uniform_float("object_to_clip", object_to_clip.T.astype(np.float32).ravel().tolist())
            if shaders.uses_uniform(shader, "object_to_view_z"):
                shader.uniform_float("object_to_view_z", object_to_view[2].astype(np.float32).tolist())
            shader.uniform_int("walk_triangle_count", mesh.triangle_count)
            shader.uniform_sampler("walk_group_boxes", group_boxes)
            shader.uniform_sampler("triangle_flag_table", mesh.flag_table())
            _bind_mesh(shader, pass_variant, mesh)
            for first_row, end_row in _table_rows(mesh.triangle_count, ranges):
                # (NDC rows of the table: a fragment per texel, one per triangle.)
                low, high = (2.0 * first_row / table.height - 1.0, 2.0 * end_row / table.height - 1.0)
                draw_rectangle(shader, (-1.0, low, 1.0, high))
        mesh.walk_key = key
    finally:
        gpu.state.viewport_set(*saved_viewport)
        gpu.state.blend_set(saved[0])
        gpu.state.depth_test_set(saved[1])
        gpu.state.depth_mask_set(saved[2])
    return table


def _table_rows(triangle_count: int, ranges=None) -> list:
    """(first row, end row) of each run of the walk table's rows that
    holds a triangle of ``ranges`` ((first triangle, count) arrays; None:
    every triangle), in order: 2^WALK_TABLE_SHIFT triangles a row."""
    shift = shaders.WALK_TABLE_SHIFT
    if ranges is None:
        return [(0, -(-triangle_count // (1 << shift)))] if triangle_count else []
    first, count = np.asarray(ranges[0], np.int64), np.asarray(ranges[1], np.int64)
    keep = count > 0
    rows = []
    for low, high in zip((first[keep] >> shift).tolist(), (((first + count - 1)[keep] >> shift) + 1).tolist()):
        if rows and low <= rows[-1][1]:
            rows[-1] = (rows[-1][0], max(rows[-1][1], high))
        else:
            rows.append((low, high))
    return rows


def _point_texels_state(table) -> None:
    """GPU state for a pass that writes the texels of ``table`` (the bound
    framebuffer's) one for one, by points or by a rectangle's fragments:
    its viewport, no blend and no depth. One texel a point: Blender's
    viewport leaves a point size of its own (programmable or fixed)
    behind, which widened the points over their neighbours' texels after a
    viewport draw. (Its draws set their own again: nothing to put back.)"""
    gpu.state.viewport_set(0, 0, table.width, table.height)
    gpu.state.blend_set("NONE")
    gpu.state.depth_test_set("NONE")
    gpu.state.depth_mask_set(False)
    gpu.state.program_point_size_set(False)
    gpu.state.point_size_set(1.0)


def _material_table(mesh, materials, tables: dict):
    """Texture of the IndexMA value of each triangle of ``mesh`` for one
    object's materials (face material index -> slot -> the material's
    pass_index; an index past the last slot uses the last, as Blender does).
    Shared by the instances with the same materials in one draw."""
    key = (id(mesh), None if materials is None else (id(materials[0]), materials[1]))
    table = tables.get(key)
    if table is None:
        values = np.zeros((mesh.triangle_count, 4), dtype=np.float32)
        if materials is not None and len(materials[1]):
            face_slot, slot_pass = materials
            slots = np.asarray(slot_pass, dtype=np.float32)
            face = np.asarray(mesh.triangle_polygons_cpu)
            face_ok = face < len(face_slot)
            slot = np.clip(face_slot[np.where(face_ok, face, 0)], 0, len(slots) - 1)
            values[:, 0] = np.where(face_ok, slots[slot], 0.0)
        table = tables[key] = table_texture(values)
    return table


def _set_object_block(shader, block, world: np.ndarray, mirrored: bool, pass_index: float):
    """Bind the render passes' per-object values (shaders.OBJECT_BLOCK_GLSL):
    the normal matrix (inverse transpose of the object's 3x3), negated for a
    mirrored object so that gl_FrontFacing says which side the camera sees,
    and the object's pass index. One block, updated per object."""
    normal_matrix, det = inverse_transpose3(world[:3, :3])
    if not (det != 0.0 and np.isfinite(det)):
        normal_matrix = np.zeros((3, 3))
    if mirrored:
        normal_matrix = -normal_matrix
    values = np.zeros((3, 4), dtype=np.float32)
    values[:, :3] = normal_matrix.T  # columns
    values[0, 3] = pass_index
    data = values.tobytes()
    if block is None:
        block = gpu.types.GPUUniformBuf(data)
        shader.uniform_block("object_params", block)
    else:
        block.update(data)
    return block


def _draw_instanced(groups: list[InstancedDraw], variant, call: _DrawCall) -> None:
    """One draw_instanced call per (mesh, style, facing) group; every
    instance's matrices in one float texture for the whole frame."""
    ubo, settings, stats, extras, numbering = call.ubo, call.settings, call.stats, call.extras, call.numbering
    shader = shaders.get(replace(variant, instanced=True, setup_table=False, walk_table=False))
    table = table_texture(np.concatenate([_instance_rows(g.object_to_view, g.object_to_clip, g.info) for g in groups]))
    shader.bind()
    bound = None
    shader.uniform_block("params", ubo(bound))
    shader.uniform_sampler("instance_table", table)
    _bind_extras(shader, variant, extras)
    numbering.bind(shader)
    # (A resolve that needs no corner of the triangle, a cage look's flat
    # wire in pixels, reads no instance's matrices at all.)
    uses_instances = shaders.uses_uniform(shader, "instance_base")
    base = 0
    for group in groups:
        mesh, style, object_to_clip, mirrored = group.mesh, group.style, group.object_to_clip, group.mirrored
        count = len(object_to_clip)
        if style is not bound:
            bound = style
            shader.uniform_block("params", ubo(style))
        if settings.use_backface_culling and not numbering.draws_over_record:
            gpu.state.face_culling_set("FRONT" if mirrored else "BACK")
        if uses_instances:
            shader.uniform_int("instance_base", base)
        _bind_mesh(shader, variant, mesh)
        numbering.draw(shader, mesh, lambda mesh=mesh: mesh.batch, object_to_clip, instance_count=count)
        base += count * shaders.INSTANCE_TEXELS
        stats.objects_drawn += count
        stats.triangles_drawn += count * mesh.triangle_count
        stats.extra["instanced_draws"] = stats.extra.get("instanced_draws", 0) + 1
