"""User interface: the SolidWire sidebar panel, the render-properties panel,
the presets menu and the checkbox in the viewport's Overlays popover.

The UI only shows settings and calls operators. Settings that do not apply
right now are greyed out (``active = False``), never hidden, so the layout
does not jump while the user works.
"""

from __future__ import annotations

import bpy

from ..core import schema
from ..core.ids import ENGINE_ID
from . import ops, presets

# Operators shown under a section's rows.
_SECTION_OPERATORS = {"fade": ((ops.SOLIDWIRE_OT_fade_from_visible.bl_idname, "DRIVER_DISTANCE"),)}


def draw_look_settings(layout, props) -> None:
    """The look, one column per schema section, rows in schema order
    (shared by the sidebar and the render-properties panel). A row that does
    not apply right now is greyed out by its setting's ``active_if``."""
    layout.use_property_split = True
    layout.use_property_decorate = False
    for section, heading in schema.SECTIONS:
        col = layout.column(align=True)
        if section == "classes":
            _draw_edge_classes(col, props, heading)
            continue
        for setting in schema.settings_in(schema.SCENE):
            if setting.section != section:
                continue
            row = col.row()
            if setting.active_if is not None:
                row.active = bool(setting.active_if(props))
            row.prop(props, setting.name)
        for idname, icon in _SECTION_OPERATORS.get(section, ()):
            col.operator(idname, icon=icon)


def _draw_edge_classes(col, props, heading) -> None:
    """One compact row per edge class: its switch, then colour, width and
    pattern (greyed while the class is off)."""
    col.label(text=heading)
    for name, label, *_rest in schema.EDGE_CLASS_STYLES:
        row = col.row(align=True)
        split = row.split(factor=0.4, align=True)
        split.use_property_split = False
        split.prop(props, f"use_{name}_edges", text=label)
        values = split.row(align=True)
        values.use_property_split = False
        values.active = bool(getattr(props, f"use_{name}_edges"))
        values.prop(props, f"{name}_color", text="")
        values.prop(props, f"{name}_thickness", text="")
        values.prop(props, f"{name}_pattern", text="")


def draw_object_settings(layout, obj) -> None:
    """An object's own settings (``object.solidwire``), rows in schema order;
    the override's values are greyed while the override is off. An older
    file's ``solidwire_exclude`` shows only while it is set, so it can be
    cleared."""
    props = getattr(obj, "solidwire", None)
    if props is None:
        return
    layout.use_property_split = True
    layout.use_property_decorate = False
    col = layout.column(align=True)
    for setting in schema.settings_in(schema.OBJECT):
        row = col.row()
        if setting.active_if is not None:
            row.active = bool(setting.active_if(props))
        row.prop(props, setting.name)
    if getattr(obj, "solidwire_exclude", False):
        col.prop(obj, "solidwire_exclude", text="Overlay Off (older file)")


def draw_presets_header(layout) -> None:
    """Presets menu with + and -, as in Blender's own preset menus."""
    row = layout.row(align=True)
    row.menu(SOLIDWIRE_MT_presets.bl_idname, text=ops.active_preset_name or "Presets", icon="PRESET")
    row.operator(ops.SOLIDWIRE_OT_preset_add.bl_idname, text="", icon="ADD")
    row.operator(ops.SOLIDWIRE_OT_preset_remove.bl_idname, text="", icon="REMOVE")


class SOLIDWIRE_MT_presets(bpy.types.Menu):
    """Built-in presets, the user's own, then Import / Export. Each entry's
    tooltip is its preset's description (the apply operator's
    ``description``)."""

    bl_idname = "SOLIDWIRE_MT_presets"
    bl_label = "SolidWire Presets"

    def draw(self, context):
        layout = self.layout
        try:
            builtin = presets.builtin_presets()
            user, problems = presets.user_presets()
        except presets.PresetError as exc:  # a broken install: say so in the menu
            layout.label(text=str(exc), icon="ERROR")
            builtin, (user, problems) = [], ([], [])
        for preset in builtin:
            layout.operator(ops.SOLIDWIRE_OT_preset_apply.bl_idname, text=preset.name).name = preset.name
        if user:
            layout.separator()
            for preset in user:
                layout.operator(
                    ops.SOLIDWIRE_OT_preset_apply.bl_idname, text=preset.name, icon="USER"
                ).name = preset.name
        for problem in problems:
            layout.label(text=problem, icon="ERROR")
        layout.separator()
        layout.operator(ops.SOLIDWIRE_OT_preset_import.bl_idname, text="Import Preset...", icon="IMPORT")
        layout.operator(ops.SOLIDWIRE_OT_preset_export.bl_idname, text="Export Preset...", icon="EXPORT")


class VIEW3D_PT_solidwire(bpy.types.Panel):
    bl_idname = "VIEW3D_PT_solidwire"
    bl_label = "SolidWire"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "SolidWire"

    @classmethod
    def poll(cls, context):
        return getattr(context.scene, "solidwire", None) is not None

    def draw_header(self, context):
        draw_toggle(self.layout, context, text="")

    def draw_header_preset(self, context):
        draw_presets_header(self.layout)

    def draw(self, context):
        props = context.scene.solidwire
        layout = self.layout
        draw_look_settings(layout, props)

        layout.separator()
        col = layout.column(heading="Overlay")
        col.active = ops.overlay_shown(context)
        col.prop(props, "only_selected")
        col.prop(props, "overlay_edit_mode")

        # The active object's own settings (also in Object Properties).
        layout.separator()
        obj = context.object
        if obj is not None and getattr(obj, "solidwire", None) is not None:
            layout.label(text=f"Object '{obj.name}'", icon="OBJECT_DATA")
            draw_object_settings(layout, obj)
        else:
            row = layout.row()
            row.enabled = False
            row.label(text="No active object")

        # Wire over a Cycles/EEVEE/Workbench render (ops_composite.py).
        layout.separator()
        layout.menu("SOLIDWIRE_MT_render_wire_over", text="Render Wire Over", icon="RENDER_STILL")


class RENDER_PT_solidwire(bpy.types.Panel):
    bl_idname = "RENDER_PT_solidwire"
    bl_label = "SolidWire"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "render"
    COMPAT_ENGINES = {ENGINE_ID}

    @classmethod
    def poll(cls, context):
        return context.engine in cls.COMPAT_ENGINES and getattr(context.scene, "solidwire", None) is not None

    def draw_header_preset(self, context):
        draw_presets_header(self.layout)

    def draw(self, context):
        draw_look_settings(self.layout, context.scene.solidwire)


def draw_overlay_popover(self, context) -> None:
    """Appended to the viewport's Overlays popover (VIEW3D_PT_overlay)."""
    props = getattr(context.scene, "solidwire", None)
    if props is None:
        return
    layout = self.layout
    layout.separator()
    row = layout.row(heading="SolidWire")
    draw_toggle(row, context, text="Solid Wireframe")


def draw_toggle(layout, context, text: str) -> None:
    """This viewport's SolidWire checkbox. The toggle lives on the screen
    and an entry is created on first use, which a draw function may not do,
    so the checkbox is the toggle operator drawn as one (no undo step)."""
    shown = ops.overlay_shown(context)
    layout.operator(
        ops.SOLIDWIRE_OT_toggle_overlay.bl_idname,
        text=text,
        icon="CHECKBOX_HLT" if shown else "CHECKBOX_DEHLT",
        emboss=False,
    )


class OBJECT_PT_solidwire(bpy.types.Panel):
    """Object Properties > SolidWire: the object's own settings, for every
    engine (the viewport overlay draws over any engine)."""

    bl_idname = "OBJECT_PT_solidwire"
    bl_label = "SolidWire"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "object"
    bl_options = {"DEFAULT_CLOSED"}

    @classmethod
    def poll(cls, context):
        obj = getattr(context, "object", None)
        return obj is not None and getattr(obj, "solidwire", None) is not None

    def draw(self, context):
        draw_object_settings(self.layout, context.object)


# Blender's own pass switches the engine writes (docs/image_model.md §6).
BLENDER_PASSES = tuple(p.switch for p in schema.RENDER_PASSES if not p.own)


class VIEWLAYER_PT_solidwire_passes(bpy.types.Panel):
    """View Layer Properties > Passes while SolidWire is the engine: the
    passes it writes, Blender's and its own (``view_layer.solidwire``)."""

    bl_idname = "VIEWLAYER_PT_solidwire_passes"
    bl_label = "Passes"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "view_layer"
    COMPAT_ENGINES = {ENGINE_ID}

    @classmethod
    def poll(cls, context):
        return context.engine in cls.COMPAT_ENGINES and getattr(context, "view_layer", None) is not None

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        layout.use_property_decorate = False
        view_layer = context.view_layer
        col = layout.column(heading="Data", align=True)
        for name in BLENDER_PASSES:
            col.prop(view_layer, name)
        props = getattr(view_layer, "solidwire", None)
        if props is not None:
            col = layout.column(heading="SolidWire", align=True)
            for setting in schema.settings_in(schema.VIEW_LAYER):
                col.prop(props, setting.name)


classes = (
    SOLIDWIRE_MT_presets,
    VIEW3D_PT_solidwire,
    RENDER_PT_solidwire,
    OBJECT_PT_solidwire,
    VIEWLAYER_PT_solidwire_passes,
)

# (Blender panel, our draw function): appended at register, removed at unregister.
_APPENDS = (("VIEW3D_PT_overlay", draw_overlay_popover),)


def register_appends() -> None:
    for panel_name, function in _APPENDS:
        panel = getattr(bpy.types, panel_name, None)
        if panel is not None:
            panel.remove(function)  # never twice, even after a failed unregister
            panel.append(function)


def unregister_appends() -> None:
    for panel_name, function in _APPENDS:
        panel = getattr(bpy.types, panel_name, None)
        if panel is not None:
            panel.remove(function)


def appended_draw_functions(panel_name: str) -> list:
    """Our functions in ``panel_name``'s draw list (for tests)."""
    panel = getattr(bpy.types, panel_name, None)
    functions = getattr(getattr(panel, "draw", None), "_draw_funcs", [])
    return [f for f in functions if f in {fn for _name, fn in _APPENDS}]
