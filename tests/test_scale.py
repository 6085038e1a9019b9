"""Scale, asserted through ``solidwire_addon.stats()``: the GPU
cache reuses what did not change, shares one upload between duplicates and
instances, frees what is gone; culling and instanced drawing."""

from __future__ import annotations

import bpy
import numpy as np

import solidwire_addon
from solidwire_addon.blender import runtime
from solidwire_addon.core import draw
from solidwire_addon.core.view import outside_frustum_many
from tests.support import scenes


def render(scene) -> dict:
    bpy.ops.render.render(scene=scene.name)
    return solidwire_addon.stats()


def ten_cubes(width=64, height=48):
    scene = scenes.empty_scene(width, height)
    scenes.add_camera(scene, location=(0.0, -30.0, 10.0), target=(0.0, 0.0, 0.0))
    cubes = [scenes.cube(scene, f"Cube{i}", location=(2.0 * i - 9.0, 0.0, 0.0)) for i in range(10)]
    return scene, cubes


def test_second_render_of_unchanged_scene_extracts_nothing():
    scene, _cubes = ten_cubes()
    first = render(scene)
    assert first["meshes_extracted"] == 10
    second = render(scene)
    assert second["meshes_extracted"] == 0
    assert second["meshes_reused"] == 10
    assert second["objects_drawn"] == 10


def test_camera_object_and_material_changes_extract_nothing():
    scene, cubes = ten_cubes()
    render(scene)
    scene.camera.location.x += 1.5
    assert render(scene)["meshes_extracted"] == 0
    cubes[2].location.z += 1.0
    cubes[3].rotation_euler.z += 0.5
    assert render(scene)["meshes_extracted"] == 0
    cubes[4].data.materials.append(bpy.data.materials.new("Red"))
    assert render(scene)["meshes_extracted"] == 0


def test_editing_one_mesh_of_ten_reextracts_one():
    scene, cubes = ten_cubes()
    render(scene)
    cubes[6].data.vertices[0].co.z += 0.5
    cubes[6].data.update()
    stats = render(scene)
    # Only a vertex moved (same faces, same quad splits): positions alone go up again.
    assert stats["meshes_extracted"] == 0
    assert stats["meshes_repositioned"] == 1
    assert stats["meshes_reused"] == 9


def test_a_move_that_changes_the_triangles_reextracts():
    """Positions-only re-upload only when the triangles stay the same: a quad
    folded over its diagonal splits the other way, and an n-gon that Blender
    triangulates anew after a move; both go through full extraction. A move
    after which Blender splits the n-gon as before keeps the upload."""
    scene, _cubes = ten_cubes()
    quad = scenes.from_pydata(scene, "Quad", [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)], [(0, 1, 2, 3)])
    hexagon = scenes.from_pydata(
        scene, "Hexagon", [(np.cos(a), np.sin(a), 2.0) for a in np.linspace(0, 2 * np.pi, 7)[:-1]], [tuple(range(6))]
    )
    render(scene)
    quad.data.vertices[1].co = (0.9, 0.1, 0.0)  # still split along 0-2
    quad.data.update()
    stats = render(scene)
    assert (stats["meshes_extracted"], stats["meshes_repositioned"]) == (0, 1)
    quad.data.vertices[1].co = (0.2, 0.8, 0.0)  # corners 1 and 3 on one side of 0-2: split 1-3
    quad.data.update()
    stats = render(scene)
    assert (stats["meshes_extracted"], stats["meshes_repositioned"]) == (1, 0)

    def split():
        hexagon.data.calc_loop_triangles()
        return sorted(tuple(sorted(t.vertices)) for t in hexagon.data.loop_triangles)

    before = split()
    hexagon.data.vertices[0].co.z += 0.3  # out of the plane: Blender splits it as before
    hexagon.data.update()
    assert split() == before
    stats = render(scene)
    assert (stats["meshes_extracted"], stats["meshes_repositioned"]) == (0, 1)
    hexagon.data.vertices[0].co.x = -0.8  # across the hexagon: a dart, split anew
    hexagon.data.update()
    assert split() != before
    stats = render(scene)
    assert (stats["meshes_extracted"], stats["meshes_repositioned"]) == (1, 0)


def test_topology_change_is_seen():
    scene, cubes = ten_cubes()
    render(scene)
    mesh = cubes[1].data
    mesh.polygons[0].flip()  # same vertices, reversed corner order
    mesh.update()
    assert render(scene)["meshes_extracted"] == 1


def test_linked_duplicates_share_one_upload():
    scene = scenes.empty_scene(64, 48)
    scenes.add_camera(scene, location=(0.0, -60.0, 60.0), target=(0.0, 0.0, 0.0))
    source = scenes.cube(scene, "Source", size=0.5)
    for i in range(499):
        dup = bpy.data.objects.new(f"Dup{i}", source.data)
        scene.collection.objects.link(dup)
        dup.location = (i % 25 - 12.0, i // 25 - 10.0, 0.0)
    stats = render(scene)
    assert stats["meshes_extracted"] == 1
    assert stats["meshes_cached"] == 1
    assert stats["objects_drawn"] == 500
    assert stats["triangles_drawn"] == 500 * 12


def test_collection_and_geometry_node_instances_share_one_upload():
    scene = scenes.empty_scene(64, 48)
    scenes.add_camera(scene, location=(0.0, -40.0, 30.0), target=(0.0, 0.0, 0.0))
    # A collection instanced by three empties.
    collection = bpy.data.collections.new("Props")
    prop = bpy.data.objects.new("Prop", scenes.cube(scene, "PropMesh").data)
    collection.objects.link(prop)
    bpy.data.objects.remove(bpy.data.objects["PropMesh"])
    for i in range(3):
        empty = bpy.data.objects.new(f"Instancer{i}", None)
        empty.instance_type = "COLLECTION"
        empty.instance_collection = collection
        empty.location = (4.0 * i - 4.0, 0.0, 0.0)
        scene.collection.objects.link(empty)
    # A geometry-nodes scatter of one geometry on a 4 x 4 grid.
    scatter = scenes.cube(scene, "Scatter", size=0.3, location=(0.0, 8.0, 0.0))
    tree = bpy.data.node_groups.new("scatter", "GeometryNodeTree")
    tree.interface.new_socket("Geometry", in_out="INPUT", socket_type="NodeSocketGeometry")
    tree.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
    group_in, group_out = tree.nodes.new("NodeGroupInput"), tree.nodes.new("NodeGroupOutput")
    grid = tree.nodes.new("GeometryNodeMeshGrid")
    grid.inputs["Vertices X"].default_value = grid.inputs["Vertices Y"].default_value = 4
    on_points = tree.nodes.new("GeometryNodeInstanceOnPoints")
    tree.links.new(grid.outputs[0], on_points.inputs["Points"])
    tree.links.new(group_in.outputs[0], on_points.inputs["Instance"])
    tree.links.new(on_points.outputs[0], group_out.inputs[0])
    scatter.modifiers.new("Scatter", "NODES").node_group = tree

    stats = render(scene)
    assert stats["objects_drawn"] == 3 + 16
    assert stats["meshes_extracted"] == 2  # the prop once, the scattered geometry once
    assert render(scene)["meshes_extracted"] == 0


def test_object_behind_camera_is_culled():
    scene, _cubes = ten_cubes()
    behind = scenes.cube(scene, "Behind", location=(0.0, -45.0, 15.0))
    stats = render(scene)
    assert stats["objects_culled"] == 1
    assert stats["objects_drawn"] == 10
    # Culled before any GPU work: its mesh is not even extracted ...
    assert stats["meshes_extracted"] == 10
    assert stats["meshes_cached"] == 10
    # ... until it comes into view.
    behind.location = (0.0, 5.0, 0.0)
    stats = render(scene)
    assert stats["meshes_extracted"] == 1
    assert stats["objects_drawn"] == 11 and stats["objects_culled"] == 0


def test_duplicates_partly_in_view_are_extracted_once_and_culled_one_by_one():
    scene, _cubes = ten_cubes()
    source = scenes.cube(scene, "Shared", location=(0.0, -45.0, 15.0))  # behind the camera
    for i, location in enumerate([(0.0, -50.0, 15.0), (0.0, 3.0, 0.0), (3.0, 3.0, 0.0)]):
        dup = bpy.data.objects.new(f"Shared{i}", source.data)
        dup.location = location
        scene.collection.objects.link(dup)
    stats = render(scene)
    assert stats["objects_drawn"] == 12
    assert stats["objects_culled"] == 2
    assert stats["meshes_extracted"] == 11


def test_objects_without_faces_are_never_extracted():
    scene, _cubes = ten_cubes()
    scenes.from_pydata(scene, "Points", [(0, 0, 0), (1, 0, 0)], [])
    scenes.cube(scene, "Hidden").hide_render = True
    stats = render(scene)
    assert stats["meshes_extracted"] == 10
    assert stats["objects_drawn"] == 10


def test_deleted_object_frees_its_cache_entry():
    scene, cubes = ten_cubes()
    before = render(scene)
    assert before["meshes_cached"] == 10
    mesh = cubes[5].data
    bpy.data.objects.remove(cubes[5])
    bpy.data.meshes.remove(mesh)
    after = render(scene)
    assert after["meshes_cached"] == 9
    assert after["gpu_bytes"] < before["gpu_bytes"]
    assert after["meshes_extracted"] == 0


def test_loading_a_file_frees_every_gpu_mesh():
    scene, _cubes = ten_cubes()
    render(scene)
    assert len(runtime.mesh_cache) == 10
    bpy.ops.wm.read_factory_settings(use_empty=True)
    assert len(runtime.mesh_cache) == 0


def test_animation_reextracts_only_the_deforming_object():
    scene, cubes = ten_cubes()
    wave = cubes[0].modifiers.new("Wave", "WAVE")  # time-dependent deformation
    wave.height = 0.5
    cubes[0].modifiers.new("Subdivision", "SUBSURF").render_levels = 2
    cubes[1].location.z = 0.0
    cubes[1].keyframe_insert("location", frame=1)
    cubes[1].location.z = 3.0
    cubes[1].keyframe_insert("location", frame=5)  # moving, not deforming
    scene.frame_set(1)
    assert render(scene)["meshes_extracted"] == 10
    for frame in (2, 3, 4):
        scene.frame_set(frame)
        stats = render(scene)
        # The wave moves vertices: re-uploaded as positions, or re-extracted
        # where it changes a quad's split.
        assert stats["meshes_extracted"] + stats["meshes_repositioned"] == 1, frame
        assert stats["meshes_reused"] == 9


def test_instanced_drawing_matches_per_object_drawing(monkeypatch):
    from solidwire_addon.blender import engine

    scene = scenes.empty_scene(160, 120, diagonal_mode="DASHED", use_backface_culling=True)
    scenes.add_camera(scene, location=(0.0, -30.0, 20.0), target=(0.0, 0.0, 0.0))
    monkey = scenes.monkey(scene, "Monkey")
    hexagon = scenes.from_pydata(
        scene, "Hexagon", [(np.cos(a), np.sin(a), 0.0) for a in np.linspace(0, 2 * np.pi, 7)[:-1]], [tuple(range(6))]
    )
    rng = np.random.default_rng(3)
    for i in range(60):
        obj = bpy.data.objects.new(f"Copy{i}", (monkey if i % 2 else hexagon).data)
        scene.collection.objects.link(obj)
        obj.location = rng.uniform(-10.0, 10.0, 3)
        obj.rotation_euler = rng.uniform(0.0, 6.0, 3)
        obj.scale = (1.0, -1.0 if i % 3 == 0 else 1.0, 1.0)  # mirrored ones too
    depsgraph = bpy.context.evaluated_depsgraph_get()

    monkeypatch.setattr(draw, "INSTANCING_MIN", 10**9)
    per_object, _ = engine.render_scene(depsgraph, (160, 120))
    per_object_stats = solidwire_addon.stats()
    monkeypatch.setattr(draw, "INSTANCING_MIN", 2)
    instanced, _ = engine.render_scene(depsgraph, (160, 120))
    instanced_stats = solidwire_addon.stats()

    assert instanced_stats.get("instanced_draws", 0) >= 2
    assert "instanced_draws" not in per_object_stats
    assert (per_object[..., 3] > 0.5).sum() > 500
    np.testing.assert_array_equal(instanced, per_object)
    for key in ("objects_drawn", "objects_culled", "triangles_drawn"):
        assert instanced_stats[key] == per_object_stats[key]


def test_vectorised_frustum_culling_matches_per_instance():
    rng = np.random.default_rng(5)
    matrices = rng.normal(size=(200, 4, 4))
    lo, hi = np.array([-1.0, -2.0, -0.5]), np.array([1.0, 0.5, 2.0])
    many = outside_frustum_many(matrices, lo, hi)

    def outside(matrix):  # the plain definition: all 8 corners beyond one clip plane
        corners = np.array([[x, y, z, 1.0] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
        x, y, z, w = (corners @ matrix.T).T
        return any(((x > w).all(), (x < -w).all(), (y > w).all(), (y < -w).all(), (z > w).all(), (z < -w).all()))

    one_by_one = [outside(m) for m in matrices]
    np.testing.assert_array_equal(many, one_by_one)
    assert many.any() and not many.all()


def test_viewport_trusts_depsgraph_updates(monkeypatch):
    """The viewport's depsgraph reports edits through runtime's handler, so an
    unchanged mesh is reused without even a fingerprint; an edited one is
    re-extracted."""
    from solidwire_addon.blender import gather
    from solidwire_addon.blender.gpu_context import ensure_gpu

    _scene, cubes = ten_cubes()
    ensure_gpu()
    runtime.begin_frame(reuse=True)  # installs the handlers
    fingerprints = []
    real_fingerprint = gather.fingerprint
    monkeypatch.setattr(
        gather, "fingerprint", lambda mesh, *more: fingerprints.append(mesh.name) or real_fingerprint(mesh, *more)
    )

    def frame():
        runtime.mesh_cache.reset_counters()
        depsgraph = bpy.context.evaluated_depsgraph_get()
        assert depsgraph.mode == "VIEWPORT"
        gather.gather(depsgraph, runtime.mesh_cache)
        cache = runtime.mesh_cache
        return cache.extracted + cache.repositioned, cache.reused

    assert frame() == (10, 0)
    fingerprints.clear()
    assert frame() == (0, 10)
    assert fingerprints == []  # pointer + update counters were enough
    cubes[7].location.x += 1.0  # a transform update: no geometry version bump
    assert frame() == (0, 10)
    assert fingerprints == []
    cubes[2].data.vertices[1].co.x += 0.25
    cubes[2].data.update()
    assert frame() == (1, 9)
