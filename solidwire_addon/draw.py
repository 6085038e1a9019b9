"""The one drawing path shared by every target (render engine, viewport
overlay, command line, benchmark).

Input is plain data: GPU meshes with float64 object matrices, a view
(float64 view and projection matrices plus the viewport rectangle) and a
:class:`DrawSettings` snapshot. Nothing here reads ``bpy.context``; the caller
binds the framebuffer it wants drawn into.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from . import shaders
from .log import warn_once
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
    # Beyond SPEC 1.4 (issue 7): how the line width varies with depth.
    thickness_mode: str = "PIXELS"  # PIXELS | WORLD | DEPTH
    world_thickness: float = 0.02  # scene units (WORLD)
    thickness_far: float = 0.5  # px at thickness_depth_end (DEPTH)
    thickness_depth_start: float = 2.0
    thickness_depth_end: float = 20.0
    # Hidden-line style (issue 7): edges behind the visible surface, dashed.
    use_hidden_lines: bool = False
    hidden_alpha: float = 0.35
    hidden_period: float = 8.0
    hidden_duty: float = 0.5
    # Full-width silhouettes (issue 7; off by default so renders follow
    # SPEC 1.3's single-pass model unless asked).
    use_silhouettes: bool = False

    def __post_init__(self):
        # No panel can set NaN or Inf, but a script or a driver can: such a
        # number would turn every pixel NaN (colours) or silently blank the
        # frame (softness, fade). It falls back to the default, said once.
        for name, spec in self.__dataclass_fields__.items():
            value, default = getattr(self, name), spec.default
            if isinstance(default, float):
                ok = isinstance(value, (int, float)) and math.isfinite(value)
                fixed = float(value) if ok else default
            elif isinstance(default, tuple):
                fixed = tuple(float(c) if math.isfinite(c) else d for c, d in zip(value, default))
                ok = fixed == tuple(value)
            else:
                continue
            if not ok:
                warn_once(("setting", name), f"SolidWire: setting '{name}' is not a finite number ({value}); using {fixed}")
            object.__setattr__(self, name, fixed)

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
            thickness_mode={"WORLD": shaders.THICKNESS_WORLD, "DEPTH": shaders.THICKNESS_DEPTH}.get(
                self.thickness_mode, shaders.THICKNESS_PIXELS
            ),
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


def pack_params(settings: DrawSettings, viewport, projection=None) -> bytes:
    """The std140 parameter block (see shaders/params.glsl).

    ``projection`` (the view's) is needed for world-space thickness: window
    pixels per scene unit across the view at clip w = 1 are
    0.5 * height * projection[1][1]; the shader divides by the fragment's w."""
    fade_start, fade_end = float(settings.fade_start), float(settings.fade_end)
    px_per_unit = 0.0 if projection is None else 0.5 * float(viewport[3]) * abs(float(projection[1][1]))
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
        min(max(float(settings.hidden_alpha), 0.0), 1.0),
        min(max(float(settings.hidden_duty), 0.0), 1.0),
        0.5 * max(float(settings.thickness_far), 0.0),
        float(settings.thickness_depth_start),
        float(settings.thickness_depth_end),
        0.5 * max(float(settings.world_thickness), 0.0) * px_per_unit,
        max(float(settings.hidden_period), 1e-3),
        0.0,
        0.0,
        0.0,
    ]
    assert len(values) == shaders.PARAMS_FLOATS
    return np.asarray(values, dtype=np.float32).tobytes()


_BOX_CORNERS = np.array([[x, y, z, 1.0] for x in (0, 1) for y in (0, 1) for z in (0, 1)])


def outside_frustum_many(object_to_clip: np.ndarray, bounds_min, bounds_max) -> np.ndarray:
    """(N,) bool: box outside a clip plane, for (N, 4, 4) matrices at once
    (one einsum instead of a Python call per instance)."""
    lo, hi = np.asarray(bounds_min), np.asarray(bounds_max)
    corners = _BOX_CORNERS.copy()
    corners[:, :3] = lo + corners[:, :3] * (hi - lo)
    clip = np.einsum("kj,nij->nki", corners, object_to_clip)  # (N, 8, 4)
    x, y, z, w = np.moveaxis(clip, 2, 0)
    outside = (x > w).all(1) | (x < -w).all(1) | (y > w).all(1) | (y < -w).all(1) | (z > w).all(1) | (z < -w).all(1)
    return outside


# A mesh drawn by at least this many visible instances is drawn with one
# draw_instanced call (matrices from a float texture) instead of one draw per
# instance; scripts/bench_scale.py measures both.
INSTANCING_MIN = 16


def _groups(items, view: View, cull: bool, stats: DrawStats):
    """Items grouped by GPU mesh with their float64-composed matrices, culled
    (vectorised over each group). Yields (mesh, world (N,4,4), object_to_view,
    object_to_clip) with only the visible instances."""
    by_mesh: dict[int, list] = {}
    for item in items:
        by_mesh.setdefault(id(item.mesh), []).append(item)
    for group in by_mesh.values():
        mesh = group[0].mesh
        world = np.stack([item.matrix for item in group]) if len(group) > 1 else group[0].matrix[None]
        # float64 all the way to here: the mesh centre and any large world
        # translation cancel against the view before rounding to float32.
        object_to_view = view.view_matrix @ world @ translation(mesh.centre)
        object_to_clip = view.projection @ object_to_view
        if cull:
            outside = outside_frustum_many(object_to_clip, mesh.bounds_min, mesh.bounds_max)
            if outside.any():
                stats.objects_culled += int(outside.sum())
                keep = ~outside
                world, object_to_view, object_to_clip = world[keep], object_to_view[keep], object_to_clip[keep]
        if len(world):
            yield mesh, world, object_to_view, object_to_clip


def _instance_rows(object_to_view: np.ndarray, object_to_clip: np.ndarray) -> np.ndarray:
    """(N * INSTANCE_TEXELS, 4) float32: per instance the 4 columns of
    object_to_clip then the view-z row (shaders/instancing.glsl)."""
    rows = np.empty((len(object_to_clip), shaders.INSTANCE_TEXELS, 4), dtype=np.float32)
    rows[:, :4, :] = np.swapaxes(object_to_clip, 1, 2)
    rows[:, 4, :] = object_to_view[:, 2, :]
    return rows.reshape(-1, 4)


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
    method: str = "exact",
    depth_test: str = "LESS_EQUAL",
    depth_write: bool = True,
    hidden_pass: bool = False,
) -> DrawStats:
    """Draw ``items`` into the bound framebuffer with depth test and write.

    Every fragment of a face writes depth (nothing is discarded), so a wire is
    only ever seen on the face that is the visible surface there.

    ``method`` is the developer/benchmark switch (shaders.METHODS); anything
    but "exact" is a published method kept for comparison (see methods.py;
    "offset_lines" here is only its line pass, methods.draw_method does both)."""
    import gpu

    stats = DrawStats()
    if not items:
        return stats
    variant = settings.shader_variant(write_view_depth, depth_bias)
    if hidden_pass:
        variant = replace(variant, hidden_pass=True, write_view_depth=False)
    if method != "exact":
        from . import methods  # noqa: F401  (registers the method sources)

        variant = replace(variant, method=method)
    ubo = gpu.types.GPUUniformBuf(pack_params(settings, view.viewport, view.projection))
    gpu.state.depth_test_set(depth_test)
    gpu.state.depth_mask_set(depth_write)
    # Window-space winding flips with a mirroring view or a projection that
    # mirrors x or y (the z flip of a GL projection does not change winding).
    flip = np.linalg.det(view.view_matrix[:3, :3]) * view.projection[0, 0] * view.projection[1, 1] < 0.0
    groups = list(_groups(items, view, cull, stats))
    try:
        # Meshes with n-gons need the fragment stage's outline walk; the rest
        # use a variant without it (llvmpipe pays for a loop even when it runs
        # zero times), so tri/quad meshes never pay for n-gons.
        for with_ngons in (False, True):
            batch = [g for g in groups if (method == "exact" and g[0].has_ngons) == with_ngons]
            if batch:
                _draw_groups(batch, replace(variant, ngons=with_ngons), ubo, settings, method, flip, stats)
    finally:
        gpu.state.face_culling_set("NONE")
    return stats


def _draw_groups(groups, variant, ubo, settings: DrawSettings, method: str, flip: bool, stats: DrawStats) -> None:
    """Draw (mesh, world, object_to_view, object_to_clip) groups with one
    shader variant: per object, or instanced for meshes with many instances."""
    import gpu

    shader = shaders.get(variant)
    # The view depth is only computed when depth fade or the depth target
    # reads it; otherwise the compiler drops this uniform and setting it fails.
    try:
        shader.uniform_from_name("object_to_view_z")
        uses_view_depth = True
    except ValueError:
        uses_view_depth = False
    shader.bind()
    shader.uniform_block("params", ubo)
    instanced = []  # (mesh, object_to_view, object_to_clip, mirrored) drawn with draw_instanced
    for mesh, world, object_to_view_all, object_to_clip_all in groups:
        mirrored_all = (np.linalg.det(world[:, :3, :3]) < 0.0) != flip
        if method == "exact" and len(world) >= INSTANCING_MIN:
            if settings.use_backface_culling and mirrored_all.any() and not mirrored_all.all():
                for side in (False, True):
                    pick = mirrored_all == side
                    instanced.append((mesh, object_to_view_all[pick], object_to_clip_all[pick], side))
            else:
                instanced.append((mesh, object_to_view_all, object_to_clip_all, bool(mirrored_all[0])))
            continue
        for object_to_view, object_to_clip, mirrored in zip(object_to_view_all, object_to_clip_all, mirrored_all):
            if settings.use_backface_culling:
                gpu.state.face_culling_set("FRONT" if mirrored else "BACK")
            shader.uniform_float("object_to_clip", object_to_clip.T.astype(np.float32).ravel().tolist())
            if uses_view_depth:
                shader.uniform_float("object_to_view_z", object_to_view[2].astype(np.float32).tolist())
            shader.uniform_sampler("vertex_positions", mesh.positions)
            shader.uniform_sampler("triangle_vertices", mesh.triangles)
            if method == "exact":
                if variant.ngons:
                    shader.uniform_sampler("ngon_corners", mesh.ngon_corners)
                mesh.batch.draw(shader)
            else:
                from . import methods

                methods.batch_for(mesh, method).draw(shader)
            stats.objects_drawn += 1
            stats.triangles_drawn += mesh.triangle_count
    if instanced:
        _draw_instanced(instanced, variant, ubo, settings, stats)


def _draw_instanced(groups, variant, ubo, settings: DrawSettings, stats: DrawStats) -> None:
    """One draw_instanced call per (mesh, facing) group; every instance's
    matrices in one float texture for the whole frame."""
    import gpu

    from .cache import _table_texture

    shader = shaders.get(replace(variant, instanced=True))
    table = _table_texture(np.concatenate([_instance_rows(o2v, o2c) for _mesh, o2v, o2c, _side in groups]))
    shader.bind()
    shader.uniform_block("params", ubo)
    shader.uniform_sampler("instance_table", table)
    base = 0
    for mesh, _o2v, object_to_clip, mirrored in groups:
        count = len(object_to_clip)
        if settings.use_backface_culling:
            gpu.state.face_culling_set("FRONT" if mirrored else "BACK")
        shader.uniform_int("instance_base", base)
        shader.uniform_sampler("vertex_positions", mesh.positions)
        shader.uniform_sampler("triangle_vertices", mesh.triangles)
        if variant.ngons:
            shader.uniform_sampler("ngon_corners", mesh.ngon_corners)
        mesh.batch.draw_instanced(shader, instance_start=0, instance_count=count)
        base += count * shaders.INSTANCE_TEXELS
        stats.objects_drawn += count
        stats.triangles_drawn += count * mesh.triangle_count
        stats.extra["instanced_draws"] = stats.extra.get("instanced_draws", 0) + 1


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
        if settings.use_hidden_lines:
            # Fill, then hidden lines over it, then the visible wire (as the
            # render does: offscreen._render_with_hidden_lines).
            wire_only = replace(settings, use_fill=False)
            if settings.use_fill:
                draw(items, view, replace(settings, wire_color=(*settings.wire_color[:3], 0.0)), depth_bias=depth_bias)
            draw_hidden_lines(items, view, wire_only, depth_bias=depth_bias)
            stats = draw(items, view, wire_only, depth_bias=depth_bias)
        else:
            stats = draw(items, view, settings, depth_bias=depth_bias)
        if settings.use_silhouettes:
            from . import silhouettes

            silhouettes.draw_silhouettes(items, view, settings, overlay_bias=depth_bias)
    finally:
        gpu.state.color_mask_set(True, True, True, True)
        gpu.state.blend_set(saved_blend)
        gpu.state.depth_test_set(saved_depth_test)
        gpu.state.depth_mask_set(saved_depth_mask)
    return stats


def draw_hidden_lines(items, view: View, settings: DrawSettings, **kwargs) -> DrawStats:
    """The hidden-line pass (issue 7): every face behind the depth already in
    the bound framebuffer draws its real edges dimmed and dashed, blended
    with premultiplied "over" (the caller sets the blend mode). Strictly
    GREATER, so the visible surface itself never passes: the same shader
    wrote that depth, so there is no z-fight. With one wire colour "over" is
    commutative (alpha = 1 - prod(1 - a_k)), so draw order does not matter."""
    return draw(items, view, settings, depth_test="GREATER", depth_write=False, hidden_pass=True, **kwargs)
