"""Render the line styles that go beyond the published single-pass method
(full-width silhouettes, hidden lines, world-space and depth-cue thickness)
next to the plain SPEC look, and write a labelled sheet (docs/line_styles.png).

    .venv/bin/python -m scripts.line_styles_gallery [-o docs/line_styles.png]
"""

from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


from scripts import preset_gallery

CELL = preset_gallery.CELL
PAPER = (0.93, 0.92, 0.88)
INK = (0.02, 0.04, 0.12, 1.0)

LOOK = dict(use_fill=True, fill_shading="FLAT", fill_color=PAPER, wire_color=INK, thickness=1.6, softness=0.9)
STYLES = (
    ("Single pass (SPEC): outlines half width", {}),
    ("Full-width silhouettes", dict(use_silhouettes=True)),
    (
        "Hidden lines, dashed (technical drawing)",
        dict(use_silhouettes=True, use_hidden_lines=True, hidden_alpha=0.5, hidden_period=7.0, hidden_duty=0.55),
    ),
    ("World-space thickness (0.025 units)", dict(thickness_mode="WORLD", world_thickness=0.025)),
    (
        "Depth cue: 3 px near to 0.6 px far",
        dict(
            thickness_mode="DEPTH",
            thickness=3.0,
            thickness_far=0.6,
            thickness_depth_start=4.0,
            thickness_depth_end=16.0,
        ),
    ),
    ("Dashed diagonals + silhouettes", dict(diagonal_mode="DASHED", pattern_period=7.0, use_silhouettes=True)),
)


def build_scene():
    scene, _objects = preset_gallery.still_life(CELL, "Paper", PAPER)
    return scene


def render_cells(scene):
    return preset_gallery.render_looks(scene, STYLES, LOOK, CELL, reset=True)


def main(argv=None) -> int:
    return preset_gallery.run_gallery(
        argv, __doc__.splitlines()[0], ROOT / "docs" / "line_styles.png", build_scene, render_cells
    )


if __name__ == "__main__":
    sys.exit(main())
