"""Which edges are drawn and how (image model §3.4-§3.7): regions, edge
classes with their own styles, density fade. Renders through the engine are
compared with the float64 reference (the region bookkeeping on arrays:
tests/pure/test_edge_select_arrays.py)."""

from __future__ import annotations

import math

import bpy
import numpy as np
import pytest

from tests.support import accuracy, reference, scenes

# ---------------------------------------------------------------- against the reference


def _marked_cube(scene):
    """A bevelled-looking cube: sharp, seam, crease and Freestyle marks on
    different edges, plus an open grid (boundary)."""
    cube = scenes.cube(scene, size=1.6, location=(0.0, 0.0, 0.8), rotation=(0.0, 0.0, 0.4))
    mesh = cube.data
    mesh.edges[0].use_edge_sharp = True
    mesh.edges[1].use_seam = True
    mesh.edges[2].use_seam = True
    mesh.edges[2].use_edge_sharp = True  # two classes on one edge
    crease = mesh.attributes.new("crease_edge", "FLOAT", "EDGE")
    crease.data[3].value = 1.0
    freestyle = mesh.attributes.new("freestyle_edge", "BOOLEAN", "EDGE")
    freestyle.data[5].value = True
    scenes.grid(scene, x_segments=3, y_segments=3, size=2.5, location=(0.0, 0.0, -0.2))
    scenes.add_camera(scene, location=(3.5, -4.0, 3.2), target=(0.0, 0.0, 0.4))
    return cube


CLASS_LOOK = dict(
    use_boundary_edges=True,
    boundary_thickness=3.0,
    boundary_color=(1.0, 0.0, 0.0, 1.0),
    use_sharp_edges=True,
    sharp_thickness=4.0,
    sharp_color=(0.0, 1.0, 0.0, 1.0),
    use_seam_edges=True,
    seam_thickness=2.5,
    seam_pattern="DASHED",
    seam_color=(0.0, 0.0, 1.0, 1.0),
    use_crease_edges=True,
    crease_thickness=0.5,
    crease_pattern="DOTTED",
    use_freestyle_edges=True,
    freestyle_thickness=5.0,
    pattern_period=10.0,
    thickness=1.0,
)


def test_edge_classes_match_the_reference(output_dir):
    scene = scenes.empty_scene(240, 180, **CLASS_LOOK)
    _marked_cube(scene)
    report = accuracy.measure(scene, "edge_classes", output_dir)
    accuracy.assert_accurate(report)
    # The classes really change the picture: wider lines, other colours.
    rgba = scenes.load_png(output_dir / "edge_classes.png")
    ref = reference.render_reference(scene)
    green = (rgba[..., 1] > 0.9) & (rgba[..., 0] < 0.1) & (rgba[..., 3] > 0.9)
    red = (rgba[..., 0] > 0.9) & (rgba[..., 1] < 0.1) & (rgba[..., 3] > 0.9)
    assert green.sum() > 50 and red.sum() > 100
    # The colour of each solid sample is the colour of the style the
    # reference picks (but where two styles tie at full strength, which a
    # rounding step decides).
    solid = (rgba[..., 3] > 0.99) & ~ref.on_silhouette & np.isfinite(ref.wire).all(axis=-1)
    expected = reference.srgb_encode(ref.wire)
    wrong = np.abs(rgba[..., :3] - expected).max(axis=-1) > 0.02
    assert solid.sum() > 500 and (wrong & solid).sum() <= 0.005 * solid.sum()


def test_classes_switched_on_change_nothing_on_a_mesh_without_such_edges(output_dir):
    scene = scenes.empty_scene(160, 120, thickness=1.5)
    scenes.cube(scene, size=1.5)
    scenes.add_camera(scene, location=(3.0, -3.0, 2.5), target=(0, 0, 0))
    plain = scenes.render_to_file(scene, output_dir / "classes_off.png")
    for name in ("sharp", "seam", "crease", "freestyle"):
        setattr(scene.solidwire, f"use_{name}_edges", True)
        setattr(scene.solidwire, f"{name}_thickness", 6.0)
    again = scenes.render_to_file(scene, output_dir / "classes_on_no_marks.png")
    np.testing.assert_allclose(again, plain, atol=1.5 / 65535)


def test_regions_give_clean_corners_where_edges_are_hidden(output_dir):
    """A flat grid with the edge angle keeps only its boundary, drawn as one
    region: the corners are as clean as a single quad's."""
    scene = scenes.empty_scene(200, 150, edge_angle=math.radians(20.0), thickness=3.0)
    scenes.grid(scene, x_segments=4, y_segments=4, size=3.0)
    scenes.add_camera(scene, location=(0.4, -3.0, 3.6), target=(0, 0, 0))
    report = accuracy.measure(scene, "regions_grid", output_dir)
    accuracy.assert_accurate(report)
    # The whole interior is free of lines: only the outline is drawn.
    ref = reference.render_reference(scene)
    covered = ref.face >= 0
    assert (ref.d_real[covered] >= 0).all()
    single = scenes.empty_scene(200, 150, thickness=3.0)
    scenes.grid(single, x_segments=1, y_segments=1, size=3.0)
    scenes.add_camera(single, location=(0.4, -3.0, 3.6), target=(0, 0, 0))
    one_quad = scenes.render_to_file(single, output_dir / "regions_single_quad.png")[..., 3]
    grid_image = scenes.load_png(output_dir / "regions_grid.png")[..., 3]
    assert np.abs(one_quad - grid_image).max() < 3.0 / 255.0


@pytest.mark.parametrize("diagonals", ["HIDDEN", "SOLID"])
def test_density_fade_matches_the_reference(diagonals, output_dir):
    scene = scenes.empty_scene(
        220, 160, use_density_fade=True, density_fade_length=24.0, diagonal_mode=diagonals, thickness=1.0
    )
    scenes.grid(scene, x_segments=48, y_segments=48, size=8.0)
    scenes.add_camera(scene, location=(0.0, -6.5, 1.6), target=(0.0, 1.0, 0.0))
    report = accuracy.measure(scene, f"density_fade_{diagonals.lower()}", output_dir)
    accuracy.assert_accurate(report)
    # Far away the short edges are gone; near the camera lines are drawn.
    ref = reference.render_reference(scene)
    unfaded = reference.SettingsWith(scene.solidwire, use_density_fade=False)
    faded = reference.render_reference(scene, settings=unfaded)
    assert ref.intensity.sum() < 0.8 * faded.intensity.sum()
    assert ref.intensity[: len(ref.rows) // 4].max() > 0.99


@pytest.mark.parametrize("folded", [False, True])
def test_a_fade_below_zero_pixels_fades_nothing(folded, output_dir):
    """Density fade on with a length of 0: the image the fade switched off
    gives, where dotted diagonals meet too (with the fade on, a style takes
    its strongest faded line, and the dots of two diagonals that meet at a
    corner differ from the nearest one's alone)."""
    look = dict(diagonal_mode="DOTTED", pattern_period=3.0, pattern_duty=0.3, thickness=2.0)
    scene = scenes.empty_scene(160, 120, use_density_fade=True, density_fade_length=0.0, **look)
    cylinder = scenes.tube(scene, segments=12, depth=1.0, rotation=(0.9, 0.0, 0.3))
    if folded:  # an n-gon that is not flat takes another path (image model §4.3)
        cylinder.data.vertices[1].co.z += 0.3
    scenes.add_camera(scene, location=(0.0, -3.2, 2.2), target=(0.0, 0.0, 0.1))
    report = accuracy.measure(scene, f"fade_below_zero_{folded}", output_dir)
    accuracy.assert_accurate(report)
    faded = scenes.render_to_file(scene, output_dir / f"fade_below_zero_{folded}.png")
    scene.solidwire.use_density_fade = False
    plain = scenes.render_to_file(scene, output_dir / f"fade_below_zero_{folded}_off.png")
    assert np.array_equal(faded, plain)


# ---------------------------------------------------------------- cage edges


def _subdivided_monkey(scene, levels=2):
    monkey = scenes.monkey(scene, subdivisions=levels, rotation=(0.2, 0.0, 0.5))
    scenes.add_camera(scene, location=(2.0, -4.0, 1.5), target=(0, 0, 0))
    return monkey


@pytest.mark.parametrize(
    "look",
    [
        dict(),
        dict(edge_angle=math.radians(25.0)),
        dict(use_density_fade=True, density_fade_length=30.0, diagonal_mode="DASHED"),
        dict(use_silhouettes=True, use_boundary_edges=True, boundary_thickness=2.5),
        dict(use_hidden_lines=True, use_seam_edges=True),
    ],
)
def test_cage_edges_match_the_reference(look, output_dir):
    """The lines of a subdivided mesh come from its cage edges, running along
    the smooth surface (the reference finds them on its own, through an
    attribute Blender carries onto child edges)."""
    scene = scenes.empty_scene(240, 180, use_cage_edges=True, thickness=1.0, **look)
    monkey = _subdivided_monkey(scene)
    name = "cage_" + ("_".join(look) or "plain")
    before = (set(monkey.data.attributes.keys()), [m.name for m in monkey.modifiers], len(bpy.data.meshes))
    report = accuracy.measure(scene, name, output_dir)
    accuracy.assert_accurate(report)
    assert (set(monkey.data.attributes.keys()), [m.name for m in monkey.modifiers], len(bpy.data.meshes)) == before
    if look.get("use_density_fade") or look.get("use_hidden_lines"):
        return  # (every evaluated edge fades out entirely; hidden lines add lines)
    # Far fewer lines than every evaluated edge.
    every_edge = reference.SettingsWith(scene.solidwire, use_cage_edges=False)
    everything = reference.render_reference(scene, settings=every_edge)
    ref = reference.render_reference(scene)
    assert ref.intensity.sum() < 0.6 * everything.intensity.sum()
