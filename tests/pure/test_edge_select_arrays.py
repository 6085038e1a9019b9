"""Edge selection on plain arrays, without Blender (image model
§3.4-§3.6): which edges a region walks, its block and its lines (a region
past the walk limit included), the segments of an edge of several classes,
the ends of a chain, the runs of the region-lines pass and the spheres
around their regions.
(tests/test_edge_selection.py renders the same rules against the float64
reference.)"""

from __future__ import annotations

import numpy as np
import pytest

from solidwire_addon.core import edge_select, extract


def _strip(columns: int):
    """A 1 x ``columns`` strip of unit quads: arrays, corner ids, offsets,
    corner edges and edge vertex pairs."""
    positions = np.array([[x, y, 0] for y in (0, 1) for x in range(columns + 1)], np.float32)
    top = columns + 1
    faces = [(x, x + 1, top + x + 1, top + x) for x in range(columns)]
    corner_vert = np.array([v for f in faces for v in f], np.int32)
    offsets = np.arange(0, 4 * columns + 1, 4, dtype=np.int32)
    index: dict = {}
    corner_edge = []
    for f in faces:
        for k in range(4):
            key = tuple(sorted((f[k], f[(k + 1) % 4])))
            corner_edge.append(index.setdefault(key, len(index)))
    verts = np.array(list(index), np.int64)
    arrays = extract.build_arrays_fast(positions, corner_vert, offsets)
    return arrays, corner_vert, offsets, np.array(corner_edge), verts, index


def test_a_region_walks_every_drawn_edge_around_it():
    arrays, corner_vert, offsets, corner_edge, verts, index = _strip(3)
    drawn = np.ones(len(verts), bool)
    drawn[index[(1, 5)]] = False  # joins quads 0 and 1
    stats = edge_select.select_edges(arrays, corner_vert, offsets, corner_edge, edge_select.EdgeInputs(verts, drawn))
    assert (stats.hidden_edges, stats.regions, stats.listed_triangles) == (1, 1, 4)
    listed = (arrays.edge_flags & extract.IN_REGION) != 0
    assert listed.tolist() == [True] * 4 + [False] * 2  # the third quad keeps its own edges
    # The region's block: its 6 drawn boundary edges, lower id first, style 0.
    start = int(arrays.triangles[0, 3]) - len(arrays.ngon_corners)
    count = int(arrays.edge_flags[0]) >> extract.NGON_SHIFT
    block = arrays.region_table[start : start + edge_select.TEXELS_PER_SEGMENT * count : 2]
    assert sorted(map(tuple, block[:, :2].astype(int).tolist())) == sorted(
        [(0, 1), (1, 2), (4, 5), (5, 6), (0, 4), (2, 6)]
    )
    assert (block[:, 2] == 0).all()
    # The hidden edge is neither a line nor a diagonal of the triangles that own it.
    tri_edges = [tuple(sorted((int(t[i]), int(t[(i + 1) % 3])))) for t in arrays.triangles[:4] for i in range(3)]
    flags = np.repeat(arrays.edge_flags[:4], 3)
    bits = np.tile([extract.EDGE0_HIDDEN, extract.EDGE0_HIDDEN << 1, extract.EDGE0_HIDDEN << 2], 4)
    hidden = [e for e, f, b in zip(tri_edges, flags, bits) if f & b]
    assert hidden == [(1, 5), (1, 5)]


def test_a_large_region_is_one_block_and_its_lines_one_table():
    arrays, corner_vert, offsets, corner_edge, verts, index = _strip(40)
    drawn = np.ones(len(verts), bool)
    for x in range(1, 40):
        drawn[index[(x, 41 + x)]] = False  # one region of 40 quads, 82 drawn edges
    stats = edge_select.select_edges(arrays, corner_vert, offsets, corner_edge, edge_select.EdgeInputs(verts, drawn))
    # No size limit: every triangle walks the region's whole block ...
    assert stats.regions == 1 and stats.listed_triangles == arrays.triangle_count
    assert ((arrays.edge_flags >> extract.NGON_SHIFT) == 82).all()
    # ... and the region-lines table holds each of its 82 drawn edges once,
    # with the region (face 0's label) on one side and nothing on the other.
    lines = arrays.region_lines.reshape(-1, 2, 4)
    assert stats.region_lines == len(lines) == 82
    ends = {(int(a), int(b)) for a, b in lines[:, 0, :2]}
    assert ends == {tuple(sorted(map(int, verts[e]))) for e in range(len(verts)) if drawn[e]}
    assert (lines[:, 0, 3] == 0).all() and (lines[:, 1, 2] == edge_select.NO_REGION).all()
    assert (arrays.triangle_regions == 0).all()


def test_an_edge_between_two_regions_is_one_line_naming_both():
    arrays, corner_vert, offsets, corner_edge, verts, index = _strip(4)
    drawn = np.ones(len(verts), bool)
    drawn[index[(1, 6)]] = False  # quads 0 + 1 form a region, 2 + 3 another
    drawn[index[(3, 8)]] = False
    edge_select.select_edges(arrays, corner_vert, offsets, corner_edge, edge_select.EdgeInputs(verts, drawn))
    lines = arrays.region_lines.reshape(-1, 2, 4)
    shared = [row for row in lines if (int(row[0, 0]), int(row[0, 1])) == (2, 7)]
    assert len(shared) == 1 and sorted((shared[0][0, 3], shared[0][1, 2])) == [0.0, 2.0]
    assert sorted(set(arrays.triangle_regions.tolist())) == [0.0, 2.0]


def test_an_edge_of_several_classes_gets_a_segment_per_class():
    arrays, corner_vert, offsets, corner_edge, verts, index = _strip(1)
    classes = np.zeros(len(verts), np.int64)
    classes[index[(0, 1)]] = edge_select.CLASS_BIT["sharp"] | edge_select.CLASS_BIT["seam"]
    edge_select.select_edges(
        arrays, corner_vert, offsets, corner_edge, edge_select.EdgeInputs(verts, None, classes, boundary_class=False)
    )
    styles = arrays.region_table[0::2]
    bottom = styles[(styles[:, 0] == 0) & (styles[:, 1] == 1), 2]
    assert sorted(bottom.tolist()) == [
        1 + edge_select.EDGE_CLASSES.index("sharp"),
        1 + edge_select.EDGE_CLASSES.index("seam"),
    ]
    assert sorted(styles[:, 2].tolist()).count(0) == 3


def test_chain_ends_are_the_ends_of_the_path():
    verts = np.array([[0, 4], [4, 5], [5, 1], [1, 7]])
    ends = edge_select._chain_ends(verts, np.array([0, 0, 0, 1]))
    assert sorted(ends[0]) == [0, 1] and sorted(ends[2]) == [0, 1]
    assert sorted(ends[3]) == [1, 7]


def test_a_region_too_large_to_walk_keeps_all_its_lines_for_the_region_lines_pass():
    """Past WALK_LIMIT drawn edges a region's faces walk their own edges
    (where a pixel walks at all), while the region-lines table still holds
    every drawn edge of the region."""
    columns = edge_select.WALK_LIMIT  # 2 * columns + 2 drawn edges: over the limit
    arrays, corner_vert, offsets, corner_edge, verts, index = _strip(columns)
    drawn = np.ones(len(verts), bool)
    top = columns + 1
    for x in range(1, columns):
        drawn[index[(x, top + x)]] = False
    edge_select.select_edges(arrays, corner_vert, offsets, corner_edge, edge_select.EdgeInputs(verts, drawn))
    assert len(arrays.region_lines) // 2 == 2 * columns + 2
    # Every triangle reads the region lines; its own block holds at most its
    # quad's four edges.
    assert ((arrays.edge_flags & extract.REGION_LINES) != 0).all()
    assert ((arrays.edge_flags >> extract.NGON_SHIFT) <= 4).all()


def _runs(arrays):
    """[(first entry, entries)] of the region-lines table's runs."""
    return [(int(first), int(count)) for first, count in arrays.region_line_runs[:, :2]]


def test_consecutive_pieces_of_a_chain_share_a_quad():
    """The region-lines pass draws runs of up to RUN_SEGMENTS consecutive
    entries of one chain, style and pair of regions as one quad: a strip
    whose long sides are two chains (as a cage edge's pieces, numbered one
    after another) has runs of eight, four and single side edges."""
    columns = 20
    arrays, corner_vert, offsets, corner_edge, verts, index = _strip(columns)
    top = columns + 1
    bottom = [index[(x, x + 1)] for x in range(columns)]
    upper = [index[(top + x, top + x + 1)] for x in range(columns)]
    # Number the edges as a subdivision does: each chain's pieces in a row.
    order = bottom + upper + [e for e in range(len(verts)) if e not in set(bottom + upper)]
    renumber = np.empty(len(verts), np.int64)
    renumber[order] = np.arange(len(verts))
    verts, corner_edge = verts[order], renumber[corner_edge]
    chain = np.arange(len(verts)) + 2
    chain[:columns], chain[columns : 2 * columns] = 0, 1
    drawn = np.ones(len(verts), bool)
    drawn[2 * columns :] = False  # the verticals: one region (but the two ends stay drawn)
    drawn[[renumber[index[(0, top)]], renumber[index[(columns, top + columns)]]]] = True
    edge_select.select_edges(
        arrays, corner_vert, offsets, corner_edge, edge_select.EdgeInputs(verts, drawn, chain=chain)
    )
    lines = arrays.region_lines.reshape(-1, 2, 4)
    assert len(lines) == 2 * columns + 2
    runs = _runs(arrays)
    assert arrays.region_run_segments == edge_select.RUN_SEGMENTS
    assert sorted(count for _, count in runs) == [1, 1, 4, 4, 8, 8, 8, 8]
    # The runs cover the table once, in order, each one chain, style and
    # pair of regions.
    assert [first for first, _ in runs] == list(np.cumsum([0] + [count for _, count in runs[:-1]]))
    for first, count in runs:
        run = lines[first : first + count]
        assert (run[:, 1, :2] == run[0, 1, :2]).all()  # chain ends
        assert (run[:, 0, 2:] == run[0, 0, 2:]).all() and (run[:, 1, 2] == run[0, 1, 2]).all()


def test_edges_that_are_their_own_chains_are_one_quad_each():
    arrays, corner_vert, offsets, corner_edge, verts, index = _strip(6)
    drawn = np.ones(len(verts), bool)
    for x in range(1, 6):
        drawn[index[(x, 7 + x)]] = False
    edge_select.select_edges(arrays, corner_vert, offsets, corner_edge, edge_select.EdgeInputs(verts, drawn))
    assert arrays.region_run_segments == 1
    assert _runs(arrays) == [(k, 1) for k in range(len(arrays.region_lines) // 2)]


def _known_strip_regions(index, drawn, verts, pairs_of_quads: int):
    """KnownRegions of a strip whose quads 2k and 2k + 1 form region k."""
    face_start = np.arange(0, 2 * pairs_of_quads + 1, 2)
    edges, edge_start = [], [0]
    for k in range(pairs_of_quads):
        x = 2 * k
        own = {
            index[key]
            for key in index
            if set(key) <= {x, x + 1, x + 2, *(v + 2 * pairs_of_quads + 1 for v in (x, x + 1, x + 2))}
        }
        edges += sorted(e for e in own if drawn[e])
        edge_start.append(len(edges))
    return edge_select.KnownRegions(face_start, np.array(edge_start), np.array(edges))


def _select_both(columns, regions_for, monkeypatch, hidden=None, classes_for=None, joined_x=()):
    """The arrays through the known regions (the same as the general
    path's) and whether the known regions were taken. ``hidden``: the x of
    each vertical edge that is not drawn (default: every odd one, so that
    quads 2k and 2k + 1 form region k). ``classes_for(index, drawn)``: the
    edges' class bits. ``joined_x``: the x of vertical edges the regions'
    mask draws but the selection hides (EdgeInputs.joined)."""
    taken = []
    real = edge_select._select_known_regions
    monkeypatch.setattr(edge_select, "_select_known_regions", lambda *args: taken.append(real(*args)) or taken[-1])
    results = []
    for known in (True, False):
        arrays, corner_vert, offsets, corner_edge, verts, index = _strip(columns)
        drawn = np.ones(len(verts), bool)
        top = columns + 1
        for x in range(1, columns, 2) if hidden is None else hidden:
            drawn[index[(x, top + x)]] = False
        ends = verts.copy()
        regions = regions_for(index, drawn, verts) if known else None
        joined = np.zeros(len(verts), bool)
        for x in joined_x:
            joined[index[(x, top + x)]] = True
        drawn &= ~joined
        classes = None if classes_for is None else classes_for(index, drawn)
        inputs = edge_select.EdgeInputs(
            verts, drawn, classes, chain_ends=ends, regions=regions, joined=joined if known else None
        )
        results.append((arrays, edge_select.select_edges(arrays, corner_vert, offsets, corner_edge, inputs)))
    (fast, fast_stats), (general, general_stats) = results
    assert fast_stats == general_stats
    for field in ("triangles", "edge_flags", "region_table", "region_lines", "region_line_runs", "triangle_regions"):
        a, b = getattr(fast, field), getattr(general, field)
        assert (a is None) == (b is None) and (a is None or (a.dtype == b.dtype and np.array_equal(a, b))), field
    return fast, bool(taken) and taken[0] is not None


def test_known_regions_give_the_general_path_arrays(monkeypatch):
    """Regions the caller knows (a subdivision's cage faces) are written per
    region and per quad: the same arrays as finding them."""
    fast, taken = _select_both(6, lambda index, drawn, verts: _known_strip_regions(index, drawn, verts, 3), monkeypatch)
    assert taken
    assert sorted(set(fast.triangle_regions.tolist())) == [0.0, 2.0, 4.0]


def test_known_regions_that_do_not_fit_the_mesh_are_found_instead(monkeypatch):
    """A list that does not cover the faces, names an edge that is not
    drawn, has a region of one face or names an edge twice: the general
    path decides."""

    def short(index, drawn, verts):
        known = _known_strip_regions(index, drawn, verts, 3)
        return edge_select.KnownRegions(known.face_start[:-1], known.edge_start[:-1], known.region_edges)

    def hidden_edge(index, drawn, verts):
        known = _known_strip_regions(index, drawn, verts, 3)
        known.region_edges[0] = int(np.flatnonzero(~drawn)[0])
        return known

    def single_faces(index, drawn, verts):
        return edge_select.KnownRegions(np.arange(7), np.arange(7), np.flatnonzero(drawn)[:6])

    def repeated_edge(index, drawn, verts):  # (a corrupt cage face names one edge twice)
        known = _known_strip_regions(index, drawn, verts, 3)
        known.region_edges[1] = known.region_edges[0]
        return known

    for regions_for in (short, hidden_edge, single_faces, repeated_edge):
        assert not _select_both(6, regions_for, monkeypatch)[1]
        monkeypatch.undo()


def test_known_regions_past_the_walk_limit_give_the_general_path_arrays(monkeypatch):
    """A known region past WALK_LIMIT drawn edges beside one under it: its
    faces get blocks of their own drawn edges, after the small region's
    block, as the general path lays them out; its lines are still every
    drawn edge of the region."""
    columns = edge_select.WALK_LIMIT + 4
    top = columns + 1

    def regions_for(index, drawn, verts):
        def drawn_edges(faces):
            return sorted(
                {
                    index[key]
                    for x in faces
                    for key in ((x, x + 1), (top + x, top + x + 1), (x, top + x), (x + 1, top + x + 1))
                    if drawn[index[key]]
                }
            )

        small, large = drawn_edges(range(2)), drawn_edges(range(2, columns))
        assert len(large) > edge_select.WALK_LIMIT >= len(small)
        return edge_select.KnownRegions(
            np.array([0, 2, columns]), np.array([0, len(small), len(small) + len(large)]), np.array(small + large)
        )

    # Quads 0 and 1: a small region; quads 2 on: one of 2 * columns - 2 drawn edges.
    fast, taken = _select_both(columns, regions_for, monkeypatch, hidden=[1, *range(3, columns)])
    assert taken
    # The small region's quads walk its six drawn edges; the large
    # region's quads their own: two, three at either end of it.
    segments = (fast.edge_flags >> extract.NGON_SHIFT)[0::2]
    assert segments.tolist() == [6, 6, 3] + [2] * (columns - 4) + [3]
    assert len(fast.region_lines) // 2 == 2 * columns + 3  # every drawn edge once: sides, 3 verticals


def _strip_classes(pick):
    """classes_for for _select_both: sharp on every drawn edge ``pick``
    takes, seam too on every other one of them."""
    sharp, seam = edge_select.CLASS_BIT["sharp"], edge_select.CLASS_BIT["seam"]

    def classes_for(index, drawn):
        classes = np.zeros(len(drawn), np.int64)
        for k, edge in enumerate(pick(index, drawn)):
            classes[edge] = sharp | (seam if k % 2 else 0)
        return classes

    return classes_for


def test_known_regions_with_classed_edges_give_the_general_path_arrays(monkeypatch):
    """Classes on drawn edges only style them: the known regions hold, each
    classed edge one segment and one line entry per class, in the general
    path's order; also where a region is past WALK_LIMIT."""
    regions_for = lambda index, drawn, verts: _known_strip_regions(index, drawn, verts, 3)
    some_drawn = _strip_classes(lambda index, drawn: np.flatnonzero(drawn)[::3])
    fast, taken = _select_both(6, regions_for, monkeypatch, classes_for=some_drawn)
    assert taken
    assert len(fast.region_lines) // 2 > np.count_nonzero(fast.region_lines[0::2, 2] == 0) > 0
    monkeypatch.undo()

    columns = edge_select.WALK_LIMIT + 4

    def one_large_region(index, drawn, verts):
        edges = np.flatnonzero(drawn)
        return edge_select.KnownRegions(np.array([0, columns]), np.array([0, len(edges)]), edges)

    fast, taken = _select_both(columns, one_large_region, monkeypatch, hidden=range(1, columns), classes_for=some_drawn)
    assert taken
    assert (fast.region_table[0::2, 2] > 0).any()


def test_known_regions_refuse_classes_that_change_them(monkeypatch):
    """A class on an edge the mask hides shows it: the regions change, and
    the general path decides."""
    regions_for = lambda index, drawn, verts: _known_strip_regions(index, drawn, verts, 3)
    on_hidden = _strip_classes(lambda index, drawn: np.flatnonzero(~drawn)[:1])
    assert not _select_both(6, regions_for, monkeypatch, classes_for=on_hidden)[1]


def test_known_regions_whose_classes_lengthen_a_block_past_the_walk_limit(monkeypatch):
    """A region of WALK_LIMIT drawn edges or fewer keeps its one block when
    classes double its segments past WALK_LIMIT, as the general path does
    (the limit is on drawn edges)."""
    columns = 40  # one region of 2 * 40 + 2 drawn edges: under WALK_LIMIT, not once classed twice

    def one_region(index, drawn, verts):
        edges = np.flatnonzero(drawn)
        assert len(edges) <= edge_select.WALK_LIMIT < 2 * len(edges)
        return edge_select.KnownRegions(np.array([0, columns]), np.array([0, len(edges)]), edges)

    def every_drawn_twice(index, drawn):
        return np.where(drawn, edge_select.CLASS_BIT["sharp"] | edge_select.CLASS_BIT["seam"], 0)

    fast, taken = _select_both(
        columns, one_region, monkeypatch, hidden=range(1, columns), classes_for=every_drawn_twice
    )
    assert taken
    assert ((fast.edge_flags >> extract.NGON_SHIFT) == 2 * (2 * columns + 2)).all()


def test_known_regions_joined_across_hidden_edges_give_the_general_path_arrays(monkeypatch):
    """Regions known for a mask, with some of its edges hidden beyond it
    (the edge angle beside the cage): the regions on either side become
    one (join_regions), its edges listed once; as the general path finds
    them."""
    regions_for = lambda index, drawn, verts: _known_strip_regions(index, drawn, verts, 4)
    joins = []
    real_join = edge_select.join_regions
    monkeypatch.setattr(edge_select, "join_regions", lambda *args: joins.append(real_join(*args)) or joins[-1])
    fast, taken = _select_both(8, regions_for, monkeypatch, joined_x=[2, 6])
    assert taken
    # Quads 0-3 and 4-7: two regions of two pieces each.
    assert sorted(set(fast.triangle_regions.tolist())) == [0.0, 4.0]
    assert joins[0].piece_region.tolist() == [0, 0, 1, 1]
    monkeypatch.undo()

    # One join in the middle: regions 1 and 2 (quads 2-5) become one.
    fast, taken = _select_both(8, regions_for, monkeypatch, joined_x=[4])
    assert taken and sorted(set(fast.triangle_regions.tolist())) == [0.0, 2.0, 6.0]


def test_the_angle_between_normals_is_the_arccos_angle_whichever_way_it_is_gathered():
    # The edge angle compares cosines instead of taking arccos, and gathers
    # unit normals per face (many pairs) or per pair (an edit's few rows).
    # Both ways must give the same bits, and the same answer as the angle
    # itself wherever the angle is not within rounding of the threshold.
    rng = np.random.default_rng(7)
    normals = rng.normal(size=(400, 3)).astype(np.float32)
    normals[:5] *= 1e-20  # tiny but not zero: unit length all the same
    normals[5] = 0.0  # a zero normal is 90 degrees from anything
    f1, f2 = rng.integers(0, 400, 1000), rng.integers(0, 400, 1000)
    f2[:10] = f1[:10]  # a face with itself is never flat
    n1, n2 = normals[f1].astype(np.float64), normals[f2].astype(np.float64)
    cosine = np.einsum("ij,ij->i", n1, n2) / np.maximum(np.linalg.norm(n1, axis=1) * np.linalg.norm(n2, axis=1), 1e-300)
    between = np.arccos(np.clip(cosine, -1.0, 1.0))
    for angle in (1e-3, 0.3, np.pi / 2, 2.0, np.pi, 4.0):
        many = edge_select._pairs_flat(normals, f1, f2, angle)  # more pairs than faces
        few = np.concatenate(
            [edge_select._pairs_flat(normals, f1[i : i + 100], f2[i : i + 100], angle) for i in range(0, 1000, 100)]
        )
        assert np.array_equal(many, few)
        clear = np.abs(between - angle) > 1e-9
        assert np.array_equal(many[clear], ((between < angle) & (f1 != f2))[clear])
        assert not many[:10].any()
        assert many[f1 == 5].sum() == (angle > np.pi / 2) * (f2[f1 == 5] != 5).sum()
    # Below about 1e-8 radians cos(angle) rounds to 1: the angle between
    # two normals is then either 0 (the cosine rounds to 1 or above) or
    # past the threshold, and the cosine test must still say which.
    same = np.repeat(normals[6:7], 50, axis=0) * np.exp2(rng.integers(-3, 4, (50, 1))).astype(np.float32)
    first, pairs = np.zeros(49, np.int64), np.arange(1, 50)
    n1, n2 = same[first].astype(np.float64), same[pairs].astype(np.float64)
    cosine = np.einsum("ij,ij->i", n1, n2) / (np.linalg.norm(n1, axis=1) * np.linalg.norm(n2, axis=1))
    for angle in (1e-12, 1e-9):
        expected = np.arccos(np.clip(cosine, -1.0, 1.0)) < angle
        assert np.array_equal(edge_select._pairs_flat(same, first, pairs, angle), expected)


def _grid_of_triangles_and_quads(rng, size: int):
    """A ``size`` x ``size`` grid whose cells are a quad or two triangles
    (split along either diagonal), each face's corners starting at a random
    one of them, the vertices jittered so far that some quads are concave
    and split along their other diagonal: positions, corner ids, offsets, corner
    edges and edge vertex pairs."""
    row = size + 1
    positions = np.array([[x, y, 0] for y in range(row) for x in range(row)], np.float32)
    positions += rng.uniform(-0.45, 0.45, positions.shape).astype(np.float32)
    faces = []
    for y in range(size):
        for x in range(size):
            a, b, c, d = y * row + x, y * row + x + 1, (y + 1) * row + x + 1, (y + 1) * row + x
            cell = ([(a, b, c, d)], [(a, b, c), (a, c, d)], [(a, b, d), (b, c, d)])[rng.integers(3)]
            for face in cell:
                turn = int(rng.integers(len(face)))
                faces.append(face[turn:] + face[:turn])
    corner_vert = np.array([v for f in faces for v in f], np.int32)
    offsets = np.concatenate([[0], np.cumsum([len(f) for f in faces])]).astype(np.int32)
    index: dict = {}
    corner_edge = [
        index.setdefault(tuple(sorted((f[k], f[(k + 1) % len(f)]))), len(index)) for f in faces for k in range(len(f))
    ]
    return positions, corner_vert, offsets, np.array(corner_edge), np.array(list(index), np.int64)


def test_rows_of_triangles_and_quads_are_marked_as_the_general_path_marks_them(monkeypatch):
    """A mesh of triangles and quads marks its rows' hidden edges by a
    lookup per row (build_arrays_fast's layout); the arrays are the general
    path's bit for bit, which finds each row's corners in its face."""
    rng = np.random.default_rng(7)
    taken = []
    real = edge_select._mark_tri_and_quad_rows
    monkeypatch.setattr(edge_select, "_mark_tri_and_quad_rows", lambda *args: taken.append(real(*args)) or taken[-1])
    trials = 12
    flips = []
    for trial in range(trials):
        positions, corner_vert, offsets, corner_edge, verts = _grid_of_triangles_and_quads(rng, int(rng.integers(3, 9)))
        drawn = rng.random(len(verts)) < rng.uniform(0.2, 0.9)
        classes = (
            np.where(rng.random(len(verts)) < 0.1, 1 << rng.integers(3, size=len(verts)), 0) if trial % 2 else None
        )
        results = []
        for shortcut in (True, False):
            arrays = extract.build_arrays_fast(positions, corner_vert, offsets)
            assert arrays.quad_flip is not None
            flips.append(arrays.quad_flip.mean())
            if not shortcut:
                arrays.quad_flip = None  # the general path: each row's corners found in its face
            inputs = edge_select.EdgeInputs(verts, drawn.copy(), classes)
            results.append((arrays, edge_select.select_edges(arrays, corner_vert, offsets, corner_edge, inputs)))
        (fast, fast_stats), (general, general_stats) = results
        assert fast_stats == general_stats
        for field in ("triangles", "edge_flags", "region_table", "region_lines", "triangle_regions"):
            a, b = getattr(fast, field), getattr(general, field)
            assert (a is None) == (b is None) and (a is None or np.array_equal(a, b)), (trial, field)
        hidden_bits = extract.EDGE0_HIDDEN | extract.EDGE0_HIDDEN << 1 | extract.EDGE0_HIDDEN << 2
        hidden = (fast.edge_flags & hidden_bits) != 0
        assert hidden.any() and not hidden.all()
    assert taken == [True, False] * trials
    assert 0 < np.mean(flips) < 0.5  # quads split along either diagonal


@pytest.mark.parametrize("listing", ["scattered", "region by region"])
def test_each_runs_sphere_holds_every_triangle_of_its_regions(listing):
    """edge_select.run_bounds: the sphere of each run of region lines holds
    every corner of the triangles of the run's one or two regions (named
    as the tables name them: faces measuring their own edges below
    NO_REGION) as float32 stores it, and is no larger than the box of those
    corners needs; with triangles scattered, some in no region, and with
    every triangle listed region by region (a cage look)."""
    rng = np.random.default_rng(7)
    positions = np.zeros((400, 4), np.float32)
    positions[:, :3] = rng.normal(size=(400, 3)) * np.array([3.0, 0.5, 80.0]) + np.array([1e3, -20.0, 0.0])
    triangles = rng.integers(0, 400, size=(300, 4)).astype(np.int32)
    label = rng.integers(0, 9, size=300)
    names = np.where(label % 3 == 0, edge_select.OWN_REGION_BASE - label, label).astype(np.float32)
    if listing == "scattered":
        names[rng.random(300) < 0.2] = edge_select.NO_REGION
    else:
        names.sort()
    carried = sorted(set(names[names != edge_select.NO_REGION].tolist()))
    # Runs of one entry each: every pair of regions, and each with none.
    pairs = [(a, b) for a in carried for b in carried if a < b] + [(a, edge_select.NO_REGION) for a in carried]
    lines = np.zeros((2 * len(pairs), 4), np.float32)
    lines[0::2, 3] = [a for a, _ in pairs]
    lines[1::2, 2] = [b for _, b in pairs]
    runs = np.zeros((len(pairs), 4), np.float32)
    runs[:, 0], runs[:, 1] = np.arange(len(pairs)), 1
    corner_vertices = np.ascontiguousarray(triangles[:, :3].T, dtype=np.intp)
    listing = edge_select.region_listing(names, corner_vertices)
    bounds = edge_select.run_bounds(listing, positions, lines, runs)
    assert bounds.shape == (len(pairs), 4) and bounds.dtype == np.float32
    for (a, b), sphere in zip(pairs, bounds):
        of_run = (names == a) | ((names == b) & (b != edge_select.NO_REGION))
        corners = positions[triangles[of_run, :3].ravel(), :3].astype(np.float64)
        centre, radius = sphere[:3].astype(np.float64), float(sphere[3])
        assert np.linalg.norm(corners - centre, axis=1).max() <= radius
        half_diagonal = 0.5 * np.linalg.norm(corners.max(axis=0) - corners.min(axis=0))
        assert radius <= half_diagonal * (1.0 + 1e-5) + 1e-3
