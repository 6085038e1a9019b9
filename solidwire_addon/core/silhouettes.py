"""Full-width silhouettes (image model §5.5): the outer half of contour and boundary
edges, which the single-pass method cannot draw (a face only covers its own
side of an edge).

Definition (docs/image_model.md §5.5 has it in full; tests/support/reference.py
evaluates it in float64):
- Candidates are real polygon edges with one adjacent face (boundary) or two.
  For an edge with two faces, it is a *contour* in this view when both faces
  project to the same side of the edge's window line (the surface folds
  over). Boundary and contour edges are *silhouette* edges. Non-manifold
  edges (three or more faces) are not.
- At a sample p on the outer side of a silhouette edge e (opposite to its
  face's side), with q the point of e's near-clipped segment whose projection
  is nearest to p, e contributes P(d_e(p)) (thickness and fade taken at q's
  depth) unless the visible surface at p is nearer than q. The outer
  intensity is the maximum over edges, and it is composited over the image
  ("over" with the wire colour).

Method: screen-space fins. Each candidate edge is a quad expanded in window
space around its near-clipped segment (vertex pulling, like the main pass);
the fragment stage recomputes the exact distance, tests the side and the
occlusion against the main pass's depth texture itself, and writes
1 - intensity as its depth so a LESS depth test keeps the maximum over
overlapping fins (there is no MAX blend in Blender's gpu module). Non-contour
fins are collapsed in the vertex stage, so the contour test is per view and
costs no CPU work when the camera moves.
"""

from __future__ import annotations

from dataclasses import replace

import gpu
import numpy as np

from . import shaders
from .cache import table_texture, texture_bytes
from .draw import DrawTarget, bind_display_transform, indexed_quad_batch, params_block, shader_variant
from .extract import EDGE0_REAL, EDGE1_REAL, EDGE2_REAL
from .view import line_reach, translation

NO_FACE = -1.0
# Each triangle corner's next one and the third one.
_NEXT_CORNER = np.array([1, 2, 0], np.intp)
_THIRD_CORNER = np.array([2, 0, 1], np.intp)


def outer_reach(settings, view) -> tuple | None:
    """How far past its mesh's own projection an outer half can reach, as
    view.outside_frustum_many's ``reach`` (view.line_reach: the fin's reach
    of shaders/silhouette_vert.glsl is the line's), or None with
    silhouettes off."""
    return line_reach(settings, view) if settings.use_silhouettes else None


def candidate_edges(triangles: np.ndarray, edge_flags: np.ndarray) -> np.ndarray:
    """(E, 4) float32 rows (a, b, o_f, o_g): the real edges with one or two
    adjacent faces, ascending by (a, b), a < b; o_f / o_g are the third
    vertices of the triangles on either side, in triangle order (o_g = -1
    for a boundary edge)."""
    tris = np.ascontiguousarray(triangles[:, :3], dtype=np.int32)
    real = np.stack(
        [(edge_flags & EDGE0_REAL) != 0, (edge_flags & EDGE1_REAL) != 0, (edge_flags & EDGE2_REAL) != 0], axis=1
    )
    # Edge k of a triangle runs from its corner k to corner k + 1; the
    # third corner is k + 2: the corners, the next ones and the third ones
    # as three flat arrays, gathered where the edge is real.
    at = np.flatnonzero(real.reshape(-1))
    if len(at) == 0:
        return np.zeros((0, 4), np.float32)
    a = tris.reshape(-1).take(at)
    b = tris.take(_NEXT_CORNER, axis=1).reshape(-1).take(at)
    o = tris.take(_THIRD_CORNER, axis=1).reshape(-1).take(at)
    vertex_count = np.int64(max(int(a.max()), int(b.max())) + 1)
    # One key per edge, (a, b) ordered; a stable sort keeps each edge's
    # triangles in triangle order (timsort: the keys of a mesh's triangles
    # come in runs: about twice as fast as a lexsort of the two ids).
    key = np.minimum(a, b).astype(np.int64) * vertex_count + np.maximum(a, b)
    order = np.argsort(key, kind="stable")
    key, o = key.take(order), o.take(order)
    start = np.ones(len(key), bool)
    np.not_equal(key[1:], key[:-1], out=start[1:])
    first = np.flatnonzero(start)
    counts = np.diff(np.append(first, len(key)))
    keep = counts <= 2  # non-manifold edges are not silhouettes
    first = first[keep]
    two = counts[keep] == 2
    rows = np.empty((len(first), 4), dtype=np.float32)
    low, high = np.divmod(key.take(first), vertex_count)
    rows[:, 0] = low
    rows[:, 1] = high
    rows[:, 2] = o.take(first)
    rows[:, 3] = np.where(two, o.take(np.minimum(first + 1, len(o) - 1)), NO_FACE)
    return rows


def edge_table(mesh):
    """(texture, count) of ``mesh``'s candidate edges, built on first use."""
    if mesh.silhouette_edges is None:
        rows = candidate_edges(mesh.triangles_cpu, mesh.edge_flags_cpu)
        mesh.silhouette_edges = (table_texture(rows), len(rows))
        mesh.gpu_bytes += texture_bytes(mesh.silhouette_edges[0])
    return mesh.silhouette_edges


def draw_silhouettes(items, view, settings, target: DrawTarget, scene_depth_texture=None) -> None:
    """Draw the outer halves into the bound framebuffer.

    Render: an R32F intensity target with its own depth buffer cleared to 1,
    ``scene_depth_texture`` the main pass's depth (see the module docstring);
    ``target.linear_depth`` as the surface pass wrote it. Viewport overlay
    (``target.depth_bias`` > 0): straight into the viewport with "over"
    blending, occluded by its depth buffer; the caller sets the blend;
    ``target.display`` (a display_transform.DisplayLUT) colour-manages the
    colour."""
    overlay_bias = target.depth_bias
    variant = shader_variant(settings, target)
    if not overlay_bias:
        variant = replace(variant, display_transform=False)
    shader = shaders.get_silhouette(variant, overlay_bias)
    ubo = gpu.types.GPUUniformBuf(params_block(settings, view, target))
    shader.bind()
    shader.uniform_block("params", ubo)
    if variant.display_transform:
        bind_display_transform(shader, target.display)
    if overlay_bias:
        gpu.state.depth_test_set("LESS_EQUAL")
        gpu.state.depth_mask_set(False)
    else:
        shader.uniform_sampler("scene_depth", scene_depth_texture)
        gpu.state.depth_test_set("LESS")
        gpu.state.depth_mask_set(True)
    gpu.state.face_culling_set("NONE")
    # View depth is compiled in only for fade and depth-cue thickness.
    uses_view_depth = shaders.uses_uniform(shader, "object_to_view_z")
    for item in items:
        mesh = item.mesh
        table, count = edge_table(mesh)
        if count == 0:
            continue
        object_to_view = view.view_matrix @ item.matrix @ translation(mesh.centre)
        object_to_clip = view.projection @ object_to_view
        shader.uniform_float("object_to_clip", object_to_clip.T.astype(np.float32).ravel().tolist())
        if uses_view_depth:
            shader.uniform_float("object_to_view_z", object_to_view[2].astype(np.float32).tolist())
        shader.uniform_sampler("vertex_positions", mesh.positions)
        shader.uniform_sampler("silhouette_edges", table)
        shader.uniform_int("edge_count", count)
        indexed_quad_batch(count).draw_range(shader, elem_start=0, elem_count=6 * count)
