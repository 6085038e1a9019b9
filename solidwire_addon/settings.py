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
    thickness_mode: EnumProperty(
        name="Thickness Mode",
        description="How the line width varies with distance from the camera",
        items=(
            ("PIXELS", "Pixels", "The same width in pixels everywhere"),
            ("WORLD", "World", "A width in scene units: lines thin out with distance, like real wires"),
            ("DEPTH", "Depth Cue", "Width goes from Thickness at Near to Far Thickness at Far"),
        ),
        default=_DEFAULTS.thickness_mode,
        update=redraw_viewports,
    )
    world_thickness: FloatProperty(
        name="World Thickness",
        description="Full core width of an interior edge in scene units",
        default=_DEFAULTS.world_thickness,
        min=0.0,
        soft_max=1.0,
        subtype="DISTANCE",
        update=redraw_viewports,
    )
    thickness_far: FloatProperty(
        name="Far Thickness",
        description="Core width at the far end of the depth-cue range, in pixels",
        default=_DEFAULTS.thickness_far,
        min=0.0,
        max=1000.0,
        soft_max=20.0,
        subtype="PIXEL",
        update=redraw_viewports,
    )
    thickness_depth_start: FloatProperty(
        name="Near",
        description="View depth where the depth cue starts (Thickness before it)",
        default=_DEFAULTS.thickness_depth_start,
        min=0.0,
        subtype="DISTANCE",
        update=redraw_viewports,
    )
    thickness_depth_end: FloatProperty(
        name="Far",
        description="View depth where the depth cue ends (Far Thickness beyond it)",
        default=_DEFAULTS.thickness_depth_end,
        min=0.0,
        subtype="DISTANCE",
        update=redraw_viewports,
    )
    use_silhouettes: BoolProperty(
        name="Full Silhouettes",
        description=(
            "Give silhouette and boundary edges their outer half too, so outlines are as wide as "
            "interior edges (renders; hidden by nearer surfaces)"
        ),
        default=_DEFAULTS.use_silhouettes,
        update=redraw_viewports,
    )
    use_hidden_lines: BoolProperty(
        name="Hidden Lines",
        description="Also draw edges hidden behind surfaces, dimmed and dashed (technical-drawing style)",
        default=_DEFAULTS.use_hidden_lines,
        update=redraw_viewports,
    )
    hidden_alpha: FloatProperty(
        name="Hidden Opacity",
        description="Opacity of hidden edges relative to the wire",
        default=_DEFAULTS.hidden_alpha,
        min=0.0,
        max=1.0,
        subtype="FACTOR",
        update=redraw_viewports,
    )
    hidden_period: FloatProperty(
        name="Hidden Dash Period",
        description="Length of one dash cycle of hidden edges, in pixels",
        default=_DEFAULTS.hidden_period,
        min=1.0,
        max=1000.0,
        soft_max=64.0,
        subtype="PIXEL",
        update=redraw_viewports,
    )
    hidden_duty: FloatProperty(
        name="Hidden Dash Duty",
        description="Fraction of each hidden-edge dash cycle that is drawn",
        default=_DEFAULTS.hidden_duty,
        min=0.0,
        max=1.0,
        subtype="FACTOR",
        update=redraw_viewports,
    )
    # Viewport overlay only (the render draws every renderable mesh).
    only_selected: BoolProperty(
        name="Only Selected",
        description="Draw the viewport overlay on selected objects only",
        default=False,
        update=redraw_viewports,
    )

    def snapshot(self) -> DrawSettings:
        return DrawSettings.from_properties(self)


classes = (SolidWireSettings,)


def register_properties() -> None:
    bpy.types.Scene.solidwire = bpy.props.PointerProperty(type=SolidWireSettings)
    # Per-object opt-out of the viewport overlay.
    bpy.types.Object.solidwire_exclude = BoolProperty(
        name="Exclude from SolidWire Overlay",
        description="Do not draw the SolidWire overlay on this object in 3D viewports",
        default=False,
        update=redraw_viewports,
    )


def unregister_properties() -> None:
    if hasattr(bpy.types.Scene, "solidwire"):
        del bpy.types.Scene.solidwire
    if hasattr(bpy.types.Object, "solidwire_exclude"):
        del bpy.types.Object.solidwire_exclude
