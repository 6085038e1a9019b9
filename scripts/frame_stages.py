"""Where one SolidWire F12 frame goes, stage by stage (used by
``scripts.bench_engines``; nothing here ships with the add-on).

A GPU driver runs draws asynchronously, so the time a draw call takes to
return says little. While a :class:`StageProbe` is active, every GPU stage
(each pass's draw calls, the compute set-up) ends with a 1-pixel read of the
bound framebuffer, which waits until the GPU has finished, and every stage's
time is counted without the stages nested in it. The probe wraps the add-on's
own functions from outside and puts them back on exit. The sync points
serialise work that would otherwise overlap, so the stages add up to a little
more than an unprobed frame; the benchmark prints both.
"""

from __future__ import annotations

import functools
import statistics
import time
from collections import defaultdict

import gpu

from solidwire_addon.blender import engine
from solidwire_addon.core import draw as draw_mod
from solidwire_addon.core import passes, silhouettes, targets

# Stage names, in the order a frame runs them.
EXTRACT = "extract / validate the cached meshes"
UPLOAD = "upload"
SETUP = "edge set-up (compute, direct draws)"
DIRECT = "surface pass, drawn directly"
VISIBILITY = "surface pass: visibility stage"
RESOLVE = "surface pass: resolve stage"
HIDDEN = "hidden lines"
WIRE = "wire pass (blended)"
SILHOUETTES = "silhouette outer halves"
READBACK = "readback"
SILHOUETTE_COMPOSITE = "silhouette composite (CPU)"
FILM = "film composite (CPU)"
TRANSFER = "transfer into the result (foreach_set)"
HAND_OVER = "Blender's begin_result / end_result"
OTHER = "the rest (depsgraph, gather, Blender's render set-up)"
ORDER = (EXTRACT, UPLOAD, SETUP, DIRECT, VISIBILITY, RESOLVE, HIDDEN, WIRE, SILHOUETTES, READBACK,
         SILHOUETTE_COMPOSITE, FILM, TRANSFER, HAND_OVER, OTHER)


def _sync() -> None:
    """Wait for the GPU: a read waits for every draw into the framebuffer."""
    framebuffer = gpu.state.active_framebuffer_get()
    framebuffer.read_color(0, 0, 1, 1, 4, 0, "FLOAT")


def _draw_stage(kwargs) -> str:
    stage = kwargs.get("stage")
    if stage == draw_mod.VISIBILITY:
        return VISIBILITY
    if stage == draw_mod.RESOLVE:
        return RESOLVE
    if kwargs.get("hidden_pass"):
        return HIDDEN
    if kwargs.get("depth_write") is False:
        return WIRE
    return DIRECT


class StageProbe:
    """``with StageProbe() as probe: bpy.ops.render.render(...)`` then
    ``probe.frames`` holds one {stage: ms} per frame (call
    :meth:`end_frame` after each render)."""

    def __init__(self):
        self.frames: list[dict] = []
        self._current = defaultdict(float)
        self._stack: list[list[float]] = []  # [start, time of nested stages]
        self._saved = []

    def _timed(self, owner, name: str, label, gpu_work: bool) -> None:
        original = getattr(owner, name)
        self._saved.append((owner, name, original))
        probe = self

        @functools.wraps(original)
        def wrapper(*args, **kwargs):
            stage = label(kwargs) if callable(label) else label
            probe._stack.append([time.perf_counter(), 0.0])
            try:
                result = original(*args, **kwargs)
                if gpu_work:
                    _sync()
                return result
            finally:
                start, nested = probe._stack.pop()
                elapsed = time.perf_counter() - start
                probe._current[stage] += (elapsed - nested) * 1000.0
                if probe._stack:
                    probe._stack[-1][1] += elapsed

        setattr(owner, name, wrapper)

    def __enter__(self):
        self._timed(draw_mod, "_run_setup", SETUP, True)
        self._timed(draw_mod, "draw", _draw_stage, True)
        self._timed(silhouettes, "draw_silhouettes", SILHOUETTES, True)
        self._timed(targets.Targets, "read", READBACK, False)
        self._timed(passes, "_composite_silhouettes", SILHOUETTE_COMPOSITE, False)
        self._timed(engine, "composite_film", FILM, False)
        self._timed(engine, "write_pass", TRANSFER, False)
        self._timed(engine.SolidWireRenderEngine, "_write", HAND_OVER, False)
        return self

    def __exit__(self, *exc):
        for owner, name, original in reversed(self._saved):
            setattr(owner, name, original)
        self._saved.clear()

    def end_frame(self, frame_ms: float, stats: dict) -> None:
        """Close a frame of ``frame_ms`` (the whole F12) with the add-on's
        own counters for extraction and upload."""
        frame = dict(self._current)
        frame[EXTRACT] = stats.get("ms_extract", 0.0)  # upload not included
        if stats.get("ms_upload", 0.0) > 0.0:
            frame[UPLOAD] = stats["ms_upload"]
        frame[OTHER] = frame_ms - sum(frame.values())
        self.frames.append(frame)
        self._current.clear()

    def table(self, unprobed_ms: float) -> list[str]:
        """Markdown rows: median ms per stage and its share of the probed frame."""
        ran = [stage for stage in ORDER if any(stage in f for f in self.frames)]
        medians = {stage: statistics.median(f.get(stage, 0.0) for f in self.frames) for stage in ran}
        total = sum(medians.values())
        lines = ["| stage | ms (median) | share |", "|---|---:|---:|"]
        for stage in ran:
            lines.append(f"| {stage} | {medians[stage]:.1f} | {100.0 * medians[stage] / total:.0f} % |")
        lines.append(f"| **probed frame** (stages synchronised) | {total:.0f} | |")
        lines.append(f"| unprobed frame (median F12 above) | {unprobed_ms:.0f} | |")
        return lines
