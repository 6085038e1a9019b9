"""The one drawing path shared by every target (render engine, viewport
overlay, command line, benchmark).

Input is plain data: GPU meshes with float64 object matrices, a view
(float64 view and projection matrices plus the viewport rectangle) and a
:class:`DrawSettings` snapshot. Nothing here reads ``bpy.context``; the caller
binds the framebuffer it wants drawn into.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from . import shaders
from .cache import GPUMesh

DIAGONAL_MODES = ("HIDDEN", "SOLID", "DOTTED", "DASHED")
DEFAULT_DUTY = {"DOTTED": 0.25, "DASHED": 0.5}


@dataclass(frozen=True)
class DrawSettings:
    """A plain snapshot of ``scene.solidwire`` (SPEC section 2)."""

    thickness: float = 1.5
    softness: float = 1.0
    wire_color: tuple = (0.0, 0.0, 0.0, 1.0)
    use_fill: bool = False
    fill_color: tuple = (1.0, 1.0, 1.0, 1.0)
    diagonal_mode: str = "HIDDEN"
    pattern_period: float = 8.0
    pattern_duty: float = 0.25
    use_fade: bool = False
    fade_start: float = 10.0
    fade_end: float = 50.0
    use_backface_culling: bool = False

    @classmethod
    def from_properties(cls, props) -> "DrawSettings":
        """Snapshot of a ``scene.solidwire`` property group (or any object with
        the same attribute names)."""
        values = {}
        for name in cls.__dataclass_fields__:
            value = getattr(props, name)
            if name.endswith("_color"):
                value = tuple(float(c) for c in value)
            values[name] = value
        return cls(**values)

    def shader_variant(self, write_view_depth: bool = False, depth_bias: float = 0.0) -> shaders.ShaderVariant:
        diagonals = {
            "HIDDEN": shaders.DIAGONALS_HIDDEN,
            "SOLID": shaders.DIAGONALS_SOLID,
        }.get(self.diagonal_mode, shaders.DIAGONALS_PATTERN)
        return shaders.ShaderVariant(
            diagonals=diagonals,
            use_fill=bool(self.use_fill),
            use_fade=bool(self.use_fade),
            write_view_depth=write_view_depth,
            depth_bias=depth_bias,
        )


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


@dataclass
class DrawItem:
    """One drawn object or instance: a GPU mesh and its object -> world matrix."""

    mesh: GPUMesh
    matrix: np.ndarray  # (4, 4) float64


@dataclass
class DrawStats:
    objects_drawn: int = 0
    objects_culled: int = 0
    triangles_drawn: int = 0
    extra: dict = field(default_factory=dict)


def translation(offset) -> np.ndarray:
    m = np.eye(4)
    m[:3, 3] = offset
    return m


def pack_params(settings: DrawSettings, viewport) -> bytes:
    """The std140 parameter block (see shaders.PARAMS_TYPEDEF)."""
    fade_start, fade_end = float(settings.fade_start), float(settings.fade_end)
    values = [
        *settings.wire_color,
        *settings.fill_color,
        *(float(v) for v in viewport),
        0.5 * max(float(settings.thickness), 0.0),
        max(float(settings.softness), 1e-4),
        fade_start,
        fade_end,
        max(float(settings.pattern_period), 1e-3),
        min(max(float(settings.pattern_duty), 0.0), 1.0),
        0.0,
        0.0,
    ]
    assert len(values) == shaders.PARAMS_FLOATS
    return np.asarray(values, dtype=np.float32).tobytes()


_BOX_CORNERS = np.array([[x, y, z, 1.0] for x in (0, 1) for y in (0, 1) for z in (0, 1)])


def outside_frustum(object_to_clip: np.ndarray, bounds_min, bounds_max) -> bool:
    """True when the box lies wholly outside one clip plane (conservative)."""
    lo, hi = np.asarray(bounds_min), np.asarray(bounds_max)
    corners = _BOX_CORNERS.copy()
    corners[:, :3] = lo + corners[:, :3] * (hi - lo)
    clip = corners @ object_to_clip.T  # (8, 4)
    x, y, z, w = clip.T
    return bool(
        (x > w).all() or (x < -w).all() or (y > w).all() or (y < -w).all() or (z > w).all() or (z < -w).all()
    )


def draw(
    items,
    view: View,
    settings: DrawSettings,
    *,
    write_view_depth: bool = False,
    cull: bool = True,
    depth_bias: float = 0.0,
) -> DrawStats:
    """Draw ``items`` into the bound framebuffer with depth test and write.

    Every fragment of a face writes depth (nothing is discarded), so a wire is
    only ever seen on the face that is the visible surface there."""
    import gpu

    stats = DrawStats()
    if not items:
        return stats
    shader = shaders.get(settings.shader_variant(write_view_depth, depth_bias))
    ubo = gpu.types.GPUUniformBuf(pack_params(settings, view.viewport))

    shader.bind()
    shader.uniform_block("params", ubo)
    gpu.state.depth_test_set("LESS_EQUAL")
    gpu.state.depth_mask_set(True)
    # Window-space winding flips with a mirroring view or a projection that
    # mirrors x or y (the z flip of a GL projection does not change winding).
    flip = np.linalg.det(view.view_matrix[:3, :3]) * view.projection[0, 0] * view.projection[1, 1] < 0.0
    try:
        for item in items:
            mesh = item.mesh
            # float64 all the way to here: the mesh centre and any large world
            # translation cancel against the view before rounding to float32.
            object_to_view = view.view_matrix @ item.matrix @ translation(mesh.centre)
            object_to_clip = view.projection @ object_to_view
            if cull and outside_frustum(object_to_clip, mesh.bounds_min, mesh.bounds_max):
                stats.objects_culled += 1
                continue
            if settings.use_backface_culling:
                mirrored = (np.linalg.det(item.matrix[:3, :3]) < 0.0) != flip
                gpu.state.face_culling_set("FRONT" if mirrored else "BACK")
            shader.uniform_float("object_to_clip", object_to_clip.T.astype(np.float32).ravel().tolist())
            shader.uniform_float("object_to_view_z", object_to_view[2].astype(np.float32).tolist())
            shader.uniform_sampler("vertex_positions", mesh.positions)
            shader.uniform_sampler("triangle_vertices", mesh.triangles)
            shader.uniform_sampler("ngon_corners", mesh.ngon_corners)
            mesh.batch.draw(shader)
            stats.objects_drawn += 1
            stats.triangles_drawn += mesh.triangle_count
    finally:
        gpu.state.face_culling_set("NONE")
    return stats


# NDC depth bias of the viewport overlay (2^-18: 32 steps of a 24-bit depth
# buffer, about 4 float32 ULPs of z/w near 1). Enough to win the tie with
# Blender's own depth of the same surface (a few ULPs off, computed from other
# float32 matrices); small enough that a surface more than a hair behind
# another stays hidden. See DEPTH_BIAS in shaders/solidwire_vert.glsl.
OVERLAY_DEPTH_BIAS = 2.0**-18


def draw_overlay(items, view: View, settings: DrawSettings, *, depth_bias: float = OVERLAY_DEPTH_BIAS) -> DrawStats:
    """Draw ``items`` over a bound framebuffer that already holds the scene's
    colour and depth (a 3D viewport after its own drawing).

    Two passes: a depth-only pre-pass, then the colour pass with
    premultiplied alpha blending and depth test LESS_EQUAL. The pre-pass makes
    only the nearest of our own surfaces pass the colour pass (no back
    edges show through where the scene depth is empty, as in X-ray or
    Wireframe shading); the scene's depth hides wires behind other geometry.
    GPU state is restored afterwards."""
    import gpu

    saved_blend = gpu.state.blend_get()
    saved_depth_test = gpu.state.depth_test_get()
    saved_depth_mask = gpu.state.depth_mask_get()
    try:
        gpu.state.blend_set("NONE")
        gpu.state.color_mask_set(False, False, False, False)
        draw(items, view, settings, depth_bias=depth_bias)
        gpu.state.color_mask_set(True, True, True, True)
        gpu.state.blend_set("ALPHA_PREMULT")
        stats = draw(items, view, settings, depth_bias=depth_bias)
    finally:
        gpu.state.color_mask_set(True, True, True, True)
        gpu.state.blend_set(saved_blend)
        gpu.state.depth_test_set(saved_depth_test)
        gpu.state.depth_mask_set(saved_depth_mask)
    return stats
