"""The command line inside the extension: ``blender -c solidwire render``.

There is no Blender executable here, so the registered command's function
(``cli.command``, what Blender calls with the words after ``-c solidwire``)
runs in this process with an argv, exactly as Blender would call it. The
scripts/render.py wrapper is tested both ways in test_cli.py.
"""

from __future__ import annotations

import json
import threading
from pathlib import Path

import bpy
import numpy as np
import pytest

from solidwire_addon.blender import cli
from tests.support import scenes


def _animated_blend(tmp_path: Path, *, step: int = 1) -> Path:
    scene = scenes.empty_scene(32, 24)
    cube = scenes.cube(scene, size=1.5)
    scenes.add_camera(scene)
    for frame, x in ((1, -1.5), (6, 1.5)):
        cube.location.x = x
        cube.keyframe_insert("location", frame=frame)
    scene.frame_start, scene.frame_end, scene.frame_step = 1, 6, step
    scene.frame_current = 2
    scene.render.image_settings.file_format = "PNG"
    scene.render.filepath = str(tmp_path / "scene_out" / "shot_")
    path = tmp_path / "anim.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path), copy=True)
    return path


def _json_records(text: str) -> list[dict]:
    return [json.loads(line) for line in text.splitlines() if line.startswith("{")]


def run(capsys, *argv) -> tuple[int, str, str]:
    code = cli.command([str(a) for a in argv])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def test_the_command_is_registered_with_blender():
    # Blender 4.2+ has register_cli_command; the add-on registered it.
    assert hasattr(bpy.utils, "register_cli_command")
    assert cli._cli_handle is not None


def test_help_and_unknown_commands(capsys):
    code, out, _err = run(capsys, "--help")
    assert code == 0 and "render" in out
    code, _out, err = run(capsys)
    assert code == 2
    code, _out, err = run(capsys, "paint")
    assert code == 2 and err.strip() == "solidwire: error: unknown command 'paint' (commands: render)"
    with pytest.raises(SystemExit) as exit_info:  # argparse's own --help
        cli.command(["render", "--help"])
    assert exit_info.value.code == 0
    assert "--thickness" in capsys.readouterr().out


def test_animation_renders_the_scene_range_with_its_step_to_the_scene_path(tmp_path, capsys):
    blend = _animated_blend(tmp_path, step=2)
    code, out, err = run(capsys, "render", blend, "-a", "--progress", "json")
    assert code == 0, err
    records = _json_records(out)
    assert [r["frame"] for r in records] == [1, 3, 5]
    # Without -o: the scene's output path, numbered and with its extension as Blender does.
    expected = [tmp_path / "scene_out" / f"shot_{n:04d}.png" for n in (1, 3, 5)]
    assert [Path(r["output"]) for r in records] == expected
    assert all(path.is_file() for path in expected)
    assert sorted((tmp_path / "scene_out").iterdir()) == expected
    for record in records:
        assert record["count"] == 3 and record["seconds"] > 0 and record["stats"]["objects_drawn"] == 1
    images = [scenes.load_png(path) for path in expected]
    assert not np.array_equal(images[0], images[2])  # the cube moved


def test_start_end_and_jump_override_the_range(tmp_path, capsys):
    blend = _animated_blend(tmp_path, step=2)
    code, out, err = run(
        capsys, "render", blend, "-s", 2, "-e", 4, "-j", 1, "-o", tmp_path / "f_##.png", "--progress", "json"
    )
    assert code == 0, err
    assert [r["frame"] for r in _json_records(out)] == [2, 3, 4]
    assert sorted(p.name for p in tmp_path.glob("f_*.png")) == ["f_02.png", "f_03.png", "f_04.png"]


def test_frame_lists_and_the_current_frame(tmp_path, capsys):
    blend = _animated_blend(tmp_path)
    code, out, err = run(capsys, "render", blend, "-f", "1,4..5", "-o", tmp_path / "l_#.png", "--progress", "json")
    assert code == 0, err
    assert [r["frame"] for r in _json_records(out)] == [1, 4, 5]
    code, out, err = run(capsys, "render", blend, "-o", tmp_path / "current.png")
    assert code == 0, err
    assert (tmp_path / "current.png").is_file() and "rendered" in out  # frame_current (2), text progress


def test_a_preset_applies_before_the_other_options(tmp_path, capsys):
    blend = _animated_blend(tmp_path)
    code, _out, err = run(capsys, "render", blend, "-o", tmp_path / "p.png", "--preset", "Blueprint", "--thickness", 3)
    assert code == 0, err
    props = bpy.context.scene.solidwire  # the file the command opened
    blueprint = next(p for p in cli.presets.builtin_presets() if p.name == "Blueprint")
    assert props.thickness == pytest.approx(3.0)
    assert tuple(props.wire_color) == pytest.approx(blueprint.values["wire_color"])


@pytest.mark.parametrize(
    "args, expected",
    [
        (("--fade", 50, 10), "--fade: END (10) must be beyond START (50)"),
        (("--thickness-depth", 5, 5), "--thickness-depth: FAR (5) must be beyond NEAR (5)"),
        (("--fade", 1, 2, "--no-fade"), "give either --fade or --no-fade"),
        (("-a", "-f", 1), "give only one of"),
        (("-s", 5, "-e", 2), "ends before it starts"),
        (("--preset", "No Such Look"), "--preset: no preset named 'No Such Look'"),
        (("--preset", "missing.json"), "--preset: missing.json: cannot read"),
        (("--thickness", 5000), "--thickness = 5000 is out of range 0..1000"),
        (("--diagonals", "wavy"), "--diagonals"),
        (("-j", 0), "--frame-jump"),
    ],
)
def test_bad_options_are_one_line_and_exit_2(tmp_path, capsys, args, expected):
    blend = _animated_blend(tmp_path)
    code, _out, err = run(capsys, "render", blend, "-o", tmp_path / "bad.png", *args)
    lines = [line for line in err.splitlines() if line.strip() and "EGL Error" not in line]
    assert code == 2, err
    assert len(lines) == 1 and lines[0].startswith("solidwire: error: ") and expected in lines[0], lines
    assert not (tmp_path / "bad.png").exists()


def test_a_run_leaves_no_thread_behind(tmp_path, capsys):
    # The signal watcher must be gone when the command returns, whether it
    # rendered or refused: a thread alive at interpreter exit keeps the bpy
    # 4.5 module from shutting Blender down, and the process hangs there.
    blend = _animated_blend(tmp_path)
    before = set(threading.enumerate())
    for extra in ((), ("--thickness", 5000)):
        code, _out, err = run(capsys, "render", blend, "-o", tmp_path / "still.png", "-f", 1, *extra)
        assert code == (2 if extra else 0), err
        assert set(threading.enumerate()) <= before, [t.name for t in set(threading.enumerate()) - before]


def test_no_output_path_anywhere_is_an_error(tmp_path, capsys):
    blend = _animated_blend(tmp_path)
    bpy.ops.wm.open_mainfile(filepath=str(blend))
    bpy.context.scene.render.filepath = ""
    bpy.ops.wm.save_mainfile()
    code, _out, err = run(capsys, "render", blend)
    assert code == 2 and "has no output path: pass -o PATH" in err


def test_every_look_setting_has_an_option_from_the_schema():
    from solidwire_addon.core import schema

    parser = cli.build_parser()
    flags = {flag for action in parser._actions for flag in action.option_strings}
    for setting in schema.settings_in(schema.SCENE):
        if setting.flag:
            assert setting.flag in flags, setting.name
    assert {"-o", "-f", "-a", "-s", "-e", "-j", "--preset", "--progress"} <= flags
