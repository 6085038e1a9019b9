"""The viewport overlay in every shading mode and viewport state, headless.

Each state of the table in docs/user/overlay.md ("Viewport states") is turned
into the plain inputs the draw handler reads (``core/overlay_state.py``:
``ViewportState`` / ``ObjectState``), planned by the same pure function the
handler calls, and drawn by ``blender/overlay.py::draw_scene_overlay`` (and so
``core/passes.py::draw_over_viewport``) into the offscreen sRGB target of
tests/test_overlay.py, with or without a Blender-like scene depth. The image
is checked against the float64 reference (tests/support/reference.py) or
against the rule that table states for that state.
"""

from __future__ import annotations

from types import SimpleNamespace

import bpy
import numpy as np
import pytest

from solidwire_addon.blender import overlay
from solidwire_addon.blender.gpu_context import ensure_gpu
from solidwire_addon.blender.views import camera_view
from solidwire_addon.core import overlay_state
from solidwire_addon.core.overlay_state import MATERIAL, RENDERED, WIREFRAME, ViewportState
from tests.support import accuracy, reference, scenes
from tests.test_overlay import HEIGHT, WIDTH, FakeViewport, build_scene

pytestmark = pytest.mark.filterwarnings("ignore:'DEPTH24_STENCIL8' is deprecated:DeprecationWarning")


@pytest.fixture(autouse=True)
def gpu_ready():
    ensure_gpu()


def draw_state(scene, state: ViewportState, depth_objects=(), size=(WIDTH, HEIGHT)):
    """The overlay's alpha (= wire alpha * I) for ``state`` over a scene depth
    of ``depth_objects`` (none: empty depth, as Blender leaves it where it
    draws no surface), and the frame stats."""
    depsgraph = bpy.context.evaluated_depsgraph_get()
    view = camera_view(scene, depsgraph, size)
    plan = overlay_state.plan_overlay(state)
    assert plan is not None
    viewport = FakeViewport(*size)
    if depth_objects:
        viewport.depth_pass(depsgraph, view, list(depth_objects))
    stats = viewport.draw_overlay(
        depsgraph,
        view,
        scene.solidwire.snapshot(),
        plan=plan,
        object_filter=overlay.object_filter(plan, bpy.context.view_layer),
    )
    return viewport.rgba()[..., 3], stats


def assert_matches_reference(scene, alpha, state: ViewportState, size=(WIDTH, HEIGHT)):
    plan = overlay_state.plan_overlay(state)
    settings = overlay_state.draw_settings(plan, scene.solidwire.snapshot())
    ref = reference.render_reference(scene, size=size, settings=settings)
    report = reference.error_report(alpha, ref)
    accuracy.assert_accurate(report)
    assert ref.intensity.max() > 0.9, "the scene draws visible wires"


# -- what the handler reads ------------------------------------------------------


def test_handler_reads_each_region_state():
    """What the handler reads from a context: the shading's own X-ray fields
    (Wireframe has its own), each region's clipping (quad view: per region),
    the UI scale and the scene's overlay settings."""
    scene = scenes.empty_scene(show_overlay=True, only_selected=True)
    planes = [(1.0, 0.0, 0.0, 0.0)] + [(0.0, 0.0, 0.0, 0.0)] * 5
    shading = SimpleNamespace(
        type="WIREFRAME", show_xray=False, xray_alpha=1.0, show_xray_wireframe=True, xray_alpha_wireframe=0.3
    )
    space = SimpleNamespace(shading=shading, overlay=SimpleNamespace(show_overlays=True))
    preferences = SimpleNamespace(system=SimpleNamespace(pixel_size=2.0))

    def context(region_3d):
        return SimpleNamespace(
            scene=scene,
            space_data=space,
            region=object(),
            region_data=region_3d,
            screen=None,
            area=None,
            preferences=preferences,
        )

    clipped = overlay.viewport_state(context(SimpleNamespace(use_clip_planes=True, clip_planes=planes)))
    free = overlay.viewport_state(context(SimpleNamespace(use_clip_planes=False, clip_planes=planes)))
    assert clipped.shading == WIREFRAME and clipped.xray and clipped.xray_alpha == pytest.approx(0.3)
    assert clipped.pixel_size == 2.0 and clipped.only_selected and clipped.show
    assert np.array_equal(overlay_state.plan_overlay(clipped).clip_planes, np.array(planes))
    assert free.clip_planes is None
    assert overlay.viewport_state(context(None)) is None  # not a 3D region


# -- images per state ----------------------------------------------------------------

SHADING_STATES = {
    "solid": (ViewportState(), True),
    "solid_xray_alpha_1": (ViewportState(xray=True, xray_alpha=1.0), True),
    "solid_xray_half": (ViewportState(xray=True, xray_alpha=0.5), True),
    "solid_xray_zero": (ViewportState(xray=True, xray_alpha=0.0), False),
    "wireframe_xray": (ViewportState(shading=WIREFRAME, xray=True, xray_alpha=0.5), False),
    "wireframe_opaque": (ViewportState(shading=WIREFRAME), True),
    "material_preview": (ViewportState(shading=MATERIAL), True),
    "rendered_eevee": (ViewportState(shading=RENDERED), True),  # EEVEE writes the viewport depth
    "rendered_cycles_no_depth": (ViewportState(shading=RENDERED), False),  # depth absent
}


@pytest.mark.parametrize("name", list(SHADING_STATES))
def test_shading_mode_matches_reference(name):
    """Every shading mode, with Blender's depth present or absent: the
    overlay shows the wire of the nearest surface, as the reference does."""
    state, with_depth = SHADING_STATES[name]
    scene, objects = build_scene(thickness=1.5, diagonal_mode="SOLID")
    alpha, stats = draw_state(scene, state, objects if with_depth else ())
    assert stats["objects_drawn"] == 2
    assert_matches_reference(scene, alpha, state)


@pytest.mark.parametrize("name", list(SHADING_STATES))
def test_a_redraw_that_changes_nothing_composites_the_frame_before(name):
    """A frame drawn directly (here: the meshes are too sparse to defer; in
    X-ray and Wireframe shading every mesh) is kept once a redraw repeats
    the key of the one before, and from then on composited: every redraw
    of every shading mode matches the reference, as the first does, and a
    redraw from the kept image equals the one drawn directly."""
    from solidwire_addon.core import targets

    state, with_depth = SHADING_STATES[name]
    scene, objects = build_scene(thickness=1.5, diagonal_mode="SOLID")
    targets.release()
    depth = objects if with_depth else ()
    direct, stats = draw_state(scene, state, depth)
    assert not stats.get("frame_reused")
    draw_state(scene, state, depth)  # (drawn into the kept image)
    again, stats = draw_state(scene, state, depth)
    assert stats.get("frame_reused") == 1 and stats["objects_drawn"] == 2
    assert np.array_equal(again, direct)
    assert_matches_reference(scene, again, state)


def _occluder_scene():
    """A grid behind a cube that only Blender draws (opted out of SolidWire)."""
    scene = scenes.empty_scene(WIDTH, HEIGHT, thickness=2.0, diagonal_mode="SOLID")
    scenes.add_camera(scene, location=(0.0, -10.0, 0.0))
    grid = scenes.grid(scene, "Grid", x_segments=8, y_segments=8, size=1.5, rotation=(1.5708, 0, 0))
    occluder = scenes.cube(scene, "Occluder", size=3.0, location=(0.0, -3.0, 0.0))
    occluder.solidwire_exclude = True
    return scene, grid, occluder


@pytest.mark.parametrize(
    "state",
    [
        ViewportState(xray=True, xray_alpha=0.5),
        ViewportState(xray=True, xray_alpha=0.0),
        ViewportState(shading=WIREFRAME, xray=True, xray_alpha=0.5),
    ],
    ids=["solid_xray_half", "solid_xray_zero", "wireframe_xray"],
)
def test_xray_sees_through_blender_depth(state):
    """Rule: with X-ray active Blender's depth hides nothing; the image is the
    one over an empty depth. Without X-ray the same depth hides the grid."""
    scene, grid, occluder = _occluder_scene()
    opaque, _ = draw_state(scene, ViewportState(), (grid, occluder))
    assert opaque.max() == 0.0
    seen, _ = draw_state(scene, state, (grid, occluder))
    bare, _ = draw_state(scene, ViewportState(), ())
    assert bare.max() > 0.9
    assert np.abs(seen - bare).max() <= 1.0 / 255.0


def test_clipping_region_cuts_the_overlay():
    """Alt+B: nothing is drawn outside the planes; inside, the image is the
    unclipped one (a face-on grid, the plane x = 0.2 keeps x >= 0.2)."""
    scene = scenes.empty_scene(WIDTH, HEIGHT, thickness=2.0, diagonal_mode="SOLID")
    scenes.add_camera(scene, location=(0.0, -10.0, 0.0))
    grid = scenes.grid(scene, "Grid", x_segments=8, y_segments=8, size=3.0, rotation=(1.5708, 0, 0))
    planes = [(1.0, 0.0, 0.0, -0.2)] + [(0.0, 0.0, 0.0, 0.0)] * 5
    free, _ = draw_state(scene, ViewportState(), (grid,))
    clipped, _ = draw_state(scene, ViewportState(clip_planes=planes), (grid,))
    # Window column of world x = 0.2 on the grid plane (y = 0).
    depsgraph = bpy.context.evaluated_depsgraph_get()
    view = camera_view(scene, depsgraph, (WIDTH, HEIGHT))
    clip = view.projection @ view.view_matrix @ np.array([0.2, 0.0, 0.0, 1.0])
    column = (clip[0] / clip[3] * 0.5 + 0.5) * WIDTH
    cols = np.arange(WIDTH) + 0.5
    outside, inside = cols < column - 0.5, cols > column + 0.5
    assert free[:, outside].max() > 0.9, "the wire is there without clipping"
    assert clipped[:, outside].max() == 0.0
    assert np.abs(clipped[:, inside] - free[:, inside]).max() <= 1.0 / 255.0


def test_clipping_box_on_a_solid_scene(output_dir):
    """A clipping box (4 side planes, as Alt+B makes) around the middle of the
    view over the cube-and-sphere scene: outside it nothing, inside exactly
    the unclipped image wherever the visible surface is not cut."""
    scene, objects = build_scene(thickness=1.5, diagonal_mode="SOLID")
    depsgraph = bpy.context.evaluated_depsgraph_get()
    view = camera_view(scene, depsgraph, (WIDTH, HEIGHT))
    # Planes through the camera and the window rectangle [60, 140] x [40, 110],
    # built in clip space and taken back to world space.
    world_to_clip = view.projection @ view.view_matrix
    x0, x1 = 60 / WIDTH * 2 - 1, 140 / WIDTH * 2 - 1
    y0, y1 = 40 / HEIGHT * 2 - 1, 110 / HEIGHT * 2 - 1
    clip_planes = np.array([[1, 0, 0, -x0], [-1, 0, 0, x1], [0, 1, 0, -y0], [0, -1, 0, y1]], dtype=np.float64)
    rows = np.array([[p[0], p[1], 0.0, p[3]] for p in clip_planes])
    world_planes = rows @ world_to_clip
    planes = [tuple(p) for p in world_planes] + [(0.0, 0.0, 0.0, 0.0)] * 2
    free, _ = draw_state(scene, ViewportState(), objects)
    clipped, _ = draw_state(scene, ViewportState(clip_planes=planes), objects)
    ii, jj = np.meshgrid(np.arange(WIDTH) + 0.5, np.arange(HEIGHT) + 0.5)
    inside = (ii > 61) & (ii < 139) & (jj > 41) & (jj < 109)
    outside = (ii < 59) | (ii > 141) | (jj < 39) | (jj > 111)
    assert free[outside].max() > 0.9 and free[inside].max() > 0.9
    # For eyes: the wire in red, the region outside the box in blue.
    accuracy.save_error_image(output_dir / "overlay_clipping_box.png", clipped / 10.0, outside)
    assert clipped[outside].max() == 0.0
    assert np.abs(clipped[inside] - free[inside]).max() <= 1.0 / 255.0


def test_clip_start_cuts_through_an_object():
    """The viewport's clip start inside the cube: the near plane opens it and
    the overlay shows what the reference shows (the inside faces' wire)."""
    scene = scenes.empty_scene(WIDTH, HEIGHT, thickness=1.5, diagonal_mode="SOLID")
    scenes.add_camera(scene, location=(4.0, -3.0, 2.5), clip=(5.2, 40.0))
    cube = scenes.cube(scene, "Cube", size=2.0)
    scenes.uv_sphere(scene, "Back", radius=1.2, location=(-1.6, 1.8, -0.3))
    sphere = bpy.data.objects["Back"]
    alpha, _ = draw_state(scene, ViewportState(), (cube, sphere))
    assert_matches_reference(scene, alpha, ViewportState())


def test_hidpi_lines_are_ui_scaled():
    """pixel_size 2: every pixel length doubles (the reference at doubled
    thickness, softness and pattern lengths), so the wire covers about twice
    the pixels."""
    scene, objects = build_scene(thickness=1.5, diagonal_mode="DOTTED")
    hidpi = ViewportState(pixel_size=2.0)
    alpha, _ = draw_state(scene, hidpi, objects)
    assert_matches_reference(scene, alpha, hidpi)
    alpha_1x, _ = draw_state(scene, ViewportState(), objects)
    assert 1.4 < alpha.sum() / alpha_1x.sum() < 2.4


def _two_objects_one_in_mode(mode: str):
    scene, objects = build_scene(thickness=1.5, diagonal_mode="SOLID")
    front, _back = objects
    for obj in bpy.context.view_layer.objects:
        obj.select_set(obj == front)
    bpy.context.view_layer.objects.active = front
    bpy.ops.object.mode_set(mode=mode)
    return scene, objects


def test_edit_mode_objects_left_to_blender_by_default():
    scene, _objects = _two_objects_one_in_mode("EDIT")
    try:
        # (Blender-like depth is left out: the test's depth pass reads
        # Object Mode mesh data. A shading that leaves no depth, as Cycles'
        # Rendered view does, makes the own depth pre-pass stand in for it.)
        no_depth = ViewportState(shading=RENDERED)
        _alpha, stats = draw_state(scene, no_depth)
        assert stats["objects_drawn"] == 1, "the edited cube is left to Blender's edit wire"
        alpha, stats = draw_state(scene, ViewportState(shading=RENDERED, draw_edit_mode=True))
        assert stats["objects_drawn"] == 2
    finally:
        bpy.ops.object.mode_set(mode="OBJECT")
    # Drawn on request, the edited object looks as in Object Mode.
    assert_matches_reference(scene, alpha, ViewportState())


@pytest.mark.parametrize("mode", ["SCULPT", "WEIGHT_PAINT", "VERTEX_PAINT"])
def test_paint_and_sculpt_modes_draw_everything(mode):
    scene, objects = _two_objects_one_in_mode(mode)
    try:
        alpha, stats = draw_state(scene, ViewportState(), objects)
    finally:
        bpy.ops.object.mode_set(mode="OBJECT")
    assert stats["objects_drawn"] == 2
    assert_matches_reference(scene, alpha, ViewportState())


def test_hidden_and_excluded_collections_are_not_drawn():
    scene, objects = build_scene(thickness=1.5, diagonal_mode="SOLID")
    front, back = objects
    hidden = bpy.data.collections.new("Hidden")
    excluded = bpy.data.collections.new("Excluded")
    for collection in (hidden, excluded):
        scene.collection.children.link(collection)
    extra_hidden = scenes.cube(scene, "InHidden", size=1.0, location=(0.0, -2.0, 1.5))
    extra_excluded = scenes.cube(scene, "InExcluded", size=1.0, location=(1.5, -2.0, 1.5))
    for obj, collection in ((extra_hidden, hidden), (extra_excluded, excluded)):
        scene.collection.objects.unlink(obj)
        collection.objects.link(obj)
    layers = bpy.context.view_layer.layer_collection.children
    layers["Hidden"].hide_viewport = True
    layers["Excluded"].exclude = True
    back.hide_set(True)
    alpha, stats = draw_state(scene, ViewportState(), (front,))
    assert stats["objects_drawn"] == 1
    back.hide_set(False)
    # The image is the front cube's alone: the reference of a scene without the others.
    for obj in (back, extra_hidden, extra_excluded):
        bpy.data.objects.remove(obj)
    assert_matches_reference(scene, alpha, ViewportState())


def test_handler_reads_this_viewports_own_switch():
    """The handler asks the 3D View being drawn, not the scene: a viewport
    switched on draws while the scene default is off, and the other 3D View
    of the same screen does not."""
    scene = scenes.empty_scene(show_overlay=False)
    screen = bpy.data.screens["Animation"]
    first, second = [area for area in screen.areas if area.type == "VIEW_3D"][:2]
    overlay.set_viewport_shows(screen, first, True)
    region_3d = SimpleNamespace(use_clip_planes=False)

    def state(area):
        context = SimpleNamespace(
            scene=scene,
            space_data=None,
            region=object(),
            region_data=region_3d,
            screen=screen,
            area=area,
            preferences=bpy.context.preferences,
        )
        return overlay_state.plan_overlay(overlay.viewport_state(context))

    assert state(first) is not None
    assert state(second) is None


def test_nothing_to_draw_leaves_the_viewport_untouched():
    """A frame with no object to draw (here every object opted out) changes
    neither colour nor depth, not even in X-ray, where a frame that draws
    clears the depth to use only its own surfaces."""
    scene, objects = build_scene(thickness=1.5)
    for obj in objects:
        obj.solidwire.show_in_viewport = False
    depsgraph = bpy.context.evaluated_depsgraph_get()
    view = camera_view(scene, depsgraph, (WIDTH, HEIGHT))
    viewport = FakeViewport(WIDTH, HEIGHT)
    viewport.depth_pass(depsgraph, view, objects)

    def depth():
        values = np.array(viewport.depth.read().to_list(), dtype=np.float64)
        if values.max() > 1.0:  # Blender 4.2 reads depth-stencil packed: 24-bit depth, 8-bit stencil
            values = np.floor(values / 256.0) / (2**24 - 1)
        return values

    before_depth, before_rgba = depth(), viewport.rgba()
    assert (before_depth < 1.0).any()
    plan = overlay_state.plan_overlay(ViewportState(xray=True, xray_alpha=0.5))
    assert not plan.scene_depth
    stats = viewport.draw_overlay(
        depsgraph,
        view,
        scene.solidwire.snapshot(),
        plan=plan,
        object_filter=overlay.object_filter(plan, bpy.context.view_layer),
    )
    assert stats["objects_drawn"] == 0
    assert np.array_equal(depth(), before_depth)
    assert np.array_equal(viewport.rgba(), before_rgba)


def test_an_object_blender_draws_as_wire_keeps_the_own_depth_pre_pass():
    """In Solid shading Blender's depth holds every surface it draws solid,
    so the overlay skips its own depth pre-pass; an object displayed as Wire
    leaves no surface in that depth, and its back edges must still stay
    hidden behind its front faces."""
    scene, objects = build_scene(thickness=1.5, diagonal_mode="SOLID")
    wire, solid = objects
    wire.display_type = "WIRE"
    alpha, stats = draw_state(scene, ViewportState(), (solid,))
    assert stats["objects_drawn"] == 2
    assert_matches_reference(scene, alpha, ViewportState())
