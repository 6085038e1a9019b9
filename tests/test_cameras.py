"""Cameras a render cannot draw: a panoramic camera or stereo (multiview)
output is refused with one line naming it, never a silent perspective
image; the viewport overlay does not use the scene camera and still draws."""

from __future__ import annotations

import bpy
import numpy as np
import pytest

from solidwire_addon.blender.gpu_context import ensure_gpu
from solidwire_addon.blender.views import camera_view
from solidwire_addon.core import log
from tests.support import scenes
from tests.test_overlay import FakeViewport

W, H = 40, 30


@pytest.fixture(autouse=True)
def fresh_messages():
    log.forget()
    yield
    log.forget()


def _cube_scene():
    scene = scenes.empty_scene(W, H)
    scenes.cube(scene)
    scenes.add_camera(scene, location=(3.0, -4.0, 2.5), target=(0, 0, 0))
    return scene


PANORAMA_TYPES = [item.identifier for item in bpy.types.Camera.bl_rna.properties["panorama_type"].enum_items]


@pytest.mark.parametrize("panorama_type", PANORAMA_TYPES)
def test_panoramic_camera_is_refused_with_one_line(panorama_type, output_dir, capfd):
    scene = _cube_scene()
    scene.camera.data.type = "PANO"
    scene.camera.data.panorama_type = panorama_type
    name = bpy.types.Camera.bl_rna.properties["panorama_type"].enum_items[panorama_type].name
    path = output_dir / f"pano_{panorama_type}.png"
    path.unlink(missing_ok=True)
    capfd.readouterr()
    with pytest.raises(RuntimeError) as raised:
        scenes.render_still(scene, path)
    err = capfd.readouterr()
    text = str(raised.value)
    assert "panoramic" in text and f"({name})" in text and "'Camera'" in text, text
    said = [line for line in (err.out + err.err).splitlines() if "panoramic" in line]
    assert len(said) <= 1, said  # one line (Blender may also print the report)
    assert not path.exists()  # no perspective picture written instead


def test_perspective_camera_still_renders(output_dir):
    """The check does not refuse the cameras SolidWire draws."""
    scene = _cube_scene()
    for kind in ("PERSP", "ORTHO"):
        scene.camera.data.type = kind
        path = scenes.render_still(scene, output_dir / f"camera_{kind}.png")
        assert scenes.load_png(path)[..., 3].max() > 0.5


def test_stereo_multiview_is_refused_with_one_line(output_dir):
    scene = _cube_scene()
    scene.render.use_multiview = True
    path = output_dir / "multiview.png"
    path.unlink(missing_ok=True)
    with pytest.raises(RuntimeError, match=r"Stereoscopy \(multiview\)"):
        scenes.render_still(scene, path)
    assert not path.exists()


def test_overlay_draws_with_a_panoramic_scene_camera():
    """The overlay draws the viewport's view, whatever the scene camera is:
    the same view draws the same pixels with a panoramic camera."""
    ensure_gpu()
    scene = _cube_scene()
    # A view like a viewport's: the perspective camera's matrices.
    view = camera_view(scene, bpy.context.evaluated_depsgraph_get(), (W, H))

    def draw() -> np.ndarray:
        # Solid shading: Blender's depth holds the cube's surface.
        depsgraph = bpy.context.evaluated_depsgraph_get()
        viewport = FakeViewport(W, H)
        viewport.depth_pass(depsgraph, view, [scene.objects["Cube"]])
        viewport.draw_overlay(depsgraph, view, scene.solidwire.snapshot())
        return viewport.rgba()

    perspective = draw()
    scene.camera.data.type = "PANO"
    panoramic = draw()
    assert perspective[..., 3].max() > 0
    assert np.array_equal(perspective, panoramic)
