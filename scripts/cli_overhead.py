"""Per-frame cost of the command line against Blender's own animation render
with the SolidWire engine (``blender -b SCENE.blend -E SOLIDWIRE -a``), on
the same frames of the same scene, and where the command line's time goes.

    python scripts/cli_overhead.py [--frames 40] [--repeats 5] [--size 640 360]

Each measurement renders a short and a long range into a fresh folder and
takes the difference, so the file load and other fixed costs drop out; the
two paths alternate and the median is reported, because a shared machine's
load changes from one second to the next. Results are printed as a
Markdown table (docs/dev/command-line-overhead.md holds one).
"""

from __future__ import annotations

import argparse
import contextlib
import cProfile
import io
import os
import pstats
import shutil
import statistics
import sys
import tempfile
import time
from pathlib import Path

import bpy

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

import solidwire_addon
from solidwire_addon.blender import cli


def build_scene(path: Path, size: tuple[int, int]) -> Path:
    from tests.support import scenes

    scene = scenes.empty_scene(*size)
    monkey = scenes.monkey(scene, subdivisions=1)
    scenes.cube(scene, "Cube", size=1.0, location=(2.2, 0.8, -0.5))
    scenes.add_camera(scene)
    for frame, z in ((1, 0.0), (200, 6.28)):
        monkey.rotation_euler.z = z
        monkey.keyframe_insert("rotation_euler", frame=frame)
    scene.frame_start, scene.frame_end = 1, 200
    scene.render.image_settings.file_format = "PNG"
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    return path


@contextlib.contextmanager
def quiet():
    """Blender's "Saved:" lines come from C: silence file descriptor 1."""
    sys.stdout.flush()
    saved = os.dup(1)
    with open(os.devnull, "w") as null:
        os.dup2(null.fileno(), 1)
        try:
            with contextlib.redirect_stdout(io.StringIO()):
                yield
        finally:
            sys.stdout.flush()
            os.dup2(saved, 1)
            os.close(saved)


def engine_anim(blend: Path, out: Path, frames: int) -> float:
    bpy.ops.wm.open_mainfile(filepath=str(blend))
    scene = bpy.context.scene
    scene.render.engine = "SOLIDWIRE"
    scene.render.filepath = str(out / "f_####")
    scene.frame_start, scene.frame_end = 1, frames
    start = time.perf_counter()
    bpy.ops.render.render(animation=True, scene=scene.name)
    return time.perf_counter() - start


def workbench_anim(blend: Path, out: Path, frames: int) -> float:
    """Blender's Workbench on the same frames: flat lighting, single colour
    (its cheapest look), as ``blender -b SCENE.blend -E BLENDER_WORKBENCH -a``."""
    bpy.ops.wm.open_mainfile(filepath=str(blend))
    scene = bpy.context.scene
    scene.render.engine = "BLENDER_WORKBENCH"
    scene.display.shading.light = "FLAT"
    scene.display.shading.color_type = "SINGLE"
    scene.render.filepath = str(out / "f_####")
    scene.frame_start, scene.frame_end = 1, frames
    start = time.perf_counter()
    bpy.ops.render.render(animation=True, scene=scene.name)
    return time.perf_counter() - start


def command_line(blend: Path, out: Path, frames: int, *extra: str) -> float:
    start = time.perf_counter()
    code = cli.main([str(blend), "-o", str(out / "f_####.png"), "-s", "1", "-e", str(frames), *extra])
    if code:
        raise SystemExit(f"the command line failed ({code})")
    return time.perf_counter() - start


def frame_by_frame(blend: Path, out: Path, frames: int) -> float:
    """The command line's render-per-frame path (taken when overwriting is
    off, with placeholders, for --over): --no-overwrite into an empty folder."""
    return command_line(blend, out, frames, "--no-overwrite")


def per_frame(run, blend: Path, work: Path, short: int, long: int) -> float:
    times = []
    for frames in (short, long):
        out = work / f"{run.__name__}-{frames}"
        shutil.rmtree(out, ignore_errors=True)
        with quiet():
            times.append(run(blend, out, frames))
        shutil.rmtree(out, ignore_errors=True)
    return (times[1] - times[0]) / (long - short)


STAGES = {
    "render operator(s), in all": "<built-in method _bpy.ops.call>",
    "SolidWire engine, in all": "engine.py:render",
    "engine: set-up (camera, settings, gather)": "engine.py:__init__",
    "engine: draw passes": "passes.py:render_passes",
    "engine: read back pixels": "targets.py:read",
    "engine: hand pixels to Blender": "engine.py:_write",
    "rename into place (os.replace)": "<built-in method posix.replace>",
    # cProfile does not time bpy's own functions (scene.frame_set) apart from
    # their caller: they are in this line.
    "command line's own Python (progress, stats, checks, frame_set)": "cli.py",
}
DERIVED = (
    "Blender: render depsgraph, render result, PNG encode and write",
    "render operator(s), in all",
    "SolidWire engine, in all",
)


def _matches(key: tuple, needle: str) -> bool:
    filename, _line, name = key
    if filename == "~":
        return needle in name
    if needle.endswith(".py"):
        return filename.endswith("/" + needle)
    return f"{filename.rsplit('/', 1)[-1]}:{name}" == needle  # file:function


def stage_breakdown(run, blend: Path, work: Path, frames: int) -> dict:
    out = work / "profile"
    shutil.rmtree(out, ignore_errors=True)
    profile = cProfile.Profile()
    with quiet():
        profile.enable()
        run(blend, out, frames)
        profile.disable()
    shutil.rmtree(out, ignore_errors=True)
    stats = pstats.Stats(profile).stats
    result = {}
    for label, needle in STAGES.items():
        # Inclusive time, except for the command line's own Python, which is
        # its functions' own time (tottime) without what they call.
        column = 2 if needle == "cli.py" else 3
        total = sum(entry[column] for key, entry in stats.items() if _matches(key, needle))
        result[label] = total / frames * 1000.0
    label, whole, part = DERIVED
    result[label] = result[whole] - result[part]
    return result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--frames", type=int, default=40)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--size", type=int, nargs=2, default=(640, 360))
    args = parser.parse_args()
    solidwire_addon.register()
    try:
        with tempfile.TemporaryDirectory(prefix="solidwire-overhead-") as folder:
            work = Path(folder)
            with quiet():
                blend = build_scene(work / "scene.blend", tuple(args.size))
            engine, command, single, workbench = [], [], [], []
            for _ in range(args.repeats):
                workbench.append(per_frame(workbench_anim, blend, work, 5, 5 + args.frames))
                engine.append(per_frame(engine_anim, blend, work, 5, 5 + args.frames))
                command.append(per_frame(command_line, blend, work, 5, 5 + args.frames))
                single.append(per_frame(frame_by_frame, blend, work, 5, 5 + args.frames))
            stages = {
                name: stage_breakdown(run, blend, work, args.frames)
                for name, run in (("animation", command_line), ("frame by frame", frame_by_frame))
            }
    finally:
        solidwire_addon.unregister()
    e, c, f, w = (statistics.median(values) * 1000 for values in (engine, command, single, workbench))
    width, height = args.size
    print(f"| path ({width}x{height}, {args.frames} frames, median of {args.repeats}) | ms per frame | vs `-a` |")
    print("|---|---|---|")
    print(f"| `-E SOLIDWIRE -a` (Blender's animation render) | {e:.1f} | 1.00 |")
    print(f"| command line, `-s 1 -e N` (runs drawn by Blender's animation render) | {c:.1f} | {c / e:.2f} |")
    print(f"| command line, frame by frame (`--no-overwrite`, placeholders, `--over`) | {f:.1f} | {f / e:.2f} |")
    print(f"| for scale: Workbench, flat lighting (`-E BLENDER_WORKBENCH -a`) | {w:.1f} | {w / e:.2f} |")
    print()
    print("| stage (cProfile, so slower than above; inclusive) | animation | frame by frame |")
    print("|---|---|---|")
    for label in [*STAGES, DERIVED[0]]:
        print(f"| {label} | {stages['animation'][label]:.2f} | {stages['frame by frame'][label]:.2f} |")


if __name__ == "__main__":
    main()
