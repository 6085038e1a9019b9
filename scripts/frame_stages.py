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

import bpy
import gpu
import numpy as np
from gpu_extras.batch import batch_for_shader
from mathutils import Matrix

from solidwire_addon.blender import engine
from solidwire_addon.blender.gpu_context import ensure_gpu
from solidwire_addon.blender.views import camera_view
from solidwire_addon.core import draw as draw_mod
from solidwire_addon.core import passes, silhouettes, targets

# Stage names, in the order a frame runs them.
EXTRACT = "extract / validate the cached meshes"
UPLOAD = "upload"
SETUP = "edge set-up (compute, direct draws)"
DIRECT = "surface pass, drawn directly"
VISIBILITY = "surface pass: visibility stage"
REGION_LINES = "region-lines pass"
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
ORDER = (
    EXTRACT,
    UPLOAD,
    SETUP,
    DIRECT,
    VISIBILITY,
    REGION_LINES,
    RESOLVE,
    HIDDEN,
    WIRE,
    SILHOUETTES,
    READBACK,
    SILHOUETTE_COMPOSITE,
    FILM,
    TRANSFER,
    HAND_OVER,
    OTHER,
)


def _sync() -> None:
    """Wait for the GPU: a read waits for every draw into the framebuffer.
    Its depth is read too: the region-lines pass draws into a framebuffer of
    a depth image alone, where a colour read waits for nothing (llvmpipe
    then draws those lines when a later stage reads their image, and the
    probe counted them there)."""
    framebuffer = gpu.state.active_framebuffer_get()
    framebuffer.read_color(0, 0, 1, 1, 4, 0, "FLOAT")
    framebuffer.read_depth(0, 0, 1, 1)


def _draw_stage(kwargs) -> str:
    target = kwargs.get("target") or draw_mod.DrawTarget()
    if target.stage == draw_mod.VISIBILITY:
        return VISIBILITY
    if target.stage == draw_mod.RESOLVE:
        return RESOLVE
    if target.stage == draw_mod.LINES:
        return HIDDEN if target.lines == draw_mod.HIDDEN_LINES else REGION_LINES
    if target.lines == draw_mod.HIDDEN_LINES:
        return HIDDEN
    if not target.depth_write:
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


def bare_draw(scene, obj, size, repeats: int = 5) -> tuple[float, int]:
    """(median ms, pixels covered) of the cheapest draw of ``obj``'s triangles a rasteriser
    can do: one indexed batch of the evaluated mesh's positions with
    Blender's built-in uniform-colour shader (no varying, no shading), depth
    tested into an 8-bit target of the frame's size from the scene camera,
    synchronised by a 1-pixel read. Every engine that draws the mesh pays at
    least this; on a software rasteriser it is the floor of a frame."""
    ensure_gpu()
    depsgraph = bpy.context.evaluated_depsgraph_get()
    mesh = obj.evaluated_get(depsgraph).data
    mesh.calc_loop_triangles()
    positions = np.empty((len(mesh.vertices), 3), dtype=np.float32)
    mesh.vertices.foreach_get("co", positions.reshape(-1))
    triangles = np.empty((len(mesh.loop_triangles), 3), dtype=np.int32)
    mesh.loop_triangles.foreach_get("vertices", triangles.reshape(-1))
    view = camera_view(scene, depsgraph, size)
    object_to_clip = view.projection @ view.view_matrix @ np.array(obj.matrix_world, dtype=np.float64)
    shader = gpu.shader.from_builtin("UNIFORM_COLOR")
    batch = batch_for_shader(shader, "TRIS", {"pos": positions}, indices=triangles)
    offscreen = gpu.types.GPUOffScreen(size[0], size[1], format="RGBA8")
    times = []
    try:
        with offscreen.bind():
            framebuffer = gpu.state.active_framebuffer_get()
            gpu.matrix.load_matrix(Matrix.Identity(4))
            gpu.matrix.load_projection_matrix(Matrix(object_to_clip.tolist()))
            gpu.state.depth_test_set("LESS_EQUAL")
            gpu.state.depth_mask_set(True)
            shader.uniform_float("color", (0.8, 0.8, 0.8, 1.0))
            for turn in range(repeats + 1):
                start = time.perf_counter()
                framebuffer.clear(color=(0.0, 0.0, 0.0, 0.0), depth=1.0)
                batch.draw(shader)
                _sync()
                if turn:  # the first draw compiles
                    times.append((time.perf_counter() - start) * 1000.0)
            depth = np.asarray(framebuffer.read_depth(0, 0, size[0], size[1]).to_list(), dtype=np.float32)
            gpu.state.depth_test_set("NONE")
            gpu.state.depth_mask_set(False)
    finally:
        offscreen.free()
    return statistics.median(times), int((depth < 1.0).sum())
