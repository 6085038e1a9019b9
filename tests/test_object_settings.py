"""Per-object settings (``object.solidwire``, docs/image_model.md §5.9):
show in viewport / render, the style override and instances, through the
render engine against the float64 reference and through the overlay."""

from __future__ import annotations

import bpy
import numpy as np
import pytest

from solidwire_addon.blender import engine, gather, overlay, runtime
from tests.support import reference, scenes

WIDTH, HEIGHT = 120, 80


def _override(obj, wire, thickness, fill):
    props = obj.solidwire
    props.use_override = True
    props.wire_color, props.thickness, props.fill_color = wire, thickness, fill


def _expected_rgba(scene, ref) -> np.ndarray:
    """The image model's premultiplied colour (§5.1, §5.2) from the
    reference's intensity, each face coloured by its style object."""
    scene_props = scene.solidwire
    wire = np.zeros((len(ref.objects) + 1, 4))
    fill = np.zeros((len(ref.objects) + 1, 3))
    for index, name in enumerate(ref.objects):
        props = bpy.data.objects[name].solidwire
        source = props if props.use_override else scene_props
        wire[index], fill[index] = source.wire_color, source.fill_color[:3]
    idx = np.where(ref.face_object >= 0, ref.face_object, len(ref.objects))
    covered = (ref.face_object >= 0)[..., None]
    a = wire[idx, 3:4] * ref.intensity[..., None]
    if scene_props.use_fill:
        rgb = a * wire[idx, :3] + (1.0 - a) * fill[idx]
        return np.where(covered, np.concatenate([rgb, np.ones_like(a)], axis=-1), 0.0)
    return np.where(covered, np.concatenate([a * wire[idx, :3], a], axis=-1), 0.0)


def _assert_matches_reference(scene, rgba, ref):
    expected = _expected_rgba(scene, ref)
    error = np.abs(rgba - expected).max(axis=-1)[~ref.on_silhouette]
    assert np.isfinite(rgba).all()
    assert np.percentile(error, 99.9) <= 2.0 / 255.0, np.percentile(error, 99.9)
    assert error.max() <= 0.1, error.max()


@pytest.mark.parametrize("use_fill", [True, False])
def test_show_in_render_and_override_match_the_reference(use_fill):
    scene = scenes.empty_scene(WIDTH, HEIGHT, use_fill=use_fill)
    scene.solidwire.fill_color = (0.0, 0.4, 0.0)
    scenes.add_camera(scene, location=(0.0, -10.0, 2.0), target=(0.0, 0.0, 0.0))
    scenes.cube(scene, "Plain", size=1.6, location=(-2.4, 0.0, 0.0), rotation=(0.3, 0.2, 0.5))
    styled = scenes.uv_sphere(scene, "Styled", location=(0.0, 0.0, 0.0), radius=1.2)
    _override(styled, (1.0, 0.2, 0.0, 0.8), 4.0, (0.0, 0.0, 1.0))
    old = scenes.monkey(scene, "OldFile", location=(2.6, 0.0, 0.0))
    old.solidwire_exclude = True  # the older viewport opt-out: still rendered
    occluder = scenes.cube(scene, "NotRendered", size=3.0, location=(0.0, -3.0, 0.0))
    occluder.solidwire.show_in_render = False  # neither drawn nor hiding the sphere

    depsgraph = bpy.context.evaluated_depsgraph_get()
    rgba, _depth = engine.render_scene(depsgraph, (WIDTH, HEIGHT))
    ref = reference.render_reference(scene)
    assert sorted(ref.objects) == ["OldFile", "Plain", "Styled"]
    on_styled = ref.face_object == ref.objects.index("Styled")
    assert on_styled.sum() > 500  # the sphere is visible through the unrendered cube
    _assert_matches_reference(scene, rgba, ref)
    # The override shows: its wire is red, and it is thicker than the scene's.
    red = on_styled & (ref.intensity > 0.9)
    assert red.any() and (rgba[red, 0] > 0.5).all() and (rgba[red, 1] < 0.5).all()


def test_instances_take_the_settings_of_the_object_they_instance():
    scene = scenes.empty_scene(WIDTH, HEIGHT)
    scenes.add_camera(scene, location=(0.0, -20.0, 9.0), target=(0.0, 0.0, 0.0))
    # 40 linked duplicates of one mesh (drawn with one instanced call per
    # style), every other one with its own style.
    first = scenes.cube(scene, "Dup0", size=0.8, location=(-7.0, 0.0, 0.0))
    duplicates = [first]
    for k in range(1, 40):
        obj = bpy.data.objects.new(f"Dup{k}", first.data)
        scene.collection.objects.link(obj)
        obj.location = (-7.0 + (k % 8) * 2.0, (k // 8) * 2.0, 0.0)
        obj.rotation_euler = (0.1 * k, 0.2, 0.05 * k)
        duplicates.append(obj)
    for obj in duplicates[::2]:
        _override(obj, (0.0, 1.0, 0.0, 1.0), 3.0, (1.0, 1.0, 1.0))
    # A collection instance of a styled sphere the scene does not hold, and
    # a second instancer of it that is off in renders.
    proto = bpy.data.collections.new("Proto")
    sphere = scenes.uv_sphere(scene, "ProtoSphere", radius=0.9)
    scene.collection.objects.unlink(sphere)
    proto.objects.link(sphere)
    _override(sphere, (1.0, 0.0, 1.0, 1.0), 2.5, (1.0, 1.0, 1.0))
    for name, location, shown in (("Shown", (0.0, -3.0, 2.5), True), ("Off", (3.0, -3.0, 2.5), False)):
        instancer = bpy.data.objects.new(name, None)
        instancer.instance_type = "COLLECTION"
        instancer.instance_collection = proto
        instancer.location = location
        instancer.solidwire.show_in_render = shown
        scene.collection.objects.link(instancer)

    depsgraph = bpy.context.evaluated_depsgraph_get()
    runtime.begin_frame()
    items, _seen, _ms = gather.gather(
        depsgraph, runtime.mesh_cache, object_settings=gather.ObjectSettings(gather.SHOW_IN_RENDER, bpy.data.objects)
    )
    assert len(items) == 41
    styles = [item.style for item in items]
    assert sum(s is not None and s.thickness == 3.0 for s in styles) == 20
    assert sum(s is not None and s.thickness == 2.5 for s in styles) == 1

    rgba, _depth = engine.render_scene(depsgraph, (WIDTH, HEIGHT))
    assert runtime.stats().get("instanced_draws", 0) >= 2
    ref = reference.render_reference(scene)
    assert ref.objects.count("ProtoSphere") == 1
    _assert_matches_reference(scene, rgba, ref)


def test_overlay_honours_show_in_viewport():
    scene = scenes.empty_scene()
    shown = scenes.cube(scene, "Shown")
    render_only = scenes.cube(scene, "RenderOnly", location=(3, 0, 0))
    render_only.solidwire.show_in_viewport = False
    viewport_only = scenes.cube(scene, "ViewportOnly", location=(0, 3, 0))
    viewport_only.solidwire.show_in_render = False
    keep = overlay.viewport_object_filter(bpy.context.view_layer)
    assert keep(shown) and keep(viewport_only) and not keep(render_only)

    depsgraph = bpy.context.evaluated_depsgraph_get()
    for show, expected in ((gather.SHOW_IN_VIEWPORT, 2), (gather.SHOW_IN_RENDER, 2)):
        runtime.begin_frame()
        items, _seen, _ms = gather.gather(
            depsgraph, runtime.mesh_cache, object_settings=gather.ObjectSettings(show, bpy.data.objects)
        )
        assert len(items) == expected
    # The older opt-out is the viewport switch.
    shown.solidwire_exclude = True
    runtime.begin_frame()
    items, _seen, _ms = gather.gather(
        depsgraph, runtime.mesh_cache, object_settings=gather.ObjectSettings(gather.SHOW_IN_VIEWPORT, bpy.data.objects)
    )
    assert len(items) == 1
