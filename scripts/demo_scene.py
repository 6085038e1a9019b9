"""The built-in demo scene of ``scripts/render.py --demo``.

A small still life that shows what SolidWire draws: Suzanne with a
subdivision modifier (quads), a torus (quads), a cylinder with 16-sided
n-gon caps, a bevelled cube (quads, triangles and n-gons after the
modifier) and a floor grid, in fill mode (studio-lit) with dotted diagonals so the
triangulation of quads and n-gons is visible but quieter than the real edges.

The scene is built in a new scene of the current file with bmesh and
modifiers only (no operators, no file reset), so it works the same in the bpy
module and inside ``blender -b`` with the extension installed and enabled.
"""

from __future__ import annotations

import math

import bmesh
import bpy
from mathutils import Vector

SCENE_NAME = "SolidWire Demo"
RESOLUTION = (960, 540)

# Colours are linear (scene-referred); the Standard view transform shows them
# as written.
WORLD_COLOR = (0.30, 0.36, 0.45)
FILL_COLOR = (0.93, 0.91, 0.86)
WIRE_COLOR = (0.045, 0.05, 0.07, 1.0)


def _object(scene, name: str, build, *, location=(0, 0, 0), rotation=(0, 0, 0), scale=(1, 1, 1)):
    mesh = bpy.data.meshes.new(name)
    bm = bmesh.new()
    build(bm)
    bm.to_mesh(mesh)
    bm.free()
    obj = bpy.data.objects.new(name, mesh)
    scene.collection.objects.link(obj)
    obj.location = location
    obj.rotation_euler = rotation
    obj.scale = scale
    return obj


def _torus(bm, major_radius=1.0, minor_radius=0.32, major_segments=32, minor_segments=12) -> None:
    rings = []
    for i in range(major_segments):
        u = 2.0 * math.pi * i / major_segments
        ring = []
        for j in range(minor_segments):
            v = 2.0 * math.pi * j / minor_segments
            radius = major_radius + minor_radius * math.cos(v)
            ring.append(bm.verts.new((radius * math.cos(u), radius * math.sin(u), minor_radius * math.sin(v))))
        rings.append(ring)
    for i in range(major_segments):
        a, b = rings[i], rings[(i + 1) % major_segments]
        for j in range(minor_segments):
            k = (j + 1) % minor_segments
            bm.faces.new((a[j], b[j], b[k], a[k]))


def _add_camera(scene, location, target, lens):
    data = bpy.data.cameras.new("Demo Camera")
    data.lens = lens
    data.clip_start, data.clip_end = 0.1, 100.0
    camera = bpy.data.objects.new("Demo Camera", data)
    scene.collection.objects.link(camera)
    camera.location = location
    direction = Vector(target) - Vector(location)
    camera.rotation_euler = direction.to_track_quat("-Z", "Y").to_euler()
    scene.camera = camera
    return camera


def build(name: str = SCENE_NAME):
    """Create the demo scene (a new scene each call) and return it."""
    scene = bpy.data.scenes.new(name)
    render = scene.render
    render.engine = "SOLIDWIRE"
    render.resolution_x, render.resolution_y = RESOLUTION
    render.resolution_percentage = 100
    render.film_transparent = False
    render.dither_intensity = 0.0
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"

    world = bpy.data.worlds.new(name)
    world.color = WORLD_COLOR
    scene.world = world

    look = scene.solidwire
    look.use_fill = True
    look.fill_shading = "STUDIO"
    look.fill_color = FILL_COLOR
    look.wire_color = WIRE_COLOR
    look.thickness = 1.1
    look.softness = 1.0
    look.diagonal_mode = "DOTTED"
    look.pattern_period = 6.0
    look.pattern_duty = 0.3

    suzanne = _object(
        scene,
        "Suzanne",
        lambda bm: bmesh.ops.create_monkey(bm),
        location=(0.0, 0.3, 0.45),
        rotation=(math.radians(-12), 0.0, math.radians(18)),
        scale=(1.3, 1.3, 1.3),
    )
    subdivision = suzanne.modifiers.new("Subdivision", "SUBSURF")
    subdivision.levels = subdivision.render_levels = 1
    suzanne.data.shade_smooth()  # the studio-lit fill follows Blender's smooth normals

    torus = _object(
        scene,
        "Torus",
        _torus,
        location=(-2.45, -0.6, -0.25),
        rotation=(math.radians(58), 0.0, math.radians(-25)),
        scale=(0.8, 0.8, 0.8),
    )
    torus.data.shade_smooth()

    def cylinder(bm):
        bmesh.ops.create_cone(
            bm,
            cap_ends=True,
            cap_tris=False,
            segments=16,
            radius1=0.65,
            radius2=0.65,
            depth=1.6,
        )

    _object(scene, "Cylinder", cylinder, location=(2.5, 1.2, -0.2), rotation=(0.0, 0.0, math.radians(10)))

    cube = _object(
        scene,
        "Bevelled Cube",
        lambda bm: bmesh.ops.create_cube(bm, size=1.1),
        location=(1.85, -1.35, -0.45),
        rotation=(0.0, 0.0, math.radians(28)),
    )
    bevel = cube.modifiers.new("Bevel", "BEVEL")
    bevel.width = 0.14
    bevel.segments = 2

    _add_camera(scene, location=(1.0, -9.5, 2.7), target=(0.15, 0.0, -0.1), lens=40.0)
    return scene
