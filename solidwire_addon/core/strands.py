"""Hair (Curves objects) and point clouds in SolidWire's look
(docs/user/hair-and-points.md).

Plain numpy in, GPU draws out; nothing here reads Blender data
(blender/strands.py turns a depsgraph's Curves and PointCloud instances into
:class:`StrandItem`).

* A strand is a polyline (a Catmull-Rom curve evaluated as Blender does, a
  poly curve as is). Each segment is a screen-space quad; the fragment stage
  measures the exact window distance d to the near-clipped segment and draws
  I = P(d) with half-width max(h, projected radius), in the wire's colour.
* A point is a disc of its projected radius: its outline is
  P(|distance to the rim|) in the wire's colour; inside, the fill colour
  (Fill on) or nothing (Fill off; the disc still hides what is behind it).

Both are hidden by nearer mesh surfaces. In a render they go into targets of
their own, where per pixel the primitive with the largest weight (I, or 1
inside a disc) wins, nearest on ties, so the segments of one strand join
without a seam; that layer is then composited "over" the mesh passes and its
covered pixels (weight >= 1/2) enter the Depth pass. In the viewport overlay
they blend "over" the viewport straight away, under its depth buffer.
"""

from __future__ import annotations

import zlib
from dataclasses import dataclass, replace

import gpu
import numpy as np

from . import colors, matcaps, shaders
from .cache import table_texture
from .draw import (
    DrawTarget,
    bind_display_transform,
    clip_space_planes,
    indexed_quad_batch,
    params_block,
    shader_variant,
    styled,
)
from .extract import drawable
from .log import one_line, warn_once
from .targets import read_texture
from .view import determinant3, line_reach, outside_frustum_many, translation

CURVES, POINTS = "curves", "points"

# Blender's curve types (the ``curve_type`` attribute).
CATMULL_ROM, POLY, BEZIER, NURBS = 0, 1, 2, 3
DEFAULT_RESOLUTION = 12  # Blender's default of the ``resolution`` attribute


@dataclass
class StrandGeometry:
    """One evaluated Curves or PointCloud datablock, ready to upload.

    ``points`` (N, 4) float32: position relative to ``centre`` (float64; the
    draw composes the translation in float64 so large coordinates keep their
    precision) and radius; ``bounds_min``/``bounds_max`` the box of those
    positions, ``radius_max`` the largest radius (object units).
    ``segments`` (S, 4) float32 rows (i0, i1, previous, next) of point
    indices (curves only): the segment's ends and the points before i0 and
    after i1 along the strand (-1: none), which the overlay uses to decide
    which of the two segments at a joint paints a pixel."""

    kind: str
    points: np.ndarray
    segments: np.ndarray | None
    centre: np.ndarray
    bounds_min: np.ndarray
    bounds_max: np.ndarray
    radius_max: float
    dropped: int = 0  # points left out for a non-finite position or radius
    _textures: tuple | None = None

    @property
    def count(self) -> int:
        """Primitives drawn: segments of a strand, points of a cloud."""
        return len(self.segments) if self.kind == CURVES else len(self.points)

    def textures(self):
        """(point table, segment table or None), uploaded on first use."""
        if self._textures is None:
            segments = table_texture(self.segments) if self.kind == CURVES else None
            self._textures = (table_texture(self.points), segments)
        return self._textures


@dataclass
class StrandItem:
    """One drawn Curves or PointCloud instance."""

    geometry: StrandGeometry
    matrix: np.ndarray  # (4, 4) float64 object -> world
    style: object = None  # core.view.Style (the object's override) or None
    source: object = None  # core.colors.ItemSource (colour sources) or None
    name: str = ""


# -- extraction (numpy) --------------------------------------------------------------


def catmull_rom(points: np.ndarray, resolution: int, cyclic: bool) -> np.ndarray:
    """A uniform Catmull-Rom curve through ``points`` (..., n, k) sampled
    ``resolution`` times per segment, as Blender evaluates its CATMULL_ROM
    curves: every control point is on the curve, an open curve's end
    segments extrapolate a neighbour (2 p_0 - p_1), and the last point is
    appended (the first again for a closed curve). Leading axes are curves
    of the same size, evaluated at once."""
    points = np.asarray(points, dtype=np.float64)
    n = points.shape[-2]
    resolution = max(int(resolution), 1)
    if n < 2:
        return points.copy()
    if cyclic:
        ext = np.concatenate([points[..., -1:, :], points, points[..., :2, :]], axis=-2)
        segments = n
    else:
        ext = np.concatenate(
            [2.0 * points[..., :1, :] - points[..., 1:2, :], points, 2.0 * points[..., -1:, :] - points[..., -2:-1, :]],
            axis=-2,
        )
        segments = n - 1
    t = np.arange(resolution, dtype=np.float64) / resolution
    t2, t3 = t * t, t * t * t
    weights = (
        0.5 * (-t3 + 2.0 * t2 - t),
        0.5 * (3.0 * t3 - 5.0 * t2 + 2.0),
        0.5 * (-3.0 * t3 + 4.0 * t2 + t),
        0.5 * (t3 - t2),
    )
    i = np.arange(segments)
    out = sum(w[:, None] * ext[..., i + k, None, :] for k, w in enumerate(weights))  # (..., segments, res, k)
    out = out.reshape(*points.shape[:-2], segments * resolution, points.shape[-1])
    return np.concatenate([out, points[..., :1, :] if cyclic else points[..., -1:, :]], axis=-2)


def _chain(n: int, closed: bool, wrapped: bool) -> np.ndarray:
    """(S, 4) rows (i0, i1, previous, next) of a polyline of n points (-1:
    no neighbour); ``closed`` adds the segment back to the first point,
    ``wrapped`` says the last point is the first one again."""
    a = np.arange(n - 1)
    seg = np.stack([a, a + 1, a - 1, a + 2], axis=1)
    seg[-1, 3] = -1
    if closed:
        seg = np.concatenate([seg, [[n - 1, 0, n - 2, 1]]])
        seg[0, 2], seg[-2, 3] = n - 1, 0
    elif wrapped and n > 2:
        seg[0, 2], seg[-1, 3] = n - 2, 1
    return seg


def _finish(kind, values: np.ndarray, segments: np.ndarray | None, dropped: int) -> StrandGeometry | None:
    """(N, 4) float64 positions + radius -> StrandGeometry (None: empty)."""
    if not len(values) or (segments is not None and not len(segments)):
        return None
    lo, hi = values[:, :3].min(axis=0), values[:, :3].max(axis=0)
    centre = 0.5 * (lo + hi)
    rows = values.copy()
    rows[:, :3] -= centre
    rows = rows.astype(np.float32)
    seg_rows = None
    if segments is not None:
        seg_rows = np.asarray(segments, dtype=np.float32)
    radius_max = float(np.max(values[:, 3], initial=0.0))
    return StrandGeometry(kind, rows, seg_rows, centre, lo - centre, hi - centre, radius_max, dropped)


def bezier(points: np.ndarray, left: np.ndarray, right: np.ndarray, resolution: int, cyclic: bool) -> np.ndarray:
    """Cubic Bezier segments through ``points`` (..., n, 4: position and
    radius) with handles ``left`` / ``right`` (..., n, 3), ``resolution``
    samples per segment, as Blender evaluates BEZIER curves: segment i runs
    p_i, right_i, left_(i+1), p_(i+1); the radius goes linearly from p_i to
    p_(i+1). The last point is appended (the first again when closed)."""
    points = np.asarray(points, dtype=np.float64)
    n = points.shape[-2]
    resolution = max(int(resolution), 1)
    nxt = np.r_[np.arange(1, n), 0] if cyclic else np.arange(1, n)
    cur = np.arange(len(nxt))
    t = (np.arange(resolution, dtype=np.float64) / resolution)[:, None]
    s_ = 1.0 - t
    p0, p3 = points[..., cur, None, :3], points[..., nxt, None, :3]
    p1, p2 = np.asarray(right, np.float64)[..., cur, None, :], np.asarray(left, np.float64)[..., nxt, None, :]
    xyz = s_**3 * p0 + 3.0 * s_ * s_ * t * p1 + 3.0 * s_ * t * t * p2 + t**3 * p3
    r = points[..., cur, None, 3:] * s_ + points[..., nxt, None, 3:] * t
    out = np.concatenate([xyz, r], axis=-1).reshape(*points.shape[:-2], len(cur) * resolution, 4)
    return np.concatenate([out, points[..., :1, :] if cyclic else points[..., -1:, :]], axis=-2)


def curves_geometry(
    positions, radius=None, offsets=None, curve_types=None, resolutions=None, cyclic=None, handles=None
) -> StrandGeometry | None:
    """Strands of a Curves datablock: ``positions`` (P, 3) control points,
    ``radius`` (P,) (None: 0), ``offsets`` (C + 1,) first point of each
    curve, per curve ``curve_types``, ``resolutions`` and ``cyclic`` (None:
    Blender's defaults, Catmull-Rom at 12), ``handles`` (left, right) (P, 3)
    each, or None. Catmull-Rom curves and Bezier curves with handles are
    evaluated (positions and radius alike); other types draw their control
    polygon. A segment with an end that is not drawable (extract.drawable)
    is left out. None when nothing is left."""
    positions = np.asarray(positions, dtype=np.float64).reshape(-1, 3)
    count = len(positions)
    radius = np.zeros(count) if radius is None else np.asarray(radius, dtype=np.float64).reshape(-1)
    offsets = np.array([0, count]) if offsets is None else np.asarray(offsets, dtype=np.int64)
    curve_count = len(offsets) - 1
    values = np.concatenate([positions, radius[:, None]], axis=1)
    sizes = np.diff(offsets)
    kinds = np.full(curve_count, CATMULL_ROM) if curve_types is None else np.asarray(curve_types, np.int64)
    res = (
        np.full(curve_count, DEFAULT_RESOLUTION)
        if resolutions is None
        else np.maximum(np.asarray(resolutions, np.int64), 1)
    )
    closed = np.zeros(curve_count, bool) if cyclic is None else np.asarray(cyclic, bool)
    # How each curve is evaluated: 1 Catmull-Rom, 2 Bezier, 0 its control polygon.
    method = np.where((kinds == CATMULL_ROM) & (sizes >= 2), 1, 0)
    if handles is not None:
        method = np.where((kinds == BEZIER) & (sizes >= 2), 2, method)
    res = np.where(method > 0, res, 0)  # (not a key for the other types)
    # Curves of one size, method, resolution and closure are evaluated at
    # once (hair: usually one group for the whole datablock).
    keys = np.stack([sizes, method, res, closed], axis=1)
    groups, group_of = np.unique(keys, axis=0, return_inverse=True)
    parts, segments = [], []
    total, dropped = 0, 0
    for g, (n, how, resolution, is_closed) in enumerate(groups):
        members = np.nonzero(group_of.reshape(-1) == g)[0]
        rows = offsets[members][:, None] + np.arange(n)[None, :]
        control = values[rows]  # (m, n, 4)
        if how:
            # A point that is not drawable spreads NaN and Inf to the
            # evaluated points near it (Inf * 0): expected, and those are
            # left out below, so numpy's warning would only reach Blender's
            # console.
            with np.errstate(invalid="ignore", over="ignore"):
                if how == 1:
                    evaluated = catmull_rom(control, int(resolution), bool(is_closed))
                else:
                    left, right = (np.asarray(h, dtype=np.float64).reshape(-1, 3)[rows] for h in handles)
                    evaluated = bezier(control, left, right, int(resolution), bool(is_closed))
            chain = _chain(evaluated.shape[1], False, bool(is_closed)) if evaluated.shape[1] >= 2 else None
        else:
            evaluated = control
            chain = _chain(int(n), bool(is_closed) and n > 2, False) if n >= 2 else None
        m, e = evaluated.shape[:2]
        parts.append(evaluated.reshape(-1, 4))
        if chain is not None:
            good = drawable(evaluated, axis=2)  # (m, e): positions and radius, as a mesh's vertices (§2.1)
            dropped += int((~good).sum())
            base = total + e * np.arange(m)[:, None, None]
            seg = np.where(chain[None] >= 0, chain[None] + base, -1)  # (m, S, 4)
            # A segment with an end that is not drawable is left out; such
            # a neighbour is no neighbour.
            flat_good = good.reshape(-1)
            ends_ok = flat_good[seg[..., 0] - total] & flat_good[seg[..., 1] - total]
            for column in (2, 3):
                has = seg[..., column] >= 0
                ok = np.where(has, flat_good[np.maximum(seg[..., column] - total, 0)], False)
                seg[..., column] = np.where(ok, seg[..., column], -1)
            segments.append(seg[ends_ok])
        total += m * e
    if not parts:
        return None
    values = np.concatenate(parts)
    segments = np.concatenate(segments) if segments else np.zeros((0, 4), np.int64)
    # Points no kept segment uses (non-finite ones among them) stay out of
    # the bounds: renumber the used ones (a neighbour no segment uses
    # becomes -1).
    used = np.zeros(len(values), bool)
    used[segments[:, :2].ravel()] = True
    new_index = np.where(used, np.cumsum(used) - 1, -1)
    renumbered = np.where(segments >= 0, new_index[np.maximum(segments, 0)], -1)
    return _finish(CURVES, values[used], renumbered, dropped)


def points_geometry(positions, radius=None) -> StrandGeometry | None:
    """Discs of a PointCloud: ``positions`` (P, 3), ``radius`` (P,) (None:
    0). A point whose position or radius is not drawable (extract.drawable) is
    left out."""
    positions = np.asarray(positions, dtype=np.float64).reshape(-1, 3)
    radius = np.zeros(len(positions)) if radius is None else np.asarray(radius, dtype=np.float64).reshape(-1)
    values = np.concatenate([positions, radius[:, None]], axis=1)
    good = drawable(values, axis=1)
    return _finish(POINTS, values[good], None, int((~good).sum()))


class GeometryCache:
    """Evaluated strands and points (with their uploaded tables) by the
    content they were made from, so an unchanged datablock is neither
    evaluated nor uploaded again on the next frame or redraw. Keyed by a
    fingerprint of the inputs (counts and CRC-32 of every array), so a
    stale entry can never be drawn; the least recently used entries go
    beyond ``size``."""

    def __init__(self, size: int = 32):
        self.size = size
        self.entries: dict = {}
        self.hits = self.misses = 0

    @staticmethod
    def fingerprint(kind: str, *arrays) -> tuple:
        return (
            kind,
            *(
                (None if a is None else (a.shape, str(a.dtype), zlib.crc32(np.ascontiguousarray(a).view(np.uint8))))
                for a in arrays
            ),
        )

    def get(self, key, make):
        """The geometry of ``key`` (a fingerprint), made by ``make()`` when
        new (None is remembered too)."""
        if key in self.entries:
            self.hits += 1
            geometry = self.entries.pop(key)
        else:
            self.misses += 1
            geometry = make()
        self.entries[key] = geometry  # most recent last
        while len(self.entries) > self.size:
            del self.entries[next(iter(self.entries))]
        return geometry

    def clear(self) -> None:
        self.entries.clear()


geometry_cache = GeometryCache()


# -- drawing ---------------------------------------------------------------------


class _Targets:
    """The render's strand layer: colour, (view depth, weight) and a depth
    buffer holding the winner key, one set per size."""

    def __init__(self, size):
        self.size = size
        self.color = gpu.types.GPUTexture(size, format="RGBA32F")
        self.info = gpu.types.GPUTexture(size, format="RGBA32F")
        self.depth = gpu.types.GPUTexture(size, format="DEPTH_COMPONENT32F")


_targets: list = []


def _targets_for(width: int, height: int) -> _Targets:
    if not _targets or _targets[0].size != (width, height):
        _targets.clear()  # free the old textures first
        _targets.append(_Targets((width, height)))
    return _targets[0]


def release() -> None:
    """Drop every GPU object of this module (add-on unregister)."""
    _targets.clear()
    geometry_cache.clear()


def _radius_scale(matrix: np.ndarray) -> float:
    """Scene units per object unit of a radius: the cube root of the
    object's volume scale (a uniform scale exactly)."""
    det = abs(float(determinant3(matrix[:3, :3])))
    return det ** (1.0 / 3.0) if np.isfinite(det) else 0.0


def _draw(items, view, settings, target: DrawTarget, scene_depth=None) -> int:
    """Draw ``items`` into the bound framebuffer (the caller sets blending
    and the depth test) as ``target`` describes: the overlay form with a
    depth bias (its display transform and clipping region too), else the
    render form over ``scene_depth``. Returns the number of items drawn."""
    overlay_bias = target.depth_bias
    variant = shader_variant(settings, target)
    if not overlay_bias:
        variant = replace(variant, display_transform=False, clip_planes=False)
    matcap = None
    if variant.shading == shaders.SHADING_MATCAP:
        matcap = matcaps.texture(settings.matcap)
        if matcap is None:
            variant = replace(variant, shading=shaders.SHADING_FLAT)
    clip_block = None
    if variant.clip_planes:
        rows = clip_space_planes(target.clip_planes, view)
        clip_block = gpu.types.GPUUniformBuf(np.asarray(rows, dtype=np.float32).tobytes())
    px_per_unit = 0.5 * float(view.viewport[3]) * abs(float(view.projection[1][1]))
    blocks: dict = {}
    drawn = 0
    for kind in (CURVES, POINTS):
        shader = None
        for item in items:
            geometry = item.geometry
            if geometry.kind != kind or geometry.count == 0:
                continue
            object_to_view = view.view_matrix @ item.matrix @ translation(geometry.centre)
            object_to_clip = view.projection @ object_to_view
            radius_scale = _radius_scale(item.matrix)
            # A line reaches past its points by its width and, in any
            # direction whatever the object's scale, by its radius (pixels
            # at clip w = 1): the vertex stage's quads (strand_vert.glsl).
            reach = line_reach(styled(settings, item.style), view, geometry.radius_max * radius_scale * px_per_unit)
            if outside_frustum_many(object_to_clip[None], geometry.bounds_min, geometry.bounds_max, reach)[0]:
                continue
            if shader is None:
                shader = shaders.get_strand(kind == POINTS, variant, overlay_bias)
                shader.bind()
                if overlay_bias:
                    if variant.display_transform:
                        bind_display_transform(shader, target.display)
                    if clip_block is not None:
                        shader.uniform_block("clip_params", clip_block)
                else:
                    shader.uniform_sampler("scene_depth", scene_depth)
                if kind == POINTS and matcap is not None and variant.use_fill:
                    shader.uniform_sampler("matcap_image", matcap)
            key = (item.style, item.source)
            block = blocks.get(key)
            if block is None:
                item_settings = styled(settings, item.style)
                wire, fill, _materials = colors.item_colors(item.source, item_settings)
                item_settings = replace(
                    item_settings, wire_color=(*wire, item_settings.wire_color[3]), fill_color=tuple(fill)
                )
                block = blocks[key] = gpu.types.GPUUniformBuf(params_block(item_settings, view, target))
            shader.uniform_block("params", block)
            shader.uniform_float("object_to_clip", object_to_clip.T.astype(np.float32).ravel().tolist())
            shader.uniform_float("object_to_view_z", object_to_view[2].astype(np.float32).tolist())
            shader.uniform_float("strand_view", [px_per_unit, radius_scale, 0.0, 0.0])
            point_table, segment_table = geometry.textures()
            shader.uniform_sampler("vertex_positions", point_table)
            if segment_table is not None:
                shader.uniform_sampler("strand_segments", segment_table)
            indexed_quad_batch(geometry.count).draw_range(shader, elem_start=0, elem_count=6 * geometry.count)
            drawn += 1
    return drawn


def composite_render(rgba, depth, surface_targets, view, settings, items):
    """The render's strand layer over ``rgba`` (premultiplied, (H, W, 4),
    changed in place), hidden by the mesh depth in ``surface_targets``;
    ``depth`` (view depth or None) takes the strands' depth where they
    cover (weight >= 1/2). Returns (rgba, depth). A failure here (a GPU
    backend that refuses the shader, say) leaves the meshes' image as it
    is and says so once."""
    try:
        return _composite_render(rgba, depth, surface_targets, view, settings, items)
    except Exception as exc:  # noqa: BLE001 - the meshes' image must survive
        warn_once(("strands draw", type(exc).__name__), f"SolidWire: hair and point clouds not drawn: {one_line(exc)}")
        return rgba, depth


def _composite_render(rgba, depth, surface_targets, view, settings, items):
    width, height = view.width, view.height
    targets = _targets_for(width, height)
    framebuffer = gpu.types.GPUFrameBuffer(depth_slot=targets.depth, color_slots=(targets.color, targets.info))
    with framebuffer.bind():
        gpu.state.depth_mask_set(True)
        gpu.state.color_mask_set(True, True, True, True)
        gpu.state.blend_set("NONE")
        framebuffer.clear(color=(0.0, 0.0, 0.0, 0.0), depth=1.0)
        gpu.state.viewport_set(0, 0, width, height)
        gpu.state.depth_test_set("LESS")
        gpu.state.face_culling_set("NONE")
        try:
            drawn = _draw(items, view, settings, DrawTarget(), scene_depth=surface_targets.depth)
        finally:
            gpu.state.depth_test_set("NONE")
            gpu.state.depth_mask_set(False)
    if not drawn:
        return rgba, depth
    layer = read_texture(targets.color, 4)
    info = read_texture(targets.info, 4)
    rgba *= 1.0 - layer[..., 3:4]
    rgba += layer
    if depth is not None:
        covered = info[..., 1] >= 0.5
        depth[covered] = np.minimum(depth[covered], info[..., 0][covered])
    return rgba, depth


def draw_over_viewport(items, view, settings, target: DrawTarget) -> int:
    """The strands over the bound viewport framebuffer: "over" blending,
    occluded by its depth buffer (LESS_EQUAL, no depth write), moved towards
    the camera by ``target.depth_bias``, cut by the viewport's clipping
    region (``target.clip_planes``, (6, 4) world-space planes) when there is
    one, through ``target.display``. The caller restores the GPU state."""
    gpu.state.blend_set("ALPHA_PREMULT")
    gpu.state.depth_test_set("LESS_EQUAL")
    gpu.state.depth_mask_set(False)
    gpu.state.face_culling_set("NONE")
    try:
        return _draw(items, view, settings, target)
    except Exception as exc:  # noqa: BLE001 - the meshes' overlay must survive
        warn_once(
            ("strands overlay", type(exc).__name__), f"SolidWire: hair and point clouds not drawn: {one_line(exc)}"
        )
        return 0
