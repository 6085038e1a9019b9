"""What a redraw after an edit costs under the angle threshold: the viewport
overlay redrawn after one vertex moved, after a light sculpt-like stroke
(1 % of the vertices) and after a move that takes edges across the angle, with the incremental edge angle check (a move that
keeps every edge on its side of the angle repositions the mesh) against a
full extraction of the edited mesh (the behaviour before the check; the
DrawOptions.reposition_meshes off).

    .venv/bin/python -m scripts.bench_angle_edits [--size 1280x720] [--repeats 5]

Rounds alternate between the two ways in one process, so that a change in
machine load hits both alike; the table gives the median of each: the whole
redraw, and the mesh's own part of it (extraction, or check and position
upload; the frame's ms_extract + ms_upload).
"""

from __future__ import annotations

import argparse
import math
import sys

import numpy as np

import solidwire_addon
from scripts.bench_regions import Viewport, apply, apply_subdivision, build_scene
from solidwire_addon.blender import mesh_reading, runtime
from solidwire_addon.blender.gpu_context import ensure_gpu
from solidwire_addon.core.options import DrawOptions


def one_vertex(mesh, step: int) -> None:
    vertex = mesh.vertices[(7919 * step) % len(mesh.vertices)]
    vertex.co.z += 2e-4 * (1 if step % 2 else -1)
    mesh.update()


def across(mesh, step: int) -> None:
    """One vertex pulled far enough to move edges across the angle: the
    incremental check finds it and the mesh is extracted again (what the
    check costs when it cannot help)."""
    vertex = mesh.vertices[(7919 * step) % len(mesh.vertices)]
    vertex.co.z += 0.05 * (1 if step % 2 else -1)
    mesh.update()


def stroke(mesh, step: int) -> None:
    """The 1 % of vertices nearest a vertex, pushed along their direction
    from the origin with a smooth falloff (a light brush stroke)."""
    positions = mesh_reading.read_positions(mesh).astype(np.float64)
    centre = positions[(7919 * step) % len(positions)]
    distance = np.linalg.norm(positions - centre, axis=1)
    ids = np.argsort(distance)[: max(1, len(positions) // 100)]
    falloff = (1.0 - (distance[ids] / max(distance[ids].max(), 1e-9)) ** 2) ** 2
    direction = positions[ids] / np.maximum(np.linalg.norm(positions[ids], axis=1, keepdims=True), 1e-9)
    positions[ids] += (2e-4 if step % 2 else -2e-4) * falloff[:, None] * direction
    mesh.vertices.foreach_set("co", positions.astype(np.float32).ravel())
    mesh.update()


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", default="1280x720")
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args(argv)
    size = tuple(int(v) for v in args.size.split("x"))
    solidwire_addon.register()
    try:
        ensure_gpu()
        viewport = Viewport(size)
        scene, monkey = build_scene(size, 2)
        modifier = monkey.modifiers[0]
        modifier.show_viewport = modifier.show_render = False
        apply_subdivision(monkey, 3)
        apply(scene, dict(edge_angle=math.radians(20.0)))
        mesh = monkey.data
        cache = runtime.mesh_cache
        print(
            f"{size[0]}x{size[1]}, Suzanne subdivided 3 times and applied ({len(mesh.polygons):,} faces), "
            f"edge angle 20 degrees; median of {args.repeats} alternating rounds\n"
        )
        print(
            "| edit | redraw, full extraction (ms) | redraw, incremental check (ms) | ratio |"
            " mesh update, full (ms) | mesh update, check (ms) | ratio | repositioned |"
        )
        print("|---|---:|---:|---:|---:|---:|---:|---:|")
        edits = (("one vertex", one_vertex), ("1 % of the vertices", stroke), ("one vertex, across the angle", across))
        for name, edit in edits:
            redraws = {True: [], False: []}
            updates = {True: [], False: []}  # the mesh's part: extraction or check, plus upload
            repositioned = 0
            viewport.redraw_ms(scene)
            step = 0
            for _round in range(args.repeats):
                for incremental in (False, True):
                    edit(mesh, step)
                    step += 1
                    cache.reset_counters()
                    with runtime.drawing_with(DrawOptions(reposition_meshes=incremental)):
                        redraws[incremental].append(viewport.redraw_ms(scene))
                    stats = solidwire_addon.stats()
                    updates[incremental].append(stats["ms_extract"] + stats["ms_upload"])
                    if incremental:
                        repositioned += cache.repositioned
            full, check = np.median(redraws[False]), np.median(redraws[True])
            full_update, check_update = np.median(updates[False]), np.median(updates[True])
            print(
                f"| {name} | {full:.0f} | {check:.0f} | {check / full:.2f}x | {full_update:.1f} | {check_update:.1f} |"
                f" {check_update / full_update:.2f}x | {repositioned}/{args.repeats} |",
                flush=True,
            )
    finally:
        solidwire_addon.unregister()
    return 0


if __name__ == "__main__":
    sys.exit(main())
