"""Text, curves, surfaces and metaballs show their outlines and profiles,
not the triangulation of their flat fills; Tessellation shows it again."""

from __future__ import annotations

import bpy
import numpy as np
import pytest

from tests.support import accuracy, reference, scenes

W, H = 96, 72


def _disc_scene(**settings):
    """A filled 2D Bézier circle (24 outline vertices) tilted towards the
    camera: a flat fill Blender triangulates as it likes."""
    scene = scenes.empty_scene(W, H, **settings)
    bpy.ops.curve.primitive_bezier_circle_add(radius=1.0)
    disc = bpy.context.active_object
    disc.data.dimensions = "2D"
    disc.data.fill_mode = "BOTH"
    disc.data.resolution_u = 6
    disc.rotation_euler = (0.5, 0.2, 0.3)
    scenes.add_camera(scene, location=(0.4, -3.2, 2.2), target=(0.0, 0.0, 0.0))
    return scene, disc


def _evaluated_mesh(obj):
    """(vertices, faces) of ``obj``'s evaluated mesh, in object space."""
    evaluated = obj.evaluated_get(bpy.context.evaluated_depsgraph_get())
    mesh = evaluated.to_mesh()
    try:
        verts = [tuple(v.co) for v in mesh.vertices]
        faces = [tuple(p.vertices) for p in mesh.polygons]
    finally:
        evaluated.to_mesh_clear()
    return verts, faces


def _outline_loop(faces) -> list:
    """The boundary of a disc of faces as one ordered vertex loop."""
    uses: dict = {}
    for face in faces:
        for a, b in zip(face, face[1:] + face[:1]):
            key = (min(a, b), max(a, b))
            uses[key] = uses.get(key, 0) + 1
    nxt: dict = {}
    for face in faces:
        for a, b in zip(face, face[1:] + face[:1]):
            if uses[(min(a, b), max(a, b))] == 1:
                nxt[a] = b
    start = next(iter(nxt))
    loop = [start]
    while nxt[loop[-1]] != start:
        loop.append(nxt[loop[-1]])
    return loop


def _replace_with_mesh(scene, obj, verts, faces):
    """A mesh object with ``verts`` and ``faces`` where ``obj`` was."""
    mesh = bpy.data.meshes.new("Copy")
    mesh.from_pydata(verts, [], faces)
    mesh.update()
    copy = bpy.data.objects.new("Copy", mesh)
    copy.matrix_world = obj.matrix_world.copy()
    scene.collection.objects.link(copy)
    bpy.data.objects.remove(obj)
    return copy


def test_filled_curve_draws_its_outline_like_one_ngon(output_dir):
    """The filled circle renders as the float64 reference of a mesh with one
    n-gon of the same outline: no line inside the fill."""
    scene, disc = _disc_scene()
    verts, faces = _evaluated_mesh(disc)
    assert len(faces) > 10  # the fill is triangulated
    rgba = scenes.render_to_file(scene, output_dir / "outline_disc.png")
    # The reference evaluates §3.9 on the curve itself, too.
    accuracy.assert_accurate(reference.error_report(rgba[..., 3], reference.render_reference(scene)))
    loop = _outline_loop(faces)
    _replace_with_mesh(scene, disc, verts, [tuple(loop)])
    ref = reference.render_reference(scene)
    report = reference.error_report(rgba[..., 3], ref)
    accuracy.assert_accurate(report)
    # Not vacuous: the triangulation's own lines would be far off.
    interior = (ref.face >= 0) & (ref.intensity < 0.01) & ~ref.on_silhouette
    assert interior.sum() > 200


def test_tessellation_setting_draws_every_edge(output_dir):
    """With Tessellation on, the curve draws exactly as a mesh made of its
    evaluated faces; with it off, inner lines are gone."""
    scene, disc = _disc_scene(show_tessellation=True)
    verts, faces = _evaluated_mesh(disc)
    tessellated = scenes.render_to_file(scene, output_dir / "tessellated_disc.png")
    accuracy.assert_accurate(reference.error_report(tessellated[..., 3], reference.render_reference(scene)))
    scene.solidwire.show_tessellation = False
    outlined = scenes.render_to_file(scene, output_dir / "outlined_disc.png")
    _replace_with_mesh(scene, disc, verts, faces)
    scene.solidwire.show_tessellation = True  # (no effect on a mesh object)
    as_mesh = scenes.render_to_file(scene, output_dir / "disc_as_mesh.png")
    ref = reference.render_reference(scene)
    accuracy.assert_accurate(reference.error_report(tessellated[..., 3], ref))
    assert np.abs(as_mesh[..., 3] - tessellated[..., 3]).max() <= 2.0 / 255.0
    assert (tessellated[..., 3] - outlined[..., 3]).sum() > 20.0  # the inner lines


@pytest.mark.parametrize("kind", ["FONT", "SURFACE", "META"])
def test_other_tessellated_sources_render_without_errors(kind, output_dir, capfd):
    """Text, a NURBS surface and a metaball render under the default look
    with the outline rule and without it, with no message."""
    # Text large enough that its letters' insides are more than their
    # outlines' reach (at W x H the outline lines alone cover them).
    scene = scenes.empty_scene(4 * W, 4 * H) if kind == "FONT" else scenes.empty_scene(W, H)
    if kind == "FONT":
        data = bpy.data.curves.new("Text", "FONT")
        data.body = "Ab"
        obj = bpy.data.objects.new("Text", data)
        scene.collection.objects.link(obj)
    elif kind == "SURFACE":
        bpy.ops.surface.primitive_nurbs_surface_torus_add()
    else:
        bpy.ops.object.metaball_add()
    scenes.add_camera(scene, location=(0.5, -4.0, 2.0), target=(0.4, 0.0, 0.0))
    capfd.readouterr()
    images = []
    for show in (False, True):
        scene.solidwire.show_tessellation = show
        images.append(scenes.render_to_file(scene, output_dir / f"tessellated_{kind}_{show}.png"))
    err = capfd.readouterr()
    assert "SolidWire" not in err.err, err.err
    assert all(image[..., 3].max() > 0.5 for image in images)
    if kind == "FONT":  # flat letter faces: the triangulation shows only with Tessellation
        assert (images[1][..., 3] - images[0][..., 3]).sum() > 0.3 * images[0][..., 3].sum()


def test_text_outlines_are_not_faded_as_dense(output_dir):
    """A letter's outline is a chain of short segments along a smooth
    curve: Fade Dense Objects (default look) leaves text alone, while the
    same segments as a plain mesh count as dense."""
    scene = scenes.default_look(scenes.empty_scene(W, H))
    data = bpy.data.curves.new("Text", "FONT")
    data.body = "S"
    data.resolution_u = 24
    text = bpy.data.objects.new("Text", data)
    scene.collection.objects.link(text)
    # Far enough that the letter's segments are well under Fade Below on
    # screen with every Blender version's tessellation of the glyph.
    scenes.add_camera(scene, location=(0.3, -2.4, 1.8), target=(0.3, 0.3, 0.0))
    assert scene.solidwire.use_object_density_fade
    default = scenes.render_to_file(scene, output_dir / "text_default.png")
    scene.solidwire.use_object_density_fade = False
    unfaded = scenes.render_to_file(scene, output_dir / "text_unfaded.png")
    assert np.array_equal(default, unfaded)
    # The same geometry as a mesh object is faded: the rule is live here.
    verts, faces = _evaluated_mesh(text)
    _replace_with_mesh(scene, text, verts, faces)
    mesh_unfaded = scenes.render_to_file(scene, output_dir / "text_mesh_unfaded.png")
    scene.solidwire.use_object_density_fade = True
    mesh_default = scenes.render_to_file(scene, output_dir / "text_mesh_default.png")
    assert np.abs(mesh_default - mesh_unfaded).max() > 0.1


def test_geometry_nodes_on_a_curve_make_an_ordinary_mesh(output_dir):
    """A curve object whose geometry nodes output a grid of quads (geometry
    the user designed) draws every edge of it, as the reference of a mesh
    does: only Blender's own tessellation is drawn as outlines."""
    scene, disc = _disc_scene()
    tree = bpy.data.node_groups.new("Grid", "GeometryNodeTree")
    tree.interface.new_socket("Geometry", in_out="INPUT", socket_type="NodeSocketGeometry")
    tree.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
    grid = tree.nodes.new("GeometryNodeMeshGrid")
    grid.inputs["Vertices X"].default_value = 4
    grid.inputs["Vertices Y"].default_value = 4
    out = tree.nodes.new("NodeGroupOutput")
    tree.links.new(grid.outputs["Mesh"], out.inputs[0])
    disc.modifiers.new("Grid", "NODES").node_group = tree
    rgba = scenes.render_to_file(scene, output_dir / "curve_nodes_grid.png")
    ref = reference.render_reference(scene)
    accuracy.assert_accurate(reference.error_report(rgba[..., 3], ref))
    # The flat grid's inner lines are there (as Tessellation off would hide them).
    scene.solidwire.show_tessellation = True
    assert np.array_equal(scenes.render_to_file(scene, output_dir / "curve_nodes_grid_t.png"), rgba)
    assert (ref.intensity > 0.5).sum() > 60
