"""Presets: built-ins look different, user presets round-trip, bad files are
refused with one clear line and change nothing."""

from __future__ import annotations

import itertools
import json
from pathlib import Path
from types import SimpleNamespace

import bpy
import numpy as np
import pytest

import solidwire_addon
from solidwire_addon.blender import engine, ops, presets, ui
from solidwire_addon.blender.gpu_context import ensure_gpu
from tests.support import scenes

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
        applied, expected = snapshot(scene.solidwire), snapshot_of(preset)
        for key in preset.from_scene:  # measured on this scene instead
            applied.pop(key), expected.pop(key)
        assert applied == expected, preset.name
        images[preset.name] = render(scene)
    default = images.pop("Default")
    for name, image in images.items():
        assert np.abs(image - default).mean() > 0.01, f"'{name}' looks like the default"
    for (name_a, a), (name_b, b) in itertools.combinations(images.items(), 2):
        assert np.abs(a - b).mean() > 0.01, f"'{name_a}' and '{name_b}' look alike"


def snapshot_of(preset) -> dict:
    return {
        key: [round(c, 6) for c in value]
        if isinstance(value, tuple)
        else (round(value, 6) if isinstance(value, float) else value)
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

    # Saving again under the same name replaces it, when asked to.
    props.thickness = 4.0
    with pytest.raises(RuntimeError, match="a user preset named 'My Look' exists"):
        bpy.ops.solidwire.preset_add(name="My Look")
    assert presets.find("My Look").values["thickness"] == 2.75
    bpy.ops.solidwire.preset_add(name="My Look", overwrite=True)
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
    "duplicate key": (
        '{"solidwire_preset": 1, "name": "A", "name": "B", "settings": {"thickness": 1}}',
        "appears twice",
    ),
    "wrong version": (json.dumps(_document() | {"solidwire_preset": 2}), "'solidwire_preset' must be 1"),
    "no settings": (
        json.dumps({"solidwire_preset": 1, "name": "Empty", "settings": {}}),
        "'settings' must be a non-empty",
    ),
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
    preset = presets.parse(
        json.dumps({"solidwire_preset": 1, "name": "P", "settings": {"pattern_duty": 0.7, "diagonal_mode": "DOTTED"}})
    )
    presets.apply(preset, scene.solidwire)
    assert scene.solidwire.diagonal_mode == "DOTTED"
    assert scene.solidwire.pattern_duty == pytest.approx(0.7)
    assert scene.solidwire.thickness == 3.0


def test_user_presets_live_in_blenders_user_presets_folder():
    """Where Blender keeps add-on presets (user scripts/presets/<name>): it
    survives uninstalling, reinstalling and upgrading the extension, and a
    checkout (scripts/render.py) sees the same folder."""
    folder = presets.user_dir()
    assert folder.is_dir()
    assert folder == Path(bpy.utils.user_resource("SCRIPTS", path="presets/solidwire"))
    assert Path(solidwire_addon.__file__).resolve().parent not in folder.resolve().parents


def test_bad_preset_names_are_refused(user_dir):
    with pytest.raises(RuntimeError, match="no letters or digits"):
        bpy.ops.solidwire.preset_add(name="../../")
    assert list(user_dir.iterdir()) == []


def test_presets_of_older_versions_move_to_the_presets_folder_once(monkeypatch, user_dir):
    """Installed as an extension (package bl_ext.<repo>.solidwire...), older
    versions saved presets in the extension's user folder, which Blender
    deletes on uninstall; a checkout saved them in the config folder. Both
    move to the presets folder, without replacing a preset already there."""
    from_a_checkout = presets.user_dir()
    monkeypatch.setattr(presets, "__package__", "bl_ext.user_default.solidwire.solidwire_addon")
    monkeypatch.setattr(presets, "_migrated", set())
    extension_dir = Path(bpy.utils.extension_path_user("bl_ext.user_default.solidwire", path="presets", create=True))
    config_dir = Path(bpy.utils.user_resource("CONFIG")) / "solidwire_presets"
    config_dir.mkdir(parents=True, exist_ok=True)
    old_look = presets.to_json("Old Look", {"thickness": 2.5})
    (extension_dir / "old_look.json").write_text(old_look, encoding="utf-8")
    (config_dir / "checkout_look.json").write_text(
        presets.to_json("Checkout Look", {"thickness": 4.0}), encoding="utf-8"
    )
    (user_dir / "kept.json").write_text(presets.to_json("Kept", {"thickness": 1.0}), encoding="utf-8")
    (config_dir / "kept.json").write_text(presets.to_json("Kept", {"thickness": 9.0}), encoding="utf-8")
    try:
        assert presets.user_dir() == from_a_checkout == user_dir  # the extension and a checkout: one folder
        assert presets.find("Old Look").values["thickness"] == 2.5
        assert presets.find("Checkout Look").path == user_dir / "checkout_look.json"
        assert presets.find("Kept").values["thickness"] == 1.0  # the one already there wins
        assert not extension_dir.exists()  # emptied and removed
        assert [p.name for p in config_dir.iterdir()] == ["kept.json"]  # never overwritten, never lost
    finally:
        for folder in (extension_dir, config_dir):
            if folder.exists():
                for path in folder.iterdir():
                    path.unlink()
                folder.rmdir()


def test_an_unknown_preset_name_lists_close_matches_and_every_name():
    with pytest.raises(presets.PresetNotFound):
        presets.find("Bluprint")
    message = presets.unknown_preset_message("Bluprint", [p.name for p in presets.all_presets()])
    assert message.startswith("no preset named 'Bluprint' (did you mean 'Blueprint'? presets: ")
    assert all(p.name in message for p in presets.builtin_presets())
    assert "\n" not in message


# ------------------------------------------------- fade range from the scene


FADE = "Fade into Distance"


def far_model_scene(distance: float = 11.0):
    """Suzanne ``distance`` m in front of the camera (her depth about
    distance -/+ 0.9), beyond the Fade preset's stored 5..8 m."""
    scene = scenes.empty_scene(*SIZE)
    scenes.add_camera(scene, location=(0.0, -distance, 0.0), target=(0.0, 0.0, 0.0), lens=120.0)
    model = scenes.monkey(scene, rotation=(0.0, 0.0, 0.5))
    return scene, model


def model_depths(scene, model, view_matrix=None) -> tuple[float, float]:
    """(nearest, farthest) view depth of the model's vertices, seen from
    ``view_matrix`` (default: the scene camera)."""
    bpy.context.view_layer.update()
    if view_matrix is None:
        view_matrix = scene.camera.matrix_world.normalized().inverted()
    view = np.array(view_matrix, dtype=np.float64)
    verts = np.array([(*(model.matrix_world @ v.co), 1.0) for v in model.data.vertices])
    depth = -(verts @ view[2])
    return float(depth.min()), float(depth.max())


def test_fade_preset_measures_its_range_on_the_scene():
    """The bug: the stored 5..8 m range made a model 11 m away vanish. The
    preset takes its range from the scene when applied: it contains the
    model and the render shows it."""
    fade = presets.find(FADE)
    assert fade.from_scene == ("fade_start", "fade_end")
    assert "measured" in fade.description and "5 to 8" in fade.description

    scene, model = far_model_scene(11.0)
    near, far = model_depths(scene, model)
    assert 10.0 < near < far < 12.5

    # What the stored numbers alone give: nothing at all.
    presets.apply(fade, scene.solidwire)
    assert (scene.solidwire.fade_start, scene.solidwire.fade_end) == (5.0, 8.0)
    assert render(scene)[..., 3].max() == 0.0

    assert bpy.ops.solidwire.preset_apply(name=FADE) == {"FINISHED"}
    props = scene.solidwire
    assert props.use_fade
    assert props.fade_start <= near < far <= props.fade_end
    assert props.fade_end - props.fade_start < 3.0  # the model's depth, not an arbitrary wide range
    alpha = render(scene)[..., 3]
    assert alpha.max() > 0.5 and (alpha > 0.05).sum() > 200


def test_fade_preset_follows_the_camera_distance():
    for distance in (3.0, 40.0):
        scene, model = far_model_scene(distance)
        bpy.ops.solidwire.preset_apply(name=FADE)
        near, far = model_depths(scene, model)
        assert scene.solidwire.fade_start <= near < far <= scene.solidwire.fade_end, distance


def test_fade_preset_measures_from_the_viewport():
    """In a 3D View the range is measured from that view (here the factory
    file's, ~18 m from the model), like "Fade Range from Visible Objects"."""
    scene, model = far_model_scene(11.0)
    area = next(a for a in bpy.data.screens["Layout"].areas if a.type == "VIEW_3D")
    space = area.spaces.active
    near, far = model_depths(scene, model, space.region_3d.view_matrix)
    assert near > 14.0  # not the camera's 11 m
    with bpy.context.temp_override(area=area, space_data=space):
        assert bpy.ops.solidwire.preset_apply(name=FADE) == {"FINISHED"}
    props = scene.solidwire
    assert props.fade_start <= near < far <= props.fade_end < far + 2.0


def test_fade_preset_with_nothing_to_measure_keeps_its_numbers(capfd):
    scene = scenes.empty_scene()  # no camera, no viewport, no mesh
    assert bpy.ops.solidwire.preset_apply(name=FADE) == {"FINISHED"}
    assert (scene.solidwire.fade_start, scene.solidwire.fade_end) == (5.0, 8.0)
    assert "nothing visible to measure the fade range from; kept 5 to 8" in capfd.readouterr().out
    # A camera but nothing in front of it: the same.
    scenes.add_camera(scene, location=(0.0, -5.0, 0.0), target=(0.0, 0.0, 0.0))
    scenes.cube(scene, location=(0.0, -20.0, 0.0))  # behind the camera
    note = presets.apply(presets.find(FADE), scene.solidwire, depth_range=lambda: None)
    assert note.startswith("nothing visible")
    # A measurement beyond the settings' range is not used either.
    note = presets.apply(presets.find(FADE), scene.solidwire, depth_range=lambda: (1.0, 1e12))
    assert note.startswith("nothing visible") and scene.solidwire.fade_end == 8.0


def test_fade_preset_on_the_command_line():
    """``--preset`` measures from the scene camera (after ``--camera``), and
    only objects a render draws count; ``--fade`` still wins."""
    from solidwire_addon.blender import cli

    scene, model = far_model_scene(11.0)
    ghost = scenes.cube(scene, "NotRendered", location=(0.0, 60.0, 0.0))
    ghost.hide_render = True
    args = cli.build_parser().parse_args(["--preset", FADE])
    cli.apply_options(scene, args)
    near, far = model_depths(scene, model)
    assert scene.solidwire.fade_start <= near < far <= scene.solidwire.fade_end < 13.5

    scenes.add_camera(scene, location=(0.0, -25.0, 0.0), target=(0.0, 0.0, 0.0), name="Far Camera")
    scene.camera = bpy.data.objects["Camera"]
    cli.apply_options(scene, cli.build_parser().parse_args(["--preset", FADE, "--camera", "Far Camera"]))
    assert 23.0 < scene.solidwire.fade_start < 25.0 < scene.solidwire.fade_end < 27.0

    cli.apply_options(scene, cli.build_parser().parse_args(["--preset", FADE, "--fade", "1", "2"]))
    assert (scene.solidwire.fade_start, scene.solidwire.fade_end) == (1.0, 2.0)


FROM_SCENE_ERRORS = {
    "not a list": ("fade", "'from_scene' must be a list of setting names"),
    "unknown setting": (["fade_start", "fade_end", "glow"], "unknown setting 'glow' in 'from_scene'"),
    "not measurable": (["thickness"], "'thickness' cannot be taken from the scene"),
    "half a range": (["fade_end"], "'from_scene' must name fade_start and fade_end once each"),
    "twice": (["fade_start", "fade_start", "fade_end"], "'from_scene' must name fade_start and fade_end once each"),
}


@pytest.mark.parametrize("case", list(FROM_SCENE_ERRORS))
def test_bad_from_scene_is_refused(case):
    value, message = FROM_SCENE_ERRORS[case]
    with pytest.raises(presets.PresetError, match=message):
        presets.parse(json.dumps(_document() | {"from_scene": value}), source="x.json")


def test_plain_presets_are_written_as_before():
    """Only a preset that measures its fade range carries "from_scene": every
    other file stays what an older version reads."""
    scene = scenes.empty_scene()
    data = json.loads(presets.to_json("Plain", presets.values_of(scene.solidwire)))
    assert set(data) == {"solidwire_preset", "name", "description", "settings"}
    assert data["solidwire_preset"] == 1


# ----------------------------------------------------------------- tooltips


def test_menu_entries_show_the_presets_description_as_tooltip(user_dir):
    apply_op = bpy.types.SOLIDWIRE_OT_preset_apply
    for preset in presets.builtin_presets():
        assert apply_op.description(bpy.context, SimpleNamespace(name=preset.name)) == preset.description
    scenes.empty_scene()
    bpy.ops.solidwire.preset_add(name="Described", preset_description="Thick red lines for reviews")
    bpy.ops.solidwire.preset_add(name="Undescribed")
    assert apply_op.description(bpy.context, SimpleNamespace(name="Described")) == "Thick red lines for reviews"
    assert apply_op.description(bpy.context, SimpleNamespace(name="Undescribed")) == "Your preset (undescribed.json)"
    assert apply_op.description(bpy.context, SimpleNamespace(name="Gone")) == "no preset named 'Gone'"
    assert apply_op.description(bpy.context, SimpleNamespace(name="")) == apply_op.__doc__


class MenuLayout:
    """Records a menu's entries: (operator, text, properties set) and labels."""

    def __init__(self):
        self.entries, self.labels = [], []
        self.alert = False

    def operator(self, idname, text="", icon="NONE"):
        props = SimpleNamespace()
        self.entries.append((idname, text, props))
        return props

    def label(self, text="", icon="NONE"):
        self.labels.append(text)

    def separator(self):
        pass

    def prop(self, data, name, text=""):
        assert name in data.bl_rna.properties, name
        self.entries.append(("prop", text or name, None))

    def row(self):
        return self


def draw_menu() -> MenuLayout:
    layout = MenuLayout()
    ui.SOLIDWIRE_MT_presets.draw(SimpleNamespace(layout=layout), bpy.context)
    return layout


def test_presets_menu_has_import_and_export(user_dir):
    scenes.empty_scene()
    bpy.ops.solidwire.preset_add(name="線画")
    menu = draw_menu()
    applied = [(text, props.name) for idname, text, props in menu.entries if idname == "solidwire.preset_apply"]
    assert applied[-1] == ("線画", "線画")
    assert [idname for idname, _text, _props in menu.entries[-2:]] == [
        "solidwire.preset_import",
        "solidwire.preset_export",
    ]


# --------------------------------------------------- names: built-ins, look-alikes


@pytest.mark.parametrize(
    "name",
    ["Blueprint", "blueprint", "  BLUEPRINT  ", "Fade into Distance", "fade-into-distance", "FADE_INTO_DISTANCE"],
)
def test_a_user_preset_cannot_take_a_builtin_name(name, user_dir):
    """Refused, not renamed: a preset saved under a name other than the one
    typed would be a surprise, and one name meaning two looks (menu,
    --preset, farm jobs) would be worse. The message names the built-in."""
    scenes.empty_scene()
    with pytest.raises(
        RuntimeError,
        match=r"is the name of the built-in preset '(Blueprint|Fade into Distance)'; "
        "choose another name",
    ) as caught:
        bpy.ops.solidwire.preset_add(name=name)
    assert "\n" not in str(caught.value).strip()
    assert list(user_dir.iterdir()) == []


def test_a_builtin_named_file_from_elsewhere_is_skipped_with_a_message(user_dir):
    """A user file named like a built-in (by hand, or an older version) never
    shadows it: it is listed as a problem and the built-in stays."""
    text = presets.to_json("blueprint", {"thickness": 9.0})
    (user_dir / "blueprint.json").write_text(text, encoding="utf-8")
    valid, problems = presets.user_presets()
    assert valid == [] and len(problems) == 1
    assert problems[0].startswith("blueprint.json: 'blueprint' is named like the built-in preset 'Blueprint'")
    assert presets.find("blueprint").builtin and presets.find("Blueprint").values["thickness"] != 9.0


@pytest.mark.parametrize("other", ["my look", "My_Look", "  MY LOOK ", "my-look!"])
def test_a_lookalike_name_does_not_silently_overwrite(other, user_dir):
    scene = scenes.empty_scene()
    scene.solidwire.thickness = 2.0
    bpy.ops.solidwire.preset_add(name="My Look")
    scene.solidwire.thickness = 5.0
    with pytest.raises(RuntimeError, match="a user preset named 'My Look' exists; choose another name or overwrite it"):
        bpy.ops.solidwire.preset_add(name=other)
    assert presets.find("My Look").values["thickness"] == 2.0
    # Explicitly: replaced, in the same file, under the new spelling.
    bpy.ops.solidwire.preset_add(name=other, overwrite=True)
    assert [p.name for p in presets.user_presets()[0]] == [other.strip()]
    assert [p.name for p in user_dir.glob("*.json")] == ["my_look.json"]
    assert presets.find(other.strip()).values["thickness"] == 5.0


def test_the_add_dialog_says_what_saving_would_do(user_dir):
    """Before OK: a built-in's name is flagged; an existing look-alike user
    preset shows the Overwrite box (in red while unticked)."""
    scenes.empty_scene()
    bpy.ops.solidwire.preset_add(name="My Look")
    rna = bpy.ops.solidwire.preset_add.get_rna_type()

    def dialog(name, overwrite=False):
        layout = MenuLayout()
        operator = SimpleNamespace(layout=layout, name=name, overwrite=overwrite, preset_description="", bl_rna=rna)
        ops.SOLIDWIRE_OT_preset_add.draw(operator, bpy.context)
        return layout

    assert dialog("New Look").labels == []
    assert [text for kind, text, _ in dialog("New Look").entries] == ["name", "preset_description"]
    assert dialog(" blueprint ").labels == ["'Blueprint' is a built-in preset: choose another name"]
    layout = dialog("my_look")
    assert layout.entries[-1][:2] == ("prop", "Overwrite 'My Look'") and layout.alert
    assert not dialog("my_look", overwrite=True).alert


def test_find_and_remove_accept_the_name_up_to_case(user_dir):
    scenes.empty_scene()
    bpy.ops.solidwire.preset_add(name="My Look")
    assert presets.find("my look").name == "My Look"
    assert presets.find("blueprint").name == "Blueprint"
    assert ops.active_preset_name == "My Look"
    bpy.ops.solidwire.preset_remove(name="MY_LOOK")
    assert list(user_dir.glob("*.json")) == []
    assert ops.active_preset_name == ""


# ------------------------------------------------------------ non-ASCII names


@pytest.mark.parametrize(
    "name, filename",
    [
        ("Böse Linien", "böse_linien.json"),
        ("線画", "線画.json"),
        ("Ünïcödé — Look", "ünïcödé_look.json"),
        ("हिन्दी", "हिन्दी.json"),
    ],
)
def test_non_ascii_names_keep_their_letters(name, filename, user_dir):
    scene = scenes.empty_scene()
    props = scene.solidwire
    props.thickness, props.wire_color = 3.25, (0.2, 0.4, 0.6, 1.0)
    saved = snapshot(props)
    bpy.ops.solidwire.preset_add(name=name)
    assert ops.active_preset_name == name

    path = user_dir / filename
    assert [p.name for p in user_dir.iterdir()] == [filename]
    assert json.loads(path.read_text(encoding="utf-8"))["name"] == name
    assert name in path.read_text(encoding="utf-8")  # readable in the file, not \\u-escaped

    assert [p.name for p in presets.user_presets()[0]] == [name]
    assert [text for idname, text, _p in draw_menu().entries if idname == "solidwire.preset_apply"][-1] == name
    bpy.ops.solidwire.preset_apply(name="Default")
    bpy.ops.solidwire.preset_apply(name=name)
    assert snapshot(props) == saved
    assert ops.active_preset_name == name


def test_non_ascii_lookalikes_are_the_same_preset(user_dir):
    """Case folding and Unicode normalisation: "BÖSE LINIEN" and a
    decomposed "Böse Linien" (o + combining diaeresis) are the same name."""
    scenes.empty_scene()
    bpy.ops.solidwire.preset_add(name="Böse Linien")
    for other in ("BÖSE LINIEN", "Bo\u0308se Linien", "böse_linien"):
        with pytest.raises(RuntimeError, match="a user preset named 'Böse Linien' exists"):
            bpy.ops.solidwire.preset_add(name=other)
    # Names in different scripts are different presets.
    bpy.ops.solidwire.preset_add(name="Bose Linien")
    assert len(list(user_dir.glob("*.json"))) == 2


def test_file_names_stay_safe_for_any_name():
    assert presets.filename_for("../../etc/passwd") == "etc_passwd.json"
    assert presets.filename_for("CON") == "con_.json" and presets.filename_for("lpt1") == "lpt1_.json"
    long = presets.filename_for("𠀀" * 64)  # 4 bytes each in UTF-8
    assert len(long.encode("utf-8")) <= 130 and long.endswith(".json")
    assert presets.filename_for("𠀀" * 64) == long and presets.filename_for("𠀀" * 63) != long
    with pytest.raises(presets.PresetError, match="no letters or digits"):
        presets.filename_for("🎨 -- 🎨")


def test_a_name_of_64_characters_in_any_script_is_accepted(user_dir):
    scenes.empty_scene()
    name = "線" * 64
    bpy.ops.solidwire.preset_add(name=name)
    assert presets.find(name).name == name
    with pytest.raises(RuntimeError, match="at most 64 characters"):
        bpy.ops.solidwire.preset_add(name="線" * 65)


# -------------------------------------------------------- export and import


def test_export_current_settings_and_import_them_back(user_dir, tmp_path):
    scene = scenes.empty_scene()
    props = scene.solidwire
    props.thickness, props.diagonal_mode = 3.5, "DOTTED"
    saved = snapshot(props)
    path = ops.export_preset_file(tmp_path / "shared", props, name="Shared Look", description="For the team")
    assert path == tmp_path / "shared.json"
    exported = presets.load(path)
    assert (exported.name, exported.description) == ("Shared Look", "For the team")
    assert list(user_dir.iterdir()) == []  # exporting adds nothing to the user's presets

    bpy.ops.solidwire.preset_apply(name="Default")
    imported = presets.import_file(path)
    assert imported.name == "Shared Look" and imported.path.parent == user_dir
    bpy.ops.solidwire.preset_apply(name="Shared Look")
    assert snapshot(props) == saved


def test_export_a_chosen_preset_keeps_its_meaning(user_dir, tmp_path):
    scenes.empty_scene()
    path = ops.export_preset_file(tmp_path / "fade.json", None, preset=FADE)
    exported = presets.load(path)
    builtin = presets.find(FADE)
    assert (exported.values, exported.description, exported.from_scene) == (
        builtin.values,
        builtin.description,
        builtin.from_scene,
    )
    # Importing it under its own name would shadow the built-in: refused.
    with pytest.raises(presets.PresetError, match="is the name of the built-in preset 'Fade into Distance'"):
        presets.import_file(path)
    mine = presets.import_file(path, name="My Fade")
    assert mine.from_scene == builtin.from_scene and mine.values == builtin.values


def test_export_and_import_operators(user_dir, tmp_path):
    scene = scenes.empty_scene()
    scene.solidwire.thickness = 6.0
    target = tmp_path / "mine.json"
    assert bpy.ops.solidwire.preset_export(filepath=str(target), name="Operator Look") == {"FINISHED"}
    assert presets.load(target).values["thickness"] == 6.0
    assert bpy.ops.solidwire.preset_export(filepath=str(tmp_path / "blueprint.json"), preset="Blueprint") == {
        "FINISHED"
    }
    assert presets.load(tmp_path / "blueprint.json").values == presets.find("Blueprint").values

    assert bpy.ops.solidwire.preset_import(filepath=str(target)) == {"FINISHED"}
    assert presets.find("Operator Look").path.parent == user_dir
    # The same name again: refused unless asked to overwrite; or another name.
    with pytest.raises(RuntimeError, match="cannot import preset: a user preset named 'Operator Look' exists"):
        bpy.ops.solidwire.preset_import(filepath=str(target))
    assert bpy.ops.solidwire.preset_import(filepath=str(target), overwrite=True) == {"FINISHED"}
    assert bpy.ops.solidwire.preset_import(filepath=str(target), name="Böse Linien") == {"FINISHED"}
    assert sorted(p.name for p in presets.user_presets()[0]) == ["Böse Linien", "Operator Look"]

    with pytest.raises(RuntimeError, match="is the name of the built-in preset 'Blueprint'"):
        bpy.ops.solidwire.preset_import(filepath=str(tmp_path / "blueprint.json"))
    assert bpy.ops.solidwire.preset_import(filepath=str(tmp_path / "blueprint.json"), name="My Blueprint") == {
        "FINISHED"
    }
    with pytest.raises(RuntimeError, match="cannot export preset: no preset named 'Nope'"):
        bpy.ops.solidwire.preset_export(filepath=str(tmp_path / "x.json"), preset="Nope")
    with pytest.raises(
        RuntimeError, match="cannot export preset: x.json: cannot write \\(No such file or directory\\)"
    ):
        bpy.ops.solidwire.preset_export(filepath=str(tmp_path / "missing" / "x.json"))


@pytest.mark.parametrize("case", list(CORRUPT))
def test_import_refuses_a_bad_file_with_one_line(case, user_dir, tmp_path):
    text, message = CORRUPT[case]
    path = tmp_path / "incoming.json"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(RuntimeError) as caught:
        bpy.ops.solidwire.preset_import(filepath=str(path))
    line = str(caught.value).strip()
    assert "\n" not in line and "cannot import preset: incoming.json: " in line and message in line
    assert list(user_dir.iterdir()) == []


def test_import_refuses_what_is_not_a_preset_file(user_dir, tmp_path):
    for path, message in ((tmp_path / "absent.json", "absent.json: cannot read"), (tmp_path, "not a regular file")):
        with pytest.raises(RuntimeError, match=message):
            bpy.ops.solidwire.preset_import(filepath=str(path))
    assert list(user_dir.iterdir()) == []
