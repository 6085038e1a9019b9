"""A default look that stays readable on dense scenes (Fade Dense Objects,
on by default) and leaves readable scenes exactly as they were."""

from __future__ import annotations

import dataclasses
import math

import bpy
import numpy as np
import pytest

from scripts import dense_scenes
from solidwire_addon.blender import presets
from solidwire_addon.core import schema
from tests.support import robustness


def test_spheres_20px_across_are_mostly_fill_by_default():
    """40 of the gallery's 1,000 spheres (the same size on screen, 20 px):
    with the default look at most half of the object pixels are nearer the
    wire colour than the fill; without the rule nearly all of them are."""
    scene = dense_scenes.sphere_grid(8, 5)
    share, pixels, _image = dense_scenes.wire_share(scene)
    off, _pixels, _image = dense_scenes.wire_share(scene, use_object_density_fade=False)
    assert pixels > 40 * 250  # every sphere drawn, ~314 px each
    assert share <= 0.5, share
    assert off > 0.9, off


def test_demo_scene_is_unchanged_by_the_default():
    """The demo at its own size: the default look and the look without Fade
    Dense Objects are the same image, bit for bit."""
    scene = dense_scenes.demo()
    assert scene.solidwire.use_object_density_fade  # the demo keeps the add-on's default
    on, covered = dense_scenes.render(scene)
    off, _covered = dense_scenes.render(scene, use_object_density_fade=False)
    assert covered.sum() > 50000
    assert np.array_equal(on, off)


def _median_edge(mesh) -> float:
    ends = np.array([e.vertices[:] for e in mesh.edges])
    co = np.array([v.co[:] for v in mesh.vertices])
    return float(np.median(np.linalg.norm(co[ends[:, 0]] - co[ends[:, 1]], axis=1)))


@pytest.mark.parametrize("diameter_px", [34.0, 46.0, 80.0])
def test_partial_fade_is_the_wire_opacity_times_g(diameter_px, output_dir):
    """One sphere under an orthographic camera: its typical edge is
    ell = median edge length x scale x pixels per unit, and the default look
    draws exactly what the look without the rule draws with the wire's
    opacity times g = clamp(2 ell / L - 1, 0, 1) (rounded down to 1/64)."""
    scene = dense_scenes.sphere_grid(1, 1, px=diameter_px)
    sphere = next(obj for obj in scene.objects if obj.type == "MESH")
    sphere.scale = (1.5, 1.5, 1.5)
    camera = scene.camera.data
    width = scene.render.resolution_x
    pixels_per_unit = width / camera.ortho_scale  # horizontal sensor fit
    ell = _median_edge(sphere.data) * 1.5 * pixels_per_unit
    full = scene.solidwire.density_fade_length
    g = math.floor(min(max(2.0 * ell / full - 1.0, 0.0), 1.0) * 64.0) / 64.0
    faded = robustness.render_exr(scene, output_dir / f"dense_fade_{diameter_px:g}.exr")
    scene.solidwire.use_object_density_fade = False
    wire = tuple(scene.solidwire.wire_color)
    scene.solidwire.wire_color = (*wire[:3], wire[3] * g)
    expected = robustness.render_exr(scene, output_dir / f"dense_fade_{diameter_px:g}_expected.exr")
    assert (expected[..., 3] > 0).sum() > 100
    if diameter_px < 54.0:
        assert 0.0 < g < 1.0, g  # the case is a partial fade
    else:
        assert g == 1.0
    assert np.array_equal(faded, expected)


def test_default_and_presets_agree_on_the_rule():
    """The default preset holds the new default; presets that show every
    edge on purpose keep it off."""
    assert schema.BY_NAME["use_object_density_fade"].default is True
    assert presets.find("Default").values["use_object_density_fade"] is True
    for name in ("Topology", "Triangles"):
        preset = next((p for p in presets.builtin_presets() if p.name.startswith(name)), None)
        if preset is not None:
            assert preset.values["use_object_density_fade"] is False, name


def test_overlay_fades_dense_objects_too():
    """The viewport overlay applies the same rule (a dense sphere grid's
    overlay wire is gone by default, present without the rule)."""
    import gpu

    from solidwire_addon.blender import overlay
    from solidwire_addon.blender.views import camera_view

    scene = dense_scenes.sphere_grid(4, 3)
    width, height = scene.render.resolution_x, scene.render.resolution_y
    view = camera_view(scene, bpy.context.evaluated_depsgraph_get(), (width, height))

    def alpha_sum() -> float:
        color = gpu.types.GPUTexture((width, height), format="RGBA8")
        depth = gpu.types.GPUTexture((width, height), format="DEPTH32F_STENCIL8")
        framebuffer = gpu.types.GPUFrameBuffer(depth_slot=depth, color_slots=(color,))
        with framebuffer.bind():
            framebuffer.clear(color=(0.0, 0.0, 0.0, 0.0), depth=1.0)
            gpu.state.viewport_set(0, 0, width, height)
            settings = dataclasses.replace(scene.solidwire.snapshot(), use_fill=False)
            overlay.draw_scene_overlay(bpy.context.evaluated_depsgraph_get(), view, settings)
        buf = color.read()
        buf.dimensions = width * height * 4
        return float(np.array(buf, dtype=np.float64).reshape(height, width, 4)[..., 3].sum())

    faded = alpha_sum()
    scene.solidwire.use_object_density_fade = False
    full = alpha_sum()
    assert full > 1000.0
    assert faded < 0.01 * full
