"""Deforming animation in the add-on's default look (shaded fill, cage edges):
a frame that only moves vertices (shape keys, an armature) uploads positions
and corner normals again without a full extraction, and draws what a fresh
extraction of that frame draws; whatever changes the faces, the triangles,
the edge marks, or moves an edge across the edge angle still goes through a
full extraction (tests/test_edge_angle_edits.py: moves that do not)."""

from __future__ import annotations

import math

import bmesh
import numpy as np
import pytest

import solidwire_addon
from solidwire_addon.blender import mesh_reading, runtime
from solidwire_addon.core import cache, draw, extract, shaders
from solidwire_addon.core.options import DrawOptions
from tests.support import accuracy, reference, scenes

FRAMES = (1, 2, 3, 4)


def default_look_scene(width=160, height=120):
    """An empty scene in the add-on's default look (shaded fill, cage edges)."""
    scene = scenes.default_look(scenes.empty_scene(width, height))
    assert scene.solidwire.use_fill and scene.solidwire.fill_shading == "STUDIO" and scene.solidwire.use_cage_edges
    scene.solidwire.wire_color = (0.05, 0.05, 0.05, 1.0)
    return scene


def shape_key_monkey(scene):
    """Suzanne with a subdivision modifier (cage edges count) and an animated
    shape key that swells and twists her (the corner normals change)."""
    monkey = scenes.monkey(scene, "Shaped", subdivisions=1, rotation=(0.2, 0.0, 0.5))
    for poly in monkey.data.polygons:
        poly.use_smooth = poly.index % 3 != 0  # smooth and flat corners both
    scenes.add_swell_shape_key(monkey, (FRAMES[0], FRAMES[-1]))
    scenes.add_camera(scene, location=(2.0, -4.0, 1.5), target=(0.0, 0.0, 0.0))
    return monkey


def armature_tube(scene, collapse: bool = False):
    """A smooth tube of quads bent by a two-bone armature; with ``collapse``,
    one quad at the joint has an edge collapsed (two corners on one spot):
    its split is too close to call in every frame."""
    tube = scenes.tube(scene, segments=16, radius=0.5, depth=4.0, caps=False)
    mesh = tube.data
    # Rings of quads along z, so the bend shows on many faces.
    bm = bmesh.new()
    bm.from_mesh(mesh)
    bmesh.ops.subdivide_edges(
        bm, edges=[e for e in bm.edges if abs(e.verts[0].co.z - e.verts[1].co.z) > 1.0], cuts=11, use_grid_fill=False
    )
    bm.to_mesh(mesh)
    bm.free()
    for poly in mesh.polygons:
        poly.use_smooth = True
    if collapse:
        poly = min(mesh.polygons, key=lambda p: abs(p.center.z - 0.1))
        a, b = poly.vertices[0], poly.vertices[1]
        mesh.vertices[b].co = mesh.vertices[a].co
        mesh.update()
        positions = mesh_reading.read_positions(mesh)
        quads = mesh_reading.read_corner_verts(mesh).reshape(-1, 4)
        assert extract.quad_flip(positions, quads)[1].any()
    scenes.add_bend_rig(scene, tube, (FRAMES[0], FRAMES[-1]), angle_deg=70.0)
    scenes.add_camera(scene, location=(8.0, -3.0, 1.0), target=(0.0, 0.0, 0.5))
    return tube


def armature_tube_collapsed(scene):
    return armature_tube(scene, collapse=True)


def render(scene, path):
    rgba = scenes.render_to_file(scene, path)
    return rgba, solidwire_addon.stats()


def difference_report(measured, expected) -> dict:
    """The accuracy statistics (reference._statistics, SPEC 1.5) of the
    largest per-sample channel difference between two renders."""
    return reference._statistics(np.abs(measured - expected).max(axis=-1).ravel())


@pytest.mark.parametrize(
    "build, setup_min",
    [
        (shape_key_monkey, draw.SETUP_TABLE_MIN),  # cage edges: an outline table, never the pre-pass
        (armature_tube, draw.SETUP_TABLE_MIN),
        (armature_tube, 1),
        (armature_tube_collapsed, draw.SETUP_TABLE_MIN),  # a quad split Blender settles every frame
    ],
    ids=["shape_key", "armature", "armature_setup_prepass", "armature_degenerate_quad"],
)
def test_deformation_uploads_positions_and_normals_only(build, setup_min, monkeypatch, output_dir):
    # The set-up pre-pass (big tri/quad meshes in a direct draw; here forced
    # on a small one, with the render's surface pass drawn directly) keeps a
    # per-mesh table that must follow the new positions.
    if setup_min == 1 and not shaders.setup_available():
        pytest.skip("no compute shaders here")
    monkeypatch.setattr(draw, "SETUP_TABLE_MIN", setup_min)
    # (Tested in renders here too, where a software rasteriser leaves it off.)
    monkeypatch.setattr(shaders, "setup_dispatch_allowed", shaders.setup_available)
    monkeypatch.setattr(runtime, "options", DrawOptions(deferred_surface=setup_min != 1))
    setup_calls = []
    real_setup = draw._run_setup
    monkeypatch.setattr(draw, "_run_setup", lambda *args: (setup_calls.append(1), real_setup(*args)))
    scene = default_look_scene()
    obj = build(scene)
    name = f"deform_{obj.name.lower()}_{setup_min}"
    warm_images = []
    for frame in FRAMES:  # one cache through the animation
        scene.frame_set(frame)
        warm, stats = render(scene, output_dir / f"{name}_{frame}_warm.png")
        warm_images.append(warm)
        if frame == FRAMES[0]:
            assert stats["meshes_extracted"] == 1
        else:
            assert (stats["meshes_extracted"], stats["meshes_repositioned"]) == (0, 1), frame
    cold_images = []
    for frame, warm in zip(FRAMES, warm_images):  # each frame from an empty cache: a full extraction
        scene.frame_set(frame)
        runtime.mesh_cache.clear()
        cold, stats = render(scene, output_dir / f"{name}_{frame}_cold.png")
        assert stats["meshes_extracted"] == 1
        accuracy.assert_accurate({**difference_report(warm, cold), "nan": int(np.isnan(warm).sum())})
        cold_images.append(cold)
    assert (len(setup_calls) > 0) == (setup_min == 1)
    # The frames really differ (fill shading and lines): stale positions or
    # normals would fail the comparisons above.
    for frame, image in zip(FRAMES[1:], cold_images[1:]):
        report = difference_report(image, cold_images[0])
        assert report["max"] > 0.3 and report["over_2_255"] > 200, (frame, report)


@pytest.mark.parametrize("by_vertex", [False, True], ids=["primitive_id", "by_vertex"])
def test_deferred_deformation_keeps_the_index_buffer(by_vertex, monkeypatch, output_dir):
    """Drawn deferred, a frame that only moves vertices uploads the
    visibility batch's vertex buffer again but keeps its index buffer (and,
    numbered by vertex, which corners are copied): those depend on the
    triangles alone. Each frame still equals a fresh extraction's."""
    monkeypatch.setattr(draw, "DEFERRED_MIN_DENSITY", 0.0)
    monkeypatch.setattr(runtime, "options", DrawOptions(triangle_ids_by_vertex=by_vertex))
    index_buffers = []
    real_index_buffer = cache.gpu.types.GPUIndexBuf

    def counting_index_buffer(*args, **kwargs):
        index_buffers.append(kwargs.get("type"))
        return real_index_buffer(*args, **kwargs)

    monkeypatch.setattr(cache.gpu.types, "GPUIndexBuf", counting_index_buffer)
    scene = default_look_scene()
    armature_tube(scene)
    warm_images = []
    for frame in FRAMES:
        scene.frame_set(frame)
        image, _stats = render(scene, output_dir / f"deferred_move_{by_vertex}_{frame}.png")
        warm_images.append(image)
    assert shaders.deferred_available()
    assert index_buffers == ["TRIS"]  # made once, at the first frame
    runtime.mesh_cache.clear()
    cold, _stats = render(scene, output_dir / f"deferred_move_{by_vertex}_cold.png")
    accuracy.assert_accurate({**difference_report(warm_images[-1], cold), "nan": int(np.isnan(cold).sum())})
    assert len(index_buffers) == 2
    assert difference_report(warm_images[-1], warm_images[0])["over_2_255"] > 200  # the frames really differ


def test_repositioned_frame_matches_the_reference(output_dir):
    """The last frame of the shape-key animation, drawn from uploads reused
    since the first frame, against the float64 reference's shaded fill."""
    scene = default_look_scene(200, 150)
    shape_key_monkey(scene)
    for frame in FRAMES:
        scene.frame_set(frame)
        rgba, stats = render(scene, output_dir / "deform_reference.png")
    assert stats["meshes_repositioned"] == 1 and stats["meshes_extracted"] == 0
    ref = reference.render_reference(scene)
    expected = reference.expected_fill_rgb(ref, float(scene.solidwire.wire_color[3]))
    accuracy.assert_accurate(reference.color_error_report(rgba, expected, ref))


def test_topology_change_mid_animation_reextracts(output_dir):
    """A Build modifier adds faces every frame: never a positions-only upload."""
    scene = default_look_scene()
    obj = shape_key_monkey(scene)
    build = obj.modifiers.new("Build", "BUILD")
    obj.modifiers.move(len(obj.modifiers) - 1, 0)  # before the subdivision
    build.frame_start, build.frame_duration = FRAMES[0] - 2, 2 * len(FRAMES)  # some faces at the first frame
    for frame in FRAMES:
        scene.frame_set(frame)
        _rgba, stats = render(scene, output_dir / "deform_build.png")
        assert (stats["meshes_extracted"], stats["meshes_repositioned"]) == (1, 0), frame


def test_edge_marks_and_edge_angle_reextract(output_dir):
    """A sharp mark changes which edges carry a class without moving a
    vertex; with an edge angle this deformation moves edges across it,
    which changes which edges are drawn. Both need the full extraction."""
    scene = default_look_scene()
    scene.solidwire.use_sharp_edges = True
    obj = shape_key_monkey(scene)
    scene.frame_set(FRAMES[0])
    render(scene, output_dir / "deform_marks.png")
    obj.data.edges[5].use_edge_sharp = True
    _rgba, stats = render(scene, output_dir / "deform_marks.png")
    assert (stats["meshes_extracted"], stats["meshes_repositioned"]) == (1, 0)
    # The same deformation with no edge angle: positions only ...
    scene.frame_set(FRAMES[1])
    _rgba, stats = render(scene, output_dir / "deform_marks.png")
    assert (stats["meshes_extracted"], stats["meshes_repositioned"]) == (0, 1)
    # ... with an edge angle: extracted again.
    scene.solidwire.edge_angle = math.radians(20.0)
    scene.frame_set(FRAMES[2])
    render(scene, output_dir / "deform_marks.png")
    scene.frame_set(FRAMES[3])
    _rgba, stats = render(scene, output_dir / "deform_marks.png")
    assert (stats["meshes_extracted"], stats["meshes_repositioned"]) == (1, 0)


def test_normals_that_follow_the_positions_are_not_checksummed(monkeypatch, output_dir):
    """Flat (per face) and plain smooth (per vertex) normals follow from the
    positions and faces, which the fingerprint covers: a render validating an
    unchanged mesh reads no normals, a moved mesh reads them once to be
    shaded anew, and a change of where the normals live (flat to smooth,
    then a sharp edge) still re-extracts."""
    reads = []
    real_read_normals = mesh_reading.read_normals
    monkeypatch.setattr(
        mesh_reading, "read_normals", lambda mesh, domain: (reads.append(domain), real_read_normals(mesh, domain))[1]
    )
    scene = default_look_scene()
    monkey = scenes.monkey(scene, "Flat", subdivisions=1, rotation=(0.2, 0.0, 0.5))
    scenes.add_camera(scene, location=(2.0, -4.0, 1.5), target=(0.0, 0.0, 0.0))
    mesh = monkey.data
    mesh.polygons.foreach_set("use_smooth", [False] * len(mesh.polygons))
    mesh.update()
    _image, stats = render(scene, output_dir / "derived_first.png")
    assert stats["meshes_extracted"] == 1 and reads == [extract.NORMALS_BY_TRIANGLE]

    reads.clear()
    _image, stats = render(scene, output_dir / "derived_again.png")
    assert (stats["meshes_extracted"], stats["meshes_repositioned"], reads) == (0, 0, [])

    positions = mesh_reading.read_positions(mesh)
    positions[:, 2] *= 1.3
    mesh.vertices.foreach_set("co", positions.reshape(-1))
    mesh.update()
    reads.clear()
    moved, stats = render(scene, output_dir / "derived_moved.png")
    assert (stats["meshes_extracted"], stats["meshes_repositioned"]) == (0, 1)
    assert reads == [extract.NORMALS_BY_TRIANGLE]
    runtime.mesh_cache.clear()
    cold, _stats = render(scene, output_dir / "derived_moved_cold.png")
    accuracy.assert_accurate({**difference_report(moved, cold), "nan": int(np.isnan(moved).sum())})

    mesh.polygons.foreach_set("use_smooth", [True] * len(mesh.polygons))
    mesh.update()
    smooth, stats = render(scene, output_dir / "derived_smooth.png")
    assert stats["meshes_extracted"] == 1
    assert difference_report(smooth, cold)["over_2_255"] > 200  # shaded anew

    mesh.edges[0].use_edge_sharp = True
    mesh.update()
    reads.clear()
    _image, stats = render(scene, output_dir / "derived_sharp.png")
    assert stats["meshes_extracted"] == 1 and extract.NORMALS_BY_CORNER in reads


def test_a_mesh_of_ngons_moves_without_extraction_while_blender_splits_it_alike(output_dir):
    """A tube with 16-sided caps: a move that keeps Blender's triangulation of
    every n-gon uploads positions only and draws what the reference does; a
    move that makes Blender split a cap another way (a corner pushed deep
    inside it) is extracted again, and draws what the reference does too."""
    scene = scenes.empty_scene(200, 150, thickness=1.5)
    tube = scenes.tube(scene, segments=16, depth=1.0, rotation=(0.9, 0.1, 0.3))
    scenes.add_camera(scene, location=(0.0, -5.0, 3.0), target=(0.0, 0.0, 0.0))
    cap = max(tube.data.polygons, key=lambda face: len(face.vertices))
    corner = tube.data.vertices[cap.vertices[5]]

    def cap_triangles():
        tube.data.calc_loop_triangles()
        return sorted(tuple(sorted(t.vertices)) for t in tube.data.loop_triangles if t.polygon_index == cap.index)

    render(scene, output_dir / "deform_ngons.png")
    before = cap_triangles()
    corner.co.z += 0.2  # out of the cap's plane, same split
    tube.data.update()
    assert cap_triangles() == before
    rgba, stats = render(scene, output_dir / "deform_ngons.png")
    assert (stats["meshes_extracted"], stats["meshes_repositioned"]) == (0, 1)
    accuracy.assert_accurate(reference.error_report(rgba[..., 3], reference.render_reference(scene)))
    corner.co.x *= 0.1  # deep inside the cap: a dart Blender splits another way
    corner.co.y *= 0.1
    tube.data.update()
    assert cap_triangles() != before
    rgba, stats = render(scene, output_dir / "deform_ngons.png")
    assert (stats["meshes_extracted"], stats["meshes_repositioned"]) == (1, 0)
    accuracy.assert_accurate(reference.error_report(rgba[..., 3], reference.render_reference(scene)))
