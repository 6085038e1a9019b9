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

# The look of the image model's sections 1.2-1.4 (no shading, no colour
# sources, no fill): what the accuracy tests measure unless they ask for more.
CORE_LOOK = dict(
    use_fill=False,
    fill_shading="FLAT",
    fill_color=(1.0, 1.0, 1.0),
    fill_color_source="SINGLE",
    wire_color_source="SINGLE",
    use_cage_edges=False,
    use_object_density_fade=False,
)


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
    # Tests measure the core image model (wire only, flat fill, every
    # evaluated edge): the add-on's friendlier defaults (shaded fill, cage
    # edges) are set explicitly off.
    for key, value in CORE_LOOK.items():
        setattr(scene.solidwire, key, value)
    for key, value in solidwire.items():
        setattr(scene.solidwire, key, value)
    return scene


def default_look(scene):
    """Back to the add-on's own defaults for what CORE_LOOK switches off (a
    Studio-shaded fill, cage edges, Fade Dense Objects): the look a user
    starts from."""
    for key in CORE_LOOK:
        scene.solidwire.property_unset(key)
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


def tube(scene, name="Tube", segments=16, radius=1.0, depth=2.0, *, top_radius=None, caps=True, **kwargs):
    """A cylinder (a cone where ``top_radius`` differs) of ``segments``
    sides whose caps (``caps``) are single n-gons."""
    top = radius if top_radius is None else top_radius

    def build(bm):
        bmesh.ops.create_cone(
            bm, cap_ends=caps, cap_tris=False, segments=segments, radius1=radius, radius2=top, depth=depth
        )

    return mesh_object(scene, name, build, **kwargs)


def grid(scene, name="Grid", x_segments=10, y_segments=10, size=10.0, **kwargs):
    return mesh_object(
        scene,
        name,
        lambda bm: bmesh.ops.create_grid(bm, x_segments=x_segments, y_segments=y_segments, size=size),
        **kwargs,
    )


def add_swell_shape_key(obj, frames: tuple, strength: float = 1.0):
    """A shape key that swells ``obj`` towards +z and twists it about z,
    animated from 0 at ``frames[0]`` to 1 at ``frames[1]`` (every vertex
    moves and the corner normals turn: a deforming animation)."""
    obj.shape_key_add(name="Basis")
    key = obj.shape_key_add(name="Swell")
    count = len(obj.data.vertices)
    basis = np.empty(count * 3, np.float32)
    obj.data.vertices.foreach_get("co", basis)
    basis = basis.reshape(-1, 3).astype(np.float64)
    angle = 0.6 * strength * basis[:, 2]
    swollen = basis * (1.0 + 0.25 * strength * basis[:, 2:3])
    x, y = swollen[:, 0].copy(), swollen[:, 1].copy()
    swollen[:, 0] = x * np.cos(angle) - y * np.sin(angle)
    swollen[:, 1] = x * np.sin(angle) + y * np.cos(angle)
    key.data.foreach_set("co", swollen.astype(np.float32).ravel())
    for frame, value in zip(frames, (0.0, 1.0)):
        key.value = value
        key.keyframe_insert("value", frame=frame)
    return key


def add_bend_rig(scene, obj, frames: tuple, *, joint_z: float = 0.0, blend: float = 0.5, angle_deg: float = 60.0):
    """A two-bone armature bending ``obj`` at height ``joint_z`` (its own
    space): vertices above the joint follow the upper bone, below it the
    lower one, blended over ``blend`` either side. The upper bone turns
    about x from 0 at ``frames[0]`` to ``angle_deg`` at ``frames[1]``."""
    mesh = obj.data
    count = len(mesh.vertices)
    co = np.empty(count * 3, np.float32)
    mesh.vertices.foreach_get("co", co)
    z = co.reshape(-1, 3)[:, 2].astype(np.float64)
    low, high = float(z.min()), float(z.max())

    armature = bpy.data.armatures.new(f"{obj.name}Rig")
    rig = bpy.data.objects.new(f"{obj.name}Rig", armature)
    scene.collection.objects.link(rig)
    rig.matrix_world = obj.matrix_world  # the bones in the mesh's own space
    bpy.context.view_layer.objects.active = rig
    bpy.ops.object.mode_set(mode="EDIT")
    lower = armature.edit_bones.new("Lower")
    lower.head, lower.tail = (0.0, 0.0, low), (0.0, 0.0, joint_z)
    upper = armature.edit_bones.new("Upper")
    upper.head, upper.tail = (0.0, 0.0, joint_z), (0.0, 0.0, max(high, joint_z + 0.1))
    upper.parent = lower
    bpy.ops.object.mode_set(mode="OBJECT")

    # Weights in fine steps (one vertex-group call per step, not per vertex):
    # coarse steps would shear the small faces they cut across, folding them.
    levels = 2000
    steps = np.round(np.clip((z - joint_z + blend) / (2.0 * blend), 0.0, 1.0) * levels).astype(int)
    groups = {name: obj.vertex_groups.new(name=name) for name in ("Lower", "Upper")}
    order = np.argsort(steps, kind="stable")
    values, first = np.unique(steps[order], return_index=True)
    for step, ids in zip(values.tolist(), np.split(order, first[1:])):
        groups["Upper"].add(ids.tolist(), step / levels, "REPLACE")
        groups["Lower"].add(ids.tolist(), 1.0 - step / levels, "REPLACE")
    obj.modifiers.new("Armature", "ARMATURE").object = rig
    obj.modifiers.move(len(obj.modifiers) - 1, 0)  # before any subdivision
    bone = rig.pose.bones["Upper"]
    bone.rotation_mode = "XYZ"
    for frame, angle in zip(frames, (0.0, math.radians(angle_deg))):
        bone.rotation_euler = (angle, 0.0, 0.0)
        bone.keyframe_insert("rotation_euler", frame=frame)
    return rig


def add_mirror_and_array(obj, *, merge: bool = False, count: int = 2, offset=None):
    """A Mirror (merging its halves or not) then an Array of ``count``
    copies that merges nothing, after whatever ``obj`` already has: the
    modifiers Blender's overlay keeps the cage through unless they merge."""
    obj.modifiers.new("Mirror", "MIRROR").use_mirror_merge = merge
    array = obj.modifiers.new("Array", "ARRAY")
    array.count = count
    array.use_merge_vertices = False
    if offset is not None:
        array.relative_offset_displace = offset
    return array


def uv_sphere(scene, name="Sphere", segments=16, rings=8, radius=1.0, **kwargs):
    return mesh_object(
        scene,
        name,
        lambda bm: bmesh.ops.create_uvsphere(bm, u_segments=segments, v_segments=rings, radius=radius),
        **kwargs,
    )


def enable_freestyle(scene, on: bool = True) -> None:
    """Freestyle on (or off) for the scene and its first view layer. An empty
    factory file's line set has no line style, and Freestyle then draws
    nothing (an error inside its own script): it gets a new default one."""
    scene.render.use_freestyle = on
    if not on:
        return
    view_layer = scene.view_layers[0]
    view_layer.use_freestyle = True
    settings = view_layer.freestyle_settings
    lineset = settings.linesets.active or settings.linesets.new("LineSet")
    if lineset.linestyle is None:
        lineset.linestyle = bpy.data.linestyles.new("LineStyle")


def render_still(scene, path: Path, **image_settings) -> Path:
    """Render ``scene`` through the real engine with write_still to ``path``
    (its folder made), with these image settings applied in order."""
    path = Path(path).resolve()
    path.parent.mkdir(parents=True, exist_ok=True)
    scene.render.filepath = str(path)
    settings = scene.render.image_settings
    for name, value in image_settings.items():
        setattr(settings, name, value)
    bpy.ops.render.render(write_still=True, scene=scene.name)
    return path


def render_to_file(scene, path: Path, *, depth16: bool = True) -> np.ndarray:
    """Render through the real engine with write_still and read the file back.

    Returns straight RGBA, float64, shape (H, W, 4), bottom row first (window
    row j = array row j)."""
    path = render_still(scene, path, file_format="PNG", color_mode="RGBA", color_depth="16" if depth16 else "8")
    return load_png(path)


def render_multilayer_exr(scene, path: Path) -> dict:
    """Render to an uncompressed float multilayer EXR (every view layer and
    pass Blender writes) and read it back: {channel name: (H, W) float32}."""
    # Imported here: this module is also used by a process that must only
    # see the installed extension (tests/test_packaging.py).
    from solidwire_addon.core import compat, exr

    compat.set_media_type(scene.render.image_settings, "MULTI_LAYER_IMAGE")  # Blender 5; no-op on 4.x
    scene.render.use_file_extension = False
    path = render_still(scene, path, file_format="OPEN_EXR_MULTILAYER", color_depth="32", exr_codec="NONE")
    return exr.read_exr(path)


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


# ------------------------------------------------ benchmark and stress scenes
#
# Shared by scripts/bench/ (at 1280 x 720) and tests/test_stress.py (small).
# Each builder adds objects and a camera to a scene made by empty_scene() and
# returns the objects that the benchmark turns (empty: the scene stays still).

MESH_DIR = Path(__file__).resolve().parent.parent / "cache" / "meshes"


def load_obj(scene, name: str, path: Path, **kwargs):
    """A triangle/polygon OBJ (``v`` and ``f`` lines only) as a mesh object."""
    verts, faces = [], []
    with open(path, encoding="ascii", errors="replace") as source:
        for line in source:
            if line.startswith("v "):
                verts.append(tuple(float(c) for c in line.split()[1:4]))
            elif line.startswith("f "):
                faces.append(tuple(int(c.split("/")[0]) - 1 for c in line.split()[1:]))
    return from_pydata(scene, name, verts, faces, **kwargs)


def frame_object(scene, obj, *, lens: float = 50.0, azimuth: float = -60.0, elevation: float = 20.0, fill: float = 1.6):
    """Camera looking at ``obj``'s bounding-box sphere, ``fill`` times that
    sphere's radius per half frame height (the sphere is loose around these
    meshes: 1.6 makes them fill most of the frame, as in the papers' views)."""
    from mathutils import Vector

    corners = [obj.matrix_world @ Vector(c) for c in obj.bound_box]
    centre = sum(corners, Vector()) / 8.0
    radius = max((c - centre).length for c in corners)
    sensor = 36.0
    r = scene.render
    half_fov = math.atan(0.5 * sensor * min(r.resolution_y / r.resolution_x, 1.0) / lens)
    distance = radius / math.sin(half_fov) / fill
    location = Vector(orbit_location(distance, azimuth, elevation)) + centre
    return add_camera(
        scene, location=tuple(location), target=tuple(centre), lens=lens, clip=(distance * 0.01, distance * 10.0)
    )


def teapot_scene(scene):
    obj = load_obj(scene, "Teapot", MESH_DIR / "teapot.obj")
    frame_object(scene, obj)
    return [obj]


def bunny_scene(scene):
    # glmark2's bunny is y-up; Blender is z-up.
    obj = load_obj(scene, "Bunny", MESH_DIR / "bunny.obj", rotation_euler=(math.pi / 2, 0.0, 0.0))
    bpy.context.view_layer.update()
    frame_object(scene, obj)
    return [obj]


def suzanne_1m_scene(scene):
    # Suzanne at subdivision level 5: 1,007,616 triangles (stands in for the
    # papers' 1.09M-triangle Buddha).
    obj = monkey(scene, "Suzanne5", subdivisions=5)
    frame_object(scene, obj, azimuth=-75.0)
    return [obj]


def near_plane_scene(scene):
    # A floor and a wall of big quads running past and behind a camera close
    # to the floor: triangles with corners behind the viewpoint whose other
    # corners project thousands of pixels away (the NVIDIA "tricky case" and
    # the float32 cancellation the Kakadu article analyses).
    grid(scene, "Floor", x_segments=4, y_segments=4, size=40.0, location=(0, 0, 0), rotation=(0, 0, 0.3))
    grid(scene, "Wall", x_segments=4, y_segments=2, size=40.0, location=(-3, 0, 0), rotation=(0, math.pi / 2, 0.0))
    monkey(scene, location=(0.5, 6.0, 1.0))
    add_camera(scene, location=(0.4, -1.0, 0.5), target=(-1.0, 6.0, 0.6), lens=18.0, clip=(0.05, 300.0))
    return []


# Three corners, the first far behind the camera of add_clipped_corners_camera
# (near clip 0.01): the edges from it cross the near plane and end some
# 10^5 px off-screen, where float32 window points round by about 0.01 px.
CORNERS_THROUGH_THE_NEAR_PLANE = [(-27.54, -0.19, 27.06), (1.297, -0.0365, -0.5913), (0.6522, -0.1639, 1.5426)]


def add_clipped_corners_camera(scene):
    """The camera of CORNERS_THROUGH_THE_NEAR_PLANE (found by the fuzz)."""
    return add_camera(
        scene,
        location=(-0.119, -1.123, 0.960),
        target=(0.0, 0.0, 0.915),
        lens=84.5,
        shift=(-0.09, -0.18),
        clip=(0.01, 100.0),
    )


def far_scene(offset: float):
    def build(scene):
        monkey(scene, subdivisions=1, location=(offset, offset, 0.0))
        add_camera(scene, location=(offset + 3.0, offset - 3.0, 1.5), target=(offset, offset, 0.0))
        return []

    return build


def slivers_scene(scene):
    # 100 columns of two triangles each, 100 units long and 0.01 wide:
    # aspect 1e4, about 1.3 px wide and ~1e4 px long on screen, tilted.
    n, length, width = 100, 100.0, 0.01
    verts, faces = [], []
    for i in range(n):
        x0 = (i - n / 2) * width
        base = len(verts)
        verts += [
            (x0, -length / 2, 0.0),
            (x0 + width, -length / 2, 0.0),
            (x0 + width, length / 2, 0.0),
            (x0, length / 2, 0.0),
        ]
        faces += [(base, base + 1, base + 2), (base, base + 2, base + 3)]
    from_pydata(scene, "Slivers", verts, faces, rotation_euler=(0.0, 0.0, 0.5))
    add_camera(scene, location=(0.0, -0.5, 9.0), target=(0.0, 0.0, 0.0), lens=50.0)
    return []


def subpixel_scene(scene):
    # Suzanne at level 3 (~63k triangles) about 150 px wide: most triangles
    # are smaller than a pixel.
    monkey(scene, subdivisions=3)
    add_camera(scene, location=(0.0, -30.0, 4.0), target=(0.0, 0.0, 0.0), lens=50.0)
    return []


def ortho_scene(scene):
    monkey(scene, subdivisions=2, rotation=(0.3, 0.0, 0.6))
    cube(scene, location=(2.5, 0.5, -0.5), size=1.0)
    add_camera(scene, location=(6, -6, 4), target=(0, 0, 0), ortho_scale=6.0, shift=(0.1, -0.05))
    return []


def lens_6mm_scene(scene):
    # Inside a room with a 6 mm lens: extreme perspective, faces all around
    # and behind the camera.
    cube(scene, "Room", size=8.0)
    uv_sphere(scene, location=(1.0, 2.0, -1.5), radius=1.0, segments=32, rings=16)
    monkey(scene, location=(-1.5, 2.5, 0.5), subdivisions=1)
    add_camera(scene, location=(0.3, -2.5, 0.4), target=(0.0, 2.5, -0.2), lens=6.0, clip=(0.05, 50.0))
    return []


MESH_SCENES = {"teapot": teapot_scene, "bunny": bunny_scene, "suzanne_1m": suzanne_1m_scene}
MESH_FILES = {"teapot": MESH_DIR / "teapot.obj", "bunny": MESH_DIR / "bunny.obj"}
STRESS_SCENES = {
    "near_plane": near_plane_scene,
    "far_1e5": far_scene(1e5),
    "far_1e6": far_scene(1e6),
    "slivers": slivers_scene,
    "subpixel": subpixel_scene,
    "ortho": ortho_scene,
    "lens_6mm": lens_6mm_scene,
}
