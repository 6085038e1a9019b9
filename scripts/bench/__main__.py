"""Run time against error: SolidWire's exact method and the published methods.

For every method x scene at 1280 x 720 (``--size``), this measures

- the median time per frame over ``--frames`` frames after ``--warmup``
  frames, each frame synchronised with the GPU (one pixel read back; Blender's
  gpu module exposes no glFinish). The methods take turns frame by frame, so
  background load affects them alike. The mesh scenes turn around a vertical axis
  like the papers' benchmarks; the stress scenes stand still.
- the error of one frame against the float64 reference of the image model
  (tests/support/reference.py, docs/image_model.md §7): mean, 99.9th percentile and max |dI| and
  the count of pixels with |dI| > 2/255, silhouette samples excluded. The
  reference is slow numpy, so it is evaluated on sampled window rows (every
  ``--ref-row-step``-th row, same camera as the full-size frame); the output
  says which rows.

Peers in the same run: Blender's Workbench engine in Solid and in Wireframe
shading (time; error for Wireframe, whose alpha is a line intensity too), and
Freestyle lines over one teapot frame (Cycles at 1 sample; time only).

Outputs under ``--out`` (default out/bench/): results.json, results.md (the
table), time_vs_error.png (one point per method and scene, log axes) and
near_plane_crops.png (the near-plane glitch: nvidia2007 vs kakadu_clip vs
exact). matplotlib is needed for the pictures only (requirements-bench.txt).

    python -m scripts.bench [--quick] [--method exact --method nvidia2007 ...]
                            [--scene teapot ...] [--frames 20] [--no-peers]
                            [--engines 1280x720 --engines 3840x2160]

``--engines WxH`` adds the F12 table of scripts/bench_engines.py at that
size (SolidWire against Workbench flat and wireframe, Freestyle unless
``--no-peers``, and the floor: a bare draw of the same triangles), with
SolidWire's frame stage by stage, to the output and to results.md.

Run scripts/fetch_meshes.py first for the teapot and bunny (optional: their
scenes are skipped when the meshes are missing).

Line settings: thickness 0, softness 1 px (the papers' prefiltered profile
I(d) = 2^(-2 d^2), docs/image_model.md §4), diagonals SOLID (every
triangle edge drawn): the published methods draw every triangle edge, so with
SOLID all methods are asked for the same lines and differ only in how they
compute the distance to them.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import statistics
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
os.environ.setdefault("BLENDER_USER_RESOURCES", tempfile.mkdtemp(prefix="solidwire-bench-"))

import bpy
import numpy as np

import solidwire_addon
from scripts.bench import methods
from solidwire_addon.blender import gather
from solidwire_addon.blender import views as view_mod
from solidwire_addon.blender.gpu_context import ensure_gpu
from solidwire_addon.core.cache import MeshCache
from solidwire_addon.core.settings import DrawSettings
from solidwire_addon.core.view import translation
from tests.support import scenes

try:  # written by the lead alongside this script; the bench times without it
    from tests.support import reference
except ImportError:  # pragma: no cover
    reference = None

SCENE_ORDER = ["teapot", "bunny", "suzanne_1m", *scenes.STRESS_SCENES]
QUICK_SCENES = ["teapot", "near_plane", "far_1e6"]
LINE_SETTINGS = dict(thickness=0.0, softness=1.0, diagonal_mode="SOLID")
TURN_DEGREES_PER_FRAME = 3.0


# ------------------------------------------------------------------ scenes


def build_scene(name: str, width: int, height: int):
    """(scene, turning objects) or None when the scene's mesh is missing."""
    path = scenes.MESH_FILES.get(name)
    if path is not None and not path.exists():
        return None
    scene = scenes.empty_scene(width, height, **LINE_SETTINGS)
    builder = scenes.MESH_SCENES.get(name) or scenes.STRESS_SCENES[name]
    turning = builder(scene)
    bpy.context.view_layer.update()
    return scene, turning


def turn_matrices(items, turning_names, frame: int, base):
    """Set each turning item's matrix to its frame-0 matrix turned about the
    world z axis through its bounding-box centre."""
    angle = math.radians(TURN_DEGREES_PER_FRAME * frame)
    c, s = math.cos(angle), math.sin(angle)
    rotation = np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]])
    for item, matrix0, turns in zip(items, base, turning_names):
        if not turns:
            continue
        centre = matrix0 @ np.append(item.mesh.centre, 1.0)
        to_centre = translation(centre[:3])
        item.matrix = to_centre @ rotation @ translation(-centre[:3]) @ matrix0


# ----------------------------------------------------------------- measuring


def time_methods(method_list, items, view, settings, turning, base, warmup: int, frames: int):
    """{method: (times ms, frame-0 intensity)}. The methods take turns frame
    by frame (round robin), so load from other processes on a shared machine
    falls on all of them alike and the ratios of one run stay meaningful."""
    renderers = {m: methods.Renderer(m, view.width, view.height) for m in method_list}
    times = {m: [] for m in method_list}
    for frame in range(warmup + frames):
        turn_matrices(items, turning, frame, base)
        for method, renderer in renderers.items():
            start = time.perf_counter()
            renderer.draw(items, view, settings)
            renderer.sync()
            if frame >= warmup:
                times[method].append((time.perf_counter() - start) * 1000.0)
    turn_matrices(items, turning, 0, base)
    out = {}
    for method, renderer in renderers.items():
        renderer.draw(items, view, settings)
        rgba, _depth = renderer.read()
        out[method] = (times[method], rgba[..., 3].astype(np.float64))
    renderers.clear()
    return out


def error_numbers(intensity_full, ref):
    if ref is None:
        return None
    measured = intensity_full[ref.rows]
    report = reference.error_report(measured, ref)
    return {k: report[k] for k in ("mean", "p999", "max", "over_2_255", "pixels", "silhouette_pixels", "nan")}


def render_engine_peer(scene, engine: str, shading: str | None, repeats: int, out_dir: Path, freestyle=False):
    """Median seconds of bpy.ops.render.render for a Blender engine, and the
    straight alpha of one rendered frame (bottom row first)."""
    scene.render.engine = engine
    if shading is not None:
        scene.display.shading.type = shading
        scene.display.shading.color_type = "SINGLE"
        scene.display.shading.show_xray = False
    if engine == "CYCLES":
        scene.cycles.samples = 1
        scene.cycles.device = "CPU"
        scene.cycles.use_denoising = False
    scenes.enable_freestyle(scene, freestyle)
    if freestyle:
        scene.render.line_thickness_mode = "ABSOLUTE"
        scene.render.line_thickness = 1.0
    path = out_dir / f"peer_{engine}_{shading or 'freestyle'}.png"
    scene.render.filepath = str(path)
    scene.render.image_settings.file_format = "PNG"
    scene.render.image_settings.color_mode = "RGBA"
    scene.render.image_settings.color_depth = "16"
    times = []
    for i in range(repeats):
        start = time.perf_counter()
        bpy.ops.render.render(write_still=(i == repeats - 1), scene=scene.name)
        times.append((time.perf_counter() - start) * 1000.0)
    alpha = scenes.load_png(path)[..., 3]
    scene.render.engine = "SOLIDWIRE"
    scenes.enable_freestyle(scene, False)
    return times, alpha


# ------------------------------------------------------------------ outputs


def fmt_err(value):
    return "-" if value is None else (f"{value:.2e}" if 0 < value < 1e-3 else f"{value:.4f}")


def write_markdown(results, meta, path: Path):
    lines = [
        (
            f"Machine: {meta['machine']}. Frame {meta['size'][0]}x{meta['size'][1]}; time = median ms per frame over "
            f"{meta['frames']} frames after {meta['warmup']} warm-up frames, GPU synchronised (CPU timings on llvmpipe). "
            f"Error vs the float64 reference on {meta['reference_rows']}, silhouette samples excluded."
        ),
        "",
        "| scene | method | ms/frame | x fill_only | mean abs dI | p99.9 abs dI | max abs dI | px > 2/255 |",
        "|---|---|---:|---:|---:|---:|---:|---:|",
    ]
    for scene_name, rows in results.items():
        fill = next((r["ms"] for r in rows if r["method"] == "fill_only"), None)
        for r in rows:
            e = r.get("error") or {}
            ratio = f"{r['ms'] / fill:.2f}" if (fill and r.get("ms") and not r["method"].startswith("peer")) else "-"
            ms = f"{r['ms']:.1f}" if r.get("ms") is not None else "-"
            lines.append(
                f"| {scene_name} | {r['method']} | {ms} | {ratio} | {fmt_err(e.get('mean'))} | {fmt_err(e.get('p999'))} "
                f"| {fmt_err(e.get('max'))} | {e.get('over_2_255', '-')} |"
            )
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")


def targets_summary(results):
    """The benchmark's targets, measured: exact / fill_only ratio on the mesh
    scenes; lowest error and Pareto front per scene."""
    summary = {}
    for scene_name, rows in results.items():
        own = [r for r in rows if not r["method"].startswith("peer") and r.get("error")]
        by = {r["method"]: r for r in own}
        if "exact" not in by:
            continue
        ex = by["exact"]
        entry = {}
        if "fill_only" in by:
            entry["exact_over_fill_only"] = ex["ms"] / by["fill_only"]["ms"]
        # exact_direct is exact itself (the same image, drawn without the
        # deferred surface): a timing reference, not a competitor.
        others = [r for r in own if r["method"] not in ("exact", "exact_direct", "fill_only")]
        # "Error" ranks visible errors first: pixels off by more than 2/255,
        # then the 99.9th percentile, then the mean. Each single metric is
        # reported too, since they do not always agree.
        key = lambda r: (r["error"]["over_2_255"], r["error"]["p999"], r["error"]["mean"])
        entry["exact_lowest_error"] = all(key(ex) <= key(r) for r in others)
        entry["beaten_by"] = [r["method"] for r in others if key(r) < key(ex)]
        for metric in ("over_2_255", "p999", "max", "mean"):
            entry[f"lower_{metric}_than_exact"] = [
                r["method"] for r in others if r["error"][metric] < ex["error"][metric]
            ]
        entry["dominates_exact"] = [r["method"] for r in others if r["ms"] < ex["ms"] and key(r) <= key(ex)]
        entry["exact_on_pareto_front"] = not entry["dominates_exact"]
        summary[scene_name] = entry
    return summary


def plot(results, path: Path, meta):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    markers = dict(zip(methods.ALL_METHODS, "o^vsDPX*"))
    markers.update({"peer_workbench_wireframe": "h"})
    scene_names = list(results)
    colours = [plt.cm.tab10(i % 10) for i in range(len(scene_names))]
    fig, axes = plt.subplots(1, 2, figsize=(13, 5.5))
    floor = 1e-5
    for ax, metric, label in ((axes[0], "mean", "mean |dI|"), (axes[1], "p999", "99.9th percentile |dI|")):
        for colour, scene_name in zip(colours, scene_names):
            for r in results[scene_name]:
                if not r.get("error") or r["method"] == "fill_only":
                    continue
                ax.scatter(
                    r["ms"],
                    max(r["error"][metric], floor),
                    marker=markers.get(r["method"], "o"),
                    color=colour,
                    s=46,
                    edgecolors="black",
                    linewidths=0.4,
                )
        ax.set_xscale("log")
        # Ticks at 1, 2, 5 x 10^k in plain numbers: over less than two
        # decades matplotlib's own minor labels run into each other.
        ax.xaxis.set_major_locator(plt.LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
        ax.xaxis.set_major_formatter(plt.FuncFormatter(lambda value, _pos: f"{value:g}"))
        ax.xaxis.set_minor_formatter(plt.NullFormatter())
        ax.set_yscale("log")
        ax.set_xlabel("ms per frame (median; CPU timings, Mesa llvmpipe)")
        ax.set_ylabel(f"{label} vs float64 reference (floored at {floor:g})")
        ax.axhline(2 / 255, color="grey", lw=0.8, ls="--")
        ax.grid(True, which="both", lw=0.3, alpha=0.5)
    from matplotlib.lines import Line2D

    handles = [
        Line2D([], [], marker=markers.get(m, "o"), ls="", color="grey", markeredgecolor="black", label=m)
        for m in [*methods.ALL_METHODS, "peer_workbench_wireframe"]
        if m != "fill_only"
    ]
    handles += [Line2D([], [], marker="o", ls="", color=c, label=s) for c, s in zip(colours, scene_names)]
    fig.legend(handles=handles, loc="center right", fontsize=8, frameon=False)
    fig.suptitle(
        f"SolidWire benchmark: time vs error, {meta['size'][0]}x{meta['size'][1]} ({meta['machine']})", fontsize=10
    )
    fig.tight_layout(rect=(0, 0, 0.83, 0.95))
    fig.savefig(path, dpi=80)
    plt.close(fig)


def crops(images: dict, path: Path, crop=(220, 150), zoom=3):
    """Side-by-side crops of the near-plane glitch. The window is centred on
    the strongest local difference between nvidia2007 and kakadu_clip (the
    tricky-case cancellation), or nvidia2007 and exact if those agree."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = [m for m in ("nvidia2007", "kakadu_clip", "exact") if m in images]
    if "nvidia2007" not in images:
        return None
    base = images["nvidia2007"]
    other = images.get("kakadu_clip", images.get("exact"))
    diff = np.abs(base - other)
    if diff.max() == 0 and "exact" in images:
        diff = np.abs(base - images["exact"])
    _h, _w = base.shape
    cw, ch = crop
    # Box-sum of the difference over crop-sized windows (integral image).
    integral = np.pad(diff, ((1, 0), (1, 0))).cumsum(0).cumsum(1)
    sums = integral[ch:, cw:] - integral[:-ch, cw:] - integral[ch:, :-cw] + integral[:-ch, :-cw]
    y0, x0 = np.unravel_index(np.argmax(sums), sums.shape)
    fig, axes = plt.subplots(1, len(names), figsize=(3.2 * len(names), 2.6))
    for ax, name in zip(np.atleast_1d(axes), names):
        tile = images[name][y0 : y0 + ch, x0 : x0 + cw]
        ax.imshow(
            np.repeat(np.repeat(tile, zoom, 0), zoom, 1),
            origin="lower",
            cmap="gray",
            vmin=0,
            vmax=1,
            interpolation="nearest",
        )
        ax.set_title(name, fontsize=9)
        ax.set_xticks([])
        ax.set_yticks([])
    fig.suptitle(f"near_plane scene, window x {x0}..{x0 + cw}, y {y0}..{y0 + ch} (from bottom), {zoom}x", fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return [int(x0), int(y0), cw, ch]


# --------------------------------------------------------------------- main


def machine_name():
    import gpu

    cpus = os.cpu_count()
    return f"{cpus}-core CPU ({platform.processor() or platform.machine()}), {gpu.platform.renderer_get()}"


def main(argv=None):
    parser = argparse.ArgumentParser(description="SolidWire run time vs error benchmark")
    parser.add_argument("--quick", action="store_true", help="smoke test: 3 scenes, few frames, coarse reference rows")
    parser.add_argument("--method", action="append", choices=methods.ALL_METHODS, help="methods to run (repeatable)")
    parser.add_argument("--scene", action="append", choices=SCENE_ORDER, help="scenes to run (repeatable)")
    parser.add_argument("--size", default="1280x720")
    parser.add_argument("--frames", type=int, default=None)
    parser.add_argument("--warmup", type=int, default=None)
    parser.add_argument("--ref-row-step", type=int, default=None, help="reference on every N-th window row")
    parser.add_argument("--no-peers", action="store_true", help="skip Workbench and Freestyle")
    parser.add_argument("--out", default=str(ROOT / "out" / "bench"))
    parser.add_argument("--docs", metavar="DIR", help="also copy the two pictures there (e.g. docs/, for the manual)")
    parser.add_argument(
        "--engines",
        action="append",
        metavar="WxH",
        help="also time F12 against Blender's own engines at this size, with the SolidWire frame "
        "stage by stage (scripts/bench_engines.py; repeatable)",
    )
    args = parser.parse_args(argv)

    width, height = (int(v) for v in args.size.lower().split("x"))
    frames = args.frames or (4 if args.quick else 15)
    warmup = args.warmup or (2 if args.quick else 3)
    row_step = args.ref_row_step or (24 if args.quick else 6)
    method_list = args.method or list(methods.ALL_METHODS)
    scene_list = args.scene or (QUICK_SCENES if args.quick else SCENE_ORDER)
    out_dir = Path(args.out)
    out_dir.mkdir(parents=True, exist_ok=True)

    solidwire_addon.register()
    ensure_gpu()
    meta = {
        "machine": machine_name(),
        "size": [width, height],
        "frames": frames,
        "warmup": warmup,
        "reference_rows": f"every {row_step}th window row from row {row_step // 2} ({height // row_step} rows, full width)",
        "line_settings": LINE_SETTINGS,
        "quick": bool(args.quick),
        "turn_degrees_per_frame": TURN_DEGREES_PER_FRAME,
        "peers": "Workbench: whole bpy.ops.render.render at its default settings (render_aa 8 samples); "
        "Freestyle: Cycles 1 sample + Freestyle lines, one teapot frame",
    }
    print(f"bench: {meta['machine']}; {width}x{height}; {frames} frames after {warmup} warm-up", flush=True)
    results, skipped, crop_images, extras = {}, [], {}, {}
    for scene_name in scene_list:
        built = build_scene(scene_name, width, height)
        if built is None:
            print(f"bench: skip {scene_name}: mesh missing (run scripts/fetch_meshes.py)", flush=True)
            skipped.append(scene_name)
            continue
        scene, turning_objects = built
        depsgraph = bpy.context.evaluated_depsgraph_get()
        cache = MeshCache()
        items, _keys, _ms = gather.gather(depsgraph, cache)
        turning_names = {o.name for o in turning_objects}
        # gather() walks the same instances in the same order; pair by name.
        instance_names = [inst.object.name for inst in depsgraph.object_instances if inst.object.type == "MESH"]
        turning = [name in turning_names for name in instance_names][: len(items)]
        base = [it.matrix.copy() for it in items]
        view = view_mod.camera_view(scene, depsgraph)
        settings = DrawSettings.from_properties(scene.solidwire)
        triangles = sum(it.mesh.triangle_count for it in items)

        ref = None
        if reference is not None:
            start = time.perf_counter()
            rows = np.arange(row_step // 2, height, row_step)
            ref = reference.render_reference(scene, depsgraph, size=(width, height), rows=rows)
            print(
                f"bench: {scene_name}: {triangles} triangles; reference on {len(rows)} rows "
                f"in {time.perf_counter() - start:.1f} s",
                flush=True,
            )

        rows_out = []
        measured = time_methods(method_list, items, view, settings, turning, base, warmup, frames)
        for method in method_list:
            times, intensity = measured[method]
            row = {
                "method": method,
                "ms": statistics.median(times),
                "ms_all": times,
                "error": error_numbers(intensity, ref),
                "triangles": triangles,
            }
            rows_out.append(row)
            if scene_name == "near_plane" and method in ("nvidia2007", "kakadu_clip", "exact"):
                crop_images[method] = intensity
            e = row["error"] or {}
            print(
                f"bench: {scene_name:11s} {method:16s} {row['ms']:9.2f} ms  mean {e.get('mean', float('nan')):.2e} "
                f"p99.9 {e.get('p999', float('nan')):.2e} max {e.get('max', float('nan')):.3f} "
                f">2/255 {e.get('over_2_255', '-')}",
                flush=True,
            )

        if not args.no_peers and scene_name in ("teapot", "bunny", "suzanne_1m", "near_plane"):
            repeats = 2 if args.quick else 3
            for shading in ("SOLID", "WIREFRAME"):
                times, alpha = render_engine_peer(scene, "BLENDER_WORKBENCH", shading, repeats, out_dir)
                # Error only where meaningful: Wireframe's alpha is a line
                # intensity too (Solid has no lines). An empty image (seen
                # with llvmpipe in background mode) gets no error either.
                err = error_numbers(alpha, ref) if (shading == "WIREFRAME" and alpha.max() > 0) else None
                if shading == "WIREFRAME" and alpha.max() == 0:
                    print("bench: note: Workbench Wireframe returned an empty image here; time only", flush=True)
                rows_out.append(
                    {
                        "method": f"peer_workbench_{shading.lower()}",
                        "ms": statistics.median(times),
                        "ms_all": times,
                        "error": err,
                        "triangles": triangles,
                    }
                )
                print(
                    f"bench: {scene_name:11s} workbench {shading:9s} {statistics.median(times):9.2f} ms "
                    f"(whole bpy.ops.render.render)",
                    flush=True,
                )
            if scene_name == "teapot":
                times, _alpha = render_engine_peer(scene, "CYCLES", None, 1, out_dir, freestyle=True)
                rows_out.append(
                    {
                        "method": "peer_freestyle_cycles_1spp",
                        "ms": times[0],
                        "ms_all": times,
                        "error": None,
                        "triangles": triangles,
                    }
                )
                print(f"bench: teapot      freestyle (Cycles 1 spp) {times[0]:9.2f} ms", flush=True)
        results[scene_name] = rows_out
        methods.release()

    summary = targets_summary(results)
    data = {"meta": meta, "results": results, "targets": summary, "skipped": skipped}
    engine_lines = []
    for text in args.engines or ():
        from scripts import bench_engines

        engine_size = tuple(int(v) for v in text.lower().split("x"))
        engine_lines += bench_engines.run(
            engine_size, subdivisions=5, repeats=2 if args.quick else 5, freestyle=not args.no_peers
        )
        print("\n".join(engine_lines), flush=True)
    if engine_lines:
        data["engines_markdown"] = engine_lines
    if crop_images:
        extras["crop_window"] = crops(crop_images, out_dir / "near_plane_crops.png")
        data["crop_window"] = extras["crop_window"]
    (out_dir / "results.json").write_text(json.dumps(data, indent=1), encoding="utf-8")
    write_markdown(results, meta, out_dir / "results.md")
    if engine_lines:
        with (out_dir / "results.md").open("a", encoding="utf-8") as markdown:
            markdown.write("\n## Against Blender's own engines (F12)\n\n" + "\n".join(engine_lines) + "\n")
    plot(results, out_dir / "time_vs_error.png", meta)
    if args.docs:
        import shutil

        docs = Path(args.docs)
        docs.mkdir(parents=True, exist_ok=True)
        for name in ("time_vs_error.png", "near_plane_crops.png"):
            if (out_dir / name).exists():
                shutil.copyfile(out_dir / name, docs / f"bench_{name}")
    print(json.dumps(summary, indent=1))
    print(
        f"bench: wrote {out_dir}/results.json, results.md, time_vs_error.png"
        + (", near_plane_crops.png" if crop_images else "")
    )
    solidwire_addon.unregister()
    return 0


if __name__ == "__main__":
    sys.exit(main())
