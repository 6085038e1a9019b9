"""Features that were built apart, used together: shaded fill and colour
sources with per-object overrides, render passes and the viewport clipping
region. Each alone is tested elsewhere;
these check that the shader variants combine (samplers, blocks, push
constants) and that an override shows through the colour table."""

from __future__ import annotations

import bpy
import numpy as np
import pytest

from solidwire_addon.blender import engine
from solidwire_addon.core import shaders
from tests.support import scenes

WIDTH, HEIGHT = 120, 80


@pytest.mark.parametrize(
    "variant",
    [
        shaders.ShaderVariant(
            use_fill=True,
            shading=shaders.SHADING_STUDIO,
            item_colors=True,
            material_colors=True,
            write_aovs=True,
            write_view_depth=True,
            linear_depth=True,
        ),
        shaders.ShaderVariant(
            use_fill=True, shading=shaders.SHADING_MATCAP, item_colors=True, clip_planes=True, depth_bias=1e-5
        ),
        shaders.ShaderVariant(
            use_fill=True,
            shading=shaders.SHADING_STUDIO,
            item_colors=True,
            clip_planes=True,
            instanced=True,
            depth_bias=1e-5,
        ),
        shaders.ShaderVariant(use_fill=True, clip_planes=True, write_aovs=True, ngons=True),
    ],
)
def test_combined_variants_compile(variant):
    assert shaders.get(variant) is not None


def _two_cubes(**solidwire):
    scene = scenes.empty_scene(WIDTH, HEIGHT, **solidwire)
    scenes.add_camera(scene, location=(0.0, -10.0, 4.0), target=(0.0, 0.0, 0.0))
    plain = scenes.cube(scene, "Plain", size=2.0, location=(-2.2, 0.0, 0.0), rotation=(0.3, 0.2, 0.5))
    styled = scenes.cube(scene, "Styled", size=2.0, location=(2.2, 0.0, 0.0), rotation=(0.3, 0.2, 0.5))
    return scene, plain, styled


def _override(obj, fill, wire=(0.0, 0.0, 0.0, 1.0), thickness=1.0):
    props = obj.solidwire
    props.use_override = True
    props.wire_color, props.thickness, props.fill_color = wire, thickness, fill


def test_override_fill_is_shaded_and_passes_are_written():
    scene, plain, styled = _two_cubes(use_fill=True, fill_shading="STUDIO", fill_color=(0.8, 0.8, 0.8))
    scene.solidwire.wire_color = (0.0, 0.0, 0.0, 0.0)  # fill only
    _override(styled, (0.0, 0.0, 1.0), wire=(0.0, 0.0, 0.0, 0.0))
    plain.pass_index, styled.pass_index = 3, 7
    depsgraph = bpy.context.evaluated_depsgraph_get()
    extra: dict = {}
    rgba, _depth = engine.render_scene(depsgraph, (WIDTH, HEIGHT), extra_passes=("IndexOB", "Normal"), extra_out=extra)
    index = extra["IndexOB"][..., 0]
    on_plain, on_styled = index == 3, index == 7
    assert on_plain.sum() > 200 and on_styled.sum() > 200
    # The override's blue fill, lit by the studio lights (several shades).
    blue = rgba[on_styled]
    assert (blue[:, 2] > 0.2).all() and (blue[:, :2] < 0.02).all()
    assert np.ptp(np.round(blue[:, 2], 2)) > 0.05
    grey = rgba[on_plain]
    assert (np.abs(grey[:, 0] - grey[:, 2]) < 0.02).all() and (grey[:, 0] > 0.1).all()
    normals = extra["Normal"][on_styled]
    assert np.allclose(np.linalg.norm(normals, axis=-1), 1.0, atol=1e-3)


def test_override_colours_feed_the_colour_sources():
    """With a per-item colour table (wire source RANDOM), an overridden
    object's SINGLE fill is its override's; material colours and IndexMA
    read their own tables in one draw."""
    scene, plain, styled = _two_cubes(
        use_fill=True, fill_shading="FLAT", fill_color=(0.8, 0.8, 0.8), wire_color_source="RANDOM"
    )
    scene.solidwire.wire_color = (0.0, 0.0, 0.0, 0.0)
    _override(styled, (1.0, 0.0, 0.0), wire=(0.0, 0.0, 0.0, 0.0))
    depsgraph = bpy.context.evaluated_depsgraph_get()
    extra: dict = {}
    rgba, _depth = engine.render_scene(depsgraph, (WIDTH, HEIGHT), extra_passes=("IndexOB",), extra_out=extra)
    covered = rgba[..., 3] > 0.99
    left = covered.copy()
    left[:, WIDTH // 2 :] = False
    right = covered.copy()
    right[:, : WIDTH // 2] = False
    assert np.allclose(rgba[left][:, :3], 0.8, atol=0.01)
    assert np.allclose(rgba[right][:, :3], (1.0, 0.0, 0.0), atol=0.01)

    # Material colours with the IndexMA pass (corner table and material table).
    material = bpy.data.materials.new("Green")
    material.diffuse_color = (0.0, 1.0, 0.0, 1.0)
    material.pass_index = 5
    plain.data.materials.append(material)
    scene.solidwire.fill_color_source = "MATERIAL"
    depsgraph = bpy.context.evaluated_depsgraph_get()
    extra = {}
    rgba, _depth = engine.render_scene(depsgraph, (WIDTH, HEIGHT), extra_passes=("IndexMA",), extra_out=extra)
    on_plain = extra["IndexMA"][..., 0] == 5
    assert on_plain.sum() > 200
    assert np.allclose(rgba[on_plain][:, :3], (0.0, 1.0, 0.0), atol=0.01)
