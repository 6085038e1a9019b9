"""Viewport overlay target, tested without a window.

No 3D viewport exists headless, so the viewport is rebuilt offscreen the way
Blender's draw manager leaves it for a POST_VIEW handler: an SRGB8_A8 colour
target and a depth buffer that a *separate* depth pass of the scene has
filled (here Blender's builtin UNIFORM_COLOR shader with float32 matrices, a
different arithmetic path from ours, like Solid shading). The overlay's own
draw function is then called with a view, exactly as the handler calls it
with the region's matrices, and compared with the render engine's image.
"""

from __future__ import annotations

import bpy
import numpy as np
import pytest

from solidwire_addon.blender import engine, overlay, runtime
from solidwire_addon.blender.gather import gather
from solidwire_addon.blender.gpu_context import ensure_gpu
from solidwire_addon.blender.views import camera_view
from solidwire_addon.core import draw, log, overlay_state, passes
from solidwire_addon.core.targets import BACKGROUND_DEPTH
from solidwire_addon.core.view import View
from tests.support import scenes
from tests.support.viewport import draw_scene_depth

WIDTH, HEIGHT = 200, 150


@pytest.fixture(autouse=True)
def gpu_ready():
    ensure_gpu()


class FakeViewport:
    """The colour and depth buffers a POST_VIEW handler draws into."""

    def __init__(self, width: int, height: int, depth_format: str = "DEPTH32F_STENCIL8"):
        import gpu

        ensure_gpu()
        self.size = (width, height)
        self.color = gpu.types.GPUTexture((width, height), format="SRGB8_A8")
        self.depth = gpu.types.GPUTexture((width, height), format=depth_format)
        self.framebuffer = gpu.types.GPUFrameBuffer(depth_slot=self.depth, color_slots=(self.color,))
        with self.framebuffer.bind():
            self.framebuffer.clear(color=(0.0, 0.0, 0.0, 0.0), depth=1.0)

    def depth_pass(self, depsgraph, view: View, objects) -> None:
        """Blender-like depth of ``objects`` (viewport.draw_scene_depth)."""
        draw_scene_depth(self.framebuffer, self.size, depsgraph, view, objects)

    def draw_overlay(self, depsgraph, view, settings, **kwargs) -> dict:
        with self.framebuffer.bind():
            import gpu

            gpu.state.viewport_set(0, 0, *self.size)
            return overlay.draw_scene_overlay(depsgraph, view, settings, **kwargs)

    def rgba(self) -> np.ndarray:
        """(H, W, 4) in 0..1, colour still sRGB-encoded, bottom row first."""
        buf = self.color.read()
        buf.dimensions = self.size[0] * self.size[1] * 4
        return np.array(buf, dtype=np.float64).reshape(self.size[1], self.size[0], 4) / 255.0


def srgb_to_linear(c):
    c = np.asarray(c, dtype=np.float64)
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def silhouette_mask(depth: np.ndarray, radius: int = 2) -> np.ndarray:
    """Pixels within ``radius`` of a depth discontinuity or a coverage edge of
    the engine's view-depth image (where coverage alone may differ)."""
    covered = depth < BACKGROUND_DEPTH
    d = np.where(covered, depth, 0.0)
    edge = np.zeros_like(covered)
    for axis in (0, 1):
        jump = (np.diff(covered.astype(np.int8), axis=axis) != 0) | (
            np.abs(np.diff(d, axis=axis)) > 0.05 * np.maximum(d[:-1] if axis == 0 else d[:, :-1], 1e-6)
        )
        if axis == 0:
            edge[:-1] |= jump
            edge[1:] |= jump
        else:
            edge[:, :-1] |= jump
            edge[:, 1:] |= jump
    grown = edge.copy()
    for _ in range(radius):
        g = grown.copy()
        g[1:] |= grown[:-1]
        g[:-1] |= grown[1:]
        g[:, 1:] |= grown[:, :-1]
        g[:, :-1] |= grown[:, 1:]
        grown = g
    return grown


def build_scene(**solidwire):
    scene = scenes.empty_scene(WIDTH, HEIGHT, **solidwire)
    scenes.add_camera(scene, location=(6.0, -5.0, 4.0))
    front = scenes.cube(scene, "Front", size=1.6)
    back = scenes.uv_sphere(scene, "Back", radius=1.2, location=(-1.6, 1.8, -0.3))
    return scene, [front, back]


# Older viewports use a 24-bit depth buffer (deprecated name in 5.0, still valid).
pytestmark = pytest.mark.filterwarnings("ignore:'DEPTH24_STENCIL8' is deprecated:DeprecationWarning")


@pytest.mark.parametrize("diagonal_mode", ["HIDDEN", "SOLID", "DOTTED"])
@pytest.mark.parametrize("depth_format", ["DEPTH32F_STENCIL8", "DEPTH24_STENCIL8"])
def test_overlay_matches_render_engine(diagonal_mode, depth_format, output_dir):
    scene, objects = build_scene(diagonal_mode=diagonal_mode, thickness=1.5)
    depsgraph = bpy.context.evaluated_depsgraph_get()
    rgba_engine, depth_engine = engine.render_scene(depsgraph, (WIDTH, HEIGHT))
    view = camera_view(scene, depsgraph, (WIDTH, HEIGHT))

    viewport = FakeViewport(WIDTH, HEIGHT, depth_format)
    viewport.depth_pass(depsgraph, view, objects)
    stats = viewport.draw_overlay(depsgraph, view, scene.solidwire.snapshot())
    assert stats["objects_drawn"] == 2
    rgba_overlay = viewport.rgba()

    alpha_engine, alpha_overlay = rgba_engine[..., 3], rgba_overlay[..., 3]
    assert alpha_engine.max() > 0.9, "the scene draws visible wires"
    diff = np.abs(alpha_overlay - alpha_engine)
    off_silhouette = ~silhouette_mask(depth_engine)
    p999 = np.percentile(diff[off_silhouette], 99.9)
    worst = diff[off_silhouette].max()
    if worst > 0.1:
        scenes_dir = output_dir / f"overlay_diff_{diagonal_mode}_{depth_format}.npy"
        np.save(scenes_dir, diff)
    assert p999 <= 2.0 / 255.0 + 1e-9, f"p99.9 |dI| = {p999 * 255:.2f}/255"
    assert worst <= 0.1, f"max |dI| off silhouettes = {worst:.3f}"


def test_overlay_colour_is_the_picked_linear_colour():
    """Without a display LUT (``display=None``; the scene's colour management
    is tests/test_overlay_color_management.py's subject) the SRGB8_A8 target
    stores sRGB(linear colour): decoding a wire core pixel gives back exactly
    the scene-linear colour the user picked."""
    picked = (0.2, 0.5, 0.05, 1.0)
    scene, objects = build_scene(thickness=6.0)
    scene.solidwire.wire_color = picked
    depsgraph = bpy.context.evaluated_depsgraph_get()
    view = camera_view(scene, depsgraph, (WIDTH, HEIGHT))
    viewport = FakeViewport(WIDTH, HEIGHT)
    viewport.depth_pass(depsgraph, view, objects)
    viewport.draw_overlay(depsgraph, view, scene.solidwire.snapshot(), display=None)
    rgba = viewport.rgba()
    core = rgba[..., 3] > 0.999
    assert core.sum() > 50
    decoded = srgb_to_linear(rgba[core][:, :3])
    assert np.allclose(decoded.mean(axis=0), picked[:3], atol=0.01)


def _occlusion_scene():
    scene = scenes.empty_scene(WIDTH, HEIGHT, thickness=2.0, diagonal_mode="SOLID")
    scenes.add_camera(scene, location=(0.0, -10.0, 0.0))
    hidden = scenes.grid(scene, "Hidden", x_segments=8, y_segments=8, size=1.5, rotation=(1.5708, 0, 0))
    # An occluder that is *not* drawn by the overlay (opted out), only by the
    # viewport's own shading: its depth alone must hide the grid's wire.
    occluder = scenes.cube(scene, "Occluder", size=3.0, location=(0.0, -3.0, 0.0))
    occluder.solidwire_exclude = True
    return scene, hidden, occluder


def test_occluded_object_wire_does_not_show():
    scene, hidden, occluder = _occlusion_scene()
    depsgraph = bpy.context.evaluated_depsgraph_get()
    view = camera_view(scene, depsgraph, (WIDTH, HEIGHT))
    keep = overlay.viewport_object_filter(bpy.context.view_layer)

    # Control: without the occluder's depth the grid's wire is there.
    bare = FakeViewport(WIDTH, HEIGHT)
    bare.depth_pass(depsgraph, view, [hidden])
    bare.draw_overlay(depsgraph, view, scene.solidwire.snapshot(), object_filter=keep)
    assert bare.rgba()[..., 3].max() > 0.9

    occluded = FakeViewport(WIDTH, HEIGHT)
    occluded.depth_pass(depsgraph, view, [hidden, occluder])
    stats = occluded.draw_overlay(depsgraph, view, scene.solidwire.snapshot(), object_filter=keep)
    assert stats["objects_drawn"] == 1  # the occluder is opted out
    assert occluded.rgba()[..., 3].max() == 0.0


def test_no_back_edges_through_without_scene_depth():
    """X-ray / Wireframe shading leave no scene depth: the depth pre-pass still
    keeps a closed mesh's back faces from showing their wire."""
    scene = scenes.empty_scene(WIDTH, HEIGHT, thickness=1.5)
    scenes.add_camera(scene, location=(6.0, -5.0, 4.0))
    scenes.cube(scene, "Cube", size=2.0)
    depsgraph = bpy.context.evaluated_depsgraph_get()
    rgba_engine, _depth = engine.render_scene(depsgraph, (WIDTH, HEIGHT))
    view = camera_view(scene, depsgraph, (WIDTH, HEIGHT))
    viewport = FakeViewport(WIDTH, HEIGHT)  # empty depth
    xray = overlay_state.plan_overlay(overlay_state.ViewportState(shading="WIREFRAME", xray=True, xray_alpha=0.5))
    viewport.draw_overlay(depsgraph, view, scene.solidwire.snapshot(), plan=xray)
    diff = np.abs(viewport.rgba()[..., 3] - rgba_engine[..., 3])
    assert diff.max() <= 2.0 / 255.0 + 1e-9


def test_depth_bias_is_needed_and_small():
    """Over Blender-like depth of the very same surface the biased overlay
    draws every wire pixel; and a surface just behind another (far more than
    the bias) stays hidden."""
    scene, objects = build_scene(thickness=1.5, diagonal_mode="SOLID")
    depsgraph = bpy.context.evaluated_depsgraph_get()
    view = camera_view(scene, depsgraph, (WIDTH, HEIGHT))
    settings = scene.solidwire.snapshot()
    frame = runtime.begin_frame()
    items, seen, _ms = gather(depsgraph, runtime.mesh_cache)

    def coverage(bias):
        import gpu

        viewport = FakeViewport(WIDTH, HEIGHT, "DEPTH24_STENCIL8")
        viewport.depth_pass(depsgraph, view, objects)
        with viewport.framebuffer.bind():
            gpu.state.viewport_set(0, 0, WIDTH, HEIGHT)
            passes.draw_over_viewport(items, view, settings, depth_bias=bias)
        return viewport.rgba()[..., 3]

    biased = coverage(passes.OVERLAY_DEPTH_BIAS)
    unbiased = coverage(0.0)
    runtime.end_frame(frame, draw.DrawStats(), 0.0, 0.0, seen)
    lit = biased > 0.5
    assert lit.sum() > 100
    # Without the bias some wire pixels lose the depth tie (stipple); with it
    # none do. (Reported, not required: exact ties depend on the GPU.)
    lost = int((lit & (unbiased < 0.5)).sum())
    print(f"wire pixels lost without depth bias: {lost} of {int(lit.sum())}")
    # The bias in view depth at the far side of the scene stays tiny.
    n, f = 0.1, 100.0  # the test camera's clip range
    z = 12.0
    # NDC z(z_view) = (f+n)/(f-n) - 2fn/((f-n) z): dz_view = bias / (dNDC/dz).
    dndc_dz = 2 * f * n / ((f - n) * z * z)
    assert passes.OVERLAY_DEPTH_BIAS / dndc_dz < 0.01 * z


def test_visibility_filter():
    scene = scenes.empty_scene()
    shown = scenes.cube(scene, "Shown")
    hidden = scenes.cube(scene, "Hidden", location=(3, 0, 0))
    hidden.hide_set(True)
    opted_out = scenes.cube(scene, "OptedOut", location=(0, 3, 0))
    opted_out.solidwire_exclude = True
    collection = bpy.data.collections.new("HiddenCollection")
    scene.collection.children.link(collection)
    in_hidden_collection = scenes.cube(scene, "InHiddenCollection", location=(0, -3, 0))
    scene.collection.objects.unlink(in_hidden_collection)
    collection.objects.link(in_hidden_collection)
    view_layer = bpy.context.view_layer
    view_layer.layer_collection.children["HiddenCollection"].hide_viewport = True

    keep = overlay.viewport_object_filter(view_layer)
    assert keep(shown)
    assert not keep(hidden)
    assert not keep(opted_out)
    assert not keep(in_hidden_collection)

    shown.select_set(False)
    selected = scenes.cube(scene, "Selected", location=(3, 3, 0))
    selected.select_set(True)
    keep_selected = overlay.viewport_object_filter(view_layer, only_selected=True)
    assert keep_selected(selected) and not keep_selected(shown)


def test_frame_filter_answers_as_the_filter_once_per_object(monkeypatch):
    """The draw handler's filter (one frame) keeps exactly what the plain
    filter keeps, and reads each object once however many instances ask."""

    scene = scenes.empty_scene()
    shown = scenes.cube(scene, "Shown")
    hidden = scenes.cube(scene, "Hidden", location=(3, 0, 0))
    hidden.hide_set(True)
    opted_out = scenes.cube(scene, "OptedOut", location=(0, 3, 0))
    opted_out.solidwire.show_in_viewport = False
    selected = scenes.cube(scene, "Selected", location=(3, 3, 0))
    for obj in scene.objects:
        obj.select_set(obj is selected)
    view_layer = bpy.context.view_layer
    for state in (
        overlay_state.ViewportState(),
        overlay_state.ViewportState(only_selected=True),
        overlay_state.ViewportState(draw_edit_mode=False),
    ):
        plan = overlay_state.plan_overlay(state)
        plain = overlay.object_filter(plan, view_layer)
        per_frame = overlay.frame_object_filter(plan, view_layer)
        for obj in (shown, hidden, opted_out, selected):
            assert per_frame(obj) == plain(obj), (state, obj.name)

    reads = []
    real = overlay.object_state
    monkeypatch.setattr(overlay, "object_state", lambda obj, *args: reads.append(obj.name) or real(obj, *args))
    per_frame = overlay.frame_object_filter(overlay_state.plan_overlay(overlay_state.ViewportState()), view_layer)
    for _ in range(3):
        assert per_frame(shown)
    assert reads == ["Shown"]


def test_instances_follow_their_instancer():
    """A collection instance is drawn when its instancer is visible, even
    though the instanced collection itself is excluded from the view layer."""
    scene = scenes.empty_scene()
    source = bpy.data.collections.new("Source")
    scene.collection.children.link(source)
    part = scenes.cube(scene, "Part")
    scene.collection.objects.unlink(part)
    source.objects.link(part)
    bpy.context.view_layer.layer_collection.children["Source"].exclude = True
    instancer = bpy.data.objects.new("Instancer", None)
    instancer.instance_type = "COLLECTION"
    instancer.instance_collection = source
    scene.collection.objects.link(instancer)

    depsgraph = bpy.context.evaluated_depsgraph_get()
    keep = overlay.viewport_object_filter(bpy.context.view_layer)
    runtime.begin_frame()
    items, _seen, _ms = gather(depsgraph, runtime.mesh_cache, object_filter=keep)
    assert len(items) == 1
    instancer.solidwire_exclude = True
    runtime.begin_frame()
    items, _seen, _ms = gather(depsgraph, runtime.mesh_cache, object_filter=keep)
    assert items == []


def test_edit_mode_mesh_is_drawn_as_edited():
    import bmesh

    scene = scenes.empty_scene()
    obj = scenes.cube(scene, "Edited")
    bpy.context.view_layer.objects.active = obj
    obj.select_set(True)
    bpy.ops.object.mode_set(mode="EDIT")
    try:
        bm = bmesh.from_edit_mesh(obj.data)
        bm.verts.ensure_lookup_table()
        bm.verts[0].co.x += 5.0
        bmesh.update_edit_mesh(obj.data)
        depsgraph = bpy.context.evaluated_depsgraph_get()
        runtime.begin_frame()
        items, _seen, _ms = gather(depsgraph, runtime.mesh_cache)
        assert len(items) == 1 and items[0].mesh.triangle_count == 12
        extent = items[0].mesh.bounds_max - items[0].mesh.bounds_min
        assert extent[0] == pytest.approx(5.0)  # the moved vertex (x: -1 -> 4) is in the drawn mesh
    finally:
        bpy.ops.object.mode_set(mode="OBJECT")


def test_draw_handler_never_raises(monkeypatch, capsys):
    scene = scenes.empty_scene(show_overlay=True)
    scenes.cube(scene)
    # Headless there is no region: the handler returns quietly.
    overlay._draw_callback()

    def broken(*_args, **_kwargs):
        raise RuntimeError("boom")

    monkeypatch.setattr(overlay, "region_view", lambda *_a: View(np.eye(4), np.eye(4), (0, 0, 8, 8)))
    monkeypatch.setattr(overlay, "draw_scene_overlay", broken)

    class FakeContext:
        def __init__(self):
            self.scene = bpy.context.scene
            self.space_data = None
            self.region = object()
            self.region_data = object()
            self.view_layer = bpy.context.view_layer
            self.screen = None
            self.area = None
            self.preferences = bpy.context.preferences

        def evaluated_depsgraph_get(self):
            return bpy.context.evaluated_depsgraph_get()

    class FakeBpy:
        context = FakeContext()

    monkeypatch.setattr(overlay, "bpy", FakeBpy)
    log.forget()
    overlay._draw_callback()
    overlay._draw_callback()  # a second failure is not reported again
    err = capsys.readouterr().err
    assert err.count("SolidWire overlay: RuntimeError: boom") == 1


def test_handler_registered_once():
    import solidwire_addon

    assert overlay.is_registered()
    solidwire_addon.register()  # idempotent
    assert overlay.is_registered()
    solidwire_addon.unregister()
    assert not overlay.is_registered()
    assert not hasattr(bpy.types.Object, "solidwire_exclude")
    solidwire_addon.register()
    assert overlay.is_registered()


def test_redraws_reuse_meshes_and_see_edits():
    """A redraw with nothing changed extracts nothing; an edit is drawn at once."""
    scene, objects = build_scene()
    view_layer = bpy.context.view_layer
    keep = overlay.viewport_object_filter(view_layer)

    def redraw():
        depsgraph = bpy.context.evaluated_depsgraph_get()
        view = camera_view(scene, depsgraph, (WIDTH, HEIGHT))
        viewport = FakeViewport(WIDTH, HEIGHT)
        viewport.depth_pass(depsgraph, view, objects)  # (Solid shading: Blender's depth holds the surfaces)
        stats = viewport.draw_overlay(depsgraph, view, scene.solidwire.snapshot(), object_filter=keep)
        return stats, viewport.rgba()[..., 3]

    first, alpha_first = redraw()
    assert first["objects_drawn"] == 2
    second, alpha_second = redraw()
    assert second["meshes_extracted"] == 0 and second["meshes_reused"] == 2
    assert np.array_equal(alpha_first, alpha_second)

    front = objects[0]
    front.data.vertices[0].co.z += 0.7
    front.data.update()
    third, alpha_third = redraw()
    # Only a vertex moved: the position table alone is uploaded again ...
    assert third["meshes_extracted"] == 0 and third["meshes_repositioned"] == 1
    assert not np.array_equal(alpha_second, alpha_third)
    # ... and draws exactly what a full extraction draws.
    runtime.mesh_cache.clear()
    fourth, alpha_fourth = redraw()
    assert fourth["meshes_extracted"] == 2
    assert np.array_equal(alpha_third, alpha_fourth)


@pytest.mark.parametrize(
    "features",
    [{"use_hidden_lines": True}, {"use_silhouettes": True}, {"use_hidden_lines": True, "use_fill": True}],
    ids=["hidden_lines", "silhouettes", "hidden_lines_fill"],
)
def test_overlay_matches_render_engine_with_line_styles(features, output_dir):
    """Hidden-line style and full-width silhouettes look the same in
    the viewport as in the render. Silhouette fins blend "over" in the
    viewport (the render keeps the exact maximum), so only the corner pixels
    where two fins overlap may differ; they are few and bounded."""
    scene, objects = build_scene(thickness=1.5, **features)
    depsgraph = bpy.context.evaluated_depsgraph_get()
    rgba_engine, depth_engine = engine.render_scene(depsgraph, (WIDTH, HEIGHT))
    view = camera_view(scene, depsgraph, (WIDTH, HEIGHT))
    viewport = FakeViewport(WIDTH, HEIGHT, "DEPTH32F_STENCIL8")
    viewport.depth_pass(depsgraph, view, objects)
    viewport.draw_overlay(depsgraph, view, scene.solidwire.snapshot())
    rgba_overlay = viewport.rgba()
    diff = np.abs(rgba_overlay[..., 3] - rgba_engine[..., 3])
    # Outer halves reach h + 2s = 2.75 px beyond a silhouette.
    off_silhouette = ~silhouette_mask(depth_engine, radius=4 if "use_silhouettes" in features else 1)
    assert rgba_engine[..., 3].max() > 0.9
    assert np.percentile(diff[off_silhouette], 99.9) <= 2.0 / 255.0 + 1e-9
    assert diff[off_silhouette].max() <= 0.1
    if "use_silhouettes" in features:
        wire = rgba_engine[..., 3] > 0.01
        assert (diff > 2.0 / 255.0).sum() <= 0.05 * wire.sum()
        assert diff.max() <= 0.3
