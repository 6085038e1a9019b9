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
    # Before Blender 4.3 (no set_types; writing the curve_type attribute
    # leaves Blender's type counts stale and evaluation aborts) the types
    # and handles are set by a geometry-nodes modifier (_typed_curves).
    by_modifier = bool(sizes) and not hasattr(data, "set_types")
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
        if by_modifier:
            data.attributes.new(_TYPE, "INT", "CURVE").data.foreach_set("value", kinds)
        else:
            # (set_types: a foreach_set on the INT8 attribute overruns its buffer.)
            for kind, type_name in ((CATMULL_ROM, "CATMULL_ROM"), (POLY, "POLY"), (BEZIER, "BEZIER")):
                indices = [i for i, k in enumerate(kinds) if k == kind]
                if indices:
                    data.set_types(type=type_name, indices=indices)
        if handles is not None:
            for attribute, values in zip(("handle_left", "handle_right"), handles):
                stored = _HANDLE[attribute] if by_modifier else attribute
                data.attributes.new(stored, "FLOAT_VECTOR", "POINT").data.foreach_set(
                    "vector", np.asarray(values, dtype=np.float32).ravel()
                )
        if resolution is not None:
            data.attributes.new("resolution", "INT", "CURVE").data.foreach_set("value", [resolution] * len(curves))
    obj = bpy.data.objects.new(name, data)
    obj.location = location
    obj.scale = scale
    scene.collection.objects.link(obj)
    if by_modifier:
        obj.modifiers.new("Types", "NODES").node_group = _typed_curves(handles is not None)
    return obj


_TYPE = "test_curve_type"
_HANDLE = {"handle_left": "test_handle_left", "handle_right": "test_handle_right"}


def _typed_curves(handles: bool):
    """Geometry nodes giving each curve the type in its _TYPE attribute and,
    with ``handles``, the Bezier handles in the _HANDLE attributes."""
    group = bpy.data.node_groups.new("TypedCurves", "GeometryNodeTree")
    group.interface.new_socket("Geometry", in_out="INPUT", socket_type="NodeSocketGeometry")
    group.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
    nodes, links = group.nodes, group.links
    geometry = nodes.new("NodeGroupInput").outputs[0]
    kind = nodes.new("GeometryNodeInputNamedAttribute")
    kind.data_type = "INT"
    kind.inputs["Name"].default_value = _TYPE
    for value, type_name in ((CATMULL_ROM, "CATMULL_ROM"), (POLY, "POLY"), (BEZIER, "BEZIER")):
        is_type = nodes.new("FunctionNodeCompare")
        is_type.data_type, is_type.operation = "INT", "EQUAL"
        links.new(kind.outputs["Attribute"], is_type.inputs[2])
        is_type.inputs[3].default_value = value
        set_type = nodes.new("GeometryNodeCurveSplineType")
        set_type.spline_type = type_name
        links.new(geometry, set_type.inputs["Curve"])
        links.new(is_type.outputs[0], set_type.inputs["Selection"])
        geometry = set_type.outputs[0]
    if handles:
        for side in ("LEFT", "RIGHT"):
            position = nodes.new("GeometryNodeInputNamedAttribute")
            position.data_type = "FLOAT_VECTOR"
            position.inputs["Name"].default_value = _HANDLE[f"handle_{side.lower()}"]
            set_handles = nodes.new("GeometryNodeSetCurveHandlePositions")
            set_handles.mode = side
            links.new(geometry, set_handles.inputs["Curve"])
            links.new(position.outputs["Attribute"], set_handles.inputs["Position"])
            geometry = set_handles.outputs[0]
    links.new(geometry, nodes.new("NodeGroupOutput").inputs[0])
    return group


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
