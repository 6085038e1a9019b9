"""Blender mesh -> numpy arrays: every read of an evaluated mesh's data.

``core/`` takes plain arrays and never a Blender mesh; this module is where
the two meet. Only bulk reads (``foreach_get`` on attribute arrays, a raw
memcpy where Blender keeps a generic attribute) and no per-element Python
loops, except for the few triangles :func:`blender_triangles` looks up one by
one. The triangles drawn are exactly Blender's own (``loop_triangles``): the
fast path (:func:`extract_mesh`) lets core/extract.py build the triangles of
tris and quads with Blender's quad split rule (reading ``loop_triangles``
through RNA costs ~0.1 s per million triangles, most of the budget) and asks
Blender only for n-gons and for quads whose split is numerically undecided.
"""

from __future__ import annotations

import zlib
from collections.abc import Callable

import numpy as np

from ..core import edge_select, extract
from ..core.edge_select import CLASS_BIT, EdgeInputs, Selection, SelectionStats
from ..core.extract import NORMALS_BY_TRIANGLE, NORMALS_BY_VERTEX, MeshArrays

# Above this many triangles to ask Blender about, one bulk read of all of
# ``loop_triangles`` is cheaper than reading them one by one.
BLENDER_TRIS_ONE_BY_ONE = 4096


def _read(collection, attr: str, count: int, dtype, width: int = 1) -> np.ndarray:
    out = np.empty(count * width, dtype=dtype)
    if count:
        collection.foreach_get(attr, out)
    return out if width == 1 else out.reshape(count, width)


def _read_attribute(mesh, name: str, prop: str, count: int, dtype, width: int = 1):
    """A generic attribute array read through ``mesh.attributes`` (a raw
    memcpy: ~10x faster than ``vertices.co`` / ``loops.vertex_index``, which
    go through RNA per element). None when the attribute is missing."""
    attribute = mesh.attributes.get(name)
    if attribute is None:
        return None
    out = np.empty(count * width, dtype=dtype)
    if count:
        attribute.data.foreach_get(prop, out)
    return out if width == 1 else out.reshape(count, width)


# ---------------------------------------------------------------- geometry


def read_material_indices(mesh) -> np.ndarray:
    """(F,) int32 material slot index of each face (0 without the attribute)."""
    count = len(mesh.polygons)
    values = _read_attribute(mesh, "material_index", "value", count, np.int32)
    return np.zeros(count, dtype=np.int32) if values is None else values


def read_positions(mesh) -> np.ndarray:
    """(V, 3) float32 vertex positions."""
    count = len(mesh.vertices)
    out = _read_attribute(mesh, "position", "vector", count, np.float32, 3)
    return out if out is not None else _read(mesh.vertices, "co", count, np.float32, 3)


def drawn_vertex_box(obj, box):
    """``box`` ((lo, hi), the evaluated object's bound box as Blender
    reports it) checked against the vertices: with a vertex that is not
    drawn (NaN, Inf or past extract.COORDINATE_LIMIT) Blender's box can miss
    the drawn ones, or span nothing but that vertex. Then the box of the
    drawable vertices; None where there are none, or the positions cannot be
    read. One read of the positions (about 2 ms per million vertices on the
    2-core VM)."""
    if obj.original.mode == "EDIT":
        return box  # the evaluated mesh can be an empty wrapper (blender/gather.py)
    try:
        positions = read_positions(obj.data)
    except (AttributeError, RuntimeError, ValueError):
        return None
    drawable = extract.drawable_vertices(positions)
    if drawable is None:
        return box
    drawn = positions[drawable].astype(np.float64)
    return (drawn.min(axis=0), drawn.max(axis=0)) if len(drawn) else None


def read_corner_verts(mesh) -> np.ndarray:
    """(L,) int32 vertex of each face corner (loop)."""
    count = len(mesh.loops)
    out = _read_attribute(mesh, ".corner_vert", "value", count, np.int32)
    return out if out is not None else _read(mesh.loops, "vertex_index", count, np.int32)


def read_face_offsets(mesh) -> np.ndarray:
    """(P + 1,) int32 face offsets: face i owns corners offsets[i]:offsets[i+1].

    Blender stores faces as offsets into the corner arrays, so the sizes come
    from ``loop_triangle_polygons`` (a raw int array, a face of n corners has
    n - 2 triangles) with one bincount, ~6x cheaper than reading
    ``polygons.loop_start``. The RNA read is the fallback if the counts do not
    add up (they always should)."""
    face_count = len(mesh.polygons)
    corner_count = len(mesh.loops)
    offsets = np.empty(face_count + 1, dtype=np.int32)
    offsets[0] = 0
    tri_count = corner_count - 2 * face_count
    tri_polygons = mesh.loop_triangle_polygons
    if face_count and len(tri_polygons) == tri_count:
        tri_faces = _read(tri_polygons, "value", tri_count, np.int32)
        sizes = np.bincount(tri_faces, minlength=face_count)
        if len(sizes) == face_count:
            sizes += 2
            np.cumsum(sizes, out=offsets[1:])
            if offsets[-1] == corner_count:
                return offsets
    offsets[:-1] = _read(mesh.polygons, "loop_start", face_count, np.int32)
    offsets[-1] = corner_count
    return offsets


def read_face_normals(mesh) -> np.ndarray:
    """(P, 3) float32: Blender's face normals (mesh space)."""
    return _read(mesh.polygon_normals, "vector", len(mesh.polygons), np.float32, 3)


def drawn_face_normals(mesh, arrays: MeshArrays, corner_vert, face_offsets: np.ndarray) -> np.ndarray:
    """(P, 3) float32: Blender's face normals, NaN for a face dropped for a
    corner that is not drawable (``arrays``: the mesh's extraction, which knows
    whether it dropped any): such a face is not drawn and has no normal,
    whatever Blender reports for it, so no rule that compares normals (the
    edge angle, a tessellation's coplanar faces) hides an edge beside it
    (image model §3.4). ``corner_vert``: read here where None and needed."""
    normals = read_face_normals(mesh)
    if arrays.dropped_triangles:
        positions = arrays.source_positions if arrays.source_positions is not None else read_positions(mesh)
        corners = corner_vert if corner_vert is not None else read_corner_verts(mesh)
        normals = extract.without_dropped_faces(normals, positions, corners, face_offsets[:-1])
    return normals


def read_mesh(mesh) -> dict[str, np.ndarray]:
    """Bulk-read a Blender mesh with Blender's triangles (``loop_triangles``):
    the input of core.extract.build_arrays (the reference path)."""
    offsets = read_face_offsets(mesh)
    loop_tris = mesh.loop_triangles  # computed lazily by Blender and cached on the mesh
    tri_count = len(loop_tris)
    return {
        "positions": read_positions(mesh),
        "corner_vert": read_corner_verts(mesh),
        "loop_start": offsets[:-1],
        "loop_total": np.diff(offsets),
        "tri_loops": _read(loop_tris, "loops", tri_count, np.int32, 3),
        "tri_polygons": _read(mesh.loop_triangle_polygons, "value", tri_count, np.int32),
    }


def blender_triangles(mesh) -> Callable[[np.ndarray], np.ndarray]:
    """``tri_indices -> (N, 3) corner ids`` of Blender's own ``loop_triangles``:
    one by one for a few, one bulk read for many."""
    cache = {}

    def lookup(tri_indices: np.ndarray) -> np.ndarray:
        tri_indices = np.asarray(tri_indices)
        loop_tris = mesh.loop_triangles
        if "all" in cache or len(tri_indices) > BLENDER_TRIS_ONE_BY_ONE:
            if "all" not in cache:
                cache["all"] = _read(loop_tris, "loops", len(loop_tris), np.int32, 3)
            return cache["all"][tri_indices]
        out = np.empty((len(tri_indices), 3), dtype=np.int32)
        for row, index in enumerate(tri_indices.tolist()):  # few: see BLENDER_TRIS_ONE_BY_ONE
            out[row] = loop_tris[index].loops
        return out

    return lookup


def read_mesh_fast(mesh) -> dict:
    """Bulk-read a mesh for core.extract.build_arrays_fast (no triangle reads)."""
    return {
        "positions": read_positions(mesh),
        "corner_vert": read_corner_verts(mesh),
        "face_offsets": read_face_offsets(mesh),
        "blender_tris": blender_triangles(mesh),
    }


def extract_mesh(mesh, *, positions=None, corner_vert=None, corners=None, face_offsets=None) -> MeshArrays:
    """Evaluated Blender mesh -> core.extract.MeshArrays (fast path).

    ``positions`` / ``corner_vert`` may be passed when the caller has just
    read them (the GPU cache reads them for its change fingerprint), and
    ``face_offsets`` when the caller reads them too (edge selection).
    ``corners``: also build the corner table (shaded fill, material colours);
    True, or the (normals, materials, domain) of :func:`read_corner_inputs` when the
    caller has them already (normals None: read here)."""
    data = (
        read_mesh_fast(mesh)
        if positions is None and face_offsets is None
        else {
            "positions": positions if positions is not None else read_positions(mesh),
            "corner_vert": corner_vert if corner_vert is not None else read_corner_verts(mesh),
            "face_offsets": face_offsets if face_offsets is not None else read_face_offsets(mesh),
            "blender_tris": blender_triangles(mesh),
        }
    )
    arrays = extract.build_arrays_fast(**data)
    if corners:
        normals, materials, domain = read_corner_inputs(mesh) if corners is True else corners
        if normals is None:
            normals = read_normals(mesh, domain)
        arrays.corners = extract.corner_table(
            arrays, data["corner_vert"], data["face_offsets"], normals, materials, domain
        )
    return arrays


def extract_mesh_naive(mesh) -> MeshArrays:
    """The reference path: Blender's ``loop_triangles`` for every face."""
    return extract.build_arrays(**read_mesh(mesh))


# ---------------------------------------------------------------- shading


def read_corner_domain(mesh) -> tuple[np.ndarray, int]:
    """(material index per face (P,) int32, domain NORMALS_BY_*) of
    :func:`read_corner_inputs`, without the normals (core.extract.normals_domain
    decides the domain)."""
    materials = read_material_indices(mesh)
    return materials, extract.normals_domain(getattr(mesh, "normals_domain", "CORNER"), materials)  # Blender 4.1+


def read_normals(mesh, domain: int) -> np.ndarray:
    """Blender's normals of ``mesh`` on ``domain`` (NORMALS_BY_*), (N, 3) float32."""
    if domain == NORMALS_BY_VERTEX:
        return _read(mesh.vertex_normals, "vector", len(mesh.vertices), np.float32, 3)
    if domain == NORMALS_BY_TRIANGLE:
        return _read(mesh.polygon_normals, "vector", len(mesh.polygons), np.float32, 3)
    return _read(mesh.corner_normals, "vector", len(mesh.loops), np.float32, 3)


def read_corner_inputs(mesh) -> tuple[np.ndarray, np.ndarray, int]:
    """(normals (N, 3) float32, material index per face (P,) int32, domain
    NORMALS_BY_*): what core.extract.corner_table needs. The normals are
    Blender's own (smooth, flat, sharp edges and custom normals as the mesh
    defines them; ``Mesh.normals_domain`` says where they vary), so the fill
    is shaded as Blender shades it."""
    materials, domain = read_corner_domain(mesh)
    return read_normals(mesh, domain), materials, domain


def read_attribute_colors(mesh):
    """(colours (N, 4) float32 scene-linear RGBA, domain "POINT" or
    "CORNER") of the mesh's active colour attribute, as Workbench's
    Attribute colour shows it (byte colours are read decoded to linear);
    None when it has none on those domains."""
    attributes = getattr(mesh, "color_attributes", None)
    attribute = None if attributes is None else attributes.active_color
    if attribute is None or attribute.domain not in ("POINT", "CORNER"):
        return None
    count = len(attribute.data)
    values = np.empty(count * 4, np.float32)
    if count:
        attribute.data.foreach_get("color", values)
    return values.reshape(-1, 4), attribute.domain


def attribute_colors_checksum(mesh) -> tuple:
    """What identifies the active colour attribute's content (for the mesh
    cache: painting changes it without moving a vertex)."""
    colors = read_attribute_colors(mesh)
    if colors is None:
        return (None,)
    return (colors[1], zlib.crc32(memoryview(np.ascontiguousarray(colors[0])).cast("B")))


# ---------------------------------------------------------------- edges

# Blender's edge data per class: (attribute names to try, kind). Seams are
# "uv_seam" from Blender 5.0 on and ".uv_seam" before; a crease counts when
# it is above zero.
_CLASS_ATTRIBUTES = {
    "sharp": ("sharp_edge",),
    "crease": ("crease_edge",),
    "seam": ("uv_seam", ".uv_seam"),
    "freestyle": ("freestyle_edge",),
}


# What a caller passes for edge class bits it has not read (None: read, no data).
UNREAD = object()


def read_edge_classes(mesh, enabled) -> np.ndarray | None:
    """(E,) class bits of ``mesh``'s edges for the enabled classes (other
    than boundary, which is topology), read from Blender's edge attributes;
    None when no enabled class has data."""
    count = len(mesh.edges)
    bits = None
    for name in enabled:
        if name == "freestyle" and mesh.attributes.get("freestyle_edge") is None:
            # Blender 4.x keeps Freestyle marks outside the attributes.
            values = np.zeros(count, bool)
            try:
                if count:
                    mesh.edges.foreach_get("use_freestyle_mark", values)
            except (AttributeError, TypeError, RuntimeError):
                continue
            if values.any():
                bits = np.zeros(count, np.int64) if bits is None else bits
                bits[values] |= CLASS_BIT[name]
            continue
        for attribute_name in _CLASS_ATTRIBUTES.get(name, ()):
            attribute = mesh.attributes.get(attribute_name)
            if attribute is None or attribute.domain != "EDGE":
                continue
            values = np.zeros(count, dtype=np.float32 if attribute.data_type == "FLOAT" else bool)
            if count:
                attribute.data.foreach_get("value", values)
            if bits is None:
                bits = np.zeros(count, np.int64)
            bits[values > 0] |= CLASS_BIT[name]
            break
    return bits


def read_edge_verts(mesh) -> np.ndarray:
    """(E, 2) int32 vertex ids of each edge: the raw attribute where Blender
    has it (a memcpy, ~50x faster than the per-element ``edges.vertices``)."""
    edge_count = len(mesh.edges)
    verts = _read_raw(mesh, ".edge_verts", edge_count, 2)
    if verts is None:
        verts = np.empty(edge_count * 2, np.int32)
        if edge_count:
            mesh.edges.foreach_get("vertices", verts)
    return verts.reshape(-1, 2)


def read_edge_topology(mesh) -> tuple[np.ndarray, np.ndarray]:
    """((E, 2) edge vertex ids, (L,) the edge of each face corner): raw
    attribute reads where Blender has them (a memcpy, ~50x faster than the
    per-element ``edges.vertices`` / ``loops.edge_index``)."""
    return read_edge_verts(mesh), read_corner_edges(mesh)


def read_corner_edges(mesh) -> np.ndarray:
    """(L,) int32 the edge of each face corner (the raw attribute where
    Blender has it)."""
    corner_count = len(mesh.loops)
    corner_edge = _read_raw(mesh, ".corner_edge", corner_count, 1)
    if corner_edge is None:
        corner_edge = np.empty(corner_count, np.int32)
        if corner_count:
            mesh.loops.foreach_get("edge_index", corner_edge)
    return corner_edge


def _read_raw(mesh, name: str, count: int, width: int):
    attribute = mesh.attributes.get(name)
    if attribute is None or len(attribute.data) != count:
        return None
    out = np.empty(count * width, np.int32)
    if count:
        attribute.data.foreach_get("value", out)
    return out


def apply_edge_selection(
    arrays: MeshArrays,
    mesh,
    corner_vert: np.ndarray,
    face_offsets: np.ndarray,
    selection: Selection,
    cage: tuple | None = None,
    class_bits=UNREAD,
) -> SelectionStats:
    """Read ``mesh``'s edges and apply ``selection`` to ``arrays``
    (core.edge_select.select_edges). ``cage``: (drawn mask, chain ids or
    None[, chain ends[, regions[, (E, 2) edge vertex ids as read]]]) of the
    evaluated edges from the cage detection (blender/cage.py) or an outline
    mask (blender/outlines.py), or None (no subdivision, or cage edges
    off). The regions (KnownRegions, or the SubdivisionLayout
    core/edge_select.py reads them from, or a function giving either) are
    those of the mask alone: joined across the edges the edge angle hides,
    and used only where the enabled classes only style edges that are
    drawn (a function is called only then, by select_edges).
    (select_edges copies the mask where it changes it.) ``class_bits``:
    read_edge_classes of the selection's classes where the caller has read
    them (the fingerprint checksums them)."""
    verts = cage[4] if cage is not None and len(cage) > 4 else None
    if verts is None:
        verts, corner_edge = read_edge_topology(mesh)
    else:
        corner_edge = read_corner_edges(mesh)
    drawn = chain = chain_ends = regions = None
    if cage is not None:
        drawn, chain = np.asarray(cage[0], bool), cage[1]
        chain_ends = cage[2] if len(cage) > 2 else None
        regions = cage[3] if len(cage) > 3 else None
    joined = None
    if selection.edge_angle > 0.0:
        # Beside a mask only its edges can be hidden by the angle: only they are tested.
        normals = drawn_face_normals(mesh, arrays, corner_vert, face_offsets)
        state = edge_select.EdgeAngleState(
            corner_edge, face_offsets, normals, len(verts), selection.edge_angle, candidates=drawn
        )
        arrays.edge_angle_state = state  # a move of vertices is checked against it
        drawn = ~state.flat if drawn is None else drawn & ~state.flat
        joined = state.flat  # the mask's regions join across these (edge_select.join_regions)
    others = tuple(c for c in selection.classes if c != "boundary")
    inputs = EdgeInputs(
        verts,
        drawn,
        (read_edge_classes(mesh, others) if class_bits is UNREAD else class_bits) if others else None,
        "boundary" in selection.classes,
        chain,
        chain_ends,
        # The boundary class and the regions' check both need it: counted once.
        corner_uses=np.bincount(corner_edge, minlength=len(verts)) if "boundary" in selection.classes else None,
    )
    if not inputs.selects_anything and not arrays.has_ngons:
        return SelectionStats()  # (every edge drawn: only n-gons change, as regions of their own)
    inputs.regions = regions  # a function is called only where they apply (select_edges)
    inputs.joined = joined
    return edge_select.select_edges(arrays, corner_vert, face_offsets, corner_edge, inputs)
