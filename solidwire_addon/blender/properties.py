"""The Blender properties, made from the schema (``core/schema.py``).

One PropertyGroup class per scope that has settings: ``scene.solidwire``,
and ``object.solidwire`` / ``view_layer.solidwire`` as soon as the schema
declares settings there. Every property redraws the 3D viewports when it
changes.
"""

from __future__ import annotations

import types

import bpy
from bpy.props import (
    BoolProperty,
    CollectionProperty,
    EnumProperty,
    FloatProperty,
    FloatVectorProperty,
    IntProperty,
    PointerProperty,
)

from ..core import schema
from ..core.settings import DrawSettings
from . import matcap_files
from .runtime import redraw_viewports

# Where each scope's PropertyGroup is attached.
_OWNERS = {schema.SCENE: "Scene", schema.OBJECT: "Object", schema.VIEW_LAYER: "ViewLayer"}
ATTRIBUTE = "solidwire"


def _diagonal_mode_changed(self, _context) -> None:
    duty = schema.DEFAULT_DUTY.get(self.diagonal_mode)
    if duty is not None:
        self.pattern_duty = duty
    redraw_viewports()


def _matcap_changed(self, _context) -> None:
    """Decode the chosen matcap now, in the main thread (matcap_files.py)."""
    if self.fill_shading == "MATCAP":
        matcap_files.prepare(self.matcap)
    redraw_viewports()


def _passes_changed(self, _context) -> None:
    """A pass switched on or off: Blender asks the engine for its passes
    again (the compositor's Render Layers node shows them at once)."""
    scene = self.id_data
    for view_layer in getattr(scene, "view_layers", ()):
        if view_layer.solidwire == self:
            try:
                view_layer.update_render_passes()
            except (AttributeError, RuntimeError):
                pass  # the passes are asked for again at the next render anyway


# Blender holds each property's update callback as a Python function. The
# bpy 4.2 module never lets go of it, nor of a property group's methods,
# not even when the class is unregistered; a function whose globals reach
# the ``bpy`` module keeps that module alive past interpreter shutdown.
# Blender's own shutdown then never runs, and the process crashes as it
# exits (exit status 139, after any script or farm job that registered the
# add-on; 4.5 and later free them). So Blender is handed stand-ins whose
# only global is this table, filled while the add-on is registered and
# emptied when it is not: what a stand-in keeps alive then is an empty dict.
_CALLBACK_TABLE: dict = {}
_CALLBACKS: dict = {}


def _stand_in(function, method: bool = False):
    """What Blender holds in place of ``function``: an update callback
    ``(self, context)`` or, with ``method``, a method ``(self)``, calling
    ``function`` through the table.
    Blender checks an update callback's positional arguments, hence a
    signature of its own and no ``*args``."""
    name = f"{function.__module__}.{function.__qualname__}"
    _CALLBACKS[name] = function
    if method:

        def call(self):
            return _CALLBACK_TABLE[name](self)
    else:

        def call(self, context):
            return _CALLBACK_TABLE[name](self, context)

    return types.FunctionType(call.__code__, {"_CALLBACK_TABLE": _CALLBACK_TABLE}, name, None, call.__closure__)


def _snapshot(props) -> DrawSettings:
    return DrawSettings.from_properties(props)


# Settings whose change does more than redraw.
_UPDATES = {
    "diagonal_mode": _diagonal_mode_changed,
    "fill_shading": _matcap_changed,
    "matcap": _matcap_changed,
    **{s.name: _passes_changed for s in schema.settings_in(schema.VIEW_LAYER) if s.name.startswith("use_pass_")},
}


def make_property(setting: schema.Setting):
    """The bpy.props definition of one schema setting."""
    common = dict(
        name=setting.label,
        description=setting.description,
        update=_stand_in(_UPDATES.get(setting.name, redraw_viewports)),
    )
    if setting.kind == schema.BOOL:
        return BoolProperty(default=setting.default, **common)
    if setting.kind == schema.ENUM:
        return EnumProperty(items=setting.items, default=setting.default, **common)
    limits = {}
    for key, value in (
        ("min", setting.minimum),
        ("max", setting.maximum),
        ("soft_min", setting.soft_min),
        ("soft_max", setting.soft_max),
    ):
        if value is not None and abs(value) != float("inf"):
            limits[key] = value
    if setting.kind == schema.COLOR:
        return FloatVectorProperty(default=setting.default, size=setting.size, subtype="COLOR", **limits, **common)
    return FloatProperty(default=setting.default, subtype=setting.subtype, **limits, **common)


def make_group(scope: str):
    """A PropertyGroup class with every setting of ``scope``."""
    annotations = {s.name: make_property(s) for s in schema.settings_in(scope)}
    name = f"SolidWire{scope.title().replace('_', '')}Settings"
    namespace = {"__annotations__": annotations, "__module__": __name__}
    if scope == schema.SCENE:
        namespace["snapshot"] = _stand_in(_snapshot, method=True)
    return type(name, (bpy.types.PropertyGroup,), namespace)


GROUPS = {scope: make_group(scope) for scope in _OWNERS if schema.settings_in(scope)}
SolidWireSettings = GROUPS[schema.SCENE]


class SolidWireViewportToggle(bpy.types.PropertyGroup):
    """One 3D View's own SolidWire toggle, kept on its screen.

    Blender lets add-ons register properties on ID types only (not on Area,
    SpaceView3D or View3DOverlay), so the toggle lives in a collection on the
    Screen, keyed by the area's index in ``screen.areas``. Screens are UI
    data: a change adds no undo step (Blender's ID_CHECK_UNDO leaves screens
    out) and is saved with the file's UI. Indices are stable while areas are
    split (new areas go last); joining areas can move a toggle to the
    neighbouring 3D View, and a maximised area (its own temporary screen)
    starts from the scene default."""

    area_index: IntProperty(name="Area", description="Index of the 3D View in screen.areas", min=0)
    show: BoolProperty(
        name="SolidWire Overlay",
        description="Draw the solid wireframe over meshes in this 3D View",
        default=False,
        update=_stand_in(redraw_viewports),
    )


classes = (*GROUPS.values(), SolidWireViewportToggle)
VIEWPORTS_ATTRIBUTE = "solidwire_viewports"


def register_properties() -> None:
    _CALLBACK_TABLE.update(_CALLBACKS)
    for scope, group in GROUPS.items():
        setattr(getattr(bpy.types, _OWNERS[scope]), ATTRIBUTE, PointerProperty(type=group))
    setattr(bpy.types.Screen, VIEWPORTS_ATTRIBUTE, CollectionProperty(type=SolidWireViewportToggle))
    # Per-object opt-out of the viewport overlay.
    bpy.types.Object.solidwire_exclude = BoolProperty(
        name="Exclude from SolidWire Overlay",
        description="Do not draw the SolidWire overlay on this object in 3D viewports",
        default=False,
        update=_stand_in(redraw_viewports),
    )


def unregister_properties() -> None:
    for scope in GROUPS:
        owner = getattr(bpy.types, _OWNERS[scope])
        if hasattr(owner, ATTRIBUTE):
            delattr(owner, ATTRIBUTE)
    if hasattr(bpy.types.Screen, VIEWPORTS_ATTRIBUTE):
        delattr(bpy.types.Screen, VIEWPORTS_ATTRIBUTE)
    if hasattr(bpy.types.Object, "solidwire_exclude"):
        del bpy.types.Object.solidwire_exclude
    _CALLBACK_TABLE.clear()
