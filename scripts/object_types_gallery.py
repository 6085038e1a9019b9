"""Each object type SolidWire draws, beside Blender's Workbench rendering the
same scene, for docs/user/objects.md (docs/object_types.png):

    .venv/bin/python -m scripts.object_types_gallery [-o docs/object_types.png]

One row per object type: a subdivided mesh (cage edges), text, a bevelled
filled curve, a NURBS surface, metaballs, instances on a grid's vertices,
hair (a Curves object) and a point cloud. Left: the SOLIDWIRE render engine
with the add-on's default look (Studio fill, cage edges); right: Workbench
(Solid shading, Studio light) of the same scene and camera. Both over the
same grey.
"""

from __future__ import annotations

import argparse
import math
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

import bpy  # first: importing bpy makes mathutils importable

# isort: split
import bmesh
import numpy as np

# isort: split
import solidwire_addon
from scripts import hair_points_gallery, outlines_gallery, preset_gallery
from solidwire_addon.blender import engine
from solidwire_addon.blender.gpu_context import ensure_gpu
from tests.support import scenes, strand_scenes

CELL = (320, 200)


def _subdivided_mesh(scene):
    suzanne = scenes.monkey(scene, subdivisions=2, rotation=(0.0, 0.0, math.radians(-20)))
    suzanne.data.shade_smooth()
    scenes.add_camera(scene, location=(1.0, -4.6, 0.9), target=(0.0, 0.0, 0.05), lens=50.0)


def _text(scene):
    outlines_gallery.text(scene)
    scenes.add_camera(scene, location=(0.6, -4.0, 1.6), target=(0.0, 0.0, 0.3), lens=50.0)


def _curve(scene):
    outlines_gallery.filled_curve(scene)
    scenes.add_camera(scene, location=(0.0, -5.6, 2.4), target=(0.0, 0.0, 0.0), lens=50.0)


def _surface(scene):
    outlines_gallery.nurbs_sphere(scene)
    scenes.add_camera(scene, location=(1.5, -4.4, 2.2), target=(0.0, 0.0, 0.0), lens=50.0)


def _metaballs(scene):
    outlines_gallery.metaballs(scene)
    scenes.add_camera(scene, location=(0.6, -4.5, 2.0), target=(0.5, 0.0, 0.0), lens=55.0)


def _instances(scene):
    # A cone instanced on each vertex of a 4 x 3 grid (Instancing: Vertices);
    # the grid itself is not rendered.
    grid = scenes.grid(scene, "Instancer", x_segments=3, y_segments=2, size=1.3)
    grid.instance_type = "VERTS"
    grid.show_instancer_for_render = grid.show_instancer_for_viewport = False
    cone = scenes.mesh_object(
        scene,
        "Cone",
        lambda bm: bmesh.ops.create_cone(bm, cap_ends=True, segments=12, radius1=0.35, radius2=0.0, depth=0.8),
        location=(0.0, 0.0, 0.4),
    )
    cone.parent = grid
    scenes.add_camera(scene, location=(3.2, -5.4, 3.6), target=(0.0, 0.0, 0.2), lens=45.0)


def _hair(scene):
    rng = np.random.default_rng(3)
    head = scenes.uv_sphere(scene, "Head", segments=24, rings=12, radius=0.7)
    head.data.shade_smooth()
    curves = []
    for _ in range(60):
        theta, phi = rng.uniform(0.0, 2.0 * np.pi), rng.uniform(0.0, 1.0)
        normal = np.array([np.sin(phi) * np.cos(theta), np.sin(phi) * np.sin(theta), np.cos(phi)])
        t = np.linspace(0.0, 1.0, 5)[:, None]
        droop = np.array([0.0, 0.0, -1.0]) * t * t * 0.45
        curves.append(0.7 * normal + t * 0.65 * (normal + rng.normal(0.0, 0.15, 3)) + droop)
    radii = [np.linspace(0.014, 0.003, 5) for _ in curves]
    strand_scenes.hair(scene, "Hair", curves, radii, types=[strand_scenes.CATMULL_ROM] * len(curves), resolution=6)
    scenes.add_camera(scene, location=(2.4, -5.0, 1.8), target=(0.0, 0.0, 0.4), lens=50.0)


def _points(scene):
    rng = np.random.default_rng(11)
    angles = np.linspace(0.0, 2.0 * np.pi, 36, endpoint=False)
    ring = np.stack([1.3 * np.cos(angles), 1.3 * np.sin(angles), 0.1 * np.sin(3.0 * angles)], axis=1)
    strand_scenes.point_cloud(scene, "Ring", ring, 0.08)
    strand_scenes.point_cloud(scene, "Pebbles", rng.uniform((-0.7, -0.7, -0.1), (0.7, 0.7, 0.4), (7, 3)), 0.18)
    scenes.add_camera(scene, location=(2.2, -4.6, 2.8), target=(0.0, 0.0, 0.1), lens=50.0)


SOURCES = (
    ("Subdivided mesh", _subdivided_mesh),
    ("Text", _text),
    ("Curve, fill and bevel", _curve),
    ("NURBS surface", _surface),
    ("Metaballs", _metaballs),
    ("Instances on vertices", _instances),
    ("Hair (Curves)", _hair),
    ("Point cloud", _points),
)


def render_cells(folder: Path) -> list:
    ensure_gpu()
    background = np.broadcast_to(np.asarray(preset_gallery.BACKGROUND), (CELL[1], CELL[0], 3))
    cells = []
    for label, build in SOURCES:
        scene = scenes.empty_scene(*CELL)
        scenes.default_look(scene)  # the add-on's defaults: Studio fill, cage edges
        scene.solidwire.property_unset("wire_color")  # black
        scene.solidwire.use_fill = True
        scene.solidwire.fill_shading = "STUDIO"
        build(scene)
        rgba, _depth = engine.render_scene(bpy.context.evaluated_depsgraph_get(), CELL)
        cells.append((f"SolidWire: {label}", preset_gallery.over(rgba, background)))
        workbench = hair_points_gallery.workbench(scene, folder)
        cells.append((f"Workbench: {label}", preset_gallery.over(workbench, background)))
    return cells


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-o", "--output", type=Path, default=ROOT / "docs" / "object_types.png")
    args = parser.parse_args(argv)
    solidwire_addon.register()
    try:
        with tempfile.TemporaryDirectory(prefix="solidwire-gallery-") as folder:
            cells = render_cells(Path(folder))
        preset_gallery.write_sheet(cells, args.output, columns=2, cell=CELL)
    finally:
        solidwire_addon.unregister()
    return 0


if __name__ == "__main__":
    sys.exit(main())
