"""Soak (opt-in, marked slow): a 1000-frame background animation render
keeps resident memory flat and the GPU mesh cache bounded.

    .venv/bin/python -m pytest tests/test_soak.py --run-slow -s
    (make soak; SOLIDWIRE_SOAK_FRAMES=N for another length)

Every frame deforms a mesh (wave modifier) and moves an object and the
camera, so meshes are re-extracted and re-uploaded every frame. A
``render_post`` handler samples RSS and the add-on's stats; the figures go to
tests/output/soak.json and the test's output.
"""

from __future__ import annotations

import json
import os

import bpy
import pytest

import solidwire_addon
from tests.support import scenes

FRAMES = int(os.environ.get("SOLIDWIRE_SOAK_FRAMES", "1000"))
WARMUP = min(100, FRAMES // 5)  # allocator and caches settle first
RSS_GROWTH_LIMIT_MB = 32.0

pytestmark = pytest.mark.slow  # make soak


def _rss_mb() -> float:
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2**20


def _animated_scene(frames: int):
    scene = scenes.empty_scene(
        96, 72, thickness=1.5, diagonal_mode="DASHED", use_fade=True, fade_start=4.0, fade_end=14.0
    )
    scene.frame_start, scene.frame_end = 1, frames
    monkey = scenes.monkey(scene, "Waving", subdivisions=1)
    wave = monkey.modifiers.new("Wave", "WAVE")
    wave.height, wave.width, wave.speed = 0.2, 0.6, 0.05
    cube = scenes.cube(scene, "Spinning", size=1.0, location=(2.2, 0.0, 0.0))
    cube.keyframe_insert("rotation_euler", frame=1)
    cube.rotation_euler = (0.0, 0.0, 31.4)
    cube.keyframe_insert("rotation_euler", frame=frames)
    scenes.grid(scene, "Floor", x_segments=12, y_segments=12, size=10.0, location=(0, 0, -1))
    camera = scenes.add_camera(scene, location=(4.0, -6.0, 2.5), target=(0.5, 0.0, 0.0))
    camera.keyframe_insert("location", frame=1)
    camera.location = (6.0, -3.0, 3.5)
    camera.keyframe_insert("location", frame=frames)
    return scene


def test_soak_animation_memory_is_flat(tmp_path, output_dir):
    scene = _animated_scene(FRAMES)
    scene.render.filepath = str(tmp_path / "frame_####")
    scene.render.image_settings.file_format = "PNG"
    samples = []

    def sample(_scene, _depsgraph=None):
        stats = solidwire_addon.stats()
        samples.append(
            {
                "frame": _scene.frame_current,
                "rss_mb": _rss_mb(),
                "meshes_cached": stats.get("meshes_cached", 0),
                "gpu_bytes": stats.get("gpu_bytes", 0),
                "meshes_extracted": stats.get("meshes_extracted", 0),
            }
        )

    rss_before = _rss_mb()
    bpy.app.handlers.render_post.append(sample)
    try:
        bpy.ops.render.render(animation=True, scene=scene.name)
    finally:
        bpy.app.handlers.render_post.remove(sample)

    assert len(samples) == FRAMES
    written = sorted(tmp_path.glob("frame_*.png"))
    assert len(written) == FRAMES
    rss = [s["rss_mb"] for s in samples]
    settled = rss[WARMUP:]
    gpu = [s["gpu_bytes"] for s in samples]
    summary = {
        "frames": FRAMES,
        "rss_before_mb": round(rss_before, 1),
        "rss_first_frame_mb": round(rss[0], 1),
        "rss_after_warmup_mb": round(settled[0], 1),
        "rss_end_mb": round(rss[-1], 1),
        "rss_peak_mb": round(max(rss), 1),
        "rss_growth_after_warmup_mb": round(rss[-1] - settled[0], 1),
        "gpu_bytes_first": gpu[0],
        "gpu_bytes_max": max(gpu),
        "gpu_bytes_end": gpu[-1],
        "meshes_cached_max": max(s["meshes_cached"] for s in samples),
        "meshes_extracted_per_frame_median": sorted(s["meshes_extracted"] for s in samples)[FRAMES // 2],
    }
    print("\nSOAK", json.dumps(summary))
    (output_dir / "soak.json").write_text(
        json.dumps({"summary": summary, "samples": samples[:: max(FRAMES // 100, 1)]}, indent=1)
    )

    # The deforming mesh really is re-extracted every frame (else: no soak).
    assert summary["meshes_extracted_per_frame_median"] >= 1
    # Memory flat: what grows after warm-up must stay small...
    assert summary["rss_growth_after_warmup_mb"] < RSS_GROWTH_LIMIT_MB, summary
    assert max(settled) - settled[0] < RSS_GROWTH_LIMIT_MB * 1.5, summary
    # ...and the GPU cache holds one entry per drawn mesh, never more.
    assert summary["meshes_cached_max"] <= 3, summary
    assert summary["gpu_bytes_max"] <= 2 * max(gpu[:WARMUP]), summary
