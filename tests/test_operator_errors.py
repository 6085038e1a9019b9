"""Every operator's failure paths end in one line, never a traceback: bad
input is found before any long work (the wire-over output path before the
beauty render), and an unexpected exception is reported, not raised."""

from __future__ import annotations

import os

import bpy
import pytest

from solidwire_addon.blender import composite, ops, presets
from tests.support import scenes


@pytest.fixture
def scene(monkeypatch):
    scene = scenes.empty_scene(32, 24)
    scenes.cube(scene)
    scenes.add_camera(scene)
    scene.render.engine = "BLENDER_WORKBENCH"

    def no_render(*_args, **_kwargs):
        raise AssertionError("rendered although the input was bad")

    # Every failure below must be found before anything is rendered.
    monkeypatch.setattr(composite, "render_layers", no_render)
    return scene


def _fails(operator, expected: str, capfd, **kwargs) -> str:
    capfd.readouterr()
    with pytest.raises(RuntimeError) as info:
        operator(**kwargs)
    message = str(info.value).strip()
    captured = capfd.readouterr()
    assert expected in message, message
    assert len(message.splitlines()) == 1, message
    assert "Traceback" not in captured.err + captured.out + message
    return message


def test_wire_over_checks_the_output_path_before_rendering(scene, tmp_path, capfd):
    a_file = tmp_path / "file.txt"
    a_file.write_text("x")
    _fails(
        bpy.ops.solidwire.render_wire_over,
        "is a file, not a folder",
        capfd,
        engine="BLENDER_WORKBENCH",
        filepath=str(a_file / "out.png"),
        show_result=False,
    )
    _fails(
        bpy.ops.solidwire.render_wire_over,
        "is a directory",
        capfd,
        engine="BLENDER_WORKBENCH",
        filepath=str(tmp_path),
        show_result=False,
    )
    if os.geteuid() != 0:  # root writes anywhere
        locked = tmp_path / "locked"
        locked.mkdir()
        locked.chmod(0o555)
        try:
            _fails(
                bpy.ops.solidwire.render_wire_over,
                "cannot write to",
                capfd,
                engine="BLENDER_WORKBENCH",
                filepath=str(locked / "out.png"),
                show_result=False,
            )
        finally:
            locked.chmod(0o755)


def test_wire_over_checks_engine_camera_and_format_before_rendering(scene, tmp_path, capfd):
    path = str(tmp_path / "out.png")
    scene.render.engine = "SOLIDWIRE"
    _fails(
        bpy.ops.solidwire.render_wire_over, "SolidWire itself", capfd, engine="SCENE", filepath=path, show_result=False
    )
    scene.render.engine = "BLENDER_WORKBENCH"
    image = scene.render.image_settings
    if hasattr(image, "media_type"):
        image.media_type = "VIDEO"
    image.file_format = "FFMPEG"
    _fails(bpy.ops.solidwire.render_wire_over, "is a video", capfd, engine="SCENE", filepath=path, show_result=False)


def test_wire_over_without_camera(tmp_path, capfd, monkeypatch):
    scene = scenes.empty_scene(32, 24)
    scene.render.engine = "BLENDER_WORKBENCH"
    _fails(
        bpy.ops.solidwire.render_wire_over,
        "has no camera",
        capfd,
        engine="SCENE",
        filepath=str(tmp_path / "out.png"),
        show_result=False,
    )


def test_preset_operators_fail_with_one_line(scene, capfd, monkeypatch):
    _fails(bpy.ops.solidwire.preset_apply, "no preset named 'Nope'", capfd, name="Nope")
    _fails(bpy.ops.solidwire.preset_add, "has no letters or digits", capfd, name="!!!")
    monkeypatch.setattr(ops, "active_preset_name", "Something")
    builtin = presets.builtin_presets()[0].name
    _fails(bpy.ops.solidwire.preset_remove, "cannot be removed", capfd, name=builtin)
    _fails(bpy.ops.solidwire.preset_remove, "no user preset named 'Gone'", capfd, name="Gone")


def test_fade_range_without_a_view(capfd):
    scenes.empty_scene()
    _fails(bpy.ops.solidwire.fade_from_visible, "no 3D viewport or scene camera", capfd)


def test_an_unexpected_exception_is_one_line(scene, capfd, monkeypatch):
    def broken(_preset, _props, **_options):
        raise ValueError("settings on fire\nsecond line")

    monkeypatch.setattr(presets, "apply", broken)
    builtin = presets.builtin_presets()[0].name
    _fails(
        bpy.ops.solidwire.preset_apply,
        "Apply SolidWire Preset failed: ValueError: settings on fire second line",
        capfd,
        name=builtin,
    )
