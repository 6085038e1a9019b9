"""Blender's real viewport, headless: what SolidWire's overlay costs on top of
it, against Blender's own Wireframe overlay.

    .venv/bin/python -m scripts.bench_viewport [--quick] [--repeats 3] [--size 1280x720]
        [--levels 3 4 5] [--profile] [--output docs/dev/viewport-benchmark.md]

``GPUOffScreen.draw_view3d`` draws a 3D View of the startup screens (Solid
shading and Blender's overlays, colour-managed) into an offscreen;
SolidWire's overlay is then drawn into the same offscreen, over Blender's
colour and depth, as its POST_VIEW handler would (tests/support/viewport.py).
Scenes: Suzanne subdivided 3 / 4 / 5 times (62k / 252k / 1M triangles),
once applied (a plain mesh) and once as a Subdivision modifier at that level.

A frame is: the depsgraph evaluated (the edit, if any, is made just before
and not timed), Blender's viewport drawn, SolidWire's overlay drawn (when in
the configuration), then a one-pixel read that waits for the GPU. Each
configuration, each time it takes its turn, gets an untimed frame first
(Blender builds its batches for a newly shown overlay, SolidWire extracts
for a new look), then one timed frame of each redraw kind; configurations
take turns for ``--repeats`` rounds and the best is reported (one round
where a frame takes over SLOW_FRAME_MS). Ratios compare numbers of the same
run. Blender's viewport anti-aliasing is off: one sample a redraw, as while
a user drags (see build_scene).

Edits: one vertex moved, or the 1 % of vertices nearest to one vertex moved
together (a sculpt dab), each by a quarter of the mean edge length; or the
object moved. On the modifier scenes the cage mesh is edited.
"""

from __future__ import annotations

import argparse
import os
import platform
import tempfile
import time
from dataclasses import dataclass

os.environ.setdefault("BLENDER_USER_RESOURCES", tempfile.mkdtemp(prefix="solidwire-user-"))

import bpy
import gpu
import numpy as np

import solidwire_addon
from solidwire_addon.core import draw as draw_mod
from solidwire_addon.core import passes
from tests.support import scenes
from tests.support.viewport import HeadlessViewport, set_overlays

MACHINE = "2-core x86-64 VM, Mesa llvmpipe, bpy 5.0.1"
LEVELS = {3: "62k", 4: "252k", 5: "1M"}
KINDS = ("applied", "modifier")

# Configurations: (name, Blender's wireframe overlay, SolidWire look or None).
# A look is the scene settings changed from the add-on's defaults.
LOOKS = {
    "default": {},
    "all edges": {"use_cage_edges": False},
    "fill off": {"use_fill": False},
}
CONFIGS = (
    ("Blender's viewport alone", False, None),
    ("+ Blender's wireframe overlay", True, None),
    *((f"+ SolidWire, {look}", False, look) for look in LOOKS),
)

# Redraw kinds: a static redraw, and redraws after an edit.
STATIC, VERTEX, STROKE, OBJECT = "static", "1 vertex moved", "1 % of vertices moved", "object moved"
REDRAWS = (STATIC, VERTEX, STROKE, OBJECT)

# A configuration whose first frame takes longer than this is timed in one
# round only (marked ¹ in the table).
SLOW_FRAME_MS = 1500.0


def default_look(scene) -> None:
    """The add-on's own defaults for every scene setting (tests' scenes
    switch the friendlier ones off), overlay shown."""
    props = scene.solidwire
    for name in props.bl_rna.properties.keys():  # noqa: SIM118 - an RNA collection, not a dict
        if name != "rna_type":
            props.property_unset(name)
    props.show_overlay = True


def build_scene(kind: str, level: int, size):
    """Suzanne subdivided ``level`` times (applied, or a Subdivision modifier
    at that viewport level), framed by a camera at ``size``."""
    scene = scenes.empty_scene(*size, transparent=False)
    # One anti-aliasing sample per redraw, as the viewport shows while a
    # user drags or sculpts: with the default 8-sample TAA, draw_view3d draws
    # all eight samples in one call after any change (+460 ms at 62k here)
    # and a static redraw only presents the accumulated image.
    bpy.context.preferences.system.viewport_aa = "OFF"
    default_look(scene)
    # The factory file's view transform (tests use Standard): what a user sees.
    scene.view_settings.view_transform = "AgX"
    obj = scenes.monkey(scene, "Suzanne", subdivisions=level)
    if kind == "applied":
        evaluated = obj.evaluated_get(bpy.context.evaluated_depsgraph_get())
        applied = bpy.data.meshes.new_from_object(evaluated)
        obj.modifiers.clear()
        obj.data = applied
    scenes.frame_object(scene, obj, azimuth=-75.0)
    obj.select_set(False)  # no selection outline: the object as a user looks at it
    return scene, obj


@dataclass
class Edits:
    """The edits made before a redraw (each undoes the previous one's
    direction, so the mesh does not drift)."""

    obj: object
    sign: float = 1.0

    def __post_init__(self):
        mesh = self.obj.data
        self.positions = np.empty((len(mesh.vertices), 3), dtype=np.float32)
        mesh.attributes["position"].data.foreach_get("vector", self.positions.ravel())
        # A sculpt stroke: the 1 % of vertices nearest to one vertex, pushed
        # along a direction (the whole block of positions written back).
        centre = self.positions[len(self.positions) // 3]
        count = max(1, len(self.positions) // 100)
        self.stroke = np.argsort(np.linalg.norm(self.positions - centre, axis=1))[:count]
        self.scale = float(np.ptp(self.positions, axis=0).max())
        edges = np.empty(len(mesh.edges) * 2, dtype=np.int32)
        mesh.edges.foreach_get("vertices", edges)
        ends = self.positions[edges.reshape(-1, 2)]
        # A quarter of the mean edge length: an interactive step (a drag, a
        # sculpt dab) small enough that Blender keeps most quads' splits; a
        # step that flips a split changes the triangles, not just positions.
        self.step = 0.25 * float(np.linalg.norm(ends[:, 0] - ends[:, 1], axis=1).mean())

    def make(self, redraw: str) -> None:
        self.sign = -self.sign
        mesh = self.obj.data
        step = self.step * self.sign
        if redraw == VERTEX:
            mesh.vertices[int(self.stroke[0])].co.z += step
            mesh.update()
        elif redraw == STROKE:
            self.positions[self.stroke, 2] += step
            mesh.attributes["position"].data.foreach_set("vector", self.positions.ravel())
            mesh.update()
        elif redraw == OBJECT:
            self.obj.location.x += 0.01 * self.scale * self.sign


def frame(viewport: HeadlessViewport, solidwire: bool, cpu: list | None = None) -> float:
    """One synchronised frame (ms). ``cpu``: gets the frame's CPU time (ms,
    every thread of the process: llvmpipe's rasteriser threads too), which
    load on a shared machine moves far less than the wall time."""
    start, start_cpu = time.perf_counter(), time.process_time()
    depsgraph = bpy.context.evaluated_depsgraph_get()
    viewport.draw_blender()
    if solidwire:
        viewport.draw_solidwire(depsgraph)
    viewport.sync()
    if cpu is not None:
        cpu.append((time.process_time() - start_cpu) * 1000.0)
    return (time.perf_counter() - start) * 1000.0


def configure(scene, viewport: HeadlessViewport, wireframe: bool, look) -> None:
    set_overlays(viewport.space, wireframe=wireframe)
    default_look(scene)
    for name, value in LOOKS.get(look, {}).items():
        setattr(scene.solidwire, name, value)


def measure(kind: str, level: int, size, repeats: int) -> tuple[dict, dict]:
    """{config: {redraw: best ms}} and facts about the scene."""
    scene, obj = build_scene(kind, level, size)
    viewport = HeadlessViewport(*size)
    try:
        viewport.look_through(scene)
        edits = Edits(obj)
        once = set()
        times = {name: {redraw: float("inf") for redraw in REDRAWS} for name, _w, _l in CONFIGS}
        cpu_times = {name: {redraw: float("inf") for redraw in REDRAWS} for name, _w, _l in CONFIGS}
        for turn in range(repeats):
            # Configurations take turns round by round, so that a burst of
            # load on a shared machine hits them alike.
            for name, wireframe, look in CONFIGS:
                if name in once:
                    continue
                configure(scene, viewport, wireframe, look)
                warm = frame(viewport, look is not None)  # untimed: batches / extraction for this configuration
                if look is not None:
                    # Untimed too: the overlay keeps its image from the second
                    # redraw with the same view and look on (passes._overlay_surface).
                    frame(viewport, True)
                if turn == 0 and warm > SLOW_FRAME_MS:
                    # Keeps the default run within minutes; a frame this
                    # long varies far less than the differences it shows.
                    once.add(name)
                for redraw in REDRAWS:
                    if redraw != STATIC:
                        edits.make(redraw)
                    spent = []
                    times[name][redraw] = min(times[name][redraw], frame(viewport, look is not None, spent))
                    cpu_times[name][redraw] = min(cpu_times[name][redraw], spent[0])
        evaluated = obj.evaluated_get(bpy.context.evaluated_depsgraph_get())
        facts = {
            "triangles": sum(len(p.vertices) - 2 for p in evaluated.data.polygons),
            "vertices": len(obj.data.vertices),
            "once": once,
            "cpu": cpu_times,
        }
    finally:
        viewport.free()
    return times, facts


def table(results) -> list[str]:
    """Markdown: one row per (scene, configuration), ms per redraw kind and
    the ratio to Blender's wireframe overlay frame of the same redraw."""
    lines = ["| mesh | configuration | " + " | ".join(REDRAWS) + " |", "|---|---|" + "---:|" * len(REDRAWS)]
    for (kind, level), (times, facts) in results.items():
        alone, wire = times[CONFIGS[0][0]], times[CONFIGS[1][0]]
        wire_cpu = facts["cpu"][CONFIGS[1][0]]
        label = (
            f"{LEVELS.get(level, level)} {kind} ({facts['triangles']:,} tris"
            + (f", cage {facts['vertices']:,} verts" if kind == "modifier" else "")
            + ")"
        )
        for name, _wireframe, look in CONFIGS:
            cells = []
            for redraw in REDRAWS:
                ms = times[name][redraw]
                if name == CONFIGS[0][0]:
                    cells.append(f"{ms:.0f}")
                elif look is None:
                    cells.append(f"{ms:.0f} (+{ms - alone[redraw]:.0f})")
                else:
                    cpu = facts["cpu"][name][redraw] / wire_cpu[redraw]
                    cells.append(f"{ms:.0f} (+{ms - alone[redraw]:.0f}; {ms / wire[redraw]:.2f}x; CPU {cpu:.2f}x)")
            mark = " ¹" if name in facts["once"] else ""
            lines.append(f"| {label} | {name}{mark} | " + " | ".join(cells) + " |")
            label = ""
    return lines


# -- where SolidWire's overlay frame goes -------------------------------------------

# The overlay's draw calls by their target's stage (draw_mod.DrawTarget): the
# deferred surface's record, region lines and resolve into the overlay's own
# targets (passes._overlay_surface), then its composite into Blender's
# buffer; a call without a stage is the direct surface pass (meshes sparse on
# screen, or every mesh where the record cannot serve), or the depth
# pre-pass before it where Blender's depth does not hold the surfaces.
STAGE_NAMES = {
    "visibility": "record (visibility stage)",
    "lines": "region lines",
    "resolve": "resolve",
    None: "direct surface pass",
}
COMPOSITE = "composite into Blender's buffer"


def _stage_name(kwargs) -> str:
    stage = (kwargs.get("target") or draw_mod.DrawTarget()).stage
    return STAGE_NAMES.get(stage, str(stage))


class OverlayProbe:
    """Splits SolidWire's overlay into its stages: each draw_mod.draw call
    (one per pass) is timed twice, the Python that records it and the GPU
    time a one-pixel read then waits for. Wraps the function from outside
    and puts it back on exit."""

    def __init__(self):
        self.calls: list[tuple[str, float, float]] = []

    def __enter__(self):
        self._original = draw_mod.draw
        self._composite = passes._composite_overlay_surface
        probe = self

        def timer(function, name_of):
            def timed(*args, **kwargs):
                start = time.perf_counter()
                result = function(*args, **kwargs)
                recorded = time.perf_counter()
                gpu.state.active_framebuffer_get().read_color(0, 0, 1, 1, 4, 0, "UBYTE")
                name = name_of(kwargs)
                probe.calls.append((name, (recorded - start) * 1000.0, (time.perf_counter() - recorded) * 1000.0))
                return result

            return timed

        draw_mod.draw = timer(self._original, _stage_name)
        passes._composite_overlay_surface = timer(self._composite, lambda _kw: COMPOSITE)
        return self

    def __exit__(self, *exc):
        draw_mod.draw = self._original
        passes._composite_overlay_surface = self._composite


def profile(kind: str, level: int, size, repeats: int) -> list[str]:
    """Markdown rows: SolidWire's overlay frame (default look) by stage, a
    static redraw and one after a vertex moved, best of ``repeats`` each."""
    scene, obj = build_scene(kind, level, size)
    viewport = HeadlessViewport(*size)
    rows = {}
    try:
        viewport.look_through(scene)
        edits = Edits(obj)
        set_overlays(viewport.space, wireframe=False)
        frame(viewport, True)
        for redraw in (STATIC, VERTEX):
            best = None
            for _ in range(repeats):
                if redraw != STATIC:
                    edits.make(redraw)
                start = time.perf_counter()
                depsgraph = bpy.context.evaluated_depsgraph_get()
                evaluated = time.perf_counter()
                viewport.draw_blender()
                viewport.sync()
                blender = time.perf_counter()
                with OverlayProbe() as probe, viewport.offscreen.bind():
                    gpu.state.viewport_set(0, 0, *size)
                    overlay_start = time.perf_counter()
                    stats = solidwire_addon.blender.overlay.draw_scene_overlay(
                        depsgraph, viewport.view, scene.solidwire.snapshot()
                    )
                    overlay_ms = (time.perf_counter() - overlay_start) * 1000.0
                stages = {
                    "depsgraph evaluation": (evaluated - start) * 1000.0,
                    "Blender's viewport (draw_view3d, synchronised)": (blender - evaluated) * 1000.0,
                    "SolidWire: gather + validate / extract (stats ms_extract)": stats["ms_extract"],
                    "SolidWire: upload (stats ms_upload)": stats["ms_upload"],
                }
                for name, cpu, gpu_ms in probe.calls:
                    key = f"SolidWire: {name}, Python / draw calls"
                    stages[key] = stages.get(key, 0.0) + cpu
                    key = f"SolidWire: {name}, GPU (waited for)"
                    stages[key] = stages.get(key, 0.0) + gpu_ms
                accounted = stats["ms_extract"] + stats["ms_upload"] + sum(c + g for _n, c, g in probe.calls)
                stages["SolidWire: the rest (display LUT, frame begin/end)"] = overlay_ms - accounted
                total = sum(stages.values())
                if best is None or total < best[0]:
                    best = (total, stages, stats)
            rows[redraw] = best
    finally:
        viewport.free()
    names = list(dict.fromkeys([*rows[STATIC][1], *rows[VERTEX][1]]))
    lines = [f"| stage | {STATIC} ms | after {VERTEX} ms |", "|---|---:|---:|"]
    for name in names:
        lines.append(f"| {name} | " + " | ".join(f"{rows[r][1].get(name, 0.0):.1f}" for r in (STATIC, VERTEX)) + " |")
    lines.append(
        "| **frame** (stages synchronised) | " + " | ".join(f"{rows[r][0]:.0f}" for r in (STATIC, VERTEX)) + " |"
    )
    stats = rows[VERTEX][2]
    lines += [
        "",
        (
            f"After the edit: meshes extracted {stats['meshes_extracted']}, repositioned "
            f"{stats.get('meshes_repositioned', 0)}, reused {stats['meshes_reused']}; "
            f"{stats['triangles_drawn']:,} triangles drawn."
        ),
    ]
    return lines


BEGIN, END = "<!-- bench_viewport: begin -->", "<!-- bench_viewport: end -->"


def write_report(path: str, text: str) -> None:
    """Put ``text`` between the BEGIN / END markers of ``path`` (the page's
    own words around them stay), or make the page of it alone."""
    block = f"{BEGIN}\n{text}\n{END}"
    try:
        with open(path, encoding="utf-8") as handle:
            page = handle.read()
    except FileNotFoundError:
        page = ""
    if BEGIN in page and END in page:
        page = page[: page.index(BEGIN)] + block + page[page.index(END) + len(END) :]
    else:
        page = block + "\n"
    with open(path, "w", encoding="utf-8") as handle:
        handle.write(page)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="62k triangles only")
    parser.add_argument("--levels", type=int, nargs="+", default=None, help="subdivision levels (default 3 4 5)")
    parser.add_argument("--kinds", nargs="+", default=list(KINDS), choices=KINDS)
    parser.add_argument("--size", default="1280x720")
    parser.add_argument(
        "--repeats", type=int, default=2, help="timed frames per configuration and redraw kind; the best counts"
    )
    parser.add_argument(
        "--profile", action="store_true", help="also SolidWire's overlay frame by stage (252k applied, default look)"
    )
    parser.add_argument(
        "--output",
        help="also write the report into this Markdown page, between its "
        "bench_viewport markers (the rest of the page stays)",
    )
    args = parser.parse_args()
    size = tuple(int(v) for v in args.size.lower().split("x"))
    levels = args.levels or ([3] if args.quick else sorted(LEVELS))
    solidwire_addon.register()
    started = time.perf_counter()
    load_before = os.getloadavg()[0]
    try:
        results = {}
        for level in levels:
            for kind in args.kinds:
                results[(kind, level)] = measure(kind, level, size, args.repeats)
                print(f"measured {kind} level {level} ({time.perf_counter() - started:.0f} s)", flush=True)
        lines = [
            f"## Viewport redraws at {size[0]} x {size[1]}",
            "",
            (
                f"Machine: {MACHINE} ({platform.machine()}, {os.cpu_count()} CPUs seen; load average "
                f"{load_before:.1f} at the start, {os.getloadavg()[0]:.1f} at the end); best of {args.repeats}; "
                f"GPU subdivision {'on' if bpy.context.preferences.system.use_gpu_subdivision else 'off'}. "
                "ms per synchronised frame (depsgraph evaluation, Blender's viewport, SolidWire's overlay, "
                "one-pixel read); (+ms) over Blender's viewport alone; SolidWire's x: its frame over the "
                "frame with Blender's wireframe overlay instead, and the same for the frames' CPU time (every "
                "thread of the process, llvmpipe's included: steadier than wall time on a loaded machine). "
                "¹: a configuration slower than "
                f"{SLOW_FRAME_MS / 1000:.1f} s a frame, timed in one round."
            ),
            "",
        ]
        lines += table(results)
        if args.profile:
            lines += [
                "",
                (f"### SolidWire's overlay frame by stage (252k applied, default look, best of {args.repeats})"),
                "",
            ]
            lines += profile("applied", 4, size, args.repeats)
        lines.append("")
        lines.append(f"(run took {time.perf_counter() - started:.0f} s)")
        text = "\n".join(lines)
        print(text, flush=True)
        if args.output and args.quick:
            # A 62k-only table would replace the page's full one.
            print(f"(--quick: {args.output} left as it is)")
        elif args.output:
            write_report(args.output, text)
    finally:
        solidwire_addon.unregister()


if __name__ == "__main__":
    main()
