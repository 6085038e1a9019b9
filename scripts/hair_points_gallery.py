"""Hair and a point cloud, SolidWire beside Blender's Workbench, for
docs/user/hair-and-points.md (docs/hair_points.png):

    .venv/bin/python -m scripts.hair_points_gallery [-o docs/hair_points.png]

Left: the SOLIDWIRE render engine with the add-on's default look (Studio
fill, cage edges); right: Workbench (Solid shading, Studio light) of the same
scene and camera. Both over the same grey.
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

import bpy
import numpy as np

import solidwire_addon
from scripts import preset_gallery
from solidwire_addon.blender import engine
from solidwire_addon.blender.gpu_context import ensure_gpu
from tests.support import scenes, strand_scenes

CELL = (420, 315)


def build_scene():
    scene = scenes.empty_scene(*CELL)
    scenes.default_look(scene)
    scene.solidwire.wire_color = (0.0, 0.0, 0.0, 1.0)
    scene.solidwire.thickness = 1.2
    rng = np.random.default_rng(7)
    head = scenes.uv_sphere(scene, "Head", segments=24, rings=12, radius=0.8, location=(0.0, 0.0, 0.8))
    head.data.shade_smooth()
    curves = []
    for _ in range(70):
        # Roots on the upper half of the head, strands leaning outwards.
        theta, phi = rng.uniform(0.0, 2.0 * np.pi), rng.uniform(0.0, 0.9)
        normal = np.array([np.sin(phi) * np.cos(theta), np.sin(phi) * np.sin(theta), np.cos(phi)])
        root = np.array([0.0, 0.0, 0.8]) + 0.8 * normal
        t = np.linspace(0.0, 1.0, 5)[:, None]
        droop = np.array([0.0, 0.0, -1.0]) * t * t * 0.5
        curves.append(root + t * 0.7 * (normal + rng.normal(0.0, 0.15, 3)) + droop)
    radii = [np.linspace(0.012, 0.002, 5) for _ in curves]
    strand_scenes.hair(scene, "Hair", curves, radii, types=[strand_scenes.CATMULL_ROM] * len(curves), resolution=6)
    angles = np.linspace(0.0, 2.0 * np.pi, 40, endpoint=False)
    ring = np.stack([1.9 * np.cos(angles), 1.9 * np.sin(angles), 0.15 + 0.1 * np.sin(3.0 * angles)], axis=1)
    strand_scenes.point_cloud(scene, "Ring", ring, 0.07)
    strand_scenes.point_cloud(scene, "Pebbles", rng.uniform((-2.5, -1.5, 0.2), (2.5, 2.5, 0.2), (6, 3)), 0.2)
    scenes.grid(scene, "Floor", x_segments=8, y_segments=8, size=3.5)
    scenes.add_camera(scene, location=(4.2, -5.4, 3.3), target=(0.0, 0.3, 0.7), lens=42.0)
    return scene


def workbench(scene, folder: Path) -> np.ndarray:
    """Blender's Workbench render of the scene (Solid shading, Studio
    light), linear premultiplied."""
    scene.render.engine = "BLENDER_WORKBENCH"
    scene.display.shading.light = "STUDIO"
    scene.display.shading.color_type = "MATERIAL"
    straight = scenes.render_to_file(scene, folder / "workbench.png")
    scene.render.engine = "SOLIDWIRE"
    rgb = preset_gallery.srgb_decode(straight[..., :3]) * straight[..., 3:4]
    return np.concatenate([rgb, straight[..., 3:4]], axis=-1)


def render_cells(scene, folder: Path):
    ensure_gpu()
    background = np.broadcast_to(np.asarray(preset_gallery.BACKGROUND), (CELL[1], CELL[0], 3))
    rgba, _depth = engine.render_scene(bpy.context.evaluated_depsgraph_get(), CELL)
    solidwire = preset_gallery.over(rgba, background)
    return [("SolidWire", solidwire), ("Workbench", preset_gallery.over(workbench(scene, folder), background))]


def main(argv=None) -> int:
    import argparse

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-o", "--output", type=Path, default=ROOT / "docs" / "hair_points.png")
    args = parser.parse_args(argv)
    solidwire_addon.register()
    try:
        scene = build_scene()
        with tempfile.TemporaryDirectory(prefix="solidwire-gallery-") as folder:
            cells = render_cells(scene, Path(folder))
        preset_gallery.write_sheet(cells, args.output, columns=2, cell=CELL)
    finally:
        solidwire_addon.unregister()
    return 0


if __name__ == "__main__":
    sys.exit(main())
