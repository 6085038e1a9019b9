"""Operators (toggle, fade range, presets and preset files) and the add-on keymap.

Operators change settings or preset files and nothing else: drawing happens in
the overlay handler, reacting to the settings' update callbacks.
"""

from __future__ import annotations

from pathlib import Path

import bpy
from bpy.props import BoolProperty, StringProperty
from bpy_extras.io_utils import ExportHelper, ImportHelper

from ..core.log import one_line
from . import overlay, presets
from .fade_range import visible_depth_extent
from .operator_errors import one_line_errors
from .overlay import viewport_object_filter
from .runtime import redraw_viewports

# Default key of the overlay toggle in the 3D View: Ctrl+Shift+Alt+W ("W" for
# wire). Shift+Alt+W is taken in Blender's default keymap (Sculpt: expand face
# sets, Pose: selection sets) and mode keymaps win over the 3D View keymap, so
# the plain chord would silently do nothing there. tests/test_ui.py checks the
# chord against Blender's default keymap data.
TOGGLE_KEY = {"type": "W", "value": "PRESS", "shift": True, "ctrl": True, "alt": True}

_keymap_items: list = []

# The name of the preset last applied or saved (shown on the presets menu and
# removed by "-"), like Blender's own preset menus.
active_preset_name = ""


def _solidwire(context):
    return context.scene.solidwire


def current_viewport(context):
    """(screen, area) of the 3D View the operator or panel acts on, or None."""
    area = getattr(context, "area", None)
    screen = getattr(context, "screen", None)
    if area is None or screen is None or area.type != "VIEW_3D":
        return None
    return screen, area


def overlay_shown(context) -> bool:
    """Whether SolidWire is on in the current 3D View (the scene default
    outside a 3D View)."""
    props = _solidwire(context)
    viewport = current_viewport(context)
    if viewport is None:
        return bool(props.show_overlay)
    return overlay.viewport_shows(*viewport, props)


class SOLIDWIRE_OT_toggle_overlay(bpy.types.Operator):
    """Show or hide the SolidWire overlay in this 3D View (outside a 3D View: the default for viewports)"""

    bl_idname = "solidwire.toggle_overlay"
    bl_label = "Toggle SolidWire Overlay"
    # No UNDO: the toggle is view state kept on the screen, like Blender's own
    # overlay options; undoing a modelling step must not flip it.
    bl_options = {"REGISTER"}

    @classmethod
    def poll(cls, context):
        return getattr(context.scene, "solidwire", None) is not None

    @one_line_errors
    def execute(self, context):
        props = _solidwire(context)
        viewport = current_viewport(context)
        if viewport is None:
            props.show_overlay = not props.show_overlay
        else:
            overlay.set_viewport_shows(*viewport, not overlay.viewport_shows(*viewport, props))
            viewport[1].tag_redraw()
        return {"FINISHED"}


def fade_view(context):
    """(view matrix, 3D View space or None) that fade ranges are measured
    from: the current 3D View, else the scene camera; None with neither."""
    space = (
        context.space_data if getattr(context, "space_data", None) and context.space_data.type == "VIEW_3D" else None
    )
    # From the sidebar the current region is not the 3D region itself:
    # fall back to the space's main 3D region.
    region_3d = getattr(context, "region_data", None) or getattr(space, "region_3d", None)
    if region_3d is not None and hasattr(region_3d, "view_matrix"):
        return region_3d.view_matrix, space
    if context.scene.camera is not None:
        return context.scene.camera.matrix_world.normalized().inverted(), space
    return None


def visible_fade_range(context):
    """(near, far) view depth of the objects the overlay draws, seen from
    :func:`fade_view`, or None when there is no view or no visible mesh in
    front of it."""
    depsgraph = context.evaluated_depsgraph_get()  # first: the camera's matrix is then current
    view = fade_view(context)
    if view is None:
        return None
    view_matrix, space = view
    props = _solidwire(context)
    keep = viewport_object_filter(
        context.view_layer, space, only_selected=props.only_selected, draw_edit_mode=props.overlay_edit_mode
    )
    return visible_depth_extent(depsgraph, view_matrix, keep)


class SOLIDWIRE_OT_fade_from_visible(bpy.types.Operator):
    """Set the depth fade range to the depth extent of the visible objects, seen from this viewport (or from the scene camera outside a viewport), and turn depth fade on"""

    bl_idname = "solidwire.fade_from_visible"
    bl_label = "Fade Range from Visible Objects"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        return getattr(context.scene, "solidwire", None) is not None

    @one_line_errors
    def execute(self, context):
        props = _solidwire(context)
        if fade_view(context) is None:
            self.report({"ERROR"}, "SolidWire: no 3D viewport or scene camera to measure depth from")
            return {"CANCELLED"}
        extent = visible_fade_range(context)
        if extent is None:
            self.report({"WARNING"}, "SolidWire: no visible mesh in front of the view")
            return {"CANCELLED"}
        props.fade_start, props.fade_end = extent
        props.use_fade = True
        self.report({"INFO"}, f"SolidWire: depth fade {extent[0]:.3g} to {extent[1]:.3g}")
        return {"FINISHED"}


def _preset_tooltip(name: str) -> str:
    """A preset's description for its menu entry (read on hover)."""
    try:
        preset = presets.find(name)
    except presets.PresetError as exc:
        return str(exc)
    if preset.description:
        return preset.description
    return "Your preset" + (f" ({preset.path.name})" if preset.path is not None else "")


class SOLIDWIRE_OT_preset_apply(bpy.types.Operator):
    """Apply a SolidWire preset"""

    bl_idname = "solidwire.preset_apply"
    bl_label = "Apply SolidWire Preset"
    bl_options = {"REGISTER", "UNDO"}

    name: StringProperty(name="Preset", description="Name of the preset to apply")

    @classmethod
    def description(cls, context, properties):
        return _preset_tooltip(properties.name) if properties.name else cls.__doc__

    @one_line_errors
    def execute(self, context):
        global active_preset_name
        try:
            preset = presets.find(self.name)
        except presets.PresetError as exc:
            self.report({"ERROR"}, f"SolidWire: {exc}")
            return {"CANCELLED"}
        note = presets.apply(preset, _solidwire(context), depth_range=lambda: visible_fade_range(context))
        active_preset_name = preset.name
        if note:
            self.report({"INFO"}, f"SolidWire: '{preset.name}': {note}")
        redraw_viewports()
        return {"FINISHED"}


OVERWRITE_HELP = (
    "Replace your preset of the same name (names that differ only in case, spaces or punctuation are the same preset)"
)


def draw_name_check(layout, operator) -> None:
    """Under the Add dialog's name: what saving under it would do. A
    built-in's name is refused (said here, before OK); an existing user
    preset of that name shows the Overwrite box, unticked and in red."""
    name = operator.name
    try:
        clash = presets.find(name) if name.strip() else None
    except presets.PresetError:
        clash = None
    if clash is not None and clash.builtin:
        layout.label(text=f"'{clash.name}' is a built-in preset: choose another name", icon="ERROR")
        return
    existing = presets.user_preset_like(name)
    if existing is not None:
        row = layout.row()
        row.alert = not operator.overwrite
        row.prop(operator, "overwrite", text=f"Overwrite '{existing.name}'")


class SOLIDWIRE_OT_preset_add(bpy.types.Operator):
    """Save the current SolidWire settings as a user preset"""

    bl_idname = "solidwire.preset_add"
    bl_label = "Add SolidWire Preset"
    bl_options = {"REGISTER"}

    # No maxlen: Blender counts it in bytes and could cut a character of a
    # non-Latin name in half; the length (in characters) is checked on save.
    name: StringProperty(name="Name", description="Name of the new preset", default="My Preset")
    # Not "description": that name is the operator's tooltip hook in Blender.
    preset_description: StringProperty(name="Description", description="Shown as the preset's tooltip", default="")
    overwrite: BoolProperty(name="Overwrite", default=False, description=OVERWRITE_HELP)

    @one_line_errors
    def invoke(self, context, event):
        return context.window_manager.invoke_props_dialog(self)

    def draw(self, context):
        layout = self.layout
        layout.prop(self, "name")
        layout.prop(self, "preset_description")
        draw_name_check(layout, self)

    @one_line_errors
    def execute(self, context):
        global active_preset_name
        try:
            path = presets.save(
                self.name, _solidwire(context), description=self.preset_description, overwrite=self.overwrite
            )
        except (presets.PresetError, OSError) as exc:
            self.report({"ERROR"}, f"SolidWire: cannot save preset: {exc}")
            return {"CANCELLED"}
        active_preset_name = self.name.strip()
        self.report({"INFO"}, f"SolidWire: saved preset '{active_preset_name}' to {path}")
        return {"FINISHED"}


class SOLIDWIRE_OT_preset_remove(bpy.types.Operator):
    """Delete the active SolidWire user preset (built-in presets cannot be removed)"""

    bl_idname = "solidwire.preset_remove"
    bl_label = "Remove SolidWire Preset"
    bl_options = {"REGISTER"}

    name: StringProperty(name="Preset", description="User preset to delete (default: the active one)")

    @classmethod
    def poll(cls, context):
        return bool(active_preset_name)

    @one_line_errors
    def invoke(self, context, event):
        if not self.name:
            self.name = active_preset_name
        return context.window_manager.invoke_confirm(self, event)

    @one_line_errors
    def execute(self, context):
        global active_preset_name
        name = self.name or active_preset_name
        try:
            presets.remove(name)
        except (presets.PresetError, OSError) as exc:
            self.report({"ERROR"}, f"SolidWire: {exc}")
            return {"CANCELLED"}
        if active_preset_name:
            try:  # "my look" removes "My Look": the active one may be gone
                presets.find(active_preset_name)
            except presets.PresetError:
                active_preset_name = ""
        return {"FINISHED"}


def _preset_names(self, context, edit_text):
    """Search list of the Export operator's Preset field."""
    text = edit_text.casefold()
    return [p.name for p in presets.all_presets() if text in p.name.casefold()]


def export_preset_file(path, props, *, preset: str = "", name: str = "", description: str = "") -> Path:
    """What "Export Preset" writes: the preset called ``preset`` when given,
    else ``props``' current settings under ``name``. Adds ``.json`` to a path
    without it. PresetError / OSError when it cannot."""
    path = Path(path)
    if path.suffix.lower() != ".json":
        path = path.with_name(path.name + ".json")
    if preset:
        chosen = presets.find(preset)
    else:
        chosen = presets.Preset((name or "").strip() or "My Preset", presets.values_of(props), description)
    return presets.export(path, chosen)


def _default_export_name() -> str:
    """The active preset's name when it is the user's own, else "My Preset"
    (a built-in's name could not be imported back)."""
    if active_preset_name:
        try:
            if not presets.find(active_preset_name).builtin:
                return active_preset_name
        except presets.PresetError:
            pass
    return "My Preset"


class SOLIDWIRE_OT_preset_export(bpy.types.Operator, ExportHelper):
    """Write the current SolidWire settings (or a chosen preset) to a preset file, to keep or share"""

    bl_idname = "solidwire.preset_export"
    bl_label = "Export SolidWire Preset"
    bl_options = {"REGISTER"}

    filename_ext = ".json"
    filter_glob: StringProperty(default="*.json", options={"HIDDEN"})
    preset: StringProperty(
        name="Preset",
        description="Preset to export (empty: the current settings)",
        search=_preset_names,
    )
    name: StringProperty(name="Name", description="Name the current settings get in the file")
    preset_description: StringProperty(name="Description", description="Description written with the current settings")

    @classmethod
    def poll(cls, context):
        return getattr(context.scene, "solidwire", None) is not None

    @one_line_errors
    def invoke(self, context, event):
        if not self.name:
            self.name = _default_export_name()
        if not self.filepath:
            try:
                self.filepath = presets.filename_for(self.preset or self.name)
            except presets.PresetError:
                self.filepath = "preset.json"
        context.window_manager.fileselect_add(self)
        return {"RUNNING_MODAL"}

    def draw(self, context):
        layout = self.layout
        layout.prop(self, "preset")
        col = layout.column()
        col.active = not self.preset  # name and description: current settings only
        col.prop(self, "name")
        col.prop(self, "preset_description")

    @one_line_errors
    def execute(self, context):
        if not self.filepath:
            self.report({"ERROR"}, "SolidWire: cannot export preset: no file chosen")
            return {"CANCELLED"}
        try:
            path = export_preset_file(
                bpy.path.abspath(self.filepath),
                _solidwire(context),
                preset=self.preset,
                name=self.name or _default_export_name(),
                description=self.preset_description,
            )
        except (presets.PresetError, OSError) as exc:
            self.report({"ERROR"}, f"SolidWire: cannot export preset: {one_line(exc)}")
            return {"CANCELLED"}
        self.report({"INFO"}, f"SolidWire: exported preset to {path}")
        return {"FINISHED"}


class SOLIDWIRE_OT_preset_import(bpy.types.Operator, ImportHelper):
    """Add a preset file (.json) to your SolidWire presets; the file is checked completely first"""

    bl_idname = "solidwire.preset_import"
    bl_label = "Import SolidWire Preset"
    bl_options = {"REGISTER"}

    filename_ext = ".json"
    filter_glob: StringProperty(default="*.json", options={"HIDDEN"})
    name: StringProperty(name="Name", description="Import under this name (empty: the name in the file)")
    overwrite: BoolProperty(name="Overwrite", default=False, description=OVERWRITE_HELP)

    def draw(self, context):
        layout = self.layout
        layout.prop(self, "name")
        layout.prop(self, "overwrite")

    @one_line_errors
    def execute(self, context):
        if not self.filepath:
            self.report({"ERROR"}, "SolidWire: cannot import preset: no file chosen")
            return {"CANCELLED"}
        try:
            preset = presets.import_file(
                Path(bpy.path.abspath(self.filepath)), name=self.name, overwrite=self.overwrite
            )
        except (presets.PresetError, OSError) as exc:
            self.report({"ERROR"}, f"SolidWire: cannot import preset: {one_line(exc)}")
            return {"CANCELLED"}
        self.report({"INFO"}, f"SolidWire: imported preset '{preset.name}'")
        return {"FINISHED"}


classes = (
    SOLIDWIRE_OT_toggle_overlay,
    SOLIDWIRE_OT_fade_from_visible,
    SOLIDWIRE_OT_preset_apply,
    SOLIDWIRE_OT_preset_add,
    SOLIDWIRE_OT_preset_remove,
    SOLIDWIRE_OT_preset_export,
    SOLIDWIRE_OT_preset_import,
)


def register_keymaps() -> None:
    if _keymap_items:
        return
    keyconfig = bpy.context.window_manager.keyconfigs.addon
    if keyconfig is None:  # no add-on keyconfig (some background sessions)
        return
    keymap = keyconfig.keymaps.new(name="3D View", space_type="VIEW_3D")
    item = keymap.keymap_items.new(SOLIDWIRE_OT_toggle_overlay.bl_idname, **TOGGLE_KEY)
    _keymap_items.append((keymap, item))


def unregister_keymaps() -> None:
    for keymap, item in _keymap_items:
        try:
            keymap.keymap_items.remove(item)
        except (ReferenceError, RuntimeError):
            pass  # already gone with its keyconfig
    _keymap_items.clear()
