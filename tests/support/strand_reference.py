"""Float64 reference of hair and point clouds (docs/user/hair-and-points.md), on
top of the mesh reference (tests/support/reference.py).

Per sample c (pixel centre) and primitive:

* strand segment [A, B] (object space, near-clipped in clip space, projected
  to window points a, b): s = the window parameter of the point of [a, b]
  nearest c, d = |c - (a + s (b - a))|, u = s w_a / (s w_a + (1 - s) w_b)
  (perspective-correct), q = A + u (B - A); at q: view depth z, clip w,
  radius r (linear in u, times the object's radius scale cbrt|det M|);
  half-width h' = max(h, r * px_per_unit / w) with px_per_unit =
  H/2 |P[1][1]|; I = P(d; h') (times the depth fade at z when on),
  weight = I; depth = z - r.
* point p (centre in front of the near plane): window centre o, radius
  R = r px_per_unit / w; rim = |c - o| - R; I = P(|rim|; h) (times the
  depth fade at z_p); weight = 1
  inside (rim <= 0) else I; depth = z_p - r.

A primitive is visible at c when its depth <= the visible mesh surface's
depth there (and the clip end). Of the visible ones, the largest weight
wins, weights in the same step floor((1 - weight) * 1023) counting as equal
and the nearest of those winning (a depth below 0, a front behind the
camera, counting as 0: two such in one step are a tie); its I gives a = wire alpha * I, composited "over"
the mesh image: alpha = a + (1 - a) a_mesh.

Samples where the occlusion test is undecided (primitive depth within a
relative 1e-5 of the surface's), or where a weight within float32 rounding
of a step boundary meets a rival, count as silhouette samples (SPEC 1.5).
"""

from __future__ import annotations

from dataclasses import dataclass

import bpy
import numpy as np

from tests.support import reference

UNDECIDED = 1e-5  # relative depth difference below which occlusion is a tie
BUCKETS = 1023.0  # weights within one 1/1023 step count as equal: the nearest wins


@dataclass
class StrandReference:
    intensity: np.ndarray  # (H, W) total line intensity (mesh wire and strands, relative to wire alpha)
    strand: np.ndarray  # (H, W) the winning strand/point intensity (0: none)
    weight: np.ndarray  # (H, W) its weight
    on_silhouette: np.ndarray  # (H, W) mesh silhouettes and undecided occlusion
    depth: np.ndarray  # (H, W) depth of the winner (inf: none)
    mesh: reference.ReferenceResult
    reached: np.ndarray  # (H, W) how many primitives (strand segments, points) reach the sample unhidden
    reached_any: np.ndarray  # (H, W) the same, hidden or not
    groups: np.ndarray  # (H, W) how many strands and points reach it, hidden or not (a strand's segments are one)
    apart: np.ndarray  # (H, W) two segments of one strand reach it that do not meet, or not only those that do


def catmull_rom(points, resolution, cyclic):
    """Blender's uniform Catmull-Rom evaluation (open ends extrapolate
    2 p0 - p1), float64."""
    points = np.asarray(points, dtype=np.float64)
    n = len(points)
    if n < 2:
        return points
    resolution = max(int(resolution), 1)  # (at 1, a closed curve still has its closing segment)
    ext = (
        np.concatenate([points[-1:], points, points[:2]])
        if cyclic
        else np.concatenate([2 * points[:1] - points[1:2], points, 2 * points[-1:] - points[-2:-1]])
    )
    out = []
    for i in range(n if cyclic else n - 1):
        p0, p1, p2, p3 = ext[i : i + 4]
        for k in range(resolution):
            t = k / resolution
            out.append(
                0.5
                * (
                    (2 * p1)
                    + (-p0 + p2) * t
                    + (2 * p0 - 5 * p1 + 4 * p2 - p3) * t * t
                    + (-p0 + 3 * p1 - 3 * p2 + p3) * t**3
                )
            )
    out.append(points[0] if cyclic else points[-1])
    return np.array(out)


def bezier(points, left, right, resolution, cyclic):
    """Blender's cubic Bezier evaluation: segment i from p_i over right_i
    and left_(i+1) to p_(i+1), radius linear; float64."""
    n = len(points)
    out = []
    for i in range(n if cyclic else n - 1):
        j = (i + 1) % n
        for k in range(resolution):
            t = k / resolution
            xyz = (
                (1 - t) ** 3 * points[i, :3]
                + 3 * (1 - t) ** 2 * t * right[i]
                + 3 * (1 - t) * t * t * left[j]
                + t**3 * points[j, :3]
            )
            out.append(np.append(xyz, (1 - t) * points[i, 3] + t * points[j, 3]))
    out.append(points[0] if cyclic else points[-1])
    return np.array(out)


def _attribute(data, name, count, width, prop, dtype=np.float64):
    attribute = data.attributes.get(name)
    if attribute is None or len(attribute.data) != count:
        return None
    values = np.empty(count * width, dtype=np.float64 if dtype is np.float64 else dtype)
    attribute.data.foreach_get(prop, values)
    return values.reshape(count, width) if width > 1 else values


def primitives(depsgraph, show="show_in_render"):
    """(segments [(A, B, rA, rB, matrix, name, strand)], points [(p, r,
    matrix, name)]) of every shown Curves / PointCloud instance, object
    space; ``strand`` numbers the strands (a strand's segments are
    consecutive)."""
    segments, points = [], []
    strand = 0
    for instance in depsgraph.object_instances:
        obj = instance.object
        if obj.type not in ("CURVES", "POINTCLOUD"):
            continue
        if not instance.is_instance and not instance.show_self:
            continue
        props = getattr(obj.original, "solidwire", None)
        if props is not None and not getattr(props, show):
            continue
        matrix = np.array(instance.matrix_world, dtype=np.float64)
        data = obj.data
        count = len(data.points)
        if count == 0:
            continue
        pos = _attribute(data, "position", count, 3, "vector")
        rad = _attribute(data, "radius", count, 1, "value")
        rad = np.zeros(count) if rad is None else rad
        if obj.type == "POINTCLOUD":
            for p, r in zip(pos, rad):
                if reference.drawable(p) and reference.drawable([r]):
                    points.append((p, max(r, 0.0), matrix, obj.name))
            continue
        ncurves = len(data.curves)
        offsets = np.empty(ncurves + 1, np.int32)
        data.curve_offset_data.foreach_get("value", offsets)
        types = _attribute(data, "curve_type", ncurves, 1, "value", np.int32)
        res = _attribute(data, "resolution", ncurves, 1, "value", np.int32)
        cyc = _attribute(data, "cyclic", ncurves, 1, "value", bool)
        for c in range(ncurves):
            ctrl = np.concatenate([pos[offsets[c] : offsets[c + 1]], rad[offsets[c] : offsets[c + 1], None]], axis=1)
            closed = bool(cyc[c]) if cyc is not None else False
            kind = int(types[c]) if types is not None else 0
            left = _attribute(data, "handle_left", count, 3, "vector")
            right = _attribute(data, "handle_right", count, 3, "vector")
            # Huge or non-finite control points (the fuzz draws them) give
            # inf or NaN here; such points are not drawable and are dropped
            # below, as the add-on drops them.
            with np.errstate(invalid="ignore", over="ignore"):
                ev = _evaluated(ctrl, kind, closed, res[c] if res is not None else 12, left, right, offsets[c : c + 2])
            if ev is not None:
                pairs = [(i, i + 1) for i in range(len(ev) - 1)]
            else:
                ev = ctrl
                pairs = [(i, i + 1) for i in range(len(ev) - 1)] + (
                    [(len(ev) - 1, 0)] if closed and len(ev) > 2 else []
                )
            strand += 1
            for i, j in pairs:
                if reference.drawable(ev[i]) and reference.drawable(ev[j]):
                    segments.append(
                        (ev[i, :3], ev[j, :3], max(ev[i, 3], 0.0), max(ev[j, 3], 0.0), matrix, obj.name, strand)
                    )
    return segments, points


def _evaluated(ctrl, kind, closed, resolution, left, right, span):
    """A curve's evaluated points (Catmull-Rom or Bezier), or None for a
    poly curve or one too short to evaluate (drawn through its control
    points)."""
    if kind == 0 and len(ctrl) >= 2:
        return catmull_rom(ctrl, int(resolution), closed)
    if kind == 2 and len(ctrl) >= 2 and left is not None and right is not None:
        return bezier(ctrl, left[span[0] : span[1]], right[span[0] : span[1]], int(resolution), closed)
    return None


def render_strand_reference(scene, depsgraph=None, settings=None, mesh=None) -> StrandReference:
    if depsgraph is None:
        depsgraph = bpy.context.evaluated_depsgraph_get()
    s = settings if settings is not None else scene.solidwire
    mesh = mesh if mesh is not None else reference.render_reference(scene, depsgraph, settings=settings)
    height, width = mesh.intensity.shape
    view_matrix, proj = reference._camera(scene, depsgraph, width, height)
    near, far = reference._clip_depths(proj)
    ppu = 0.5 * height * abs(proj[1, 1])
    h = 0.5 * float(s.thickness)
    soft = float(s.softness)
    surface = np.where(np.isfinite(mesh.depth), mesh.depth, np.inf)
    limit = np.minimum(surface, far)

    best_w = np.zeros((height, width))
    best_i = np.zeros((height, width))
    best_z = np.full((height, width), np.inf)
    undecided = np.zeros((height, width), bool)
    near = np.zeros((height, width), bool)  # a candidate so far sat on a bucket boundary
    reached = np.zeros((height, width), np.int32)
    reached_any = np.zeros((height, width), np.int32)
    groups = np.zeros((height, width), np.int32)
    last_group = np.full((height, width), np.iinfo(np.int64).min, np.int64)  # (no group yet)
    last_order = np.full((height, width), -2, np.int64)
    apart = np.zeros((height, width), bool)

    def window(clip):
        return np.array([(clip[0] / clip[3] + 1) * 0.5 * width, (clip[1] / clip[3] + 1) * 0.5 * height])

    def consider(x0, x1, y0, y1, weight, intensity, depth, group, order=-2):
        """Offer a primitive's values (of strand or point ``group``, the
        ``order``-th segment of all) over the pixel box [x0, x1) x [y0, y1)."""
        box = (slice(y0, y1), slice(x0, x1))
        lim = limit[box]
        visible = (depth <= lim) & (weight > 0)
        reached[box] += visible
        reaches = (weight > 0) & (depth <= far)
        reached_any[box] += reaches
        new_group = reaches & (last_group[box] != group)
        groups[box] += new_group
        apart[box] |= reaches & ~new_group & (last_order[box] != order - 1)
        last_group[box] = np.where(new_group, group, last_group[box])
        last_order[box] = np.where(reaches, order, last_order[box])
        close = np.isfinite(lim) & (np.abs(depth - lim) <= UNDECIDED * np.maximum(np.abs(lim), 1e-9)) & (weight > 0)
        undecided[box] |= close
        bw, bz = best_w[box], best_z[box]
        rank, best_rank = np.floor((1.0 - weight) * BUCKETS), np.floor((1.0 - bw) * BUCKETS)
        # (A front behind the camera is at the camera: the render keys depth from 0.)
        key, best_key = np.maximum(depth, 0.0), np.maximum(bz, 0.0)
        better = visible & ((rank < best_rank) | ((rank == best_rank) & (key < best_key)))
        undecided[box] |= visible & (bw > 0) & (rank == best_rank) & (key == 0.0) & (best_key == 0.0)
        # float32 may put a weight on the other side of a bucket boundary
        # (an exact 1 never moves); with a rival there, the winner is a tie.
        x = (1.0 - weight) * BUCKETS
        frac = x - np.floor(x)
        near_boundary = visible & (x > 0) & ((frac < 1e-3) | (frac > 1 - 1e-3))
        undecided[box] |= (near_boundary & (bw > 0)) | (visible & (bw > 0) & near[box])
        near[box] |= near_boundary
        best_w[box] = np.where(better, weight, bw)
        best_i[box] = np.where(better, intensity, best_i[box])
        best_z[box] = np.where(better, depth, bz)

    def pixel_box(lo, hi):
        x0, y0 = max(int(np.floor(lo[0])), 0), max(int(np.floor(lo[1])), 0)
        x1, y1 = min(int(np.ceil(hi[0])) + 1, width), min(int(np.ceil(hi[1])) + 1, height)
        return x0, x1, y0, y1

    segments, points = primitives(depsgraph)
    for order, (a_obj, b_obj, ra, rb, matrix, _name, strand) in enumerate(segments):
        scale = abs(np.linalg.det(matrix[:3, :3])) ** (1 / 3)
        o2v = view_matrix @ matrix
        va, vb = o2v @ np.append(a_obj, 1.0), o2v @ np.append(b_obj, 1.0)
        ka, kb = proj @ va, proj @ vb
        fa, fb = ka[2] + ka[3], kb[2] + kb[3]
        if fa < 0 and fb < 0:
            continue
        za, zb = -va[2], -vb[2]
        ra, rb = ra * scale, rb * scale
        ta = fa / (fa - fb) if fa < 0 else 0.0
        tb = fb / (fb - fa) if fb < 0 else 0.0
        ka, kb, za, zb, ra, rb = (
            ka + ta * (kb - ka),
            kb + tb * (ka - kb),
            za + ta * (zb - za),
            zb + tb * (za - zb),
            ra + ta * (rb - ra),
            rb + tb * (ra - rb),
        )
        wa_, wb_ = window(ka), window(kb)
        reach = max(h, ra * ppu / ka[3], rb * ppu / kb[3]) + 2 * soft + 1
        x0, x1, y0, y1 = pixel_box(np.minimum(wa_, wb_) - reach, np.maximum(wa_, wb_) + reach)
        if x0 >= x1 or y0 >= y1:
            continue
        px, py = np.meshgrid(np.arange(x0, x1) + 0.5, np.arange(y0, y1) + 0.5)
        ab = wb_ - wa_
        len2 = ab @ ab
        t = np.clip(((px - wa_[0]) * ab[0] + (py - wa_[1]) * ab[1]) / len2, 0, 1) if len2 > 0 else np.zeros_like(px)
        d = np.hypot(px - (wa_[0] + t * ab[0]), py - (wa_[1] + t * ab[1]))
        u = t * ka[3] / (t * ka[3] + (1 - t) * kb[3])
        w = ka[3] + u * (kb[3] - ka[3])
        z = za + u * (zb - za)
        r = ra + u * (rb - ra)
        value = reference.profile(d, 2.0 * np.maximum(h, r * ppu / w), soft)  # (full width)
        if getattr(s, "use_fade", False):
            value = value * reference._fade(s, z)
        consider(x0, x1, y0, y1, value, value, z - r, strand, order)
        undecided[y0:y1, x0:x1] |= _end_by_rounding(
            px, py, wa_, wb_, reach, (ka[3], kb[3]), (za, zb), (ra, rb), h, s, ppu
        )
    for point_number, (p_obj, r, matrix, _name) in enumerate(points):
        scale = abs(np.linalg.det(matrix[:3, :3])) ** (1 / 3)
        v = view_matrix @ matrix @ np.append(p_obj, 1.0)
        k = proj @ v
        if k[2] + k[3] < 0 or k[3] <= 0:
            continue
        r = r * scale
        o = window(k)
        radius = r * ppu / k[3]
        reach = radius + h + 2 * soft + 1
        x0, x1, y0, y1 = pixel_box(o - reach, o + reach)
        if x0 >= x1 or y0 >= y1:
            continue
        px, py = np.meshgrid(np.arange(x0, x1) + 0.5, np.arange(y0, y1) + 0.5)
        rim = np.hypot(px - o[0], py - o[1]) - radius
        value = reference.profile(np.abs(rim), 2.0 * h, soft)
        if getattr(s, "use_fade", False):
            value = value * reference._fade(s, np.full_like(px, -v[2]))
        consider(x0, x1, y0, y1, np.where(rim <= 0, 1.0, value), value, np.full_like(px, -v[2] - r), -1 - point_number)

    wire_alpha = float(s.wire_color[3])
    a_s = best_i * wire_alpha
    a_m = mesh.intensity * wire_alpha
    total = (a_s + (1 - a_s) * a_m) / max(wire_alpha, 1e-12)
    return StrandReference(
        total, best_i, best_w, mesh.on_silhouette | undecided, best_z, mesh, reached, reached_any, groups, apart
    )


def _end_by_rounding(px, py, wa, wb, reach, w_ends, z_ends, r_ends, h, s, ppu) -> np.ndarray:
    """Samples (px, py) of a segment whose window direction float32 cannot
    fix to 0.01 px over its reach (as a silhouette's, image model §7.2:
    its ends' window coordinates carry about 2^-22 of their size M), where
    that direction's error, M 2^-22 / |b - a| radians, could move the
    nearest point q to the other end, and the two ends give different
    intensities (their radius or depth differ): which end a sample measures
    is rounding's choice there."""
    ab = wb - wa
    length = float(np.hypot(*ab))
    size = max(np.abs(wa).max(), np.abs(wb).max())
    slack = size * 2.0**-22
    if length * reference.SIDE_REACH_PX >= reach * slack:
        return np.zeros(px.shape, bool)
    if length > 0:
        along = ((px - wa[0]) * ab[0] + (py - wa[1]) * ab[1]) / length
        across = np.abs((px - wa[0]) * ab[1] - (py - wa[1]) * ab[0]) / length
        band = np.abs(along - 0.5 * length) <= 0.5 * length + across * slack / length + slack
    else:
        band = np.ones(px.shape, bool)
    ends = []
    for (ex, ey), w, z, r in zip((wa, wb), w_ends, z_ends, r_ends):
        value = reference.profile(np.hypot(px - ex, py - ey), 2.0 * max(h, r * ppu / w), float(s.softness))
        if getattr(s, "use_fade", False):
            value = value * reference._fade(s, np.full_like(px, z))
        ends.append(value)
    return band & (np.abs(ends[0] - ends[1]) > 1e-3)


def error_report(measured, ref: StrandReference) -> dict:
    """SPEC 1.5 numbers of ``measured`` against the combined reference."""
    return reference.error_report(
        measured,
        reference.ReferenceResult(ref.intensity, ref.on_silhouette, ref.mesh.face, ref.mesh.depth, ref.mesh.rows),
    )
