"""Bad geometry never takes a render down.

Each faulty object sits beside a good one, out of its way in the picture.
Every case checks, through the real engine and a float EXR file (which keeps
NaN): no exception escapes, no NaN/Inf pixel, the picture matches the float64
reference (the faulty object is skipped or drawn without its bad faces), the
good object's pixels are exactly those of a render without the faulty object,
and at most one message, printed once across two renders, names the object.
"""

from __future__ import annotations

import math

import bpy
import numpy as np
import pytest

from solidwire_addon.core import extract, log
from tests.support import accuracy, reference, robustness, scenes

W, H = 96, 64
NAN, INF = math.nan, math.inf


@pytest.fixture(autouse=True)
def fresh_messages():
    """Messages are said once per session; each test starts afresh."""
    log.forget()
    yield
    log.forget()


def _mesh_object(scene, name, verts, edges, faces, location):
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata([tuple(v) for v in verts], list(edges), [tuple(f) for f in faces])
    mesh.update()  # no validate(): keep the bad data as it is
    obj = bpy.data.objects.new(name, mesh)
    scene.collection.objects.link(obj)
    obj.location = location
    return obj


def _strip(n=3):
    """A strip of n unit quads along x (vertex ids 2k, 2k+1 at x = k)."""
    verts = [(k - n / 2, 0.0, z) for k in range(n + 1) for z in (-0.8, 0.8)]
    faces = [(2 * k, 2 * k + 2, 2 * k + 3, 2 * k + 1) for k in range(n)]
    return verts, faces


def _nonfinite(scene, name, loc):
    verts, faces = _strip(3)
    verts[2] = (NAN, 0.0, -0.8)  # quad 0 and quad 1 share vertex 2
    verts[7] = (1.5, INF, 0.8)  # quad 2
    verts.append((0.0, -NAN, 2.0))  # loose and NaN
    # plus a healthy triangle so something of the object is drawn
    verts += [(-1.4, 0.0, 1.0), (-0.6, 0.0, 1.0), (-1.0, 0.0, 1.6)]
    faces.append((9, 10, 11))
    return _mesh_object(scene, name, verts, [], faces, loc)


def _all_nonfinite(scene, name, loc):
    verts, faces = _strip(2)
    verts = [(NAN, y, z) for (_x, y, z) in verts]
    return _mesh_object(scene, name, verts, [], faces, loc)


def _nan_misleading_bound_box(scene, name, loc):
    # Blender 5.0's bound box of this mesh is finite but wrong: x in [40, 40],
    # out of view, while the healthy triangle at the origin is in view (4.2's
    # is right). The box must not cull the object before extraction.
    verts = [(-0.6, 0.0, -0.5), (0.6, 0.0, -0.5), (0.0, 0.0, 0.6), (NAN, 0.0, 0.0)]
    verts += [(40.0, 0.0, 0.0), (40.0, 0.0, 1.0), (40.0, 0.0, 2.0)]
    return _mesh_object(scene, name, verts, [], [(0, 1, 2), (3, 4, 5, 6)], loc)


def _zero_area(scene, name, loc):
    # Distinct vertices on one line, and a quad whose corners coincide in
    # pairs: zero area, never visible (SPEC 1.2).
    verts = [(-1, 0, 0), (0, 0, 0), (1, 0, 0), (0, 0, 1), (0, 0, 1), (0.5, 0, 1), (0.5, 0, 1)]
    return _mesh_object(scene, name, verts, [], [(0, 1, 2), (3, 4, 5, 6)], loc)


def _repeated_vertex(scene, name, loc):
    # Corrupt faces that use one vertex twice (Blender keeps them until
    # Mesh > Clean Up): (0, 1, 1, 2) is a triangle with a zero-length edge,
    # (3, 3, 3) a point, (4, 5, 4) a segment.
    verts = [(-1, 0, -0.8), (1, 0, -0.8), (0, 0, 0.8), (0, 0, 1.5), (0.5, 0, 1.5), (1, 0, 1.5)]
    return _mesh_object(scene, name, verts, [], [(0, 1, 1, 2), (3, 3, 3), (4, 5, 4)], loc)


def _loose_only(scene, name, loc):
    verts = [(-1, 0, 0), (1, 0, 0), (0, 0, 1), (0.5, 0.5, 0.5)]
    return _mesh_object(scene, name, verts, [(0, 1), (1, 2)], [], loc)


def _empty(scene, name, loc):
    return _mesh_object(scene, name, [], [], [], loc)


def _huge_far_away(scene, name, loc):
    # 1e8-scale coordinates: a triangle 1e8 away and one spanning 1e8
    # (both out of view here: the good object must not notice).
    verts = [(1e8, 1e8, 0), (1e8 + 1, 1e8, 0), (1e8, 1e8 + 1, 0), (0, 5e7, 0), (-1e8, 5e7, 0), (0, 5e7, 1e8)]
    return _mesh_object(scene, name, verts, [], [(0, 1, 2), (3, 4, 5)], loc)


def _huge_coordinates(scene, name, loc):
    # Finite, but past what float32 can square: 3e38 is what Blender stores
    # for a curve point set to inf; 2e19 squared overflows float32. Their
    # faces are dropped as a NaN vertex's are (image model §2.1); 1e19, just
    # under the limit, is kept (that face runs out of the picture).
    verts, faces = _strip(3)
    verts[2] = (3.0e38, 0.0, -0.8)  # quads 0 and 1
    verts[7] = (1.5, -2.0e19, 0.8)  # quad 2
    verts += [(-1.4, 0.0, 1.0), (-0.6, 0.0, 1.0), (-1.0, 0.0, 1.6), (-1.0, 1.0e19, 1.6)]
    faces += [(8, 9, 10), (8, 10, 11)]
    return _mesh_object(scene, name, verts, [], faces, loc)


# case -> (builder, text the one message must contain or None, draws anything)
CASES = {
    "nan_and_inf_vertices": (_nonfinite, "non-finite", True),
    "all_vertices_nan": (_all_nonfinite, "non-finite", False),
    "nan_vertex_misleads_bound_box": (_nan_misleading_bound_box, "non-finite", True),
    "zero_area_faces": (_zero_area, None, False),
    "face_uses_vertex_twice": (_repeated_vertex, "uses one vertex twice", True),
    "loose_edges_and_vertices_only": (_loose_only, "no faces", False),
    # An empty mesh is also what a pure instancer evaluates to: no message.
    "empty_mesh": (_empty, None, False),
    "coordinates_1e8": (_huge_far_away, None, False),
    "huge_coordinates": (_huge_coordinates, "huge (1.8e19 or more)", True),
}


def _base_scene():
    scene = scenes.empty_scene(W, H, thickness=1.5)
    location = robustness.cube_beside(scene)
    return scene, location


@pytest.mark.parametrize("case", list(CASES))
def test_bad_object_beside_a_good_one(case, output_dir, capfd):
    build, message, draws = CASES[case]
    scene, location = _base_scene()
    without = robustness.render_exr(scene, output_dir / f"bad_{case}_without.exr")
    name = f"Faulty_{case}"
    build(scene, name, location)
    capfd.readouterr()

    # Two renders: the message must come once, not every frame.
    first = robustness.render_exr(scene, output_dir / f"bad_{case}.exr")
    second = robustness.render_exr(scene, output_dir / f"bad_{case}.exr")
    err = capfd.readouterr()
    said = robustness.lines_of(err.out + err.err, f"'{name}'")

    for image in (first, second):
        assert np.isfinite(image).all(), f"{case}: NaN/Inf pixels"
    assert np.array_equal(first, second)

    # The good object is drawn exactly as without the faulty one.
    good = without[..., 3] > 0
    assert good.sum() > 100
    assert np.array_equal(first[good], without[good]), case
    if not draws:
        assert np.array_equal(first, without), f"{case}: the faulty object drew something"
    else:
        assert (first[..., 3] > 0.5).sum() > (without[..., 3] > 0.5).sum() + 20, f"{case}: its good faces are missing"

    # And the whole picture is the image model's (bad faces are not drawn).
    ref = reference.render_reference(scene)
    report = reference.error_report(first[..., 3].astype(np.float64), ref)
    accuracy.assert_accurate(report)

    if message is None:
        assert len(said) <= 1, said
    else:
        assert len(said) == 1, f"expected one message naming {name!r}, got: {said}"
        assert message in said[0], said


def test_overlay_with_every_bad_object(capfd):
    """The viewport overlay goes through the same path: all the faulty
    objects at once, two redraws, no exception, no NaN, one message each."""
    from solidwire_addon.blender.gpu_context import ensure_gpu

    scene, location = _base_scene()
    ensure_gpu()
    viewport = robustness.Viewport(W, H)
    _stats, without = viewport.draw(scene)
    for index, (case, (build, _message, _draws)) in enumerate(CASES.items()):
        build(scene, f"Overlay_{case}", (location[0], 2.0 * index, location[2]))
    capfd.readouterr()
    first_stats, first = viewport.draw(scene)
    _stats, second = viewport.draw(scene)
    err = capfd.readouterr()
    assert np.isfinite(first).all() and np.array_equal(first, second)
    good = without > 0
    assert good.sum() > 100 and np.array_equal(first[good], without[good])
    assert first_stats["objects_drawn"] >= 2
    for case, (_build, message, _draws) in CASES.items():
        said = robustness.lines_of(err.out + err.err, f"'Overlay_{case}'")
        assert len(said) == (1 if message else len(said)) and len(said) <= 1, (case, said)


def test_a_wrong_bound_box_does_not_cull_a_mesh_with_a_nan_vertex(output_dir, monkeypatch):
    """Whatever box Blender reports for a mesh with a non-finite vertex (some
    versions report a finite box that misses finite vertices), the object is
    culled before extraction only by the box of its finite vertices."""
    from solidwire_addon.blender import gather
    from solidwire_addon.blender import runtime as addon_runtime

    scene, location = _base_scene()
    without = robustness.render_exr(scene, output_dir / "wrong_box_without.exr")
    _nan_misleading_bound_box(scene, "Misleading", location)
    out_of_view = (np.array([40.0, 0.0, -0.5]), np.array([40.0, 0.0, 2.0]))
    monkeypatch.setattr(gather, "_bound_box", lambda obj: out_of_view if obj.name == "Misleading" else None)
    image = robustness.render_exr(scene, output_dir / "wrong_box.exr")
    assert addon_runtime.stats()["objects_culled"] == 0
    assert (image[..., 3] > 0.5).sum() > (without[..., 3] > 0.5).sum() + 20, "the in-view triangle is missing"
    report = reference.error_report(image[..., 3].astype(np.float64), reference.render_reference(scene))
    accuracy.assert_accurate(report)


def test_the_viewport_culls_a_mesh_with_a_nan_vertex_by_its_finite_vertices():
    """The viewport extracts every mesh and culls at draw time by the box of
    the vertices it draws: out of view, a mesh with a NaN vertex is culled at
    every redraw; once an edit moves its triangle into view (Blender's box
    may still say otherwise), the next redraw draws it."""
    from solidwire_addon.blender.gpu_context import ensure_gpu

    scene, location = _base_scene()
    ensure_gpu()
    viewport = robustness.Viewport(W, H)
    _stats, without = viewport.draw(scene)
    in_view = [(-0.6, 0.0, -0.5), (0.6, 0.0, -0.5), (0.0, 0.0, 0.6)]
    away = [(x + 40.0, y, z) for x, y, z in in_view]
    verts = [*away, (NAN, 0.0, 0.0), (40.0, 0.0, 0.0), (40.0, 0.0, 1.0), (40.0, 0.0, 2.0)]
    obj = _mesh_object(scene, "Away", verts, [], [(0, 1, 2), (3, 4, 5, 6)], location)
    for _redraw in range(2):
        stats, image = viewport.draw(scene)
        assert stats["objects_culled"] == 1 and np.array_equal(image, without)
    for vertex, co in zip(obj.data.vertices, in_view):
        vertex.co = co
    obj.data.update()
    stats, image = viewport.draw(scene)
    assert stats["objects_culled"] == 0
    assert (image > 0.5).sum() > (without > 0.5).sum() + 20, "the triangle moved into view is missing"


def test_a_face_with_a_nan_corner_is_dropped_whole():
    """A quad with one NaN corner: both its triangles go (a kept half would
    draw edges to a corner that has no position)."""
    verts, faces = _strip(2)
    verts[0] = (NAN, 0.0, 0.0)
    arrays = extract.build_arrays(
        positions=np.array(verts, np.float32),
        corner_vert=np.array([v for f in faces for v in f], np.int32),
        loop_start=np.array([0, 4], np.int32),
        loop_total=np.array([4, 4], np.int32),
        tri_loops=np.array([[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]], np.int32),
        tri_polygons=np.array([0, 0, 1, 1], np.int32),
    )
    assert arrays.dropped_triangles == 2
    assert arrays.triangle_polygons.tolist() == [1, 1]
    assert np.isfinite(arrays.positions).all() and np.isfinite(arrays.centre).all()


@pytest.mark.parametrize("bad", [-INF, INF], ids=["-inf", "inf"])
def test_an_edge_beside_a_dropped_face_stays_drawn_under_the_edge_angle(bad, output_dir):
    """A dropped face has no normal (image model §2.1, §3.4), whatever
    Blender gives it (+Z for a triangle with an infinite corner): under an
    edge angle the edge it shares with a drawn quad stays drawn, and no
    region joins the quad to it. Before, the quad lying flat under +Z lost
    that edge and drew the dropped face's other edges across itself
    instead (a random-mesh test: 110 pixels up to 1.0)."""
    scene = scenes.empty_scene(W, H, edge_angle=math.radians(30.0), thickness=1.5)
    verts = [(-1.0, -0.8, 0.0), (0.6, -0.8, 0.0), (0.6, 0.8, 0.0), (-1.0, 0.8, 0.0), (bad, 0.2, 0.0)]
    _mesh_object(scene, "Dropped", verts, [], [(0, 1, 2, 3), (1, 4, 2)], (0.0, 0.0, 0.0))
    scenes.add_camera(scene, location=(0.3, -1.0, 4.0), target=(0, 0, 0))
    report = accuracy.measure(scene, f"dropped_face_beside_edge_angle_{'minus' if bad < 0 else 'plus'}_inf", output_dir)
    accuracy.assert_accurate(report)
    ref = reference.render_reference(scene)
    x_right = np.flatnonzero((ref.intensity > 0.9).any(axis=0)).max()
    assert x_right > W // 2, "the quad's right edge, shared with the dropped face, is drawn"


def test_a_curve_edge_beside_a_dropped_face_stays_its_outline(output_dir):
    """A curve's tessellation hides the edges between its coplanar faces
    (image model §3.9), and that rule compares face normals too: a face
    dropped for a non-finite corner has none (§3.4). Here a ribbon lies flat
    under +Z, and its last point is NaN, so its second segment's face is
    dropped (Blender gives it the normal +Z as well). The edge the two
    segments share is the drawn face's outline. Before, the outline mask
    read Blender's normals and hid it (a random test of tessellated sources:
    a silhouette missing beside a bevel's dropped ring; 100 pixels up to 1.0
    here)."""
    scene = scenes.empty_scene(64, 48, thickness=1.5)
    curve = bpy.data.curves.new("Ribbon", "CURVE")
    curve.dimensions = "3D"
    curve.extrude = 0.3
    spline = curve.splines.new("POLY")
    spline.points.add(2)
    for point, x in zip(spline.points, (-1.0, 0.4, float("nan"))):
        point.co = (x, 0.0, 0.0, 1.0)
        point.tilt = math.pi / 2  # the ribbon lies in the XY plane
    ribbon = bpy.data.objects.new("Ribbon", curve)
    scene.collection.objects.link(ribbon)
    scenes.add_camera(scene, location=(0.0, -0.3, 4.0), target=(0, 0, 0))
    report = accuracy.measure(scene, "curve_edge_beside_dropped_face", output_dir)
    accuracy.assert_accurate(report)
    ref = reference.render_reference(scene)
    lit_columns = np.flatnonzero((ref.intensity > 0.9).sum(axis=0) > 10)
    assert len(lit_columns) == 2, "the ribbon's two ends are drawn across it"


@pytest.mark.parametrize("edge_angle", [0.0, 0.5], ids=["own-faces", "one-region"])
def test_an_edge_whose_ends_coincide_draws_the_point_it_shrinks_to(edge_angle, output_dir):
    """An edge whose two vertices lie at one position (an unmerged seam, a
    NURBS sphere's pole) is a point, drawn as the disc a very short edge
    draws there (image model §3.2), whether the resolve or the region-lines
    pass draws it. Here it is marked sharp (a class 6 px wide beside the
    1 px wire), so the disc shows. Before, a point drew nothing while an
    edge 1e-5 long drew the disc, so a render and the float64 reference
    disagreed wherever float32 rounded such an edge to a point and float64
    did not (a random text, curve and surface test: a pole's disc missing,
    0.12 at its edge)."""
    images = {}
    for name, gap, sharp in (("point", 0.0, True), ("short", 1e-5, True), ("unmarked", 0.0, False)):
        scene = scenes.empty_scene(
            W, H, edge_angle=edge_angle, thickness=1.0, use_sharp_edges=True, sharp_thickness=6.0
        )
        # A 2 x 2 grid whose middle vertex is two: P (0) and P' (1), both
        # corners of the lower right and upper left faces, whose shared
        # edge P P' has no length.
        verts = [(0.0, 0.0, 0.0), (gap, 0.0, 0.0)]
        verts += [(x, 0.0, z) for z, x in ((-0.8, -0.9), (-0.8, 0.0), (-0.8, 0.9), (0.0, 0.9))]  # 2-5
        verts += [(x, 0.0, z) for z, x in ((0.8, 0.9), (0.8, 0.0), (0.8, -0.9), (0.0, -0.9))]  # 6-9
        faces = [(2, 3, 0, 9), (3, 4, 5, 1, 0), (1, 5, 6, 7), (9, 0, 1, 7, 8)]
        obj = _mesh_object(scene, "Seam", verts, [], faces, (0.0, 0.0, 0.0))
        next(e for e in obj.data.edges if set(e.vertices) == {0, 1}).use_edge_sharp = sharp
        scenes.add_camera(scene, location=(0.2, -4.0, 0.3), target=(0.0, 0.0, 0.0))
        report = accuracy.measure(scene, f"coincident_ends_{name}_{edge_angle}", output_dir)
        accuracy.assert_accurate(report)
        images[name] = scenes.load_png(output_dir / f"coincident_ends_{name}_{edge_angle}.png")[..., 3]
    assert np.abs(images["point"] - images["short"]).max() <= 2.0 / 255.0
    # Not vacuous: the class's disc adds to what the wire draws there.
    assert (images["point"] - images["unmarked"]).sum() > 5.0


def test_degenerate_triangles_are_counted():
    arrays = extract.build_arrays(
        positions=np.array([(0, 0, 0), (1, 0, 0), (0, 1, 0)], np.float32),
        corner_vert=np.array([0, 1, 1, 2], np.int32),
        loop_start=np.array([0], np.int32),
        loop_total=np.array([4], np.int32),
        tri_loops=np.array([[0, 1, 2], [0, 2, 3]], np.int32),
        tri_polygons=np.array([0, 0], np.int32),
    )
    assert arrays.degenerate_triangles == 1


def test_an_object_that_fails_to_upload_is_skipped_alone(output_dir, capfd, monkeypatch):
    """Any failure while one object is prepared (here: its GPU upload) skips
    that object with one message; the rest of the frame is drawn."""
    from solidwire_addon.core import cache

    scene, location = _base_scene()
    without = robustness.render_exr(scene, output_dir / "upload_fail_without.exr")
    scenes.monkey(scene, "Unlucky", location=location)

    real = cache.GPUMesh

    class FailingGPUMesh(real):
        def __init__(self, arrays, *args, **kwargs):
            if arrays.vertex_count == 507:  # Suzanne
                raise MemoryError("GPU out of memory (simulated)")
            super().__init__(arrays, *args, **kwargs)

    monkeypatch.setattr(cache, "GPUMesh", FailingGPUMesh)
    capfd.readouterr()
    first = robustness.render_exr(scene, output_dir / "upload_fail.exr")
    robustness.render_exr(scene, output_dir / "upload_fail.exr")
    err = capfd.readouterr()
    said = robustness.lines_of(err.out + err.err, "'Unlucky'")
    assert np.array_equal(first, without)
    assert len(said) == 1 and "MemoryError" in said[0], said


def test_coordinates_1e8_in_view_match_reference(output_dir):
    """A 2e8-wide floor under a small cube, camera close: float32 on the GPU
    still matches the float64 reference (the far ends are only clipped)."""
    scene = scenes.empty_scene(W, H)
    scenes.grid(scene, "HugeFloor", x_segments=4, y_segments=4, size=2e8, location=(0.3, 0.2, -1.0))
    scenes.cube(scene, size=1.0)
    scenes.add_camera(scene, location=(3.0, -3.0, 1.5), target=(0, 0, 0), clip=(0.1, 1000.0))
    report = accuracy.measure(scene, "coordinates_1e8_floor", output_dir)
    accuracy.assert_accurate(report)
    assert report["pixels"] > 0


def test_object_1e8_from_origin_matches_reference(output_dir):
    scene = scenes.empty_scene(W, H)
    scenes.monkey(scene, location=(1e8, -1e8, 1e8))
    scenes.add_camera(scene, location=(1e8 + 2.0, -1e8 - 4.0, 1e8 + 1.5), target=(1e8, -1e8, 1e8))
    report = accuracy.measure(scene, "object_at_1e8", output_dir)
    accuracy.assert_accurate(report)


def test_stray_far_vertex_does_not_spoil_the_faces(output_dir):
    """One loose vertex 1e6 away once moved the re-centring point to ~5e5,
    where float32 cannot hold the real faces (p99.9 |dI| = 1.0)."""
    scene = scenes.empty_scene(64, 48)
    _mesh_object(
        scene, "Stray", [(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0), (1e6, 1e6, 1e6)], [], [(0, 1, 2, 3)], (0, 0, 0)
    )
    scenes.add_camera(scene, location=(0.5, -3.0, 3.0), target=(0, 0, 0))
    report = accuracy.measure(scene, "stray_far_vertex", output_dir)
    accuracy.assert_accurate(report)


def test_the_coordinate_limit_holds_in_the_mesh_s_own_space(output_dir, capfd):
    """The limit of 1.8e19 is on the mesh's own coordinates, as Blender
    stores them (image model §2.1), whatever the object's scale: a face
    with a corner at 2e19 in an object scaled by 0.25 is dropped, one with
    a corner at 1e19 in an object scaled by 4 is drawn (it runs away from
    the camera, past the far clip: see image model §2.1 on float32's range
    across the view)."""
    scene = scenes.empty_scene(64, 48)
    for name, far_corner, scale, x in (
        ("Shrunk", (-2.0e19, 0.0, 1.0), 0.25, -1.2),  # 5e18 in the world
        ("Grown", (0.0, 1.0e19, 1.0), 4.0, 1.2),  # 4e19 in the world
    ):
        near_corners = [(-1.0 / scale, 0.0, -1.0 / scale), (1.0 / scale, 0.0, -1.0 / scale), (0.0, 0.0, 1.0 / scale)]
        obj = _mesh_object(scene, name, [*near_corners, far_corner], [], [(0, 1, 2), (0, 2, 3)], (x, 0.0, 0.0))
        obj.scale = (scale, scale, scale)
    scenes.add_camera(scene, location=(0.0, -6.0, 0.5), target=(0.0, 0.0, 0.0))
    capfd.readouterr()
    report = accuracy.measure(scene, "coordinate_limit_in_mesh_space", output_dir)
    said = capfd.readouterr()
    accuracy.assert_accurate(report)
    assert "'Shrunk'" in said.out + said.err and "'Grown'" not in said.out + said.err


def test_messages_are_capped(capfd):
    """Thousands of broken objects (or an error text that changes every
    redraw) print at most MAX_MESSAGES lines and one line saying so."""
    capfd.readouterr()
    for index in range(3 * log.MAX_MESSAGES):
        log.warn_once(("test", index), f"SolidWire: message {index}")
        log.warn_once(("test", index), f"SolidWire: message {index}")
    lines = [line for line in capfd.readouterr().err.splitlines() if line.startswith("SolidWire")]
    assert len(lines) == log.MAX_MESSAGES + 1
    assert "further ones are not shown" in lines[-1]
    assert len(log._said) <= log.MAX_MESSAGES + 1
