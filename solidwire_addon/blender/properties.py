"""The Blender properties, made from the schema (``core/schema.py``).

One PropertyGroup class per scope that has settings: ``scene.solidwire``,
and ``object.solidwire`` / ``view_layer.solidwire`` as soon as the schema
declares settings there. Every property redraws the 3D viewports when it
changes.
"""

from __future__ import annotations

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, FloatVectorProperty, PointerProperty

from ..core import schema
from ..core.settings import DrawSettings
from . import matcap_files

# Where each scope's PropertyGroup is attached.
_OWNERS = {schema.SCENE: "Scene", schema.OBJECT: "Object", schema.VIEW_LAYER: "ViewLayer"}
ATTRIBUTE = "solidwire"


def redraw_viewports(_self=None, _context=None) -> None:
    """Settings changes show at once in every 3D viewport."""
    wm = getattr(bpy.context, "window_manager", None)
    for window in getattr(wm, "windows", ()):
        for area in window.screen.areas:
            if area.type == "VIEW_3D":
                area.tag_redraw()


def _diagonal_mode_changed(self, _context) -> None:
    duty = schema.DEFAULT_DUTY.get(self.diagonal_mode)
    if duty is not None:
        self.pattern_duty = duty
    redraw_viewports()


def _matcap_changed(self, _context) -> None:
    """Decode the chosen matcap now, in the main thread (matcap_files.py)."""
    if self.fill_shading == "MATCAP":
        matcap_files.request(self.matcap)
    redraw_viewports()


# Settings whose change does more than redraw.
_UPDATES = {"diagonal_mode": _diagonal_mode_changed, "fill_shading": _matcap_changed, "matcap": _matcap_changed}


def make_property(setting: schema.Setting):
    """The bpy.props definition of one schema setting."""
    common = dict(
        name=setting.label,
        description=setting.description,
        update=_UPDATES.get(setting.name, redraw_viewports),
    )
    if setting.kind == schema.BOOL:
        return BoolProperty(default=setting.default, **common)
    if setting.kind == schema.ENUM:
        return EnumProperty(items=setting.items, default=setting.default, **common)
    limits = {}
    for key, value in (("min", setting.minimum), ("max", setting.maximum),
                       ("soft_min", setting.soft_min), ("soft_max", setting.soft_max)):
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
        namespace["snapshot"] = lambda self: DrawSettings.from_properties(self)
    return type(name, (bpy.types.PropertyGroup,), namespace)


GROUPS = {scope: make_group(scope) for scope in _OWNERS if schema.settings_in(scope)}
SolidWireSettings = GROUPS[schema.SCENE]

classes = tuple(GROUPS.values())


def register_properties() -> None:
    for scope, group in GROUPS.items():
        setattr(getattr(bpy.types, _OWNERS[scope]), ATTRIBUTE, PointerProperty(type=group))
    # Per-object opt-out of the viewport overlay.
    bpy.types.Object.solidwire_exclude = BoolProperty(
        name="Exclude from SolidWire Overlay",
        description="Do not draw the SolidWire overlay on this object in 3D viewports",
        default=False,
        update=redraw_viewports,
    )


def unregister_properties() -> None:
    for scope in GROUPS:
        owner = getattr(bpy.types, _OWNERS[scope])
        if hasattr(owner, ATTRIBUTE):
            delattr(owner, ATTRIBUTE)
    if hasattr(bpy.types.Object, "solidwire_exclude"):
        del bpy.types.Object.solidwire_exclude
