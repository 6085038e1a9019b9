"""Premultiplied "over" on a whole float32 frame, in place (plain numpy).

A frame read back from the GPU is (H, W, 4) float32, premultiplied. At 4K
that is 133 MB, and every full-frame temporary numpy makes of that size is
fresh memory the kernel must fault in page by page: the textbook one-liner
``out = rgba.copy(); out[..., :3] += (1 - a) * film`` made three of them and
cost ~0.2 s of a 4K frame on a 2-core machine (about a quarter of it). These
helpers change the frame where it lies, one channel at a time through one
(H, W) scratch array, with the same float32 operations in the same order as
that one-liner (so the same bits).
"""

from __future__ import annotations

import numpy as np


def over_film(rgba: np.ndarray, film_rgb) -> None:
    """``rgba`` over an opaque film of colour ``film_rgb``, in place:
    colour += (1 - alpha) * film, alpha = 1."""
    gap = np.subtract(np.float32(1.0), rgba[..., 3], dtype=np.float32)
    scratch = np.empty_like(gap)
    for channel, value in enumerate(np.asarray(film_rgb, dtype=np.float32)[:3]):
        np.multiply(gap, value, out=scratch)
        rgba[..., channel] += scratch
    rgba[..., 3] = 1.0


def color_over(rgba: np.ndarray, color, coverage: np.ndarray) -> None:
    """``color`` (straight RGBA) covering ``coverage`` ((H, W) in 0..1) of
    each pixel, premultiplied over ``rgba``, in place:
    rgba = (1 - a) * rgba + a * (rgb, 1) with a = coverage * alpha."""
    color = np.asarray(color, dtype=np.float32)
    alpha = np.multiply(coverage, color[3], dtype=np.float32)
    keep = np.subtract(np.float32(1.0), alpha, dtype=np.float32)
    scratch = np.empty_like(alpha)
    for channel, value in enumerate((color[0], color[1], color[2], np.float32(1.0))):
        rgba[..., channel] *= keep
        np.multiply(alpha, value, out=scratch)
        rgba[..., channel] += scratch
