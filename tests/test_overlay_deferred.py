"""The viewport overlay's deferred surface (docs/image_model.md §2.5, the
overlay section of docs/dev/viewport-benchmark.md): where Blender's depth
holds every surface, a mesh dense on screen is recorded into the overlay's
own targets (which triangle each pixel shows, over a depth of its own) and
resolved into Blender's buffer, where the record's depth (less the
overlay's bias) meets Blender's depth test. A redraw that changes nothing
the record depends on reuses it.

Every mesh is deferred here however sparse (the threshold is set to 0),
and the image is checked against the float64 reference, against the
direct pass's image, and frame against fresh frame."""

from __future__ import annotations

import bpy
import numpy as np
import pytest
from mathutils import Vector

from solidwire_addon.blender import runtime
from solidwire_addon.blender.gpu_context import ensure_gpu
from solidwire_addon.blender.views import camera_view
from solidwire_addon.core import draw, overlay_state, passes
from solidwire_addon.core.options import DrawOptions
from solidwire_addon.core.overlay_state import MATERIAL, ViewportState
from tests.support import accuracy, reference, scenes
from tests.test_deferred_surface import _stages, refuse_variants
from tests.test_overlay import HEIGHT, WIDTH, FakeViewport, build_scene

pytestmark = pytest.mark.filterwarnings("ignore:'DEPTH24_STENCIL8' is deprecated:DeprecationWarning")


@pytest.fixture(autouse=True)
def every_mesh_deferred(monkeypatch):
    ensure_gpu()
    monkeypatch.setattr(passes, "OVERLAY_DEFERRED_MIN_DENSITY", 0.0)


SOLID = ViewportState()


def _draw(scene, depth_objects, state=SOLID, depth_format="DEPTH32F_STENCIL8", size=(WIDTH, HEIGHT)):
    """(rgba in 0..1 as the screen shows it, stats) of one overlay frame over
    a Blender-like depth of ``depth_objects``."""
    depsgraph = bpy.context.evaluated_depsgraph_get()
    view = camera_view(scene, depsgraph, size)
    plan = overlay_state.plan_overlay(state)
    viewport = FakeViewport(*size, depth_format)
    viewport.depth_pass(depsgraph, view, list(depth_objects))
    stats = viewport.draw_overlay(depsgraph, view, scene.solidwire.snapshot(), plan=plan)
    return viewport.rgba(), stats


def _assert_matches_reference(scene, alpha, state=SOLID):
    plan = overlay_state.plan_overlay(state)
    settings = overlay_state.draw_settings(plan, scene.solidwire.snapshot())
    ref = reference.render_reference(scene, size=alpha.shape[::-1], settings=settings)
    accuracy.assert_accurate(reference.error_report(alpha, ref))
    assert ref.intensity.max() > 0.9, "the scene draws visible wires"


@pytest.mark.parametrize("depth_format", ["DEPTH32F_STENCIL8", "DEPTH24_STENCIL8"])
@pytest.mark.parametrize("look", ["default", "flat", "fill_off", "dotted"])
def test_deferred_overlay_matches_reference(look, depth_format, monkeypatch):
    """Solid shading over Blender's depth (24-bit as older viewports, or
    float): the record and resolve draw what the reference draws, and no
    surface of ours draws directly."""
    looks = {
        "default": {},
        "flat": {"fill_shading": "FLAT"},
        "fill_off": {"use_fill": False},
        "dotted": {"diagonal_mode": "DOTTED"},
    }
    scene, objects = build_scene(thickness=1.5, **looks[look])
    calls = _stages(monkeypatch)
    rgba, stats = _draw(scene, objects, depth_format=depth_format)
    assert stats["objects_drawn"] == 2
    assert calls.count(draw.VISIBILITY) == 1 and calls.count(draw.RESOLVE) == 1, calls
    _assert_matches_reference(scene, rgba[..., 3])


@pytest.mark.parametrize("silhouettes", [False, True], ids=["plain", "silhouettes"])
def test_deferred_overlay_draws_the_direct_image(silhouettes, monkeypatch):
    """Colour and alpha as the direct pass draws them, up to float32
    rounding of the resolve's interpolation (within 1/255 of the display
    encoding), over the same Blender depth; full-width silhouettes, drawn
    after the surface against the depth it leaves, alike."""
    scene, objects = build_scene(thickness=1.5, diagonal_mode="SOLID", use_silhouettes=silhouettes)
    deferred, _stats = _draw(scene, objects)
    monkeypatch.setattr(runtime, "options", DrawOptions(deferred_surface=False))
    calls = _stages(monkeypatch)
    direct, _stats = _draw(scene, objects)
    assert draw.RESOLVE not in calls
    assert direct[..., 3].max() > 0.9
    assert np.abs(deferred - direct).max() <= 1.0 / 255.0 + 1e-9


# The viewport states whose depth holds none of our surfaces
# (test_overlay_states.SHADING_STATES): X-ray, Wireframe shading.
WITHOUT_SCENE_SURFACES = ("solid_xray_half", "solid_xray_zero", "wireframe_xray", "wireframe_opaque")


@pytest.mark.parametrize("name", WITHOUT_SCENE_SURFACES)
def test_deferred_overlay_without_blenders_surfaces(name, monkeypatch):
    """In X-ray and Wireframe shading Blender's depth holds none of our
    surfaces: every mesh deferred, the composite writes our nearest depth
    itself (no depth-only pre-pass), and the image is the reference's and
    the direct pass's, with Blender's depth present or cleared."""
    from tests.test_overlay_states import SHADING_STATES

    state, with_depth = SHADING_STATES[name]
    scene, objects = build_scene(thickness=1.5, diagonal_mode="SOLID")
    depth = objects if with_depth else ()
    calls = _stages(monkeypatch)
    deferred, stats = _draw(scene, depth, state)
    assert stats["objects_drawn"] == 2
    assert calls.count(draw.VISIBILITY) == 1 and calls.count(draw.RESOLVE) == 1, calls
    _assert_matches_reference(scene, deferred[..., 3], state)
    monkeypatch.setattr(runtime, "options", DrawOptions(deferred_surface=False))
    calls.clear()
    direct, _stats = _draw(scene, depth, state)
    assert draw.RESOLVE not in calls
    assert np.abs(deferred - direct).max() <= 1.0 / 255.0 + 1e-9


@pytest.mark.parametrize("name", ["solid", "solid_xray_half"])
def test_a_frame_of_deferred_and_direct_meshes(name, monkeypatch):
    """One mesh deferred, one drawn directly: over Blender's depth of both
    (Solid) the split stands; where that depth holds none of our surfaces
    (X-ray) the direct mesh would need the deferred one's depth before its
    colour and the other way round, so the whole frame is drawn directly.
    Either way the image is the reference's."""
    from tests.test_overlay_states import SHADING_STATES

    state, _with_depth = SHADING_STATES[name]
    scene, objects = build_scene(thickness=1.5, diagonal_mode="SOLID")
    split = draw.split_deferred
    monkeypatch.setattr(draw, "split_deferred", lambda items, *args: (split(items, *args)[0][:1], items[1:]))
    calls = _stages(monkeypatch)
    rgba, stats = _draw(scene, objects, state)
    assert stats["objects_drawn"] == 2
    assert (draw.RESOLVE in calls) == (name == "solid"), calls
    _assert_matches_reference(scene, rgba[..., 3], state)


def test_material_preview_and_blender_only_occluder():
    """Material Preview keeps Blender's depth too; a cube that only Blender
    draws (opted out of SolidWire) hides what lies behind it, though the
    overlay's own record, which never sees that cube, holds the grid."""
    scene = scenes.empty_scene(WIDTH, HEIGHT, thickness=2.0, diagonal_mode="SOLID")
    scenes.add_camera(scene, location=(0.0, -10.0, 0.0))
    grid = scenes.grid(scene, "Grid", x_segments=8, y_segments=8, size=1.5, rotation=(1.5708, 0, 0))
    occluder = scenes.cube(scene, "Occluder", size=1.2, location=(0.4, -3.0, 0.2))
    occluder.solidwire_exclude = True
    state = ViewportState(shading=MATERIAL)
    rgba, stats = _draw(scene, (grid, occluder), state)
    assert stats["objects_drawn"] == 1
    alpha = rgba[..., 3]
    occluder.hide_render = occluder.hide_viewport = True
    without, _stats = _draw(scene, (grid,), state)
    _assert_matches_reference(scene, without[..., 3], state)
    occluder.hide_render = occluder.hide_viewport = False
    # The occluder faces the camera: its window footprint is its front
    # face's rectangle.
    depsgraph = bpy.context.evaluated_depsgraph_get()
    view = camera_view(scene, depsgraph, (WIDTH, HEIGHT))
    corners = np.array([(x, -3.6, z, 1.0) for x in (-0.2, 1.0) for z in (-0.4, 0.8)])
    clip = (view.projection @ view.view_matrix @ corners.T).T
    window = (clip[:, :2] / clip[:, 3:] * 0.5 + 0.5) * (WIDTH, HEIGHT)
    (x0, y0), (x1, y1) = window.min(axis=0), window.max(axis=0)
    ys, xs = np.mgrid[0:HEIGHT, 0:WIDTH] + 0.5
    inside = (xs > x0 + 2) & (xs < x1 - 2) & (ys > y0 + 2) & (ys < y1 - 2)
    outside = (xs < x0 - 3) | (xs > x1 + 3) | (ys < y0 - 3) | (ys > y1 + 3)
    assert (without[..., 3][inside] > 0.5).sum() > 50, "the grid's wire lies behind the occluder"
    assert alpha[inside].max() == 0.0
    assert without[..., 3][outside].max() > 0.9
    assert np.abs(alpha[outside] - without[..., 3][outside]).max() <= 1.0 / 255.0 + 1e-9


def _path(stats) -> str:
    """How the frame drew its deferred surface (passes._overlay_surface)."""
    names = ("surface_straight", "record_reused", "surface_reused", "surface_edited", "surface_partial")
    paths = [name for name in names if stats.get(name)]
    assert len(paths) == 1, stats
    return paths[0]


def test_what_is_kept_between_redraws():
    """A redraw after a change (the first one, another setting, a moved
    object, another view) records again and resolves straight into
    Blender's buffer; the next redraw that changes nothing resolves the
    kept record into an image it keeps, and the ones after only composite
    that image. An edit (vertices moved) keeps its image, for the next edit
    of a drag. Every frame equals a fresh one (after edits, up to the
    rounding of the centre they kept)."""
    scene, objects = build_scene(thickness=1.5, diagonal_mode="SOLID")
    front, _back = objects

    def frame():
        rgba, stats = _draw(scene, objects)
        return rgba, _path(stats)

    first, path = frame()
    assert path == "surface_straight"
    again, path = frame()
    assert path == "record_reused" and np.array_equal(first, again)
    third, path = frame()
    assert path == "surface_reused" and np.array_equal(first, third)
    scene.solidwire.thickness = 3.0
    thicker, path = frame()
    assert path == "surface_straight" and not np.array_equal(first, thicker)
    _thicker, path = frame()
    assert path == "record_reused"
    # Vertices moved within the bounds (flat fill: no shading normals)
    # redraw only what they changed in the kept image.
    front.data.vertices[0].co.z += 0.3
    front.data.update()
    edited, path = frame()
    assert path == "surface_partial" and not np.array_equal(thicker, edited)
    kept, path = frame()
    assert path == "surface_reused" and np.array_equal(edited, kept)
    # Past the bounds: everything again, kept for the next edit.
    front.data.vertices[0].co.z -= 0.8
    front.data.update()
    past, path = frame()
    assert path == "surface_edited" and not np.array_equal(edited, past)
    front.data.vertices[0].co.z += 0.1
    front.data.update()
    dragged, path = frame()
    assert path == "surface_partial" and not np.array_equal(past, dragged)
    scene.solidwire.thickness = 1.5  # the same meshes drawn afresh
    frame()
    scene.solidwire.thickness = 3.0
    again, path = frame()
    assert path == "surface_straight" and np.array_equal(dragged, again)
    front.location.x += 0.1
    moved, path = frame()
    assert path == "surface_straight" and not np.array_equal(dragged, moved)
    runtime.mesh_cache.clear()
    fresh, path = frame()
    # The edits above kept the mesh's centre (extract.reposition) where a
    # fresh extraction centres it again: the same image up to float32
    # rounding, which can move a pixel by one step of the 8-bit encoding.
    assert path == "surface_straight" and np.abs(moved - fresh).max() <= 1.0 / 255.0 + 1e-9
    scene.camera.location.z += 0.5
    other_view, path = frame()
    assert path == "surface_straight" and not np.array_equal(moved, other_view)
    _assert_matches_reference(scene, other_view[..., 3])


@pytest.mark.parametrize("look", ["default", "cage"])
def test_a_drag_redraws_only_what_it_changes(look):
    """Vertices that move within the mesh's bounds (a drag) redraw the kept
    image only inside the window rectangle they changed, shading normals
    and region lines included, and equal a fresh frame (which the tests
    above hold to the reference). A move the image cannot follow so (the first
    move of a shaded mesh, whose earlier normals were not kept) redraws
    everything and keeps the image."""
    looks = {"default": {"diagonal_mode": "SOLID"}, "cage": {"use_cage_edges": True}}
    scene = scenes.empty_scene(WIDTH, HEIGHT, thickness=1.5, use_fill=True, fill_shading="STUDIO", **looks[look])
    scenes.add_camera(scene, location=(6.0, -5.0, 4.0))
    front = scenes.cube(scene, "Front", size=1.6, location=(1.2, -0.4, 0.0))
    sphere = scenes.uv_sphere(scene, "Back", radius=1.2, location=(-1.6, 1.8, -0.3))
    for polygon in sphere.data.polygons:  # shading normals that follow the move
        polygon.use_smooth = True
    if look == "cage":
        modifier = sphere.modifiers.new("Subdivision", "SUBSURF")
        modifier.levels = 2
    objects = [front, sphere]

    def frame():
        rgba, stats = _draw(scene, objects)
        return rgba, _path(stats)

    # Vertices off every axis, so that they stay within the bounds: the one
    # that faces the camera most, dented deep (its neighbours' shading
    # normals turn), and one on the silhouette's side, pulled out (its
    # lines reach past every vertex the move changed).
    towards = Vector(scene.camera.location) - sphere.location
    inside = [v for v in sphere.data.vertices if min(abs(c) for c in v.co) > 0.15]
    dented = max(inside, key=lambda v: v.co.normalized().dot(towards.normalized()))
    pulled = min(inside, key=lambda v: abs(v.co.normalized().dot(towards.normalized()) - 0.3))

    def drag(step):
        dented.co *= 0.85 - 0.1 * step
        pulled.co *= 1.03 + 0.02 * step
        sphere.data.update()

    frame()
    frame()
    drag(0)
    first_edit, path = frame()
    assert path == "surface_edited"
    for step in (1, 2):
        drag(step)
        edited, path = frame()
        assert path == "surface_partial"
        assert not np.array_equal(first_edit, edited)
    runtime.mesh_cache.clear()
    fresh, path = frame()
    assert path == "surface_straight" and np.array_equal(edited, fresh)


@pytest.mark.parametrize("look", ["default", "cage", "ngon"])
def test_an_edit_redraws_up_to_the_lines_reach(look):
    """A grid facing the camera, smooth-shaded: a vertex moved across and
    out of the plane changes its lines up to their reach past every vertex
    it moved, and the shading of faces that do not touch it (their corners'
    normals turn). The partial redraw equals a fresh frame at every step;
    also beside an n-gon (two faces next to the moved vertex's merged: a
    corner of its own would make Blender split it anew), whose outline
    comes from the region-lines pass and whose diagonals show."""
    looks = {
        "default": {"diagonal_mode": "SOLID"},
        "cage": {"use_cage_edges": True},
        "ngon": {"diagonal_mode": "SOLID"},
    }
    scene = scenes.empty_scene(WIDTH, HEIGHT, thickness=2.5, use_fill=True, fill_shading="STUDIO", **looks[look])
    scenes.add_camera(scene, location=(0.0, -10.0, 0.0))
    plane = scenes.grid(scene, "Grid", x_segments=6, y_segments=6, size=1.5, rotation=(1.5708, 0, 0))
    for polygon in plane.data.polygons:
        polygon.use_smooth = True
    if look == "cage":
        plane.modifiers.new("Subdivision", "SUBSURF").levels = 1
    vertices = plane.data.vertices
    # Two corners off the plane set the bounds the moves stay within.
    corners = sorted(vertices, key=lambda v: (v.co.x, v.co.y))
    corners[0].co.z, corners[-1].co.z = 0.5, -0.5
    moved = min(vertices, key=lambda v: (v.co.x - 0.25) ** 2 + (v.co.y - 0.25) ** 2)
    if look == "ngon":
        import bmesh

        bm = bmesh.new()
        bm.from_mesh(plane.data)
        bm.verts.ensure_lookup_table()
        moved_index = moved.index
        near = set(bm.verts[moved_index].link_faces)
        beside = [f for f in bm.faces if f not in near and any(e in g.edges for g in near for e in f.edges)]
        pair = next([f, g] for f in beside for g in beside if f is not g and set(f.edges) & set(g.edges))
        merged = bmesh.ops.dissolve_faces(bm, faces=pair)["region"]
        assert len(merged) == 1 and len(merged[0].verts) == 6
        bm.to_mesh(plane.data)
        bm.free()
        moved = plane.data.vertices[moved_index]  # (the mesh's arrays were written anew)
    plane.data.update()

    def frame():
        rgba, stats = _draw(scene, [plane])
        return rgba, _path(stats)

    frame()
    frame()
    for _drag in range(2):
        # A drag: the first move of a freshly extracted shaded mesh redraws
        # everything (its earlier normals were not kept), the next only
        # what it changed.
        before, path = frame()
        assert path == "surface_reused"
        for expected in ("surface_edited", "surface_partial"):
            moved.co.x += 0.06
            moved.co.z += 0.12
            plane.data.update()
            edited, path = frame()
            assert path == expected and not np.array_equal(before, edited)
            before = edited
        runtime.mesh_cache.clear()
        fresh, _path_fresh = frame()
        assert np.array_equal(edited, fresh), np.abs(edited - fresh).max()
        frame()  # kept from now on


def _frames(scene, obj):
    """(frame, stats): ``frame()`` draws one overlay frame of ``obj`` and
    returns (rgba, how it drew its surface: _path); its stats go to the list
    ``stats``."""
    frame_stats = []

    def frame():
        rgba, stats = _draw(scene, [obj])
        frame_stats.append(stats)
        return rgba, _path(stats)

    return frame, frame_stats


@pytest.mark.parametrize(("software", "classes"), [(True, False), (False, False), (True, True)])
def test_a_partial_redraw_draws_the_region_lines_that_reach_it(monkeypatch, software, classes):
    """A dense subdivided grid, one vertex dragged near a corner: on a
    software rasteriser the partial redraw draws again only the
    region-lines runs that can reach its rectangle (their segments' window
    box widened by the lines' reach), elsewhere every run (the scissor drops
    the rest), and either equals a fresh frame: lines of edges just outside
    the rectangle that reach into it included (the grid's cells are
    narrower than the reach). With edge classes (sharp edges across the
    grid, one of them through the rectangle) the wire's runs and the
    classes' are drawn apart, each picked alike."""
    monkeypatch.setattr(passes.shaders, "software_rasteriser", lambda: software)
    look = dict(use_sharp_edges=True, sharp_thickness=3.0, sharp_pattern="DASHED") if classes else {}
    scene = scenes.empty_scene(WIDTH, HEIGHT, thickness=2.0, use_cage_edges=True, **look)
    scenes.add_camera(scene, location=(0.0, -10.0, 0.0))
    plane = scenes.grid(scene, "Grid", x_segments=40, y_segments=30, size=2.0, rotation=(1.5708, 0, 0))
    if classes:
        for edge in plane.data.edges:
            ys = [plane.data.vertices[v].co.y for v in edge.vertices]
            edge.use_edge_sharp = abs(ys[0] - ys[1]) < 1e-6 and round(ys[0] * 29 / 2.0) % 6 == 0
    plane.modifiers.new("Subdivision", "SUBSURF").levels = 1
    vertices = plane.data.vertices
    corners = sorted(vertices, key=lambda v: (v.co.x, v.co.y))
    corners[0].co.z, corners[-1].co.z = 0.3, -0.3  # the bounds the drag stays within
    moved = min(vertices, key=lambda v: (v.co.x + 1.2) ** 2 + (v.co.y - 0.9) ** 2)
    plane.data.update()
    frame, frame_stats = _frames(scene, plane)
    frame()
    frame()
    for _step in range(2):
        moved.co.x += 0.02
        moved.co.z += 0.05
        plane.data.update()
        edited, path = frame()
        assert path == "surface_partial"
        # Runs of two entries (a cage edge cut once): most stay out.
        (mesh,) = runtime.mesh_cache.meshes()
        runs = mesh.region_run_count
        assert 0 < mesh.region_wire_runs < runs if classes else mesh.region_wire_runs == runs
        left_out = frame_stats[-1].get("region_runs_left_out", 0)
        assert left_out > 0.8 * runs if software else left_out == 0
    runtime.mesh_cache.clear()
    fresh, _path_fresh = frame()
    assert np.array_equal(edited, fresh), np.abs(edited - fresh).max()


@pytest.mark.parametrize("software", [True, False])
def test_a_partial_redraw_records_the_triangles_that_can_cover_it(monkeypatch, software):
    """A dense grid whose triangles run row by row, every edge drawn: on a
    software rasteriser a partial redraw records again only the blocks of
    triangles whose boxes reach its rectangle, elsewhere every triangle
    (the scissor drops the rest), and either equals a fresh frame. The
    boxes follow the moves: a small quad listed first (in the first block,
    with the grid's bottom rows) is dragged from the bottom to the top, and
    an edit beside where it went must record that block (a box left where
    the quad was would leave it out)."""
    monkeypatch.setattr(passes.shaders, "software_rasteriser", lambda: software)
    scene = scenes.empty_scene(WIDTH, HEIGHT, thickness=1.5)
    scenes.add_camera(scene, location=(0.0, -10.0, 0.0))
    columns, rows = 60, 40
    quad = [(-0.8, -0.9, 0.1), (-0.7, -0.9, 0.1), (-0.7, -0.8, 0.1), (-0.8, -0.8, 0.1)]
    xs, ys = np.meshgrid(np.linspace(-1.0, 1.0, columns + 1), np.linspace(-1.0, 1.0, rows + 1))
    grid = [(x, y, 0.0) for x, y in zip(xs.ravel(), ys.ravel())]
    first = len(quad)
    faces = [(0, 1, 2, 3)] + [
        (
            first + r * (columns + 1) + c,
            first + r * (columns + 1) + c + 1,
            first + (r + 1) * (columns + 1) + c + 1,
            first + (r + 1) * (columns + 1) + c,
        )
        for r in range(rows)
        for c in range(columns)
    ]
    plane = scenes.from_pydata(scene, "Grid", quad + grid, faces, rotation_euler=(1.5708, 0, 0))
    vertices = plane.data.vertices
    frame, frame_stats = _frames(scene, plane)
    frame()
    frame()
    triangles = frame_stats[-1]["triangles_drawn"]
    for _step in range(4):  # bottom to top, each step an edit of a drag
        for k in range(4):
            vertices[k].co.y += 0.42
        plane.data.update()
        edited, path = frame()
        assert path == "surface_partial"
    beside = min(vertices[first:], key=lambda v: (v.co.x + 0.6) ** 2 + (v.co.y - 0.85) ** 2)
    beside.co.z += 0.05
    plane.data.update()
    edited, path = frame()
    assert path == "surface_partial"
    left_out = frame_stats[-1].get("record_triangles_left_out", 0)
    assert left_out > 0.5 * triangles if software else left_out == 0
    runtime.mesh_cache.clear()
    fresh, _path_fresh = frame()
    assert np.array_equal(edited, fresh), np.abs(edited - fresh).max()


def test_cage_look_alike_on_every_path():
    """The cage look (multi-face regions: their lines drawn over the record,
    docs/image_model.md §2.6), Suzanne-like dense: resolved straight, resolved
    from the kept record and composited from the kept image, the same image,
    which matches the reference."""
    scene = scenes.empty_scene(WIDTH, HEIGHT, use_cage_edges=True, thickness=1.5)
    scenes.add_camera(scene, location=(3.2, -4.5, 2.4), target=(0, 0, 0))
    cube = scenes.cube(scene, rotation=(0.3, 0.1, 0.6))
    modifier = cube.modifiers.new("Subdivision", "SUBSURF")
    modifier.levels = modifier.render_levels = 3
    images = []
    for expected in ("surface_straight", "record_reused", "surface_reused"):
        rgba, stats = _draw(scene, [cube])
        assert _path(stats) == expected and stats.get("region_line_entries", 0) > 0
        images.append(rgba)
    assert all(np.array_equal(images[0], image) for image in images[1:])
    _assert_matches_reference(scene, images[0][..., 3])


@pytest.mark.parametrize("cage", [True, False])
def test_cage_look_with_classes_takes_each_lines_colour(cage):
    """Edge classes on the cage look's regions in the viewport: the region
    lines carry each pixel's style beside its intensity (one packed depth
    value, shaders/edge_styles.glsl), so every solid sample takes the
    colour of the style the reference picks, drawn straight and from the
    kept image alike. Without the cage look every face is its own region:
    those with a classed edge measure their other edges themselves and the
    region lines are the classed edges alone (edge_select.OWN_EDGES_MEASURED)."""
    from solidwire_addon.core import edge_select

    scene = scenes.empty_scene(
        WIDTH,
        HEIGHT,
        use_cage_edges=cage,
        thickness=1.5,
        use_sharp_edges=True,
        sharp_thickness=3.0,
        sharp_color=(0.0, 1.0, 0.0, 1.0),
    )
    scenes.add_camera(scene, location=(3.2, -4.5, 2.4), target=(0, 0, 0))
    cube = scenes.cube(scene, rotation=(0.3, 0.1, 0.6))
    for edge in cube.data.edges[:4]:
        edge.use_edge_sharp = True
    modifier = cube.modifiers.new("Subdivision", "SUBSURF")
    modifier.levels = modifier.render_levels = 3
    straight, stats = _draw(scene, [cube])
    assert _path(stats) == "surface_straight" and stats.get("region_line_entries", 0) > 0
    (mesh,) = runtime.mesh_cache.meshes()
    own = (mesh.edge_flags_cpu & edge_select.OWN_EDGES_MEASURED) == edge_select.OWN_EDGES_MEASURED
    assert own.any() != cage
    kept, stats = _draw(scene, [cube])
    assert np.array_equal(straight, kept)
    _assert_matches_reference(scene, straight[..., 3])
    plan = overlay_state.plan_overlay(SOLID)
    settings = overlay_state.draw_settings(plan, scene.solidwire.snapshot())
    ref = reference.render_reference(scene, size=(WIDTH, HEIGHT), settings=settings)
    solid = (straight[..., 3] > 0.99) & ~ref.on_silhouette & (ref.intensity > 0.99)
    wrong = np.abs(straight[..., :3] - reference.srgb_encode(ref.wire)).max(axis=-1) > 0.02
    green = solid & (straight[..., 1] > 0.9) & (straight[..., 0] < 0.1)
    assert green.sum() > 30 and (solid & ~green).sum() > 30, (green.sum(), solid.sum())
    assert (wrong & solid).sum() <= 0.005 * solid.sum(), (wrong & solid).sum()


def test_clipping_region_and_hidden_lines_stay_direct(monkeypatch):
    """Passes the record cannot serve (a clipping region, hidden lines)
    keep the direct pass."""
    scene, objects = build_scene(thickness=1.5, use_hidden_lines=True)
    calls = _stages(monkeypatch)
    _draw(scene, objects)
    assert draw.VISIBILITY not in calls and draw.RESOLVE not in calls
    scene.solidwire.use_hidden_lines = False
    calls.clear()
    _draw(scene, objects, ViewportState(clip_planes=((0.0, 0.0, 1.0, 0.5),) * 6))
    assert draw.VISIBILITY not in calls and draw.RESOLVE not in calls


def test_a_refused_stage_falls_back_to_the_direct_pass(monkeypatch, capsys):
    """A backend that refuses the composite draws the direct pass's image,
    with one message, and draws directly from then on."""
    from solidwire_addon.core import log, shaders

    log.forget()  # messages said by earlier tests are said again
    scene, objects = build_scene(thickness=1.5, diagonal_mode="SOLID")
    monkeypatch.setattr(runtime, "options", DrawOptions(deferred_surface=False))
    expected, _stats = _draw(scene, objects)
    monkeypatch.setattr(runtime, "options", DrawOptions(deferred_surface=True))
    monkeypatch.setattr(shaders, "_deferred_support", [True])

    def refuse(*_args):
        raise shaders.DeferredUnavailable("composite refused")

    monkeypatch.setattr(shaders, "get_overlay_composite", refuse)
    calls = _stages(monkeypatch)
    got, _stats = _draw(scene, objects)
    assert not shaders.deferred_available()
    assert draw.VISIBILITY not in calls and draw.RESOLVE not in calls
    assert np.array_equal(got, expected)
    assert "deferred surface pass is not available" in capsys.readouterr().err


def test_a_refused_straight_resolve_draws_directly(monkeypatch, capsys):
    """A backend that refuses the resolve straight into Blender's buffer
    draws those meshes directly instead (the direct pass's image), with one
    message, and draws directly from then on."""
    from solidwire_addon.core import log, shaders

    log.forget()
    scene, objects = build_scene(thickness=1.5, diagonal_mode="SOLID")
    monkeypatch.setattr(runtime, "options", DrawOptions(deferred_surface=False))
    expected, _stats = _draw(scene, objects)
    monkeypatch.setattr(runtime, "options", DrawOptions(deferred_surface=True))
    monkeypatch.setattr(shaders, "_deferred_support", [True])
    refuse_variants(monkeypatch, lambda variant: variant.record_depth, "straight resolve refused")
    got, stats = _draw(scene, objects)
    assert stats["objects_drawn"] == 2
    assert not shaders.deferred_available()
    assert np.abs(got - expected).max() <= 1.0 / 255.0 + 1e-9
    assert "deferred surface pass is not available" in capsys.readouterr().err
    calls = _stages(monkeypatch)
    _draw(scene, objects)
    assert draw.VISIBILITY not in calls and draw.RESOLVE not in calls
