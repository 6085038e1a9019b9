"""Dense scenes under the default look, with and without Density Fade, and
the demo scene, which the default must leave as it was: the numbers and the
gallery (docs/dense_scenes.png) behind the Density Fade default.

    .venv/bin/python -m scripts.dense_scenes [-o docs/dense_scenes.png] [--lengths 4 6 8]

Scenes: 1,000 linked UV spheres (Blender's default 32 x 16) about 20 px
across, seen whole; 5,000 geometry-nodes instances of an icosphere receding
from the camera; a NURBS torus at a high resolution; the demo scene of
``scripts/render.py --demo``. Each dense scene is rendered with Density Fade
off and with the default look; the measure is the share of object pixels
whose colour is nearer the wire's than the fill's (line intensity I >= 1/2,
read from the Wire pass). The demo is rendered with Density Fade off and on
at each length asked for, and the images compared pixel by pixel.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

import bpy  # first: importing bpy makes bmesh and mathutils importable

# isort: split
import bmesh
import numpy as np
from mathutils import Vector

import solidwire_addon
from solidwire_addon.blender import engine
from solidwire_addon.blender.gpu_context import ensure_gpu
from solidwire_addon.core import schema

SPHERE_GRID = (40, 25)  # 1,000 spheres
SPHERE_PX = 20.0  # diameter on screen
SPHERE_SPACING = 1.25  # centre distance in diameters
INSTANCE_GRID = (100, 50)  # 5,000 instances
CELL = (480, 300)
WIRE_NEAR = 0.5  # I >= 1/2: the pixel's colour is nearer the wire's than the fill's


def _fresh_scene(width: int, height: int):
    """An empty file whose scene renders with SOLIDWIRE at the add-on's own
    defaults (the look an artist starts from), on a transparent film so
    object pixels can be told from the background."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = "SOLIDWIRE"
    scene.render.resolution_x, scene.render.resolution_y = width, height
    scene.render.resolution_percentage = 100
    scene.render.film_transparent = True
    scene.render.dither_intensity = 0.0
    scene.view_settings.view_transform = "Standard"
    return scene


def _camera(scene, location, target, *, lens=50.0, ortho_scale=None):
    data = bpy.data.cameras.new("Camera")
    data.lens = lens
    data.clip_start, data.clip_end = 0.1, 1000.0
    if ortho_scale is not None:
        data.type = "ORTHO"
        data.ortho_scale = ortho_scale
    camera = bpy.data.objects.new("Camera", data)
    scene.collection.objects.link(camera)
    camera.location = location
    camera.rotation_euler = (Vector(target) - Vector(location)).to_track_quat("-Z", "Y").to_euler()
    scene.camera = camera
    return camera


def sphere_grid(columns: int = SPHERE_GRID[0], rows: int = SPHERE_GRID[1], px: float = SPHERE_PX):
    """``columns`` x ``rows`` linked duplicates of one UV sphere (radius 1,
    Blender's default 32 segments and 16 rings), seen from above by an
    orthographic camera at ``px`` pixels per sphere diameter."""
    pitch = 2.0 * SPHERE_SPACING
    width, height = round(columns * SPHERE_SPACING * px), round(rows * SPHERE_SPACING * px)
    scene = _fresh_scene(width, height)
    mesh = bpy.data.meshes.new("Sphere")
    bm = bmesh.new()
    bmesh.ops.create_uvsphere(bm, u_segments=32, v_segments=16, radius=1.0)
    bm.to_mesh(mesh)
    bm.free()
    mesh.shade_smooth()
    for i in range(columns):
        for j in range(rows):
            obj = bpy.data.objects.new(f"Sphere.{i:02d}.{j:02d}", mesh)
            obj.location = ((i - (columns - 1) / 2) * pitch, (j - (rows - 1) / 2) * pitch, 0.0)
            scene.collection.objects.link(obj)
    # A slight tilt, so the spheres are not all seen pole-on.
    _camera(scene, (0.0, -30.0, 100.0), (0.0, 0.0, 0.0), ortho_scale=columns * pitch)
    scene.camera.data.sensor_fit = "HORIZONTAL"
    return scene


def instances(columns: int = INSTANCE_GRID[0], rows: int = INSTANCE_GRID[1], size=CELL):
    """``columns`` x ``rows`` geometry-nodes instances of an icosphere on a
    grid that recedes from the camera (near ones large, far ones a few px)."""
    scene = _fresh_scene(*size)
    tree = bpy.data.node_groups.new("Instances", "GeometryNodeTree")
    tree.interface.new_socket("Geometry", in_out="INPUT", socket_type="NodeSocketGeometry")
    tree.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
    grid = tree.nodes.new("GeometryNodeMeshGrid")
    grid.inputs["Vertices X"].default_value = columns
    grid.inputs["Vertices Y"].default_value = rows
    grid.inputs["Size X"].default_value = columns * 1.0
    grid.inputs["Size Y"].default_value = rows * 1.0
    ico = tree.nodes.new("GeometryNodeMeshIcoSphere")
    ico.inputs["Radius"].default_value = 0.4
    ico.inputs["Subdivisions"].default_value = 3
    place = tree.nodes.new("GeometryNodeInstanceOnPoints")
    out = tree.nodes.new("NodeGroupOutput")
    tree.links.new(grid.outputs["Mesh"], place.inputs["Points"])
    tree.links.new(ico.outputs["Mesh"], place.inputs["Instance"])
    tree.links.new(place.outputs["Instances"], out.inputs[0])
    obj = bpy.data.objects.new("Instancer", bpy.data.meshes.new("Instancer"))
    scene.collection.objects.link(obj)
    obj.modifiers.new("Instances", "NODES").node_group = tree
    _camera(scene, (0.0, -rows * 0.62, 9.0), (0.0, rows * 0.3, 0.0), lens=30.0)
    return scene


def nurbs_torus(size=CELL, resolution: int = 24):
    """A NURBS torus (Add > Surface > NURBS Torus) at surface resolution
    ``resolution``: about 2 px per face across most of it."""
    scene = _fresh_scene(*size)
    bpy.ops.surface.primitive_nurbs_surface_torus_add()
    torus = bpy.context.active_object
    torus.data.resolution_u = torus.data.resolution_v = resolution
    torus.rotation_euler = (math.radians(50.0), 0.0, math.radians(20.0))
    _camera(scene, (0.0, -5.0, 1.7), (0.0, 0.0, 0.0), lens=50.0)
    return scene


def demo():
    sys.path.insert(0, str(ROOT / "scripts"))
    import demo_scene

    bpy.ops.wm.read_factory_settings(use_empty=True)
    return demo_scene.build()


def render(scene, size=None, **settings):
    """(premultiplied RGBA, object mask) of ``scene`` with ``settings`` over
    its own, bottom row first; the settings are restored afterwards."""
    ensure_gpu()
    # Copies: a colour property reads as a live array.
    before = {name: _plain(getattr(scene.solidwire, name)) for name in settings}
    for name, value in settings.items():
        setattr(scene.solidwire, name, value)
    try:
        depsgraph = scene.view_layers[0].depsgraph  # (the demo is not the context's scene)
        depsgraph.update()
        rgba, depth = engine.render_scene(depsgraph, size)
    finally:
        for name, value in before.items():
            setattr(scene.solidwire, name, value)
    width, height = size or (scene.render.resolution_x, scene.render.resolution_y)
    covered = np.asarray(depth).reshape(height, width) < 1.0e9
    return np.asarray(rgba, dtype=np.float64).reshape(height, width, 4), covered


def _plain(value):
    return tuple(value) if hasattr(value, "__len__") and not isinstance(value, str) else value


def wire_share(scene, size=None, **settings) -> tuple:
    """(share, object pixels, image): the share of object pixels whose colour
    is nearer the wire's than the fill's under ``settings``. The fill alone
    (the same look with a transparent wire) tells how far each pixel went
    towards the wire: colour = fill + w (wire - fill), w = I x opacity, so
    w = |colour - fill| / |wire - fill| (summed over RGB)."""
    image, covered = render(scene, size, **settings)
    look = {"wire_color": tuple(scene.solidwire.wire_color), **settings}
    clear = (*tuple(look["wire_color"])[:3], 0.0)
    fill, _covered = render(scene, size, **{**settings, "wire_color": clear})
    wire = np.asarray(tuple(look["wire_color"])[:3])
    towards = np.abs(image[..., :3] - fill[..., :3]).sum(axis=-1)
    span = np.abs(wire - fill[..., :3]).sum(axis=-1)
    weight = np.where(span > 1e-6, towards / np.maximum(span, 1e-6), 0.0)
    share = float((weight[covered] >= WIRE_NEAR).sum() / max(int(covered.sum()), 1))
    return share, int(covered.sum()), image


def demo_change(lengths) -> list:
    """For each Fade Below length: (length, pixels differing by more than
    half an 8-bit level, largest difference in 8-bit levels) of the demo
    with Fade Dense Objects against the demo without it; and the same for
    per-line Density Fade, which the demo's end-on edges show up in."""
    scene = demo()
    off, _covered = render(scene, use_object_density_fade=False, use_density_fade=False)
    rows = []
    for length in lengths:
        for rule in ("use_object_density_fade", "use_density_fade"):
            on, _covered = render(scene, **{rule: True}, density_fade_length=float(length))
            diff = np.abs(_srgb(on[..., :3]) - _srgb(off[..., :3])) * 255.0
            rows.append((rule, float(length), int((diff.max(axis=-1) > 0.5).sum()), float(diff.max())))
    return rows


def _srgb(linear):
    c = np.clip(linear, 0.0, 1.0)
    return np.where(c <= 0.0031308, c * 12.92, 1.055 * np.power(c, 1 / 2.4) - 0.055)


def _cell(rgba, crop=None):
    """Linear RGB over a mid grey, cropped to CELL around the centre."""
    height, width = rgba.shape[:2]
    cw, ch = CELL
    x0, y0 = max((width - cw) // 2, 0), max((height - ch) // 2, 0)
    part = rgba[y0 : y0 + ch, x0 : x0 + cw]
    background = np.array([0.18, 0.2, 0.23])
    return part[..., :3] + (1.0 - part[..., 3:4]) * background


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-o", "--output", type=Path, default=ROOT / "docs" / "dense_scenes.png")
    parser.add_argument("--lengths", type=float, nargs="*", default=[])
    args = parser.parse_args(argv)
    from scripts import preset_gallery

    solidwire_addon.register()
    try:
        default_length = schema.BY_NAME["density_fade_length"].default
        for rule, length, changed, largest in demo_change(args.lengths or [default_length]):
            print(f"demo, {rule} at {length:g} px: {changed} pixels changed, largest {largest:.2f} levels")
        cells = []
        for label, build in (
            ("1,000 spheres (1:1 crop)", sphere_grid),
            ("5,000 instances", instances),
            ("NURBS torus", nurbs_torus),
        ):
            scene = build()
            for fade in (False, True):
                start = time.perf_counter()
                share, pixels, image = wire_share(scene, use_object_density_fade=fade)
                ms = (time.perf_counter() - start) * 1000.0
                state = "default look" if fade else "Fade Dense Objects off"
                print(
                    f"{label}: {state}: {share:.1%} of {pixels} object pixels near the wire colour "
                    f"(two renders, {ms:.0f} ms)"
                )
                cells.append((f"{label}, {'default' if fade else 'fade off'}: {share:.0%} wire", _cell(image)))
        scene = demo()
        image, _covered = render(scene, size=CELL, use_object_density_fade=False)
        cells.append(("Demo, Fade Dense Objects off", image[..., :3]))
        image, _covered = render(scene, size=CELL)
        cells.append(("Demo, default look (identical)", image[..., :3]))
        preset_gallery.write_sheet(cells, args.output, columns=2, cell=CELL)
    finally:
        solidwire_addon.unregister()
    return 0


if __name__ == "__main__":
    sys.exit(main())
