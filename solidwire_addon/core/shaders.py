"""The one shader loader: GLSL files in ``shaders/`` -> compiled GPU shaders.

The interface (samplers, push constants, the parameter block and the flat
varyings) is declared here once; the GLSL bodies live in files so they can be
read, diffed and linted as GLSL. Variants are compiled on first use and kept
for the life of the process (see _cache for why), keyed by
the feature flags that change the generated code, so a feature that is off
costs nothing at run time.
"""

from __future__ import annotations

import atexit
import contextlib
import warnings
from dataclasses import dataclass
from pathlib import Path

import gpu

from . import compat, display_transform, schema

# The extension root's shaders/ folder (this file is solidwire_addon/core/shaders.py).
SHADER_DIR = Path(__file__).resolve().parents[2] / "shaders"

THICKNESS_PIXELS, THICKNESS_WORLD, THICKNESS_DEPTH = 0, 1, 2

EDGE_COUNT = 5  # three triangle edges + two edges to a quad's 4th corner
# Segments of a region block that the vertex stage hands to the fragment
# stage (those within reach of the triangle); more than this and the
# fragment stage walks the whole block (solidwire_vert.glsl), or with the
# walk-table pre-pass those of up to as many of its groups as hold them.
SEGMENT_SLOTS = 6

DIAGONALS_HIDDEN, DIAGONALS_SOLID, DIAGONALS_PATTERN = 0, 1, 2

# Fill shading (docs/image_model.md §5.8); FLAT is §5.2's flat fill.
SHADING_FLAT, SHADING_STUDIO, SHADING_MATCAP = 0, 1, 2

# Texels per triangle of the set-up table (layout in setup_comp.glsl).
SETUP_TEXELS = 7
# Triangles per row of the set-up table: a triangle's texels share a row
# (4095 texels wide, under the 16384 limit for 9.5M triangles).
SETUP_ROW_TRIANGLES = 585
SETUP_MAX_TRIANGLES = SETUP_ROW_TRIANGLES * 16384
# The walk-table pre-pass's table (shaders/walk_table_frag.glsl): 2^SHIFT
# triangles a row; two picks a channel, below WALK_PICK_BASE each (a block
# longer than that is walked whole).
WALK_TABLE_SHIFT = 12
WALK_PICK_BASE = 4096
# Segments of a region block per group of the walk-table groups
# (shaders/walk_groups_vert.glsl): the pre-pass tests a group's window box
# before it sets up any of them. A cage edge at level 3 is a chain of 8.
WALK_GROUP = 4
SETUP_GROUP_SIZE = 64  # compute invocations per work group, one per triangle

CLIP_PLANES = 6  # as many as Blender's clipping region (RegionView3D.clip_planes)


@dataclass(frozen=True)
class ShaderVariant:
    """Everything that changes the compiled code (and nothing else)."""

    diagonals: int = DIAGONALS_HIDDEN
    use_fill: bool = False
    use_fade: bool = False
    write_view_depth: bool = False
    # Viewport overlay: NDC depth bias towards the camera (0 = none); see
    # DEPTH_BIAS in edge_geometry.glsl (biased) and view.OVERLAY_DEPTH_BIAS.
    depth_bias: float = 0.0
    thickness_mode: int = THICKNESS_PIXELS
    # Hidden-line style (image model §5.4): the pass that draws faces behind the
    # visible surface, real edges only, dimmed and dashed, no fill.
    hidden_pass: bool = False
    # The mesh has n-gons: the fragment stage walks their outlines and
    # diagonals (USE_NGONS); tri/quad meshes get a variant without that code.
    ngons: bool = False
    # The render's offscreen passes write view depth / clip end as depth
    # (LINEAR_DEPTH, see solidwire_frag.glsl); the viewport overlay keeps
    # Blender's depth mapping, whose buffer it shares.
    linear_depth: bool = False
    # Render passes beyond Combined and Depth (image model §6): a third and
    # fourth colour output with d_real, I_vis and the object index, and the
    # world-space face normal. Only the render's surface pass of a view
    # layer that asks for them compiles this.
    write_aovs: bool = False
    # Many instances of one mesh in one draw_instanced call,
    # each reading its matrices from a float texture by gl_InstanceID (see
    # shaders/instancing.glsl and draw.py).
    instanced: bool = False
    # Viewport clipping region (Alt+B): fragments outside CLIP_PLANES
    # clip-space planes are discarded (USE_CLIP_PLANES; image model §5.6).
    clip_planes: bool = False
    # Shaded fill (SHADING_*): the vertex stage pulls corner normals.
    shading: int = SHADING_FLAT
    # Per-object wire/fill colours from the frame's colour table
    # (core/colors.py); with material_colors, the fill per face material.
    item_colors: bool = False
    material_colors: bool = False
    # Edge classes (image model §3.6): the fragment stage keeps the nearest
    # edge of each of STYLE_COUNT line styles instead of one.
    edge_classes: bool = False
    # Density fade (image model §3.7): lines of short edges fade.
    density_fade: bool = False
    # Viewport overlay only: the scene's colour management applied last
    # (DISPLAY_TRANSFORM, shaders/display_transform.glsl, image model §9).
    display_transform: bool = False
    # Big non-instanced tri/quad meshes: the vertex stage reads each
    # triangle's edge set-up from the table the set-up pre-pass wrote
    # (SETUP_TABLE, shaders/setup_comp.glsl) instead of setting it up at
    # every corner.
    setup_table: bool = False
    # The deferred surface (docs/image_model.md §2.5): ``visibility`` is the
    # pass that only records which triangle each pixel shows (it reads just
    # ``instanced`` and ``linear_depth`` of the variant); ``resolve`` is the
    # exact path's fragment stage run once per pixel over that record.
    visibility: bool = False
    resolve: bool = False
    # Visibility pass only: the triangle number comes with the provoking
    # vertex (a "triangle" attribute; cache.GPUMesh.visibility_batch) instead
    # of gl_PrimitiveID (triangle_ids_by_vertex says when).
    triangle_ids_by_vertex: bool = False
    # Every triangle of the draw lies in front of the near plane (its box
    # does, with a margin; view.wholly_in_front): the edge set-up compiles
    # without its clipping code (ALL_IN_FRONT), which a CPU rasteriser
    # would otherwise run for every triangle or pixel, branch or not.
    in_front: bool = False
    # Region lines (docs/image_model.md §2.6): ``region_lines_pass`` is the
    # pass that draws the lines of multi-face regions as screen-space quads
    # over the visibility record (it reads only thickness_mode,
    # edge_classes, density_fade and instanced); ``region_lines`` is a
    # surface pass (resolve, or the overlay's direct draw) that reads that
    # pass's image for those regions' triangles.
    region_lines_pass: bool = False
    region_lines: bool = False
    # The Edge Distance pass over regions (docs/image_model.md §2.6): the
    # region-lines pass keeping each pixel's nearest line distance instead
    # of its strongest line (``line_distance``, LINE_DISTANCE), and a
    # resolve that takes d_real from that image where a line is within
    # reach, so that it need not walk its regions for d (``region_distance``,
    # REGION_DISTANCE_IMAGE).
    line_distance: bool = False
    region_distance: bool = False
    # Region-lines pass only: segments per quad (1, 2, 4 or 8; the mesh's
    # cache.GPUMesh.region_run_segments).
    run_segments: int = 1
    # The hidden layers of multi-face regions, drawn by depth peeling
    # (docs/image_model.md §2.6, passes._peel_hidden_regions). Visibility
    # pass: ``region_layers`` records only the triangles whose lines come
    # from the region-lines pass (REGION_LAYERS), ``peel_layer`` only those
    # strictly behind the depth in the ``peel_depth`` image (PEEL_LAYER). The
    # region-lines pass with ``hidden_pass`` draws such a layer's lines. A
    # direct hidden-line pass with ``region_layers_peeled`` leaves those
    # triangles out (REGION_LAYERS_PEELED).
    region_layers: bool = False
    peel_layer: bool = False
    region_layers_peeled: bool = False
    # The direct hidden-line pass, or the region layers' record, of a mesh
    # whose n-gons may not be flat: a triangle of an n-gon also tests its
    # face's other triangles, as a quad's tests its other one
    # (quad_partner.glsl, NGON_SIBLINGS; docs/image_model.md §5.4).
    ngon_siblings: bool = False
    # Resolve only: every triangle of the draw takes its lines from the
    # region-lines image and no diagonal is drawn (a cage look), so no
    # triangle edge is set up per pixel (NO_EDGE_SETUP).
    no_edge_setup: bool = False
    # The fill alone: a surface pass that shows no line and writes no render
    # pass (the surface under hidden lines, whose wire is drawn on its own):
    # no line is measured (NO_EDGE_SETUP, no block walk).
    no_lines: bool = False
    # Resolve only, viewport overlay: the resolve writes the record's window
    # depth less DEPTH_BIAS (RECORD_DEPTH), as the overlay's composite does,
    # to resolve straight into Blender's buffer.
    record_depth: bool = False
    # A surface pass that measures no line of a class itself (every class
    # line comes from the region-lines pass) but colours the winning style:
    # the class colours without the per-style distance code (STYLE_COLORS).
    style_colors: bool = False
    # The mesh has faces that measure their own edges beside a block of
    # classed ones (core/edge_select.py OWN_EDGES_MEASURED): the vertex
    # stage reads such a quad's 4th corner from its block (OWN_EDGES);
    # other meshes get a variant without that code, which a CPU rasteriser
    # would run at every corner or resolved pixel, branch or not.
    own_edges: bool = False
    # The ATTRIBUTE fill source for a mesh that has a colour attribute: the
    # fill is its colours, interpolated over each triangle (ATTRIBUTE_COLORS).
    attribute_colors: bool = False
    # Walked regions in a direct draw (a mesh of large regions that is not
    # peeled, docs/dev/how-it-works.md "Walked regions"): ``walk_table_pass``
    # is the pre-pass that picks, once per triangle, the segments of its
    # block within reach (shaders/walk_table_frag.glsl); a draw with
    # ``walk_table`` reads those picks (WALK_TABLE) instead of choosing them
    # at its provoking corner.
    walk_table: bool = False
    walk_table_pass: bool = False
    # A hidden-line draw with ``walk_table`` of only the region triangles
    # (no quad corner of their own) whose picks hold every line within their
    # reach (WALK_PICKS_ONLY, core/cache.GPUMesh.walked_triangles): nothing
    # else of theirs is a line, so no edge of their own is set up and the
    # fragment stage measures the picks alone. A CPU rasteriser runs every
    # loop and branch compiled in for every fragment, taken or not: the
    # other triangles' block and outline walks and their own edges cost these
    # ones as much as themselves.
    walk_picks_only: bool = False
    # The surface pass of the render under hidden lines: the colour is the
    # fill alone and the visible wire goes to an output of its own
    # (WIRE_LAYER, frag_wire), drawn unblended like the colour, so that the
    # hidden lines can be blended between the two (passes.WirePass).
    wire_layer: bool = False

    @property
    def uses_corners(self) -> bool:
        """The corner table (normals, material indices) is read."""
        return self.shading != SHADING_FLAT or self.material_colors

    @property
    def per_item(self) -> bool:
        """The per-object normal matrix and item info are read."""
        return self.uses_corners or self.item_colors


# Two GL contexts draw SolidWire: a render (bpy.ops.render.render, F12) draws
# in the render engine's own context, everything else (viewport overlay,
# scripts) in the window/script context. Compiled programs are kept apart per
# context (``gl_context``): a program compiled and drawn with in one context
# and then drawn with in the other gave wrong images there (part of the
# surface missing after the window context had drawn the same variant), and
# deleting a program from one context after the other had drawn with it
# crashed llvmpipe later inside an unrelated draw (segfault in swrast_dri
# during batch.draw). Programs also live for the whole process: reused across
# unregister/register and freed only at interpreter exit, while Blender's GPU
# context still exists. A program is a few KiB of driver memory.
_cache: dict[tuple, object] = {}
RENDER_ENGINE_CONTEXT = "render-engine"  # the render engine's own GL context (gl_context)
_context = "window"


def current_gl_context() -> str:
    """The GL context the draw calls of the moment go to (see gl_context)."""
    return _context


def in_render_engine_context() -> bool:
    """Whether the draw calls of the moment go to the render engine's own GL
    context (gl_context)."""
    return _context == RENDER_ENGINE_CONTEXT


@contextlib.contextmanager
def gl_context(name: str):
    """Draw calls inside use the programs of GL context ``name`` (the render
    engine says RENDER_ENGINE_CONTEXT; everything else is "window")."""
    global _context
    previous, _context = _context, name
    try:
        yield
    finally:
        _context = previous


def _keep(cache: dict, key, shader):
    """Store a compiled program; the first one installs the exit hook that
    frees them all while Blender's GPU context still exists (the cache is
    emptied only by that hook)."""
    if not cache:
        atexit.register(release_at_exit)
    cache[key] = shader
    return shader


def read_source(name: str, directory: Path = SHADER_DIR) -> str:
    path = directory / name
    try:
        return path.read_text(encoding="utf-8")
    except OSError as exc:  # a broken install: say which file is missing
        raise RuntimeError(f"SolidWire shader file missing: {path.name} ({exc.strerror})") from None


def edge_styles_source() -> str:
    """shaders/edge_styles.glsl after the per-style lookups the schema
    generates (one definition of the edge classes and their order)."""
    return schema.style_lookup_glsl() + read_source("edge_styles.glsl")


def uses_uniform(shader, name: str) -> bool:
    """Whether the compiled ``shader`` kept uniform ``name`` (the compiler
    drops one a variant does not read, and setting it then fails)."""
    try:
        shader.uniform_from_name(name)
    except ValueError:
        return False
    return True


# Every sampler's (slot, kind), defined once. Names that share a slot are
# never declared in one program: a mesh table and the fin / strand tables
# (slot 1), the outline table, the region-lines table and the scene depth
# (2), the instanced and per-object item tables (3), the corner table and
# the per-triangle regions (4), the matcap and the region-lines runs'
# bounds (6: the region-lines pass shades nothing), the attribute colours
# and the per-triangle faces (13: a hidden-line pass draws no attribute
# colour).
SAMPLERS = {
    "vertex_positions": (0, "FLOAT_2D"),
    "triangle_vertices": (1, "FLOAT_2D"),
    "silhouette_edges": (1, "FLOAT_2D"),
    "strand_segments": (1, "FLOAT_2D"),
    "ngon_corners": (2, "FLOAT_2D"),
    "region_lines": (2, "FLOAT_2D"),
    "scene_depth": (2, "DEPTH_2D"),
    "instance_table": (3, "FLOAT_2D"),
    "item_table": (3, "FLOAT_2D"),
    "corner_table": (4, "FLOAT_2D"),
    "triangle_regions": (4, "FLOAT_2D"),
    "item_colors": (5, "FLOAT_2D"),
    "matcap_image": (6, "FLOAT_2D"),
    "run_bounds": (6, "FLOAT_2D"),
    "triangle_material": (7, "FLOAT_2D"),
    "display_lut": (8, "FLOAT_3D"),
    "setup_table": (9, "FLOAT_2D"),
    "walk_table": (9, "FLOAT_2D"),  # (never beside the set-up table: a walked mesh has blocks)
    "walk_group_boxes": (9, "FLOAT_2D"),  # (the walk-table pre-pass's: its draw reads the table there)
    "visibility": (10, "FLOAT_2D"),
    "triangle_flag_table": (11, "FLOAT_2D"),
    "region_line_image": (12, "DEPTH_2D"),
    "attribute_colors": (13, "FLOAT_2D"),
    "triangle_faces": (13, "FLOAT_2D"),
    "record_depth": (14, "DEPTH_2D"),
    "peel_depth": (14, "DEPTH_2D"),
    "surface_image": (15, "FLOAT_2D"),
    # (The render's resolve binds no surface image.)
    "region_distance_image": (15, "DEPTH_2D"),
}


def add_sampler(info, name: str) -> None:
    """Declare sampler ``name`` in create-info ``info`` at its slot (SAMPLERS)."""
    slot, kind = SAMPLERS[name]
    info.sampler(slot, kind, name)


def pulling_info(*, push_matrices: bool = True):
    """Create-info with what every SolidWire shader shares: the parameter
    block (generated from the schema), the position table (vertex pulling)
    and, unless the matrices come from an instance table, the object -> clip
    and view-z push constants."""
    info = gpu.types.GPUShaderCreateInfo()
    info.typedef_source(schema.param_block_glsl())
    info.uniform_buf(0, "SolidWireParams", "params")
    if push_matrices:
        info.push_constant("MAT4", "object_to_clip")
        info.push_constant("VEC4", "object_to_view_z")
    add_sampler(info, "vertex_positions")
    return info


def output_and_feature_defines(info, variant: ShaderVariant) -> None:
    """Fragment outputs and the feature defines the exact path and the
    benchmark's method variants share (same outputs, profile and colours)."""
    info.fragment_out(0, "VEC4", "frag_color")
    if variant.write_view_depth:
        info.fragment_out(1, "FLOAT", "frag_view_depth")
        info.define("WRITE_VIEW_DEPTH", "1")
    if variant.wire_layer:
        if not variant.write_view_depth or variant.hidden_pass or variant.display_transform:
            raise ValueError("only the render's surface pass puts its wire in a layer of its own")
        # The colour target after the view depth's and the render passes'
        # (targets.Targets._color_slots).
        info.fragment_out(4 if variant.write_aovs else 2, "VEC4", "frag_wire")
        info.define("WIRE_LAYER", "1")
    info.define("DIAGONALS", str(variant.diagonals))
    if variant.use_fill:
        info.define("USE_FILL", "1")
    if variant.use_fade:
        info.define("USE_FADE", "1")


class _Interface:
    """The varyings of the exact path, declared once: handed to a
    GPUStageInterfaceInfo for the two-stage program, or declared as plain
    globals for the resolve pass, which runs both stages' code in one
    fragment shader (resolve_frag.glsl)."""

    def __init__(self):
        self.entries = []  # (interpolation, type, name)

    def flat(self, kind: str, name: str) -> None:
        self.entries.append(("flat", kind, name))

    def smooth(self, kind: str, name: str) -> None:
        self.entries.append(("smooth", kind, name))

    def stage_interface(self):
        iface = gpu.types.GPUStageInterfaceInfo("solidwire_iface")
        for interpolation, kind, name in self.entries:
            getattr(iface, interpolation)(kind, name)
        return iface

    def globals_glsl(self) -> str:
        return "".join(f"{kind.lower()} {name};\n" for _interpolation, kind, name in self.entries)


def _create_info(variant: ShaderVariant):
    if variant.visibility:
        return _visibility_create_info(variant)
    if variant.region_lines_pass:
        return _region_lines_create_info(variant)
    iface = _Interface()
    for i in range(EDGE_COUNT):
        iface.flat("VEC3", f"edge_line{i}")
        iface.flat("VEC2", f"edge_span{i}")
    iface.flat("INT", "triangle_flags")
    iface.flat("INT", "ngon_corner_start")
    if variant.ngons:
        iface.flat("INT", "segment_count")
        for i in range(SEGMENT_SLOTS):
            iface.flat("VEC4", f"segment_line{i}")  # line xyz, span.x
            iface.flat("VEC4", f"segment_rest{i}")  # span.y, style, chain length, -
    if variant.walk_table and not variant.walk_picks_only:
        iface.flat("VEC3", "walk_near_groups")  # the groups a count below -1 walks (walk_table_frag.glsl)
    iface.smooth("FLOAT", "view_depth")
    if variant.hidden_pass and not variant.resolve:
        # The other triangle of a quad's (solidwire_frag.glsl, leave_out_the_visible_face).
        for name in ("partner0", "partner2", "partner3"):
            iface.flat("VEC4", name)
        iface.flat("VEC3", "partner_window_depth")
        if variant.ngon_siblings:
            iface.flat("INT", "hidden_triangle")  # (its n-gon's other triangles lie beside it)

    info = pulling_info(push_matrices=not variant.instanced)
    if variant.instanced:
        info.push_constant("INT", "instance_base")
        add_sampler(info, "instance_table")
        iface.flat("INT", "instance_slot")
    if variant.clip_planes:
        _add_clip_planes(info, iface)
    add_sampler(info, "triangle_vertices")
    add_sampler(info, "ngon_corners")
    _add_fill_and_colours(info, iface, variant)
    if variant.setup_table:
        if variant.ngons or variant.instanced:
            raise ValueError("the set-up table is for non-instanced tri/quad meshes")
        add_sampler(info, "setup_table")
        info.define("SETUP_TABLE", "1")
        info.define("SETUP_TEXELS", str(SETUP_TEXELS))
        info.define("SETUP_ROW_TRIANGLES", str(SETUP_ROW_TRIANGLES))
    if variant.resolve:
        # One rectangle per draw; the triangle comes from the visibility
        # record, its edge flags from a table (the batch's attribute is
        # per corner, out of a fragment stage's reach).
        info.vertex_in(0, "INT", "rect_corner")
        info.push_constant("INT", "draw_number")
        info.push_constant("VEC4", "resolve_rect")
        add_sampler(info, "visibility")
        if not variant.no_edge_setup:  # (NO_EDGE_SETUP reads no edge flags)
            add_sampler(info, "triangle_flag_table")
        info.define("RESOLVE_PASS", "1")
        if variant.record_depth:
            if not variant.depth_bias:
                raise ValueError("a resolve that writes the record's depth needs the overlay's depth bias")
            add_sampler(info, "record_depth")
            info.define("RECORD_DEPTH", "1")
            compat.depth_write(info, "ANY")
    elif variant.walk_table_pass:
        # One rectangle over the table's rows, a fragment per triangle
        # (walk_table_frag.glsl): its edge flags from a table, as the resolve's.
        info.vertex_in(0, "INT", "rect_corner")
        info.push_constant("VEC4", "resolve_rect")
        add_sampler(info, "triangle_flag_table")
    else:
        info.vertex_in(0, "INT", "edge_flags")
    if variant.region_lines:
        if variant.write_aovs and not variant.region_distance:
            # (Its pixels would not walk their regions for d.)
            raise ValueError("the render passes' outputs over region lines need the lines' distances too")
        add_sampler(info, "region_line_image")
        info.define("REGION_LINE_IMAGE", "1")
    if variant.region_distance:
        if not variant.write_aovs:
            raise ValueError("only the render passes' outputs over region lines read their distances")
        add_sampler(info, "region_distance_image")
        info.define("REGION_DISTANCE_IMAGE", "1")
    if variant.no_edge_setup:
        lines_elsewhere = variant.resolve and variant.region_lines
        if not (lines_elsewhere or variant.no_lines) or variant.ngons or variant.setup_table:
            raise ValueError(
                "only a resolve whose lines all come from the region-lines image, or a fill alone, skips the edge set-up"
            )
        info.define("NO_EDGE_SETUP", "1")
    output_and_feature_defines(info, variant)
    info.define("THICKNESS_MODE", str(variant.thickness_mode))
    if variant.in_front:
        info.define("ALL_IN_FRONT", "1")
    if variant.hidden_pass:
        info.define("HIDDEN_PASS", "1")
        _define_partner_depth_hair(info, variant.linear_depth)
        if not variant.linear_depth:
            # (leave_out_the_visible_face: only ever a nearer depth than its own.)
            compat.depth_write(info, "LESS")
    if variant.region_layers_peeled:
        if not variant.hidden_pass or variant.resolve:
            raise ValueError("only the direct hidden-line pass leaves the peeled region layers out")
        info.define("REGION_LAYERS_PEELED", "1")
    if variant.ngon_siblings:
        if not variant.hidden_pass or variant.resolve or variant.attribute_colors:
            raise ValueError("only the direct hidden-line pass tests an n-gon's other triangles")
        add_sampler(info, "triangle_faces")
        info.define("NGON_SIBLINGS", "1")
    if variant.linear_depth:
        if variant.resolve:
            raise ValueError("the resolve pass writes no depth (the visibility pass did)")
        info.define("LINEAR_DEPTH", "1")
        compat.depth_write(info, "ANY")
    if variant.walk_table or variant.walk_table_pass:
        if not variant.ngons or variant.instanced or variant.resolve or variant.setup_table:
            raise ValueError("only a direct, non-instanced draw that walks blocks has a walk table")
        info.define("WALK_TABLE_SHIFT", str(WALK_TABLE_SHIFT))
        info.define("WALK_PICK_BASE", str(WALK_PICK_BASE))
        info.define("WALK_GROUP", str(WALK_GROUP))
    if variant.walk_table:
        add_sampler(info, "walk_table")
        info.define("WALK_TABLE", "1")
    if variant.walk_picks_only:
        if not (variant.walk_table and variant.hidden_pass):
            raise ValueError("only a hidden-line draw that reads a walk table draws its picked triangles alone")
        info.define("WALK_PICKS_ONLY", "1")
    if variant.ngons:
        info.define("USE_NGONS", "1")
        info.define("SEGMENT_SLOTS", str(SEGMENT_SLOTS))
        info.define("PROVOKING_CORNERS", str(_provoking_corners()))
    info.define("STYLE_COUNT", str(schema.STYLE_COUNT if variant.edge_classes else 1))
    if variant.style_colors:
        info.define("STYLE_COLORS", "1")
    if variant.own_edges:
        if variant.no_edge_setup:
            raise ValueError("a variant that sets up no edge measures none of its own")
        info.define("OWN_EDGES", "1")
    if variant.density_fade:
        info.define("USE_DENSITY_FADE", "1")
    if variant.write_aovs:
        _add_render_pass_outputs(info, iface)
    if variant.depth_bias:
        info.define("DEPTH_BIAS", repr(float(variant.depth_bias)))
    if variant.display_transform:
        add_display_transform(info)
    if variant.write_aovs or variant.clip_planes:
        # One typedef source holds every block's struct (a later call
        # replaces the one pulling_info set).
        info.typedef_source(
            schema.param_block_glsl()
            + (OBJECT_BLOCK_GLSL if variant.write_aovs else "")
            + (CLIP_BLOCK_GLSL if variant.clip_planes else "")
        )
    if variant.walk_table_pass:
        _add_walk_table_sources(info, variant, iface)
        return info
    if not variant.resolve:
        info.vertex_out(iface.stage_interface())  # last: the steps above add varyings
    _add_sources(info, variant, iface)
    return info


# The walk-table pre-pass's stand-ins for the vertex stage's inputs (set by
# walk_table_frag.glsl before it runs the corner code).
_WALK_TABLE_GLOBALS = """#define WALK_TABLE_PASS 1
int edge_flags;
int sw_vertex_id;
#define SW_VERTEX_ID sw_vertex_id
int walk_picks[SEGMENT_SLOTS];
int walk_group_picks[SEGMENT_SLOTS];
"""


def _add_walk_table_sources(info, variant: ShaderVariant, iface: _Interface) -> None:
    """The walk-table pre-pass (shaders/walk_table_frag.glsl): the draw's
    own corner code with every varying a plain global, run in a fragment
    per triangle as its provoking corner, writing one texel of picks."""
    if variant.clip_planes:
        raise ValueError("the walk-table pre-pass is not clipped (its fragments are table texels)")
    info.push_constant("INT", "walk_triangle_count")
    add_sampler(info, "walk_group_boxes")
    common = read_source("common.glsl") + read_source("edge_geometry.glsl") + read_source("quad_partner.glsl")
    styles = read_source("line_style.glsl") + edge_styles_source()
    head = read_source("item_table.glsl") if variant.per_item else ""
    info.vertex_source(read_source("resolve_vert.glsl"))
    info.fragment_source(
        _WALK_TABLE_GLOBALS
        + iface.globals_glsl()
        + head
        + common
        + styles
        + read_source("clip_region.glsl")
        + read_source("solidwire_vert.glsl")
        + read_source("walk_table_frag.glsl")
    )


def _define_partner_depth_hair(info, linear_depth: bool) -> None:
    """How near a quad's other triangle (shaders/quad_partner.glsl) counts as
    at a depth: relative in view depth, absolute in window depth (a few
    steps of a 24-bit buffer); far above the rounding of two interpolations
    of one depth, far below any real gap."""
    info.define("PARTNER_DEPTH_HAIR", "1.0e-5" if linear_depth else "2.0e-7")


def _add_clip_planes(info, iface) -> None:
    """The clipping region's planes and distances (shaders/clip_region.glsl).
    A block of their own, not push constants: those stay within the 128
    bytes every backend guarantees (object_to_clip, object_to_view_z and
    item_slot use 84, the overlay's display_shaper 8 more). The caller
    puts CLIP_BLOCK_GLSL in the typedef source."""
    info.uniform_buf(2, "SolidWireClip", "clip_params")
    iface.smooth("VEC4", "clip_distance_a")
    iface.smooth("VEC2", "clip_distance_b")
    info.define("USE_CLIP_PLANES", "1")


def _visibility_create_info(variant: ShaderVariant):
    """The visibility pass (visibility_vert.glsl): positions pulled as the
    exact path pulls them (from the position table, by each vertex's
    "source_vertex"), depth as it writes it, and per pixel the triangle,
    instance and draw that won the depth test."""
    iface = gpu.types.GPUStageInterfaceInfo("solidwire_visibility_iface")
    iface.smooth("FLOAT", "view_depth")
    info = pulling_info(push_matrices=not variant.instanced)
    if variant.triangle_ids_by_vertex:
        iface.flat("FLOAT", "visible_triangle")
        info.vertex_in(1, "FLOAT", "triangle")
        info.define("SW_TRIANGLE_BY_VERTEX", "1")
    info.push_constant("INT", "draw_number")
    if variant.instanced:
        iface.flat("FLOAT", "visible_instance")
        info.push_constant("INT", "instance_base")
        add_sampler(info, "instance_table")
    info.vertex_in(0, "INT", "source_vertex")
    if variant.clip_planes:
        # (The viewport overlay's record inside a clipping region: what the
        # region cuts away is not the surface a pixel shows.)
        _add_clip_planes(info, iface)
        info.typedef_source(schema.param_block_glsl() + CLIP_BLOCK_GLSL)
    if variant.region_layers:
        if not variant.linear_depth:
            raise ValueError("the region layers are recorded in linear depth")
        add_sampler(info, "triangle_regions")
        info.define("REGION_LAYERS", "1")
        if variant.triangle_ids_by_vertex:
            for name in ("partner0", "partner2", "partner3"):
                iface.flat("VEC4", name)
        # (A layer is never the visible face itself: its quad's other
        # triangle, from the triangle table and the flags.)
        add_sampler(info, "triangle_vertices")
        add_sampler(info, "triangle_flag_table")
        _define_partner_depth_hair(info, linear_depth=True)
        if variant.ngon_siblings:
            add_sampler(info, "triangle_faces")
            info.define("NGON_SIBLINGS", "1")
    elif variant.ngon_siblings:
        raise ValueError("only the region layers' record tests an n-gon's other triangles")
    if variant.peel_layer:
        if not variant.region_layers:
            raise ValueError("only the region layers are peeled")
        add_sampler(info, "peel_depth")
        info.define("PEEL_LAYER", "1")
    info.vertex_out(iface)
    info.fragment_out(0, "VEC4", "frag_visible")
    if variant.linear_depth:
        # (Without it the rasteriser's own window depth: the viewport
        # overlay's record, whose resolve hands it to Blender's depth test.)
        info.define("LINEAR_DEPTH", "1")
        compat.depth_write(info, "ANY")
    # (fetch_texel, common.glsl: the exact path reads positions so.)
    prologue = read_source("common.glsl") + read_source("edge_geometry.glsl")
    if variant.region_layers:
        prologue += read_source("quad_partner.glsl")
    if variant.instanced:
        info.define("SW_INSTANCED", "1")
        prologue = (
            f"#define SW_INSTANCE_SLOT (instance_base + {INSTANCE_TEXELS} * gl_InstanceID)\n"
            + read_source("instancing.glsl")
            + prologue
        )
    clip = read_source("clip_region.glsl")
    info.vertex_source(prologue + clip + read_source("visibility_vert.glsl"))
    fragment_head = read_source("common.glsl")
    if variant.region_layers:
        fragment_head += read_source("edge_geometry.glsl") + read_source("quad_partner.glsl")
        if variant.instanced:
            fragment_head = (
                f"#define SW_INSTANCE_SLOT (instance_base + {INSTANCE_TEXELS} * int(visible_instance))\n"
                + read_source("instancing.glsl")
                + fragment_head
            )
    info.fragment_source(fragment_head + _CLIP_DISTANCES_IN + clip + read_source("visibility_frag.glsl"))
    return info


def _region_lines_create_info(variant: ShaderVariant):
    """The region-lines pass (region_lines_vert/frag.glsl): a quad per
    run of the mesh's region-lines table, the exact distance to each of its
    segments per fragment, the strongest line per pixel kept through the
    depth test."""
    iface = gpu.types.GPUStageInterfaceInfo("solidwire_region_lines_iface")
    # Each segment of a run: (line, span start) and its span end, four ends
    # to a varying (at most 8 segments: 40 components). Only as many as the
    # mesh's runs hold: a rasteriser pays for the varyings at every pixel.
    for j in range(variant.run_segments):
        iface.flat("VEC4", f"run_line{j}")
    for j in range((variant.run_segments + 3) // 4):
        iface.flat("VEC4", f"run_ends{j}")
    iface.flat("INT", "run_length")
    iface.flat("INT", "line_style")
    iface.flat("VEC2", "line_regions")
    iface.flat("FLOAT", "line_chain")
    info = pulling_info(push_matrices=not variant.instanced)
    add_sampler(info, "triangle_vertices")  # bound with every mesh (draw._bind_mesh), unread
    add_sampler(info, "region_lines")
    add_sampler(info, "triangle_regions")
    add_sampler(info, "visibility")
    if variant.thickness_mode == THICKNESS_WORLD:  # (quads sized by their regions' nearest point)
        add_sampler(info, "run_bounds")
    info.push_constant("INT", "draw_number")
    info.push_constant("INT", "line_first")
    info.push_constant("INT", "line_count")
    info.push_constant("VEC2", "clip_w_of_depth")
    prologue = ""
    if variant.instanced:
        iface.flat("FLOAT", "line_instance")
        info.push_constant("INT", "instance_base")
        add_sampler(info, "instance_table")
        info.define("SW_INSTANCED", "1")
        prologue = f"#define SW_INSTANCE_SLOT (instance_base + {INSTANCE_TEXELS} * gl_InstanceID)\n" + read_source(
            "instancing.glsl"
        )
    display = ""
    if variant.hidden_pass:
        # A hidden layer's lines (HIDDEN_PASS): the nearest line's distance
        # as depth and the layer's colour, in the wire's style alone.
        if variant.edge_classes or variant.density_fade or variant.line_distance:
            raise ValueError("a hidden layer's lines have the wire's style alone")
        info.define("HIDDEN_PASS", "1")
        info.fragment_out(0, "VEC4", "frag_color")
        if variant.use_fade:
            info.define("USE_FADE", "1")
        if variant.item_colors:
            if not variant.instanced:
                info.push_constant("INT", "item_slot")
                add_sampler(info, "item_table")
                prologue = read_source("item_table.glsl")
            add_sampler(info, "item_colors")
            info.define("ITEM_COLORS", "1")
            iface.flat("VEC3", "item_wire")
        if variant.display_transform:
            add_display_transform(info)
            display = read_source("display_transform.glsl")
    info.vertex_in(0, "INT", "quad_corner")
    info.vertex_out(iface)
    # Otherwise no colour output: the line is its depth (edge_styles.glsl line_code).
    compat.depth_write(info, "ANY")
    info.define("THICKNESS_MODE", str(variant.thickness_mode))
    info.define("RUN_SEGMENTS", str(variant.run_segments))
    info.define("STYLE_COUNT", str(schema.STYLE_COUNT if variant.edge_classes else 1))
    if variant.density_fade:
        info.define("USE_DENSITY_FADE", "1")
    if variant.in_front:
        info.define("ALL_IN_FRONT", "1")
    if variant.line_distance:
        info.define("LINE_DISTANCE", "1")
    body = (
        read_source("common.glsl")
        + read_source("edge_geometry.glsl")
        + read_source("line_style.glsl")
        + edge_styles_source()
    )
    info.vertex_source(prologue + body + read_source("region_lines_vert.glsl"))
    fragment_prologue = prologue.replace("gl_InstanceID", "0")  # the fragment stage transforms nothing
    info.fragment_source(fragment_prologue + body + display + read_source("region_lines_frag.glsl"))
    return info


def software_rasteriser() -> bool:
    """Whether the GPU module draws through a software rasteriser (Mesa's
    llvmpipe, the machines without a GPU), which runs the vertex stage and
    sets up every triangle on the CPU, even those the scissor then drops."""
    try:
        return gpu.platform.device_type_get() == "SOFTWARE"
    except (AttributeError, RuntimeError):
        return False


def triangle_ids_by_vertex() -> bool:
    """Whether the visibility pass numbers triangles by their provoking
    vertex rather than with gl_PrimitiveID: on a software rasteriser under
    OpenGL. There the primitive ID costs llvmpipe its primitive-assembly
    bookkeeping (~35 ms of a 1M-triangle 1280 x 720 frame of ~210 ms on 2
    cores), while a GPU hands it out for free and the copied corners would
    only cost memory. OpenGL's provoking vertex is the last corner, which
    Blender keeps (see _provoking_corners). options.DrawOptions can
    choose either (tests compare the two)."""
    try:
        return gpu.platform.backend_type_get() == "OPENGL" and software_rasteriser()
    except (AttributeError, RuntimeError):
        return False


def _provoking_corners() -> int:
    """1 when the provoking vertex of flat outputs is known to be the last
    (OpenGL, whose default Blender keeps), else 2 (first or last)."""
    try:
        return 1 if gpu.platform.backend_type_get() == "OPENGL" else 2
    except (AttributeError, RuntimeError):
        return 2


def _add_fill_and_colours(info, iface, variant: ShaderVariant) -> None:
    """Per-item tables, corner normals, shading and colour sources (image
    model §5.8): only what the variant uses is declared."""
    if variant.per_item:
        if not variant.instanced:
            # normal_to_view / item_info come from item_table (item_table.glsl).
            info.push_constant("INT", "item_slot")
            add_sampler(info, "item_table")
        info.define("PER_ITEM", "1")
    if variant.uses_corners:
        add_sampler(info, "corner_table")
        # Where the mesh's normals live (extract.NORMALS_BY_*): a row of the
        # corner table per vertex, triangle or triangle corner.
        info.push_constant("INT", "normal_domain")
        info.define("USE_CORNERS", "1")
        iface.smooth("VEC3", "shading_normal")
    info.define("SHADING", str(variant.shading))
    if variant.shading == SHADING_MATCAP:
        add_sampler(info, "matcap_image")
    if variant.item_colors:
        add_sampler(info, "item_colors")
        info.define("ITEM_COLORS", "1")
        iface.flat("VEC3", "item_wire")
        iface.flat("VEC3", "item_fill")
    if variant.material_colors:
        info.define("MATERIAL_COLORS", "1")
    if variant.attribute_colors:
        add_sampler(info, "attribute_colors")
        info.push_constant("INT", "attribute_domain")
        info.define("ATTRIBUTE_COLORS", "1")
        iface.smooth("VEC3", "attribute_fill")


def add_display_transform(info) -> None:
    """The overlay's colour management (core/display_transform.py): the LUT,
    the shaper constants and the merge power."""
    add_sampler(info, "display_lut")
    info.push_constant("VEC2", "display_shaper")
    info.define("DISPLAY_TRANSFORM", "1")
    info.define("OVERLAY_MERGE_GAMMA", repr(float(display_transform.OVERLAY_MERGE_GAMMA)))


def _display_source(variant: ShaderVariant) -> str:
    return read_source("display_transform.glsl") if variant.display_transform else ""


def _add_render_pass_outputs(info, iface) -> None:
    """The render passes' extra outputs and inputs (image model §6)."""
    # Per-object values in a block of their own (push constants are full);
    # the instanced variant does not have them (draw.py draws object by
    # object when passes are written).
    info.uniform_buf(1, "SolidWireObject", "object_params")
    add_sampler(info, "triangle_material")
    iface.flat("FLOAT", "material_pass_index")
    info.fragment_out(2, "VEC4", "frag_aov")
    info.fragment_out(3, "VEC4", "frag_normal")
    info.define("WRITE_AOVS", "1")
    iface.flat("VEC3", "face_normal")


def _add_sources(info, variant: ShaderVariant, iface: _Interface) -> None:
    """The GLSL files of the exact path, in the order each stage needs them.
    The SW_ names stand for the builtins a stage reads (resolve_frag.glsl
    supplies its own)."""
    common = read_source("common.glsl") + read_source("edge_geometry.glsl") + read_source("quad_partner.glsl")
    styles = read_source("line_style.glsl") + edge_styles_source()
    fill = read_source("fill_shading.glsl")
    if variant.instanced:
        instancing = read_source("instancing.glsl")
        vertex_head = _INSTANCE_SLOT_VERT + instancing
        fragment_head = _INSTANCE_SLOT_FRAG + instancing
    else:
        vertex_head = fragment_head = read_source("item_table.glsl") if variant.per_item else ""
    clip = read_source("clip_region.glsl")
    fragment_tail = fill + _display_source(variant) + read_source("solidwire_frag.glsl")
    if variant.resolve:
        instance_slot = (
            f"#define SW_INSTANCE_SLOT (instance_slot = instance_base + {INSTANCE_TEXELS} * sw_instance_id)\n"
            if variant.instanced
            else ""
        )
        info.vertex_source(read_source("resolve_vert.glsl"))
        info.fragment_source(
            _RESOLVE_GLOBALS
            + iface.globals_glsl()
            + instance_slot
            + (instancing if variant.instanced else vertex_head)
            + common
            + styles
            + clip
            + read_source("solidwire_vert.glsl")
            + fragment_tail
            + read_source("resolve_frag.glsl")
        )
        return
    info.vertex_source(
        "#define SW_VERTEX_ID gl_VertexID\n" + vertex_head + common + styles + clip + read_source("solidwire_vert.glsl")
    )
    info.fragment_source(
        "#define SW_FRONT_FACING gl_FrontFacing\n#define SW_INV_CLIP_W gl_FragCoord.w\n"
        + fragment_head
        + common
        + styles
        + _CLIP_DISTANCES_IN
        + clip
        + fragment_tail
    )


# What a stage that reads the clipping region's distances as inputs says
# before shaders/clip_region.glsl.
_CLIP_DISTANCES_IN = "#define SW_CLIP_DISTANCES_IN\n"


# The resolve pass's stand-ins for the vertex stage's inputs and the
# fragment stage's builtins (set by resolve_frag.glsl before each call).
_RESOLVE_GLOBALS = """int edge_flags;
int sw_vertex_id;
int sw_instance_id;
bool sw_front_facing;
float sw_inv_clip_w;
vec4 sw_corner_clip0, sw_corner_clip1, sw_corner_clip2;
vec4 sw_triangle_ids;
#define SW_VERTEX_ID sw_vertex_id
#define SW_FRONT_FACING sw_front_facing
#define SW_INV_CLIP_W sw_inv_clip_w
"""


# Per-object values of the render passes (std140): the columns of the normal
# matrix, the object's pass index in the first column's w.
OBJECT_BLOCK_GLSL = """struct SolidWireObject {
  vec4 normal_matrix0;
  vec4 normal_matrix1;
  vec4 normal_matrix2;
};
"""
OBJECT_BLOCK_FLOATS = 12

# The viewport clipping region's clip-space planes (std140: vec4 stride 16).
CLIP_BLOCK_GLSL = f"""struct SolidWireClip {{
  vec4 planes[{CLIP_PLANES}];
}};
"""

# Instanced variant of the exact path: shaders/instancing.glsl is prepended
# to the unchanged stage sources (it turns the two push constants into reads
# from `instance_table`); each stage says where its instance's texels start.
INSTANCE_TEXELS = 9
ITEM_TEXELS = 4  # per object of the non-instanced path (item_table.glsl)
_INSTANCE_SLOT_VERT = f"#define SW_INSTANCE_SLOT (instance_slot = instance_base + {INSTANCE_TEXELS} * gl_InstanceID)\n"
_INSTANCE_SLOT_FRAG = "#define SW_INSTANCE_SLOT instance_slot\n"


class DeferredUnavailable(RuntimeError):
    """A stage of the deferred surface does not compile here."""


def get(variant: ShaderVariant):
    """The compiled shader for ``variant`` (compiled once, then cached)."""
    key = (_context, variant)
    shader = _cache.get(key)
    if shader is None:
        try:
            shader = _keep(_cache, key, gpu.shader.create_from_info(_create_info(variant)))
        except Exception as exc:
            if variant.visibility or variant.resolve or variant.region_lines_pass:
                raise DeferredUnavailable(str(exc)) from exc
            raise
    return shader


_deferred_support = [True]


def deferred_available() -> bool:
    """Whether the deferred surface is still in use in this process (see
    disable_deferred)."""
    return _deferred_support[0]


def disable_deferred() -> None:
    """Never use the deferred surface again in this process (a stage failed
    to compile): the direct surface pass draws the same image, except that
    without a visibility record the lines of a region are walked, face by
    face past edge_select.WALK_LIMIT (docs/image_model.md §2.6)."""
    _deferred_support[0] = False


_setup_support: list = []


def setup_dispatch_allowed() -> bool:
    """Whether the set-up pre-pass may dispatch in the GL context of the
    moment: wherever compute shaders run (setup_available), except a
    software rasteriser's render engine context. Its dispatch there has
    crashed llvmpipe (docs/dev/robustness.md), and a render draws directly
    only meshes sparse on screen (draw.DEFERRED_MIN_DENSITY), where the
    pre-pass saved nothing measurable (F12 of 63k triangles filling a
    3840 x 2160 frame: 249.5 ms with it, 250.6 without, medians of four
    alternating rounds on llvmpipe)."""
    return setup_available() and not (in_render_engine_context() and software_rasteriser())


def setup_available() -> bool:
    """Whether this Blender and GPU backend run compute shaders (the set-up
    pre-pass); asked once."""
    if not _setup_support:
        ok = hasattr(gpu, "compute") and hasattr(gpu.types.GPUShaderCreateInfo, "compute_source")
        query = getattr(gpu.capabilities, "compute_shader_support_get", None)
        if ok and query is not None:
            # Deprecated in Blender 5 (every backend has compute there).
            try:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore", DeprecationWarning)
                    ok = bool(query())
            except (RuntimeError, SystemError):  # no GPU context yet: ask again later
                return False
        _setup_support.append(ok)
    return _setup_support[0]


def disable_setup() -> None:
    """Never use the set-up pre-pass again in this process (it failed)."""
    _setup_support[:] = [False]


def _pulling_info_in_front(in_front: bool):
    """pulling_info() for a pass over a mesh's edges: without the clipping
    code (ALL_IN_FRONT) where the draw lies wholly in front of the near
    plane."""
    info = pulling_info()
    if in_front:
        info.define("ALL_IN_FRONT", "1")
    return info


def get_setup(in_front: bool = False):
    """The set-up pre-pass (shaders/setup_comp.glsl): one invocation per
    triangle writes its SETUP_TEXELS texels of edge set-up. ``in_front``:
    for a draw wholly in front of the near plane, compiled without the
    clipping code (ALL_IN_FRONT, as ShaderVariant.in_front)."""
    key = (_context, "setup", bool(in_front))
    shader = _cache.get(key)
    if shader is None:
        info = _pulling_info_in_front(in_front)
        info.push_constant("INT", "triangle_count")
        add_sampler(info, "triangle_vertices")
        info.image(0, "RGBA32F", "FLOAT_2D", "setup_table", qualifiers={"WRITE"})
        info.local_group_size(SETUP_GROUP_SIZE)
        info.define("SETUP_TEXELS", str(SETUP_TEXELS))
        info.define("SETUP_ROW_TRIANGLES", str(SETUP_ROW_TRIANGLES))
        info.compute_source(
            read_source("common.glsl") + read_source("edge_geometry.glsl") + read_source("setup_comp.glsl")
        )
        shader = _keep(_cache, key, gpu.shader.create_from_info(info))
    return shader


def get_walk_groups(in_front: bool = False):
    """The walk-table groups (shaders/walk_groups_vert.glsl): one point per
    group of WALK_GROUP segments of a region block writes the window box
    of their ends. ``in_front``: compiled without the near-plane test
    (ALL_IN_FRONT, as ShaderVariant.in_front)."""
    key = (_context, "walk groups", bool(in_front))
    shader = _cache.get(key)
    if shader is None:
        info = _pulling_info_in_front(in_front)
        add_sampler(info, "ngon_corners")
        info.vertex_in(0, "INT", "group_texel")
        info.vertex_in(1, "INT", "group_size")
        info.push_constant("IVEC2", "group_table_size")
        iface = gpu.types.GPUStageInterfaceInfo("solidwire_walk_groups_iface")
        iface.flat("VEC4", "group_box")
        info.vertex_out(iface)
        info.fragment_out(0, "VEC4", "frag_color")
        info.define("WALK_GROUP", str(WALK_GROUP))
        info.vertex_source(
            read_source("common.glsl") + read_source("edge_geometry.glsl") + read_source("walk_groups_vert.glsl")
        )
        info.fragment_source(read_source("walk_groups_frag.glsl"))
        shader = _keep(_cache, key, gpu.shader.create_from_info(info))
    return shader


def get_overlay_composite(depth_bias: float, linear_record: bool = False):
    """The viewport overlay's composite (shaders/overlay_composite_frag.glsl
    over resolve_vert.glsl's rectangle): the kept surface image into
    Blender's buffer at the record's depth less ``depth_bias`` and
    Blender's allowance (push constants ``depth_rows``, the projection's
    P22, P23, P32, P33, and ``blender_depth_allowance``: window_depth_shift
    in common.glsl); ``linear_record``: the record holds view depth / clip
    end (a hidden layer's), turned into window depth by the projection's
    depth rows (push constant ``window_depth_rows``: those rows with the
    clip end folded into the first and third)."""
    key = (_context, "overlay composite", float(depth_bias), linear_record)
    shader = _cache.get(key)
    if shader is None:
        info = gpu.types.GPUShaderCreateInfo()
        info.vertex_in(0, "INT", "rect_corner")
        info.push_constant("VEC4", "resolve_rect")
        add_sampler(info, "record_depth")
        add_sampler(info, "surface_image")
        info.push_constant("VEC4", "depth_rows")
        info.push_constant("VEC4", "blender_depth_allowance")
        info.define("DEPTH_BIAS", repr(float(depth_bias)))
        if linear_record:
            info.push_constant("VEC4", "window_depth_rows")
            info.define("LINEAR_RECORD", "1")
        info.fragment_out(0, "VEC4", "frag_color")
        compat.depth_write(info, "ANY")
        info.vertex_source(read_source("resolve_vert.glsl"))
        info.fragment_source(read_source("common.glsl") + read_source("overlay_composite_frag.glsl"))
        try:
            shader = _keep(_cache, key, gpu.shader.create_from_info(info))
        except Exception as exc:
            raise DeferredUnavailable(str(exc)) from exc
    return shader


def release_at_exit() -> None:
    """Free every compiled program (interpreter exit only; see _cache)."""
    _cache.clear()


# Full-width silhouettes (image model §5.5): the fin pass of silhouettes.py. Shares
# the parameter block, vertex pulling and edge geometry with the exact path.


def get_silhouette(variant: ShaderVariant, overlay_bias: float = 0.0):
    """The fin shader; ``overlay_bias`` > 0 gives the viewport-overlay form
    (colour output, fixed-function occlusion; see silhouette_frag.glsl),
    with the variant's display transform."""
    key = ShaderVariant(
        use_fade=variant.use_fade,
        thickness_mode=variant.thickness_mode,
        depth_bias=overlay_bias,
        linear_depth=variant.linear_depth and not overlay_bias,
        display_transform=variant.display_transform and bool(overlay_bias),
    )
    shader = _cache.get((_context, "silhouette", key))
    if shader is None:
        iface = gpu.types.GPUStageInterfaceInfo("solidwire_fin_iface")
        iface.flat("VEC4", "fin_a")
        iface.flat("VEC4", "fin_b")
        iface.flat("VEC3", "fin_line")
        iface.flat("VEC2", "fin_span")
        iface.flat("FLOAT", "fin_inner_sign")
        iface.flat("VEC2", "fin_view_depth")
        info = pulling_info()
        info.push_constant("INT", "edge_count")
        add_sampler(info, "silhouette_edges")
        add_sampler(info, "scene_depth")
        info.vertex_in(0, "INT", "quad_corner")
        info.vertex_out(iface)
        if key.depth_bias:
            info.fragment_out(0, "VEC4", "frag_color")
            info.define("OVERLAY_FINS", repr(float(key.depth_bias)))
        else:
            info.fragment_out(0, "FLOAT", "frag_intensity")
        compat.depth_write(info, "ANY")
        info.define("THICKNESS_MODE", str(key.thickness_mode))
        if key.linear_depth:
            info.define("LINEAR_DEPTH", "1")
        if key.use_fade:
            info.define("USE_FADE", "1")
        if key.display_transform:
            add_display_transform(info)
        common = read_source("common.glsl") + read_source("edge_geometry.glsl")
        info.vertex_source(common + read_source("silhouette_vert.glsl"))
        info.fragment_source(
            common + read_source("line_style.glsl") + _display_source(key) + read_source("silhouette_frag.glsl")
        )
        shader = _keep(_cache, (_context, "silhouette", key), gpu.shader.create_from_info(info))
    return shader


# Hair and point clouds (docs/user/hair-and-points.md): the quad pass of
# core/strands.py. Shares the parameter block, vertex pulling and the line
# profile with the exact path.


def get_strand(points: bool, variant: ShaderVariant, overlay_bias: float = 0.0):
    """The strand shader (``points``: the disc form). ``overlay_bias`` > 0
    gives the viewport-overlay form (colour "over" the viewport, its depth
    buffer occludes; see strand_frag.glsl), with the variant's display
    transform; otherwise the render form (colour and (depth, weight)
    outputs, occluded by the ``scene_depth`` texture)."""
    key = (
        bool(points),
        ShaderVariant(
            use_fade=variant.use_fade,
            use_fill=variant.use_fill and bool(points),
            thickness_mode=variant.thickness_mode,
            depth_bias=overlay_bias,
            display_transform=variant.display_transform and bool(overlay_bias),
            clip_planes=variant.clip_planes and bool(overlay_bias),
            shading=variant.shading if points and variant.use_fill else SHADING_FLAT,
        ),
    )
    shader = _cache.get((_context, "strand", key))
    if shader is None:
        flags = key[1]
        iface = gpu.types.GPUStageInterfaceInfo("solidwire_strand_iface")
        if points:
            iface.flat("VEC4", "disc")  # window centre, radius px, view depth of the centre
            iface.flat("VEC2", "disc_extra")  # radius in scene units, 1 / clip w
            if flags.clip_planes:
                iface.flat("VEC4", "disc_clip")  # the centre in clip space
        else:
            iface.flat("VEC4", "seg_a")
            iface.flat("VEC4", "seg_b")
            iface.flat("VEC3", "seg_line")  # edge_setup's window line and span, from the viewport centre
            iface.flat("VEC2", "seg_span")
            iface.flat("VEC2", "seg_depth")
            iface.flat("VEC2", "seg_radius")
            if overlay_bias:
                iface.flat("VEC4", "seg_split")  # bisector normals at the two joints (overlay)
                iface.flat("VEC4", "seg_points")  # its two points and their neighbours (overlay)
                # The neighbour segments from each joint (strand_vert.glsl, neighbour_from_joint).
                iface.flat("VEC4", "neighbour_a_window")
                iface.flat("VEC4", "neighbour_a_depth")
                iface.flat("VEC4", "neighbour_b_window")
                iface.flat("VEC4", "neighbour_b_depth")
                iface.flat("VEC4", "neighbour_radii")
        info = pulling_info()
        # Push constants: 104 of the 128 bytes every backend guarantees with
        # the overlay's display_shaper (draw_range draws exactly the
        # primitives there are, so no count is needed).
        info.push_constant("VEC4", "strand_view")  # px per unit at w = 1, radius scale
        add_sampler(info, "strand_segments")
        info.vertex_in(0, "INT", "quad_corner")
        info.vertex_out(iface)
        info.fragment_out(0, "VEC4", "frag_color")
        if flags.depth_bias:
            info.define("STRAND_OVERLAY", repr(float(flags.depth_bias)))
        else:
            add_sampler(info, "scene_depth")
            info.fragment_out(1, "VEC4", "frag_info")
        compat.depth_write(info, "ANY")
        info.define("THICKNESS_MODE", str(flags.thickness_mode))
        if points:
            info.define("STRAND_POINTS", "1")
        if flags.use_fade:
            info.define("USE_FADE", "1")
        if flags.use_fill:
            info.define("USE_FILL", "1")
        shading_source = ""
        if flags.shading != SHADING_FLAT:
            # A disc's inside is shaded as the sphere it stands for, by the
            # mesh fill's own code (fill_shading.glsl), whose inputs are
            # declared here as plain globals the fragment stage sets.
            info.define("SHADING", str(flags.shading))
            if flags.shading == SHADING_MATCAP:
                add_sampler(info, "matcap_image")
            shading_source = "#define SW_FRONT_FACING true\nvec3 shading_normal;\nvec4 item_info;\n" + read_source(
                "fill_shading.glsl"
            )
        if flags.display_transform:
            add_display_transform(info)
        if flags.clip_planes:
            # (A block, as in the exact path: the push constants are full.)
            info.uniform_buf(2, "SolidWireClip", "clip_params")
            info.typedef_source(schema.param_block_glsl() + CLIP_BLOCK_GLSL)
            info.define("USE_CLIP_PLANES", "1")
        common = (
            read_source("common.glsl")
            + read_source("edge_geometry.glsl")
            + read_source("line_style.glsl")
            + read_source("strand_common.glsl")
        )
        info.vertex_source(common + read_source("strand_vert.glsl"))
        info.fragment_source(common + _display_source(flags) + shading_source + read_source("strand_frag.glsl"))
        shader = _keep(_cache, (_context, "strand", key), gpu.shader.create_from_info(info))
    return shader
