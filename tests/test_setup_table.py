"""The set-up pre-pass (shaders/setup_comp.glsl): in a direct draw (the
viewport overlay, the hidden-line and wire passes) the vertex stage of a big
mesh reads each triangle's edge set-up from a table written once per draw
instead of setting it up at every corner. Same code path, so the image is
the same to the bit; forced on for small scenes here, with the render's
surface pass drawn directly (it is deferred otherwise and sets up each
visible triangle per pixel, tests/test_deferred_surface.py)."""

from __future__ import annotations

import numpy as np
import pytest

from solidwire_addon.blender import runtime
from solidwire_addon.core import draw, shaders
from solidwire_addon.core.options import DrawOptions
from tests.support import scenes

_DISPATCH_ALLOWED = shaders.setup_dispatch_allowed  # as shipped (the tests below patch it)


def _quads_tris_mirrored_shared(scene):
    scenes.near_plane_scene(scene)  # edges crossing the near plane
    shared = scenes.monkey(scene, "Left", location=(-1.5, 4.0, 0.8))
    twin = shared.copy()  # a second object drawing the same mesh
    twin.name = "Right"
    twin.location = (2.5, 5.0, 0.8)
    twin.scale = (-1.0, 1.0, 1.0)  # mirrored
    scene.collection.objects.link(twin)
    solo = scenes.monkey(scene, "Solo", location=(0.5, 7.0, 1.5))  # its own mesh, mirrored
    solo.scale = (1.0, -1.0, 1.0)
    scenes.cube(scene, "Box", location=(1.0, 3.0, 0.3), size=0.6)


def _render(scene, path, setup_min, monkeypatch, software_renders: bool = True):
    """A render with the surface pass drawn directly, the pre-pass from
    ``setup_min`` triangles on; ``software_renders``: whether a software
    rasteriser's render may dispatch it too (shaders.setup_dispatch_allowed
    says no; allowed here by default, to test the pre-pass on this machine)."""
    calls = []
    real = draw._run_setup
    monkeypatch.setattr(runtime, "options", DrawOptions(deferred_surface=False))
    monkeypatch.setattr(draw, "SETUP_TABLE_MIN", setup_min)
    allowed = shaders.setup_available if software_renders else _DISPATCH_ALLOWED
    monkeypatch.setattr(shaders, "setup_dispatch_allowed", allowed)
    # Per pre-pass run: whether it ran without its clipping code (in_front).
    monkeypatch.setattr(draw, "_run_setup", lambda *args: (calls.append(args[3:4] == (True,)), real(*args)))
    channels = scenes.render_multilayer_exr(scene, path)
    return channels, calls


@pytest.mark.parametrize("fill", [False, True])
def test_setup_table_gives_the_same_image(fill, output_dir, monkeypatch):
    if not shaders.setup_available():
        pytest.skip("no compute shaders here")
    scene = scenes.empty_scene(200, 150, use_fill=fill)
    _quads_tris_mirrored_shared(scene)
    per_corner, runs = _render(scene, output_dir / f"setup_off_{fill}.exr", 10**12, monkeypatch)
    assert runs == []
    table, runs = _render(scene, output_dir / f"setup_on_{fill}.exr", 1, monkeypatch)
    # Floor, wall, box and the mirrored monkey with its own mesh; the two
    # objects that share a mesh keep the per-corner set-up.
    assert len(runs) >= 4
    # Both pre-pass variants ran: the floor and wall cross the near plane,
    # the monkeys and the box lie wholly in front of it (ALL_IN_FRONT).
    assert True in runs and False in runs
    assert per_corner.keys() == table.keys()
    for name, values in per_corner.items():
        np.testing.assert_array_equal(table[name], values, err_msg=name)


def test_a_software_render_keeps_the_per_corner_set_up(output_dir, monkeypatch):
    """On a software rasteriser the render engine's context dispatches no
    pre-pass (its dispatch there has crashed llvmpipe), whatever the mesh
    size, and draws the same image; the viewport's context still does
    (test_a_redraw_that_changes_nothing_keeps_the_table)."""
    if not shaders.setup_available():
        pytest.skip("no compute shaders here")
    scene = scenes.empty_scene(120, 90)
    _quads_tris_mirrored_shared(scene)
    with_table, runs = _render(scene, output_dir / "setup_software_on.exr", 1, monkeypatch)
    assert len(runs) >= 4
    default, runs = _render(scene, output_dir / "setup_software_default.exr", 1, monkeypatch, software_renders=False)
    assert (runs == []) == shaders.software_rasteriser()
    for name, values in with_table.items():
        np.testing.assert_array_equal(default[name], values, err_msg=name)


def test_a_failing_pre_pass_falls_back_to_the_per_corner_set_up(output_dir, monkeypatch):
    """A backend whose compiler refuses the pre-pass draws the same image
    without it, with one message, instead of failing the render."""
    if not shaders.setup_available():
        pytest.skip("no compute shaders here")
    scene = scenes.empty_scene(120, 90)
    _quads_tris_mirrored_shared(scene)
    expected, _runs = _render(scene, output_dir / "setup_fallback_expected.exr", 10**12, monkeypatch)

    def refuse(*_variant):
        raise RuntimeError("compute shader refused")

    monkeypatch.setattr(shaders, "get_setup", refuse)
    monkeypatch.setattr(shaders, "_setup_support", [True])
    got, runs = _render(scene, output_dir / "setup_fallback.exr", 1, monkeypatch)
    assert runs == [] and shaders.setup_available() is False
    for name, values in expected.items():
        np.testing.assert_array_equal(got[name], values, err_msg=name)


def test_a_redraw_that_changes_nothing_keeps_the_table(monkeypatch):
    """The viewport overlay's direct pass sets a mesh up once per view: a
    redraw with the same mesh, matrix and viewport dispatches nothing and
    draws the same image; a moved vertex, a moved object or another
    viewport size set it up again, and every frame equals the per-corner
    set-up's."""
    if not shaders.setup_available():
        pytest.skip("no compute shaders here")
    import bpy

    from solidwire_addon.blender.views import camera_view
    from tests.test_overlay import FakeViewport

    scene = scenes.empty_scene(160, 120, diagonal_mode="SOLID")
    monkey = scenes.monkey(scene, "Monkey", subdivisions=1)
    scenes.add_camera(scene, location=(0.0, -4.0, 1.0), target=(0.0, 0.0, 0.0))
    monkeypatch.setattr(runtime, "options", DrawOptions(deferred_surface=False))
    dispatches = []
    real_dispatch = draw.gpu.compute.dispatch
    monkeypatch.setattr(draw.gpu.compute, "dispatch", lambda *args: (dispatches.append(1), real_dispatch(*args)))

    def frame(setup_min=1, size=(160, 120)):
        monkeypatch.setattr(draw, "SETUP_TABLE_MIN", setup_min)
        dispatches.clear()
        depsgraph = bpy.context.evaluated_depsgraph_get()
        view = camera_view(scene, depsgraph, size)
        viewport = FakeViewport(*size)
        viewport.depth_pass(depsgraph, view, [monkey])
        viewport.draw_overlay(depsgraph, view, scene.solidwire.snapshot(), display=None)
        return viewport.rgba(), len(dispatches)

    first, runs = frame()
    assert runs == 1
    assert first[..., 3].max() > 0.9
    again, runs = frame()
    assert runs == 0 and np.array_equal(first, again)
    per_corner, runs = frame(setup_min=10**12)
    assert runs == 0 and np.array_equal(first, per_corner)
    monkey.data.vertices[0].co.z += 0.2
    monkey.data.update()
    edited, runs = frame()
    assert runs == 1 and np.array_equal(edited, frame(setup_min=10**12)[0])
    monkey.location.x += 0.05
    moved, runs = frame()
    assert runs == 1 and np.array_equal(moved, frame(setup_min=10**12)[0])
    assert not np.array_equal(edited, moved)
    bigger, runs = frame(size=(200, 150))
    assert runs == 1 and np.array_equal(bigger, frame(setup_min=10**12, size=(200, 150))[0])
