"""Blender's real viewport, drawn headless, with SolidWire's overlay in it.

``GPUOffScreen.draw_view3d`` draws a startup screen's 3D View (Solid
shading, Blender's overlays, the scene's colour management) into an
offscreen; SolidWire's overlay is drawn into the same offscreen afterwards,
over Blender's colour and depth, as the POST_VIEW handler draws it
(tests/support/viewport.py). Unlike tests/test_overlay.py, whose depth is a
stand-in depth pass, the depth here is Blender's own.
"""

from __future__ import annotations

import bpy
import numpy as np
import pytest

from solidwire_addon.blender import color_management
from solidwire_addon.blender.views import camera_view
from solidwire_addon.core import display_transform
from tests.support import scenes
from tests.support.viewport import HeadlessViewport, ViewportUnavailable, set_overlays
from tests.test_overlay import FakeViewport, srgb_to_linear

WIDTH, HEIGHT = 240, 180
OBJECT_COLOR = (0.8, 0.05, 0.05)  # Blender's flat single colour: far from the grey background and the grid
WIRE = (0.05, 0.9, 0.1, 1.0)


@pytest.fixture
def viewport():
    """A headless 3D View of WIDTH x HEIGHT, one anti-aliasing sample (every
    draw a complete, deterministic image). Skips where Blender cannot draw
    its viewport headless."""
    preferences = bpy.context.preferences.system
    saved_aa = preferences.viewport_aa
    made = []

    def make(scene):
        # Set here, after the test's scene is made: reading the factory
        # settings resets the preferences too.
        preferences.viewport_aa = "OFF"
        try:
            result = HeadlessViewport(WIDTH, HEIGHT)
            made.append(result)
            result.look_through(scene)
            result.draw_blender()
        except ViewportUnavailable as exc:
            pytest.skip(f"Blender's viewport cannot be drawn headless here: {exc}")
        return result

    yield make
    for result in made:
        result.free()
    preferences.viewport_aa = saved_aa


def flat_solid_shading(space, color=OBJECT_COLOR) -> None:
    """Solid shading with one flat colour: every pixel of an object is
    exactly ``color`` after colour management."""
    shading = space.shading
    shading.type = "SOLID"
    shading.light = "FLAT"
    shading.color_type = "SINGLE"
    shading.single_color = color
    shading.show_xray = False
    shading.show_shadows = False
    shading.show_cavity = False
    shading.show_object_outline = False
    shading.show_specular_highlight = False


def two_objects(**solidwire):
    scene = scenes.empty_scene(WIDTH, HEIGHT, wire_color=WIRE, thickness=1.5, **solidwire)
    scenes.add_camera(scene, location=(6.0, -5.0, 4.0))
    front = scenes.cube(scene, "Front", size=1.6)
    back = scenes.uv_sphere(scene, "Back", radius=1.2, location=(-1.6, 1.8, -0.3))
    for obj in (front, back):
        obj.select_set(False)
    return scene, [front, back]


def covered(view, objects) -> np.ndarray:
    """Pixels where Blender draws ``objects``: the image with them differs
    from the image with them hidden."""
    with_objects = view.rgba()
    for obj in objects:
        obj.hide_set(True)
    view.draw_blender()
    without = view.rgba()
    for obj in objects:
        obj.hide_set(False)
    view.draw_blender()
    return (with_objects != without).any(axis=-1)


def grow(mask: np.ndarray, radius: int = 1) -> np.ndarray:
    out = mask.copy()
    for _ in range(radius):
        grown = out.copy()
        grown[1:] |= out[:-1]
        grown[:-1] |= out[1:]
        grown[:, 1:] |= out[:, :-1]
        grown[:, :-1] |= out[:, 1:]
        out = grown
    return out


def test_solidwire_lines_land_on_the_mesh_blender_draws(viewport):
    """In one image with Blender's overlays (grid, axes): every pixel that
    SolidWire's overlay changes lies on an object Blender drew, and its lines
    sit where Blender's own wireframe overlay draws the same edges."""
    scene, objects = two_objects(diagonal_mode="SOLID")
    view = viewport(scene)
    flat_solid_shading(view.space)
    set_overlays(view.space, wireframe=False)
    view.draw_blender()
    blender = view.rgba()
    on_object = covered(view, objects)
    assert on_object.sum() > 0.1 * WIDTH * HEIGHT, "Blender draws the objects"
    assert (~on_object).sum() > 0.3 * WIDTH * HEIGHT, "and the background around them"

    stats = view.draw_solidwire()
    combined = view.rgba()
    assert stats["objects_drawn"] == 2
    changed = (combined != blender).any(axis=-1)
    assert changed.sum() > 500, "SolidWire's lines are in the image"
    # Same rasterised triangles, same view: coverage agrees to the pixel.
    # (Allowed: a few pixels on a silhouette, where the two depth
    # computations may pick different sides of the same edge.)
    outside = changed & ~on_object
    assert (changed & ~grow(on_object)).sum() == 0
    assert outside.sum() <= 0.002 * changed.sum(), f"{outside.sum()} of {changed.sum()} changed pixels off the objects"
    # Outside the objects, Blender's overlays (grid lines, axes) are untouched.
    assert np.array_equal(combined[~grow(on_object)], blender[~grow(on_object)])

    # Blender's wireframe overlay (every edge) against SolidWire's wire: the
    # pixels Blender's wireframe adds lie on or next to SolidWire's lines.
    set_overlays(view.space, wireframe=True)
    view.draw_blender()
    blender_wire = (view.rgba() != blender).any(axis=-1) & on_object
    assert blender_wire.sum() > 200
    near = blender_wire & grow(changed, 1)
    assert near.sum() >= 0.95 * blender_wire.sum(), f"{near.sum()} of {blender_wire.sum()} wireframe pixels near"


def test_hidden_lines_stay_behind_another_blender_object(viewport):
    """An object that only Blender draws (SolidWire is off for it) hides the
    SolidWire lines of the grid behind it, through Blender's own depth; with
    that object hidden the same pixels show the lines."""
    scene = scenes.empty_scene(WIDTH, HEIGHT, wire_color=WIRE, thickness=2.0, diagonal_mode="SOLID")
    scenes.add_camera(scene, location=(0.0, -10.0, 0.0))
    grid = scenes.grid(scene, "Hidden", x_segments=8, y_segments=8, size=1.5, rotation=(1.5708, 0, 0))
    occluder = scenes.cube(scene, "Occluder", size=1.6, location=(0.4, -3.0, 0.0))
    occluder.solidwire.show_in_viewport = False
    for obj in (grid, occluder):
        obj.select_set(False)
    view = viewport(scene)
    flat_solid_shading(view.space)
    # Each object its own colour: hiding one then changes every pixel it covers.
    view.space.shading.color_type = "OBJECT"
    grid.color = (*OBJECT_COLOR, 1.0)
    occluder.color = (0.1, 0.1, 0.8, 1.0)
    set_overlays(view.space)
    view.draw_blender()
    occluder_pixels = covered(view, [occluder])
    occluder.hide_set(True)
    grid_pixels = covered(view, [grid])  # the grid's whole footprint
    occluder.hide_set(False)
    blocked = occluder_pixels & grid_pixels
    assert blocked.sum() > 500, "the occluder stands in front of part of the grid"
    inner = blocked & ~grow(~blocked, 2)  # away from the occluder's outline

    def solidwire_changes():
        view.draw_blender()
        before = view.rgba()
        stats = view.draw_solidwire()
        return (view.rgba() != before).any(axis=-1), stats

    changed, stats = solidwire_changes()
    assert stats["objects_drawn"] == 1  # the grid; the occluder is opted out
    assert changed[grid_pixels & ~occluder_pixels].sum() > 100, "the grid's visible lines are drawn"
    assert changed[inner].sum() == 0, "no line shows through the occluder"

    occluder.hide_set(True)
    changed_bare, _stats = solidwire_changes()
    assert changed_bare[inner].sum() > 50, "control: without the occluder the lines are there"


def wire_over_flat_solid(viewport, scene) -> tuple[np.ndarray, np.ndarray]:
    """(the float64 reference's intensity, where SolidWire's green wire
    shows over Blender's flat red Solid shading) of ``scene`` in the
    headless viewport, Blender's overlays off."""
    from tests.support import reference

    strong = reference.render_reference(scene).intensity
    view = viewport(scene)
    flat_solid_shading(view.space)
    set_overlays(view.space, overlays=False)
    view.draw_blender()
    view.draw_solidwire()
    rgba = view.rgba().astype(np.float64) / 255.0
    return strong, rgba[..., 1] - rgba[..., 0] > 0.3


@pytest.mark.parametrize("hidden_lines", [False, True], ids=["wire", "hidden_lines"])
@pytest.mark.parametrize("subdivisions", [0, 2], ids=["drawn_directly", "deferred"])
@pytest.mark.parametrize("offset, most_hidden", [(2000.0, 0.001), (1e5, 0.05)], ids=["2_km", "100_km"])
def test_wire_far_from_the_origin_stays_in_front_of_blenders_depth(
    viewport, subdivisions, hidden_lines, offset, most_hidden
):
    """Suzanne far from the world origin: Blender's Solid shading projects
    her through float32 matrices, so its depth of her slanted faces strays
    by far more than the overlay's constant bias, and 4 % (2,000 units
    away) to 20 % (100,000) of the wire's full-intensity pixels (those of
    the float64 reference) used to fail Blender's depth test. The overlay
    moves its surface towards the camera by that rounding too
    (view.blender_depth_allowance): 2,000 units away the wire is whole
    again, directly drawn or deferred. 100,000 units away the allowance's
    cap (0.4 % of the distance from the camera) leaves a few per cent, and
    keeps her far side, which only Blender's depth hides where Suzanne is
    drawn directly, from showing its wire through her: nowhere does a line
    show where the reference has none."""
    scene = scenes.empty_scene(WIDTH, HEIGHT, wire_color=WIRE, use_hidden_lines=hidden_lines)
    monkey = scenes.monkey(scene, location=(offset, offset, 0.0), subdivisions=subdivisions)
    scenes.add_camera(scene, location=(offset + 3.0, offset - 3.0, 1.5), target=(offset, offset, 0.0))
    monkey.select_set(False)
    strong, green = wire_over_flat_solid(viewport, scene)
    full = strong > 0.9
    assert full.sum() > 5000
    missing = int((full & ~green).sum())
    assert missing <= most_hidden * full.sum(), f"{missing} of {full.sum()} full-intensity wire pixels hidden"
    assert int((green & (strong < 0.02)).sum()) <= 2, "no line where the reference has none"


@pytest.mark.parametrize("subdivisions", [0, 3], ids=["drawn_directly", "deferred"])
def test_wire_of_a_ground_reaching_far_behind_the_camera(viewport, subdivisions):
    """A ground 400 units long seen from 5 cm above it, near clip 1 cm (as
    walking over a terrain in the viewport). Its positions used to be
    re-centred on the middle of its bounds, 200 units away: the corners
    near the camera rounded by the spacing of that size, and the surface
    the overlay drew strayed from Blender's depth of the same corners by
    more than its bias wherever the near plane cuts the quads steeply, so
    the wire vanished there. Positions now keep Blender's float32 values
    (extract._centre_of): the wire shows wherever the reference has it."""
    scene = scenes.empty_scene(WIDTH, HEIGHT, wire_color=WIRE, thickness=1.5, diagonal_mode="SOLID")
    corners = [(-1.0123457, -400.0, 0.0137), (0.9876543, -404.0, 0.00731), (1.1234567, 2.3456789, -0.0123)]
    ground = scenes.from_pydata(scene, "Ground", [*corners, (-0.9345678, 2.1234567, 0.00987)], [(0, 1, 2, 3)])
    if subdivisions:
        modifier = ground.modifiers.new("Subdivision", "SUBSURF")
        modifier.subdivision_type, modifier.levels = "SIMPLE", subdivisions
    scenes.add_camera(scene, location=(0.0, 0.0, 0.05), target=(0.2, 2.0, 0.0), lens=24.0, clip=(0.01, 100.0))
    ground.select_set(False)
    strong, green = wire_over_flat_solid(viewport, scene)
    full = strong > 0.9
    assert full.sum() > 200
    missing = int((full & ~green).sum())
    assert missing == 0, f"{missing} of {full.sum()} full-intensity wire pixels hidden"
    assert int((green & (strong < 0.02)).sum()) <= 2, "no line where the reference has none"


def flat_colours(view_transform: str):
    """(Blender's Solid colour, SolidWire's fill colour as the screen shows
    it, the scene's display transform of the colour), each (N, 3) in 0..1
    over the inner pixels of a cube, for one flat scene-linear colour."""
    scene = scenes.empty_scene(
        WIDTH, HEIGHT, use_fill=True, fill_shading="FLAT", fill_color=FLAT_COLOR, wire_color=(0.0, 0.0, 0.0, 0.0)
    )
    scene.view_settings.view_transform = view_transform
    scenes.add_camera(scene, location=(6.0, -5.0, 4.0))
    cube = scenes.cube(scene, "Cube", size=2.4)
    cube.select_set(False)
    return scene, cube


def inner_pixels(view, objects) -> np.ndarray:
    on_object = covered(view, objects)
    return on_object & ~grow(~on_object, 2)


def solidwire_on_screen(scene, inner, **draw) -> np.ndarray:
    """SolidWire's overlay buffer (SRGB8_A8) as the viewport merges it: read
    back to linear, then the 2.2 power of the overlay merge."""
    depsgraph = bpy.context.evaluated_depsgraph_get()
    fake = FakeViewport(WIDTH, HEIGHT)
    fake.draw_overlay(depsgraph, camera_view(scene, depsgraph, (WIDTH, HEIGHT)), scene.solidwire.snapshot(), **draw)
    stored = fake.rgba()
    assert (stored[inner][:, 3] > 0.999).all(), "SolidWire's fill covers the pixels Blender's object covers"
    return srgb_to_linear(stored[inner][:, :3]) ** (1.0 / display_transform.OVERLAY_MERGE_GAMMA)


FLAT_COLOR = (0.05, 0.3, 0.6)


def blender_flat(view, cube) -> tuple[np.ndarray, np.ndarray]:
    flat_solid_shading(view.space, FLAT_COLOR)
    set_overlays(view.space, overlays=False)
    view.draw_blender()
    inner = inner_pixels(view, [cube])
    assert inner.sum() > 1000
    blender = view.rgba()[inner][:, :3] / 255.0
    # One flat colour (a few pixels a level or two off, as Blender's viewport draws them).
    mode = np.median(blender, axis=0)
    assert (np.abs(blender - mode).max(axis=1) <= 0.5 / 255.0).mean() >= 0.95
    return inner, blender


def test_flat_fill_matches_blender_flat_solid_colour(viewport):
    """With the Standard view transform, Blender's Solid shading of one flat
    colour and SolidWire's flat fill of the same scene-linear colour, each as
    the screen shows it: equal within 3/255 at every pixel."""
    scene, cube = flat_colours("Standard")
    view = viewport(scene)
    inner, blender = blender_flat(view, cube)
    screen = solidwire_on_screen(scene, inner)
    error = np.abs(screen - blender)
    assert error.max() <= 3.0 / 255.0, f"max difference {error.max() * 255:.2f}/255"
    assert np.median(error) <= 1.0 / 255.0


def test_solid_shading_keeps_standard_while_solidwire_follows_the_scene(viewport):
    """Under AgX Blender's Solid shading still draws the Standard colour (the
    viewport applies the scene's view transform only from Material Preview
    on), while SolidWire's overlay shows the F12 render's AgX colour
    (docs/image_model.md section 9: viewport = render). The two then differ
    by design; this pins both facts."""
    scene, cube = flat_colours("AgX")
    view = viewport(scene)
    inner, blender = blender_flat(view, cube)
    standard = _srgb_encode(np.array(FLAT_COLOR))
    assert np.abs(np.median(blender, axis=0) - standard).max() <= 1.5 / 255.0
    rendered = color_management.transform_colors(scene, [FLAT_COLOR])[0]
    screen = solidwire_on_screen(scene, inner)
    assert np.abs(screen - rendered).max() <= 3.0 / 255.0
    assert np.abs(np.median(screen, axis=0) - np.median(blender, axis=0)).max() > 10.0 / 255.0
    # Control: without its display transform SolidWire would show neither.
    untransformed = solidwire_on_screen(scene, inner, display=None)
    assert np.abs(untransformed - rendered).max() > 10.0 / 255.0


def _srgb_encode(linear: np.ndarray) -> np.ndarray:
    return np.where(linear <= 0.0031308, 12.92 * linear, 1.055 * np.power(linear, 1.0 / 2.4) - 0.055)
