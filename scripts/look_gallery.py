"""Render the fill shadings (FLAT, STUDIO, MATCAP) and the colour sources
(object, material, random) on one small scene and write a sheet for the
manual (docs/looks.png): top row Flat, Studio, MatCap; bottom row fill from
Object colour, from Material colour, Random per object (wire too).

    .venv/bin/python -m scripts.look_gallery [-o docs/looks.png]

The world is Blender's default 0.05 grey, as in a new file.
"""

from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

import bpy

from scripts import preset_gallery

CELL = (360, 270)
LOOK = dict(
    use_fill=True,
    fill_shading="STUDIO",
    fill_color=(0.8, 0.8, 0.8),
    wire_color=(0.0, 0.0, 0.0, 1.0),
    thickness=1.2,
    softness=1.0,
    fill_color_source="SINGLE",
    wire_color_source="SINGLE",
    use_cage_edges=True,
)  # the default look (the test scenes switch cage edges off)
CELLS = (
    ("Flat fill (the image model's core)", dict(fill_shading="FLAT")),
    ("Studio: camera-fixed lights (default)", {}),
    ("MatCap: clay_brown", dict(fill_shading="MATCAP", matcap="clay_brown", fill_color=(1.0, 1.0, 1.0))),
    ("Fill from Object colour", dict(fill_color_source="OBJECT")),
    ("Fill from Material colour", dict(fill_color_source="MATERIAL")),
    ("Random per object, wire too", dict(fill_color_source="RANDOM", wire_color_source="RANDOM")),
)


def build_scene():
    scene, (suzanne, cube, sphere, floor) = preset_gallery.still_life(CELL, "World", (0.05, 0.05, 0.05))
    suzanne.data.shade_smooth()
    suzanne.color = (0.85, 0.45, 0.2, 1.0)
    cube.color = (0.2, 0.5, 0.85, 1.0)
    for name, colour in (("Teal", (0.1, 0.55, 0.5, 1.0)), ("Sand", (0.85, 0.7, 0.4, 1.0))):
        material = bpy.data.materials.new(name)
        material.diffuse_color = colour
        cube.data.materials.append(material)
    for poly in cube.data.polygons:
        poly.material_index = poly.index % 2
    sphere.data.shade_smooth()
    sphere.color = (0.4, 0.75, 0.3, 1.0)
    floor.color = (0.6, 0.6, 0.62, 1.0)
    return scene


def render_cells(scene):
    return preset_gallery.render_looks(scene, CELLS, LOOK, CELL, reset=False)


def main(argv=None) -> int:
    return preset_gallery.run_gallery(
        argv, __doc__.splitlines()[0], ROOT / "docs" / "looks.png", build_scene, render_cells, cell=CELL
    )


if __name__ == "__main__":
    sys.exit(main())
