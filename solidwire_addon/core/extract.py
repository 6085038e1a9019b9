"""Extraction: a mesh's arrays -> GPU-ready numpy arrays.

Takes plain arrays (vertex positions, the vertex of each face corner, face
offsets; blender/mesh_reading.py reads them from an evaluated mesh) and
works in vectorised numpy: no per-element Python loops. The triangles are
exactly Blender's own (``loop_triangles``), so the faces we draw are the
faces Blender draws; the fast path (:func:`build_arrays_fast`) builds the
triangles of tris and quads itself with Blender's own quad split rule and
asks its ``blender_tris`` callback only for n-gons and for quads whose split
is numerically undecided; :func:`build_arrays` takes Blender's triangles for
every face (the reference path). For each triangle we record which of its
three edges are polygon boundary edges ("real") and which are diagonals
added by triangulation, and for a quad the id of its 4th corner so a
fragment can measure the distance to all four quad edges (clean corners
next to a hidden diagonal).

Corner order is rotated (never reflected, so winding and back-face culling are
unchanged) so that a quad triangle's diagonal is always edge 2 (p2 -> p0) and
its 4th corner joins p2 and p0.
"""

from __future__ import annotations

import zlib
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

EDGE0_REAL, EDGE1_REAL, EDGE2_REAL, HAS_QUAD_CORNER, IS_NGON = 1, 2, 4, 8, 16
# A quad's edges p2-p3 / p3-p0 not drawn (edge angle, cage edges; image
# model §3.4): neither a line nor a diagonal.
EDGE3_HIDDEN, EDGE4_HIDDEN = 64, 128
# The triangle's own edge k is a polygon edge that is not drawn.
EDGE0_HIDDEN = 256  # << k for edges 1 and 2
# The triangle walks a block of segments (its region's drawn edges, see
# edge_select.py) that starts at column 3; edge_flags >> NGON_SHIFT is the
# segment count.
IN_REGION = 2048
# The triangle lies in a region of several faces: where the render draws the
# region lines as a pass of their own (docs/image_model.md §2.6), its lines come from
# that pass and it walks only the diagonals at the head of its block.
REGION_LINES = 4096
NGON_SHIFT = 13  # edge_flags >> NGON_SHIFT is an n-gon's corner count

# Vertex ids travel to the GPU as float32 texels: exact below 2**24.
MAX_VERTICES = 1 << 24


@dataclass
class MeshArrays:
    """Arrays for one mesh, in the mesh's own space re-centred on `centre`.

    Positions are stored relative to the centre of their bounding box (the
    offset is folded into the object matrix in float64), so a mesh far from
    the origin keeps full float32 precision on the GPU.
    """

    positions: np.ndarray  # (V, 3) float32, relative to centre
    centre: np.ndarray  # (3,) float64
    triangles: np.ndarray  # (T, 4) int32: p0, p1, p2, quad 4th corner / n-gon corner start / p0
    edge_flags: np.ndarray  # (T,) int32, EDGE*_REAL | HAS_QUAD_CORNER
    triangle_polygons: np.ndarray  # (T,) int32 polygon index of each triangle
    bounds_min: np.ndarray  # (3,) float64, mesh space (not re-centred)
    bounds_max: np.ndarray  # (3,) float64
    dropped_triangles: int = 0  # triangles skipped for vertices that are not drawable (drawable_vertices)
    # Vertex ids of every n-gon's outline in loop order, one polygon after
    # another; an n-gon triangle's column 3 says where its polygon starts.
    ngon_corners: np.ndarray = None
    # Triangles that use one vertex twice (a corrupt face such as (0, 1, 1, 2)):
    # zero area, so never rasterised; counted for the user message only.
    degenerate_triangles: int = 0
    # Shading only (see corner_table): (3T, 4) float32, per triangle corner in
    # the order of ``triangles``: Blender's corner normal xyz and the face's
    # material index. None when the fill is not shaded by normals/materials.
    corners: np.ndarray = None
    # Edge selection (edge_select.py): per entry of ngon_corners, 1 where
    # that outline slot starts an edge that is not drawn. None: all drawn.
    ngon_hidden: np.ndarray = None
    # (S, 4) float32 segment blocks of listed triangles (edge_select.py);
    # they follow ngon_corners in the GPU's outline table. None: no blocks.
    region_table: np.ndarray = None
    # The lines of multi-face regions (edge_select._region_lines): (2N, 4)
    # float32, and each triangle's region (NO_REGION outside one). None:
    # no multi-face region.
    region_lines: np.ndarray = None
    triangle_regions: np.ndarray = None
    # Runs of that table drawn as one quad each (edge_select._line_runs):
    # (R, 4) float32 (first entry, entries, 0, 0), and the most entries a
    # run holds (1, 2, 4 or 8).
    region_line_runs: np.ndarray = None
    region_run_segments: int = 1
    # Some listed triangle measures its own edges and reads its quad's
    # fourth corner from its block (edge_select.OWN_EDGES_MEASURED).
    own_edges_measured: bool = False
    # Every n-gon is a region of its own (edge_select.select_edges): then,
    # where they are flat (ngons_flat), a triangle's own diagonals give its
    # n-gon's (draw._Part.variant). Their outlines: every n-gon's corner
    # vertex ids, one after another, and where each starts.
    ngons_alone: bool = False
    ngon_outlines: tuple = None
    # The ATTRIBUTE fill source: the active colour attribute as (R, 4)
    # float32 scene-linear RGBA rows, one per vertex (attribute_domain
    # NORMALS_BY_VERTEX) or per triangle corner (NORMALS_BY_CORNER); None:
    # the mesh has none.
    attribute_colors: np.ndarray = None
    attribute_domain: int = 0
    # (3T,) int32 polygon corner of each triangle corner (-1: none), kept with
    # ``corners`` so a moved mesh refills its table (fill_corner_table);
    # only for normals by corner.
    corner_rows: np.ndarray | None = None
    # What one row of ``corners`` is for (NORMALS_BY_*).
    normal_domain: int = 2
    # Set when positions alone decide nothing but the quad diagonals (tris and
    # quads only, every vertex finite): the quads' vertex ids, their split
    # and a checksum of the face sizes, so that an edit that only moves
    # vertices can be re-uploaded as positions (see reposition()).
    quads: np.ndarray | None = None
    quad_flip: np.ndarray | None = None
    face_offsets_crc: int | None = None
    source_positions: np.ndarray | None = None  # (V, 3) float32 as read, to find moved vertices
    # With n-gons: the indices of their triangles in Blender's triangles,
    # Blender's corners for each and each one's face, as extracted: a move
    # keeps the triangles only while Blender still splits every n-gon so.
    ngon_triangles: tuple | None = None
    # The edge angle test's state (edge_select.EdgeAngleState) when it chose
    # the drawn edges: a move of vertices is checked against it.
    edge_angle_state: object | None = None

    @property
    def mesh_bounds(self) -> tuple:
        """(bounds_min, bounds_max) in mesh space, as GPUMesh keeps them too."""
        return self.bounds_min, self.bounds_max

    @property
    def triangle_count(self) -> int:
        return int(self.triangles.shape[0])

    @property
    def vertex_count(self) -> int:
        return int(self.positions.shape[0])

    @property
    def has_ngons(self) -> bool:
        """Whether the mesh has faces of more than four corners (their
        outlines: ``ngon_corners``)."""
        return len(self.ngon_corners) > 0

    @property
    def nbytes(self) -> int:
        return sum(a.nbytes for a in (self.positions, self.triangles, self.edge_flags, self.triangle_polygons))


class ExtractError(ValueError):
    """A mesh that cannot be drawn; the message is one line for the user."""


def _check_vertex_count(positions: np.ndarray) -> None:
    if positions.shape[0] >= MAX_VERTICES:
        raise ExtractError(
            f"mesh has {positions.shape[0]:,} vertices; SolidWire draws at most {MAX_VERTICES - 1:,} per mesh"
        )


def _triangles_from_loops(tri_loops, tri_polygons, loop_start, loop_total, corner_vert):
    """Blender triangles (corner ids) -> (triangles (T, 4) int32, real (3, T)
    bool, is_quad (T,) bool), quads rotated so the diagonal is edge 2.

    Column-wise int32 arithmetic: no int64 casts, no modulo, no fancy row
    re-ordering (each ``np.where`` is one pass over a column)."""
    a0, a1, a2 = (np.ascontiguousarray(tri_loops[:, k]) for k in range(3))
    start = loop_start[tri_polygons]
    total = loop_total[tri_polygons]
    end = start + total

    def next_corner(x):  # the next corner in the polygon's cycle
        y = x + 1
        return np.where(y == end, start, y)

    n0, n1, n2 = next_corner(a0), next_corner(a1), next_corner(a2)
    # Edge k joins corners k and k+1 (mod 3); it is a real polygon edge when
    # the two corners are neighbours in the polygon's cycle.
    r0 = (a1 == n0) | (a0 == n1)
    r1 = (a2 == n1) | (a1 == n2)
    r2 = (a0 == n2) | (a2 == n0)

    # Quads: rotate (never reflect: winding is kept) so the diagonal is edge 2.
    is_quad = total == 4
    d0 = is_quad & ~r0
    d1 = is_quad & ~r1

    def rotate(x0, x1, x2):
        return (
            np.where(d0, x1, np.where(d1, x2, x0)),
            np.where(d0, x2, np.where(d1, x0, x1)),
            np.where(d0, x0, np.where(d1, x1, x2)),
        )

    a0, a1, a2 = rotate(a0, a1, a2)
    r0, r1, r2 = rotate(r0, r1, r2)
    # A quad's 4th corner is the one its triangle does not use (corner ranks
    # within the quad sum to 0+1+2+3 = 6).
    fourth = np.where(is_quad, start + 6 - ((a0 - start) + (a1 - start) + (a2 - start)), a0)

    triangles = np.empty((len(a0), 4), dtype=np.int32)
    for k, loops in enumerate((a0, a1, a2, fourth)):
        triangles[:, k] = corner_vert[loops]
    return triangles, np.stack([r0, r1, r2]), is_quad


def _edge_flags(real, is_quad) -> np.ndarray:
    flags = real[0].astype(np.int32)
    flags += real[1] * EDGE1_REAL
    flags += real[2] * EDGE2_REAL
    flags += is_quad * HAS_QUAD_CORNER
    return flags


def _pack_ngons(tri_ids, real, tri_polygons, loop_start, loop_total, corner_vert):
    """N-gons: the fragment stage walks the polygon's whole outline and all of
    its diagonals (see solidwire_frag.glsl), so pack, per n-gon with triangles
    here, a block of n outline ids (loop order) followed by its n - 3
    diagonals as id pairs. Returns (ngon_corners, the block start of each
    given triangle's polygon). ``tri_ids`` (N, 3), ``real`` (N, 3) and
    ``tri_polygons`` (N,) are the n-gon triangles only."""
    ngon_polys = np.unique(tri_polygons)
    sizes = loop_total[ngon_polys].astype(np.int64)
    block = 3 * sizes - 6
    offsets = np.cumsum(block) - block
    ngon_corners = np.zeros(int(block.sum()), dtype=np.int32)
    rank_in_outline = np.arange(sizes.sum()) - np.repeat(np.cumsum(sizes) - sizes, sizes)
    outline_loops = np.repeat(loop_start[ngon_polys].astype(np.int64), sizes) + rank_in_outline
    ngon_corners[np.repeat(offsets, sizes) + rank_in_outline] = corner_vert[outline_loops]
    # Diagonals default to a degenerate pair (a point: no edge) so a
    # triangulation that yields fewer than n - 3 still fills the block.
    diag_slots = np.repeat(offsets + sizes, 2 * (sizes - 3)) + (
        np.arange(2 * (sizes - 3).sum()) - np.repeat(np.cumsum(2 * (sizes - 3)) - 2 * (sizes - 3), 2 * (sizes - 3))
    )
    ngon_corners[diag_slots] = np.repeat(corner_vert[loop_start[ngon_polys]], 2 * (sizes - 3))
    pairs = np.stack([tri_ids, np.roll(tri_ids, -1, axis=1)], axis=2)[~real]  # (D, 2)
    pair_poly = np.repeat(tri_polygons, (~real).sum(axis=1)).astype(np.int64)
    # The distinct (polygon, lower id, upper id) diagonals in that order, each
    # vertex pair as one key: a two-key lexsort, where np.unique of rows
    # (axis=0) sorts structured rows several times slower (it was 85 % of this).
    low = pairs.min(axis=1).astype(np.int64)
    high = pairs.max(axis=1).astype(np.int64)
    vertex_span = np.int64(int(high.max(initial=0)) + 1)
    key = low * vertex_span + high
    order = np.lexsort((key, pair_poly))
    pair_poly, key = pair_poly[order], key[order]
    first_of_kind = np.ones(len(key), bool)
    first_of_kind[1:] = (key[1:] != key[:-1]) | (pair_poly[1:] != pair_poly[:-1])
    diag_poly = pair_poly[first_of_kind]
    diag_low, diag_high = np.divmod(key[first_of_kind], vertex_span)
    poly_rank = np.searchsorted(ngon_polys, diag_poly)
    first_of_poly = np.searchsorted(diag_poly, diag_poly, side="left")
    rank = np.arange(len(diag_poly)) - first_of_poly
    ok = rank < sizes[poly_rank] - 3
    slot = offsets[poly_rank] + sizes[poly_rank] + 2 * rank
    ngon_corners[slot[ok]] = diag_low[ok]
    ngon_corners[slot[ok] + 1] = diag_high[ok]
    return ngon_corners, offsets[np.searchsorted(ngon_polys, tri_polygons)]


def _face_vertices(vertex_count: int, corners: np.ndarray) -> np.ndarray | None:
    """Mask of the vertices some drawn face uses, or None when that is all of
    them (the common case: no loose vertices)."""
    used = np.zeros(vertex_count, dtype=bool)
    used[corners] = True
    return None if used.all() else used


def _recentre(
    positions: np.ndarray,
    drawable_vertex: np.ndarray | None,
    columns: np.ndarray | None = None,
    face_vertex: np.ndarray | None = None,
):
    """(local float32, centre, bounds_min, bounds_max).

    Bounds and centre cover the drawable vertices that drawn faces use
    (``drawable_vertex`` / ``face_vertex`` None: all of them): a loose vertex
    far away must neither move the centre (the faces would lose float32
    precision) nor widen the bounds used for culling (see _centre_of)."""
    if drawable_vertex is None and face_vertex is None:
        if len(positions):
            # Reductions over an (N, 3) array's short axis are slow in numpy:
            # reduce each contiguous column of the transposed copy instead.
            columns = np.ascontiguousarray(positions.T) if columns is None else columns
            bounds_min = np.array([c.min() for c in columns], dtype=np.float64)
            bounds_max = np.array([c.max() for c in columns], dtype=np.float64)
        else:
            bounds_min = bounds_max = np.zeros(3)
        centre = _centre_of(bounds_min, bounds_max)
        local = np.subtract(positions, centre.astype(np.float32))
        return local, centre, bounds_min, bounds_max
    counted = (
        drawable_vertex
        if face_vertex is None
        else (face_vertex if drawable_vertex is None else drawable_vertex & face_vertex)
    )
    if not counted.any():
        zero = np.zeros(3)
        return np.zeros_like(positions), zero, zero.copy(), zero.copy()
    bounds_min = positions[counted].min(axis=0).astype(np.float64)
    bounds_max = positions[counted].max(axis=0).astype(np.float64)
    centre = _centre_of(bounds_min, bounds_max)
    local = np.subtract(positions, centre.astype(np.float32))
    if drawable_vertex is not None:
        local[~drawable_vertex] = 0.0
    return local, centre, bounds_min, bounds_max


def _centre_of(bounds_min: np.ndarray, bounds_max: np.ndarray) -> np.ndarray:
    """(3,) float64, a float32 value per axis: where the positions are
    re-centred, chosen so that no position rounds.

    Re-centring wins precision where a mesh lies far from its origin: the
    float64 matrix takes the large offset, and the float32 products on the
    GPU see only the small local coordinates. But a position less the
    centre is a float32 subtraction, exact only where the position lies
    within a factor of two of the centre (Sterbenz's lemma); elsewhere it
    rounds to the spacing of the centre's size. That moved the surface of
    a mesh whose bounds reach far past its origin (one vertex 40 units
    away, the rest near the camera) by more than the viewport overlay's
    depth bias from Blender's own depth of the same float32 positions, and
    the overlay hid its wire there. So on each axis the centre is the
    middle of the bounds where that middle keeps every position within a
    factor of two of it (the bounds on one side of 0, the far end at most
    three times the near one), and 0 otherwise: the bounds then reach the
    origin or nearly, so the positions themselves are no larger than the
    mesh and re-centring had nothing to win. The positions are then
    Blender's own, exactly, on every axis. A float32 centre keeps the
    subtraction one float32 operation (a float64 one made every vertex a
    cast, a subtraction and a cast back: 10 of 60 ms of a 1M-triangle
    extraction). The bounds are exact in float32: min and max round
    nothing."""
    middle = (0.5 * (bounds_min + bounds_max)).astype(np.float32).astype(np.float64)
    # Sterbenz on [lo, hi] (both of the middle's sign): |middle| / 2 <= |p| <= 2 |middle|.
    near, far = np.minimum(np.abs(bounds_min), np.abs(bounds_max)), np.maximum(np.abs(bounds_min), np.abs(bounds_max))
    exact = (bounds_min * bounds_max > 0.0) & (0.5 * np.abs(middle) <= near) & (far <= 2.0 * np.abs(middle))
    return np.where(exact, middle, 0.0)


# A vertex with a coordinate of magnitude 2**64 (about 1.8e19) or more is
# not drawn, as if it were NaN (image model §2.1): float32, in which Blender
# and the GPU compute, overflows when it squares such a coordinate (a
# length, a normal), and near 3.4e38 its projection overflows where the
# float64 reference's would not. No real scene comes near it; a curve point
# set to inf does (Blender stores it as 3.4e38).
COORDINATE_LIMIT = 2.0**64


def drawable(values: np.ndarray, axis: int) -> np.ndarray:
    """Where every value along ``axis`` is finite and below
    COORDINATE_LIMIT in magnitude (NaN compares False)."""
    with np.errstate(invalid="ignore"):
        return (np.abs(values) < COORDINATE_LIMIT).all(axis=axis)


def drawable_vertices(positions: np.ndarray) -> np.ndarray | None:
    """None when every vertex is drawable (finite, every coordinate below
    COORDINATE_LIMIT in magnitude), else the per-vertex mask. One float32
    dot product of the coordinates with themselves answers the common case:
    when it is finite no square overflowed, so every coordinate is below
    the limit (NaN and Inf propagate; a sum that overflows only sends us
    to the exact check). It is about 9x cheaper than a float64 sum."""
    flat = np.ascontiguousarray(positions, dtype=np.float32).reshape(-1)
    with np.errstate(invalid="ignore", over="ignore"):  # Inf * 0 and overflow are expected here
        if np.isfinite(np.dot(flat, flat)):
            return None
    mask = drawable(positions, axis=1)
    return None if mask.all() else mask


def _drawable_faces(drawable_vertex: np.ndarray, corner_vert: np.ndarray, loop_start: np.ndarray) -> np.ndarray:
    """Per face: True when every corner's vertex is drawable (drawable_vertices)."""
    ok = np.ones(len(loop_start), dtype=bool)
    bad_corners = np.flatnonzero(~drawable_vertex[corner_vert])
    if len(bad_corners):
        order = np.argsort(loop_start, kind="stable")
        # The face of a corner: the last face starting at or before it.
        ok[order[np.searchsorted(loop_start[order], bad_corners, side="right") - 1]] = False
    return ok


def without_dropped_faces(face_normals: np.ndarray, positions: np.ndarray, corner_vert, face_starts) -> np.ndarray:
    """``face_normals`` (F, 3) with NaN rows for the faces with a
    corner that is not drawable (drawable_vertices): such a face is not
    drawn (image model §2.1), so it has no normal, and the edge angle hides
    no edge beside it (§3.4). ``face_normals`` itself where every vertex is
    drawable."""
    drawable_vertex = drawable_vertices(positions)
    if drawable_vertex is None:
        return face_normals
    normals = np.array(face_normals, np.float32)
    normals[~_drawable_faces(drawable_vertex, np.asarray(corner_vert), np.asarray(face_starts))] = np.nan
    return normals


def _degenerate_count(triangles: np.ndarray) -> int:
    """Triangles that use one vertex twice (corrupt faces such as (0, 1, 1, 2))."""
    a, b, c = triangles[:, 0], triangles[:, 1], triangles[:, 2]
    return int(np.count_nonzero((a == b) | (b == c) | (c == a)))


def build_arrays(
    positions: np.ndarray,
    corner_vert: np.ndarray,
    loop_start: np.ndarray,
    loop_total: np.ndarray,
    tri_loops: np.ndarray,
    tri_polygons: np.ndarray,
) -> MeshArrays:
    """Pure-numpy part of extraction from Blender's own triangles (testable
    without Blender; the reference for :func:`build_arrays_fast`)."""
    positions = np.asarray(positions, dtype=np.float32).reshape(-1, 3)
    _check_vertex_count(positions)
    corner_vert = np.asarray(corner_vert, dtype=np.int32)
    loop_start = np.asarray(loop_start, dtype=np.int32)
    loop_total = np.asarray(loop_total, dtype=np.int32)
    tri_loops = np.asarray(tri_loops, dtype=np.int32).reshape(-1, 3)
    tri_polygons = np.asarray(tri_polygons, dtype=np.int32)

    # A vertex at NaN/Inf (or past COORDINATE_LIMIT) cannot be projected:
    # drop every triangle of each face that uses it (the whole face: a kept
    # triangle of it would draw edges to a corner that has no position) and
    # keep its bounds out of the centre, rather than poison the image.
    drawable_vertex = drawable_vertices(positions)
    dropped = 0
    if drawable_vertex is not None:
        keep = _drawable_faces(drawable_vertex, corner_vert, loop_start)[tri_polygons]
        dropped = int((~keep).sum())
        tri_loops, tri_polygons = tri_loops[keep], tri_polygons[keep]

    triangles, real, is_quad = _triangles_from_loops(tri_loops, tri_polygons, loop_start, loop_total, corner_vert)
    flags = _edge_flags(real, is_quad)

    ngon_corners = np.zeros(0, dtype=np.int32)
    is_ngon_tri = loop_total[tri_polygons] > 4
    if is_ngon_tri.any():
        ngon_corners, block_start = _pack_ngons(
            triangles[is_ngon_tri, :3],
            real[:, is_ngon_tri].T,
            tri_polygons[is_ngon_tri],
            loop_start,
            loop_total,
            corner_vert,
        )
        triangles[is_ngon_tri, 3] = block_start
        flags[is_ngon_tri] |= IS_NGON | (loop_total[tri_polygons[is_ngon_tri]] << NGON_SHIFT)

    face_vertex = _face_vertices(len(positions), triangles[:, :3].ravel())
    local, centre, bounds_min, bounds_max = _recentre(positions, drawable_vertex, face_vertex=face_vertex)
    return MeshArrays(
        local,
        centre,
        triangles,
        flags,
        tri_polygons.copy(),
        bounds_min,
        bounds_max,
        dropped,
        ngon_corners,
        degenerate_triangles=_degenerate_count(triangles),
    )


# ---------------------------------------------------------------------------
# Fast path: Blender's quad split rule in numpy.

# A quad is "undecided" when |dot| of the flip test is below this fraction of
# its magnitude: there float32 rounding (or a compiler's FMA contraction in
# Blender's build) could tip Blender's answer either way, so Blender is asked.
# Exactly degenerate quads (zero-area halves, dot == 0) land here too.
QUAD_UNDECIDED = 1.0e-5


def quad_flip(positions: np.ndarray, quads: np.ndarray, columns: np.ndarray | None = None):
    """Blender's quad split test for (Q, 4) vertex ids: (flip, undecided).

    Blender (``mesh_calc_tessellation_for_face_impl``, mesh_tessellate.cc)
    splits quad (0, 1, 2, 3) into (0, 1, 2) + (0, 2, 3), unless
    ``is_quad_flip_v3_first_third_fast`` says corners 1 and 3 lie on the same
    side of diagonal 0-2 (the quad folds over it), then (0, 1, 3) + (1, 2, 3):

        d12 = v2 - v1; d13 = v3 - v1; d14 = v4 - v1
        flip = dot(cross(d12, d13), cross(d14, d13)) > 0

    evaluated here in float32 in the same operation order, so the answer is
    bit-identical wherever Blender's build does not contract to FMA; quads
    within QUAD_UNDECIDED of the threshold are flagged for Blender to settle.
    ``columns`` is ``positions.T`` made contiguous (1-D gathers per axis are
    several times faster than gathering (N, 3) rows)."""
    with np.errstate(invalid="ignore", over="ignore"):  # NaN/Inf vertices: see build_arrays
        return _quad_flip(positions, quads, columns)


def _quad_flip(positions, quads, columns):
    if columns is None:
        columns = np.ascontiguousarray(np.asarray(positions, dtype=np.float32).T)
    i1, i2, i3, i4 = (np.ascontiguousarray(quads[:, k]) for k in range(4))
    d12, d13, d14 = [], [], []
    for axis in columns:
        v1 = axis.take(i1)
        d12.append(axis.take(i2) - v1)
        d13.append(axis.take(i3) - v1)
        d14.append(axis.take(i4) - v1)
    x12, y12, z12 = d12
    x13, y13, z13 = d13
    x14, y14, z14 = d14
    # cross_v3_v3v3(r, a, b): r = (a1 b2 - a2 b1, a2 b0 - a0 b2, a0 b1 - a1 b0)
    ax = y12 * z13 - z12 * y13
    ay = z12 * x13 - x12 * z13
    az = x12 * y13 - y12 * x13
    bx = y14 * z13 - z14 * y13
    by = z14 * x13 - x14 * z13
    bz = x14 * y13 - y14 * x13
    dot = ax * bx
    dot += ay * by  # dot_v3v3: left to right
    dot += az * bz
    flip = dot > np.float32(0.0)
    # Undecided: |dot| <= eps |d12| |d13|^2 |d14|, the size of its products.
    n12 = x12 * x12 + y12 * y12 + z12 * z12
    n14 = x14 * x14 + y14 * y14 + z14 * z14
    n13 = x13 * x13 + y13 * y13 + z13 * z13
    n12 *= n14
    np.sqrt(n12, out=n12)
    n12 *= n13
    n12 *= np.float32(QUAD_UNDECIDED)
    undecided = np.abs(dot) <= n12
    return flip, undecided


def ngons_flat(positions: np.ndarray, outlines) -> bool:
    """Whether every n-gon of ``outlines`` (MeshArrays.ngon_outlines) lies
    in one plane, up to the rounding of float32 coordinates: each corner
    within a millionth of the n-gon's size and distance from the origin of
    the plane through its centroid normal to its Newell normal. The
    projection of such a face folds nowhere (only a plane seen edge-on,
    where it is no wider than that rounding); its triangles' windows still
    overlap where its outline crosses itself (ngon_triangles_overlap). A
    face with no area is not flat."""
    corners, starts = outlines
    if not len(starts):
        return True
    points = np.asarray(positions, np.float64)[corners, :3]
    sizes = np.diff(np.append(starts, len(corners)))
    # Each corner's next one round its face.
    following = np.arange(1, len(corners) + 1)
    following[starts + sizes - 1] = starts
    after = points[following]
    normal = np.add.reduceat(np.cross(points, after), starts, axis=0)  # Newell's (twice the area vector)
    length = np.linalg.norm(normal, axis=1)
    if not (length > 0.0).all():
        return False
    normal /= length[:, None]
    centre = np.add.reduceat(points, starts, axis=0) / sizes[:, None]
    offset = points - np.repeat(centre, sizes, axis=0)
    distance = np.abs(np.einsum("ij,ij->i", offset, np.repeat(normal, sizes, axis=0)))
    scale = np.maximum.reduceat(np.linalg.norm(offset, axis=1), starts) + np.abs(centre).max(axis=1)
    return bool((np.maximum.reduceat(distance, starts) <= 1e-6 * scale).all())


def ngon_triangles_overlap(positions: np.ndarray, triangles: np.ndarray, triangle_polygons: np.ndarray) -> bool:
    """Whether the triangles of some n-gon can overlap on screen: they do
    not all face one way in one plane, so that the sum of their areas
    exceeds the area of their sum (a face that is not flat, or a flat one
    whose outline crosses itself, which Blender still splits into triangles
    that lie on one another). ``triangles``: (T, >= 3) corner vertex ids in
    Blender's order, where each polygon's triangles are consecutive;
    ``triangle_polygons``: (T,) their polygons. An n-gon whose triangles
    all face one way in one plane projects without folding (a plane seen
    edge-on is no wider than rounding)."""
    polygons = np.asarray(triangle_polygons, np.int64)
    if not len(polygons):
        return False
    starts = np.flatnonzero(np.r_[True, polygons[1:] != polygons[:-1]])
    counts = np.diff(np.r_[starts, len(polygons)])
    ngon = counts >= 3
    if not ngon.any():
        return False
    sizes = counts[ngon]
    firsts = np.r_[0, np.cumsum(sizes)[:-1]]
    rows = np.repeat(starts[ngon] - firsts, sizes) + np.arange(int(sizes.sum()))
    corners = np.asarray(triangles)[rows, :3].astype(np.int64)
    points = np.asarray(positions, np.float64)[:, :3]
    a, b, c = points[corners[:, 0]], points[corners[:, 1]], points[corners[:, 2]]
    area = np.cross(b - a, c - a)
    apart = np.add.reduceat(np.linalg.norm(area, axis=1), firsts)
    together = np.linalg.norm(np.add.reduceat(area, firsts, axis=0), axis=1)
    return bool((apart > together * (1.0 + 1e-6) + 1e-30).any())


def build_arrays_fast(
    positions: np.ndarray,
    corner_vert: np.ndarray,
    face_offsets: np.ndarray,
    blender_tris: Callable[[np.ndarray], np.ndarray] | None = None,
) -> MeshArrays:
    """Same result as :func:`build_arrays` on Blender's triangles, with tris
    and quads triangulated here.

    ``blender_tris(tri_indices) -> (N, 3) corner ids`` returns Blender's own
    triangles by index; it is asked for n-gon triangles and undecided quads
    only (and is only needed when the mesh has those)."""
    positions = np.asarray(positions, dtype=np.float32).reshape(-1, 3)
    _check_vertex_count(positions)
    corner_vert = np.asarray(corner_vert, dtype=np.int32)
    offsets = np.asarray(face_offsets, dtype=np.int32)
    face_count = len(offsets) - 1
    sizes = np.diff(offsets)
    loop_start = offsets[:-1]
    # Blender stores a face's triangles at poly_to_tri_count(i, start) = start - 2 i.
    tri_start = loop_start - 2 * np.arange(face_count, dtype=np.int32)
    tri_count = int(offsets[-1]) - 2 * face_count

    def ask_blender(tri_indices):
        if blender_tris is None:
            raise ValueError("this mesh needs Blender's triangulation (n-gons or undecided quads)")
        return np.asarray(blender_tris(tri_indices), dtype=np.int32).reshape(-1, 3)

    drawable_vertex = drawable_vertices(positions)
    all_quads = face_count > 0 and tri_count == 2 * face_count and int(sizes.min()) == 4
    if all_quads:
        quad_faces = None
        quads = corner_vert.reshape(face_count, 4)
        quad_loop_start, quad_tri_start = loop_start, tri_start
    else:
        quad_faces = np.flatnonzero(sizes == 4)
        quad_loop_start = loop_start[quad_faces]
        quad_tri_start = tri_start[quad_faces]
        quads = corner_vert[quad_loop_start[:, None] + np.arange(4, dtype=np.int32)]
    tri_faces = None if all_quads else np.flatnonzero(sizes == 3)
    ngon_faces = None if all_quads else np.flatnonzero(sizes > 4)

    columns = np.ascontiguousarray(positions.T)  # (3, V): see quad_flip
    flip, undecided = quad_flip(positions, quads, columns) if len(quads) else (np.zeros(0, bool), np.zeros(0, bool))
    undecided = np.flatnonzero(undecided)
    if len(undecided):
        # Blender's first triangle of a flipped quad is (0, 1, 3).
        first = ask_blender(quad_tri_start[undecided])
        flip[undecided] = first[:, 2] == quad_loop_start[undecided] + 3

    if drawable_vertex is not None:
        # Rare: hand the full triangle list to the reference path, which
        # drops triangles with corners that are not drawable and repacks n-gons.
        tri_loops = np.empty((tri_count, 3), dtype=np.int32)
        ql = quad_loop_start[:, None] + np.where(flip[:, None], [[0, 1, 3]], [[0, 1, 2]]).astype(np.int32)
        tri_loops[quad_tri_start] = ql
        tri_loops[quad_tri_start + 1] = quad_loop_start[:, None] + np.where(
            flip[:, None], [[1, 2, 3]], [[0, 2, 3]]
        ).astype(np.int32)
        if tri_faces is not None and len(tri_faces):
            tri_loops[tri_start[tri_faces]] = loop_start[tri_faces, None] + np.arange(3, dtype=np.int32)
        if ngon_faces is not None and len(ngon_faces):
            rows = _ngon_tri_rows(tri_start, sizes, ngon_faces)
            tri_loops[rows] = ask_blender(rows)
        tri_polygons = np.repeat(np.arange(face_count, dtype=np.int32), sizes - 2)
        return build_arrays(positions, corner_vert, loop_start, sizes, tri_loops, tri_polygons)

    triangles = np.empty((tri_count, 4), dtype=np.int32)
    flags = np.empty(tri_count, dtype=np.int32)
    # Quad rows, diagonal as edge 2 and the 4th corner in column 3 (what
    # build_arrays' rotation gives for Blender's triangles):
    #   not flipped: (0, 1, 2 | 3) and (2, 3, 0 | 1)
    #   flipped:     (3, 0, 1 | 2) and (1, 2, 3 | 0)
    q = [quads[:, k] for k in range(4)]
    order_first = ((0, 1, 2, 3), (3, 0, 1, 2))  # (not flipped, flipped)
    order_second = ((2, 3, 0, 1), (1, 2, 3, 0))

    def fill_quad_rows(rows_first, rows_second):
        # One np.where per output column: no (Q, 4) temporaries.
        for k in range(4):
            rows_first[:, k] = np.where(flip, q[order_first[1][k]], q[order_first[0][k]])
            rows_second[:, k] = np.where(flip, q[order_second[1][k]], q[order_second[0][k]])

    quad_flags = EDGE0_REAL | EDGE1_REAL | HAS_QUAD_CORNER
    ngon_triangles = None  # (MeshArrays.ngon_triangles)
    if all_quads:
        pairs = triangles.reshape(face_count, 2, 4)
        fill_quad_rows(pairs[:, 0], pairs[:, 1])
        flags[:] = quad_flags
        tri_polygons = np.repeat(np.arange(face_count, dtype=np.int32), 2)
        ngon_corners = np.zeros(0, dtype=np.int32)
    else:
        first_rows = np.empty((len(quads), 4), dtype=np.int32)
        second_rows = np.empty((len(quads), 4), dtype=np.int32)
        fill_quad_rows(first_rows, second_rows)
        triangles[quad_tri_start] = first_rows
        triangles[quad_tri_start + 1] = second_rows
        flags[quad_tri_start] = quad_flags
        flags[quad_tri_start + 1] = quad_flags
        tri_polygons = np.repeat(np.arange(face_count, dtype=np.int32), sizes - 2)
        if len(tri_faces):
            rows = tri_start[tri_faces]
            corners = corner_vert[loop_start[tri_faces, None] + np.arange(3, dtype=np.int32)]
            triangles[rows, :3] = corners
            triangles[rows, 3] = corners[:, 0]
            flags[rows] = EDGE0_REAL | EDGE1_REAL | EDGE2_REAL
        ngon_corners = np.zeros(0, dtype=np.int32)
        if len(ngon_faces):
            rows = _ngon_tri_rows(tri_start, sizes, ngon_faces)
            polys = tri_polygons[rows]
            ngon_triangles = (rows, ask_blender(rows), polys)
            ngon_tris, real, is_quad = _triangles_from_loops(ngon_triangles[1], polys, loop_start, sizes, corner_vert)
            ngon_flags = _edge_flags(real, is_quad)
            ngon_corners, block_start = _pack_ngons(ngon_tris[:, :3], real.T, polys, loop_start, sizes, corner_vert)
            ngon_tris[:, 3] = block_start
            ngon_flags |= IS_NGON | (sizes[polys] << NGON_SHIFT)
            triangles[rows] = ngon_tris
            flags[rows] = ngon_flags

    # Every corner of a face is a corner of one of its triangles: the same
    # vertex set as build_arrays' triangles[:, :3], read from fewer entries.
    face_vertex = _face_vertices(len(positions), corner_vert)
    local, centre, bounds_min, bounds_max = _recentre(positions, None, columns, face_vertex)
    arrays = MeshArrays(
        local,
        centre,
        triangles,
        flags,
        tri_polygons,
        bounds_min,
        bounds_max,
        0,
        ngon_corners,
        degenerate_triangles=_degenerate_count(triangles),
    )
    arrays.quads, arrays.quad_flip, arrays.source_positions = quads, flip, positions
    arrays.face_offsets_crc = zlib.crc32(memoryview(np.ascontiguousarray(offsets)).cast("B"))
    arrays.ngon_triangles = ngon_triangles
    return arrays


def reposition(
    previous,
    positions: np.ndarray,
    corner_vert: np.ndarray,
    face_offsets: np.ndarray,
    blender_tris: Callable[[np.ndarray], np.ndarray] | None = None,
):
    """(local positions, centre, bounds_min, bounds_max, source positions)
    for new vertex positions of a mesh whose faces are unchanged, or None when the new
    positions change more than positions: a quad split differently, an
    n-gon that Blender now triangulates differently (asked of
    ``blender_tris``; without it, a mesh with n-gons is refused), a
    non-finite vertex, other face sizes. A moved quad too close to call (a
    degenerate one stays so in every frame) is settled by ``blender_tris``
    as in :func:`build_arrays_fast`; without it, None.

    ``previous`` is what the last extraction kept (``quads``, ``quad_flip``,
    ``face_offsets_crc``, ``source_positions``, ``ngon_triangles``,
    ``centre`` and ``mesh_bounds``); the caller has checked that the
    vertex, corner and face counts and the corner vertices are the same."""
    quads, flip = getattr(previous, "quads", None), getattr(previous, "quad_flip", None)
    if quads is None or flip is None or previous.face_offsets_crc is None:
        return None
    positions = np.asarray(positions, dtype=np.float32).reshape(-1, 3)
    if len(positions) != previous.vertex_count or drawable_vertices(positions) is not None:
        return None
    offsets = np.ascontiguousarray(face_offsets, dtype=np.int32)
    if zlib.crc32(memoryview(offsets).cast("B")) != previous.face_offsets_crc:
        return None
    old = getattr(previous, "source_positions", None)
    if old is None or old.shape != positions.shape:
        return None
    # Column-wise ORs and flat index arithmetic instead of reductions over
    # the short axis of (N, 3) / (Q, 4) arrays, which numpy does slowly.
    changed = (positions != old).view(np.uint8)
    moved = (changed[:, 0] | changed[:, 1] | changed[:, 2]).view(bool)
    moved_count = int(np.count_nonzero(moved))
    everything = moved_count == len(positions)  # a deformation moves every vertex
    if len(quads) and moved_count:
        # Only quads with a moved corner can split differently.
        if everything:
            touched, touched_quads = None, quads
        else:
            # flatnonzero is sorted: made unique without sorting again.
            touched = _sorted_unique(np.flatnonzero(moved[quads.ravel()]) // 4)
            touched_quads = quads[touched]
        if len(touched_quads):
            if 4 * len(touched_quads) >= len(positions):
                # Many quads: gather from all positions (one transposed copy).
                new_flip, undecided = quad_flip(positions, touched_quads)
            else:
                # A local edit: the few vertices involved, renumbered.
                ids, corners = np.unique(touched_quads, return_inverse=True)
                new_flip, undecided = quad_flip(positions[ids], corners.reshape(-1, 4).astype(np.int32))
            if undecided.any():
                if blender_tris is None:
                    return None
                asked = np.flatnonzero(undecided)
                quad_index = asked if touched is None else touched[asked]
                face = np.flatnonzero(np.diff(offsets) == 4)[quad_index]  # quads are the 4-corner faces in order
                loop_start = offsets[face]
                # Blender's first triangle of a flipped quad is (0, 1, 3).
                first = np.asarray(blender_tris(loop_start - 2 * face), dtype=np.int32).reshape(-1, 3)
                new_flip[asked] = first[:, 2] == loop_start + 3
            if not np.array_equal(new_flip, flip if touched is None else flip[touched]):
                return None
    ngon_triangles = getattr(previous, "ngon_triangles", None)
    if ngon_triangles is not None and moved_count:
        # An n-gon's triangulation follows its own corners' positions: the
        # triangles hold while Blender splits every n-gon with a moved
        # corner as before (asked for those alone: reading every triangle
        # of a 116k-triangle mesh was half of a local edit's redraw).
        rows, corners, faces = ngon_triangles
        if not everything:
            moved_corner = moved.take(np.asarray(corner_vert))
            moved_face = np.logical_or.reduceat(moved_corner, offsets[:-1])
            near = moved_face.take(faces)
            rows, corners = rows[near], corners[near]
        if len(rows) and (
            blender_tris is None or not np.array_equal(np.asarray(blender_tris(rows)).reshape(-1, 3), corners)
        ):
            return None
    # The centre stays where it was (any nearby centre keeps float32
    # precision); the bounds grow to take in the moved vertices, never
    # shrink (culling only needs them to enclose the mesh).
    centre = previous.centre
    bounds_min, bounds_max = previous.mesh_bounds
    if moved_count:
        columns = np.ascontiguousarray((positions if everything else positions[moved]).T)
        bounds_min = np.minimum(bounds_min, [float(c.min()) for c in columns])
        bounds_max = np.maximum(bounds_max, [float(c.max()) for c in columns])
    local = np.subtract(positions, np.asarray(centre).astype(np.float32))  # (a float32 centre: _centre_of)
    return local, centre, bounds_min, bounds_max, positions


def boxes_of_triangle_runs(positions: np.ndarray, corner_vertices: np.ndarray, starts: np.ndarray):
    """(low, high) (R, 3) float32: the box of the corners of each run of
    consecutive triangles, ``corner_vertices`` (3, T) intp a contiguous row
    per corner, the runs starting at ``starts`` (ascending, from 0), at
    ``positions`` (N, >= 3)."""
    low = np.empty((len(starts), 3), np.float32)
    high = np.empty((len(starts), 3), np.float32)
    for axis in range(3 if len(starts) else 0):
        # (Gathers from a contiguous copy of the column: numpy would copy
        # the strided column for every gather anyway.)
        column = np.ascontiguousarray(positions[:, axis])
        values = [column.take(vertices) for vertices in corner_vertices]
        low[:, axis] = np.minimum.reduce([np.minimum.reduceat(v, starts) for v in values])
        high[:, axis] = np.maximum.reduce([np.maximum.reduceat(v, starts) for v in values])
    return low, high


def distinct(keys: np.ndarray) -> np.ndarray:
    """np.unique(keys) by a stable sort: timsort finds the ascending runs
    already there, and keys grouped by face or region mostly ascend (a
    level-4 cage's region keys: 6x faster than np.unique's quicksort)."""
    return _sorted_unique(np.sort(keys, kind="stable"))


def _sorted_unique(ids: np.ndarray) -> np.ndarray:
    """The distinct values of an already sorted array (np.unique sorts again)."""
    if len(ids) < 2:
        return ids
    keep = np.empty(len(ids), dtype=bool)
    keep[0] = True
    np.not_equal(ids[1:], ids[:-1], out=keep[1:])
    return ids[keep]


def _ngon_tri_rows(tri_start, sizes, ngon_faces) -> np.ndarray:
    """Indices of every triangle of the given faces (in Blender's order)."""
    counts = sizes[ngon_faces] - 2
    first = np.repeat(tri_start[ngon_faces], counts)
    rank = np.arange(int(counts.sum()), dtype=np.int32) - np.repeat(np.cumsum(counts) - counts, counts).astype(np.int32)
    return first + rank


# Where the shading normals of a mesh live, so where its corner table has a
# row: per vertex (smooth shading without sharp edges or custom normals), per
# triangle (flat shading: its face's normal) or per triangle corner. The
# first two are Blender's own normals on a smaller domain: a third or less
# of the rows, no corner lookup, and what a deformation uploads again.
NORMALS_BY_VERTEX, NORMALS_BY_TRIANGLE, NORMALS_BY_CORNER = 0, 1, 2


def normals_domain(blender_domain: str, materials: np.ndarray) -> int:
    """Where a mesh's corner table has its rows (NORMALS_BY_*), from where
    Blender's normals vary (``Mesh.normals_domain``: "POINT", "FACE" or
    "CORNER") and the material index of each face. Per vertex only with a
    single material (a vertex has no material of its own)."""
    if blender_domain == "POINT" and (len(materials) == 0 or bool((materials == materials[0]).all())):
        return NORMALS_BY_VERTEX
    if blender_domain == "FACE":
        return NORMALS_BY_TRIANGLE
    return NORMALS_BY_CORNER


def attach_attribute_colors(
    arrays: MeshArrays, colors: np.ndarray, domain: str, corner_vert: np.ndarray, face_offsets: np.ndarray
) -> None:
    """Put a colour attribute's values (``colors`` (N, 4) scene-linear RGBA
    on Blender's ``domain`` "POINT" or "CORNER") into ``arrays`` as the rows
    the vertex stage reads: per vertex, or per corner of each drawn triangle
    (through :func:`corner_rows`). A colour that is not finite reads as
    black rather than poisoning the interpolation."""
    colors = np.nan_to_num(colors, nan=0.0, posinf=0.0, neginf=0.0)
    if domain == "POINT":
        if len(colors) != arrays.vertex_count:
            return
        arrays.attribute_colors, arrays.attribute_domain = colors, NORMALS_BY_VERTEX
        return
    rows = arrays.corner_rows if arrays.corner_rows is not None else corner_rows(arrays, corner_vert, face_offsets)
    table = np.zeros((len(rows), 4), np.float32)
    found = (rows >= 0) & (rows < len(colors))
    table[found] = colors[rows[found]]
    arrays.attribute_colors, arrays.attribute_domain = table, NORMALS_BY_CORNER


def normals_follow_geometry(domain: int) -> bool:
    """Whether normals on ``domain`` are a function of the positions and the
    faces alone: per face (Newell's normal) and per vertex (smooth shading
    without sharp edges or custom normals). Per corner they may also carry
    sharp edges, custom normals, or a material split (a vertex normal per
    corner; conservatively treated alike)."""
    return domain != NORMALS_BY_CORNER


def corner_table(
    arrays: MeshArrays,
    corner_vert: np.ndarray,
    face_offsets: np.ndarray,
    normals: np.ndarray,
    materials: np.ndarray,
    domain: int = NORMALS_BY_CORNER,
) -> np.ndarray:
    """(R, 4) float32: a normal and a material index per row, the rows by
    ``domain`` (NORMALS_BY_*): one per vertex (the single material), one per
    drawn triangle (its face's normal and material), or one per corner of
    each drawn triangle (the order of ``arrays.triangles``, which the vertex
    stage reads by gl_VertexID: the normal of that polygon corner). By
    corner, also keeps the corner lookup in ``arrays.corner_rows`` so that a
    mesh that only moves can refill the table from new normals (see
    :func:`fill_corner_table`)."""
    arrays.normal_domain = domain
    if domain == NORMALS_BY_CORNER:
        arrays.corner_rows = corner_rows(arrays, corner_vert, face_offsets)
    return fill_corner_table(arrays.corner_rows, arrays.triangle_polygons, normals, materials, domain)


def corner_rows(arrays: MeshArrays, corner_vert: np.ndarray, face_offsets: np.ndarray) -> np.ndarray:
    """(3T,) int32: the polygon corner (loop) of each triangle corner of
    ``arrays.triangles``, -1 where there is none. Depends on the faces and
    triangles alone, never on positions.

    A triangle row holds vertex ids, not corners: the corner is the first
    one (in corner order) of the triangle's polygon with that vertex (unique
    in any polygon that is not degenerate; a face that uses a vertex twice
    has zero-area triangles that never draw). Tris and quads compare the
    triangle's vertices with their polygon's (at most four) corners
    directly, a few vectorised comparisons where a sort of every corner took
    most of a first render's extraction; n-gon triangles look theirs up in
    the sorted (polygon, vertex) keys."""
    count = arrays.triangle_count
    if count == 0 or len(corner_vert) == 0:
        return np.full(3 * count, -1, dtype=np.int32)
    polygons = arrays.triangle_polygons.astype(np.int64)
    corner_vert = np.asarray(corner_vert)
    face_offsets = np.asarray(face_offsets, dtype=np.int64)
    vertices = arrays.triangles[:, :3]
    starts = face_offsets[polygons]
    sizes = face_offsets[polygons + 1] - starts
    corner = np.full(vertices.shape, -1, dtype=np.int64)
    last = max(len(corner_vert) - 1, 0)
    small = sizes <= 4
    for k in range(4):
        candidate = starts + k
        at_k = corner_vert[np.minimum(candidate, last)]
        match = ((k < sizes) & small)[:, None] & (at_k[:, None] == vertices) & (corner < 0)
        np.copyto(corner, candidate[:, None], where=match)
    rest = np.flatnonzero(sizes > 4)
    if len(rest):
        vertex_count = np.int64(max(arrays.vertex_count, 1))
        all_sizes = np.diff(face_offsets)
        corner_face = np.repeat(np.arange(len(all_sizes), dtype=np.int64), all_sizes)
        keys = corner_face * vertex_count + corner_vert.astype(np.int64)
        order = np.argsort(keys, kind="stable")
        sorted_keys = keys[order]
        wanted = (polygons[rest, None] * vertex_count + vertices[rest].astype(np.int64)).reshape(-1)
        at = np.minimum(np.searchsorted(sorted_keys, wanted), len(sorted_keys) - 1)
        corner[rest] = np.where(sorted_keys[at] == wanted, order[at], -1).reshape(-1, 3)
    return corner.reshape(-1).astype(np.int32)


def fill_corner_table(
    rows, triangle_polygons: np.ndarray, normals: np.ndarray, materials: np.ndarray, domain: int = NORMALS_BY_CORNER
) -> np.ndarray:
    """The corner table (see :func:`corner_table`) of ``domain``: by
    corner from the corner lookup ``rows`` of :func:`corner_rows` (one
    gather of the corner normals and the material index of each triangle's
    polygon); by triangle from its face; by vertex the normals themselves."""
    normals = np.asarray(normals, np.float32).reshape(-1, 3)
    if domain == NORMALS_BY_VERTEX:
        table = np.zeros((len(normals), 4), dtype=np.float32)
        table[:, :3] = normals
        table[:, 3] = np.clip(materials[0], 0, 32767) if len(materials) else 0
        return table
    if domain == NORMALS_BY_TRIANGLE:
        if len(normals) == 0 or len(triangle_polygons) == 0:
            table = np.zeros((len(triangle_polygons), 4), dtype=np.float32)
            if len(materials):
                table[:, 3] = np.clip(materials[triangle_polygons], 0, 32767)
            return table
        # A face's row (normal, material), then one gather of whole rows.
        face = np.zeros((len(normals), 4), dtype=np.float32)
        face[:, :3] = normals
        if len(materials):
            face[:, 3] = np.clip(materials, 0, 32767)
        return _take_rows(face, triangle_polygons)
    table = np.zeros((len(rows), 4), dtype=np.float32)
    if len(rows) == 0:
        return table
    count = len(triangle_polygons)
    material = materials[triangle_polygons] if len(materials) else np.zeros(count, np.int32)
    found = rows >= 0
    if found.any():
        lost = not found.all()
        padded = np.zeros((len(normals), 4), dtype=np.float32)
        padded[:, :3] = normals
        table = _take_rows(padded, np.where(found, rows, 0) if lost else rows)
        if lost:
            table[~found, :3] = 0.0
    table[:, 3] = np.repeat(np.clip(material, 0, 32767), 3)
    return table


def _take_rows(table: np.ndarray, indices: np.ndarray) -> np.ndarray:
    """``table[indices]`` for a C-contiguous (N, 4) float32 table, 2-3x
    faster: each row is gathered as one 16-byte item (a complex128 view,
    whose copy moves the bytes as they are, NaN payloads included) instead
    of four float32 elements."""
    rows = table.view(np.complex128).reshape(-1)
    return rows.take(indices).view(np.float32).reshape(-1, 4)
