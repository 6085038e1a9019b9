"""Viewport target: the SolidWire overlay in every 3D viewport.

A ``SpaceView3D`` draw handler (``'WINDOW'``, ``'POST_VIEW'``) draws the
solid wireframe over what Blender has drawn, through the same
gather -> cache -> draw path as the render engine (:func:`draw_scene_overlay`
is the whole target; the handler only reads the viewport's view and
visibility and calls it). Tests call :func:`draw_scene_overlay` directly with
a camera's view inside an offscreen framebuffer.

Colour: a POST_VIEW handler draws into the viewport's overlay framebuffer,
whose colour texture is ``SRGB8_A8`` (gpu_viewport.cc, "dtxl_color_overlay"),
and Blender does not colour-manage that buffer: it merges it over the
colour-managed scene in a 2.2-power space. So the overlay applies the scene's
colour management itself, last in its fragment stages, through a display
LUT that Blender made (color_management.py, core/display_transform.py,
docs/image_model.md §9): the screen then shows the colours of the F12 render
(AgX, Filmic, looks, exposure, ...). Alpha is never encoded, so the
intensity I reaches the screen exactly.
"""

from __future__ import annotations

import time

import bpy

from ..core import colors, overlay_state, passes
from ..core.log import one_line, warn_once
from ..core.view import DrawStats, View
from . import color_management, density, gather, properties, runtime, setting_repair, strands
from .views import region_view

_handle = None


# -- the per-viewport toggle (stored on the screen; see properties.py) ----------


def _area_index(screen, area) -> int | None:
    for index, candidate in enumerate(getattr(screen, "areas", ())):
        if candidate == area:
            return index
    return None


def viewport_toggle(screen, area):
    """This 3D View's toggle entry, or None when it never had one."""
    index = _area_index(screen, area)
    if index is None:
        return None
    for entry in getattr(screen, properties.VIEWPORTS_ATTRIBUTE, ()):
        if entry.area_index == index:
            return entry
    return None


def viewport_shows(screen, area, scene_props) -> bool:
    """Whether SolidWire is on in this 3D View: its own toggle, or the
    scene's default for a viewport that never had one."""
    entry = viewport_toggle(screen, area)
    if entry is not None:
        return bool(entry.show)
    return bool(getattr(scene_props, "show_overlay", False))


def set_viewport_shows(screen, area, show: bool) -> None:
    entry = viewport_toggle(screen, area)
    if entry is None:
        index = _area_index(screen, area)
        if index is None:
            raise ValueError("the area is not part of the screen")
        entry = getattr(screen, properties.VIEWPORTS_ATTRIBUTE).add()
        entry.area_index = index
    entry.show = bool(show)


# -- what the overlay draws ------------------------------------------------------


def object_state(obj, view_layer, space_view3d=None, plan=None) -> overlay_state.ObjectState:
    """Read one object's plain state for this viewport.

    ``visible_get`` covers hide states (eye icon, ``hide_viewport``),
    collection visibility, and local view when ``space_view3d`` is given.
    The per-object switch (``object.solidwire.show_in_viewport``, or the
    older ``solidwire_exclude``) makes the object excluded. With ``plan``
    only what the plan's rule looks at is read (overlay_state.keep_object:
    selection only for "only selected", the mode only when Edit Mode objects
    are left out); the rest keeps its default."""
    props = getattr(obj, "solidwire", None)
    try:
        visible = obj.visible_get(view_layer=view_layer, viewport=space_view3d)
    except (TypeError, RuntimeError):
        # Not in this view layer (e.g. an instancer from a linked scene):
        # the depsgraph already decided it is drawn.
        visible = True
    selected = False
    if plan is None or plan.only_selected:
        try:
            selected = obj.select_get(view_layer=view_layer)
        except (TypeError, RuntimeError):
            selected = False
    in_edit_mode = False
    if plan is None or not plan.draw_edit_mode:
        in_edit_mode = getattr(obj, "mode", "OBJECT") == "EDIT"
    return overlay_state.ObjectState(
        visible=bool(visible),
        selected=bool(selected),
        excluded=bool(getattr(obj, "solidwire_exclude", False))
        or (props is not None and not getattr(props, "show_in_viewport", True)),
        in_edit_mode=in_edit_mode,
    )


def object_filter(plan, view_layer, space_view3d=None):
    """``object_filter`` for gather(): the plan's rule on each object's state."""

    def keep(obj) -> bool:
        return overlay_state.keep_object(plan, object_state(obj, view_layer, space_view3d, plan))

    return keep


def frame_object_filter(plan, view_layer, space_view3d=None):
    """:func:`object_filter` for one frame: each original object's answer is
    read once and remembered, since gather() asks for every instance and an
    instancer (particles, collection instances, geometry nodes) owns
    thousands. Only for a single draw: an edit between two gathers would not
    be seen."""
    keep_object = object_filter(plan, view_layer, space_view3d)
    known: dict = {}

    def keep(obj) -> bool:
        uid = obj.session_uid
        answer = known.get(uid)
        if answer is None:
            answer = known[uid] = keep_object(obj)
        return answer

    return keep


def viewport_object_filter(view_layer, space_view3d=None, *, only_selected: bool = False, draw_edit_mode: bool = True):
    """``object_filter`` for gather() outside a draw (operators, tests):
    visibility, opt-out and "only selected"; Edit Mode objects kept unless
    ``draw_edit_mode`` is False."""
    plan = overlay_state.plan_overlay(
        overlay_state.ViewportState(only_selected=only_selected, draw_edit_mode=draw_edit_mode)
    )
    return object_filter(plan, view_layer, space_view3d)


def viewport_state(context) -> overlay_state.ViewportState | None:
    """Read the plain state of the viewport being drawn (None: not a 3D View
    region or no SolidWire settings)."""
    props = getattr(context.scene, "solidwire", None)
    if props is None:
        return None
    space = context.space_data
    region_3d = context.region_data
    if context.region is None or region_3d is None:
        return None
    shading = getattr(space, "shading", None)
    shading_type = getattr(shading, "type", overlay_state.SOLID)
    if shading_type == overlay_state.WIREFRAME:
        xray, alpha = getattr(shading, "show_xray_wireframe", False), getattr(shading, "xray_alpha_wireframe", 1.0)
    else:
        xray, alpha = getattr(shading, "show_xray", False), getattr(shading, "xray_alpha", 1.0)
    clip_planes = None
    if getattr(region_3d, "use_clip_planes", False):
        clip_planes = tuple(tuple(plane) for plane in region_3d.clip_planes)
    overlay = getattr(space, "overlay", None)
    return overlay_state.ViewportState(
        show=viewport_shows(context.screen, context.area, props),
        show_overlays=bool(getattr(overlay, "show_overlays", True)),
        shading=shading_type,
        xray=bool(xray),
        xray_alpha=float(alpha),
        clip_planes=clip_planes,
        pixel_size=float(context.preferences.system.pixel_size),
        only_selected=bool(props.only_selected),
        draw_edit_mode=bool(props.overlay_edit_mode),
    )


# draw_scene_overlay's default: the display LUT of the depsgraph's scene.
SCENE_COLOR_MANAGEMENT = "scene"


def draw_scene_overlay(
    depsgraph, view: View, settings, *, object_filter=None, plan=None, display=SCENE_COLOR_MANAGEMENT
) -> dict:
    """Draw the overlay of ``depsgraph``'s scene into the bound framebuffer,
    which already holds the scene's colour and depth. ``plan`` (an
    ``overlay_state.OverlayPlan``) carries the viewport state: depth source,
    clipping planes and UI scale. ``display``: the display LUT the colours
    leave through (color_management.display_lut), by default the scene's,
    made now if needed; None draws scene-linear colours. Returns the frame
    stats."""
    if plan is None:
        plan = overlay_state.plan_overlay(overlay_state.ViewportState())
    if display is SCENE_COLOR_MANAGEMENT:
        display = color_management.display_lut(depsgraph.scene)
    # Meshes are reused across redraws: the viewport depsgraph reports every
    # edit before it is drawn, and gather() re-extracts only what changed.
    options = runtime.options  # read once per redraw and handed down
    frame = runtime.begin_frame(reuse=options.reuse_meshes)
    object_settings = gather.ObjectSettings(gather.SHOW_IN_VIEWPORT, bpy.data.objects)
    items, seen, ms_extract = gather.gather(
        depsgraph,
        runtime.mesh_cache,
        object_filter=object_filter,
        object_settings=object_settings,
        edge_lengths=density.needs_lengths(settings),
        tessellation=bool(settings.show_tessellation),
        reposition=options.reposition_meshes,
        **gather.gather_options(settings),
    )
    setting_repair.report_later(object_settings.messages)
    drawn = overlay_state.draw_settings(plan, settings)
    # Pixel lengths at the UI scale: the objects' own Thickness first, then
    # the density fade, which styles items from what they draw with.
    items = overlay_state.draw_items(plan, items)
    density.fade_dense_items(items, view, drawn)
    # Hair and point clouds (blender/strands.py), drawn by the same passes.
    strand_items = strands.gather_strands(
        depsgraph,
        object_filter=object_filter,
        object_settings=gather.ObjectSettings(gather.SHOW_IN_VIEWPORT, bpy.data.objects),
        colors=colors.needs_item_colors(settings),
    )
    start = time.perf_counter()
    if items or strand_items:
        stats = passes.draw_over_viewport(
            items,
            view,
            drawn,
            scene_depth=plan.scene_depth,
            scene_surfaces=plan.scene_surfaces,
            clip_planes=plan.clip_planes,
            display=display,
            strands=strand_items,
            options=options,
        )
    else:
        # Nothing to draw (every object hidden, opted out or not drawable):
        # leave the viewport's buffers and GPU state as Blender left them;
        # without scene depth the passes would clear the depth first.
        stats = DrawStats()
    ms_draw = (time.perf_counter() - start) * 1000.0
    return runtime.end_frame(frame, stats, ms_extract, ms_draw, seen)


def _draw_callback() -> None:
    """The POST_VIEW handler: reads the context into plain state, the rest is
    core/overlay_state.py. Never raises: a failure is reported once and the
    next redraw tries again."""
    try:
        context = bpy.context
        state = viewport_state(context)
        plan = overlay_state.plan_overlay(state) if state is not None else None
        if plan is None:
            return
        # A stored NaN draws as its default; the stored value is put right
        # by a timer (no data changes while Blender draws).
        settings, messages = setting_repair.checked_snapshot(context.scene, defer=True)
        setting_repair.report_later(messages)
        draw_scene_overlay(
            context.evaluated_depsgraph_get(),
            region_view(context.region, context.region_data),
            settings,
            object_filter=frame_object_filter(plan, context.view_layer, context.space_data),
            plan=plan,
            # Never built inside a draw: asked of a timer (color_management).
            display=color_management.display_lut(context.scene, request=True),
        )
    except Exception as exc:  # noqa: BLE001 - a draw handler must never raise
        warn_once(
            ("overlay", type(exc).__name__, str(exc)), f"SolidWire overlay: {type(exc).__name__}: {one_line(exc)}"
        )


def is_registered() -> bool:
    return _handle is not None


def register() -> None:
    global _handle
    if _handle is None:
        _handle = bpy.types.SpaceView3D.draw_handler_add(_draw_callback, (), "WINDOW", "POST_VIEW")


def unregister() -> None:
    global _handle
    if _handle is not None:
        bpy.types.SpaceView3D.draw_handler_remove(_handle, "WINDOW")
        _handle = None
