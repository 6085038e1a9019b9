"""Scale benchmark: what SolidWire costs as scenes grow.

Measured in one run, each against the path it replaces:

1. extraction ms per million triangles, Suzanne subdivided to level 5
   (1,007,616 triangles): the fast path (own quad split, bulk attribute
   reads) against the naive path (Blender's ``loop_triangles`` read through
   RNA, same numpy core), best of ``--repeat``;
2. first-frame and steady-state frame time of a 1000-object scene (every
   object its own mesh), with the GPU cache reused vs cleared every frame;
3. the same for 10,000 instances of one mesh (a geometry-nodes scatter of a cube),
   drawn with one draw_instanced call vs one draw call per instance;
4. GPU bytes per triangle (Suzanne level 5, from stats()["gpu_bytes"]);
5. peak memory (RSS) for a ~10-million-triangle scene (run in a fresh
   process so earlier parts do not count);
6. the frame time of a 250-frame animation render (Blender's own
   ``render(animation=True)``, the ``-a`` path) with one deforming object
   among 100 static ones, with reuse vs without;
7. the viewport overlay's redraw cost after one edit (``--part
   interactive`` runs only this): a vertex moved in Edit Mode on Suzanne
   level 5, one of 1000 objects moved, one vertex of one of them moved;
8. a deforming 1M-triangle mesh (only with ``--part animation_1m``, apart
   from the full run: a few minutes):
   Suzanne subdivided to level 5 and applied, bent by a two-bone armature
   and, apart, swollen by a shape key, ``--anim-1m-frames`` frames in the
   add-on's default look (Studio fill, cage edges) at 1280 x 720 (640 x 360
   with ``--quick``, Suzanne level 4): per-frame F12 time of SolidWire,
   of SolidWire re-extracting every frame (the default look's path before
   deformations re-uploaded positions and corner normals alone) and of Workbench (flat light, single colour, no AA, as in
   scripts/bench_engines.py), engines taking turns frame by frame (a noisy
   machine hits them alike; the frame change itself is not timed), median
   of the frames after the first; SolidWire's extract and upload ms and
   meshes extracted / repositioned per frame.

Frame times are the wall time of ``bpy.ops.render.render`` (Blender's
depsgraph evaluation included) and SolidWire's own share (stats
``ms_total``). The GPU here may be a software rasteriser (Mesa llvmpipe):
the table says which renderer ran, and draw times mean CPU time then.

    python -m scripts.bench_scale [--quick] [--out out/bench_scale.md]
        [--part memory|interactive|animation_1m] [--anim-1m-frames 8]

Prints a Markdown table and writes it (plus a .json) under out/.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
os.environ.setdefault("BLENDER_USER_RESOURCES", tempfile.mkdtemp(prefix="solidwire-bench-"))

import bpy
import numpy as np

import solidwire_addon
from solidwire_addon.blender import mesh_reading, runtime
from solidwire_addon.blender.gpu_context import ensure_gpu
from solidwire_addon.core import draw, extract
from solidwire_addon.core.options import DrawOptions
from tests.support import scenes


def rss_mib() -> float:
    """Peak resident set size of this process so far, MiB (Linux: KiB)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def renderer() -> str:
    import gpu

    try:
        return f"{gpu.platform.renderer_get()} ({gpu.platform.backend_type_get()})"
    except Exception:  # noqa: BLE001 - informational only
        return "unknown"


def render_once(scene) -> tuple[float, dict]:
    start = time.perf_counter()
    bpy.ops.render.render(scene=scene.name)
    return (time.perf_counter() - start) * 1000.0, solidwire_addon.stats()


def frames(scene, count: int) -> dict:
    """First frame and the median of ``count - 1`` more, wall and SolidWire ms."""
    first_wall, first = render_once(scene)
    rest = [render_once(scene) for _ in range(max(count - 1, 1))]
    return {
        "first_wall_ms": first_wall,
        "first_sw_ms": first["ms_total"],
        "first_extract_ms": first["ms_extract"] + first.get("ms_upload", 0.0),
        "steady_wall_ms": statistics.median(w for w, _ in rest),
        "steady_sw_ms": statistics.median(s["ms_total"] for _, s in rest),
        "steady_extract_ms": statistics.median(s["ms_extract"] + s.get("ms_upload", 0.0) for _, s in rest),
        "steady_draw_ms": statistics.median(s["ms_draw"] for _, s in rest),
        "meshes_extracted_steady": rest[-1][1]["meshes_extracted"],
        "objects_drawn": rest[-1][1]["objects_drawn"],
        "objects_culled": rest[-1][1]["objects_culled"],
        "instanced_draws": rest[-1][1].get("instanced_draws", 0),
        "triangles_drawn": rest[-1][1]["triangles_drawn"],
    }


# --------------------------------------------------------------------------
# 1 + 4: extraction speed and GPU bytes per triangle


def bench_extraction(level: int, repeat: int) -> dict:
    scene = scenes.empty_scene(320, 240)
    scenes.add_camera(scene, location=(0.0, -4.0, 0.5), target=(0.0, 0.0, 0.0))
    obj = scenes.monkey(scene, subdivisions=level)
    mesh = obj.evaluated_get(bpy.context.evaluated_depsgraph_get()).data
    tris = len(mesh.loop_triangles)

    def best(func) -> float:
        times = []
        for _ in range(repeat):
            start = time.perf_counter()
            func()
            times.append(time.perf_counter() - start)
        return min(times) * 1000.0

    fast = best(lambda: mesh_reading.extract_mesh(mesh))
    naive = best(lambda: mesh_reading.extract_mesh_naive(mesh))
    raw = mesh_reading.read_mesh(mesh)
    core = best(lambda: extract.build_arrays(**raw))
    fast_core_input = mesh_reading.read_mesh_fast(mesh)
    fast_core = best(lambda: extract.build_arrays_fast(**fast_core_input))
    _wall, stats = render_once(scene)
    per_m = 1.0e6 / tris
    return {
        "triangles": tris,
        "fast_ms": fast,
        "naive_ms": naive,
        "fast_ms_per_mtri": fast * per_m,
        "naive_ms_per_mtri": naive * per_m,
        "build_arrays_ms": core,
        "build_arrays_fast_ms": fast_core,
        "gpu_bytes": stats["gpu_bytes"],
        "gpu_bytes_per_triangle": stats["gpu_bytes"] / tris,
        "upload_ms": stats.get("ms_upload", float("nan")),
    }


# --------------------------------------------------------------------------
# 2: many objects


def many_objects_scene(count: int):
    scene = scenes.empty_scene(640, 360)
    side = int(np.ceil(np.sqrt(count)))
    # The whole grid in view (nothing culled): the frame draws all of it.
    scenes.add_camera(scene, location=(0.0, -2.6 * side, 2.4 * side), target=(0.0, 0.0, 0.0), clip=(0.1, 1.0e4))
    template = scenes.monkey(scene, "Template")
    for i in range(count - 1):
        obj = bpy.data.objects.new(f"Obj{i}", template.data.copy())  # its own mesh each
        scene.collection.objects.link(obj)
        obj.location = (2.5 * (i % side) - 1.25 * side, 2.5 * (i // side) - 1.25 * side, 0.0)
    return scene


def bench_many_objects(count: int, frame_count: int) -> dict:
    scene = many_objects_scene(count)
    out = {}
    for reuse in (True, False):
        runtime.mesh_cache.clear()
        with runtime.drawing_with(DrawOptions(reuse_meshes=reuse)):
            out["reuse" if reuse else "no_reuse"] = frames(scene, frame_count)
    return out


# --------------------------------------------------------------------------
# 3: many instances of one mesh


def instances_scene(count: int, *, tiny: bool = False):
    # A small image: llvmpipe's rasterisation (the same work either way) would
    # otherwise hide the per-instance CPU cost that instancing saves. ``tiny``
    # goes further (one triangle per instance, 64 x 36 pixels) so the frame is
    # almost only the cost of submitting the draws.
    scene = scenes.empty_scene(64, 36) if tiny else scenes.empty_scene(160, 90)
    side = int(np.ceil(np.sqrt(count)))
    scenes.add_camera(scene, location=(0.0, -3.0 * side, 2.8 * side), target=(0.0, 0.0, 0.0), clip=(0.1, 1.0e4))
    # A small mesh (a cube, 12 triangles): the per-instance CPU cost is what
    # instancing saves; a heavy mesh would only measure llvmpipe's raster.
    if tiny:
        scatter = scenes.from_pydata(scene, "Scatter", [(-1, 0, 0), (1, 0, 0), (0, 1, 0)], [(0, 1, 2)])
    else:
        scatter = scenes.cube(scene, "Scatter")
    tree = bpy.data.node_groups.new("scatter", "GeometryNodeTree")
    tree.interface.new_socket("Geometry", in_out="INPUT", socket_type="NodeSocketGeometry")
    tree.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
    group_in, group_out = tree.nodes.new("NodeGroupInput"), tree.nodes.new("NodeGroupOutput")
    grid = tree.nodes.new("GeometryNodeMeshGrid")
    grid.inputs["Vertices X"].default_value = side
    grid.inputs["Vertices Y"].default_value = count // side
    grid.inputs["Size X"].default_value = grid.inputs["Size Y"].default_value = 2.5 * side
    on_points = tree.nodes.new("GeometryNodeInstanceOnPoints")
    tree.links.new(grid.outputs[0], on_points.inputs["Points"])
    tree.links.new(group_in.outputs[0], on_points.inputs["Instance"])
    tree.links.new(on_points.outputs[0], group_out.inputs[0])
    scatter.modifiers.new("Scatter", "NODES").node_group = tree
    return scene


def bench_instances(count: int, frame_count: int, *, tiny: bool = False) -> dict:
    scene = instances_scene(count, tiny=tiny)
    out = {}
    saved = draw.INSTANCING_MIN
    for mode, minimum in (("instanced", saved), ("per_instance", 10**9)):
        draw.INSTANCING_MIN = minimum
        render_once(scene)  # compile this mode's shader variant outside the timings
        runtime.mesh_cache.clear()
        out[mode] = frames(scene, frame_count)
    draw.INSTANCING_MIN = saved
    return out


# --------------------------------------------------------------------------
# 5: peak memory (own process)


def bench_memory(objects: int, level: int) -> dict:
    ensure_gpu()
    scene = scenes.empty_scene(320, 240)
    scenes.add_camera(scene, location=(0.0, -5.0 * objects, 2.5 * objects), target=(0.0, 0.0, 0.0), clip=(0.1, 1.0e4))
    for i in range(objects):
        scenes.monkey(scene, f"Heavy{i}", subdivisions=level, location=(3.0 * i - 1.5 * objects, 0.0, 0.0))
    bpy.context.evaluated_depsgraph_get()
    before = rss_mib()
    wall, stats = render_once(scene)
    wall2, stats2 = render_once(scene)
    return {
        "triangles": stats["triangles_drawn"],
        "rss_before_render_mib": before,
        "rss_peak_mib": rss_mib(),
        "first_wall_ms": wall,
        "second_wall_ms": wall2,
        "first_extract_ms": stats["ms_extract"],
        "first_upload_ms": stats.get("ms_upload", float("nan")),
        "second_meshes_extracted": stats2["meshes_extracted"],
        "gpu_bytes": stats["gpu_bytes"],
    }


# --------------------------------------------------------------------------
# 6: animation


def animation_scene(static: int, frame_end: int, directory: str):
    scene = scenes.empty_scene(320, 240)
    side = int(np.ceil(np.sqrt(static)))
    scenes.add_camera(scene, location=(0.0, -3.2 * side, 3.0 * side), target=(0.0, 0.0, 0.0), clip=(0.1, 1.0e4))
    template = scenes.monkey(scene, "Static", subdivisions=1)
    template.location = (-1.25 * side, -1.25 * side, 0.0)
    for i in range(static - 1):
        obj = bpy.data.objects.new(f"Static{i}", template.data.copy())
        scene.collection.objects.link(obj)
        obj.location = (2.5 * ((i + 1) % side) - 1.25 * side, 2.5 * ((i + 1) // side) - 1.25 * side, 0.0)
    mover = scenes.monkey(scene, "Deforming", subdivisions=1, location=(0.0, 0.0, 2.0))
    mover.modifiers.new("Wave", "WAVE").height = 0.3  # time-dependent deformation
    scene.frame_start, scene.frame_end = 1, frame_end
    scene.render.filepath = os.path.join(directory, "frame_####")
    scene.render.image_settings.file_format = "PNG"
    return scene


def bench_animation(static: int, frame_end: int) -> dict:
    out = {}
    with tempfile.TemporaryDirectory(prefix="solidwire-anim-") as directory:
        scene = animation_scene(static, frame_end, directory)
        per_frame: list[dict] = []

        def record(_scene, *_args):
            per_frame.append(solidwire_addon.stats())

        bpy.app.handlers.render_post.append(record)
        try:
            for reuse in (True, False):
                runtime.mesh_cache.clear()
                per_frame.clear()
                start = time.perf_counter()
                with runtime.drawing_with(DrawOptions(reuse_meshes=reuse)):
                    bpy.ops.render.render(animation=True, scene=scene.name)
                wall = (time.perf_counter() - start) * 1000.0
                later = per_frame[1:] or per_frame
                out["reuse" if reuse else "no_reuse"] = {
                    "frames": len(per_frame),
                    "wall_ms_per_frame": wall / max(len(per_frame), 1),
                    "sw_ms_per_frame": statistics.mean(s["ms_total"] for s in later),
                    "extract_ms_per_frame": statistics.mean(s["ms_extract"] + s.get("ms_upload", 0.0) for s in later),
                    "meshes_extracted_per_frame": statistics.mean(s["meshes_extracted"] for s in later),
                }
        finally:
            bpy.app.handlers.render_post.remove(record)
    return out


# --------------------------------------------------------------------------
# 8: a deforming 1M-triangle mesh against Workbench, frame by frame

# (engine, cache emptied before each frame, label). The baseline empties the
# cache (a full extraction) rather than switching reposition off: with the
# engines taking turns, the frame's first SolidWire render has already
# uploaded it, and a switched-off reposition would find nothing changed.
ANIMATION_1M_RUNS = (
    ("SOLIDWIRE", False, "SolidWire (positions and corner normals re-uploaded)"),
    ("SOLIDWIRE", True, "SolidWire, full re-extraction every frame (baseline)"),
    ("WORKBENCH_FLAT", False, "Workbench flat, single colour, no AA"),
)


def deforming_1m_scene(kind: str, level: int, size: tuple, frame_count: int):
    """Suzanne subdivided ``level`` times and applied (the same mesh as
    scripts/bench_engines.py), in the default look, deformed by ``kind``
    ("armature" or "shape_key") from frame 1 to ``frame_count``."""
    from scripts.bench_engines import applied_mesh_scene

    scene, obj = applied_mesh_scene(*size, level)
    scenes.default_look(scene)
    frames = (1, frame_count)
    if kind == "armature":
        scenes.add_bend_rig(scene, obj, frames, joint_z=0.0, blend=0.4, angle_deg=35.0)
    else:
        scenes.add_swell_shape_key(obj, frames, strength=0.5)
    scene.frame_start, scene.frame_end = frames
    return scene, obj


def bench_animation_1m(level: int, size: tuple, frame_count: int) -> dict:
    from scripts.bench_engines import configure

    out = {}
    for kind in ("armature", "shape_key"):
        scene, obj = deforming_1m_scene(kind, level, size, frame_count)
        triangles = sum(len(p.vertices) - 2 for p in obj.data.polygons)
        runtime.mesh_cache.clear()
        samples = {label: [] for _engine, _reuse, label in ANIMATION_1M_RUNS}
        for frame in range(1, frame_count + 1):
            scene.frame_set(frame)
            for engine, fresh, label in ANIMATION_1M_RUNS:
                configure(scene, engine)
                if fresh:
                    runtime.mesh_cache.clear()
                wall, stats = render_once(scene)
                samples[label].append((wall, stats if engine == "SOLIDWIRE" else None))
        result = {"triangles": triangles, "frames": frame_count}
        for engine, _allow, label in ANIMATION_1M_RUNS:
            later = samples[label][1:]
            row = {"first_ms": samples[label][0][0], "ms_per_frame": statistics.median(w for w, _ in later)}
            if engine == "SOLIDWIRE":
                for key in (
                    "ms_extract",
                    "ms_upload",
                    "ms_draw",
                    "ms_total",
                    "meshes_extracted",
                    "meshes_repositioned",
                ):
                    row[key] = statistics.median(s.get(key, 0.0) for _, s in later)
            result[label] = row
        out[kind] = result
    return out


def animation_1m_table(r: dict, size: tuple) -> str:
    lines = [
        (
            f"| deforming mesh, {size[0]} x {size[1]} | per frame ms (median) | first frame ms | x Workbench | extract ms "
            "| upload ms | draw ms | meshes extracted / repositioned per frame |"
        ),
        "|---|---:|---:|---:|---:|---:|---:|---|",
    ]
    for kind, result in r.items():
        base = result[ANIMATION_1M_RUNS[-1][2]]["ms_per_frame"]
        what = f"{kind.replace('_', ' ')}, {result['triangles']:,} tris, {result['frames']} frames"
        for engine, _allow, label in ANIMATION_1M_RUNS:
            row = result[label]
            solidwire = engine == "SOLIDWIRE"
            cells = (
                (
                    f"{row['ms_extract']:.0f} | {row['ms_upload']:.0f} | {row['ms_draw']:.0f} | "
                    f"{row['meshes_extracted']:.0f} / {row['meshes_repositioned']:.0f}"
                )
                if solidwire
                else " | | | "
            )
            lines.append(
                f"| {what}: {label} | {row['ms_per_frame']:.0f} | {row['first_ms']:.0f} | "
                f"{row['ms_per_frame'] / base:.2f} | {cells} |"
            )
    return "\n".join(lines) + "\n"


# --------------------------------------------------------------------------
# 7: interactive cost of the viewport overlay (edits between redraws)


class _Viewport:
    """An offscreen stand-in for a 3D viewport's overlay framebuffer."""

    def __init__(self, width: int, height: int):
        import gpu

        self.size = (width, height)
        self.color = gpu.types.GPUTexture(self.size, format="SRGB8_A8")
        self.depth = gpu.types.GPUTexture(self.size, format="DEPTH32F_STENCIL8")
        self.framebuffer = gpu.types.GPUFrameBuffer(depth_slot=self.depth, color_slots=(self.color,))

    def redraw(self, scene, plan) -> dict:
        """One overlay redraw as the draw handler does it (depsgraph
        evaluation, gather, draw), waited for; ms of each part."""
        import gpu

        from solidwire_addon.blender import overlay
        from solidwire_addon.blender.views import camera_view

        start = time.perf_counter()
        depsgraph = bpy.context.evaluated_depsgraph_get()
        ms_depsgraph = (time.perf_counter() - start) * 1000.0
        view = camera_view(scene, depsgraph, self.size)
        with self.framebuffer.bind():
            self.framebuffer.clear(color=(0.0, 0.0, 0.0, 0.0), depth=1.0)
            gpu.state.viewport_set(0, 0, *self.size)
            stats = overlay.draw_scene_overlay(
                depsgraph,
                view,
                scene.solidwire.snapshot(),
                object_filter=overlay.object_filter(plan, bpy.context.view_layer),
                plan=plan,
            )
            self.framebuffer.read_color(0, 0, 1, 1, 4, 0, "UBYTE")  # wait for the GPU
        stats["ms_redraw"] = (time.perf_counter() - start) * 1000.0
        stats["ms_depsgraph"] = ms_depsgraph
        return stats


def _median_stats(samples: list) -> dict:
    keys = (
        "ms_redraw",
        "ms_depsgraph",
        "ms_extract",
        "ms_upload",
        "ms_draw",
        "meshes_extracted",
        "meshes_repositioned",
        "triangles_drawn",
    )
    return {key: statistics.median(s[key] for s in samples) for key in keys}


def bench_interactive(level: int, objects: int, edits: int) -> dict:
    """Redraw cost after one edit: a vertex moved in Edit Mode on a 1M-triangle
    mesh, one of ``objects`` objects moved, one of them edited. Each against
    a redraw with nothing changed."""
    import bmesh

    from solidwire_addon.core import overlay_state

    plan = overlay_state.plan_overlay(overlay_state.ViewportState(draw_edit_mode=True))
    viewport = _Viewport(640, 360)
    out = {}

    scene = scenes.empty_scene(640, 360)
    scenes.add_camera(scene, location=(0.0, -4.0, 0.5), target=(0.0, 0.0, 0.0))
    obj = scenes.monkey(scene, subdivisions=level)
    runtime.mesh_cache.clear()
    viewport.redraw(scene, plan)
    out["big_steady"] = _median_stats([viewport.redraw(scene, plan) for _ in range(edits)])
    bpy.context.view_layer.objects.active = obj
    obj.select_set(True)
    bpy.ops.object.mode_set(mode="EDIT")
    viewport.redraw(scene, plan)
    bm = bmesh.from_edit_mesh(obj.data)
    bm.verts.ensure_lookup_table()
    for name, allow in (("big_edit_vertex", True), ("big_edit_vertex_full", False)):
        samples = []
        with runtime.drawing_with(DrawOptions(reposition_meshes=allow)):
            for i in range(edits):
                bm.verts[i].co.z += 0.01
                bmesh.update_edit_mesh(obj.data)
                samples.append(viewport.redraw(scene, plan))
        out[name] = _median_stats(samples)
    bpy.ops.object.mode_set(mode="OBJECT")

    scene = many_objects_scene(objects)
    runtime.mesh_cache.clear()
    viewport.redraw(scene, plan)
    out["objects_steady"] = _median_stats([viewport.redraw(scene, plan) for _ in range(edits)])
    moved = bpy.data.objects["Obj0"]
    samples = []
    for _ in range(edits):
        moved.location.z += 0.1
        samples.append(viewport.redraw(scene, plan))
    out["objects_move_one"] = _median_stats(samples)
    for name, allow in (("objects_edit_one", True), ("objects_edit_one_full", False)):
        samples = []
        with runtime.drawing_with(DrawOptions(reposition_meshes=allow)):
            for i in range(edits):
                moved.data.vertices[i].co.z += 0.01
                moved.data.update()
                samples.append(viewport.redraw(scene, plan))
        out[name] = _median_stats(samples)
    out["big_triangles"] = out["big_steady"]["triangles_drawn"]
    return out


def interactive_table(r: dict, args) -> str:
    def row(name, s):
        return (
            f"| {name} | {s['ms_redraw']:.0f} | {s['ms_depsgraph']:.0f} | {s['ms_extract']:.0f} | "
            f"{s['ms_upload']:.1f} | {s['ms_draw']:.0f} | {s['meshes_extracted']:.0f} | {s['meshes_repositioned']:.0f} |"
        )

    big = f"Suzanne L{args.level} ({r['big_triangles']:,.0f} tris) in Edit Mode"
    lines = [
        (
            "| overlay redraw, 640 x 360 (median) | total ms | depsgraph ms | extract ms | upload ms | draw ms "
            "| meshes re-extracted | positions re-uploaded |"
        ),
        "|---|---|---|---|---|---|---|---|",
        row(f"{big}: nothing changed", r["big_steady"]),
        row(f"{big}: one vertex moved", r["big_edit_vertex"]),
        row(f"{big}: one vertex moved, full re-extraction (baseline)", r["big_edit_vertex_full"]),
        row(f"{args.objects} objects: nothing changed", r["objects_steady"]),
        row(f"{args.objects} objects: one object moved", r["objects_move_one"]),
        row(f"{args.objects} objects: one vertex of one object moved", r["objects_edit_one"]),
        row(f"{args.objects} objects: one vertex moved, full re-extraction (baseline)", r["objects_edit_one_full"]),
    ]
    return "\n".join(lines) + "\n"


def table(results: dict, args) -> str:
    e = results["extraction"]
    o = results["objects"]
    i = results["instances"]
    t = results["instances_tiny"]
    m = results["memory"]
    a = results["animation"]
    rows = [
        (
            f"Extraction, Suzanne L{args.level} ({e['triangles']:,} tris), ms per M tris",
            f"{e['fast_ms_per_mtri']:.0f}",
            f"{e['naive_ms_per_mtri']:.0f} (loop_triangles)",
        ),
        ("GPU bytes per triangle", f"{e['gpu_bytes_per_triangle']:.1f}", ""),
        (
            f"{args.objects} objects (own mesh each, {o['reuse']['triangles_drawn']:,} tris drawn): first frame, ms (SolidWire share)",
            f"{o['reuse']['first_wall_ms']:.0f} ({o['reuse']['first_sw_ms']:.0f})",
            f"{o['no_reuse']['first_wall_ms']:.0f} ({o['no_reuse']['first_sw_ms']:.0f}) (no reuse)",
        ),
        (
            f"{args.objects} objects: steady frame, ms (SolidWire share)",
            f"{o['reuse']['steady_wall_ms']:.0f} ({o['reuse']['steady_sw_ms']:.0f})",
            f"{o['no_reuse']['steady_wall_ms']:.0f} ({o['no_reuse']['steady_sw_ms']:.0f}) (no reuse)",
        ),
        (
            f"{args.objects} objects: steady extraction+upload, ms",
            f"{o['reuse']['steady_extract_ms']:.1f}",
            f"{o['no_reuse']['steady_extract_ms']:.1f} (no reuse)",
        ),
        (
            f"{args.instances:,} instances of one mesh ({i['instanced']['objects_drawn']:,} drawn): first frame, ms (SolidWire share)",
            f"{i['instanced']['first_wall_ms']:.0f} ({i['instanced']['first_sw_ms']:.0f})",
            f"{i['per_instance']['first_wall_ms']:.0f} ({i['per_instance']['first_sw_ms']:.0f}) (draw per instance)",
        ),
        (
            f"{args.instances:,} instances: steady frame, ms (SolidWire share)",
            f"{i['instanced']['steady_wall_ms']:.0f} ({i['instanced']['steady_sw_ms']:.0f})",
            f"{i['per_instance']['steady_wall_ms']:.0f} ({i['per_instance']['steady_sw_ms']:.0f}) (draw per instance)",
        ),
        (
            f"{args.instances:,} instances: draw call time, ms",
            f"{i['instanced']['steady_draw_ms']:.0f}",
            f"{i['per_instance']['steady_draw_ms']:.0f} (draw per instance)",
        ),
        (
            f"{args.instances:,} one-triangle instances, 64 x 36 px: steady frame / draw, ms",
            f"{t['instanced']['steady_sw_ms']:.0f} / {t['instanced']['steady_draw_ms']:.0f}",
            f"{t['per_instance']['steady_sw_ms']:.0f} / {t['per_instance']['steady_draw_ms']:.0f} (draw per instance)",
        ),
        (
            f"Peak RSS, {m['triangles'] / 1e6:.1f}M-triangle scene, MiB",
            f"{m['rss_peak_mib']:.0f}",
            f"{m['rss_before_render_mib']:.0f} before the first render",
        ),
        (
            f"Animation, {a['reuse']['frames']} frames, 1 deforming + {args.static} static: ms per frame (SolidWire share)",
            f"{a['reuse']['wall_ms_per_frame']:.0f} ({a['reuse']['sw_ms_per_frame']:.0f})",
            f"{a['no_reuse']['wall_ms_per_frame']:.0f} ({a['no_reuse']['sw_ms_per_frame']:.0f}) (no reuse)",
        ),
        (
            "Animation: meshes extracted per frame (after the first)",
            f"{a['reuse']['meshes_extracted_per_frame']:.1f}",
            f"{a['no_reuse']['meshes_extracted_per_frame']:.1f} (no reuse)",
        ),
    ]
    lines = [
        f"Machine: {platform.processor() or platform.machine()}, {os.cpu_count()} CPU cores, "
        f"renderer {results['renderer']}; bpy {bpy.app.version_string}." + (" --quick sizes." if args.quick else ""),
        "",
        "| measure | SolidWire | baseline |",
        "|---|---|---|",
    ]
    lines += [f"| {name} | {ours} | {base} |" for name, ours, base in rows]
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="small sizes (a minute or so)")
    parser.add_argument("--out", default=str(ROOT / "out" / "bench_scale.md"))
    parser.add_argument(
        "--part",
        choices=["memory", "interactive", "animation_1m"],
        help="run one part only (interactive: overlay redraw cost after an edit; "
        "animation_1m: a deforming 1M-triangle mesh against Workbench)",
    )
    parser.add_argument("--anim-1m-frames", type=int, default=8, help="frames of --part animation_1m")
    args = parser.parse_args(argv)
    args.level = 4 if args.quick else 5
    args.repeat = 3 if args.quick else 5
    args.objects = 200 if args.quick else 1000
    args.instances = 2000 if args.quick else 10000
    args.frames = 4 if args.quick else 6
    args.static = 100
    args.edits = 3 if args.quick else 5
    args.anim_frames = 20 if args.quick else 250
    args.memory_objects, args.memory_level = (2, 5) if args.quick else (10, 5)

    solidwire_addon.register()
    if args.part == "memory":
        print(json.dumps(bench_memory(args.memory_objects, args.memory_level)), flush=True)
        os._exit(0)  # skip Blender's teardown: only the numbers matter here

    ensure_gpu()
    results = {"renderer": renderer()}
    if args.part == "interactive":
        results["interactive"] = bench_interactive(args.level, args.objects, args.edits)
        text = f"Renderer {results['renderer']}; bpy {bpy.app.version_string}.\n\n" + interactive_table(
            results["interactive"], args
        )
        print(text, flush=True)
        out = Path(args.out).with_name("bench_interactive.md")
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text(text, encoding="utf-8")
        os._exit(0)
    if args.part == "animation_1m":
        size = (640, 360) if args.quick else (1280, 720)
        results["animation_1m"] = bench_animation_1m(args.level, size, max(args.anim_1m_frames, 2))
        text = (
            f"Renderer {results['renderer']}; {platform.machine()}, {os.cpu_count()} CPU cores; "
            f"bpy {bpy.app.version_string}.\n\n" + animation_1m_table(results["animation_1m"], size)
        )
        print(text, flush=True)
        out = Path(args.out).with_name("bench_animation_1m.md")
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text(text, encoding="utf-8")
        out.with_suffix(".json").write_text(json.dumps(results, indent=2), encoding="utf-8")
        os._exit(0)
    print("extraction ...", file=sys.stderr)
    results["extraction"] = bench_extraction(args.level, args.repeat)
    print(f"{args.objects} objects ...", file=sys.stderr)
    results["objects"] = bench_many_objects(args.objects, args.frames)
    print(f"{args.instances} instances ...", file=sys.stderr)
    results["instances"] = bench_instances(args.instances, args.frames)
    results["instances_tiny"] = bench_instances(args.instances, args.frames, tiny=True)
    print(f"animation, {args.anim_frames} frames ...", file=sys.stderr)
    results["animation"] = bench_animation(args.static, args.anim_frames)
    print("memory (own process) ...", file=sys.stderr)
    child = subprocess.run(
        [sys.executable, __file__, "--part", "memory"] + (["--quick"] if args.quick else []),
        capture_output=True,
        text=True,
        check=False,
    )
    lines = [line for line in child.stdout.splitlines() if line.startswith("{")]
    if not lines:
        raise RuntimeError(f"memory part failed ({child.returncode}): {child.stderr[-2000:]}")
    results["memory"] = json.loads(lines[-1])
    print("interactive ...", file=sys.stderr)
    results["interactive"] = bench_interactive(args.level, args.objects, args.edits)

    text = table(results, args) + "\n" + interactive_table(results["interactive"], args)
    print(text)
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(text, encoding="utf-8")
    out.with_suffix(".json").write_text(json.dumps(results, indent=2), encoding="utf-8")
    sys.stdout.flush()
    os._exit(0)  # Blender's teardown after heavy GPU use can crash; the results are written


if __name__ == "__main__":
    sys.exit(main())
