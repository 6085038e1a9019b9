"""GPU cache: one upload per mesh, shared by every object and instance using it.

A :class:`GPUMesh` holds what the vertex stage pulls from (a position table
and a triangle table, both RGBA32F textures) and a triangle-list batch whose
only attribute is the per-corner edge-flag word. Entries are keyed by the
caller (see blender/gather.py: the evaluated mesh's identity plus a change counter),
never hold Blender data, and are dropped when the key is invalidated or no
longer seen, which frees their GPU memory.
"""

from __future__ import annotations

import itertools
import time

import gpu
import numpy as np

from .edge_select import (
    OWN_EDGES_MEASURED,
    TEXELS_PER_REGION_LINE,
    TEXELS_PER_SEGMENT,
    region_listing,
    run_bounds,
)
from .extract import (
    HAS_QUAD_CORNER,
    IN_REGION,
    IS_NGON,
    NGON_SHIFT,
    NORMALS_BY_TRIANGLE,
    NORMALS_BY_VERTEX,
    REGION_LINES,
    MeshArrays,
    boxes_of_triangle_runs,
    ngon_triangles_overlap,
    ngons_flat,
)
from .shaders import WALK_GROUP, WALK_TABLE_SHIFT

TABLE_WIDTH = 4096  # texels per row; rows stay below the 16384 texture limit up to 67M entries

# Consecutive triangles per box of GPUMesh.triangle_block_corners: what a
# partial redraw's record leaves out at a time (draw.triangle_ranges_reaching).
# A subdivision lists each cage corner's children together (4**(L-1) quads,
# 512 triangles at level 5), so blocks this size stay small on screen; a
# level-5 Suzanne has ~2000 of them, whose corners a redraw projects in
# well under a millisecond.
RECORD_BLOCK_TRIANGLES = 512


def table_shape(count: int) -> tuple[int, int]:
    """(width, height) of a table of ``count`` texels: TABLE_WIDTH texels a
    row, or one row of ``count`` for a shorter table. Every shader finds
    texel i at (i % TABLE_WIDTH, i // TABLE_WIDTH) with a mask and a shift
    (fetch_texel in shaders/common.glsl, TABLE_ROW_SHIFT): no integer
    division, which a CPU rasteriser runs lane by lane."""
    count = max(count, 1)
    width = min(count, TABLE_WIDTH)
    return width, -(-count // width)


def table_texture(rows4: np.ndarray):
    """(N, 4) float32 (or integers float32 holds exactly) -> RGBA32F
    texture laid out by table_shape."""
    return _table(rows4, 4, "RGBA32F")


def value_table_texture(values: np.ndarray):
    """(N,) float32 -> R32F texture laid out by table_shape: a value per
    texel, a quarter of an RGBA table's memory (a shader reads it as
    .x of the texel)."""
    return _table(values, 1, "R32F")


def _table(rows: np.ndarray, channels: int, texture_format: str):
    width, height = table_shape(len(rows))
    buf = gpu.types.Buffer("FLOAT", width * height * channels)
    # Fill through numpy's view of the buffer: one memcpy instead of a
    # per-element Python sequence copy.
    view = np.asarray(buf)
    view[: rows.size] = rows.reshape(-1)
    view[rows.size :] = 0.0
    return gpu.types.GPUTexture((width, height), format=texture_format, data=buf)


def table_channel(texture):
    """The first channel of every texel of a float ``texture`` (rows from
    the first), as a flat FLOAT ``gpu.types.Buffer``: a quarter of what
    reading an RGBA texture whole moves."""
    buf = gpu.types.Buffer("FLOAT", texture.width * texture.height)
    framebuffer = gpu.types.GPUFrameBuffer(color_slots=(texture,))
    with framebuffer.bind():
        framebuffer.read_color(0, 0, texture.width, texture.height, 1, 0, "FLOAT", data=buf)
    return buf


def texture_bytes(texture) -> int:
    """The GPU memory of a table made here (float32 channels)."""
    channels = {"RGBA32F": 4, "RG32F": 2, "R32F": 1}[texture.format]
    return texture.width * texture.height * 4 * channels


def _provoking_triangle_numbers(vertex_count: int, triangles: np.ndarray):
    """(copied vertices, triangle number + 1 per vertex, index triangles)
    of a visibility batch whose triangles are numbered by their last corner
    (see GPUMesh.visibility_batch). One triangle ending at a vertex keeps the
    vertex (whichever wrote it last below: any one will do); every other
    gets a copy of it, appended after the original vertices in the order of
    ``copied vertices``. Corners keep their order, so each triangle is
    rasterised exactly as before. Depends on the triangles alone, so a mesh
    that only moves keeps it. ``triangles`` ((T, 3) int32, the caller's own
    copy) becomes the index triangles: the copies are written into it."""
    count = len(triangles)
    last = np.ascontiguousarray(triangles[:, 2])
    rows = np.arange(count, dtype=np.int32)
    owner = np.full(vertex_count, -1, dtype=np.int32)
    owner[last] = rows  # repeated vertices: one of their triangles wins
    copied = np.flatnonzero(owner[last] != rows)
    copied_vertices = last[copied]
    numbers = np.empty(vertex_count + len(copied), dtype=np.float32)
    # A vertex keeps the number of the triangle that won it, 0 (none) where
    # it ends no triangle: owner + 1 either way.
    np.add(owner, 1, out=numbers[:vertex_count], casting="unsafe")
    numbers[vertex_count:] = copied + 1
    triangles[copied, 2] = vertex_count + np.arange(len(copied), dtype=np.int32)
    return copied_vertices, numbers, triangles


_serials = itertools.count(1)


class GPUMesh:
    """GPU resources of one extracted mesh."""

    def __init__(self, arrays: MeshArrays):
        # Which mesh and which of its shapes this is (``version`` counts
        # position uploads): what a cached image drawn from it depends on.
        self.serial = next(_serials)
        self.version = 0
        self._corner_rows_uploaded = None  # the corner rows of the last move (last_move)
        self.triangle_count = arrays.triangle_count
        self.centre = arrays.centre
        self.bounds_min = arrays.bounds_min - arrays.centre
        self.bounds_max = arrays.bounds_max - arrays.centre

        positions = np.zeros((arrays.vertex_count, 4), dtype=np.float32)
        positions[:, :3] = arrays.positions
        self.positions = table_texture(positions)
        # (Integer rows are converted as they are copied into the upload.)
        self.triangles = table_texture(arrays.triangles)
        # One outline table: the n-gon blocks, then the segment blocks of the
        # triangles that walk their region (core/edge_select.py).
        region = arrays.region_table if arrays.region_table is not None else np.zeros((0, 4), np.float32)
        outline_rows = len(arrays.ngon_corners) + len(region)
        ngon = np.zeros((max(outline_rows, 1), 4), dtype=np.float32)
        ngon[: len(arrays.ngon_corners), 0] = arrays.ngon_corners
        if arrays.ngon_hidden is not None:
            ngon[: len(arrays.ngon_hidden), 1] = arrays.ngon_hidden  # outline edge not drawn
        ngon[len(arrays.ngon_corners) : outline_rows] = region
        self.ngon_corners = table_texture(ngon)
        self.has_ngons = outline_rows > 0
        # Every triangle that walks a block lies in a region and no triangle
        # walks an n-gon's own outline (edge selection lists every n-gon as a
        # region: edge_select.select_edges): where the region-lines pass
        # measures the lines, no triangle walks anything but a listed
        # n-gon's diagonals, which only a shown diagonal needs, and not even
        # that where each triangle's own give them (draw._Part.variant).
        flags = arrays.edge_flags
        walks_ngon_outline = arrays.has_ngons and bool(np.any(flags & IS_NGON))
        region_pass_only = arrays.region_lines is not None and not walks_ngon_outline
        self.blocks_hold_ngon_diagonals = arrays.has_ngons
        self.ngons_alone = arrays.ngons_alone
        self._ngon_outlines = arrays.ngon_outlines
        self._ngons_flat = None  # (version, ngons_flat()), found on first use after each move
        # Every triangle flagged REGION_LINES (a cage look): one reduction
        # answers both questions below.
        every_triangle_region_lines = region_pass_only and bool(np.bitwise_and.reduce(flags) & REGION_LINES)
        self.blocks_only_for_region_lines = region_pass_only and (
            every_triangle_region_lines or not np.any((flags & IN_REGION != 0) & (flags & REGION_LINES == 0))
        )
        # Shading normals and material indices, a texel per vertex, triangle
        # or triangle corner (normal_domain); only for a shaded or
        # per-material fill.
        self.corners = None if arrays.corners is None else table_texture(arrays.corners)
        # The ATTRIBUTE fill source's colours, a row per vertex or triangle
        # corner (attribute_domain); None: the mesh has no colour attribute.
        self.attribute_colors = None if arrays.attribute_colors is None else table_texture(arrays.attribute_colors)
        self.attribute_domain = arrays.attribute_domain
        self.corner_rows = arrays.corner_rows  # to refill the corner table when the mesh moves
        self.normal_domain = arrays.normal_domain  # what a row of the corner table is for
        # Kept (no copy) so the silhouette pass can derive its edge table on
        # first use without re-extracting; see silhouettes.py.
        self.triangles_cpu = arrays.triangles
        # The IndexMA pass maps triangles to their faces' materials (draw.py).
        self.triangle_polygons_cpu = arrays.triangle_polygons
        self.edge_flags_cpu = arrays.edge_flags
        self.silhouette_edges = None  # (texture, count), built lazily
        # The lines of multi-face regions and each triangle's region
        # (edge_select._region_lines), uploaded on first use (region_tables).
        self._region_lines_cpu = arrays.region_lines
        self._region_line_runs_cpu = arrays.region_line_runs
        self.region_run_segments = arrays.region_run_segments
        self.own_edges_measured = arrays.own_edges_measured
        # The runs of the wire (style 0): the first ones, as edge selection
        # writes the entries by style (draw.WIRE_RUNS).
        self.region_wire_runs = _wire_runs(arrays.region_line_runs, arrays.region_lines)
        # Every triangle takes its lines from the region-lines pass and
        # there is no n-gon (a cage look): a resolve that reads the pass's
        # image sets up no triangle edge (ShaderVariant.no_edge_setup).
        self.lines_only_from_region_pass = every_triangle_region_lines and not arrays.own_edges_measured
        # Some triangle reads the region-lines image: also a mesh whose
        # regions have no drawn line (a closed mesh under a wide edge angle),
        # which the image's record must hold all the same, so that no line
        # of a region behind it shows through it (passes._line_image_readers).
        self.reads_region_line_image = every_triangle_region_lines or bool(np.any(flags & REGION_LINES))
        self._triangle_regions_cpu = arrays.triangle_regions
        self._region_tables = None
        self._run_bounds = None  # (version, run_bounds_table()), made on first use after each move
        self._region_listing = None  # edge_select.region_listing, made with the first run_bounds_table()
        self._region_sizes = None  # (region lines, region_sizes()), made on first use
        self._run_vertices = None  # run_points(), made on first use
        self._block_boxes = None  # (version, low, high) of triangle_block_corners(), made on first use
        self._moved_triangles = None  # (version, which triangles the move to it moved): _change_box
        self._corner_vertex_rows = None  # _corner_vertices(), made at the first move
        self._faces_in_order = None  # whether the triangles are numbered face by face (_triangles_of_faces)
        # The set-up pre-pass's output for big meshes (draw._run_setup), made
        # on first use, and what it was set up for (draw._setup_key): kept
        # while the mesh, its matrix and the viewport stay the same.
        self.setup_table = None
        self.setup_key = None
        self._flag_table = None  # flag_table(), made on first use
        self._face_table = None  # face_table(), made on first use
        self._ngons_fold = None  # (version, ngons_may_fold())
        self._visibility = None  # (by_vertex, visibility_batch(), its bytes), made on first use, kept across moves
        self._position_rows = positions  # (N, 4), w 0: as uploaded (_local_positions, run_points)
        # What reposition() needs to tell a move of vertices from a new shape.
        self.vertex_count = arrays.vertex_count
        self.quads = arrays.quads
        self.quad_flip = arrays.quad_flip
        self.face_offsets_crc = arrays.face_offsets_crc
        self.source_positions = arrays.source_positions
        self.ngon_triangles = arrays.ngon_triangles
        self.edge_angle_state = arrays.edge_angle_state  # edge_select.EdgeAngleState
        self.mesh_bounds = (arrays.bounds_min, arrays.bounds_max)  # mesh space

        self._batch = None  # batch, made on first use
        self._corner_buffer = None  # its vertex buffer, shared with batch_of_triangles()
        self._walk_table = None  # walk_table(), made on first use
        self._walk_groups = None  # (points batch or None, box table): walk_groups(), made on first use
        # What the walk table holds now (draw._walk_key; None: not known),
        # and what was read back from it for that walk: (walk key,
        # walked_triangles()) and {id(those triangles): (them, their batch)}.
        self.walk_key = None
        self._walked_triangles = None
        self._walked_batches = {}
        self.gpu_bytes = sum(
            texture_bytes(table)
            for table in (self.positions, self.triangles, self.ngon_corners, self.corners, self.attribute_colors)
            if table is not None
        )

    @property
    def batch(self):
        """The direct draw's non-indexed triangle list, whose only attribute
        is the per-corner edge-flag word (the vertex stage pulls the rest).
        Made on first use: a mesh only ever drawn deferred never needs it."""
        if self._batch is None:
            self._batch = gpu.types.GPUBatch(type="TRIS", buf=self._corners())
        return self._batch

    def batch_of_triangles(self, triangles: np.ndarray):
        """:attr:`batch` for the triangles ``triangles`` (ascending numbers)
        alone: an index buffer over the same corners, so gl_VertexID is
        still 3 t + corner and the vertex stage pulls what it always does.
        Made per pick (its index buffer is as long as the pick); those of
        the very arrays walked_triangles() keeps for the last walk are kept
        with them, so a second draw over the same walk builds none."""
        kept = self._walked_batches.get(id(triangles))
        if kept is not None and kept[0] is triangles:
            return kept[1]
        corners = 3 * triangles.astype(np.int32)[:, None] + np.arange(3, dtype=np.int32)
        batch = gpu.types.GPUBatch(
            type="TRIS", buf=self._corners(), elem=gpu.types.GPUIndexBuf(type="TRIS", seq=corners)
        )
        known = self._walked_triangles
        if known is not None and any(triangles is part for part in known[1]):
            self._walked_batches[id(triangles)] = (triangles, batch)
        return batch

    def _corners(self):
        """The direct draw's vertex buffer: three corners a triangle, in
        table order, each with its triangle's edge-flag word."""
        if self._corner_buffer is None:
            fmt = gpu.types.GPUVertFormat()
            fmt.attr_add(id="edge_flags", comp_type="I32", len=1, fetch_mode="INT")
            vbo = gpu.types.GPUVertBuf(fmt, 3 * self.triangle_count)
            vbo.attr_fill("edge_flags", np.repeat(self.edge_flags_cpu, 3))
            self._corner_buffer = vbo
            self.gpu_bytes += 3 * self.triangle_count * 4
        return self._corner_buffer

    def walk_table(self):
        """The RGBA32F table of the walk-table pre-pass (core/draw.py
        _run_walk_table, shaders/walk_table_frag.glsl): a texel per
        triangle, 2^WALK_TABLE_SHIFT a row. Made on first use: only meshes
        whose regions are walked in a direct draw need it. (No framebuffer
        is kept: one belongs to the GL context that made it, and a mesh is
        drawn by the viewport's and the render engine's.)"""
        if self._walk_table is None:
            width = 1 << WALK_TABLE_SHIFT
            self._walk_table = gpu.types.GPUTexture((width, max(1, -(-self.triangle_count // width))), format="RGBA32F")
            self.gpu_bytes += texture_bytes(self._walk_table)
        return self._walk_table

    def walk_groups(self):
        """(points batch, RGBA32F box table) of the walk-table groups
        (core/draw.py _run_walk_table, shaders/walk_groups_vert.glsl): one
        point per group of WALK_GROUP consecutive segments of each block
        that a triangle walks, with the texel of its first segment and how
        many it holds; the table is laid out as the outline table, a box at
        each group's first texel. Made on first use, as walk_table()."""
        if self._walk_groups is None:
            flags = np.asarray(self.edge_flags_cpu, dtype=np.int64)
            walks = (flags & IN_REGION) != 0
            # A triangle that measures its own edges has its face's corners
            # ahead of its block (solidwire_vert.glsl main()).
            header = np.where((flags[walks] & OWN_EDGES_MEASURED) == OWN_EDGES_MEASURED, TEXELS_PER_SEGMENT, 0)
            starts = self.triangles_cpu[walks, 3].astype(np.int64) + header
            blocks = np.unique(np.stack([starts, flags[walks] >> NGON_SHIFT], axis=1), axis=0)
            blocks = blocks[blocks[:, 1] > 0]
            per_block = -(-blocks[:, 1] // WALK_GROUP)
            block_of = np.repeat(np.arange(len(blocks)), per_block)
            first_group = np.cumsum(per_block) - per_block
            group = np.arange(len(block_of)) - first_group[block_of]
            texels = blocks[block_of, 0] + TEXELS_PER_SEGMENT * WALK_GROUP * group
            sizes = np.minimum(blocks[block_of, 1] - WALK_GROUP * group, WALK_GROUP)
            batch = None  # (no block: nothing walks, nothing reads a box)
            if len(texels):
                fmt = gpu.types.GPUVertFormat()
                fmt.attr_add(id="group_texel", comp_type="I32", len=1, fetch_mode="INT")
                fmt.attr_add(id="group_size", comp_type="I32", len=1, fetch_mode="INT")
                vbo = gpu.types.GPUVertBuf(fmt, len(texels))
                vbo.attr_fill("group_texel", texels.astype(np.int32))
                vbo.attr_fill("group_size", sizes.astype(np.int32))
                batch = gpu.types.GPUBatch(type="POINTS", buf=vbo)
            boxes = gpu.types.GPUTexture((self.ngon_corners.width, self.ngon_corners.height), format="RGBA32F")
            self._walk_groups = (batch, boxes)
            self.gpu_bytes += 8 * len(texels) + texture_bytes(boxes)
        return self._walk_groups

    def walked_triangles(self, ranges=None) -> tuple[np.ndarray, np.ndarray]:
        """After the walk-table pre-pass: the triangles (ascending) that
        can show a line in a hidden-line draw, in two parts: (every other,
        picked). *Picked*: a region's triangle with no quad corner of its
        own for which the pre-pass kept segments (a count above 0), which
        hold every line within its reach (its own drawn edges are in its
        region's block, at distance 0, so they were kept), and which it
        therefore measures alone (shaders.ShaderVariant.walk_picks_only).
        *Every other*: those outside a multi-face region, and the region's
        triangles that walk their whole block or the groups of it near
        them (a count below 0) or have a quad corner. A region's triangle
        with a count of 0 shows nothing and is in neither. ``ranges``
        (first triangle, count): only inside those, the only texels the
        pre-pass wrote. Reads the counts back
        (one float a triangle), once per walk (:attr:`walk_key`): a second
        draw over the same walk gets the same arrays."""
        known = self._walked_triangles  # (the walk's key holds its ranges too)
        if known is not None and self.walk_key is not None and known[0] == self.walk_key:
            return known[1]
        counts = np.asarray(table_channel(self.walk_table()), dtype=np.float32)[: self.triangle_count]
        flags = self.edge_flags_cpu
        listed = (flags & IN_REGION) != 0
        picked = listed & ((flags & HAS_QUAD_CORNER) == 0) & (counts > 0.0)
        other = (counts != 0.0) | ~listed
        if ranges is not None:
            first, count = ranges
            starts = np.zeros(self.triangle_count + 1, dtype=np.int32)
            np.add.at(starts, first, 1)
            np.add.at(starts, first + count, -1)
            inside = np.cumsum(starts[:-1]) > 0
            picked &= inside
            other &= inside
        parts = (np.flatnonzero(other & ~picked), np.flatnonzero(picked))
        self._walked_triangles = (self.walk_key, parts)
        self._walked_batches = {}
        return parts

    def flag_table(self):
        """The edge-flag word of every triangle, as an RG32F texture
        (table_shape; low 12 bits, the rest: both halves whole
        numbers that float32 holds exactly, and Blender's Python API uploads
        only float data): what the deferred surface's resolve pass reads
        where the direct draw has the per-corner attribute. Made on first
        use."""
        if self._flag_table is None:
            width, height = table_shape(self.triangle_count)
            buf = gpu.types.Buffer("FLOAT", width * height * 2)
            view = np.asarray(buf).reshape(-1, 2)
            flags = np.asarray(self.edge_flags_cpu, dtype=np.int32)
            np.bitwise_and(flags, 0xFFF, out=view[: self.triangle_count, 0], casting="unsafe")
            np.right_shift(flags, 12, out=view[: self.triangle_count, 1], casting="unsafe")
            view[self.triangle_count :] = 0.0
            self._flag_table = gpu.types.GPUTexture((width, height), format="RG32F", data=buf)
            self.gpu_bytes += texture_bytes(self._flag_table)
        return self._flag_table

    def face_table(self):
        """The polygon of every triangle, as an R32F texture (table_shape;
        the low 24 bits of its index, which float32 holds exactly: the
        triangles compared lie a few dozen rows apart, so their polygons
        never differ by 2^24): what tells a folded n-gon's other triangles
        apart (shaders/quad_partner.glsl, NGON_SIBLINGS), as the flags do
        not once the n-gon walks a block. Made on first use."""
        if self._face_table is None:
            faces = np.bitwise_and(np.asarray(self.triangle_polygons_cpu, dtype=np.int64), 0xFFFFFF)
            self._face_table = value_table_texture(faces.astype(np.float32))
            self.gpu_bytes += texture_bytes(self._face_table)
        return self._face_table

    def ngons_may_fold(self) -> bool:
        """Whether the triangles of some n-gon can overlap on screen at the
        mesh's current positions (extract.ngon_triangles_overlap): where
        they can, a hidden-line pass tests each triangle's face's other
        triangles (shaders/quad_partner.glsl, NGON_SIBLINGS)."""
        known = self._ngons_fold
        if known is None or known[0] != self.version:
            fold = self.has_ngons and ngon_triangles_overlap(
                self._position_rows, self.triangles_cpu, self.triangle_polygons_cpu
            )
            known = self._ngons_fold = (self.version, fold)
        return known[1]

    def ngons_flat(self) -> bool:
        """Whether every n-gon of the mesh lies in one plane at its current
        positions (extract.ngons_flat; True without n-gon outlines)."""
        known = self._ngons_flat
        if known is None or known[0] != self.version:
            flat = self._ngon_outlines is None or ngons_flat(self._position_rows, self._ngon_outlines)
            known = self._ngons_flat = (self.version, flat)
        return known[1]

    @property
    def region_line_count(self) -> int:
        """Entries of the region-lines table (0: no multi-face region)."""
        lines = self._region_lines_cpu
        return 0 if lines is None else len(lines) // 2

    @property
    def region_run_count(self) -> int:
        """Runs of the region-lines table: the quads the pass draws."""
        runs = self._region_line_runs_cpu
        return 0 if runs is None else len(runs)

    def region_sizes(self) -> tuple[int, float, int]:
        """(the most line entries a region has, the mean over the triangles
        in regions of their own region's entries, the triangles in no
        multi-face region): what a walk of the regions' edges costs per
        triangle, against the hidden layers' depth peeling
        (passes._peeled_items), and whether a peeled mesh leaves any
        triangle to the direct hidden-line pass. Computed on first use
        after the region lines change (topology or classes), not at
        extraction."""
        lines, regions = self._region_lines_cpu, self._triangle_regions_cpu
        known = self._region_sizes
        if known is not None and known[0] is lines:
            return known[1]
        if lines is None or regions is None:
            sizes = (0, 0.0, self.triangle_count)
        else:
            owners = np.concatenate([lines[0::2, 3], lines[1::2, 2]]).astype(np.int64)
            in_regions = regions >= 0
            of_triangle = regions[in_regions].astype(np.int64)
            # (A region may own no line at all: a closed surface whose
            # edges the edge angle hides, with no class. It counts 0.)
            most_region = int(of_triangle.max()) + 1 if len(of_triangle) else 0
            counts = np.bincount(owners[owners >= 0], minlength=most_region)
            mean = float(counts[of_triangle].mean()) if len(of_triangle) else 0.0
            outside = self.triangle_count - len(of_triangle)
            sizes = (int(counts.max()) if len(counts) else 0, mean, outside)
        self._region_sizes = (lines, sizes)
        return sizes

    def region_tables(self):
        """(region-lines table, per-triangle region table) as textures
        (docs/image_model.md §2.6), made on first use. The first holds the
        runs (a texel each: the texel of the run's first entry, its
        entries), then the entries."""
        if self._region_tables is None:
            runs = self._region_line_runs_cpu.copy()
            runs[:, 0] = len(runs) + TEXELS_PER_REGION_LINE * runs[:, 0]
            lines = np.concatenate([runs, self._region_lines_cpu])
            regions = np.asarray(self._triangle_regions_cpu, np.float32)
            self._region_tables = (table_texture(lines), value_table_texture(regions))
            self.gpu_bytes += sum(texture_bytes(t) for t in self._region_tables)
        return self._region_tables

    def run_bounds_table(self):
        """The sphere around each region-lines run's regions at the mesh's
        current positions (edge_select.run_bounds) as an RGBA32F table,
        a texel per run: what sizes the region-lines pass's quads in world
        widths. Made on first use after each move (a move of any vertex
        can change any sphere)."""
        known = self._run_bounds
        if known is None or known[0] != self.version:
            if self._region_listing is None:
                self._region_listing = region_listing(self._triangle_regions_cpu, self._corner_vertices())
            bounds = run_bounds(
                self._region_listing, self._position_rows, self._region_lines_cpu, self._region_line_runs_cpu
            )
            texture = table_texture(bounds)
            self.gpu_bytes += texture_bytes(texture) - (0 if known is None else texture_bytes(known[1]))
            known = self._run_bounds = (self.version, texture)
        return known[1]

    @property
    def _local_positions(self) -> np.ndarray:
        """(N, 3) mesh-space positions as uploaded (a view)."""
        return self._position_rows[:, :3]

    def run_points(self):
        """(points, corners): the mesh-space position (x, y, z, 0) of every vertex at
        which a segment of a region-lines run ends, and each run's segment
        ends as rows of ``points``, transposed: (2 L, R) (L: the most
        segments a run holds; a shorter run repeats its last segment's).
        Which vertices is found on first use and kept (a move keeps the
        runs); their positions are read now. What a partial redraw reads to
        leave out the runs that cannot reach its rectangle
        (draw.runs_reaching)."""
        if self._run_vertices is None:
            runs = self._region_line_runs_cpu
            first, count = runs[:, 0].astype(np.int64), runs[:, 1].astype(np.int64)
            slot = np.minimum(np.arange(self.region_run_segments), count[:, None] - 1)
            rows = TEXELS_PER_REGION_LINE * (first[:, None] + slot)
            ends = self._region_lines_cpu[rows.ravel(), :2].astype(np.intp).ravel()
            # The distinct ends by a scatter over the vertices, not a sort
            # (np.unique): this runs at the first edit after an extraction.
            used = np.zeros(len(self._local_positions), bool)
            used[ends] = True
            vertices = np.flatnonzero(used)
            row_of = np.empty(len(used), np.intp)  # read only where used
            row_of[vertices] = np.arange(len(vertices))
            corners = row_of.take(ends).reshape(len(runs), -1)
            self._run_vertices = (vertices, np.ascontiguousarray(corners.T))
        vertices, corners = self._run_vertices
        # (A gather of whole contiguous rows: several times faster than one
        # of the strided (N, 3) view.)
        return self._position_rows.take(vertices, axis=0), corners

    def prepare_partial_redraws(self) -> None:
        """Make now what a software rasteriser's partial redraw reads to
        leave out what cannot reach its rectangle and is kept across moves:
        the boxes of the triangle blocks (measure_triangle_blocks) and which
        vertices end the region-lines runs (run_points)."""
        self.measure_triangle_blocks()
        if self.region_run_count:
            self.run_points()

    def triangle_block_corners(self) -> np.ndarray:
        """(8 K, 4): the corners (x, y, z, 0: mesh space as uploaded, as
        run_points) of the box around each block of RECORD_BLOCK_TRIANGLES
        consecutive triangles (the last block may hold fewer), corner c of
        every block before corner c + 1 of any. What a partial redraw reads
        to leave out of its record the triangles that cannot cover its
        rectangle (draw.triangle_ranges_reaching)."""
        low, high = self.measure_triangle_blocks()
        corners = np.zeros((8, len(low), 4), np.float32)
        for corner in range(8):
            for axis in range(3):
                corners[corner, :, axis] = (high if corner >> axis & 1 else low)[:, axis]
        return corners.reshape(-1, 4)

    def measure_triangle_blocks(self):
        """(low, high) (K, 3) of the boxes of triangle_block_corners, made
        on first use and kept with the positions: after a move that
        _change_box has measured only the blocks with a moved triangle are
        measured again (a drag moves a few: about 1 ms for a level-5
        Suzanne on a 2-core machine), after any other every block (about
        20 ms there)."""
        boxes = self._block_boxes
        if boxes is None or boxes[0] != self.version:
            moved = self._moved_triangles
            if boxes is not None and boxes[0] == self.version - 1 and moved is not None and moved[0] == self.version:
                low, high = boxes[1], boxes[2]
                self._measure_blocks_again(moved[1], low, high)
            else:
                low, high = self._measure_blocks()
            boxes = self._block_boxes = (self.version, low, high)
        return boxes[1], boxes[2]

    def _measure_blocks(self):
        """(low, high) (K, 3) of every block of triangle_block_corners."""
        # (The corner rows of a mesh that has moved, else made for this
        # measure alone: a mesh that is only looked at keeps no copy.)
        corner_vertices = self._corner_vertex_rows
        if corner_vertices is None:
            corner_vertices = _corner_vertex_rows(self.triangles_cpu)
        starts = np.arange(0, self.triangle_count, RECORD_BLOCK_TRIANGLES)
        return boxes_of_triangle_runs(self._position_rows, corner_vertices, starts)

    def _measure_blocks_again(self, moved: np.ndarray, low: np.ndarray, high: np.ndarray) -> None:
        """Measure again, in place, the blocks of ``low`` / ``high`` that
        hold a triangle of the (T,) bool mask ``moved``."""
        blocks = np.flatnonzero(np.logical_or.reduceat(moved, np.arange(0, len(moved), RECORD_BLOCK_TRIANGLES)))
        if not len(blocks):
            return
        # Every block as RECORD_BLOCK_TRIANGLES rows: the last one's missing
        # rows repeat its last triangle, which changes no bound.
        rows = blocks[:, None] * RECORD_BLOCK_TRIANGLES + np.arange(RECORD_BLOCK_TRIANGLES)
        np.minimum(rows, self.triangle_count - 1, out=rows)
        corners = self.triangles_cpu.take(rows.reshape(-1), axis=0)[:, :3].reshape(-1)
        # (Few rows: gathered whole, which copies no column.)
        points = self._position_rows.take(corners, axis=0)
        for axis in range(3):
            values = points[:, axis].reshape(len(blocks), -1)
            low[blocks, axis] = values.min(axis=1)
            high[blocks, axis] = values.max(axis=1)

    def visibility_batch(self, by_vertex: bool = False):
        """An indexed triangle batch (the triangle table as index buffer)
        for the deferred surface's visibility pass: each vertex is
        transformed once, not once per corner. Its vertices hold which row
        of the position table each stands for ("source_vertex"), which the
        pass reads as the exact path does: the batch depends on the
        triangles alone, so a mesh that moves keeps it (a move uploads the
        position table and nothing else). Made on first use.

        The pass numbers the triangles as the triangle table does, either
        with gl_PrimitiveID or, with ``by_vertex``, with a "triangle"
        attribute that each triangle's last corner (OpenGL's provoking
        vertex, whose value a flat output takes) carries for it. A vertex
        can carry that for one triangle only, so every other triangle ending
        at it gets a copy of the vertex as its last corner: the same row of
        the position table, so the same coverage and depth. This costs ~12
        bytes per triangle and saves a software rasteriser its primitive-ID
        bookkeeping (shaders.triangle_ids_by_vertex)."""
        if self._visibility is not None and self._visibility[0] != by_vertex:
            self._drop_visibility_batch()
        if self._visibility is None:
            triangles = np.array(self.triangles_cpu[:, :3], dtype=np.int32, order="C")  # (a copy: written into below)
            sources = np.arange(self.vertex_count, dtype=np.int32)
            fmt = gpu.types.GPUVertFormat()
            fmt.attr_add(id="source_vertex", comp_type="I32", len=1, fetch_mode="INT")
            if by_vertex:
                copied, numbers, triangles = _provoking_triangle_numbers(self.vertex_count, triangles)
                sources = np.concatenate([sources, copied.astype(np.int32)])
                fmt.attr_add(id="triangle", comp_type="F32", len=1, fetch_mode="FLOAT")
            vbo = gpu.types.GPUVertBuf(fmt, len(sources))
            vbo.attr_fill("source_vertex", sources)
            if by_vertex:
                vbo.attr_fill("triangle", numbers)
            batch = gpu.types.GPUBatch(type="TRIS", buf=vbo, elem=gpu.types.GPUIndexBuf(type="TRIS", seq=triangles))
            size = self.triangle_count * 12 + len(sources) * (8 if by_vertex else 4)
            self._visibility = (by_vertex, batch, size)
            self.gpu_bytes += size
        return self._visibility[1]

    def _drop_visibility_batch(self) -> None:
        if self._visibility is not None:
            self.gpu_bytes -= self._visibility[2]
            self._visibility = None

    def replace_positions(
        self,
        local: np.ndarray,
        centre,
        bounds_min,
        bounds_max,
        source_positions=None,
        corners: np.ndarray | None = None,
    ) -> None:
        """New vertex positions, same faces and triangles: only the position
        table is uploaded again, and the corner table when ``corners`` (the
        corner normals follow a deformation). The triangle and outline
        tables, the edge-flag and visibility batches and the silhouette edges
        depend on the faces and the edge selection alone; the set-up table is set up again
        from the new positions (its key holds ``version``)."""
        positions = np.zeros((len(local), 4), dtype=np.float32)
        positions[:, :3] = local
        self.positions = table_texture(positions)
        if corners is not None and self.corners is not None:
            self.corners = table_texture(corners)
        self.version += 1
        # The shape before, for last_move(): asked of a viewport overlay only.
        self._before_move = (self._position_rows, self.centre, self.mesh_bounds, self._corner_rows_uploaded)
        self._moved_box = None
        self._corner_rows_uploaded = corners
        self._position_rows = positions
        self.centre = centre
        self.bounds_min = bounds_min - centre
        self.bounds_max = bounds_max - centre
        self.mesh_bounds = (bounds_min, bounds_max)
        self.source_positions = source_positions

    def last_move(self):
        """What the last replace_positions() changed, for a viewport overlay
        that keeps its image and draws again only where it changed
        (passes._overlay_surface): ``(version, box)``, ``box`` the
        mesh-space (low, high) around every vertex of every face whose
        drawing inputs changed (a moved vertex, a changed corner row),
        before and after, or None when no face changed. None when that
        cannot be told: never moved, the centre or the bounds moved
        (positions are stored relative to the centre, and the bounds decide
        a draw's variant), or the corner rows changed with no earlier ones
        kept (a shaded mesh keeps them from its first move on)."""
        before = getattr(self, "_before_move", None)
        if before is None:
            return None
        if self._moved_box is None:
            self._moved_box = (self._change_box(*before),)
        box = self._moved_box[0]
        return box if box is None else (self.version, box[0])

    def _change_box(self, old, old_centre, old_bounds, old_corners):
        rows, corners = self._position_rows, self._corner_rows_uploaded
        if (
            old.shape != rows.shape
            or not np.array_equal(np.asarray(old_centre), np.asarray(self.centre))
            or not (
                np.array_equal(old_bounds[0], self.mesh_bounds[0])
                and np.array_equal(old_bounds[1], self.mesh_bounds[1])
            )
        ):
            return None
        vertex_moved = _rows_differ(old, rows)
        corner_vertices = self._corner_vertices()

        def touching(vertex_mask):
            return vertex_mask[corner_vertices[0]] | vertex_mask[corner_vertices[1]] | vertex_mask[corner_vertices[2]]

        triangle_changed = touching(vertex_moved)
        # Which triangles moved: the blocks of triangle_block_corners to measure again.
        self._moved_triangles = (self.version, triangle_changed.copy())
        if corners is not None:
            if old_corners is None or old_corners.shape != corners.shape:
                return None
            changed_rows = np.flatnonzero(_rows_differ(old_corners, corners))
            if self.normal_domain == NORMALS_BY_VERTEX:
                vertex_moved[changed_rows] = True
                triangle_changed = touching(vertex_moved)
            elif self.normal_domain == NORMALS_BY_TRIANGLE:
                triangle_changed[changed_rows] = True
            else:
                triangle_changed[changed_rows // 3] = True
        # A face's triangles set up its outline together (a quad's fourth
        # corner, an n-gon's corners): a changed face redraws every one.
        triangles = self._triangles_of_faces(np.flatnonzero(triangle_changed))
        if not len(triangles):
            return (None,)
        vertices = np.unique(corner_vertices[:, triangles])
        points = np.concatenate([old[vertices, :3], rows[vertices, :3]]).astype(np.float64) + np.asarray(self.centre)
        return ((points.min(axis=0), points.max(axis=0)),)

    def _corner_vertices(self) -> np.ndarray:
        """(3, T) intp: each triangle's corner vertices, a contiguous row per
        corner, in numpy's own index type (gathers by the columns of the
        (T, 4) int32 triangle table cost two to three times more: each
        copies and widens its indices first). Made at the first move and
        kept: the triangles do not change when vertices move."""
        if self._corner_vertex_rows is None:
            self._corner_vertex_rows = _corner_vertex_rows(self.triangles_cpu)
        return self._corner_vertex_rows

    def _triangles_of_faces(self, triangles: np.ndarray) -> np.ndarray:
        """Every triangle of the faces of ``triangles`` (ascending): where the
        triangles are numbered face by face, as the extraction numbers them,
        found by a search around the few faces instead of a pass over every
        triangle."""
        polygons = np.asarray(self.triangle_polygons_cpu)
        if self._faces_in_order is None:
            self._faces_in_order = bool(np.all(polygons[1:] >= polygons[:-1]))
        if not self._faces_in_order:
            touched = np.zeros(int(polygons.max(initial=-1)) + 1, dtype=bool)
            touched[polygons[triangles]] = True
            return np.flatnonzero(touched[polygons])
        faces = np.unique(polygons[triangles])
        first = np.searchsorted(polygons, faces, side="left")
        count = np.searchsorted(polygons, faces, side="right") - first
        # first[k], first[k] + 1, ... for count[k] each, face after face.
        return np.repeat(first - np.cumsum(count) + count, count) + np.arange(int(count.sum()))


def _wire_runs(runs: np.ndarray | None, lines: np.ndarray | None) -> int:
    """How many of the region-lines ``runs`` are of the wire (style 0):
    they lead, as edge selection writes the entries by style; 0 where the
    styles do not ascend (then every run is drawn with the classes' code)."""
    if runs is None or not len(runs):
        return 0
    styles = lines[TEXELS_PER_REGION_LINE * runs[:, 0].astype(np.intp), 2]
    if (styles[1:] < styles[:-1]).any():
        return 0
    return int(np.searchsorted(styles, 0.5))


def _corner_vertex_rows(triangles: np.ndarray) -> np.ndarray:
    """(3, T) intp: column k of the (T, 4) triangle table as row k."""
    return np.ascontiguousarray(triangles[:, :3].T, dtype=np.intp)


def _rows_differ(before: np.ndarray, after: np.ndarray) -> np.ndarray:
    """(N,) bool: which rows of two (N, 4) float32 tables differ, bit for
    bit (two 64-bit compares a row: -0.0 against 0.0 differs, which only
    redraws more)."""
    before = np.ascontiguousarray(before, dtype=np.float32).view(np.int64)
    after = np.ascontiguousarray(after, dtype=np.float32).view(np.int64)
    differs = before != after
    return differs[:, 0] | differs[:, 1]


class MeshCache:
    """GPU meshes by key, with counters for stats().

    Keys are plain tuples (see blender/gather.py: a depsgraph mode plus session_uid
    based identity), never Blender data, so nothing here dangles across undo
    or file load. Each entry remembers two validity tokens:

    * ``fast``: cheap proof that nothing changed (the evaluated mesh's
      pointer plus the update counters of runtime's depsgraph handler); only
      set by callers that trust depsgraph updates (the viewport);
    * ``fingerprint``: counts plus a checksum of positions and topology,
      compared when ``fast`` does not match (every render: a render's
      depsgraph is new each frame unless persistent data is on, so pointers
      and update lists say nothing about what changed since the last frame).
    """

    def __init__(self):
        self._entries: dict[object, GPUMesh] = {}
        self._tokens: dict[object, tuple] = {}  # key -> (fast, fingerprint)
        self.extracted = 0
        self.reused = 0
        self.repositioned = 0  # meshes whose positions alone were uploaded again
        self.culled = 0  # instances culled before their mesh was ever extracted
        self.ms_upload = 0.0

    def meshes(self) -> list:
        """The GPU meshes held now (statistics and tests)."""
        return list(self._entries.values())

    def __len__(self) -> int:
        return len(self._entries)

    def __contains__(self, key) -> bool:
        return key in self._entries

    def get_validated(self, key, fast, fingerprint, make_arrays, reposition=None):
        """The GPU mesh for ``key`` if it is still valid, else a rebuilt one.

        ``fast`` is a token or None; ``fingerprint()`` computes the content
        fingerprint (called only when the fast token does not match) and
        returns ``(fingerprint, context)``; the fingerprint is a pair
        ``(topology, shape)``: what decides the faces, triangles and edge
        selection, and what a deformation changes (positions, corner
        normals). ``make_arrays(context)`` extracts (``context`` lets it
        reuse what the fingerprint already read). When only the shape
        changed, ``reposition(entry, context)`` may return the arguments of
        :meth:`GPUMesh.replace_positions` and only those tables are
        uploaded; None sends it through a full extraction.
        Returns ``(GPUMesh or None, extracted: bool)``."""
        entry = self._entries.get(key)
        tokens = self._tokens.get(key)
        if entry is not None and fast is not None and tokens is not None and tokens[0] == fast:
            self.reused += 1
            return entry, False
        content, context = fingerprint()
        if entry is not None and tokens is not None and tokens[1] == content:
            self._tokens[key] = (fast, content)
            self.reused += 1
            return entry, False
        if entry is not None and tokens is not None and reposition is not None and tokens[1][0] == content[0]:
            moved = reposition(entry, context)
            if moved is not None:
                start = time.perf_counter()
                entry.replace_positions(*moved)
                self.ms_upload += (time.perf_counter() - start) * 1000.0
                self._tokens[key] = (fast, content)
                self.repositioned += 1
                return entry, True
        self._entries.pop(key, None)  # free the old upload before making the new one
        mesh = self._build(key, make_arrays(context), (fast, content))
        return mesh, True

    def _build(self, key, arrays, tokens) -> GPUMesh | None:
        self.extracted += 1
        if arrays is None or arrays.triangle_count == 0:
            self._entries.pop(key, None)
            self._tokens.pop(key, None)
            return None
        start = time.perf_counter()
        entry = GPUMesh(arrays)
        self.ms_upload += (time.perf_counter() - start) * 1000.0
        self._entries[key] = entry
        if tokens is not None:
            self._tokens[key] = tokens
        return entry

    def discard(self, key) -> None:
        self._entries.pop(key, None)
        self._tokens.pop(key, None)

    def keep_only(self, keys, *, scope=None) -> None:
        """Drop every entry whose key is not in ``keys`` (frees GPU memory).

        With ``scope``, only entries whose key starts with ``scope`` are
        considered (a render frame must not evict the viewport's meshes)."""
        keys = set(keys)
        for key in [k for k in self._entries if k not in keys]:
            if scope is None or (isinstance(key, tuple) and key[: len(scope)] == scope):
                self.discard(key)

    def clear(self) -> None:
        self._entries.clear()
        self._tokens.clear()

    def reset_counters(self) -> None:
        self.extracted = 0
        self.reused = 0
        self.repositioned = 0
        self.culled = 0
        self.ms_upload = 0.0

    @property
    def gpu_bytes(self) -> int:
        return sum(e.gpu_bytes for e in self._entries.values())
