"""SolidWire: anti-aliased solid wireframe for Blender, computed per fragment
on the filled triangles from the exact window-space distance to each face's
edges.

Data flows one way: scene -> gather / mesh reading -> extract -> GPU cache ->
pass plan -> draw -> targets (render engine, command line, viewport overlay).
``core`` holds the plain-data and GPU side, ``blender`` everything that
faces Blender; the image model is defined in docs/image_model.md.
``register()`` and ``unregister()`` are safe to call repeatedly and leave
nothing behind.
"""

from __future__ import annotations

import atexit

# Importing the package starts nothing: the Blender side is imported by
# register() (and what follows it), so that core's modules without GPU work
# (extraction, edge selection, the schema, the overlay's rules) import and
# are tested in a Python without Blender (tests/pure/).
_registered = False


def _classes() -> tuple:
    """Every class the add-on registers with Blender, in registration order."""
    from .blender import engine, ops, ops_composite, properties, setting_repair, ui

    return (
        *properties.classes,
        *engine.classes,
        *setting_repair.classes,
        *ops.classes,
        *ops_composite.classes,
        *ui.classes,
    )


def register() -> None:
    global _registered
    if _registered:
        return
    import bpy

    from .blender import cli, engine, matcap_files, ops, overlay, properties, ui

    for cls in _classes():
        bpy.utils.register_class(cls)
    properties.register_properties()
    engine.register_compat()
    ui.register_appends()
    ops.register_keymaps()
    overlay.register()
    matcap_files.register()
    cli.register_command()
    atexit.register(_at_exit)
    _registered = True


def unregister() -> None:
    global _registered
    if not _registered:
        return
    import bpy

    from .blender import cli, engine, matcap_files, ops, overlay, properties, ui
    from .core import log

    cli.unregister_command()
    matcap_files.unregister()
    overlay.unregister()
    ops.unregister_keymaps()
    ui.unregister_appends()
    engine.unregister_compat()
    properties.unregister_properties()
    for cls in reversed(_classes()):
        bpy.utils.unregister_class(cls)
    release_gpu()
    atexit.unregister(_at_exit)
    log.forget()
    _registered = False


def _at_exit() -> None:
    """Interpreter exit while registered (the bpy module; Blender itself
    disables add-ons when it quits): unregister as Blender would. A GPU object
    or a draw handler that outlives Blender's GPU context crashes the process
    on exit (exit code 139 after a render, bpy 4.5 and 5.0)."""
    unregister()


def release_gpu() -> None:
    """Free the GPU objects the add-on holds (targets, meshes, quad batches,
    display LUTs). Compiled shader programs are the exception: they live
    until interpreter exit (core/shaders.py says why)."""
    from .blender import color_management, runtime
    from .core import draw, matcaps, strands, targets

    targets.release()
    runtime.release()
    strands.release()
    draw.release_rectangle()
    matcaps.clear()
    color_management.release()


def stats() -> dict:
    """Statistics of the last drawn frame (see docs/user/command-line.md)."""
    from .blender import runtime

    return runtime.stats()
