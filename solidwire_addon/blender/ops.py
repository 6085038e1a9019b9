"""Operators (toggle, fade range, presets) and the add-on keymap.

Operators change settings or preset files and nothing else: drawing happens in
the overlay handler, reacting to the settings' update callbacks.
"""

from __future__ import annotations

import functools

import bpy
import numpy as np
from bpy.props import StringProperty

from . import overlay, presets
from .overlay import viewport_object_filter
from .properties import redraw_viewports

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


def one_line_errors(method):
    """Wrap an operator's ``execute`` / ``invoke``: an unexpected exception is
    reported as one line (``bpy.ops`` raises RuntimeError with it) and the
    operator is cancelled, instead of Blender printing a traceback. Expected
    problems are checked and reported by the operators themselves."""

    def run(self, *args):
        try:
            return method(self, *args)
        except Exception as exc:  # noqa: BLE001 - no traceback from an operator
            message = " ".join(str(exc).split()) or type(exc).__name__
            self.report({"ERROR"}, f"SolidWire: {self.bl_label} failed: {type(exc).__name__}: {message}")
            return {"CANCELLED"}

    # Blender checks the argument count of execute (self, context) and
    # invoke (self, context, event), so the wrapper keeps it.
    if method.__code__.co_argcount == 3:
        def guarded(self, context, event):
            return run(self, context, event)
    else:
        def guarded(self, context):
            return run(self, context)
    return functools.wraps(method)(guarded)


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


def visible_depth_extent(depsgraph, view_matrix, object_filter=None):
    """(nearest, farthest) view depth of the bounding boxes of the drawn mesh
    objects, or None when there are none in front of the view.

    Depth is distance along the viewing axis (as the depth fade uses, docs/image_model.md §4), so
    (start, end) = extent fades from the nearest object to the farthest."""
    view = np.asarray(view_matrix, dtype=np.float64)
    depths = []
    for instance in depsgraph.object_instances:
        obj = instance.object
        if obj.type != "MESH":
            continue
        owner = instance.parent if instance.is_instance and instance.parent is not None else obj
        if object_filter is not None and not object_filter(owner.original):
            continue
        corners = np.ones((8, 4))
        corners[:, :3] = np.array(obj.bound_box, dtype=np.float64)
        world = corners @ np.array(instance.matrix_world, dtype=np.float64).T
        depths.append(-(world @ view[2]))
    if not depths:
        return None
    depths = np.concatenate(depths)
    depths = depths[np.isfinite(depths)]  # an object with a broken transform says nothing
    if not len(depths):
        return None
    near, far = max(float(depths.min()), 0.0), float(depths.max())
    if far <= 0.0:
        return None
    return near, far


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
        space = context.space_data if getattr(context, "space_data", None) and context.space_data.type == "VIEW_3D" else None
        # From the sidebar the current region is not the 3D region itself:
        # fall back to the space's main 3D region.
        region_3d = getattr(context, "region_data", None) or getattr(space, "region_3d", None)
        if region_3d is not None and hasattr(region_3d, "view_matrix"):
            view_matrix = region_3d.view_matrix
        elif context.scene.camera is not None:
            view_matrix = context.scene.camera.matrix_world.normalized().inverted()
        else:
            self.report({"ERROR"}, "SolidWire: no 3D viewport or scene camera to measure depth from")
            return {"CANCELLED"}
        keep = viewport_object_filter(
            context.view_layer, space, only_selected=props.only_selected, draw_edit_mode=props.overlay_edit_mode
        )
        extent = visible_depth_extent(context.evaluated_depsgraph_get(), view_matrix, keep)
        if extent is None:
            self.report({"WARNING"}, "SolidWire: no visible mesh in front of the view")
            return {"CANCELLED"}
        props.fade_start, props.fade_end = extent
        props.use_fade = True
        self.report({"INFO"}, f"SolidWire: depth fade {extent[0]:.3g} to {extent[1]:.3g}")
        return {"FINISHED"}


class SOLIDWIRE_OT_preset_apply(bpy.types.Operator):
    """Apply a SolidWire preset"""

    bl_idname = "solidwire.preset_apply"
    bl_label = "Apply SolidWire Preset"
    bl_options = {"REGISTER", "UNDO"}

    name: StringProperty(name="Preset", description="Name of the preset to apply")

    @one_line_errors
    def execute(self, context):
        global active_preset_name
        try:
            preset = presets.find(self.name)
        except presets.PresetError as exc:
            self.report({"ERROR"}, f"SolidWire: {exc}")
            return {"CANCELLED"}
        presets.apply(preset, _solidwire(context))
        active_preset_name = preset.name
        redraw_viewports()
        return {"FINISHED"}


class SOLIDWIRE_OT_preset_add(bpy.types.Operator):
    """Save the current SolidWire settings as a user preset"""

    bl_idname = "solidwire.preset_add"
    bl_label = "Add SolidWire Preset"
    bl_options = {"REGISTER"}

    name: StringProperty(name="Name", description="Name of the new preset", default="My Preset", maxlen=64)

    @one_line_errors
    def invoke(self, context, event):
        return context.window_manager.invoke_props_dialog(self)

    @one_line_errors
    def execute(self, context):
        global active_preset_name
        try:
            path = presets.save(self.name, _solidwire(context))
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
        if active_preset_name == name:
            active_preset_name = ""
        return {"FINISHED"}


classes = (
    SOLIDWIRE_OT_toggle_overlay,
    SOLIDWIRE_OT_fade_from_visible,
    SOLIDWIRE_OT_preset_apply,
    SOLIDWIRE_OT_preset_add,
    SOLIDWIRE_OT_preset_remove,
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
