"""``scene.solidwire``: the user-facing settings (names fixed by SPEC section 2)."""

from __future__ import annotations

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, FloatVectorProperty

from .draw import DEFAULT_DUTY, DrawSettings

_DEFAULTS = DrawSettings()


def redraw_viewports(_self=None, context=None) -> None:
    """Settings changes show at once in every 3D viewport."""
    wm = getattr(bpy.context, "window_manager", None)
    for window in getattr(wm, "windows", ()):
        for area in window.screen.areas:
            if area.type == "VIEW_3D":
                area.tag_redraw()


def _diagonal_mode_changed(self, context) -> None:
    # Dotted and dashed have their own natural duty cycle (SPEC 1.4).
    duty = DEFAULT_DUTY.get(self.diagonal_mode)
    if duty is not None:
        self.pattern_duty = duty
    redraw_viewports()


class SolidWireSettings(bpy.types.PropertyGroup):
    show_overlay: BoolProperty(
        name="SolidWire Overlay",
        description="Draw the solid wireframe over meshes in 3D viewports",
        default=False,
        update=redraw_viewports,
    )
    thickness: FloatProperty(
        name="Thickness",
        description="Full width of an interior edge's opaque core, in pixels",
        default=_DEFAULTS.thickness,
        min=0.0,
        max=1000.0,
        soft_max=20.0,
        subtype="PIXEL",
        update=redraw_viewports,
    )
    softness: FloatProperty(
        name="Softness",
        description="Width of the anti-aliased falloff on each side of the core, in pixels",
        default=_DEFAULTS.softness,
        min=0.01,
        max=100.0,
        soft_min=0.25,
        soft_max=4.0,
        subtype="PIXEL",
        update=redraw_viewports,
    )
    wire_color: FloatVectorProperty(
        name="Wire Color",
        description="Wire colour and opacity",
        default=_DEFAULTS.wire_color,
        size=4,
        min=0.0,
        max=1.0,
        subtype="COLOR",
        update=redraw_viewports,
    )
    use_fill: BoolProperty(
        name="Fill",
        description="Fill faces with an opaque colour under the wire instead of drawing the wire alone",
        default=_DEFAULTS.use_fill,
        update=redraw_viewports,
    )
    fill_color: FloatVectorProperty(
        name="Fill Color",
        description="Colour of the faces when Fill is on (drawn opaque)",
        default=_DEFAULTS.fill_color,
        size=4,
        min=0.0,
        max=1.0,
        subtype="COLOR",
        update=redraw_viewports,
    )
    diagonal_mode: EnumProperty(
        name="Diagonals",
        description="How edges added by triangulating quads and n-gons are drawn",
        items=(
            ("HIDDEN", "Hidden", "Show quads and n-gons as themselves: diagonals are not drawn"),
            ("SOLID", "Solid", "Draw every triangle edge"),
            ("DOTTED", "Dotted", "Draw diagonals as a dotted line"),
            ("DASHED", "Dashed", "Draw diagonals as a dashed line"),
        ),
        default=_DEFAULTS.diagonal_mode,
        update=_diagonal_mode_changed,
    )
    pattern_period: FloatProperty(
        name="Period",
        description="Length of one on/off cycle of the diagonal pattern, in pixels",
        default=_DEFAULTS.pattern_period,
        min=1.0,
        max=1000.0,
        soft_max=64.0,
        subtype="PIXEL",
        update=redraw_viewports,
    )
    pattern_duty: FloatProperty(
        name="Duty",
        description="Fraction of each period that is drawn",
        default=_DEFAULTS.pattern_duty,
        min=0.0,
        max=1.0,
        subtype="FACTOR",
        update=redraw_viewports,
    )
    use_fade: BoolProperty(
        name="Depth Fade",
        description="Fade the wire out with distance from the camera",
        default=_DEFAULTS.use_fade,
        update=redraw_viewports,
    )
    fade_start: FloatProperty(
        name="Fade Start",
        description="View depth where fading begins (full intensity before it)",
        default=_DEFAULTS.fade_start,
        min=0.0,
        subtype="DISTANCE",
        update=redraw_viewports,
    )
    fade_end: FloatProperty(
        name="Fade End",
        description="View depth where the wire has faded out completely",
        default=_DEFAULTS.fade_end,
        min=0.0,
        subtype="DISTANCE",
        update=redraw_viewports,
    )
    use_backface_culling: BoolProperty(
        name="Backface Culling",
        description="Faces seen from behind neither draw nor hide what is behind them",
        default=_DEFAULTS.use_backface_culling,
        update=redraw_viewports,
    )

    def snapshot(self) -> DrawSettings:
        return DrawSettings.from_properties(self)


classes = (SolidWireSettings,)


def register_properties() -> None:
    bpy.types.Scene.solidwire = bpy.props.PointerProperty(type=SolidWireSettings)


def unregister_properties() -> None:
    if hasattr(bpy.types.Scene, "solidwire"):
        del bpy.types.Scene.solidwire
