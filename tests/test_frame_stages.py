"""The benchmark's stage probe (scripts/frame_stages.py): it times each stage
of a real F12 frame, leaves the image as it is, and puts every function it
wrapped back."""

from __future__ import annotations

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


def test_probe_times_the_region_lines_pass_as_its_own_stage(tmp_path):
    """The cage look draws its regions' lines in a pass of their own, into a
    depth image alone: the probe names it and waits for it there, instead
    of folding it into the surface drawn directly (and its time into the
    stage that reads its image)."""
    scene = scenes.empty_scene(96, 72, transparent=False, use_cage_edges=True)
    obj = scenes.monkey(scene)
    obj.modifiers.new("Subdivision", "SUBSURF").levels = 2
    obj.modifiers["Subdivision"].render_levels = 2
    scenes.add_camera(scene, location=(2.0, -4.0, 1.5), target=(0.0, 0.0, 0.0))
    with frame_stages.StageProbe() as probe:
        scenes.render_to_file(scene, tmp_path / "cage.png")
        probe.end_frame(1000.0, solidwire_addon.stats())
    (frame,) = probe.frames
    assert frame.get(frame_stages.REGION_LINES, 0.0) > 0.0, frame
    assert any(frame_stages.REGION_LINES in row for row in probe.table(900.0))


def test_bare_draw_covers_what_solidwire_draws(tmp_path):
    """The benchmark's floor (frame_stages.bare_draw): the same triangles
    from the same camera, so the same pixels up to float32 rounding of the
    matrices at the silhouette."""
    scene = scenes.empty_scene(96, 72)
    obj = scenes.monkey(scene, subdivisions=2)
    scenes.add_camera(scene, location=(2.0, -4.0, 1.5), target=(0.0, 0.0, 0.0))
    rgba = scenes.render_to_file(scene, tmp_path / "solidwire.png")
    covered = int((rgba[..., 3] > 0.0).sum())
    milliseconds, bare_covered = frame_stages.bare_draw(scene, obj, (96, 72), repeats=2)
    assert milliseconds > 0.0
    assert covered > 1000
    assert abs(bare_covered - covered) <= 0.01 * covered, (bare_covered, covered)


def test_engines_table_lists_every_engine_the_floor_and_the_stages():
    """scripts.bench_engines (also ``python -m scripts.bench --engines``):
    one row per engine with a steady time, the bare-draw floor, then
    SolidWire's frame stage by stage."""
    from scripts import bench_engines

    lines = bench_engines.run((64, 48), subdivisions=1, repeats=1, freestyle=False)
    rows = {line.split(" | ")[0].lstrip("| "): line for line in lines if line.startswith("| ")}
    for _name, label in bench_engines.ENGINES:
        cells = rows[label].strip("| ").split(" | ")
        assert float(cells[1]) > 0.0 and float(cells[3]) > 0.0, rows[label]
    assert any(label.startswith("floor: bare indexed draw") for label in rows)
    assert any(line.startswith("SolidWire's first render:") and "MiB of memory touched" in line for line in lines)
    assert any(frame_stages.READBACK in line for line in lines)
    assert lines[-2].startswith("| unprobed frame")
