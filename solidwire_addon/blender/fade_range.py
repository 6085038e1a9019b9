"""Depth fade ranges measured from the scene: the view depth of the drawn
objects' bounding boxes. Used by the fade operators (ops.py) and by a
``from_scene`` preset's fade range on the command line (cli.py); no UI."""

from __future__ import annotations

import bpy
import numpy as np

from . import mesh_reading


def visible_depth_extent(depsgraph, view_matrix, object_filter=None):
    """(nearest, farthest) view depth of the bounding boxes of the drawn mesh
    objects, or None when there are none in front of the view.

    Depth is distance along the viewing axis (as the depth fade uses, docs/image_model.md §4), so
    (start, end) = extent fades from the nearest object to the farthest."""
    view = np.asarray(view_matrix, dtype=np.float64)
    depths = []
    boxes = {}  # evaluated mesh -> the box of its drawn vertices
    for instance in depsgraph.object_instances:
        obj = instance.object
        if obj.type != "MESH":
            continue
        owner = instance.parent if instance.is_instance and instance.parent is not None else obj
        if object_filter is not None and not object_filter(owner.original):
            continue
        pointer = obj.data.as_pointer()
        if pointer not in boxes:  # (read once per mesh, however many instances draw it)
            box = np.array(obj.bound_box, dtype=np.float64)
            boxes[pointer] = mesh_reading.drawn_vertex_box(obj, (box.min(axis=0), box.max(axis=0)))
        box = boxes[pointer]
        if box is None:
            continue
        corners = np.ones((8, 4))
        corners[:, :3] = [[box[(k >> axis) & 1][axis] for axis in range(3)] for k in range(8)]
        world = corners @ np.array(instance.matrix_world, dtype=np.float64).T
        depths.append(-(world @ view[2]))
    if not depths:
        return None
    depths = np.concatenate(depths)
    depths = depths[np.isfinite(depths)]  # an object with a broken transform says nothing
    if not len(depths):
        return None
    near, far = max(float(depths.min()), 0.0), float(depths.max())
    if far <= 0.0:
        return None
    return near, far


def camera_fade_range(scene):
    """(near, far) view depth, from ``scene``'s camera, of the meshes a render
    of it draws (visible, not disabled in renders), or None: the fade range of
    a ``from_scene`` preset on the command line."""
    if scene.camera is None:
        return None
    with bpy.context.temp_override(scene=scene, view_layer=scene.view_layers[0]):
        depsgraph = bpy.context.evaluated_depsgraph_get()
    camera = scene.camera.evaluated_get(depsgraph)
    view_matrix = camera.matrix_world.normalized().inverted()
    return visible_depth_extent(depsgraph, view_matrix, lambda obj: not obj.hide_render)
