"""Viewport = render: the overlay shows the colours of the F12 render under the
scene's colour management (docs/image_model.md §9).

The viewport is rebuilt offscreen as in tests/test_overlay.py (an SRGB8_A8
overlay target: the GPU stores sRGB(out) in 8 bits, as Blender's overlay
buffer does). What the screen then shows is emulated with Blender's own
merge of the overlay buffer (OCIO_ProcessColor, ``do_overlay_merge``: the
buffer is read back to linear and leaves through a 1/2.2 power where the
overlay is opaque). That is compared with the PNG the SOLIDWIRE engine's F12
render writes with the same scene's view transform.
"""

from __future__ import annotations

import bpy
import numpy as np
import pytest

from solidwire_addon.blender import color_management, engine
from solidwire_addon.blender.gpu_context import ensure_gpu
from solidwire_addon.blender.views import camera_view
from solidwire_addon.core import display_transform, shaders
from solidwire_addon.core.targets import BACKGROUND_DEPTH
from tests.support import scenes
from tests.test_overlay import FakeViewport, srgb_to_linear

pytestmark = pytest.mark.filterwarnings("ignore:'DEPTH24_STENCIL8' is deprecated:DeprecationWarning")

WIDTH, HEIGHT = 160, 120
TOLERANCE = 3.0 / 255.0
WIRE = (0.5, 0.2, 0.1, 1.0)  # 188/124/89 in the viewport against 174/122/92 rendered (AgX) before §9
FILL = (0.05, 0.3, 0.6)

# view settings per case (display device sRGB unless said)
CASES = {
    "standard": dict(view_transform="Standard"),
    "agx": dict(view_transform="AgX"),
    "filmic": dict(view_transform="Filmic"),
    "agx_punchy_exposure_gamma": dict(view_transform="AgX", look="AgX - Punchy", exposure=0.7, gamma=1.2),
}


@pytest.fixture(autouse=True)
def gpu_ready():
    ensure_gpu()


def set_view(scene, view_transform, look="None", exposure=0.0, gamma=1.0, display_device="sRGB"):
    scene.display_settings.display_device = display_device
    scene.view_settings.view_transform = view_transform
    scene.view_settings.look = look
    scene.view_settings.exposure = exposure
    scene.view_settings.gamma = gamma


def on_screen(stored: np.ndarray) -> np.ndarray:
    """What Blender shows of an opaque overlay pixel whose buffer holds
    ``stored`` (sRGB-encoded 0..1, 8-bit): read back to linear by the SRGB8_A8
    texture, merged in the 2.2-power space."""
    return srgb_to_linear(stored) ** (1.0 / display_transform.OVERLAY_MERGE_GAMMA)


def build_scene(**solidwire):
    scene = scenes.empty_scene(WIDTH, HEIGHT, **solidwire)
    scenes.add_camera(scene, location=(6.0, -5.0, 4.0))
    scenes.cube(scene, "Front", size=2.4)
    scenes.uv_sphere(scene, "Back", radius=1.2, location=(-1.6, 1.8, -0.3))
    return scene


def erode(mask: np.ndarray, radius: int = 2) -> np.ndarray:
    out = mask.copy()
    for _ in range(radius):
        grown = out.copy()
        grown[1:] &= out[:-1]
        grown[:-1] &= out[1:]
        grown[:, 1:] &= out[:, :-1]
        grown[:, :-1] &= out[:, 1:]
        out = grown
    return out


def overlay_and_render(scene, tmp_path, with_depth=False, **draw):
    """(screen RGB, overlay alpha, PNG RGBA, engine's linear RGBA[, engine's
    view depth]), bottom row first; ``draw``: draw_scene_overlay's options."""
    depsgraph = bpy.context.evaluated_depsgraph_get()
    png = scenes.render_to_file(scene, tmp_path / "render.png")
    linear, depth = engine.render_scene(depsgraph, (WIDTH, HEIGHT))
    view = camera_view(scene, depsgraph, (WIDTH, HEIGHT))
    viewport = FakeViewport(WIDTH, HEIGHT)
    viewport.draw_overlay(depsgraph, view, scene.solidwire.snapshot(), **draw)
    stored = viewport.rgba()
    out = on_screen(stored[..., :3]), stored[..., 3], png, linear
    return (*out, depth) if with_depth else out


def flat_pixels(linear: np.ndarray, color) -> np.ndarray:
    """Pixels whose scene-linear render colour is exactly ``color`` (opaque)."""
    return (np.abs(linear[..., :3] - np.asarray(color[:3])).max(axis=-1) < 1e-5) & (linear[..., 3] > 0.9999)


@pytest.mark.parametrize("case", list(CASES))
def test_flat_colours_match_the_render(case, tmp_path):
    """Fill and wire core pixels: the screen shows the PNG's colour within 3/255."""
    scene = build_scene(use_fill=True, fill_color=FILL, wire_color=WIRE, thickness=6.0, diagonal_mode="SOLID")
    set_view(scene, **CASES[case])
    screen, alpha, png, linear = overlay_and_render(scene, tmp_path)
    opaque = erode((alpha > 0.999) & (png[..., 3] > 0.9999))
    for name, color in (("fill", FILL), ("wire", WIRE)):
        pixels = opaque & flat_pixels(linear, color)
        assert pixels.sum() > 50, f"{name}: too few flat pixels"
        error = np.abs(screen[pixels] - png[pixels][:, :3]).max()
        assert error <= TOLERANCE, f"{case} {name}: max error {error * 255:.2f}/255"
    # Everything opaque (the anti-aliased mix of wire and fill too: both
    # paths mix scene-linear, then transform).
    error = np.abs(screen[opaque] - png[opaque][:, :3]).max()
    assert error <= TOLERANCE, f"{case}: max error over all opaque pixels {error * 255:.2f}/255"


def test_without_the_table_the_viewport_differs(tmp_path):
    """The comparison above sees the problem: scene-linear output (before
    §9) is far off the AgX render."""
    scene = build_scene(use_fill=True, fill_color=FILL, wire_color=WIRE, thickness=6.0, diagonal_mode="SOLID")
    set_view(scene, "AgX")
    screen, alpha, png, linear = overlay_and_render(scene, tmp_path, display=None)
    pixels = erode((alpha > 0.999) & (png[..., 3] > 0.9999)) & flat_pixels(linear, WIRE)
    assert np.abs(screen[pixels] - png[pixels][:, :3]).max() > 10.0 / 255.0


def test_the_fix_is_visible():
    """The numbers of the report: AgX shows the wire (0.5, 0.2, 0.1) as the
    render's 174/122/92, not sRGB's 188/124/89."""
    scene = scenes.empty_scene(8, 8)
    set_view(scene, "AgX")
    lut = color_management.display_lut(scene)
    rendered = color_management.transform_colors(scene, [WIRE[:3]])[0]
    assert np.round(rendered * 255).tolist() == [174, 122, 92]
    assert np.abs(lut_lookup(lut, WIRE[:3]) - rendered).max() <= 1.0 / 255.0


def test_wire_over_transparency_and_silhouettes(tmp_path):
    """Wire only (premultiplied over nothing) with full silhouettes: the
    fin shader applies the transform too; wire cores match the render."""
    scene = build_scene(wire_color=WIRE, thickness=6.0, diagonal_mode="SOLID", use_silhouettes=True)
    set_view(scene, "AgX", look="AgX - Medium High Contrast")
    screen, alpha, png, _linear, depth = overlay_and_render(scene, tmp_path, with_depth=True)
    core = erode((alpha > 0.999) & (png[..., 3] > 0.9999), 1)
    assert core.sum() > 100
    error = np.abs(screen[core] - png[core][:, :3]).max()
    assert error <= TOLERANCE, f"max error {error * 255:.2f}/255"
    # Some of them lie outside every face: drawn by the fins alone.
    assert (core & (depth >= BACKGROUND_DEPTH)).sum() > 10


def test_hidden_lines_draw_with_the_transform(tmp_path):
    """The hidden-line and wire passes compile and draw with the LUT."""
    scene = build_scene(use_fill=True, fill_color=FILL, wire_color=WIRE, thickness=6.0, use_hidden_lines=True)
    set_view(scene, "Filmic")
    screen, alpha, png, linear = overlay_and_render(scene, tmp_path)
    opaque = erode((alpha > 0.999) & (png[..., 3] > 0.9999))
    pixels = opaque & flat_pixels(linear, FILL)
    assert pixels.sum() > 50
    assert np.abs(screen[pixels] - png[pixels][:, :3]).max() <= TOLERANCE


# -- the table itself -------------------------------------------------------------------


def lut_lookup(lut, colors) -> np.ndarray:
    """The shader's lookup (display_transform.glsl) in float64, before the
    merge power: shaper, then tetrahedral interpolation of the display
    values, with the shader's tie rules."""
    colors = np.maximum(np.asarray(colors, dtype=np.float64).reshape(-1, 3), 0.0)
    k, n = lut.shaper
    last = lut.size - 1
    u = np.clip(np.log2(1.0 + colors * k) * n, 0.0, 1.0) * last
    i = np.minimum(u.astype(int), last - 1)
    f = u - i
    rolled, back = f[:, [1, 2, 0]], f[:, [2, 0, 1]]  # f.yzx, f.zxy
    largest = ((f >= rolled) & ~(back >= f)).astype(int)  # step(f.yzx, f) * (1 - step(f, f.zxy))
    smallest = ((rolled >= f) & ~(f >= back)).astype(int)  # step(f, f.yzx) * (1 - step(f.zxy, f))
    f_max, f_min = f.max(axis=1, keepdims=True), f.min(axis=1, keepdims=True)
    f_mid = f.sum(axis=1, keepdims=True) - f_max - f_min

    def texel(node):
        return lut.display[node[:, 2], node[:, 1], node[:, 0]].astype(np.float64)

    return (
        (1.0 - f_max) * texel(i)
        + (f_max - f_mid) * texel(i + largest)
        + (f_mid - f_min) * texel(i + 1 - smallest)
        + f_min * texel(i + 1)
    )


# Measured error of the table against Blender's exact transform (bpy 5.0.1,
# 5000 colours), in 255ths: (p99.9 in [0, 1], max in [0, 1], max up to 1.3),
# with some margin. The transforms people view with are within 2.5/255;
# transforms with sharp features (Khronos PBR Neutral's highlight
# desaturation, ACES 1.3 near zero, Filmic Log's log toe below the shaper's
# knee) are less exact, and are kept at what they measure. False Color is a
# step function no interpolated table follows (it is not tested).
ACCURACY = {
    "standard": (dict(view_transform="Standard"), 0.5, 0.5, 0.5),
    "agx": (dict(view_transform="AgX"), 1.5, 2.5, 2.5),
    "filmic": (dict(view_transform="Filmic"), 1.0, 1.0, 1.0),
    "agx_punchy_exposure": (dict(view_transform="AgX", look="AgX - Punchy", exposure=0.7), 2.0, 2.5, 2.5),
    "standard_exposure_up": (dict(view_transform="Standard", exposure=2.0), 0.5, 0.5, 0.5),
    "agx_display_p3": (dict(view_transform="AgX", display_device="Display P3"), 1.0, 1.5, 1.5),
    "aces_2": (dict(view_transform="ACES 2.0"), 1.0, 1.5, 1.5),
    "khronos_pbr_neutral": (dict(view_transform="Khronos PBR Neutral"), 3.0, 3.5, 3.5),
    "aces_1_3": (dict(view_transform="ACES 1.3"), 6.5, 10.5, 10.5),
    "filmic_log": (dict(view_transform="Filmic Log"), 9.0, 9.0, 9.0),
}


@pytest.mark.parametrize("case", list(ACCURACY))
def test_table_interpolation_error(case):
    """The table against Blender's exact transform of 5000 colours (in [0, 1],
    and up to 1.3 as shaded fills reach)."""
    view, p999, worst_unit, worst = ACCURACY[case]
    scene = scenes.empty_scene(8, 8)
    try:
        set_view(scene, **view)
    except TypeError as exc:  # a view transform this Blender's OCIO config lacks
        pytest.skip(str(exc))
    rng = np.random.default_rng(7)
    colors = np.concatenate([rng.random((3000, 3)), rng.random((1000, 3)) ** 3, rng.random((1000, 3)) * 1.3])
    exact = color_management.transform_colors(scene, colors)
    error = np.abs(lut_lookup(color_management.display_lut(scene), colors) - exact).max(axis=1) * 255.0
    unit = (colors <= 1.0).all(axis=1)
    assert np.percentile(error[unit], 99.9) <= p999, f"p99.9 {np.percentile(error[unit], 99.9):.2f}/255"
    assert error[unit].max() <= worst_unit, f"max {error[unit].max():.2f}/255"
    assert error.max() <= worst, f"max up to 1.3: {error.max():.2f}/255"


def test_nodes_the_render_clips_at():
    """White (y = 1 after exposure) is a node, so Standard's clip is exact."""
    axis = display_transform.grid_axis(0.0)
    assert axis[display_transform.WHITE_NODE] == pytest.approx(1.0, abs=1e-12)
    assert axis[0] == 0.0 and axis[-1] == pytest.approx(display_transform.SHAPER_MAX)
    assert display_transform.grid_axis(1.0)[display_transform.WHITE_NODE] == pytest.approx(0.5)
    k, n = display_transform.shaper_constants(1.0)
    assert np.log2(1.0 + 0.5 * k) * n * (display_transform.LUT_SIZE - 1) == pytest.approx(display_transform.WHITE_NODE)


# -- cache and clean-up --------------------------------------------------------------------


def test_nothing_is_left_behind_and_tables_are_cached(tmp_path, monkeypatch):
    scene = scenes.empty_scene(8, 8)
    set_view(scene, "AgX", exposure=0.25)
    color_management.release()
    before = (len(bpy.data.scenes), len(bpy.data.images), len(bpy.data.node_groups))
    made = []
    real_mkdtemp = color_management.tempfile.mkdtemp

    def mkdtemp(**kwargs):
        made.append(real_mkdtemp(**kwargs))
        return made[-1]

    monkeypatch.setattr(color_management.tempfile, "mkdtemp", mkdtemp)
    lut = color_management.display_lut(scene)
    assert (len(bpy.data.scenes), len(bpy.data.images), len(bpy.data.node_groups)) == before
    assert made and not any(__import__("os").path.exists(folder) for folder in made)
    assert color_management.display_lut(scene) is lut, "the same settings reuse the table"
    assert len(made) == 1
    scene.view_settings.exposure = 0.5
    other = color_management.display_lut(scene)
    assert other is not lut and other.exposure == 0.5
    scene.view_settings.exposure = 0.25
    assert color_management.display_lut(scene) is lut, "switching back is free"
    # A curve changes the table only while it is used.
    key = color_management.settings_key(scene)
    scene.view_settings.curve_mapping.curves[3].points[0].location = (0.0, 0.2)
    assert color_management.settings_key(scene) == key
    scene.view_settings.use_curve_mapping = True
    assert color_management.settings_key(scene) != key


def test_curve_mapping_is_copied():
    """The scratch scene gets the scene's curves: the table darkens with them."""
    scene = scenes.empty_scene(8, 8)
    set_view(scene, "Standard")
    scene.view_settings.use_curve_mapping = True
    curve = scene.view_settings.curve_mapping.curves[3]  # combined
    curve.points[1].location = (1.0, 0.5)
    curve.points.new(0.5, 0.1)
    scene.view_settings.curve_mapping.update()
    grey = [(0.5, 0.5, 0.5)]
    curved = color_management.transform_colors(scene, grey)[0]
    assert np.abs(lut_lookup(color_management.display_lut(scene), grey)[0] - curved).max() <= 1.5 / 255.0
    scene.view_settings.use_curve_mapping = False
    straight = color_management.transform_colors(scene, grey)[0]
    assert curved[0] < straight[0] - 0.1


def test_the_draw_handler_never_builds(monkeypatch):
    """In the interface a missing table is made by a timer, outside the draw;
    meanwhile the scene's previous table (or none) is used."""
    scene = scenes.empty_scene(8, 8)
    set_view(scene, "Filmic")
    color_management.release()
    monkeypatch.setattr(color_management, "_can_build_now", lambda: False)
    built = []
    real_build = color_management.build
    monkeypatch.setattr(color_management, "build", lambda s: built.append(1) or real_build(s))
    assert color_management.display_lut(scene, request=True) is None
    assert not built
    assert bpy.app.timers.is_registered(color_management._build_requested)
    bpy.app.timers.unregister(color_management._build_requested)
    color_management._build_requested()
    assert built == [1]
    first = color_management.display_lut(scene, request=True)
    assert first is not None
    scene.view_settings.exposure = 1.0
    assert color_management.display_lut(scene, request=True) is first, "the previous table while the new one is made"
    color_management.release()
    assert not bpy.app.timers.is_registered(color_management._build_requested)


def test_blender_merges_overlays_in_a_2_2_power_space():
    """The output power rests on Blender's display shader (OCIO_ProcessColor:
    the scene is raised to 2.2, the overlay buffer added, the sum raised to
    1/2.2). Its GLSL is embedded as text in Blender's binary; read it there,
    so a Blender that merges otherwise fails here rather than in a viewport."""
    import mmap
    from pathlib import Path

    # The bpy module's binary: bpy/__init__.so (.pyd) above the scripts'
    # bpy package that ``import bpy`` ends up with.
    binaries = [
        found
        for parent in Path(bpy.__file__).resolve().parents
        for pattern in ("__init__*.so", "__init__*.pyd")
        for found in parent.glob(pattern)
    ]
    for path in binaries:
        with open(path, "rb") as file, mmap.mmap(file.fileno(), 0, access=mmap.ACCESS_READ) as data:
            at = data.find(b"col += col_overlay")
            if at < 0:
                continue
            merge = data[max(at - 600, 0) : at + 200]
            assert b"2.2)" in merge[:600] and b"1.0 / 2.2" in merge[600:], merge.decode("latin1")
            assert display_transform.OVERLAY_MERGE_GAMMA == 2.2
            return
    pytest.skip("Blender's display shader is not readable in this build")


@pytest.mark.parametrize(
    "variant",
    [
        shaders.ShaderVariant(
            use_fill=True,
            shading=shaders.SHADING_STUDIO,
            item_colors=True,
            clip_planes=True,
            instanced=True,
            depth_bias=1e-5,
            display_transform=True,
        ),
        shaders.ShaderVariant(
            use_fill=True, shading=shaders.SHADING_MATCAP, ngons=True, depth_bias=1e-5, display_transform=True
        ),
        shaders.ShaderVariant(
            hidden_pass=True,
            diagonals=shaders.DIAGONALS_PATTERN,
            use_fade=True,
            depth_bias=1e-5,
            display_transform=True,
        ),
    ],
    ids=["instanced_clipped_studio", "matcap_ngons", "hidden_pass"],
)
def test_overlay_variants_compile(variant):
    assert shaders.get(variant) is not None
    fins = shaders.get_silhouette(variant, overlay_bias=1e-5)
    assert shaders.uses_uniform(fins, "display_shaper")


def test_the_render_path_has_no_display_transform(monkeypatch):
    """Only the overlay's variants compile the transform: a render (fill,
    hidden lines, silhouettes) stays scene-linear, whatever the view
    transform."""
    scene = build_scene(use_fill=True, wire_color=WIRE, use_hidden_lines=True, use_silhouettes=True)
    set_view(scene, "AgX")
    used = []
    real_get, real_fins = shaders.get, shaders.get_silhouette
    monkeypatch.setattr(shaders, "get", lambda variant: used.append(variant) or real_get(variant))
    monkeypatch.setattr(
        shaders,
        "get_silhouette",
        lambda variant, overlay_bias=0.0: used.append(variant) or real_fins(variant, overlay_bias),
    )
    rgba, _depth = engine.render_scene(bpy.context.evaluated_depsgraph_get(), (WIDTH, HEIGHT))
    assert rgba[..., 3].max() > 0.9
    assert used and not any(variant.display_transform for variant in used)
