"""What the viewport overlay draws in each viewport state, as a pure function
of plain inputs (docs/image_model.md §5.6).

The draw handler (``blender/overlay.py``) only reads ``bpy.context`` into a
:class:`ViewportState` and, per object, an :class:`ObjectState`; every
decision is made here, so tests can call it with any state a real window
could be in (X-ray, Rendered shading, clipping region, HiDPI, Edit Mode...).

Rules (docs/user/overlay.md, "Viewport states"):

* Nothing is drawn when this viewport's SolidWire toggle is off or the
  viewport's own Overlays switch is off.
* Occlusion: Blender's depth is used as it stands, except with X-ray active
  (Solid or Wireframe shading, X-ray on with alpha < 1: Blender's
  ``XRAY_ACTIVE``), where the scene is seen through and Blender's depth is no
  surface. Then only SolidWire's own nearest surface hides wires. Material
  Preview and Rendered shading ignore the X-ray button, as Blender does.
  Where Blender's depth is empty (Cycles viewport without a depth pass) the
  own depth pre-pass alone decides, which is the same image.
* Clipping region (Alt+B, ``region_3d.use_clip_planes``): fragments outside
  Blender's world-space planes (kept where ``dot(plane, (x, 1)) >= 0``) are
  discarded in every pass; full-width silhouettes are off while clipping
  (their fins are not clipped).
* HiDPI: every length in pixels (settings with subtype PIXEL) is multiplied
  by Blender's UI scale ``preferences.system.pixel_size``, as Blender's own
  overlay line widths are: the wire looks the same size on a 2x display.
* Objects: visible in this viewport (hide states, collections, local view),
  not opted out, selected when "Only Selected" is on; objects in Edit Mode
  are left to Blender's own edit wire unless "Draw in Edit Mode" is on.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from . import schema

SOLID, WIREFRAME, MATERIAL, RENDERED = "SOLID", "WIREFRAME", "MATERIAL", "RENDERED"


@dataclass(frozen=True)
class ViewportState:
    """Plain inputs read from one viewport region and its scene."""

    show: bool = True  # this viewport's SolidWire toggle (scene default when never set)
    show_overlays: bool = True  # the viewport's own Overlays switch
    shading: str = SOLID  # space.shading.type
    xray: bool = False  # show_xray (Solid) or show_xray_wireframe (Wireframe)
    xray_alpha: float = 1.0  # xray_alpha or xray_alpha_wireframe
    clip_planes: tuple | None = None  # region_3d.clip_planes when use_clip_planes, else None
    pixel_size: float = 1.0  # preferences.system.pixel_size
    only_selected: bool = False
    draw_edit_mode: bool = False


@dataclass(frozen=True)
class ObjectState:
    """Plain inputs read from one object for this viewport."""

    visible: bool = True  # visible_get(view_layer, viewport): hide, collections, local view
    selected: bool = False
    excluded: bool = False  # object.solidwire.show_in_viewport off (or the older solidwire_exclude)
    in_edit_mode: bool = False


@dataclass(frozen=True)
class OverlayPlan:
    """What the overlay draws in one viewport."""

    scene_depth: bool  # occlude by the depth Blender has drawn (else own depth only)
    clip_planes: np.ndarray | None  # (6, 4) world-space planes, or None
    pixel_scale: float
    only_selected: bool
    draw_edit_mode: bool
    # Blender's depth holds the surface of every object it draws solid (Solid
    # shading and Material Preview, no X-ray): our own depth pre-pass can go.
    scene_surfaces: bool = False


def xray_active(state: ViewportState) -> bool:
    """Blender's XRAY_ACTIVE: X-ray on with alpha below 1 in Solid or
    Wireframe shading (Material Preview and Rendered have no X-ray)."""
    return state.shading in (SOLID, WIREFRAME) and bool(state.xray) and float(state.xray_alpha) < 1.0


def _planes(clip_planes) -> np.ndarray | None:
    if clip_planes is None:
        return None
    planes = np.asarray(clip_planes, dtype=np.float64).reshape(-1, 4)
    if planes.shape[0] == 0 or not np.isfinite(planes).all():
        return None
    # Blender keeps 6 planes; unused ones are zero and keep everything.
    out = np.zeros((6, 4))
    out[: min(len(planes), 6)] = planes[:6]
    return out


def _pixel_scale(pixel_size) -> float:
    try:
        scale = float(pixel_size)
    except (TypeError, ValueError):
        return 1.0
    return scale if np.isfinite(scale) and scale > 0.0 else 1.0


def plan_overlay(state: ViewportState) -> OverlayPlan | None:
    """The overlay plan for ``state``, or None when nothing is drawn."""
    if not state.show or not state.show_overlays:
        return None
    return OverlayPlan(
        scene_depth=not xray_active(state),
        scene_surfaces=state.shading in (SOLID, MATERIAL) and not xray_active(state),
        clip_planes=_planes(state.clip_planes),
        pixel_scale=_pixel_scale(state.pixel_size),
        only_selected=bool(state.only_selected),
        draw_edit_mode=bool(state.draw_edit_mode),
    )


def keep_object(plan: OverlayPlan, obj: ObjectState) -> bool:
    """Whether the overlay draws ``obj`` (an instance follows its instancer)."""
    if obj.excluded or not obj.visible:
        return False
    if plan.only_selected and not obj.selected:
        return False
    return not (obj.in_edit_mode and not plan.draw_edit_mode)


PIXEL_SETTINGS = tuple(
    s.name for s in schema.SETTINGS if s.kind == schema.FLOAT and s.subtype == "PIXEL" and s.in_snapshot
)


def draw_items(plan: OverlayPlan, items):
    """``items`` as this viewport draws them: an object's own Thickness is a
    pixel length like the scene's, so it takes the UI scale too."""
    if plan.pixel_scale == 1.0:
        return items
    return [
        item
        if item.style is None
        else replace(item, style=replace(item.style, thickness=item.style.thickness * plan.pixel_scale))
        for item in items
    ]


def draw_settings(plan: OverlayPlan, settings):
    """``settings`` as this viewport draws them: pixel lengths times the UI
    scale, silhouettes off while clipping."""
    changes = {}
    if plan.pixel_scale != 1.0:
        changes = {name: getattr(settings, name) * plan.pixel_scale for name in PIXEL_SETTINGS}
    if plan.clip_planes is not None and getattr(settings, "use_silhouettes", False):
        changes["use_silhouettes"] = False
    return replace(settings, **changes) if changes else settings
