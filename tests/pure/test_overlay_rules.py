"""The overlay's rules per viewport state, without Blender: the pure
function the draw handler calls (core/overlay_state.py) on plain inputs,
for the table in docs/user/overlay.md ("Viewport states").
(tests/test_overlay_states.py draws each state and checks the images.)"""

from __future__ import annotations

import math

import numpy as np
import pytest

from solidwire_addon.core import overlay_state
from solidwire_addon.core.overlay_state import MATERIAL, RENDERED, WIREFRAME, ObjectState, ViewportState
from solidwire_addon.core.settings import DrawSettings


@pytest.mark.parametrize(
    "state, scene_depth",
    [
        (ViewportState(), True),
        (ViewportState(xray=True, xray_alpha=1.0), True),  # X-ray at alpha 1 is opaque (Blender: not XRAY_ENABLED)
        (ViewportState(xray=True, xray_alpha=0.5), False),
        (ViewportState(xray=True, xray_alpha=0.0), False),
        (ViewportState(shading=WIREFRAME, xray=True, xray_alpha=0.5), False),
        (ViewportState(shading=WIREFRAME, xray=False, xray_alpha=0.5), True),
        (ViewportState(shading=MATERIAL, xray=True, xray_alpha=0.5), True),  # no X-ray in Material Preview
        (ViewportState(shading=RENDERED, xray=True, xray_alpha=0.5), True),
    ],
    ids=["solid", "xray_alpha_1", "xray_half", "xray_zero", "wire_xray", "wire_opaque", "material", "rendered"],
)
def test_depth_source_per_shading(state, scene_depth):
    plan = overlay_state.plan_overlay(state)
    assert plan.scene_depth is scene_depth
    assert plan.clip_planes is None and plan.pixel_scale == 1.0


def test_nothing_drawn_when_switched_off():
    assert overlay_state.plan_overlay(ViewportState(show=False)) is None
    assert overlay_state.plan_overlay(ViewportState(show_overlays=False)) is None


def test_which_objects():
    plan = overlay_state.plan_overlay(ViewportState())
    keep = lambda **kw: overlay_state.keep_object(plan, ObjectState(**kw))
    assert keep(visible=True)
    assert not keep(visible=False)  # hidden, hidden/excluded collection, outside local view
    assert not keep(visible=True, excluded=True)
    assert not keep(visible=True, in_edit_mode=True), "Blender draws its own edit wire"
    edit = overlay_state.plan_overlay(ViewportState(draw_edit_mode=True))
    assert overlay_state.keep_object(edit, ObjectState(in_edit_mode=True))
    selected = overlay_state.plan_overlay(ViewportState(only_selected=True))
    assert overlay_state.keep_object(selected, ObjectState(selected=True))
    assert not overlay_state.keep_object(selected, ObjectState(selected=False))


def test_pixel_lengths_follow_the_ui_scale():
    plan = overlay_state.plan_overlay(ViewportState(pixel_size=2.0))
    base = DrawSettings()
    scaled = overlay_state.draw_settings(plan, base)
    for name in ("thickness", "softness", "thickness_far", "pattern_period", "hidden_period"):
        assert getattr(scaled, name) == pytest.approx(2.0 * getattr(base, name)), name
    assert scaled.world_thickness == base.world_thickness
    assert scaled.fade_start == base.fade_start
    for bad in (0.0, -1.0, float("nan"), None):
        assert overlay_state.plan_overlay(ViewportState(pixel_size=bad)).pixel_scale == 1.0


def _perspective(near=0.1, far=100.0, focal=2.0, aspect=4.0 / 3.0):
    p = np.zeros((4, 4))
    p[0, 0], p[1, 1] = focal / aspect, focal
    p[2, 2], p[2, 3] = -(far + near) / (far - near), -2.0 * far * near / (far - near)
    p[3, 2] = -1.0
    return p


def _looking_from(eye) -> np.ndarray:
    """A view matrix of a camera at ``eye`` looking down -Z (no rotation)."""
    view = np.eye(4)
    view[:3, 3] = -np.asarray(eye, dtype=np.float64)
    return view


def _window_shift(view_depth, allowance, projection):
    """What shaders/common.glsl's window_depth_shift gives, in float64."""
    p22, p23, p32, p33 = projection[2, 2], projection[2, 3], projection[3, 2], projection[3, 3]
    slack = min(allowance[0] + allowance[1] * abs(view_depth), allowance[2] + allowance[3] * abs(view_depth))
    w_here = p33 - p32 * view_depth
    return 0.5 * slack * (p22 * p33 - p23 * p32) / ((w_here + p32 * slack) * w_here)


def test_blender_depth_allowance_grows_with_the_distance_from_the_origin():
    """The overlay's allowance for Blender's float32 depth
    (view.blender_depth_allowance): BLENDER_DEPTH_ULPS spacings of the
    largest coordinate a drawn point can have, at most BLENDER_DEPTH_MOST
    of the point's distance. Near the origin it moves a surface less than
    the constant NDC bias does from 15 near-clip distances on (the
    overlay's depth test is as before: closer, both move it by
    hundred-thousandths of a unit); 2,000 units away, more than 2^-14 in
    NDC at 4 units from the camera, which Blender's own viewport needs
    there (tests/test_viewport_headless.py); 100,000 units away, no more
    than the cap."""
    from solidwire_addon.core.view import (
        BLENDER_DEPTH_MOST,
        BLENDER_DEPTH_ULPS,
        OVERLAY_DEPTH_BIAS,
        View,
        blender_depth_allowance,
    )

    projection = _perspective()
    spacing = BLENDER_DEPTH_ULPS * 2.0**-24
    corner_ray = math.sqrt(1.0 + (1.0 / projection[0, 0]) ** 2 + (1.0 / projection[1, 1]) ** 2)

    def allowance(eye):
        return blender_depth_allowance(View(_looking_from(eye), projection, (0, 0, 640, 480)))

    for eye in ((3.0, -4.0, 0.0), (2003.0, 1997.0, 1.5)):
        a, b, c, e = allowance(eye)
        assert a == pytest.approx(spacing * math.dist(eye, (0.0, 0.0, 0.0)))
        assert b == pytest.approx(spacing * corner_ray)
        assert (c, e) == (0.0, BLENDER_DEPTH_MOST)
    near, far, farther = allowance((3.0, -4.0, 0.0)), allowance((2003.0, 1997.0, 1.5)), allowance((1e5, 1e5, 0.0))
    for depth in (1.5, 4.0, 50.0):
        assert -2.0 * _window_shift(depth, near, projection) < OVERLAY_DEPTH_BIAS
    assert near[0] + near[1] * 0.5 < 3e-5
    assert -2.0 * _window_shift(4.0, far, projection) > 2.0**-14
    capped = (4.0 * BLENDER_DEPTH_MOST, 0.0, 4.0 * BLENDER_DEPTH_MOST, 0.0)
    assert _window_shift(4.0, farther, projection) == pytest.approx(_window_shift(4.0, capped, projection))


def test_blender_depth_allowance_of_an_orthographic_view():
    """Orthographic: the window's half diagonal joins the camera's distance
    (a point lies that far off the axis at any depth), one unit per unit of
    depth, and the cap is a fraction of that half diagonal plus the depth;
    the shift in window depth for a given slack is the same at every depth."""
    from solidwire_addon.core.view import BLENDER_DEPTH_MOST, BLENDER_DEPTH_ULPS, View, blender_depth_allowance

    projection = np.eye(4)
    projection[0, 0], projection[1, 1] = 1.0 / 8.0, 1.0 / 6.0  # a 16 x 12 window
    projection[2, 2], projection[2, 3] = -2.0 / 99.9, -100.1 / 99.9
    a, b, c, e = blender_depth_allowance(View(_looking_from((0.0, 0.0, 500.0)), projection, (0, 0, 640, 480)))
    spacing = BLENDER_DEPTH_ULPS * 2.0**-24
    assert a == pytest.approx(spacing * (500.0 + 10.0)) and b == pytest.approx(spacing)
    assert c == pytest.approx(BLENDER_DEPTH_MOST * 10.0) and e == BLENDER_DEPTH_MOST
    fixed = (a, 0.0, 1.0, 0.0)
    assert _window_shift(1.0, fixed, projection) == pytest.approx(_window_shift(90.0, fixed, projection))
