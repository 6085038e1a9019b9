"""Cage edges: which edges of a subdivided evaluated mesh come from edges of
the mesh the subdivision started from (docs/image_model.md, cage edges), as
Blender's own wireframe overlay shows a subdivided mesh.

Nothing is stored in the user's data: the answer is read from the evaluated
mesh's edge order, which Blender's subdivision (``subdiv_foreach.cc``,
``subdiv_mesh.cc``; Subdivision Surface and Multiresolution alike) lays out
as follows for a coarse mesh of V vertices and E edges at level L
(n = 2**L edges per coarse edge):

* vertices ``[0, V)`` are the coarse vertices, in their order; vertices
  ``V + e*(n-1) + k`` (k < n-1) are the ones inside coarse edge e;
* edges ``[e*n, (e+1)*n)`` are the children of coarse edge e, a chain
  ``(a, V+e*(n-1)), (V+e*(n-1), V+e*(n-1)+1), ..., (V+e*(n-1)+n-2, b)`` from
  its first vertex a to its second b (loose edges included); every edge
  inside a face comes after them, from ``E*n`` on.

So the mask is ``arange(len(edges)) < E*n``. E and L are solved from the
counts (faces F' = C * 4**(L-1) for C coarse face corners, edges
E' = n*E + n/2*(n-1)*C) and the chain layout above is then checked on the
edge array itself, exactly: a count that fits by chance, a level lowered by
Simplify, a modifier after the subdivision that changed the topology or an
evaluated mesh that is the coarse one (the subdivision did nothing) never
passes for a subdivided one. Stacked subdivision modifiers are peeled one by
one (the children of a child are children of the coarse edge).

What the evaluated mesh is (read in Blender 5.0's source):

* GPU subdivision: the last Subdivision Surface modifier of a viewport
  evaluation (and any in background mode or for render) only attaches its
  settings to the coarse mesh; but ``Object.data`` of an evaluated object
  (RNA ``rna_Object_data_get``) and ``Object.to_mesh()``
  (``mesh_new_from_mesh``) both call ``BKE_mesh_wrapper_ensure_subdivision``,
  which subdivides on the CPU. Python therefore always sees the subdivided
  mesh (and reading it makes Blender subdivide on the CPU as well).
* Multiresolution in Sculpt Mode (without "Sculpt Base Mesh") evaluates to
  a copy of the coarse mesh plus CCG grids Python cannot see; a subdivision
  that fails (a mesh without faces) also leaves the coarse mesh. Then every
  edge is a cage edge and :func:`cage_edge_mask` returns None.
"""

from __future__ import annotations

import numpy as np

SUBDIVISION_TYPES = frozenset({"SUBSURF", "MULTIRES"})

# Modifiers that keep the topology (vertex/edge/face counts and order): they
# move vertices or write data layers only. One of these after a subdivision
# keeps its edge order; any other enabled modifier after it makes the answer
# unknowable (None). (bpy 5.0 names; unknown names are simply not listed.)
TOPOLOGY_KEEPING_TYPES = frozenset(
    {
        # Deform
        "ARMATURE",
        "CAST",
        "CURVE",
        "DISPLACE",
        "HOOK",
        "LAPLACIANDEFORM",
        "LATTICE",
        "MESH_DEFORM",
        "SHRINKWRAP",
        "SIMPLE_DEFORM",
        "SMOOTH",
        "CORRECTIVE_SMOOTH",
        "LAPLACIANSMOOTH",
        "SURFACE_DEFORM",
        "WARP",
        "WAVE",
        "MESH_CACHE",
        # Data only (normals, UVs, weights, transferred layers)
        "NORMAL_EDIT",
        "WEIGHTED_NORMAL",
        "UV_PROJECT",
        "UV_WARP",
        "VERTEX_WEIGHT_EDIT",
        "VERTEX_WEIGHT_MIX",
        "VERTEX_WEIGHT_PROXIMITY",
        "DATA_TRANSFER",
        # Physics that pass the mesh through (deform only)
        "CLOTH",
        "SOFT_BODY",
        "COLLISION",
        "SURFACE",
        "PARTICLE_SYSTEM",
    }
)

MAX_LEVEL = 11  # Subdivision Surface's own limit


def _modifier_enabled(md, render: bool, edit: bool) -> bool:
    if render:
        return bool(md.show_render)
    return bool(md.show_viewport) and (not edit or bool(md.show_in_editmode))


def _requested_level(md, render: bool, sculpt: bool) -> int:
    """The level a subdivision modifier asks for (Simplify may lower it)."""
    if md.type == "MULTIRES":
        if render:
            level = md.render_levels
        elif sculpt:
            level = md.sculpt_levels
        else:
            level = md.levels
        return max(0, min(int(level), int(md.total_levels)))
    return max(0, int(md.render_levels if render else md.levels))


def _stack(obj, render: bool):
    """(requested (level, Optimal Display) of the subdivision modifiers in
    stack order, whether only topology-keeping modifiers come before the
    first one) or None when the answer is unknowable or trivial (no
    subdivision modifier, a modifier that changes the topology after one,
    or the last one shows every edge: Optimal Display off)."""
    original = getattr(obj, "original", None) or obj
    mode = getattr(original, "mode", "OBJECT")
    edit = mode == "EDIT"
    sculpt = mode == "SCULPT"
    levels: list[int] = []
    plain_before = True
    for md in obj.modifiers:
        if not _modifier_enabled(md, render, edit):
            continue
        kind = md.type
        if kind in SUBDIVISION_TYPES:
            if edit and kind == "MULTIRES":
                continue  # Multires is not evaluated in Edit Mode
            # Optimal Display (show_only_control_edges), per modifier as in
            # Blender's own overlay: off, the modifier's new edges show too.
            levels.append((_requested_level(md, render, sculpt), bool(getattr(md, "show_only_control_edges", True))))
        elif kind in TOPOLOGY_KEEPING_TYPES:
            continue
        elif levels:
            return None  # topology changed after a subdivision
        else:
            plain_before = False
    levels = [entry for entry in levels if entry[0] > 0]
    if not levels or not levels[-1][1]:
        return None
    return levels, plain_before


def _read_edges(mesh) -> np.ndarray:
    """(E, 2) int32 vertex indices of every edge (a raw attribute read)."""
    count = len(mesh.edges)
    out = np.empty(count * 2, dtype=np.int32)
    if count:
        attribute = mesh.attributes.get(".edge_verts")
        if attribute is not None and len(attribute.data) == count:
            attribute.data.foreach_get("value", out)
        else:
            mesh.edges.foreach_get("vertices", out)
    return out.reshape(count, 2)


def peel(edges: np.ndarray, verts_num: int, faces_num: int, level: int):
    """Undo one subdivision at ``level`` >= 1 in the index layout:
    ``(coarse edges (E, 2), coarse vertex count, coarse face count)`` when
    ``edges`` (those of a mesh of ``verts_num`` vertices and ``faces_num``
    faces) are laid out exactly as Blender lays out the subdivision of such
    a coarse mesh, else None."""
    n = 1 << level  # child edges per coarse edge
    m = n >> 1
    if faces_num % (m * m):
        return None
    corners = faces_num // (m * m)  # coarse face corners: F' = C * 4**(L-1)
    rest = len(edges) - m * (n - 1) * corners  # E' = n*E + m*(n-1)*C
    if rest <= 0 or rest % n:
        return None
    coarse_edges_num = rest // n
    chains = edges[: coarse_edges_num * n].reshape(coarse_edges_num, 2 * n)
    coarse_verts_num = int(chains[0, 1])  # the first vertex inside coarse edge 0
    # V' = V + (n-1)*E + F + C*m*(m-1): one centre per coarse face, m-1
    # vertices on each of its C spokes and (m-1)**2 in each of its C quarters.
    coarse_faces_num = verts_num - coarse_verts_num - (n - 1) * coarse_edges_num - corners * m * (m - 1)
    if coarse_verts_num <= 0 or coarse_faces_num < 0 or 3 * coarse_faces_num > corners:
        return None
    if (corners == 0) != (coarse_faces_num == 0):
        return None
    ends = chains[:, [0, -1]]
    if ends.min() < 0 or ends.max() >= coarse_verts_num:
        return None
    inside = chains[:, 1:-1]  # (V + e*(n-1)) + (0, 0, 1, 1, ..., n-2, n-2)
    start = coarse_verts_num + (n - 1) * np.arange(coarse_edges_num, dtype=np.int64)
    step = np.repeat(np.arange(n - 1, dtype=np.int64), 2)
    if not np.array_equal(inside, start[:, None] + step[None, :]):
        return None
    return np.ascontiguousarray(ends), coarse_verts_num, coarse_faces_num


def _cage_counts(obj):
    """(vertices, edges) of the object's own mesh as it enters the modifier
    stack (the edit BMesh's in Edit Mode, else the mesh datablock's), or
    None when it has no mesh datablock. In Edit Mode both are returned, as
    the depsgraph evaluated one of them."""
    original = getattr(obj, "original", None) or obj
    data = getattr(original, "data", None)
    if getattr(original, "type", None) != "MESH" or data is None:
        return None
    counts = [(len(data.vertices), len(data.edges))]
    if getattr(data, "is_editmode", False):
        import bmesh

        bm = bmesh.from_edit_mesh(data)
        counts.append((len(bm.verts), len(bm.edges)))
    return counts


def _cage_layout(obj, mesh, *, render: bool):
    """(E,) bool, True for the edges of ``mesh`` (the evaluated mesh of
    ``obj``, original or evaluated object) that come from an edge of the
    cage (the mesh before its Subdivision Surface / Multiresolution
    modifiers); None to draw every edge: no such modifier enabled for this
    mode (``render``: the render depsgraph's settings), level 0, a mesh the
    subdivision left coarse, or one whose origin cannot be told (a modifier
    after the subdivision that changes the topology, an edge layout that is
    not the subdivision's).

    Returned as (edges that are cage children, children per cage edge,
    (C, 2) the two end vertices of each cage edge): the mask is the first
    ones, each cage edge's children consecutive. A subdivision keeps the
    coarse vertices' numbers, so the ends are vertices of ``mesh`` too."""
    stack = _stack(obj, render)
    if stack is None:
        return None
    levels, plain_before = stack
    edges_num = len(mesh.edges)
    if edges_num == 0:
        return None
    edges = _read_edges(mesh)
    verts_num, faces_num = len(mesh.vertices), len(mesh.polygons)
    total = 1  # child edges per cage edge so far
    own_mesh = True  # peeled down to the object's own mesh
    for requested, optimal in reversed(levels):
        if not optimal:
            # This modifier shows every edge it makes: the drawn edges are
            # the children of all of its input's edges.
            own_mesh = False
            break
        # Simplify can lower a level (and 0 skips the modifier): the first
        # level whose layout fits is the one used; none fits -> skipped.
        for level in range(min(requested, MAX_LEVEL), 0, -1):
            peeled = peel(edges, verts_num, faces_num, level)
            if peeled is not None:
                edges, verts_num, faces_num = peeled
                total <<= level
                break
    if total == 1:
        return None  # left coarse: every edge is a cage edge
    if plain_before and own_mesh:
        counts = _cage_counts(obj)
        if counts is not None and (verts_num, len(edges)) not in counts:
            return None  # not this object's own mesh (or not yet re-evaluated)
    cage_children = len(edges) * total
    if cage_children >= edges_num:
        return None  # a mesh without faces: every edge comes from a cage edge
    return cage_children, total, edges


def cage_edge_mask(obj, mesh, *, render: bool):
    """(E,) bool: True for the evaluated edges that come from a cage edge, or
    None to draw every edge (see _cage_layout)."""
    layout = _cage_layout(obj, mesh, render=render)
    if layout is None:
        return None
    mask = np.zeros(len(mesh.edges), dtype=bool)
    mask[: layout[0]] = True
    return mask


def cage_edges(obj, mesh, *, render: bool):
    """(drawn mask, chain id per edge, (E, 2) chain ends per edge) for
    core/edge_select.py, or None: the children of one cage edge share a
    chain id and ends, so the density fade measures the whole cage edge,
    not its pieces (an edge that is no cage child is its own chain)."""
    layout = _cage_layout(obj, mesh, render=render)
    if layout is None:
        return None
    children, per_edge, cage = layout
    index = np.arange(len(mesh.edges), dtype=np.int64)
    mask = index < children
    ends = _read_edges(mesh).astype(np.int64)
    ends[:children] = np.repeat(np.asarray(cage, np.int64), per_edge, axis=0)
    return mask, np.where(mask, index // per_edge, -1 - index), ends


def subdivides(obj, render: bool) -> bool:
    """Whether a subdivision modifier enabled for this mode subdivides
    ``obj``: only then can cage edges differ from all edges."""
    return _stack(obj, render) is not None


def cage_key(obj, render: bool):
    """Hashable: changes whenever :func:`cage_edge_mask` of the same
    evaluated geometry could change (modifier types, enabled flags and
    subdivision levels; Edit / Sculpt Mode). Combine it with the mesh's own
    cache key (which covers the geometry)."""
    original = getattr(obj, "original", None) or obj
    parts = [bool(render), getattr(original, "mode", "OBJECT")]
    for md in obj.modifiers:
        entry = (md.type, bool(md.show_viewport), bool(md.show_render), bool(md.show_in_editmode))
        if md.type == "SUBSURF":
            entry += (int(md.levels), int(md.render_levels), bool(md.show_only_control_edges))
        elif md.type == "MULTIRES":
            entry += (
                int(md.levels),
                int(md.render_levels),
                int(md.sculpt_levels),
                int(md.total_levels),
                bool(md.use_sculpt_base_mesh),
                bool(md.show_only_control_edges),
            )
        parts.append(entry)
    return tuple(parts)
