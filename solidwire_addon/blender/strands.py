"""Scene -> hair and point-cloud draw items (core/strands.py draws them).

Every instance of a Curves or PointCloud object in the evaluated depsgraph
(an object of that type, or what a geometry-nodes modifier makes) follows the
same visibility and per-object rules as a mesh instance (gather.instance_shown): the
target's object filter, ``object.solidwire.show_in_render`` /
``show_in_viewport``, the style override and the colour sources. The
attributes are read each frame (a few bulk reads); what is made from them
(evaluated curves, uploaded tables) is reused while they stay the same
(core/strands.GeometryCache).
"""

from __future__ import annotations

import numpy as np

from ..core import strands
from ..core.log import one_line, warn_once
from . import gather

KINDS = ("CURVES", "POINTCLOUD")


def _read(attributes, name: str, count: int, width: int, prop: str, dtype=np.float32):
    """An attribute's values ((count,) or (count, width)), or None when the
    datablock does not have it or its size is not ``count``."""
    attribute = attributes.get(name)
    if attribute is None or len(attribute.data) != count:
        return None
    values = np.empty(count * width, dtype=dtype)
    attribute.data.foreach_get(prop, values)
    return values.reshape(count, width) if width > 1 else values


def geometry_of(obj) -> strands.StrandGeometry | None:
    """The StrandGeometry of an evaluated Curves or PointCloud object (None:
    nothing to draw)."""
    data = obj.data
    attributes = data.attributes
    count = len(data.points)
    if count == 0:
        return None
    positions = _read(attributes, "position", count, 3, "vector")
    if positions is None:
        return None
    radius = _read(attributes, "radius", count, 1, "value")
    cache = strands.geometry_cache
    if obj.type == "POINTCLOUD":
        return cache.get(
            cache.fingerprint(strands.POINTS, positions, radius), lambda: strands.points_geometry(positions, radius)
        )
    curve_count = len(data.curves)
    offsets = np.empty(curve_count + 1, dtype=np.int32)
    data.curve_offset_data.foreach_get("value", offsets)
    curve_types = _read(attributes, "curve_type", curve_count, 1, "value", np.int32)
    resolutions = _read(attributes, "resolution", curve_count, 1, "value", np.int32)
    cyclic = _read(attributes, "cyclic", curve_count, 1, "value", bool)
    handles = None
    if curve_types is not None and (curve_types == strands.BEZIER).any():
        left = _read(attributes, "handle_left", count, 3, "vector")
        right = _read(attributes, "handle_right", count, 3, "vector")
        handles = None if left is None or right is None else (left, right)
        if handles is None:
            warn_once(
                ("curve handles", obj.name),
                f"SolidWire: '{obj.name}' has Bezier curves without handle positions; their control polygons are drawn",
            )
    if curve_types is not None and (curve_types == strands.NURBS).any():
        warn_once(
            ("curve types", obj.name), f"SolidWire: '{obj.name}' has NURBS curves; their control polygons are drawn"
        )
    key = cache.fingerprint(
        strands.CURVES, positions, radius, offsets, curve_types, resolutions, cyclic, *(handles or (None, None))
    )
    return cache.get(
        key, lambda: strands.curves_geometry(positions, radius, offsets, curve_types, resolutions, cyclic, handles)
    )


def gather_strands(depsgraph, *, object_filter=None, object_settings=None, colors: bool = False):
    """(StrandItem list) of every shown Curves and PointCloud instance of
    ``depsgraph``. Never raises for one object: a datablock that cannot be
    read is skipped with one line, and an empty one (no points, or only
    non-finite ones) with one line too."""
    items = []
    by_data: dict = {}
    for instance in depsgraph.object_instances:
        obj = instance.object
        if obj.type not in KINDS:
            continue
        try:
            shown = gather.instance_shown(instance, obj, object_filter, object_settings)
            if shown is None:
                continue
            _parent, style, _pass_index = shown
            pointer = obj.data.as_pointer()
            if pointer not in by_data:
                geometry = geometry_of(obj)
                by_data[pointer] = geometry
                if geometry is None:
                    what = (
                        "no points" if len(obj.data.points) == 0 else "no points with finite coordinates under 1.8e19"
                    )
                    warn_once(("strands empty", obj.name), f"SolidWire skips '{obj.name}': it has {what}")
                elif geometry.dropped:
                    count = geometry.dropped
                    warn_once(
                        ("strands nonfinite", obj.name),
                        f"SolidWire: '{obj.name}' has {count} point{'s' if count != 1 else ''} with a non-finite "
                        "(NaN/Inf) or huge (1.8e19 or more) coordinate or radius, left out (with the strand "
                        "segments that touch them)",
                    )
            geometry = by_data[pointer]
            if geometry is None:
                continue
            source = gather.item_source(obj) if colors else None
            items.append(
                strands.StrandItem(geometry, np.array(instance.matrix_world, dtype=np.float64), style, source, obj.name)
            )
        except Exception as exc:  # noqa: BLE001 - one bad object must not blank the frame
            warn_once(("strands", obj.name), f"SolidWire skips '{obj.name}': {type(exc).__name__}: {one_line(exc)}")
    return items
