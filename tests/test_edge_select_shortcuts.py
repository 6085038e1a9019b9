"""Edge selection's shortcuts for a subdivision's layout give the general
path's arrays bit for bit (core/edge_select.py): the regions the cage
layout gives (blender/cage.py) written per region, region labels found over
runs of consecutive joined faces, and the hidden-edge marks of a mesh of
quads, or of triangles and quads, by row lookup, each against the
components of the faces themselves and the search by vertex pair. On real evaluated meshes: Suzanne's cage at levels
1-5, an n-gon cage, Multiresolution, Mirror and Array copies after the
subdivision (with an Array's caps past the regions), the regions read
from the evaluated mesh's own layout (a modifier before the subdivision,
Edit Mode), and meshes where a shortcut must refuse (triangles and n-gons
under the edge angle, a subdivision whose quads a modifier triangulated,
an Array cap with triangles, a hidden or a classed edge, a layout that
does not hold); cage faces past the walk limit take blocks of their own
edges."""

from __future__ import annotations

import math

import bmesh
import numpy as np
import pytest

from solidwire_addon.blender import cage, mesh_reading
from solidwire_addon.core import edge_select
from tests.support import scenes

ARRAY_FIELDS = (
    "triangles",
    "edge_flags",
    "region_table",
    "region_lines",
    "region_line_runs",
    "triangle_regions",
    "ngon_hidden",
    "ngon_corners",
)


def _general_labels(face_count, f1, f2):
    """The components of the faces themselves, no runs."""
    return edge_select._components(face_count, np.asarray(f1, np.int64), np.asarray(f2, np.int64))


def _select(obj, selection, path, monkeypatch, *, cage_edges_of=None):
    """(arrays, stats, whether the shortcut of ``path`` applied, whether
    the region lines were written per chain) after the selection on
    ``obj``'s evaluated mesh. ``path``: "regions" (the regions the cage
    layout gives, the quad rows as extracted), "shortcuts" (regions found
    over runs, the quad rows checked on the triangles), "general" (neither).
    ``cage_edges_of``: changes the cage's (mask, chains, ends, regions,
    verts) before they are used."""
    import bpy

    obj_eval = obj.evaluated_get(bpy.context.evaluated_depsgraph_get())
    # Edit Mode: to_mesh() gives the edited geometry, as the extraction reads it.
    mesh = obj_eval.to_mesh() if obj.mode == "EDIT" else obj_eval.data
    arrays = mesh_reading.extract_mesh(mesh)
    corner_vert = mesh_reading.read_corner_verts(mesh)
    offsets = mesh_reading.read_face_offsets(mesh)
    cage_edges = None
    if selection.use_cage:
        cage_edges = cage.cage_edges(obj, mesh, render=False, regions=path == "regions")
        assert cage_edges is not None
        if cage_edges_of is not None:
            cage_edges = cage_edges_of(cage_edges)
    applied, per_chain = [], []
    with monkeypatch.context() as patch:
        if path == "general":
            patch.setattr(edge_select, "_mark_quad_rows", lambda *args: False)
            patch.setattr(edge_select, "_mark_tri_and_quad_rows", lambda *args: False)
            patch.setattr(edge_select, "_region_labels", _general_labels)
        else:
            spied = "_select_known_regions" if path == "regions" else "_mark_quad_rows"
            real = getattr(edge_select, spied)

            def spy(*args):
                result = real(*args)
                applied.append(result is not None and result is not False)
                return result

            patch.setattr(edge_select, spied, spy)
            if path == "shortcuts":
                arrays.quad_flip = None  # the rows are checked on the triangles
            real_chains = edge_select._chain_region_lines
            patch.setattr(
                edge_select,
                "_chain_region_lines",
                lambda *args: per_chain.append(real_chains(*args)) or per_chain[-1],
            )
        stats = mesh_reading.apply_edge_selection(arrays, mesh, corner_vert, offsets, selection, cage_edges)
    return arrays, stats, any(applied), any(lines is not None for lines in per_chain)


def _assert_same_arrays(other, general, path="") -> None:
    for field in ARRAY_FIELDS:
        a, b = getattr(other, field), getattr(general, field)
        assert (a is None) == (b is None), (path, field)
        if a is not None:
            assert a.dtype == b.dtype and np.array_equal(a, b), (path, field)
    assert other.region_run_segments == general.region_run_segments, path


def _assert_same_as_general(
    obj,
    selection,
    monkeypatch,
    *,
    rows_expected: bool,
    regions_expected: bool = False,
    chains_expected: bool | None = None,
    cage_edges_of=None,
):
    """The shortcuts give the general path's arrays; ``regions_expected``:
    the known regions apply, and (unless ``chains_expected`` says
    otherwise) write the region lines per chain."""
    if chains_expected is None:
        chains_expected = regions_expected
    general, general_stats, _, _ = _select(obj, selection, "general", monkeypatch, cage_edges_of=cage_edges_of)
    for path, expected in (("shortcuts", rows_expected), ("regions", regions_expected)):
        other, stats, applied, per_chain = _select(obj, selection, path, monkeypatch, cage_edges_of=cage_edges_of)
        assert applied == expected, path
        if path == "regions":
            assert per_chain == chains_expected
        assert stats == general_stats, path
        _assert_same_arrays(other, general, path)
    assert general.region_lines is not None and len(general.region_lines)
    return general


def _subdivide(obj, level):
    modifier = obj.modifiers.new("Subdivision", "SUBSURF")
    modifier.levels = modifier.render_levels = level
    return modifier


CAGE = edge_select.Selection(use_cage=True)


@pytest.mark.parametrize("level", [1, 2, 3, 4, 5])
def test_suzanne_cage_at_every_level(level, monkeypatch):
    scene = scenes.empty_scene()
    obj = scenes.monkey(scene)
    _subdivide(obj, level)
    _assert_same_as_general(obj, CAGE, monkeypatch, rows_expected=True, regions_expected=True)


def _cylinder(scene, segments=12):
    return scenes.tube(scene, "Cylinder", segments=segments)


@pytest.mark.parametrize("level", [1, 3])
def test_ngon_cage(level, monkeypatch):
    scene = scenes.empty_scene()
    obj = _cylinder(scene)
    _subdivide(obj, level)
    _assert_same_as_general(obj, CAGE, monkeypatch, rows_expected=True, regions_expected=True)


def test_mirror_and_array_copies_after_the_subdivision(monkeypatch):
    scene = scenes.empty_scene()
    obj = scenes.monkey(scene)
    _subdivide(obj, 2)
    scenes.add_mirror_and_array(obj, count=3)
    _assert_same_as_general(obj, CAGE, monkeypatch, rows_expected=True, regions_expected=True)


def test_chains_with_the_same_ends_take_the_lines_per_edge(monkeypatch):
    """Two consecutive cage edges whose pieces name the same chain ends
    could be one run of the region-lines pass: the lines are then written
    edge by edge (and still give the general path's arrays)."""
    scene = scenes.empty_scene()
    obj = scenes.monkey(scene)
    _subdivide(obj, 2)

    def same_ends(cage_edges):
        mask, chains, ends, regions, verts = cage_edges
        ends = ends.copy()
        ends[4:8] = ends[0]  # cage edge 1's four pieces end where cage edge 0's do
        return mask, chains, ends, regions, verts

    _assert_same_as_general(
        obj,
        CAGE,
        monkeypatch,
        rows_expected=True,
        regions_expected=True,
        chains_expected=False,
        cage_edges_of=same_ends,
    )


def test_triangles_and_ngons_under_the_edge_angle_take_the_general_marks(monkeypatch):
    scene = scenes.empty_scene()
    obj = _cylinder(scene, segments=24)
    cone = scenes.tube(scene, "Cone", segments=32, top_radius=0.0)
    angle = edge_select.Selection(edge_angle=math.radians(20.0))
    for mesh_object in (obj, cone):
        _assert_same_as_general(mesh_object, angle, monkeypatch, rows_expected=False)
        monkeypatch.undo()


def test_a_subdivision_triangulated_afterwards_takes_the_general_marks(monkeypatch):
    scene = scenes.empty_scene()
    obj = scenes.monkey(scene)
    _subdivide(obj, 2)
    obj.modifiers.new("Triangulate", "TRIANGULATE")
    angle = edge_select.Selection(edge_angle=math.radians(10.0))
    _assert_same_as_general(obj, angle, monkeypatch, rows_expected=False)


@pytest.mark.parametrize("stack", ["own mesh", "triangulated subdivision", "UV sphere"])
def test_triangles_and_quads_take_the_row_lookup(stack, monkeypatch):
    """A mesh of triangles and quads (Suzanne's own, a subdivision
    triangulated afterwards, a UV sphere's fans) under the edge angle and
    the classes marks its rows by the lookup per row: the general path's
    arrays."""
    scene = scenes.empty_scene()
    if stack == "UV sphere":
        obj = scenes.mesh_object(
            scene, "Sphere", lambda bm: bmesh.ops.create_uvsphere(bm, u_segments=12, v_segments=8, radius=1.0)
        )
    else:
        obj = scenes.monkey(scene)
    if stack == "triangulated subdivision":
        _subdivide(obj, 1)
        obj.modifiers.new("Triangulate", "TRIANGULATE")
    for edge in obj.data.edges:
        edge.use_seam = edge.index % 7 == 0
    selection = edge_select.Selection(edge_angle=math.radians(15.0), classes=("seam",))
    general, general_stats, _, _ = _select(obj, selection, "general", monkeypatch)
    taken = []
    real = edge_select._mark_tri_and_quad_rows
    monkeypatch.setattr(edge_select, "_mark_tri_and_quad_rows", lambda *args: taken.append(real(*args)) or taken[-1])
    other, stats, _, _ = _select(obj, selection, "regions", monkeypatch)
    assert taken == [True]
    assert stats == general_stats
    _assert_same_arrays(other, general)
    hidden = general.edge_flags & (edge_select.EDGE0_HIDDEN | edge_select.EDGE3_HIDDEN)
    assert hidden.any()


def test_concave_quads_split_along_their_other_diagonal(monkeypatch):
    """A quad split from its corner 3 (concave, as Blender splits it) takes
    the row lookup turned to that corner."""
    import bpy

    scene = scenes.empty_scene()
    # Chevrons: each quad's second corner dents in past the diagonal from its
    # first corner to its third.
    verts, faces = [], []
    for k in range(4):
        x = 2.5 * k
        base = len(verts)
        verts += [(x, 0.0, 0.0), (x + 1.0, 0.5, 0.0), (x + 2.0, 0.0, 0.0), (x + 1.0, 2.0, 0.0)]
        faces.append((base, base + 1, base + 2, base + 3))
    obj = scenes.from_pydata(scene, "Chevrons", verts, faces)
    _subdivide(obj, 1).subdivision_type = "SIMPLE"
    mesh = obj.evaluated_get(bpy.context.evaluated_depsgraph_get()).data
    arrays = mesh_reading.extract_mesh(mesh)
    quads = mesh_reading.read_corner_verts(mesh).reshape(-1, 4)
    assert (arrays.triangles[0::2, 0] != quads[:, 0]).any()  # some quads split the other way
    _assert_same_as_general(obj, CAGE, monkeypatch, rows_expected=True, regions_expected=True)


@pytest.mark.parametrize(("segments", "level"), [(24, 3), (5, 5)])
def test_cage_faces_past_the_walk_limit(segments, level, monkeypatch):
    """A cage face whose region is past WALK_LIMIT (a 24-gon at level 3:
    192 drawn edges; a pentagon at level 5: 160), from the object's own
    mesh or behind a modifier: its faces get blocks of their own drawn
    edges, as the general path gives them, beside the side quads' region
    blocks."""
    assert segments * 2**level > edge_select.WALK_LIMIT
    scene = scenes.empty_scene()
    cylinder = _cylinder(scene, segments=segments)
    _subdivide(cylinder, level)
    _assert_same_as_general(cylinder, CAGE, monkeypatch, rows_expected=True, regions_expected=True)
    behind = _cylinder(scene, segments=segments)
    behind.modifiers.new("Mirror", "MIRROR").use_mirror_merge = False
    _subdivide(behind, level)
    _assert_same_as_general(behind, CAGE, monkeypatch, rows_expected=True, regions_expected=True)


ALL_CLASSES = edge_select.Selection(classes=tuple(edge_select.EDGE_CLASSES), use_cage=True)


# The line styles of the classes _mark_classes marks, and of the boundary class.
_STYLES = {1.0 + edge_select.EDGE_CLASSES.index(name) for name in ("seam", "sharp", "crease")}
_BOUNDARY = 1.0 + edge_select.EDGE_CLASSES.index("boundary")


def _mark_classes(obj, count):
    """Seam, sharp and crease marks on the first ``count`` cage edges, a
    third of them in two classes at once (two segments and two line
    entries each)."""
    for edge in obj.data.edges[:count]:
        edge.use_seam = edge.index % 3 != 1
        edge.use_edge_sharp = edge.index % 3 != 0
    crease = obj.data.attributes.new("crease_edge", "FLOAT", "EDGE")
    crease.data.foreach_set("value", [1.0 if index % 4 == 0 else 0.0 for index in range(len(obj.data.edges))])


@pytest.mark.parametrize(("shape", "marked"), [("sphere", False), ("sphere", True), ("Suzanne", True)])
def test_edge_classes_beside_the_cage_keep_its_regions(shape, marked, monkeypatch):
    """Every edge class on (the Edge Classes preset) beside the cage: marks
    live on cage edges, and a subdivision's boundary edges (Suzanne's eye
    holes) are cage children, so the classes only style edges the cage
    draws. The cage's regions apply, the classed edges' segments and line
    entries one per class, as the general path lays them out."""
    scene = scenes.empty_scene()
    if shape == "sphere":
        obj = scenes.mesh_object(
            scene,
            "Sphere",
            lambda bm: bmesh.ops.create_uvsphere(bm, u_segments=12, v_segments=8, radius=1.0),
        )
    else:
        obj = scenes.monkey(scene)
    if marked:
        _mark_classes(obj, 40)
    _subdivide(obj, 2)
    general = _assert_same_as_general(obj, ALL_CLASSES, monkeypatch, rows_expected=True, regions_expected=True)
    styles = set(general.region_lines[0::2, 2].tolist())
    assert styles == ({0.0, *_STYLES} if marked else {0.0}) | ({_BOUNDARY} if shape == "Suzanne" else set())


def test_edge_classes_on_cage_faces_past_the_walk_limit(monkeypatch):
    """Classed edges around a 24-gon cap at level 3 (a region past
    WALK_LIMIT, whose faces get blocks of their own edges) and on the side
    quads' regions: the general path's blocks, one segment per class."""
    scene = scenes.empty_scene()
    cylinder = _cylinder(scene, segments=24)
    _mark_classes(cylinder, len(cylinder.data.edges) // 2)
    _subdivide(cylinder, 3)
    general = _assert_same_as_general(cylinder, ALL_CLASSES, monkeypatch, rows_expected=True, regions_expected=True)
    assert set(general.region_table[0::2, 2].tolist()) >= {0.0, *_STYLES}


@pytest.mark.parametrize(
    ("shape", "before", "degrees", "classes"),
    [
        ("Suzanne", None, 20.0, ()),
        ("Suzanne", None, 40.0, tuple(edge_select.EDGE_CLASSES)),
        ("Suzanne", "MIRROR", 30.0, ()),
        ("Cylinder", None, 20.0, ()),
    ],
)
def test_the_edge_angle_beside_the_cage_joins_its_regions(shape, before, degrees, classes, monkeypatch):
    """The edge angle beside the cage look hides cage edges between faces
    that meet at less than the angle: the cage faces on either side form
    one region (join_regions), from the object's own mesh or from the
    layout behind a modifier, with classes, and with a 24-gon cap whose
    region is past the walk limit: the general path's arrays."""
    scene = scenes.empty_scene()
    obj = scenes.monkey(scene) if shape == "Suzanne" else _cylinder(scene, segments=24)
    if classes:
        _mark_classes(obj, 40)
    if before:
        _modifier_before(obj, before)
    _subdivide(obj, 2 if shape == "Suzanne" else 3)
    selection = edge_select.Selection(edge_angle=math.radians(degrees), classes=classes, use_cage=True)
    joins = []
    real_join = edge_select.join_regions
    monkeypatch.setattr(edge_select, "join_regions", lambda *args: joins.append(real_join(*args)) or joins[-1])
    general = _assert_same_as_general(
        obj, selection, monkeypatch, rows_expected=True, regions_expected=True, chains_expected=False
    )
    joined = [regions for regions in joins if regions is not None and regions.piece_region is not None]
    assert joined, "some cage faces are joined"
    merged = joined[-1]
    assert len(merged.edge_start) - 1 < len(merged.face_start) - 1  # fewer regions than cage faces
    assert len(set(general.triangle_regions.tolist())) == len(merged.edge_start) - 1


@pytest.mark.parametrize(
    ("caps", "level", "stack"),
    [
        ("end", 1, "own mesh"),
        ("both", 3, "own mesh"),
        ("both", 2, "Mirror before"),
        ("end", 2, "Edit Mode"),
        ("big end", 1, "own mesh"),
    ],
)
def test_an_array_with_caps_keeps_the_cage_regions(caps, level, stack, monkeypatch):
    """The caps an Array adds after its copies (quads here) are plain faces
    past the listed regions. Where they are a small share of the mesh
    (edge_select.PLAIN_LISTED_SHARE) they are listed too, each face a
    region of its own, and the general path lists them; where they are
    more (a big grid as the cap), the regions the layout gives still apply,
    with the general path's arrays, the caps' triangles in no region. The
    regions are read from the object's own mesh, or from the evaluated
    mesh's layout (a modifier before the subdivision, Edit Mode)."""
    import bpy

    scene = scenes.empty_scene()
    capped = scenes.monkey(scene)
    if stack == "Mirror before":
        _modifier_before(capped, "MIRROR")
    _subdivide(capped, level)
    array = scenes.add_mirror_and_array(capped, count=2, offset=(1.3, 0.0, 0.0))
    if caps == "big end":
        array.end_cap = scenes.grid(scene, "End cap", x_segments=61, y_segments=61, size=0.4)
    else:
        array.end_cap = scenes.cube(scene, "End cap", size=0.4)
    if caps == "both":
        array.start_cap = scenes.cube(scene, "Start cap", size=0.3, location=(0.0, 2.0, 0.0))
    cap_faces = len(array.end_cap.data.polygons) + (6 if caps == "both" else 0)
    face_count = len(capped.evaluated_get(bpy.context.evaluated_depsgraph_get()).data.polygons)
    listed_too = cap_faces <= edge_select.PLAIN_LISTED_SHARE * face_count
    assert listed_too == (caps != "big end")
    if stack == "Edit Mode":
        bpy.context.view_layer.objects.active = capped
        capped.select_set(True)
        bpy.ops.object.mode_set(mode="EDIT")
    try:
        general = _assert_same_as_general(
            capped, CAGE, monkeypatch, rows_expected=True, regions_expected=not listed_too
        )
    finally:
        if stack == "Edit Mode":
            bpy.ops.object.mode_set(mode="OBJECT")
    cap_regions = general.triangle_regions[-2 * cap_faces :]
    if listed_too:  # a region each
        assert len(np.unique(cap_regions)) == cap_faces and (cap_regions >= 0).all()
        assert not np.isin(cap_regions, general.triangle_regions[: -2 * cap_faces]).any()
    else:
        assert (cap_regions == edge_select.NO_REGION).all()
    assert (general.triangle_regions[: -2 * cap_faces] >= 0).all()


def test_the_cage_regions_refuse_what_they_cannot_tell(monkeypatch):
    """An Array whose cap has triangles (no quad rows), a hidden edge (the
    edge angle beside the cage look hides a flat cap's inner edges) or an
    edge of a drawn class (its border, of the boundary class) takes the
    regions found from the mesh."""
    scene = scenes.empty_scene()
    capped = scenes.monkey(scene)
    _subdivide(capped, 1)
    array = capped.modifiers.new("Array", "ARRAY")
    array.use_merge_vertices = False
    array.end_cap = scenes.monkey(scene)  # its triangles: no quad rows either
    _assert_same_as_general(capped, CAGE, monkeypatch, rows_expected=False, regions_expected=False)
    bpy = pytest.importorskip("bpy")
    flat_cap = scenes.grid(scene, "Flat cap", x_segments=3, y_segments=3, size=0.5)
    array.end_cap = flat_cap  # a flat grid: the angle hides its inner edges
    angle = edge_select.Selection(use_cage=True, edge_angle=math.radians(10.0))
    bpy.context.view_layer.update()
    _assert_same_as_general(capped, angle, monkeypatch, rows_expected=True, regions_expected=False)
    # Without the angle every edge of the flat cap is drawn, and its border
    # is of the boundary class: a cap face with a classed edge is listed.
    boundary = edge_select.Selection(use_cage=True, classes=("boundary",))
    _assert_same_as_general(capped, boundary, monkeypatch, rows_expected=True, regions_expected=False)


def _modifier_before(obj, kind):
    modifier = obj.modifiers.new(kind, kind)
    if kind == "MIRROR":
        modifier.use_mirror_merge = False
    elif kind == "BEVEL":
        modifier.width = 0.02
        modifier.segments = 2
    elif kind == "SOLIDIFY":
        modifier.thickness = 0.05
    return modifier


@pytest.mark.parametrize(
    ("kind", "level"), [("MIRROR", 1), ("MIRROR", 2), ("MIRROR", 4), ("BEVEL", 2), ("SOLIDIFY", 3)]
)
def test_cage_regions_behind_a_modifier_before_the_subdivision(kind, level, monkeypatch):
    """The subdivision's input is not the object's own mesh: its regions are
    read from the evaluated mesh's layout (edge_select.regions_from_layout)."""
    scene = scenes.empty_scene()
    obj = scenes.monkey(scene)
    _modifier_before(obj, kind)
    _subdivide(obj, level)
    _assert_same_as_general(obj, CAGE, monkeypatch, rows_expected=True, regions_expected=True)


def test_ngon_cage_behind_a_merging_mirror_with_copies_after(monkeypatch):
    """n-gon cage faces, a Mirror that merges vertices before the
    subdivision, Mirror and Array copies after it."""
    scene = scenes.empty_scene()
    obj = _cylinder(scene, segments=9)
    obj.modifiers.new("Mirror", "MIRROR").use_mirror_merge = True
    _subdivide(obj, 2)
    after = obj.modifiers.new("MirrorAfter", "MIRROR")
    after.use_axis = (False, True, False)
    after.use_mirror_merge = False
    array = obj.modifiers.new("Array", "ARRAY")
    array.count = 2
    array.use_merge_vertices = False
    # Merged on the mirror plane, some cage edges bound four faces: their
    # lines are one entry per pair of regions, not one per chain.
    _assert_same_as_general(obj, CAGE, monkeypatch, rows_expected=True, regions_expected=True, chains_expected=False)


@pytest.mark.parametrize("before", [None, "MIRROR"])
def test_cage_regions_in_edit_mode(before, monkeypatch):
    """Edit Mode: the regions come from the evaluated mesh's layout, before
    and after a topology edit of the BMesh (n-gons made by cutting edges)."""
    import bpy

    scene = scenes.empty_scene()
    obj = scenes.monkey(scene)
    if before:
        _modifier_before(obj, before)
    _subdivide(obj, 2)
    bpy.context.view_layer.objects.active = obj
    obj.select_set(True)
    bpy.ops.object.mode_set(mode="EDIT")
    try:
        _assert_same_as_general(obj, CAGE, monkeypatch, rows_expected=True, regions_expected=True)
        bm = bmesh.from_edit_mesh(obj.data)
        bm.edges.ensure_lookup_table()
        bmesh.ops.subdivide_edges(bm, edges=[bm.edges[i] for i in range(0, 40, 3)], cuts=1)  # n-gons
        bmesh.update_edit_mesh(obj.data)
        _assert_same_as_general(obj, CAGE, monkeypatch, rows_expected=True, regions_expected=True)
    finally:
        bpy.ops.object.mode_set(mode="OBJECT")


def _layout_inputs(obj):
    """(layout, corner_vert, corner_edge, edge verts, drawn, face count) of
    ``obj``'s evaluated mesh, a modifier before its subdivision."""
    import bpy

    mesh = obj.evaluated_get(bpy.context.evaluated_depsgraph_get()).data
    drawn, _chain, _ends, known_regions, _verts = cage.cage_edges(obj, mesh, render=False, regions=True)
    layout = known_regions()
    assert isinstance(layout, edge_select.SubdivisionLayout)
    verts, corner_edge = mesh_reading.read_edge_topology(mesh)
    corner_vert = mesh_reading.read_corner_verts(mesh)
    return layout, corner_vert, corner_edge, verts, drawn, len(mesh.polygons)


def test_a_layout_that_does_not_hold_gives_no_regions():
    """Each thing regions_from_layout reads is checked: children of two
    coarse faces swapped, a child of one moved into another's run, a count
    one off, a drawn mask that is not the first edges."""
    import dataclasses

    scene = scenes.empty_scene()
    obj = scenes.monkey(scene)
    _modifier_before(obj, "MIRROR")
    _subdivide(obj, 2)
    layout, corner_vert, corner_edge, verts, drawn, faces = _layout_inputs(obj)
    known = edge_select.regions_from_layout(layout, corner_vert, corner_edge, verts, drawn, faces)
    assert known is not None and len(known.face_start) == layout.coarse_faces + 1
    n = 1 << layout.level
    assert known.chain_edges == n  # each coarse edge's children listed whole

    def refused(**changed):
        args = dict(corner_vert=corner_vert, corner_edge=corner_edge, verts=verts, drawn=drawn, layout=layout)
        args.update(changed)
        return (
            edge_select.regions_from_layout(
                args["layout"], args["corner_vert"], args["corner_edge"], args["verts"], args["drawn"], faces
            )
            is None
        )

    quads = corner_vert.reshape(-1, 4)
    swapped = quads.copy()
    swapped[[0, -1]] = swapped[[-1, 0]]  # a child of the first coarse face and of the last
    assert refused(
        corner_vert=swapped.reshape(-1),
        corner_edge=corner_edge.reshape(-1, 4)[[-1, *range(1, faces - 1), 0]].reshape(-1),
    )
    moved = quads.copy()
    moved[0, 1] = moved[16 * 4, 0]  # a vertex of a later coarse face's own
    assert refused(corner_vert=moved.reshape(-1))
    assert refused(layout=dataclasses.replace(layout, coarse_faces=layout.coarse_faces - 1))
    assert refused(layout=dataclasses.replace(layout, subdivided_verts=layout.subdivided_verts + 1))
    assert refused(layout=dataclasses.replace(layout, coarse_edges=layout.coarse_edges - 1))
    shifted = drawn.copy()
    shifted[layout.coarse_edges * n - 1] = False
    assert refused(drawn=shifted)


def test_multires_cage(monkeypatch):
    """Multiresolution subdivides through the same layout as Subdivision
    Surface: its cage regions give the general path's arrays too."""
    import bpy

    scene = scenes.empty_scene()
    obj = scenes.monkey(scene)
    modifier = obj.modifiers.new("Multires", "MULTIRES")
    with bpy.context.temp_override(object=obj, active_object=obj):
        for _ in range(2):
            bpy.ops.object.multires_subdivide(modifier=modifier.name, mode="CATMULL_CLARK")
    _assert_same_as_general(obj, CAGE, monkeypatch, rows_expected=True, regions_expected=True)


@pytest.mark.parametrize("seed", range(16))
def test_random_marks_angles_and_stacks_give_the_general_path_arrays(seed, monkeypatch):
    """Seeded random cases of what the known regions take: Suzanne, a
    cylinder with n-gon caps or a UV sphere, random seam and sharp marks,
    a modifier before the subdivision or none, levels 1-3, an edge angle
    from none to 20 degrees and a random set of classes beside the cage:
    the general path's arrays, whether the regions were taken or not."""
    rng = np.random.default_rng(seed)
    scene = scenes.empty_scene()
    shape = ("Suzanne", "cylinder", "sphere")[seed % 3]
    if shape == "Suzanne":
        obj = scenes.monkey(scene)
    elif shape == "cylinder":
        obj = _cylinder(scene, segments=int(rng.integers(5, 30)))
    else:
        obj = scenes.mesh_object(
            scene, "Sphere", lambda bm: bmesh.ops.create_uvsphere(bm, u_segments=10, v_segments=7, radius=1.0)
        )
    for edge in obj.data.edges:
        draw = rng.random()
        edge.use_seam = draw < 0.15
        edge.use_edge_sharp = 0.1 < draw < 0.2
    if rng.random() < 0.4:
        _modifier_before(obj, str(rng.choice(["MIRROR", "BEVEL", "SOLIDIFY"])))
    _subdivide(obj, int(rng.integers(1, 4)))
    selection = edge_select.Selection(
        edge_angle=math.radians(float(rng.choice([0.0, 2.0, 5.0, 10.0, 20.0]))),
        classes=tuple(name for name in edge_select.EDGE_CLASSES if rng.random() < 0.5),
        use_cage=True,
    )
    general, general_stats, _, _ = _select(obj, selection, "general", monkeypatch)
    other, stats, _applied, _per_chain = _select(obj, selection, "regions", monkeypatch)
    assert stats == general_stats
    _assert_same_arrays(other, general)
