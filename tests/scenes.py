"""Scene builders and render helpers for tests (and the benchmark).

Every builder starts from an empty file, so tests do not depend on each
other's leftovers. Meshes are built with bmesh (no operator context needed).
"""

from __future__ import annotations

import math
from pathlib import Path

import bmesh
import bpy
import numpy as np
from mathutils import Vector


def empty_scene(width: int = 160, height: int = 120, *, transparent: bool = True, **solidwire):
    """A fresh empty file whose scene renders with SOLIDWIRE at ``width`` x ``height``."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = "SOLIDWIRE"
    scene.render.resolution_x = width
    scene.render.resolution_y = height
    scene.render.resolution_percentage = 100
    scene.render.film_transparent = transparent
    scene.render.dither_intensity = 0.0
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    scene.solidwire.wire_color = (1.0, 1.0, 1.0, 1.0)
    for key, value in solidwire.items():
        setattr(scene.solidwire, key, value)
    return scene


def add_camera(
    scene,
    location=(7.0, -6.0, 5.0),
    target=(0.0, 0.0, 0.0),
    *,
    lens: float = 50.0,
    ortho_scale: float | None = None,
    shift=(0.0, 0.0),
    clip=(0.1, 100.0),
    sensor_fit: str = "AUTO",
    name: str = "Camera",
):
    data = bpy.data.cameras.new(name)
    data.lens = lens
    if ortho_scale is not None:
        data.type = "ORTHO"
        data.ortho_scale = ortho_scale
    data.shift_x, data.shift_y = shift
    data.clip_start, data.clip_end = clip
    data.sensor_fit = sensor_fit
    cam = bpy.data.objects.new(name, data)
    scene.collection.objects.link(cam)
    cam.location = location
    direction = Vector(target) - Vector(location)
    cam.rotation_euler = direction.to_track_quat("-Z", "Y").to_euler()
    scene.camera = cam
    return cam


def mesh_object(scene, name: str, build, *, location=(0, 0, 0), rotation=(0, 0, 0), scale=(1, 1, 1)):
    """Object whose mesh is made by ``build(bm)`` (a bmesh callback)."""
    mesh = bpy.data.meshes.new(name)
    bm = bmesh.new()
    build(bm)
    bm.to_mesh(mesh)
    bm.free()
    obj = bpy.data.objects.new(name, mesh)
    scene.collection.objects.link(obj)
    obj.location, obj.rotation_euler, obj.scale = location, rotation, scale
    return obj


def from_pydata(scene, name: str, verts, faces, **kwargs):
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata([tuple(v) for v in verts], [], [tuple(f) for f in faces])
    mesh.update()
    obj = bpy.data.objects.new(name, mesh)
    scene.collection.objects.link(obj)
    for key, value in kwargs.items():
        setattr(obj, key, value)
    return obj


def cube(scene, name="Cube", size=2.0, **kwargs):
    return mesh_object(scene, name, lambda bm: bmesh.ops.create_cube(bm, size=size), **kwargs)


def monkey(scene, name="Suzanne", subdivisions: int = 0, **kwargs):
    obj = mesh_object(scene, name, lambda bm: bmesh.ops.create_monkey(bm), **kwargs)
    if subdivisions:
        mod = obj.modifiers.new("Subdivision", "SUBSURF")
        mod.levels = mod.render_levels = subdivisions
    return obj


def grid(scene, name="Grid", x_segments=10, y_segments=10, size=10.0, **kwargs):
    return mesh_object(
        scene,
        name,
        lambda bm: bmesh.ops.create_grid(bm, x_segments=x_segments, y_segments=y_segments, size=size),
        **kwargs,
    )


def uv_sphere(scene, name="Sphere", segments=16, rings=8, radius=1.0, **kwargs):
    return mesh_object(
        scene,
        name,
        lambda bm: bmesh.ops.create_uvsphere(bm, u_segments=segments, v_segments=rings, radius=radius),
        **kwargs,
    )


def render_to_file(scene, path: Path, *, depth16: bool = True) -> np.ndarray:
    """Render through the real engine with write_still and read the file back.

    Returns straight RGBA, float64, shape (H, W, 4), bottom row first (window
    row j = array row j)."""
    path = Path(path).resolve()
    path.parent.mkdir(parents=True, exist_ok=True)
    scene.render.filepath = str(path)
    settings = scene.render.image_settings
    settings.file_format = "PNG"
    settings.color_mode = "RGBA"
    settings.color_depth = "16" if depth16 else "8"
    bpy.ops.render.render(write_still=True, scene=scene.name)
    return load_png(path)


def load_png(path: Path) -> np.ndarray:
    image = bpy.data.images.load(str(Path(path).resolve()), check_existing=False)
    # The values as stored in the file (what an outside checker reads):
    # without this Blender decodes 16-bit PNGs to linear floats.
    image.colorspace_settings.name = "Non-Color"
    try:
        width, height = image.size
        pixels = np.empty(width * height * 4, dtype=np.float32)
        image.pixels.foreach_get(pixels)
    finally:
        bpy.data.images.remove(image)
    return pixels.reshape(height, width, 4).astype(np.float64)


def orbit_location(distance: float, azimuth_deg: float, elevation_deg: float):
    az, el = math.radians(azimuth_deg), math.radians(elevation_deg)
    return (
        distance * math.cos(el) * math.cos(az),
        distance * math.cos(el) * math.sin(az),
        distance * math.sin(el),
    )
