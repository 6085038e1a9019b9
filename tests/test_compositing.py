"""Frame compositing in place (core.compositing): the film under a render and
the silhouettes' outer halves over it, against the premultiplied "over"
formula in float64, on frames with partial coverage, and through the
render engine (an opaque film is the transparent render over the world
colour)."""

from __future__ import annotations

import bpy
import numpy as np
import pytest

from solidwire_addon.blender import engine
from solidwire_addon.core import compositing
from tests.support import scenes


def _frame(seed: int, height: int = 37, width: int = 53) -> np.ndarray:
    """A premultiplied frame: empty, opaque and partly covered pixels."""
    rng = np.random.default_rng(seed)
    alpha = rng.choice([0.0, 1.0, 0.25, 0.5], size=(height, width)).astype(np.float32)
    alpha = np.where(rng.random((height, width)) < 0.5, alpha, rng.random((height, width)).astype(np.float32))
    colour = rng.random((height, width, 3)).astype(np.float32) * alpha[..., None]
    return np.concatenate([colour, alpha[..., None]], axis=-1)


# One block for the whole frame, then blocks of 1 and 3 rows (the last one
# shorter): the frame is composited block by block (compositing.BLOCK_PIXELS).
BLOCKS = [compositing.BLOCK_PIXELS, 53, 160]


@pytest.mark.parametrize("block_pixels", BLOCKS)
def test_over_film_is_premultiplied_over_an_opaque_colour(block_pixels, monkeypatch):
    monkeypatch.setattr(compositing, "BLOCK_PIXELS", block_pixels)
    frame = _frame(1)
    film = (0.2, 0.45, 0.7)
    expected = frame.astype(np.float64)
    expected[..., :3] += (1.0 - expected[..., 3:4]) * np.asarray(film)
    expected[..., 3] = 1.0
    result = frame.copy()
    compositing.over_film(result, film)
    assert np.abs(result - expected).max() < 1e-6
    # The same bits as the float32 one-liner (see compositing's docstring).
    one_liner = frame.copy()
    one_liner[..., :3] += (np.float32(1.0) - frame[..., 3:4]) * np.asarray(film, dtype=np.float32)
    one_liner[..., 3] = 1.0
    assert np.array_equal(result, one_liner)
    # Opaque pixels keep their colour exactly; empty ones become the film.
    opaque, empty = frame[..., 3] == 1.0, frame[..., 3] == 0.0
    assert opaque.any() and empty.any()
    assert np.array_equal(result[opaque], frame[opaque])
    assert np.allclose(result[empty][:, :3], np.asarray(film, dtype=np.float32))


@pytest.mark.parametrize("block_pixels", BLOCKS)
def test_colour_over_blends_by_coverage_and_alpha(block_pixels, monkeypatch):
    monkeypatch.setattr(compositing, "BLOCK_PIXELS", block_pixels)
    frame = _frame(2)
    coverage = np.random.default_rng(3).choice([0.0, 1.0, 0.3], size=frame.shape[:2]).astype(np.float32)
    wire = (0.9, 0.1, 0.3, 0.8)
    a = coverage.astype(np.float64)[..., None] * wire[3]
    expected = (1.0 - a) * frame + a * np.asarray(wire[:3] + (1.0,))
    result = frame.copy()
    compositing.color_over(result, wire, coverage)
    assert np.abs(result - expected).max() < 1e-6
    untouched = coverage == 0.0
    assert np.array_equal(result[untouched], frame[untouched])


def test_opaque_film_render_is_the_transparent_render_over_the_world():
    """The engine's film composite on a real frame: anti-aliased silhouette
    pixels (partial alpha) get exactly the share of world colour the
    premultiplied formula gives them."""
    scene = scenes.empty_scene(96, 72, transparent=True)
    world = bpy.data.worlds.new("World")
    world.color = (0.3, 0.5, 0.1)
    scene.world = world
    scenes.monkey(scene)
    scenes.add_camera(scene, location=(2.0, -4.0, 1.5), target=(0.0, 0.0, 0.0))
    transparent, _depth = engine.render_scene(bpy.context.evaluated_depsgraph_get())
    transparent = transparent.copy()
    scene.render.film_transparent = False
    opaque, _depth = engine.render_scene(bpy.context.evaluated_depsgraph_get())
    partial = (transparent[..., 3] > 0.05) & (transparent[..., 3] < 0.95)
    assert partial.sum() > 20
    expected = transparent.astype(np.float64)
    expected[..., :3] += (1.0 - expected[..., 3:4]) * np.asarray(world.color)
    expected[..., 3] = 1.0
    assert np.abs(opaque - expected).max() < 1e-6
