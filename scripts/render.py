"""The SolidWire command line for a repository checkout (the installed
extension offers the same as ``blender -c solidwire render``):

    python scripts/render.py SCENE.blend [-o OUT.png] [options]          (bpy module)
    blender -b SCENE.blend --python scripts/render.py -- [options]

Every option is the extension's (solidwire_addon/blender/cli.py; ``--help``
lists them). This wrapper adds ``--demo`` (render scripts/demo_scene.py's
scene instead of a file) and uses the installed, enabled extension when
Blender has one, else this repository's package, registered for the run.
"""

from __future__ import annotations

import atexit
import importlib
import os
import runpy
import sys
from pathlib import Path

import bpy

SCRIPT_DIR = Path(__file__).resolve().parent
REPO_ROOT = SCRIPT_DIR.parent
ENGINE_ID = "SOLIDWIRE"


def script_arguments(argv: list[str]) -> list[str]:
    """The arguments meant for this script.

    Inside the Blender executable everything before ``--`` belongs to
    Blender; with the bpy module, Python's own argv is ours. (The bpy module
    leaves ``bpy.app.binary_path`` empty.)"""
    if bpy.app.binary_path:
        return argv[argv.index("--") + 1 :] if "--" in argv else []
    return argv[1:]


def ensure_addon():
    """(package, registered_here): the installed, enabled extension if there
    is one (Blender registered it at start-up), else this repository's
    package, registered now."""
    for cls in bpy.types.RenderEngine.__subclasses__():
        # A disabled add-on's class object lives on (its module still holds
        # it), so registration is checked, not existence.
        if getattr(cls, "bl_idname", None) == ENGINE_ID and getattr(cls, "is_registered", False):
            # e.g. bl_ext.user_default.solidwire.solidwire_addon.blender.engine -> ...solidwire_addon
            return importlib.import_module(cls.__module__.rsplit(".", 2)[0]), False
    if str(REPO_ROOT) not in sys.path:
        sys.path.insert(0, str(REPO_ROOT))
    import solidwire_addon

    solidwire_addon.register()
    return solidwire_addon, True


def build_demo():
    return runpy.run_path(str(SCRIPT_DIR / "demo_scene.py"))["build"]()


def main(argv: list[str]) -> int:
    arguments = script_arguments(argv)
    demo = "--demo" in arguments
    if demo:
        arguments = [a for a in arguments if a != "--demo"]
    addon, registered_here = ensure_addon()
    cli = importlib.import_module(addon.__name__ + ".blender.cli")
    try:
        return cli.main(arguments, prog="scripts/render.py", build_demo=build_demo if demo else None)
    finally:
        if registered_here:
            # Release GPU resources while the GPU still exists: nothing else
            # unregisters a package registered by hand, and freeing them at
            # interpreter exit crashes the process after the image is written.
            addon.unregister()


# The bpy module before 5.0 does not always leave cleanly (upstream bugs,
# reproduced without SolidWire): 4.2 crashes at interpreter exit once any
# property with an update callback was registered, and 4.5 can hang there
# for good, in the destructor of its audio device's closing thread, which
# its shutdown did not stop (every time while any Python thread is still
# alive; the command line's own signal watcher is joined before it returns,
# but the hang was also seen once without it). The image is written and the
# exit code decided, so the wrapper leaves without Python's finalisation there.
# The bpy module is told apart from Blender itself by its modules: Blender
# builds mathutils into its executable, the bpy module loads it as an
# extension (bpy.app.binary_path cannot tell: tests simulate Blender with it).
_EXIT_UNRELIABLE = "mathutils" not in sys.builtin_module_names and bpy.app.version < (5, 0, 0)


def _leave_without_finalising(code: int) -> None:
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(code)


def _run(argv: list[str]) -> int:
    # The command line handles SIGINT itself once it runs; before that (while
    # the add-on registers) Ctrl+C still ends the run with one line.
    try:
        return main(argv)
    except KeyboardInterrupt:
        print("solidwire: stopped by SIGINT", file=sys.stderr, flush=True)
        return 130


if __name__ == "__main__":
    code = _run(sys.argv)
    if _EXIT_UNRELIABLE:
        # At exit, not now: a caller that ran this script (runpy) goes on first.
        atexit.register(_leave_without_finalising, code)
    # Inside Blender a script that returns lets Blender exit 0, so a failure
    # must leave through SystemExit; with the bpy module the same is harmless.
    if code:
        sys.exit(code)
