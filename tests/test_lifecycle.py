"""Lifecycle: register/unregister leaves nothing behind
(measured: classes, properties, handlers, draw handler, keymaps, timers,
panel appends, exit hooks, GPU objects); the add-on keeps no Blender data; the
overlay survives file load, undo, deletion, scene switch and renders."""

from __future__ import annotations

import gc
import os
import subprocess
import sys
import textwrap
import types
from pathlib import Path

import bpy
import numpy as np
import pytest

import solidwire_addon
from solidwire_addon.blender import ops, overlay, runtime, ui
from solidwire_addon.blender.gpu_context import ensure_gpu
from solidwire_addon.core import log
from tests.support import robustness, scenes

ROOT = Path(__file__).resolve().parent.parent


def _handler_lists():
    for name in dir(bpy.app.handlers):
        value = getattr(bpy.app.handlers, name)
        if isinstance(value, list):
            yield name, value


def _ours(func) -> bool:
    return getattr(func, "__module__", "").startswith("solidwire_addon")


def _addon_functions():
    for module in robustness.addon_modules():
        for value in vars(module).values():
            if isinstance(value, types.FunctionType) and _ours(value):
                yield value


def leftovers() -> dict:
    """Everything the add-on can leave in Blender or in its own module state,
    by kind; empty lists when nothing is there."""
    keyconfig = bpy.context.window_manager.keyconfigs.addon
    keymap_items = []
    if keyconfig is not None:
        for keymap in keyconfig.keymaps:
            keymap_items += [
                f"{keymap.name}:{k.idname}" for k in keymap.keymap_items if k.idname.startswith("solidwire.")
            ]
    compat = []
    for name in dir(bpy.types):
        engines = getattr(getattr(bpy.types, name, None), "COMPAT_ENGINES", None)
        if isinstance(engines, set) and "SOLIDWIRE" in engines:
            compat.append(name)
    return {
        "classes": [c.__name__ for c in solidwire_addon._classes() if c.is_registered],
        "bpy.types": [n for n in dir(bpy.types) if "solidwire" in n.lower()],
        "properties": [
            f"{t.__name__}.{p}"
            for t in (bpy.types.Scene, bpy.types.Object, bpy.types.WindowManager, bpy.types.ViewLayer)
            for p in t.bl_rna.properties.keys()  # noqa: SIM118  (iterating the collection gives properties, not names)
            if "solidwire" in p
        ],
        "app handlers": [f"{name}:{f.__name__}" for name, funcs in _handler_lists() for f in funcs if _ours(f)],
        "draw handler": [overlay._handle] if overlay._handle is not None else [],
        "keymap items": keymap_items + [repr(k) for k in ops._keymap_items],
        "panel appends": [
            f for p in ("VIEW3D_PT_overlay", "OBJECT_PT_visibility") for f in ui.appended_draw_functions(p)
        ],
        "compat panels": compat,
        "timers": [f.__name__ for f in _addon_functions() if bpy.app.timers.is_registered(f)],
        "exit hook": ["_at_exit"] if _exit_hook_registered() else [],
        "GPU objects": [
            path
            for path in robustness.scan_module_state(robustness.is_gpu_object)
            if not path.startswith(SHADER_PROGRAMS)
        ],
        "messages said": list(log._said),
    }


# The one documented exception: compiled shader programs live for the whole
# process and are freed at interpreter exit (solidwire_addon/core/shaders.py
# says why: freeing them while another GL context used them crashed llvmpipe).
SHADER_PROGRAMS = ("solidwire_addon.core.shaders._cache",)


def _exit_hook_registered() -> bool:
    """atexit cannot be listed (and its C array is invisible to gc): the
    exit hook's reference count says whether atexit holds it. Unregistered,
    only the package namespace and getrefcount's own argument refer to it."""
    return sys.getrefcount(solidwire_addon._at_exit) > 2


def _measure() -> dict:
    return leftovers()


def _render_small(path):
    scene = scenes.empty_scene(48, 36, show_overlay=True)
    scenes.cube(scene)
    scenes.add_camera(scene)
    robustness.render_exr(scene, path)
    return scene


def _rss_mb() -> float:
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2**20


# ------------------------------------------------------- register cycles


def test_registered_state_is_measurable(output_dir):
    """The measurement sees what a registered, used add-on holds (so the
    'nothing left' checks below can fail)."""
    _render_small(output_dir / "lifecycle_probe.exr")
    state = _measure()
    for kind in (
        "classes",
        "bpy.types",
        "properties",
        "app handlers",
        "draw handler",
        "panel appends",
        "compat panels",
        "exit hook",
        "GPU objects",
    ):
        assert state[kind], f"cannot see {kind} while registered: {state}"


def test_100_register_cycles_leave_nothing_behind(tmp_path):
    solidwire_addon.unregister()
    try:
        clean = _measure()
        assert not any(clean.values()), clean
        rss = []
        for cycle in range(100):
            solidwire_addon.register()
            if cycle % 10 == 0:
                # Use it: shaders, meshes, targets, handlers, messages.
                _render_small(tmp_path / "cycle.exr")
                ensure_gpu()
                robustness.Viewport().draw(bpy.context.scene)
                log.warn_once(("lifecycle", cycle), "SolidWire: (lifecycle test message)")
            solidwire_addon.unregister()
            if cycle in (10, 99):
                gc.collect()
                rss.append(_rss_mb())
            state = _measure()
            assert not any(state.values()), f"after cycle {cycle}: {state}"
        print(f"RSS after cycle 10: {rss[0]:.1f} MB, after cycle 99: {rss[1]:.1f} MB")
        assert rss[1] - rss[0] < 40.0, rss
    finally:
        solidwire_addon.register()


def test_register_and_unregister_are_idempotent():
    solidwire_addon.register()
    solidwire_addon.register()
    assert overlay.is_registered()
    solidwire_addon.unregister()
    solidwire_addon.unregister()
    try:
        assert not any(_measure().values())
    finally:
        solidwire_addon.register()


@pytest.mark.parametrize("unregistered", [False, True], ids=["registered", "unregistered"])
def test_process_exits_cleanly_after_rendering(tmp_path, unregistered):
    """Blender tears its GPU context down at exit; a GPU object of ours still
    alive then crashed the process (exit code 139) after writing the image.
    On bpy 4.2 a callback Blender never frees crashed it too, registered or
    not (blender/properties.py's stand-ins)."""
    script = f"""
        import sys; sys.path[:0] = [{str(ROOT)!r}]
        import bpy, solidwire_addon
        from tests.support import scenes, robustness
        solidwire_addon.register()
        scene = scenes.empty_scene(32, 24); scenes.cube(scene); scenes.add_camera(scene)
        robustness.render_exr(scene, {str(tmp_path / "exit.exr")!r})
        if {unregistered!r}:
            solidwire_addon.unregister()
        print("RENDERED")
    """
    env = dict(os.environ, BLENDER_USER_RESOURCES=str(tmp_path / "user"))
    result = subprocess.run(
        [sys.executable, "-c", textwrap.dedent(script)],
        capture_output=True,
        text=True,
        timeout=300,
        env=env,
        check=False,
    )
    assert "RENDERED" in result.stdout
    assert result.returncode == 0, result.stderr[-2000:]


# --------------------------------------------------- no Blender data held


def test_addon_state_holds_no_blender_data(output_dir):
    """Module state holds no bpy_struct (a stale one crashes after undo or
    file load), except the keymap items Blender asks add-ons to keep."""
    scene = _render_small(output_dir / "no_blender_data.exr")
    ensure_gpu()
    robustness.Viewport().draw(scene)
    held = [p for p in robustness.scan_module_state(robustness.is_blender_data) if "_keymap_items" not in p]
    assert held == []


def test_handlers_are_persistent_and_hold_no_blender_data(output_dir):
    _render_small(output_dir / "handlers.exr")
    ours = [(name, f) for name, funcs in _handler_lists() for f in funcs if _ours(f)]
    assert ours, "expected the cache invalidation handlers after a render"
    for name, func in ours:
        assert hasattr(func, "_bpy_persistent"), f"{name}:{func.__name__} is dropped by a file load"
        captured = list(func.__defaults__ or ()) + [c.cell_contents for c in (func.__closure__ or ())]
        assert not any(isinstance(v, bpy.types.bpy_struct) for v in captured), (name, func)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    after = [(name, f) for name, funcs in _handler_lists() for f in funcs if _ours(f)]
    assert after == ours


# ---------------------------------------------------------------- overlay


def _overlay_scene():
    scene = scenes.empty_scene(64, 48, show_overlay=True)
    keep = scenes.cube(scene, "Keep", size=1.2, location=(-1.2, 0, 0))
    gone = scenes.monkey(scene, "Gone", location=(1.3, 0, 0))
    scenes.add_camera(scene, location=(0.0, -7.0, 1.0), target=(0, 0, 0))
    return scene, keep, gone


def test_overlay_handler_headless_is_quiet(capfd):
    _overlay_scene()
    capfd.readouterr()
    overlay._draw_callback()  # no region headless: returns, never raises
    err = capfd.readouterr()
    assert "SolidWire" not in err.out + err.err


def test_overlay_survives_deletion_load_scene_switch_and_renders(output_dir):
    ensure_gpu()
    viewport = robustness.Viewport()
    scene, _keep, gone = _overlay_scene()
    stats, alpha_both = viewport.draw(scene)
    assert stats["objects_drawn"] == 2

    # Deletion: the deleted mesh is neither drawn nor kept on the GPU.
    mesh = gone.data
    bpy.data.objects.remove(gone)
    bpy.data.meshes.remove(mesh)
    stats, alpha_one = viewport.draw(scene)
    assert stats["objects_drawn"] == 1 and stats["meshes_cached"] == 1
    assert alpha_one.sum() < alpha_both.sum()

    # Render while the overlay is on: both targets keep working.
    robustness.render_exr(scene, output_dir / "overlay_render.exr")
    stats, alpha_after_render = viewport.draw(scene)
    assert np.array_equal(alpha_after_render, alpha_one)

    # Scene switch: another scene's depsgraph draws that scene only.
    other = bpy.data.scenes.new("Other")
    other.render.engine = "SOLIDWIRE"
    other.solidwire.show_overlay = True
    scenes.uv_sphere(other, "Ball")
    other.camera = scene.camera
    other.collection.objects.link(scene.camera)
    other_depsgraph = other.view_layers[0].depsgraph
    other_depsgraph.update()  # not the window's scene headless: evaluate it here
    stats, _ = viewport.draw(other, other_depsgraph)
    assert stats["objects_drawn"] == 1
    stats, alpha_back = viewport.draw(scene)
    assert np.array_equal(alpha_back, alpha_one)

    # File load: nothing of the old file is drawn or kept.
    bpy.ops.wm.read_factory_settings(use_empty=True)
    assert len(runtime.mesh_cache) == 0
    new_scene, _keep, _gone = _overlay_scene()
    stats, alpha_new = viewport.draw(new_scene)
    assert stats["objects_drawn"] == 2
    assert np.array_equal(alpha_new, alpha_both)


def test_overlay_across_undo(output_dir):
    """Undo replaces every datablock (memfile undo): the overlay must draw
    the restored geometry, not a stale upload. Background mode only has an
    undo stack after an explicit ed.undo_push()."""
    ensure_gpu()
    viewport = robustness.Viewport()
    scene, keep, _gone = _overlay_scene()
    bpy.ops.ed.undo_push(message="before edit")
    _stats, alpha_before = viewport.draw(scene)
    keep.data.vertices[0].co.x -= 0.8
    keep.data.update()
    bpy.ops.ed.undo_push(message="edit")
    _stats, alpha_edited = viewport.draw(scene)
    assert not np.array_equal(alpha_before, alpha_edited)
    bpy.ops.ed.undo()
    scene = bpy.context.scene  # the old Python objects are stale now
    assert scene.objects["Keep"].data.vertices[0].co.x == pytest.approx(-0.6)
    _stats, alpha_undone = viewport.draw(scene)
    assert np.array_equal(alpha_undone, alpha_before)
    bpy.ops.ed.redo()
    _stats, alpha_redone = viewport.draw(bpy.context.scene)
    assert np.array_equal(alpha_redone, alpha_edited)


# The order that crashed llvmpipe (segfault in swrast_dri inside batch.draw)
# while compiled programs were freed at unregister: an engine render, then
# unregister/register cycles, then overlay draws. core/shaders.py says why
# programs now live for the whole process.
CRASH_ORDER = (
    "tests/test_overlay.py::test_overlay_matches_render_engine[DEPTH24_STENCIL8-HIDDEN]",
    "tests/test_lifecycle.py::test_registered_state_is_measurable",
    "tests/test_lifecycle.py::test_register_and_unregister_are_idempotent",
    "tests/test_lifecycle.py::test_addon_state_holds_no_blender_data",
    "tests/test_lifecycle.py::test_overlay_survives_deletion_load_scene_switch_and_renders",
)


# The order that crashed llvmpipe inside the set-up pre-pass's compute
# dispatch while the deferred resolve used it (docs/dev/robustness.md, the
# set-up pre-pass in the deferred stages): a render with a Cycles beauty, a
# deferred render, Blender's own viewport drawn headless, then a render after
# a re-extraction. Crashed every time with the pre-pass in the resolve.
SETUP_CRASH_ORDER = (
    "tests/test_composite.py::test_wire_hidden_where_beauty_shows_a_nearer_surface",
    "tests/test_deferred_surface.py::test_deferred_surface_with_an_orthographic_camera",
    "tests/test_viewport_headless.py::test_flat_fill_matches_blender_flat_solid_colour",
    "tests/test_scale.py::test_a_move_that_changes_the_triangles_reextracts",
)


def _run_order_in_a_subprocess(order, tmp_path):
    """Run the tests ``order`` names, in that order, in a fresh process, so
    that a driver crash fails this test instead of ending the suite."""
    env = dict(os.environ, SOLIDWIRE_INNER_RUN="1", BLENDER_USER_RESOURCES=str(tmp_path / "user"))
    result = subprocess.run(
        [
            sys.executable,
            "-X",
            "faulthandler",
            "-m",
            "pytest",
            "-q",
            "-p",
            "no:cacheprovider",
            "-p",
            "no:randomly",
            *order,
        ],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    assert result.returncode == 0, (result.stdout + result.stderr)[-3000:]
    return result


def test_the_test_order_that_crashed_the_driver_passes(tmp_path):
    if os.environ.get("SOLIDWIRE_INNER_RUN"):
        pytest.skip("already inside the crash-order run")
    result = _run_order_in_a_subprocess(CRASH_ORDER, tmp_path)
    assert f"{len(CRASH_ORDER)} passed" in result.stdout


def test_the_test_order_that_crashed_the_set_up_dispatch_passes(tmp_path):
    if os.environ.get("SOLIDWIRE_INNER_RUN"):
        pytest.skip("already inside the crash-order run")
    result = _run_order_in_a_subprocess(SETUP_CRASH_ORDER, tmp_path)
    assert f"{len(SETUP_CRASH_ORDER)} passed" in result.stdout
