"""The pass plan: which passes draw a frame, in which order, with which
settings. One plan serves every target; the two executors below differ only
in where the passes land.

    surface      every drawn face: depth, the fill colour and (unless hidden
                 lines are on) the visible wire, in one pass
    hidden       hidden lines, behind the surface depth, blended "over"
    wire         the visible wire over the hidden lines (only with hidden lines)
    silhouettes  the outer half of silhouette edges (image model §5.5)

* :func:`render` (render engine, command line, tests): float offscreen
  targets, read back as premultiplied RGBA plus view depth.
* :func:`draw_over_viewport` (viewport overlay): straight into a bound
  framebuffer that already holds the scene's colour and depth.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import gpu
import numpy as np

from . import colors
from . import draw as draw_mod
from . import silhouettes
from .targets import read_texture, targets_for
from .view import View

SURFACE, HIDDEN, WIRE, SILHOUETTES = "surface", "hidden", "wire", "silhouettes"


@dataclass(frozen=True)
class Pass:
    kind: str
    settings: object  # the DrawSettings this pass draws with


def plan(settings) -> tuple[Pass, ...]:
    """The passes ``settings`` need, in drawing order (an option that is off
    adds no pass)."""
    if settings.use_hidden_lines:
        # Hidden lines sit under the visible wire and over the fill: the
        # surface pass draws the fill (wire switched off), then hidden lines,
        # then the wire on its own.
        wire_only = replace(settings, use_fill=False)
        passes = [
            Pass(SURFACE, replace(settings, wire_color=(*settings.wire_color[:3], 0.0))),
            Pass(HIDDEN, wire_only),
            Pass(WIRE, wire_only),
        ]
    else:
        passes = [Pass(SURFACE, settings)]
    if settings.use_silhouettes:
        passes.append(Pass(SILHOUETTES, settings))
    return tuple(passes)


def gather_options(settings) -> dict:
    """What the draw items of a frame with ``settings`` must carry (keyword
    arguments of blender/gather.gather): corner tables for a shaded fill or
    material colours, colour-source inputs for per-object colours."""
    return {"corners": draw_mod.needs_corners(settings), "colors": colors.needs_item_colors(settings),
            "edge_angle": float(settings.edge_angle)}


def render(items, view: View, settings, *, cull: bool = True):
    """Draw ``items`` offscreen; return (rgba, view_depth, stats).

    ``rgba`` is (H, W, 4) float32, premultiplied, bottom row first, over a
    transparent background; ``view_depth`` is (H, W) with BACKGROUND_DEPTH
    where nothing was drawn. The caller makes sure the GPU is usable."""
    width, height = view.width, view.height
    targets = targets_for(width, height)
    steps = plan(settings)
    stats = None
    framebuffer = targets.framebuffer()
    with framebuffer.bind():
        framebuffer.clear(color=(0.0, 0.0, 0.0, 0.0), depth=1.0)
        gpu.state.viewport_set(0, 0, width, height)
        stats = draw_mod.draw(items, view, steps[0].settings, write_view_depth=True, cull=cull)
        gpu.state.depth_test_set("NONE")
        gpu.state.depth_mask_set(False)
    blended = [step for step in steps[1:] if step.kind in (HIDDEN, WIRE)]
    if blended:
        # A framebuffer without the view-depth target: blended passes must
        # leave the surface's view depth alone.
        with targets.color_framebuffer().bind():
            gpu.state.viewport_set(0, 0, width, height)
            gpu.state.blend_set("ALPHA_PREMULT")
            try:
                for step in blended:
                    if step.kind == HIDDEN:
                        draw_mod.draw_hidden_lines(items, view, step.settings, cull=cull)
                    else:
                        draw_mod.draw(items, view, step.settings, depth_write=False, cull=cull)
            finally:
                gpu.state.blend_set("NONE")
                gpu.state.depth_test_set("NONE")
    rgba, depth = targets.read()
    if any(step.kind == SILHOUETTES for step in steps):
        rgba = _composite_silhouettes(rgba, targets, items, view, settings)
    return rgba, depth, stats


def _composite_silhouettes(rgba, targets, items, view, settings):
    """Draw the outer halves of silhouette edges (max intensity per pixel,
    occluded by the surface pass's depth) and composite them over ``rgba``
    with the wire colour ("over", premultiplied)."""
    framebuffer = targets.silhouette_framebuffer()
    with framebuffer.bind():
        framebuffer.clear(color=(0.0, 0.0, 0.0, 0.0), depth=1.0)
        gpu.state.viewport_set(0, 0, view.width, view.height)
        silhouettes.draw_silhouettes(items, view, settings, targets.depth)
        gpu.state.depth_test_set("NONE")
        gpu.state.depth_mask_set(False)
    outer = read_texture(targets.outer, 1)[..., 0:1]
    wire = np.asarray(settings.wire_color, dtype=np.float32)
    alpha = outer * wire[3]
    over = np.concatenate([wire[:3] * alpha, alpha], axis=-1)
    return over + (1.0 - alpha) * rgba


# NDC depth bias of the viewport overlay (2^-18: 32 steps of a 24-bit depth
# buffer, about 4 float32 ULPs of z/w near 1). Enough to win the tie with
# Blender's own depth of the same surface (a few ULPs off, computed from other
# float32 matrices); small enough that a surface more than a hair behind
# another stays hidden. See DEPTH_BIAS in shaders/solidwire_vert.glsl.
OVERLAY_DEPTH_BIAS = 2.0**-18


def draw_over_viewport(items, view: View, settings, *, depth_bias: float = OVERLAY_DEPTH_BIAS):
    """Draw ``items`` over a bound framebuffer that already holds the scene's
    colour and depth (a 3D viewport after its own drawing). Returns the
    DrawStats of the surface pass.

    A depth-only pre-pass comes first, so only the nearest of our own
    surfaces passes the colour passes (no back edges show through where the
    scene depth is empty, as in X-ray or Wireframe shading); the scene's depth
    hides wires behind other geometry. Then the plan's passes, blended with
    premultiplied alpha at depth test LESS_EQUAL. GPU state is restored."""
    saved_blend = gpu.state.blend_get()
    saved_depth_test = gpu.state.depth_test_get()
    saved_depth_mask = gpu.state.depth_mask_get()
    stats = None
    try:
        gpu.state.blend_set("NONE")
        gpu.state.color_mask_set(False, False, False, False)
        draw_mod.draw(items, view, settings, depth_bias=depth_bias)
        gpu.state.color_mask_set(True, True, True, True)
        gpu.state.blend_set("ALPHA_PREMULT")
        for step in plan(settings):
            if step.kind == SURFACE:
                # With hidden lines the surface pass only carries the fill.
                if settings.use_hidden_lines and not settings.use_fill:
                    continue
                surface_stats = draw_mod.draw(items, view, step.settings, depth_bias=depth_bias)
                stats = stats or surface_stats
            elif step.kind == HIDDEN:
                draw_mod.draw_hidden_lines(items, view, step.settings, depth_bias=depth_bias)
            elif step.kind == WIRE:
                stats = draw_mod.draw(items, view, step.settings, depth_bias=depth_bias)
            elif step.kind == SILHOUETTES:
                silhouettes.draw_silhouettes(items, view, step.settings, overlay_bias=depth_bias)
    finally:
        gpu.state.color_mask_set(True, True, True, True)
        gpu.state.blend_set(saved_blend)
        gpu.state.depth_test_set(saved_depth_test)
        gpu.state.depth_mask_set(saved_depth_mask)
    return stats if stats is not None else draw_mod.DrawStats()
