"""SolidWire: anti-aliased solid wireframe for Blender, computed per fragment
on the filled triangles from the exact window-space distance to each face's
edges.

Data flows one way: scene -> gather/extract -> GPU cache -> draw -> targets
(render engine, command line; viewport overlay). ``register()`` and
``unregister()`` are safe to call repeatedly and leave nothing behind.
"""

from __future__ import annotations

import bpy

from . import engine, log, offscreen, runtime, settings, shaders

_classes = (*settings.classes, *engine.classes)
_registered = False


def register() -> None:
    global _registered
    if _registered:
        return
    for cls in _classes:
        bpy.utils.register_class(cls)
    settings.register_properties()
    engine.register_compat()
    _registered = True


def unregister() -> None:
    global _registered
    if not _registered:
        return
    engine.unregister_compat()
    settings.unregister_properties()
    for cls in reversed(_classes):
        bpy.utils.unregister_class(cls)
    offscreen.release()
    runtime.release()
    shaders.clear()
    log.forget()
    _registered = False


def stats() -> dict:
    """Statistics of the last drawn frame (SPEC section 2)."""
    return runtime.stats()
