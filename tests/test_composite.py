"""Wire over a beauty render (solidwire_addon/composite.py, ops_composite.py,
scripts/render.py --over).

Beauty renders are tiny (96 x 72, Cycles 1-2 samples on the CPU, or
Workbench); EEVEE works on a GPU-less machine too but spends minutes
compiling shaders on llvmpipe, so it is not rendered here.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import bpy
import numpy as np
import pytest

from solidwire_addon.blender import composite
from solidwire_addon.core import compat
from tests.support import scenes

ROOT = Path(__file__).resolve().parent.parent
W, H = 96, 72
FRONT_DEPTH = 5.0  # view depth of the front plane in occlusion_scene()


def lit(scene):
    """A world colour and a sun, so the beauty is not black."""
    world = bpy.data.worlds.new("World")
    world.color = (0.05, 0.06, 0.08)
    scene.world = world
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy = 3.0
    sun.rotation_euler = (0.6, 0.2, -0.4)
    scene.collection.objects.link(sun)


def cycles_tiny(scene, samples: int = 1):
    scene.cycles.device = "CPU"
    scene.cycles.samples = samples
    scene.cycles.use_denoising = False
    scene.cycles.seed = 0
    # Sample (almost exactly) at pixel centres, as SolidWire does.
    scene.cycles.pixel_filter_type = "BOX"
    scene.cycles.filter_width = 0.01


def occlusion_scene(*, front: bool = True):
    """A plane facing the camera at view depth 5 hides the left part of a
    subdivided Suzanne (depth ~8) from a camera on the -Y axis."""
    scene = scenes.empty_scene(W, H, transparent=False, thickness=1.5)
    lit(scene)
    scenes.monkey(scene, subdivisions=1, location=(0.0, 2.0, 0.0), rotation=(0.0, 0.0, 0.0))
    if front:
        verts = [(-1.2, -1.0, -0.6), (-0.2, -1.0, -0.6), (-0.2, -1.0, 0.9), (-1.2, -1.0, 0.9)]
        scenes.from_pydata(scene, "Front", verts, [(0, 1, 2, 3)])
    scenes.add_camera(scene, location=(0.0, -6.0, 0.0), target=(0.0, 0.0, 0.0), lens=50.0)
    return scene


def plain_render(scene, engine: str, path: Path, *, transparent: bool | None = None) -> dict:
    """An ordinary render of ``scene`` with ``engine`` to a float EXR, read back."""
    scene.render.engine = engine
    if transparent is not None:
        scene.render.film_transparent = transparent
    return scenes.render_multilayer_exr(scene, path)


def rgba_of(channels: dict) -> np.ndarray:
    """The image of a single-layer or multilayer EXR."""
    if "A" in channels:
        return np.stack([channels[c] for c in "RGBA"], axis=-1)
    return composite.exr_pass(channels, "ViewLayer", "Combined", "RGBA")


def exr_output(scene):
    image = scene.render.image_settings
    compat.set_media_type(image, "IMAGE")
    image.file_format = "OPEN_EXR"
    image.color_mode = "RGBA"
    image.color_depth = "32"
    image.exr_codec = "NONE"


def erode(mask: np.ndarray, steps: int) -> np.ndarray:
    out = mask.copy()
    for _ in range(steps):
        shrunk = out.copy()
        shrunk[1:] &= out[:-1]
        shrunk[:-1] &= out[1:]
        shrunk[:, 1:] &= out[:, :-1]
        shrunk[:, :-1] &= out[:, 1:]
        out = shrunk
    return out


# -- the composite is the alpha-over of the two parts --------------------------


@pytest.mark.parametrize("engine", ["BLENDER_WORKBENCH", "CYCLES"])
def test_composite_equals_alpha_over_of_separate_renders(engine, tmp_path):
    scene = occlusion_scene()
    cycles_tiny(scene, samples=2)
    exr_output(scene)
    out = tmp_path / "over.exr"
    layers = composite.render_wire_over(scene, out, engine, keep_layers=True)

    written = composite.read_exr(out)
    composite_file = np.stack([written[c] for c in "RGBA"], axis=-1)
    assert composite_file.shape == (H, W, 4)

    # The two layers exactly as Blender wrote them ...
    beauty = rgba_of(composite.read_exr(tmp_path / "over.beauty.exr"))
    wire = rgba_of(composite.read_exr(tmp_path / "over.wire.exr"))
    expected = wire + (1.0 - wire[..., 3:4]) * beauty
    np.testing.assert_allclose(composite_file, expected, rtol=1e-6, atol=1e-6)
    np.testing.assert_array_equal(layers.beauty, beauty)
    np.testing.assert_array_equal(layers.wire, wire)
    # Not a vacuous check: there is a wire, and a beauty under it.
    assert (wire[..., 3] > 0.5).sum() > 100
    assert beauty[..., :3].max() > 0.1

    # ... are the ordinary renders of the two parts: the wire exactly (SolidWire
    # is deterministic), the beauty up to the engine's own run-to-run noise
    # (Workbench's half-float anti-aliasing differs by ~1e-3 between runs).
    separate_beauty = rgba_of(plain_render(scene, engine, tmp_path / "beauty.exr"))
    separate_wire = rgba_of(plain_render(scene, "SOLIDWIRE", tmp_path / "wire.exr", transparent=True))
    np.testing.assert_array_equal(separate_wire, wire)
    np.testing.assert_allclose(separate_beauty, beauty, atol=4e-3)
    assert np.abs(separate_beauty - beauty).mean() < 1e-4


@pytest.mark.parametrize("transparent", [False, True])
def test_composite_goes_through_the_scene_colour_management(tmp_path, transparent):
    """Written as a PNG with the scene's view transform (AgX), the composite
    equals Blender's own PNG of the beauty wherever the wire is absent (with
    straight alpha on a transparent film)."""
    scene = occlusion_scene()
    scene.render.film_transparent = transparent
    scene.view_settings.view_transform = "AgX"
    image = scene.render.image_settings
    image.file_format = "PNG"
    image.color_mode = "RGBA"
    image.color_depth = "16"
    cycles_tiny(scene)  # deterministic (Workbench differs by ~1e-3 run to run)
    out = tmp_path / "over.png"
    layers = composite.render_wire_over(scene, out, "CYCLES")
    mine = scenes.load_png(out)

    scene.render.engine = "CYCLES"
    theirs = scenes.render_to_file(scene, tmp_path / "beauty.png")
    clear = layers.wire[..., 3] == 0.0
    assert clear.sum() > 0.5 * W * H
    assert np.abs(mine - theirs)[clear].max() <= 2.0 / 65535.0
    # And the wire shows where it is drawn.
    drawn = layers.wire[..., 3] > 0.9
    assert np.abs(mine - theirs)[drawn].max() > 0.1


def test_beauty_is_the_compositor_output_when_the_scene_composites():
    scene = occlusion_scene()
    cycles_tiny(scene)
    if not compat.has_compositor_node_group(scene):
        pytest.skip("Blender before 5.0: compositor node tree API differs")
    plain = composite.render_layers(scene, "CYCLES")
    tree = bpy.data.node_groups.new("Invert", "CompositorNodeTree")
    tree.interface.new_socket("Image", in_out="OUTPUT", socket_type="NodeSocketColor")
    layers_node = tree.nodes.new("CompositorNodeRLayers")
    invert = tree.nodes.new("CompositorNodeInvert")
    output = tree.nodes.new("NodeGroupOutput")
    tree.links.new(layers_node.outputs["Image"], invert.inputs["Color"])
    tree.links.new(invert.outputs[0], output.inputs[0])
    compat.set_compositor_node_group(scene, tree)
    scene.render.use_compositing = True
    inverted = composite.render_layers(scene, "CYCLES")
    np.testing.assert_allclose(inverted.beauty[..., :3], 1.0 - plain.beauty[..., :3], atol=1e-4)
    # The wire pass never goes through the compositor.
    np.testing.assert_array_equal(inverted.wire, plain.wire)


# -- the wire is hidden exactly where the beauty shows a nearer surface --------


def test_wire_hidden_where_beauty_shows_a_nearer_surface(tmp_path):
    scene = occlusion_scene()
    cycles_tiny(scene)
    layers = composite.render_layers(scene, "CYCLES", depth=True)
    zb, zw = layers.beauty_depth, layers.wire_depth
    assert zb is not None and zw is not None

    # Inside the front plane's silhouette (2 px in from its edge, and more
    # than a wire's reach from its own border edges): only the beauty.
    front = np.abs(zb - FRONT_DEPTH) < 1e-3
    inside = erode(front, 2 + 4)
    assert inside.sum() > 300
    np.testing.assert_allclose(layers.composite[inside], layers.beauty[inside], atol=1e-7)
    assert layers.wire[..., 3][inside].max() == 0.0

    # ... where the back object's wires would otherwise be drawn.
    bare = occlusion_scene(front=False)
    bare_wire = composite.render_layers(bare, "BLENDER_WORKBENCH").wire
    assert (bare_wire[..., 3][inside] > 0.5).sum() > 30

    # Both renders see the same surfaces at the same depth: compare covered
    # pixels away from depth discontinuities and grazing slopes.
    covered = (zb < 1e9) & (zw < 1e9)
    assert np.array_equal(erode(zb < 1e9, 1), erode(zw < 1e9, 1) & erode(zb < 1e9, 1))
    smooth = covered.copy()
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            neighbour = np.roll(np.roll(zb, dy, axis=0), dx, axis=1)
            smooth &= np.abs(neighbour - zb) < 0.02 * zb
    smooth = erode(smooth, 1)
    assert smooth.sum() > 1000
    relative = np.abs(zw - zb)[smooth] / zb[smooth]
    assert relative.max() < 1e-3, relative.max()
    # Silhouettes agree too: no pixel is covered in one and empty in the other
    # except on the one-pixel rim of a silhouette (coverage differs there).
    disagree = (zb < 1e9) != (zw < 1e9)
    rim = (zb < 1e9) & ~erode(zb < 1e9, 1) | (zb >= 1e9) & ~erode(zb >= 1e9, 1)
    assert not (disagree & ~rim).any()


# -- settings restored, nothing left behind ------------------------------------


def _state(scene):
    r, im = scene.render, scene.render.image_settings
    return {
        "engine": r.engine,
        "filepath": r.filepath,
        "ext": r.use_file_extension,
        "motion": r.use_motion_blur,
        "border": r.use_border,
        "film": r.film_transparent,
        "comp": r.use_compositing,
        "seq": r.use_sequencer,
        "media": getattr(im, "media_type", None),
        "format": im.file_format,
        "mode": im.color_mode,
        "depth": im.color_depth,
        "codec": im.exr_codec,
        "z": scene.view_layers[0].use_pass_z,
        "fill": scene.solidwire.use_fill,
        "samples": scene.cycles.samples,
    }


def _recording_mkdtemp(monkeypatch):
    made = []
    original = composite.tempfile.mkdtemp

    def mkdtemp(*args, **kwargs):
        made.append(Path(original(*args, **kwargs)))
        return str(made[-1])

    monkeypatch.setattr(composite.tempfile, "mkdtemp", mkdtemp)
    return made


def test_scene_settings_restored_and_nothing_left_behind(tmp_path, monkeypatch):
    scene = occlusion_scene()
    scene.render.engine = "CYCLES"
    cycles_tiny(scene, samples=7)
    scene.render.use_motion_blur = True
    scene.render.use_border = True
    scene.render.filepath = "//frames/f_####"
    scene.render.image_settings.file_format = "JPEG"
    scene.solidwire.use_fill = True
    before = _state(scene)
    images = set(bpy.data.images.keys()) - {"Render Result"}
    made = _recording_mkdtemp(monkeypatch)

    composite.render_wire_over(scene, tmp_path / "over.jpg", "WORKBENCH", depth=True, samples=1)
    assert (tmp_path / "over.jpg").is_file()
    assert _state(scene) == before
    assert set(bpy.data.images.keys()) - {"Render Result"} == images
    assert made and not any(p.exists() for p in made)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["over.jpg"]


def test_settings_restored_when_a_render_fails(monkeypatch):
    scene = occlusion_scene()
    before = _state(scene)
    made = _recording_mkdtemp(monkeypatch)
    real = composite._render_to

    def failing(scene, engine, path, layer):
        if engine == "SOLIDWIRE":  # after the beauty, mid-way through the changes
            raise composite.CompositeError("boom")
        return real(scene, engine, path, layer)

    monkeypatch.setattr(composite, "_render_to", failing)
    with pytest.raises(composite.CompositeError, match="boom"):
        composite.render_layers(scene, "BLENDER_WORKBENCH", depth=True)
    assert _state(scene) == before
    assert made and not any(p.exists() for p in made)


def test_keep_layers_writes_the_float_layers(tmp_path):
    scene = occlusion_scene()
    scene.render.image_settings.file_format = "PNG"
    layers = composite.render_wire_over(scene, tmp_path / "shot.png", "BLENDER_WORKBENCH", keep_layers=True)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["shot.beauty.exr", "shot.png", "shot.wire.exr"]
    wire = rgba_of(composite.read_exr(tmp_path / "shot.wire.exr"))
    np.testing.assert_array_equal(wire, layers.wire)


# -- alignment: resolution percentage, lens shift, pixel aspect ----------------


def test_layers_align_with_percentage_shift_and_pixel_aspect():
    """With a wire thicker than any face, the wire pass is SolidWire's
    coverage; on a transparent film the beauty's alpha is Cycles' coverage
    (one sample at the pixel centre). The two agree pixel for pixel with
    resolution percentage, lens shift and non-square pixels."""
    scene = occlusion_scene()
    scene.render.resolution_x, scene.render.resolution_y = 160, 100
    scene.render.resolution_percentage = 50
    scene.render.pixel_aspect_x = 1.5
    scene.render.film_transparent = True
    scene.camera.data.shift_x, scene.camera.data.shift_y = 0.1, -0.05
    scene.camera.data.sensor_fit = "VERTICAL"
    scene.solidwire.thickness = 1000.0
    cycles_tiny(scene)
    layers = composite.render_layers(scene, "CYCLES")
    assert layers.composite.shape == (50, 80, 4)
    covered_b = layers.beauty[..., 3] > 0.5
    covered_w = layers.wire[..., 3] > 0.5
    assert 400 < covered_b.sum() < 0.9 * 50 * 80
    assert set(np.unique(layers.beauty[..., 3])) <= {0.0, 1.0}
    assert set(np.unique(layers.wire[..., 3])) <= {0.0, 1.0}
    # Pixel centres within Cycles' 0.005 px filter jitter of an edge may flip.
    assert (covered_b != covered_w).sum() <= 2


# -- engines -------------------------------------------------------------------


def test_engine_names():
    scene = occlusion_scene()
    assert composite.resolve_engine(scene, "cycles") == "CYCLES"
    assert composite.resolve_engine(scene, "EEVEE") in ("BLENDER_EEVEE", "BLENDER_EEVEE_NEXT")
    assert composite.resolve_engine(scene, "BLENDER_EEVEE_NEXT") in ("BLENDER_EEVEE", "BLENDER_EEVEE_NEXT")
    assert composite.resolve_engine(scene, "workbench") == "BLENDER_WORKBENCH"
    with pytest.raises(composite.EngineError, match=r"unknown or unavailable render engine 'LUXCORE'.*CYCLES"):
        composite.resolve_engine(scene, "LUXCORE")
    with pytest.raises(composite.EngineError, match="SolidWire"):
        composite.resolve_engine(scene, "SOLIDWIRE")
    with pytest.raises(composite.EngineError, match="SolidWire itself"):
        composite.resolve_engine(scene, "SCENE")  # the scene's engine is SOLIDWIRE
    scene.render.engine = "CYCLES"
    assert composite.resolve_engine(scene, None) == "CYCLES"
    assert scene.render.engine == "CYCLES"


def test_unknown_engine_fails_before_rendering(tmp_path):
    scene = occlusion_scene()
    with pytest.raises(composite.EngineError):
        composite.render_wire_over(scene, tmp_path / "x.png", "NOPE")
    assert not any(tmp_path.iterdir())
    assert scene.render.engine == "SOLIDWIRE"


def test_video_output_format_is_refused(tmp_path):
    scene = occlusion_scene()
    if not compat.set_media_type(scene.render.image_settings, "VIDEO"):
        scene.render.image_settings.file_format = "FFMPEG"  # Blender 4.x: the format is the family
    with pytest.raises(composite.CompositeError, match="video"):
        composite.render_wire_over(scene, tmp_path / "x.mp4", "WORKBENCH")


# -- operator ------------------------------------------------------------------


def test_operator_runs_headless_and_writes_the_file(tmp_path):
    scene = occlusion_scene()
    scene.render.image_settings.file_format = "PNG"
    out = tmp_path / "op.png"
    with bpy.context.temp_override(scene=scene):
        result = bpy.ops.solidwire.render_wire_over(engine="BLENDER_WORKBENCH", filepath=str(out))
    assert result == {"FINISHED"}
    png = scenes.load_png(out)
    assert png.shape == (H, W, 4)
    assert scene.render.engine == "SOLIDWIRE"


def test_operator_default_path_and_error(tmp_path):
    scene = occlusion_scene()
    scene.render.filepath = str(tmp_path / "shot_")
    scene.render.image_settings.file_format = "PNG"
    with bpy.context.temp_override(scene=scene):
        assert bpy.ops.solidwire.render_wire_over(engine="BLENDER_WORKBENCH") == {"FINISHED"}
        # The scene's engine is SolidWire: "Scene Engine" has nothing to draw under the wire.
        with pytest.raises(RuntimeError, match="SolidWire itself"):
            bpy.ops.solidwire.render_wire_over(engine="SCENE")
    assert [p.name for p in tmp_path.iterdir()] == [f"shot_{scene.frame_current:04d}_wire_over.png"]


def test_sidebar_menu_lists_the_engines():
    from types import SimpleNamespace

    class Layout:
        def __init__(self):
            self.ops = []

        def operator(self, idname, text=""):
            op = SimpleNamespace()
            self.ops.append((idname, text, op))
            return op

    scene = occlusion_scene()
    menu = bpy.types.SOLIDWIRE_MT_render_wire_over
    for engine, expected in (
        ("SOLIDWIRE", ["CYCLES", "BLENDER_EEVEE", "BLENDER_WORKBENCH"]),
        ("CYCLES", ["SCENE", "CYCLES", "BLENDER_EEVEE", "BLENDER_WORKBENCH"]),
    ):
        scene.render.engine = engine
        layout = Layout()
        menu.draw(SimpleNamespace(layout=layout), SimpleNamespace(scene=scene))
        assert [op.engine for _id, _text, op in layout.ops] == expected
        assert {idname for idname, _text, _op in layout.ops} == {"solidwire.render_wire_over"}


# -- command line --------------------------------------------------------------


def _cli(*args):
    return subprocess.run(
        [sys.executable, str(ROOT / "scripts" / "render.py"), *args],
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )


def test_cli_over(tmp_path):
    out = tmp_path / "demo_over.png"
    run = _cli("--demo", "-o", str(out), "--width", "96", "--height", "54", "--over", "workbench", "--over-layers")
    assert run.returncode == 0, run.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["demo_over.beauty.exr", "demo_over.png", "demo_over.wire.exr"]
    assert scenes.load_png(out).shape == (54, 96, 4)
    # Only what was asked for is announced: no "Saved:" line for the
    # temporary layer files (one, in Blender's form, for the composite), and
    # one progress line for the composite.
    assert [line for line in run.stdout.splitlines() if "Saved:" in line] == [f"Saved: '{out}'"], run.stdout
    assert [line for line in run.stdout.splitlines() if line.startswith("solidwire: rendered")] == [
        f"solidwire: rendered {out} (96x54) in " + line.split(" in ")[-1]
        for line in run.stdout.splitlines()
        if line.startswith("solidwire: rendered")
    ] and "solidwire: rendered" in run.stdout


@pytest.mark.parametrize(
    "args, message",
    [
        (("--over", "LUXCORE"), "solidwire: error: --over: unknown or unavailable render engine 'LUXCORE'"),
        (("--over", "SOLIDWIRE"), "solidwire: error: --over:"),
        (("--over-layers",), "solidwire: error: --over-samples and --over-layers need --over ENGINE"),
    ],
)
def test_cli_over_errors(tmp_path, args, message):
    run = _cli("--demo", "-o", str(tmp_path / "x.png"), *args)
    assert run.returncode == 2
    assert message in run.stderr
    assert not any(tmp_path.iterdir())


@pytest.mark.eevee  # EEVEE's first render compiles shaders for minutes on llvmpipe
def test_wire_over_eevee(tmp_path):
    scene = occlusion_scene()
    scene.eevee.taa_render_samples = 1
    scene.render.image_settings.file_format = "PNG"
    layers = composite.render_wire_over(scene, tmp_path / "eevee.png", "EEVEE", depth=True)
    assert layers.engine in ("BLENDER_EEVEE", "BLENDER_EEVEE_NEXT")
    zb, zw = layers.beauty_depth, layers.wire_depth
    smooth = erode((zb < 1e9) & (zw < 1e9), 2) & (np.abs(zb - FRONT_DEPTH) < 1e-2)
    assert smooth.sum() > 300
    np.testing.assert_allclose(zw[smooth], zb[smooth], rtol=1e-3)
    assert scenes.load_png(tmp_path / "eevee.png").shape == (H, W, 4)
