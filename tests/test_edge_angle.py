"""Edge angle (image model §3.4): edges between two faces that meet at less
than `edge_angle` are not drawn (neither lines nor diagonals), and the lines
of the faces around them come from their whole region; boundary and
non-manifold edges always are drawn. Against the float64 reference."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tests.support import accuracy, reference, scenes


def _smooth_subdivided(scene):
    # The angle alone: every evaluated edge is a candidate (cage edges off).
    scene.solidwire.use_cage_edges = False
    monkey = scenes.monkey(scene, subdivisions=2, rotation=(0.2, 0.0, 0.5))
    scenes.add_camera(scene, location=(2.0, -4.0, 1.5), target=(0, 0, 0))
    return monkey


def _coplanar_ngons(scene):
    # Two hexagons and a quad in one plane (their shared edges are flat),
    # folded against a third n-gon at 60 degrees (that edge stays drawn).
    verts = [
        (0, 0, 0),
        (1, -0.6, 0),
        (2, 0, 0),
        (2, 1, 0),
        (1, 1.6, 0),
        (0, 1, 0),  # hexagon A
        (3, -0.6, 0),
        (4, 0, 0),
        (4, 1, 0),
        (3, 1.6, 0),  # hexagon B shares 2-3
        (1, 2.6, 0),
        (2, 2.6, 0),  # quad 4-3-... above
        (-0.8, -0.3, 0.7),
        (-0.9, 1.2, 0.8),
        (-0.5, 0.5, 1.4),  # pentagon folded up at 0-5
    ]
    faces = [(0, 1, 2, 3, 4, 5), (2, 6, 7, 8, 9, 3), (4, 3, 11, 10), (5, 0, 12, 14, 13)]
    scenes.from_pydata(scene, "Ngons", verts, faces)
    scenes.add_camera(scene, location=(1.6, -3.5, 4.5), target=(1.5, 0.8, 0.2), lens=30.0)


@pytest.mark.parametrize("mode", ["HIDDEN", "SOLID", "DASHED"])
def test_flat_edges_are_not_drawn_on_a_subdivided_mesh(mode, output_dir):
    scene = scenes.empty_scene(200, 150, edge_angle=math.radians(12.0), diagonal_mode=mode, thickness=1.0)
    _smooth_subdivided(scene)
    report = accuracy.measure(scene, f"edge_angle_subdivided_{mode.lower()}", output_dir)
    accuracy.assert_accurate(report)


@pytest.mark.parametrize(("level", "degrees"), [(2, 5.0), (3, 3.0)])
def test_the_angle_beside_the_cage_hides_flat_cage_edges(level, degrees, output_dir):
    """Cage edges and the angle together: a cage edge whose pieces meet at
    less than the angle is hidden piece by piece, and the cage faces on
    either side draw their lines from their joined region; against the
    reference, which finds the regions from the mesh itself. Sharp edges
    show through the angle."""
    scene = scenes.empty_scene(
        200, 150, use_cage_edges=True, edge_angle=math.radians(degrees), use_sharp_edges=True, thickness=1.5
    )
    monkey = scenes.monkey(scene, subdivisions=level, rotation=(0.2, 0.0, 0.5))
    for edge in monkey.data.edges[:60]:
        edge.use_edge_sharp = edge.index % 3 == 0
    scenes.add_camera(scene, location=(2.0, -4.0, 1.5), target=(0, 0, 0))
    report = accuracy.measure(scene, f"edge_angle_cage_level{level}", output_dir)
    accuracy.assert_accurate(report)
    ref = reference.render_reference(scene)
    ref_cage = reference.render_reference(scene, settings=reference.SettingsWith(scene.solidwire, edge_angle=0.0))
    # The angle hides about a third of the cage's pieces (not all of them).
    assert 0.3 * ref_cage.intensity.sum() < ref.intensity.sum() < 0.9 * ref_cage.intensity.sum()


def test_ngon_outlines_and_quad_corners_follow_the_angle(output_dir):
    scene = scenes.empty_scene(220, 160, edge_angle=math.radians(5.0), diagonal_mode="SOLID", thickness=2.0)
    _coplanar_ngons(scene)
    report = accuracy.measure(scene, "edge_angle_ngons", output_dir)
    accuracy.assert_accurate(report)
    for mode in ("HIDDEN", "DOTTED"):
        scene.solidwire.diagonal_mode = mode
        accuracy.assert_accurate(accuracy.measure(scene, f"edge_angle_ngons_{mode.lower()}", output_dir))


def test_angle_hides_lines_and_zero_changes_nothing(output_dir):
    """The threshold really removes lines, and 0 (the default) is the core
    image exactly."""
    scene = scenes.empty_scene(200, 150, thickness=1.0)
    _smooth_subdivided(scene)
    plain = scenes.render_to_file(scene, output_dir / "edge_angle_off.png")[..., 3]
    scene.solidwire.edge_angle = 0.0
    again = scenes.render_to_file(scene, output_dir / "edge_angle_zero.png")[..., 3]
    np.testing.assert_array_equal(plain, again)
    scene.solidwire.edge_angle = math.radians(12.0)
    fewer = scenes.render_to_file(scene, output_dir / "edge_angle_12.png")[..., 3]
    assert fewer.sum() < 0.7 * plain.sum()


def test_boundary_and_sharp_folds_stay(output_dir):
    """A flat grid keeps only its boundary; a cube keeps every edge (90°)."""
    scene = scenes.empty_scene(160, 120, edge_angle=math.radians(30.0), thickness=1.0)
    scenes.grid(scene, x_segments=6, y_segments=6, size=3.0)
    scenes.cube(scene, size=1.0, location=(0.0, 0.0, 1.0))
    scenes.add_camera(scene, location=(4.0, -4.0, 4.0), target=(0, 0, 0.3))
    report = accuracy.measure(scene, "edge_angle_boundary", output_dir)
    accuracy.assert_accurate(report)
    ref = reference.render_reference(scene)
    ref_all = reference.render_reference(scene, settings=reference.SettingsWith(scene.solidwire, edge_angle=0.0))
    grid_only = ref.face >= 0
    assert ref.intensity[grid_only].sum() < 0.6 * ref_all.intensity[grid_only].sum()
