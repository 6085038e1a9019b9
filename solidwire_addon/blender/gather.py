"""Scene -> draw items: walk the evaluated depsgraph's object instances, get
each drawn mesh from the GPU cache (extracting it only when it is new or its
evaluated geometry changed) and pair it with its instance matrix.

Cache keys say *which* mesh, stably across depsgraphs, undo and frames, and
never hold Blender data (see cache.MeshCache for *whether* it is still valid):

* ``(mode, "mesh", mesh uid)``: an object drawn with its mesh datablock as is
  (no modifiers, no shape keys): every linked duplicate and every collection
  instance of such objects shares this one upload;
* ``(mode, "object", object uid)``: an object whose own evaluation made its
  geometry (modifiers, shape keys, Edit Mode);
* ``(mode, "instances", parent uid, n)``: the n-th distinct mesh that a
  geometry-nodes object instances (its instances of one geometry share it).

``mode`` is the depsgraph's (viewport and render levels differ).
"""

from __future__ import annotations

import time
import zlib
from dataclasses import replace

import numpy as np

from ..core import draw as draw_mod
from ..core import edge_select, extract
from ..core.cache import MeshCache
from ..core.colors import ItemSource, needs_attribute_colors, needs_item_colors
from ..core.log import one_line, warn_once
from ..core.schema import OBJECT, OVERRIDE_FIELDS
from ..core.view import DrawItem, Style, outside_frustum_many
from . import cage, density, mesh_reading, outlines, runtime, setting_repair

# Which per-object switch a target honours (object.solidwire, docs/image_model.md §5.9).
SHOW_IN_RENDER, SHOW_IN_VIEWPORT = "show_in_render", "show_in_viewport"


class ObjectSettings:
    """The per-object settings (``object.solidwire``) of one frame, read once
    per original object: whether it is shown in this target and its style
    override. ``show`` is SHOW_IN_RENDER or SHOW_IN_VIEWPORT; for the
    viewport the older ``solidwire_exclude`` property still opts out."""

    def __init__(self, show: str, objects=(), *, pass_index: bool = False):
        """``objects`` (``bpy.data.objects``) are scanned once: when none has
        a setting off its default and no pass index is wanted, gather()
        skips the per-instance look-up altogether (``active`` is False), so
        scenes that do not use these settings pay one scan per frame."""
        self.show = show
        self._known: dict[int, tuple] = {}
        # One line per object override that held a NaN (put right in the
        # object too, setting_repair.py); the target reports them.
        self.messages: list[str] = []
        self.active = pass_index or any(self._non_default(obj) for obj in objects)

    def _non_default(self, obj) -> bool:
        props = getattr(obj, "solidwire", None)
        if props is not None and (props.use_override or not getattr(props, self.show)):
            return True
        return self.show == SHOW_IN_VIEWPORT and bool(getattr(obj, "solidwire_exclude", False))

    def lookup(self, obj) -> tuple:
        """(shown, Style or None, pass index) of an evaluated object's
        original, read once per original and frame."""
        obj_orig = obj.original
        uid = obj_orig.session_uid
        known = self._known.get(uid)
        if known is None:
            props = getattr(obj_orig, "solidwire", None)
            shown, style = True, None
            if props is not None:
                shown = bool(getattr(props, self.show))
                if props.use_override:
                    values = {name: getattr(props, name) for name in OVERRIDE_FIELDS}
                    repairs = setting_repair.find_repairs(props, OBJECT)
                    if repairs:
                        values.update({name: fixed for name, (_stored, fixed) in repairs.items()})
                        setting_repair.store(props, repairs, defer=self.show == SHOW_IN_VIEWPORT)
                        self.messages += [
                            setting_repair.message(f"object '{obj_orig.name}'", name, *pair)
                            for name, pair in repairs.items()
                        ]
                    style = Style(
                        tuple(float(c) for c in values["wire_color"]),
                        float(values["thickness"]),
                        tuple(float(c) for c in values["fill_color"]),
                    )
            if self.show == SHOW_IN_VIEWPORT and getattr(obj_orig, "solidwire_exclude", False):
                shown = False
            known = self._known[uid] = (shown, style, int(getattr(obj_orig, "pass_index", 0)))
        return known


# The cage key of a tessellated source drawn as outlines (outlines.py).
OUTLINE_KEY = "outlines"


class SeenKeys(set):
    """The keys a frame drew, plus the scope (depsgraph mode) they cover."""

    scope: tuple | None = None


def _is_plain(obj_orig) -> bool:
    """Its evaluated mesh is its mesh datablock as is (shared by duplicates)."""
    data = obj_orig.data
    return len(obj_orig.modifiers) == 0 and getattr(data, "shape_keys", None) is None and obj_orig.mode != "EDIT"


def fingerprint(mesh, corners: bool = False, edge_classes: tuple = (), attribute_colors: bool = False):
    """(fingerprint, (positions, corner_vert, corner inputs, edge class
    bits)) of a mesh's drawn geometry.

    Counts plus CRC32 of the vertex positions and corner vertices (~4 GB/s),
    read with the same bulk reads extraction needs, which then reuses them.
    With ``corners`` (shaded fill), the material indices and where the
    normals live too, and the corner normals themselves where they can
    change without moving a vertex (sharp edges, custom normals); normals
    per face or per vertex follow from the positions and faces
    (extract.normals_follow_geometry), so they are neither read nor
    checksummed here (None in the context: read when the mesh is extracted
    or moved). With ``edge_classes``, the edge data of those classes
    (marking a seam moves nothing either; the bits read are handed on,
    mesh_reading.UNREAD without classes); with ``attribute_colors``, the
    active colour attribute (painting moves nothing).

    The fingerprint is ``(topology, shape)`` (see MeshCache.get_validated):
    a deformation changes the shape part alone, and then positions and
    corner normals may be uploaded again without a full extraction."""
    positions = mesh_reading.read_positions(mesh)
    corner_vert = mesh_reading.read_corner_verts(mesh)
    topology = (
        len(positions),
        len(mesh.edges),
        len(corner_vert),
        len(mesh.polygons),
        _crc(corner_vert),
    )
    class_bits = mesh_reading.UNREAD
    if edge_classes:
        class_bits = mesh_reading.read_edge_classes(mesh, edge_classes)
        topology += (0,) if class_bits is None else (_crc(class_bits),)
    shape = (_crc(positions),)
    if attribute_colors:
        topology += mesh_reading.attribute_colors_checksum(mesh)
    corner_inputs = None
    if corners:
        materials, domain = mesh_reading.read_corner_domain(mesh)
        topology += (_crc(materials), domain)
        normals = None
        if not extract.normals_follow_geometry(domain):
            normals = mesh_reading.read_normals(mesh, domain)
            shape += (_crc(normals),)
        corner_inputs = (normals, materials, domain)
    return (topology, shape), (positions, corner_vert, corner_inputs, class_bits)


def _crc(array: np.ndarray) -> int:
    return zlib.crc32(memoryview(np.ascontiguousarray(array)).cast("B"))


def item_source(obj) -> ItemSource:
    """What the colour sources read from an evaluated object (core/colors.py):
    its name, its viewport colour and its material slots' viewport colours."""
    materials = []
    for slot in obj.material_slots:
        material = slot.material
        materials.append(None if material is None else tuple(float(c) for c in material.diffuse_color[:3]))
    return ItemSource(obj.name, tuple(float(c) for c in obj.color[:3]), tuple(materials))


# The default edge selection (every option off); Selection is frozen, so one
# instance serves every call.
NO_SELECTION = edge_select.Selection()


def gather_options(settings) -> dict:
    """What the draw items of a frame with ``settings`` must carry (keyword
    arguments of :func:`gather`): corner tables for a shaded fill or
    material colours, colour-source inputs for per-object colours, the
    active colour attribute, and the edge selection."""
    return {
        "corners": draw_mod.needs_corners(settings),
        "colors": needs_item_colors(settings),
        "attribute_colors": needs_attribute_colors(settings),
        "edges": edge_select.Selection(
            float(settings.edge_angle), draw_mod.edge_classes_of(settings), bool(settings.use_cage_edges)
        ),
    }


def gather(
    depsgraph,
    cache: MeshCache,
    *,
    object_filter=None,
    trust_updates: bool | None = None,
    view=None,
    view_reach=None,
    should_stop=None,
    corners: bool = False,
    colors: bool = False,
    attribute_colors: bool = False,
    edges: edge_select.Selection = NO_SELECTION,
    object_settings: ObjectSettings | None = None,
    materials: bool = False,
    edge_lengths: bool = False,
    tessellation: bool = False,
    reposition: bool = True,
):
    """(items, seen keys, ms_extract) for every drawn mesh instance of ``depsgraph``.

    ``object_filter(original_object) -> bool`` lets a target skip objects
    (viewport visibility, per-object opt-out) before any extraction.
    ``trust_updates`` (default: viewport depsgraphs) lets an unchanged mesh be
    recognised by pointer and depsgraph update counters alone; otherwise
    (renders) a changed pointer is settled by the content fingerprint.
    With ``view`` (a core.view.View), a mesh the cache does not hold yet is not
    extracted at all while every instance of it lies outside the view
    frustum (its evaluated bound box against the clip planes); those
    instances count as culled; ``view_reach`` widens that view by how far
    drawing reaches past a mesh (silhouettes.outer_reach). ``should_stop()`` (a render's Esc) is asked
    before each object's work; when it says True, gathering ends there.
    ``corners``: meshes carry their corner table (shaded fill, material
    colours; a separate cache entry, so FLAT draws never pay for it).
    ``colors``: each item carries its object's :class:`ItemSource`.
    ``attribute_colors``: meshes carry their active colour attribute
    (the ATTRIBUTE fill source), a separate cache entry.
    ``edges``: which edges are drawn and in which style (edge angle, cage
    edges, edge classes; core/edge_select.py), a separate cache entry for
    each selection.

    ``object_settings`` applies the per-object settings: an object drawn
    itself follows its own; an instance is drawn only if both its instancer
    and the object it instances are shown, and takes the style override of
    the object it instances (docs/image_model.md §5.9). ``materials`` (the
    IndexMA pass) gives each item its faces' material slots and the slots'
    material pass indices. ``edge_lengths`` (Fade Dense Objects) gives each
    GPU mesh its typical edge length (``mesh.edge_length``, density.py).
    ``tessellation`` (Tessellation): text, curves, surfaces and metaballs
    draw every edge of their tessellation instead of their outlines
    (outlines.py). ``reposition`` (options.DrawOptions.reposition_meshes):
    a mesh whose shape alone changed uploads its new positions only;
    False extracts it again in full."""
    if trust_updates is None:
        trust_updates = depsgraph.mode == "VIEWPORT"
    frame = _FrameGather(
        depsgraph,
        cache,
        trust_updates=trust_updates,
        view=view,
        view_reach=view_reach,
        corners=corners,
        edges=edges,
        outlines=not tessellation,
        attribute_colors=attribute_colors,
        reposition=reposition,
    )
    items: list[DrawItem] = []
    for instance in depsgraph.object_instances:
        obj = instance.object
        if obj.type != "MESH":
            continue
        if should_stop is not None and should_stop():
            break
        shown = instance_shown(instance, obj, object_filter, object_settings)
        if shown is None:
            continue
        parent, style, pass_index = shown
        mesh = frame.mesh_for(instance, obj, parent)
        if mesh is None:
            continue
        if edge_lengths and getattr(mesh, "edge_length", None) is None:
            mesh.edge_length = frame.edge_length_of(obj)
        item = DrawItem(
            mesh,
            np.array(instance.matrix_world, dtype=np.float64),
            frame.source_of(obj) if colors else None,
            style,
            pass_index,
        )
        if materials:
            item.materials = _materials_of(obj, obj.data, obj.data.as_pointer(), frame.face_slots)
        # Blender's Solid shading writes the depth of objects drawn solid,
        # except those shown in front (they have a depth of their own).
        item.in_scene_depth = obj.display_type in _SOLID_DISPLAY and not obj.show_in_front
        items.append(item)
    frame.finish()
    return items, frame.seen, frame.ms_extract


_SOLID_DISPLAY = frozenset(("SOLID", "TEXTURED"))


def instance_shown(instance, obj, object_filter, object_settings):
    """(parent, style, pass index) of a drawn instance, or None when the
    target does not draw it. An instance is as visible as the object that
    instances it (its source may well be hidden or in an excluded
    collection); per-object settings need both shown (image model §5.9)."""
    is_instance = instance.is_instance
    if not is_instance and not instance.show_self:
        return None
    parent = instance.parent if is_instance else None
    owner = parent if parent is not None else obj
    if object_filter is not None and not object_filter(owner.original):
        return None
    style, pass_index = None, 0
    if object_settings is not None and object_settings.active:
        shown, style, pass_index = object_settings.lookup(obj)
        if not shown or (parent is not None and not object_settings.lookup(parent)[0]):
            return None
    return parent, style, pass_index


class _FrameGather:
    """What one gather() keeps while it walks the instances: which evaluated
    mesh became which GPU mesh this frame, keys in use, meshes deferred
    because every instance so far lay outside the view, colour-source inputs
    and material slots read once per object/mesh."""

    def __init__(
        self,
        depsgraph,
        cache: MeshCache,
        *,
        trust_updates: bool,
        view,
        view_reach=None,
        corners: bool,
        edges: edge_select.Selection,
        outlines: bool = True,
        attribute_colors: bool = False,
        reposition: bool = True,
    ):
        self.cache = cache
        self.reposition = reposition
        self.mode = depsgraph.mode
        self.trust = (depsgraph.as_pointer(), runtime.epoch) if trust_updates else None
        self.versions = runtime.geometry_version
        self.corners, self.edges, self.outlines = corners, edges, outlines
        self.attribute_colors = attribute_colors
        self.view_projection = None if view is None else view.projection @ view.view_matrix
        self.view_reach = view_reach
        self.seen = SeenKeys()
        self.seen.scope = (self.mode,)
        self.ms_extract = 0.0
        self.by_pointer: dict[int, object] = {}  # evaluated mesh -> GPUMesh (or None) this frame
        self.key_pointer: dict[tuple, int] = {}  # key -> the evaluated mesh it stands for this frame
        self.instancer_meshes: dict[int, int] = {}  # geometry-nodes parent uid -> distinct meshes so far
        self.deferred: dict[int, tuple] = {}  # culled, never-extracted mesh -> (key, uids, bound box, culled)
        self.sources: dict[int, ItemSource] = {}  # evaluated object -> its colour-source inputs
        self.face_slots: dict[int, np.ndarray] = {}  # evaluated mesh -> material slot per face
        self.edge_choice: dict[int, tuple] = {}  # evaluated object -> (edge selection, cage key)

    def mesh_for(self, instance, obj, parent):
        """The GPU mesh an instance draws (None: nothing to draw, or culled)."""
        data = obj.data
        pointer = data.as_pointer()
        if pointer in self.deferred:
            key, uids, box, culled = self.deferred[pointer]
            if _outside(self.view_projection, instance, box, self.view_reach):
                self.deferred[pointer] = (key, uids, box, culled + 1)
                return None
            # A visible instance after all: extract now (the earlier ones are
            # outside the view and stay culled).
            del self.deferred[pointer]
            self.cache.culled += culled
            self.seen.add(key)
            self.by_pointer[pointer] = self._resolve_safely(obj, data, pointer, key, uids)
        if pointer not in self.by_pointer:
            mesh = None
            # Objects without faces are never extracted; in Edit Mode the
            # evaluated mesh can be an empty wrapper (see _mesh_for).
            if len(data.polygons) or obj.original.mode == "EDIT":
                try:
                    key, uids = self._key(obj, pointer, parent)
                except Exception as exc:  # noqa: BLE001 - one bad object must not blank the frame
                    warn_once(
                        ("object", obj.name),
                        f"SolidWire skips object '{obj.name}': {type(exc).__name__}: {one_line(exc)}",
                    )
                    key = None
                if key is not None:
                    if self.view_projection is not None and key not in self.cache:
                        box = _bound_box(obj)
                        if box is not None and _outside(self.view_projection, instance, box, self.view_reach):
                            # Only an off-screen object pays for the check: a
                            # small part of what extracting it would cost.
                            box = mesh_reading.drawn_vertex_box(obj, box)
                        if box is not None and _outside(self.view_projection, instance, box, self.view_reach):
                            self.deferred[pointer] = (key, uids, box, 1)
                            return None
                    self.seen.add(key)
                    mesh = self._resolve_safely(obj, data, pointer, key, uids)
            elif len(data.vertices):  # (an empty mesh, e.g. a pure instancer's own, says nothing)
                warn_once(
                    ("nofaces", obj.name),
                    f"SolidWire: object '{obj.name}' has no faces; nothing to draw "
                    "(loose edges and vertices are not drawn)",
                )
            self.by_pointer[pointer] = mesh
        return self.by_pointer[pointer]

    def _key(self, obj, pointer, parent):
        key, uids = _key_for(obj, pointer, parent, self.mode, self.key_pointer, self.instancer_meshes)
        if self.corners:
            key = (*key, "corners")
        if self.attribute_colors:
            key = (*key, "attribute colors")
        edges, cage_key = self._edges_for(obj)
        if edges.active:
            key = (*key, "edges", edges, cage_key)
        return key, uids

    def _resolve_safely(self, obj, data, pointer, key, uids):
        try:
            edges, cage_key = self._edges_for(obj)
            mesh, ms = _mesh_for(
                obj,
                data,
                pointer,
                key,
                uids,
                self.cache,
                self.trust,
                self.versions,
                self.corners,
                edges,
                self.mode == "RENDER",
                outline=cage_key == OUTLINE_KEY,
                attribute_colors=self.attribute_colors,
                allow_reposition=self.reposition,
            )
        except Exception as exc:  # noqa: BLE001 - one bad object must not blank the frame
            warn_once(
                ("object", obj.name), f"SolidWire skips object '{obj.name}': {type(exc).__name__}: {one_line(exc)}"
            )
            return None
        self.ms_extract += ms
        return mesh

    def _edges_for(self, obj):
        """(selection, cage key) for one object: cage edges only count on a
        mesh that a subdivision modifier subdivides (any other mesh keeps
        the plain, cheaper path). Asked once per object and frame."""
        known = self.edge_choice.get(obj.as_pointer())
        if known is not None:
            return known
        edges = self.edges
        cage_key = None
        tessellated = outlines.is_tessellated(obj)
        if tessellated and self.outlines:
            # The outline mask goes in through the cage input (a
            # tessellation has no cage of its own).
            edges = replace(edges, use_cage=True)
            cage_key = OUTLINE_KEY
        elif tessellated:
            edges = replace(edges, use_cage=False)
        elif edges.use_cage:
            render = self.mode == "RENDER"
            if cage.subdivides(obj.original, render):
                cage_key = cage.cage_key(obj.original, render)
            else:
                edges = replace(edges, use_cage=False)
        known = self.edge_choice[obj.as_pointer()] = (edges, cage_key)
        return known

    def edge_length_of(self, obj) -> float:
        """The typical edge length of the lines ``obj`` draws: its cage's
        (the original mesh's) where cage edges are drawn, else its evaluated
        mesh's. Read once per GPU mesh (kept on it until it is extracted
        again); 0.0 (never faded) for text and curves, and when it cannot
        be read."""
        if outlines.is_curve_outline(obj):
            # Text and curves draw outlines and profiles: chains of short
            # segments along smooth curves, which their segment length says
            # nothing about (a letter would fade away).
            return 0.0
        try:
            cage_drawn = self._edges_for(obj)[1] not in (None, OUTLINE_KEY)
            return density.typical_edge_length(obj.original.data if cage_drawn else obj.data)
        except (AttributeError, ReferenceError, RuntimeError, TypeError, ValueError) as exc:
            warn_once(("edge_length", obj.name), f"SolidWire: no edge length for '{obj.name}' (never faded): {exc}")
            return 0.0

    def source_of(self, obj) -> ItemSource:
        source = self.sources.get(obj.as_pointer())
        if source is None:
            source = self.sources[obj.as_pointer()] = item_source(obj)
        return source

    def finish(self) -> None:
        for _key, _uids, _box, culled in self.deferred.values():
            self.cache.culled += culled  # never extracted: every instance outside the view


def _edge_angle_holds(entry, mesh) -> bool:
    """Whether a move of ``mesh``'s vertices (same faces) leaves every edge
    on its side of the edge angle, checked against what the extraction kept
    (edge_select.EdgeAngleState): only edges next to a face that turned are
    measured again. Then the drawn edges and regions stay as they are."""
    state = getattr(entry, "edge_angle_state", None)
    return state is not None and state.still_flat(mesh_reading.read_face_normals(mesh))


def _materials_of(obj, data, pointer, face_slots) -> tuple | None:
    """(material slot per face, pass_index per slot) of an evaluated object."""
    try:
        slots = face_slots.get(pointer)
        if slots is None:
            slots = face_slots[pointer] = mesh_reading.read_material_indices(data)
        passes = tuple(float(s.material.pass_index) if s.material is not None else 0.0 for s in obj.material_slots)
    except (AttributeError, RuntimeError, ValueError) as exc:
        warn_once(("materials", obj.name), f"SolidWire: no material indices for '{obj.name}': {exc}")
        return None
    return slots, passes


def _bound_box(obj):
    """(lo, hi) of the evaluated object's bound box in its own space, or None
    when Blender has none for it (then it is not culled before extraction)."""
    try:
        corners = np.array(obj.bound_box, dtype=np.float64)
    except (AttributeError, TypeError, ValueError):
        return None
    if corners.shape != (8, 3) or not np.isfinite(corners).all() or not corners.any():
        return None
    return corners.min(axis=0), corners.max(axis=0)


def _outside(view_projection, instance, box, reach=None) -> bool:
    object_to_clip = view_projection @ np.array(instance.matrix_world, dtype=np.float64)
    return bool(outside_frustum_many(object_to_clip[None], *box, reach)[0])


def _key_for(obj, pointer, parent, mode, key_pointer, instancer_meshes):
    """(cache key, session_uids whose geometry updates invalidate it)."""
    obj_orig = obj.original
    uids = [obj_orig.session_uid]
    if parent is not None and parent.original == obj_orig:
        # Geometry made by a geometry-nodes (or other) instancer: the n-th
        # distinct mesh it instances this frame.
        number = instancer_meshes.get(uids[0], 0)
        instancer_meshes[uids[0]] = number + 1
        key = (mode, "instances", uids[0], number)
    elif _is_plain(obj_orig):
        mesh_uid = obj_orig.data.session_uid
        uids.append(mesh_uid)
        key = (mode, "mesh", mesh_uid)
        if key_pointer.get(key, pointer) != pointer:
            key = (mode, "object", uids[0])  # not the shared mesh after all
    else:
        key = (mode, "object", uids[0])
    if key_pointer.get(key, pointer) != pointer:
        key = (*key, pointer)  # never let two different meshes share an entry in one frame
    key_pointer[key] = pointer
    return key, uids


def _mesh_for(
    obj,
    data,
    pointer,
    key,
    uids,
    cache,
    trust,
    versions,
    corners=False,
    edges: edge_select.Selection = NO_SELECTION,
    render: bool = False,
    outline: bool = False,
    attribute_colors: bool = False,
    allow_reposition: bool = True,
):
    """(GPUMesh or None, ms spent validating/extracting) for one evaluated
    mesh. ``outline``: the drawn mask is outlines.py's (``edges.use_cage``
    says a mask is passed), not the cage's; ``allow_reposition`` False
    extracts a mesh whose shape changed in full."""
    obj_orig = obj.original
    fast = None
    if trust is not None:
        fast = (*trust, pointer, *(versions.get(uid, 0) for uid in uids))

    in_edit_mode = obj_orig.mode == "EDIT"
    start = time.perf_counter()
    upload_before = cache.ms_upload
    source = []  # made on first use: an unchanged mesh needs no to_mesh()

    def get_source():
        if not source:
            # In Edit Mode the evaluated mesh can be an empty wrapper around
            # the BMesh being edited; to_mesh() gives its current geometry.
            source.append(obj.to_mesh() if in_edit_mode else data)
        return source[0]

    def make_arrays(context):
        positions, corner_vert, corner_inputs, class_bits = context
        try:
            source_mesh = get_source()
            # Edge selection reads the face offsets too: once for both.
            face_offsets = mesh_reading.read_face_offsets(source_mesh)
            arrays = mesh_reading.extract_mesh(
                source_mesh,
                positions=positions,
                corner_vert=corner_vert,
                corners=corner_inputs if corners else None,
                face_offsets=face_offsets,
            )
            # Every look selects edges on a mesh with n-gons: each n-gon's
            # outline is drawn by the region-lines pass (edge_select.select_edges).
            if edges.active or arrays.has_ngons:
                if corner_vert is None and arrays.dropped_triangles:
                    corner_vert = mesh_reading.read_corner_verts(source_mesh)  # read once for both below
                cage_edges = None
                if outline:
                    normals = mesh_reading.drawn_face_normals(source_mesh, arrays, corner_vert, face_offsets)
                    cage_edges = outlines.outline_mask(source_mesh, normals, face_offsets)
                elif edges.use_cage:
                    # The cage's regions (joined across what the angle hides); select_edges
                    # takes them only where the enabled classes style drawn edges alone.
                    cage_edges = cage.cage_edges(obj.original, source_mesh, render=render, regions=True)
                mesh_reading.apply_edge_selection(
                    arrays,
                    source_mesh,
                    corner_vert if corner_vert is not None else mesh_reading.read_corner_verts(source_mesh),
                    face_offsets,
                    edges,
                    cage_edges,
                    class_bits,
                )
            read_colors = mesh_reading.read_attribute_colors(source_mesh) if attribute_colors else None
            if read_colors is not None:
                extract.attach_attribute_colors(
                    arrays,
                    *read_colors,
                    corner_vert if corner_vert is not None else mesh_reading.read_corner_verts(source_mesh),
                    mesh_reading.read_face_offsets(source_mesh),
                )
        except extract.ExtractError as exc:
            warn_once(("extract", obj.name), f"SolidWire skips object '{obj.name}': {exc}")
            return None
        if arrays.dropped_triangles:
            warn_once(
                ("nonfinite", obj.name),
                f"SolidWire: object '{obj.name}' has {arrays.dropped_triangles} triangles in faces with "
                "non-finite (NaN/Inf) or huge (1.8e19 or more) vertex coordinates; those faces are not drawn",
            )
        if arrays.degenerate_triangles:
            warn_once(
                ("degenerate", obj.name),
                f"SolidWire: object '{obj.name}' has {arrays.degenerate_triangles} degenerate triangles "
                "(a face uses one vertex twice); they are not drawn (Mesh > Clean Up can fix this)",
            )
        return arrays

    def reposition(entry, context):
        positions, corner_vert, corner_inputs, _class_bits = context
        source_mesh = get_source()
        if edges.follows_positions and (outline or not _edge_angle_holds(entry, source_mesh)):
            # An edge crossed the angle: other drawn edges and regions. (An
            # outline's own mask follows the positions too; it is not kept.)
            return None
        moved = extract.reposition(
            entry,
            positions,
            corner_vert,
            mesh_reading.read_face_offsets(source_mesh),
            mesh_reading.blender_triangles(source_mesh),
        )
        if moved is None or not corners:
            return moved
        normals, materials, domain = corner_inputs
        if domain == extract.NORMALS_BY_CORNER and entry.corner_rows is None:
            return None
        if normals is None:  # not read by the fingerprint (they follow the positions)
            normals = mesh_reading.read_normals(source_mesh, domain)
        # The normals follow the deformation; which corner each triangle
        # corner is does not (same faces, same triangles; the domain is part
        # of the fingerprint's topology).
        return (
            *moved,
            extract.fill_corner_table(entry.corner_rows, entry.triangle_polygons_cpu, normals, materials, domain),
        )

    try:
        # A deformation re-uploads positions (and corner normals) only; with
        # the edge angle, only while every edge stays on its side of the
        # angle (else which edges are drawn changes: extracted again).
        mesh, _extracted = cache.get_validated(
            key,
            fast,
            lambda: fingerprint(get_source(), corners, edges.classes, attribute_colors),
            make_arrays,
            reposition if allow_reposition else None,
        )
    finally:
        if in_edit_mode and source:
            obj.to_mesh_clear()
    # Upload time is reported apart (stats "ms_upload").
    return mesh, (time.perf_counter() - start) * 1000.0 - (cache.ms_upload - upload_before)
