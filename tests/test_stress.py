"""Numerical stress suite: the benchmark's stress scenes through the exact
path, against the float64 reference (SPEC 1.5 thresholds, no NaN/Inf), and
proof that the benchmark's near-plane scene really breaks the NVIDIA 2007
method (so its tricky case is exercised). Nothing here is timed.

The scenes are the ones scripts/bench/ measures (tests/support/scenes.py), at the
benchmark's size (float32 error grows with window coordinates, so a smaller
frame would hide it); the reference is evaluated on every ROW_STEP-th window
row to keep the float64 numpy evaluation affordable.
"""

from __future__ import annotations

import bpy
import numpy as np
import pytest

from scripts.bench import methods
from solidwire_addon.blender import gather
from solidwire_addon.blender import views as view_mod
from solidwire_addon.blender.gpu_context import ensure_gpu
from solidwire_addon.core.cache import MeshCache
from solidwire_addon.core.settings import DrawSettings
from tests.support import accuracy, reference, robustness, scenes

pytestmark = pytest.mark.stress

SIZE = (1280, 720)
ROW_STEP = 8
# The SPEC defaults, and the benchmark's settings: the papers' prefiltered
# profile (T = 0, s = 1, where no opaque core hides distance errors) with every
# triangle edge drawn.
LINE_SETTINGS = {
    "defaults": {},
    "bench": {"thickness": 0.0, "softness": 1.0, "diagonal_mode": "SOLID"},
}


def _stress_scene(name: str, **solidwire):
    scene = scenes.empty_scene(*SIZE, **solidwire)
    scenes.STRESS_SCENES[name](scene)
    bpy.context.view_layer.update()
    return scene


@pytest.mark.parametrize("settings", list(LINE_SETTINGS))
@pytest.mark.parametrize("name", list(scenes.STRESS_SCENES))
def test_exact_path_meets_thresholds(name, settings, output_dir):
    scene = _stress_scene(name, **LINE_SETTINGS[settings])
    rgba = scenes.render_to_file(scene, output_dir / f"stress_{name}_{settings}.png")
    ref = reference.render_reference(scene, rows=np.arange(ROW_STEP // 2, SIZE[1], ROW_STEP))
    measured = rgba[ref.rows, :, 3]
    report = reference.error_report(measured, ref)
    report["name"] = f"{name}/{settings}"
    accuracy.assert_accurate(report)


def _method_intensity(scene, method: str) -> np.ndarray:
    """Line intensity (alpha on a transparent film) of ``method``."""
    ensure_gpu()  # gather() uploads meshes: the GPU must be up first
    depsgraph = bpy.context.evaluated_depsgraph_get()
    items, _keys, _ms = gather.gather(depsgraph, MeshCache())
    view = view_mod.camera_view(scene, depsgraph)
    settings = DrawSettings.from_properties(scene.solidwire)
    rgba, _depth, _stats = methods.render(items, view, settings, method)
    return rgba[..., 3].astype(np.float64)


def test_nvidia2007_fails_on_near_plane_scene():
    scene = _stress_scene("near_plane", **LINE_SETTINGS["bench"])
    ref = reference.render_reference(scene, rows=np.arange(ROW_STEP // 2, SIZE[1], ROW_STEP))
    nvidia = _method_intensity(scene, "nvidia2007")[ref.rows]
    kakadu = _method_intensity(scene, "kakadu_clip")[ref.rows]
    report = reference.error_report(nvidia, ref)
    # The published method misses the thresholds the exact path meets here ...
    assert report["p999"] > accuracy.P999_LIMIT or report["max"] > accuracy.MAX_LIMIT, report
    # ... and part of that is the tricky case: nvidia2007 and kakadu_clip run
    # the same code except for the Liang-Barsky fix of tricky-case triangles,
    # so pixels where they differ are tricky-case pixels with the float32
    # cancellation glitch.
    off_silhouette = ~ref.on_silhouette
    glitch = np.abs(nvidia - kakadu)[off_silhouette]
    assert np.count_nonzero(glitch > 2.0 / 255.0) > 0
    assert (
        np.abs(kakadu - ref.intensity)[off_silhouette][glitch > 2.0 / 255.0].mean()
        < glitch[glitch > 2.0 / 255.0].mean()
    )


@pytest.mark.parametrize(
    "method", ["nvidia2007", "kakadu_clip", "barycentric", "offset_lines", "offset_lines_2x", "fill_only"]
)
def test_method_variants_render_finite_images(method):
    """Every developer method compiles, draws and returns finite values."""
    scene = scenes.empty_scene(320, 180, diagonal_mode="SOLID")
    scenes.monkey(scene)
    scenes.add_camera(scene, location=(4.0, -4.0, 3.0))
    intensity = _method_intensity(scene, method)
    assert np.isfinite(intensity).all()
    if method == "fill_only":
        assert intensity.max() == 0.0
    else:
        assert intensity.max() > 0.5


def test_exact_path_on_dense_mesh():
    """Suzanne at subdivision level 5 (1,007,616 triangles, the benchmark's
    1M scene) at 1280 x 720 with the papers' profile: edges of about a pixel
    all over the frame. (It failed while edge lines were set up as the cross
    product of absolute homogeneous window coordinates: ~0.03 px lost on
    pixel-sized edges; see edge_geometry.glsl.)"""
    scene = scenes.empty_scene(*SIZE, **LINE_SETTINGS["bench"])
    scenes.suzanne_1m_scene(scene)
    bpy.context.view_layer.update()
    depsgraph = bpy.context.evaluated_depsgraph_get()
    ref = reference.render_reference(scene, depsgraph, rows=np.arange(ROW_STEP // 2, SIZE[1], 4 * ROW_STEP))
    measured = _method_intensity(scene, "exact")[ref.rows]
    report = reference.error_report(measured, ref)
    accuracy.assert_accurate(report)


@pytest.mark.parametrize("ortho", [False, True], ids=["perspective", "orthographic"])
def test_huge_clip_end(ortho, output_dir):
    """Clip end 1e9: the reference stays finite (its rays start at the camera
    or, orthographic, on the near plane, never at a far plane with w ~ 0),
    it is the reference of the same view with an ordinary clip end (only
    depth changes with the clip end), and the engine meets the thresholds."""
    scene = scenes.empty_scene(320, 180, diagonal_mode="SOLID")
    scenes.monkey(scene)
    scenes.cube(scene, "Cube", size=1.0, location=(1.5, 1.0, -0.5))
    camera = scenes.add_camera(scene, location=(4.0, -4.0, 3.0), clip=(0.1, 1.0e9), ortho_scale=5.0 if ortho else None)
    bpy.context.view_layer.update()
    ref = reference.render_reference(scene)
    assert np.isfinite(ref.intensity).all()
    assert (ref.face >= 0).sum() > 0.1 * ref.face.size  # the objects are seen ...
    assert np.isfinite(ref.depth[ref.face >= 0]).all()
    assert ref.intensity.max() > 0.9  # ... with their wire
    if not ortho:
        # Orthographic depth over a 1e9 clip range is below float32 resolution
        # (objects z-fight in any depth buffer), so the engine is compared in
        # perspective only; the reference itself is checked for both.
        rgba = scenes.render_to_file(scene, output_dir / "stress_clip_end_1e9.png")
        report = reference.error_report(rgba[..., 3], ref)
        report["name"] = "clip_end_1e9"
        accuracy.assert_accurate(report)
    camera.data.clip_end = 100.0
    bpy.context.view_layer.update()
    ordinary = reference.render_reference(scene)
    np.testing.assert_array_equal(ref.face, ordinary.face)
    np.testing.assert_allclose(ref.intensity, ordinary.intensity, rtol=0.0, atol=1e-9)


def test_a_dashed_line_through_the_near_plane_keeps_its_phase(output_dir):
    """A triangle with a corner far behind the camera: two of its edges cross
    the near plane and end thousands of pixels off-screen, where their
    dashes begin. The clipped end takes the near plane's own clip w
    (edge_geometry.glsl near_clipped): the interpolated one, the small
    difference of large numbers, moved the dashes by up to a fifth of their
    fall-off (max error 0.19; found by the fuzz)."""
    scene = scenes.empty_scene(
        320, 240, thickness=0.0, use_boundary_edges=True, boundary_thickness=0.0, boundary_pattern="DASHED"
    )
    data = bpy.data.meshes.new("Sliver")
    data.from_pydata([(0.9, 0.0, -0.17), (-10.9, -14.5, -36.2), (0.0, 0.0, 0.63)], [], [(0, 1, 2)])
    obj = bpy.data.objects.new("Sliver", data)
    scene.collection.objects.link(obj)
    obj.rotation_euler, obj.scale, obj.location = (0.0, 2.81, 0.3), (1.47, -0.3, -0.61), (0.0, 0.0, -0.2)
    scenes.add_camera(scene, location=(4.34, 0.0, -2.76), target=(0.02, 0.0, 0.64), lens=64.0, clip=(0.1, 20.0))
    report = accuracy.measure(scene, "dashes_through_the_near_plane", output_dir)
    accuracy.assert_accurate(report)
    assert report["max"] < 0.01


@pytest.mark.parametrize("path", ["render", "overlay"])
def test_a_silhouette_through_the_near_plane_keeps_its_distance(path, output_dir):
    """A triangle with a corner behind the camera, seen at a near clip of
    0.01: two of its boundary edges cross the near plane and end some 10^5
    px off-screen. Their outer halves measured the distance from that
    clipped end's window point, whose float32 rounding (about 0.01 px there)
    moved the whole fall-off of a sharp line (softness 0.25) by up to 0.05;
    they now take the line and span of the main pass (edge_setup in
    shaders/edge_geometry.glsl), anchored near the screen. Found by the
    fuzz of every line option."""
    scene = scenes.empty_scene(
        160, 120, thickness=3.0, softness=0.25, use_silhouettes=True, use_boundary_edges=True, boundary_thickness=2.0
    )
    scenes.from_pydata(scene, "Behind", scenes.CORNERS_THROUGH_THE_NEAR_PLANE, [(0, 1, 2)])
    scenes.add_clipped_corners_camera(scene)
    ref = reference.render_reference(scene)
    alpha = robustness.image_alpha(scene, path, output_dir / "silhouette_through_the_near_plane.png")
    report = reference.error_report(alpha, ref)
    print(report)
    accuracy.assert_accurate(report)
    assert report["max"] < 0.01
    without = reference.render_reference(scene, settings=reference.SettingsWith(scene.solidwire, use_silhouettes=False))
    assert ((ref.intensity - without.intensity) > 0.5).sum() > 30  # outer halves really drawn
