"""Toggle operator, keymap, panels, menu and popover entry, headless.

Panels cannot be drawn without a window, so their draw functions are called
with a recording stand-in for ``UILayout``: it checks that every property and
operator they name exists, and records which rows are greyed out.
"""

from __future__ import annotations

import importlib.util
import os
from types import SimpleNamespace

import bpy
import pytest

import solidwire_addon
from solidwire_addon.blender import ops, presets, ui
from solidwire_addon.core import schema
from tests.support import scenes

SPEC_PROPERTIES = (
    "thickness",
    "softness",
    "wire_color",
    "use_fill",
    "fill_color",
    "diagonal_mode",
    "pattern_period",
    "pattern_duty",
    "use_fade",
    "fade_start",
    "fade_end",
    "use_backface_culling",
)


class FakeLayout:
    """Records what a draw function puts in a layout; fails on unknown names."""

    def __init__(self, parent=None):
        self.parent = parent
        self.active = True
        self.enabled = True
        self.use_property_split = False
        self.use_property_decorate = True
        self.props: list[tuple] = []  # (data, name, greyed)
        self.operators: list[str] = []
        self.menus: list[str] = []
        self.labels: list[str] = []
        self.root = parent.root if parent else self

    def greyed(self) -> bool:
        node = self
        while node is not None:
            if not node.active or not node.enabled:
                return True
            node = node.parent
        return False

    def _child(self, *_args, **_kwargs):
        return FakeLayout(self)

    row = column = box = split = column_flow = grid_flow = _child

    def separator(self, *_args, **_kwargs):
        pass

    def label(self, text="", **_kwargs):
        self.root.labels.append(text)

    def prop(self, data, name, **_kwargs):
        assert name in data.bl_rna.properties, f"no property {name!r} on {data!r}"
        self.root.props.append((data, name, self.greyed()))

    def operator(self, idname, **_kwargs):
        category, _, name = idname.partition(".")
        assert hasattr(getattr(bpy.ops, category), name) and getattr(getattr(bpy.ops, category), name).get_rna_type()
        self.root.operators.append(idname)
        return SimpleNamespace()

    def menu(self, idname, **_kwargs):
        assert hasattr(bpy.types, idname), idname
        self.root.menus.append(idname)

    def operator_menu_enum(self, idname, property, **_kwargs):
        self.operator(idname)
        category, _, name = idname.partition(".")
        rna = getattr(getattr(bpy.ops, category), name).get_rna_type()
        assert property in rna.properties, f"{idname} has no property {property!r}"

    def greyed_props(self, data=None) -> dict:
        """{name: greyed} of the rows drawn for ``data`` (default: every row
        except an object's own settings, which share names with the scene's)."""
        if data is not None:
            return {name: greyed for d, name, greyed in self.props if d == data}
        return {name: greyed for d, name, greyed in self.props if type(d).__name__ != "SolidWireObjectSettings"}


def draw_with(function, context, owner=None):
    layout = FakeLayout()
    function(SimpleNamespace(layout=layout), context)
    return layout


def test_toggle_operator_flips_show_overlay():
    scene = scenes.empty_scene()
    assert scene.solidwire.show_overlay is False
    assert bpy.ops.solidwire.toggle_overlay() == {"FINISHED"}
    assert scene.solidwire.show_overlay is True
    bpy.ops.solidwire.toggle_overlay()
    assert scene.solidwire.show_overlay is False


def _blender_default_keymap():
    path = os.path.join(
        bpy.utils.resource_path("LOCAL"), "scripts", "presets", "keyconfig", "keymap_data", "blender_default.py"
    )
    spec = importlib.util.spec_from_file_location("solidwire_test_blender_default", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.generate_keymaps(module.Params())


def _chord(event: dict) -> tuple:
    return (event["type"], *(bool(event.get(m)) for m in ("shift", "ctrl", "alt", "oskey")))


def test_toggle_key_is_registered_and_free_in_blender_default_keymap():
    keymap = bpy.context.window_manager.keyconfigs.addon.keymaps["3D View"]
    items = [kmi for kmi in keymap.keymap_items if kmi.idname == "solidwire.toggle_overlay"]
    assert len(items) == 1
    kmi = items[0]
    assert (kmi.type, kmi.shift, kmi.ctrl, kmi.alt) == ("W", True, True, True)

    ours = _chord(ops.TOGGLE_KEY)
    clashes = [
        (name, idname)
        for name, _params, data in _blender_default_keymap()
        for idname, event, _props in data["items"]
        if isinstance(event, dict) and not event.get("any") and _chord(event) == ours
    ]
    assert clashes == []
    # ...while the obvious Shift+Alt+W is taken (why ours has Ctrl too).
    plain = ("W", True, False, True, False)
    assert any(
        isinstance(event, dict) and _chord(event) == plain
        for _name, _params, data in _blender_default_keymap()
        for _idname, event, _props in data["items"]
    )


def test_unregister_leaves_nothing_behind():
    def our_keymap_items():
        keymap = bpy.context.window_manager.keyconfigs.addon.keymaps.get("3D View")
        return [] if keymap is None else [k for k in keymap.keymap_items if k.idname.startswith("solidwire.")]

    solidwire_addon.unregister()
    try:
        assert our_keymap_items() == []
        assert ui.appended_draw_functions("VIEW3D_PT_overlay") == []
        assert ui.appended_draw_functions("OBJECT_PT_visibility") == []
        assert not hasattr(bpy.types, "VIEW3D_PT_solidwire")
        assert not hasattr(bpy.types.Scene, "solidwire")
        assert not hasattr(bpy.types.Object, "solidwire_exclude")
        solidwire_addon.unregister()  # twice is fine
    finally:
        solidwire_addon.register()
        solidwire_addon.register()  # and so is registering twice
    assert len(our_keymap_items()) == 1
    assert ui.appended_draw_functions("VIEW3D_PT_overlay") == [ui.draw_overlay_popover]


def test_panels_menu_and_popover_are_registered():
    for name in ("VIEW3D_PT_solidwire", "RENDER_PT_solidwire", "SOLIDWIRE_MT_presets"):
        assert hasattr(bpy.types, name), name
    assert bpy.types.VIEW3D_PT_solidwire.bl_region_type == "UI"
    assert bpy.types.VIEW3D_PT_solidwire.bl_category == "SolidWire"
    assert ui.appended_draw_functions("VIEW3D_PT_overlay") == [ui.draw_overlay_popover]
    assert bpy.types.OBJECT_PT_solidwire.bl_context == "object"


@pytest.fixture
def context():
    scene = scenes.empty_scene()
    obj = scenes.cube(scene)
    return SimpleNamespace(scene=scene, object=obj, engine="SOLIDWIRE")


def test_sidebar_panel_draws_every_setting(context):
    layout = draw_with(ui.VIEW3D_PT_solidwire.draw, context)
    drawn = layout.greyed_props()
    for name in (*SPEC_PROPERTIES, "only_selected", "overlay_edit_mode"):
        assert name in drawn, name
    # The active object's own settings, the override's values greyed while it is off.
    assert layout.greyed_props(context.object.solidwire) == {
        "show_in_viewport": False,
        "show_in_render": False,
        "use_override": False,
        "wire_color": True,
        "thickness": True,
        "fill_color": True,
    }
    assert "solidwire.fade_from_visible" in layout.operators

    header = draw_with(ui.VIEW3D_PT_solidwire.draw_header, context)
    assert header.operators == ["solidwire.toggle_overlay"]
    preset_header = draw_with(ui.VIEW3D_PT_solidwire.draw_header_preset, context)
    assert preset_header.menus == ["SOLIDWIRE_MT_presets"]
    assert preset_header.operators == ["solidwire.preset_add", "solidwire.preset_remove"]


def test_rows_that_do_not_apply_are_greyed_not_hidden(context):
    props = context.scene.solidwire
    props.use_fill, props.diagonal_mode, props.use_fade, props.show_overlay = False, "SOLID", False, False
    greyed = draw_with(ui.VIEW3D_PT_solidwire.draw, context).greyed_props()
    for name in ("fill_color", "pattern_period", "pattern_duty", "fade_start", "fade_end", "only_selected"):
        assert greyed[name], f"{name} should be greyed"
    assert not greyed["thickness"]

    for name in (
        "hidden_alpha",
        "hidden_period",
        "hidden_duty",
        "world_thickness",
        "thickness_far",
        "density_fade_length",
        "seam_color",
        "sharp_thickness",
        "boundary_pattern",
    ):
        assert greyed[name], f"{name} should be greyed"

    props.use_fill, props.diagonal_mode, props.use_fade, props.show_overlay = True, "DASHED", True, True
    props.use_density_fade = True
    for name, *_rest in schema.EDGE_CLASS_STYLES:
        setattr(props, f"use_{name}_edges", True)
    props.use_hidden_lines, props.thickness_mode = True, "DEPTH"
    props.fill_shading = "MATCAP"
    greyed = draw_with(ui.VIEW3D_PT_solidwire.draw, context).greyed_props()
    assert {name for name, g in greyed.items() if g} == {"world_thickness"}

    # World-space width: the pixel widths do not apply, the world width
    # does; Thickness stays live while a class is on, since each class's
    # width keeps its ratio to it (image model §3.6).
    props.thickness_mode = "WORLD"
    greyed = draw_with(ui.VIEW3D_PT_solidwire.draw, context).greyed_props()
    assert {name for name, g in greyed.items() if g} == {
        "thickness_far",
        "thickness_depth_start",
        "thickness_depth_end",
    }
    for name, *_rest in schema.EDGE_CLASS_STYLES:
        setattr(props, f"use_{name}_edges", False)
    greyed = draw_with(ui.VIEW3D_PT_solidwire.draw, context).greyed_props()
    assert greyed["thickness"] and not greyed["world_thickness"]
    props.use_hidden_lines, props.thickness_mode = False, "PIXELS"
    props.use_density_fade = False
    for name, *_rest in schema.EDGE_CLASS_STYLES:
        setattr(props, f"use_{name}_edges", False)


def test_render_panel_and_its_poll(context):
    assert ui.RENDER_PT_solidwire.poll(context)
    assert not ui.RENDER_PT_solidwire.poll(SimpleNamespace(scene=context.scene, engine="CYCLES"))
    drawn = draw_with(ui.RENDER_PT_solidwire.draw, context).greyed_props()
    assert set(SPEC_PROPERTIES) <= set(drawn)


def test_presets_menu_lists_builtin_and_user_presets(context):
    folder = presets.user_dir()
    bpy.ops.solidwire.preset_add(name="Menu Test")
    (folder / "broken.json").write_text("{", encoding="utf-8")
    try:
        layout = draw_with(ui.SOLIDWIRE_MT_presets.draw, context)
        assert layout.operators.count("solidwire.preset_apply") == len(presets.builtin_presets()) + 1
        assert any(label.startswith("broken.json: not valid JSON") for label in layout.labels)
    finally:
        for path in folder.glob("*.json"):
            path.unlink()
        ops.active_preset_name = ""


def test_overlay_popover_and_object_entries(context):
    layout = draw_with(ui.draw_overlay_popover, context)
    assert layout.operators == ["solidwire.toggle_overlay"]
    obj = context.object
    assert ui.OBJECT_PT_solidwire.poll(context)
    layout = draw_with(ui.OBJECT_PT_solidwire.draw, context)
    assert "solidwire_exclude" not in layout.greyed_props()
    obj.solidwire.use_override = True
    assert not any(draw_with(ui.OBJECT_PT_solidwire.draw, context).greyed_props(obj.solidwire).values())
    # An older file's opt-out shows while it is set, so it can be cleared.
    obj.solidwire_exclude = True
    assert draw_with(ui.OBJECT_PT_solidwire.draw, context).greyed_props()["solidwire_exclude"] is False


def test_fade_range_from_visible_objects():
    scene = scenes.empty_scene()
    scenes.add_camera(scene, location=(0.0, -10.0, 0.0), target=(0.0, 0.0, 0.0))
    scenes.cube(scene, "Near", size=2.0, location=(0.0, -4.0, 0.0))  # depth 5..7
    scenes.cube(scene, "Far", size=2.0, location=(0.0, 6.0, 0.0))  # depth 15..17
    hidden = scenes.cube(scene, "Hidden", size=2.0, location=(0.0, 30.0, 0.0))
    hidden.hide_set(True)
    excluded = scenes.cube(scene, "Excluded", size=2.0, location=(0.0, 40.0, 0.0))
    excluded.solidwire_exclude = True
    # Outside a viewport the scene camera is the view.
    assert bpy.ops.solidwire.fade_from_visible() == {"FINISHED"}
    props = scene.solidwire
    assert props.use_fade
    assert (props.fade_start, props.fade_end) == pytest.approx((5.0, 17.0), abs=1e-4)


def test_fade_range_takes_the_finite_vertices_of_a_mesh_with_a_nan_vertex():
    """Blender's box of a mesh with a NaN vertex can be finite and miss
    vertices (Blender 5.0 gives this one depth 16 alone); the fade range
    spans its finite vertices."""
    scene = scenes.empty_scene()
    scenes.add_camera(scene, location=(0.0, -10.0, 0.0), target=(0.0, 0.0, 0.0))
    nan = float("nan")
    verts = [(-1.0, -4.0, -1.0), (1.0, -4.0, -1.0), (0.0, -4.0, 1.0), (0.0, nan, 0.0)]
    verts += [(0.0, 6.0, 0.0), (1.0, 6.0, 0.0), (0.0, 6.0, 1.0)]
    mesh = bpy.data.meshes.new("Broken")
    mesh.from_pydata(verts, [], [(0, 1, 2), (3, 4, 5, 6)])
    scene.collection.objects.link(bpy.data.objects.new("Broken", mesh))
    assert bpy.ops.solidwire.fade_from_visible() == {"FINISHED"}
    assert (scene.solidwire.fade_start, scene.solidwire.fade_end) == pytest.approx((6.0, 16.0), abs=1e-4)


def _two_viewports():
    """A screen of the factory file with two 3D Views (Animation workspace)."""
    screen = bpy.data.screens["Animation"]
    views = [area for area in screen.areas if area.type == "VIEW_3D"]
    assert len(views) >= 2
    return screen, views[0], views[1]


def test_each_viewport_has_its_own_toggle(tmp_path):
    from solidwire_addon.blender import overlay

    scene = scenes.empty_scene()
    props = scene.solidwire
    screen, first, second = _two_viewports()
    assert not overlay.viewport_shows(screen, first, props) and not overlay.viewport_shows(screen, second, props)
    with bpy.context.temp_override(screen=screen, area=first):
        assert ops.overlay_shown(bpy.context) is False
        assert bpy.ops.solidwire.toggle_overlay() == {"FINISHED"}
        assert ops.overlay_shown(bpy.context) is True
        # The checkbox drawn in this viewport shows its own state.
        layout = draw_with(ui.draw_overlay_popover, bpy.context)
    assert overlay.viewport_shows(screen, first, props)
    assert not overlay.viewport_shows(screen, second, props)
    assert props.show_overlay is False, "the scene default is not touched"

    # The scene setting is the default of viewports that never had a toggle.
    props.show_overlay = True
    assert overlay.viewport_shows(screen, second, props)
    with bpy.context.temp_override(screen=screen, area=first):
        bpy.ops.solidwire.toggle_overlay()
    assert not overlay.viewport_shows(screen, first, props)
    assert overlay.viewport_shows(screen, second, props)
    props.show_overlay = False
    with bpy.context.temp_override(screen=screen, area=first):
        bpy.ops.solidwire.toggle_overlay()

    # The choice is saved with the file's UI and comes back on reopening.
    path = tmp_path / "viewport_toggle.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    bpy.ops.wm.open_mainfile(filepath=str(path), load_ui=True)
    screen, first, second = _two_viewports()
    props = bpy.context.scene.solidwire
    assert overlay.viewport_shows(screen, first, props)
    assert not overlay.viewport_shows(screen, second, props)
    assert layout.operators == ["solidwire.toggle_overlay"]


def test_toggle_adds_no_undo_step():
    """View state, like Blender's own overlay options: no UNDO in the
    operator, and the toggle lives on a Screen, an ID type Blender's undo
    leaves out (ID_CHECK_UNDO), so a button on it pushes no undo step either."""
    from solidwire_addon.blender import properties

    assert "UNDO" not in ops.SOLIDWIRE_OT_toggle_overlay.bl_options
    toggles = bpy.types.Screen.bl_rna.properties[properties.VIEWPORTS_ATTRIBUTE]
    assert toggles.fixed_type.identifier == properties.SolidWireViewportToggle.__name__


def test_view_layer_passes_panel(context):
    view_layer = context.scene.view_layers[0]
    ctx = SimpleNamespace(scene=context.scene, engine="SOLIDWIRE", view_layer=view_layer)
    assert ui.VIEWLAYER_PT_solidwire_passes.poll(ctx)
    assert not ui.VIEWLAYER_PT_solidwire_passes.poll(SimpleNamespace(engine="CYCLES", view_layer=view_layer))
    drawn = draw_with(ui.VIEWLAYER_PT_solidwire_passes.draw, ctx).greyed_props()
    assert set(drawn) == {
        "use_pass_z",
        "use_pass_normal",
        "use_pass_object_index",
        "use_pass_material_index",
        "use_pass_wire",
        "use_pass_hidden_wire",
        "use_pass_edge_distance",
    }
    # Switching a pass asks Blender for the engine's passes again (no error headless).
    view_layer.solidwire.use_pass_wire = True
    view_layer.solidwire.use_pass_wire = False
