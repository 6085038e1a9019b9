"""Scene -> draw items: walk the evaluated depsgraph's object instances, get
each drawn mesh from the GPU cache (extracting it only when the cache does
not have it) and pair it with its instance matrix."""

from __future__ import annotations

import time

import numpy as np

from . import extract
from .cache import MeshCache
from .draw import DrawItem
from .log import warn_once


def mesh_key(obj_eval):
    """Cache key of an evaluated object's mesh.

    Instances of one evaluated mesh share the same pointer, so linked
    duplicates and instances share one upload. The pointer is only trusted
    within one evaluation: callers drop keys the depsgraph reports as updated
    (see cache invalidation in the targets)."""
    return obj_eval.data.as_pointer()


def gather(depsgraph, cache: MeshCache, *, object_filter=None):
    """(items, timing) for every drawn mesh instance of ``depsgraph``.

    ``object_filter(original_object) -> bool`` lets a target skip objects
    (viewport visibility, per-object opt-out) before any extraction."""
    items: list[DrawItem] = []
    seen = set()
    ms_extract = 0.0
    for instance in depsgraph.object_instances:
        obj = instance.object
        if obj.type != "MESH":
            continue
        if not instance.is_instance and not instance.show_self:
            continue
        if object_filter is not None and not object_filter(obj.original):
            continue
        key = mesh_key(obj)
        seen.add(key)

        def make_arrays(obj=obj):
            nonlocal ms_extract
            start = time.perf_counter()
            try:
                arrays = extract.extract_mesh(obj.data)
            except extract.ExtractError as exc:
                warn_once(("extract", obj.name), f"SolidWire skips object '{obj.name}': {exc}")
                return None
            finally:
                ms_extract += (time.perf_counter() - start) * 1000.0
            if arrays.dropped_triangles:
                warn_once(
                    ("nonfinite", obj.name),
                    f"SolidWire: object '{obj.name}' has {arrays.dropped_triangles} triangles with "
                    "non-finite (NaN/Inf) vertices; they are not drawn",
                )
            return arrays

        mesh = cache.get(key, make_arrays)
        if mesh is None:
            continue
        items.append(DrawItem(mesh, np.array(instance.matrix_world, dtype=np.float64)))
    return items, seen, ms_extract
