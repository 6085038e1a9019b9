"""What each fill shading and colour source costs: one scene rendered with
the option off and on, in the same process, warm (meshes cached, shaders
compiled) and cold (first frame after the cache is emptied: extraction of
the corner table included).

    .venv/bin/python -m scripts.look_cost [--repeats 5]

Prints a Markdown table (median milliseconds) for the README.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time

import bpy

from tests.support import scenes
import solidwire_addon
from solidwire_addon.blender import engine, runtime
from solidwire_addon.blender.gpu_context import ensure_gpu

SIZE = (1280, 720)
BASE = dict(use_fill=True, fill_shading="FLAT", fill_color_source="SINGLE", wire_color_source="SINGLE",
            fill_color=(0.8, 0.8, 0.8), wire_color=(0.0, 0.0, 0.0, 1.0))
OPTIONS = (
    ("Flat fill (baseline)", {}),
    ("STUDIO shading", dict(fill_shading="STUDIO")),
    ("MATCAP shading", dict(fill_shading="MATCAP", matcap="clay_studio")),
    ("Fill source OBJECT", dict(fill_color_source="OBJECT")),
    ("Fill source MATERIAL", dict(fill_color_source="MATERIAL")),
    ("Fill + wire source RANDOM", dict(fill_color_source="RANDOM", wire_color_source="RANDOM")),
    ("STUDIO + MATERIAL (everything)", dict(fill_shading="STUDIO", fill_color_source="MATERIAL")),
)


def build_scene():
    scene = scenes.empty_scene(*SIZE, transparent=False)
    suzanne = scenes.monkey(scene, subdivisions=3)
    suzanne.data.shade_smooth()
    for k in range(6):
        obj = bpy.data.objects.new(f"Suzanne{k}", suzanne.data)
        scene.collection.objects.link(obj)
        obj.location = (2.6 * (k % 3) - 2.6, 2.5 + 2.5 * (k // 3), 0.0)
    scenes.add_camera(scene, location=(0.0, -7.0, 3.0), target=(0.0, 1.5, 0.0), lens=35.0)
    return scene


def measure(scene, settings: dict, repeats: int) -> tuple[float, float]:
    for name, value in {**BASE, **settings}.items():
        setattr(scene.solidwire, name, value)
    depsgraph = bpy.context.evaluated_depsgraph_get()
    runtime.mesh_cache.clear()
    start = time.perf_counter()
    engine.render_scene(depsgraph, SIZE)  # cold: extraction (and shader compile on first use)
    engine.render_scene(depsgraph, SIZE)  # compiled now; still warm-up
    runtime.mesh_cache.clear()
    start = time.perf_counter()
    engine.render_scene(depsgraph, SIZE)
    cold = (time.perf_counter() - start) * 1000.0
    warm = []
    for _ in range(repeats):
        start = time.perf_counter()
        engine.render_scene(depsgraph, SIZE)
        warm.append((time.perf_counter() - start) * 1000.0)
    return cold, statistics.median(warm)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args(argv)
    solidwire_addon.register()
    try:
        ensure_gpu()
        scene = build_scene()
        triangles = sum(len(o.evaluated_get(bpy.context.evaluated_depsgraph_get()).data.loop_triangles)
                        for o in scene.objects if o.type == "MESH")
        print(f"{SIZE[0]}x{SIZE[1]}, {triangles} triangles in 7 objects, median of {args.repeats}\n")
        print("| option | warm render (ms) | vs flat | first frame, meshes extracted (ms) |")
        print("|---|---:|---:|---:|")
        base = None
        for label, settings in OPTIONS:
            cold, warm = measure(scene, settings, args.repeats)
            base = warm if base is None else base
            print(f"| {label} | {warm:.0f} | {warm / base:.2f}x | {cold:.0f} |")
    finally:
        solidwire_addon.unregister()
    return 0


if __name__ == "__main__":
    sys.exit(main())
