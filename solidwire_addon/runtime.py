"""Process-wide state of the add-on: the GPU mesh cache and the statistics
of the last drawn frame (``solidwire_addon.stats()``)."""

from __future__ import annotations

import time

from .cache import MeshCache

mesh_cache = MeshCache()
_last_stats: dict = {}


def begin_frame(*, reuse: bool = False) -> float:
    """Start counting a frame. Without ``reuse`` the cache starts empty.

    Reuse across frames is only safe where the caller invalidates keys of
    meshes the depsgraph reports as changed (viewport overlay)."""
    if not reuse:
        mesh_cache.clear()
    mesh_cache.reset_counters()
    return time.perf_counter()


def end_frame(start: float, draw_stats, ms_extract: float, ms_draw: float, seen_keys) -> dict:
    mesh_cache.keep_only(seen_keys)
    _last_stats.clear()
    _last_stats.update(
        objects_drawn=draw_stats.objects_drawn,
        objects_culled=draw_stats.objects_culled,
        triangles_drawn=draw_stats.triangles_drawn,
        meshes_extracted=mesh_cache.extracted,
        meshes_reused=mesh_cache.reused,
        meshes_cached=len(mesh_cache),
        gpu_bytes=mesh_cache.gpu_bytes,
        ms_extract=ms_extract,
        ms_draw=ms_draw,
        ms_total=(time.perf_counter() - start) * 1000.0,
    )
    return dict(_last_stats)


def stats() -> dict:
    return dict(_last_stats)


def release() -> None:
    mesh_cache.clear()
    _last_stats.clear()
