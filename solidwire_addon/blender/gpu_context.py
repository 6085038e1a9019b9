"""GPU availability in background mode, handled once for the whole package.

Blender's ``gpu`` module refuses to draw in background mode until the GPU has
been initialised. Rendering through a RenderEngine with
``bl_use_gpu_context = True`` initialises it, after which ``gpu`` works
everywhere in the process. :func:`ensure_gpu` does that with a tiny throwaway
scene rendered by the SOLIDWIRE engine, whose render() returns at once for it.
"""

from __future__ import annotations

import bpy
import gpu

from ..core.ids import ENGINE_ID

INIT_SCENE_NAME = ".solidwire_gpu_init"

_ready = False


def gpu_available() -> bool:
    try:
        gpu.types.GPUOffScreen(1, 1)
    except SystemError:
        return False
    return True


def is_init_scene(scene) -> bool:
    return scene.name == INIT_SCENE_NAME


def ensure_gpu() -> None:
    """Make ``gpu`` usable; a no-op when it already is (UI sessions, repeats)."""
    global _ready
    if _ready:
        return
    if gpu_available():
        _ready = True
        return
    scene = bpy.data.scenes.new(INIT_SCENE_NAME)
    camera_data = bpy.data.cameras.new(INIT_SCENE_NAME)
    camera = bpy.data.objects.new(INIT_SCENE_NAME, camera_data)
    try:
        scene.collection.objects.link(camera)
        scene.camera = camera
        scene.render.engine = ENGINE_ID
        scene.render.resolution_x = scene.render.resolution_y = 4
        scene.render.resolution_percentage = 100
        bpy.ops.render.render(scene=scene.name)
    finally:
        bpy.data.objects.remove(camera)
        bpy.data.cameras.remove(camera_data)
        bpy.data.scenes.remove(scene)
    if not gpu_available():
        raise RuntimeError("SolidWire could not initialise the GPU in background mode")
    _ready = True
