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

    def silhouette_framebuffer(self):
        """Outer-half intensity (R32F) with its own depth buffer, created on
        first use (see silhouettes.py)."""
        import gpu

        if getattr(self, "outer", None) is None:
            width, height = self.size
            self.outer = gpu.types.GPUTexture((width, height), format="R32F")
            self.outer_depth = gpu.types.GPUTexture((width, height), format="DEPTH_COMPONENT32F")
        return gpu.types.GPUFrameBuffer(depth_slot=self.outer_depth, color_slots=(self.outer,))

    def color_framebuffer(self):
        """Colour and depth only, for blended passes that must leave the
        view-depth target alone."""
        import gpu

        return gpu.types.GPUFrameBuffer(depth_slot=self.depth, color_slots=(self.color,))


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
    from . import methods  # developer method variants keep their own targets

    methods.release()


def render(items, view: draw_mod.View, settings: draw_mod.DrawSettings, *, cull: bool = True, method: str = "exact"):
    """Draw ``items`` and return (rgba, view_depth, stats).

    ``rgba`` is (H, W, 4) float32, premultiplied, bottom row first, over a
    transparent background; ``view_depth`` is (H, W) with BACKGROUND_DEPTH
    where nothing was drawn. ``method`` is the developer/benchmark switch
    (methods.ALL_METHODS); the add-on itself always uses "exact"."""
    import gpu

    ensure_gpu()
    if method != "exact":
        from . import methods

        return methods.render(items, view, settings, method, cull=cull)
    width, height = view.width, view.height
    targets = targets_for(width, height)
    framebuffer = targets.framebuffer()
    with framebuffer.bind():
        framebuffer.clear(color=(0.0, 0.0, 0.0, 0.0), depth=1.0)
        gpu.state.viewport_set(0, 0, width, height)
        if settings.use_hidden_lines:
            stats = _render_with_hidden_lines(targets, items, view, settings, cull)
        else:
            stats = draw_mod.draw(items, view, settings, write_view_depth=True, cull=cull)
        gpu.state.depth_test_set("NONE")
        gpu.state.depth_mask_set(False)
    rgba = _read_texture(targets.color, 4)
    if settings.use_silhouettes:
        rgba = _composite_silhouettes(rgba, targets, items, view, settings)
    depth = _read_texture(targets.view_depth, 1)[..., 0]
    covered = _read_texture(targets.depth, 1)[..., 0] < 1.0
    depth = np.where(covered, depth, BACKGROUND_DEPTH)
    return rgba, depth, stats


def _render_with_hidden_lines(targets, items, view, settings, cull):
    """Three passes, so hidden lines sit under the visible wire and over the
    fill: (1) the base pass writes depth, view depth and the fill colour
    (transparent in overlay mode) with the wire switched off; (2) hidden
    edges, strictly behind that depth, blended over; (3) the visible wire
    (at equal depth) blended over that. Blended passes use a framebuffer
    without the view-depth target."""
    import gpu
    from dataclasses import replace

    base = replace(settings, wire_color=(*settings.wire_color[:3], 0.0))
    stats = draw_mod.draw(items, view, base, write_view_depth=True, cull=cull)
    wire_only = replace(settings, use_fill=False)
    with targets.color_framebuffer().bind():
        gpu.state.viewport_set(0, 0, view.width, view.height)
        gpu.state.blend_set("ALPHA_PREMULT")
        try:
            draw_mod.draw_hidden_lines(items, view, wire_only, cull=cull)
            draw_mod.draw(items, view, wire_only, depth_write=False, cull=cull)
        finally:
            gpu.state.blend_set("NONE")
    return stats


def _composite_silhouettes(rgba, targets, items, view, settings):
    """Draw the outer halves of silhouette edges (max intensity per pixel,
    occluded by the main pass's depth) and composite them over ``rgba``
    with the wire colour ("over", premultiplied)."""
    import gpu

    from . import silhouettes

    framebuffer = targets.silhouette_framebuffer()
    with framebuffer.bind():
        framebuffer.clear(color=(0.0, 0.0, 0.0, 0.0), depth=1.0)
        gpu.state.viewport_set(0, 0, view.width, view.height)
        silhouettes.draw_silhouettes(items, view, settings, targets.depth)
        gpu.state.depth_test_set("NONE")
        gpu.state.depth_mask_set(False)
    outer = _read_texture(targets.outer, 1)[..., 0:1]
    wire = np.asarray(settings.wire_color, dtype=np.float32)
    alpha = outer * wire[3]
    over = np.concatenate([wire[:3] * alpha, alpha], axis=-1)
    return over + (1.0 - alpha) * rgba
