"""MatCap images for the MATCAP fill (docs/image_model.md §5.8), as GPU
textures kept by name.

The core does not read files through Blender: the Blender side installs a
loader (``set_loader``) that returns a matcap's (diffuse, specular) pixels,
each an (H, W, 4) float32 array bottom row first (specular None when the
matcap has none), or None when the file is missing. One texture holds both:
rows 0..H-1 the diffuse pass, rows H..2H-1 the specular one (zeros without
it). Textures are made on first use and freed by :func:`clear`.
"""

from __future__ import annotations

from collections.abc import Callable

import gpu
import numpy as np

from .log import warn_once

_loader: Callable | None = None
_textures: dict[str, object] = {}

# What a loader returns when it cannot decode now but will later (Blender's
# interface: see blender/matcap_files.py); the fill is flat until then.
PENDING = "pending"


def set_loader(loader: Callable | None) -> None:
    global _loader
    _loader = loader
    clear()


def texture(name: str):
    """The RGBA32F texture of matcap ``name``, or None (one message) when it
    cannot be loaded: the fill is then drawn FLAT."""
    if name in _textures:
        return _textures[name]
    pixels = None
    if _loader is not None:
        try:
            pixels = _loader(name)
        except Exception as exc:  # noqa: BLE001 - a bad file must not break the frame
            warn_once(("matcap", name), f"SolidWire: matcap '{name}' could not be read ({exc}); drawing a flat fill")
            pixels = None
    if pixels is PENDING:
        warn_once(("matcap pending", name), f"SolidWire: matcap '{name}' is still loading; the fill is flat until then")
        return None
    if pixels is None:
        warn_once(("matcap", name), f"SolidWire: matcap '{name}' is not available; drawing a flat fill")
        _textures[name] = None
        return None
    diffuse, specular = pixels
    diffuse = np.asarray(diffuse, dtype=np.float32)
    specular = np.zeros_like(diffuse) if specular is None else np.asarray(specular, dtype=np.float32)
    pixels = np.ascontiguousarray(np.concatenate([diffuse, specular], axis=0))
    height, width = pixels.shape[:2]
    buf = gpu.types.Buffer("FLOAT", width * height * 4)
    np.asarray(buf)[:] = pixels.reshape(-1)
    _textures[name] = gpu.types.GPUTexture((width, height), format="RGBA32F", data=buf)
    return _textures[name]


def forget(name: str) -> None:
    """Ask the loader again for ``name`` on next use."""
    _textures.pop(name, None)


def clear() -> None:
    _textures.clear()
