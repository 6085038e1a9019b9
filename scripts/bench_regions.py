"""What the cage look and the other edge selections cost against drawing
every edge of the same mesh: F12 (a warm render), the viewport overlay (a
static redraw and a redraw after one vertex moved) and the first render's
extraction, for Suzanne under a Subdivision Surface modifier at levels 2-5;
then the angle threshold and edge classes against a plain frame.
``--stacks`` instead measures the first extraction alone for the stacks
whose cage regions are read from the evaluated mesh's layout (a modifier
before the subdivision, Edit Mode) and for the object's own mesh, the cage
look with those regions and with the regions found from the mesh, against
every edge. ``--ngon-diagonals`` instead measures F12 of a tube with caps
of 32 to 1,024 corners in each diagonal mode; ``--walks`` the cage look's
F12 with hidden lines and with the Edge Distance pass (levels up to 4),
where pixels still walk their regions' edges. ``--hidden-lines`` gives the
main table with hidden lines on in both looks (the overlay keeps its hidden
lines, fill and wire between redraws), ``--shading xray|wireframe`` with
the overlay's redraws in X-ray or Wireframe shading (X-ray alpha 0.5).

    .venv/bin/python -m scripts.bench_regions [--size 1280x720] [--repeats 3] [--levels 2 3 4 5] [--stacks [--stack NAME]]
    .venv/bin/python -m scripts.bench_regions --ngon-diagonals
    .venv/bin/python -m scripts.bench_regions --walks [--levels 2 3 4]
    .venv/bin/python -m scripts.bench_regions --hidden-lines [--levels 2 3 4 5]
    .venv/bin/python -m scripts.bench_regions --shading xray|wireframe [--levels 2 3 4 5]
    .venv/bin/python -m scripts.bench_regions --runs 16 [--levels 2 3 4 5] [--json FILE]

Every ratio is taken within one process, rounds alternating between the two
looks so that a change in machine load hits both alike; the table gives the
best of the rounds (Markdown, for the README). ``--runs N`` repeats the main
tables in N fresh processes, one after another, and gives each ratio's
median and range over them: the README's tables, which one process alone
cannot give on a noisy machine. ``--json FILE`` also writes the milliseconds
(with ``--runs``, a list of every run's).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time

import bpy
import gpu

import solidwire_addon
from solidwire_addon.blender import engine, overlay, runtime
from solidwire_addon.blender.gpu_context import ensure_gpu
from solidwire_addon.blender.views import camera_view
from solidwire_addon.core import edge_select, overlay_state, passes
from tests.support import scenes

PLAIN = dict(
    use_fill=True,
    use_cage_edges=False,
    edge_angle=0.0,
    use_density_fade=False,
    diagonal_mode="HIDDEN",
    use_boundary_edges=False,
    use_sharp_edges=False,
    use_seam_edges=False,
    use_crease_edges=False,
    use_freestyle_edges=False,
)


def build_scene(size, level: int, before=(), shape: str = "Suzanne", capped_array: bool = False):
    """Suzanne (or a 32-sided cylinder with n-gon caps: ``shape``
    "Cylinder") under a Subdivision Surface at ``level``, the modifiers
    ``before`` (types) ahead of it; ``capped_array``: a Mirror and an Array
    of two with a cube at each end after it."""
    scene = scenes.empty_scene(*size, transparent=False)
    if shape == "Cylinder":
        monkey = scenes.tube(scene, "Cylinder", segments=32, rotation=(0.3, 0.0, 0.5))
    else:
        monkey = scenes.monkey(scene, rotation=(0.0, 0.0, 0.5))
    for edge in monkey.data.edges[:80]:  # marked edges for the edge classes
        edge.use_seam = edge.index % 2 == 0
        edge.use_edge_sharp = edge.index % 2 == 1
    for kind in before:
        modifier = monkey.modifiers.new(kind, kind)
        if kind == "MIRROR":
            modifier.use_mirror_merge = False
        elif kind == "BEVEL":
            modifier.width, modifier.segments = 0.02, 2
        elif kind == "SOLIDIFY":
            modifier.thickness = 0.05
    modifier = monkey.modifiers.new("Subdivision", "SUBSURF")
    modifier.levels = modifier.render_levels = level
    if capped_array:
        array = scenes.add_mirror_and_array(monkey, count=2, offset=(1.2, 0.0, 0.0))
        for end in ("start_cap", "end_cap"):
            cap = scenes.cube(scene, end, size=0.3)
            cap.hide_render = cap.hide_viewport = True
            setattr(array, end, cap)
    scenes.add_camera(scene, location=(1.2, -3.4, 1.0), target=(0.0, 0.0, 0.0), lens=45.0)
    return scene, monkey


def apply(scene, look: dict) -> None:
    for name, value in {**PLAIN, **look}.items():
        setattr(scene.solidwire, name, value)


def f12_ms(scene, size, extra_passes=()) -> float:
    depsgraph = bpy.context.evaluated_depsgraph_get()
    start = time.perf_counter()
    engine.render_scene(depsgraph, size, extra_passes=extra_passes)
    return (time.perf_counter() - start) * 1000.0


# Viewport states for --shading (core/overlay_state.py), X-ray at half alpha.
SHADINGS = {
    "solid": overlay_state.ViewportState(),
    "xray": overlay_state.ViewportState(xray=True, xray_alpha=0.5),
    "wireframe": overlay_state.ViewportState(shading=overlay_state.WIREFRAME, xray=True, xray_alpha=0.5),
}


class Viewport:
    """An offscreen standing in for a 3D viewport (colour + depth), drawn
    into by the overlay as its POST_VIEW handler would, in the viewport
    state ``shading`` (a key of SHADINGS)."""

    def __init__(self, size, shading: str = "solid"):
        self.size = size
        self.offscreen = gpu.types.GPUOffScreen(*size, format="RGBA8")
        self.plan = overlay_state.plan_overlay(SHADINGS[shading])

    def redraw_ms(self, scene) -> float:
        depsgraph = bpy.context.evaluated_depsgraph_get()
        view = camera_view(scene, depsgraph, self.size)
        start = time.perf_counter()
        with self.offscreen.bind():
            fb = gpu.state.active_framebuffer_get()
            fb.clear(color=(0.2, 0.2, 0.2, 1.0), depth=1.0)
            gpu.state.viewport_set(0, 0, *self.size)
            overlay.draw_scene_overlay(depsgraph, view, scene.solidwire.snapshot(), plan=self.plan)
            fb.read_color(0, 0, 1, 1, 4, 0, "UBYTE")  # waits for the GPU
        return (time.perf_counter() - start) * 1000.0


def nudge(obj, step: int) -> None:
    vertex = obj.data.vertices[step % len(obj.data.vertices)]
    vertex.co.z += 1e-3 * (1 if step % 2 else -1)
    obj.data.update()


def first_extract_ms(scene, size) -> float:
    runtime.mesh_cache.clear()
    engine.render_scene(bpy.context.evaluated_depsgraph_get(), size)
    return solidwire_addon.stats()["ms_extract"]


def compare(scene, monkey, size, looks, repeats: int, viewport: Viewport | None):
    """{look: {measure: best ms}} over alternating rounds."""
    best: dict = {name: {} for name in looks}

    def keep(name, key, value):
        best[name][key] = min(best[name].get(key, math.inf), value)

    for name, look in looks.items():  # compile every variant, fill the cache
        apply(scene, look)
        f12_ms(scene, size)
        if viewport:
            viewport.redraw_ms(scene)
    for round_ in range(repeats):
        for name, look in looks.items():
            apply(scene, look)
            f12_ms(scene, size)
            keep(name, "f12", f12_ms(scene, size))
            if viewport:
                # A look's first redraw records it, the second keeps its
                # image (passes._overlay_surface): a static redraw is the third.
                viewport.redraw_ms(scene)
                viewport.redraw_ms(scene)
                keep(name, "redraw", viewport.redraw_ms(scene))
                nudge(monkey, round_)
                keep(name, "edit", viewport.redraw_ms(scene))
            keep(name, "extract", first_extract_ms(scene, size))
    return best


# Every edge class on, as the Edge Classes preset (build_scene marks 80
# of Suzanne's edges seam or sharp; its eye holes are boundary edges).
EVERY_CLASS = dict(use_boundary_edges=True, use_sharp_edges=True, use_seam_edges=True, use_crease_edges=True)

# (name, shape, modifier types before the subdivision, Edit Mode, look
# beside the cage or every edge, a Mirror and a capped Array after it)
STACKS = (
    ("own mesh", "Suzanne", (), False, {}, False),
    ("Mirror, Subdivision", "Suzanne", ("MIRROR",), False, {}, False),
    ("Bevel, Subdivision", "Suzanne", ("BEVEL",), False, {}, False),
    ("Solidify, Subdivision", "Suzanne", ("SOLIDIFY",), False, {}, False),
    ("Edit Mode", "Suzanne", (), True, {}, False),
    ("Edit Mode, Mirror, Subdivision", "Suzanne", ("MIRROR",), True, {}, False),
    # Its caps' regions pass WALK_LIMIT from level 3: blocks of their faces' own edges.
    ("Cylinder, 32-gon caps", "Cylinder", (), False, {}, False),
    ("own mesh, every edge class on", "Suzanne", (), False, EVERY_CLASS, False),
    # Cage faces meeting at under 30 degrees join into one region (join_regions).
    ("own mesh, edge angle 30°", "Suzanne", (), False, dict(edge_angle=math.radians(30.0)), False),
    ("Mirror, Subdivision, edge angle 30°", "Suzanne", ("MIRROR",), False, dict(edge_angle=math.radians(30.0)), False),
    # The caps follow the copies: faces past the listed regions.
    ("Subdivision, Mirror, Array with caps", "Suzanne", (), False, {}, True),
    ("Edit Mode, Subdivision, Mirror, Array with caps", "Suzanne", (), True, {}, True),
)


def stack_table(size, levels, repeats: int, names=()) -> None:
    """First extraction of the cage look against every edge (each with the
    stack's look beside it) for STACKS (those whose name contains one of
    ``names``, when given),
    with the regions the cage layout gives and with the regions found from
    the mesh (the layout's shortcut switched off), rounds alternating."""
    print(
        "| stack | level | triangles | every edge (ms) | cage, regions found (ms) | ratio |"
        " cage, regions from the layout (ms) | ratio |"
    )
    print("|---|---:|---:|" + "---:|" * 5)
    shortcut = edge_select._select_known_regions
    taken = []  # whether each call took the regions it was given

    def spy(*args):
        result = shortcut(*args)
        taken.append(result is not None)
        return result

    for name, shape, before, edit, look_extra, capped_array in STACKS:
        if names and not any(part in name for part in names):
            continue
        for level in levels:
            bpy.ops.wm.read_factory_settings(use_empty=True)
            solidwire_addon.register()
            scene, monkey = build_scene(size, level, before, shape, capped_array)
            if edit:
                bpy.context.view_layer.objects.active = monkey
                monkey.select_set(True)
                bpy.ops.object.mode_set(mode="EDIT")
            triangles = len(monkey.evaluated_get(bpy.context.evaluated_depsgraph_get()).data.loop_triangles)
            looks = {"all": (False, spy), "found": (True, lambda *args: None), "layout": (True, spy)}
            best: dict = {}
            refused = False
            try:
                for round_ in range(repeats + 1):  # the first round warms up
                    for look, (use_cage, select) in looks.items():
                        apply(scene, dict(look_extra, use_cage_edges=use_cage))
                        edge_select._select_known_regions = select
                        taken.clear()
                        ms = first_extract_ms(scene, size)
                        if look == "layout":
                            refused = not any(taken)
                        if round_:
                            best[look] = min(best.get(look, math.inf), ms)
            finally:
                edge_select._select_known_regions = shortcut
                if edit:
                    bpy.ops.object.mode_set(mode="OBJECT")
            a, f, k = best["all"], best["found"], best["layout"]
            # Refused: where the layout cannot tell (see edge_select._select_known_regions).
            layout_cells = "refused | –" if refused else f"{k:.1f} | {k / a:.2f}x"
            print(
                f"| {name} | {level} | {triangles:,} | {a:.1f} | {f:.1f} | {f / a:.2f}x | {layout_cells} |", flush=True
            )


def ngon_diagonal_table(size, repeats: int, corners=(32, 256, 1024)) -> None:
    """F12 of a tube whose caps are n-gons of ``corners`` corners, seen
    from above at an angle, in each diagonal mode (best of ``repeats``):
    what showing the diagonals of large n-gons costs."""
    modes = ("HIDDEN", "SOLID", "DASHED")
    print("| cap corners | " + " | ".join(f"{mode.lower()} diagonals (ms)" for mode in modes) + " |")
    print("|---:|" + "---:|" * len(modes))
    for count in corners:
        bpy.ops.wm.read_factory_settings(use_empty=True)
        solidwire_addon.register()
        scene = scenes.empty_scene(*size, transparent=False)
        scenes.tube(scene, segments=count, rotation=(0.6, 0.0, 0.5))
        scenes.add_camera(scene, location=(0.0, -3.4, 2.0), target=(0.0, 0.0, 0.0), lens=45.0)
        cells = []
        for mode in modes:
            apply(scene, dict(diagonal_mode=mode))
            f12_ms(scene, size)  # compiles the variant
            cells.append(f"{min(f12_ms(scene, size) for _ in range(repeats)):.0f}")
        print(f"| {count} | " + " | ".join(cells) + " |", flush=True)


def walk_table(size, levels, repeats: int) -> None:
    """F12 of the cage look against every edge where pixels still walk
    their regions' edges instead of reading the region-lines image (image
    model §2.6): with hidden lines, and with the Edge Distance pass."""
    cases = (
        ("hidden lines", dict(use_hidden_lines=True), ()),
        ("Edge Distance pass", dict(use_hidden_lines=False), (passes.EDGE_DISTANCE_PASS,)),
    )
    print("| case | level | every edge (ms) | cage (ms) | ratio |")
    print("|---|---:|---:|---:|---:|")
    for name, look, extra in cases:
        for level in levels:
            bpy.ops.wm.read_factory_settings(use_empty=True)
            solidwire_addon.register()
            scene, _monkey = build_scene(size, level)
            best = {}
            for round_ in range(repeats + 1):  # the first round warms up
                for cage in (False, True):
                    apply(scene, dict(look, use_cage_edges=cage))
                    ms = f12_ms(scene, size, extra)
                    if round_:
                        best[cage] = min(best.get(cage, math.inf), ms)
            a, c = best[False], best[True]
            print(f"| {name} | {level} | {a:.0f} | {c:.0f} | {c / a:.2f}x |", flush=True)


# The main table's measures (compare's keys) and the looks of the second
# table against the plain frame, in the order the tables print them.
MEASURES = (
    ("f12", "F12"),
    ("redraw", "overlay redraw"),
    ("edit", "redraw after an edit"),
    ("extract", "first extraction"),
)
ANGLE_LOOKS = {
    "plain": {},
    "angle": dict(edge_angle=math.radians(20.0)),
    "classes": dict(use_boundary_edges=True, use_sharp_edges=True, use_seam_edges=True),
    "angle + classes": dict(edge_angle=math.radians(20.0), use_sharp_edges=True, use_seam_edges=True),
}


def machine(size) -> str:
    """What drew the numbers (times are only comparable on one machine):
    the GPU driver's renderer, Blender's version, the CPU count, the size."""
    return (
        f"{gpu.platform.renderer_get()}, Blender {bpy.app.version_string}, {os.cpu_count()} CPUs, {size[0]} x {size[1]}"
    )


def measure_tables(size, levels, repeats: int, shading: str, hidden_lines: bool) -> dict:
    """The main table's measures (best ms of each look, per level) and,
    in Solid shading without hidden lines, the second table's (per look):
    {"levels": {level: {"triangles": n, "all": {...}, "cage": {...}}},
    "looks": {name: {"f12": ms, "redraw": ms}}}."""
    viewport = Viewport(size, shading)
    base = dict(use_hidden_lines=True) if hidden_lines else {}
    conditions = f"overlay in {shading} shading" + (", hidden lines on in both looks" if hidden_lines else "")
    results: dict = {"machine": machine(size), "conditions": conditions, "levels": {}, "looks": {}}
    for level in levels:
        bpy.ops.wm.read_factory_settings(use_empty=True)
        solidwire_addon.register()
        scene, monkey = build_scene(size, level)
        triangles = len(monkey.evaluated_get(bpy.context.evaluated_depsgraph_get()).data.loop_triangles)
        looks = {"all": base, "cage": dict(base, use_cage_edges=True)}
        results["levels"][str(level)] = dict(
            triangles=triangles, **compare(scene, monkey, size, looks, repeats, viewport)
        )
    if hidden_lines or shading != "solid":
        return results
    bpy.ops.wm.read_factory_settings(use_empty=True)
    solidwire_addon.register()
    scene, monkey = build_scene(size, 2)
    modifier = monkey.modifiers[0]
    modifier.show_viewport = modifier.show_render = False
    bpy.ops.object.select_all(action="DESELECT")
    apply_subdivision(monkey, 3)
    results["looks_triangles"] = len(monkey.data.loop_triangles)
    results["looks"] = compare(scene, monkey, size, ANGLE_LOOKS, repeats, viewport)
    return results


def print_tables(results: dict) -> None:
    """One run's tables (best of its rounds, Markdown)."""
    print(
        "| level | triangles | F12 every edge (ms) | F12 cage | ratio | overlay redraw every edge | cage | ratio |"
        " edit redraw every edge | cage | ratio | first extraction every edge | cage | ratio |"
    )
    print("|---:|---:|" + "---:|" * 12)
    for level, row in results["levels"].items():
        cells = []
        for key, _title in MEASURES:
            a, c = row["all"][key], row["cage"][key]
            cells += [f"{a:.0f}", f"{c:.0f}", f"{c / a:.2f}x"]
        print(f"| {level} | {row['triangles']:,} | " + " | ".join(cells) + " |", flush=True)
    looks = results["looks"]
    if not looks:
        return
    print(
        f"\nSuzanne subdivided 3 times and applied ({results['looks_triangles']:,} triangles); "
        "ratio against the plain frame\n"
    )
    print("| look | F12 (ms) | ratio | overlay redraw (ms) | ratio |")
    print("|---|---:|---:|---:|---:|")
    for name, best in looks.items():
        f, r = best["f12"], best["redraw"]
        print(
            f"| {name} | {f:.0f} | {f / looks['plain']['f12']:.2f}x | {r:.0f} | {r / looks['plain']['redraw']:.2f}x |"
        )


def _median_and_range(values) -> str:
    """'1.03× (0.87–1.20)': the median of ``values`` and their range."""
    return f"{statistics.median(values):.2f}× ({min(values):.2f}–{max(values):.2f})"


def summary_tables(runs: list) -> str:
    """The README's tables from several runs' results (measure_tables):
    each ratio the median of the runs' ratios, with their range, and the
    median milliseconds of each look beside it."""
    lines = [
        f"{runs[0]['machine']}, {runs[0]['conditions']}: medians (ranges) of {len(runs)} runs; ratio = cage / every edge",
        "",
        "| Subdivision level | " + " | ".join(title for _key, title in MEASURES) + " |",
        "|---|" + "---:|" * len(MEASURES),
    ]
    milliseconds = []
    for level, row in runs[0]["levels"].items():
        cells, ms = [], []
        for key, _title in MEASURES:
            every = [run["levels"][level]["all"][key] for run in runs]
            cage = [run["levels"][level]["cage"][key] for run in runs]
            cells.append(_median_and_range([c / a for a, c in zip(every, cage)]))
            ms.append(f"{statistics.median(every):.1f} / {statistics.median(cage):.1f}")
        triangles = row["triangles"]
        lines.append(f"| {level} ({round(triangles / 1000):,}k triangles) | " + " | ".join(cells) + " |")
        milliseconds.append(f"| {level} | " + " | ".join(ms) + " |")
    lines += [
        "",
        "median ms, every edge / cage:",
        "",
        "| level | " + " | ".join(title for _key, title in MEASURES) + " |",
        "|---:|" + "---:|" * len(MEASURES),
        *milliseconds,
    ]
    if runs[0]["looks"]:
        lines += [
            "",
            f"Suzanne subdivided 3 times and applied ({runs[0]['looks_triangles']:,} triangles), against the plain frame:",
            "",
            "| look | F12 | overlay redraw |",
            "|---|---:|---:|",
        ]
        for name in runs[0]["looks"]:
            if name == "plain":
                continue
            cells = [
                _median_and_range([run["looks"][name][key] / run["looks"]["plain"][key] for run in runs])
                for key in ("f12", "redraw")
            ]
            lines.append(f"| {name} | " + " | ".join(cells) + " |")
        plain = statistics.median(run["looks"]["plain"]["f12"] for run in runs)
        lines.append(f"\n(the plain frame's F12: median {plain:.1f} ms)")
    return "\n".join(lines)


def run_many(argv: list, runs: int, json_path: str | None = None) -> int:
    """The main tables from ``runs`` fresh processes of this benchmark
    (``argv`` as _child_argv leaves it), one after another: medians and
    ranges, as the README gives them; ``json_path``: every run's results,
    a list, written there too. A fresh process a run, as a user's session
    would be: what one process compiles or caches does not carry over."""
    results = []
    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, "run.json")
        for index in range(runs):
            print(f"run {index + 1} of {runs}", file=sys.stderr, flush=True)
            done = subprocess.run([sys.executable, "-m", "scripts.bench_regions", *argv, "--json", path], check=False)
            if done.returncode != 0:
                print(f"error: run {index + 1} failed (exit status {done.returncode})", file=sys.stderr)
                return 1
            with open(path, encoding="utf-8") as file:
                results.append(json.load(file))
    if json_path:
        with open(json_path, "w", encoding="utf-8") as file:
            json.dump(results, file)
    print(summary_tables(results))
    return 0


def _child_argv(argv: list) -> list:
    """``argv`` less its --runs and --json options (``--runs N`` or
    ``--runs=N``): what each of run_many's processes is given."""
    kept, skip = [], False
    for arg in argv:
        if skip:
            skip = False
        elif arg in ("--runs", "--json"):
            skip = True
        elif not arg.startswith(("--runs=", "--json=")):
            kept.append(arg)
    return kept


def main(argv=None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", default="1280x720")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--levels", type=int, nargs="+", default=[2, 3, 4, 5])
    parser.add_argument("--stacks", action="store_true", help="the first extraction behind other stacks only")
    parser.add_argument("--stack", action="append", default=[], help="with --stacks: only stacks whose name holds this")
    parser.add_argument("--ngon-diagonals", action="store_true", help="F12 of large n-gons' diagonals only")
    parser.add_argument("--walks", action="store_true", help="F12 with hidden lines and the Edge Distance pass only")
    parser.add_argument("--hidden-lines", action="store_true", help="the main table with hidden lines on")
    parser.add_argument(
        "--shading", choices=tuple(SHADINGS), default="solid", help="the viewport state of the overlay's redraws"
    )
    parser.add_argument(
        "--runs", type=int, default=1, help="the main tables from this many fresh processes: medians and ranges"
    )
    parser.add_argument(
        "--json", help="also write the main tables' results (milliseconds; with --runs, a list of every run's) here"
    )
    args = parser.parse_args(argv)
    size = tuple(int(v) for v in args.size.split("x"))
    if args.runs > 1:
        if args.walks or args.ngon_diagonals or args.stacks:
            parser.error("--runs gives the main tables only")
        return run_many(_child_argv(argv), args.runs, args.json)
    solidwire_addon.register()
    try:
        ensure_gpu()
        if args.walks:
            print(f"{size[0]}x{size[1]}, F12, best of {args.repeats} alternating rounds\n")
            walk_table(size, [level for level in args.levels if level <= 4], args.repeats)
            return 0
        if args.ngon_diagonals:
            print(f"{size[0]}x{size[1]}, F12, best of {args.repeats}\n")
            ngon_diagonal_table(size, args.repeats)
            return 0
        if args.stacks:
            print(f"{size[0]}x{size[1]}, first extraction, best of {args.repeats} alternating rounds\n")
            stack_table(size, args.levels, args.repeats, args.stack)
            return 0
        print(f"{size[0]}x{size[1]}, best of {args.repeats} alternating rounds; ratio = cage / every edge")
        if args.shading != "solid":
            print(f"overlay redraws in {args.shading} shading (X-ray, alpha 0.5)")
        print("hidden lines on in both looks\n" if args.hidden_lines else "")
        results = measure_tables(size, args.levels, args.repeats, args.shading, args.hidden_lines)
        print_tables(results)
        if args.json:
            with open(args.json, "w", encoding="utf-8") as file:
                json.dump(results, file)
    finally:
        solidwire_addon.unregister()
    return 0


def apply_subdivision(obj, levels: int) -> None:
    """Subdivide the mesh itself (no modifier): a dense mesh whose regions
    come from the angle threshold alone."""
    import bmesh

    mesh = obj.data
    bm = bmesh.new()
    bm.from_mesh(mesh)
    for _ in range(levels):
        bmesh.ops.subdivide_edges(bm, edges=bm.edges[:], cuts=1, use_grid_fill=True, smooth=1.0)
    bm.to_mesh(mesh)
    bm.free()
    mesh.calc_loop_triangles()


if __name__ == "__main__":
    sys.exit(main())
