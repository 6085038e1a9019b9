"""Error of the exact path against the float64 reference (SPEC 1.5) on the
core test scenes, as a Markdown table for the manual (docs/dev/accuracy.md).

    .venv/bin/python -m scripts.accuracy_report [--size 200x150] [--edges]

Renders each scene of tests/test_render_reference.py through the SOLIDWIRE
engine to a 16-bit PNG (so the numbers include file quantisation) and
compares its alpha with the reference's line intensity. ``--edges``: the
edge-selection looks instead (cage edges, edge angle, regions, edge
classes, density fade; image model §3.4-§3.7).
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
os.environ.setdefault("BLENDER_USER_RESOURCES", tempfile.mkdtemp(prefix="solidwire-user-"))

import solidwire_addon
from tests import test_edge_selection as selection
from tests import test_render_reference as cases
from tests.support import (
    accuracy,
    scenes,
)

# The edge-selection looks: (name, settings, scene builder).
EDGE_CASES = (
    ("cage edges (Suzanne, level 2)", dict(use_cage_edges=True, thickness=1.0), selection._subdivided_monkey),
    (
        "cage edges + edge angle 25°",
        dict(use_cage_edges=True, edge_angle=0.436, thickness=1.0),
        selection._subdivided_monkey,
    ),
    (
        "cage edges + density fade, dashed diagonals",
        dict(
            use_cage_edges=True, use_density_fade=True, density_fade_length=30.0, diagonal_mode="DASHED", thickness=1.0
        ),
        selection._subdivided_monkey,
    ),
    ("edge angle 20°, one region (grid)", dict(edge_angle=0.349, thickness=3.0), None),
    ("edge classes (5 styles, patterns)", selection.CLASS_LOOK, selection._marked_cube),
)


def _grid(scene):
    scenes.grid(scene, x_segments=4, y_segments=4, size=3.0)
    scenes.add_camera(scene, location=(0.4, -3.0, 3.6), target=(0, 0, 0))


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", default="200x150", help="render size WxH")
    parser.add_argument("--edges", action="store_true", help="the edge-selection looks")
    args = parser.parse_args(argv)
    width, height = (int(v) for v in args.size.lower().split("x"))
    solidwire_addon.register()
    rows = []
    try:
        with tempfile.TemporaryDirectory(prefix="solidwire-accuracy-") as folder:
            if args.edges:
                for k, (name, settings, build) in enumerate(EDGE_CASES):
                    scene = scenes.empty_scene(width, height, **settings)
                    (build or _grid)(scene)
                    rows.append(accuracy.measure(scene, f"edges{k}", Path(folder)))
                    rows[-1]["name"] = name
            else:
                for name, build in cases.SCENES.items():
                    scene = scenes.empty_scene(width, height, thickness=1.5)
                    build(scene)
                    rows.append(accuracy.measure(scene, name, Path(folder)))
    finally:
        solidwire_addon.unregister()
    print(f"| scene ({width} x {height}) | mean abs dI | p99.9 | max | px > 2/255 | silhouette px |")
    print("|---|---:|---:|---:|---:|---:|")
    for r in rows:
        print(
            f"| {r['name']} | {r['mean']:.1e} | {r['p999']:.1e} | {r['max']:.1e} | {r['over_2_255']} | {r['silhouette_pixels']} |"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
