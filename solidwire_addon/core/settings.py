"""The plain settings snapshot the draw path takes, and the parameter block
packed from it. Both are made from the schema (``core/schema.py``).

:class:`DrawSettings` is a frozen dataclass with one field per schema setting
that is ``in_snapshot``; ``DrawSettings()`` holds the defaults. Non-finite
numbers (a script or a driver can set NaN) fall back to the default with one
message, so no frame turns NaN or silently blank.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from . import schema
from .log import warn_once

_SNAPSHOT = tuple(s for s in schema.SETTINGS if s.in_snapshot and s.scope == schema.SCENE)


def _post_init(self) -> None:
    for setting in _SNAPSHOT:
        value, default = getattr(self, setting.name), setting.default
        if setting.kind == schema.FLOAT:
            ok = isinstance(value, (int, float)) and math.isfinite(value)
            fixed = float(value) if ok else default
        elif setting.kind == schema.COLOR:
            fixed = tuple(float(c) if math.isfinite(c) else d for c, d in zip(value, default))
            ok = fixed == tuple(value)
        else:
            continue
        if not ok:
            warn_once(
                ("setting", setting.name),
                f"SolidWire: setting '{setting.name}' is not a finite number ({value}); using {fixed}",
            )
        object.__setattr__(self, setting.name, fixed)


@classmethod
def _from_properties(cls, props) -> DrawSettings:
    """Snapshot of a property group made from the schema (or any object
    with the same attribute names)."""
    values = {}
    for setting in _SNAPSHOT:
        value = getattr(props, setting.name)
        if setting.kind == schema.COLOR:
            value = tuple(float(c) for c in value)
        values[setting.name] = value
    return cls(**values)


DrawSettings = dataclasses.make_dataclass(
    "DrawSettings",
    [(s.name, type(s.default), dataclasses.field(default=s.default)) for s in _SNAPSHOT],
    namespace={"__post_init__": _post_init, "from_properties": _from_properties, "__module__": __name__},
    frozen=True,
)
DrawSettings.__doc__ = "A plain, immutable snapshot of the scene's SolidWire settings (see core/schema.py)."


def depth_rows(projection) -> tuple:
    """(P22, P23, P32, P33) of a GL projection: a point at view depth d has
    clip z = P23 - P22 d and clip w = P33 - P32 d."""
    return tuple(float(projection[row][column]) for row, column in ((2, 2), (2, 3), (3, 2), (3, 3)))


def clip_end_of(projection) -> float:
    """The far clip distance of a GL projection matrix (perspective or
    orthographic), from its third row."""
    p22, p23 = float(projection[2][2]), float(projection[2][3])
    if float(projection[3][3]) == 1.0:  # orthographic: p22 = -2/(f-n), p23 = -(f+n)/(f-n)
        far = (p23 - 1.0) / p22
    else:  # perspective: p22 = -(f+n)/(f-n), p23 = -2fn/(f-n)
        far = p23 / (p22 + 1.0) if p22 != -1.0 else math.inf
    return far if math.isfinite(far) and far > 0.0 else 1.0e30


def _class_width_scale(thickness: float) -> float:
    """schema.VIEW_PARAMS' class_width_scale: 1 / (thickness / 2)."""
    if not thickness > 0.0:
        return 0.0
    return min(2.0 / thickness, float(np.finfo(np.float32).max))


def pack_params(
    settings, viewport, projection=None, blender_depth_allowance=(0.0,) * 4, class_reference: float | None = None
) -> bytes:
    """The std140 parameter block (layout: schema.PARAM_BLOCK).

    ``projection`` (the view's) is needed for world-space thickness: window
    pixels per scene unit across the view at clip w = 1 are
    0.5 * height * projection[1][1]; the shader divides by the fragment's w.
    ``blender_depth_allowance``: the viewport overlay's
    view.blender_depth_allowance, none elsewhere. ``class_reference``: the
    Thickness class widths keep their ratio to (image model §3.6), the
    scene's; None: ``settings.thickness`` (they are the scene's)."""
    if class_reference is None:
        class_reference = settings.thickness
    px_per_unit = 0.0 if projection is None else 0.5 * float(viewport[3]) * abs(float(projection[1][1]))
    view_values = {
        "viewport": tuple(float(v) for v in viewport),
        "world_half_thickness_px": 0.5 * max(float(settings.world_thickness), 0.0) * px_per_unit,
        "class_width_scale": _class_width_scale(float(class_reference)),
        "inv_clip_end": 0.0 if projection is None else 1.0 / clip_end_of(projection),
        "depth_rows": (0.0,) * 4 if projection is None else depth_rows(projection),
        "blender_depth_allowance": tuple(float(v) for v in blender_depth_allowance),
    }
    values: list[float] = []
    for member in schema.PARAM_BLOCK:
        if member.setting is not None:
            value = member.setting.param.pack(getattr(settings, member.setting.name))
        else:
            value = view_values.get(member.glsl, 0.0)
        if member.glsl_type == "vec4":
            values.extend(float(v) for v in value)
        else:
            values.append(float(value))
    assert len(values) == schema.PARAM_FLOATS
    return np.asarray(values, dtype=np.float32).tobytes()
