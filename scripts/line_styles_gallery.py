"""Render the line styles that go beyond the published single-pass method
(full-width silhouettes, hidden lines, world-space and depth-cue thickness)
next to the plain SPEC look, and write a labelled sheet (docs/line_styles.png).

    .venv/bin/python -m scripts.line_styles_gallery [-o docs/line_styles.png]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

import bpy  # noqa: E402

from scripts import preset_gallery  # noqa: E402  (compose/write: the same sheet layout as the presets gallery)
from tests.support import scenes  # noqa: E402
import solidwire_addon  # noqa: E402

CELL = preset_gallery.CELL
PAPER = (0.93, 0.92, 0.88)
INK = (0.02, 0.04, 0.12, 1.0)

LOOK = dict(use_fill=True, fill_shading="FLAT", fill_color=PAPER, wire_color=INK, thickness=1.6, softness=0.9)
STYLES = (
    ("Single pass (SPEC): outlines half width", {}),
    ("Full-width silhouettes", dict(use_silhouettes=True)),
    ("Hidden lines, dashed (technical drawing)", dict(use_silhouettes=True, use_hidden_lines=True, hidden_alpha=0.5,
                                                      hidden_period=7.0, hidden_duty=0.55)),
    ("World-space thickness (0.025 units)", dict(thickness_mode="WORLD", world_thickness=0.025)),
    ("Depth cue: 3 px near to 0.6 px far", dict(thickness_mode="DEPTH", thickness=3.0, thickness_far=0.6,
                                                 thickness_depth_start=4.0, thickness_depth_end=16.0)),
    ("Dashed diagonals + silhouettes", dict(diagonal_mode="DASHED", pattern_period=7.0, use_silhouettes=True)),
)


def build_scene():
    scene = scenes.empty_scene(*CELL, transparent=False)
    world = bpy.data.worlds.new("Paper")
    world.color = PAPER
    scene.world = world
    scenes.monkey(scene, subdivisions=1, location=(0.0, 0.0, 0.05), rotation=(0.0, 0.0, -0.35))
    scenes.cube(scene, size=1.1, location=(1.7, 1.2, -0.4), rotation=(0.0, 0.0, 0.6))
    scenes.uv_sphere(scene, segments=20, rings=10, radius=0.7, location=(-1.9, 1.4, -0.3))
    scenes.grid(scene, "Floor", x_segments=14, y_segments=14, size=16.0, location=(0, 3.0, -1.0))
    scenes.add_camera(scene, location=(2.6, -5.2, 2.2), target=(0.0, 0.6, -0.3), lens=42.0)
    return scene


def render_cells(scene):
    return preset_gallery.render_looks(scene, STYLES, LOOK, CELL, reset=True)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-o", "--output", type=Path, default=ROOT / "docs" / "line_styles.png")
    args = parser.parse_args(argv)
    solidwire_addon.register()
    try:
        scene = build_scene()
        cells = render_cells(scene)
        preset_gallery.write(preset_gallery.compose(cells, columns=3), cells, args.output, columns=3)
    finally:
        solidwire_addon.unregister()
    print(f"wrote {args.output} ({args.output.stat().st_size // 1024} KiB)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
