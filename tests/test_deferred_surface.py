"""The deferred surface pass (docs/image_model.md §2.5): the render first
records which triangle each pixel shows, then runs the exact fragment stage
once per recorded pixel. It must give the direct pass's image: the same
depth to the bit (the same rasterisation), the same wire and fill up to
float32 rounding (the flat inputs come from the same code; 1/w, facing and
the smooth normal are computed from the triangle instead of interpolated by
the rasteriser), and every render pass alike."""

from __future__ import annotations

import bpy
import numpy as np
import pytest

import solidwire_addon
from solidwire_addon.blender import runtime
from solidwire_addon.core import draw, passes, shaders
from solidwire_addon.core.options import DrawOptions
from tests.support import reference, scenes
from tests.test_render_passes import _enable_all

# Colour and render passes: the same up to float32 rounding of the
# analytically interpolated normal and 1/w (far below 1/255).
COLOUR_TOLERANCE = 2e-5


def refuse_variants(monkeypatch, refused, reason: str) -> None:
    """Make the shader compiler refuse every variant for which
    ``refused(variant)`` holds, as a backend without that stage would."""
    real_get = shaders.get

    def get(variant):
        if refused(variant):
            raise shaders.DeferredUnavailable(reason)
        return real_get(variant)

    monkeypatch.setattr(shaders, "get", get)


def _stages(monkeypatch):
    """Record the stage of every draw.draw call."""
    calls = []
    real = draw.draw

    def spy(*args, **kwargs):
        calls.append((kwargs.get("target") or draw.DrawTarget()).stage)
        return real(*args, **kwargs)

    monkeypatch.setattr(draw, "draw", spy)
    return calls


def _render_both(scene, path, monkeypatch):
    """(direct channels, deferred channels) of one multilayer EXR render
    each, and the stages the deferred render drew (every mesh deferred,
    however sparse on screen)."""
    monkeypatch.setattr(draw, "DEFERRED_MIN_DENSITY", 0.0)
    calls = _stages(monkeypatch)
    monkeypatch.setattr(runtime, "options", DrawOptions(deferred_surface=False))
    direct = scenes.render_multilayer_exr(scene, path.with_name(path.stem + "_direct.exr"))
    # (Drawn directly, a mesh with multi-face regions still has its lines
    # drawn over a record of its own; no pixel is resolved.)
    assert draw.RESOLVE not in calls
    calls.clear()
    monkeypatch.setattr(runtime, "options", DrawOptions(deferred_surface=True))
    deferred = scenes.render_multilayer_exr(scene, path.with_name(path.stem + "_deferred.exr"))
    # Every stage compiled (a refused one falls back to the direct image,
    # which would hide it here).
    assert shaders.deferred_available()
    return direct, deferred, list(calls)


# Below every line's reach (h + 2s, softness 1 px): where the Edge Distance
# pass is exact on both paths. Beyond a line's reach it only says "at least
# that far" (image model §6), and the two paths may say it differently: the
# direct one walks a region's edges, the deferred one measures its lines in
# the region-lines pass, which stops at their reach.
EDGE_DISTANCE_EXACT_BELOW = 2.0


def _assert_same(direct: dict, deferred: dict, undecided=None) -> None:
    """The same render passes, Hidden Wire outside ``undecided`` (the
    reference's undecided samples, where given): where a hidden layer's
    nearest line is tied with another (beyond the shared end of two edges)
    the dash phase of either is right (image model §7), and the direct pass,
    walking a region's edges, and the deferred one, peeling its layers
    (§2.6), may take different ones."""
    assert direct.keys() == deferred.keys()
    for name, values in direct.items():
        if name.endswith("Hidden Wire.X") and undecided is not None:
            decided = ~undecided
            assert decided.mean() > 0.8, name
            np.testing.assert_allclose(
                deferred[name][decided], values[decided], rtol=0.0, atol=COLOUR_TOLERANCE, err_msg=name
            )
        elif name.endswith((".Z", ".Depth.Z")) or "Depth" in name:
            np.testing.assert_array_equal(deferred[name], values, err_msg=name)
        elif name.endswith("Edge Distance.X"):
            near = np.minimum(values, deferred[name]) < EDGE_DISTANCE_EXACT_BELOW
            assert near.sum() > 100, name
            np.testing.assert_allclose(
                deferred[name][near], values[near], rtol=0.0, atol=COLOUR_TOLERANCE, err_msg=name
            )
            assert (deferred[name][~near] >= EDGE_DISTANCE_EXACT_BELOW).all(), name
        else:
            np.testing.assert_allclose(deferred[name], values, rtol=0.0, atol=COLOUR_TOLERANCE, err_msg=name)


def _mixed_scene(scene):
    """Tris, quads, n-gons, a mesh shared by a mirrored twin, edges through
    the near plane, and enough copies of one mesh to be drawn instanced."""
    scenes.near_plane_scene(scene)
    shared = scenes.monkey(scene, "Left", location=(-1.5, 4.0, 0.8))
    twin = shared.copy()
    twin.name = "Right"
    twin.location = (2.5, 5.0, 0.8)
    twin.scale = (-1.0, 1.0, 1.0)
    scene.collection.objects.link(twin)
    hexagon = scenes.from_pydata(
        scene,
        "Hexagon",
        [(np.cos(a), np.sin(a), 0.0) for a in np.linspace(0, 2 * np.pi, 7)[:-1]],
        [tuple(range(6))],
        location=(-2.0, 6.0, 2.0),
        rotation_euler=(1.2, 0.3, 0.0),
    )
    hexagon.data.materials.append(bpy.data.materials.new("Red"))
    rng = np.random.default_rng(7)
    box = scenes.cube(scene, "Box", size=0.3, location=(0.0, 6.0, 0.3))
    for i in range(draw.INSTANCING_MIN + 2):
        copy = bpy.data.objects.new(f"Box{i}", box.data)
        scene.collection.objects.link(copy)
        copy.location = (rng.uniform(-3.0, 3.0), rng.uniform(4.0, 9.0), rng.uniform(0.0, 2.5))
        copy.rotation_euler = rng.uniform(0.0, 6.0, 3)
        copy.scale = (1.0, -1.0 if i % 3 == 0 else 1.0, 1.0)


LOOKS = {
    "wire_only": {},
    "studio_fill": dict(use_fill=True, fill_shading="STUDIO", diagonal_mode="DASHED"),
    "matcap_materials": dict(
        use_fill=True, fill_shading="MATCAP", fill_color_source="MATERIAL", wire_color_source="RANDOM"
    ),
    "world_thickness_fade_culling": dict(
        thickness_mode="WORLD", use_fade=True, use_backface_culling=True, use_fill=True
    ),
    "classes_density_angle": dict(
        use_boundary_edges=True, use_sharp_edges=True, use_density_fade=True, edge_angle=20.0, use_fill=True
    ),
    "hidden_lines_silhouettes": dict(use_hidden_lines=True, use_silhouettes=True, use_fill=True),
}
INSTANCED_LOOKS = ("wire_only", "studio_fill")


@pytest.mark.parametrize("look", sorted(LOOKS))
def test_deferred_surface_gives_the_direct_image(look, output_dir, monkeypatch):
    scene = scenes.empty_scene(200, 150, **LOOKS[look])
    _mixed_scene(scene)
    # With render passes every object draws on its own; without them the
    # boxes share one instanced draw (its own visibility and resolve code).
    instanced = look in INSTANCED_LOOKS
    if not instanced:
        _enable_all(scene.view_layers[0])
    direct, deferred, stages = _render_both(scene, output_dir / f"deferred_{look}.exr", monkeypatch)
    # (The hexagon, an n-gon, is a region of its own: its outline comes from
    # the region-lines pass, between the record and the resolve.)
    assert [stage for stage in stages if stage != draw.LINES][:3] == [None, draw.VISIBILITY, draw.RESOLVE]
    assert (solidwire_addon.stats().get("instanced_draws", 0) > 0) == instanced
    combined = next(name for name in direct if name.endswith("Combined.A"))
    assert (direct[combined] > 0.0).sum() > 2000  # something was drawn
    undecided = None
    if not instanced:
        # (The Hidden Wire pass follows the hidden-line settings whether or
        # not the image shows hidden lines: so does the reference here.)
        settings = scene.solidwire
        settings.use_hidden_lines = True
        undecided = reference.render_reference(scene).on_silhouette
    _assert_same(direct, deferred, undecided)


def test_deferred_surface_with_an_orthographic_camera(output_dir, monkeypatch):
    scene = scenes.empty_scene(160, 120, use_fill=True, fill_shading="STUDIO")
    scenes.ortho_scene(scene)
    direct, deferred, stages = _render_both(scene, output_dir / "deferred_ortho.exr", monkeypatch)
    assert draw.RESOLVE in stages
    _assert_same(direct, deferred)


def test_deferred_surface_cut_by_the_far_clip_plane(output_dir, monkeypatch):
    """A floor running out through the far clip plane and a wall right at
    it: pixels at the far end of the depth range are resolved like every
    other (the resolve's rectangle, at the far end, is depth-tested against
    the record)."""
    scene = scenes.empty_scene(160, 120, use_fill=True, fill_shading="STUDIO")
    scenes.grid(scene, "Floor", x_segments=40, y_segments=40, size=30.0, location=(0.0, 0.0, -1.0))
    # Facing the camera right at the far plane: every pixel's depth is 1.
    wall_rotation = (0.5 * np.pi, 0.0, 0.0)
    scenes.grid(scene, "Wall", x_segments=24, y_segments=24, size=8.0, location=(0.0, 8.0, 0.0), rotation=wall_rotation)
    scenes.add_camera(scene, location=(0.0, 0.0, 0.0), target=(0.0, 8.0, 0.0), clip=(0.5, 8.0))
    direct, deferred, stages = _render_both(scene, output_dir / "deferred_far_plane.exr", monkeypatch)
    assert draw.RESOLVE in stages
    _assert_same(direct, deferred)


def test_a_deferred_frame_reads_nothing_of_the_last_frames_record(output_dir, monkeypatch):
    """Every mesh deferred, nothing drawn directly: the record is not
    cleared between frames, so a frame whose surfaces cover other pixels
    than the last one's (the object moved off them) must still resolve
    only its own."""
    scene = scenes.empty_scene(160, 120, use_cage_edges=True, use_fill=True, fill_shading="STUDIO")
    monkey = scenes.monkey(scene, rotation=(0.0, 0.0, 0.5))
    modifier = monkey.modifiers.new("Subdivision", "SUBSURF")
    modifier.levels = modifier.render_levels = 1
    scenes.add_camera(scene, location=(1.2, -3.4, 1.0), target=(0.0, 0.0, 0.0))
    cleared = []
    real_record = passes._record_visibility

    def record(*args, **kwargs):
        if runtime.options.deferred_surface:  # (the direct frame's lines have a record of their own)
            cleared.append(kwargs.get("clear_record", True))
        return real_record(*args, **kwargs)

    monkeypatch.setattr(passes, "_record_visibility", record)
    _render_both(scene, output_dir / "deferred_first_frame.exr", monkeypatch)
    monkey.location = (0.9, 0.0, -0.4)
    monkey.scale = (0.5, 0.5, 0.5)
    direct, deferred, _stages = _render_both(scene, output_dir / "deferred_second_frame.exr", monkeypatch)
    assert cleared == [False, False]
    _assert_same(direct, deferred)


def test_a_deferred_stage_that_does_not_compile_falls_back_to_the_direct_pass(output_dir, monkeypatch, capsys):
    """A backend whose compiler refuses a deferred stage draws the same image
    with the direct pass, says so once, and does not try again."""
    scene = scenes.empty_scene(120, 90, use_fill=True)
    _mixed_scene(scene)
    monkeypatch.setattr(runtime, "options", DrawOptions(deferred_surface=False))
    expected = scenes.render_multilayer_exr(scene, output_dir / "deferred_fallback_expected.exr")
    monkeypatch.setattr(runtime, "options", DrawOptions(deferred_surface=True))
    refuse_variants(monkeypatch, lambda variant: variant.resolve, "resolve refused")
    monkeypatch.setattr(shaders, "_deferred_support", [True])
    got = scenes.render_multilayer_exr(scene, output_dir / "deferred_fallback.exr")
    assert shaders.deferred_available() is False
    assert "deferred surface pass is not available" in capsys.readouterr().err
    for name, values in expected.items():
        np.testing.assert_array_equal(got[name], values, err_msg=name)


def test_deferred_and_direct_meshes_share_one_surface(output_dir, monkeypatch):
    """Meshes dense on screen are deferred, the rest drawn directly into the
    same depth buffer first: the image is the all-direct one, occlusion
    between the two kinds included."""
    scene = scenes.empty_scene(200, 150, use_fill=True, fill_shading="STUDIO")
    _mixed_scene(scene)
    monkeypatch.setattr(runtime, "options", DrawOptions(deferred_surface=False))
    direct = scenes.render_multilayer_exr(scene, output_dir / "deferred_mixed_direct.exr")
    monkeypatch.setattr(runtime, "options", DrawOptions(deferred_surface=True))
    real_split = draw.split_deferred
    halves = []

    def every_other_mesh(items, view, min_density=None):
        deferred, rest = real_split(items, view, min_density)
        everything = deferred + rest
        meshes = sorted({id(item.mesh) for item in everything})
        chosen = set(meshes[::2])
        halves.append((len(chosen), len(meshes)))
        return (
            [item for item in everything if id(item.mesh) in chosen],
            [item for item in everything if id(item.mesh) not in chosen],
        )

    monkeypatch.setattr(draw, "split_deferred", every_other_mesh)
    mixed = scenes.render_multilayer_exr(scene, output_dir / "deferred_mixed.exr")
    assert halves and 0 < halves[0][0] < halves[0][1] and shaders.deferred_available()
    _assert_same(direct, mixed)


class _Mesh:
    centre = np.zeros(3)
    bounds_min = -np.ones(3)
    bounds_max = np.ones(3)
    has_ngons = False
    region_line_count = 0

    def __init__(self, triangles):
        self.triangle_count = triangles


class _Item:
    matrix = np.eye(4)

    def __init__(self, mesh):
        self.mesh = mesh


def _camera_view():
    from solidwire_addon.core.view import View

    view_matrix = np.eye(4)
    view_matrix[2, 3] = -10.0  # the unit box 10 units ahead
    near, far = 0.1, 100.0
    projection = np.array(
        [
            [2.0, 0, 0, 0],
            [0, 2.0, 0, 0],
            [0, 0, (far + near) / (near - far), 2 * far * near / (near - far)],
            [0, 0, -1.0, 0],
        ]
    )
    return View(view_matrix, projection, (0, 0, 1000, 1000))


def test_dense_meshes_are_deferred_sparse_ones_direct():
    """The split follows triangles per pixel of the meshes' window boxes
    (the unit box here covers about 230 x 230 of 1000 x 1000 pixels)."""
    from solidwire_addon.core.view import box_pixels, window_boxes

    view = _camera_view()
    to_clip = view.projection @ view.view_matrix
    pixels = float(box_pixels(window_boxes(to_clip[None], -np.ones(3), np.ones(3)), view)[0])
    assert 40_000 < pixels < 70_000
    threshold = draw.DEFERRED_MIN_DENSITY * pixels  # triangles from which a plain mesh is deferred
    sparse, dense = _Item(_Mesh(int(0.9 * threshold))), _Item(_Mesh(int(1.1 * threshold)))
    deferred, direct = draw.split_deferred([sparse, dense], view)
    assert deferred == [dense] and direct == [sparse]
    count = int(1.5 * threshold / draw.DEFERRED_BLOCK_WEIGHT)
    plain, blocky = _Mesh(count), _Mesh(count)
    blocky.has_ngons = True  # n-gon and region blocks make a triangle dearer to set up
    deferred, direct = draw.split_deferred([_Item(plain), _Item(blocky)], view)
    assert [item.mesh for item in deferred] == [blocky] and [item.mesh for item in direct] == [plain]
    # Multi-face regions draw their lines over the visibility record: such a
    # mesh is deferred however sparse.
    regions = _Mesh(10)
    regions.region_line_count = 4
    assert draw.split_deferred([_Item(regions)], view)[0][0].mesh is regions


def test_numbers_beyond_float32_whole_numbers_keep_the_direct_pass():
    """Triangle, instance and draw numbers travel as float32 whole numbers:
    a mesh that would overflow them is drawn directly."""
    view = _camera_view()
    huge = _Item(_Mesh(draw.DEFERRED_MAX))
    assert draw.split_deferred([huge], view) == ([], [huge])
    huge.mesh.triangle_count = draw.DEFERRED_MAX - 1
    assert draw.split_deferred([huge], view) == ([huge], [])
    empty = _Item(_Mesh(0))  # nothing to rasterise: never an empty index buffer
    assert draw.split_deferred([empty], view) == ([], [empty])


@pytest.mark.parametrize("look", sorted(INSTANCED_LOOKS))
def test_both_triangle_numberings_give_the_same_frame(look, output_dir, monkeypatch):
    """The visibility pass numbers triangles with gl_PrimitiveID or, on a
    software rasteriser, by their provoking vertex
    (shaders.triangle_ids_by_vertex): the same frame to the bit either way,
    instanced draws included."""
    scene = scenes.empty_scene(200, 150, **LOOKS[look])
    _mixed_scene(scene)
    monkeypatch.setattr(draw, "DEFERRED_MIN_DENSITY", 0.0)
    frames = {}
    for by_vertex in (False, True):
        monkeypatch.setattr(runtime, "options", DrawOptions(triangle_ids_by_vertex=by_vertex))
        frames[by_vertex] = scenes.render_multilayer_exr(scene, output_dir / f"numbering_{look}_{by_vertex}.exr")
        assert shaders.deferred_available()
    assert solidwire_addon.stats().get("instanced_draws", 0) > 0
    for name, values in frames[False].items():
        np.testing.assert_array_equal(frames[True][name], values, err_msg=name)
    combined = next(name for name in frames[False] if name.endswith("Combined.A"))
    assert (frames[False][combined] > 0.0).sum() > 2000


def test_provoking_vertex_numbering_keeps_every_triangle():
    """Every triangle's last corner carries its number; copies keep the
    position, and the corners stay in order (so the same rasterisation)."""
    from solidwire_addon.core.cache import _provoking_triangle_numbers

    rng = np.random.default_rng(3)
    positions = rng.random((50, 3)).astype(np.float32)
    triangles = rng.integers(0, 40, size=(300, 3)).astype(np.int32)  # vertices 40..49 end no triangle
    copied, numbers, out_triangles = _provoking_triangle_numbers(len(positions), triangles.copy())  # (writes into it)
    out_positions = np.concatenate([positions, positions[copied]])
    np.testing.assert_array_equal(out_positions[:50], positions)
    np.testing.assert_array_equal(out_triangles[:, :2], triangles[:, :2])
    np.testing.assert_array_equal(out_positions[out_triangles], positions[triangles])
    np.testing.assert_array_equal(numbers[out_triangles[:, 2]], np.arange(1, 301))
    # One triangle per distinct last vertex keeps it; the rest are copies.
    assert len(out_positions) == 50 + 300 - len(np.unique(triangles[:, 2]))
