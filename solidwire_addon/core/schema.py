"""The settings schema: every user-facing setting, defined once.

Everything else is made from this table and nothing else repeats it:

* the Blender PropertyGroups (``blender/properties.py``: type, default, hard
  and soft range, subtype, label, tooltip, enum items);
* the plain, immutable snapshot the draw path takes (``core/settings.py``);
* preset validation (``blender/presets.py``: which keys, types and ranges);
* the command-line options (``blender/cli.py``: flag, parser, range check);
* the panel rows (``blender/ui.py``: section, order, when a row is greyed);
* the shader parameter block (``core/shaders.py`` generates the GLSL struct
  ``SolidWireParams`` from :data:`PARAM_BLOCK`; ``core/settings.py`` packs it).

Adding a setting is one :class:`Setting` entry here, plus the shader or draw
code that uses it. The meaning of each setting is defined in
``docs/image_model.md``; the tooltips here are the short form of it.

This module imports nothing from Blender: it is plain data.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

# Where a setting lives in Blender: ``scene.solidwire``, ``object.solidwire``
# or ``view_layer.solidwire``.
SCENE, OBJECT, VIEW_LAYER = "SCENE", "OBJECT", "VIEW_LAYER"

BOOL, FLOAT, COLOR, ENUM = "BOOL", "FLOAT", "COLOR", "ENUM"

# Pass ``cli=NO_FLAG`` for a setting that has no command-line option.
NO_FLAG = ""


@dataclass(frozen=True)
class Param:
    """A slot of the shader parameter block (std140).

    ``glsl`` is the member name in ``SolidWireParams``; ``pack(value)`` maps
    the setting's value to what the shader reads (a float or 4 floats)."""

    glsl: str
    pack: Callable = float


@dataclass(frozen=True)
class Setting:
    name: str
    kind: str  # BOOL, FLOAT, COLOR (RGBA, scene linear) or ENUM
    default: object
    label: str
    description: str
    scope: str = SCENE
    minimum: float = -math.inf  # hard range: nothing outside it is accepted
    maximum: float = math.inf
    soft_min: float | None = None  # slider range in the panel
    soft_max: float | None = None
    subtype: str = "NONE"  # Blender property subtype: PIXEL, DISTANCE, FACTOR, ...
    items: tuple = ()  # ENUM: (identifier, label, description) triples
    section: str | None = None  # panel section (see SECTIONS); None = not in the look panel
    active_if: Callable | None = None  # props -> bool: row greyed out when False
    cli: str | None = None  # flag; None = "--name-with-dashes", NO_FLAG = none
    param: Param | None = None  # slot in the shader parameter block
    in_snapshot: bool = True  # part of the draw path's settings snapshot
    in_preset: bool = True  # saved in and applied from presets
    size: int = 4  # COLOR: 4 (RGBA) or 3 (RGB, no alpha slider)

    @property
    def choices(self) -> tuple:
        return tuple(item[0] for item in self.items)

    @property
    def flag(self) -> str:
        """The command-line flag ('' when there is none)."""
        if self.cli is None:
            return "--" + self.name.replace("_", "-")
        return self.cli

    def check(self, value):
        """``value`` converted to this setting's Python type, or ValueError
        with a one-line reason (used by presets and the command line)."""
        if self.kind == BOOL:
            if not isinstance(value, bool):
                raise ValueError(f"'{self.name}' must be true or false, not {value!r}")
            return value
        if self.kind == ENUM:
            if value not in self.choices:
                raise ValueError(f"'{self.name}' must be one of {', '.join(self.choices)}, not {value!r}")
            return value
        if self.kind == COLOR:
            what = "RGBA" if self.size == 4 else "RGB"
            # An RGB colour also takes RGBA (older presets, '#RRGGBBAA'): the
            # alpha is dropped. An RGBA colour needs all four.
            sizes = (3, 4) if self.size == 3 else (4,)
            if not (isinstance(value, (list, tuple)) and len(value) in sizes and all(_is_number(c) for c in value)):
                raise ValueError(f"'{self.name}' must be a list of {self.size} numbers ({what}, linear), not {value!r}")
            if not all(0.0 <= c <= 1.0 for c in value):
                raise ValueError(f"'{self.name}' components must lie in 0..1, got {list(value)}")
            value = tuple(float(c) for c in value)
            return value[: self.size]
        if not _is_number(value):
            raise ValueError(f"'{self.name}' must be a number, not {value!r}")
        if not math.isfinite(value):
            raise ValueError(f"'{self.name}' must be a finite number, not {value!r}")
        if not (self.minimum <= value <= self.maximum):
            raise ValueError(f"'{self.name}' = {value:g} is out of range {self.minimum:g}..{self.maximum:g}")
        return float(value)


def _is_number(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _half(value) -> float:
    """Widths are set as full widths; the shaders work with half widths."""
    return 0.5 * max(float(value), 0.0)


def _clamp01(value) -> float:
    return min(max(float(value), 0.0), 1.0)


def _rgb1(value) -> tuple:
    """An RGB colour in a vec4 slot."""
    return (*(float(c) for c in tuple(value)[:3]), 1.0)


def _at_least(low: float) -> Callable:
    return lambda value: max(float(value), low)


# Panel sections, in panel order: (identifier, heading shown above it or "").
SECTIONS = (
    ("line", ""),
    ("fill", ""),
    ("colors", ""),
    ("edges", "Edges"),
    ("classes", "Edge Classes"),
    ("diagonals", ""),
    ("fade", ""),
    ("hidden", ""),
    ("culling", ""),
)

# Blender's bundled matcaps (datafiles/studiolights/matcap/NAME.exr, the same
# set from 4.0 to 5.x); a name whose file is missing falls back to FLAT with
# one message.
MATCAPS = (
    "basic_bright",
    "basic_dark",
    "basic_grey",
    "basic_side",
    "ceramic_dark",
    "ceramic_lightbulb",
    "check_normal+y",
    "check_rim_dark",
    "check_rim_light",
    "clay_brown",
    "clay_green",
    "clay_studio",
    "clay_warm",
    "fullmetal",
    "hard_surface_grey",
    "hard_surface_red",
    "metal_bronze",
    "metal_carpaint",
    "pearl",
    "red_wax",
    "resin",
    "toon_dark",
    "toon_light",
)

PATTERN_MODES = ("DOTTED", "DASHED")
# Dotted and dashed have their own natural duty cycle (image model §4.3):
# choosing one of these modes sets the duty.
DEFAULT_DUTY = {"DOTTED": 0.25, "DASHED": 0.5}

# Edge classes (docs/image_model.md §3.6), in style order (core/edge_select.py
# EDGE_CLASSES): (name, label, what it is, default colour, width, pattern).
EDGE_CLASS_STYLES = (
    ("boundary", "Boundary", "edges with one face", (0.0, 0.0, 0.0, 1.0), 3.0, "SOLID"),
    ("sharp", "Sharp", "edges marked Sharp", (0.0, 0.3, 0.85, 1.0), 2.0, "SOLID"),
    ("crease", "Crease", "edges with a subdivision crease", (0.85, 0.1, 0.6, 1.0), 2.0, "SOLID"),
    ("seam", "Seam", "edges marked as UV seams", (0.9, 0.2, 0.05, 1.0), 2.0, "DASHED"),
    ("freestyle", "Freestyle", "edges marked for Freestyle", (0.05, 0.6, 0.2, 1.0), 2.0, "SOLID"),
)
LINE_PATTERNS = (
    ("SOLID", "Solid", "A continuous line"),
    ("DOTTED", "Dotted", "Short dashes (a quarter of each period)"),
    ("DASHED", "Dashed", "Dashes half of each period long"),
)
# The fraction of each period a pattern draws (1: solid).
PATTERN_DUTY = {"SOLID": 1.0, "DOTTED": 0.25, "DASHED": 0.5}


def _classes_on(props) -> bool:
    """Whether some edge class is switched on in ``props``."""
    return any(getattr(props, f"use_{edge_class[0]}_edges", False) for edge_class in EDGE_CLASS_STYLES)


def edge_class_settings(name, label, what, color, width, pattern) -> tuple:
    """The four settings of one edge class: on/off, colour, width, pattern."""
    active = lambda p, flag=f"use_{name}_edges": getattr(p, flag)
    return (
        Setting(
            f"use_{name}_edges",
            BOOL,
            False,
            f"{label} Edges",
            f"Draw {what} in their own style (they are then always drawn)",
            section="classes",
            cli=f"--{name}-edges",
        ),
        Setting(
            f"{name}_color",
            COLOR,
            color,
            "Color",
            f"Colour and opacity of {what}",
            minimum=0.0,
            maximum=1.0,
            subtype="COLOR",
            section="classes",
            active_if=active,
            cli=NO_FLAG,
            param=Param(f"{name}_color", tuple),
        ),
        Setting(
            f"{name}_thickness",
            FLOAT,
            width,
            "Thickness",
            f"Core width of {what} in pixels, beside the wire's Thickness: every thickness mode and an "
            "object's own Thickness keep that ratio to the wire",
            minimum=0.0,
            maximum=1000.0,
            soft_max=20.0,
            subtype="PIXEL",
            section="classes",
            active_if=active,
            cli=NO_FLAG,
            param=Param(f"{name}_half_thickness", _half),
        ),
        Setting(
            f"{name}_pattern",
            ENUM,
            pattern,
            "Pattern",
            f"Line pattern of {what} (the period is the diagonals' Period)",
            items=LINE_PATTERNS,
            section="classes",
            active_if=active,
            cli=NO_FLAG,
            param=Param(f"{name}_duty", PATTERN_DUTY.__getitem__),
        ),
    )


SETTINGS: tuple[Setting, ...] = (
    Setting(
        "show_overlay",
        BOOL,
        False,
        "SolidWire Overlay",
        "Default for 3D viewports without their own SolidWire toggle (each viewport has its own)",
        cli=NO_FLAG,
        in_snapshot=False,
        in_preset=False,
    ),
    # -- line ----------------------------------------------------------------
    Setting(
        "thickness_mode",
        ENUM,
        "PIXELS",
        "Thickness Mode",
        "How the line width varies with distance from the camera",
        items=(
            ("PIXELS", "Pixels", "The same width in pixels everywhere"),
            ("WORLD", "World", "A width in scene units: lines thin out with distance, like real wires"),
            ("DEPTH", "Depth Cue", "Width goes from Thickness at Near to Far Thickness at Far"),
        ),
        section="line",
    ),
    Setting(
        "thickness",
        FLOAT,
        1.5,
        "Thickness",
        "Full width of an interior edge's opaque core, in pixels (World mode: what the edge classes' "
        "widths are measured against)",
        minimum=0.0,
        maximum=1000.0,
        soft_max=20.0,
        subtype="PIXEL",
        section="line",
        # (In World mode it still sets the ratio of each class's width to the wire's.)
        active_if=lambda p: p.thickness_mode != "WORLD" or _classes_on(p),
        param=Param("half_thickness", _half),
    ),
    Setting(
        "world_thickness",
        FLOAT,
        0.02,
        "World Thickness",
        "Full core width of an interior edge in scene units",
        minimum=0.0,
        maximum=1.0e9,
        soft_max=1.0,
        subtype="DISTANCE",
        section="line",
        active_if=lambda p: p.thickness_mode == "WORLD",
        # Packed with the view (see VIEW_PARAMS: world_half_thickness_px).
    ),
    Setting(
        "softness",
        FLOAT,
        1.0,
        "Softness",
        "Width of the anti-aliased falloff on each side of the core, in pixels",
        minimum=0.01,
        maximum=100.0,
        soft_min=0.25,
        soft_max=4.0,
        subtype="PIXEL",
        section="line",
        param=Param("softness", _at_least(1e-4)),
    ),
    Setting(
        "thickness_far",
        FLOAT,
        0.5,
        "Far Thickness",
        "Core width at the far end of the depth-cue range, in pixels",
        minimum=0.0,
        maximum=1000.0,
        soft_max=20.0,
        subtype="PIXEL",
        section="line",
        active_if=lambda p: p.thickness_mode == "DEPTH",
        param=Param("half_thickness_far", _half),
    ),
    Setting(
        "thickness_depth_start",
        FLOAT,
        2.0,
        "Near",
        "View depth where the depth cue starts (Thickness before it)",
        minimum=0.0,
        maximum=1.0e9,
        subtype="DISTANCE",
        section="line",
        active_if=lambda p: p.thickness_mode == "DEPTH",
        param=Param("thickness_depth_start"),
    ),
    Setting(
        "thickness_depth_end",
        FLOAT,
        20.0,
        "Far",
        "View depth where the depth cue ends (Far Thickness beyond it)",
        minimum=0.0,
        maximum=1.0e9,
        subtype="DISTANCE",
        section="line",
        active_if=lambda p: p.thickness_mode == "DEPTH",
        param=Param("thickness_depth_end"),
    ),
    Setting(
        "wire_color",
        COLOR,
        (0.0, 0.0, 0.0, 1.0),
        "Wire Color",
        "Wire colour and opacity",
        minimum=0.0,
        maximum=1.0,
        subtype="COLOR",
        section="line",
        param=Param("wire_color", tuple),
    ),
    Setting(
        "use_silhouettes",
        BOOL,
        False,
        "Full Silhouettes",
        "Give silhouette and boundary edges their outer half too, so outlines are as wide as "
        "interior edges (renders; hidden by nearer surfaces)",
        section="line",
        cli="--silhouettes",
    ),
    # -- which edges are drawn (docs/image_model.md §3.4-§3.6) ----------------
    Setting(
        "use_cage_edges",
        BOOL,
        True,
        "Cage Edges",
        "On meshes subdivided by a Subdivision Surface or Multiresolution modifier, draw only the edges that "
        "come from the original mesh's edges, running along the smooth surface (like Blender's overlay)",
        section="edges",
        cli="--cage-edges",
    ),
    Setting(
        "edge_angle",
        FLOAT,
        0.0,
        "Edge Angle",
        "Edges between two faces that meet at less than this angle are not drawn; boundary and non-manifold "
        "edges always are",
        minimum=0.0,
        maximum=math.pi,
        subtype="ANGLE",
        section="edges",
    ),
    Setting(
        "use_density_fade",
        BOOL,
        False,
        "Density Fade",
        "Fade out lines whose edge is short on screen, so dense or distant meshes stay readable",
        section="edges",
        cli="--density-fade",
    ),
    Setting(
        "show_tessellation",
        BOOL,
        False,
        "Tessellation",
        "On text, curves, surfaces and metaballs, draw every edge of the mesh Blender makes of them (flat fills "
        "show their triangles) instead of their outlines and profiles",
        section="edges",
        cli="--tessellation",
    ),
    Setting(
        "use_object_density_fade",
        BOOL,
        True,
        "Fade Dense Objects",
        "Fade the whole wire of an object or instance whose edges are typically short on screen even at its "
        "nearest point (crowds of small or distant objects show their fill instead of a mass of lines)",
        section="edges",
        cli="--fade-dense-objects",
    ),
    Setting(
        "density_fade_length",
        FLOAT,
        8.0,
        "Fade Below",
        "An edge this long on screen (pixels) is drawn in full; shorter edges fade, and edges under half of it "
        "are not drawn (Density Fade: each line's own length; Fade Dense Objects: an object's typical edge)",
        minimum=0.0,
        maximum=10000.0,
        soft_max=64.0,
        subtype="PIXEL",
        section="edges",
        active_if=lambda p: p.use_density_fade or p.use_object_density_fade,
        param=Param("density_fade_length", lambda v: max(float(v), 0.0)),
    ),
    *(setting for edge_class in EDGE_CLASS_STYLES for setting in edge_class_settings(*edge_class)),
    # -- fill ----------------------------------------------------------------
    Setting(
        "use_fill",
        BOOL,
        True,
        "Fill",
        "Fill faces with an opaque, shaded colour under the wire instead of drawing the wire alone",
        section="fill",
        cli="--fill",
    ),
    Setting(
        "fill_shading",
        ENUM,
        "STUDIO",
        "Shading",
        "How the fill is lit (docs/image_model.md §5.8)",
        items=(
            ("FLAT", "Flat", "One flat colour, no lighting"),
            ("STUDIO", "Studio", "Lit by lights fixed to the camera, like Workbench's studio lighting"),
            ("MATCAP", "MatCap", "One of Blender's bundled material captures, indexed by the view-space normal"),
        ),
        section="fill",
        active_if=lambda p: p.use_fill,
        cli="--shading",
    ),
    Setting(
        "matcap",
        ENUM,
        "clay_studio",
        "MatCap",
        "Which of Blender's bundled matcaps (datafiles/studiolights/matcap) lights the fill",
        items=tuple((name, name.replace("_", " ").title(), f"Blender's bundled matcap {name}.exr") for name in MATCAPS),
        section="fill",
        active_if=lambda p: p.use_fill and p.fill_shading == "MATCAP",
    ),
    Setting(
        "fill_color",
        COLOR,
        (0.8, 0.8, 0.8),
        "Fill Color",
        "Colour of the faces when Fill is on (always opaque: there is no fill alpha)",
        minimum=0.0,
        maximum=1.0,
        subtype="COLOR",
        size=3,
        section="fill",
        active_if=lambda p: p.use_fill,
        param=Param("fill_color", _rgb1),
    ),
    # -- colour sources --------------------------------------------------------
    Setting(
        "fill_color_source",
        ENUM,
        "SINGLE",
        "Fill Source",
        "Where each face's fill colour comes from",
        items=(
            ("SINGLE", "Single", "Fill Color for every object"),
            ("OBJECT", "Object", "The object's own colour (Object Properties > Viewport Display > Color)"),
            ("MATERIAL", "Material", "Each face's material viewport colour (Material > Viewport Display > Color)"),
            ("RANDOM", "Random", "A stable colour per object, made from its name"),
            (
                "ATTRIBUTE",
                "Attribute",
                (
                    "The mesh's active colour attribute (vertex colours), as Workbench's "
                    "Attribute colour; Fill Color where a mesh has none"
                ),
            ),
        ),
        section="colors",
        active_if=lambda p: p.use_fill,
        cli="--fill-source",
    ),
    Setting(
        "wire_color_source",
        ENUM,
        "SINGLE",
        "Wire Source",
        "Where each object's wire colour comes from (the alpha is always Wire Color's)",
        items=(
            ("SINGLE", "Single", "Wire Color for every object"),
            ("OBJECT", "Object", "The object's own colour (Object Properties > Viewport Display > Color)"),
            ("RANDOM", "Random", "A stable colour per object, made from its name"),
        ),
        section="colors",
        cli="--wire-source",
    ),
    # -- diagonals -----------------------------------------------------------
    Setting(
        "diagonal_mode",
        ENUM,
        "HIDDEN",
        "Diagonals",
        "How edges added by triangulating quads and n-gons are drawn",
        items=(
            ("HIDDEN", "Hidden", "Show quads and n-gons as themselves: diagonals are not drawn"),
            ("SOLID", "Solid", "Draw every triangle edge"),
            ("DOTTED", "Dotted", "Draw diagonals as a dotted line"),
            ("DASHED", "Dashed", "Draw diagonals as a dashed line"),
        ),
        section="diagonals",
        cli="--diagonals",
    ),
    Setting(
        "pattern_period",
        FLOAT,
        8.0,
        "Period",
        "Length of one on/off cycle of the diagonal pattern, in pixels",
        minimum=1.0,
        maximum=1000.0,
        soft_max=64.0,
        subtype="PIXEL",
        section="diagonals",
        active_if=lambda p: p.diagonal_mode in PATTERN_MODES,
        param=Param("pattern_period", _at_least(1e-3)),
    ),
    Setting(
        "pattern_duty",
        FLOAT,
        0.25,
        "Duty",
        "Fraction of each period that is drawn",
        minimum=0.0,
        maximum=1.0,
        subtype="FACTOR",
        section="diagonals",
        active_if=lambda p: p.diagonal_mode in PATTERN_MODES,
        param=Param("pattern_duty", _clamp01),
    ),
    # -- depth fade ----------------------------------------------------------
    Setting(
        "use_fade",
        BOOL,
        False,
        "Depth Fade",
        "Fade the wire out with distance from the camera",
        section="fade",
        cli=NO_FLAG,  # see CLI_RANGES: --fade START END / --no-fade
    ),
    Setting(
        "fade_start",
        FLOAT,
        10.0,
        "Fade Start",
        "View depth where fading begins (full intensity before it)",
        minimum=0.0,
        maximum=1.0e9,
        subtype="DISTANCE",
        section="fade",
        active_if=lambda p: p.use_fade,
        param=Param("fade_start"),
    ),
    Setting(
        "fade_end",
        FLOAT,
        50.0,
        "Fade End",
        "View depth where the wire has faded out completely",
        minimum=0.0,
        maximum=1.0e9,
        subtype="DISTANCE",
        section="fade",
        active_if=lambda p: p.use_fade,
        param=Param("fade_end"),
    ),
    # -- hidden lines --------------------------------------------------------
    Setting(
        "use_hidden_lines",
        BOOL,
        False,
        "Hidden Lines",
        "Also draw edges hidden behind surfaces, dimmed and dashed (technical-drawing style)",
        section="hidden",
        cli="--hidden-lines",
    ),
    Setting(
        "hidden_alpha",
        FLOAT,
        0.35,
        "Hidden Opacity",
        "Opacity of hidden edges relative to the wire",
        minimum=0.0,
        maximum=1.0,
        subtype="FACTOR",
        section="hidden",
        active_if=lambda p: p.use_hidden_lines,
        param=Param("hidden_alpha", _clamp01),
    ),
    Setting(
        "hidden_period",
        FLOAT,
        8.0,
        "Hidden Dash Period",
        "Length of one dash cycle of hidden edges, in pixels",
        minimum=1.0,
        maximum=1000.0,
        soft_max=64.0,
        subtype="PIXEL",
        section="hidden",
        active_if=lambda p: p.use_hidden_lines,
        param=Param("hidden_period", _at_least(1e-3)),
    ),
    Setting(
        "hidden_duty",
        FLOAT,
        0.5,
        "Hidden Dash Duty",
        "Fraction of each hidden-edge dash cycle that is drawn",
        minimum=0.0,
        maximum=1.0,
        subtype="FACTOR",
        section="hidden",
        active_if=lambda p: p.use_hidden_lines,
        param=Param("hidden_duty", _clamp01),
    ),
    # -- culling -------------------------------------------------------------
    Setting(
        "use_backface_culling",
        BOOL,
        False,
        "Backface Culling",
        "Faces seen from behind neither draw nor hide what is behind them",
        section="culling",
        cli="--backface-culling",
        # (The hidden-line passes ask whether a folded face's other triangle is culled: quad_partner.glsl.)
        param=Param("backface_culling", float),
    ),
    # -- viewport overlay only (the render draws every renderable mesh) --------
    Setting(
        "only_selected",
        BOOL,
        False,
        "Only Selected",
        "Draw the viewport overlay on selected objects only",
        cli=NO_FLAG,
        in_snapshot=False,
        in_preset=False,
    ),
    Setting(
        "overlay_edit_mode",
        BOOL,
        False,
        "Draw in Edit Mode",
        "Also draw the viewport overlay on objects in Edit Mode (over Blender's own edit wire)",
        cli=NO_FLAG,
        in_snapshot=False,
        in_preset=False,
    ),
)

# -- per object (object.solidwire; docs/image_model.md §5.9) ---------------------
# Not part of the scene's snapshot, presets or command line: gather() reads
# them per drawn instance. The override's three values share their names with
# the scene settings they replace (scope tells them apart).
_OVERRIDE_ACTIVE = lambda p: p.use_override
OBJECT_SETTINGS: tuple[Setting, ...] = (
    Setting(
        "show_in_viewport",
        BOOL,
        True,
        "Show in Viewport",
        "Draw the SolidWire overlay on this object in 3D viewports",
        scope=OBJECT,
        section="object",
        cli=NO_FLAG,
        in_snapshot=False,
        in_preset=False,
    ),
    Setting(
        "show_in_render",
        BOOL,
        True,
        "Show in Render",
        "Draw this object in SolidWire renders (it neither draws nor hides anything when off)",
        scope=OBJECT,
        section="object",
        cli=NO_FLAG,
        in_snapshot=False,
        in_preset=False,
    ),
    Setting(
        "use_override",
        BOOL,
        False,
        "Override Style",
        "Give this object (and its instances) its own wire colour, thickness and fill colour",
        scope=OBJECT,
        section="object",
        cli=NO_FLAG,
        in_snapshot=False,
        in_preset=False,
    ),
    Setting(
        "wire_color",
        COLOR,
        (0.0, 0.0, 0.0, 1.0),
        "Wire Color",
        "This object's wire colour and opacity",
        scope=OBJECT,
        minimum=0.0,
        maximum=1.0,
        subtype="COLOR",
        section="object",
        active_if=_OVERRIDE_ACTIVE,
        cli=NO_FLAG,
        in_snapshot=False,
        in_preset=False,
    ),
    Setting(
        "thickness",
        FLOAT,
        1.5,
        "Thickness",
        "This object's line width in pixels (Pixels and Depth Cue modes: the near width)",
        scope=OBJECT,
        minimum=0.0,
        maximum=1000.0,
        soft_max=20.0,
        subtype="PIXEL",
        section="object",
        active_if=_OVERRIDE_ACTIVE,
        cli=NO_FLAG,
        in_snapshot=False,
        in_preset=False,
    ),
    Setting(
        "fill_color",
        COLOR,
        (1.0, 1.0, 1.0),
        "Fill Color",
        "This object's fill colour (when Fill is on; RGB like the scene's, always opaque)",
        scope=OBJECT,
        minimum=0.0,
        maximum=1.0,
        subtype="COLOR",
        size=3,
        section="object",
        active_if=_OVERRIDE_ACTIVE,
        cli=NO_FLAG,
        in_snapshot=False,
        in_preset=False,
    ),
)
# The style values an object's override replaces (same names as the scene's).
OVERRIDE_FIELDS = ("wire_color", "thickness", "fill_color")

# -- per view layer (view_layer.solidwire; docs/image_model.md §6) --------------
# Render passes of SolidWire's own, switched on per view layer (the engine
# registers and writes them; View Layer Properties > Passes shows them).
VIEW_LAYER_SETTINGS: tuple[Setting, ...] = (
    Setting(
        "use_pass_wire",
        BOOL,
        False,
        "Wire",
        "Render pass 'Wire': the line intensity of the visible wire, 0 to 1, without colour or opacity",
        scope=VIEW_LAYER,
        cli=NO_FLAG,
        in_snapshot=False,
        in_preset=False,
    ),
    Setting(
        "use_pass_hidden_wire",
        BOOL,
        False,
        "Hidden Wire",
        "Render pass 'Hidden Wire': the coverage of the dimmed, dashed hidden edges (Hidden Lines style), "
        "whether or not Hidden Lines is on",
        scope=VIEW_LAYER,
        cli=NO_FLAG,
        in_snapshot=False,
        in_preset=False,
    ),
    Setting(
        "use_pass_edge_distance",
        BOOL,
        False,
        "Edge Distance",
        "Render pass 'Edge Distance': window-pixel distance to the nearest edge of the visible face "
        "(1e10 where nothing is drawn), to restyle lines in the compositor",
        scope=VIEW_LAYER,
        cli=NO_FLAG,
        in_snapshot=False,
        in_preset=False,
    ),
)

SETTINGS = (*SETTINGS, *OBJECT_SETTINGS, *VIEW_LAYER_SETTINGS)


# -- render passes (docs/image_model.md §6) --------------------------------------
@dataclass(frozen=True)
class RenderPass:
    """A pass the engine writes beyond Combined, as Blender registers it."""

    name: str  # the pass's name in Blender's render result
    switch: str  # the view layer property that turns it on
    own: bool  # True: on view_layer.solidwire (a VIEW_LAYER setting); False: Blender's own switch
    channels: int
    channel_ids: str
    kind: str  # Blender's pass type


DEPTH_PASS = "Depth"
NORMAL_PASS, OBJECT_INDEX_PASS, MATERIAL_INDEX_PASS = "Normal", "IndexOB", "IndexMA"
WIRE_PASS, HIDDEN_WIRE_PASS, EDGE_DISTANCE_PASS = "Wire", "Hidden Wire", "Edge Distance"

# The one list of render passes: the engine registers and writes them in
# this order (blender/engine.py), View Layer Properties > Passes shows their
# switches (blender/ui.py), and core/passes.py draws the extra ones.
RENDER_PASSES = (
    RenderPass(DEPTH_PASS, "use_pass_z", False, 1, "Z", "VALUE"),
    RenderPass(NORMAL_PASS, "use_pass_normal", False, 3, "XYZ", "VECTOR"),
    RenderPass(OBJECT_INDEX_PASS, "use_pass_object_index", False, 1, "X", "VALUE"),
    RenderPass(MATERIAL_INDEX_PASS, "use_pass_material_index", False, 1, "X", "VALUE"),
    RenderPass(WIRE_PASS, "use_pass_wire", True, 1, "X", "VALUE"),
    RenderPass(HIDDEN_WIRE_PASS, "use_pass_hidden_wire", True, 1, "X", "VALUE"),
    RenderPass(EDGE_DISTANCE_PASS, "use_pass_edge_distance", True, 1, "X", "VALUE"),
)
# Beyond Combined and Depth: the passes drawn on request (``extra_passes``).
EXTRA_PASSES = tuple(p.name for p in RENDER_PASSES if p.name != DEPTH_PASS)

# (scope, name) -> setting: a name may exist in several scopes.
BY_SCOPE: dict[tuple[str, str], Setting] = {(s.scope, s.name): s for s in SETTINGS}
assert len(BY_SCOPE) == len(SETTINGS), "a setting is defined twice in one scope"
# The scene's settings by name.
BY_NAME: dict[str, Setting] = {s.name: s for s in SETTINGS if s.scope == SCENE}


def settings_in(scope: str) -> tuple[Setting, ...]:
    return tuple(s for s in SETTINGS if s.scope == scope)


def preset_settings() -> tuple[Setting, ...]:
    """Settings saved in presets, in the order they are applied.

    ``diagonal_mode`` comes before ``pattern_duty`` (choosing a pattern mode
    resets the duty), which declaration order guarantees."""
    return tuple(s for s in SETTINGS if s.in_preset and s.scope == SCENE)


# Command-line options that set two settings at once, as (flag, (first,
# second), metavars, the bool they switch on, the flag that switches it off).
# The second value must not be smaller than the first.
@dataclass(frozen=True)
class CliRange:
    flag: str
    names: tuple
    metavar: tuple
    enables: str | None = None
    off_flag: str | None = None
    help: str = ""


CLI_RANGES = (
    CliRange(
        "--fade",
        ("fade_start", "fade_end"),
        ("START", "END"),
        enables="use_fade",
        off_flag="--no-fade",
        help="fade the wire out between these view depths (scene units; END beyond START)",
    ),
    CliRange(
        "--thickness-depth",
        ("thickness_depth_start", "thickness_depth_end"),
        ("NEAR", "FAR"),
        help="view depths where the depth cue starts and ends (DEPTH; FAR beyond NEAR)",
    ),
)


# -- shader parameter block ----------------------------------------------------
# Slots that depend on the view, not on one setting: (glsl name, kind).
# ``core/settings.py`` fills them from the View.
VIEW_PARAMS = (
    ("viewport", "vec4"),  # x0, y0, width, height of the target, px
    ("world_half_thickness_px", "float"),  # world_thickness / 2 in px at clip w = 1
    # 2 / the scene's Thickness (0 where it is 0, float32's largest where
    # it overflows): what an edge class's width is multiplied by per unit of
    # the wire's, whose width carries the thickness mode and an object's own
    # Thickness (image model §3.6). Divided in float64: a Thickness below
    # float32's normal range would be 0 to a GPU.
    ("class_width_scale", "float"),
    ("inv_clip_end", "float"),  # 1 / the view's clip end (linear depth of the render)
    ("depth_rows", "vec4"),  # the projection's P22, P23, P32, P33 (view depth <-> window depth)
    # Viewport overlay: (a, b, c, e), its points moved min(a + b |d|, c + e |d|)
    # towards the camera before Blender's depth test (view.blender_depth_allowance).
    ("blender_depth_allowance", "vec4"),
)


@dataclass(frozen=True)
class BlockMember:
    glsl: str
    glsl_type: str  # "vec4" or "float"
    setting: Setting | None  # None: a view slot (VIEW_PARAMS) or padding


def _param_block() -> tuple[BlockMember, ...]:
    """The std140 layout: every vec4 first, then floats, padded to whole vec4s
    (so no member needs alignment padding of its own)."""
    members = [
        BlockMember(s.param.glsl, "vec4" if s.kind == COLOR else "float", s)
        for s in SETTINGS
        if s.param and s.scope == SCENE
    ]
    members += [BlockMember(name, kind, None) for name, kind in VIEW_PARAMS]
    vec4s = [m for m in members if m.glsl_type == "vec4"]
    floats = [m for m in members if m.glsl_type == "float"]
    padding = [BlockMember(f"_pad{i}", "float", None) for i in range(-len(floats) % 4)]
    return (*vec4s, *floats, *padding)


PARAM_BLOCK: tuple[BlockMember, ...] = _param_block()
PARAM_FLOATS = sum(4 if m.glsl_type == "vec4" else 1 for m in PARAM_BLOCK)


EDGE_CLASS_NAMES = tuple(edge_class[0] for edge_class in EDGE_CLASS_STYLES)
# Line styles: 0 the wire, k + 1 the class EDGE_CLASS_NAMES[k].
STYLE_COUNT = 1 + len(EDGE_CLASS_NAMES)


def style_lookup_glsl() -> str:
    """The GLSL lookups of each line style's width, pattern duty and colour
    in the parameter block (shaders/edge_styles.glsl uses them), one case
    per edge class in EDGE_CLASS_STYLES order."""

    def lookup(glsl_type: str, function: str, member: str, fallback: str) -> list[str]:
        cases = [f"    case {k + 1}: return params.{name}_{member};" for k, name in enumerate(EDGE_CLASS_NAMES)]
        return [
            f"{glsl_type} {function}(int style)",
            "{",
            "  switch (style) {",
            *cases,
            "  }",
            f"  return {fallback};",
            "}",
        ]

    lines = [
        "/* Generated from solidwire_addon/core/schema.py (EDGE_CLASS_STYLES): style k + 1 is class k. */",
        f"#define CLASS_STYLE_COUNT {len(EDGE_CLASS_NAMES)}",
        "#if STYLE_COUNT > 1 || defined(STYLE_COLORS)",
        *lookup("float", "style_own_half_thickness", "half_thickness", "params.half_thickness"),
        *lookup("float", "style_duty", "duty", "1.0"),
        *lookup("vec4", "style_color", "color", "params.wire_color"),
        "#endif",
        "",
    ]
    return "\n".join(lines)


def param_block_glsl() -> str:
    """The GLSL declaration of the parameter block's struct."""
    lines = ["/* Generated from solidwire_addon/core/schema.py (PARAM_BLOCK); std140. */", "struct SolidWireParams {"]
    lines += [f"  {m.glsl_type} {m.glsl};" for m in PARAM_BLOCK]
    lines.append("};\n")
    return "\n".join(lines)
