"""Gallery images of the wire pass over a shaded Cycles render (docs/user/wire-over.md,
"Wire over EEVEE / Cycles renders"):

    .venv/bin/python -m scripts.wire_over_gallery [--out docs] [--samples 48]

writes docs/wire_over_suzanne.png (Suzanne, subdivision level 1, wire over a
Cycles render), docs/wire_over_layers.png (the beauty, the wire pass on a
checkerboard, and the composite side by side) and, when the Stanford bunny is
in cache/meshes (scripts/fetch_meshes.py), docs/wire_over_bunny.png (the
bunny decimated to a few thousand triangles so that the topology reads at
this size). Everything goes through solidwire_addon.composite, as the
operator and ``scripts/render.py --over CYCLES`` do.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

import bpy
import numpy as np
from mathutils import Vector

import solidwire_addon
from solidwire_addon.blender import composite
from tests.support import scenes

SIZE = (640, 400)


def material(name, color, roughness=0.45, subsurface=0.0):
    mat = bpy.data.materials.new(name)
    if not mat.node_tree:
        mat.use_nodes = True  # Blender < 5 only: 5.0 materials always have nodes
    bsdf = mat.node_tree.nodes.get("Principled BSDF")
    bsdf.inputs["Base Color"].default_value = (*color, 1.0)
    bsdf.inputs["Roughness"].default_value = roughness
    if subsurface:
        bsdf.inputs["Subsurface Weight"].default_value = subsurface
        bsdf.inputs["Subsurface Radius"].default_value = (0.3, 0.15, 0.08)
        bsdf.inputs["Subsurface Scale"].default_value = 0.05
    return mat


def area_light(scene, name, location, target, energy, size, color=(1.0, 1.0, 1.0)):
    light = bpy.data.lights.new(name, "AREA")
    light.energy, light.size, light.color = energy, size, color
    obj = bpy.data.objects.new(name, light)
    scene.collection.objects.link(obj)
    obj.location = location
    obj.rotation_euler = (Vector(target) - Vector(location)).to_track_quat("-Z", "Y").to_euler()
    return obj


def studio(scene, samples: int, floor_z: float):
    """A soft three-light studio with a large floor (its border out of frame)."""
    world = bpy.data.worlds.new("Studio")
    if not world.node_tree:
        world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.045, 0.05, 0.06, 1.0)
    scene.world = world
    floor = scenes.grid(scene, "Floor", x_segments=1, y_segments=1, size=60.0, location=(0, 0, floor_z))
    floor.data.materials.append(material("Floor", (0.085, 0.09, 0.10), roughness=0.55))
    area_light(scene, "Key", (-3.5, -4.5, 4.5), (0, 0, 0), 800.0, 3.0, (1.0, 0.95, 0.88))
    area_light(scene, "Fill", (6.0, -3.0, 1.5), (0, 0, 0), 220.0, 6.0, (0.85, 0.9, 1.0))
    area_light(scene, "Rim", (-1.0, 6.0, 4.0), (0, 0, 0), 700.0, 3.0)
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = samples
    scene.cycles.use_denoising = True
    scene.render.film_transparent = False
    scene.view_settings.view_transform = "AgX"
    scene.view_settings.look = "AgX - Medium High Contrast"
    image = scene.render.image_settings
    image.file_format = "PNG"
    image.color_mode = "RGB"
    image.color_depth = "8"
    scene.render.dither_intensity = 1.0


def wire_look(scene, color=(0.02, 0.03, 0.05, 0.9), thickness=0.8):
    props = scene.solidwire
    props.wire_color = color
    props.thickness = thickness
    props.softness = 1.0
    props.diagonal_mode = "HIDDEN"
    props.use_fade = False


def suzanne_scene(samples: int):
    scene = scenes.empty_scene(*SIZE, transparent=False)
    obj = scenes.monkey(scene, subdivisions=1, location=(0, 0, 0), rotation=(math.radians(-12), 0, math.radians(-28)))
    for polygon in obj.data.polygons:
        polygon.use_smooth = True
    obj.data.materials.append(material("Clay", (0.62, 0.33, 0.20), roughness=0.42, subsurface=0.15))
    studio(scene, samples, floor_z=-0.8)
    scenes.add_camera(scene, location=(3.4, -6.8, 2.1), target=(0.05, 0, 0.0), lens=62.0, clip=(0.1, 100.0))
    wire_look(scene)
    return scene


def bunny_scene(samples: int, ratio: float):
    scene = scenes.empty_scene(*SIZE, transparent=False)
    obj = scenes.load_obj(scene, "Bunny", scenes.MESH_DIR / "bunny.obj", rotation_euler=(math.pi / 2, 0.0, 0.0))
    decimate = obj.modifiers.new("Decimate", "DECIMATE")
    decimate.ratio = ratio
    for polygon in obj.data.polygons:
        polygon.use_smooth = True
    bpy.context.view_layer.update()
    # Stand it on the origin, about 2 units tall.
    corners = [obj.matrix_world @ Vector(c) for c in obj.bound_box]
    low = Vector((min(c.x for c in corners), min(c.y for c in corners), min(c.z for c in corners)))
    high = Vector((max(c.x for c in corners), max(c.y for c in corners), max(c.z for c in corners)))
    scale = 2.0 / (high.z - low.z)
    obj.scale = (scale,) * 3
    centre = (low + high) / 2
    obj.location = (-centre.x * scale, -centre.y * scale, -low.z * scale - 1.0)
    obj.data.materials.append(material("Porcelain", (0.78, 0.76, 0.72), roughness=0.3, subsurface=0.1))
    studio(scene, samples, floor_z=-1.0)
    scenes.add_camera(scene, location=(-2.2, -6.8, 1.6), target=(0.0, 0.0, -0.05), lens=60.0, clip=(0.1, 100.0))
    wire_look(scene, color=(0.03, 0.04, 0.08, 0.85), thickness=0.6)
    return scene


def save_rgb(scene, rgba: np.ndarray, path: Path) -> None:
    composite.save_image(scene, rgba, path)
    print(f"wrote {path} ({path.stat().st_size // 1024} KB)", flush=True)


def checkerboard(height: int, width: int, cell: int = 12) -> np.ndarray:
    y, x = np.mgrid[0:height, 0:width]
    light = ((x // cell + y // cell) % 2).astype(np.float32)
    value = 0.35 + 0.25 * light  # linear greys
    out = np.ones((height, width, 4), dtype=np.float32)
    out[..., :3] = value[..., None]
    return out


def layers_strip(layers: composite.Layers) -> np.ndarray:
    """Beauty | wire pass over a checkerboard | composite, 1/2 size each."""

    def half(image):
        return image.reshape(image.shape[0] // 2, 2, image.shape[1] // 2, 2, 4).mean(axis=(1, 3))

    beauty, wire, over = half(layers.beauty), half(layers.wire), half(layers.composite)
    wire_on_checker = composite.alpha_over(wire, checkerboard(*wire.shape[:2]))
    gap = np.ones((beauty.shape[0], 4, 4), dtype=np.float32)
    return np.concatenate([beauty, gap, wire_on_checker, gap, over], axis=1)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=ROOT / "docs")
    parser.add_argument("--samples", type=int, default=48)
    parser.add_argument("--bunny-ratio", type=float, default=0.045, help="decimation ratio of the bunny")
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    solidwire_addon.register()
    try:
        scene = suzanne_scene(args.samples)
        layers = composite.render_wire_over(scene, args.out / "wire_over_suzanne.png", "CYCLES")
        print(f"wrote {args.out / 'wire_over_suzanne.png'}", flush=True)
        save_rgb(scene, layers_strip(layers), args.out / "wire_over_layers.png")
        # The same shot with full-width silhouettes (outer halves of outlines).
        scene.solidwire.use_silhouettes = True
        composite.render_wire_over(scene, args.out / "wire_over_suzanne_silhouettes.png", "CYCLES")
        print(f"wrote {args.out / 'wire_over_suzanne_silhouettes.png'}", flush=True)
        bunny = scenes.MESH_DIR / "bunny.obj"
        if bunny.is_file():
            scene = bunny_scene(args.samples, args.bunny_ratio)
            composite.render_wire_over(scene, args.out / "wire_over_bunny.png", "CYCLES")
            print(f"wrote {args.out / 'wire_over_bunny.png'}", flush=True)
            scene.solidwire.use_silhouettes = True
            composite.render_wire_over(scene, args.out / "wire_over_bunny_silhouettes.png", "CYCLES")
            print(f"wrote {args.out / 'wire_over_bunny_silhouettes.png'}", flush=True)
        else:
            print(f"skipped the bunny: {bunny} is missing (scripts/fetch_meshes.py)", flush=True)
    finally:
        solidwire_addon.unregister()
    return 0


if __name__ == "__main__":
    sys.exit(main())
