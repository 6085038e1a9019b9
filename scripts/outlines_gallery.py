"""Text, a bevelled curve, a NURBS surface and metaballs under the default
look (outlines and profiles) and with Tessellation on: docs/outlines.png.

    .venv/bin/python -m scripts.outlines_gallery [-o docs/outlines.png]
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

import bpy  # first: importing bpy makes mathutils importable

# isort: split
import solidwire_addon
from scripts import dense_scenes, preset_gallery
from solidwire_addon.blender import engine
from solidwire_addon.blender.gpu_context import ensure_gpu

CELL = (320, 240)


def text(scene):
    """A bevelled, extruded "SoW" standing up (the geometry alone)."""
    data = bpy.data.curves.new("Text", "FONT")
    data.body = "SoW"
    data.extrude = 0.08
    data.bevel_depth = 0.02
    data.align_x = "CENTER"
    obj = bpy.data.objects.new("Text", data)
    scene.collection.objects.link(obj)
    obj.rotation_euler = (math.radians(70), 0.0, 0.0)


def filled_curve(scene):
    """A filled 2D Bezier circle, extruded and bevelled."""
    bpy.ops.curve.primitive_bezier_circle_add(radius=1.0)
    ring = bpy.context.active_object
    ring.data.dimensions = "2D"
    ring.data.fill_mode = "BOTH"
    ring.data.extrude = 0.15
    ring.data.bevel_depth = 0.05
    ring.rotation_euler = (math.radians(55), 0.0, math.radians(20))


def nurbs_sphere(scene):
    """A NURBS sphere at a low resolution."""
    bpy.ops.surface.primitive_nurbs_surface_sphere_add(radius=1.0)
    sphere = bpy.context.active_object
    sphere.data.resolution_u = sphere.data.resolution_v = 3


def metaballs(scene):
    """Two metaballs melting together (viewport and render resolution alike)."""
    bpy.ops.object.metaball_add(radius=1.0)
    balls = bpy.context.active_object
    balls.data.resolution = balls.data.render_resolution = 0.25
    element = balls.data.elements.new()
    element.co = (1.1, 0.0, 0.3)
    element.radius = 0.8


# (label, geometry, camera location, target, lens)
SOURCES = (
    ("Text", text, (0.6, -3.2, 1.4), (0.0, 0.0, 0.3), 45.0),
    ("Filled curve, bevel", filled_curve, (0.0, -4.2, 1.8), (0.0, 0.0, 0.0), 50.0),
    ("NURBS sphere", nurbs_sphere, (1.5, -4.0, 2.0), (0.0, 0.0, 0.0), 50.0),
    ("Metaballs", metaballs, (0.6, -4.5, 2.0), (0.5, 0.0, 0.0), 50.0),
)


def render_cells() -> list:
    ensure_gpu()
    rows: list = [[], []]
    for label, build, location, target, lens in SOURCES:
        scene = dense_scenes._fresh_scene(*CELL)
        scene.render.film_transparent = False
        world = bpy.data.worlds.new("World")
        world.color = (0.18, 0.2, 0.23)
        scene.world = world
        build(scene)
        dense_scenes._camera(scene, location, target, lens=lens)
        for row, show in enumerate((False, True)):
            scene.solidwire.show_tessellation = show
            rgba, _depth = engine.render_scene(bpy.context.evaluated_depsgraph_get(), CELL)
            rows[row].append((label + (" + Tessellation" if show else ""), rgba[..., :3]))
    return rows[0] + rows[1]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-o", "--output", type=Path, default=ROOT / "docs" / "outlines.png")
    args = parser.parse_args(argv)
    solidwire_addon.register()
    try:
        preset_gallery.write_sheet(render_cells(), args.output, columns=len(SOURCES), cell=CELL)
    finally:
        solidwire_addon.unregister()
    return 0


if __name__ == "__main__":
    sys.exit(main())
