"""Render passes (docs/image_model.md §6): Blender's Normal, IndexOB, IndexMA and
SolidWire's Wire, Hidden Wire and Edge Distance, each against its
definition, in a multilayer EXR with two view layers."""

from __future__ import annotations

import bpy
import numpy as np
from mathutils import Vector

from solidwire_addon.blender import engine
from solidwire_addon.core import draw as draw_mod
from solidwire_addon.core import exr, passes
from tests.support import reference, scenes
from tests.test_engine_blender import _multilayer_render, _two_layer_scene

P999, MAX = 2.0 / 255.0, 0.1
ALL_PASSES = ("Normal", "IndexOB", "IndexMA", "Wire", "Hidden Wire", "Edge Distance")


def _enable_all(view_layer) -> None:
    view_layer.use_pass_z = True
    view_layer.use_pass_normal = True
    view_layer.use_pass_object_index = True
    view_layer.use_pass_material_index = True
    props = view_layer.solidwire
    props.use_pass_wire = props.use_pass_hidden_wire = props.use_pass_edge_distance = True


def _layer_reference(scene, view_layer, *, hidden_lines=False):
    """The reference of ``view_layer``'s objects: headless, only the context's
    view layer has a depsgraph, so it borrows the layer's collection
    switches for the evaluation."""
    active = bpy.context.view_layer
    children = active.layer_collection.children
    saved = {child.name: child.exclude for child in children}
    for child in view_layer.layer_collection.children:
        children[child.name].exclude = child.exclude
    scene.solidwire.use_hidden_lines = hidden_lines
    try:
        return reference.render_reference(scene, bpy.context.evaluated_depsgraph_get())
    finally:
        scene.solidwire.use_hidden_lines = False
        for name, exclude in saved.items():
            children[name].exclude = exclude


def _expected_normals(scene, ref) -> np.ndarray:
    """World-space polygon normal of the visible face, turned towards the
    camera (all faces of these scenes are planar), 0 on background."""
    camera = scene.camera.matrix_world.translation
    out = np.zeros((*ref.face.shape, 3))
    for index, name in enumerate(ref.objects):
        obj = bpy.data.objects[name]
        normal_matrix = obj.matrix_world.to_3x3().inverted().transposed()
        here = ref.face_object == index
        for pixel_face in np.unique(ref.face[here]):
            polygon = obj.data.polygons[int(pixel_face) - ref.object_face_offsets[index]]
            n = (normal_matrix @ polygon.normal).normalized()
            centre = obj.matrix_world @ polygon.center
            if n.dot(Vector(camera) - centre) < 0.0:
                n = -n
            out[ref.face == pixel_face] = tuple(n)
    return out


def _check_layer(scene, view_layer, channels, name: str, pass_indices: dict) -> None:
    ref = _layer_reference(scene, view_layer)
    ref_hidden = _layer_reference(scene, view_layer, hidden_lines=True)
    off = ~ref.on_silhouette & ~ref_hidden.on_silhouette
    covered = ref.face >= 0

    def channel(pass_name, ids):
        value = exr.exr_pass(channels, name, pass_name, ids)
        assert value is not None, f"{name}: no {pass_name} pass"
        return value

    wire = channel("Wire", "X")[..., 0]
    error = np.abs(wire - ref.intensity)[off]
    assert np.percentile(error, 99.9) <= P999 and error.max() <= MAX, (name, error.max())

    # d_real in window px on covered samples; 1e10 on background.
    distance = channel("Edge Distance", "X")[..., 0]
    near = off & covered & (ref.d_real < 50.0)
    assert near.sum() > 200
    assert np.abs(distance[near] - ref.d_real[near]).max() <= 2e-3, name
    assert (distance[off & ~covered] == 1e10).all()

    hidden = channel("Hidden Wire", "X")[..., 0]
    error = np.abs(hidden - ref_hidden.hidden)[off]
    assert ref_hidden.hidden.max() > 0.3  # there are hidden edges to see (hidden_alpha 0.35)
    assert np.percentile(error, 99.9) <= P999 and error.max() <= MAX, (name, error.max())

    index = channel("IndexOB", "X")[..., 0]
    expected = np.zeros(ref.face.shape)
    for k, object_name in enumerate(ref.objects):
        expected[ref.face_object == k] = pass_indices[object_name]
    assert (index[off] == expected[off]).all(), name

    material = channel("IndexMA", "X")[..., 0]
    expected = np.zeros(ref.face.shape)
    for k, object_name in enumerate(ref.objects):
        obj = bpy.data.objects[object_name]
        passes_of_slots = [slot.material.pass_index for slot in obj.material_slots]
        here = ref.face_object == k
        for face in np.unique(ref.face[here]):
            polygon = obj.data.polygons[int(face) - ref.object_face_offsets[k]]
            if passes_of_slots:
                expected[ref.face == face] = passes_of_slots[min(polygon.material_index, len(passes_of_slots) - 1)]
    assert (material[off] == expected[off]).all(), name
    assert name != "Left" or set(np.unique(material[off])) == {0.0, 2.0, 9.0}

    normal = channel("Normal", "XYZ")
    assert np.abs(normal - _expected_normals(scene, ref))[off].max() <= 1e-4, name


def test_every_pass_of_two_view_layers_in_one_multilayer_exr(tmp_path):
    scene = _two_layer_scene()
    left_cube, right_sphere = bpy.data.objects["LeftCube"], bpy.data.objects["RightSphere"]
    left_cube.pass_index, right_sphere.pass_index = 3, 11
    left_cube.rotation_euler = (0.4, 0.3, 0.2)
    for pass_index in (2, 9):
        material = bpy.data.materials.new(f"Pass{pass_index}")
        material.pass_index = pass_index
        left_cube.data.materials.append(material)
    for polygon in left_cube.data.polygons:
        polygon.material_index = 1 if polygon.normal.y < -0.5 else 0  # the face towards the camera
    for view_layer in scene.view_layers:
        _enable_all(view_layer)
    channels = _multilayer_render(scene, tmp_path / "passes.exr")
    for view_layer in scene.view_layers:
        _check_layer(scene, view_layer, channels, view_layer.name, {"LeftCube": 3, "RightSphere": 11})


def test_passes_are_written_only_when_asked_for(tmp_path, monkeypatch):
    scene = scenes.empty_scene(48, 36)
    scenes.add_camera(scene, location=(2.5, -4.0, 1.8))
    scenes.cube(scene)
    calls = []
    real_draw = draw_mod.draw

    def spy(*args, **kwargs):
        calls.append((kwargs.get("target") or draw_mod.DrawTarget()).aovs)
        return real_draw(*args, **kwargs)

    monkeypatch.setattr(draw_mod, "draw", spy)
    view_layer = scene.view_layers[0]
    channels = _multilayer_render(scene, tmp_path / "plain.exr")
    assert not any(name.split(".")[1] in ALL_PASSES for name in channels)
    assert calls and not any(calls)  # the plain render draws no pass outputs

    view_layer.solidwire.use_pass_edge_distance = True
    calls.clear()
    channels = _multilayer_render(scene, tmp_path / "one.exr")
    assert {name.split(".")[1] for name in channels} == {"Combined", "Edge Distance"}
    assert any(calls)
    assert engine.extra_passes_of(view_layer) == (passes.EDGE_DISTANCE_PASS,)


def test_mirrored_object_normals_face_the_camera():
    scene = scenes.empty_scene(48, 36)
    scenes.add_camera(scene, location=(0.0, -6.0, 0.0))
    scenes.cube(scene, scale=(-1.0, 1.0, 1.0), rotation=(0.3, 0.0, 0.4))
    depsgraph = bpy.context.evaluated_depsgraph_get()
    extra = {}
    engine.render_scene(depsgraph, (48, 36), extra_passes=(passes.NORMAL_PASS,), extra_out=extra)
    normal = extra[passes.NORMAL_PASS]
    ref = reference.render_reference(scene, size=(48, 36))
    off = ~ref.on_silhouette
    assert np.abs(normal - _expected_normals(scene, ref))[off].max() <= 1e-4


def test_render_passes_leave_the_image_alone_under_hidden_lines(tmp_path):
    """Asking for every render pass changes no pixel of the Combined image,
    also under hidden lines, where the surface pass puts the visible wire in
    a layer of its own for the hidden lines to go between it and the fill:
    a cage look with edge classes in their own colours, dotted diagonals and
    a shaded fill (it once drew the class lines in the wire's colour when
    the passes were on)."""
    scene = scenes.empty_scene(
        160,
        120,
        use_fill=True,
        fill_shading="STUDIO",
        use_hidden_lines=True,
        hidden_alpha=0.6,
        use_cage_edges=True,
        use_seam_edges=True,
        use_sharp_edges=True,
        diagonal_mode="DOTTED",
    )
    scenes.add_camera(scene, location=(1.2, -3.4, 1.0), target=(0.0, 0.0, 0.0), lens=45.0)
    monkey = scenes.monkey(scene, rotation=(0.0, 0.0, 0.5))
    monkey.modifiers.new("Subdivision", "SUBSURF").levels = 1
    for edge in monkey.data.edges[:80]:
        edge.use_seam = edge.index % 2 == 0
        edge.use_edge_sharp = edge.index % 2 == 1
    plain = _multilayer_render(scene, tmp_path / "plain.exr")
    _enable_all(scene.view_layers[0])
    with_passes = _multilayer_render(scene, tmp_path / "passes.exr")
    layer = scene.view_layers[0].name
    combined = [
        np.stack([channels[f"{layer}.Combined.{c}"] for c in "RGBA"], axis=-1) for channels in (plain, with_passes)
    ]
    assert np.abs(combined[1] - combined[0]).max() <= 1e-6
    # The image shows the class colours, the wire's and the hidden lines.
    wire = exr.exr_pass(with_passes, layer, "Wire", "X")[..., 0]
    hidden = exr.exr_pass(with_passes, layer, "Hidden Wire", "X")[..., 0]
    assert (wire > 0.9).sum() > 200 and (hidden > 0.5).sum() > 50
    lines = combined[0][wire > 0.9][:, :3]
    assert len(np.unique(np.round(lines, 2), axis=0)) >= 3
