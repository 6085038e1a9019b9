"""Viewport colour management of the overlay (docs/image_model.md §9): the
scene's view transform as a 3D lookup table the overlay's fragment stages
apply last (shaders/display_transform.glsl).

Why a table. A render's colours are scene-linear and Blender applies the
scene's colour management (display device, view transform, look, exposure,
gamma, curves, white balance) when it shows or saves the render. The overlay
draws into the viewport's overlay buffer, which Blender does *not* colour
manage: without this step a wire looked like sRGB(colour) in the viewport
and like AgX(colour) in the render. Blender's OCIO processors are not
reachable from Python, so the Blender side (blender/color_management.py)
lets Blender transform a grid of colours (a float image saved "as render")
and hands the result here as plain data. The transform is the one a saved
render goes through, so the table matches the F12 image by construction,
whatever the OCIO config defines (AgX, Filmic, Khroma, looks, ...).

Grid. ``LUT_SIZE`` nodes per channel, placed by a per-channel shaper on the
exposure-scaled value y = x * 2^exposure:

    s(y) = log2(1 + y / SHAPER_KNEE) / log2(1 + SHAPER_MAX / SHAPER_KNEE)

linear below the knee (dark colours and a channel near zero), logarithmic
above it (a view transform's tone curve is close to linear in log2). White
(y = 1, where Standard clips) is node WHITE_NODE exactly, so a clipping view
transform has its kink on a node. Inputs above SHAPER_MAX (about 6x white)
are clamped to it (a decision, not a limit of the method: those are colours
brighter than anything a colour picker gives without HDR values; AgX is
already white there, Filmic within a few levels of it). Negative inputs are
clamped to 0. Interpolation is tetrahedral in the display-encoded values
(the file's values), which measured more accurate than interpolating after
the power below; 65 nodes keep the interpolation error of AgX, whose gamut
compression bends sharply near saturated colours, under about 2/255 for
colours in [0, 1] (Standard and Filmic: under 1/255; the measured numbers of
other transforms are in tests/test_overlay_color_management.py).

Output. Blender merges the overlay buffer (SRGB8_A8: it stores sRGB(out) and
reads back ``out``) over the colour-managed scene in a "display linear" space
taken as a 2.2 power (gpu_shader_display_transform_frag.glsl,
OCIO_ProcessColor, ``do_overlay_merge``): the pixel on screen is
``out ^ (1 / 2.2)`` where the overlay is opaque. So the shader writes
``display ^ OVERLAY_MERGE_GAMMA`` (un-premultiplied, transformed,
re-premultiplied), and the screen shows the display-encoded value of the
render. (Writing sRGB^-1(display) instead, which a plain sRGB target would
suggest, is off by up to 8/255 in dark colours on screen.)
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import gpu
import numpy as np

LUT_SIZE = 65
SHAPER_KNEE = 1.0 / 64.0
WHITE_NODE = 45  # node index of y = 1 (of LUT_SIZE - 1 steps)
# log2(1 + SHAPER_MAX / SHAPER_KNEE): the shaper's span, fixed by WHITE_NODE.
SHAPER_SPAN = math.log2(1.0 + 1.0 / SHAPER_KNEE) * (LUT_SIZE - 1) / WHITE_NODE
SHAPER_MAX = SHAPER_KNEE * (2.0**SHAPER_SPAN - 1.0)
# The power of Blender's overlay merge (see the module docstring).
OVERLAY_MERGE_GAMMA = 2.2


def grid_axis(exposure: float = 0.0) -> np.ndarray:
    """(LUT_SIZE,) float64: the scene-linear value of each node of one
    channel (the inverse of the shaper at i / (LUT_SIZE - 1))."""
    u = np.linspace(0.0, 1.0, LUT_SIZE)
    return SHAPER_KNEE * (np.exp2(u * SHAPER_SPAN) - 1.0) / 2.0 ** float(exposure)


def grid_colors(exposure: float = 0.0) -> np.ndarray:
    """(N^3, 3) float32 scene-linear colours, N = LUT_SIZE: node (r, g, b)
    at row (b * N + g) * N + r, red fastest (the order of a 3D texture and
    of an image N^2 wide and N high, bottom row first)."""
    axis = grid_axis(exposure)
    b, g, r = np.meshgrid(axis, axis, axis, indexing="ij")
    return np.stack([r.ravel(), g.ravel(), b.ravel()], axis=1).astype(np.float32)


def shaper_constants(exposure: float = 0.0) -> tuple[float, float]:
    """(k, n) of the shader: s(x) = log2(1 + k x) * n."""
    return 2.0 ** float(exposure) / SHAPER_KNEE, 1.0 / SHAPER_SPAN


@dataclass(eq=False)
class DisplayLUT:
    """One colour management as a table: ``display[b, g, r]`` is the
    display-encoded RGB (0..1, as written to a PNG) of grid node (r, g, b);
    ``exposure`` places the nodes (grid_axis); ``key`` says which settings
    it was made from."""

    key: tuple
    display: np.ndarray  # (N, N, N, 3) float32
    exposure: float = 0.0
    _texture: object = field(default=None, repr=False)

    @property
    def size(self) -> int:
        return int(self.display.shape[0])

    @property
    def shaper(self) -> tuple[float, float]:
        return shaper_constants(self.exposure)

    def texture(self):
        """The RGBA16F 3D texture (made on first use, in a GPU context).
        Half floats keep 11 bits: 0.1/255 at white."""
        if self._texture is None:
            n = self.size
            rgba = np.ones((n, n, n, 4), dtype=np.float32)
            rgba[..., :3] = self.display
            buf = gpu.types.Buffer("FLOAT", rgba.size)
            np.asarray(buf)[:] = rgba.reshape(-1)
            self._texture = gpu.types.GPUTexture((n, n, n), format="RGBA16F", data=buf)
        return self._texture

    def release(self) -> None:
        self._texture = None
