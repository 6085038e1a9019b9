"""The command line as a render farm or pipeline uses it: interrupted,
requeued, given Blender's frame syntax, failing.

Signals are real (``proc.send_signal``) and sent after the process says it
has written a frame, never after a delay; files are real files read back.
Runs that need no signal call ``cli.command`` (what ``blender -c solidwire``
calls) in this process, which is much faster than a new process each.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import bpy
import pytest

from solidwire_addon.blender import cli, presets
from solidwire_addon.core import exr
from tests.support import scenes
from tests.test_cli import RENDER_SCRIPT, ROOT, TIMEOUT_S, _env, meaningful_lines

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def _blend(tmp_path: Path, *, size=(48, 36), frames=(1, 6), name="anim.blend", **render) -> Path:
    scene = scenes.empty_scene(*size)
    cube = scenes.cube(scene, size=1.5)
    scenes.add_camera(scene)
    for frame, x in ((frames[0], -1.5), (frames[1], 1.5)):
        cube.location.x = x
        cube.keyframe_insert("location", frame=frame)
    scene.frame_start, scene.frame_end = frames
    scene.render.image_settings.file_format = "PNG"
    scene.render.filepath = str(tmp_path / "scene_out" / "shot_")
    for key, value in render.items():
        setattr(scene.render, key, value)
    path = tmp_path / name
    bpy.ops.wm.save_as_mainfile(filepath=str(path), copy=True)
    return path


def command(capsys, *argv) -> tuple[int, str, list[str]]:
    code = cli.command(["render", *map(str, argv)])
    captured = capsys.readouterr()
    return code, captured.out, meaningful_lines(captured.err)


def records(out: str) -> list[dict]:
    return [json.loads(line) for line in out.splitlines() if line.startswith("{")]


def assert_complete_png(path: Path, size: tuple[int, int]) -> None:
    """A whole PNG: signature, IEND at the end, and Blender reads its pixels."""
    data = path.read_bytes()
    assert data.startswith(PNG_MAGIC) and data.endswith(b"IEND\xaeB`\x82"), f"{path.name} is not a whole PNG"
    image = scenes.load_png(path)
    assert image.shape[:2] == (size[1], size[0])


def leftovers(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.rglob("*") if cli.TEMP_SUFFIX in p.name or "write-test" in p.name)


# -- signals -------------------------------------------------------------------


def _start(*args, env=None) -> subprocess.Popen:
    return subprocess.Popen(
        [sys.executable, str(RENDER_SCRIPT), *map(str, args)],
        env=env or _env(),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


def _wait_for_first_frame(proc: subprocess.Popen) -> dict:
    """Read progress until one frame is reported written; then the run is
    between or inside frames, the state a signal is tested in. The pipe is
    read a byte at a time: a buffered read can take the next frame's record
    along (a loaded machine writes two before the test reads), and
    communicate(), which reads the pipe itself, would never see it."""
    fd, line = proc.stdout.fileno(), b""
    while byte := os.read(fd, 1):
        if byte != b"\n":
            line += byte
        elif line.startswith(b"{"):
            return json.loads(line)
        else:
            line = b""
    raise AssertionError(f"no frame was reported; exit {proc.wait()}: {proc.stderr.read()}")


@pytest.mark.parametrize("signum, code, name", [(signal.SIGINT, 130, "SIGINT"), (signal.SIGTERM, 143, "SIGTERM")])
@pytest.mark.parametrize(
    "options", [pytest.param((), id="animation-render"), pytest.param(("--no-overwrite",), id="frame-by-frame")]
)
def test_a_signal_stops_after_the_frame_with_one_line(tmp_path, signum, code, name, options):
    size = (48, 36)
    blend = _blend(tmp_path, size=size, frames=(1, 400))
    out = tmp_path / "frames"
    proc = _start(blend, "-o", out / "f_####.png", "-a", "--progress", "json", *options)
    try:
        first = _wait_for_first_frame(proc)
        proc.send_signal(signum)
        stdout, stderr = proc.communicate(timeout=TIMEOUT_S)
    finally:
        proc.kill()
    assert proc.returncode == code, stderr
    assert "Traceback" not in stderr and "KeyboardInterrupt" not in stderr, stderr
    lines = meaningful_lines(stderr)
    assert len(lines) == 1 and lines[0].startswith(f"solidwire: stopped by {name} after "), lines
    written = sorted(out.glob("f_*.png"))
    reported = [first] + records(stdout)
    assert 1 <= len(written) < 400, "the run neither stopped nor rendered"
    # Every frame reported is there, and every file there is a whole image.
    assert {Path(r["output"]) for r in reported} == set(written)
    for path in written:
        assert_complete_png(path, size)
    assert leftovers(tmp_path) == []


@pytest.mark.parametrize("signals", [pytest.param(2, id="second-SIGTERM-stops-at-once"), pytest.param(0, id="SIGKILL")])
def test_a_killed_run_never_leaves_a_partial_frame(tmp_path, signals):
    """Large frames, stopped hard while they render or are written: a file
    under a frame's name is always a whole image."""
    size = (1920, 1080)
    blend = _blend(tmp_path, size=size, frames=(1, 60))
    out = tmp_path / "frames"
    proc = _start(blend, "-o", out / "f_####.png", "-a", "--progress", "json")
    try:
        _wait_for_first_frame(proc)
        if signals:
            for _ in range(signals):
                proc.send_signal(signal.SIGTERM)
        else:
            proc.kill()
        _stdout, stderr = proc.communicate(timeout=TIMEOUT_S)
    finally:
        proc.kill()
    for path in sorted(out.glob("f_*.png")):
        assert_complete_png(path, size)
    if signals:
        assert proc.returncode == 143, stderr
        assert "Traceback" not in stderr
        assert len(meaningful_lines(stderr)) == 1, stderr
        assert leftovers(tmp_path) == []  # the frame in progress was cleaned up
    else:
        # SIGKILL cannot be handled: a hidden temporary file may stay, never a frame.
        assert all(name.startswith(".") and name.endswith(cli.TEMP_SUFFIX) for name in leftovers(tmp_path))


# -- overwrite and placeholders --------------------------------------------------


def test_existing_frames_are_skipped_when_the_scene_does_not_overwrite(tmp_path, capsys):
    blend = _blend(tmp_path, use_overwrite=False)
    out = tmp_path / "seq"
    out.mkdir()
    kept = out / "f_3.png"
    kept.write_bytes(b"rendered by another machine")
    placeholder = out / "f_5.png"
    placeholder.touch()  # another machine's placeholder: its frame
    code, stdout, err = command(capsys, blend, "-o", out / "f_#.png", "-s", 2, "-e", 5, "--progress", "json")
    assert code == 0, err
    result = records(stdout)
    assert [(r["frame"], r.get("skipped", False)) for r in result] == [(2, False), (3, True), (4, False), (5, True)]
    assert kept.read_bytes() == b"rendered by another machine" and placeholder.stat().st_size == 0
    # Blender's own lines, which farm software reads (Flamenco's Worker counts
    # a skipped frame as progress and previews the file a "Saved:" line names).
    lines = stdout.splitlines()
    assert f'skipping existing frame "{kept}"' in lines
    assert f"Saved: '{out / 'f_2.png'}'" in lines
    assert_complete_png(out / "f_2.png", (48, 36))

    code, stdout, err = command(capsys, blend, "-o", out / "f_#.png", "-f", 3, "--overwrite")
    assert code == 0, err
    assert_complete_png(kept, (48, 36))


def test_no_overwrite_overrides_the_scene(tmp_path, capsys):
    blend = _blend(tmp_path)  # the scene overwrites (Blender's default)
    out = tmp_path / "f.png"
    out.write_bytes(b"keep me")
    code, stdout, err = command(capsys, blend, "-o", out, "-f", 1, "--no-overwrite")
    assert code == 0, err
    assert out.read_bytes() == b"keep me" and "skipped" in stdout
    code, _stdout, err = command(capsys, blend, "-o", out, "-f", 1)
    assert code == 0, err
    assert_complete_png(out, (48, 36))


def _run_with_a_broken_engine(tmp_path: Path, *args) -> subprocess.CompletedProcess:
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
        sys.argv = ["render.py", *{[str(a) for a in args]!r}]
        try:
            runpy.run_path({str(RENDER_SCRIPT)!r}, run_name="__main__")
        finally:
            solidwire_addon.unregister()
        """
    )
    return subprocess.run(
        [sys.executable, "-c", script],
        cwd=tmp_path,
        check=False,
        env=_env(),
        capture_output=True,
        text=True,
        timeout=TIMEOUT_S,
    )


@pytest.mark.parametrize(
    "placeholder", [pytest.param(True, id="frame-by-frame"), pytest.param(False, id="animation-render")]
)
def test_a_failed_frame_removes_its_placeholder_and_the_folders_it_made(tmp_path, placeholder):
    blend = _blend(tmp_path, use_placeholder=placeholder)
    result = _run_with_a_broken_engine(tmp_path, blend, "-o", tmp_path / "new" / "deeper" / "f_##.png", "-a")
    assert result.returncode == 1, result.stdout + result.stderr
    assert meaningful_lines(result.stderr)[-1].startswith("solidwire: error: render failed: frame 1:")
    assert "Traceback" not in result.stderr
    assert not (tmp_path / "new").exists()


# -- nothing written on failure ----------------------------------------------------


@pytest.mark.parametrize(
    "make_args, expected",
    [
        pytest.param(lambda t: [t / "missing.blend", "-o", t / "out" / "a" / "f.png"], "does not exist", id="missing"),
        pytest.param(
            lambda t: [_blend(t), "-o", t / "out" / "a" / "f.png", "--preset", "Nope"],
            "no preset named",
            id="bad-preset",
        ),
        pytest.param(
            lambda t: [_blend(t), "-o", t / "out" / "a" / "f_#.png", "-f", "5..2"],
            "ends before it starts",
            id="backwards-range",
        ),
    ],
)
def test_a_failed_run_creates_no_folder(tmp_path, make_args, expected):
    result = subprocess.run(
        [sys.executable, str(RENDER_SCRIPT), *map(str, make_args(tmp_path))],
        cwd=tmp_path,
        check=False,
        env=_env(),
        capture_output=True,
        text=True,
        timeout=TIMEOUT_S,
    )
    lines = meaningful_lines(result.stderr)
    assert result.returncode == 2 and len(lines) == 1 and expected in lines[0], result.stderr
    assert not (tmp_path / "out").exists()


# -- Blender's frame syntax --------------------------------------------------------


@pytest.mark.parametrize(
    "args, frames",
    [
        (("-f", "-1"), [6]),  # the scene's last frame, as Blender reads it
        (("-f", "+1"), [2]),  # start + 1
        (("-f", "1,3,5..6"), [1, 3, 5, 6]),
        (("-f", "-2..-1"), [5, 6]),
        (("-f", "2000000"), [1048574]),  # clamped to Blender's last frame
        (("-s", "+2", "-e", "-2"), [3, 4]),  # relative to the scene's start and end
        (("-s", "-2", "-e", "0"), [-1, 0]),  # start - 2
    ],
)
def test_frames_follow_blenders_command_line(tmp_path, capsys, args, frames):
    blend = _blend(tmp_path)
    code, stdout, err = command(capsys, blend, "-o", tmp_path / "f_###.png", *args, "--progress", "json")
    assert code == 0, err
    assert [r["frame"] for r in records(stdout)] == frames


def test_negative_frames_are_named_as_blender_names_them(tmp_path, capsys):
    blend = _blend(tmp_path)
    code, _stdout, err = command(capsys, blend, "-o", tmp_path / "f_####.png", "-s", "-3", "-e", "+0")
    assert code == 0, err
    names = sorted(p.name for p in tmp_path.glob("f_*.png"))
    # C's "%.4d": four digits after the minus sign (BLI_path_frame).
    assert names[:3] == ["f_-0001.png", "f_-0002.png", "f_0000.png"]
    # The scene's own path, numbered by Blender itself, agrees.
    bpy.ops.wm.open_mainfile(filepath=str(blend))
    bpy.context.scene.render.filepath = str(tmp_path / "f_####")
    assert Path(bpy.context.scene.render.frame_path(frame=-2)).name == "f_-0002.png"


# -- formats and passes ------------------------------------------------------------


def _multilayer_blend(tmp_path: Path) -> Path:
    blend = _blend(tmp_path)
    bpy.ops.wm.open_mainfile(filepath=str(blend))
    scene = bpy.context.scene
    from solidwire_addon.core import compat

    compat.set_media_type(scene.render.image_settings, "MULTI_LAYER_IMAGE")
    scene.render.image_settings.file_format = "OPEN_EXR_MULTILAYER"
    scene.render.image_settings.exr_codec = "NONE"  # what the test's reader reads
    scene.view_layers[0].use_pass_z = True
    scene.render.filepath = str(tmp_path / "scene_out" / "ml_")
    bpy.ops.wm.save_mainfile()
    return blend


def test_exr_output_keeps_a_multilayer_scenes_passes(tmp_path, capsys):
    blend = _multilayer_blend(tmp_path)
    code, _stdout, err = command(capsys, blend, "-o", tmp_path / "shot_####.exr", "-f", 1)
    assert code == 0, err
    assert err == []  # nothing dropped, nothing to say
    channels = exr.read_exr(tmp_path / "shot_0001.exr")
    assert any(".Depth." in name for name in channels), sorted(channels)
    assert any(".Combined." in name for name in channels), sorted(channels)


def test_a_single_image_format_says_that_passes_are_dropped(tmp_path, capsys):
    blend = _multilayer_blend(tmp_path)
    code, _stdout, err = command(capsys, blend, "-o", tmp_path / "shot_####.png", "-f", 1)
    assert code == 0
    depth = bpy.types.ViewLayer.bl_rna.properties["use_pass_z"].name  # Blender's UI name: "Z" before 4.5
    assert err == [
        f"solidwire: note: '.png' holds one image: the scene's passes {depth} are not written; -o NAME.exr keeps them"
    ], err
    assert_complete_png(tmp_path / "shot_0001.png", (48, 36))


def test_over_writes_a_single_layer_exr_and_says_the_passes_are_dropped(tmp_path, capsys):
    blend = _multilayer_blend(tmp_path)
    code, _stdout, err = command(capsys, blend, "-o", tmp_path / "over_#.exr", "-f", 1, "--over", "WORKBENCH")
    assert code == 0, err
    assert len(err) == 1 and err[0].startswith("solidwire: note: the --over composite is one image"), err
    channels = exr.read_exr(tmp_path / "over_1.exr")
    assert sorted(channels) == ["A", "B", "G", "R"]


def test_over_with_a_multilayer_scene_is_refused_before_rendering(tmp_path, capsys):
    blend = _multilayer_blend(tmp_path)
    code, _stdout, err = command(capsys, blend, "-f", 1, "--over", "WORKBENCH")
    assert code == 2 and len(err) == 1 and "--over" in err[0] and "multilayer" in err[0], err
    assert not (tmp_path / "scene_out").exists()


def test_a_video_scene_without_o_is_refused_before_rendering(tmp_path, capsys):
    blend = _blend(tmp_path)
    bpy.ops.wm.open_mainfile(filepath=str(blend))
    from solidwire_addon.core import compat

    image_settings = bpy.context.scene.render.image_settings
    if not compat.set_media_type(image_settings, "VIDEO"):
        image_settings.file_format = "FFMPEG"  # Blender 4.x: the format is the family
    bpy.ops.wm.save_mainfile()
    code, _stdout, err = command(capsys, blend, "-a")
    assert code == 2 and len(err) == 1 and "video" in err[0], err
    assert not (tmp_path / "scene_out").exists()


def test_stereo_views_to_separate_files_are_refused_before_rendering(tmp_path, capsys):
    blend = _blend(tmp_path)
    bpy.ops.wm.open_mainfile(filepath=str(blend))
    bpy.context.scene.render.use_multiview = True
    bpy.context.scene.render.image_settings.views_format = "INDIVIDUAL"
    bpy.ops.wm.save_mainfile()
    code, _stdout, err = command(capsys, blend, "-o", tmp_path / "out" / "f_#.png", "-a")
    assert code == 2 and len(err) == 1 and "stereo views" in err[0], err
    assert not (tmp_path / "out").exists()


# -- presets -----------------------------------------------------------------------


def test_an_unknown_preset_names_the_close_match_and_the_presets(tmp_path, capsys):
    code, _stdout, err = command(capsys, _blend(tmp_path), "-o", tmp_path / "p.png", "--preset", "Bluprint")
    assert code == 2 and len(err) == 1, err
    assert "no preset named 'Bluprint' (did you mean 'Blueprint'?" in err[0] and "Technical Drawing" in err[0]


def test_the_wrapper_sees_the_presets_saved_in_blender(tmp_path):
    """A preset saved from the panel (here: this process, Blender's user
    folder in BLENDER_USER_RESOURCES) is what scripts/render.py applies."""
    scene = scenes.empty_scene(16, 16)
    scene.solidwire.thickness = 7.5
    saved = presets.save("Farm Look", scene.solidwire, overwrite=True)
    try:
        env = _env()
        env["BLENDER_USER_RESOURCES"] = os.environ["BLENDER_USER_RESOURCES"]
        result = subprocess.run(
            [
                sys.executable,
                str(RENDER_SCRIPT),
                str(_blend(tmp_path)),
                "-o",
                str(tmp_path / "look.png"),
                "--preset",
                "farm look",
            ],
            check=False,
            env=env,
            capture_output=True,
            text=True,
            timeout=TIMEOUT_S,
        )
        assert result.returncode == 0, result.stderr
        assert (tmp_path / "look.png").is_file()
    finally:
        saved.unlink()


@pytest.mark.parametrize(
    "options", [pytest.param((), id="animation-render"), pytest.param(("--no-overwrite",), id="frame-by-frame")]
)
def test_braces_in_the_output_path_are_written_as_they_are(tmp_path, capsys, options):
    """Blender (from 4.5) reads "{name}" in an output path as a template
    variable; the path given with -o is a plain path."""
    out = tmp_path / "shot {v2}"
    code, _stdout, err = command(capsys, _blend(tmp_path), "-o", out / "f_#.png", "-s", 1, "-e", 2, *options)
    assert code == 0, err
    assert sorted(p.name for p in out.iterdir()) == ["f_1.png", "f_2.png"]


def test_runs_of_frames_go_through_blenders_animation_render(tmp_path):
    """Where Blender need not decide frame by frame, a run of frames is one
    animation render (one render depsgraph for the run, the speed of
    -E SOLIDWIRE -a; see docs/dev/command-line-overhead.md). Blender's own
    "Saved:" lines show which path wrote the frames: the animation render
    writes the run's temporary ".frame.NNNNNNN" names."""
    blend = _blend(tmp_path)

    def blender_saved_lines(name: str, *options) -> list[str]:
        result = subprocess.run(
            [
                sys.executable,
                str(RENDER_SCRIPT),
                str(blend),
                "-o",
                str(tmp_path / name),
                "-s",
                "1",
                "-e",
                "3",
                *options,
            ],
            check=False,
            env=_env(),
            capture_output=True,
            text=True,
            timeout=TIMEOUT_S,
        )
        assert result.returncode == 0, result.stderr
        return [line for line in result.stdout.splitlines() if "Saved: '" in line and cli.TEMP_SUFFIX in line]

    assert len([line for line in blender_saved_lines("a_#.png") if "/.frame." in line]) == 3
    frame_by_frame = blender_saved_lines("b_#.png", "--no-overwrite")  # Blender's rule decides per frame
    assert len(frame_by_frame) == 3 and not any("/.frame." in line for line in frame_by_frame)
