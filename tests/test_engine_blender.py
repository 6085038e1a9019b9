"""SOLIDWIRE as a Blender render engine: view layers, render region, the
result always ended, Esc, and Blender's generic panels."""

from __future__ import annotations

import bpy
import numpy as np
import pytest

from solidwire_addon.blender import engine, gather, runtime
from solidwire_addon.core import exr
from tests.support import scenes

_multilayer_render = scenes.render_multilayer_exr


def _two_layer_scene():
    """A cube on the left in collection Left, a sphere on the right in
    collection Right; layer 'Left' excludes Right, layer 'Right' excludes Left."""
    scene = scenes.empty_scene(64, 48)
    scenes.add_camera(scene, location=(0.0, -10.0, 0.0), target=(0.0, 0.0, 0.0))
    left_objects = scenes.cube(scene, name="LeftCube", size=1.5, location=(-2.0, 0.0, 0.0))
    right_objects = scenes.uv_sphere(scene, name="RightSphere", location=(2.0, 0.0, 0.0))
    for name, obj in (("Left", left_objects), ("Right", right_objects)):
        collection = bpy.data.collections.new(name)
        scene.collection.children.link(collection)
        for owner in list(obj.users_collection):
            owner.objects.unlink(obj)
        collection.objects.link(obj)
    first = scene.view_layers[0]
    first.name = "Left"
    second = scene.view_layers.new("Right")
    first.layer_collection.children["Right"].exclude = True
    second.layer_collection.children["Left"].exclude = True
    return scene


def test_each_view_layer_is_rendered_into_its_own_result_layer(tmp_path):
    scene = _two_layer_scene()
    channels = _multilayer_render(scene, tmp_path / "layers.exr")
    left = exr.exr_pass(channels, "Left", "Combined", "RGBA")
    right = exr.exr_pass(channels, "Right", "Combined", "RGBA")
    assert left is not None and right is not None
    half = left.shape[1] // 2
    # Each layer shows only its own collection's object, on its own side.
    assert left[:, :half, 3].max() > 0.5 and left[:, half:, 3].max() == 0.0
    assert right[:, half:, 3].max() > 0.5 and right[:, :half, 3].max() == 0.0


@pytest.fixture
def region_scene():
    scene = scenes.empty_scene(80, 60)
    scenes.monkey(scene)
    scenes.add_camera(scene, location=(2.5, -4.0, 1.8), target=(0.0, 0.0, 0.0))
    return scene


@pytest.mark.parametrize("crop", [True, False])
def test_render_region_matches_the_full_render(tmp_path, region_scene, crop):
    full = scenes.render_to_file(region_scene, tmp_path / "full.png")
    render = region_scene.render
    render.use_border = True
    render.use_crop_to_border = crop
    render.border_min_x, render.border_max_x = 0.25, 0.8
    render.border_min_y, render.border_max_y = 0.1, 0.6
    part = scenes.render_to_file(region_scene, tmp_path / "region.png")
    x0, y0, w, h = engine.region_of(region_scene, 80, 60)
    assert (x0, y0, w, h) == (20, 6, 44, 30)
    if crop:
        assert part.shape[:2] == (h, w)
        window = part
    else:
        assert part.shape[:2] == (60, 80)
        window = part[y0 : y0 + h, x0 : x0 + w]
        outside = np.ones((60, 80), bool)
        outside[y0 : y0 + h, x0 : x0 + w] = False
        assert part[outside, 3].max() == 0.0  # nothing drawn outside the region
    expected = full[y0 : y0 + h, x0 : x0 + w]
    assert window[..., 3].max() > 0.5
    assert np.abs(window - expected).max() <= 1.5 / 65535


def test_a_failure_while_writing_still_ends_the_result(region_scene, tmp_path, monkeypatch):
    def broken(_render_pass, _array):
        raise RuntimeError("disk on fire")

    monkeypatch.setattr(engine, "write_pass", broken)
    region_scene.render.filepath = str(tmp_path / "broken.png")
    with pytest.raises(RuntimeError, match="could not write the result: RuntimeError: disk on fire"):
        bpy.ops.render.render(write_still=True, scene=region_scene.name)
    monkeypatch.undo()
    image = scenes.render_to_file(region_scene, tmp_path / "after.png")  # Blender is fine afterwards
    assert image[..., 3].max() > 0.5


def test_esc_stops_before_drawing(region_scene):
    depsgraph = bpy.context.evaluated_depsgraph_get()
    runtime.begin_frame()
    items, _seen, _ms = gather.gather(depsgraph, runtime.mesh_cache, should_stop=lambda: True)
    assert items == []
    assert engine.render_scene(depsgraph, (80, 60), should_stop=lambda: True) is None
    stages = []
    rendered = engine.render_scene(depsgraph, (80, 60), report=lambda text, fraction: stages.append(fraction))
    assert rendered is not None and stages == sorted(stages) and len(stages) >= 3


TABS = {"data", "object", "world", "render", "output", "view_layer", "physics", "constraint", "modifier", "material"}


def _panels_for(engine_id: str) -> set[str]:
    names = set()
    for panel in bpy.types.Panel.__subclasses__():
        engines = getattr(panel, "COMPAT_ENGINES", None)
        in_tabs = getattr(panel, "bl_space_type", "") == "PROPERTIES" and getattr(panel, "bl_context", "") in TABS
        if in_tabs and isinstance(engines, set) and engine_id in engines:
            names.add(panel.__name__)
    return names


def test_blenders_generic_panels_offer_solidwire():
    solidwire, workbench = _panels_for("SOLIDWIRE"), _panels_for("BLENDER_WORKBENCH")
    # Every panel Workbench gets that is marked for any engine, SolidWire gets too.
    generic = {name for name in workbench if "BLENDER_RENDER" in getattr(bpy.types, name).COMPAT_ENGINES}
    assert generic - {"RENDER_PT_simplify"} <= solidwire, sorted(generic - solidwire)
    for needed in (
        "DATA_PT_lens",
        "DATA_PT_camera",
        "DATA_PT_vertex_groups",
        "DATA_PT_shape_keys",
        "DATA_PT_uv_texture",
        "OBJECT_PT_visibility",
        "WORLD_PT_context_world",
    ):
        assert needed in solidwire, needed
    # Engine-specific panels (not marked for any engine) stay hidden, apart
    # from the film's transparency switch.
    specific = {name for name in solidwire if "BLENDER_RENDER" not in getattr(bpy.types, name).COMPAT_ENGINES}
    assert specific <= {
        "CYCLES_RENDER_PT_film_transparency",
        "RENDER_PT_eevee_film",
        "RENDER_PT_solidwire",
        "VIEWLAYER_PT_solidwire_passes",
    }, sorted(specific)
    print(f"panels in {sorted(TABS)}: SOLIDWIRE {len(solidwire)}, BLENDER_WORKBENCH {len(workbench)}")


@pytest.mark.parametrize("use_region", [False, True])
def test_tiled_frames_equal_the_frame_drawn_in_one_piece(tmp_path, region_scene, monkeypatch, use_region):
    """Big frames are drawn tile by tile (engine.TILE_PIXELS); with tiny tiles
    the image equals the one-piece render (each tile is an exact window of
    the frame's projection)."""
    region_scene.solidwire.use_silhouettes = True  # the fin pass is tiled too
    region_scene.solidwire.diagonal_mode = "DASHED"
    if use_region:
        render = region_scene.render
        render.use_border, render.use_crop_to_border = True, True
        render.border_min_x, render.border_max_x, render.border_min_y, render.border_max_y = 0.1, 0.9, 0.2, 0.95
    whole = scenes.render_to_file(region_scene, tmp_path / "whole.png")
    monkeypatch.setattr(engine, "TILE_PIXELS", 17 * 13)
    tiles = list(engine.tiles_of(engine.region_of(region_scene, 80, 60)))
    assert len(tiles) > 6 and len({(w, h) for _x, _y, w, h in tiles}) > 1  # uneven edge tiles too
    tiled = scenes.render_to_file(region_scene, tmp_path / "tiled.png")
    assert tiled.shape == whole.shape and whole[..., 3].max() > 0.5
    assert np.abs(tiled - whole).max() <= 1.5 / 65535


def test_a_render_after_the_window_context_drew_is_right(tmp_path):
    """F12 draws in the render engine's own GL context, the overlay and
    scripts in the window context. A program drawn with in both gave a wrong
    F12 image (most of the surface missing); each context now has its own
    programs (core/shaders.py, gl_context)."""
    scene = _two_layer_scene()
    _multilayer_render(scene, tmp_path / "layers.exr")  # the engine context draws these variants
    scene = scenes.empty_scene(80, 60)
    scenes.monkey(scene)
    scenes.add_camera(scene, location=(2.5, -4.0, 1.8), target=(0.0, 0.0, 0.0))
    window_rgba, _depth = engine.render_scene(bpy.context.evaluated_depsgraph_get(), (80, 60))  # window context
    scene = scenes.empty_scene(80, 60)  # a new file: new meshes, same variants
    scenes.monkey(scene)
    scenes.add_camera(scene, location=(2.5, -4.0, 1.8), target=(0.0, 0.0, 0.0))
    f12 = scenes.render_to_file(scene, tmp_path / "f12.png")
    assert np.abs(f12[..., 3] - window_rgba[..., 3]).max() <= 1.5 / 65535


def test_kept_readback_equals_a_fresh_one_and_is_reused(region_scene):
    """The render engine reads each tile into buffers the targets keep
    (core.targets.Targets.read): the same pixels as a fresh readback, and the
    next tile of that size lands in the same memory."""
    region_scene.render.film_transparent = False  # the film is composited in place, into the kept buffer
    frame = engine.PreparedFrame(bpy.context.evaluated_depsgraph_get(), (80, 60))
    try:
        fresh_rgba, fresh_depth, _extra = frame.draw((0, 0, 80, 60))
        kept_rgba, kept_depth, _extra = frame.draw((0, 0, 80, 60), keep_readback=True)
        assert np.array_equal(kept_rgba, fresh_rgba) and np.array_equal(kept_depth, fresh_depth)
        assert fresh_rgba[..., 3].min() == 1.0 and (fresh_depth < 1e9).sum() > 300
        first = kept_rgba.copy()
        shifted_rgba, _depth, _extra = frame.draw((20, 10, 80, 60), keep_readback=True)
        assert np.shares_memory(shifted_rgba, kept_rgba) and not np.shares_memory(fresh_rgba, kept_rgba)
        assert not np.array_equal(shifted_rgba, first)  # another window of the frame, in the same buffer
    finally:
        frame.finish()


def test_a_frame_without_a_depth_pass_reads_no_view_depth(region_scene, tmp_path, monkeypatch):
    """The render engine reads back only what the view layer's passes need:
    without the Depth pass the view depth stays on the GPU, and Combined is
    the same as with it."""
    from solidwire_addon.core import targets

    asked = []
    real_read = targets.Targets.read

    def spy(self, **kwargs):
        asked.append(kwargs.get("depth", True))
        return real_read(self, **kwargs)

    monkeypatch.setattr(targets.Targets, "read", spy)
    layer = region_scene.view_layers[0]
    channels = {}
    for use_pass_z in (True, False):
        layer.use_pass_z = use_pass_z
        asked.clear()
        channels[use_pass_z] = _multilayer_render(region_scene, tmp_path / f"depth_{use_pass_z}.exr")
        assert asked == [use_pass_z]
    with_depth, without_depth = channels[True], channels[False]
    depth_names = [name for name in with_depth if "Depth" in name]
    assert depth_names and not any("Depth" in name for name in without_depth)
    assert (with_depth[depth_names[0]] < 1e9).sum() > 300
    for name, values in without_depth.items():
        np.testing.assert_array_equal(values, with_depth[name], err_msg=name)
