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

from . import colors, matcaps, shaders
from .cache import table_texture
from .log import warn_once
from .settings import pack_params
from .view import DrawStats, View, outside_frustum_many, translation


def shader_variant(settings, write_view_depth: bool = False, depth_bias: float = 0.0) -> shaders.ShaderVariant:
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
        thickness_mode={"WORLD": shaders.THICKNESS_WORLD, "DEPTH": shaders.THICKNESS_DEPTH}.get(
            settings.thickness_mode, shaders.THICKNESS_PIXELS
        ),
        shading=fill_shading(settings),
        item_colors=colors.needs_item_colors(settings),
        material_colors=colors.needs_material_colors(settings),
    )


def fill_shading(settings) -> int:
    """The shading the fill asks for (none without a fill)."""
    if not settings.use_fill:
        return shaders.SHADING_FLAT
    return {"STUDIO": shaders.SHADING_STUDIO, "MATCAP": shaders.SHADING_MATCAP}.get(
        settings.fill_shading, shaders.SHADING_FLAT
    )


def needs_corners(settings) -> bool:
    """Whether meshes must carry their corner table (normals, material
    indices): extracted and uploaded only then (see gather)."""
    return fill_shading(settings) != shaders.SHADING_FLAT or colors.needs_material_colors(settings)


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


def _groups(items, view: View, cull: bool, stats: DrawStats):
    """Items grouped by GPU mesh with their float64-composed matrices, culled
    (vectorised over each group). Yields (mesh, world (N,4,4), object_to_view,
    object_to_clip, item indices (N,)) with only the visible instances."""
    by_mesh: dict[int, list] = {}
    for index, item in enumerate(items):
        by_mesh.setdefault(id(item.mesh), []).append(index)
    for group in by_mesh.values():
        mesh = items[group[0]].mesh
        indices = np.asarray(group, dtype=np.int64)
        world = np.stack([items[i].matrix for i in group]) if len(group) > 1 else items[group[0]].matrix[None]
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
                indices = indices[keep]
        if len(world):
            yield mesh, world, object_to_view, object_to_clip, indices


def normal_to_view(object_to_view: np.ndarray) -> np.ndarray:
    """(..., 4, 4): the inverse transpose of the 3x3 part (normals to view
    space), as a 4x4 with zeros elsewhere; non-invertible -> zeros."""
    linear = object_to_view[..., :3, :3]
    out = np.zeros(linear.shape[:-2] + (4, 4))
    with np.errstate(all="ignore"):
        ok = np.abs(np.linalg.det(linear)) > 1e-300
        safe = np.where(ok[..., None, None], linear, np.eye(3))
        out[..., :3, :3] = np.swapaxes(np.linalg.inv(safe), -1, -2) * ok[..., None, None]
    return out


def _instance_rows(object_to_view, object_to_clip, info) -> np.ndarray:
    """(N * INSTANCE_TEXELS, 4) float32: per instance the 4 columns of
    object_to_clip, the view-z row, the 3 columns of the normal matrix and
    the item info (colour-table base, mirrored) (shaders/instancing.glsl)."""
    rows = np.zeros((len(object_to_clip), shaders.INSTANCE_TEXELS, 4), dtype=np.float32)
    rows[:, :4, :] = np.swapaxes(object_to_clip, 1, 2)
    rows[:, 4, :] = object_to_view[:, 2, :]
    rows[:, 5:8, :] = np.swapaxes(normal_to_view(object_to_view), 1, 2)[:, :3, :]
    rows[:, 8, :] = info
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
    program=EXACT,
) -> DrawStats:
    """Draw ``items`` into the bound framebuffer with depth test and write.

    Every fragment of a face writes depth (nothing is discarded), so a wire is
    only ever seen on the face that is the visible surface there."""
    stats = DrawStats()
    if not items:
        return stats
    variant = shader_variant(settings, write_view_depth, depth_bias)
    if hidden_pass:
        variant = replace(variant, hidden_pass=True, write_view_depth=False, shading=shaders.SHADING_FLAT,
                          material_colors=False)
    extras = {}
    if variant.shading == shaders.SHADING_MATCAP:
        extras["matcap_image"] = matcaps.texture(settings.matcap)
        if extras["matcap_image"] is None:
            variant = replace(variant, shading=shaders.SHADING_FLAT)
    if variant.shading != shaders.SHADING_FLAT or variant.material_colors:
        if any(item.mesh.corners is None for item in items):
            # Meshes gathered without their corner table (a caller that did
            # not ask for it): draw flat rather than read a missing table.
            warn_once(("corners",), "SolidWire: meshes were gathered without normals; drawing a flat fill")
            variant = replace(variant, shading=shaders.SHADING_FLAT, material_colors=False)
    bases = np.zeros(len(items), dtype=np.int64)
    if variant.item_colors:
        table, bases = colors.color_table(items, settings)
        extras["item_colors"] = table_texture(table)
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
            batch = [g for g in groups if (program.supports_ngons and g[0].has_ngons) == with_ngons]
            if batch:
                _draw_groups(batch, replace(variant, ngons=with_ngons), ubo, settings, program, flip, stats,
                             extras, bases)
    finally:
        gpu.state.face_culling_set("NONE")
    return stats


def _bind_extras(shader, variant, extras) -> None:
    """Samplers of the shaded fill and the colour sources."""
    if variant.shading == shaders.SHADING_MATCAP:
        shader.uniform_sampler("matcap_image", extras["matcap_image"])
    if variant.item_colors:
        shader.uniform_sampler("item_colors", extras["item_colors"])


def _bind_mesh(shader, variant, mesh) -> None:
    shader.uniform_sampler("vertex_positions", mesh.positions)
    shader.uniform_sampler("triangle_vertices", mesh.triangles)
    if variant.ngons:
        shader.uniform_sampler("ngon_corners", mesh.ngon_corners)
    if variant.uses_corners:
        shader.uniform_sampler("corner_table", mesh.corners)


def _draw_groups(groups, variant, ubo, settings, program, flip: bool, stats: DrawStats, extras=None,
                 bases=None) -> None:
    """Draw (mesh, world, object_to_view, object_to_clip, item indices)
    groups with one shader variant: per object, or instanced for meshes with
    many instances."""
    extras = extras or {}
    shader = program.shader(variant)
    uses_view_depth = shaders.uses_uniform(shader, "object_to_view_z")
    shader.bind()
    shader.uniform_block("params", ubo)
    _bind_extras(shader, variant, extras)
    instanced = []  # (mesh, object_to_view, object_to_clip, info, mirrored) drawn with draw_instanced
    single = []  # (mesh, object_to_view, object_to_clip, info, mirrored) drawn one by one
    for mesh, world, object_to_view_all, object_to_clip_all, indices in groups:
        mirrored_all = (np.linalg.det(world[:, :3, :3]) < 0.0) != flip
        info_all = np.zeros((len(world), 4))
        if bases is not None and len(bases):
            info_all[:, 0] = bases[indices]
        info_all[:, 1] = mirrored_all
        if program.supports_instancing and len(world) >= INSTANCING_MIN:
            if settings.use_backface_culling and mirrored_all.any() and not mirrored_all.all():
                for side in (False, True):
                    pick = mirrored_all == side
                    instanced.append((mesh, object_to_view_all[pick], object_to_clip_all[pick], info_all[pick], side))
            else:
                instanced.append((mesh, object_to_view_all, object_to_clip_all, info_all, bool(mirrored_all[0])))
            continue
        single.extend(zip([mesh] * len(world), object_to_view_all, object_to_clip_all, info_all, mirrored_all))
    if single and variant.per_item:
        # Normal matrices and item info of every object in one texture
        # (item_table.glsl); each draw says its slot.
        rows = np.zeros((len(single), shaders.ITEM_TEXELS, 4), dtype=np.float32)
        rows[:, :3, :] = np.swapaxes(normal_to_view(np.stack([o2v for _m, o2v, _c, _i, _s in single])), 1, 2)[:, :3, :]
        rows[:, 3, :] = np.stack([info for _m, _v, _c, info, _s in single])
        item_table = table_texture(rows.reshape(-1, 4))  # kept alive until the draws are done
        shader.uniform_sampler("item_table", item_table)
    if single:
        for slot, (mesh, object_to_view, object_to_clip, _info, mirrored) in enumerate(single):
            if settings.use_backface_culling:
                gpu.state.face_culling_set("FRONT" if mirrored else "BACK")
            shader.uniform_float("object_to_clip", object_to_clip.T.astype(np.float32).ravel().tolist())
            if uses_view_depth:
                shader.uniform_float("object_to_view_z", object_to_view[2].astype(np.float32).tolist())
            if variant.per_item:
                shader.uniform_int("item_slot", slot)
            _bind_mesh(shader, variant, mesh)
            program.batch(mesh).draw(shader)
            stats.objects_drawn += 1
            stats.triangles_drawn += mesh.triangle_count
    if instanced:
        _draw_instanced(instanced, variant, ubo, settings, stats, extras)


def _draw_instanced(groups, variant, ubo, settings, stats: DrawStats, extras=None) -> None:
    """One draw_instanced call per (mesh, facing) group; every instance's
    matrices in one float texture for the whole frame."""
    shader = shaders.get(replace(variant, instanced=True))
    table = table_texture(np.concatenate([_instance_rows(o2v, o2c, info) for _mesh, o2v, o2c, info, _side in groups]))
    shader.bind()
    shader.uniform_block("params", ubo)
    shader.uniform_sampler("instance_table", table)
    _bind_extras(shader, variant, extras or {})
    base = 0
    for mesh, _o2v, object_to_clip, _info, mirrored in groups:
        count = len(object_to_clip)
        if settings.use_backface_culling:
            gpu.state.face_culling_set("FRONT" if mirrored else "BACK")
        shader.uniform_int("instance_base", base)
        _bind_mesh(shader, variant, mesh)
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
