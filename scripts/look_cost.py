"""What each fill shading and colour source costs: one scene rendered with
the option off and on, in the same process, warm (meshes cached, shaders
compiled; wall time of a whole render) and the extraction + upload time of
a frame that finds the mesh cache empty (the corner table included).

    .venv/bin/python -m scripts.look_cost [--repeats 5]

Prints a Markdown table (median milliseconds) for the manual (docs/dev/benchmarks.md); the render
column is the deferred surface pass, with the direct one beside it.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time

import bpy

import solidwire_addon
from solidwire_addon.blender import engine, runtime
from solidwire_addon.blender.gpu_context import ensure_gpu
from solidwire_addon.core.options import DrawOptions
from tests.support import scenes

SIZE = (1920, 1080)
BASE = dict(
    use_fill=True,
    fill_shading="FLAT",
    fill_color_source="SINGLE",
    wire_color_source="SINGLE",
    fill_color=(0.8, 0.8, 0.8),
    wire_color=(0.0, 0.0, 0.0, 1.0),
    edge_angle=0.0,
    use_cage_edges=False,
    use_density_fade=False,
    use_boundary_edges=False,
    use_sharp_edges=False,
    use_seam_edges=False,
)
OPTIONS = (
    ("Flat fill (baseline)", {}),
    ("STUDIO shading", dict(fill_shading="STUDIO")),
    ("MATCAP shading", dict(fill_shading="MATCAP", matcap="clay_studio")),
    ("Fill source OBJECT", dict(fill_color_source="OBJECT")),
    ("Fill source MATERIAL", dict(fill_color_source="MATERIAL")),
    ("Fill + wire source RANDOM", dict(fill_color_source="RANDOM", wire_color_source="RANDOM")),
    ("STUDIO + MATERIAL", dict(fill_shading="STUDIO", fill_color_source="MATERIAL")),
    ("Edge angle 10°", dict(edge_angle=0.1745)),
    ("Cage edges (regions of 16 faces)", dict(use_cage_edges=True)),
    ("Density fade", dict(use_density_fade=True, density_fade_length=8.0)),
    ("Cage edges + density fade", dict(use_cage_edges=True, use_density_fade=True, density_fade_length=8.0)),
    ("Edge classes: boundary, sharp, seam", dict(use_boundary_edges=True, use_sharp_edges=True, use_seam_edges=True)),
    (
        "Cage edges + edge classes",
        dict(use_cage_edges=True, use_boundary_edges=True, use_sharp_edges=True, use_seam_edges=True),
    ),
)


def build_scene():
    scene = scenes.empty_scene(*SIZE, transparent=False)
    red = bpy.data.materials.new("Red")
    red.diffuse_color = (0.8, 0.2, 0.1, 1.0)
    for k in range(7):
        suzanne = scenes.monkey(
            scene, f"Suzanne{k}", subdivisions=2, location=(2.6 * (k % 4) - 3.9, 2.5 * (k // 4), 0.0)
        )
        suzanne.data.shade_smooth()
        for edge in suzanne.data.edges[:60]:  # some marked edges for the edge classes
            edge.use_seam = edge.index % 2 == 0
            edge.use_edge_sharp = edge.index % 2 == 1
        suzanne.data.materials.append(red)
        suzanne.color = (0.1 * k, 0.5, 0.8, 1.0)
    scenes.add_camera(scene, location=(0.0, -7.0, 3.0), target=(0.0, 1.5, 0.0), lens=30.0)
    return scene


def apply(scene, settings: dict) -> None:
    for name, value in {**BASE, **settings}.items():
        setattr(scene.solidwire, name, value)


def first_frame_ms(scene, settings: dict) -> float:
    """Extraction + upload of a frame that finds the cache empty (stats)."""
    apply(scene, settings)
    runtime.mesh_cache.clear()
    engine.render_scene(bpy.context.evaluated_depsgraph_get(), SIZE)
    stats = solidwire_addon.stats()
    return stats["ms_extract"] + stats.get("ms_upload", 0.0)


def warm_ms(scene, settings: dict, deferred: bool = True) -> float:
    apply(scene, settings)
    depsgraph = bpy.context.evaluated_depsgraph_get()
    start = time.perf_counter()
    engine.render_scene(depsgraph, SIZE, options=DrawOptions(deferred_surface=deferred))
    return (time.perf_counter() - start) * 1000.0


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args(argv)
    solidwire_addon.register()
    try:
        ensure_gpu()
        scene = build_scene()
        triangles = sum(
            len(o.evaluated_get(bpy.context.evaluated_depsgraph_get()).data.loop_triangles)
            for o in scene.objects
            if o.type == "MESH"
        )
        print(f"{SIZE[0]}x{SIZE[1]}, {triangles} triangles in 7 objects, median of {args.repeats} rounds\n")
        print(
            "| option | render, meshes cached (ms) | vs flat | direct surface pass (ms) | "
            "extract + upload, first frame (ms) |"
        )
        print("|---|---:|---:|---:|---:|")
        for _label, settings in OPTIONS:  # compile every variant, fill the cache
            for deferred in (True, False):
                warm_ms(scene, settings, deferred)
                warm_ms(scene, settings, deferred)
        # Rounds over all options, so a change in machine load hits them alike.
        warm = {label: [] for label, _settings in OPTIONS}
        cold = {label: [] for label, _settings in OPTIONS}
        direct = {label: [] for label, _settings in OPTIONS}
        for _round in range(args.repeats):
            for label, settings in OPTIONS:
                cold[label].append(first_frame_ms(scene, settings))
                warm_ms(scene, settings)
                warm[label].append(warm_ms(scene, settings))
                direct[label].append(warm_ms(scene, settings, deferred=False))
        base = statistics.median(warm[OPTIONS[0][0]])
        for label, _settings in OPTIONS:
            w, c = statistics.median(warm[label]), statistics.median(cold[label])
            d = statistics.median(direct[label])
            print(f"| {label} | {w:.0f} | {w / base:.2f}x | {d:.0f} | {c:.0f} |")
    finally:
        solidwire_addon.unregister()
    return 0


if __name__ == "__main__":
    sys.exit(main())
