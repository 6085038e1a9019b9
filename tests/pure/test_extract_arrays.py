"""Extraction on plain arrays, without Blender: the triangles of tris and
quads built by Blender's quad split rule equal build_arrays fed Blender's
triangles; a moved mesh's positions-only re-upload equals a full extraction
or is refused; the corner table holds each row's normal and material.
(tests/test_extract.py checks the same against Blender's own meshes.)"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from solidwire_addon.core import extract
from tests.support.mesh_arrays import assert_same_arrays


def test_build_arrays_fast_without_blender():
    """The pure-numpy core on a hand-made quad + triangle, against
    build_arrays fed the triangles Blender would make."""
    positions = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [2, 0, 0]], dtype=np.float32)
    corner_vert = np.array([0, 1, 2, 3, 1, 4, 2], dtype=np.int32)
    offsets = np.array([0, 4, 7], dtype=np.int32)
    fast = extract.build_arrays_fast(positions, corner_vert, offsets)
    reference = extract.build_arrays(
        positions, corner_vert, offsets[:-1], np.diff(offsets), [[0, 1, 2], [0, 2, 3], [4, 5, 6]], [0, 0, 1]
    )
    assert_same_arrays(fast, reference)
    # Quad diagonal is edge 2 and the 4th corner sits in column 3.
    np.testing.assert_array_equal(fast.triangles[:2], [[0, 1, 2, 3], [2, 3, 0, 1]])
    assert list(fast.edge_flags) == [11, 11, 7]


def test_flipped_quad_without_blender():
    # Corners 1 and 3 on the same side of diagonal 0-2 (concave at corner 3):
    # Blender splits along 1-3.
    positions = np.array([[0, 0, 0], [2, 0, 0], [1, 1, 0], [0.4, 0.1, 0]], dtype=np.float32)
    fast = extract.build_arrays_fast(positions, np.arange(4, dtype=np.int32), np.array([0, 4], dtype=np.int32))
    reference = extract.build_arrays(positions, np.arange(4), [0], [4], [[0, 1, 3], [1, 2, 3]], [0, 0])
    assert_same_arrays(fast, reference)
    np.testing.assert_array_equal(fast.triangles, [[3, 0, 1, 2], [1, 2, 3, 0]])


def _quad_grid(n: int = 12, seed: int = 1):
    rng = np.random.default_rng(seed)
    xs, ys = np.meshgrid(np.arange(n + 1, dtype=np.float32), np.arange(n + 1, dtype=np.float32))
    positions = np.stack([xs.ravel(), ys.ravel(), rng.uniform(-0.05, 0.05, (n + 1) ** 2)], axis=1).astype(np.float32)
    faces = [
        (j * (n + 1) + i, j * (n + 1) + i + 1, (j + 1) * (n + 1) + i + 1, (j + 1) * (n + 1) + i)
        for j in range(n)
        for i in range(n)
    ]
    corner_vert = np.array(faces, dtype=np.int32).ravel()
    offsets = np.arange(0, len(corner_vert) + 1, 4, dtype=np.int32)
    return positions, corner_vert, offsets


def test_reposition_is_a_full_extraction_of_the_moved_mesh():
    """Positions-only re-upload: same triangles, and the same world positions
    as extracting the moved mesh from scratch (bounds may only grow)."""
    positions, corner_vert, offsets = _quad_grid()
    arrays = extract.build_arrays_fast(positions, corner_vert, offsets)
    moved = positions.copy()
    moved[17] += (0.02, -0.01, 0.3)
    moved[40, 2] -= 0.2
    result = extract.reposition(arrays, moved, corner_vert, offsets)
    assert result is not None
    local, centre, bounds_min, bounds_max, source = result
    full = extract.build_arrays_fast(moved, corner_vert, offsets)
    np.testing.assert_array_equal(full.triangles, arrays.triangles)
    np.testing.assert_array_equal(full.edge_flags, arrays.edge_flags)
    np.testing.assert_allclose(local + centre, full.positions + full.centre, atol=1e-5)
    assert (bounds_min <= full.bounds_min).all() and (bounds_max >= full.bounds_max).all()
    assert np.shares_memory(source, moved)  # kept as read, no copy


def _bend(positions: np.ndarray, angle: float) -> np.ndarray:
    """Every vertex moved: the grid rolled about the y axis (a deformation)."""
    radius = float(positions[:, 0].max()) / angle
    theta = positions[:, 0] / radius
    r = radius - positions[:, 2]
    return np.stack([r * np.sin(theta), positions[:, 1] + 0.25, radius - r * np.cos(theta)], axis=1).astype(np.float32)


def test_reposition_of_a_deformation_is_a_full_extraction():
    """Every vertex moved (the path a deforming animation takes): same
    triangles, the world positions of a fresh extraction; a single quad
    folded among them still refuses."""
    positions, corner_vert, offsets = _quad_grid()
    arrays = extract.build_arrays_fast(positions, corner_vert, offsets)
    bent = _bend(positions, 1.5)
    assert (bent != positions).any(axis=1).all()
    result = extract.reposition(arrays, bent, corner_vert, offsets)
    assert result is not None
    local, centre, bounds_min, bounds_max, _source = result
    full = extract.build_arrays_fast(bent, corner_vert, offsets)
    np.testing.assert_array_equal(full.triangles, arrays.triangles)
    np.testing.assert_allclose(local + centre, full.positions + full.centre, atol=1e-5)
    assert (bounds_min <= full.bounds_min).all() and (bounds_max >= full.bounds_max).all()
    q = arrays.quads[40]
    bent[q[1]] = 0.9 * bent[q[3]] + 0.1 * bent[q[0]]
    assert extract.reposition(arrays, bent, corner_vert, offsets) is None


def test_reposition_asks_blender_about_a_quad_too_close_to_call():
    """A degenerate quad (an edge collapsed: two corners on one spot) is
    undecided in every frame; its split comes from Blender's triangles, as at
    extraction, instead of sending the whole mesh to a full extraction."""
    positions, corner_vert, offsets = _quad_grid()
    q = corner_vert[4 * 30 : 4 * 31]
    positions[q[2]] = positions[q[1]]

    def blender_tris(flipped):
        def lookup(tri_indices):  # the first triangle of each asked quad, as Blender splits it
            face = np.asarray(tri_indices) // 2
            corners = [0, 1, 3] if flipped else [0, 1, 2]
            return 4 * face[:, None] + np.array(corners)

        return lookup

    arrays = extract.build_arrays_fast(positions, corner_vert, offsets, blender_tris=blender_tris(False))
    bent = _bend(positions, 1.5)
    assert extract.quad_flip(bent, arrays.quads)[1][30]  # still undecided
    assert extract.reposition(arrays, bent, corner_vert, offsets) is None
    assert extract.reposition(arrays, bent, corner_vert, offsets, blender_tris(True)) is None  # split changed
    result = extract.reposition(arrays, bent, corner_vert, offsets, blender_tris(False))
    assert result is not None
    local, centre = result[:2]
    full = extract.build_arrays_fast(bent, corner_vert, offsets, blender_tris=blender_tris(False))
    np.testing.assert_array_equal(full.triangles, arrays.triangles)
    np.testing.assert_allclose(local + centre, full.positions + full.centre, atol=1e-5)


def test_corner_table_refilled_from_new_normals_equals_a_fresh_one():
    """The corner lookup kept at extraction refills the table of a moved mesh
    exactly as a fresh corner_table does (normals per loop, materials per face)."""
    positions, corner_vert, offsets = _quad_grid(6)
    arrays = extract.build_arrays_fast(positions, corner_vert, offsets)
    rng = np.random.default_rng(4)
    materials = rng.integers(0, 3, len(offsets) - 1).astype(np.int32)
    first = extract.corner_table(
        arrays, corner_vert, offsets, rng.normal(size=(len(corner_vert), 3)).astype(np.float32), materials
    )
    normals = rng.normal(size=(len(corner_vert), 3)).astype(np.float32)
    refilled = extract.fill_corner_table(arrays.corner_rows, arrays.triangle_polygons, normals, materials)
    fresh = extract.corner_table(
        extract.build_arrays_fast(positions, corner_vert, offsets), corner_vert, offsets, normals, materials
    )
    np.testing.assert_array_equal(refilled, fresh)
    assert not np.array_equal(refilled, first)
    # Each triangle corner carries the normal of its own polygon corner.
    rows = arrays.corner_rows.reshape(-1, 3)
    np.testing.assert_array_equal(corner_vert[rows], arrays.triangles[:, :3])


@pytest.mark.parametrize("domain", [extract.NORMALS_BY_VERTEX, extract.NORMALS_BY_TRIANGLE, extract.NORMALS_BY_CORNER])
def test_corner_table_rows_hold_their_normal_and_material(domain):
    """Every row of the corner table, by each domain, is the normal of its
    vertex / face / polygon corner and the material of its face (clamped to
    0..32767), NaN normals passed on as they are; a triangle corner with no
    polygon corner (-1) gets a zero normal."""
    rng = np.random.default_rng(7)
    faces, triangles = 40, 80
    triangle_polygons = np.repeat(np.arange(faces, dtype=np.int32), 2)
    materials = rng.integers(-2, 40000, faces).astype(np.int32)
    if domain == extract.NORMALS_BY_VERTEX:
        materials[:] = 5
        count = 30
    else:
        count = faces if domain == extract.NORMALS_BY_TRIANGLE else 4 * faces
    normals = rng.normal(size=(count, 3)).astype(np.float32)
    normals[3, 1] = np.nan
    rows = rng.integers(0, count, 3 * triangles).astype(np.int32)
    rows[[5, 17]] = -1
    table = extract.fill_corner_table(rows, triangle_polygons, normals, materials, domain)
    clamped = np.clip(materials, 0, 32767).astype(np.float32)
    if domain == extract.NORMALS_BY_VERTEX:
        expected_normals, expected_materials = normals, np.full(count, 5.0, np.float32)
    elif domain == extract.NORMALS_BY_TRIANGLE:
        expected_normals, expected_materials = normals[triangle_polygons], clamped[triangle_polygons]
    else:
        expected_normals = np.where((rows >= 0)[:, None], normals[np.maximum(rows, 0)], 0.0)
        expected_materials = np.repeat(clamped[triangle_polygons], 3)
    assert table.shape == (len(expected_normals), 4) and table.dtype == np.float32
    np.testing.assert_array_equal(table[:, :3], expected_normals)
    np.testing.assert_array_equal(table[:, 3], expected_materials)
    assert np.isnan(table[:, 1]).any()


def test_reposition_refuses_what_changes_the_triangles():
    positions, corner_vert, offsets = _quad_grid()
    arrays = extract.build_arrays_fast(positions, corner_vert, offsets)
    # Corner 1 of the first quad pulled over the diagonal 0-2, next to corner 3:
    # the quad now splits along 1-3.
    q = arrays.quads[0]
    folded = positions.copy()
    folded[q[1]] = 0.9 * positions[q[3]] + 0.1 * positions[q[0]]
    assert extract.reposition(arrays, folded, corner_vert, offsets) is None
    assert not np.array_equal(extract.build_arrays_fast(folded, corner_vert, offsets).triangles, arrays.triangles)
    # A non-finite vertex or other face sizes: full extraction.
    broken = positions.copy()
    broken[3, 0] = np.nan
    assert extract.reposition(arrays, broken, corner_vert, offsets) is None
    regrouped = offsets.copy()
    regrouped[1] -= 1
    regrouped[2] += 0
    assert extract.reposition(arrays, positions, corner_vert, regrouped) is None


def test_reposition_of_ngons_holds_while_blender_splits_them_alike():
    """A hexagon beside a quad: a move keeps the triangles while Blender
    triangulates the hexagon as before (asked of Blender: without it, a
    full extraction), and the result is a full extraction's; a move after
    which Blender splits it another way is a full extraction."""
    hexagon = [(np.cos(a), np.sin(a), 0.0) for a in np.linspace(0, 2 * np.pi, 7)[:-1]]
    positions = np.array(hexagon + [(1.0, -1.0, 0.0), (2.0, -1.0, 0.0), (2.0, 0.0, 0.0)], dtype=np.float32)
    corner_vert = np.array([0, 1, 2, 3, 4, 5, 6, 7, 8, 0], dtype=np.int32)
    offsets = np.array([0, 6, 10], dtype=np.int32)
    fan = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 5]])
    other_fan = np.array([[1, 2, 3], [1, 3, 4], [1, 4, 5], [1, 5, 0]])

    def blender_tris(split):
        return lambda rows: split[np.asarray(rows)]  # the hexagon's triangles are Blender's rows 0-3

    arrays = extract.build_arrays_fast(positions, corner_vert, offsets, blender_tris=blender_tris(fan))
    assert arrays.ngon_triangles is not None
    moved = positions.copy()
    moved[2] += (0.05, 0.1, 0.2)
    moved[7, 2] -= 0.3
    assert extract.reposition(arrays, moved, corner_vert, offsets) is None  # no one to ask
    quad_moved = positions.copy()
    quad_moved[7, 2] -= 0.3  # the quad alone: the hexagon's split is not asked
    assert extract.reposition(arrays, quad_moved, corner_vert, offsets) is not None
    assert extract.reposition(arrays, moved, corner_vert, offsets, blender_tris(other_fan)) is None
    result = extract.reposition(arrays, moved, corner_vert, offsets, blender_tris(fan))
    assert result is not None
    local, centre = result[:2]
    full = extract.build_arrays_fast(moved, corner_vert, offsets, blender_tris=blender_tris(fan))
    np.testing.assert_array_equal(full.triangles, arrays.triangles)
    np.testing.assert_array_equal(full.ngon_corners, arrays.ngon_corners)
    np.testing.assert_allclose(local + centre, full.positions + full.centre, atol=1e-5)


def test_infinite_vertices_of_both_signs_leave_their_faces_out_without_a_numpy_warning():
    """A mesh with a vertex at +Inf and one at -Inf: the faces that use them
    are left out (the one-line message is the caller's), and numpy's
    warning about Inf - Inf, which would reach Blender's console, is not
    raised."""
    positions = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [2, 0, 0], [2, 1, 0]], dtype=np.float32)
    corner_vert = np.array([0, 1, 2, 3, 1, 4, 5, 2], dtype=np.int32)
    offsets = np.array([0, 4, 8], dtype=np.int32)
    positions[4, 0] = np.inf
    positions[5, 1] = -np.inf
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        arrays = extract.build_arrays_fast(positions, corner_vert, offsets)
    assert arrays.triangle_count == 2  # the first quad only
    assert set(np.unique(arrays.triangles[:, :3])) <= {0, 1, 2, 3}


@pytest.mark.parametrize("shape", ["random", "grouped", "empty", "one"])
def test_distinct_is_numpy_unique(shape):
    """extract.distinct, the stable-sort unique the region keys use, gives
    np.unique's answer: random keys with repeats, keys grouped by region
    (ascending groups, shuffled within each, repeats across groups), none,
    one."""
    rng = np.random.default_rng(7)
    if shape == "random":
        keys = rng.integers(0, 500, 3000)
    elif shape == "grouped":
        groups = [1000 * g + rng.permutation(rng.integers(1, 60, 40)) for g in range(50)]
        keys = np.concatenate(groups)
    else:
        keys = np.arange(0 if shape == "empty" else 1, dtype=np.int64) * 3
    result = extract.distinct(keys)
    assert result.dtype == keys.dtype
    np.testing.assert_array_equal(result, np.unique(keys))


def test_ngon_blocks_hold_the_outline_then_each_diagonal_once():
    """extract._pack_ngons on random n-gons (5 to 40 corners, triangulated as
    fans from a random corner, one n-gon given twice as many triangles as it
    has): per n-gon, its outline's vertex ids in corner order, then its
    n - 3 distinct diagonals as (lower, upper) pairs, ascending; each
    triangle points at its n-gon's block."""
    rng = np.random.default_rng(5)
    sizes = rng.integers(5, 41, 60)
    loop_start = np.concatenate([[0], np.cumsum(sizes)[:-1]])
    corner_vert = rng.permutation(2 * int(sizes.sum()))[: int(sizes.sum())].astype(np.int32)
    tris, polys, reals, expected = [], [], [], []
    for face, (start, n) in enumerate(zip(loop_start.tolist(), sizes.tolist())):
        turn = int(rng.integers(0, n))
        ring = [int(corner_vert[start + (turn + k) % n]) for k in range(n)]
        fan = [((ring[0], ring[k], ring[k + 1]), (k == 1, True, k == n - 2)) for k in range(1, n - 1)]
        for (a, b, c), real in fan * (2 if face == 3 else 1):  # repeated triangles: diagonals listed twice
            tris.append((a, b, c))
            polys.append(face)
            reals.append(real)
        diagonals = sorted({(min(ring[0], ring[k]), max(ring[0], ring[k])) for k in range(2, n - 1)})
        expected.append(corner_vert[start : start + n].tolist() + [v for pair in diagonals for v in pair])
    ngon_corners, block_start = extract._pack_ngons(
        np.array(tris, np.int32), np.array(reals, bool), np.array(polys, np.int64), loop_start, sizes, corner_vert
    )
    np.testing.assert_array_equal(ngon_corners, np.concatenate(expected))
    starts = np.concatenate([[0], np.cumsum([len(block) for block in expected])[:-1]])
    np.testing.assert_array_equal(block_start, starts[polys])


def test_ngons_flat_holds_for_a_turned_plane_and_not_for_a_bend():
    """A 40-gon in a plane turned every way (its float32 corners rounded
    off that plane) is flat, far from the origin too (the tolerance follows
    the coordinates' rounding); lifting one corner by a thousandth of its
    size, or a face with no area, is not."""
    rng = np.random.default_rng(3)
    angle = np.linspace(0.0, 2.0 * np.pi, 40, endpoint=False)
    ring = np.stack([np.cos(angle), np.sin(angle), np.zeros_like(angle)], axis=1)
    turn, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    outlines = (np.arange(40), np.array([0]))
    for origin in (np.zeros(3), np.array([1.0e4, -3.0e3, 7.0e2])):
        corners = (ring @ turn.T + origin).astype(np.float32)
        assert extract.ngons_flat(corners, outlines)
    lifted = (ring @ turn.T).astype(np.float32)
    lifted[7] += (1.0e-3 * turn[:, 2]).astype(np.float32)
    assert not extract.ngons_flat(lifted, outlines)
    assert not extract.ngons_flat(np.zeros((40, 3), np.float32), outlines)
    # Two faces: each judged by itself, and one bent face is enough.
    two = (np.concatenate([np.arange(40), np.arange(40, 80)]), np.array([0, 40]))
    flat = ring @ turn.T
    bent = flat.copy()
    bent[3, 2] += 0.1
    assert extract.ngons_flat(np.concatenate([flat, flat + 5.0]).astype(np.float32), two)
    assert not extract.ngons_flat(np.concatenate([flat, bent]).astype(np.float32), two)
