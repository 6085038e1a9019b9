"""Outlines of tessellated sources (docs/user/objects.md): text, curves with fill,
bevel or extrusion, NURBS surfaces and metaballs reach SolidWire as the
mesh Blender tessellates them into, and a flat fill (a letter's face, a
filled curve) is an arbitrary fan of triangles that says nothing about the
shape. For those objects an edge between two faces that lie in one plane
is not drawn: the faces of a flat fill form one region (core/edge_select.py)
whose outline is drawn, and the profile edges where the surface bends stay.
``show_tessellation`` draws every edge again.

The mask goes into the same input as the cage edges (edge_select's drawn
mask), so no mesh data is changed and nothing is saved in the file.
"""

from __future__ import annotations

import numpy as np

from ..core import edge_select
from .mesh_reading import read_edge_topology, read_face_offsets

# Object types whose evaluated mesh is a tessellation Blender made.
TESSELLATED_TYPES = frozenset({"FONT", "CURVE", "SURFACE", "META"})
# Faces whose normals differ by less than this lie in one plane (float32
# normals of coplanar faces differ by ~1e-7 rad; the finest curved
# tessellation Blender makes bends by far more than this per edge).
COPLANAR_ANGLE = 1.0e-3


def _source_type(obj) -> str:
    """The type of the object whose tessellation ``obj``'s mesh is, or
    "MESH" when its geometry is authored: a geometry-nodes modifier on a
    text or curve object makes (or instances) meshes of the user's own
    design, which are drawn as meshes."""
    original = getattr(obj, "original", None) or obj
    kind = getattr(original, "type", "MESH")
    if kind != "MESH" and any(md.type == "NODES" for md in getattr(original, "modifiers", ())):
        return "MESH"
    return kind


def is_tessellated(obj) -> bool:
    """Whether an evaluated object's mesh is the tessellation of a text,
    curve, surface or metaball object."""
    return _source_type(obj) in TESSELLATED_TYPES


def is_curve_outline(obj) -> bool:
    """Whether an evaluated object's mesh is the tessellation of a text or
    curve object: its lines follow the letters' and curves' outlines."""
    return _source_type(obj) in ("FONT", "CURVE")


def outline_mask(mesh, face_normals: np.ndarray, face_offsets: np.ndarray | None = None) -> tuple[np.ndarray, None]:
    """(drawn mask, chain ids = None) of ``mesh``'s edges in the form
    mesh_reading.apply_edge_selection takes for its cage input: False for an edge
    of exactly two faces in one plane. ``face_normals``: the drawn faces'
    normals (mesh_reading.drawn_face_normals: a dropped face has none, so
    the edge it shares with a drawn face is that face's outline)."""
    if face_offsets is None:
        face_offsets = read_face_offsets(mesh)
    verts, corner_edge = read_edge_topology(mesh)
    flat = edge_select.flat_edges(corner_edge, face_offsets, face_normals, len(verts), COPLANAR_ANGLE)
    return ~flat, None
