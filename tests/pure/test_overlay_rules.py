"""The overlay's rules per viewport state, without Blender: the pure
function the draw handler calls (core/overlay_state.py) on plain inputs,
for the table in docs/user/overlay.md ("Viewport states").
(tests/test_overlay_states.py draws each state and checks the images.)"""

from __future__ import annotations

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
