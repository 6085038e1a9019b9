"""One pass of the solid wireframe: a shader variant, the parameter block
and the batches of the drawn meshes, into the bound framebuffer.

Input is plain data (``core/view.py``): draw items with float64 object
matrices, a view and a settings snapshot (``core/settings.py``). Which passes
run, in which order and with which blending is the pass plan's business
(``core/passes.py``); nothing here reads ``bpy.context``.
"""

from __future__ import annotations

from dataclasses import replace

import gpu
import numpy as np

from . import shaders
from .cache import table_texture
from .settings import pack_params
from .view import DrawStats, View, outside_frustum_many, translation


def shader_variant(settings, write_view_depth: bool = False, depth_bias: float = 0.0,
                   linear_depth: bool = False) -> shaders.ShaderVariant:
    """The compiled-code features ``settings`` ask for."""
    diagonals = {
        "HIDDEN": shaders.DIAGONALS_HIDDEN,
        "SOLID": shaders.DIAGONALS_SOLID,
    }.get(settings.diagonal_mode, shaders.DIAGONALS_PATTERN)
    return shaders.ShaderVariant(
        diagonals=diagonals,
        use_fill=bool(settings.use_fill),
        use_fade=bool(settings.use_fade),
        write_view_depth=write_view_depth,
        depth_bias=depth_bias,
        linear_depth=linear_depth,
        thickness_mode={"WORLD": shaders.THICKNESS_WORLD, "DEPTH": shaders.THICKNESS_DEPTH}.get(
            settings.thickness_mode, shaders.THICKNESS_PIXELS
        ),
    )


class ExactProgram:
    """How the add-on draws a mesh: the exact edge-distance shaders over the
    mesh's triangle batch. The benchmark (scripts/bench/methods.py) passes
    its own program with the same two methods to draw a published method
    through this same pass."""

    supports_ngons = True
    supports_instancing = True

    def shader(self, variant):
        return shaders.get(variant)

    def batch(self, mesh):
        return mesh.batch


EXACT = ExactProgram()


# A mesh drawn by at least this many visible instances is drawn with one
# draw_instanced call (matrices from a float texture) instead of one draw per
# instance; scripts/bench_scale.py measures both.
INSTANCING_MIN = 16


def styled(settings, style, show_wire: bool = True):
    """``settings`` with an object's style override applied
    (docs/image_model.md §5.9); ``show_wire=False`` keeps the wire out of the
    pass whatever the override's colour (the fill-only surface pass under
    hidden lines)."""
    if style is not None:
        settings = replace(settings, wire_color=style.wire_color, thickness=style.thickness,
                           fill_color=style.fill_color)
    if not show_wire and settings.wire_color[3] != 0.0:
        settings = replace(settings, wire_color=(*settings.wire_color[:3], 0.0))
    return settings


def _groups(items, view: View, cull: bool, stats: DrawStats, pass_indices: bool = False):
    """Items grouped by GPU mesh and style with their float64-composed
    matrices, culled (vectorised over each group). Yields (mesh, style,
    world (N,4,4), object_to_view, object_to_clip, pass indices (N,) or
    None) with only the visible instances."""
    by_mesh: dict = {}
    for item in items:
        # Plain items key by mesh alone: no tuple per item on the common path.
        key = id(item.mesh) if item.style is None else (id(item.mesh), item.style)
        by_mesh.setdefault(key, []).append(item)
    for group in by_mesh.values():
        mesh, style = group[0].mesh, group[0].style
        world = np.stack([item.matrix for item in group]) if len(group) > 1 else group[0].matrix[None]
        # float64 all the way to here: the mesh centre and any large world
        # translation cancel against the view before rounding to float32.
        object_to_view = view.view_matrix @ world @ translation(mesh.centre)
        object_to_clip = view.projection @ object_to_view
        indices = np.array([item.pass_index for item in group], dtype=np.float64) if pass_indices else None
        materials = [item.materials for item in group] if pass_indices else None
        if cull:
            outside = outside_frustum_many(object_to_clip, mesh.bounds_min, mesh.bounds_max)
            if outside.any():
                stats.objects_culled += int(outside.sum())
                keep = ~outside
                world, object_to_view, object_to_clip = world[keep], object_to_view[keep], object_to_clip[keep]
                if indices is not None:
                    indices = indices[keep]
                    materials = [m for m, k in zip(materials, keep) if k]
        if len(world):
            yield mesh, style, world, object_to_view, object_to_clip, (indices, materials)


def _instance_rows(object_to_view: np.ndarray, object_to_clip: np.ndarray) -> np.ndarray:
    """(N * INSTANCE_TEXELS, 4) float32: per instance the 4 columns of
    object_to_clip then the view-z row (shaders/instancing.glsl)."""
    rows = np.empty((len(object_to_clip), shaders.INSTANCE_TEXELS, 4), dtype=np.float32)
    rows[:, :4, :] = np.swapaxes(object_to_clip, 1, 2)
    rows[:, 4, :] = object_to_view[:, 2, :]
    return rows.reshape(-1, 4)




def draw(
    items,
    view: View,
    settings,
    *,
    write_view_depth: bool = False,
    cull: bool = True,
    depth_bias: float = 0.0,
    depth_test: str = "LESS_EQUAL",
    depth_write: bool = True,
    hidden_pass: bool = False,
    show_wire: bool = True,
    write_aovs: bool = False,
    linear_depth: bool = False,
    clip_planes=None,
    program=EXACT,
) -> DrawStats:
    """Draw ``items`` into the bound framebuffer with depth test and write.

    Every fragment of a face writes depth (nothing is discarded), so a wire is
    only ever seen on the face that is the visible surface there. Items with
    a style override draw with their own parameter block (one per distinct
    style); the variant does not depend on the style. ``clip_planes``
    ((6, 4) world-space planes of a viewport's clipping region): fragments
    outside them are discarded."""
    stats = DrawStats()
    if not items:
        return stats
    settings = styled(settings, None, show_wire)
    variant = shader_variant(settings, write_view_depth, depth_bias, linear_depth)
    if hidden_pass:
        variant = replace(variant, hidden_pass=True, write_view_depth=False)
    if write_aovs:
        variant = replace(variant, write_aovs=True)
    clip_rows = None
    if clip_planes is not None:
        variant = replace(variant, clip_planes=True)
        clip_rows = clip_space_planes(clip_planes, view)
    blocks = {None: gpu.types.GPUUniformBuf(pack_params(settings, view.viewport, view.projection))}

    def ubo(style):
        block = blocks.get(style)
        if block is None:
            block = blocks[style] = gpu.types.GPUUniformBuf(
                pack_params(styled(settings, style, show_wire), view.viewport, view.projection))
        return block

    gpu.state.depth_test_set(depth_test)
    gpu.state.depth_mask_set(depth_write)
    # Window-space winding flips with a mirroring view or a projection that
    # mirrors x or y (the z flip of a GL projection does not change winding).
    flip = np.linalg.det(view.view_matrix[:3, :3]) * view.projection[0, 0] * view.projection[1, 1] < 0.0
    groups = list(_groups(items, view, cull, stats, pass_indices=write_aovs))
    try:
        # Meshes with n-gons need the fragment stage's outline walk; the rest
        # use a variant without it (llvmpipe pays for a loop even when it runs
        # zero times), so tri/quad meshes never pay for n-gons.
        for with_ngons in (False, True):
            batch = [g for g in groups if (program.supports_ngons and g[0].has_ngons) == with_ngons]
            if batch:
                _draw_groups(batch, replace(variant, ngons=with_ngons), ubo, settings, program, flip, stats, clip_rows)
    finally:
        gpu.state.face_culling_set("NONE")
    return stats


def clip_space_planes(planes, view: View) -> list:
    """World-space planes (kept where dot(plane, (x, 1)) >= 0, Blender's
    convention) as clip-space planes, flattened for the shader: with
    clip = P V world, dot(plane, world) = dot(plane P V^-1, clip), the same
    for every object, and linear in clip space, so the interpolated distance
    is exact across a triangle."""
    world = np.asarray(planes, dtype=np.float64).reshape(-1, 4)
    rows = np.zeros((shaders.CLIP_PLANES, 4))
    rows[: len(world)] = world[: shaders.CLIP_PLANES] @ np.linalg.inv(view.projection @ view.view_matrix)
    # Scale each plane so float32 keeps its precision (the sign is what counts).
    norms = np.abs(rows).max(axis=1, keepdims=True)
    rows = np.where(norms > 0.0, rows / np.where(norms > 0.0, norms, 1.0), 0.0)
    return rows.astype(np.float32).ravel().tolist()


def _set_clip_planes(shader, rows: list) -> None:
    # An array uniform: uniform_float takes at most 16 floats.
    buffer = gpu.types.Buffer("FLOAT", len(rows), rows)
    shader.uniform_vector_float(shader.uniform_from_name("clip_planes"), buffer, 4, shaders.CLIP_PLANES)


def _draw_groups(groups, variant, ubo, settings, program, flip: bool, stats: DrawStats, clip_rows=None) -> None:
    """Draw (mesh, style, world, object_to_view, object_to_clip) groups with
    one shader variant: per object, or instanced for meshes with many
    instances. ``ubo(style)`` is the parameter block of a style."""
    shader = program.shader(variant)
    uses_view_depth = shaders.uses_uniform(shader, "object_to_view_z")
    shader.bind()
    bound = None
    shader.uniform_block("params", ubo(bound))
    if clip_rows is not None:
        _set_clip_planes(shader, clip_rows)
    instanced = []  # (mesh, style, object_to_view, object_to_clip, mirrored) drawn with draw_instanced
    object_block = None  # the render passes' per-object block (write_aovs only)
    material_tables: dict = {}  # (mesh, materials) -> triangle -> material pass index texture
    for mesh, style, world, object_to_view_all, object_to_clip_all, (indices, materials) in groups:
        mirrored_all = (np.linalg.det(world[:, :3, :3]) < 0.0) != flip
        # (The instanced variant has no per-object pass values: with passes
        # every object is drawn on its own.)
        if program.supports_instancing and len(world) >= INSTANCING_MIN and not variant.write_aovs:
            if settings.use_backface_culling and mirrored_all.any() and not mirrored_all.all():
                for side in (False, True):
                    pick = mirrored_all == side
                    instanced.append((mesh, style, object_to_view_all[pick], object_to_clip_all[pick], side))
            else:
                instanced.append((mesh, style, object_to_view_all, object_to_clip_all, bool(mirrored_all[0])))
            continue
        if style is not bound:
            bound = style
            shader.uniform_block("params", ubo(style))
        for k, (object_to_view, object_to_clip, mirrored) in enumerate(
                zip(object_to_view_all, object_to_clip_all, mirrored_all)):
            if settings.use_backface_culling:
                gpu.state.face_culling_set("FRONT" if mirrored else "BACK")
            if variant.write_aovs:
                object_block = _set_object_block(shader, object_block, world[k], bool(mirrored), float(indices[k]))
                shader.uniform_sampler("triangle_material", _material_table(mesh, materials[k], material_tables))
            shader.uniform_float("object_to_clip", object_to_clip.T.astype(np.float32).ravel().tolist())
            if uses_view_depth:
                shader.uniform_float("object_to_view_z", object_to_view[2].astype(np.float32).tolist())
            shader.uniform_sampler("vertex_positions", mesh.positions)
            shader.uniform_sampler("triangle_vertices", mesh.triangles)
            if variant.ngons:
                shader.uniform_sampler("ngon_corners", mesh.ngon_corners)
            program.batch(mesh).draw(shader)
            stats.objects_drawn += 1
            stats.triangles_drawn += mesh.triangle_count
    if instanced:
        _draw_instanced(instanced, variant, ubo, settings, stats, clip_rows)


def _material_table(mesh, materials, tables: dict):
    """Texture of the IndexMA value of each triangle of ``mesh`` for one
    object's materials (face material index -> slot -> the material's
    pass_index; an index past the last slot uses the last, as Blender does).
    Shared by the instances with the same materials in one draw."""
    key = (id(mesh), None if materials is None else (id(materials[0]), materials[1]))
    table = tables.get(key)
    if table is None:
        values = np.zeros((mesh.triangle_count, 4), dtype=np.float32)
        if materials is not None and len(materials[1]):
            face_slot, slot_pass = materials
            slots = np.asarray(slot_pass, dtype=np.float32)
            face = np.asarray(mesh.triangle_polygons_cpu)
            face_ok = face < len(face_slot)
            slot = np.clip(face_slot[np.where(face_ok, face, 0)], 0, len(slots) - 1)
            values[:, 0] = np.where(face_ok, slots[slot], 0.0)
        table = tables[key] = table_texture(values)
    return table


def _set_object_block(shader, block, world: np.ndarray, mirrored: bool, pass_index: float):
    """Bind the render passes' per-object values (shaders.OBJECT_BLOCK_GLSL):
    the normal matrix (inverse transpose of the object's 3x3), negated for a
    mirrored object so that gl_FrontFacing says which side the camera sees,
    and the object's pass index. One block, updated per object."""
    try:
        normal_matrix = np.linalg.inv(world[:3, :3]).T
    except np.linalg.LinAlgError:
        normal_matrix = np.zeros((3, 3))
    if mirrored:
        normal_matrix = -normal_matrix
    values = np.zeros((3, 4), dtype=np.float32)
    values[:, :3] = normal_matrix.T  # columns
    values[0, 3] = pass_index
    data = values.tobytes()
    if block is None:
        block = gpu.types.GPUUniformBuf(data)
        shader.uniform_block("object_params", block)
    else:
        block.update(data)
    return block


def _draw_instanced(groups, variant, ubo, settings, stats: DrawStats, clip_rows=None) -> None:
    """One draw_instanced call per (mesh, style, facing) group; every
    instance's matrices in one float texture for the whole frame."""
    shader = shaders.get(replace(variant, instanced=True))
    table = table_texture(np.concatenate([_instance_rows(o2v, o2c) for _mesh, _style, o2v, o2c, _side in groups]))
    shader.bind()
    bound = None
    shader.uniform_block("params", ubo(bound))
    if clip_rows is not None:
        _set_clip_planes(shader, clip_rows)
    shader.uniform_sampler("instance_table", table)
    base = 0
    for mesh, style, _o2v, object_to_clip, mirrored in groups:
        count = len(object_to_clip)
        if style is not bound:
            bound = style
            shader.uniform_block("params", ubo(style))
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


def draw_hidden_lines(items, view: View, settings, **kwargs) -> DrawStats:
    """The hidden-line pass (image model §5.4): every face behind the depth
    already in the bound framebuffer draws its real edges dimmed and dashed,
    blended with premultiplied "over" (the caller sets the blend mode).
    Strictly GREATER, so the visible surface itself never passes: the same
    shader wrote that depth, so there is no z-fight. With one wire colour
    "over" is commutative (alpha = 1 - prod(1 - a_k)), so draw order does
    not matter."""
    return draw(items, view, settings, depth_test="GREATER", depth_write=False, hidden_pass=True, **kwargs)
