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
passes for a subdivided one. Only the last subdivision modifier counts (see
_stack), and the copies a Mirror or an Array after it makes are undone in
the index layout first (_carried_copies), then checked on the whole edge
array (_copies_match), as Blender's overlay keeps the cage through them.

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

import functools

import numpy as np

from ..core import edge_select
from . import mesh_reading

SUBDIVISION_TYPES = frozenset({"SUBSURF", "MULTIRES"})

# Modifiers that keep the topology (vertex/edge/face counts and order): they
# move vertices or write data layers only, and Blender copies the mesh with
# its Optimal Display marks. One of these after a subdivision keeps its edge
# order; see CAGE_CARRYING_TYPES for the others that keep the cage. (bpy 5.0
# names; unknown names are simply not listed.)
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


# Modifiers after the subdivision that carry Blender's Optimal Display
# marks (``Mesh.runtime->subsurf_optimal_display_edges``) on to their result
# in Blender 5.0's source, and so keep the cage in Blender's own overlay:
#
# * Mirror (``BKE_mesh_mirror_apply_mirror_on_axis_for_modifier``) copies
#   the marks to both halves, per mirrored axis; but Bisect (a BMesh round
#   trip) and a vertex merge that merges anything (``mesh_merge_verts``
#   makes a new mesh) drop them.
# * Array (``MOD_array.cc``) copies them to every copy when Merge is off,
#   and gives a cap the cap mesh's own marks (every edge when it has none);
#   with Merge on it drops them, whether or not anything merges.
# * Weld returns its input when nothing is within its distance (the marks
#   stay); when it welds, it makes a new mesh without them.
# * The topology-keeping modifiers above copy the mesh (``mesh_copy_data``
#   keeps the marks).
#
# Every other modifier makes a new mesh without the marks: Blender's
# overlay then shows every edge, and so does SolidWire (None).
# Tested against Blender's overlay in tests/test_cage_edges_mask.py.
CAGE_CARRYING_TYPES = frozenset({"MIRROR", "ARRAY", "WELD"})


def _stack(obj, render: bool):
    """(the level and modifier of the last subdivision modifier, the enabled
    modifiers after it, whether its input is the object's own mesh), or None
    when every edge shows: no subdivision modifier enabled (or at level 0),
    Optimal Display off on the last one, or a modifier after it that drops
    Blender's Optimal Display marks (see CAGE_CARRYING_TYPES).

    Only the last subdivision decides which edges show: Blender's
    subdivision marks the children of every edge of its input
    (``subdiv_mesh.cc``, ``subdiv_copy_edge_data``), whatever an earlier
    modifier marked, so an earlier subdivision's new edges show too."""
    original = getattr(obj, "original", None) or obj
    mode = getattr(original, "mode", "OBJECT")
    edit = mode == "EDIT"
    sculpt = mode == "SCULPT"
    last = None  # (level, modifier)
    after: list = []
    own_input = False
    topology_changed = False  # by an enabled modifier so far
    for md in obj.modifiers:
        if not _modifier_enabled(md, render, edit):
            continue
        kind = md.type
        if kind in SUBDIVISION_TYPES:
            if edit and kind == "MULTIRES":
                continue  # Multires is not evaluated in Edit Mode
            level = _requested_level(md, render, sculpt)
            if level <= 0:
                continue  # a subdivision at level 0 returns its input
            last, after, own_input = (level, md), [], not topology_changed
            topology_changed = True
        elif kind in TOPOLOGY_KEEPING_TYPES:
            continue
        else:
            topology_changed = True
            if last is not None:
                after.append(md)
    if last is None:
        return None
    # Optimal Display (show_only_control_edges), per modifier as in
    # Blender's own overlay: off on the last one, every edge shows.
    if not bool(getattr(last[1], "show_only_control_edges", True)):
        return None
    if any(md.type not in CAGE_CARRYING_TYPES for md in after):
        return None
    return last[0], after, own_input


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
    ends = np.ascontiguousarray(chains[:, :: 2 * n - 1])  # columns 0 and 2n - 1
    if ends.view(f"u{ends.dtype.itemsize}").max() >= coarse_verts_num:  # a negative id is a large unsigned one
        return None
    # Row e inside: V + e*(n-1) + (0, 0, 1, 1, ..., n-2, n-2), so all rows
    # together are the vertices V, V + 1, ... each twice.
    inside = np.arange(coarse_verts_num, coarse_verts_num + coarse_edges_num * (n - 1), dtype=edges.dtype).repeat(2)
    if not (chains[:, 1:-1] == inside.reshape(coarse_edges_num, 2 * n - 2)).all():
        return None
    return ends, coarse_verts_num, coarse_faces_num


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
    """Which edges of ``mesh`` (the evaluated mesh of ``obj``, original or
    evaluated object) come from an edge of the cage: the input of the last
    Subdivision Surface / Multiresolution modifier, as Blender's overlay
    shows it. None to draw every edge: no such modifier enabled for this
    mode (``render``: the render depsgraph's settings), level 0, Optimal
    Display off, a mesh the subdivision left coarse, a modifier after it
    that drops Blender's Optimal Display marks (CAGE_CARRYING_TYPES), or an
    edge layout that is not the one these modifiers make.

    Returned as (edges of the subdivision's own result that are cage
    children, children per cage edge, (C, 2) the two end vertices of each
    cage edge, the copies made after the subdivision (_carried_copies;
    empty when ``mesh`` is the subdivision's result)): in the subdivision's
    result the mask is the first edges, each cage edge's children
    consecutive, and a subdivision keeps the coarse vertices' numbers, so
    the ends are vertices of ``mesh`` too."""
    stack = _stack(obj, render)
    if stack is None:
        return None
    requested, after, own_input = stack
    edges_num = len(mesh.edges)
    if edges_num == 0:
        return None
    edges = _read_edges(mesh)
    verts_num, faces_num = len(mesh.vertices), len(mesh.polygons)
    carried = _carried_copies(after, edges, verts_num, faces_num)
    if carried is None:
        return None
    steps, (sub_edges_num, verts_num, faces_num) = carried
    sub_verts_num = verts_num
    sub_edges = edges[:sub_edges_num]  # every copy keeps its input first
    # Simplify can lower a level (and 0 skips the modifier): the first level
    # whose layout fits is the one used; none fits -> left coarse.
    for level in range(min(requested, MAX_LEVEL), 0, -1):
        peeled = peel(sub_edges, verts_num, faces_num, level)
        if peeled is not None:
            break
    else:
        return None  # left coarse: every edge is a cage edge
    cage, verts_num, cage_faces_num = peeled
    if own_input:
        counts = _cage_counts(obj)
        if counts is not None and (verts_num, len(cage)) not in counts:
            return None  # not this object's own mesh (or not yet re-evaluated)
    per_edge = 1 << level
    cage_children = len(cage) * per_edge
    if cage_children >= sub_edges_num:
        return None  # a mesh without faces: every edge comes from a cage edge
    if steps and not _copies_match(steps, edges, sub_edges_num):
        return None  # not the layout of these copies (a merge, a weld)
    # What _known_regions needs of the cage mesh and the subdivided one.
    cage_mesh = (verts_num, cage_faces_num, faces_num, own_input, sub_verts_num, sub_edges_num)
    return cage_children, per_edge, cage, steps, cage_mesh, edges


def _carried_copies(after, edges, verts_num: int, faces_num: int):
    """Undo, in the index layout, the copies that the modifiers ``after``
    the last subdivision (CAGE_CARRYING_TYPES, stack order) made of the
    subdivided mesh: ``(steps, (edges, vertices, faces) of the subdivided
    mesh))`` where each step, in stack order, is ``(copies, vertices of its
    input, caps)``: ``copies`` copies of its input one after the other (its
    vertex numbers shifted by the input's vertex count for each), then each
    cap's ``((E, 2) edges, vertex count, drawn mask, face count)``
    (_cap_layout). None where the
    marks are dropped or the counts do not fit (the caller checks the
    edges themselves)."""
    edges_num = len(edges)
    steps = []
    for md in reversed(after):
        kind = md.type
        if kind == "MIRROR":
            # Axes X, Y, Z are mirrored in that order, each doubling the mesh.
            for axis in (2, 1, 0):
                if not md.use_axis[axis]:
                    continue
                if md.use_bisect_axis[axis]:
                    return None  # bisected through a BMesh: the marks are gone
                if edges_num % 2 or verts_num % 2 or faces_num % 2:
                    return None  # merged vertices (or not a mirror copy at all)
                edges_num, verts_num, faces_num = edges_num // 2, verts_num // 2, faces_num // 2
                steps.append((2, verts_num, ()))
        elif kind == "ARRAY":
            if md.use_merge_vertices:
                return None  # Blender drops the marks whenever Merge is on
            caps = []
            for cap_object in (md.start_cap, md.end_cap):
                if cap_object is None:
                    continue
                cap = _cap_layout(cap_object)
                if cap is None:
                    return None
                caps.append(cap)
                edges_num -= len(cap[0])
                verts_num -= cap[1]
                faces_num -= cap[3]
            if min(edges_num, verts_num, faces_num) <= 0:
                return None
            count = _array_count(md, edges, edges_num, verts_num, faces_num)
            if count is None:
                return None
            edges_num, verts_num, faces_num = edges_num // count, verts_num // count, faces_num // count
            steps.append((count, verts_num, tuple(caps)))
        # WELD: it kept its input only if nothing was welded, which the
        # caller's check of the whole layout tells, but for one case: a weld
        # whose result still reads exactly as the subdivision of a smaller
        # cage, which is then drawn where Blender shows every edge (image
        # model §3.5).
    return steps[::-1], (edges_num, verts_num, faces_num)


def _array_count(md, edges, edges_num: int, verts_num: int, faces_num: int):
    """How many copies an Array modifier made of a mesh now ``edges_num``
    edges (caps taken off): its Count, or for Fit Length / Fit Curve (a
    count that follows the geometry) the largest count whose second copy
    is the first one shifted."""
    if md.fit_type == "FIXED_COUNT":
        count = max(1, int(md.count))
        if edges_num % count or verts_num % count or faces_num % count:
            return None
        return count
    common = int(np.gcd.reduce([edges_num, verts_num, faces_num]))
    for count in range(common, 1, -1):
        if common % count:
            continue
        size, shift = edges_num // count, verts_num // count
        if np.array_equal(edges[size : 2 * size], edges[:size] + shift):
            return count
    return 1


def _cap_layout(cap_object):
    """((E, 2) edges, vertex count, drawn mask, face count) of an Array
    cap, or None when it cannot be told: a cap whose evaluated mesh is its
    own mesh (no enabled modifier) gives every edge, as Blender gives a cap
    without Optimal Display marks; a cap with modifiers of its own (its
    marks would come from its own evaluation) is not followed."""
    original = getattr(cap_object, "original", None) or cap_object
    data = getattr(original, "data", None)
    if getattr(original, "type", None) != "MESH" or data is None:
        return None
    if any(md.show_viewport or md.show_render for md in original.modifiers):
        return None
    cap_edges = _read_edges(data).astype(np.int64)
    return cap_edges, len(data.vertices), np.ones(len(cap_edges), bool), len(data.polygons)


def _copies_match(steps, edges, size: int) -> bool:
    """Whether ``edges`` (the evaluated mesh's) are exactly what the copies
    of ``steps`` make of their first ``size`` edges: each copy its input's
    edges with the vertex numbers shifted, each cap its own edges after
    them. Every step's result is the start of the final array (a later
    copy keeps its input first), so each is checked in place."""
    for copies, verts_in, caps in steps:
        block = edges[: copies * size].reshape(copies, size, 2)
        shift = (np.arange(1, copies, dtype=np.int64) * verts_in)[:, None, None]
        if not np.array_equal(block[1:] - block[:1].astype(np.int64), np.broadcast_to(shift, block[1:].shape)):
            return False
        end, first_vertex = copies * size, copies * verts_in
        for cap_edges, cap_verts, _cap_mask, _cap_faces in caps:
            if not np.array_equal(edges[end : end + len(cap_edges)], cap_edges + first_vertex):
                return False
            end += len(cap_edges)
            first_vertex += cap_verts
        size = end
    return size == len(edges)


def _carry(steps, mask, ends):
    """Follow the subdivided mesh's (drawn mask, chain ends) through the
    copies of ``steps`` (_carried_copies): each copy keeps its edges' marks
    and its ends (shifted with its vertices); a cap's edges are their own
    chains (their own ends)."""
    for copies, verts_in, caps in steps:
        size = len(mask)
        ends = (np.broadcast_to(ends, (copies, size, 2)) + (np.arange(copies) * verts_in)[:, None, None]).reshape(-1, 2)
        mask = np.tile(mask, copies)
        first_vertex = copies * verts_in
        for cap_edges, cap_verts, cap_mask, _cap_faces in caps:
            ends = np.concatenate([ends, cap_edges + first_vertex])
            mask = np.concatenate([mask, cap_mask])
            first_vertex += cap_verts
    return mask, ends


def cage_edge_mask(obj, mesh, *, render: bool):
    """(E,) bool: True for the evaluated edges that come from a cage edge, or
    None to draw every edge (see _cage_layout)."""
    layout = _cage_layout(obj, mesh, render=render)
    if layout is None:
        return None
    children, _per_edge, _cage, steps, _cage_mesh, _edges = layout
    if steps:
        return cage_edges(obj, mesh, render=render, layout=layout)[0]
    mask = np.zeros(len(mesh.edges), dtype=bool)
    mask[:children] = True
    return mask


def cage_edges(obj, mesh, *, render: bool, layout=None, regions: bool = False):
    """(drawn mask, None, (E, 2) chain ends per edge, regions, (E, 2) edge
    vertex ids as read) for core/edge_select.py (its EdgeInputs: no chain
    ids, as the ends say which edges are pieces of one), or None: the
    children of one cage edge share their chain's ends, so the density
    fade measures the whole cage edge, not its pieces (an edge that is no
    cage child is its own chain, its own ends). ``regions``: also a
    function giving the regions of that mask as the layout gives them, or
    the layout to read them from (_known_regions; None where it cannot
    tell), else None. It runs on first use: asked only where they apply
    (core/edge_select.py's select_edges: no class names an edge the mask
    hides)."""
    if layout is None:
        layout = _cage_layout(obj, mesh, render=render)
    if layout is None:
        return None
    children, per_edge, cage, steps, _cage_mesh, edges = layout
    known = functools.partial(_known_regions, obj, mesh, layout) if regions else None
    size = _subdivided_edge_count(steps, len(edges))
    mask = np.zeros(size, bool)
    mask[:children] = True
    ends = edges[:size].copy()
    ends[:children] = np.repeat(cage, per_edge, axis=0)
    if steps:
        mask, ends = _carry(steps, mask, ends)
    return mask, None, ends, known, edges


def _known_regions(obj, mesh, layout) -> edge_select.KnownRegions | edge_select.SubdivisionLayout | None:
    """The regions of the cage mask (core/edge_select.py) from the layout:
    read from the object's own mesh where that is the subdivision's input,
    else (a modifier before the subdivision made its input; Edit Mode, whose
    mesh datablock lags the edited one) the layout itself, for
    core/edge_select.py to read them from the evaluated mesh's corners
    (``regions_from_layout``); None where a step before the last has
    caps. The last Array's caps follow every copy: their faces come after
    every listed region (KnownRegions: faces past the list), each cap face
    its own region.

    Blender's subdivision (``subdiv_foreach.cc``, ``subdiv_foreach_faces``)
    makes the children of each cage face one after another, in cage face
    order: a quad's 4**L as one grid, an n-gon's n * 4**(L-1) as one grid per
    corner; so a cage face of n corners has n * 4**(L-1) children either way.
    Every edge inside a cage face is hidden and joins two of its children,
    which form one connected patch, and every edge on its outline is a child
    of one of its cage edges, all drawn: the region of each cage face is
    exactly its children, bounded by the children of its cage edges, which
    it lists in whole chains (KnownRegions.chain_edges: each cage edge's
    children consecutive, with the cage edge's ends as chain ends). The
    cage mesh read here is checked to be the one the layout was peeled to
    (its vertex, face and corner counts and every edge)."""
    _children, per_edge, cage, steps, cage_mesh, _edges = layout
    if any(caps for _copies, _verts, caps in steps[:-1]):
        return None  # caps copied by a later step: faces of no region between listed ones
    caps = steps[-1][2] if steps else ()
    # The caps' faces and edges come last (after every copy): past the regions.
    cap_faces = sum(cap[3] for cap in caps)
    cap_edges = sum(len(cap[0]) for cap in caps)
    verts_num, faces_num, sub_faces_num, own_input, sub_verts_num, sub_edges_num = cage_mesh
    original = getattr(obj, "original", None) or obj
    data = getattr(original, "data", None)
    if (
        not own_input
        or getattr(original, "type", None) != "MESH"
        or data is None
        or getattr(original, "mode", "OBJECT") == "EDIT"
    ):
        return edge_select.SubdivisionLayout(
            level=per_edge.bit_length() - 1,
            coarse_verts=verts_num,
            coarse_edges=len(cage),
            coarse_faces=faces_num,
            subdivided_verts=sub_verts_num,
            subdivided_edges=sub_edges_num,
            subdivided_faces=sub_faces_num,
            copies=tuple(copies for copies, _verts, _caps in steps),
            cap_faces=cap_faces,
            cap_edges=cap_edges,
        )
    children_per_corner = (per_edge // 2) ** 2  # 4**(L-1)
    if (
        len(data.vertices) != verts_num
        or len(data.polygons) != faces_num
        or len(data.loops) * children_per_corner != sub_faces_num
    ):
        return None
    cage_edge_verts, corner_edge = mesh_reading.read_edge_topology(data)
    if cage_edge_verts.shape != cage.shape or not (cage_edge_verts == cage).all():
        return None
    offsets = mesh_reading.read_face_offsets(data)
    # Each cage face's edges, ascending: (face, edge) keys sorted, which
    # moves each key only among its own face's corners (the faces' keys
    # are len(cage) apart). A face that names an edge twice (a corrupt
    # face) lists it twice: core/edge_select.py, which checks that each
    # list ascends strictly, then finds the regions itself.
    face_key = np.arange(0, faces_num * len(cage), len(cage), dtype=np.int64).repeat(offsets[1:] - offsets[:-1])
    keys = face_key + corner_edge
    keys.sort(kind="stable")  # timsort: the keys ascend face to face, which it exploits (2-3x the default)
    # Every edge's children, consecutive (whole chains: KnownRegions.chain_edges).
    keys -= face_key
    keys *= per_edge
    edges = edge_select.whole_chains(keys, per_edge)
    face_start = np.multiply(offsets, children_per_corner, dtype=np.int64)
    edge_start = np.multiply(offsets, per_edge, dtype=np.int64)
    known = edge_select.KnownRegions(face_start, edge_start, edges, per_edge)
    copies = tuple(copies for copies, _verts, _caps in steps)
    return edge_select.copied_regions(
        known, copies, sub_faces_num, sub_edges_num, len(mesh.polygons) - cap_faces, len(mesh.edges) - cap_edges
    )


def _subdivided_edge_count(steps, edges_num: int) -> int:
    """Edges of the subdivided mesh that ``steps`` copied into ``edges_num``."""
    for copies, _verts_in, caps in reversed(steps):
        edges_num = (edges_num - sum(len(cap[0]) for cap in caps)) // copies
    return edges_num


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
        elif md.type in CAGE_CARRYING_TYPES:
            entry += _carrying_key(md)
        parts.append(entry)
    return tuple(parts)


def _carrying_key(md) -> tuple:
    """What of a Mirror or Array modifier decides whether it keeps the cage
    marks without changing the evaluated topology (a merge that merges
    nothing, a cap's own modifiers)."""
    if md.type == "MIRROR":
        return (
            tuple(bool(a) for a in md.use_axis),
            tuple(bool(a) for a in md.use_bisect_axis),
            bool(md.use_mirror_merge),
        )
    if md.type == "ARRAY":
        caps = []
        for cap in (md.start_cap, md.end_cap):
            original = getattr(cap, "original", None) or cap
            caps.append(
                None
                if original is None
                else (
                    original.session_uid,
                    tuple((m.type, bool(m.show_viewport), bool(m.show_render)) for m in original.modifiers),
                )
            )
        return (bool(md.use_merge_vertices), md.fit_type, int(md.count), *caps)
    return ()
