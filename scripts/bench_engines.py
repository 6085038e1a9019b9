"""F12 against Blender's own engines: SolidWire vs Workbench flat vs
Workbench wireframe (and Freestyle over Cycles at 1 sample), the whole
``bpy.ops.render.render`` of the same applied mesh and camera, plus the
per-stage breakdown of a SolidWire frame (scripts/frame_stages.py).

    .venv/bin/python -m scripts.bench_engines [--size 1280x720] [--size 3840x2160]
        [--subdivisions 5] [--repeats 3] [--freestyle]

The engines take turns render by render (so load on a shared machine hits
them alike) and ratios come from one run; the first render of each engine is
reported apart (shader compilation, GPU set-up) and left out of the median.
Prints a Markdown table.
"""

from __future__ import annotations

import argparse
import math
import os
import resource
import statistics
import tempfile
import time

os.environ.setdefault("BLENDER_USER_RESOURCES", tempfile.mkdtemp(prefix="solidwire-user-"))

import bpy
import numpy as np

import solidwire_addon
from scripts import frame_stages
from solidwire_addon.blender import runtime
from solidwire_addon.core import schema
from solidwire_addon.core.options import DrawOptions
from tests.support import scenes

# The world colour of Blender's startup file.
FACTORY_WORLD_COLOR = (0.0509, 0.0509, 0.0509)

ENGINES = (
    ("SOLIDWIRE", "SolidWire (default look)"),
    ("SOLIDWIRE_DIRECT", "SolidWire, direct surface pass (before the deferred surface)"),
    ("WORKBENCH_FLAT", "Workbench flat, single colour, no AA"),
    ("WORKBENCH_WIRE", "Workbench wireframe, no AA"),
)


def applied_mesh_scene(width: int, height: int, subdivisions: int):
    """Suzanne subdivided and applied (no modifier left), framed by the camera."""
    # The default look (Studio-lit fill, cage edges), as a plain F12 gets it.
    # An opaque film over the factory world colour, as a new file renders:
    # every engine composites the background.
    scene = scenes.empty_scene(width, height, transparent=False)
    scene.world = bpy.data.worlds.new("World")
    scene.world.color = FACTORY_WORLD_COLOR
    for setting in schema.settings_in("SCENE"):
        if setting.name in scenes.CORE_LOOK:
            setattr(scene.solidwire, setting.name, setting.default)
    obj = scenes.monkey(scene, "Suzanne", subdivisions=subdivisions)
    # Apply the subdivision: every engine then draws the same plain mesh
    # (Workbench would otherwise evaluate it on the GPU, slowly on llvmpipe).
    evaluated = obj.evaluated_get(bpy.context.evaluated_depsgraph_get())
    applied = bpy.data.meshes.new_from_object(evaluated)
    obj.modifiers.clear()
    obj.data = applied
    scenes.frame_object(scene, obj, azimuth=-75.0)
    return scene, obj


def configure(scene, engine: str) -> None:
    """Set ``scene`` up for ``engine``; the SolidWire rows draw with the
    options the render engine reads (runtime.options)."""
    render = scene.render
    runtime.options = DrawOptions(deferred_surface=engine != "SOLIDWIRE_DIRECT")
    if engine.startswith("SOLIDWIRE"):
        render.engine = "SOLIDWIRE"
        return
    render.engine = "BLENDER_WORKBENCH"
    shading = scene.display.shading
    shading.light = "FLAT"
    shading.color_type = "SINGLE"
    scene.display.render_aa = "OFF"
    shading.type = "WIREFRAME" if engine == "WORKBENCH_WIRE" else "SOLID"


def time_render(scene) -> float:
    start = time.perf_counter()
    bpy.ops.render.render(scene=scene.name)
    return time.perf_counter() - start


def touched_mib() -> float:
    """MiB of memory this process has touched for the first time so far
    (minor page faults: a page the kernel had to map on first use)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_minflt * resource.getpagesize() / 2.0**20


def first_touch_ms_per_mib(mib: int = 64) -> float:
    """What touching new memory costs on this machine: ms per MiB of a
    ``mib`` MiB fill the first time in the process, less the same fill
    again (reused memory). Meaningful at the start of a process only."""
    times = []
    for _ in range(2):
        start = time.perf_counter()
        block = np.ones(mib * 2**18, dtype=np.float32)
        times.append((time.perf_counter() - start) * 1000.0)
        del block
    return max(times[0] - times[1], 0.0) / mib


def run(size, subdivisions: int, repeats: int, freestyle: bool) -> list[str]:
    width, height = size
    scene, obj = applied_mesh_scene(width, height, subdivisions)
    triangles = sum(len(p.vertices) - 2 for p in obj.data.polygons)
    engines = list(ENGINES)
    first, times, touched, first_stats = {}, {name: [] for name, _label in engines}, {}, {}
    for turn in range(repeats + 1):
        for name, _label in engines:
            configure(scene, name)
            before = touched_mib()
            seconds = time_render(scene)
            if name == "SOLIDWIRE":
                touched[turn] = touched_mib() - before
                if turn == 0:
                    first_stats = solidwire_addon.stats()
            if turn == 0:
                first[name] = seconds
            else:
                times[name].append(seconds)
    if freestyle:
        scene.render.engine = "CYCLES"
        scene.cycles.samples = 1
        cycles_alone = time_render(scene)
        scenes.enable_freestyle(scene)
        with_freestyle = time_render(scene)
        scenes.enable_freestyle(scene, False)
        engines.append(("FREESTYLE", "Freestyle (Cycles 1 spp + Freestyle - Cycles alone)"))
        times["FREESTYLE"] = [with_freestyle - cycles_alone]
        first["FREESTYLE"] = float("nan")
    base = statistics.median(times["WORKBENCH_FLAT"])
    lines = [
        f"### {width} x {height}, Suzanne subdivided {subdivisions}x and applied ({triangles:,} triangles)",
        "",
        "| engine | steady s (median) | first s | x Workbench flat |",
        "|---|---:|---:|---:|",
    ]
    for name, label in engines:
        median = statistics.median(times[name])
        first_text = "–" if math.isnan(first[name]) else f"{first[name]:.3f}"
        lines.append(f"| {label} | {median:.3f} | {first_text} | {median / base:.2f} |")
    # What any engine pays to draw these triangles at all, in the same run.
    floor_ms, _covered = frame_stages.bare_draw(scene, obj, size, repeats)
    lines.append(
        f"| floor: bare indexed draw of the same triangles (no shading, no readback; "
        f"scripts/frame_stages.bare_draw) | {floor_ms / 1000.0:.3f} | – | {floor_ms / 1000.0 / base:.2f} |"
    )
    steady_touched = statistics.median(touched[turn] for turn in range(1, repeats + 1))
    lines += [
        "",
        (
            f"SolidWire's first render: {first['SOLIDWIRE']:.3f} s against {statistics.median(times['SOLIDWIRE']):.3f} s "
            f"steady; extraction {first_stats.get('ms_extract', 0.0):.0f} ms, upload "
            f"{first_stats.get('ms_upload', 0.0):.0f} ms; {touched[0]:.0f} MiB of memory touched for the first "
            f"time (minor page faults; {steady_touched:.0f} MiB in a steady render)."
        ),
    ]
    lines += [
        "",
        (
            f"SolidWire's steady frame by stage ({repeats} more renders with a sync after each GPU stage; "
            "scripts/frame_stages.py):"
        ),
        "",
    ]
    configure(scene, "SOLIDWIRE")
    with frame_stages.StageProbe() as probe:
        for _ in range(repeats):
            seconds = time_render(scene)
            probe.end_frame(seconds * 1000.0, solidwire_addon.stats())
    lines += probe.table(statistics.median(times["SOLIDWIRE"]) * 1000.0)
    lines.append("")
    return lines


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", action="append", help="WxH (repeatable; default 1280x720)")
    parser.add_argument("--subdivisions", type=int, default=5)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--freestyle", action="store_true")
    args = parser.parse_args()
    cost = first_touch_ms_per_mib()  # before anything else has touched memory
    print(
        f"Touching new memory here costs {cost:.2f} ms per MiB (a 64 MiB fill, first time in the process "
        "against again).\n",
        flush=True,
    )
    solidwire_addon.register()
    try:
        for text in args.size or ["1280x720"]:
            width, height = (int(v) for v in text.lower().split("x"))
            print("\n".join(run((width, height), args.subdivisions, args.repeats, args.freestyle)), flush=True)
    finally:
        solidwire_addon.unregister()


if __name__ == "__main__":
    main()
