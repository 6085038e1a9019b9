"""scripts/render.py, the command line.

Each render runs in a fresh Python process (as a user runs it): the test
process already has the add-on registered, and the CLI registers its own.
There is no Blender executable here, so the ``blender -b ... --python
scripts/render.py -- ...`` form is simulated in the bpy module: the .blend is
opened first, ``bpy.app.binary_path`` is set (it is empty only in the bpy
module) and ``sys.argv`` looks like Blender's.
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import subprocess
import sys
import tempfile
import textwrap
from pathlib import Path

import bpy
import numpy as np
import pytest

from solidwire_addon.blender import cli as render_cli
from tests.support import scenes

ROOT = Path(__file__).resolve().parent.parent
RENDER_SCRIPT = ROOT / "scripts" / "render.py"
TIMEOUT_S = 300


def _load_script_module(name: str, path: Path):
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


demo_scene = _load_script_module("solidwire_demo_scene", ROOT / "scripts" / "demo_scene.py")


def _env() -> dict:
    env = dict(os.environ)
    # A private Blender configuration per run: nothing installed, nothing shared.
    env["BLENDER_USER_RESOURCES"] = tempfile.mkdtemp(prefix="solidwire-cli-user-")
    env.pop("PYTHONPATH", None)
    return env


def run_cli(*args, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, str(RENDER_SCRIPT), *map(str, args)],
        cwd=cwd,
        env=_env(),
        capture_output=True,
        text=True,
        timeout=TIMEOUT_S,
        check=False,
    )


_SIMULATED_BLENDER = textwrap.dedent(
    """
    import runpy, sys
    import bpy
    blend, script, rest = sys.argv[1], sys.argv[2], sys.argv[3:]
    bpy.ops.wm.open_mainfile(filepath=blend)   # what `blender -b SCENE.blend` does
    bpy.app.binary_path = "/opt/blender/blender"
    sys.argv = ["blender", "-b", blend, "--python", script, "--", *rest]
    runpy.run_path(script, run_name="__main__")
    """
)


def run_cli_blender_form(blend: Path, *args, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-c", _SIMULATED_BLENDER, str(blend), str(RENDER_SCRIPT), *map(str, args)],
        cwd=cwd,
        env=_env(),
        capture_output=True,
        text=True,
        timeout=TIMEOUT_S,
        check=False,
    )


def meaningful_lines(text: str) -> list[str]:
    """Output lines minus Mesa's harmless EGL chatter (no GPU here)."""
    return [line for line in text.splitlines() if line.strip() and "EGL Error" not in line]


def assert_ok(result: subprocess.CompletedProcess) -> None:
    assert result.returncode == 0, f"exit {result.returncode}\n{result.stdout}\n{result.stderr}"
    assert "Traceback" not in result.stderr, result.stderr
    # The add-on reports skipped objects and similar problems as "SolidWire ..." lines.
    assert not [line for line in meaningful_lines(result.stderr) if line.startswith("SolidWire")], result.stderr


def srgb_from_linear(linear) -> np.ndarray:
    c = np.asarray(linear, dtype=np.float64)
    return np.where(c <= 0.0031308, 12.92 * c, 1.055 * np.power(c, 1.0 / 2.4) - 0.055)


def save_blend(scene, path: Path) -> Path:
    # copy=True: the test process keeps working on its own (unsaved) file.
    bpy.ops.wm.save_as_mainfile(filepath=str(path), copy=True)
    return path


def suzanne_blend(tmp_path: Path) -> tuple:
    scene = scenes.empty_scene(96, 72)
    scenes.monkey(scene)
    scenes.cube(scene, location=(1.8, 0.8, -0.6), size=0.8)
    scenes.add_camera(scene, location=(2.5, -4.0, 1.8), target=(0.4, 0.0, 0.0))
    return scene, save_blend(scene, tmp_path / "suzanne.blend")


# -- pure helpers (no subprocess) ----------------------------------------------


def test_frame_path_follows_blenders_hash_rule(tmp_path):
    frame_path = render_cli.frame_path
    assert frame_path(tmp_path / "shot_###.png", 7, 3) == tmp_path / "shot_007.png"
    assert frame_path(tmp_path / "a#_b##.png", 12, 1) == tmp_path / "a#_b12.png"  # the last run counts
    assert frame_path(tmp_path / "still.png", 5, 1) == tmp_path / "still.png"
    assert frame_path(tmp_path / "seq.png", 5, 3) == tmp_path / "seq0005.png"


def test_colour_option_parsing():
    assert render_cli._color("1,0.5,0") == (1.0, 0.5, 0.0, 1.0)
    assert render_cli._color("0,0,0,0.25") == (0.0, 0.0, 0.0, 0.25)
    assert render_cli._color("#ff0080") == pytest.approx((1.0, 0.0, 128 / 255, 1.0))
    for bad in ("1,0", "1,2,0", "red", "#12345", "nan,0,0"):
        with pytest.raises(argparse.ArgumentTypeError):
            render_cli._color(bad)


# -- renders -------------------------------------------------------------------


def test_demo_renders_png_with_wire_fill_and_world(tmp_path, output_dir):
    out = output_dir / "cli_demo.png"
    out.unlink(missing_ok=True)
    result = run_cli("--demo", "-o", out, "--print-stats", cwd=tmp_path)
    assert_ok(result)
    assert out.is_file() and out.stat().st_size > 0
    assert "rendered" in result.stdout and " s" in result.stdout  # the render time
    assert "triangles_drawn=" in result.stdout

    rgb = scenes.load_png(out)[..., :3]  # values as stored (sRGB encoded)
    height, width = rgb.shape[:2]
    assert (width, height) == demo_scene.RESOLUTION

    def share_near(colour_linear) -> float:
        target = srgb_from_linear(colour_linear[:3])
        return float(np.mean(np.max(np.abs(rgb - target), axis=-1) <= 3.0 / 255.0))

    wire, world = (share_near(c) for c in (demo_scene.WIRE_COLOR, demo_scene.WORLD_COLOR))
    # The fill is studio-lit: the fill colour times a light level (one factor
    # for all three channels).
    linear = np.where(rgb <= 0.04045, rgb / 12.92, ((rgb + 0.055) / 1.055) ** 2.4)
    ratio = linear / np.asarray(demo_scene.FILL_COLOR)
    lit = (np.ptp(ratio, axis=-1) < 0.03) & (ratio.mean(axis=-1) > 0.3)
    fill = float(np.mean(lit))
    assert wire > 0.01, f"too few wire pixels ({wire:.3%})"
    assert fill > 0.02, f"too few fill pixels ({fill:.3%})"
    assert world > 0.3, f"too little background ({world:.3%})"


@pytest.mark.parametrize(
    "cli_options, settings, render_settings",
    [
        pytest.param((), {}, {}, id="scene-settings"),
        pytest.param(
            (
                "--thickness",
                "3",
                "--softness",
                "0.6",
                "--wire-color",
                "1,0.2,0.1",
                "--fill",
                "--fill-color",
                "0.1,0.2,0.3",
                "--diagonals",
                "SOLID",
                "--opaque",
                "--width",
                "120",
                "--height",
                "80",
                "--percentage",
                "50",
            ),
            dict(
                thickness=3.0,
                softness=0.6,
                wire_color=(1.0, 0.2, 0.1, 1.0),
                use_fill=True,
                fill_color=(0.1, 0.2, 0.3),
                diagonal_mode="SOLID",
            ),
            dict(film_transparent=False, resolution_x=120, resolution_y=80, resolution_percentage=50),
            id="options",
        ),
        pytest.param(
            (
                "--thickness-mode",
                "DEPTH",
                "--thickness",
                "4",
                "--thickness-far",
                "1",
                "--thickness-depth",
                "3",
                "9",
                "--silhouettes",
                "--hidden-lines",
                "--hidden-alpha",
                "0.5",
                "--hidden-period",
                "6",
                "--hidden-duty",
                "0.4",
            ),
            dict(
                thickness_mode="DEPTH",
                thickness=4.0,
                thickness_far=1.0,
                thickness_depth_start=3.0,
                thickness_depth_end=9.0,
                use_silhouettes=True,
                use_hidden_lines=True,
                hidden_alpha=0.5,
                hidden_period=6.0,
                hidden_duty=0.4,
            ),
            {},
            id="line-styles",
        ),
        pytest.param(
            ("--thickness-mode", "WORLD", "--world-thickness", "0.03"),
            dict(thickness_mode="WORLD", world_thickness=0.03),
            {},
            id="world-thickness",
        ),
        pytest.param(
            (
                "--fill",
                "--shading",
                "matcap",
                "--matcap",
                "clay_brown",
                "--fill-source",
                "random",
                "--wire-source",
                "OBJECT",
                "--edge-angle",
                "0.2",
            ),
            dict(
                use_fill=True,
                fill_shading="MATCAP",
                matcap="clay_brown",
                fill_color_source="RANDOM",
                wire_color_source="OBJECT",
                edge_angle=0.2,
            ),
            {},
            id="shading-and-colour-sources",
        ),
        pytest.param(
            ("--no-fade-dense-objects", "--tessellation"),
            dict(use_object_density_fade=False, show_tessellation=True),
            {},
            id="dense-objects-and-tessellation",
        ),
    ],
)
def test_cli_renders_the_same_image_as_the_engine(tmp_path, cli_options, settings, render_settings):
    scene, blend = suzanne_blend(tmp_path)
    for name, value in settings.items():
        setattr(scene.solidwire, name, value)
    for name, value in render_settings.items():
        setattr(scene.render, name, value)
    direct = scenes.render_to_file(scene, tmp_path / "engine.png", depth16=True)

    out = tmp_path / "cli.png"
    result = run_cli(blend, "-o", out, "--color-depth", "16", *cli_options, cwd=tmp_path)
    assert_ok(result)
    via_cli = scenes.load_png(out)
    assert via_cli.shape == direct.shape
    assert np.max(direct[..., 3]) > 0.5, "the engine render shows no wire: nothing was compared"
    assert np.max(np.abs(via_cli - direct)) <= 1.0 / 65535.0


def test_blender_form_renders_the_open_file_like_the_python_form(tmp_path):
    _scene, blend = suzanne_blend(tmp_path)
    python_form = tmp_path / "python_form.png"
    blender_form = tmp_path / "blender_form.png"
    assert_ok(run_cli(blend, "-o", python_form, "--thickness", "2.5", cwd=tmp_path))
    result = run_cli_blender_form(blend, "-o", blender_form, "--thickness", "2.5", cwd=tmp_path)
    assert_ok(result)
    a, b = scenes.load_png(python_form), scenes.load_png(blender_form)
    assert a.shape == b.shape and np.max(a[..., 3]) > 0.5
    assert np.array_equal(a, b)


def test_frame_range_writes_numbered_files_with_progress(tmp_path):
    scene = scenes.empty_scene(64, 48)
    cube = scenes.cube(scene, size=1.5)
    scenes.add_camera(scene)
    for frame, x in ((1, -1.5), (3, 1.5)):
        cube.location.x = x
        cube.keyframe_insert("location", frame=frame)
    blend = save_blend(scene, tmp_path / "anim.blend")

    result = run_cli(blend, "-o", tmp_path / "seq" / "frame_###.png", "--frames", "1-3", cwd=tmp_path)
    assert_ok(result)
    paths = [tmp_path / "seq" / f"frame_{n:03d}.png" for n in (1, 2, 3)]
    assert sorted((tmp_path / "seq").iterdir()) == paths
    images = [scenes.load_png(path) for path in paths]
    assert all(np.max(image[..., 3]) > 0.5 for image in images)
    # The cube moves: every frame is its own image.
    assert not np.array_equal(images[0], images[1]) and not np.array_equal(images[1], images[2])
    for n in (1, 2, 3):
        assert f"frame {n} of 3" in result.stdout
    assert "ETA" in result.stdout


# -- expected errors: one line, exit code 2, nothing written -------------------


def _no_camera_blend(tmp_path: Path) -> Path:
    scene = scenes.empty_scene(32, 32)
    scenes.cube(scene)
    return save_blend(scene, tmp_path / "no_camera.blend")


def _text_file(tmp_path: Path) -> Path:
    path = tmp_path / "notes.blend"
    path.write_text("not a blend file\n")
    return path


@pytest.mark.parametrize(
    "make_args, expected",
    [
        pytest.param(lambda t: [t / "missing.blend", "-o", t / "out.png"], "does not exist", id="missing-file"),
        pytest.param(lambda t: [_text_file(t), "-o", t / "out.png"], "not a .blend file", id="not-a-blend"),
        pytest.param(lambda t: [_no_camera_blend(t), "-o", t / "out.png"], "has no camera", id="no-camera"),
        pytest.param(
            lambda t: [_no_camera_blend(t), "-o", t / "out.png", "--camera", "Nope"], "no camera named", id="bad-camera"
        ),
        pytest.param(lambda t: ["--demo", "-o", _text_file(t) / "out.png"], "cannot write", id="unwritable-output"),
        pytest.param(
            lambda t: ["--demo", "-o", t / "out.png", "--thickness", "-1"], "out of range", id="bad-thickness"
        ),
        pytest.param(lambda t: ["--demo", "-o", t / "out.png", "--wire-color", "1,0"], "--wire-color", id="bad-colour"),
        pytest.param(lambda t: ["--demo", "-o", t / "out.png", "--frames", "5-2"], "--frames", id="bad-frames"),
        pytest.param(lambda t: ["--demo", "-o", t / "out.xyz"], "unknown image type", id="bad-extension"),
        pytest.param(lambda t: ["-o", t / "out.png"], "no scene given", id="no-scene"),
    ],
)
def test_expected_errors_are_one_line_with_exit_code_2(tmp_path, make_args, expected):
    result = run_cli(*make_args(tmp_path), cwd=tmp_path)
    lines = meaningful_lines(result.stderr)
    assert result.returncode == 2, f"exit {result.returncode}\n{result.stdout}\n{result.stderr}"
    assert len(lines) == 1, result.stderr
    assert lines[0].startswith("solidwire: error: ") and expected in lines[0], lines[0]
    assert "Traceback" not in result.stdout + result.stderr
    assert not (tmp_path / "out.png").exists()


def test_blender_form_without_an_open_file_is_an_error(tmp_path):
    # Blender carries on with an unsaved default file when it cannot open the
    # .blend on its command line; that file must not be rendered instead.
    script = textwrap.dedent(
        f"""
        import runpy, sys, bpy
        bpy.app.binary_path = "/opt/blender/blender"
        sys.argv = ["blender", "-b", "gone.blend", "--python", {str(RENDER_SCRIPT)!r}, "--", "-o", "out.png"]
        runpy.run_path({str(RENDER_SCRIPT)!r}, run_name="__main__")
        """
    )
    result = subprocess.run(
        [sys.executable, "-c", script],
        cwd=tmp_path,
        env=_env(),
        capture_output=True,
        text=True,
        timeout=TIMEOUT_S,
        check=False,
    )
    assert result.returncode == 2
    assert meaningful_lines(result.stderr) == ["solidwire: error: no scene given: pass SCENE.blend or --demo"]
    assert not (tmp_path / "out.png").exists()


def test_a_failing_render_exits_1_with_a_clear_line(tmp_path):
    _scene, blend = suzanne_blend(tmp_path)
    script = textwrap.dedent(
        f"""
        import runpy, sys
        sys.path.insert(0, {str(ROOT)!r})
        import solidwire_addon
        from solidwire_addon.blender import engine
        solidwire_addon.register()

        def broken_render(*args, **kwargs):
            raise ValueError("simulated failure")

        engine.PreparedFrame = broken_render
        sys.argv = ["render.py", {str(blend)!r}, "-o", "out.png"]
        try:
            runpy.run_path({str(RENDER_SCRIPT)!r}, run_name="__main__")
        finally:
            solidwire_addon.unregister()
        """
    )
    result = subprocess.run(
        [sys.executable, "-c", script],
        cwd=tmp_path,
        env=_env(),
        capture_output=True,
        text=True,
        timeout=TIMEOUT_S,
        check=False,
    )
    assert result.returncode == 1, result.stdout + result.stderr
    lines = meaningful_lines(result.stderr)
    assert lines[-1].startswith("solidwire: error: render failed: ") and "simulated failure" in lines[-1], lines
    assert "Traceback" not in result.stderr
    assert not (tmp_path / "out.png").exists()
