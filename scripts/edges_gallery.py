"""Render which edges are drawn on one subdivided model and write a sheet for
the manual (docs/edges.png): top row every evaluated edge, cage edges (the
default), cage edges with an edge angle; bottom row edge classes (boundary,
sharp, seam), density fade on a dense distant grid, both together.

    .venv/bin/python -m scripts.edges_gallery [-o docs/edges.png]

The world is Blender's default 0.05 grey, as in a new file.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

from scripts import preset_gallery

CELL = (360, 270)
LOOK = dict(
    use_fill=True,
    fill_shading="STUDIO",
    fill_color=(0.8, 0.8, 0.8),
    wire_color=(0.0, 0.0, 0.0, 1.0),
    thickness=1.2,
    softness=1.0,
    use_cage_edges=True,
    edge_angle=0.0,
    use_density_fade=False,
    density_fade_length=10.0,
    use_boundary_edges=False,
    use_sharp_edges=False,
    use_seam_edges=False,
)
CLASSES = dict(
    use_boundary_edges=True,
    boundary_thickness=3.0,
    boundary_color=(0.02, 0.02, 0.02, 1.0),
    use_sharp_edges=True,
    sharp_thickness=2.5,
    sharp_color=(0.0, 0.3, 0.85, 1.0),
    use_seam_edges=True,
    seam_thickness=2.0,
    seam_color=(0.9, 0.2, 0.05, 1.0),
    seam_pattern="DASHED",
)
CELLS = (
    ("Every evaluated edge", dict(use_cage_edges=False)),
    ("Cage edges (default)", {}),
    ("Cage edges + edge angle 30°", dict(edge_angle=math.radians(30.0))),
    ("Edge classes: boundary, sharp, seam", CLASSES),
    ("Every edge + density fade", dict(use_cage_edges=False, use_density_fade=True)),
    ("Cage + classes + density fade", dict(**CLASSES, use_density_fade=True)),
)


def build_scene():
    scene, (suzanne, cube, sphere, floor) = preset_gallery.still_life(CELL, "World", (0.05, 0.05, 0.05))
    suzanne.modifiers[0].levels = suzanne.modifiers[0].render_levels = 2
    suzanne.data.shade_smooth()
    # Seams round the eyes and the ears' rims, sharp edges on the cube's top.
    for edge in suzanne.data.edges:
        edge.use_seam = edge.index < 48
    cube_sub = cube.modifiers.new("Subdivision", "SUBSURF")
    cube_sub.levels = cube_sub.render_levels = 2
    for edge in cube.data.edges:
        edge.use_edge_sharp = edge.index in (0, 1, 2, 3)
    crease = cube.data.attributes.new("crease_edge", "FLOAT", "EDGE")
    for edge in range(len(cube.data.edges)):
        crease.data[edge].value = 1.0 if edge in (0, 1, 2, 3) else 0.0
    sphere.data.shade_smooth()
    floor.scale = (1.0, 1.0, 1.0)
    return scene


def render_cells(scene):
    return preset_gallery.render_looks(scene, CELLS, LOOK, CELL)


def main(argv=None) -> int:
    return preset_gallery.run_gallery(
        argv, __doc__.splitlines()[0], ROOT / "docs" / "edges.png", build_scene, render_cells, cell=CELL
    )


if __name__ == "__main__":
    sys.exit(main())
