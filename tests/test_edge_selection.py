"""Which edges are drawn and how (image model §3.4-§3.7): regions, edge
classes with their own styles, density fade. Renders through the engine are
compared with the float64 reference; the region bookkeeping is also checked
directly on arrays."""

from __future__ import annotations

import math

import bpy
import numpy as np
import pytest

from solidwire_addon.core import edge_select, extract
from tests.support import accuracy, reference, scenes

# ---------------------------------------------------------------- bookkeeping (no GPU)


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


def test_chain_ends_are_the_ends_of_the_path():
    verts = np.array([[0, 4], [4, 5], [5, 1], [1, 7]])
    ends = edge_select._chain_ends(verts, np.array([0, 0, 0, 1]))
    assert sorted(ends[0]) == [0, 1] and sorted(ends[2]) == [0, 1]
    assert sorted(ends[3]) == [1, 7]


# ---------------------------------------------------------------- against the reference


def _marked_cube(scene):
    """A bevelled-looking cube: sharp, seam, crease and Freestyle marks on
    different edges, plus an open grid (boundary)."""
    cube = scenes.cube(scene, size=1.6, location=(0.0, 0.0, 0.8), rotation=(0.0, 0.0, 0.4))
    mesh = cube.data
    mesh.edges[0].use_edge_sharp = True
    mesh.edges[1].use_seam = True
    mesh.edges[2].use_seam = True
    mesh.edges[2].use_edge_sharp = True  # two classes on one edge
    crease = mesh.attributes.new("crease_edge", "FLOAT", "EDGE")
    crease.data[3].value = 1.0
    freestyle = mesh.attributes.new("freestyle_edge", "BOOLEAN", "EDGE")
    freestyle.data[5].value = True
    scenes.grid(scene, x_segments=3, y_segments=3, size=2.5, location=(0.0, 0.0, -0.2))
    scenes.add_camera(scene, location=(3.5, -4.0, 3.2), target=(0.0, 0.0, 0.4))
    return cube


CLASS_LOOK = dict(
    use_boundary_edges=True,
    boundary_thickness=3.0,
    boundary_color=(1.0, 0.0, 0.0, 1.0),
    use_sharp_edges=True,
    sharp_thickness=4.0,
    sharp_color=(0.0, 1.0, 0.0, 1.0),
    use_seam_edges=True,
    seam_thickness=2.5,
    seam_pattern="DASHED",
    seam_color=(0.0, 0.0, 1.0, 1.0),
    use_crease_edges=True,
    crease_thickness=0.5,
    crease_pattern="DOTTED",
    use_freestyle_edges=True,
    freestyle_thickness=5.0,
    pattern_period=10.0,
    thickness=1.0,
)


def test_edge_classes_match_the_reference(output_dir):
    scene = scenes.empty_scene(240, 180, **CLASS_LOOK)
    _marked_cube(scene)
    report = accuracy.measure(scene, "edge_classes", output_dir)
    accuracy.assert_accurate(report)
    # The classes really change the picture: wider lines, other colours.
    rgba = scenes.load_png(output_dir / "edge_classes.png")
    ref = reference.render_reference(scene)
    green = (rgba[..., 1] > 0.9) & (rgba[..., 0] < 0.1) & (rgba[..., 3] > 0.9)
    red = (rgba[..., 0] > 0.9) & (rgba[..., 1] < 0.1) & (rgba[..., 3] > 0.9)
    assert green.sum() > 50 and red.sum() > 100
    # The colour of each solid sample is the colour of the style the
    # reference picks (but where two styles tie at full strength, which a
    # rounding step decides).
    solid = (rgba[..., 3] > 0.99) & ~ref.on_silhouette & np.isfinite(ref.wire).all(axis=-1)
    expected = reference.srgb_encode(ref.wire)
    wrong = np.abs(rgba[..., :3] - expected).max(axis=-1) > 0.02
    assert solid.sum() > 500 and (wrong & solid).sum() <= 0.005 * solid.sum()


def test_classes_switched_on_change_nothing_on_a_mesh_without_such_edges(output_dir):
    scene = scenes.empty_scene(160, 120, thickness=1.5)
    scenes.cube(scene, size=1.5)
    scenes.add_camera(scene, location=(3.0, -3.0, 2.5), target=(0, 0, 0))
    plain = scenes.render_to_file(scene, output_dir / "classes_off.png")
    for name in ("sharp", "seam", "crease", "freestyle"):
        setattr(scene.solidwire, f"use_{name}_edges", True)
        setattr(scene.solidwire, f"{name}_thickness", 6.0)
    again = scenes.render_to_file(scene, output_dir / "classes_on_no_marks.png")
    np.testing.assert_allclose(again, plain, atol=1.5 / 65535)


def test_regions_give_clean_corners_where_edges_are_hidden(output_dir):
    """A flat grid with the edge angle keeps only its boundary, drawn as one
    region: the corners are as clean as a single quad's."""
    scene = scenes.empty_scene(200, 150, edge_angle=math.radians(20.0), thickness=3.0)
    scenes.grid(scene, x_segments=4, y_segments=4, size=3.0)
    scenes.add_camera(scene, location=(0.4, -3.0, 3.6), target=(0, 0, 0))
    report = accuracy.measure(scene, "regions_grid", output_dir)
    accuracy.assert_accurate(report)
    # The whole interior is free of lines: only the outline is drawn.
    ref = reference.render_reference(scene)
    covered = ref.face >= 0
    assert (ref.d_real[covered] >= 0).all()
    single = scenes.empty_scene(200, 150, thickness=3.0)
    scenes.grid(single, x_segments=1, y_segments=1, size=3.0)
    scenes.add_camera(single, location=(0.4, -3.0, 3.6), target=(0, 0, 0))
    one_quad = scenes.render_to_file(single, output_dir / "regions_single_quad.png")[..., 3]
    grid_image = scenes.load_png(output_dir / "regions_grid.png")[..., 3]
    assert np.abs(one_quad - grid_image).max() < 3.0 / 255.0


@pytest.mark.parametrize("diagonals", ["HIDDEN", "SOLID"])
def test_density_fade_matches_the_reference(diagonals, output_dir):
    scene = scenes.empty_scene(
        220, 160, use_density_fade=True, density_fade_length=24.0, diagonal_mode=diagonals, thickness=1.0
    )
    scenes.grid(scene, x_segments=48, y_segments=48, size=8.0)
    scenes.add_camera(scene, location=(0.0, -6.5, 1.6), target=(0.0, 1.0, 0.0))
    report = accuracy.measure(scene, f"density_fade_{diagonals.lower()}", output_dir)
    accuracy.assert_accurate(report)
    # Far away the short edges are gone; near the camera lines are drawn.
    ref = reference.render_reference(scene)
    unfaded = reference.SettingsWith(scene.solidwire, use_density_fade=False)
    faded = reference.render_reference(scene, settings=unfaded)
    assert ref.intensity.sum() < 0.8 * faded.intensity.sum()
    assert ref.intensity[: len(ref.rows) // 4].max() > 0.99


# ---------------------------------------------------------------- cage edges


def _subdivided_monkey(scene, levels=2):
    monkey = scenes.monkey(scene, subdivisions=levels, rotation=(0.2, 0.0, 0.5))
    scenes.add_camera(scene, location=(2.0, -4.0, 1.5), target=(0, 0, 0))
    return monkey


@pytest.mark.parametrize(
    "look",
    [
        dict(),
        dict(edge_angle=math.radians(25.0)),
        dict(use_density_fade=True, density_fade_length=30.0, diagonal_mode="DASHED"),
        dict(use_silhouettes=True, use_boundary_edges=True, boundary_thickness=2.5),
        dict(use_hidden_lines=True, use_seam_edges=True),
    ],
)
def test_cage_edges_match_the_reference(look, output_dir):
    """The lines of a subdivided mesh come from its cage edges, running along
    the smooth surface (the reference finds them on its own, through an
    attribute Blender carries onto child edges)."""
    scene = scenes.empty_scene(240, 180, use_cage_edges=True, thickness=1.0, **look)
    monkey = _subdivided_monkey(scene)
    name = "cage_" + ("_".join(look) or "plain")
    before = (set(monkey.data.attributes.keys()), [m.name for m in monkey.modifiers], len(bpy.data.meshes))
    report = accuracy.measure(scene, name, output_dir)
    accuracy.assert_accurate(report)
    assert (set(monkey.data.attributes.keys()), [m.name for m in monkey.modifiers], len(bpy.data.meshes)) == before
    if look.get("use_density_fade") or look.get("use_hidden_lines"):
        return  # (every evaluated edge fades out entirely; hidden lines add lines)
    # Far fewer lines than every evaluated edge.
    every_edge = reference.SettingsWith(scene.solidwire, use_cage_edges=False)
    everything = reference.render_reference(scene, settings=every_edge)
    ref = reference.render_reference(scene)
    assert ref.intensity.sum() < 0.6 * everything.intensity.sum()


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
