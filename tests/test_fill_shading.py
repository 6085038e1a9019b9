"""Shaded fill and colour sources (image model §5.8) against the float64
reference: FLAT, STUDIO and MATCAP with Blender's corner normals (smooth,
flat and sharp edges, a mirrored object, many instances), and the fill and
wire colour sources, measured as colour error (reference.color_error_report)."""

from __future__ import annotations

import bpy
import numpy as np
import pytest

from solidwire_addon.core import schema
from tests.support import accuracy, reference, scenes


def _shading_scene(**settings):
    scene = scenes.empty_scene(200, 150, use_fill=True, **settings)
    scene.solidwire.wire_color = (0.05, 0.05, 0.05, 1.0)
    monkey = scenes.monkey(scene, subdivisions=1, rotation=(0.2, 0.0, 0.5))
    # Half smooth, half flat, one sharp edge: every kind of corner normal.
    mesh = monkey.data
    for poly in mesh.polygons:
        poly.use_smooth = poly.index % 2 == 0
    mesh.edges[0].use_edge_sharp = True
    # A mirrored object (back faces seen from its mirrored side).
    scenes.uv_sphere(scene, "Mirrored", location=(1.9, 0.6, -0.2), radius=0.6, scale=(-1.0, 1.0, 1.0))
    for poly in bpy.data.objects["Mirrored"].data.polygons:
        poly.use_smooth = True
    scenes.add_camera(scene, location=(2.0, -4.0, 1.5), target=(0.5, 0, 0))
    return scene


def _measure(scene, name, output_dir):
    rgba = scenes.render_to_file(scene, output_dir / f"{name}.png")
    ref = reference.render_reference(scene)
    expected = reference.expected_fill_rgb(ref, float(scene.solidwire.wire_color[3]))
    report = reference.color_error_report(rgba, expected, ref)
    report["name"] = name
    return report, rgba, ref


@pytest.mark.parametrize("shading", ["FLAT", "STUDIO", "MATCAP"])
def test_fill_shading_matches_reference(shading, output_dir):
    scene = _shading_scene(fill_shading=shading, fill_color=(0.8, 0.7, 0.6), matcap="clay_studio")
    report, rgba, ref = _measure(scene, f"fill_shading_{shading.lower()}", output_dir)
    accuracy.assert_accurate(report)
    covered = (ref.face >= 0) & ~ref.on_silhouette
    spread = np.ptp(rgba[..., 0][covered & (ref.intensity < 1e-3)])
    if shading == "FLAT":
        assert spread < 1e-3  # one colour
    else:
        assert spread > 0.1  # lit: the fill is not flat


def test_every_normal_domain_matches_reference(output_dir):
    """A mesh's normals are uploaded where they vary (extract.NORMALS_BY_*):
    per vertex for smooth shading with one material, per triangle for flat
    shading, per triangle corner otherwise (here: smooth with two
    materials, so a vertex has no one material); each shades as Blender
    does."""
    from solidwire_addon.blender import runtime
    from solidwire_addon.core import extract

    scene = scenes.empty_scene(
        200, 150, use_fill=True, fill_shading="STUDIO", fill_color=(0.8, 0.7, 0.6), fill_color_source="MATERIAL"
    )
    scene.solidwire.wire_color = (0.05, 0.05, 0.05, 1.0)
    smooth = scenes.uv_sphere(scene, "Smooth", location=(-1.6, 0.0, 0.0), radius=0.7)
    flat = scenes.monkey(scene, "Flat", subdivisions=1, location=(0.2, 0.0, 0.0), rotation=(0.2, 0.0, 0.5))
    two = scenes.uv_sphere(scene, "TwoMaterials", location=(1.9, 0.3, 0.0), radius=0.6)
    for obj, use_smooth in ((smooth, True), (flat, False), (two, True)):
        for poly in obj.data.polygons:
            poly.use_smooth = use_smooth
    for name, colour in (("Red", (0.8, 0.2, 0.1, 1.0)), ("Blue", (0.1, 0.3, 0.8, 1.0))):
        material = bpy.data.materials.new(name)
        material.diffuse_color = colour
        two.data.materials.append(material)
        smooth.data.materials.append(material)  # one slot used: still one material
    for poly in two.data.polygons:
        poly.material_index = poly.index % 2
    scenes.add_camera(scene, location=(0.5, -5.0, 1.5), target=(0.2, 0, 0))
    report, _rgba, _ref = _measure(scene, "fill_normal_domains", output_dir)
    accuracy.assert_accurate(report)
    domains = sorted(entry.normal_domain for entry in runtime.mesh_cache.meshes() if entry.corners is not None)
    assert domains == [extract.NORMALS_BY_VERTEX, extract.NORMALS_BY_TRIANGLE, extract.NORMALS_BY_CORNER]


def test_matcap_is_chosen_by_name(output_dir):
    scene = _shading_scene(fill_shading="MATCAP", matcap="check_normal+y", fill_color=(1.0, 1.0, 1.0))
    report, _rgba, _ref = _measure(scene, "fill_matcap_check", output_dir)
    accuracy.assert_accurate(report)


def test_shading_of_many_instances_matches_reference(output_dir):
    """The instanced draw path (many instances of one mesh, some mirrored)
    reads its normal matrix from the instance table."""
    scene = scenes.empty_scene(200, 150, use_fill=True, fill_shading="STUDIO", fill_color=(0.9, 0.9, 0.9))
    scene.solidwire.wire_color = (0.0, 0.0, 0.0, 1.0)
    source = scenes.uv_sphere(scene, "Ball", radius=0.3)
    for poly in source.data.polygons:
        poly.use_smooth = True
    for k in range(20):
        obj = bpy.data.objects.new(f"Ball{k}", source.data)
        scene.collection.objects.link(obj)
        obj.location = ((k % 5) - 2.0, (k // 5) - 1.5, 0.0)
        obj.rotation_euler = (0.3 * k, 0.1 * k, 0.0)
        obj.scale = (-1.0 if k % 3 == 0 else 1.0, 1.0, 1.0 + 0.1 * (k % 4))
    scenes.add_camera(scene, location=(0.0, -5.0, 5.0), target=(0, 0, 0))
    report, _rgba, _ref = _measure(scene, "fill_shading_instances", output_dir)
    accuracy.assert_accurate(report)


def test_shading_keeps_the_line_intensity(output_dir):
    """Shading changes the fill, never the wire: I recovered from a white
    wire over a black STUDIO fill is the core model's."""
    scene = _shading_scene(fill_shading="STUDIO", fill_color=(0.0, 0.0, 0.0))
    scene.solidwire.wire_color = (1.0, 1.0, 1.0, 1.0)
    rgba = scenes.render_to_file(scene, output_dir / "fill_shading_intensity.png")
    ref = reference.render_reference(scene)
    srgb = rgba[..., 0]
    linear = np.where(srgb <= 0.04045, srgb / 12.92, ((srgb + 0.055) / 1.055) ** 2.4)
    accuracy.assert_accurate(reference.error_report(np.where(ref.face >= 0, linear, 0.0), ref))


def _colour_scene(**settings):
    scene = scenes.empty_scene(200, 150, **({"use_fill": True, "fill_shading": "FLAT"} | settings))
    scene.solidwire.wire_color = (0.0, 0.0, 0.0, 1.0)
    scene.solidwire.thickness = 2.0
    red = bpy.data.materials.new("Red")
    red.diffuse_color = (0.8, 0.1, 0.1, 1.0)
    blue = bpy.data.materials.new("Blue")
    blue.diffuse_color = (0.1, 0.2, 0.9, 1.0)
    cube = scenes.cube(scene, "Box", location=(-1.2, 0.0, 0.0))
    cube.data.materials.append(red)
    cube.data.materials.append(blue)
    cube.data.materials.append(None)  # an empty slot: the fill colour
    for poly in cube.data.polygons:
        poly.material_index = poly.index % 4  # index 3 is past the last slot: clamped
    cube.color = (0.2, 0.7, 0.3, 1.0)
    ball = scenes.uv_sphere(scene, "Ball", location=(1.2, 0.0, 0.0), radius=1.0)
    ball.color = (0.9, 0.8, 0.1, 1.0)
    scenes.add_camera(scene, location=(0.0, -6.0, 3.0), target=(0, 0, 0))
    return scene


@pytest.mark.parametrize(
    "fill_source, wire_source",
    [
        ("OBJECT", "SINGLE"),
        ("MATERIAL", "OBJECT"),
        ("RANDOM", "RANDOM"),
        ("SINGLE", "OBJECT"),
    ],
)
def test_colour_sources_match_reference(fill_source, wire_source, output_dir):
    scene = _colour_scene(fill_color_source=fill_source, wire_color_source=wire_source, fill_color=(0.6, 0.6, 0.6))
    report, _rgba, ref = _measure(scene, f"colors_{fill_source.lower()}_{wire_source.lower()}", output_dir)
    accuracy.assert_accurate(report)
    # The sources really differ per object/face (not one colour everywhere).
    fills = {tuple(np.round(c, 3)) for c in ref.fill[ref.face >= 0]}
    assert len(fills) >= (1 if fill_source == "SINGLE" else 2)


def test_wire_colour_source_in_wire_only_render(output_dir):
    """Without a fill the wire takes its object's colour too (premultiplied)."""
    scene = _colour_scene(use_fill=False, wire_color_source="OBJECT")
    rgba = scenes.render_to_file(scene, output_dir / "colors_wire_only.png")
    ref = reference.render_reference(scene)
    accuracy.assert_accurate(reference.error_report(rgba[..., 3], ref))
    strong = (rgba[..., 3] > 0.9) & ~ref.on_silhouette
    expected = reference.srgb_encode(ref.wire[strong])
    assert np.abs(rgba[..., :3][strong] - expected).max() < 2.0 / 255.0


def test_random_colour_is_the_documented_hash():
    """RANDOM: hue = crc32(UTF-8 name) / 2^32, S and V fixed (§5.8)."""
    import colorsys
    import zlib

    from solidwire_addon.core import colors

    for name in ("Cube", "Suzanne.001", "Ünïcode"):
        hue = zlib.crc32(name.encode("utf-8")) / 2**32
        assert colors.random_color(name, 0.5, 0.8) == colorsys.hsv_to_rgb(hue, 0.5, 0.8)


def test_fill_colour_has_no_alpha():
    """A colour with an alpha slider must use it: the fill is always opaque,
    so its colour is RGB; an RGBA value (older presets) drops the alpha."""
    setting = schema.BY_NAME["fill_color"]
    assert setting.size == 3 and len(setting.default) == 3
    assert len(bpy.context.scene.solidwire.fill_color) == 3
    assert setting.check([0.1, 0.2, 0.3, 0.5]) == (0.1, 0.2, 0.3)
    with pytest.raises(ValueError):
        setting.check([0.1, 0.2])


def test_matcap_decoding_leaves_nothing_in_the_file():
    from solidwire_addon.blender import matcap_files

    # The process's first render makes a "Render Result" image: start without
    # one so the decode is checked in that case too, whatever ran before.
    for image in [i for i in bpy.data.images if i.type == "RENDER_RESULT"]:
        bpy.data.images.remove(image)
    before = (len(bpy.data.scenes), len(bpy.data.node_groups), len(bpy.data.images))
    diffuse, specular = matcap_files.decode_pixels("metal_carpaint")
    assert diffuse.shape == (512, 512, 4)
    if bpy.app.version >= (5, 0, 0):  # 4.x's compositor does not hand over the specular layer (no highlight there)
        assert specular is not None and specular.max() > 0.0
    assert (len(bpy.data.scenes), len(bpy.data.node_groups), len(bpy.data.images)) == before
    assert matcap_files.decode_pixels("no_such_matcap") is None


def test_pending_matcap_draws_flat_until_decoded():
    """A loader that cannot decode yet (Blender's interface) gets asked
    again: nothing is cached until real pixels come."""
    from solidwire_addon.blender import matcap_files
    from solidwire_addon.core import matcaps

    answers = [matcaps.PENDING, (np.ones((4, 4, 4), np.float32), None)]
    matcaps.set_loader(lambda _name: answers.pop(0))
    try:
        assert matcaps.texture("clay_studio") is None
        assert matcaps.texture("clay_studio") is not None
        assert answers == []
    finally:
        matcaps.set_loader(matcap_files.load_pixels)


def test_defaults_make_a_readable_picture_of_the_default_scene(output_dir):
    """A plain F12 of Blender's startup scene (cube, camera, light, 0.05 grey
    world) with the add-on's defaults: a lit light fill under a dark wire."""
    bpy.ops.wm.read_factory_settings(use_empty=False)
    scene = bpy.context.scene
    scene.render.engine = "SOLIDWIRE"
    scene.render.resolution_percentage = 25
    rgba = scenes.render_to_file(scene, output_dir / "defaults_startup_scene.png", depth16=False)
    grey = rgba[..., :3].mean(axis=-1)
    world = np.median(grey[:10, :10])
    fill = grey > world + 0.25  # the lit fill is far brighter than the world
    assert fill.mean() > 0.05
    # Three faces of the cube in three clearly different shades (lit, not flat).
    levels = np.unique(np.round(grey[fill], 2))
    shades = [v for v in levels if np.count_nonzero(np.round(grey[fill], 2) == v) > 200]
    assert len(shades) >= 3 and shades[-1] - shades[0] > 0.05, shades
    # The wire is darker than the world, and there is plenty of it.
    rows, cols = np.nonzero(fill)
    box = grey[rows.min() : rows.max() + 1, cols.min() : cols.max() + 1]
    assert np.count_nonzero(box < world - 0.05) > 100


def test_a_matcap_is_never_decoded_inside_a_render(monkeypatch):
    """Decoding renders a scratch scene; started from inside a render it
    deadlocked Blender 5.3. Inside the engine's render the loader only asks
    for it (the render draws a flat fill until then); outside, choosing the
    matcap decodes it at once in background mode."""
    from solidwire_addon.blender import matcap_files
    from solidwire_addon.core import matcaps, shaders

    monkeypatch.setattr(matcap_files, "_decoded", {})
    monkeypatch.setattr(matcap_files, "_requested", set())
    decoded = []
    monkeypatch.setattr(matcap_files, "decode_pixels", lambda name: decoded.append(name) or None)
    with shaders.gl_context(shaders.RENDER_ENGINE_CONTEXT):
        assert matcap_files.load_pixels("clay_brown") is matcaps.PENDING
    assert decoded == []
    matcap_files.prepare("clay_brown")
    assert decoded == ["clay_brown"]


def _painted(obj, name: str, domain: str, data_type: str, seed: int):
    """A colour attribute of ``obj``'s mesh, made active, with random
    colours (byte colours are stored sRGB-encoded; Blender decodes them)."""
    mesh = obj.data
    attribute = mesh.color_attributes.new(name, data_type, domain)
    rng = np.random.default_rng(seed)
    colors = rng.uniform(0.05, 0.95, (len(attribute.data), 4)).astype(np.float32)
    colors[:, 3] = 1.0
    attribute.data.foreach_set("color", colors.ravel())
    mesh.color_attributes.active_color = attribute
    return attribute


@pytest.mark.parametrize("shading", ["FLAT", "STUDIO"])
@pytest.mark.parametrize("surface", ["direct", "deferred"])
def test_attribute_colours_match_reference(shading, surface, output_dir, monkeypatch):
    """The ATTRIBUTE fill source: each mesh's active colour attribute,
    interpolated over each triangle as Workbench's Attribute colour does;
    by corner (bytes) and by point (floats); a mesh without one takes Fill
    Color. Drawn directly and deferred (the resolve interpolates with its
    own barycentrics), against the float64 reference."""
    from solidwire_addon.blender import runtime
    from solidwire_addon.core import draw
    from solidwire_addon.core.options import DrawOptions

    if surface == "direct":
        monkeypatch.setattr(runtime, "options", DrawOptions(deferred_surface=False))
    else:
        monkeypatch.setattr(draw, "DEFERRED_MIN_DENSITY", 0.0)
    scene = _colour_scene(fill_color_source="ATTRIBUTE", fill_color=(0.6, 0.6, 0.6), fill_shading=shading)
    _painted(bpy.data.objects["Box"], "Paint", "CORNER", "BYTE_COLOR", 1)
    _painted(bpy.data.objects["Ball"], "Col", "POINT", "FLOAT_COLOR", 2)
    scenes.monkey(scene, "Plain", location=(0.0, 1.5, 0.8), scale=(0.5, 0.5, 0.5))  # no attribute
    report, _rgba, ref = _measure(scene, f"colors_attribute_{shading.lower()}_{surface}", output_dir)
    accuracy.assert_accurate(report)
    fills = ref.fill[ref.face >= 0]
    assert len({tuple(np.round(c, 2)) for c in fills}) > 200  # colours vary across faces
