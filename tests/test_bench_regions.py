"""The regions benchmark's README tables (scripts/bench_regions.py --runs):
several fresh processes, each ratio their median with its range, taken
from what each run measured."""

from __future__ import annotations

import json
import os
import statistics
import subprocess
import sys
from pathlib import Path

import bpy

from scripts import bench_regions

ROOT = Path(__file__).resolve().parents[1]


def test_runs_give_each_ratio_s_median_and_range_over_fresh_processes(tmp_path):
    path = tmp_path / "runs.json"
    args = ["--runs", "2", "--levels", "2", "--size", "96x54", "--repeats", "1", "--json", str(path)]
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    done = subprocess.run(
        [sys.executable, "-m", "scripts.bench_regions", *args],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    assert done.returncode == 0, done.stderr[-2000:]
    runs = json.loads(path.read_text())
    assert len(runs) == 2
    assert runs[0]["levels"]["2"]["triangles"] == runs[1]["levels"]["2"]["triangles"] > 0
    assert "96 x 54" in runs[0]["machine"] and bpy.app.version_string in runs[0]["machine"]
    assert runs[0]["conditions"] == "overlay in solid shading"
    summary = done.stdout[done.stdout.index(runs[0]["machine"]) :].rstrip("\n")
    assert summary == bench_regions.summary_tables(runs)
    # The level's row: each measure the median of the two runs' ratios, with their range.
    row = next(line for line in summary.splitlines() if line.startswith("| 2 ("))
    for (key, _title), cell in zip(bench_regions.MEASURES, row.strip("| ").split(" | ")[1:]):
        ratios = [run["levels"]["2"]["cage"][key] / run["levels"]["2"]["all"][key] for run in runs]
        assert cell == f"{statistics.median(ratios):.2f}× ({min(ratios):.2f}–{max(ratios):.2f})", key
    looks = [line for line in summary.splitlines() if line.startswith(("| angle", "| classes"))]
    assert [line.split(" | ")[0] for line in looks] == ["| angle", "| classes", "| angle + classes"]


def test_each_run_is_given_the_options_but_its_count_and_file():
    argv = ["--runs", "16", "--levels", "2", "3", "--json=all.json", "--runs=4", "--size", "640x360", "--json", "x"]
    assert bench_regions._child_argv(argv) == ["--levels", "2", "3", "--size", "640x360"]
