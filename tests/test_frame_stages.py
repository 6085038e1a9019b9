"""The benchmark's stage probe (scripts/frame_stages.py): it times each stage
of a real F12 frame, leaves the image as it is, and puts every function it
wrapped back."""

from __future__ import annotations

import bpy

import solidwire_addon
from scripts import frame_stages
from solidwire_addon.blender import engine
from solidwire_addon.core import draw as draw_mod
from tests.support import scenes


def test_probe_times_every_stage_and_restores_the_add_on(tmp_path):
    scene = scenes.empty_scene(96, 72, transparent=False)
    scenes.monkey(scene, subdivisions=2)
    scenes.add_camera(scene, location=(2.0, -4.0, 1.5), target=(0.0, 0.0, 0.0))
    plain = scenes.render_to_file(scene, tmp_path / "plain.png")
    originals = (draw_mod.draw, engine.write_pass, engine.composite_film)
    with frame_stages.StageProbe() as probe:
        probed = scenes.render_to_file(scene, tmp_path / "probed.png")
        probe.end_frame(1000.0, solidwire_addon.stats())
    assert (draw_mod.draw, engine.write_pass, engine.composite_film) == originals
    assert (probed == plain).all()
    (frame,) = probe.frames
    surface = frame.get(frame_stages.DIRECT, 0.0) + frame.get(frame_stages.RESOLVE, 0.0)
    assert surface > 0.0
    for stage in (frame_stages.READBACK, frame_stages.FILM, frame_stages.TRANSFER, frame_stages.HAND_OVER):
        assert frame[stage] > 0.0, stage
    assert abs(sum(frame.values()) - 1000.0) < 1e-6  # "the rest" closes the frame
    rows = probe.table(900.0)
    assert rows[-1].startswith("| unprobed frame") and any(frame_stages.READBACK in row for row in rows)
