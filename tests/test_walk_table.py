"""The walk-table pre-pass (shaders/walk_table_frag.glsl): where a direct
draw walks its regions' lines (under hidden lines, meshes whose regions are
not peeled), a fragment per triangle picks the segments of its block within
reach, and the draw reads those picks instead of choosing them at its
provoking corner. Same selection code, so the image is the same to the
bit, in a render (every pass) and in the viewport overlay. The hidden-line
draw then leaves out the region triangles it picked nothing for
(options.DrawOptions.drop_lineless_triangles), again the same image. The
accuracy of the walked hidden lines against the float64 reference is
tests/test_regions.py's."""

from __future__ import annotations

import math

import bpy
import gpu
import numpy as np
import pytest

from solidwire_addon.blender import runtime
from solidwire_addon.blender.views import camera_view
from solidwire_addon.core import draw, shaders, targets
from solidwire_addon.core.options import DrawOptions
from tests.support import scenes
from tests.test_overlay import FakeViewport


def _walked_scene(width: int, height: int, **look):
    """A second Suzanne under a level-2 Subdivision Surface, with cage edges
    and hidden lines (regions of 16 lines on average: walked, not peeled),
    and a sheet under a level-3 one (32), beside a floor that crosses the
    near plane."""
    scene = scenes.empty_scene(width, height, use_cage_edges=True, use_hidden_lines=True, **look)
    scenes.near_plane_scene(scene)
    monkey = scenes.monkey(scene, "Walked", location=(-0.2, 1.6, 0.6), rotation=(0.2, 0.0, 0.6))
    monkey.modifiers.new("Subdivision", "SUBSURF").levels = 2
    for edge in monkey.data.edges[:60]:
        edge.use_seam = edge.index % 2 == 0
        edge.use_edge_sharp = edge.index % 2 == 1
    # A wavy sheet behind the other Suzanne: its faces numbered row by row,
    # so a move of one corner reaches few of its blocks of triangles (an
    # edit's partial redraw).
    sheet = scenes.grid(scene, "Sheet", x_segments=12, y_segments=12, size=2.5)
    sheet.location, sheet.rotation_euler = (0.6, 7.5, 1.2), (1.45, 0.0, 0.1)
    for vertex in sheet.data.vertices:
        vertex.co.z += 0.15 * math.sin(3.0 * vertex.co.x)
    sheet.modifiers.new("Subdivision", "SUBSURF").levels = 3
    return scene


_SHIPPED_MIN_LINES = draw.WALK_TABLE_MIN_LINES


def _counting(monkeypatch, table_on: bool, drop_lineless: bool = False) -> list:
    """Turn the pre-pass on (or off), and with it the hidden-line draw's
    leaving out of the triangles it picked nothing for, and count the draws
    that asked for it: each one's mesh, triangle ranges (None: every
    triangle) and whether it kept the table walked before for the same key
    (draw._walk_key) instead of walking."""
    runs = []
    real = draw._run_walk_table

    def counted(*args, **kwargs):
        mesh = args[0]
        before = mesh.walk_key
        table = real(*args, **kwargs)
        runs.append((mesh, args[5] if len(args) > 5 else None, before is not None and mesh.walk_key is before))
        return table

    monkeypatch.setattr(draw, "WALK_TABLE_MIN_LINES", _SHIPPED_MIN_LINES if table_on else 10**9)
    monkeypatch.setattr(runtime, "options", DrawOptions(drop_lineless_triangles=drop_lineless))
    monkeypatch.setattr(draw, "_run_walk_table", counted)
    return runs


def _assert_same_hidden_lines(image, expected, reordered: bool, message: str = "") -> None:
    """The same image to the bit; where the picked triangles were drawn on
    their own (``reordered``), their hidden lines were blended after the
    others': "over" in one colour is order-free, its float32 rounding is
    not (a few units in the last place)."""
    if reordered:
        np.testing.assert_allclose(image, expected, rtol=0.0, atol=2.0**-20, err_msg=message)
    else:
        np.testing.assert_array_equal(image, expected, err_msg=message)


LOOKS = {
    "plain": {},
    # Every style's reach, the density fade's chain lengths, the angle's regions.
    "classes, fade, angle": dict(
        use_seam_edges=True, use_sharp_edges=True, use_density_fade=True, edge_angle=0.35, hidden_period=6.0
    ),
}


@pytest.mark.parametrize("look", [*LOOKS, "floor walked"])
def test_walk_table_gives_the_same_render(look, output_dir, monkeypatch):
    """Every pass the same, with the picks from the table (which tests
    groups of segments by their window boxes first) and with the
    hidden-line draw leaving out the triangles with none. "floor walked":
    the floor that crosses the near plane is walked too, so some groups
    have ends behind it (their box is the whole plane) and some triangles
    walk their whole block."""
    scene = _walked_scene(240, 180, **LOOKS.get(look, {}))
    if look == "floor walked":
        scene.objects["Floor"].modifiers.new("Subdivision", "SUBSURF").levels = 2
    runs = _counting(monkeypatch, table_on=False)
    at_corners = scenes.render_multilayer_exr(scene, output_dir / f"walk_off_{look}.exr")
    assert runs == []
    assert "lineless_triangles_left_out" not in runtime.stats()
    for drop_lineless in (False, True):
        runs = _counting(monkeypatch, table_on=True, drop_lineless=drop_lineless)
        from_table = scenes.render_multilayer_exr(scene, output_dir / f"walk_on_{look}_{drop_lineless}.exr")
        assert runs, "the pre-pass never ran: the walked mesh is not walked here any more"
        if look == "floor walked":
            assert {mesh.triangle_count for mesh, _ranges, _kept in runs} >= {
                len(obj.evaluated_get(bpy.context.evaluated_depsgraph_get()).data.loop_triangles)
                for obj in (scene.objects["Floor"],)
            }
        stats = runtime.stats()
        assert ("lineless_triangles_left_out" in stats) == drop_lineless
        left_out = stats.get("lineless_triangles_left_out", 0)
        if look == "plain":  # (under the denser lines of the other look every triangle has one near)
            assert (left_out > 0) == drop_lineless
        # Reading the picks back, the draw measures most triangles' picks
        # alone, in a draw of their own (ShaderVariant.walk_picks_only).
        assert (stats.get(draw.WALK_PICKS_DRAWN, 0) > 0) == drop_lineless
        assert at_corners.keys() == from_table.keys()
        for name, values in at_corners.items():
            _assert_same_hidden_lines(from_table[name], values, drop_lineless, f"{name}, dropped {left_out}")
    # Lines show at all (the comparison is not of two empty images).
    assert (from_table["ViewLayer.Combined.A"] > 0).mean() > 0.02


def test_walk_table_gives_the_same_overlay(monkeypatch):
    """The first redraw draws directly, the second (the same key) into the
    images the overlay keeps (passes._overlay_kept_frame), the third after
    a vertex moved all of them again, the fourth (the drag's next step)
    only the triangles that reach what it changed, the pre-pass too: each
    the same either way."""
    scene = _walked_scene(200, 150)
    walked = scene.objects["Sheet"]
    vertex = walked.data.vertices[0]
    start = tuple(vertex.co)

    def overlay_images(table_on: bool, drop_lineless: bool = False):
        runs = _counting(monkeypatch, table_on, drop_lineless)
        monkeypatch.setattr(targets, "_overlay_targets", {})  # no image kept from before
        vertex.co = start
        walked.data.update()
        images = []
        for redraw in range(4):
            if redraw >= 2:  # an edit, then its next step: the vertex moves
                vertex.co.z += 0.02
                walked.data.update()
            depsgraph = bpy.context.evaluated_depsgraph_get()
            # What Blender's own viewport leaves behind (its vertices' point
            # size): the groups' points (walk_groups) must still be one texel each.
            gpu.state.program_point_size_set(False)
            gpu.state.point_size_set(4.0)
            viewport = FakeViewport(200, 150)
            viewport.draw_overlay(depsgraph, camera_view(scene, depsgraph, (200, 150)), scene.solidwire.snapshot())
            images.append(viewport.rgba())
            left_out.append(runtime.stats().get("lineless_triangles_left_out", 0))
            picked.append(runtime.stats().get(draw.WALK_PICKS_DRAWN, 0))
        return runs, images

    left_out, picked = [], []
    runs, at_corners = overlay_images(False)
    assert runs == [] and not any(left_out) and not any(picked)
    for drop_lineless in (False, True):
        left_out, picked = [], []
        runs, from_table = overlay_images(True, drop_lineless)
        assert len(runs) >= 4
        # The edit's pre-pass drew the triangles the edit's draw drew alone.
        mesh, edit_ranges, _kept = runs[-1]
        assert edit_ranges is not None and 0 < edit_ranges[1].sum() < mesh.triangle_count
        # The kept images' two hidden-line draws (one into each image, each
        # in two with the picks read back: its picked triangles apart) walk
        # once: the others keep the first's table, inside the same ranges.
        edit_runs = [(ranges, kept) for walked_mesh, ranges, kept in runs if walked_mesh is mesh][
            -(4 if drop_lineless else 2) :
        ]
        assert [kept for _ranges, kept in edit_runs] == [False] + [True] * (len(edit_runs) - 1)
        assert all(np.array_equal(a, b) for ranges, _kept in edit_runs for a, b in zip(ranges, edit_ranges))
        # Every redraw that draws (not the one that composites what the
        # first kept) left triangles out, the edit's inside its ranges too,
        # and drew the picked ones apart.
        assert all(left_out[k] > 0 for k in (0, 2, 3)) if drop_lineless else not any(left_out)
        assert all(picked[k] > 0 for k in (0, 2, 3)) if drop_lineless else not any(picked)
        for table_image, corner_image in zip(from_table, at_corners):
            _assert_same_hidden_lines(table_image, corner_image, drop_lineless)
            assert (table_image[..., 3] > 0).mean() > 0.05
        assert not np.array_equal(from_table[3], from_table[1])  # the edit shows


def test_the_pre_pass_fills_the_rows_that_hold_the_draws_ranges():
    """The pre-pass's rectangles (draw._table_rows): every row of the table
    that holds a triangle of the ranges an edit draws, neighbours joined,
    and no other; every row of the mesh's triangles for a whole draw."""
    row = 1 << shaders.WALK_TABLE_SHIFT
    assert draw._table_rows(0) == []
    assert draw._table_rows(row) == [(0, 1)]
    assert draw._table_rows(row + 1) == [(0, 2)]
    first = np.array([5, row - 1, 3 * row, 5 * row + 7, 9 * row], dtype=np.int64)
    count = np.array([10, 2, row, 0, 1], dtype=np.int64)
    assert draw._table_rows(10 * row, (first, count)) == [(0, 2), (3, 4), (9, 10)]
