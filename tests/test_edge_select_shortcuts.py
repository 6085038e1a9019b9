"""Edge selection's shortcuts for a subdivision's layout give the general
path's arrays bit for bit (core/edge_select.py): the regions the cage
layout gives (blender/cage.py) written per region, region labels found over
runs of consecutive joined faces, and a quad-only mesh's hidden-edge marks
by row lookup, each against the components of the faces themselves and the
search by vertex pair. On real evaluated meshes: Suzanne's cage at levels
1-5, an n-gon cage, Multiresolution, Mirror and Array copies after the
subdivision, and meshes where a shortcut must refuse (triangles and n-gons
under the edge angle, a subdivision whose quads a modifier triangulated, a
modifier before the subdivision, a cage face past the walk limit)."""

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


def _select(obj, selection, path, monkeypatch):
    """(arrays, stats, whether the shortcut of ``path`` applied) after the
    selection on ``obj``'s evaluated mesh. ``path``: "regions" (the regions
    the cage layout gives, the quad rows as extracted), "shortcuts" (regions
    found over runs, the quad rows checked on the triangles), "general"
    (neither)."""
    import bpy

    mesh = obj.evaluated_get(bpy.context.evaluated_depsgraph_get()).data
    arrays = mesh_reading.extract_mesh(mesh)
    corner_vert = mesh_reading.read_corner_verts(mesh)
    offsets = mesh_reading.read_face_offsets(mesh)
    cage_edges = None
    if selection.use_cage:
        cage_edges = cage.cage_edges(obj, mesh, render=False, regions=path == "regions")
        assert cage_edges is not None
    applied = []
    with monkeypatch.context() as patch:
        if path == "general":
            patch.setattr(edge_select, "_mark_quad_rows", lambda *args: False)
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
        stats = mesh_reading.apply_edge_selection(arrays, mesh, corner_vert, offsets, selection, cage_edges)
    return arrays, stats, any(applied)


def _assert_same_as_general(obj, selection, monkeypatch, *, rows_expected: bool, regions_expected: bool = False):
    general, general_stats, _ = _select(obj, selection, "general", monkeypatch)
    for path, expected in (("shortcuts", rows_expected), ("regions", regions_expected)):
        other, stats, applied = _select(obj, selection, path, monkeypatch)
        assert applied == expected, path
        assert stats == general_stats, path
        for field in ARRAY_FIELDS:
            a, b = getattr(other, field), getattr(general, field)
            assert (a is None) == (b is None), (path, field)
            if a is not None:
                assert a.dtype == b.dtype and np.array_equal(a, b), (path, field)
        assert other.region_run_segments == general.region_run_segments, path
    assert general.region_lines is not None and len(general.region_lines)


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
    def build(bm):
        bmesh.ops.create_cone(bm, cap_ends=True, segments=segments, radius1=1.0, radius2=1.0, depth=2.0)

    return scenes.mesh_object(scene, "Cylinder", build)


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
    mirror = obj.modifiers.new("Mirror", "MIRROR")
    mirror.use_mirror_merge = False
    array = obj.modifiers.new("Array", "ARRAY")
    array.count = 3
    array.use_merge_vertices = False
    _assert_same_as_general(obj, CAGE, monkeypatch, rows_expected=True, regions_expected=True)


def test_triangles_and_ngons_under_the_edge_angle_take_the_general_marks(monkeypatch):
    scene = scenes.empty_scene()
    obj = _cylinder(scene, segments=24)
    cone = scenes.mesh_object(
        scene,
        "Cone",
        lambda bm: bmesh.ops.create_cone(bm, cap_ends=True, segments=32, radius1=1.0, radius2=0.0, depth=2.0),
    )
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


def test_the_cage_regions_refuse_what_they_cannot_tell(monkeypatch):
    """A modifier before the subdivision (its input is not the object's own
    mesh) and a cage face whose region is past WALK_LIMIT (a 24-gon at level
    3: 192 drawn edges) take the regions found from the mesh."""
    scene = scenes.empty_scene()
    obj = scenes.monkey(scene)
    obj.modifiers.new("Mirror", "MIRROR").use_mirror_merge = False
    _subdivide(obj, 2)
    _assert_same_as_general(obj, CAGE, monkeypatch, rows_expected=True, regions_expected=False)
    cylinder = _cylinder(scene, segments=24)
    _subdivide(cylinder, 3)
    _assert_same_as_general(cylinder, CAGE, monkeypatch, rows_expected=True, regions_expected=False)


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
