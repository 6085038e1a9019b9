"""Process-wide state of the add-on: the GPU mesh cache, what the depsgraph
said changed, and the statistics of the last drawn frame
(``solidwire_addon.stats()``).

Invalidation. Two sources, both holding no Blender data:

* A persistent ``depsgraph_update_post`` handler counts geometry updates per
  session_uid (``geometry_version``); ``frame_change_post``, undo/redo and
  file loads bump a global ``epoch``. The viewport, whose depsgraph lives on
  and reports every edit through that handler before it is drawn, trusts
  these: an unchanged mesh costs one dict lookup.
* Renders compare a content fingerprint per mesh instead (blender/gather.py). A
  render's depsgraph is rebuilt for every frame unless persistent data is on,
  so its pointers and its ``updates`` (everything, on a new depsgraph) say
  nothing about what changed since the previous frame, and
  ``RenderEngine.update`` sees the same new depsgraph. The fingerprint (counts
  plus a CRC of positions and corner vertices, ~8 ms per million triangles
  against ~60 ms to extract) is what lets ``-a`` and ``--frames`` re-extract
  only the objects whose evaluated geometry changed on that frame, whichever
  way Blender built the depsgraph.

A file load (``load_pre``/``load_post``) frees every GPU mesh.
"""

from __future__ import annotations

import contextlib
import time

import bpy
from bpy.app.handlers import persistent

from ..core.cache import MeshCache
from ..core.options import DrawOptions

mesh_cache = MeshCache()
_last_stats: dict = {}

geometry_version: dict[int, int] = {}  # session_uid -> geometry updates seen
epoch = 0  # bumped by frame changes, undo/redo and file loads
# What the entry points Blender calls (the render engine, the overlay's draw
# handler) draw with: they take no arguments of ours, so they read this once
# per frame and hand it down (core/options.py). The shipped defaults;
# benchmarks and tests draw with other options inside ``drawing_with``.
options = DrawOptions()
# Set by the command line while Blender's animation render draws its frames:
# Blender ends an animation render early only when the engine reports an
# error, so when this returns a reason (a stop was asked for) the engine
# reports it instead of drawing the next frame.
render_stop_reason = None  # None, or a callable () -> str | None


def _on_depsgraph_update(_scene, depsgraph) -> None:
    for update in depsgraph.updates:
        if update.is_updated_geometry:
            try:
                uid = update.id.original.session_uid
            except (AttributeError, ReferenceError):
                continue
            geometry_version[uid] = geometry_version.get(uid, 0) + 1


def _on_epoch(*_args) -> None:
    global epoch
    epoch += 1


def _on_load(*_args) -> None:
    """New file: nothing of the old one may be drawn or keep GPU memory."""
    global epoch
    epoch += 1
    mesh_cache.clear()
    geometry_version.clear()


_HANDLERS = (
    ("depsgraph_update_post", _on_depsgraph_update),
    ("frame_change_post", _on_epoch),
    ("undo_post", _on_epoch),
    ("redo_post", _on_epoch),
    ("load_pre", _on_load),
    ("load_post", _on_load),
)
_installed: list = []


def install_handlers() -> None:
    """Add the (persistent) handlers once; :func:`release` removes them."""
    if _installed:
        return
    for name, func in _HANDLERS:
        handler = persistent(func)
        getattr(bpy.app.handlers, name).append(handler)
        _installed.append((name, handler))


def remove_handlers() -> None:
    for name, handler in _installed:
        handlers = getattr(bpy.app.handlers, name)
        if handler in handlers:
            handlers.remove(handler)
    _installed.clear()


@contextlib.contextmanager
def drawing_with(draw_options: DrawOptions):
    """Frames drawn inside (F12, the overlay) use ``draw_options``; the
    previous options come back on exit."""
    global options
    previous, options = options, draw_options
    try:
        yield draw_options
    finally:
        options = previous


def begin_frame(*, reuse: bool = False) -> float:
    """Start counting a frame. Without ``reuse`` the cache starts empty.

    With ``reuse`` every mesh is validated (blender/gather.py): unchanged meshes are
    drawn from the cache, changed ones re-extracted."""
    install_handlers()
    if not reuse:
        mesh_cache.clear()
    mesh_cache.reset_counters()
    return time.perf_counter()


def end_frame(start: float, draw_stats, ms_extract: float, ms_draw: float, seen_keys) -> dict:
    # Free what this frame's depsgraph no longer draws (deleted or hidden
    # objects, replaced meshes); entries of the other depsgraph mode stay.
    mesh_cache.keep_only(seen_keys, scope=getattr(seen_keys, "scope", None))
    _last_stats.clear()
    _last_stats.update(
        objects_drawn=draw_stats.objects_drawn,
        objects_culled=draw_stats.objects_culled + mesh_cache.culled,
        triangles_drawn=draw_stats.triangles_drawn,
        meshes_extracted=mesh_cache.extracted,
        meshes_reused=mesh_cache.reused,
        meshes_repositioned=mesh_cache.repositioned,
        meshes_cached=len(mesh_cache),
        gpu_bytes=mesh_cache.gpu_bytes,
        ms_extract=ms_extract,
        ms_upload=mesh_cache.ms_upload,
        ms_draw=ms_draw,
        ms_total=(time.perf_counter() - start) * 1000.0,
    )
    _last_stats.update(getattr(draw_stats, "extra", None) or {})
    return dict(_last_stats)


def stats() -> dict:
    return dict(_last_stats)


def release() -> None:
    remove_handlers()
    mesh_cache.clear()
    geometry_version.clear()
    _last_stats.clear()


def redraw_viewports(_self=None, _context=None) -> None:
    """Ask every 3D viewport to draw again (a setting changed, a table is
    ready); also the update callback of the settings."""
    wm = getattr(bpy.context, "window_manager", None)
    for window in getattr(wm, "windows", ()):
        for area in window.screen.areas:
            if area.type == "VIEW_3D":
                area.tag_redraw()
