"""Float64 reference of the SolidWire image model (SPEC section 1).

This is the oracle every accuracy test and the benchmark compare against. It
shares no code with the add-on: it reads the evaluated scene through Blender's
own API, casts a float64 ray through every sample, and measures exact
window-space distances to the near-clipped projection of each face's edges.

    result = render_reference(scene)
    result.intensity       # (H, W) line intensity I (fade included)
    result.on_silhouette   # (H, W) samples within 0.01 px of a face change
    result.face            # (H, W) visible face id, -1 for background
    result.depth           # (H, W) view depth of the visible point (inf: none)
    result.d_real          # (H, W) distance to the visible face's real edges (inf: none)
    result.face_object     # (H, W) index into result.objects of the visible
                           # face's style object (-1: background)

Per-object settings (object.solidwire, docs/image_model.md §5.9): an instance
is drawn when its instancer and the object it instances both have
``show_in_render``; the style override (thickness here; colours are composed
by the tests from ``face_object``) is the instanced object's.

Method:
- Visibility: every triangle is clipped to the near plane only to bound the
  pixels it may cover; for those pixels a float64 ray through the sample
  (from the camera centre, or for orthographic cameras from the near plane
  along the view direction) is intersected with the triangle
  (Moller-Trumbore). The nearest hit between clip start and end wins.
  Zero-area and edge-on triangles never hit.
- Silhouette flag: the visible face is also found for four samples 0.01 px
  away; a sample whose visible face differs from any of them is "on a
  silhouette" (SPEC 1.5).
- Distances: each polygon edge is clipped to the near plane in clip space,
  its front part projected, and the point-segment distance taken in window
  pixels (pixel aspect included via the projection).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import bpy
import numpy as np

SILHOUETTE_OFFSET = 0.01  # px, SPEC 1.5
OFFSETS = np.array(
    [
        [0.0, 0.0],
        [SILHOUETTE_OFFSET, 0.0],
        [-SILHOUETTE_OFFSET, 0.0],
        [0.0, SILHOUETTE_OFFSET],
        [0.0, -SILHOUETTE_OFFSET],
    ]
)
PAIR_CHUNK = 400_000
# §2.1: a coordinate of this magnitude or more is dropped as NaN is.
COORDINATE_LIMIT = 2.0**64


def drawable(values, axis=-1) -> np.ndarray:
    """Where every value along ``axis`` is finite and below
    COORDINATE_LIMIT in magnitude (§2.1)."""
    with np.errstate(invalid="ignore"):
        return (np.abs(np.asarray(values, np.float64)) < COORDINATE_LIMIT).all(axis=axis)


@dataclass
class ReferenceResult:
    intensity: np.ndarray
    on_silhouette: np.ndarray
    face: np.ndarray
    depth: np.ndarray
    rows: np.ndarray  # window rows (j, bottom = 0) that the arrays hold
    # Image model §5.8: the shaded fill colour and the wire colour of each
    # covered sample (NaN on background), linear RGB.
    fill: np.ndarray = None  # (H, W, 3)
    wire: np.ndarray = None  # (H, W, 3)
    d_real: np.ndarray = None
    face_object: np.ndarray = None
    objects: list = None  # names of the objects whose settings style each face
    object_face_offsets: list = None  # first face id of each entry of objects
    hidden: np.ndarray = None  # (H, W) H of image model §5.4 (hidden lines on only)
    # (H, W) view depth of the nearest surface behind the visible one at the
    # sample (another face, or a triangle of its own face folded behind it;
    # +inf: none), with hidden lines on or ``depth_layers`` asked for.
    next_depth: np.ndarray = None
    # (H, W) how many triangles the sample's ray meets at the visible depth
    # (within a relative 1e-6: triangles on one another), likewise.
    level_hits: np.ndarray = None
    # (H, W) view depth of the nearest point of a silhouette whose outer half
    # would reach the sample but lies behind the visible surface there
    # (+inf: none; image model §5.5).
    hidden_outer_depth: np.ndarray = None
    # (H, W) bool: which triangle of the visible face, or which side of it,
    # the sample shows is rounding's choice (a sample 0.01 px off shows
    # another triangle of the face, as at a fold's edge; a triangle seen
    # nearly edge-on; a fold whose triangle showing the other side lies
    # level with the visible one), so a colour interpolated over the
    # triangle or lit by the seen side's normal is undecided (§7.2); None
    # where the fill is neither.
    shading_undecided: np.ndarray = None
    # (H, W) bool: the two strongest lines of different colours lie within
    # STYLE_TIE of each other, so which style's colour the sample takes
    # (§3.6) is float32's choice (two wide lines both at full strength,
    # one of them only just); its intensity is decided.
    style_undecided: np.ndarray = None


@dataclass
class _Geometry:
    """All drawn triangles of the scene in view space, float64."""

    tri_view: np.ndarray  # (T, 3, 3) view-space vertices
    tri_face: np.ndarray  # (T,) global face id
    edges_view: np.ndarray  # (E, 2, 3) view-space edge endpoints
    edge_face: np.ndarray  # (E,) global face id
    edge_real: np.ndarray  # (E,) bool: a drawn line (else a diagonal)
    edge_origin_first: np.ndarray  # (E,) bool: pattern measured from endpoint 0
    # Silhouette candidates (image model §5.5): real edges with one or two faces.
    sil_edges: np.ndarray = None  # (S, 2, 3) view-space endpoints
    sil_third: np.ndarray = None  # (S, 2, 3) third vertex of the face on each side (NaN: none)
    # Fill shading and colour sources (image model §5.8).
    tri_normals: np.ndarray = None  # (T, 3, 3) corner normals in view space (not normalised), tri_view's order
    # (T, 3, 3) the active colour attribute at each corner (linear RGB), NaN
    # for an object without one: the ATTRIBUTE fill source.
    tri_colors: np.ndarray = None
    face_fill: np.ndarray = None  # (F, 3) base fill colour of each global face
    face_wire: np.ndarray = None  # (F, 3) wire colour of each global face
    face_thickness: np.ndarray = None  # (F,) override thickness per face (NaN: the scene's)
    face_object: np.ndarray = None  # (F,) index into objects
    objects: list = None
    offsets: list = None  # first face id of each object
    # Edge selection (image model §3.4-§3.7). A line entry's edge_face is the
    # key of the block it belongs to (face_key of the faces that measure
    # to it: their region, or the face itself); diagonals keep their face.
    face_key: np.ndarray = None  # (F,) block key of each face
    edge_style: np.ndarray = None  # (E,) 0 wire, 1.. edge classes (lines only)
    chain_view: np.ndarray = None  # (E, 2, 3) ends of each entry's edge chain (density fade)


# ---------------------------------------------------------------- scene input


def _camera(scene, depsgraph, width, height):
    cam = scene.camera.evaluated_get(depsgraph)
    r = scene.render
    proj = np.array(
        cam.calc_matrix_camera(depsgraph, x=width, y=height, scale_x=r.pixel_aspect_x, scale_y=r.pixel_aspect_y),
        dtype=np.float64,
    )
    m = np.array(cam.matrix_world, dtype=np.float64)
    # Camera scale is ignored (SPEC 1.4): normalise the rotation columns.
    m[:3, :3] /= np.linalg.norm(m[:3, :3], axis=0)
    return np.linalg.inv(m), proj


def _hsv_name_color(name, saturation, value):
    """RANDOM colour source (image model §5.8): hue = crc32(UTF-8 name) / 2^32."""
    import colorsys
    import zlib

    return colorsys.hsv_to_rgb(zlib.crc32(name.encode("utf-8")) / 2.0**32, saturation, value)


def _object_colors(obj, s, npoly, material_index):
    """(face fill (P, 3), wire (3,)) of one object under the colour sources."""
    wire = np.array(s.wire_color[:3], dtype=np.float64)
    fill = np.array(s.fill_color[:3], dtype=np.float64)
    fill_source = getattr(s, "fill_color_source", "SINGLE") if getattr(s, "use_fill", False) else "SINGLE"
    wire_source = getattr(s, "wire_color_source", "SINGLE")
    if wire_source == "OBJECT":
        wire = np.array(obj.color[:3], dtype=np.float64)
    elif wire_source == "RANDOM":
        wire = np.array(_hsv_name_color(obj.name, 0.8, 0.3))
    faces = np.tile(fill, (npoly, 1))
    if fill_source == "OBJECT":
        faces[:] = np.array(obj.color[:3], dtype=np.float64)
    elif fill_source == "RANDOM":
        faces[:] = np.array(_hsv_name_color(obj.name, 0.5, 0.8))
    elif fill_source == "MATERIAL":
        slots = [
            fill if slot.material is None else np.array(slot.material.diffuse_color[:3], dtype=np.float64)
            for slot in obj.material_slots
        ]
        if slots:
            faces[:] = np.array(slots)[np.clip(material_index, 0, len(slots) - 1)]
    return faces, wire


def _corner_colors(mesh, tri_loops, tri_vertices) -> np.ndarray:
    """(T, 3, 3) the active colour attribute at each triangle corner (linear
    RGB; point colours by vertex, corner colours by loop), NaN without one.
    Read element by element, independent of the add-on's bulk reads."""
    out = np.full((len(tri_loops), 3, 3), np.nan)
    attribute = mesh.color_attributes.active_color
    if attribute is None or attribute.domain not in ("POINT", "CORNER"):
        return out
    values = np.array([tuple(item.color)[:3] for item in attribute.data], np.float64).reshape(-1, 3)
    values = np.nan_to_num(values, nan=0.0, posinf=0.0, neginf=0.0)
    index = tri_vertices if attribute.domain == "POINT" else tri_loops
    return values[index]


def _flat_edges(mesh, loop_poly, real_a, real_b, angle, poly_ok) -> set:
    """{(lo, hi)} vertex pairs of the edges that the edge angle hides. A
    dropped face (``poly_ok`` False: a corner that is not drawable, §2.1) has no
    normal: no edge beside it is hidden by the angle."""
    if not angle > 0.0:
        return set()
    normals = np.empty(len(mesh.polygons) * 3, np.float32)
    mesh.polygon_normals.foreach_get("vector", normals)
    normals = normals.reshape(-1, 3).astype(np.float64)
    normals[~poly_ok] = np.nan
    faces: dict = {}
    for f, a, b in zip(loop_poly.tolist(), real_a.tolist(), real_b.tolist()):
        faces.setdefault((min(a, b), max(a, b)), []).append(f)
    hidden = set()
    for key, fs in faces.items():
        if len(fs) == 2 and fs[0] != fs[1]:
            n1, n2 = normals[fs[0]], normals[fs[1]]
            c = np.dot(n1, n2) / max(np.linalg.norm(n1) * np.linalg.norm(n2), 1e-300)
            if np.arccos(np.clip(c, -1.0, 1.0)) < angle:
                hidden.add(key)
    return hidden


# Edge classes in style order (style k + 1 is class k), with Blender's
# attribute names; the reference reads Blender's data on its own.
EDGE_CLASSES = ("boundary", "sharp", "crease", "seam", "freestyle")
_CLASS_ATTRIBUTES = {
    "sharp": ("sharp_edge",),
    "crease": ("crease_edge",),
    "seam": ("uv_seam", ".uv_seam"),
    "freestyle": ("freestyle_edge",),
}
PATTERN_DUTY = {"SOLID": 1.0, "DOTTED": 0.25, "DASHED": 0.5}
# Tessellated sources (image model §3.9), and their coplanar angle.
TESSELLATED_TYPES = ("FONT", "CURVE", "SURFACE", "META")
COPLANAR_ANGLE = 1.0e-3


def _cage_masks(depsgraph, s) -> dict:
    """{object name: (drawn mask, chain id) per evaluated edge} for the
    meshes a subdivision modifier subdivides, found independently of the
    add-on: a temporary integer edge attribute numbers every edge of the
    last subdivision's input from 1; Blender's subdivision carries it onto
    the child edges of those edges only. Where that input is the object's
    own mesh (nothing but deform modifiers before the subdivision) the
    attribute is written on the mesh; else (a Bevel, a Triangulate, a
    Mirror... before it, whose new edges are cage edges too, each a chain
    of its own) a temporary Geometry Nodes modifier just before the
    subdivision stores it. An Array cap carries no Optimal Display marks,
    so Blender's overlay shows every cap edge: the caps' meshes get the
    attribute too, numbered past the object's edges, so each cap edge is
    drawn and a chain of its own. Removed again before returning."""
    if s is None or not getattr(s, "use_cage_edges", False):
        return {}
    render = depsgraph.mode == "RENDER"
    marked, caps, numbering = [], [], []
    for obj in bpy.context.scene.objects:
        if obj.type != "MESH" or obj.mode == "EDIT":
            continue
        subdivides = [
            m
            for m in obj.modifiers
            if m.type in ("SUBSURF", "MULTIRES")
            and (m.show_render if render else m.show_viewport)
            and (m.render_levels if render else m.levels) > 0
        ]
        if subdivides and not _keeps_optimal_display(obj, subdivides, render, depsgraph):
            continue  # Blender's overlay shows every edge
        if subdivides and "__reference_cage" not in obj.data.attributes:
            if _input_is_own_mesh(obj, subdivides[-1], render):
                attribute = obj.data.attributes.new("__reference_cage", "INT", "EDGE")
                attribute.data.foreach_set("value", np.arange(1, len(obj.data.edges) + 1, dtype=np.int32))
            else:
                numbering.append(_number_input_edges(obj, subdivides[-1]))
            marked.append(obj)
            for cap in _array_caps(obj, subdivides[-1], render):
                if "__reference_cage" not in cap.data.attributes:
                    first = _CAP_NUMBERS * (len(caps) + 1)
                    attribute = cap.data.attributes.new("__reference_cage", "INT", "EDGE")
                    attribute.data.foreach_set("value", np.arange(first, first + len(cap.data.edges), dtype=np.int32))
                    caps.append(cap)
    masks = {}
    if not marked:
        return masks
    try:
        depsgraph.update()
        for obj in marked:
            mesh = obj.evaluated_get(depsgraph).data
            values = np.zeros(len(mesh.edges), np.int32)
            attribute = mesh.attributes.get("__reference_cage")
            if attribute is None or attribute.domain != "EDGE":
                continue
            attribute.data.foreach_get("value", values)
            # Child edges of an original edge carry its id + 1 (an integer
            # edge attribute is copied to them); new inner edges get 0.
            masks[obj.name] = (values > 0, values - 1)
    finally:
        for obj, modifier, tree in numbering:
            obj.modifiers.remove(modifier)
            bpy.data.node_groups.remove(tree)
        for obj in marked + caps:
            attribute = obj.data.attributes.get("__reference_cage")
            if attribute is not None:
                obj.data.attributes.remove(attribute)
        depsgraph.update()
    return masks


def _input_is_own_mesh(obj, last_subdivision, render) -> bool:
    """Whether the last subdivision subdivides the object's own mesh, moved
    at most: only deform modifiers (or none) are enabled before it."""
    for m in obj.modifiers:
        if m == last_subdivision:
            return True
        if (m.show_render if render else m.show_viewport) and m.type not in _REFERENCE_DEFORM:
            return False
    return True


def _number_input_edges(obj, last_subdivision):
    """(obj, modifier, node group): a Geometry Nodes modifier inserted just
    before ``last_subdivision`` that stores each edge's index + 1 as the
    integer edge attribute "__reference_cage" (an index below 2**24 is
    exact through the float addition)."""
    tree = bpy.data.node_groups.new("__reference_cage", "GeometryNodeTree")
    tree.interface.new_socket("Geometry", in_out="INPUT", socket_type="NodeSocketGeometry")
    tree.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
    nodes, links = tree.nodes, tree.links
    group_in, group_out = nodes.new("NodeGroupInput"), nodes.new("NodeGroupOutput")
    store = nodes.new("GeometryNodeStoreNamedAttribute")
    store.data_type, store.domain = "INT", "EDGE"
    store.inputs["Name"].default_value = "__reference_cage"
    plus_one = nodes.new("ShaderNodeMath")
    plus_one.operation = "ADD"
    plus_one.inputs[1].default_value = 1.0
    links.new(nodes.new("GeometryNodeInputIndex").outputs[0], plus_one.inputs[0])
    links.new(plus_one.outputs[0], store.inputs["Value"])
    links.new(group_in.outputs[0], store.inputs["Geometry"])
    links.new(store.outputs[0], group_out.inputs[0])
    modifier = obj.modifiers.new("__reference_cage", "NODES")
    modifier.node_group = tree
    obj.modifiers.move(len(obj.modifiers) - 1, list(obj.modifiers).index(last_subdivision))
    return obj, modifier, tree


# Where the caps' edge numbers start (cap k from (k + 1) times this): past
# any test mesh's own edges.
_CAP_NUMBERS = 1 << 24


def _array_caps(obj, last_subdivision, render) -> list:
    """The cap objects of the Array modifiers after ``obj``'s last
    subdivision. A cap with modifiers of its own is not modelled (its marks
    would come from its own evaluation)."""
    enabled = [m for m in obj.modifiers if (m.show_render if render else m.show_viewport)]
    caps = []
    for m in enabled[enabled.index(last_subdivision) + 1 :]:
        if m.type != "ARRAY":
            continue
        for cap in (m.start_cap, m.end_cap):
            if cap is None:
                continue
            if cap.type != "MESH" or any(c.show_render or c.show_viewport for c in cap.modifiers):
                raise NotImplementedError("the reference does not model Array caps with modifiers of their own")
            caps.append(cap)
    return caps


# Modifiers after the last subdivision as Blender's overlay treats them
# (its Optimal Display marks live on the mesh's runtime data): deform
# modifiers pass the mesh on, Mirror copies the marks to both halves unless
# it bisects or merges anything, Array to every copy unless Merge is on,
# Weld keeps its input when it welds nothing; the others make a new mesh
# without them. The reference knows these types; any other raises, so that
# no test compares with a guess.
_REFERENCE_DEFORM = frozenset(
    {"CAST", "DISPLACE", "SIMPLE_DEFORM", "SMOOTH", "WAVE", "LAPLACIANSMOOTH", "CORRECTIVE_SMOOTH"}
)
_REFERENCE_DROPS = frozenset({"TRIANGULATE", "SOLIDIFY", "BEVEL", "EDGE_SPLIT", "DECIMATE", "REMESH", "NODES"})


def _keeps_optimal_display(obj, subdivides, render, depsgraph) -> bool:
    """Whether Blender's overlay hides the inner edges of ``obj``'s last
    subdivision, found by the rules above and by evaluating the mesh with
    each merge switched off (a merge that merged anything changes the
    vertex count)."""
    if len(subdivides) > 1:
        raise NotImplementedError("the reference does not model stacked subdivisions with cage edges")
    last = subdivides[-1]
    if not last.show_only_control_edges:
        return False
    enabled = [m for m in obj.modifiers if (m.show_render if render else m.show_viewport)]
    after = enabled[enabled.index(last) + 1 :]
    merging = []
    for m in after:
        if m.type in _REFERENCE_DROPS:
            return False
        if m.type == "MIRROR":
            if any(m.use_bisect_axis[axis] and m.use_axis[axis] for axis in range(3)):
                return False
            if m.use_mirror_merge:
                merging.append((m, "use_mirror_merge", False))
        elif m.type == "ARRAY":
            if m.use_merge_vertices:
                return False
        elif m.type == "WELD":
            merging.append((m, "show_render" if render else "show_viewport", False))
        elif m.type not in _REFERENCE_DEFORM:
            raise NotImplementedError(f"the reference does not know how Blender's overlay treats {m.type}")
    for m, name, off in merging:
        depsgraph.update()
        merged = len(obj.evaluated_get(depsgraph).data.vertices)
        saved = getattr(m, name)
        setattr(m, name, off)
        try:
            depsgraph.update()
            unmerged = len(obj.evaluated_get(depsgraph).data.vertices)
        finally:
            setattr(m, name, saved)
            depsgraph.update()
        if merged != unmerged:
            return False
    return True


def _connected_edges(edges: list, ev) -> list:
    """``edges`` split into groups joined by shared vertices."""
    parent = {}

    def root(v):
        while parent.setdefault(v, v) != v:
            parent[v] = parent[parent[v]]
            v = parent[v]
        return v

    for e in edges:
        parent[root(int(ev[e, 0]))] = root(int(ev[e, 1]))
    groups: dict = {}
    for e in edges:
        groups.setdefault(root(int(ev[e, 0])), []).append(e)
    return list(groups.values())


def _edge_selection(obj, mesh, s, npoly, total, loop_poly, not_drawn, cage):
    """Lines of one mesh (image model §3.4-§3.7), plain Python on small
    meshes: for each face its block key (its region if the region is walked,
    else itself) and the line entries of each block: ends (lower id first),
    style, chain ends."""
    ne = len(mesh.edges)
    ev = np.empty(ne * 2, np.int64)
    mesh.edges.foreach_get("vertices", ev)
    ev = ev.reshape(-1, 2)
    corner_edge = np.empty(len(mesh.loops), np.int64)
    mesh.loops.foreach_get("edge_index", corner_edge)
    classes_on = s is not None and any(getattr(s, f"use_{name}_edges", False) for name in EDGE_CLASSES)
    if not not_drawn and cage is None and not classes_on:
        # Every edge drawn, one style: each face measures to its own edges
        # (§1.3); vectorised for the big meshes of the stress scenes.
        pairs = np.unique(np.stack([loop_poly, corner_edge], axis=1), axis=0)
        a, b = ev[pairs[:, 1]].min(axis=1), ev[pairs[:, 1]].max(axis=1)
        return {
            "key": np.arange(npoly),
            "owner": pairs[:, 0],
            "a": a,
            "b": b,
            "style": np.zeros(len(a), np.int64),
            "chain_a": a,
            "chain_b": b,
            "hidden": set(),
        }
    uses = np.bincount(corner_edge, minlength=ne)
    drawn = np.ones(ne, bool)
    for e in range(ne):
        if (min(ev[e]), max(ev[e])) in not_drawn:
            drawn[e] = False
    chain = np.arange(ne)
    if cage is not None and len(cage[0]) == ne:
        drawn &= cage[0]
        chain = np.where(cage[0], cage[1], -1 - np.arange(ne))
    bits = np.zeros(ne, np.int64)
    for k, name in enumerate(EDGE_CLASSES):
        if s is None or not getattr(s, f"use_{name}_edges", False):
            continue
        if name == "boundary":
            bits[uses == 1] |= 1 << k
            continue
        if (
            name == "freestyle"
            and mesh.attributes.get("freestyle_edge") is None
            and hasattr(mesh.edges[0] if ne else None, "use_freestyle_mark")
        ):
            bits[[e for e in range(ne) if mesh.edges[e].use_freestyle_mark]] |= 1 << k  # Blender 4.x
            continue
        for attr_name in _CLASS_ATTRIBUTES[name]:
            attribute = mesh.attributes.get(attr_name)
            if attribute is not None and attribute.domain == "EDGE":
                values = np.zeros(ne, np.float64)
                for i, item in enumerate(attribute.data):
                    values[i] = float(item.value)
                bits[values > 0] |= 1 << k
                break
    drawn |= (uses != 2) | (bits != 0)

    # Regions: union-find over edges that are not drawn.
    parent = list(range(npoly))

    def find(x):
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    faces_of_edge = [[] for _ in range(ne)]
    for corner, e in enumerate(corner_edge):
        faces_of_edge[e].append(int(loop_poly[corner]))
    for e in np.flatnonzero(~drawn):
        fs = faces_of_edge[e]
        for f in fs[1:]:
            ra, rb = find(fs[0]), find(f)
            if ra != rb:
                parent[max(ra, rb)] = min(ra, rb)
    label = np.array([find(f) for f in range(npoly)], np.int64)
    region_edges: dict = {}
    face_edges: dict = {}
    for corner, e in enumerate(corner_edge):
        if drawn[e]:
            f = int(loop_poly[corner])
            region_edges.setdefault(int(label[f]), set()).add(int(e))
            face_edges.setdefault(f, set()).add(int(e))
    size = np.bincount(label, minlength=npoly)
    walked = size[label] > 1  # regions have no size limit (image model §3.4)
    key = np.where(walked, label, np.arange(npoly))
    entries = []  # (owner key, edge)
    for owner in sorted(set(key.tolist())):
        f = owner
        source = region_edges.get(int(label[f]), set()) if walked[f] else face_edges.get(f, set())
        entries += [(owner, e) for e in sorted(source)]

    # Chains (cage edges cut by subdivision): the ends of each chain's path.
    chain_ends = {}
    members: dict = {}
    for e in range(ne):
        members.setdefault(int(chain[e]), []).append(e)
    for group in members.values():
        # One id can name several paths (a Mirror or Array after the
        # subdivision copies each cage edge's children): one path each.
        for es in _connected_edges(group, ev):
            count: dict = {}
            for e in es:
                for v in ev[e]:
                    count[int(v)] = count.get(int(v), 0) + 1
            odd = [v for v, n in count.items() if n % 2 == 1]
            for e in es:
                chain_ends[e] = tuple(odd) if len(odd) == 2 else (int(ev[e, 0]), int(ev[e, 1]))

    owner, a, b, style, ca, cb = [], [], [], [], [], []
    for o, e in entries:
        styles = [k + 1 for k in range(len(EDGE_CLASSES)) if bits[e] >> k & 1] or [0]
        for st in styles:
            owner.append(o)
            a.append(min(ev[e]))
            b.append(max(ev[e]))
            style.append(st)
            ca.append(chain_ends[e][0])
            cb.append(chain_ends[e][1])
    hidden = {(int(min(ev[e])), int(max(ev[e]))) for e in np.flatnonzero(~drawn)}
    as_array = lambda x: np.array(x, np.int64)
    return {
        "key": key,
        "owner": as_array(owner),
        "a": as_array(a),
        "b": as_array(b),
        "style": as_array(style),
        "chain_a": as_array(ca),
        "chain_b": as_array(cb),
        "hidden": hidden,
    }


def _gather_geometry(depsgraph, view_matrix, s=None) -> _Geometry:
    tris, tri_faces, edges, edge_faces, edge_real, edge_origin = [], [], [], [], [], []
    sil_edges, sil_third = [], []
    tri_normals, face_fill, face_wire, tri_colors = [], [], [], []
    face_thickness, face_object, objects, offsets = [], [], [], []
    face_key, edge_style, chain_view = [], [], []
    cage_masks = _cage_masks(depsgraph, s)
    face_offset = 0
    for inst in depsgraph.object_instances:
        obj = inst.object
        if obj.type != "MESH":
            continue
        if not inst.is_instance and not inst.show_self:
            continue
        source = obj.original
        instancer = inst.parent.original if inst.is_instance and inst.parent is not None else source
        if not (source.solidwire.show_in_render and instancer.solidwire.show_in_render):
            continue
        mesh = obj.data
        nv, nl, npoly = len(mesh.vertices), len(mesh.loops), len(mesh.polygons)
        if npoly == 0:
            continue
        override = source.solidwire.thickness if source.solidwire.use_override else np.nan
        face_thickness.append(np.full(npoly, override, np.float64))
        face_object.append(np.full(npoly, len(objects), np.int64))
        objects.append(source.name)
        offsets.append(face_offset)
        co = np.empty(nv * 3, np.float32)
        mesh.vertices.foreach_get("co", co)
        co = co.reshape(-1, 3).astype(np.float64)
        to_view = view_matrix @ np.array(inst.matrix_world, dtype=np.float64)
        with np.errstate(invalid="ignore", over="ignore"):
            vco = co @ to_view[:3, :3].T + to_view[:3, 3]
        loop_vert = np.empty(nl, np.int64)
        mesh.loops.foreach_get("vertex_index", loop_vert)
        start = np.empty(npoly, np.int64)
        total = np.empty(npoly, np.int64)
        mesh.polygons.foreach_get("loop_start", start)
        mesh.polygons.foreach_get("loop_total", total)
        lt = mesh.loop_triangles
        ntri = len(lt)
        tri_v = np.empty(ntri * 3, np.int64)
        lt.foreach_get("vertices", tri_v)
        tri_v = tri_v.reshape(-1, 3)
        tri_p = np.empty(ntri, np.int64)
        lt.foreach_get("polygon_index", tri_p)

        # Real edges: consecutive loops of each polygon.
        loop_poly = np.repeat(np.arange(npoly), total)
        loop_idx = np.arange(nl)
        nxt = start[loop_poly] + (loop_idx - start[loop_poly] + 1) % total[loop_poly]
        real_a, real_b = loop_vert[loop_idx], loop_vert[nxt]
        # Diagonals: triangle edges that are not polygon edges of that polygon.
        key_real = set(
            zip(loop_poly.tolist(), np.minimum(real_a, real_b).tolist(), np.maximum(real_a, real_b).tolist())
        )
        diag = set()
        # A face with a corner that is not drawable (NaN, Inf or past
        # COORDINATE_LIMIT in the mesh's own space) is not drawn at all
        # (§2.1): it has no edges either, so it makes no silhouette
        # candidate and leaves its neighbours' shared edges boundaries.
        drawn_vertex = drawable(co, axis=1) & np.isfinite(vco).all(axis=1)
        poly_ok = np.bincount(loop_poly, weights=~drawn_vertex[loop_vert], minlength=npoly) == 0
        half_edges: dict = {}  # real edge -> third vertices of its drawn triangles
        for t in range(ntri):  # small meshes only (reference)
            p = int(tri_p[t])
            if not poly_ok[p]:
                continue
            for k in range(3):
                a, b = int(tri_v[t, k]), int(tri_v[t, (k + 1) % 3])
                key = (p, min(a, b), max(a, b))
                if key not in key_real:
                    diag.add(key)
                else:
                    half_edges.setdefault((min(a, b), max(a, b)), []).append(int(tri_v[t, (k + 2) % 3]))
        diag = np.array(sorted(diag), dtype=np.int64).reshape(-1, 3)

        # Edge angle (image model §3.4): an edge of exactly two distinct
        # faces whose face normals differ by less than the angle is not
        # drawn (neither a line nor a diagonal).
        angle = float(getattr(s, "edge_angle", 0.0) or 0.0)
        tessellated = source.type in TESSELLATED_TYPES and not any(md.type == "NODES" for md in source.modifiers)
        if tessellated and not getattr(s, "show_tessellation", False):
            # §3.9: the tessellation of text, curves, surfaces and metaballs
            # hides edges between coplanar faces (the angle rule at a tiny
            # angle, for these types only).
            angle = max(angle, COPLANAR_ANGLE)
        not_drawn = _flat_edges(mesh, loop_poly, real_a, real_b, angle, poly_ok)
        cage = None if tessellated else cage_masks.get(source.name)  # (§3.9: no cage of their own)
        sel = _edge_selection(obj, mesh, s, npoly, total, loop_poly, not_drawn, cage)
        sil = [(a, b, th) for (a, b), th in half_edges.items() if len(th) <= 2 and (a, b) not in sel["hidden"]]
        if sil:
            sa = np.array([e[0] for e in sil])
            sb = np.array([e[1] for e in sil])
            of = np.array([e[2][0] for e in sil])
            og = np.array([e[2][1] if len(e[2]) == 2 else -1 for e in sil])
            ok_s = drawn_vertex[sa] & drawn_vertex[sb] & drawn_vertex[of] & ((og < 0) | drawn_vertex[np.maximum(og, 0)])
            sa, sb, of, og = sa[ok_s], sb[ok_s], of[ok_s], og[ok_s]
            sil_edges.append(np.stack([vco[sa], vco[sb]], axis=1))
            third_g = np.where((og >= 0)[:, None], vco[np.maximum(og, 0)], np.nan)
            sil_third.append(np.stack([vco[of], third_g], axis=1))
        tri_ok = poly_ok[tri_p]
        # The front side is the side the (transformed) normal points to: a
        # mirroring object or camera matrix reverses view-space winding, so
        # reverse it back for the back-face test (as Blender draws them).
        mirrored = np.linalg.det(to_view[:3, :3]) < 0.0
        front_winding = tri_v[:, ::-1] if mirrored else tri_v
        tris.append(vco[front_winding[tri_ok]])
        if s is not None:
            # Corner normals (Blender's own) to view space with the inverse
            # transpose; interpolated over the triangle, then normalised.
            corner_n = np.empty(nl * 3, np.float32)
            mesh.corner_normals.foreach_get("vector", corner_n)
            corner_n = corner_n.reshape(-1, 3).astype(np.float64)
            tri_l = np.empty(ntri * 3, np.int64)
            lt.foreach_get("loops", tri_l)
            tri_l = tri_l.reshape(-1, 3)
            tri_l = tri_l[:, ::-1] if mirrored else tri_l
            with np.errstate(all="ignore"):
                nmat = np.linalg.inv(to_view[:3, :3]).T
            tri_normals.append(corner_n[tri_l[tri_ok]] @ nmat.T)
            tri_colors.append(_corner_colors(mesh, tri_l, front_winding)[tri_ok])
            material_index = np.zeros(npoly, np.int64)
            if npoly and "material_index" in mesh.attributes:
                mesh.attributes["material_index"].data.foreach_get("value", material_index)
            fills, wire = _object_colors(obj, s, npoly, material_index)
            face_fill.append(fills)
            face_wire.append(np.tile(wire, (npoly, 1)))
        tri_faces.append(face_offset + tri_p[tri_ok])
        face_key.append(face_offset + sel["key"])
        ea, eb = sel["a"], sel["b"]
        ok = drawn_vertex[ea] & drawn_vertex[eb]
        edges.append(np.stack([vco[ea[ok]], vco[eb[ok]]], axis=1))
        edge_faces.append(face_offset + sel["owner"][ok])
        edge_real.append(np.ones(ok.sum(), bool))
        edge_origin.append(np.ones(ok.sum(), bool))  # stored lower id first
        edge_style.append(sel["style"][ok])
        chain_view.append(np.stack([vco[sel["chain_a"][ok]], vco[sel["chain_b"][ok]]], axis=1))
        if len(diag):
            da, db = diag[:, 1], diag[:, 2]
            ok = poly_ok[diag[:, 0]]
            edges.append(np.stack([vco[da[ok]], vco[db[ok]]], axis=1))
            edge_faces.append(face_offset + diag[ok, 0])
            edge_real.append(np.zeros(ok.sum(), bool))
            edge_origin.append(np.ones(ok.sum(), bool))  # da < db by construction
            edge_style.append(np.zeros(ok.sum(), np.int64))
            chain_view.append(np.stack([vco[da[ok]], vco[db[ok]]], axis=1))
        face_offset += npoly

    def cat(parts, shape, dtype):
        return np.concatenate(parts) if parts else np.zeros(shape, dtype)

    return _Geometry(
        cat(tris, (0, 3, 3), np.float64),
        cat(tri_faces, (0,), np.int64),
        cat(edges, (0, 2, 3), np.float64),
        cat(edge_faces, (0,), np.int64),
        cat(edge_real, (0,), bool),
        cat(edge_origin, (0,), bool),
        cat(sil_edges, (0, 2, 3), np.float64),
        cat(sil_third, (0, 2, 3), np.float64),
        cat(tri_normals, (0, 3, 3), np.float64),
        cat(tri_colors, (0, 3, 3), np.float64),
        cat(face_fill, (0, 3), np.float64),
        cat(face_wire, (0, 3), np.float64),
        cat(face_thickness, (0,), np.float64),
        cat(face_object, (0,), np.int64),
        objects,
        offsets,
        cat(face_key, (0,), np.int64),
        cat(edge_style, (0,), np.int64),
        cat(chain_view, (0, 2, 3), np.float64),
    )


# ---------------------------------------------------------------- visibility


def _to_clip(proj, pts):
    return pts @ proj[:3, :3].T + proj[:3, 3], pts @ proj[3, :3] + proj[3, 3]


def _window(proj, pts, width, height):
    """View-space points (in front of the near plane) -> window coordinates."""
    xyz, w = _to_clip(proj, pts)
    return np.stack([(xyz[..., 0] / w + 1.0) * 0.5 * width, (xyz[..., 1] / w + 1.0) * 0.5 * height], axis=-1)


def _triangle_pixel_bounds(proj, tri_view, width, height):
    """Per triangle, the window bbox of its near-clipped part (or empty)."""
    clip_xyz, clip_w = _to_clip(proj, tri_view)  # (T,3,3), (T,3)
    front = clip_xyz[..., 2] + clip_w  # >= 0 in front of the near plane
    cand = [tri_view[:, k] for k in range(3)]
    valid = [front[:, k] >= 0 for k in range(3)]
    for k in range(3):
        a, b = k, (k + 1) % 3
        fa, fb = front[:, a], front[:, b]
        crosses = (fa >= 0) != (fb >= 0)
        with np.errstate(invalid="ignore", divide="ignore"):
            t = np.where(crosses, fa / (fa - fb), 0.0)
        cand.append(tri_view[:, a] + t[:, None] * (tri_view[:, b] - tri_view[:, a]))
        valid.append(crosses)
    pts = np.stack(cand, axis=1)  # (T, 6, 3)
    ok = np.stack(valid, axis=1)
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        win = _window(proj, pts, width, height)
    win = np.where(ok[..., None] & np.isfinite(win), win, np.nan)
    with np.errstate(invalid="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN rows: triangles with no visible corner
        lo = np.nanmin(win, axis=1)
        hi = np.nanmax(win, axis=1)
    any_ok = ok.any(axis=1) & np.isfinite(lo).all(axis=1)
    margin = 2 * SILHOUETTE_OFFSET + 1e-6
    x0 = np.clip(np.floor(lo[:, 0] - 0.5 - margin), 0, width)
    x1 = np.clip(np.ceil(hi[:, 0] - 0.5 + margin), -1, width - 1)
    y0 = np.clip(np.floor(lo[:, 1] - 0.5 - margin), 0, height)
    y1 = np.clip(np.ceil(hi[:, 1] - 0.5 + margin), -1, height - 1)
    x0, x1, y0, y1 = (np.nan_to_num(v, nan=0).astype(np.int64) for v in (x0, x1, y0, y1))
    empty = ~any_ok | (x1 < x0) | (y1 < y0)
    x1 = np.where(empty, x0 - 1, x1)
    return x0, x1, y0, y1


def _clip_depths(proj):
    """View depths (positive) of the near and far clip planes of ``proj``:
    where NDC z is -1 and +1. The far one is inf when the far plane is at
    infinity (a huge clip end rounds the float32 camera matrix to that)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        near = (proj[3, 3] + proj[2, 3]) / (proj[2, 2] + proj[3, 2])
        far = (proj[2, 3] - proj[3, 3]) / (proj[2, 2] - proj[3, 2])
    return float(near), (float(far) if np.isfinite(far) and far > near else np.inf)


def _rays(inv_proj, proj, px, py, width, height):
    """Float64 rays through window points: (origin, direction, t_near, t_far).

    Perspective: from the camera centre through the sample's point on the
    near plane; orthographic: from that near-plane point along the view
    direction. Hits are kept for t in [t_near, t_far] (clip start..end).
    Nothing is unprojected from the far plane: with a huge clip end its
    point has w ~ 0 (or exactly 0) and the ray would turn NaN."""
    x = px / width * 2.0 - 1.0
    y = py / height * 2.0 - 1.0
    near_h = np.stack([x, y, -np.ones_like(x), np.ones_like(x)], axis=-1) @ inv_proj.T
    near_pt = near_h[..., :3] / near_h[..., 3:4]
    near_depth, far_depth = _clip_depths(proj)
    if proj[3, 2] != 0.0:  # perspective: camera centre at the view origin
        origin = np.zeros_like(near_pt)
        direction = near_pt  # t = 1 on the near plane, t = depth / near beyond
        return origin, direction, 1.0, far_depth / near_depth
    origin = near_pt  # orthographic: parallel rays down -z from the near plane
    direction = np.zeros_like(near_pt)
    direction[..., 2] = -1.0
    return origin, direction, 0.0, far_depth - near_depth


# A triangle whose facing |det| is within this fraction of its scale is seen
# edge-on as far as float32 can tell (back-face culling may go either way).
FACING_TOLERANCE = 1e-5
# Barycentric slack of the near misses _hidden_edge_samples looks at: a
# sample 0.01 px outside a triangle lies 0.01 / (its size in px) outside in
# barycentrics, so this holds every such sample of a triangle 0.04 px across
# or larger (smaller ones are slivers, flagged whole); each is then measured
# in window space.
NEAR_MISS_BARYCENTRIC = 0.25


def _visibility(geo, proj, width, height, rows, backface_culling, all_hits=None, centre_hit=None, near_misses=None):
    """Nearest face for the sample of each pixel of ``rows`` and its 4 offsets.

    With a list as ``all_hits``, every hit of the centre sample is appended
    to it as (pixel, depth, face, triangle) arrays (hidden-line style); with
    a list as ``near_misses``, so is every triangle whose plane the centre
    ray meets just outside it (barycentrics within NEAR_MISS_BARYCENTRIC;
    _hidden_edge_samples measures how far in pixels). With a dict as
    ``centre_hit``, it receives the centre sample's triangle, barycentric
    (u, v) and whether its front side is seen ("tri", "u", "v", "front"),
    and where that triangle or side is undecided ("shading_undecided":
    ReferenceResult's shading_undecided)."""
    inv_proj = np.linalg.inv(proj)
    n_rows = len(rows)
    row_of = np.full(height, -1, np.int64)
    row_of[rows] = np.arange(n_rows)
    n_samples = len(OFFSETS)
    best_depth = np.full((n_samples, n_rows * width), np.inf)
    best_face = np.full((n_samples, n_rows * width), -1, np.int64)
    best_tri = np.full((n_samples, n_rows * width), -1, np.int64)
    if centre_hit is not None:
        centre_hit["tri"] = np.full(n_rows * width, -1, np.int64)
        centre_hit["u"] = np.zeros(n_rows * width)
        centre_hit["v"] = np.zeros(n_rows * width)
        centre_hit["front"] = np.ones(n_rows * width, bool)

    undecided_hits: list = []
    side_hits: list = []  # (pixel, depth, front side seen, seen edge-on) of every centre hit
    if centre_hit is not None:
        centre_hit["undecided"] = np.zeros(n_rows * width, bool)
        centre_hit["shading_undecided"] = np.zeros(n_rows * width, bool)
        # The nearest hit of another face than the centre's visible one, to
        # find faces that lie on one another (§7.2).
        runner_up = _RunnerUp(n_rows * width)
    x0, x1, y0, y1 = _triangle_pixel_bounds(proj, geo.tri_view, width, height)
    tri_ids = np.nonzero(x1 >= x0)[0]
    if len(tri_ids) == 0:
        return best_face, best_depth
    tip_slack = _tip_slack(geo.tri_view, proj, width, height) if centre_hit is not None else None
    tip_misses: list = []  # (pixel, depth, face, triangle) of centre rays just outside a triangle
    # Only rows we evaluate: count per triangle the rows of its bbox in `rows`.
    row_mask = np.zeros(height + 1, np.int64)
    row_mask[rows] = 1
    cum = np.concatenate([[0], np.cumsum(row_mask)])
    row_counts = cum[y1[tri_ids] + 1] - cum[y0[tri_ids]]
    widths = x1[tri_ids] - x0[tri_ids] + 1
    areas = np.maximum(row_counts, 0) * widths
    tri_ids, areas, widths = tri_ids[areas > 0], areas[areas > 0], widths[areas > 0]
    bounds = np.cumsum(areas)
    start = 0
    while start < len(tri_ids):
        # A chunk of triangles whose candidate pixels fit in PAIR_CHUNK.
        base = bounds[start - 1] if start else 0
        stop = max(start + 1, int(np.searchsorted(bounds, base + PAIR_CHUNK, side="right")))
        ids = tri_ids[start:stop]
        area = areas[start:stop]
        wid = widths[start:stop]
        pair_tri = np.repeat(ids, area)
        local = np.arange(area.sum()) - np.repeat(np.cumsum(area) - area, area)
        pair_w = np.repeat(wid, area)
        px = x0[pair_tri] + local % pair_w
        row_rank = local // pair_w  # k-th evaluated row inside the bbox
        py = rows[np.searchsorted(rows, y0[pair_tri]) + row_rank]
        pixel = row_of[py] * width + px
        v0 = geo.tri_view[pair_tri, 0]
        e1 = geo.tri_view[pair_tri, 1] - v0
        e2 = geo.tri_view[pair_tri, 2] - v0
        scale = np.linalg.norm(e1, axis=1) * np.linalg.norm(e2, axis=1)
        for s, (ox, oy) in enumerate(OFFSETS):
            origin, direction, t_near, t_far = _rays(inv_proj, proj, px + 0.5 + ox, py + 0.5 + oy, width, height)
            det, u_det, v_det, t_det = _ray_triangle_terms(origin, direction, v0, e1, e2)
            ok = np.abs(det) > 1e-13 * scale * np.linalg.norm(direction, axis=1)
            if backface_culling:
                # Which side faces the ray is undecided for a triangle seen
                # nearly edge-on at float32 precision (the engine's): such a
                # hit marks its sample as undecided (§7) instead of deciding.
                undecided = ok & (np.abs(det) <= FACING_TOLERANCE * scale * np.linalg.norm(direction, axis=1))
                ok &= det > 0.0  # front side faces the ray
            else:
                undecided = np.zeros(len(det), bool)
            with np.errstate(divide="ignore", invalid="ignore"):
                inv_det = np.where(ok, 1.0 / det, 0.0)
                u, v, t = u_det * inv_det, v_det * inv_det, t_det * inv_det
            inside = (u >= 0) & (v >= 0) & (u + v <= 1) & (t >= t_near) & (t <= t_far)
            hit = ok & inside
            depth = -(origin[:, 2] + t * direction[:, 2])
            if s == 0 and centre_hit is not None and undecided.any():
                with np.errstate(divide="ignore", invalid="ignore"):
                    inv_u = np.where(undecided, 1.0 / det, 0.0)
                    uu, vv, tt = u_det * inv_u, v_det * inv_u, t_det * inv_u
                near_hit = undecided & (uu >= 0) & (vv >= 0) & (uu + vv <= 1) & (tt >= t_near) & (tt <= t_far)
                undecided_hits.append((pixel[near_hit], -(origin[near_hit, 2] + tt[near_hit] * direction[near_hit, 2])))
            h_pix, h_depth, h_face = pixel[hit], depth[hit], geo.tri_face[pair_tri[hit]]
            if s == 0 and all_hits is not None:
                all_hits.append((h_pix, h_depth, h_face, pair_tri[hit]))
            if s == 0 and tip_slack is not None:
                slack = tip_slack[pair_tri]
                miss = ok & ~inside & (u >= -slack) & (v >= -slack) & (u + v <= 1 + slack)
                miss &= (t >= t_near) & (t <= t_far)
                tip_misses.append((pixel[miss], depth[miss], geo.tri_face[pair_tri[miss]], pair_tri[miss]))
            if s == 0 and near_misses is not None:
                slack = NEAR_MISS_BARYCENTRIC
                miss = ok & ~inside & (u >= -slack) & (v >= -slack) & (u + v <= 1 + slack)
                miss &= (t >= t_near) & (t <= t_far)
                near_misses.append((pixel[miss], depth[miss], geo.tri_face[pair_tri[miss]], pair_tri[miss]))
            h_tri, h_u, h_v, h_front = pair_tri[hit], u[hit], v[hit], det[hit] > 0.0
            if s == 0 and centre_hit is not None:
                edge_on = np.abs(det) <= FACING_TOLERANCE * scale * np.linalg.norm(direction, axis=1)
                side_hits.append((pixel[hit], depth[hit], h_front, edge_on[hit]))
            # Nearest hit per pixel (ties: lowest face id, deterministic).
            order = np.lexsort((h_face, h_depth, h_pix))
            h_pix, h_depth, h_face = h_pix[order], h_depth[order], h_face[order]
            h_tri, h_u, h_v, h_front = h_tri[order], h_u[order], h_v[order], h_front[order]
            first = np.ones(len(h_pix), bool)
            first[1:] = h_pix[1:] != h_pix[:-1]
            if s == 0 and centre_hit is not None:
                runner_up.add(h_pix, h_depth, h_face, first)
            h_pix, h_depth, h_face = h_pix[first], h_depth[first], h_face[first]
            h_tri, h_u, h_v, h_front = h_tri[first], h_u[first], h_v[first], h_front[first]
            closer = h_depth < best_depth[s, h_pix]
            best_depth[s, h_pix[closer]] = h_depth[closer]
            best_face[s, h_pix[closer]] = h_face[closer]
            best_tri[s, h_pix[closer]] = h_tri[closer]
            if s == 0 and centre_hit is not None:
                px_c = h_pix[closer]
                centre_hit["tri"][px_c] = h_tri[closer]
                centre_hit["u"][px_c] = h_u[closer]
                centre_hit["v"][px_c] = h_v[closer]
                centre_hit["front"][px_c] = h_front[closer]
        start = stop
    if centre_hit is not None:
        # Samples whose nearest surface may be an undecided triangle, or
        # another face at the visible one's depth.
        flagged = np.isfinite(runner_up.depth) & (runner_up.depth <= best_depth[0] * (1.0 + UNDECIDED_DEPTH))
        for pix, depth in undecided_hits + _sliver_samples(geo, proj, width, height, rows, row_of):
            near = depth <= best_depth[0, pix] * (1.0 + UNDECIDED_DEPTH)
            flagged[pix[near]] = True
        flagged |= _tip_samples(tip_misses, best_face[0], best_depth[0], geo, proj, width, height, rows)
        # Which triangle of the visible face the sample shows is rounding's
        # choice where a sample 0.01 px off shows another (a fold's edge).
        other_triangle = ((best_tri[1:] != best_tri[0]) & (best_face[1:] == best_face[0])).any(axis=0)
        flagged |= _fold_contour(geo, inv_proj, proj, width, height, rows, best_tri, best_depth)
        centre_hit["undecided"] = flagged
        centre_hit["shading_undecided"] = other_triangle | _side_undecided(
            side_hits, best_depth[0], centre_hit["front"]
        )
    return best_face, best_depth


def _fold_contour(geo, inv_proj, proj, width, height, rows, best_tri, best_depth) -> np.ndarray:
    """Samples on the contour of a folded face (§7.2): a probe 0.01 px off
    shows another triangle of the visible face, and one of the two
    triangles covers the other's sample too, at another depth. There the
    visible depth jumps within the face (the triangles lie on one another),
    so whether the rasteriser covers the sample with the near one or shows
    the far one is its rounding's choice, and with it every term that reads
    the visible depth. Triangles that only meet along an edge (a flat
    n-gon's, a bent quad's) cover no sample of one another and keep the
    depth continuous."""
    flagged = np.zeros(best_tri.shape[1], bool)
    centre_tri, centre_depth = best_tri[0], best_depth[0]
    for s in range(1, len(OFFSETS)):
        other = np.flatnonzero((best_tri[s] >= 0) & (centre_tri >= 0) & (best_tri[s] != centre_tri))
        other = other[geo.tri_face[best_tri[s, other]] == geo.tri_face[centre_tri[other]]]
        if not len(other):
            continue
        px = other % width + 0.5
        py = rows[other // width] + 0.5
        ox, oy = OFFSETS[s]
        # The probe's triangle at the centre, and the centre's at the probe.
        for tri, x, y, seen_depth in (
            (best_tri[s, other], px, py, centre_depth[other]),
            (centre_tri[other], px + ox, py + oy, best_depth[s, other]),
        ):
            depth = _triangle_depth_on_ray(geo.tri_view[tri], inv_proj, proj, x, y, width, height)
            jump = np.abs(depth - seen_depth) > UNDECIDED_DEPTH * np.abs(seen_depth)
            flagged[other[np.isfinite(depth) & jump]] = True
    return flagged


def _ray_triangle_terms(origin, direction, v0, e1, e2):
    """Möller-Trumbore for rays (origin, direction) against triangles with
    corner v0 and sides e1, e2, row by row: (det, u det, v det, t det), so
    that the barycentrics u, v and the ray parameter t are the last three
    over det (each caller divides where its det is usable)."""
    pvec = np.cross(direction, e2)
    tvec = origin - v0
    qvec = np.cross(tvec, e1)
    return (
        np.einsum("ij,ij->i", e1, pvec),
        np.einsum("ij,ij->i", tvec, pvec),
        np.einsum("ij,ij->i", direction, qvec),
        np.einsum("ij,ij->i", e2, qvec),
    )


def _triangle_depth_on_ray(corners, inv_proj, proj, x, y, width, height) -> np.ndarray:
    """View depth where the ray through window point (x, y) meets each of
    the triangles ``corners`` (N, 3, 3) within the clip range, NaN where it
    misses."""
    origin, direction, t_near, t_far = _rays(inv_proj, proj, x, y, width, height)
    v0 = corners[:, 0]
    det, u_det, v_det, t_det = _ray_triangle_terms(origin, direction, v0, corners[:, 1] - v0, corners[:, 2] - v0)
    with np.errstate(divide="ignore", invalid="ignore"):
        u, v, t = u_det / det, v_det / det, t_det / det
        hit = (det != 0.0) & (u >= 0) & (v >= 0) & (u + v <= 1) & (t >= t_near) & (t <= t_far)
        return np.where(hit, -(origin[:, 2] + t * direction[:, 2]), np.nan)


def _side_undecided(side_hits, visible_depth, visible_front) -> np.ndarray:
    """Per sample: a hit level with the visible one (UNDECIDED_DEPTH) is
    seen edge-on as far as float32 can tell (FACING_TOLERANCE), or shows
    the other side than the visible hit does."""
    flagged = np.zeros(len(visible_depth), bool)
    for pix, depth, front, edge_on in side_hits:
        level = depth <= visible_depth[pix] * (1.0 + UNDECIDED_DEPTH)
        flagged[pix[level & (edge_on | (front != visible_front[pix]))]] = True
    return flagged


# Relative depth within which which of two surfaces the engine's float32
# depth shows is rounding's choice (§7.2).
UNDECIDED_DEPTH = 1e-6


class _RunnerUp:
    """Per sample, the nearest depth of a face other than the nearest face
    over every hit added so far (inf where none): where it equals the
    visible face's depth, two faces lie on one another there (coplanar
    overlapping faces) and which one the engine shows is rounding's choice
    (§7.2). Fed the chunks of _visibility's centre hits."""

    def __init__(self, samples: int):
        self.nearest = np.full(samples, np.inf)
        self.nearest_face = np.full(samples, -1, np.int64)
        self.depth = np.full(samples, np.inf)
        self.face = np.full(samples, -1, np.int64)

    def add(self, pix, depth, face, first):
        """Hits sorted by (pixel, depth, face); ``first`` marks each pixel's
        nearest."""
        if not len(pix):
            return
        group = np.cumsum(first) - 1
        top_face = face[first]
        # The chunk's own runner-up: the first hit of another face in each
        # pixel's sorted hits.
        index = np.flatnonzero(face != top_face[group])
        index = index[np.r_[True, group[index[1:]] != group[index[:-1]]]] if len(index) else index
        chunk_second = np.full(len(top_face), np.inf)
        chunk_second_face = np.full(len(top_face), -1, np.int64)
        chunk_second[group[index]] = depth[index]
        chunk_second_face[group[index]] = face[index]
        p = pix[first]
        # Four candidates per sample: the kept nearest and runner-up, the
        # chunk's; the new nearest, then the nearest of the others' faces.
        depths = np.stack([self.nearest[p], self.depth[p], depth[first], chunk_second])
        faces = np.stack([self.nearest_face[p], self.face[p], top_face, chunk_second_face])
        best = np.argmin(depths, axis=0)
        columns = np.arange(len(p))
        best_face = faces[best, columns]
        others = np.where((faces != best_face) & (faces >= 0), depths, np.inf)
        second = np.argmin(others, axis=0)
        self.nearest[p], self.nearest_face[p] = depths[best, columns], best_face
        self.depth[p], self.face[p] = others[second, columns], faces[second, columns]


# A triangle thinner than this (its smallest window-space altitude, px) is a
# sliver: whether a sample 0.01 px from it is covered depends on the
# rasteriser's sub-pixel snapping, and probes 0.01 px apart can miss it.
SLIVER_PX = 0.05
SLIVER_REACH_PX = 0.01
# How far outside a triangle a rasteriser may still cover a sample: it
# snaps the window corners to a grid of 1/256 px (8 sub-pixel bits, as
# llvmpipe and Direct3D-class GPUs do), which moves an edge by up to
# about 0.003 px.
SNAP_REACH_PX = 2.0**-8


def _window_triangles(tri_view, proj, width, height):
    """Per triangle (view-space corners ``tri_view``, (T, 3, 3)): clip
    corners (T, 3, 4), which corners lie ahead of the near plane, whether
    the whole triangle does (and in front of the eye), window corners
    (T, 3, 2), its longest window side and smallest window altitude (0
    where it has no length)."""
    h = np.concatenate([tri_view, np.ones(tri_view.shape[:2] + (1,))], axis=2) @ proj.T
    with np.errstate(all="ignore"):
        ahead = h[..., 2] + h[..., 3] >= 0
        front = ahead.all(axis=1) & (h[..., 3] > 0).all(axis=1)
        win = (h[..., :2] / h[..., 3:4] + 1.0) * 0.5 * np.array([width, height])
        a, b, c = win[:, 0], win[:, 1], win[:, 2]
        area2 = np.abs((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]))
        longest = np.max(
            np.stack([np.linalg.norm(b - a, axis=1), np.linalg.norm(c - b, axis=1), np.linalg.norm(a - c, axis=1)]),
            axis=0,
        )
        altitude = np.where(longest > 0, area2 / np.maximum(longest, 1e-300), 0.0)
    return h, ahead, front, win, longest, altitude


def _sliver_samples(geo, proj, width, height, rows, row_of) -> list:
    """[(pixels, depth)]: samples within SLIVER_REACH_PX of a sliver triangle
    (§7: their visible face is undecided), with the sliver's nearest depth.
    A triangle through the near plane is a sliver where its front part is
    (a triangle whose plane nearly holds the eye): the polygon clipped to
    the near plane, as thin across as SLIVER_PX."""
    tri = geo.tri_view
    if len(tri) == 0:
        return []
    h, ahead, front, win, longest, altitude = _window_triangles(tri, proj, width, height)
    thin = np.flatnonzero(front & np.isfinite(win).all(axis=(1, 2)) & (altitude < SLIVER_PX) & (longest > 0))
    polygons = [(win[k], -tri[k, :, 2].max(), (h[k, :, 3], -tri[k, :, 2])) for k in thin]
    crossing = np.flatnonzero(ahead.any(axis=1) & ~ahead.all(axis=1) & np.isfinite(h).all(axis=(1, 2)))
    for k in crossing:  # few
        clipped = _near_clipped_polygon(tri[k], h[k], width, height)
        if clipped is None:
            continue
        points, depth = clipped
        if 0.0 < _polygon_width(points) < SLIVER_PX:
            polygons.append((points, depth, None))
    out = []
    evaluated = np.zeros(height, bool)
    evaluated[rows] = True
    for points, depth, plane in polygons:  # few, and each covers few pixels
        lo = np.floor(points.min(axis=0) - 1.0).astype(int)
        hi = np.ceil(points.max(axis=0) + 1.0).astype(int)
        xs = np.arange(max(lo[0], 0), min(hi[0], width))
        ys = np.arange(max(lo[1], 0), min(hi[1], height))
        ys = ys[evaluated[ys]]
        if len(xs) == 0 or len(ys) == 0:
            continue
        gx, gy = np.meshgrid(xs + 0.5, ys + 0.5)
        pts = np.stack([gx.ravel(), gy.ravel()], axis=1)
        n = len(points)
        dist = np.min(
            np.stack(
                [
                    _segment_distance(
                        pts, np.broadcast_to(points[i], pts.shape), np.broadcast_to(points[(i + 1) % n], pts.shape)
                    )[0]
                    for i in range(n)
                ]
            ),
            axis=0,
        )
        near = dist <= SLIVER_REACH_PX
        if near.any():
            pix = row_of[gy.ravel()[near].astype(int)] * width + gx.ravel()[near].astype(int)
            sample_depth = np.full(len(pix), depth)
            if plane is not None:
                sample_depth = np.minimum(sample_depth, _plane_depth_at(points, *plane, pts[near]))
            out.append((pix, sample_depth))
    return out


def _tip_slack(tri_view, proj, width, height) -> np.ndarray:
    """Per triangle, the barycentric slack that holds every centre ray
    passing within SNAP_REACH_PX (window) outside it: a sample at window
    distance d outside edge k lies d / altitude_k outside in window
    barycentrics, and the ray's barycentrics (on the triangle's plane,
    perspective-correct) differ from those by at most the ratio of its
    corners' clip w. 0 for a triangle not wholly in front of the near
    plane (_sliver_samples takes those)."""
    h, _ahead, front, _win, _longest, altitude = _window_triangles(tri_view, proj, width, height)
    slack = np.zeros(len(tri_view))
    with np.errstate(all="ignore"):
        spread = h[..., 3].max(axis=1) / h[..., 3].min(axis=1)
        wanted = 1.25 * SNAP_REACH_PX * spread / altitude
    use = front & np.isfinite(wanted)
    slack[use] = np.minimum(wanted[use], NEAR_MISS_BARYCENTRIC)
    return slack


def _tip_samples(tip_misses, face, depth, geo, proj, width, height, rows) -> np.ndarray:
    """Samples within SNAP_REACH_PX outside a triangle of another face
    than the visible one, whose plane there lies in front of the visible
    face or level with it (§7.2): the rasteriser's snapping may cover them
    with that triangle. The four probes 0.01 px off find such samples
    beside an edge; not beside a sharp tip, which can pass between them (a
    tip 0.004 px wide there, 0.0012 px from the sample, the first found)."""
    flagged = np.zeros(len(face), bool)
    if not tip_misses:
        return flagged
    pix, z, f, tri = (np.concatenate([m[k] for m in tip_misses]) for k in range(4))
    keep = (f != face[pix]) & (z <= depth[pix] * (1.0 + UNDECIDED_DEPTH))
    pix, tri = pix[keep], tri[keep]
    if len(pix) == 0:
        return flagged
    win = _window(proj, geo.tri_view[tri], width, height)  # (N, 3, 2)
    xy = np.stack([pix % width + 0.5, rows[pix // width] + 0.5], axis=1).astype(np.float64)
    distance = np.min([_segment_distance(xy, win[:, k], win[:, (k + 1) % 3])[0] for k in range(3)], axis=0)
    flagged[pix[distance <= SNAP_REACH_PX]] = True
    return flagged


def _plane_depth_at(corners, clip_w, depths, points) -> np.ndarray:
    """The view depth a rasteriser gives window ``points`` (N, 2) when it
    covers them with the triangle of window ``corners`` (3, 2), clip w
    ``clip_w`` and view depths ``depths``: its plane's, perspective-correct
    (depth / w and 1 / w are affine on screen), also at a point just
    outside it. Across a sliver's thin side that plane runs nearly along
    the rays, so a sample a snapping step outside it can take a depth far
    nearer than any of its corners (§7.2). -inf where the plane lies
    behind the eye along the sample's ray (nothing bounds the depth then)
    and the nearest corner's depth where the triangle has no window area."""
    a, b, c = corners
    area2 = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
    if area2 == 0.0:
        return np.full(len(points), depths.min())
    # Window barycentrics, extrapolated outside the triangle.
    wb = ((c[0] - b[0]) * (points[:, 1] - b[1]) - (c[1] - b[1]) * (points[:, 0] - b[0])) / area2
    wc = ((a[0] - c[0]) * (points[:, 1] - c[1]) - (a[1] - c[1]) * (points[:, 0] - c[0])) / area2
    weights = np.stack([wb, wc, 1.0 - wb - wc], axis=1)  # of corners a, b, c
    inverse_w = weights @ (1.0 / clip_w)
    depth_over_w = weights @ (depths / clip_w)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(inverse_w > 0.0, depth_over_w / inverse_w, -np.inf)


def _near_clipped_polygon(view, clip, width, height):
    """The window polygon (N, 2) of the part of a triangle (view-space
    corners ``view``, clip ``clip``) in front of the near plane, and its
    nearest view depth; None where nothing of it is."""
    ahead = clip[:, 2] + clip[:, 3]
    kept_clip, kept_view = [], []
    for i in range(3):
        j = (i + 1) % 3
        if ahead[i] >= 0:
            kept_clip.append(clip[i])
            kept_view.append(view[i])
        if (ahead[i] >= 0) != (ahead[j] >= 0):
            t = ahead[i] / (ahead[i] - ahead[j])  # (the projection is linear: one t for both)
            kept_clip.append(clip[i] + t * (clip[j] - clip[i]))
            kept_view.append(view[i] + t * (view[j] - view[i]))
    kept_clip, kept_view = np.array(kept_clip), np.array(kept_view)
    if len(kept_clip) < 3 or (kept_clip[:, 3] <= 0).any():
        return None
    points = (kept_clip[:, :2] / kept_clip[:, 3:4] + 1.0) * 0.5 * np.array([width, height])
    return points, float(-kept_view[:, 2].max())


def _polygon_width(points) -> float:
    """The smallest width of a convex polygon across: over its sides, the
    farthest corner from that side's line (0 where a side has no length)."""
    widths = []
    n = len(points)
    for i in range(n):
        edge = points[(i + 1) % n] - points[i]
        length = np.hypot(*edge)
        if length == 0.0:
            continue
        rel = points - points[i]
        widths.append(np.abs(edge[0] * rel[:, 1] - edge[1] * rel[:, 0]).max() / length)
    return min(widths) if widths else 0.0


# ---------------------------------------------------------------- distances


def _clip_edges_to_window(proj, edges_view, width, height):
    """Near-clip each edge and project its front part: (A, B, valid)."""
    xyz, w = _to_clip(proj, edges_view)  # (E,2,3), (E,2)
    front = xyz[..., 2] + w
    fa, fb = front[:, 0], front[:, 1]
    valid = (fa >= 0) | (fb >= 0)
    a, b = edges_view[:, 0], edges_view[:, 1]
    with np.errstate(divide="ignore", invalid="ignore"):
        ta = np.where(fa < 0, fa / (fa - fb), 0.0)
        tb = np.where(fb < 0, fb / (fb - fa), 0.0)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        # (edges wholly behind the near plane give NaN here; `valid` drops them)
        a_front = a + ta[:, None] * (b - a)
        b_front = b + tb[:, None] * (a - b)
        wa = _window(proj, a_front, width, height)
        wb = _window(proj, b_front, width, height)
    valid &= np.isfinite(wa).all(axis=1) & np.isfinite(wb).all(axis=1)
    return wa, wb, valid


def _segment_distance(p, a, b):
    ab = b - a
    len2 = np.einsum("ij,ij->i", ab, ab)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.clip(np.where(len2 > 0, np.einsum("ij,ij->i", p - a, ab) / len2, 0.0), 0.0, 1.0)
    closest = a + t[:, None] * ab
    return np.linalg.norm(p - closest, axis=1), t * np.sqrt(len2)


def profile(d, thickness, softness):
    """SPEC 1.4 intensity profile P(d)."""
    x = np.maximum(d - thickness / 2.0, 0.0) / softness
    return np.where(x < 2.0, np.exp2(-2.0 * x * x), 0.0)


def pattern_mask(t, period, duty):
    """Box-filtered (1 px) on/off mask along a diagonal, on for the first
    ``duty`` of every period measured from the diagonal's origin end."""

    def integral(x):
        cycles = np.floor(x / period)
        return cycles * duty * period + np.clip(x - cycles * period, 0.0, duty * period)

    return integral(t + 0.5) - integral(t - 0.5)


def _pixel_edge_pairs(pix_face, pix_xy, geo, wa, wb, valid, select):
    """Every (pixel, selected edge of the pixel's own face) pair with the
    distance, the position along the edge from its pattern origin
    (unclamped) and how far the engine's float32 may put that position
    (_phase_error): (pair_pix, pair_edge, d, along, phase_error)."""
    n = len(pix_face)
    idx = np.nonzero(select & valid)[0]
    empty = np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0), np.zeros(0), np.zeros(0)
    if len(idx) == 0 or n == 0:
        return empty
    order = idx[np.argsort(geo.edge_face[idx], kind="stable")]
    faces_sorted = geo.edge_face[order]
    lo = np.searchsorted(faces_sorted, pix_face, side="left")
    hi = np.searchsorted(faces_sorted, pix_face, side="right")
    count = hi - lo
    pair_pix = np.repeat(np.arange(n), count)
    pair_edge = order[np.repeat(lo, count) + (np.arange(count.sum()) - np.repeat(np.cumsum(count) - count, count))]
    if len(pair_pix) == 0:
        return empty
    # Pattern origin: endpoint 0 when edge_origin_first, else endpoint 1.
    first = geo.edge_origin_first[pair_edge]
    a = np.where(first[:, None], wa[pair_edge], wb[pair_edge])
    b = np.where(first[:, None], wb[pair_edge], wa[pair_edge])
    d, _ = _segment_distance(pix_xy[pair_pix], a, b)
    ab = b - a
    len_ab = np.linalg.norm(ab, axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        along = np.where(len_ab > 0, np.einsum("ij,ij->i", pix_xy[pair_pix] - a, ab) / len_ab, 0.0)
    return pair_pix, pair_edge, d, along, _phase_error(pix_xy[pair_pix], a, b, len_ab)


# A dash phase that the engine's float32 may put farther off than this (px)
# is undecided (§7.2): the mask moves with it, up to 1 per px.
PHASE_TOLERANCE_PX = 4e-3
# The error of a window position in float32, relative to its size (a few
# units in the last place).
WINDOW_ROUNDING = 2.0**-21


def _phase_error(p, a, b, len_ab):
    """How far float32 may put the position of window point p along a -> b
    from a: the ends' own rounding (in proportion to how far from the
    window's origin they lie), plus the direction's, which p's distance from
    a multiplies and the segment's length divides."""
    scale = np.maximum(np.maximum(np.abs(a).max(axis=1), np.abs(b).max(axis=1)), np.abs(p).max(axis=1))
    with np.errstate(divide="ignore", invalid="ignore"):
        return WINDOW_ROUNDING * scale * (1.0 + 2.0 * np.linalg.norm(p - a, axis=1) / len_ab)


# Two lines whose distances to a sample differ by less than this (px) are
# tied: beyond the shared end of two segments of a chain every sample is as
# far from one as from the other, and a dash pattern's phase there depends
# on which one is taken.
TIE_PX = 1e-3


def _min_distance_per_pixel(
    pix_face, pix_xy, geo, wa, wb, valid, select, want_along=False, want_index=False, ties=None
):
    """For every pixel: min distance to the selected edges of its own face
    (edge_face == pix_face; for lines, pass the faces' block keys). With a
    dict as ``ties``, ties["tied"] marks pixels whose nearest line is tied
    (TIE_PX) with another one measured from a different position."""
    n = len(pix_face)
    best = np.full(n, np.inf)
    best_along = np.zeros(n)
    best_index = np.full(n, -1)
    if ties is not None:
        ties["tied"] = np.zeros(n, bool)
    pair_pix, pair_edge, d, along, phase_error = _pixel_edge_pairs(pix_face, pix_xy, geo, wa, wb, valid, select)
    if len(pair_pix):
        order2 = np.lexsort((d, pair_pix))
        pair_pix, d, along, pair_edge = pair_pix[order2], d[order2], along[order2], pair_edge[order2]
        phase_error = phase_error[order2]
        keep = np.ones(len(pair_pix), bool)
        keep[1:] = pair_pix[1:] != pair_pix[:-1]
        best[pair_pix[keep]] = d[keep]
        best_along[pair_pix[keep]] = along[keep]
        best_index[pair_pix[keep]] = pair_edge[keep]
        if ties is not None:
            ties["tied"][pair_pix[keep & (phase_error > PHASE_TOLERANCE_PX)]] = True
            runner_up = np.flatnonzero(~keep)  # a second (or later) line of the same pixel
            runner_up = runner_up[keep[runner_up - 1]]  # the second one only
            tied = (d[runner_up] - d[runner_up - 1] <= TIE_PX) & (
                np.abs(np.abs(along[runner_up]) - np.abs(along[runner_up - 1])) > TIE_PX
            )
            ties["tied"][pair_pix[runner_up[tied]]] = True
    return (best, best_along, best_index) if want_index else (best, best_along)


def _max_value_per_pixel(pix_face, pix_xy, geo, wa, wb, valid, select, value_of, far_phase=None, mask_of=None):
    """For every pixel: the largest value_of(pair_pix, pair_edge, d) times
    mask_of(along) (a dash pattern; none: 1) over the selected edges of its
    own face (0 without any). With a bool array as ``far_phase``, it marks
    the pixels a line reaches (value_of above 0, whatever its dashes) where
    its dash phase is undecided (PHASE_TOLERANCE_PX): a pixel in a gap
    between dashes is undecided too where the phase may move a dash onto it."""
    best = np.zeros(len(pix_face))
    pair_pix, pair_edge, d, along, phase_error = _pixel_edge_pairs(pix_face, pix_xy, geo, wa, wb, valid, select)
    if len(pair_pix):
        values = value_of(pair_pix, pair_edge, d)
        reaches = values > 0.0
        if mask_of is not None:
            values = values * mask_of(along)
        np.maximum.at(best, pair_pix, values)
        if far_phase is not None:
            far_phase[pair_pix[reaches & (phase_error > PHASE_TOLERANCE_PX)]] = True
    return best


def _dashes(far_phase, period, duty):
    """(far_phase, mask_of) for _max_value_per_pixel: a line of ``duty``
    below 1 is dashed (pattern_mask along it) and marks its undecided
    phases in ``far_phase``; a solid one neither."""
    if duty >= 1.0:
        return None, None
    return far_phase, lambda along: pattern_mask(np.abs(along), period, duty)


def _line_intensity(s, geo, pix_face, pix_xy, wa, wb, valid, proj, width, height, thickness, softness):
    """(I, d_real, winning style, density(entry index), tied, runner-up)
    per covered sample: the nearest line of each style in the sample's
    block, each style's P(d) times its pattern and density fade, the
    largest taken (§3.6-§3.7); ``runner-up`` the largest of another style."""
    keys = geo.face_key[pix_face]
    chain_a, chain_b, chain_ok = _clip_edges_to_window(proj, geo.chain_view, width, height)
    chain_length = np.where(chain_ok, np.linalg.norm(np.nan_to_num(chain_b - chain_a), axis=1), np.inf)
    full = float(getattr(s, "density_fade_length", 0.0))
    use_density = bool(getattr(s, "use_density_fade", False)) and full > 0.0

    def density(index):
        if not use_density:
            return np.ones(len(index))
        length = np.where(index >= 0, chain_length[np.maximum(index, 0)], np.inf)
        return np.clip(2.0 * length / full - 1.0, 0.0, 1.0)

    value = np.zeros(len(pix_face))
    d_real = np.full(len(pix_face), np.inf)
    winner = np.zeros(len(pix_face), np.int64)
    tied = np.zeros(len(pix_face), bool)  # a patterned line's phase is undecided
    runner_up = np.zeros(len(pix_face))
    for style in range(len(EDGE_CLASSES) + 1):
        select = geo.edge_real & (geo.edge_style == style)
        if not select.any():
            continue
        name = EDGE_CLASSES[style - 1] if style else None
        pattern = getattr(s, f"{name}_pattern") if name else "SOLID"
        style_ties = {}
        d, _along, _index = _min_distance_per_pixel(
            keys, pix_xy, geo, wa, wb, valid, select, want_along=False, want_index=True, ties=style_ties
        )
        d_real = np.minimum(d_real, d)
        width_px = _class_width(s, name, thickness) if name else thickness
        duty = PATTERN_DUTY[pattern]
        if use_density or duty < 1.0:
            # The style's intensity is its strongest line (§3.6-§3.7), not
            # its nearest line's: each line fades on its own, and each
            # edge's pattern runs along that edge.
            def faded(pair_pix, pair_edge, d_pair, width_px=width_px):
                w = width_px if np.isscalar(width_px) else width_px[pair_pix]
                return profile(d_pair, w, softness) * density(pair_edge)

            v = _max_value_per_pixel(
                keys, pix_xy, geo, wa, wb, valid, select, faded, *_dashes(tied, float(s.pattern_period), duty)
            )
        else:
            v = profile(d, width_px, softness)
        runner_up = np.maximum(runner_up, np.minimum(value, v))
        wins = v > value
        winner[wins] = style
        value = np.maximum(value, v)
    return value, d_real, winner, density, tied, runner_up


def _class_width(s, name, wire_width):
    """A class's core width where the wire's is ``wire_width`` (image model
    §3.6): its Thickness scaled as the wire's width is scaled from the
    scene's Thickness (object override, thickness mode); its Thickness
    itself where the scene's Thickness is 0."""
    own, scene_width = float(getattr(s, f"{name}_thickness")), float(s.thickness)
    if scene_width <= 0.0:
        return own
    return own * np.asarray(wire_width, np.float64) / scene_width


def _thickness_at(s, z, proj, height, override=None):
    """Core width T at view depth z for the thickness mode (image model
    §4.2). ``override`` (same shape as z, NaN: none) is the object's own
    Thickness, used in place of the scene's (PIXELS and DEPTH's near width)."""
    mode = getattr(s, "thickness_mode", "PIXELS")
    near = float(s.thickness)
    if override is not None:
        near = np.where(np.isnan(override), near, override)
    if mode == "WORLD":
        clip_w = proj[3, 2] * (-z) + proj[3, 3]  # z for perspective, 1 for orthographic
        return float(s.world_thickness) * 0.5 * height * abs(proj[1, 1]) / clip_w
    if mode == "DEPTH":
        start, end = float(s.thickness_depth_start), float(s.thickness_depth_end)
        if end > start:
            t = np.clip((z - start) / (end - start), 0.0, 1.0)
        else:
            t = (z > start).astype(np.float64)
        return near + t * (float(s.thickness_far) - near)
    return np.broadcast_to(near, np.shape(z)).astype(np.float64)


def _eye(proj):
    """Homogeneous view-space camera centre: the null vector of the x, y and
    w rows of the projection ((0,0,0,1) perspective, (0,0,1,0) orthographic)."""
    _u, _s, vt = np.linalg.svd(proj[[0, 1, 3]])
    return vt[-1]


# Image model §7.2: a silhouette side sigma (§5.5) whose window
# orientation lies within this share of its float32 slack (the window
# coordinates' size times the triangle's two sides there) is one float32
# cannot tell from 0: a face that edge-on, or a triangle whose corners lie
# on one line, is a silhouette or not by rounding's sign.
SIDE_TOLERANCE = 2.0**-20
SIDE_REACH_PX = 0.01


def _outer_half(s, geo, proj, width, height, rows, depth):
    """Outer-half intensity per pixel of ``rows`` (image model §5.5; see
    solidwire_addon/core/silhouettes.py): max over silhouette edges whose outer
    side holds the sample and whose nearest point q is not behind the
    visible surface there, of P(d) * fade with thickness and fade at q;
    and the pixels an undecided edge's outer half could reach (image model
    §7.2: a side sigma that float32 cannot tell from 0, such as a
    triangle's third corner on its edge's line, decides by rounding whether
    the edge is a silhouette at all); and the view depth of the nearest q
    whose outer half would reach the sample but lies behind the visible
    surface there (+inf: none), for the overlay's depth bias (§5.6)."""
    out = np.zeros(len(rows) * width)
    unsure = np.zeros(len(rows) * width, bool)
    hidden_at = np.full(len(rows) * width, np.inf)
    if geo.sil_edges is None or len(geo.sil_edges) == 0:
        return out, unsure, hidden_at
    eye = _eye(proj)
    a, b = geo.sil_edges[:, 0], geo.sil_edges[:, 1]
    ones = np.ones((len(a), 1))

    def side(o):
        m = np.stack(
            [np.hstack([a, ones]), np.hstack([b, ones]), np.hstack([o, ones]), np.tile(eye, (len(a), 1))], axis=1
        )
        # Two equal rows make it exactly 0, which LU's rounding need not
        # give: a third corner at one of the edge's ends (a face folded
        # onto the edge), or an edge whose ends coincide.
        equal_rows = (o == a).all(axis=1) | (o == b).all(axis=1) | (a == b).all(axis=1)
        value = np.where(equal_rows, 0.0, np.linalg.det(m))
        # What float32 resolves of it: the engine takes sigma's sign from
        # the orientation of the window points (line_side in
        # shaders/silhouette_vert.glsl), cross2(b - a, o - a), which the
        # rounding of window coordinates of size M moves by about
        # 2^-23 M (|b - a| + |o - a|).
        with np.errstate(all="ignore"):  # (a point on the eye's plane: unsure)
            # (x / w, y / w also behind the eye, as the engine divides)
            pa, pb, po = (_window(proj, p, width, height) for p in (a, b, o))
            ab, ao = pb - pa, po - pa
            orientation = ab[:, 0] * ao[:, 1] - ab[:, 1] * ao[:, 0]
            size = np.abs(np.stack([pa, pb, po])).max(axis=(0, 2))
            slack = SIDE_TOLERANCE * size * (np.hypot(*ab.T) + np.hypot(*ao.T))
            unsure = ~equal_rows & ~(np.abs(orientation) > slack)
        return value, unsure

    side_f, unsure_f = side(geo.sil_third[:, 0])
    boundary = ~np.isfinite(geo.sil_third[:, 1]).all(axis=1)
    side_g, unsure_g = side(np.nan_to_num(geo.sil_third[:, 1]))
    side_g = np.where(boundary, 0.0, side_g)
    silhouette = (boundary | (side_f * side_g > 0)) & (side_f != 0)
    undecided = unsure_f | (~boundary & unsure_g)
    drawn = silhouette | undecided
    a, b, third, undecided = a[drawn], b[drawn], geo.sil_third[drawn, 0], undecided[drawn]
    wa, wb, valid = _clip_edges_to_window(proj, np.stack([a, b], axis=1), width, height)
    a, b, third, wa, wb, undecided = a[valid], b[valid], third[valid], wa[valid], wb[valid], undecided[valid]
    if len(a) == 0:
        return out, unsure, hidden_at
    # Clipped 3D endpoints (for q's depth) and their clip w.
    xyz, w = _to_clip(proj, np.stack([a, b], axis=1))
    fa, fb = xyz[:, 0, 2] + w[:, 0], xyz[:, 1, 2] + w[:, 1]
    with np.errstate(divide="ignore", invalid="ignore"):  # (the branch not taken where fa == fb)
        ta = np.where(fa < 0, fa / (fa - fb), 0.0)
        tb = np.where(fb < 0, fb / (fb - fa), 0.0)
    a3 = a + ta[:, None] * (b - a)
    b3 = b + tb[:, None] * (a - b)
    _x, wa_clip = _to_clip(proj, a3)
    _x, wb_clip = _to_clip(proj, b3)
    # Interior side: a point just inside the face from the segment's middle.
    mid = 0.5 * (a3 + b3)
    inner = _window(proj, mid + 1e-6 * (third - mid), width, height)
    ab = wb - wa
    inner_side = np.sign(ab[:, 0] * (inner[:, 1] - wa[:, 1]) - ab[:, 1] * (inner[:, 0] - wa[:, 0]))

    softness = float(s.softness)
    z_ends = -np.stack([a3[:, 2], b3[:, 2]], axis=1)
    t_max = np.max(_thickness_at(s, z_ends.ravel(), proj, height).reshape(-1, 2), axis=1)
    reach = 0.5 * t_max + 2.0 * softness + 1.0
    # A segment too short for float32 to fix its direction to 0.01 px over
    # its reach (its ends' window coordinates carry about 2^-22 of their
    # size): which side of it a sample lies on is rounding's choice.
    size = np.maximum(np.abs(wa).max(axis=1), np.abs(wb).max(axis=1))
    undecided |= np.hypot(*(wb - wa).T) * SIDE_REACH_PX < reach * size * 2.0**-22
    x0 = np.clip(np.floor(np.minimum(wa[:, 0], wb[:, 0]) - reach), 0, width).astype(np.int64)
    x1 = np.clip(np.ceil(np.maximum(wa[:, 0], wb[:, 0]) + reach), -1, width - 1).astype(np.int64)
    y0 = np.clip(np.floor(np.minimum(wa[:, 1], wb[:, 1]) - reach), 0, height).astype(np.int64)
    y1 = np.clip(np.ceil(np.maximum(wa[:, 1], wb[:, 1]) + reach), -1, height - 1).astype(np.int64)
    row_of = np.full(height, -1, np.int64)
    row_of[rows] = np.arange(len(rows))
    for e in range(len(a)):  # few silhouette edges in reference scenes
        if x1[e] < x0[e] or y1[e] < y0[e]:
            continue
        ys = np.arange(y0[e], y1[e] + 1)
        ys = ys[row_of[ys] >= 0]
        if len(ys) == 0:
            continue
        xs = np.arange(x0[e], x1[e] + 1)
        px, py = np.meshgrid(xs + 0.5, ys + 0.5)
        px, py = px.ravel(), py.ravel()
        pixel = row_of[(py - 0.5).astype(np.int64)] * width + (px - 0.5).astype(np.int64)
        rel = np.stack([px - wa[e, 0], py - wa[e, 1]], axis=1)
        cross = ab[e, 0] * rel[:, 1] - ab[e, 1] * rel[:, 0]
        outer = cross * inner_side[e] <= 0
        len2 = ab[e] @ ab[e]
        sp = np.clip(rel @ ab[e] / len2, 0.0, 1.0) if len2 > 0 else np.zeros(len(px))
        d = np.linalg.norm(rel - sp[:, None] * ab[e], axis=1)
        if undecided[e]:
            unsure[pixel[d <= reach[e]]] = True
            continue
        u = sp * wa_clip[e] / (sp * wa_clip[e] + (1.0 - sp) * wb_clip[e])
        zq = -(a3[e, 2] + u * (b3[e, 2] - a3[e, 2]))
        seen = depth[pixel] >= zq
        value = profile(d, _thickness_at(s, zq, proj, height), softness) * _fade(s, zq)
        hidden = outer & ~seen & (value > 0.0)
        np.minimum.at(hidden_at, pixel[hidden], zq[hidden])
        value = np.where(outer & seen, value, 0.0)
        np.maximum.at(out, pixel, value)
    return out, unsure, hidden_at


def _fade(s, z):
    if not s.use_fade:
        return np.ones_like(z)
    fs, fe = float(s.fade_start), float(s.fade_end)
    if fe > fs:
        return np.clip((fe - z) / (fe - fs), 0.0, 1.0)
    return (z <= fs).astype(np.float64)


def _hidden_edge_samples(all_hits, face, depth, rows, width, height, geo, proj, near_misses=()) -> np.ndarray:
    """Samples within 0.01 px of an edge of a triangle behind the visible
    surface, hit or just missed, or of a sliver there (§7: whether the
    rasteriser covers them is undecided — at a fold seen edge-on, two
    triangles meet within 1e-4 px of the sample, on either side of it)."""
    flagged = np.zeros(len(face), bool)
    # A sliver behind the visible surface: rays 0.01 px apart step over it,
    # and one whose plane nearly holds the ray has no near miss to measure.
    row_of = np.full(height, -1, np.int64)
    row_of[rows] = np.arange(len(rows))
    for pix, _depth in _sliver_samples(geo, proj, width, height, rows, row_of):
        flagged[pix[face[pix] >= 0]] = True
    found = list(all_hits or ()) + list(near_misses or ())
    if not found:
        return flagged
    pix = np.concatenate([h[0] for h in found])
    z = np.concatenate([h[1] for h in found])
    f = np.concatenate([h[2] for h in found])
    tri = np.concatenate([h[3] for h in found])
    behind = (face[pix] >= 0) & (f != face[pix]) & (z > depth[pix])
    pix, tri = pix[behind], tri[behind]
    if len(pix) == 0:
        return flagged
    corners = geo.tri_view[tri]
    h = np.concatenate([corners, np.ones(corners.shape[:2] + (1,))], axis=2) @ proj.T
    front = ((h[..., 2] + h[..., 3]) >= 0).all(axis=1) & (h[..., 3] > 0).all(axis=1)
    with np.errstate(all="ignore"):
        win = (h[..., :2] / h[..., 3:4] + 1.0) * 0.5 * np.array([width, height])
    xy = np.stack([pix % width + 0.5, rows[pix // width] + 0.5], axis=1).astype(np.float64)
    near = np.zeros(len(pix), bool)
    for k in range(3):
        d, _ = _segment_distance(xy, win[:, k], win[:, (k + 1) % 3])
        near |= d <= 0.01
    flagged[pix[near & front]] = True
    # A triangle across the near plane: the sides of its part in front,
    # the cut along the near plane among them, as the rasteriser clips it.
    for triangle in np.unique(tri[~front]):
        at = np.flatnonzero((tri == triangle) & ~front)
        clipped = _near_clipped_polygon(geo.tri_view[triangle], h[at[0]], width, height)
        if clipped is None:
            continue
        points = clipped[0]
        for k in range(len(points)):
            ends = (
                np.broadcast_to(points[k], (len(at), 2)),
                np.broadcast_to(points[(k + 1) % len(points)], (len(at), 2)),
            )
            d, _ = _segment_distance(xy[at], *ends)
            flagged[pix[at[d <= 0.01]]] = True
    return flagged


# How near the two strongest lines of different styles may lie in intensity
# for float32 to pick either one's colour (§3.6): the profile is flat where
# a line reaches full strength, so two wide lines there differ by far less.
STYLE_TIE = 1e-4

# How near two triangles of one face lie, relative to their depth, for the
# engine to count them as one hidden layer (LEVEL_DEPTH in
# shaders/quad_partner.glsl).
LEVEL_DEPTH = 1e-5


def _hidden_line_coverage(
    s, all_hits, face, depth, rows, width, geo, wa, wb, valid, proj, height, wire_alpha, undecided=None
):
    """Alpha of the hidden-line layer per pixel (image model §5.4): every
    face hit behind the visible surface contributes
    a_k = wire_alpha * hidden_alpha * P(d_real) * dash(t) * fade(z_k), with
    t measured along its nearest real edge from that edge's lower-id end;
    layers combine as 1 - prod(1 - a_k)."""
    coverage = np.zeros(len(face))
    if not all_hits:
        return coverage
    pix = np.concatenate([h[0] for h in all_hits])
    z = np.concatenate([h[1] for h in all_hits])
    f = np.concatenate([h[2] for h in all_hits])
    behind = (face[pix] >= 0) & (f != face[pix]) & (z > depth[pix])
    pix, z, f = pix[behind], z[behind], f[behind]
    # One hit per (pixel, face, depth): a face's two triangles may both
    # report a sample that lies on their shared diagonal (the same depth);
    # a folded face whose two triangles both lie behind the sample at
    # different depths is two layers, as the rasteriser draws it.
    order = np.lexsort((z, f, pix))
    pix, z, f = pix[order], z[order], f[order]
    first = np.ones(len(pix), bool)
    gap = np.abs(z[1:] - z[:-1]) / np.maximum(np.abs(z[1:]), 1e-30)
    same_face = (pix[1:] == pix[:-1]) & (f[1:] == f[:-1])
    first[1:] = ~same_face | (gap > 1e-6)
    if undecided is not None:
        # The engine counts two triangles of a face as one layer within
        # LEVEL_DEPTH of each other (its float32 depths of them cannot be
        # ordered more finely): between the two counts, undecided (§7.2).
        undecided[pix[1:][same_face & (gap > 1e-6) & (gap <= 2.0 * LEVEL_DEPTH)]] = True
    pix, z, f = pix[first], z[first], f[first]
    if len(pix) == 0:
        return coverage
    if undecided is not None:
        # Two faces behind the sample at one depth (within a relative 1e-6:
        # faces on one another, or crossing there): float32 depths cannot
        # order them, and whether the engine finds one layer or two is
        # rounding's choice (§7.2).
        by_depth = np.lexsort((z, pix))
        p, zz, ff = pix[by_depth], z[by_depth], f[by_depth]
        level = (p[1:] == p[:-1]) & (ff[1:] != ff[:-1])
        level &= np.abs(zz[1:] - zz[:-1]) <= 1e-6 * np.maximum(np.abs(zz[1:]), 1e-30)
        undecided[p[1:][level]] = True
    xy = np.stack([pix % width + 0.5, rows[pix // width] + 0.5], axis=1).astype(np.float64)
    hidden_ties = {}
    d, along = _min_distance_per_pixel(
        geo.face_key[f], xy, geo, wa, wb, valid, geo.edge_real, want_along=True, ties=hidden_ties
    )
    if undecided is not None:
        undecided[pix[hidden_ties["tied"]]] = True
    a = profile(d, _thickness_at(s, z, proj, height, geo.face_thickness[f]), float(s.softness))
    a *= float(s.hidden_alpha) * pattern_mask(np.abs(along), float(s.hidden_period), float(s.hidden_duty))
    a *= _fade(s, z) * wire_alpha
    transmit = np.ones(len(face))
    np.multiply.at(transmit, pix, 1.0 - a)
    return 1.0 - transmit


# ---------------------------------------------------------------- entry point


def render_reference(scene, depsgraph=None, size=None, rows=None, settings=None, depth_layers=False) -> ReferenceResult:
    """Evaluate SPEC section 1 in float64 for ``scene``'s camera.

    ``size`` overrides the render size (the camera projection is computed for
    it); ``rows`` restricts evaluation to some window rows (bottom = 0).
    ``settings`` defaults to ``scene.solidwire``. ``depth_layers``: report
    ``next_depth`` also with hidden lines off."""
    if depsgraph is None:
        depsgraph = bpy.context.evaluated_depsgraph_get()
    s = settings if settings is not None else scene.solidwire
    if size is None:
        pct = scene.render.resolution_percentage / 100.0
        size = (max(int(scene.render.resolution_x * pct), 1), max(int(scene.render.resolution_y * pct), 1))
    width, height = size
    rows = np.arange(height) if rows is None else np.sort(np.asarray(rows, dtype=np.int64))

    view_matrix, proj = _camera(scene, depsgraph, width, height)
    geo = _gather_geometry(depsgraph, view_matrix, s)
    hidden_lines = bool(getattr(s, "use_hidden_lines", False))
    all_hits = [] if hidden_lines or depth_layers else None
    near_misses = [] if hidden_lines else None
    centre_hit = {}
    faces, depths = _visibility(
        geo, proj, width, height, rows, bool(s.use_backface_culling), all_hits, centre_hit, near_misses
    )

    face = faces[0]
    depth = depths[0]
    on_silhouette = (faces[1:] != face[None, :]).any(axis=0) | centre_hit["undecided"]

    intensity = np.zeros(len(face))
    hidden_outer_depth = np.full(len(face), np.inf)
    winner_all = np.zeros(len(face), np.int64)  # the line style each sample takes (§3.6)
    style_undecided = np.zeros(len(face), bool)
    hidden_all = np.zeros(len(face))
    d_real_all = np.full(len(face), np.inf)
    covered = np.nonzero(face >= 0)[0]
    if len(covered):
        pix_xy = np.stack([covered % width + 0.5, rows[covered // width] + 0.5], axis=1).astype(np.float64)
        pix_face = face[covered]
        wa, wb, valid = _clip_edges_to_window(proj, geo.edges_view, width, height)
        softness = float(s.softness)
        thickness = _thickness_at(s, depth[covered], proj, height, geo.face_thickness[pix_face])
        value, d_real, winner, density, tied, runner_up = _line_intensity(
            s, geo, pix_face, pix_xy, wa, wb, valid, proj, width, height, thickness, softness
        )
        on_silhouette[covered[tied]] = True
        d_real_all[covered] = d_real
        winner_all[covered] = winner
        mode = s.diagonal_mode
        if mode != "HIDDEN":
            diag_ties = {}
            diagonals = (pix_face, pix_xy, geo, wa, wb, valid, ~geo.edge_real)
            d_diag, along, _index = _min_distance_per_pixel(
                *diagonals,
                want_along=(mode in ("DOTTED", "DASHED")),
                want_index=True,
                ties=diag_ties,
            )
            if mode in ("DOTTED", "DASHED"):
                on_silhouette[covered[diag_ties["tied"]]] = True
            diag_value = profile(d_diag, thickness, softness)
            if mode in ("DOTTED", "DASHED"):
                diag_value *= pattern_mask(np.abs(along), float(s.pattern_period), float(s.pattern_duty))
            if getattr(s, "use_density_fade", False) and float(getattr(s, "density_fade_length", 0.0)) > 0.0:
                duty = float(s.pattern_duty) if mode in ("DOTTED", "DASHED") else 1.0

                def faded(pair_pix, pair_edge, d_pair):
                    w = thickness if np.isscalar(thickness) else thickness[pair_pix]
                    return profile(d_pair, w, softness) * density(pair_edge)

                far = np.zeros(len(pix_face), bool)
                diag_value = _max_value_per_pixel(*diagonals, faded, *_dashes(far, float(s.pattern_period), duty))
                on_silhouette[covered[far]] = True
            runner_up = np.where(
                winner_all[covered] > 0, np.maximum(runner_up, np.minimum(value, diag_value)), runner_up
            )
            wins = diag_value > value
            winner_all[covered[wins]] = 0
            value = np.maximum(value, diag_value)
        style_undecided[covered] = (runner_up > 0.0) & (value - runner_up <= STYLE_TIE)
        value *= _fade(s, depth[covered])
        if hidden_lines:
            wire_alpha = float(s.wire_color[3])
            hidden = _hidden_line_coverage(
                s,
                all_hits,
                face,
                depth,
                rows,
                width,
                geo,
                wa,
                wb,
                valid,
                proj,
                height,
                wire_alpha,
                undecided=on_silhouette,
            )
            on_silhouette |= _hidden_edge_samples(all_hits, face, depth, rows, width, height, geo, proj, near_misses)
            hidden_all = hidden
            # The visible wire over the hidden lines ("over" with one colour),
            # expressed as an intensity relative to the wire alpha.
            a_vis = value * wire_alpha
            value = (a_vis + (1.0 - a_vis) * hidden[covered]) / max(wire_alpha, 1e-12)
        intensity[covered] = value

    if getattr(s, "use_silhouettes", False):
        wire_alpha = float(s.wire_color[3])
        a_out, unsure, hidden_outer_depth = _outer_half(s, geo, proj, width, height, rows, depth)
        a_out *= wire_alpha
        on_silhouette |= unsure
        a_base = intensity * wire_alpha
        intensity = (a_out + (1.0 - a_out) * a_base) / max(wire_alpha, 1e-12)

    fill, wire = _colors(s, geo, face, centre_hit)
    per_triangle_colour = getattr(s, "use_fill", False) and (
        getattr(s, "fill_shading", "FLAT") != "FLAT" or getattr(s, "fill_color_source", "SINGLE") == "ATTRIBUTE"
    )
    for k, name in enumerate(EDGE_CLASSES):
        styled = winner_all == k + 1
        if styled.any():
            wire[styled] = np.array(getattr(s, f"{name}_color")[:3], np.float64)
    shape = (len(rows), width)
    return ReferenceResult(
        intensity.reshape(shape),
        on_silhouette.reshape(shape),
        face.reshape(shape),
        depth.reshape(shape),
        rows,
        fill.reshape(*shape, 3),
        wire.reshape(*shape, 3),
        d_real_all.reshape(shape),
        np.where(face >= 0, geo.face_object[np.maximum(face, 0)] if len(geo.face_object) else -1, -1).reshape(shape),
        geo.objects,
        geo.offsets,
        hidden_all.reshape(shape),
        *(() if all_hits is None else (layer.reshape(shape) for layer in _depth_layers(all_hits, depth))),
        hidden_outer_depth=hidden_outer_depth.reshape(shape),
        shading_undecided=centre_hit["shading_undecided"].reshape(shape) if per_triangle_colour else None,
        style_undecided=style_undecided.reshape(shape),
    )


def _depth_layers(all_hits, depth) -> tuple:
    """Per sample, the view depth of the nearest hit behind the visible
    surface (+inf: none) and how many hits lie level with that surface
    (within a relative 1e-6; two triangles of a face meet there only on
    their shared diagonal, which a sample centre hardly ever hits, so more
    than one is triangles lying on one another)."""
    behind = np.full(len(depth), np.inf)
    level = np.zeros(len(depth), np.int64)
    if all_hits:
        pix = np.concatenate([h[0] for h in all_hits])
        z = np.concatenate([h[1] for h in all_hits])
        apart = np.abs(z - depth[pix]) > 1e-6 * np.abs(depth[pix])
        keep = apart & (z > depth[pix])
        np.minimum.at(behind, pix[keep], z[keep])
        np.add.at(level, pix[~apart], 1)
    return behind, level


# ---------------------------------------------------------------- fill shading

# STUDIO (image model §5.8): ambient + Lambert lights fixed to the camera
# (view space: x right, y up, +z towards the viewer): (direction, power).
STUDIO_AMBIENT = 0.25
STUDIO_LIGHTS = (((-0.35, 0.55, 0.75), 0.6), ((0.6, 0.1, 0.8), 0.2), ((0.0, 0.8, -0.6), 0.15))


def studio_light(n):
    light = np.full(n.shape[:-1], STUDIO_AMBIENT)
    for direction, power in STUDIO_LIGHTS:
        d = np.array(direction) / np.linalg.norm(direction)
        light += power * np.maximum(n @ d, 0.0)
    return light


def load_matcap(name):
    """Blender's bundled matcap ``name``: (diffuse, specular), each (H, W, 3)
    float64 bottom row first (specular zeros when the file has none).

    Multilayer matcaps come through Blender's compositor
    (blender/matcap_files.py): the pixels are Blender's decoding of the file,
    which nothing else here can read (DWAA-compressed EXR)."""
    from solidwire_addon.blender import matcap_files

    diffuse, specular = matcap_files.load_pixels(name)
    diffuse = diffuse[..., :3].astype(np.float64)
    specular = np.zeros_like(diffuse) if specular is None else specular[..., :3].astype(np.float64)
    return diffuse, specular


def matcap_bilinear(image, uv):
    """Bilinear between texel centres ((i + 1/2) / size), clamped at the border."""
    h, w = image.shape[:2]
    x = uv[:, 0] * w - 0.5
    y = uv[:, 1] * h - 0.5
    x0, y0 = np.floor(x), np.floor(y)
    tx, ty = (x - x0)[:, None], (y - y0)[:, None]
    i0 = np.clip(x0.astype(np.int64), 0, w - 1)
    i1 = np.clip(x0.astype(np.int64) + 1, 0, w - 1)
    j0 = np.clip(y0.astype(np.int64), 0, h - 1)
    j1 = np.clip(y0.astype(np.int64) + 1, 0, h - 1)
    top = image[j1, i0] * (1 - tx) + image[j1, i1] * tx
    bottom = image[j0, i0] * (1 - tx) + image[j0, i1] * tx
    return bottom * (1 - ty) + top * ty


def _colors(s, geo, face, centre_hit):
    """(fill, wire) per sample (N, 3): §5.8's shaded fill and wire colour."""
    fill = np.full((len(face), 3), np.nan)
    wire = np.full((len(face), 3), np.nan)
    covered = face >= 0
    if not covered.any() or geo.face_fill is None or len(geo.face_fill) == 0:
        return fill, wire
    f = face[covered]
    base = geo.face_fill[f]
    wire[covered] = geo.face_wire[f]
    tri = centre_hit["tri"][covered]
    u, v = centre_hit["u"][covered][:, None], centre_hit["v"][covered][:, None]
    if getattr(s, "use_fill", False) and getattr(s, "fill_color_source", "SINGLE") == "ATTRIBUTE":
        # The colour attribute interpolated at the hit (barycentrics of the
        # ray's hit: perspective-correct); Fill Color without an attribute.
        corners = geo.tri_colors[tri]
        attribute = (1 - u - v) * corners[:, 0] + u * corners[:, 1] + v * corners[:, 2]
        base = np.where(np.isnan(attribute), base, attribute)
    shading = getattr(s, "fill_shading", "FLAT") if getattr(s, "use_fill", False) else "FLAT"
    if shading == "FLAT":
        fill[covered] = base
        return fill, wire
    corners = geo.tri_normals[tri]
    n = (1 - u - v) * corners[:, 0] + u * corners[:, 1] + v * corners[:, 2]
    length = np.linalg.norm(n, axis=1, keepdims=True)
    n = np.where(length > 1e-20, n / np.where(length > 0, length, 1.0), np.array([0.0, 0.0, 1.0]))
    n = np.where(centre_hit["front"][covered][:, None], n, -n)  # the side that is seen
    if shading == "STUDIO":
        fill[covered] = base * studio_light(n)[:, None]
    else:
        diffuse, specular = load_matcap(s.matcap)
        uv = n[:, :2] * 0.5 + 0.5
        fill[covered] = base * matcap_bilinear(diffuse, uv) + matcap_bilinear(specular, uv)
    return fill, wire


def error_report(measured: np.ndarray, ref: ReferenceResult) -> dict:
    """SPEC 1.5 error numbers of a measured intensity image (same rows)."""
    diff = np.abs(measured - ref.intensity)
    off = ~ref.on_silhouette
    d = diff[off]
    nan = int(np.count_nonzero(~np.isfinite(measured)))
    d = np.nan_to_num(d, nan=1.0)
    return {
        **_statistics(d),
        "silhouette_pixels": int(np.count_nonzero(ref.on_silhouette)),
        "silhouette_max": float(np.nan_to_num(diff[ref.on_silhouette], nan=1.0).max())
        if ref.on_silhouette.any()
        else 0.0,
        "nan": nan,
    }


def _statistics(d: np.ndarray) -> dict:
    """Mean, 99.9th percentile, max, count over 2/255 and size of errors d (§7.3)."""
    return {
        "mean": float(d.mean()) if d.size else 0.0,
        "p999": float(np.percentile(d, 99.9)) if d.size else 0.0,
        "max": float(d.max()) if d.size else 0.0,
        "over_2_255": int(np.count_nonzero(d > 2.0 / 255.0)),
        "pixels": int(d.size),
    }


class SettingsWith:
    """Settings like ``props`` with some values replaced, to evaluate the
    reference for a variant of a scene's look without touching the scene."""

    def __init__(self, props, **values):
        self._props, self._values = props, values

    def __getattr__(self, name):
        return self._values[name] if name in self._values else getattr(self._props, name)


def srgb_encode(linear):
    """Linear -> the sRGB-encoded values a PNG holds (Standard view), clipped."""
    x = np.clip(linear, 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1.0 / 2.4) - 0.055)


def expected_fill_rgb(ref: ReferenceResult, wire_alpha: float) -> np.ndarray:
    """§5.2 with §5.8's colours: A c_w + (1 - A) shaded fill, A = alpha_w I."""
    a = (ref.intensity * wire_alpha)[..., None]
    return a * ref.wire + (1.0 - a) * ref.fill


def color_error_report(measured_srgb: np.ndarray, expected_linear: np.ndarray, ref: ReferenceResult) -> dict:
    """The colour error of a fill render: per sample the largest |difference|
    over R, G, B between the file's values and the encoded expected colour,
    covered samples off silhouettes only; the statistics of error_report."""
    diff = np.abs(measured_srgb[..., :3] - srgb_encode(expected_linear)).max(axis=-1)
    covered = ref.face >= 0
    off = ~ref.on_silhouette & covered
    if ref.shading_undecided is not None:
        off &= ~ref.shading_undecided
    off &= ~ref.style_undecided
    d = np.nan_to_num(diff[off], nan=1.0)
    return {
        **_statistics(d),
        "nan": int(np.count_nonzero(~np.isfinite(measured_srgb[..., :3][off]))),
    }
