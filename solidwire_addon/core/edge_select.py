"""Edge selection: which edges of a mesh are drawn, in which style, and the
regions their lines bound (docs/image_model.md §3.4-§3.6).

Every edge of the evaluated mesh is *drawn* or *not drawn* (edge angle, cage
edges). Faces joined across edges that are not drawn form a *region*; a
fragment measures its distance to the drawn edges bounding its face's
region, so a line never stops short where a neighbouring edge is hidden.
Drawn edges may carry *classes* (boundary, sharp, crease, seam, Freestyle);
each enabled class is a line style of its own.

The exact path keeps its fast per-triangle form wherever that is already the
image: a face whose edges are all drawn and carry no class ("plain") draws
from its own edges as before. Every other face is *listed*: its triangles
walk a block of segments (the drawn edges of its region, each with its
style, plus the diagonals of n-gons in it) in a table the fragment stage
reads (``region_table``). Regions have no size limit.

A fragment that walked a region of thousands of edges would pay for all of
them, so the render draws the lines of multi-face regions another way
(``region_lines``, docs/image_model.md §2.6): each drawn edge bounding such
a region is a screen-space quad whose fragments measure the exact distance
and keep the strongest line per pixel where the visible triangle lies in
one of the edge's regions (``triangle_regions``). The block walk stays for
what needs the distance beyond a line's reach (the Edge Distance pass) and
for hidden lines.

Plain numpy on arrays; no Blender.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from . import schema
from .extract import (
    EDGE0_HIDDEN,
    EDGE0_REAL,
    EDGE1_REAL,
    EDGE2_REAL,
    EDGE3_HIDDEN,
    EDGE4_HIDDEN,
    HAS_QUAD_CORNER,
    IN_REGION,
    IS_NGON,
    NGON_SHIFT,
    REGION_LINES,
    MeshArrays,
    boxes_of_triangle_runs,
    distinct,
)

# Edge classes, in style order: style k + 1 is class k (style 0 is the
# ordinary wire), defined once in the schema, which also writes the
# shaders' per-style lookups (schema.style_lookup_glsl).
EDGE_CLASSES = schema.EDGE_CLASS_NAMES
CLASS_BIT = {name: 1 << k for k, name in enumerate(EDGE_CLASSES)}
# Style of a diagonal segment in a region block (n-gon diagonals).
DIAGONAL_STYLE = 15
# Texels per segment in the region table: (lower id, upper id, style, 0)
# and (chain end, chain end, 0, 0) for the density fade.
TEXELS_PER_SEGMENT = 2
# The block walk — what a pixel does where the region-lines pass does not
# run: the layers behind the surface under hidden lines, a backend without
# the deferred surface, and the Edge Distance pass's d beyond a line's
# reach — takes a region whole up to this many drawn edges (a cage face
# subdivided five times); a larger region is walked face by face there, so
# that those paths' cost per pixel stays bounded (docs/image_model.md
# §2.6). The visible lines never are: the region-lines pass has no limit.
WALK_LIMIT = 128
# Texels per region line (shaders/region_lines_vert.glsl): (lower id, upper
# id, style, region) and (chain end, chain end, other region or NO_REGION, 0).
TEXELS_PER_REGION_LINE = 2
NO_REGION = -1.0
# The most entries a run of the region-lines pass holds
# (shaders/region_lines_vert.glsl): consecutive entries of one chain, style
# and pair of regions drawn as one quad. A cage edge at level 5 is a chain
# of 32 short segments whose quads would mostly overlap, and a rasteriser
# pays per primitive and per covered pixel. Eight segments fill 40 varying
# components, within every backend's limit.
RUN_SEGMENTS = 8
# The most a mesh's plain faces may hold of its triangles for them to be
# listed too, where every other face is (_lists_plain_faces_too). Each plain
# face listed adds its edges to the region-lines pass; the resolve then sets
# up no triangle edge at any pixel. Suzanne subdivided three times and
# applied, filling a third of a 1280 x 720 F12 (llvmpipe), under the edge
# angle: at 20 and 12 degrees 0.6 % and 4.3 % of its triangles are plain,
# and listing them took the frame from 60 to 53 and from 80 to 69 ms; at 8
# and 6 degrees (14 % and 25 %) it made no difference, at 4 degrees (43 %)
# it cost 86 -> 103 ms.
PLAIN_LISTED_SHARE = 0.1
# The flag bits a listed triangle drops before its block's bits are set: its
# quad edges and n-gon outline are in its block, and its block's segment
# count takes the bits from NGON_SHIFT up.
LISTED_FACE_DROPS = HAS_QUAD_CORNER | IS_NGON | REGION_LINES | EDGE3_HIDDEN | EDGE4_HIDDEN | (-1 << NGON_SHIFT)
# A listed triangle that keeps HAS_QUAD_CORNER measures its own edges as a
# plain one does, all but those its block holds (_measures_own_edges: a
# triangle or quad of its own with a classed edge, whose block holds the
# classed edges alone; they are marked hidden but stay real,
# _mark_edges_from_block). Its block starts with its face's corners, in the
# texels of one segment (_face_corners: its quad's fourth corner is among
# them, as the triangle's fourth column holds the block's start). Its
# triangles' region is OWN_REGION_BASE - label, below NO_REGION: the
# region-lines pass finds its classed lines there, and the hidden layers
# leave it to the direct hidden-line pass, which walks its block.
OWN_EDGES_MEASURED = IN_REGION | HAS_QUAD_CORNER
OWN_REGION_BASE = -2.0


@dataclass
class KnownRegions:
    """A mesh's regions as the caller knows them from how the mesh was made
    (blender/cage.py: the children of each cage face of a subdivision), so
    that select_edges need not find them. Region k is the faces
    ``face_start[k]`` to ``face_start[k + 1] - 1``: consecutive, every face
    in one, each region joined across edges that are not drawn and no such
    edge between two regions. Its drawn edges are
    ``region_edges[edge_start[k]:edge_start[k + 1]]``, ascending. The caller
    vouches for this and for every edge that is not drawn having exactly two
    face corners (an edge inside a cage face), for the ``drawn`` mask it
    passes with these regions and no edge classes; select_edges checks the
    rest of what its shortcut assumes and otherwise finds the regions
    itself.

    Faces from ``face_start[-1]`` on, when there are any (the caps an Array
    adds after its copies), are in no listed region: select_edges takes
    them as plain faces (each its own region, drawn from its own edges)
    where every edge they have is drawn and has no class, and otherwise
    finds the regions itself.

    ``chain_edges`` > 1 (a subdivision at level L: 2**L) says more, which
    the caller vouches for too: the listed edges come in whole chains of
    that many consecutive edges (``region_edges`` in groups of
    ``chain_edges``, each ``e, e + 1, ...``), every edge of a chain with
    the same chain ends (EdgeInputs.chain_ends) and listed by the same
    regions. The region lines are then written per chain
    (_chain_region_lines)."""

    face_start: np.ndarray  # (R + 1,) ascending, from 0 to the face count
    edge_start: np.ndarray  # (R + 1,) offsets into ``region_edges``
    region_edges: np.ndarray  # (S,) edge ids
    chain_edges: int = 1
    # Regions of several runs of faces (join_regions): ``face_start`` then
    # bounds P runs ("pieces", each a joined patch), piece p lies in region
    # ``piece_region[p]``, and regions are numbered by their first piece.
    piece_region: np.ndarray | None = None


@dataclass
class SubdivisionLayout:
    """What a subdivision's evaluated edge layout says (blender/cage.py's
    peel) when the caller cannot read the mesh it started from (a modifier
    before the subdivision made it, or Edit Mode): select_edges then reads
    the regions of the cage mask from the mesh's own corners
    (regions_from_layout). At ``level`` (n = 2**level children per coarse
    edge) the subdivided mesh is the first ``subdivided_faces`` faces,
    ``subdivided_verts`` vertices and ``subdivided_edges`` edges; its vertices are the ``coarse_verts``
    coarse ones, then n - 1 inside each of the ``coarse_edges`` coarse
    edges, then each coarse face's own, face by face; its first
    ``coarse_edges * n`` edges are the drawn ones. ``copies``: how many
    copies each Mirror or Array step after the subdivision made, in stack
    order (each copy's faces and edges follow its input's). ``cap_faces``,
    ``cap_edges``: what the last Array's caps add after every copy (faces
    past the regions: KnownRegions)."""

    level: int
    coarse_verts: int
    coarse_edges: int
    coarse_faces: int
    subdivided_verts: int
    subdivided_edges: int
    subdivided_faces: int
    copies: tuple[int, ...] = ()
    cap_faces: int = 0
    cap_edges: int = 0


@dataclass
class EdgeInputs:
    """What Blender's data says about each evaluated edge (mesh.edges order).

    ``drawn``: False for an edge that is not drawn (edge angle, not a cage
    edge); None: all drawn. ``classes``: bits of CLASS_BIT for the enabled
    classes the edge belongs to (the boundary bit is derived here from the
    topology when ``boundary_class`` is set). ``chain``: edges with the same
    chain id are pieces of one longer edge (a cage edge cut by subdivision);
    the density fade measures the chain, not the piece. None: each edge is
    its own chain."""

    verts: np.ndarray  # (E, 2) vertex ids
    drawn: np.ndarray | None = None
    classes: np.ndarray | None = None
    boundary_class: bool = False
    chain: np.ndarray | None = None
    # (E, 2) the ends of each edge's chain when the caller knows them (cage
    # edges); else found from ``chain``.
    chain_ends: np.ndarray | None = None
    # The regions of ``drawn`` when the caller knows them from how the mesh
    # was made (a subdivision's cage faces), or the layout they are read
    # from, or a function giving either (or None), called only where they
    # apply; None: found here.
    regions: KnownRegions | SubdivisionLayout | Callable[[], KnownRegions | SubdivisionLayout | None] | None = None
    # (E,) how many face corners each edge has, when the caller has counted
    # them (np.bincount of the corner edges): counted once per mesh.
    corner_uses: np.ndarray | None = None
    # (E,) edges ``drawn`` leaves out beyond the mask the regions are of (the
    # edge angle beside the cage look): the regions join across them
    # (join_regions). None: the regions are of ``drawn`` itself.
    joined: np.ndarray | None = None

    @property
    def selects_anything(self) -> bool:
        return self.drawn is not None or self.classes is not None or self.boundary_class or self.chain is not None


@dataclass
class SelectionStats:
    hidden_edges: int = 0
    regions: int = 0  # regions walked as a whole: of more than one face, or one n-gon
    listed_triangles: int = 0
    segments: int = 0
    region_lines: int = 0  # entries of the region-lines table


def _lists_plain_faces_too(plain_triangles: int, triangles: int) -> bool:
    """Whether a mesh whose other faces are all listed lists its
    ``plain_triangles`` (those of plain faces, each a region of its own
    with no classed edge) too: where they are at most PLAIN_LISTED_SHARE of
    its triangles. Then every triangle takes its lines from the
    region-lines pass, and a resolve that reads them sets up no triangle
    edge per pixel (ShaderVariant.no_edge_setup), which a software
    rasteriser pays for at every pixel; the pass then draws the plain
    faces' edges too, as it draws those of a face with a classed edge."""
    return 0 < plain_triangles <= PLAIN_LISTED_SHARE * triangles


def _face_of_corner(sizes: np.ndarray) -> np.ndarray:
    if len(sizes) and sizes.min() == sizes.max():  # one size (a subdivision's quads): a plain repeat
        return np.repeat(np.arange(len(sizes), dtype=np.int64), int(sizes[0]))
    return np.repeat(np.arange(len(sizes), dtype=np.int64), sizes)


def _region_labels(face_count: int, f1: np.ndarray, f2: np.ndarray) -> np.ndarray:
    """Connected components of faces joined by the pairs (f1, f2), f1 <= f2
    (the faces of an edge's first and last corner): each face's label is the
    smallest face id of its component.

    Runs of consecutive face ids joined pair by pair are one component each
    from the start (a subdivision lays a cage face's children out row by
    row, so a region's rows are such runs, found in one pass); the
    components are then found over the runs, a few thousand nodes where
    there were a million faces."""
    low, high = f1, f2  # faces number corners in order: a first corner's face is never the later one
    follows = high == low + 1
    next_joined = np.zeros(face_count, bool)
    next_joined[low[follows]] = True  # face f and f + 1 are joined
    starts_run = np.ones(face_count, bool)
    starts_run[1:] = ~next_joined[:-1]
    run_of_face = np.cumsum(starts_run) - 1
    run_start = np.flatnonzero(starts_run)
    across = ~follows
    run_low, run_high = run_of_face[low[across]], run_of_face[high[across]]
    # Two rows of a grid are joined by one edge per column, and those edges
    # come one after another: the same pair of runs many times over. Only
    # distinct pairs join anything, and dropping a repeat of the previous
    # pair is one pass where finding every duplicate would be a sort.
    repeat = np.zeros(len(run_low), bool)
    repeat[1:] = (run_low[1:] == run_low[:-1]) & (run_high[1:] == run_high[:-1])
    run_label = _components(len(run_start), run_low[~repeat], run_high[~repeat])
    # Runs are numbered in face order: the smallest run is the smallest face.
    return run_start[run_label][run_of_face]


def _components(count: int, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Connected components of the nodes 0..count-1 joined by the pairs
    (a, b): each node's label is the smallest node of its component.
    Hooking plus pointer jumping: a few passes over the pairs even for a
    long chain of nodes."""
    label = np.arange(count, dtype=np.int64)
    while True:
        l1, l2 = label.take(a), label.take(b)  # roots: every label points at one
        differ = l1 != l2
        if not differ.any():
            return label
        # A pair joins what its two roots join: the next round looks at the
        # roots of the pairs still apart, and no longer at pairs already in
        # one component.
        a, b = l1[differ], l2[differ]
        # Hook each larger root under a smaller one. Where one root gets
        # several, the last write wins: any of them is a valid hook, and the
        # others are joined in a later round (a plain write is far cheaper
        # than np.minimum.at).
        label[np.maximum(a, b)] = np.minimum(a, b)
        while True:
            jumped = label.take(label)
            if np.array_equal(jumped, label):
                break
            label = jumped


def _chain_ends(verts: np.ndarray, chain: np.ndarray | None) -> np.ndarray:
    """(E, 2) the two ends of each edge's chain (its own ends when the chain
    is not a simple open path); without chains, ``verts`` itself (read,
    never written)."""
    if chain is None or len(verts) == 0:
        return np.asarray(verts, np.int64)
    ends = verts.astype(np.int64)  # (a copy: written below)
    chain = chain.astype(np.int64)
    vertex_count = int(verts.max()) + 1
    keys = np.repeat(chain, 2) * vertex_count + verts.astype(np.int64).reshape(-1)
    unique, counts = np.unique(keys, return_counts=True)
    odd = unique[counts % 2 == 1]  # path ends appear once
    odd_chain, odd_vertex = odd // vertex_count, odd % vertex_count
    chains, first, per_chain = np.unique(odd_chain, return_index=True, return_counts=True)
    path = per_chain == 2
    chains, first = chains[path], first[path]
    if len(chains):
        at = np.minimum(np.searchsorted(chains, chain), len(chains) - 1)
        ok = chains[at] == chain
        ends[ok, 0] = odd_vertex[first[at[ok]]]
        ends[ok, 1] = odd_vertex[first[at[ok]] + 1]
    return ends


def edge_classes(inputs: EdgeInputs, corner_edge: np.ndarray) -> np.ndarray | None:
    """(E,) int64 class bits of every edge: the marks the caller read, and
    the boundary class from the topology (an edge with one face corner);
    None where no edge has a class."""
    edge_count = len(np.asarray(inputs.verts).reshape(-1, 2))
    marks = inputs.classes
    has_marks = marks is not None and np.asarray(marks).any()
    if not (has_marks or inputs.boundary_class):
        return None
    classes = np.asarray(marks, np.int64).copy() if has_marks else np.zeros(edge_count, np.int64)
    if inputs.boundary_class:
        classes[_corner_uses(inputs, corner_edge, edge_count) == 1] |= CLASS_BIT["boundary"]
    return classes if classes.any() else None


def _classes_style_drawn_edges(classes: np.ndarray | None, drawn) -> bool:
    """Whether the edge classes only give edges that are drawn anyway a
    style, hiding or showing nothing: the regions of the drawn mask then
    hold. So on a subdivision's cage: marks live on the cage's edges, whose
    children are all drawn, and its boundary edges are cage children."""
    return classes is None or drawn is None or not np.logical_and(classes, ~np.asarray(drawn, bool)).any()


def _corner_uses(inputs: EdgeInputs, corner_edge: np.ndarray, edge_count: int) -> np.ndarray:
    """(E,) face corners per edge: the caller's count where it has one."""
    uses = inputs.corner_uses
    if uses is not None and len(uses) == edge_count:
        return uses
    return np.bincount(np.asarray(corner_edge), minlength=edge_count)


def select_edges(
    arrays: MeshArrays, corner_vert: np.ndarray, face_offsets: np.ndarray, corner_edge: np.ndarray, inputs: EdgeInputs
) -> SelectionStats:
    """Apply ``inputs`` to ``arrays`` in place (edge flags, column 3 of
    listed triangles, ``region_table``) and say what it did. A mesh with
    n-gons is worth calling with no selection at all (every edge drawn):
    its n-gons become regions of their own (see below)."""
    classes = edge_classes(inputs, corner_edge)
    regions = inputs.regions
    if regions is not None and inputs.joined is not None and classes is not None and inputs.drawn is not None:
        # An edge of an enabled class shows though the angle would hide it
        # (as below): the regions join across the others alone.
        shown = np.logical_and(inputs.joined, classes)
        if shown.any():
            inputs = replace(inputs, drawn=inputs.drawn | shown, joined=inputs.joined & ~shown)
    if regions is not None and _classes_style_drawn_edges(classes, inputs.drawn):
        if callable(regions):  # found on first use (blender/cage.py): only here, where they apply
            regions = inputs.regions = regions()
        known = (
            None
            if regions is None
            else _select_known_regions(arrays, corner_vert, face_offsets, corner_edge, inputs, classes)
        )
        if known is not None:
            return known
    stats = SelectionStats()
    verts = np.asarray(inputs.verts, dtype=np.int64).reshape(-1, 2)
    edge_count = len(verts)
    offsets = np.asarray(face_offsets, dtype=np.int64)
    sizes = np.diff(offsets)
    face_count = len(sizes)
    corner_edge = np.asarray(corner_edge, dtype=np.int64)
    if edge_count == 0 or face_count == 0 or arrays.triangle_count == 0:
        return stats
    corner_face = _face_of_corner(sizes)
    uses = _corner_uses(inputs, corner_edge, edge_count)

    drawn = np.ones(edge_count, bool) if inputs.drawn is None else np.asarray(inputs.drawn, bool).copy()
    has_classes = classes is not None
    if classes is None:
        classes = np.zeros(edge_count, np.int64)
    # Boundary and non-manifold edges are always drawn, and so is an edge of
    # an enabled class (asking for sharp edges shows them even where the
    # angle or the cage would not).
    drawn |= uses != 2
    if has_classes:
        drawn |= classes != 0

    # Regions: faces joined across edges that are not drawn (each has two
    # faces: the one its first corner belongs to, and the one its last
    # corner belongs to).
    hidden_edges = np.flatnonzero(~drawn)
    stats.hidden_edges = len(hidden_edges)
    if len(hidden_edges):
        first_face = np.empty(edge_count, np.int64)
        first_face[corner_edge[::-1]] = corner_face[::-1]  # the last write is the first corner's
        last_face = np.empty(edge_count, np.int64)
        last_face[corner_edge] = corner_face
        label = _region_labels(face_count, first_face[hidden_edges], last_face[hidden_edges])
    else:  # every edge drawn (classes on a plain look): every face its own region
        label = np.arange(face_count, dtype=np.int64)
    region_size = np.bincount(label, minlength=face_count)
    # The regions whose lines the region-lines pass draws: those of more than
    # one face, and each n-gon on its own. An n-gon's triangles would
    # otherwise each walk its whole outline and diagonals at every pixel, a
    # cost that grows with its corners (five times a triangulated copy of
    # a mesh of n-gons of up to 57 corners, on llvmpipe); the pass draws each
    # outline edge once (image model §2.6).
    ngon_face = sizes > 4
    walked_region = (region_size > 1) | ((region_size == 1) & ngon_face)
    arrays.ngons_alone = bool((region_size[label[ngon_face]] == 1).all())
    if arrays.ngons_alone and ngon_face.any():
        ngon_sizes = sizes[ngon_face]
        first = offsets[:-1][ngon_face]
        rank = np.arange(ngon_sizes.sum()) - np.repeat(np.cumsum(ngon_sizes) - ngon_sizes, ngon_sizes)
        arrays.ngon_outlines = (
            np.asarray(corner_vert, np.intp)[np.repeat(first, ngon_sizes) + rank],
            np.concatenate(([0], np.cumsum(ngon_sizes)[:-1])),
        )
    styled_face = np.zeros(face_count, bool)
    classed_corner = None
    if has_classes:
        classed_corner = classes.take(corner_edge) != 0
        styled_face[corner_face[classed_corner]] = True
    walked = walked_region[label]
    # Faces listed on their own (a block of their own drawn edges, their
    # lines drawn by the region-lines pass): those with a classed edge, and
    # where nearly every face is listed anyway, the few plain ones too
    # (_lists_plain_faces_too). Otherwise the plain faces set up their own
    # edges at every pixel anyway, and a triangle or quad with a classed
    # edge measures its other edges itself (_measures_own_edges).
    alone = styled_face
    plain = ~walked & ~styled_face
    measures_own = None
    if _lists_plain_faces_too(int(sizes.compress(plain).sum()) - 2 * int(plain.sum()), arrays.triangle_count):
        alone = styled_face | plain
    elif has_classes and plain.any():
        measures_own = _measures_own_edges(styled_face & ~walked, sizes)
        if not measures_own.any():
            measures_own = None

    # Drawn edges of each region whose lines are listed (unique (label,
    # edge) pairs, as one key, so sorted by region): those of multi-face
    # regions and of the faces listed alone (of a face that measures its
    # own, the classed ones alone); a plain face needs none.
    drawn_corner = drawn[corner_edge]
    lines_corner = drawn_corner & (walked | alone)[corner_face]
    if measures_own is not None:
        lines_corner &= classed_corner | ~measures_own[corner_face]
    keys = distinct(label[corner_face[lines_corner]] * edge_count + corner_edge[lines_corner])
    pairs = np.stack(np.divmod(keys, edge_count), axis=1)
    # A region too large to walk (see WALK_LIMIT): its faces' blocks hold
    # their own drawn edges (the walk is then face by face); the region-lines
    # pass still draws the whole region.
    region_edges = np.bincount(pairs[:, 0], minlength=face_count) if len(pairs) else np.zeros(face_count, np.int64)
    too_large = walked & (region_edges[label] > WALK_LIMIT)
    # Owner of each listed face's block: its region's block (id = the region
    # label), or a block of its own (id = face_count + face) holding its
    # region's drawn edges (or, outside a walked region or in one too large
    # to walk, its own) plus its own n-gon diagonals: a diagonal belongs to
    # its face only (§1.3). -1: a plain face, drawn from its own edges.
    faces = np.arange(face_count)
    own_block = (walked & (ngon_face | too_large)) | (~walked & alone)
    owner = np.where(own_block, face_count + faces, np.where(walked, label, -1))

    _mark_own_edges(arrays, verts, drawn, np.asarray(corner_vert), offsets, sizes, corner_edge)
    if measures_own is not None:
        own_rows = np.flatnonzero(measures_own[arrays.triangle_polygons])
        _mark_edges_from_block(
            arrays, own_rows, verts, drawn & (classes == 0), np.asarray(corner_vert), offsets, sizes, corner_edge
        )
    listed_face = owner >= 0
    if not listed_face.any():
        return stats

    # Segments of each block.
    by_label = pairs  # (sorted by region already)
    # The distinct owners, ascending: marked in a bitmap over [0, 2 F), no sort.
    owned = np.zeros(2 * face_count, bool)
    owned[owner[listed_face]] = True
    block_owner = np.flatnonzero(owned)
    block_face = np.where(block_owner >= face_count, block_owner - face_count, block_owner)
    from_region = walked[block_face] & ~too_large[block_face]
    # Region-fed blocks: every drawn edge of the region.
    region_owner, region_label = block_owner[from_region], label[block_face[from_region]]
    lo = np.searchsorted(by_label[:, 0], region_label, side="left")
    hi = np.searchsorted(by_label[:, 0], region_label, side="right")
    count = hi - lo
    rows = np.repeat(lo, count) + (np.arange(count.sum()) - np.repeat(np.cumsum(count) - count, count))
    seg_owner = np.repeat(region_owner, count)
    seg_edge = by_label[rows, 1]
    # Face-fed blocks: the face's own drawn edges.
    own = np.zeros((0, 2), np.int64)
    if not from_region.all():  # (cage edges on a subdivision's quads: none)
        face_owned = np.zeros(face_count, bool)
        face_owned[block_face[~from_region]] = True
        own_corner = face_owned[corner_face] & drawn_corner
        if measures_own is not None:
            own_corner &= classed_corner | ~measures_own[corner_face]
        # Unique (owner, edge) pairs, as one key: sorted by owner, then edge.
        own_keys = distinct((face_count + corner_face[own_corner]) * edge_count + corner_edge[own_corner])
        own = np.stack(np.divmod(own_keys, edge_count), axis=1)
    seg_owner = np.concatenate([seg_owner, own[:, 0]])
    seg_edge = np.concatenate([seg_edge, own[:, 1]])
    # One segment per class of the edge (an edge with no class: one
    # ordinary segment).
    seg_style, (seg_owner, seg_edge) = _one_per_class(classes[seg_edge], seg_owner, seg_edge)
    ends = (
        np.asarray(inputs.chain_ends, np.int64) if inputs.chain_ends is not None else _chain_ends(verts, inputs.chain)
    )
    seg_a = np.minimum(verts[seg_edge, 0], verts[seg_edge, 1])
    seg_b = np.maximum(verts[seg_edge, 0], verts[seg_edge, 1])
    chain_a, chain_b = ends[seg_edge, 0], ends[seg_edge, 1]

    # The diagonals of each listed n-gon, into its own block.
    diag_owner, diag_a, diag_b = _ngon_diagonals(arrays, owner) if ngon_face.any() else (np.zeros(0, np.int64),) * 3
    seg_owner = np.concatenate([seg_owner, diag_owner])
    seg_a = np.concatenate([seg_a, diag_a])
    seg_b = np.concatenate([seg_b, diag_b])
    chain_a = np.concatenate([chain_a, diag_a])
    chain_b = np.concatenate([chain_b, diag_b])
    seg_style = np.concatenate([seg_style, np.full(len(diag_a), DIAGONAL_STYLE)])
    # A face that measures its own edges: its corners lead its block, in a
    # slot of a segment's texels (written below).
    corner_faces = np.zeros(0, np.int64) if measures_own is None else np.flatnonzero(measures_own)
    head = np.zeros(len(seg_owner) + len(corner_faces), bool)
    head[len(seg_owner) :] = True
    seg_owner = np.concatenate([seg_owner, face_count + corner_faces])
    seg_a, seg_b, chain_a, chain_b = (
        np.append(x, np.zeros(len(corner_faces), np.int64)) for x in (seg_a, seg_b, chain_a, chain_b)
    )
    seg_style = np.append(seg_style, np.zeros(len(corner_faces), seg_style.dtype))

    # Diagonals first in each block (after a face's corners): a triangle
    # whose lines come from the region-lines pass walks only that prefix
    # (solidwire_frag.glsl).
    order = np.lexsort((seg_style != DIAGONAL_STYLE, ~head, seg_owner))
    head = head[order]
    seg_owner, seg_a, seg_b, chain_a, chain_b, seg_style = (
        x[order] for x in (seg_owner, seg_a, seg_b, chain_a, chain_b, seg_style)
    )
    owners, first, count = np.unique(seg_owner, return_index=True, return_counts=True)
    if not np.array_equal(owners, block_owner):  # a block with no segment at all
        # Every owner is a block's and both are sorted: the blocks without
        # a segment get none, starting at 0.
        at = np.searchsorted(block_owner, owners)
        every_first, every_count = np.zeros(len(block_owner), first.dtype), np.zeros(len(block_owner), count.dtype)
        every_first[at], every_count[at] = first, count
        owners, first, count = block_owner, every_first, every_count
    table = np.zeros((TEXELS_PER_SEGMENT * len(seg_a), 4), dtype=np.float32)
    table[0::2, 0], table[0::2, 1], table[0::2, 2] = seg_a, seg_b, seg_style
    table[1::2, 0], table[1::2, 1] = chain_a, chain_b
    if len(corner_faces):
        table[0::2][head] = _face_corners(corner_faces, offsets, sizes, corner_vert)
    base = len(arrays.ngon_corners)  # region blocks follow the n-gon blocks in one table
    arrays.region_table = table

    # Each listed face's block: a lookup by owner (owners lie in [0, 2 F)),
    # far cheaper than a search; its flag bits and table start are made per
    # face and then handed to its triangles in one gather each.
    block_of_owner = np.zeros(2 * face_count, np.int64)
    block_of_owner[owners] = np.arange(len(owners))
    face_block = block_of_owner[owner]  # (meaningless where owner is -1: not listed)
    # Every listed face's lines can come from the region-lines pass
    # (REGION_LINES); its quad edges are in its block instead.
    # (A face that measures its own edges: its corners are no segment.)
    segments = count[face_block] - (0 if measures_own is None else measures_own)
    face_bits = (segments.astype(np.int32) << NGON_SHIFT) | np.int32(IN_REGION | REGION_LINES)
    face_start = (base + TEXELS_PER_SEGMENT * first[face_block]).astype(np.int32)
    polygons = arrays.triangle_polygons
    if listed_face.all():  # as with cage edges: plain slices, no mask to apply
        rows, listed_count = slice(None), len(polygons)
    else:
        rows = listed_face[polygons]
        listed_count = int(rows.sum())
        polygons = polygons[rows]
    flags = arrays.edge_flags
    drops = np.int32(LISTED_FACE_DROPS)
    if measures_own is None:
        flags[rows] = (flags[rows] & ~drops) | face_bits[polygons]
    else:
        # Its own edges stay as marked; a triangle's two quad edges are none.
        own, before = measures_own[polygons], flags[rows]
        keeps = np.where(own, np.int32(~(IS_NGON | REGION_LINES | (-1 << NGON_SHIFT))), ~drops)
        triangle_face = own & (before & HAS_QUAD_CORNER == 0)
        own_bits = np.where(own, HAS_QUAD_CORNER, 0) | np.where(triangle_face, EDGE3_HIDDEN | EDGE4_HIDDEN, 0)
        flags[rows] = (before & keeps) | face_bits[polygons] | own_bits
    arrays.triangles[rows, 3] = face_start[polygons]
    arrays.own_edges_measured = measures_own is not None
    stats.regions = int(walked_region.sum())  # sizes are counted at each region's label only
    stats.listed_triangles = listed_count
    stats.segments = len(seg_a) - len(corner_faces)
    _region_lines(arrays, verts, classes, ends, label, walked | alone, pairs, stats, measures_own)
    return stats


def _measures_own_edges(styled_alone: np.ndarray, sizes: np.ndarray) -> np.ndarray:
    """(F,) bool: the faces that measure their own edges (OWN_EDGES_MEASURED):
    of ``styled_alone`` (faces of their own with a classed edge), the
    triangles and quads. Their classed edges' lines come from their blocks
    or, over the deferred surface, the region-lines pass; their other edges
    they set up as a plain face does, which the resolve then does at every
    pixel for the mesh's plain faces anyway, where drawing them as lines
    of the pass cost more (the edge classes' F12 on llvmpipe). An n-gon's
    outline stays in its block."""
    return styled_alone & (sizes <= 4)


def _face_corners(faces: np.ndarray, offsets: np.ndarray, sizes: np.ndarray, corner_vert) -> np.ndarray:
    """(len(faces), 4) float32: the vertices of each triangle or quad of
    ``faces`` in loop order (a triangle's second repeated last): what a
    triangle of such a face reads its quad's fourth corner from, the one
    corner that is not its own (solidwire_vert.glsl)."""
    start = offsets[faces]
    corner = np.stack([start, start + 1, start + 2, np.where(sizes[faces] == 4, start + 3, start + 1)], axis=1)
    return np.asarray(corner_vert)[corner].astype(np.float32)


def _mark_edges_from_block(
    arrays: MeshArrays, rows: np.ndarray, verts, measured, corner_vert, offsets, sizes, corner_edge
) -> None:
    """For the triangle ``rows`` of faces that measure their own edges: the
    edges whose lines their blocks hold (not ``measured``) marked hidden
    as _mark_own_edges marks edges that are not drawn, but EDGEk_REAL kept:
    they are polygon edges still (the silhouettes' candidates). The
    fragment stage measures an own edge that is real and not hidden."""
    if not len(rows):
        return
    part = replace(
        arrays,
        triangles=arrays.triangles[rows],
        edge_flags=arrays.edge_flags[rows],
        triangle_polygons=arrays.triangle_polygons[rows],
        quad_flip=None,
        ngon_corners=np.zeros(0, arrays.ngon_corners.dtype),
    )
    real = part.edge_flags & (EDGE0_REAL | EDGE1_REAL | EDGE2_REAL)
    _mark_rows_in_faces(part, verts, measured, corner_vert, offsets, sizes, corner_edge)
    arrays.edge_flags[rows] = part.edge_flags | real


def regions_from_layout(
    layout: SubdivisionLayout,
    corner_vert: np.ndarray,
    corner_edge: np.ndarray,
    verts: np.ndarray,
    drawn: np.ndarray,
    face_count: int,
    corner_drawn: np.ndarray | None = None,
) -> KnownRegions | None:
    """The regions of a subdivision's cage mask (``drawn``) read from the
    evaluated mesh's own corners (``face_count`` faces, edges ``verts``) as
    ``layout`` lays them out, or None where what the layout says does not
    hold exactly.

    Blender's subdivision (``subdiv_foreach.cc``) makes each coarse face's
    children one after another in coarse face order, and each coarse face's
    own vertices (its centre and those inside it, 1 + c*m*(m-1) for c
    corners, m = n/2) one after another in the same order, after every
    vertex on a coarse edge; every child touches one of them and every edge
    inside a coarse face (a hidden one) ends at one. So a coarse face's
    children end where every such inner vertex so far is below every one
    still to come. Checked here: as many runs as coarse faces, each of
    c * m**2 children (c >= 3) whose inner vertices lie in the face's own
    range, the ranges filling the inner vertices exactly, every hidden edge
    ending at an inner vertex, the drawn edges exactly the first
    ``coarse_edges * n``. Then no hidden edge joins two runs (each run's
    inner vertices are its own); that each run is one patch, not two, is
    the layout's word (Blender's children of a face are one grid, or one
    per corner around its centre). A run's drawn edges are those its
    children's corners name, ascending (``corner_drawn``: each corner's
    edge drawn, _corner_drawn, when the caller has it); where they are
    whole chains (each coarse edge's n children from a multiple of n, none
    split between runs: checked) the regions say so
    (KnownRegions.chain_edges; the chain ends the caller passes with a
    SubdivisionLayout give each child its coarse edge's ends)."""
    n = 1 << layout.level
    m = n >> 1
    faces, edges_num, drawn_count = layout.subdivided_faces, layout.subdivided_edges, layout.coarse_edges * n
    corner_vert, corner_edge = np.asarray(corner_vert), np.asarray(corner_edge)
    if (
        faces <= 0
        or faces % (m * m)
        or min(len(corner_vert), len(corner_edge)) < 4 * faces
        or min(len(drawn), len(verts)) < edges_num
        or not 0 < drawn_count < edges_num
        or not drawn[:drawn_count].all()
        or drawn[drawn_count:edges_num].any()
    ):
        return None
    inner = layout.coarse_verts + (n - 1) * layout.coarse_edges  # the first coarse face's first own vertex
    if layout.subdivided_verts >= 1 << 31 or inner <= 0:
        return None
    hidden = np.asarray(verts[drawn_count:edges_num])
    # Blender puts the inner end second: one column is checked first.
    if hidden[:, 1].min() < inner and np.maximum(hidden[:, 0], hidden[:, 1]).min() < inner:
        return None
    # Inner vertices counted from the first: a vertex on a coarse edge or a
    # coarse vertex is negative, so as unsigned (wrapping) it is above every
    # inner one. Column by column into two face-sized arrays: a reduction
    # along rows of four, or a shifted copy of every corner, costs several
    # times more.
    quads = np.asarray(corner_vert[: 4 * faces], np.int32).reshape(faces, 4)
    top = np.maximum(quads[:, 0], quads[:, 1])
    np.maximum(top, quads[:, 2], out=top)
    np.maximum(top, quads[:, 3], out=top)
    top -= np.int32(inner)
    if top.min() < 0:
        return None  # a child that touches none of its coarse face's own vertices
    unsigned, first_inner = quads.view(np.uint32), np.uint32(inner)
    low = np.subtract(unsigned[:, 0], first_inner)
    column = np.empty_like(low)
    for k in (1, 2, 3):
        np.minimum(low, np.subtract(unsigned[:, k], first_inner, out=column), out=low)
    low = low.view(np.int32)  # every child has one inner vertex: below 2**31
    # A coarse face's children end where every inner vertex so far is below
    # every one to come: only where a child's lowest is above the previous
    # child's highest, then decided on the pieces between those places (a
    # cumulative max over every child is several times slower).
    cut = np.flatnonzero(low[1:] > top[:-1]) + 1
    piece = np.concatenate(([0], cut))
    reach = np.maximum.accumulate(np.maximum.reduceat(top, piece))
    floor = np.minimum.accumulate(np.minimum.reduceat(low, piece)[::-1])[::-1]
    face_start = np.concatenate(([0], cut[reach[:-1] < floor[1:]], [faces])).astype(np.int64)
    if len(face_start) - 1 != layout.coarse_faces:
        return None
    run_corners, rest = np.divmod(np.diff(face_start), m * m)
    if rest.any() or run_corners.min() < 3:
        return None
    inner_start = np.zeros(len(face_start), np.int64)
    np.cumsum(1 + run_corners * (m * (m - 1)), out=inner_start[1:])
    first = face_start[:-1]
    if (
        inner_start[-1] != layout.subdivided_verts - inner
        or (np.minimum.reduceat(low, first) < inner_start[:-1]).any()
        or (np.maximum.reduceat(top, first) >= inner_start[1:]).any()
    ):
        return None
    if corner_drawn is None:
        corner_drawn = _corner_drawn(drawn, corner_edge)
    at = np.flatnonzero(corner_drawn[: 4 * faces])
    # Each run's drawn corners are one stretch of ``at``: R searches, not one per corner.
    per_run = np.diff(np.searchsorted(at, 4 * face_start))
    run = np.repeat(np.arange(len(first), dtype=np.int64), per_run)
    region, edge = np.divmod(distinct(run * drawn_count + np.take(corner_edge, at)), drawn_count)
    edge_start = np.zeros(len(face_start), np.int64)
    np.cumsum(np.bincount(region, minlength=len(first)), out=edge_start[1:])
    # Whole chains (a coarse edge's n children, from a multiple of n), none
    # split between regions: the region lines are then written per chain.
    chains = edge.reshape(-1, n) if len(edge) % n == 0 else None
    whole = (
        chains is not None
        and not (edge_start % n).any()
        and not (chains[:, 0] % n).any()
        and np.array_equal(chains - chains[:, :1], np.broadcast_to(np.arange(n), chains.shape))
    )
    known = KnownRegions(face_start, edge_start, edge, n if whole else 1)
    return copied_regions(
        known, layout.copies, faces, edges_num, face_count - layout.cap_faces, len(drawn) - layout.cap_edges
    )


def join_regions(regions: KnownRegions, joined: np.ndarray) -> KnownRegions | None:
    """``regions`` (of a mask) joined across the ``joined`` edges the mask
    drew but the selection hides (the edge angle beside the cage look): two
    regions that list a joined edge become one. Each becomes a piece of
    the result (KnownRegions.piece_region), whose regions, numbered by
    their first piece, list their pieces' drawn edges once each,
    ascending. None where the lists name no edge or a negative one, or an
    edge is listed by more than two regions (a manifold cage lists each
    edge at most twice)."""
    face_start = np.asarray(regions.face_start, np.int64)
    edge_start = np.asarray(regions.edge_start, np.int64)
    edges = np.asarray(regions.region_edges, np.int64)
    pieces = len(face_start) - 1
    if (
        regions.piece_region is not None
        or pieces < 1
        or len(edges) == 0
        or edges.min() < 0
        or edge_start[-1] != len(edges)
    ):
        return None
    hidden_listing = joined.take(edges)
    if not hidden_listing.any():
        return regions
    piece_of_listing = np.repeat(np.arange(pieces, dtype=np.int64), edge_start[1:] - edge_start[:-1])
    listings = _first_and_last_listing(edges)
    if listings is None:
        return None
    edge, first, last = listings
    across = joined.take(edge)
    piece_label = _components(pieces, piece_of_listing.take(first[across]), piece_of_listing.take(last[across]))
    # Each component's label is its smallest piece: regions numbered by it.
    is_first = piece_label == np.arange(pieces)
    piece_region = (np.cumsum(is_first) - 1).take(piece_label)
    edge_count = np.int64(int(edges.max()) + 1)
    drawn_listing = ~hidden_listing
    keys = piece_region.take(piece_of_listing[drawn_listing]) * edge_count + edges[drawn_listing]
    region, edge = np.divmod(distinct(keys), edge_count)
    region_count = int(is_first.sum())
    joined_start = np.zeros(region_count + 1, np.int64)
    np.cumsum(np.bincount(region, minlength=region_count), out=joined_start[1:])
    return KnownRegions(face_start, joined_start, edge, 1, piece_region)


def whole_chains(firsts: np.ndarray, chain_edges: int) -> np.ndarray:
    """(len(firsts) * chain_edges,) int64: each chain's consecutive edges
    ``first, first + 1, ...`` (KnownRegions.chain_edges), chain by chain."""
    edges = np.empty((len(firsts), chain_edges), np.int64)
    if chain_edges <= 8:  # a column at a time: a broadcast over short rows costs several times more
        for k in range(chain_edges):
            np.add(firsts, k, out=edges[:, k])
    else:
        np.add(firsts[:, None], np.arange(chain_edges, dtype=np.int64), out=edges)
    return edges.reshape(-1)


def copied_regions(
    regions: KnownRegions, copies, faces_in: int, edges_in: int, face_count: int, edge_count: int
) -> KnownRegions | None:
    """``regions`` of a mesh of ``faces_in`` faces and ``edges_in`` edges
    carried through the copies Mirror and Array make of it (``copies``: how
    many per step, in stack order; each copy's faces and edges follow its
    input's, numbered on by the input's counts), or None where the result
    is not ``face_count`` faces and ``edge_count`` edges."""
    face_start, edge_start, edges = regions.face_start, regions.edge_start, regions.region_edges
    for count in copies:
        shift = np.arange(count, dtype=np.int64)[:, None]
        face_start = np.append((face_start[:-1] + shift * faces_in).reshape(-1), count * faces_in)
        edge_start = np.append((edge_start[:-1] + shift * len(edges)).reshape(-1), count * len(edges))
        edges = (edges + shift * edges_in).reshape(-1)
        faces_in, edges_in = count * faces_in, count * edges_in
    if faces_in != face_count or edges_in != edge_count:
        return None
    return KnownRegions(face_start, edge_start, edges, regions.chain_edges)


def _select_known_regions(
    arrays: MeshArrays,
    corner_vert: np.ndarray,
    face_offsets: np.ndarray,
    corner_edge: np.ndarray,
    inputs: EdgeInputs,
    classes: np.ndarray | None = None,
) -> SelectionStats | None:
    """select_edges for regions the caller knows (``inputs.regions``, or
    read from the layout it gives: regions_from_layout) on a mesh of quads
    only: the same arrays as the general path, written per region and per
    quad instead of found from every corner, or None (nothing written)
    where the shortcut does not apply: faces other than
    extract.build_arrays_fast's quad rows, a region of one face, a region
    list that names an edge that is not drawn, faces past the list
    (KnownRegions) with an edge that is hidden or has a class.
    ``classes``: edge_classes, which the caller has checked style only
    drawn edges (_classes_style_drawn_edges).

    Every face of the list is then in a multi-face region, so it is listed
    and its lines come from the region-lines pass (the faces past it keep
    their rows as extracted). A listed face's block is its region's
    (id = the region's first face), holding the region's drawn edges,
    ascending, one segment per class of each (one where it has none; no
    n-gon diagonal); in a region past WALK_LIMIT it is the face's own,
    holding the face's own drawn edges (_face_blocks_past_walk_limit).
    Regions listed in whole chains (KnownRegions.chain_edges) have their
    list order checked and their region lines written per chain. Regions
    known for a mask that ``inputs.joined`` thins are joined across it
    first (join_regions)."""
    regions, drawn = inputs.regions, inputs.drawn
    if drawn is None or inputs.chain_ends is None:
        return None
    offsets = np.asarray(face_offsets)
    face_count = len(offsets) - 1
    verts = np.asarray(inputs.verts).reshape(-1, 2)
    drawn = np.asarray(drawn, bool)
    prefix = _drawn_prefix(drawn)
    corner_drawn = _corner_drawn(drawn, corner_edge, prefix)  # shared with _hidden_pattern, which consumes it
    joined = None if inputs.joined is None else np.asarray(inputs.joined, bool)
    if joined is not None and (len(joined) != len(drawn) or (joined & drawn).any()):
        return None
    if isinstance(regions, SubdivisionLayout):
        if joined is None:
            regions = regions_from_layout(regions, corner_vert, corner_edge, verts, drawn, face_count, corner_drawn)
        else:  # the layout's regions are of the mask before the join
            regions = regions_from_layout(regions, corner_vert, corner_edge, verts, drawn | joined, face_count)
        if regions is None:
            return None
    if joined is not None:
        regions = join_regions(regions, joined)
        if regions is None:
            return None
    face_start = np.asarray(regions.face_start, np.int64)
    edge_start = np.asarray(regions.edge_start, np.int64)
    edges = np.asarray(regions.region_edges, np.int64)
    piece_faces = face_start[1:] - face_start[:-1]
    piece_region = regions.piece_region
    region_count = len(piece_faces) if piece_region is None else int(piece_region.max(initial=-1)) + 1
    if (
        face_count <= 0
        or len(face_start) < 2
        or len(edge_start) != region_count + 1
        or len(drawn) != len(verts)
        or (piece_region is not None and (len(piece_region) != len(piece_faces) or piece_region.min() < 0))
    ):
        return None
    per_region = edge_start[1:] - edge_start[:-1]
    if piece_region is None:
        region_faces, label = piece_faces, face_start[:-1]

        def per_face(values):
            return values.repeat(piece_faces)
    else:
        region_faces = np.bincount(piece_region, weights=piece_faces, minlength=region_count).astype(np.int64)
        # Regions are numbered by their first piece: where the running maximum rises.
        rises = np.empty(len(piece_region), bool)
        rises[0] = True
        np.greater(piece_region[1:], np.maximum.accumulate(piece_region)[:-1], out=rises[1:])
        label = face_start.take(np.flatnonzero(rises))
        if len(label) != region_count:
            return None

        def per_face(values):
            return values.take(piece_region).repeat(piece_faces)

    # Whole chains of consecutive edges (KnownRegions.chain_edges): their
    # first edges bound the ids and ascend where the list does.
    chain_edges = max(1, int(regions.chain_edges))
    firsts = edges[::chain_edges]
    listed_faces = int(face_start[-1])  # the rest: plain faces (KnownRegions)
    if (
        face_start[0] != 0
        or not 0 < listed_faces <= face_count
        or region_faces.min() < 2
        or edge_start[0] != 0
        or edge_start[-1] != len(edges)
        or per_region.min() < 1
        or firsts.min() < 0
        or firsts.max() + chain_edges > (prefix[0] if prefix[1] else len(verts))
        or not (prefix[1] or drawn[edges].all())  # (drawn edges first: all below their count)
    ):
        return None
    step = firsts[1:] - firsts[:-1]
    step[edge_start[1:-1] // chain_edges - 1] = 1  # each region's list starts afresh
    if len(step) and step.min() <= 0:
        return None
    flip = _quad_row_flip(arrays, corner_vert, offsets)
    if flip is None:
        return None
    if listed_faces < face_count:
        # Plain faces only where nothing joins them or lists them: every
        # edge drawn and none with a class (all quads: 4 corners a face),
        # and too many to be listed too (as the general path lists them).
        tail = slice(4 * listed_faces, None)
        if not corner_drawn[tail].all() or (classes is not None and classes.take(corner_edge[tail]).any()):
            return None
        if _lists_plain_faces_too(2 * (face_count - listed_faces), 2 * face_count):
            return None
    stats = SelectionStats(hidden_edges=len(drawn) - prefix[0])

    # The blocks: region k's drawn edges from table row first[k], in region order.
    ends = np.asarray(inputs.chain_ends)
    # (take gathers rows several times faster than fancy indexing; the
    # methods, here and below, skip numpy's function wrappers.)
    seg_ends = ends.take(edges, axis=0)
    table = _segment_rows(verts, seg_ends, edges)  # every region's list, as its region lines read it
    big = per_region > WALK_LIMIT  # (in drawn edges, as the general path counts)
    blocks, listing_segments = _class_segments(table, classes, edges)
    if listing_segments is None:
        region_segments, segment_start = per_region, edge_start
    else:
        segment_start = np.zeros(len(edge_start), np.int64)
        np.cumsum(np.add.reduceat(listing_segments, edge_start[:-1]), out=segment_start[1:])
        region_segments = segment_start[1:] - segment_start[:-1]
        if (region_segments[~big] > _MOST_BLOCK_SEGMENTS).any():
            return None  # (classes that are not EDGE_CLASSES: more than the quad rows' lookup holds)
    at = _hidden_pattern(drawn, corner_edge, face_count, corner_drawn)
    if big.any():
        blocks = _face_blocks_past_walk_limit(
            blocks,
            listing_segments,
            region_segments,
            per_region,
            per_face,
            big,
            at,
            corner_edge,
            verts,
            ends,
            classes,
        )
        if blocks is None:
            return None
        arrays.region_table, face_segments, face_table_start = blocks
    else:
        arrays.region_table = blocks
        face_segments = per_face(region_segments)
        face_table_start = per_face(np.multiply(segment_start[:-1], TEXELS_PER_SEGMENT, dtype=np.int32))
    if len(arrays.ngon_corners):
        face_table_start += len(arrays.ngon_corners)
    stats.segments = len(arrays.region_table) // TEXELS_PER_SEGMENT

    # Each listed quad's two rows in one 64-bit write (row 2i the low half),
    # looked up by its block's segment count, its split and its hidden edges
    # (_listed_quad_rows), written in place: no million-row temporaries.
    if listed_faces < face_count:
        at, flip = at[:listed_faces], flip[:listed_faces]
    at |= flip.view(np.uint8) << np.uint8(4)
    at |= np.left_shift(face_segments, 5, dtype=np.uint32, casting="unsafe")
    flags = arrays.edge_flags
    if flags.dtype == np.int32 and flags.flags.c_contiguous:
        _LISTED_QUAD_ROWS.take(at, out=flags.view(np.uint64)[:listed_faces], mode="clip")
    else:
        flags[: 2 * listed_faces] = np.take(_LISTED_QUAD_ROWS, at).view(np.int32)
    if arrays.triangles.flags.c_contiguous:  # a quad's two rows are one row of 8: two column writes
        quads = arrays.triangles.reshape(face_count, 8)[:listed_faces]
        quads[:, 3] = face_table_start
        quads[:, 7] = face_table_start
    else:
        arrays.triangles[: 2 * listed_faces, 3] = np.repeat(face_table_start, 2)
    label_texel = label.astype(np.float32)  # as the tables hold it
    if piece_region is None:
        regions_of_triangles = label_texel.repeat(2 * region_faces)
    else:
        regions_of_triangles = per_face(label_texel).repeat(2)
    if listed_faces < face_count:  # the plain faces' triangles: in no region
        plain = np.full(2 * (face_count - listed_faces), NO_REGION, np.float32)
        regions_of_triangles = np.concatenate([regions_of_triangles, plain])
    arrays.triangle_regions = regions_of_triangles
    stats.regions = len(label)
    stats.listed_triangles = 2 * listed_faces
    line_edges = None
    if chain_edges > 1:
        line_edges = _chain_region_lines(
            arrays, table, firsts, label_texel.repeat(per_region // chain_edges), chain_edges, stats
        )
    if line_edges is None:
        line_edges = _known_region_lines(
            arrays, verts, ends, table, seg_ends, np.repeat(label, per_region), edges, stats, classes
        )
    if classes is not None and line_edges is not None:
        _style_region_lines(arrays, classes, line_edges, ends, stats)
    return stats


def _segment_rows(verts: np.ndarray, seg_ends: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """Region-table rows (TEXELS_PER_SEGMENT texels each, no class) of the
    drawn ``edges`` in order, ``seg_ends`` their chain ends."""
    seg_verts = verts.take(edges, axis=0)
    table = np.zeros((TEXELS_PER_SEGMENT * len(edges), 4), dtype=np.float32)
    table[0::2, 0] = np.minimum(seg_verts[:, 0], seg_verts[:, 1])
    table[0::2, 1] = np.maximum(seg_verts[:, 0], seg_verts[:, 1])
    table[1::2, 0], table[1::2, 1] = seg_ends[:, 0], seg_ends[:, 1]
    return table


# Whether each corner's edge is drawn, for each of _hidden_pattern's 16 patterns.
_DRAWN_CORNERS = (np.arange(16)[:, None] >> np.arange(4)) & 1 == 0


def _class_segments(table: np.ndarray, classes: np.ndarray | None, edges: np.ndarray):
    """(block rows, segments per edge) of ``table`` (_segment_rows of
    ``edges``) with one segment per class of each edge, its style k + 1 for
    class k, in place of the edge's one (as the general path's
    _one_per_class; None: one each). Where no edge has two classes the
    styles are written into ``table`` itself (the region lines read from it
    set their own: _style_region_lines)."""
    bits = None if classes is None else classes.take(edges)
    if bits is None or not bits.any():
        return table, None
    style, row, per_edge = _class_rows(bits)
    if row is None:
        table[0::TEXELS_PER_SEGMENT, 2] = style
        return table, None
    rows = table.reshape(len(edges), -1).take(row, axis=0)
    rows[:, 2] = style
    return rows.reshape(-1, 4), per_edge


def _face_blocks_past_walk_limit(
    blocks, listing_segments, region_segments, per_region, per_face, big, hidden, corner_edge, verts, ends, classes
):
    """The blocks of _select_known_regions where some regions (``big``) are
    past WALK_LIMIT, as the general path lays them out: the other regions'
    blocks (their rows of ``blocks``, the regions' lists in order, one
    segment per class of each listed edge: ``listing_segments``, None for
    one each), then one block per face of a big region, in face order,
    holding that quad's own drawn edges ascending (``hidden``:
    _hidden_pattern's bits), each once per class. Returns (region table,
    each face's segment count, each face's first texel), or None where a
    quad names one drawn edge twice (the general path would list it once).
    A face with no drawn edge of its own starts at texel 0, as the general
    path gives a block without segments. ``per_face``: a value per region
    to one per face."""
    small_segments = np.where(big, 0, region_segments)
    faces = np.flatnonzero(per_face(big))
    pattern = hidden.take(faces)
    # The drawn corners of those faces, as (face, edge) keys sorted once:
    # most faces inside a big region have none (a sort per face of four
    # corners costs many times more).
    at = np.flatnonzero(_DRAWN_CORNERS.take(pattern, axis=0))
    local_face = at >> 2
    edge_count = np.int64(len(verts))
    edges = np.asarray(corner_edge).reshape(-1, 4).take(faces, axis=0).reshape(-1).take(at)
    keys = local_face * edge_count + edges
    keys.sort(kind="stable")  # (timsort: the keys ascend face to face, as extract.distinct's)
    if len(keys) > 1 and (keys[1:] == keys[:-1]).any():
        return None
    own_edges = keys % edge_count
    own_rows, own_segments = _class_segments(
        _segment_rows(verts, ends.take(own_edges, axis=0), own_edges), classes, own_edges
    )
    own_count = np.bincount(keys // edge_count, weights=own_segments, minlength=len(faces)).astype(np.int64)
    kept = ~big.repeat(per_region)
    if listing_segments is not None:
        kept = kept.repeat(listing_segments)
    blocks = np.concatenate(
        [blocks.reshape(-1, 4 * TEXELS_PER_SEGMENT).compress(kept, axis=0).reshape(-1, 4), own_rows]
    )
    first = per_face(np.cumsum(small_segments) - small_segments)
    own_first = int(small_segments.sum()) + np.cumsum(own_count) - own_count
    first[faces] = np.where(own_count > 0, own_first, 0)
    segments = per_face(region_segments)
    segments[faces] = own_count
    return blocks, segments, np.multiply(first, TEXELS_PER_SEGMENT, dtype=np.int32)


def _first_and_last_listing(ids: np.ndarray):
    """(the listed ids ascending, the position of each one's first listing
    in ``ids``, of its last) where no id is listed more than twice (a
    manifold cage: an edge bounds at most two regions), found by two
    scatters instead of a sort; else None."""
    counts = np.bincount(ids)
    if counts.max() > 2:
        return None
    listed = counts.nonzero()[0]
    listing = np.arange(len(ids))
    first = np.empty(len(counts), np.intp)
    first[ids[::-1]] = listing[::-1]  # the last write is the first listing's
    last = np.empty(len(counts), np.intp)
    last[ids] = listing
    return listed, first.take(listed), last.take(listed)


def _chain_region_lines(arrays: MeshArrays, table, firsts, owners, chain_edges: int, stats) -> np.ndarray | None:
    """_known_region_lines for regions listed in whole chains
    (KnownRegions.chain_edges; ``firsts``: the first edge of each listed
    chain, ``owners``: its region as a float32 texel), done per chain: a
    chain's edges are listed together by the same regions, so they are
    consecutive entries with its first edge's regions, and their texels
    are consecutive block rows. Consecutive chains with different ends
    make the runs whole chains cut into pieces of the run length, with no
    search. Returns the entries' edges, or None (nothing written) where an
    edge bounds more than two regions or two consecutive chains have the
    same ends."""
    listings = _first_and_last_listing(firsts)
    if listings is None:
        return None
    chain, first, last = listings
    # A listed chain's block rows are one row of the table seen as (chains, n * texels).
    lines = table.reshape(len(firsts), -1).take(first, axis=0).reshape(len(chain), chain_edges, -1)
    # Two consecutive chains with the same ends (texels 4 and 5 of a
    # chain's first entry, compared as one 64-bit word: equal ids always
    # are) could join into one run: left to _known_region_lines.
    chain_ends = lines.reshape(len(chain), -1).view(np.int64)[:, 2]
    if (chain_ends[1:] == chain_ends[:-1]).any():
        return None
    lines[:, :, 3] = owners.take(first)[:, None]
    lines[:, :, 6] = np.where(first != last, owners.take(last), np.float32(NO_REGION))[:, None]
    arrays.region_lines = lines.reshape(-1, 4)
    # _line_runs of groups of chain_edges entries each.
    count, length = len(chain) * chain_edges, _run_length(chain_edges)
    if chain_edges % length == 0:  # (a subdivision's 2**L: always)
        runs = np.zeros((count // length, 4), np.float32)
        runs[:, 0] = np.arange(0, count, length)
        runs[:, 1] = length
    else:
        within = np.arange(0, chain_edges, length)
        runs = np.zeros((len(chain), len(within), 4), np.float32)
        runs[:, :, 0] = np.arange(0, count, chain_edges)[:, None] + within
        runs[:, :, 1] = np.minimum(length, chain_edges - within)
    arrays.region_line_runs, arrays.region_run_segments = runs.reshape(-1, 4), length
    stats.region_lines = count
    return whole_chains(chain, chain_edges)


def _known_region_lines(
    arrays: MeshArrays, verts, ends, table, seg_ends, seg_owner, edges, stats, classes=None
) -> np.ndarray | None:
    """_region_line_table for the blocks of _select_known_regions (``table``
    its block rows without classes, owners ascending). Where no edge bounds
    more than two regions (a manifold cage) each edge is one entry, its
    region the one that lists it first and its partner the one that lists
    it last: found by two scatters instead of a sort, and its texels are
    its first listing's block texels with the regions filled in; returns
    the entries' edges, for _style_region_lines. Else the general table,
    ``classes`` and all, and None."""
    listings = _first_and_last_listing(edges)
    if listings is None:
        _region_line_table(arrays, verts, classes, ends, np.stack([seg_owner, edges], axis=1), stats)
        return None
    edge, first, last = listings
    region = np.take(seg_owner, first)
    partner = np.where(first != last, np.take(seg_owner, last), -1)
    lines = np.take(table.reshape(-1, TEXELS_PER_SEGMENT * 4), first, axis=0)
    lines[:, 3] = region
    lines[:, 6] = np.where(partner >= 0, partner, NO_REGION)
    arrays.region_lines = lines.reshape(-1, 4)
    style = np.zeros(len(edge), np.int64)
    runs = _line_runs(np.take(seg_ends, first, axis=0), style, region, partner)
    arrays.region_line_runs, arrays.region_run_segments = runs
    stats.region_lines = len(edge)
    return edge


def _style_region_lines(arrays: MeshArrays, classes: np.ndarray, edge: np.ndarray, ends: np.ndarray, stats) -> None:
    """The region lines of _select_known_regions (one unstyled entry per
    ``edge``, ascending) with classes, as _region_line_table lays them out:
    one entry per class of each edge (style k + 1 for class k, style 0
    where it has none), by style, then edge; the runs found again."""
    bits = classes.take(edge)
    if not bits.any():
        return
    style, row, _per_edge = _class_rows(bits)
    if row is None:
        row = np.arange(len(edge))
    order = np.argsort(style.astype(np.uint8), kind="stable")  # (a radix sort on bytes)
    style, row = style.take(order), row.take(order)
    lines = arrays.region_lines.reshape(len(edge), -1).take(row, axis=0)
    lines[:, 2] = style
    arrays.region_lines = lines.reshape(-1, 4)
    chain_ends = np.asarray(ends).take(edge.take(row), axis=0)
    arrays.region_line_runs, arrays.region_run_segments = _line_runs(chain_ends, style, lines[:, 3], lines[:, 6])
    stats.region_lines = len(row)


def _listed_quad_rows() -> np.ndarray:
    """(32 * (_MOST_BLOCK_SEGMENTS + 1),) uint64 indexed by 32 * block segments + 16 *
    split + hidden-edge pattern (see _mark_quad_rows): a listed quad's two
    rows' flags, row 2i in the low 32 bits: the row marks of
    _quad_row_marks applied to a quad row's flags, less what a listed face
    drops (its quad edges are in its block), with its block's bits (the
    segment count, IN_REGION and REGION_LINES) as select_edges sets them."""
    clear_of, marks_of = _quad_row_marks()
    quad_row = EDGE0_REAL | EDGE1_REAL | HAS_QUAD_CORNER
    row = ((quad_row & ~clear_of) | marks_of) & ~LISTED_FACE_DROPS  # indexed by 16 * first corner + pattern
    pattern = np.arange(16)
    # Not split: rows from corners 0 and 2; split: from corners 3 and 1.
    even = np.concatenate([row[pattern], row[48 + pattern]]).astype(np.uint64)
    odd = np.concatenate([row[32 + pattern], row[16 + pattern]]).astype(np.uint64)
    segments = np.arange(_MOST_BLOCK_SEGMENTS + 1, dtype=np.uint64)
    block = (segments << np.uint64(NGON_SHIFT)) | np.uint64(IN_REGION | REGION_LINES)
    both = np.uint64(1 | 1 << 32)
    return ((even | (odd << np.uint64(32)))[None, :] | (block * both)[:, None]).reshape(-1)


# Per combination of class bits: how many classes, and the style of the
# lowest (k + 1 for class k; 0 for none).
_CLASS_COUNT = np.array([b.bit_count() for b in range(1 << len(EDGE_CLASSES))], np.int64)
_LOWEST_STYLE = np.array([(b & -b).bit_length() for b in range(1 << len(EDGE_CLASSES))], np.int64)


def _class_rows(bits: np.ndarray):
    """(style, row, rows per input) for one row per class bit set in
    ``bits`` (its style k + 1 for class k, ascending), one row of style 0
    where no bit is set: ``row`` the input each comes from, or (style,
    None, None) where every input is one row (at most one class each: a
    lookup, no repeat)."""
    per_input = _CLASS_COUNT.take(bits)
    most = int(per_input.max(initial=0))
    if most <= 1:
        return _LOWEST_STYLE.take(bits), None, None
    np.maximum(per_input, 1, out=per_input)
    row = np.repeat(np.arange(len(bits)), per_input)
    rank = np.arange(len(row)) - np.repeat(np.cumsum(per_input) - per_input, per_input)
    left = bits.take(row)
    for dropped in range(most - 1):  # the rank-th class: the lowest once `rank` lower ones are cleared
        np.copyto(left, left & (left - 1), where=rank > dropped)
    return _LOWEST_STYLE.take(left), row, per_input


def _one_per_class(bits: np.ndarray, *columns: np.ndarray):
    """(style, columns repeated) as _class_rows lays the rows out."""
    style, row, _per_input = _class_rows(bits)
    if row is None:
        return style, columns
    return style, tuple(column.take(row, axis=0) for column in columns)


def _region_lines(
    arrays: MeshArrays, verts, classes, ends, label, lines_face, pairs, stats: SelectionStats, measures_own=None
) -> None:
    """The lines of the listed faces (``lines_face``: those of multi-face
    regions and faces with a classed edge) as a table of their own
    (``region_lines``, TEXELS_PER_REGION_LINE texels per entry) and each
    triangle's region (``triangle_regions``, NO_REGION for a plain face,
    OWN_REGION_BASE - label for a face that measures its own edges,
    ``measures_own``). An edge bounding two such regions is one entry naming
    both; a non-manifold edge bounding more is one entry per pair; an edge
    in several classes is one entry per class."""
    value = label.astype(np.float32)
    if measures_own is not None:
        value[measures_own] = OWN_REGION_BASE - value[measures_own]
    region_of_face = np.where(lines_face, value, NO_REGION)
    arrays.triangle_regions = region_of_face.astype(np.float32)[arrays.triangle_polygons]
    keep = lines_face[pairs[:, 0]] if len(pairs) else np.zeros(0, bool)
    _region_line_table(arrays, verts, classes, ends, pairs[keep], stats, None if measures_own is None else value)


def _region_line_table(arrays: MeshArrays, verts, classes, ends, pairs, stats: SelectionStats, value=None) -> None:
    """``region_lines`` and its runs from the (region, drawn edge) pairs of
    the regions whose lines the region-lines pass draws (see _region_lines),
    sorted by region. ``classes`` None: no edge has a class. ``value``: what
    the table names region k by (k itself where None)."""
    if not len(pairs):
        arrays.region_lines = arrays.region_line_runs = None
        return
    listings = _first_and_last_listing(pairs[:, 1])
    if listings is not None:
        # No edge bounds more than two regions (a manifold mesh): its entry
        # names the region that lists it first (the lower, as the pairs are
        # by region) and the one that lists it last. Two scatters, no sort.
        edge, first, last = listings
        region = pairs[:, 0].take(first)
        partner = np.where(first != last, pairs[:, 0].take(last), -1)
    else:
        pairs = pairs[np.lexsort((pairs[:, 0], pairs[:, 1]))]  # by edge, then region
        edge, region = pairs[:, 1], pairs[:, 0]
        start = np.ones(len(edge), bool)
        start[1:] = edge[1:] != edge[:-1]
        first = np.flatnonzero(start)
        rank = np.arange(len(edge)) - np.repeat(first, np.diff(np.append(first, len(edge))))
        # Ranks 0 and 1 of an edge share an entry, then 2 and 3, ...
        head = rank % 2 == 0
        has_partner = np.append(~start[1:], False) & head
        partner = np.where(has_partner, np.append(region[1:], -1), -1)
        edge, region, partner = edge[head], region[head], partner[head]
    # One entry per class of the edge (an edge with no class: one entry).
    bits = np.zeros(len(edge), np.int64) if classes is None else classes[edge]
    style, (edge, region, partner) = _one_per_class(bits, edge, region, partner)
    # By style, then edge: a chain's entries of one class follow each other
    # (_line_runs).
    order = np.argsort(style, kind="stable")
    style, edge, region, partner = style[order], edge[order], region[order], partner[order]
    _write_region_lines(arrays, verts, ends, style, edge, region, partner, stats, value)


def _write_region_lines(
    arrays: MeshArrays, verts, ends, style, edge, region, partner, stats: SelectionStats, value=None
) -> None:
    """``region_lines`` and its runs from its entries in table order: each
    entry's style, edge, region and partner region (-1: none), each region
    named by ``value`` (itself where None)."""
    table = np.zeros((TEXELS_PER_REGION_LINE * len(edge), 4), np.float32)
    edge_verts = np.take(verts, edge, axis=0)
    table[0::2, 0] = np.minimum(edge_verts[:, 0], edge_verts[:, 1])
    table[0::2, 1] = np.maximum(edge_verts[:, 0], edge_verts[:, 1])
    table[0::2, 2] = style
    table[0::2, 3] = region if value is None else value.take(region)
    edge_ends = np.take(ends, edge, axis=0)
    table[1::2, 0], table[1::2, 1] = edge_ends[:, 0], edge_ends[:, 1]
    named_partner = partner if value is None else value.take(np.maximum(partner, 0))
    table[1::2, 2] = np.where(partner >= 0, named_partner, NO_REGION)
    arrays.region_lines = table
    arrays.region_line_runs, arrays.region_run_segments = _line_runs(edge_ends, style, region, partner)
    stats.region_lines = len(edge)


@dataclass
class RegionListing:
    """The triangles of the regions whose lines the region-lines pass
    draws, region by region: fixed with the topology (cache.GPUMesh keeps
    it), so that measuring every region after a move is a gather and a
    reduction (run_bounds)."""

    corner_vertices: np.ndarray  # (3, K) intp: the corners of the listed triangles, region by region
    starts: np.ndarray  # (R,) where each region's triangles start among them
    names: np.ndarray  # (R,) each region's name as the tables name it, ascending


def region_listing(triangle_regions: np.ndarray, corner_vertices: np.ndarray) -> RegionListing:
    """The RegionListing of ``triangle_regions`` (T,) (each triangle's
    region name, NO_REGION for none), ``corner_vertices`` (3, T) intp each
    triangle's corners. A cage look lists every triangle region by region
    already: its listing is ``corner_vertices`` itself."""
    values = np.asarray(triangle_regions)
    listed = values != NO_REGION
    at = None if listed.all() else np.flatnonzero(listed)
    names = values if at is None else values[at]
    if len(names) > 1 and np.any(names[1:] < names[:-1]):
        order = np.argsort(names, kind="stable")
        at = order if at is None else at[order]
        names = names[order]
    corners = corner_vertices if at is None else corner_vertices.take(at, axis=1)
    starts = np.flatnonzero(np.diff(names, prepend=names[0] - 1)) if len(names) else np.zeros(0, np.intp)
    return RegionListing(corners, starts, names[starts])


def run_bounds(listing: RegionListing, positions: np.ndarray, region_lines, region_line_runs) -> np.ndarray:
    """(R, 4) float32: for each run of the region-lines table
    (``region_lines``, ``region_line_runs``) a sphere (centre x, y, z,
    radius) holding every triangle of the run's one or two regions at
    ``positions`` ((N, >= 3) as uploaded; the regions as ``listing`` lists
    them).

    In world widths (image model §4.2) a line is as wide as the visible
    point it lies on is near, and that point can be any point of the
    line's regions, much nearer the camera than the line's own edge. The
    region-lines pass sizes each run's quad by the nearest clip w its
    sphere reaches in the current view (shaders/region_lines_vert.glsl),
    so that no sample the line reaches lies outside the quad. The centre
    is rounded to float32 before the radius is measured, which is then
    rounded up: the float32 sphere holds the regions."""
    first = TEXELS_PER_REGION_LINE * np.asarray(region_line_runs)[:, 0].astype(np.intp)
    bounds = np.zeros((len(first), 4), np.float32)
    names = listing.names
    if not len(names):  # (no triangle in a region: no line shows)
        return bounds
    low, high = boxes_of_triangle_runs(positions, listing.corner_vertices, listing.starts)
    run_low = np.full((len(first), 3), np.inf)
    run_high = np.full((len(first), 3), -np.inf)
    for side in (region_lines[first, 3], region_lines[first + 1, 2]):  # (the entry's region, its partner)
        row = np.minimum(np.searchsorted(names, side), len(names) - 1)
        known = ((side != NO_REGION) & (names[row] == side))[:, None]
        np.minimum(run_low, np.where(known, low[row], np.inf), out=run_low)
        np.maximum(run_high, np.where(known, high[row], -np.inf), out=run_high)
    found = np.isfinite(run_low).all(axis=1)
    centre = (0.5 * (run_low[found] + run_high[found])).astype(np.float32)
    reach = np.maximum(run_high[found] - centre, centre - run_low[found])
    radius = np.sqrt((reach * reach).sum(axis=1)).astype(np.float32)
    bounds[found, :3] = centre
    bounds[found, 3] = np.nextafter(radius, np.float32(np.inf))
    return bounds


def _line_runs(chain_ends: np.ndarray, style: np.ndarray, region: np.ndarray, partner: np.ndarray):
    """((R, 4) float32 runs of the region-lines table: (first entry,
    entries, 0, 0); the most entries a run holds, 1, 2, 4 or 8). A run is
    consecutive entries with the same chain, style and regions, drawn as
    one quad by the region-lines pass. A cage edge's pieces are consecutive
    edges (blender/cage.py), so a chain's entries follow each other in the
    table's edge order. The run length is the power of two that holds the
    chains most entries are in (up to RUN_SEGMENTS): the pass's shader
    carries that many segments to every pixel, which is wasted on the
    single edges of an angle threshold."""
    count = len(style)
    same = np.zeros(count, bool)
    if count > 1:
        same[1:] = (
            (chain_ends[1:, 0] == chain_ends[:-1, 0])
            & (chain_ends[1:, 1] == chain_ends[:-1, 1])
            & (style[1:] == style[:-1])
            & (region[1:] == region[:-1])
            & (partner[1:] == partner[:-1])
        )
    group_start = np.flatnonzero(~same)
    group_size = np.diff(np.append(group_start, count))
    # The group size at which half of the entries are in groups no larger.
    sizes = np.sort(group_size)
    typical = sizes[np.searchsorted(np.cumsum(sizes), count / 2.0)]
    length = _run_length(typical)
    rank = np.arange(count) - np.repeat(group_start, group_size)
    first = np.flatnonzero(rank % length == 0)
    runs = np.zeros((len(first), 4), np.float32)
    runs[:, 0] = first
    runs[:, 1] = np.diff(np.append(first, count))
    return runs, length


def _run_length(typical: int) -> int:
    """The entries a run holds for chains of ``typical`` entries: the
    power of two that holds half a chain (a chain of two: both), up to
    RUN_SEGMENTS (see _line_runs). A chain is a curve, and the quad of a
    whole one is a box around its bend: at subdivision levels 2 and 3 the
    two quads of its halves cover fewer pixels than that box by more than
    a second quad costs (F12 on llvmpipe: 5 % and 2 % faster), and from
    level 4 on a run holds no more than half a chain anyway."""
    half = max(min(typical, 2), typical // 2)
    length = 1
    while length < min(half, RUN_SEGMENTS):
        length *= 2
    return length


def _mark_own_edges(
    arrays: MeshArrays,
    verts: np.ndarray,
    drawn: np.ndarray,
    corner_vert: np.ndarray,
    offsets: np.ndarray,
    sizes: np.ndarray,
    corner_edge: np.ndarray,
) -> None:
    """A triangle's own polygon edges that are not drawn: EDGEk_REAL cleared
    and EDGEk_HIDDEN set (neither a line nor a diagonal); the same for a
    quad's edges to its 4th corner and an n-gon's outline slots."""
    if drawn.all():
        return
    if _mark_quad_rows(arrays, drawn, corner_vert, offsets, corner_edge):
        return
    if _mark_tri_and_quad_rows(arrays, drawn, offsets, sizes, corner_edge):
        return
    _mark_rows_in_faces(arrays, verts, drawn, corner_vert, offsets, sizes, corner_edge)


def _mark_rows_in_faces(
    arrays: MeshArrays,
    verts: np.ndarray,
    drawn: np.ndarray,
    corner_vert: np.ndarray,
    offsets: np.ndarray,
    sizes: np.ndarray,
    corner_edge: np.ndarray,
) -> None:
    """_mark_own_edges for any rows: each row's corners found in its face
    (or, where they are not its face's first four, its edges looked up by
    vertex pair)."""
    vertex_count = np.int64(max(arrays.vertex_count, int(verts.max()) + 1))
    sorted_keys = []  # the hidden edges' vertex-pair keys, sorted on first use

    def hidden_by_key(x, y):
        if not sorted_keys:
            keys = np.minimum(verts[:, 0], verts[:, 1]) * vertex_count + np.maximum(verts[:, 0], verts[:, 1])
            sorted_keys.append(np.sort(keys[~drawn]))
        hidden_keys = sorted_keys[0]
        x, y = x.astype(np.int64), y.astype(np.int64)
        k = np.minimum(x, y) * vertex_count + np.maximum(x, y)
        at = np.minimum(np.searchsorted(hidden_keys, k), len(hidden_keys) - 1)
        return hidden_keys[at] == k

    tri, flags = arrays.triangles, arrays.edge_flags
    # A triangle of a tri or quad runs round its polygon in loop order from
    # some corner (extraction rotates corners, never reflects them), so its
    # edge k is the polygon edge leaving corner (first + k) mod n: found by
    # a few gathers, no search. Other triangles look edges up by vertex pair.
    size = sizes[arrays.triangle_polygons].astype(np.int32)
    start = offsets[arrays.triangle_polygons].astype(np.int32)
    last = len(corner_vert) - 1
    first = _corner_in_polygon(tri[:, 0], start, size, corner_vert)

    def corner(k):
        local = first + np.int32(k)  # < 2 * size: one subtraction wraps it
        local = np.where(local >= size, local - size, local)
        return np.minimum(start + local, last)

    walks = (size <= 4) & (first >= 0) & (corner_vert[corner(1)] == tri[:, 1]) & (corner_vert[corner(2)] == tri[:, 2])
    by_key = np.flatnonzero(~walks)

    hidden_corner = ~drawn[corner_edge]  # per polygon corner: its leaving edge is not drawn

    def hidden(k, i, j):
        """Whether the polygon edge leaving the triangle's corner k (the
        vertex pair i, j) is not drawn."""
        out = walks & hidden_corner[corner(k)]
        if len(by_key):
            out[by_key] = hidden_by_key(tri[by_key, i], tri[by_key, j])
        return out

    for k, (bit, (i, j)) in enumerate(((EDGE0_REAL, (0, 1)), (EDGE1_REAL, (1, 2)), (EDGE2_REAL, (2, 0)))):
        off = ((flags & bit) != 0) & hidden(k, i, j)
        flags[off] = (flags[off] & ~bit) | (EDGE0_HIDDEN << k)
    quad = (flags & HAS_QUAD_CORNER) != 0
    if quad.any():
        flags[quad & hidden(2, 2, 3)] |= EDGE3_HIDDEN  # a quad: p2 -> p3 leaves corner first + 2
        flags[quad & hidden(3, 3, 0)] |= EDGE4_HIDDEN
    hidden = hidden_by_key
    ngon = (flags & IS_NGON) != 0
    if ngon.any():
        blocks = np.unique(np.stack([tri[ngon, 3], flags[ngon] >> NGON_SHIFT], axis=1), axis=0)
        block_start, block_size = blocks[:, 0].astype(np.int64), blocks[:, 1].astype(np.int64)
        local = np.arange(block_size.sum()) - np.repeat(np.cumsum(block_size) - block_size, block_size)
        slot = np.repeat(block_start, block_size) + local
        slot_next = np.repeat(block_start, block_size) + (local + 1) % np.repeat(block_size, block_size)
        marks = np.zeros(len(arrays.ngon_corners), dtype=np.int32)
        marks[slot] = hidden(arrays.ngon_corners[slot], arrays.ngon_corners[slot_next])
        arrays.ngon_hidden = marks


def _mark_quad_rows(
    arrays: MeshArrays, drawn: np.ndarray, corner_vert: np.ndarray, offsets: np.ndarray, corner_edge: np.ndarray
) -> bool:
    """_mark_own_edges for a mesh of quads only (what a subdivision makes)
    whose triangle rows are those extract.build_arrays_fast writes: quad i
    as rows 2i and 2i + 1, starting at its corner 0 and 2, or 3 and 1 where
    the quad is split along its other diagonal. Each row's edges are then
    its quad's corner edges in a known order: a few column picks instead of
    finding every row's corners. False (nothing done) for any other mesh."""
    flip = _quad_row_flip(arrays, corner_vert, offsets)
    if flip is None:
        return False
    flags = arrays.edge_flags
    # Which of its quad's edges are hidden, one bit per corner, and then per
    # row a lookup of that pattern turned to the row's first corner.
    pattern = _hidden_pattern(drawn, corner_edge, len(flip)).astype(np.intp)
    clear_of, marks_of = _ROW_MARKS
    # A row starting at corner r: its edges 0, 1 and its quad edges 3, 4
    # leave corners r, r + 1, r + 2, r + 3.
    for rows, plain, flipped in ((slice(0, None, 2), 0, 3), (slice(1, None, 2), 2, 1)):
        at = np.where(flip, 16 * flipped, 16 * plain) + pattern
        flags[rows] = (flags[rows] & ~clear_of[at]) | marks_of[at]
    return True


def _mark_tri_and_quad_rows(
    arrays: MeshArrays, drawn: np.ndarray, offsets: np.ndarray, sizes: np.ndarray, corner_edge: np.ndarray
) -> bool:
    """_mark_own_edges for a mesh of triangles and quads (no n-gon) whose
    rows are those extract.build_arrays_fast writes, which it says by
    keeping a split per quad (``quad_flip``): a triangle as its row from
    corner 0, a quad as its two rows (see _mark_quad_rows). Each row's
    edges are then its face's corner edges in a known order, so one
    lookup per row of its face's hidden edges turned to its first corner
    marks it, where the general path finds every row's corners among its
    face's. False (nothing done) for any other mesh."""
    flip = arrays.quad_flip
    face_count = len(sizes)
    if (
        flip is None
        or face_count == 0
        or len(arrays.ngon_corners)
        or arrays.triangle_count != int(offsets[-1]) - 2 * face_count
        or sizes.min() < 3
        or sizes.max() > 4
    ):
        return False
    quad_faces = np.flatnonzero(sizes == 4)
    if len(quad_faces) != len(flip):
        return False
    # Which of its face's edges are hidden, one bit per corner (the edge
    # leaving it): every face has corners 0-2, a quad corner 3 too.
    hidden_corner = np.take(drawn, corner_edge)
    np.logical_not(hidden_corner, out=hidden_corner)
    hidden_corner = hidden_corner.view(np.uint8)
    start = offsets[:-1]
    pattern = hidden_corner.take(start)
    pattern |= hidden_corner.take(start + 1) << np.uint8(1)
    pattern |= hidden_corner.take(start + 2) << np.uint8(2)
    pattern[quad_faces] |= hidden_corner.take(start.take(quad_faces) + 3) << np.uint8(3)
    # Each row's entry of the lookup: 16 * its first corner for a quad's
    # rows (corners 0 and 2, or 3 and 1 where split the other way),
    # _TRIANGLE_ROWS for a triangle's; plus its face's pattern.
    row_base = np.full(arrays.triangle_count, _TRIANGLE_ROWS, np.uint8)
    quad_row = start.take(quad_faces) - 2 * quad_faces  # a face's first row (build_arrays_fast)
    row_base[quad_row] = np.where(flip, np.uint8(48), np.uint8(0))
    row_base[quad_row + 1] = np.where(flip, np.uint8(16), np.uint8(32))
    row_base += pattern.take(arrays.triangle_polygons)
    clear_of, marks_of = _ROW_MARKS
    flags = arrays.edge_flags
    flags &= ~clear_of.take(row_base)
    flags |= marks_of.take(row_base)
    return True


def _quad_row_flip(arrays: MeshArrays, corner_vert: np.ndarray, offsets: np.ndarray) -> np.ndarray | None:
    """(F,) bool for a mesh of quads only (``offsets``: its F + 1 face
    offsets) whose triangle rows are those extract.build_arrays_fast writes
    (see _mark_quad_rows): True where the quad is split along its other
    diagonal. None for any other mesh."""
    face_count = len(offsets) - 1
    if face_count <= 0 or arrays.triangle_count != 2 * face_count:
        return None
    known = arrays.quad_flip
    if known is not None and len(known) == face_count:
        # build_arrays_fast keeps a split per quad for a mesh without
        # n-gons: one per face is a mesh of quads only, its rows as it says.
        return known
    sizes = np.diff(offsets)
    if sizes.min() != 4 or sizes.max() != 4:
        return None
    tri, flags = arrays.triangles, arrays.edge_flags
    quad = np.asarray(corner_vert).reshape(face_count, 4)
    even, odd = tri[0::2], tri[1::2]
    flip = even[:, 0] != quad[:, 0]
    faces = np.arange(face_count, dtype=arrays.triangle_polygons.dtype)
    if not (
        np.array_equal(arrays.triangle_polygons[0::2], faces)
        and np.array_equal(arrays.triangle_polygons[1::2], faces)
        and np.array_equal(even[:, 0], np.where(flip, quad[:, 3], quad[:, 0]))
        and np.array_equal(even[:, 1], np.where(flip, quad[:, 0], quad[:, 1]))
        and np.array_equal(odd[:, 0], np.where(flip, quad[:, 1], quad[:, 2]))
        and (
            (flags & (EDGE0_REAL | EDGE1_REAL | HAS_QUAD_CORNER | IS_NGON))
            == (EDGE0_REAL | EDGE1_REAL | HAS_QUAD_CORNER)
        ).all()
    ):
        return None
    return flip


def _drawn_prefix(drawn: np.ndarray) -> tuple[int, bool]:
    """(how many edges are drawn, whether they are the first ones: a
    subdivision's cage children)."""
    count = int(np.count_nonzero(drawn))
    return count, bool(drawn[:count].all())


def _corner_drawn(drawn: np.ndarray, corner_edge: np.ndarray, prefix: tuple[int, bool] | None = None) -> np.ndarray:
    """(L,) bool, a fresh array: whether each corner's edge is drawn.
    ``prefix``: _drawn_prefix's answer when the caller has it."""
    drawn = np.asarray(drawn, bool)
    count, first = _drawn_prefix(drawn) if prefix is None else prefix
    if first:  # the drawn edges come first: a compare, no gather
        return np.asarray(corner_edge) < count
    return np.take(drawn, corner_edge)


def _hidden_pattern(
    drawn: np.ndarray, corner_edge: np.ndarray, face_count: int, corner_drawn: np.ndarray | None = None
) -> np.ndarray:
    """(F,) uint32 for a mesh of quads only: bit c set where the edge leaving
    the quad's corner c is not drawn. The four corners' drawn flags are one
    little-endian 32-bit word of 0/1 bytes; one multiplication gathers their
    bits into the top byte (no partial product carries into it).
    ``corner_drawn``: _corner_drawn's answer when the caller has it (it is
    written over)."""
    if corner_drawn is None:
        corner_drawn = _corner_drawn(drawn, corner_edge)
    if not np.little_endian:
        hidden = ~corner_drawn.reshape(face_count, 4)
        return (hidden * np.array([1, 2, 4, 8], np.uint32)).sum(axis=1, dtype=np.uint32)
    words = corner_drawn.view(np.uint32)  # a fresh array: changed in place
    words ^= np.uint32(0x01010101)
    words *= np.uint32(0x01020408)
    words >>= np.uint32(24)
    return words


def _quad_row_marks():
    """(clear, marks), each (64 + 8,) int32 indexed by 16 * r + p: the flag
    bits _mark_quad_rows clears and sets on a row starting at its quad's
    corner r whose quad has the hidden edges p (bit c: the edge leaving
    corner c); from _TRIANGLE_ROWS on, indexed by _TRIANGLE_ROWS + p, those
    of a triangle's row (which starts at its corner 0) with the hidden
    edges p."""
    r, p = np.divmod(np.arange(64), 16)
    h = [(p >> ((r + k) % 4)) & 1 for k in range(4)]
    clear = h[0] * EDGE0_REAL | h[1] * EDGE1_REAL
    marks = h[0] * EDGE0_HIDDEN | h[1] * (EDGE0_HIDDEN << 1) | h[2] * EDGE3_HIDDEN | h[3] * EDGE4_HIDDEN
    t = [(np.arange(8) >> k) & 1 for k in range(3)]
    tri_clear = t[0] * EDGE0_REAL | t[1] * EDGE1_REAL | t[2] * EDGE2_REAL
    tri_marks = t[0] * EDGE0_HIDDEN | t[1] * (EDGE0_HIDDEN << 1) | t[2] * (EDGE0_HIDDEN << 2)
    return (
        np.concatenate([clear, tri_clear]).astype(np.int32),
        np.concatenate([marks, tri_marks]).astype(np.int32),
    )


_TRIANGLE_ROWS = 64  # where _quad_row_marks' entries for a triangle's row start


# The most segments a region's block holds: WALK_LIMIT drawn edges (a larger
# region's faces get blocks of their own), each once per class.
_MOST_BLOCK_SEGMENTS = WALK_LIMIT * len(EDGE_CLASSES)
# Computed once: the lookup _select_known_regions writes quad rows from.
_LISTED_QUAD_ROWS = _listed_quad_rows()
_ROW_MARKS = _quad_row_marks()


def _corner_in_polygon(vertex, start, size, corner_vert) -> np.ndarray:
    """Where ``vertex`` sits among the first four corners of each row's
    polygon (``start``, ``size``), -1 where it is not one of them."""
    local = np.full(len(vertex), -1, np.int32)
    last = len(corner_vert) - 1
    for j in range(3, -1, -1):  # the first match wins (a corrupt face repeats a vertex)
        at = (j < size) & (corner_vert[np.minimum(start + j, last)] == vertex)
        local[at] = j
    return local


def _ngon_diagonals(arrays: MeshArrays, owner: np.ndarray):
    """(owner, lower id, upper id) of every diagonal of the listed n-gons."""
    flags = arrays.edge_flags
    ngon = ((flags & IS_NGON) != 0) & (owner[arrays.triangle_polygons] >= 0)
    empty = np.zeros(0, np.int64)
    if not ngon.any():
        return empty, empty, empty
    polys, first = np.unique(arrays.triangle_polygons[ngon], return_index=True)
    rows = np.flatnonzero(ngon)[first]
    start = arrays.triangles[rows, 3].astype(np.int64)
    size = (flags[rows] >> NGON_SHIFT).astype(np.int64)
    diagonals = size - 3
    poly_of = np.repeat(np.arange(len(polys)), diagonals)
    rank = np.arange(diagonals.sum()) - np.repeat(np.cumsum(diagonals) - diagonals, diagonals)
    slot = start[poly_of] + size[poly_of] + 2 * rank
    a = arrays.ngon_corners[slot].astype(np.int64)
    b = arrays.ngon_corners[slot + 1].astype(np.int64)
    keep = a != b  # a degenerate placeholder pair (fewer diagonals than n - 3)
    return owner[polys[poly_of]][keep], np.minimum(a, b)[keep], np.maximum(a, b)[keep]


def flat_edges(
    corner_edge: np.ndarray, face_offsets: np.ndarray, face_normals: np.ndarray, edge_count: int, angle: float
) -> np.ndarray:
    """(E,) True for an edge of exactly two distinct faces whose face normals
    differ by less than ``angle`` radians (the edge angle, §3.4)."""
    flat = np.zeros(edge_count, bool)
    if not angle > 0.0 or edge_count == 0:
        return flat
    edges, f1, f2 = _face_pairs(corner_edge, face_offsets, edge_count)
    flat[edges] = _pairs_flat(face_normals, f1, f2, angle)
    return flat


def _face_pairs(corner_edge: np.ndarray, face_offsets: np.ndarray, edge_count: int, candidates=None):
    """(edge ids, first face, second face) of every edge with exactly two
    face corners (among ``candidates``, an (E,) mask, where given), by
    edge; the first face is its lower corner's. Only the corners of those
    edges are looked at: beside a cage mask, a fraction of the mesh's."""
    corner_edge = np.asarray(corner_edge, np.int64)
    offsets = np.asarray(face_offsets, np.int64)
    at = None if candidates is None else np.flatnonzero(_corner_drawn(candidates, corner_edge))
    edge_of = corner_edge if at is None else corner_edge.take(at)
    uses = np.bincount(edge_of, minlength=edge_count)  # all of a candidate's corners are candidates
    edges = np.flatnonzero(uses == 2)
    # Each edge's lower and higher corner by two scatters (the last write
    # wins: written backwards, it is the lower one's), no sort.
    listing = np.arange(len(edge_of), dtype=np.int64)
    lower = np.empty(edge_count, np.int64)
    lower[edge_of[::-1]] = listing[::-1]
    higher = np.empty(edge_count, np.int64)
    higher[edge_of] = listing
    first, second = lower.take(edges), higher.take(edges)
    if at is not None:
        first, second = at.take(first), at.take(second)
    face_count = len(offsets) - 1
    sizes = offsets[1:] - offsets[:-1]
    if face_count > 0 and offsets[-1] == 4 * face_count and (sizes == 4).all():
        return edges, first >> 2, second >> 2  # quads only (a subdivision): no search
    if 8 * len(edges) < len(corner_edge):  # few corners: a search each
        return (
            edges,
            np.searchsorted(offsets, first, side="right") - 1,
            np.searchsorted(offsets, second, side="right") - 1,
        )
    corner_face = _face_of_corner(sizes)
    return edges, corner_face.take(first), corner_face.take(second)


def _pairs_flat(face_normals: np.ndarray, f1: np.ndarray, f2: np.ndarray, angle: float) -> np.ndarray:
    """Whether the faces of each pair are distinct and their normals differ
    by less than ``angle`` radians, in float64.

    The angle between two normals is under ``angle`` exactly where the
    cosine of the angle is above cos(angle) (for angles up to pi; every
    angle is under a larger one), so no arccos is taken. The cosine is the
    dot product of unit normals. Where the pairs outnumber the faces, each
    face's normal is made unit length once; for a few pairs (an edit's
    rows) only their faces are read. Both give the same bits (the same
    element-wise arithmetic), so an edit's answer is the full test's. Each
    component is gathered as its own 1-D array: a fancy index into (F, 3)
    rows costs several times more. A zero normal has cosine 0 with
    anything (90 degrees)."""
    face_normals = np.asarray(face_normals)
    f1, f2 = np.asarray(f1, np.int64), np.asarray(f2, np.int64)
    cosine = np.zeros(len(f1))
    if len(f1) > len(face_normals):
        for column in _unit_components(face_normals):
            cosine += column.take(f1) * column.take(f2)
    else:
        for first, second in zip(_unit_components(face_normals, f1), _unit_components(face_normals, f2)):
            cosine += first * second
    threshold = np.cos(angle) if angle <= np.pi else -np.inf
    # Parallel normals are 0 degrees apart, under any positive angle, also
    # one so small (under about 1e-7 radians) that its cosine is within the
    # few units of rounding of a float64 cosine of parallel unit vectors.
    parallel = cosine >= 1.0 - 4 * np.finfo(np.float64).eps
    return ((cosine > threshold) | (parallel & (angle > 0.0))) & (f1 != f2)


def _unit_components(face_normals: np.ndarray, faces: np.ndarray | None = None) -> list:
    """The x, y and z of the unit normals (float64) of every face, or of
    ``faces`` only: the same values either way."""
    columns = [
        (face_normals[:, k] if faces is None else face_normals[:, k].take(faces)).astype(np.float64) for k in range(3)
    ]
    length = np.maximum(np.sqrt(columns[0] * columns[0] + columns[1] * columns[1] + columns[2] * columns[2]), 1e-300)
    for column in columns:
        column /= length
    return columns


class EdgeAngleState:
    """What one extraction's edge angle test keeps so that a move of
    vertices (same faces) is checked incrementally: the two faces of each
    tested edge, the face normals it saw and the flat edges it found.
    :meth:`still_flat` recomputes only the edges next to a face whose
    normal changed, with the same arithmetic as :func:`flat_edges`, so its
    answer is the full test's. ``candidates``: the only edges whose
    flatness counts (the cage look's drawn edges: the angle can hide no
    other), where given; the others are neither tested nor flat."""

    def __init__(self, corner_edge, face_offsets, face_normals, edge_count: int, angle: float, candidates=None):
        self.angle = float(angle)
        pairs = _face_pairs(corner_edge, face_offsets, edge_count, candidates)
        self.tested, self.first, self.second = (ids.astype(np.int32) for ids in pairs)  # kept per mesh: half the memory
        self.normals = np.array(face_normals, np.float32)
        self.flat = np.zeros(edge_count, bool)
        if self.angle > 0.0 and edge_count:
            self.flat[self.tested] = _pairs_flat(self.normals, self.first, self.second, self.angle)

    def still_flat(self, face_normals) -> bool:
        """Whether the same edges are flat under ``face_normals`` (the same
        faces after a move). True: the new normals are kept for the next
        move. False: some edge crossed the angle (its regions change)."""
        face_normals = np.asarray(face_normals, np.float32)
        if face_normals.shape != self.normals.shape:
            return False
        changed = face_normals != self.normals
        turned = changed[:, 0] | changed[:, 1] | changed[:, 2]
        if not turned.any():
            return True
        rows = np.flatnonzero(turned[self.first] | turned[self.second])
        if len(rows):
            flat = _pairs_flat(face_normals, self.first[rows], self.second[rows], self.angle)
            if not np.array_equal(flat, self.flat[self.tested[rows]]):
                return False
        self.normals = face_normals.copy()
        return True


@dataclass(frozen=True)
class Selection:
    """What decides the drawn edges and their styles for one mesh (hashable:
    part of the GPU cache key)."""

    edge_angle: float = 0.0
    classes: tuple = ()  # enabled classes, names from EDGE_CLASSES
    use_cage: bool = False  # the caller passes the cage mask

    @property
    def active(self) -> bool:
        return self.edge_angle > 0.0 or bool(self.classes) or self.use_cage

    @property
    def follows_positions(self) -> bool:
        """Whether moving vertices can change which edges are drawn: the
        edge angle compares face normals (a move is checked against the
        extraction's EdgeAngleState). Classes (marks, boundary) and cage
        edges depend on the topology alone, so the selection of a deforming
        mesh stays as extracted."""
        return self.edge_angle > 0.0
