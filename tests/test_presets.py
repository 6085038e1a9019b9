"""Presets: built-ins look different, user presets round-trip, bad files are
refused with one clear line and change nothing."""

from __future__ import annotations

import itertools
import json
from pathlib import Path

import bpy
import numpy as np
import pytest

from tests.support import scenes
import solidwire_addon
from solidwire_addon.blender import engine
from solidwire_addon.blender import ops
from solidwire_addon.blender import presets
from solidwire_addon.blender.gpu_context import ensure_gpu

SIZE = (240, 180)


def snapshot(props) -> dict:
    return presets.values_of(props)


def preset_scene():
    scene = scenes.empty_scene(*SIZE)
    scenes.add_camera(scene, location=(0.0, -4.2, 0.6), target=(0.0, 0.0, 0.0))
    scenes.monkey(scene, rotation=(0.0, 0.0, 0.5))
    return scene


def render(scene) -> np.ndarray:
    ensure_gpu()
    rgba, _depth = engine.render_scene(bpy.context.evaluated_depsgraph_get(), SIZE)
    return rgba


@pytest.fixture
def user_dir():
    folder = presets.user_dir()
    for path in folder.glob("*.json"):
        path.unlink()
    yield folder
    for path in folder.glob("*.json"):
        path.unlink()
    ops.active_preset_name = ""


def test_builtin_presets_are_complete_and_distinct():
    builtin = presets.builtin_presets()
    assert len(builtin) >= 6
    names = [p.name for p in builtin]
    assert len(set(names)) == len(names)
    for preset in builtin:
        assert set(preset.values) == set(presets.FIELDS), preset.name
        assert preset.description
    assert names[0] == "Default"


def test_field_ranges_match_the_settings():
    """Presets validate with the same hard limits the properties enforce
    (both are made from the schema)."""
    rna = bpy.context.scene.solidwire.bl_rna.properties
    for key, field in presets.FIELDS.items():
        prop = rna[key]
        if field.kind == "FLOAT":
            assert (field.minimum, field.maximum) == pytest.approx((prop.hard_min, min(prop.hard_max, 1e9))), key
        elif field.kind == "ENUM":
            assert set(field.choices) == {item.identifier for item in prop.enum_items}, key
        elif field.kind == "COLOR":
            assert (prop.array_length, prop.hard_min, prop.hard_max) == (field.size, 0.0, 1.0), key
        else:
            assert prop.type == "BOOLEAN", key


def test_default_preset_equals_the_property_defaults():
    scene = scenes.empty_scene()
    for key in presets.FIELDS:
        scene.solidwire.property_unset(key)
    assert snapshot(scene.solidwire) == snapshot_of(presets.find("Default"))


def test_every_builtin_preset_renders_differently():
    scene = preset_scene()
    images = {}
    for preset in presets.builtin_presets():
        bpy.ops.solidwire.preset_apply(name=preset.name)
        assert snapshot(scene.solidwire) == snapshot_of(preset), preset.name
        images[preset.name] = render(scene)
    default = images.pop("Default")
    for name, image in images.items():
        assert np.abs(image - default).mean() > 0.01, f"'{name}' looks like the default"
    for (name_a, a), (name_b, b) in itertools.combinations(images.items(), 2):
        assert np.abs(a - b).mean() > 0.01, f"'{name_a}' and '{name_b}' look alike"


def snapshot_of(preset) -> dict:
    return {
        key: [round(c, 6) for c in value] if isinstance(value, tuple) else (round(value, 6) if isinstance(value, float) else value)
        for key, value in preset.values.items()
    }


def test_user_preset_round_trips(user_dir):
    scene = scenes.empty_scene()
    props = scene.solidwire
    props.thickness, props.softness = 2.75, 0.5
    props.wire_color = (0.1, 0.2, 0.3, 0.8)
    props.use_fill, props.fill_color = True, (0.9, 0.8, 0.7)
    props.diagonal_mode = "DASHED"
    props.pattern_period, props.pattern_duty = 12.0, 0.4
    props.use_fade, props.fade_start, props.fade_end = True, 3.0, 7.5
    props.use_backface_culling = True
    saved = snapshot(props)

    bpy.ops.solidwire.preset_add(name="My Look")
    path = user_dir / "my_look.json"
    assert path.is_file()
    addon_dir = Path(solidwire_addon.__file__).resolve().parent
    assert addon_dir not in path.resolve().parents, "user presets never live in the add-on folder"
    assert ops.active_preset_name == "My Look"

    bpy.ops.solidwire.preset_apply(name="Default")
    assert snapshot(props) != saved
    bpy.ops.solidwire.preset_apply(name="My Look")
    assert snapshot(props) == saved
    assert "My Look" in [p.name for p in presets.all_presets()]

    # Saving again under the same name replaces it.
    props.thickness = 4.0
    bpy.ops.solidwire.preset_add(name="My Look")
    assert presets.find("My Look").values["thickness"] == 4.0
    assert len(list(user_dir.glob("*.json"))) == 1

    bpy.ops.solidwire.preset_remove(name="My Look")
    assert not path.exists()
    assert ops.active_preset_name == ""


def test_builtin_presets_cannot_be_removed(user_dir):
    scenes.empty_scene()
    ops.active_preset_name = ""
    assert not bpy.ops.solidwire.preset_remove.poll()  # "-" is greyed out with no active preset
    bpy.ops.solidwire.preset_apply(name="Blueprint")
    assert ops.active_preset_name == "Blueprint"
    with pytest.raises(RuntimeError, match="built-in preset"):
        bpy.ops.solidwire.preset_remove()
    assert presets.find("Blueprint").builtin


def _valid_settings() -> dict:
    return dict(presets.find("Blueprint").values) | {"wire_color": [0.5, 0.5, 0.5, 1.0], "fill_color": [0, 0, 0, 1]}


def _document(**settings_override) -> dict:
    settings = {k: (list(v) if isinstance(v, tuple) else v) for k, v in _valid_settings().items()}
    settings.update(settings_override)
    return {"solidwire_preset": 1, "name": "Broken", "settings": settings}


CORRUPT = {
    "not json": ("{ this is not json", "not valid JSON"),
    "not an object": (json.dumps([1, 2, 3]), "must be a JSON object"),
    "unknown top-level key": (json.dumps(_document() | {"script": "import os"}), "unknown key 'script'"),
    "unknown setting": (json.dumps(_document(line_width=3.0)), "unknown setting 'line_width'"),
    "wrong type: bool as number": (json.dumps(_document(use_fill=1)), "'use_fill' must be true or false"),
    "wrong type: number as string": (json.dumps(_document(thickness="3")), "'thickness' must be a number"),
    "out of range": (json.dumps(_document(pattern_duty=1.5)), "'pattern_duty' = 1.5 is out of range"),
    "negative thickness": (json.dumps(_document(thickness=-1)), "'thickness' = -1 is out of range"),
    "bad enum": (json.dumps(_document(diagonal_mode="WAVY")), "'diagonal_mode' must be one of"),
    "short colour": (json.dumps(_document(wire_color=[1, 0, 0])), "'wire_color' must be a list of 4 numbers"),
    "colour out of range": (json.dumps(_document(fill_color=[2, 0, 0, 1])), "components must lie in 0..1"),
    "NaN": (json.dumps(_document()).replace('"thickness": 1.0', '"thickness": NaN'), "'NaN' is not allowed"),
    "duplicate key": ('{"solidwire_preset": 1, "name": "A", "name": "B", "settings": {"thickness": 1}}', "appears twice"),
    "wrong version": (json.dumps(_document() | {"solidwire_preset": 2}), "'solidwire_preset' must be 1"),
    "no settings": (json.dumps({"solidwire_preset": 1, "name": "Empty", "settings": {}}), "'settings' must be a non-empty"),
    "huge file": (json.dumps(_document() | {"description": "x" * 200_000}), "larger than 64 KiB"),
}


@pytest.mark.parametrize("case", list(CORRUPT))
def test_corrupt_preset_is_refused_and_changes_nothing(case, user_dir):
    text, message = CORRUPT[case]
    path = user_dir / "broken.json"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(presets.PresetError) as caught:
        presets.load(path)
    line = str(caught.value)
    assert message in line and "\n" not in line and line.startswith("broken.json: ")

    # Through the UI: the menu lists the problem; applying the valid values
    # of a partly broken preset never happens half-way.
    scene = scenes.empty_scene()
    before = snapshot(scene.solidwire)
    valid, problems = presets.user_presets()
    assert valid == [] and problems == [line]
    with pytest.raises(RuntimeError, match="no preset named"):
        bpy.ops.solidwire.preset_apply(name="Broken")
    assert snapshot(scene.solidwire) == before


def test_validation_happens_before_anything_is_applied():
    """The first keys are valid, the last is not: nothing is applied."""
    scene = scenes.empty_scene()
    before = snapshot(scene.solidwire)
    text = json.dumps(_document(use_backface_culling="yes"))
    with pytest.raises(presets.PresetError):
        presets.apply(presets.parse(text), scene.solidwire)
    assert snapshot(scene.solidwire) == before


def test_partial_preset_sets_only_its_keys_and_mode_before_duty():
    """diagonal_mode's update resets pattern_duty; a preset's own duty wins."""
    scene = scenes.empty_scene()
    scene.solidwire.thickness = 3.0
    preset = presets.parse(json.dumps({"solidwire_preset": 1, "name": "P", "settings": {"pattern_duty": 0.7, "diagonal_mode": "DOTTED"}}))
    presets.apply(preset, scene.solidwire)
    assert scene.solidwire.diagonal_mode == "DOTTED"
    assert scene.solidwire.pattern_duty == pytest.approx(0.7)
    assert scene.solidwire.thickness == 3.0


def test_user_dir_fallback_outside_the_addon():
    folder = presets.user_dir()
    assert folder.is_dir()
    assert Path(bpy.utils.user_resource("CONFIG")) in folder.parents


def test_bad_preset_names_are_refused(user_dir):
    with pytest.raises(RuntimeError, match="no letters or digits"):
        bpy.ops.solidwire.preset_add(name="../../")
    assert list(user_dir.iterdir()) == []


def test_user_dir_of_an_installed_extension(monkeypatch):
    """Installed as an extension (package bl_ext.<repo>.solidwire.solidwire_addon)
    the presets go to the extension's own user directory."""
    monkeypatch.setattr(presets, "__package__", "bl_ext.user_default.solidwire.solidwire_addon")
    folder = presets.user_dir()
    expected = Path(bpy.utils.extension_path_user("bl_ext.user_default.solidwire", path="presets"))
    assert folder == expected and folder.is_dir()
    assert Path(solidwire_addon.__file__).resolve().parent not in folder.resolve().parents
