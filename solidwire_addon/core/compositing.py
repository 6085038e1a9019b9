"""Premultiplied "over" on a whole float32 frame, in place (plain numpy).

A frame read back from the GPU is (H, W, 4) float32, premultiplied. At 4K
that is 133 MB, and every full-frame temporary numpy makes of that size is
fresh memory the kernel must fault in page by page: the textbook one-liner
``out = rgba.copy(); out[..., :3] += (1 - a) * film`` made three of them and
cost ~0.2 s of a 4K frame on a 2-core machine (about a quarter of it). These
helpers change the frame where it lies, one channel at a time, with the same
float32 operations in the same order as that one-liner (so the same bits).

They walk the frame in blocks of whole rows of about BLOCK_PIXELS pixels
(256 KiB of RGBA32F): each channel's pass then finds the block still in the
CPU cache, so the frame crosses the memory bus once instead of once per pass
(five passes: half the time of whole-frame passes at 4K), and the scratch
arrays are a block, not a frame.
"""

from __future__ import annotations

import numpy as np

BLOCK_PIXELS = 16384


def _row_blocks(rgba: np.ndarray, plane: np.ndarray | None = None, scratch_count: int = 2):
    """(block of ``rgba``, the same rows of the (H, W) ``plane`` or None,
    ``scratch_count`` (rows, W) float32 scratch arrays) for consecutive
    blocks of whole rows; the scratch arrays are reused from block to block."""
    height, width = rgba.shape[:2]
    rows = max(1, BLOCK_PIXELS // max(width, 1))
    scratch = np.empty((scratch_count, min(rows, height), width), dtype=np.float32)
    for top in range(0, height, rows):
        block = rgba[top : top + rows]
        count = len(block)
        yield block, None if plane is None else plane[top : top + rows], scratch[:, :count]


def over_film(rgba: np.ndarray, film_rgb) -> None:
    """``rgba`` over an opaque film of colour ``film_rgb``, in place:
    colour += (1 - alpha) * film, alpha = 1."""
    film = np.asarray(film_rgb, dtype=np.float32)[:3]
    for block, _plane, (gap, scratch) in _row_blocks(rgba):
        np.subtract(np.float32(1.0), block[..., 3], out=gap, dtype=np.float32)
        for channel, value in enumerate(film):
            np.multiply(gap, value, out=scratch)
            block[..., channel] += scratch
        block[..., 3] = 1.0


def color_over(rgba: np.ndarray, color, coverage: np.ndarray) -> None:
    """``color`` (straight RGBA) covering ``coverage`` ((H, W) in 0..1) of
    each pixel, premultiplied over ``rgba``, in place:
    rgba = (1 - a) * rgba + a * (rgb, 1) with a = coverage * alpha."""
    color = np.asarray(color, dtype=np.float32)
    channels = (color[0], color[1], color[2], np.float32(1.0))
    for block, cover, (alpha, keep, scratch) in _row_blocks(rgba, coverage, scratch_count=3):
        np.multiply(cover, color[3], out=alpha, dtype=np.float32)
        np.subtract(np.float32(1.0), alpha, out=keep, dtype=np.float32)
        for channel, value in enumerate(channels):
            block[..., channel] *= keep
            np.multiply(alpha, value, out=scratch)
            block[..., channel] += scratch
