"""Plain data every pass shares: the view, what is drawn, frame statistics,
and the frustum test used to skip objects.

A :class:`View` is float64 numpy matrices plus the viewport rectangle; a
:class:`DrawItem` is a GPU mesh with its float64 object matrix. Nothing here
touches Blender or the GPU.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np


@dataclass
class View:
    """Camera or viewport view: float64 matrices and the viewport rectangle."""

    view_matrix: np.ndarray  # world -> view (camera looks down -Z)
    projection: np.ndarray  # view -> clip, GL conventions
    viewport: tuple  # (x0, y0, width, height) in framebuffer pixels

    @property
    def width(self) -> int:
        return int(self.viewport[2])

    @property
    def height(self) -> int:
        return int(self.viewport[3])


# NDC depth bias of the viewport overlay (2^-18: 32 steps of a 24-bit depth
# buffer, about 4 float32 ULPs of z/w near 1). Enough to win the tie with
# Blender's own depth of the same surface (a few ULPs off, computed from other
# float32 matrices); small enough that a surface more than a hair behind
# another stays hidden. See DEPTH_BIAS in shaders/edge_geometry.glsl (biased); far
# from the world origin the overlay adds blender_depth_allowance.
OVERLAY_DEPTH_BIAS = 2.0**-18

# How far Blender's own depth of a surface may stray from ours, in float32
# spacings (ULPs) of the largest coordinate involved: Blender projects each
# vertex from its object's space through float32 matrices, so its depth of
# a surface far from the world origin is off by a few of those spacings in
# every direction, and a slanted surface's by that much over the cosine of
# its slant (at 88 degrees about 30 times more). Measured in Blender's own
# headless viewport (tests/test_viewport_headless.py): Suzanne 2,000 units
# from the origin needs about 30; 64 leaves room for wider slants and other
# backends while moving our surface no more than 64 / 2**24 of its distance
# from the origin (1 cm at 2.6 km).
BLENDER_DEPTH_ULPS = 64.0

# The most the allowance moves a point, as a fraction of its distance from
# the camera (2^-8: 1.6 cm at 4 m). Kilometres from the origin, where
# Blender's own depth strays by more than that, a surface hidden behind
# another one of ours would otherwise show its wire through it where the
# overlay lets Blender's depth hide our farther surfaces (Solid shading,
# no depth pre-pass of our own).
BLENDER_DEPTH_MOST = 2.0**-8

# No allowance: every draw that never meets Blender's depth (the render's).
NO_DEPTH_ALLOWANCE = (0.0, 0.0, 0.0, 0.0)


def blender_depth_allowance(view: View) -> tuple[float, float, float, float]:
    """(a, b, c, e): the viewport overlay moves the point it draws at view
    depth d towards the camera by min(a + b |d|, c + e |d|) scene units
    before Blender's depth test meets it (docs/image_model.md §5.6;
    shaders/common.glsl, window_depth_shift). a + b |d|: BLENDER_DEPTH_ULPS
    float32 spacings of the largest coordinate such a point can have, the
    camera's distance from the origin plus the point's from the camera (at
    most d times the length of the ray through the view's corner per unit
    of view depth; for an orthographic view the view's half diagonal plus
    |d|). c + e |d|: at most BLENDER_DEPTH_MOST of the point's distance
    from the camera (orthographic: of the view's half diagonal plus |d|)."""
    view_matrix = np.asarray(view.view_matrix, dtype=np.float64)
    p = np.asarray(view.projection, dtype=np.float64)
    eye = -view_matrix[:3, :3].T @ view_matrix[:3, 3]  # the camera in world space
    if p[0][0] == 0.0 or p[1][1] == 0.0:
        return NO_DEPTH_ALLOWANCE
    # The view's farthest corner from its axis (a lens shift moves the
    # window off the axis): per unit of view depth, or in scene units.
    perspective = p[3][3] != 1.0
    shift_x, shift_y = (p[0][2], p[1][2]) if perspective else (p[0][3], p[1][3])
    half_diagonal = math.hypot((1.0 + abs(shift_x)) / p[0][0], (1.0 + abs(shift_y)) / p[1][1])
    eye_distance = math.sqrt(float(eye @ eye))
    if perspective:  # the corner ray's length per unit of view depth
        at_eye, per_unit, window = eye_distance, math.sqrt(1.0 + half_diagonal**2), 0.0
    else:  # orthographic: a window of that half diagonal, moved |d| along the axis
        at_eye, per_unit, window = eye_distance + half_diagonal, 1.0, half_diagonal
    spacing = BLENDER_DEPTH_ULPS * 2.0**-24
    return (spacing * at_eye, spacing * per_unit, BLENDER_DEPTH_MOST * window, BLENDER_DEPTH_MOST)


@dataclass(frozen=True)
class Style:
    """An object's own wire colour, thickness and fill colour (its override,
    docs/image_model.md §5.9): replaces those three scene settings for its
    faces. Hashable, so items group by it."""

    wire_color: tuple
    thickness: float
    fill_color: tuple


@dataclass
class DrawItem:
    """One drawn object or instance: a GPU mesh, its object -> world matrix
    and its style override (None: the scene's settings)."""

    mesh: object  # core.cache.GPUMesh
    matrix: np.ndarray  # (4, 4) float64
    source: object = None  # core.colors.ItemSource: inputs of the colour sources (when asked for)
    style: Style | None = None
    pass_index: int = 0  # the IndexOB pass value (object.pass_index)
    # For the IndexMA pass only: (material slot index per face (F,) int32,
    # the pass_index of each material slot). None: every face 0.
    materials: tuple | None = None
    # Viewport overlay: the viewport's own depth buffer holds this object's
    # surface (drawn solid, not in front), so that depth alone hides what
    # lies behind it (passes.draw_over_viewport).
    in_scene_depth: bool = True


@dataclass
class DrawStats:
    objects_drawn: int = 0
    objects_culled: int = 0
    triangles_drawn: int = 0
    extra: dict = field(default_factory=dict)

    def add(self, other: DrawStats) -> None:
        """Count ``other``'s draws in too (one pass drawn in parts)."""
        self.objects_drawn += other.objects_drawn
        self.objects_culled += other.objects_culled
        self.triangles_drawn += other.triangles_drawn
        for key, value in other.extra.items():
            self.extra[key] = self.extra.get(key, 0) + value


def translation(offset) -> np.ndarray:
    m = np.eye(4)
    m[:3, 3] = offset
    return m


# Small matrices are inverted here in closed form rather than with
# np.linalg, which goes through LAPACK in the OpenBLAS that numpy's wheels
# (and Blender's) bundle. Measured on a 2-core VM with the other core busy:
# a 4x4 np.linalg.inv took 2-4 ms per call in some runs (OpenBLAS's
# threads waiting on each other; with one OpenBLAS thread, under 0.2 ms),
# once per frame and per draw group. These cost microseconds whatever the
# load.


def _entries3(linear: np.ndarray):
    """The nine entries of (..., 3, 3) matrices in float64, row by row."""
    m = np.asarray(linear, dtype=np.float64)
    return tuple(m[..., row, column] for row in range(3) for column in range(3))


def determinant3(linear: np.ndarray) -> np.ndarray:
    """(...,): the determinants of (..., 3, 3) matrices, expanded along the
    first row exactly as inverse_transpose3 does (the same bits)."""
    a, b, c, d, e, f, g, h, i = _entries3(linear)
    return a * (e * i - f * h) + b * (f * g - d * i) + c * (d * h - e * g)


def inverse_transpose3(linear: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """((..., 3, 3), (...,)): the inverse transposes of (..., 3, 3) matrices
    and their determinants, from the cofactors (the inverse is the
    transposed cofactor matrix over the determinant, so the inverse
    transpose is the cofactor matrix itself over it). Element-wise
    arithmetic only: no LAPACK, no temporary per matrix. Where the
    determinant is 0 the result is not finite: the caller decides."""
    a, b, c, d, e, f, g, h, i = _entries3(linear)
    cofactors = np.empty(np.shape(a) + (3, 3))
    cofactors[..., 0, 0], cofactors[..., 0, 1], cofactors[..., 0, 2] = e * i - f * h, f * g - d * i, d * h - e * g
    cofactors[..., 1, 0], cofactors[..., 1, 1], cofactors[..., 1, 2] = c * h - b * i, a * i - c * g, b * g - a * h
    cofactors[..., 2, 0], cofactors[..., 2, 1], cofactors[..., 2, 2] = b * f - c * e, c * d - a * f, a * e - b * d
    det = a * cofactors[..., 0, 0] + b * cofactors[..., 0, 1] + c * cofactors[..., 0, 2]
    with np.errstate(all="ignore"):
        return cofactors / np.asarray(det)[..., None, None], det


def affine_inverse(matrix: np.ndarray) -> np.ndarray:
    """The inverse of a (4, 4) matrix. An affine one (last row 0, 0, 0, 1,
    as every object's matrix in Blender) is inverted in closed form:
    (A, t) -> (A^-1, -A^-1 t); any other goes to np.linalg.inv. A singular
    affine matrix raises np.linalg.LinAlgError, as np.linalg.inv does."""
    matrix = np.asarray(matrix, dtype=np.float64)
    if not np.array_equal(matrix[3], (0.0, 0.0, 0.0, 1.0)):
        return np.linalg.inv(matrix)
    inverse_t, det = inverse_transpose3(matrix[:3, :3])
    if not (det != 0.0 and np.isfinite(det)):
        raise np.linalg.LinAlgError("singular matrix")
    out = np.eye(4)
    out[:3, :3] = inverse_t.T
    out[:3, 3] = -(out[:3, :3] * matrix[:3, 3]).sum(axis=1)
    return out


_BOX_CORNERS = np.array([[x, y, z, 1.0] for x in (0, 1) for y in (0, 1) for z in (0, 1)])


def box_clip_corners(object_to_clip: np.ndarray, bounds_min, bounds_max) -> np.ndarray:
    """(N, 8, 4): the eight corners of the box in clip space under each of
    the (N, 4, 4) (or one (4, 4)) ``object_to_clip`` (one einsum, no Python
    call per instance)."""
    lo, hi = np.asarray(bounds_min), np.asarray(bounds_max)
    corners = _BOX_CORNERS.copy()
    corners[:, :3] = lo + corners[:, :3] * (hi - lo)
    return np.einsum("kj,nij->nki", corners, np.asarray(object_to_clip).reshape(-1, 4, 4))


def outside_frustum_many(object_to_clip: np.ndarray, bounds_min, bounds_max, reach=None) -> np.ndarray:
    """(N,) bool: the box lies wholly outside one clip plane (conservative),
    for (N, 4, 4) matrices at once. ``reach`` (pixels, pixels times clip w,
    window width, height; silhouettes.outer_reach): drawing that reaches
    that far past the box's projection (the outer halves of silhouettes,
    image model §5.5), so the side planes move out by it (a half-space in
    clip space still: x > w (1 + 2 px / W) + 2 px_w / W), and a box beyond
    the far plane stays in (the background hides no outer half)."""
    clip = box_clip_corners(object_to_clip, bounds_min, bounds_max)
    x, y, z, w = np.moveaxis(clip, 2, 0)
    if reach is None:
        return (x > w).all(1) | (x < -w).all(1) | (y > w).all(1) | (y < -w).all(1) | (z > w).all(1) | (z < -w).all(1)
    pixels, per_w, width, height = reach
    wx = w * (1.0 + 2.0 * pixels / width) + 2.0 * per_w / width
    wy = w * (1.0 + 2.0 * pixels / height) + 2.0 * per_w / height
    return (x > wx).all(1) | (x < -wx).all(1) | (y > wy).all(1) | (y < -wy).all(1) | (z < -w).all(1)


def line_reach(settings, view, per_w: float = 0.0) -> tuple:
    """How far past its geometry's own projection a line drawn with
    ``settings`` can reach, as outside_frustum_many's ``reach`` (pixels,
    pixels times clip w, window width, height): the widest half-thickness,
    two softness widths and a pixel (a world thickness in pixels at clip
    w = 1, over w), and ``per_w`` more at clip w = 1 (a strand's radius)."""
    pixels = 0.5 * max(float(settings.thickness), float(settings.thickness_far)) + 2.0 * float(settings.softness) + 1.0
    if settings.thickness_mode == "WORLD":  # (settings.pack_params' world_half_thickness_px)
        per_w += 0.5 * max(float(settings.world_thickness), 0.0) * 0.5 * view.height * abs(float(view.projection[1][1]))
    return (pixels, per_w, view.width, view.height)


def wholly_in_front(object_to_clip: np.ndarray, bounds_min, bounds_max) -> bool:
    """Whether every box of (N, 4, 4) ``object_to_clip`` lies in front of the
    near plane (clip z + w > 0 at every corner) with a margin of 1e-4 of the
    largest |w|, more than float32 rounding of a vertex inside can take
    away (a vertex is a convex mix of the corners, z + w linear)."""
    clip = box_clip_corners(object_to_clip, bounds_min, bounds_max)
    depth = clip[..., 2] + clip[..., 3]
    return bool(len(clip)) and bool((depth > 1e-4 * np.abs(clip[..., 3]).max()).all())


def window_boxes(object_to_clip: np.ndarray, bounds_min, bounds_max) -> np.ndarray:
    """(N, 4) NDC rectangles (x0, y0, x1, y1), one per (N, 4, 4)
    ``object_to_clip``, each holding every pixel its box can cover, widened
    by a little slack for rounding and clamped to the view; the whole view
    where a box reaches behind the camera (no finite projection there)."""
    clip = box_clip_corners(object_to_clip, bounds_min, bounds_max)
    w = clip[..., 3]
    behind = (w <= 1e-6 * np.abs(clip[..., :3]).max(axis=(1, 2), initial=1.0)[:, None]).any(axis=1)
    with np.errstate(all="ignore"):
        ndc = clip[..., :2] / np.where(behind[:, None], 1.0, w)[..., None]
    boxes = np.concatenate([ndc.min(axis=1) - 0.01, ndc.max(axis=1) + 0.01], axis=1)
    boxes[behind] = (-1.0, -1.0, 1.0, 1.0)
    return np.clip(boxes, -1.0, 1.0)


def window_rect(object_to_clip: np.ndarray, bounds_min, bounds_max) -> tuple:
    """One NDC rectangle (x0, y0, x1, y1) over the window_boxes of every
    instance in ``object_to_clip``."""
    boxes = window_boxes(object_to_clip, bounds_min, bounds_max)
    if not len(boxes):
        return (-1.0, -1.0, 1.0, 1.0)
    return (float(boxes[:, 0].min()), float(boxes[:, 1].min()), float(boxes[:, 2].max()), float(boxes[:, 3].max()))


def box_pixels(boxes: np.ndarray, view) -> np.ndarray:
    """(N,) pixels inside NDC rectangles ``boxes`` of a ``view``."""
    return 0.25 * (boxes[:, 2] - boxes[:, 0]) * (boxes[:, 3] - boxes[:, 1]) * view.width * view.height
