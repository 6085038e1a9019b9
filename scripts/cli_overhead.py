"""Per-frame cost of the command line against Blender's own animation render
with the SolidWire engine (``blender -b SCENE.blend -E SOLIDWIRE -a``), on
the same frames of the same scene, and where the command line's time goes.

    python scripts/cli_overhead.py [--frames 40] [--repeats 5] [--size 640 360]

Each measurement renders a short and a long range into a fresh folder and
takes the difference, so the file load and other fixed costs drop out; the
two paths alternate and the median is reported, because a shared machine's
load changes from one second to the next. Results are printed as a
Markdown table (docs/command-line-overhead.md holds one).
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

import solidwire_addon  # noqa: E402
from solidwire_addon.blender import cli  # noqa: E402


def build_scene(path: Path, size: tuple[int, int]) -> Path:
    from tests.support import scenes

    scene = scenes.empty_scene(*size)
    monkey = scenes.monkey(scene)
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


def command_line(blend: Path, out: Path, frames: int) -> float:
    start = time.perf_counter()
    code = cli.main([str(blend), "-o", str(out / "f_####.png"), "-s", "1", "-e", str(frames)])
    if code:
        raise SystemExit(f"the command line failed ({code})")
    return time.perf_counter() - start


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
    "render operator (all of Blender's render of a frame)": "<built-in method _bpy.ops.call>",
    "- SolidWire engine, in all": "engine.py:210(render)",
    "  - set-up (camera, settings)": "engine.py:88(__init__)",
    "  - draw passes": "passes.py:89(render_passes)",
    "  - read back pixels": "targets.py:110(read)",
    "  - hand pixels to Blender": "engine.py:245(_write)",
    "scene.frame_set": "frame_set",
    "rename into place (os.replace)": "<built-in method posix.replace>",
    "progress, stats, checks (command line's own Python)": "cli.py",
}


def _matches(key: tuple, needle: str) -> bool:
    filename, line, name = key
    if filename == "~":
        return needle in name
    if needle.endswith(".py"):
        return filename.endswith("/" + needle)
    return f"{filename.rsplit('/', 1)[-1]}:{line}({name})" == needle


def stage_breakdown(blend: Path, work: Path, frames: int) -> dict:
    out = work / "profile"
    shutil.rmtree(out, ignore_errors=True)
    profile = cProfile.Profile()
    with quiet():
        profile.enable()
        command_line(blend, out, frames)
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
            engine, command = [], []
            for _ in range(args.repeats):
                engine.append(per_frame(engine_anim, blend, work, 5, 5 + args.frames))
                command.append(per_frame(command_line, blend, work, 5, 5 + args.frames))
            stages = stage_breakdown(blend, work, args.frames)
    finally:
        solidwire_addon.unregister()
    e, c = statistics.median(engine) * 1000, statistics.median(command) * 1000
    width, height = args.size
    print(f"| path ({width}x{height}, median of {args.repeats}) | ms per frame |")
    print("|---|---|")
    print(f"| `-E SOLIDWIRE -a` (Blender's animation render) | {e:.1f} |")
    print(f"| command line `-s 1 -e N` | {c:.1f} |")
    print(f"| ratio | {c / e:.2f} |")
    print()
    print("| command line stage (cProfile, inclusive) | ms per frame |")
    print("|---|---|")
    for label, value in stages.items():
        print(f"| {label} | {value:.2f} |")


if __name__ == "__main__":
    main()
