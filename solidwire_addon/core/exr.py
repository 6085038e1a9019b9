"""A small OpenEXR reader for what Blender writes uncompressed: scanline
files (single- or multi-part, multilayer), channels of half, float or uint.

Render Result pixels cannot be read from Python, so layers rendered by other
engines come back through EXR files (blender/composite.py). Only uncompressed
files are supported; anything else raises ValueError with one line.
"""

from __future__ import annotations

import struct
from pathlib import Path

import numpy as np


class ExrError(ValueError):
    """A file this reader cannot read; str() is one line."""


_PIXEL_TYPES = {0: ("<u4", 4), 1: ("<f2", 2), 2: ("<f4", 4)}


def _exr_headers(data: bytes, pos: int, multipart: bool):
    headers = []
    while True:
        header = {}
        while True:
            end = data.index(b"\0", pos)
            name = data[pos:end].decode("latin-1")
            pos = end + 1
            if not name:
                break
            end = data.index(b"\0", pos)
            kind = data[pos:end].decode("latin-1")
            pos = end + 1
            (size,) = struct.unpack_from("<i", data, pos)
            pos += 4
            header[name] = (kind, data[pos : pos + size])
            pos += size
        if not header:  # the empty header that ends a multi-part header list
            break
        headers.append(header)
        if not multipart:
            break
    return headers, pos


def _exr_channels(raw: bytes) -> list[tuple[str, int]]:
    channels, pos = [], 0
    while raw[pos : pos + 1] not in (b"\0", b""):
        end = raw.index(b"\0", pos)
        name = raw[pos:end].decode("latin-1")
        (pixel_type,) = struct.unpack_from("<i", raw, end + 1)
        channels.append((name, pixel_type))
        pos = end + 1 + 16
    return channels


def read_exr(path) -> dict[str, np.ndarray]:
    """Channels of an uncompressed scanline OpenEXR file (single or
    multi-part, as Blender writes renders with ``exr_codec = 'NONE'``):
    {channel name: float32 (H, W) array, bottom row first}."""
    data = Path(path).read_bytes()
    if data[:4] != b"\x76\x2f\x31\x01":
        raise ExrError(f"'{path}' is not an OpenEXR file")
    (flags,) = struct.unpack_from("<I", data, 4)
    if flags & 0x200:
        raise ExrError(f"'{path}' is a tiled OpenEXR file (expected scanlines)")
    multipart = bool(flags & 0x1000)
    headers, pos = _exr_headers(data, 8, multipart)
    parts = []
    for header in headers:
        if header["compression"][1][:1] != b"\0":
            raise ExrError(f"'{path}' is compressed (expected exr_codec 'NONE')")
        x0, y0, x1, y1 = struct.unpack("<4i", header["dataWindow"][1])
        width, height = x1 - x0 + 1, y1 - y0 + 1
        channels = _exr_channels(header["channels"][1])
        arrays = {name: np.zeros((height, width), dtype=np.float32) for name, _type in channels}
        parts.append((y0, width, channels, arrays))
        pos += 8 * height  # this part's offset table (one uncompressed line per chunk)
    while pos < len(data):
        part = 0
        if multipart:
            (part,) = struct.unpack_from("<i", data, pos)
            pos += 4
        y, size = struct.unpack_from("<ii", data, pos)
        pos += 8
        y0, width, channels, arrays = parts[part]
        offset = pos
        for name, pixel_type in channels:
            dtype, nbytes = _PIXEL_TYPES[pixel_type]
            arrays[name][y - y0] = np.frombuffer(data, dtype=dtype, count=width, offset=offset)
            offset += width * nbytes
        pos += size
    out = {}
    for _y0, _width, _channels, arrays in parts:
        for name, array in arrays.items():
            out[name] = np.ascontiguousarray(array[::-1])  # EXR rows run top down
    return out


def exr_pass(channels: dict, layer: str, name: str, components: str) -> np.ndarray | None:
    """(H, W, len(components)) array of pass ``name`` of view layer
    ``layer``, or None when the file does not hold it."""
    keys = [f"{layer}.{name}.{c}" for c in components]
    if not all(k in channels for k in keys):
        return None
    return np.stack([channels[k] for k in keys], axis=-1)


# -- images --------------------------------------------------------------------
