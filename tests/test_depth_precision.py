"""Hidden-surface decisions that do not depend on the clip range.

A panel 1e-4 of its distance in front of a wall (a few millimetres at 25 m,
an interior camera's situation) must hide the wall's lines whatever the clip
start and end are. With the standard GL depth mapping the precision left at
25 m with clip 1 cm .. 1 km is a few float32 steps and the wall bled through
in stipples; the engine writes linear view depth into its float depth buffer
instead (docs/image_model.md §2, docs/dev/robustness.md). Checked against the
float64 reference, which decides every pixel by ray casting.
"""

from __future__ import annotations

import math

import bpy
import pytest

from tests.support import accuracy, scenes

DISTANCE = 25.0
GAP = 1e-4 * DISTANCE


def _panel_scene(clip_start: float, clip_end: float, ortho: bool):
    scene = scenes.empty_scene(160, 120, diagonal_mode="SOLID")
    # The camera looks at the wall at an angle (depth varies across both
    # planes, so ties are not settled by equal depths); the panel is drawn
    # first, so the wall must lose on depth alone.
    scenes.add_camera(
        scene,
        location=(-6.0, 0.0, 2.0),
        target=(0.5, DISTANCE, 0.3),
        clip=(clip_start, clip_end),
        ortho_scale=14.0 if ortho else None,
        lens=35.0,
    )
    upright = (math.pi / 2, 0.0, 0.0)
    scenes.grid(
        scene, "Panel", x_segments=3, y_segments=3, size=4.0, location=(0.7, DISTANCE - GAP, 0.3), rotation=upright
    )
    scenes.grid(scene, "Wall", x_segments=12, y_segments=12, size=12.0, location=(0.0, DISTANCE, 0.0), rotation=upright)
    bpy.context.view_layer.update()
    return scene


@pytest.mark.parametrize("ortho", [False, True], ids=["persp", "ortho"])
@pytest.mark.parametrize(
    "clip",
    [(0.01, 1000.0), (1e-4, 1e5), (1.0, 30.0), (1e-3, 1e7)],
    ids=["1cm-1km", "0.1mm-100km", "1m-30m", "1mm-1e7"],
)
def test_a_panel_just_in_front_of_a_wall_hides_it(clip, ortho, output_dir):
    scene = _panel_scene(*clip, ortho)
    name = f"depth_{'ortho' if ortho else 'persp'}_{clip[0]:g}_{clip[1]:g}"
    report = accuracy.measure(scene, name, output_dir)
    assert report["over_2_255"] == 0, report
    accuracy.assert_accurate(report)
