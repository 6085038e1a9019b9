"""Comparing two extractions (core.extract.MeshArrays) array by array; plain
numpy, no Blender."""

from __future__ import annotations

import numpy as np

from solidwire_addon.core import extract

FIELDS = (
    "positions",
    "centre",
    "triangles",
    "edge_flags",
    "triangle_polygons",
    "bounds_min",
    "bounds_max",
    "ngon_corners",
)


def assert_same_arrays(fast: extract.MeshArrays, reference: extract.MeshArrays) -> None:
    for name in FIELDS:
        a, b = getattr(fast, name), getattr(reference, name)
        assert a.shape == b.shape, name
        assert a.dtype == b.dtype, name
        np.testing.assert_array_equal(a, b, err_msg=name)
    assert fast.dropped_triangles == reference.dropped_triangles
