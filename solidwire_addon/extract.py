"""Extraction: an evaluated Blender mesh -> GPU-ready numpy arrays.

Only bulk reads (``foreach_get``) and vectorised numpy: no per-element Python
loops. The triangles are Blender's own (``loop_triangles``), so the faces we
draw are exactly the faces Blender draws. For each triangle we record which of
its three edges are polygon boundary edges ("real") and which are diagonals
added by triangulation, and for a quad the id of its 4th corner so a fragment
can measure the distance to all four quad edges (clean corners next to a
hidden diagonal).

Corner order is rotated (never reflected, so winding and back-face culling are
unchanged) so that a quad triangle's diagonal is always edge 2 (p2 -> p0) and
its 4th corner joins p2 and p0.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

EDGE0_REAL, EDGE1_REAL, EDGE2_REAL, HAS_QUAD_CORNER, IS_NGON = 1, 2, 4, 8, 16
NGON_SHIFT = 8  # edge_flags >> NGON_SHIFT is an n-gon's corner count

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
    dropped_triangles: int = 0  # triangles skipped for non-finite vertices
    # Vertex ids of every n-gon's outline in loop order, one polygon after
    # another; an n-gon triangle's column 3 says where its polygon starts.
    ngon_corners: np.ndarray = None

    @property
    def triangle_count(self) -> int:
        return int(self.triangles.shape[0])

    @property
    def vertex_count(self) -> int:
        return int(self.positions.shape[0])

    @property
    def nbytes(self) -> int:
        return sum(a.nbytes for a in (self.positions, self.triangles, self.edge_flags, self.triangle_polygons))


class ExtractError(ValueError):
    """A mesh that cannot be drawn; the message is one line for the user."""


def _read(collection, attr: str, count: int, dtype, width: int = 1) -> np.ndarray:
    out = np.empty(count * width, dtype=dtype)
    if count:
        collection.foreach_get(attr, out)
    return out if width == 1 else out.reshape(count, width)


def read_mesh(mesh) -> dict[str, np.ndarray]:
    """Bulk-read the raw topology of a Blender mesh (evaluated or not)."""
    vertex_count = len(mesh.vertices)
    loop_count = len(mesh.loops)
    polygon_count = len(mesh.polygons)
    loop_tris = mesh.loop_triangles  # computed lazily by Blender and cached on the mesh
    tri_count = len(loop_tris)
    return {
        "positions": _read(mesh.vertices, "co", vertex_count, np.float32, 3),
        "corner_vert": _read(mesh.loops, "vertex_index", loop_count, np.int32),
        "loop_start": _read(mesh.polygons, "loop_start", polygon_count, np.int32),
        "loop_total": _read(mesh.polygons, "loop_total", polygon_count, np.int32),
        "tri_loops": _read(loop_tris, "loops", tri_count, np.int32, 3),
        "tri_polygons": _read(mesh.loop_triangle_polygons, "value", tri_count, np.int32),
    }


def build_arrays(
    positions: np.ndarray,
    corner_vert: np.ndarray,
    loop_start: np.ndarray,
    loop_total: np.ndarray,
    tri_loops: np.ndarray,
    tri_polygons: np.ndarray,
) -> MeshArrays:
    """Pure-numpy part of extraction (testable without Blender)."""
    positions = np.asarray(positions, dtype=np.float32).reshape(-1, 3)
    if positions.shape[0] >= MAX_VERTICES:
        raise ExtractError(f"mesh has {positions.shape[0]:,} vertices; SolidWire draws at most {MAX_VERTICES - 1:,} per mesh")
    tri_loops = np.asarray(tri_loops, dtype=np.int64).reshape(-1, 3)
    tri_polygons = np.asarray(tri_polygons, dtype=np.int32)

    # A vertex at NaN/Inf cannot be projected: drop the triangles that use it
    # (and keep its bounds out of the centre) rather than poison the image.
    finite_vertex = np.isfinite(positions).all(axis=1)
    dropped = 0
    if not finite_vertex.all():
        keep = finite_vertex[np.asarray(corner_vert)[tri_loops]].all(axis=1)
        dropped = int((~keep).sum())
        tri_loops, tri_polygons = tri_loops[keep], tri_polygons[keep]

    start = loop_start[tri_polygons].astype(np.int64)[:, None]
    total = loop_total[tri_polygons].astype(np.int64)[:, None]

    # Edge k of a triangle joins corner k and corner k+1 (mod 3). It is a real
    # polygon edge when the two loops are neighbours in the polygon's cycle.
    a = tri_loops
    b = np.roll(tri_loops, -1, axis=1)
    next_of_a = start + (a - start + 1) % total
    next_of_b = start + (b - start + 1) % total
    real = (b == next_of_a) | (a == next_of_b)  # (T, 3) bool

    # Quads: rotate the corners so the diagonal is edge 2, then the 4th
    # corner is the polygon's one loop this triangle does not use.
    is_quad = total[:, 0] == 4
    diag_at_0 = is_quad & ~real[:, 0]
    diag_at_1 = is_quad & ~real[:, 1]
    order = np.tile(np.arange(3), (len(a), 1))
    order[diag_at_0] = (1, 2, 0)
    order[diag_at_1] = (2, 0, 1)
    rows = np.arange(len(a))[:, None]
    tri_loops = tri_loops[rows, order]
    real = real[rows, order]
    fourth_loop = 4 * start[:, 0] + 6 - tri_loops.sum(axis=1)
    fourth_loop = np.where(is_quad, fourth_loop, tri_loops[:, 0])

    triangles = np.empty((len(a), 4), dtype=np.int32)
    triangles[:, :3] = corner_vert[tri_loops]
    triangles[:, 3] = corner_vert[fourth_loop]

    flags = (
        real[:, 0] * EDGE0_REAL + real[:, 1] * EDGE1_REAL + real[:, 2] * EDGE2_REAL + is_quad * HAS_QUAD_CORNER
    ).astype(np.int32)

    # N-gons: the fragment stage walks the polygon's whole outline and all of
    # its diagonals (see solidwire_frag.glsl), so pack, per n-gon with
    # triangles here, a block of n outline ids (loop order) followed by its
    # n - 3 diagonals as id pairs. Column 3 of an n-gon triangle says where
    # its polygon's block starts.
    ngon_corners = np.zeros(0, dtype=np.int32)
    is_ngon_tri = total[:, 0] > 4
    if is_ngon_tri.any():
        corner_vert = np.asarray(corner_vert)
        ngon_polys = np.unique(tri_polygons[is_ngon_tri])
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
        tri_ids = triangles[is_ngon_tri, :3]
        pairs = np.stack([tri_ids, np.roll(tri_ids, -1, axis=1)], axis=2)[~real[is_ngon_tri]]  # (D, 2)
        pair_poly = np.repeat(tri_polygons[is_ngon_tri], (~real[is_ngon_tri]).sum(axis=1))
        diag = np.unique(np.column_stack([pair_poly, pairs.min(axis=1), pairs.max(axis=1)]), axis=0)
        poly_rank = np.searchsorted(ngon_polys, diag[:, 0])
        first_of_poly = np.searchsorted(diag[:, 0], diag[:, 0], side="left")
        rank = np.arange(len(diag)) - first_of_poly
        ok = rank < sizes[poly_rank] - 3
        slot = offsets[poly_rank] + sizes[poly_rank] + 2 * rank
        ngon_corners[slot[ok]] = diag[ok, 1]
        ngon_corners[slot[ok] + 1] = diag[ok, 2]
        triangles[is_ngon_tri, 3] = offsets[np.searchsorted(ngon_polys, tri_polygons[is_ngon_tri])]
        flags[is_ngon_tri] |= IS_NGON | (total[is_ngon_tri, 0] << NGON_SHIFT).astype(np.int32)

    if finite_vertex.any():
        pos64 = positions.astype(np.float64)
        bounds_min = pos64[finite_vertex].min(axis=0)
        bounds_max = pos64[finite_vertex].max(axis=0)
        centre = 0.5 * (bounds_min + bounds_max)
        local = np.where(finite_vertex[:, None], pos64 - centre, 0.0).astype(np.float32)
    else:
        bounds_min = bounds_max = centre = np.zeros(3)
        local = np.zeros_like(positions)
    return MeshArrays(local, centre, triangles, flags, tri_polygons.copy(), bounds_min, bounds_max, dropped, ngon_corners)


def extract_mesh(mesh) -> MeshArrays:
    """Evaluated Blender mesh -> :class:`MeshArrays`."""
    return build_arrays(**read_mesh(mesh))
