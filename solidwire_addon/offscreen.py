"""Offscreen target: draw a view into float textures and read them back.

Used by the render engine, the command line, tests and the benchmark. The
colour target is RGBA32F (no 8-bit rounding before Blender's own colour
management), the depth buffer is 32-bit float and a second R32F target
receives the view depth for the Depth pass.
"""

from __future__ import annotations

import numpy as np

from . import draw as draw_mod
from .gpu_context import ensure_gpu

# Blender writes this depth where no surface is (what Cycles/EEVEE use).
BACKGROUND_DEPTH = 1.0e10


def _read_texture(texture, channels: int) -> np.ndarray:
    buf = texture.read()
    # A multi-dimensional gpu Buffer exports wrong strides to numpy: flatten first.
    buf.dimensions = texture.width * texture.height * channels
    return np.array(buf, dtype=np.float32).reshape(texture.height, texture.width, channels)


class Targets:
    """Colour, view-depth and depth textures of one size, reusable across frames."""

    def __init__(self, width: int, height: int):
        import gpu

        self.size = (width, height)
        self.color = gpu.types.GPUTexture((width, height), format="RGBA32F")
        self.view_depth = gpu.types.GPUTexture((width, height), format="R32F")
        self.depth = gpu.types.GPUTexture((width, height), format="DEPTH_COMPONENT32F")

    def framebuffer(self):
        """A framebuffer over the textures. Made per use: textures are shared
        between GL contexts but framebuffer objects are not, and the render
        engine's context differs from the one scripts draw in."""
        import gpu

        return gpu.types.GPUFrameBuffer(depth_slot=self.depth, color_slots=(self.color, self.view_depth))


_targets: Targets | None = None


def targets_for(width: int, height: int) -> Targets:
    global _targets
    if _targets is None or _targets.size != (width, height):
        _targets = None  # free the old textures before allocating new ones
        _targets = Targets(width, height)
    return _targets


def release() -> None:
    global _targets
    _targets = None


def render(items, view: draw_mod.View, settings: draw_mod.DrawSettings, *, cull: bool = True):
    """Draw ``items`` and return (rgba, view_depth, stats).

    ``rgba`` is (H, W, 4) float32, premultiplied, bottom row first, over a
    transparent background; ``view_depth`` is (H, W) with BACKGROUND_DEPTH
    where nothing was drawn."""
    import gpu

    ensure_gpu()
    width, height = view.width, view.height
    targets = targets_for(width, height)
    framebuffer = targets.framebuffer()
    with framebuffer.bind():
        framebuffer.clear(color=(0.0, 0.0, 0.0, 0.0), depth=1.0)
        gpu.state.viewport_set(0, 0, width, height)
        stats = draw_mod.draw(items, view, settings, write_view_depth=True, cull=cull)
        gpu.state.depth_test_set("NONE")
        gpu.state.depth_mask_set(False)
    rgba = _read_texture(targets.color, 4)
    depth = _read_texture(targets.view_depth, 1)[..., 0]
    covered = _read_texture(targets.depth, 1)[..., 0] < 1.0
    depth = np.where(covered, depth, BACKGROUND_DEPTH)
    return rgba, depth, stats
