"""Hair (Curves) and point-cloud objects for tests and galleries."""

from __future__ import annotations

import bpy
import numpy as np

CATMULL_ROM, POLY, BEZIER = 0, 1, 2


def hair(
    scene, name, curves, radii=None, *, types=None, resolution=None, handles=None, location=(0, 0, 0), scale=(1, 1, 1)
):
    """A Curves object with one curve per (n, 3) array of ``curves``;
    ``radii`` one (n,) array (or None) per curve; ``types`` per curve
    (default POLY); ``handles`` (left, right) (P, 3) positions of every
    point (Bezier curves)."""
    data = bpy.data.hair_curves.new(name)
    sizes = [len(c) for c in curves]
    if sizes:
        data.add_curves(sizes)
        positions = np.concatenate([np.asarray(c, dtype=np.float32) for c in curves])
        data.attributes["position"].data.foreach_set("vector", positions.ravel())
        if radii is not None:
            values = np.concatenate(
                [
                    np.full(n, 0.0) if r is None else np.broadcast_to(np.asarray(r, float), (n,))
                    for n, r in zip(sizes, radii)
                ]
            ).astype(np.float32)
            data.attributes.new("radius", "FLOAT", "POINT").data.foreach_set("value", values)
        kinds = [POLY] * len(curves) if types is None else list(types)
        # (set_types: a foreach_set on the INT8 attribute overruns its buffer.)
        for kind, type_name in ((CATMULL_ROM, "CATMULL_ROM"), (POLY, "POLY"), (BEZIER, "BEZIER")):
            indices = [i for i, k in enumerate(kinds) if k == kind]
            if indices:
                data.set_types(type=type_name, indices=indices)
        if handles is not None:
            for attribute, values in zip(("handle_left", "handle_right"), handles):
                data.attributes.new(attribute, "FLOAT_VECTOR", "POINT").data.foreach_set(
                    "vector", np.asarray(values, dtype=np.float32).ravel()
                )
        if resolution is not None:
            data.attributes.new("resolution", "INT", "CURVE").data.foreach_set("value", [resolution] * len(curves))
    obj = bpy.data.objects.new(name, data)
    obj.location = location
    obj.scale = scale
    scene.collection.objects.link(obj)
    return obj


def _points_group(radius: float):
    group = bpy.data.node_groups.new("MeshToPoints", "GeometryNodeTree")
    group.interface.new_socket("Geometry", in_out="INPUT", socket_type="NodeSocketGeometry")
    group.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
    group_in = group.nodes.new("NodeGroupInput")
    group_out = group.nodes.new("NodeGroupOutput")
    to_points = group.nodes.new("GeometryNodeMeshToPoints")
    to_points.inputs["Radius"].default_value = radius
    group.links.new(group_in.outputs[0], to_points.inputs["Mesh"])
    group.links.new(to_points.outputs[0], group_out.inputs[0])
    return group


def point_cloud(scene, name, points, radius: float, *, location=(0, 0, 0)):
    """A mesh object whose geometry nodes turn its vertices into a point
    cloud of one ``radius`` (Blender's Python API cannot size a PointCloud
    datablock); its evaluated instance is a POINTCLOUD."""
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata([tuple(p) for p in points], [], [])
    obj = bpy.data.objects.new(name, mesh)
    obj.location = location
    scene.collection.objects.link(obj)
    modifier = obj.modifiers.new("Points", "NODES")
    modifier.node_group = _points_group(radius)
    return obj


def hair_tuft(rng, root, count, length, spread):
    """``count`` curved strands of 6 points from ``root`` (for galleries)."""
    curves = []
    for _ in range(count):
        direction = np.array([rng.normal(0, spread), rng.normal(0, spread), 1.0])
        bend = np.array([rng.normal(0, 0.4), rng.normal(0, 0.4), 0.0])
        t = np.linspace(0.0, 1.0, 6)[:, None]
        curves.append(np.asarray(root) + length * (t * direction + t * t * bend))
    return curves
