"""DOTTED / DASHED diagonals (SPEC 1.4) measured in rendered images.

A diamond-shaped quad is seen frontally by an orthographic camera so that its
triangulation diagonal runs along one pixel row, through the pixel centres.
Along that row the line intensity is exactly the box-filtered pattern mask
m(t) (d_diag = 0 there and the profile is 1), so the on/off runs can be read
from the alpha channel: period = distance between rising edges, duty = on-run
/ period, with the edges found at the 0.5 crossings (a box-filtered step is
a linear ramp centred on the true edge).
"""

from __future__ import annotations

import bpy
import numpy as np
import pytest

from solidwire_addon.blender import engine
from solidwire_addon.blender.gpu_context import ensure_gpu
from tests.support import scenes

SIZE = 511  # odd: world y = 0 maps to the centre of pixel row 255
HALF_WIDTH, HALF_HEIGHT = 0.92, 0.6  # world units; the camera sees 2 x 2


def diamond_scene(**solidwire):
    scene = scenes.empty_scene(SIZE, SIZE, **solidwire)
    camera = scenes.add_camera(scene, location=(0.0, 0.0, 5.0), target=(0.0, 0.0, 0.0), ortho_scale=2.0)
    camera.rotation_euler = (0.0, 0.0, 0.0)
    verts = [(-HALF_WIDTH, 0, 0), (0, -HALF_HEIGHT, 0), (HALF_WIDTH, 0, 0), (0, HALF_HEIGHT, 0)]
    obj = scenes.from_pydata(scene, "Diamond", verts, [(0, 1, 2, 3)])
    mesh = obj.data
    mesh.calc_loop_triangles()
    shared = set(mesh.loop_triangles[0].vertices) & set(mesh.loop_triangles[1].vertices)
    assert shared == {0, 2}, "the test needs the horizontal diagonal"
    return scene


def render_alpha(scene) -> np.ndarray:
    ensure_gpu()
    rgba, _depth = engine.render_scene(bpy.context.evaluated_depsgraph_get(), (SIZE, SIZE))
    return rgba[..., 3].astype(np.float64)


def diagonal_profile(alpha: np.ndarray, margin_px: float = 6.0):
    """(t, m) along the diagonal's pixel row, away from the quad's corners."""
    row = alpha[SIZE // 2]
    px_per_unit = SIZE / 2.0
    x_left = SIZE / 2.0 - HALF_WIDTH * px_per_unit
    x_right = SIZE / 2.0 + HALF_WIDTH * px_per_unit
    centres = np.arange(SIZE) + 0.5
    keep = (centres > x_left + margin_px) & (centres < x_right - margin_px)
    return centres[keep], row[keep]


def crossings(t, m, rising: bool):
    above = m >= 0.5
    idx = np.nonzero((~above[:-1] & above[1:]) if rising else (above[:-1] & ~above[1:]))[0]
    # Linear interpolation of the 0.5 level between the two samples.
    return t[idx] + (0.5 - m[idx]) / (m[idx + 1] - m[idx]) * (t[idx + 1] - t[idx])


def measure(t, m):
    rises, falls = crossings(t, m, True), crossings(t, m, False)
    period = np.diff(rises).mean()
    on_runs = [falls[falls > r][0] - r for r in rises if np.any(falls > r)]
    return period, np.mean(on_runs) / period, len(rises)


@pytest.mark.parametrize(
    "mode,period,duty",
    [("DOTTED", 32.0, 0.25), ("DOTTED", 12.0, 0.25), ("DASHED", 24.0, 0.5), ("DASHED", 40.0, 0.7)],
)
def test_pattern_period_and_duty_match_the_settings(mode, period, duty):
    scene = diamond_scene(diagonal_mode=mode, thickness=1.5)
    scene.solidwire.pattern_period = period
    scene.solidwire.pattern_duty = duty  # after the mode: its update sets the mode's default duty
    t, m = diagonal_profile(render_alpha(scene))
    assert m.max() == pytest.approx(1.0, abs=1e-3) and m.min() == pytest.approx(0.0, abs=1e-3)
    measured_period, measured_duty, cycles = measure(t, m)
    assert cycles >= 8
    assert measured_period == pytest.approx(period, rel=0.05)
    assert measured_duty == pytest.approx(duty, rel=0.05)
    # The box filter keeps the mean: the fraction "on" over whole periods is q.
    whole = (t >= t[0]) & (t < t[0] + period * np.floor((t[-1] - t[0]) / period))
    assert m[whole].mean() == pytest.approx(duty, rel=0.05)


def test_dash_ends_are_antialiased():
    scene = diamond_scene(diagonal_mode="DASHED", thickness=1.5)
    scene.solidwire.pattern_period = 16.3  # ends at varying sub-pixel phases
    t, m = diagonal_profile(render_alpha(scene))
    partial = (m > 0.02) & (m < 0.98)
    rises = crossings(t, m, True)
    # Every dash end lands on one partially covered pixel or exactly on a
    # pixel boundary; never a hard 0 -> 1 jump between pixel centres.
    steps = np.abs(np.diff(m))
    assert steps.max() <= 1.0 + 1e-6
    assert partial.sum() >= len(rises)


def test_default_duties_follow_the_mode():
    scene = diamond_scene(diagonal_mode="DASHED")
    assert scene.solidwire.pattern_duty == pytest.approx(0.5)
    scene.solidwire.diagonal_mode = "DOTTED"
    assert scene.solidwire.pattern_duty == pytest.approx(0.25)


def test_pattern_does_not_crawl_when_colour_or_line_settings_change():
    scene = diamond_scene(diagonal_mode="DOTTED", thickness=1.5)
    scene.solidwire.pattern_period = 20.0
    # Margin: away from the corners, where the wider real edges now reach.
    _t, before = diagonal_profile(render_alpha(scene), margin_px=16.0)
    scene.solidwire.wire_color = (0.2, 0.9, 0.1, 1.0)
    scene.solidwire.thickness = 3.0
    scene.solidwire.softness = 1.7
    _t, after = diagonal_profile(render_alpha(scene), margin_px=16.0)
    assert np.abs(after - before).max() < 1e-4
