"""The scene's colour management as a display LUT for the viewport overlay
(core/display_transform.py, docs/image_model.md §9).

How the table is made: Blender itself transforms the grid. A scratch float
image holds the grid's scene-linear colours and is saved "as render"
(``Image.save_render``) to a 16-bit PNG by a scratch scene that carries a
copy of the scene's colour management (display device, view transform,
look, exposure, gamma, curves, white balance) and PNG output settings; the
file is read back and everything made for it is removed (nothing stays in
``bpy.data`` or on disk). A scratch scene and not the user's own: save_render
takes the file format and any output colour override from the scene's
render output settings, which must not be touched. This is the path an F12
render's colours take into a file, so the overlay matches the render for any
OCIO config, with no colour science of our own.

Cost, measured with bpy 5.0.1 on a 2-core machine (65^3 nodes): about 70 ms
(the save itself), plus once per view transform in the process the time
Blender takes to build its OCIO processor (up to ~150 ms for AgX). Tables
are therefore cached by the settings that change them (``settings_key``), a
few at a time, and never built inside a draw:

* Without an interface (the bpy module, ``blender -b``: tests, scripts) a
  table is built when first asked for.
* In Blender's interface the draw handler asks with ``request=True``: a
  table not built yet is made soon by a timer in the main thread, outside any
  draw (creating data-blocks while a viewport draws is not safe), which then
  redraws the 3D views. Meanwhile the overlay draws with the scene's last
  table (a moment of old colours while a setting is dragged), or, before the
  first one, scene-linear as before this existed.
"""

from __future__ import annotations

import os
import tempfile
import threading
from collections import OrderedDict

import bpy
import numpy as np

from ..core import compat, display_transform, shaders
from ..core.display_transform import DisplayLUT
from ..core.log import one_line, warn_once
from . import runtime

# Tables kept (LRU): one per view-transform state recently shown. Each is
# ~3 MB of numpy and ~2 MB of GPU memory.
CACHE_SIZE = 4
# Bumped when the grid or its meaning changes (part of every key).
LUT_VERSION = (display_transform.LUT_SIZE, display_transform.WHITE_NODE, display_transform.SHAPER_KNEE)

_cache: OrderedDict = OrderedDict()  # key -> DisplayLUT
_latest: dict[str, DisplayLUT] = {}  # scene name -> its last table (fallback while one is made)
_failed: set = set()  # keys whose build failed (not retried)
_requested: set[str] = set()  # scene names a timer will build for
SCRATCH_NAME = ".solidwire_display_lut"

# -- the settings that change the table ----------------------------------------------


def _value(struct, prop):
    value = getattr(struct, prop.identifier)
    if prop.type in {"FLOAT", "INT", "BOOLEAN"} and getattr(prop, "is_array", False):
        return tuple(value)
    return value


def _scalars(struct, skip=()) -> tuple:
    """(name, value) of every plain property of an RNA struct (pointers and
    collections apart), in RNA order: a setting Blender adds later (as 5.0
    added white balance) is in the key without a change here."""
    out = []
    for prop in struct.bl_rna.properties:
        if prop.identifier in skip or prop.identifier == "rna_type" or prop.type in {"POINTER", "COLLECTION"}:
            continue
        out.append((prop.identifier, _value(struct, prop)))
    return tuple(out)


def _curve_key(mapping) -> tuple:
    curves = tuple(
        tuple((tuple(point.location), point.handle_type) for point in curve.points) for curve in mapping.curves
    )
    return _scalars(mapping), curves


def settings_key(scene) -> tuple:
    """What the table of ``scene`` depends on: display and view settings
    (the curve only while it is used)."""
    view = scene.view_settings
    curves = _curve_key(view.curve_mapping) if getattr(view, "use_curve_mapping", False) else None
    return LUT_VERSION, _scalars(scene.display_settings), _scalars(view), curves


# -- building a table -------------------------------------------------------------------

# Set first, in this order: the view transforms offered depend on the display,
# the looks on the view transform.
_ORDER = ("display_device", "view_transform", "look")
# Derived from temperature and tint (and setting it rewrites them).
_DERIVED = ("white_balance_whitepoint",)


def _copy_scalars(source, target, first=(), skip=()) -> None:
    names = [name for name in first if hasattr(source, name)]
    names += [name for name, _value in _scalars(source, skip=(*names, *skip))]
    for name in names:
        prop = source.bl_rna.properties[name]
        if prop.is_readonly:
            continue
        setattr(target, name, _value(source, prop))


def _copy_curve_mapping(source, target) -> None:
    _copy_scalars(source, target)
    for src, dst in zip(source.curves, target.curves):
        while len(dst.points) < len(src.points):
            dst.points.new(0.0, 0.0)
        while len(dst.points) > len(src.points):
            dst.points.remove(dst.points[len(dst.points) - 1])
        for a, b in zip(src.points, dst.points):
            b.location = tuple(a.location)
            b.handle_type = a.handle_type
    target.update()


def copy_color_management(source, target) -> None:
    """Give scene ``target`` the colour management of scene ``source``."""
    _copy_scalars(source.display_settings, target.display_settings, first=_ORDER)
    view, into = source.view_settings, target.view_settings
    _copy_scalars(view, into, first=_ORDER, skip=_DERIVED)
    if getattr(view, "use_curve_mapping", False):
        _copy_curve_mapping(view.curve_mapping, into.curve_mapping)


def _png_settings(scene) -> None:
    compat.set_media_type(scene.render.image_settings, "IMAGE")
    settings = scene.render.image_settings
    settings.file_format = "PNG"
    settings.color_depth = "16"
    settings.color_mode = "RGB"
    settings.compression = 0  # 15 (the default) costs ~80 ms more per table
    if hasattr(settings, "color_management"):
        settings.color_management = "FOLLOW_SCENE"
    scene.render.dither_intensity = 0.0  # no noise in the table


def transform_colors(scene, colors: np.ndarray) -> np.ndarray:
    """(K, 3) scene-linear colours -> (K, 3) float64 display-encoded values
    (0..1), as a render of ``scene`` saved to a 16-bit PNG holds them."""
    colors = np.asarray(colors, dtype=np.float32).reshape(-1, 3)
    count = len(colors)
    width = min(max(count, 1), display_transform.LUT_SIZE**2)
    height = -(-max(count, 1) // width)
    pixels = np.zeros((width * height, 4), dtype=np.float32)
    pixels[:, 3] = 1.0
    pixels[:count, :3] = colors
    scratch = bpy.data.scenes.new(SCRATCH_NAME)
    image = loaded = None
    folder = tempfile.mkdtemp(prefix="solidwire-lut-")
    path = os.path.join(folder, "lut.png")
    try:
        copy_color_management(scene, scratch)
        _png_settings(scratch)
        image = bpy.data.images.new(SCRATCH_NAME, width, height, alpha=True, float_buffer=True)
        # A float image holds scene-linear colours (the default role), as a
        # render does.
        image.pixels.foreach_set(pixels.ravel())
        image.save_render(path, scene=scratch)
        loaded = bpy.data.images.load(path, check_existing=False)
        # The values as stored in the file (not decoded to linear again).
        loaded.colorspace_settings.name = "Non-Color"
        out = np.empty(width * height * 4, dtype=np.float32)
        loaded.pixels.foreach_get(out)
    finally:
        for made in (loaded, image):
            if made is not None:
                bpy.data.images.remove(made)
        bpy.data.scenes.remove(scratch)
        for leftover in (path,):
            if os.path.exists(leftover):
                os.remove(leftover)
        os.rmdir(folder)
    return out.reshape(-1, 4)[:count, :3].astype(np.float64)


def build(scene) -> DisplayLUT:
    """The table of ``scene``'s colour management, made now."""
    exposure = float(getattr(scene.view_settings, "exposure", 0.0))
    n = display_transform.LUT_SIZE
    display = transform_colors(scene, display_transform.grid_colors(exposure))
    return DisplayLUT(settings_key(scene), display.astype(np.float32).reshape(n, n, n, 3), exposure)


# -- the cache ------------------------------------------------------------------------------


def _can_build_now() -> bool:
    """As matcap decoding (blender/matcap_files.py): without an interface,
    in the main thread and not inside a render's GPU context."""
    return (
        bpy.app.background
        and threading.current_thread() is threading.main_thread()
        and not shaders.in_render_engine_context()
    )


def cached(key) -> DisplayLUT | None:
    lut = _cache.get(key)
    if lut is not None:
        _cache.move_to_end(key)
    return lut


def _store(scene_name: str, lut: DisplayLUT) -> DisplayLUT:
    _cache[lut.key] = lut
    _cache.move_to_end(lut.key)
    while len(_cache) > CACHE_SIZE:
        _cache.popitem(last=False)
    _latest[scene_name] = lut
    return lut


def _build_and_store(scene, key) -> DisplayLUT | None:
    try:
        return _store(scene.name, build(scene))
    except Exception as exc:  # noqa: BLE001 - the overlay still draws, scene-linear
        _failed.add(key)
        warn_once(
            ("display lut", type(exc).__name__, str(exc)),
            f"SolidWire: the overlay could not apply the scene's colour management "
            f"({type(exc).__name__}: {one_line(exc)}); it shows scene-linear colours",
        )
        return None


def display_lut(scene, *, request: bool = False) -> DisplayLUT | None:
    """The table of ``scene``'s colour management, or None (draw
    scene-linear). ``request`` (the draw handler): never build here; a table
    not made yet is asked of a timer and the scene's previous one returned."""
    key = settings_key(scene)
    lut = cached(key)
    if lut is not None:
        _latest[scene.name] = lut
        return lut
    if key in _failed:
        return None
    if not request or _can_build_now():
        return _build_and_store(scene, key)
    _request(scene.name)
    return _latest.get(scene.name)


def _request(scene_name: str) -> None:
    if scene_name in _requested:
        return
    _requested.add(scene_name)
    bpy.app.timers.register(_build_requested, first_interval=0.0)


def _build_requested():
    """Timer: build every requested table, then redraw the 3D views."""
    names = sorted(_requested)
    _requested.clear()
    built = False
    for name in names:
        scene = bpy.data.scenes.get(name)
        if scene is None:
            continue
        key = settings_key(scene)
        if cached(key) is None and key not in _failed:
            built = _build_and_store(scene, key) is not None or built
    if built:
        runtime.redraw_viewports()
    # once


def release() -> None:
    """Forget every table (their textures with them) and pending request."""
    if bpy.app.timers.is_registered(_build_requested):
        bpy.app.timers.unregister(_build_requested)
    for lut in _cache.values():
        lut.release()
    _cache.clear()
    _latest.clear()
    _failed.clear()
    _requested.clear()
