"""Viewport target: the SolidWire overlay in every 3D viewport.

A ``SpaceView3D`` draw handler (``'WINDOW'``, ``'POST_VIEW'``) draws the
solid wireframe over what Blender has drawn, through the same
gather -> cache -> draw path as the render engine (:func:`draw_scene_overlay`
is the whole target; the handler only reads the viewport's view and
visibility and calls it). Tests call :func:`draw_scene_overlay` directly with
a camera's view inside an offscreen framebuffer.

Colour: a POST_VIEW handler draws into the viewport's overlay framebuffer,
whose colour texture is ``SRGB8_A8`` (gpu_viewport.cc, "dtxl_color_overlay").
The hardware encodes linear shader output to sRGB on write and blends in
linear, so the scene-linear colours of ``wire_color`` / ``fill_color`` (subtype
COLOR) are passed through unchanged: the stored value is sRGB(colour), which is
what the colour swatch in the panel shows. (Blender's builtin shaders convert
*sRGB theme colours* to linear for that target; our inputs are already linear.)
Alpha is never encoded, so the intensity I reaches the screen exactly.
"""

from __future__ import annotations

import time

import bpy

from ..core import passes
from ..core.log import warn_once
from ..core.view import View
from . import gather, runtime
from .views import region_view

_handle = None


def viewport_object_filter(view_layer, space_view3d=None, *, only_selected: bool = False):
    """``object_filter`` for gather(): what this viewport shows.

    ``visible_get`` covers hide states (eye icon, ``hide_viewport``),
    collection visibility, and local view when ``space_view3d`` is given.
    The per-object opt-out and "only selected" come on top."""

    def keep(obj) -> bool:
        if getattr(obj, "solidwire_exclude", False):
            return False
        try:
            visible = obj.visible_get(view_layer=view_layer, viewport=space_view3d)
        except (TypeError, RuntimeError):
            # Not in this view layer (e.g. an instancer from a linked scene):
            # the depsgraph already decided it is drawn.
            visible = True
        if not visible:
            return False
        if only_selected and not obj.select_get(view_layer=view_layer):
            return False
        return True

    return keep


def draw_scene_overlay(depsgraph, view: View, settings, *, object_filter=None) -> dict:
    """Draw the overlay of ``depsgraph``'s scene into the bound framebuffer,
    which already holds the scene's colour and depth. Returns the frame stats."""
    # Meshes are reused across redraws: the viewport depsgraph reports every
    # edit before it is drawn, and gather() re-extracts only what changed.
    frame = runtime.begin_frame(reuse=True)
    items, seen, ms_extract = gather.gather(depsgraph, runtime.mesh_cache, object_filter=object_filter,
                                            **passes.gather_options(settings))
    start = time.perf_counter()
    stats = passes.draw_over_viewport(items, view, settings)
    ms_draw = (time.perf_counter() - start) * 1000.0
    return runtime.end_frame(frame, stats, ms_extract, ms_draw, seen)


def _draw_callback() -> None:
    """The POST_VIEW handler. Never raises: a failure is reported once and the
    next redraw tries again."""
    try:
        context = bpy.context
        props = getattr(context.scene, "solidwire", None)
        if props is None or not props.show_overlay:
            return
        space = context.space_data
        region, region_3d = context.region, context.region_data
        if region is None or region_3d is None:
            return
        overlay = getattr(space, "overlay", None)
        if overlay is not None and not overlay.show_overlays:
            return  # the viewport's own Overlays toggle hides ours too
        view_layer = context.view_layer
        draw_scene_overlay(
            context.evaluated_depsgraph_get(),
            region_view(region, region_3d),
            props.snapshot(),
            object_filter=viewport_object_filter(view_layer, space, only_selected=props.only_selected),
        )
    except Exception as exc:  # noqa: BLE001 - a draw handler must never raise
        warn_once(("overlay", type(exc).__name__, str(exc)), f"SolidWire overlay: {type(exc).__name__}: {exc}")


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
