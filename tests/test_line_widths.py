"""Line widths that follow one another (image model §3.6, §5.9): an edge
class keeps its ratio to the wire's width under an object's override and in
every thickness mode, and an object's own Thickness takes the viewport's UI
scale like the scene's."""

from __future__ import annotations

import bpy
import numpy as np
import pytest

from solidwire_addon.blender.views import camera_view
from solidwire_addon.core import overlay_state
from tests.support import accuracy, reference, scenes


def _classed_cube(scene, name="Cube", **kwargs):
    cube = scenes.cube(scene, name, rotation=(0.3, 0.1, 0.6), **kwargs)
    for edge in cube.data.edges[:5]:
        edge.use_edge_sharp = True
    return cube


def _classes_scene(mode, thickness, thickness_far):
    """A 200 x 150 scene with the sharp class 4 px wide under ``mode``
    (Depth Cue from 4 to 9 units, World widths of 0.03)."""
    return scenes.empty_scene(
        200,
        150,
        thickness=thickness,
        use_sharp_edges=True,
        sharp_thickness=4.0,
        thickness_mode=mode,
        thickness_far=thickness_far,
        thickness_depth_start=4.0,
        thickness_depth_end=9.0,
        world_thickness=0.03,
    )


@pytest.mark.parametrize("mode", ["PIXELS", "DEPTH", "WORLD"])
@pytest.mark.parametrize("override", [False, True])
def test_class_widths_follow_the_wire(mode, override, output_dir):
    scene = _classes_scene(mode, thickness=1.5, thickness_far=0.75)
    cube = _classed_cube(scene)
    scenes.cube(scene, "Other", size=1.0, location=(0.0, 2.5, -0.5))  # the scene's own widths
    if override:
        cube.solidwire.use_override = True
        cube.solidwire.thickness = 3.0
    scenes.add_camera(scene, location=(3.5, -5.0, 2.8), target=(0, 0.6, 0))
    report = accuracy.measure(scene, f"class_width_{mode.lower()}_{'override' if override else 'scene'}", output_dir)
    accuracy.assert_accurate(report)


@pytest.mark.parametrize("mode", ["PIXELS", "DEPTH", "WORLD"])
@pytest.mark.parametrize("scene_thickness, own_thickness", [(0.0, 3.0), (1.5, 0.0)], ids=["scene-0", "own-0"])
def test_class_widths_where_one_thickness_is_0(mode, scene_thickness, own_thickness, output_dir):
    """The ratio is to the scene's Thickness, never to an object's: at a
    scene Thickness of 0 an object's classes keep their own widths whatever
    its Thickness, and an object whose own Thickness is 0 keeps its classes
    where its wire still has a width (World mode's comes from World
    Thickness, Depth Cue's far end from Thickness Far). Before, the engine
    divided by the object's Thickness: classes at a scene Thickness of 0
    vanished in World widths (a random test of objects with their own
    settings: 18 pixels up to 1.0), and an object's Thickness of 0 took
    its classes' width away in every mode."""
    scene = _classes_scene(mode, thickness=scene_thickness, thickness_far=2.0)
    cube = _classed_cube(scene)
    cube.solidwire.use_override = True
    cube.solidwire.thickness = own_thickness
    scenes.add_camera(scene, location=(3.5, -5.0, 2.8), target=(0, 0.6, 0))
    name = f"class_width_{mode.lower()}_scene_{scene_thickness}_own_{own_thickness}"
    report = accuracy.measure(scene, name, output_dir)
    accuracy.assert_accurate(report)
    ref = reference.render_reference(scene)
    scene.solidwire.use_sharp_edges = False
    without = reference.render_reference(scene)
    if scene_thickness == 0.0 or mode != "PIXELS":
        assert (ref.intensity - without.intensity).sum() > 50.0  # the classes show


@pytest.mark.parametrize("thickness", [1e-30, 1.1754943508222875e-38])
def test_a_class_beside_a_vanishing_thickness(thickness, output_dir):
    """In World widths a class is T_k / T times the wire's width: beside a
    Thickness of 1e-30 or float32's smallest normal number it covers the
    faces it bounds. The ratio is taken in float64 (2 / T is still a
    float32 there), not on a GPU, which reads half that Thickness as a
    denormal and flushes it to 0, and then drew the class at its own pixel
    width (a random-mesh test found 467 pixels up to 1.0 too dark)."""
    scene = scenes.empty_scene(
        120,
        90,
        thickness=thickness,
        use_sharp_edges=True,
        sharp_thickness=2.0,
        sharp_pattern="DASHED",
        thickness_mode="WORLD",
        world_thickness=0.002,
    )
    _classed_cube(scene)
    scenes.add_camera(scene, location=(3.5, -5.0, 2.8), target=(0, 0, 0))
    report = accuracy.measure(scene, f"class_width_beside_thickness_{thickness:.0e}", output_dir)
    accuracy.assert_accurate(report)
    ref = reference.render_reference(scene)
    assert (ref.intensity > 0.99).sum() > 0.2 * (ref.face >= 0).sum()  # the dashes cross whole faces


def test_an_override_thickness_takes_the_ui_scale(output_dir):
    """At UI scale 2 a scene whose pixel lengths are halved (Thickness, Softness,
    a class's and an object's own) draws exactly as at UI scale 1."""
    from tests.test_overlay import FakeViewport

    def overlay_alpha(pixel_size: float, own_thickness: float = 4.0):
        bpy.ops.wm.read_factory_settings(use_empty=True)
        scene = scenes.empty_scene(
            160,
            120,
            thickness=2.0 / pixel_size,
            softness=1.0 / pixel_size,
            use_sharp_edges=True,
            sharp_thickness=3.0 / pixel_size,
        )
        cube = _classed_cube(scene)
        cube.solidwire.use_override = True
        cube.solidwire.thickness = own_thickness / pixel_size
        scenes.add_camera(scene, location=(3.5, -5.0, 2.8), target=(0, 0, 0))
        depsgraph = bpy.context.evaluated_depsgraph_get()
        view = camera_view(scene, depsgraph, (160, 120))
        viewport = FakeViewport(160, 120)
        viewport.depth_pass(depsgraph, view, [cube])
        plan = overlay_state.plan_overlay(overlay_state.ViewportState(pixel_size=pixel_size))
        viewport.draw_overlay(depsgraph, view, scene.solidwire.snapshot(), plan=plan, display=None)
        return viewport.rgba()[..., 3]

    plain = overlay_alpha(1.0)
    assert plain.max() > 0.9
    assert np.abs(overlay_alpha(2.0) - plain).max() <= 1.0 / 255.0
    # The object's own width left unscaled is visibly thinner: the
    # comparison above can fail.
    assert np.abs(overlay_alpha(1.0, own_thickness=2.0) - plain).max() > 0.3
