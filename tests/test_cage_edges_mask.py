"""Cage edges (blender/cage.py): which evaluated edges of a subdivided mesh
come from edges of its cage, read from Blender's subdivision edge order and
checked here against the geometry, never against that order itself."""

from __future__ import annotations

import math

import bmesh
import bpy
import numpy as np
import pytest
from mathutils import Matrix

from solidwire_addon.blender.cage import cage_edge_mask, cage_key, peel
from tests.support import scenes

# -- helpers ---------------------------------------------------------------


def _evaluated(obj):
    """(evaluated object, evaluated mesh, cleanup) as gather() reads them:
    Object.data, or to_mesh() in Edit Mode."""
    depsgraph = bpy.context.evaluated_depsgraph_get()
    obj_eval = obj.evaluated_get(depsgraph)
    if obj.mode == "EDIT":
        return obj_eval, obj_eval.to_mesh(), obj_eval.to_mesh_clear
    return obj_eval, obj_eval.data, lambda: None


def _mask(obj, *, render=False, original=False):
    obj_eval, mesh, cleanup = _evaluated(obj)
    try:
        mask = cage_edge_mask(obj if original else obj_eval, mesh, render=render)
        return mask, _edges(mesh), _positions(mesh)
    finally:
        cleanup()


def _edges(mesh) -> np.ndarray:
    out = np.empty(2 * len(mesh.edges), dtype=np.int32)
    mesh.edges.foreach_get("vertices", out)
    return out.reshape(-1, 2)


def _positions(mesh) -> np.ndarray:
    out = np.empty(3 * len(mesh.vertices), dtype=np.float64)
    mesh.vertices.foreach_get("co", out)
    return out.reshape(-1, 3)


def _on_box_edge(p, q, center=(0.0, 0.0, 0.0), half=1.0, tol=1e-5):
    """Both points on one edge of the axis-aligned box (|x - c| <= half):
    they share two coordinates that are at the box's extent."""
    p = np.asarray(p) - center
    q = np.asarray(q) - center
    shared = [i for i in range(3) if abs(abs(p[i]) - half) < tol and abs(p[i] - q[i]) < tol]
    return len(shared) >= 2


def _box_edge_set(edges, positions, centers):
    return {i for i, (a, b) in enumerate(edges) if any(_on_box_edge(positions[a], positions[b], c) for c in centers)}


def _subdivided_cube(levels=1, kind="CATMULL_CLARK", name="Cube"):
    scene = scenes.empty_scene()
    obj = scenes.cube(scene, name)
    mod = obj.modifiers.new("Subdivision", "SUBSURF")
    mod.subdivision_type = kind
    mod.levels = mod.render_levels = levels
    return scene, obj, mod


def _assert_simple_cube_cage(mask, edges, positions, cage_edges=12, centers=((0.0, 0.0, 0.0),), level=1):
    assert mask is not None and mask.dtype == bool and mask.shape == (len(edges),)
    assert int(mask.sum()) == cage_edges * 2**level
    assert set(np.flatnonzero(mask).tolist()) == _box_edge_set(edges, positions, centers)


def _assert_catmull_clark_cube_cage(mask, edges, positions, level):
    """The masked edges are 12 chains of 2^L edges joining the 8 evaluated
    corner vertices (one per original corner, on its diagonal)."""
    n = 2**level
    assert mask is not None and int(mask.sum()) == 12 * n
    masked = edges[mask]
    degree = np.bincount(masked.ravel(), minlength=len(positions))
    corners = np.flatnonzero(degree == 3)
    assert len(corners) == 8
    assert int((degree == 2).sum()) == 12 * (n - 1)
    assert int((degree > 3).sum()) == 0
    directions = positions[corners] / np.linalg.norm(positions[corners], axis=1, keepdims=True)
    assert np.allclose(np.abs(directions), 1 / math.sqrt(3), atol=1e-4)
    assert len({tuple(np.sign(d).astype(int)) for d in directions}) == 8  # one per original corner
    # Walk each chain from a corner: 2^L edges to another corner.
    neighbours: dict[int, list[int]] = {}
    for a, b in masked:
        neighbours.setdefault(int(a), []).append(int(b))
        neighbours.setdefault(int(b), []).append(int(a))
    corner_set = set(corners.tolist())
    chains = 0
    for start in corners:
        for first in neighbours[int(start)]:
            prev, cur, length = int(start), first, 1
            while cur not in corner_set:
                nxt = [v for v in neighbours[cur] if v != prev]
                assert len(nxt) == 1
                prev, cur, length = cur, nxt[0], length + 1
            assert length == n and cur != start
            chains += 1
    assert chains == 24  # 12 chains, walked from both ends


# -- Subdivision Surface -----------------------------------------------------


@pytest.mark.parametrize("level", [1, 2, 3])
def test_simple_subdivision_masks_exactly_the_edges_on_the_cube_edges(level):
    _scene, obj, _mod = _subdivided_cube(level, "SIMPLE")
    mask, edges, positions = _mask(obj)
    _assert_simple_cube_cage(mask, edges, positions, level=level)


@pytest.mark.parametrize("level", [1, 2, 3])
def test_catmull_clark_masks_chains_between_the_original_corners(level):
    _scene, obj, _mod = _subdivided_cube(level)
    mask, edges, positions = _mask(obj)
    _assert_catmull_clark_cube_cage(mask, edges, positions, level)


def test_original_and_evaluated_object_give_the_same_mask():
    _scene, obj, _mod = _subdivided_cube(2)
    from_eval, _e, _p = _mask(obj)
    from_orig, _e, _p = _mask(obj, original=True)
    assert np.array_equal(from_eval, from_orig)


def test_no_modifier_level_zero_or_disabled_draws_everything():
    scene = scenes.empty_scene()
    plain = scenes.cube(scene, "Plain")
    assert _mask(plain)[0] is None
    _scene, obj, mod = _subdivided_cube(0)
    assert _mask(obj)[0] is None
    mod.levels = 2
    mod.show_viewport = False
    assert _mask(obj)[0] is None


def test_mirror_before_the_subdivision():
    scene = scenes.empty_scene()
    obj = scenes.mesh_object(
        scene, "Half", lambda bm: bmesh.ops.create_cube(bm, size=2.0, matrix=Matrix.Translation((2.0, 0.0, 0.0)))
    )
    obj.modifiers.new("Mirror", "MIRROR")
    mod = obj.modifiers.new("Subdivision", "SUBSURF")
    mod.subdivision_type = "SIMPLE"
    mod.levels = 2
    mask, edges, positions = _mask(obj)
    _assert_simple_cube_cage(mask, edges, positions, cage_edges=24, centers=((2, 0, 0), (-2, 0, 0)), level=2)


def test_a_deform_modifier_after_the_subdivision_keeps_the_mask():
    _scene, obj, _mod = _subdivided_cube(2)
    before, edges, positions = _mask(obj)
    texture = bpy.data.textures.new("Noise", "CLOUDS")
    displace = obj.modifiers.new("Displace", "DISPLACE")
    displace.texture = texture
    displace.strength = 0.2
    smooth = obj.modifiers.new("Smooth", "SMOOTH")
    after, edges_after, positions_after = _mask(obj)
    assert not np.allclose(positions, positions_after)  # it did move the vertices
    assert np.array_equal(before, after) and np.array_equal(edges, edges_after)
    smooth.show_viewport = False
    assert np.array_equal(_mask(obj)[0], before)


@pytest.mark.parametrize("kind", ["TRIANGULATE", "SOLIDIFY", "DECIMATE", "NODES"])
def test_a_topology_changing_modifier_after_the_subdivision_gives_none(kind):
    _scene, obj, _mod = _subdivided_cube(2)
    obj.modifiers.new("After", kind)
    assert _mask(obj)[0] is None
    obj.modifiers["After"].show_viewport = False  # disabled: does not count
    assert _mask(obj)[0] is not None


def test_only_the_last_of_stacked_subdivisions_hides_edges():
    """Blender's subdivision marks the children of every edge of its input,
    whatever an earlier subdivision marked (subdiv_mesh.cc): with two
    stacked modifiers the drawn edges are the children of every edge the
    first one made, and the first one's Optimal Display changes nothing."""
    _scene, obj, mod = _subdivided_cube(1, "SIMPLE")
    second = obj.modifiers.new("Second", "SUBSURF")
    second.subdivision_type = "SIMPLE"
    second.levels = 1
    for first_optimal in (True, False):
        mod.show_only_control_edges = first_optimal
        mask, edges, positions = _mask(obj)
        first_level_edges = 12 * 2 + 6 * 4  # a cube subdivided once: 48 edges
        assert mask is not None and int(mask.sum()) == 2 * first_level_edges
        # Each drawn edge lies on a line of the first level's grid: the two
        # coordinates it does not run along are 0 or +-1 (never +-0.5).
        a, b = positions[edges[mask, 0]], positions[edges[mask, 1]]
        fixed = np.isclose(a, b, atol=1e-5)
        assert (fixed.sum(axis=1) == 2).all()
        assert np.isin(np.round(np.abs(a[fixed]), 4), (0.0, 1.0)).all()
    # The last one's Optimal Display off: every edge.
    second.show_only_control_edges = False
    assert _mask(obj)[0] is None


def test_optimal_display_off_shows_every_edge():
    _scene, obj, mod = _subdivided_cube(2, "SIMPLE")
    mod.show_only_control_edges = False
    assert _mask(obj)[0] is None
    mod.show_only_control_edges = True
    mask, edges, positions = _mask(obj)
    _assert_simple_cube_cage(mask, edges, positions, level=2)


# -- modifiers after the subdivision that keep the cage (as Blender's overlay) ----------


def _half_cube(scene, name="Half"):
    """A cube spanning x in [0, 2] without its face at x = 0: the half a
    Mirror completes (its open border stays on the mirror plane under
    subdivision, so a merging Mirror merges it)."""

    def build(bm):
        bmesh.ops.create_cube(bm, size=2.0, matrix=Matrix.Translation((1.0, 0.0, 0.0)))
        border = [f for f in bm.faces if all(abs(v.co.x) < 1e-6 for v in f.verts)]
        bmesh.ops.delete(bm, geom=border, context="FACES_ONLY")

    return scenes.mesh_object(scene, name, build)


def _subdivide(obj, level=1, kind="SIMPLE"):
    mod = obj.modifiers.new("Subdivision", "SUBSURF")
    mod.subdivision_type = kind
    mod.levels = mod.render_levels = level
    return mod


def _mirror(obj, *, merge=False, axes=(True, False, False)):
    mod = obj.modifiers.new("Mirror", "MIRROR")
    mod.use_mirror_merge = merge
    for axis, on in enumerate(axes):
        mod.use_axis[axis] = on
    return mod


def _array(obj, count=3, *, merge=False, offset=(1.2, 0.0, 0.0)):
    mod = obj.modifiers.new("Array", "ARRAY")
    mod.count = count
    mod.use_merge_vertices = merge
    mod.relative_offset_displace = offset
    return mod


def _half_cube_cage_count(level):
    return 12 * 2**level  # the open half cube keeps all 12 edges: 2^L children each


def _assert_copies_of(mask, copies, per_copy_mask):
    """``mask`` is ``copies`` copies of the subdivided mesh's own mask."""
    assert mask is not None and len(mask) == copies * len(per_copy_mask)
    assert np.array_equal(mask.reshape(copies, -1), np.tile(per_copy_mask, (copies, 1)))


@pytest.mark.parametrize("merge", [False, True])
def test_mirror_after_the_subdivision_keeps_the_cage_unless_it_merges(merge):
    scene = scenes.empty_scene()
    obj = _half_cube(scene)
    _subdivide(obj, 2, "CATMULL_CLARK")
    alone, _edges, _positions = _mask(obj)
    assert int(alone.sum()) == _half_cube_cage_count(2)
    mirror = _mirror(obj, merge=merge)
    mask, edges, positions = _mask(obj)
    if merge:
        # The border merged: Blender's merge makes a new mesh without the
        # Optimal Display marks, and its overlay shows every edge.
        assert len(edges) < 2 * len(alone) and mask is None
        # Merge on but nothing near enough to merge: still the cage.
        mirror.merge_threshold = 1e-6
        for vertex in obj.data.vertices:
            vertex.co.x += 0.5
        obj.data.update()
        _assert_copies_of(_mask(obj)[0], 2, alone)
        return
    _assert_copies_of(mask, 2, alone)
    # Both halves' cage edges, mirror images of each other.
    middles = positions[edges[mask]].mean(axis=1)
    drawn = np.round(middles, 4)
    mirrored = np.round(middles * (-1.0, 1.0, 1.0), 4)
    assert {tuple(m) for m in drawn} == {tuple(m) for m in mirrored}


def test_mirror_on_several_axes_and_an_array_after_it():
    scene = scenes.empty_scene()
    obj = _half_cube(scene)
    _subdivide(obj, 1)
    alone = _mask(obj)[0]
    _mirror(obj, axes=(True, True, False))
    _assert_copies_of(_mask(obj)[0], 4, alone)
    _array(obj, 3, offset=(0.0, 0.0, 1.5))
    mask, _edges, _positions = _mask(obj)
    _assert_copies_of(mask, 12, alone)
    assert int(mask.sum()) == 12 * _half_cube_cage_count(1)


def test_array_fit_length_and_caps():
    scene = scenes.empty_scene()
    obj = _half_cube(scene)
    _subdivide(obj, 1)
    alone = _mask(obj)[0]
    array = _array(obj)
    array.fit_type = "FIT_LENGTH"
    array.fit_length = 7.0
    mask, edges, _positions = _mask(obj)
    copies = len(edges) // len(alone)
    assert copies >= 2
    _assert_copies_of(mask, copies, alone)
    # Caps without modifiers of their own: every cap edge is drawn, as
    # Blender gives a cap without Optimal Display marks.
    cap = scenes.cube(scene, "Cap", size=0.5, location=(30.0, 0.0, 0.0))
    array.fit_type = "FIXED_COUNT"
    array.count = 2
    array.start_cap = array.end_cap = cap
    mask, edges, _positions = _mask(obj)
    assert len(edges) == 2 * len(alone) + 2 * 12
    _assert_copies_of(mask[: 2 * len(alone)], 2, alone)
    assert mask[2 * len(alone) :].all()
    # A cap with modifiers of its own is not followed: every edge.
    cap.modifiers.new("Bevel", "BEVEL")
    assert _mask(obj)[0] is None


def test_array_merge_bisect_and_weld():
    """Array with Merge on drops Blender's marks even when nothing merges;
    Bisect too; Weld keeps them only when it welds nothing."""
    scene = scenes.empty_scene()
    obj = _half_cube(scene)
    _subdivide(obj, 1)
    alone = _mask(obj)[0]
    array = _array(obj, 2, merge=True, offset=(3.0, 0.0, 0.0))
    assert _mask(obj)[0] is None
    array.use_merge_vertices = False
    assert _mask(obj)[0] is not None
    obj.modifiers.remove(array)
    mirror = _mirror(obj)
    mirror.use_bisect_axis[0] = True
    assert _mask(obj)[0] is None
    obj.modifiers.remove(mirror)
    weld = obj.modifiers.new("Weld", "WELD")
    weld.merge_threshold = 1e-6
    assert np.array_equal(_mask(obj)[0], alone)
    weld.merge_threshold = 1.5  # welds the subdivided vertices together
    mask, edges, _positions = _mask(obj)
    assert len(edges) < len(alone) and mask is None


def test_simplify_lowering_the_level_is_followed():
    scene, obj, _mod = _subdivided_cube(3)
    scene.render.use_simplify = True
    scene.render.simplify_subdivision = 1
    mask, edges, positions = _mask(obj)
    _assert_catmull_clark_cube_cage(mask, edges, positions, 1)
    scene.render.simplify_subdivision = 0
    assert _mask(obj)[0] is None


def test_ngon_loose_edge_and_loose_vertex():
    scene = scenes.empty_scene()
    ring = [(math.cos(a), math.sin(a), 0.0) for a in np.linspace(0.0, 2 * math.pi, 6)[:5]]
    mesh = bpy.data.meshes.new("Ngon")
    mesh.from_pydata(ring + [(3.0, 0.0, 0.0), (4.0, 0.0, 0.0), (5.0, 5.0, 5.0)], [(5, 6)], [(0, 1, 2, 3, 4)])
    obj = bpy.data.objects.new("Ngon", mesh)
    scene.collection.objects.link(obj)
    mod = obj.modifiers.new("Subdivision", "SUBSURF")
    mod.subdivision_type = "SIMPLE"
    segments = [(ring[i], ring[(i + 1) % 5]) for i in range(5)] + [((3.0, 0.0, 0.0), (4.0, 0.0, 0.0))]

    def on_segment(p):
        for a, b in segments:
            a, b = np.asarray(a), np.asarray(b)
            t = np.dot(p - a, b - a) / np.dot(b - a, b - a)
            if -1e-6 <= t <= 1 + 1e-6 and np.linalg.norm(a + t * (b - a) - p) < 1e-5:
                return True
        return False

    for level in (1, 2, 3):
        mod.levels = level
        mask, edges, positions = _mask(obj)
        assert mask is not None and int(mask.sum()) == 6 * 2**level
        geometric = {i for i, (a, b) in enumerate(edges) if on_segment(positions[a]) and on_segment(positions[b])}
        assert set(np.flatnonzero(mask).tolist()) == geometric


def test_a_mesh_without_faces_is_all_cage():
    scene = scenes.empty_scene()
    mesh = bpy.data.meshes.new("Wire")
    mesh.from_pydata([(0, 0, 0), (1, 0, 0), (1, 1, 0)], [(0, 1), (1, 2)], [])
    obj = bpy.data.objects.new("Wire", mesh)
    scene.collection.objects.link(obj)
    obj.modifiers.new("Subdivision", "SUBSURF").levels = 2
    assert _mask(obj)[0] is None  # every evaluated edge comes from a cage edge


def test_a_mesh_that_is_not_the_objects_gives_none():
    scene, obj, _mod = _subdivided_cube(2)
    other = scenes.uv_sphere(scene, "Sphere")
    other.modifiers.new("Subdivision", "SUBSURF").levels = 2
    depsgraph = bpy.context.evaluated_depsgraph_get()
    assert cage_edge_mask(obj, other.evaluated_get(depsgraph).data, render=False) is None


def test_peel_rejects_a_layout_that_only_fits_the_counts():
    _scene, obj, _mod = _subdivided_cube(2)
    _unused_mask, edges, positions = _mask(obj)
    faces = 96
    assert peel(edges, len(positions), faces, 2) is not None
    assert peel(edges, len(positions), faces, 1) is None  # wrong level
    shuffled = edges.copy()
    shuffled[[0, 100]] = shuffled[[100, 0]]
    assert peel(shuffled, len(positions), faces, 2) is None


# -- Multiresolution -----------------------------------------------------------


def _multires_cube(levels=3):
    scene = scenes.empty_scene()
    obj = scenes.cube(scene, "Multires")
    mod = obj.modifiers.new("Multires", "MULTIRES")
    with bpy.context.temp_override(object=obj, active_object=obj):
        for _ in range(levels):
            bpy.ops.object.multires_subdivide(modifier=mod.name, mode="CATMULL_CLARK")
    return scene, obj, mod


def test_multires_levels():
    _scene, obj, mod = _multires_cube(3)
    for level in (3, 2, 1):
        mod.levels = level
        mask, edges, positions = _mask(obj)
        _assert_catmull_clark_cube_cage(mask, edges, positions, level)
    mod.levels = 0
    assert _mask(obj)[0] is None


def test_multires_in_sculpt_mode():
    """Sculpt Mode shows sculpt_levels; without Sculpt Base Mesh the
    evaluated mesh is the coarse one (the grids are not a mesh): all cage."""
    _scene, obj, mod = _multires_cube(2)
    bpy.context.view_layer.objects.active = obj
    obj.select_set(True)
    bpy.ops.object.mode_set(mode="SCULPT")
    try:
        mod.sculpt_levels = 1
        assert _mask(obj)[0] is None
        mod.use_sculpt_base_mesh = True
        mask, edges, positions = _mask(obj)
        _assert_catmull_clark_cube_cage(mask, edges, positions, 1)
    finally:
        bpy.ops.object.mode_set(mode="OBJECT")


# -- render vs viewport ----------------------------------------------------------


class _Probe(bpy.types.RenderEngine):
    """Records, in a render depsgraph, what cage_edge_mask says."""

    bl_idname = "SOLIDWIRE_CAGE_PROBE"
    bl_label = "Cage probe"
    found: dict = {}

    def render(self, depsgraph):
        for instance in depsgraph.object_instances:
            obj = instance.object
            if obj.type == "MESH":
                mesh = obj.data
                mask = cage_edge_mask(obj, mesh, render=depsgraph.mode == "RENDER")
                type(self).found[obj.name] = (
                    depsgraph.mode,
                    len(mesh.edges),
                    None if mask is None else int(mask.sum()),
                )


@pytest.fixture
def probe_engine():
    bpy.utils.register_class(_Probe)
    _Probe.found = {}
    try:
        yield _Probe
    finally:
        bpy.utils.unregister_class(_Probe)


def test_render_levels_in_a_render_depsgraph(probe_engine):
    scene, obj, mod = _subdivided_cube(1)
    mod.render_levels = 3
    scenes.add_camera(scene)
    scene.render.engine = probe_engine.bl_idname
    bpy.ops.render.render(scene=scene.name)
    assert probe_engine.found["Cube"] == ("RENDER", 768, 12 * 8)  # level 3: 768 edges
    # The viewport depsgraph has the viewport level.
    mask, _unused_edges, _positions = _mask(obj)
    assert int(mask.sum()) == 12 * 2
    # Render Simplify lowers the render level only.
    scene.render.use_simplify = True
    scene.render.simplify_subdivision_render = 2
    bpy.ops.render.render(scene=scene.name)
    assert probe_engine.found["Cube"][2] == 12 * 4
    mod.show_render = False
    bpy.ops.render.render(scene=scene.name)
    assert probe_engine.found["Cube"][2] is None
    assert int(_mask(obj)[0].sum()) == 12 * 2  # still on in the viewport


# -- Edit Mode, user data, save/load -----------------------------------------------------


def _enter_edit_mode(obj):
    bpy.context.view_layer.objects.active = obj
    obj.select_set(True)
    bpy.ops.object.mode_set(mode="EDIT")


def test_edit_mode_follows_the_edited_cage():
    _scene, obj, _mod = _subdivided_cube(2, "SIMPLE")
    _enter_edit_mode(obj)
    try:
        mask, edges, positions = _mask(obj)
        _assert_simple_cube_cage(mask, edges, positions, level=2)
        bm = bmesh.from_edit_mesh(obj.data)
        bm.edges.ensure_lookup_table()
        bmesh.ops.subdivide_edges(bm, edges=[bm.edges[0]], cuts=1)  # 13 cage edges, two pentagons
        bmesh.update_edit_mesh(obj.data)
        mask, edges, positions = _mask(obj)
        assert mask is not None and int(mask.sum()) == 13 * 4
        assert set(np.flatnonzero(mask).tolist()) == _box_edge_set(edges, positions, [(0, 0, 0)])
        obj.modifiers["Subdivision"].show_in_editmode = False  # not evaluated in Edit Mode
        assert _mask(obj)[0] is None
    finally:
        bpy.ops.object.mode_set(mode="OBJECT")
    mask, _unused_edges, _positions = _mask(obj)
    assert int(mask.sum()) == 13 * 4


def _user_data_snapshot(obj):
    data = obj.data
    ids = {
        name: len(getattr(bpy.data, name))
        for name in ("meshes", "objects", "textures", "node_groups", "images", "texts", "materials")
    }
    attributes = sorted((a.name, a.domain, a.data_type) for a in data.attributes)
    layers = None
    if data.is_editmode:  # the edit BMesh's layers (the mesh's own are stale)
        bm = bmesh.from_edit_mesh(data)
        layers = sorted(
            (domain, kind, name)
            for domain in ("verts", "edges", "faces", "loops")
            for kind in ("int", "float", "bool", "string", "float_vector", "float_color", "color")
            if hasattr(getattr(bm, domain).layers, kind)
            for name in getattr(getattr(bm, domain).layers, kind).keys()  # noqa: SIM118  (iterating the collection gives layers, not names)
        )
    modifiers = [(m.name, m.type) for m in obj.modifiers]
    return ids, attributes, layers, modifiers, dict(data.items()), dict(obj.items())


@pytest.mark.parametrize("mode", ["OBJECT", "EDIT"])
def test_nothing_is_left_in_the_users_data(mode):
    _scene, obj, _mod = _subdivided_cube(2)
    if mode == "EDIT":
        _enter_edit_mode(obj)
    try:
        before = _user_data_snapshot(obj)
        for render in (False, True):
            _mask(obj, render=render)
            _mask(obj, render=render, original=True)
            cage_key(obj, render)
        assert _user_data_snapshot(obj) == before
    finally:
        if obj.mode == "EDIT":
            bpy.ops.object.mode_set(mode="OBJECT")


def test_same_mask_after_save_and_load(tmp_path):
    _scene, obj, _mod = _subdivided_cube(2)
    before = _mask(obj)[0]
    path = tmp_path / "cage.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path), copy=True)
    bpy.ops.wm.open_mainfile(filepath=str(path))
    loaded = bpy.data.objects["Cube"]
    after = _mask(loaded)[0]
    assert after is not None and np.array_equal(before, after)
    assert "Subdivision" in loaded.modifiers and len(loaded.modifiers) == 1


# -- cache key -----------------------------------------------------------------------


def test_cage_key_changes_with_what_decides_the_mask():
    _scene, obj, mod = _subdivided_cube(2)
    key = cage_key(obj, False)
    hash(key)
    assert cage_key(obj, False) == key
    assert cage_key(obj.evaluated_get(bpy.context.evaluated_depsgraph_get()), False) == key
    assert cage_key(obj, True) != key
    changes = [
        lambda: setattr(mod, "levels", 3),
        lambda: setattr(mod, "render_levels", 1),
        lambda: setattr(mod, "show_viewport", False),
        lambda: setattr(mod, "show_render", False),
        lambda: setattr(mod, "show_in_editmode", False),
        lambda: obj.modifiers.new("Tri", "TRIANGULATE"),
    ]
    seen = {key}
    for change in changes:
        change()
        new = cage_key(obj, False)
        assert new not in seen
        seen.add(new)


# -- edge data on the children of cage edges (documents Blender's behaviour) ----------


def test_edge_attributes_propagate_to_the_child_edges_of_cage_edges():
    """sharp_edge, crease_edge, the seam attribute ("uv_seam"; ".uv_seam"
    before Blender 4.5) and freestyle_edge are copied from a cage edge to each of its 2^L child edges and to no
    other evaluated edge, for Subdivision Surface (both types) and
    Multiresolution."""
    scene = scenes.empty_scene()
    obj = scenes.cube(scene)
    mesh = obj.data
    mesh.edges[3].use_seam = True
    mesh.edges[3].use_edge_sharp = True
    mesh.attributes.new("crease_edge", "FLOAT", "EDGE").data[3].value = 0.5
    mesh.attributes.new("freestyle_edge", "BOOLEAN", "EDGE").data[3].value = True
    seam = "uv_seam" if "uv_seam" in mesh.attributes else ".uv_seam"
    assert {seam, "sharp_edge"} <= set(mesh.attributes.keys())
    cases = [("SUBSURF", "CATMULL_CLARK"), ("SUBSURF", "SIMPLE"), ("MULTIRES", None)]
    for kind, subdivision_type in cases:
        obj.modifiers.clear()
        mod = obj.modifiers.new("Sub", kind)
        if kind == "SUBSURF":
            mod.subdivision_type = subdivision_type
            mod.levels = 2
        else:
            with bpy.context.temp_override(object=obj, active_object=obj):
                for _ in range(2):
                    bpy.ops.object.multires_subdivide(modifier=mod.name, mode="CATMULL_CLARK")
        obj_eval, evaluated, _cleanup = _evaluated(obj)
        mask = cage_edge_mask(obj_eval, evaluated, render=False)
        children = set(range(3 * 4, 4 * 4))
        assert set(np.flatnonzero(mask).tolist()) >= children
        for name in (seam, "sharp_edge", "crease_edge", "freestyle_edge"):
            values = np.array([d.value for d in evaluated.attributes[name].data])
            assert set(np.flatnonzero(values).tolist()) == children, (kind, name)
        crease = np.array([d.value for d in evaluated.attributes["crease_edge"].data])
        assert np.allclose(crease[sorted(children)], 0.5)


# -- against Blender's own overlay -----------------------------------------------------

OVERLAY_SIZE = (360, 270)


def _blender_draws(obj, mesh, clear_px: float = 4.0):
    """(shown, decidable) per evaluated edge: whether Blender's wireframe
    overlay (drawn headless, every edge its Optimal Display marks allow:
    threshold 1) has a line at the edge's middle, and whether that can be
    told (no other edge passes within ``clear_px`` of it)."""
    from tests.support.viewport import HeadlessViewport, ViewportUnavailable, set_overlays

    scene = bpy.context.scene
    try:
        view = HeadlessViewport(*OVERLAY_SIZE)
    except ViewportUnavailable as exc:
        pytest.skip(f"Blender's viewport cannot be drawn headless here: {exc}")
    shading = view.space.shading
    saved = shading.type, shading.show_xray
    try:
        view.look_through(scene)
        shading.type = "SOLID"
        shading.show_xray = True  # every edge, front or back
        try:
            set_overlays(view.space, wireframe=True)
            view.draw_blender()
            with_wire = view.rgba()
            set_overlays(view.space, wireframe=False)
            view.draw_blender()
            without = view.rgba()
        except ViewportUnavailable as exc:
            pytest.skip(f"Blender's viewport cannot be drawn headless here: {exc}")
        to_clip = np.asarray(view.view.projection) @ np.asarray(view.view.view_matrix) @ np.array(obj.matrix_world)
    finally:
        shading.type, shading.show_xray = saved
        view.free()
    wire = (with_wire != without).any(axis=-1)
    positions, edges = _positions(mesh), _edges(mesh)
    clip = np.c_[positions, np.ones(len(positions))] @ to_clip.T
    width, height = OVERLAY_SIZE
    screen = (clip[:, :2] / clip[:, 3:4] + 1.0) * 0.5 * (width, height)
    a, b = screen[edges[:, 0]], screen[edges[:, 1]]
    middles = 0.5 * (a + b)
    shown = np.zeros(len(edges), bool)
    decidable = np.zeros(len(edges), bool)
    ab = b - a
    for i, (x, y) in enumerate(middles):
        if not (2 <= x < width - 2 and 2 <= y < height - 2):
            continue
        t = np.clip(((middles[i] - a) * ab).sum(axis=1) / np.maximum((ab * ab).sum(axis=1), 1e-12), 0.0, 1.0)
        distance = np.linalg.norm(a + t[:, None] * ab - middles[i], axis=1)
        distance[i] = np.inf
        decidable[i] = distance.min() > clear_px
        shown[i] = wire[int(y) - 1 : int(y) + 2, int(x) - 1 : int(x) + 2].any()
    return shown, decidable


def _after_subdivision(obj, case):
    if case == "stacked":
        _subdivide(obj, 1)
    elif case == "mirror":
        _mirror(obj)
    elif case == "mirror merging":
        _mirror(obj, merge=True)
    elif case == "mirror merging nothing":
        _mirror(obj, merge=True).merge_threshold = 1e-4
        for vertex in obj.data.vertices:
            vertex.co.x += 0.3
        obj.data.update()
    elif case == "array with caps":
        array = _array(obj, 2)
        cap = scenes.cube(bpy.context.scene, "Cap", size=0.6, location=(40.0, 0.0, 0.0))
        array.start_cap = array.end_cap = cap
    elif case == "array":
        _array(obj, 2)
    elif case == "array merge":
        _array(obj, 2, merge=True)
    elif case == "mirror and array":
        _mirror(obj)
        _array(obj, 2, offset=(0.0, 1.3, 0.0))
    elif case == "weld welding nothing":
        obj.modifiers.new("Weld", "WELD").merge_threshold = 1e-6
    elif case == "triangulate":
        obj.modifiers.new("Triangulate", "TRIANGULATE")


@pytest.mark.parametrize(
    "case, keeps",
    [
        ("only the subdivision", True),
        ("stacked", True),
        ("mirror", True),
        ("mirror merging", False),
        ("mirror merging nothing", True),
        ("array with caps", True),
        ("array", True),
        ("array merge", False),
        ("mirror and array", True),
        ("weld welding nothing", True),
        ("triangulate", False),
    ],
)
def test_the_drawn_edges_are_the_ones_blenders_overlay_shows(case, keeps):
    """Edge by edge, where Blender's wireframe overlay draws a line (or not)
    the mask draws the edge (or not), for modifiers after the subdivision
    that keep the cage in Blender's overlay and ones that do not."""
    scene = scenes.empty_scene(*OVERLAY_SIZE)
    scenes.add_camera(scene, location=(5.0, -8.0, 6.0), target=(0.0, 0.0, 0.0))
    obj = _half_cube(scene)
    _subdivide(obj, 1, "CATMULL_CLARK")
    _after_subdivision(obj, case)
    mask, _edges_array, _positions_array = _mask(obj)
    assert (mask is not None) == keeps
    obj_eval, mesh, cleanup = _evaluated(obj)
    try:
        shown, decidable = _blender_draws(obj_eval, mesh)
        ours = np.ones(len(mesh.edges), bool) if mask is None else mask
    finally:
        cleanup()
    assert decidable.sum() >= 12, "enough edges to tell apart"
    if keeps:
        assert (~shown & decidable).sum() >= 3, "Blender hides some edges"
    disagree = np.flatnonzero(decidable & (shown != ours))
    assert len(disagree) == 0, f"edges {disagree.tolist()} differ from Blender's overlay"


def test_cage_key_follows_mirror_and_array_settings():
    scene = scenes.empty_scene()
    obj = _half_cube(scene)
    _subdivide(obj, 1)
    mirror = _mirror(obj)
    array = _array(obj, 2)
    seen = {cage_key(obj, False)}
    for change in (
        lambda: setattr(mirror, "use_mirror_merge", True),
        lambda: mirror.use_bisect_axis.__setitem__(1, True),
        lambda: setattr(array, "use_merge_vertices", True),
        lambda: setattr(array, "count", 4),
    ):
        change()
        key = cage_key(obj, False)
        assert key not in seen
        seen.add(key)
