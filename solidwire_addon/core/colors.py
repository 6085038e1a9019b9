"""Per-object colours (docs/image_model.md §5.8): the colour sources of the
fill and the wire, and the per-frame colour table the shaders read them from.

Each draw item gets a block of texels in one table: texel 0 = (wire RGB,
material count), texel 1 = (fill RGB, 0), then one texel per material slot.
The vertex stage finds its block from the item's base index (the item table,
or the instance table for instanced draws).
"""

from __future__ import annotations

import colorsys
import zlib
from dataclasses import dataclass

import numpy as np

# RANDOM: hue from the name's CRC-32, fixed saturation and value (§5.8).
RANDOM_FILL_SV = (0.5, 0.8)
RANDOM_WIRE_SV = (0.8, 0.3)


@dataclass(frozen=True)
class ItemSource:
    """What the colour sources read from one drawn object (plain data)."""

    name: str  # the object's name (RANDOM)
    color: tuple  # object.color RGB (OBJECT)
    materials: tuple = ()  # per material slot: diffuse_color RGB, or None (empty slot)


def random_color(name: str, saturation: float, value: float) -> tuple:
    """The stable colour of ``name``: hue = crc32(UTF-8 name) / 2^32, then
    HSV -> RGB (Python's colorsys), used as scene-linear RGB."""
    hue = zlib.crc32(name.encode("utf-8")) / 4294967296.0
    return colorsys.hsv_to_rgb(hue, saturation, value)


def needs_item_colors(settings) -> bool:
    return (
        bool(settings.use_fill) and settings.fill_color_source != "SINGLE"
    ) or settings.wire_color_source != "SINGLE"


def needs_attribute_colors(settings) -> bool:
    """The fill comes from each mesh's active colour attribute (meshes
    without one take Fill Color)."""
    return bool(settings.use_fill) and settings.fill_color_source == "ATTRIBUTE"


def needs_material_colors(settings) -> bool:
    return bool(settings.use_fill) and settings.fill_color_source == "MATERIAL"


def item_colors(source: ItemSource | None, settings) -> tuple[tuple, tuple, tuple]:
    """(wire RGB, fill RGB, material RGBs) of one item under ``settings``."""
    wire = tuple(settings.wire_color[:3])
    fill = tuple(settings.fill_color[:3])
    materials: tuple = ()
    if source is None:
        return wire, fill, materials
    if settings.wire_color_source == "OBJECT":
        wire = tuple(source.color[:3])
    elif settings.wire_color_source == "RANDOM":
        wire = random_color(source.name, *RANDOM_WIRE_SV)
    if settings.fill_color_source == "OBJECT":
        fill = tuple(source.color[:3])
    elif settings.fill_color_source == "RANDOM":
        fill = random_color(source.name, *RANDOM_FILL_SV)
    elif settings.fill_color_source == "MATERIAL":
        materials = tuple(fill if m is None else tuple(m[:3]) for m in source.materials)
    return wire, fill, materials


def color_table(items, settings, styled=None) -> tuple[np.ndarray, np.ndarray]:
    """((K, 4) float32 table, (len(items),) base texel of each item).
    Items with the same source (and style override) share one block.
    ``styled(style)``: the settings of an item with an object's style
    override (core/draw.styled; its wire and fill colours replace the
    scene's before the colour sources apply)."""
    rows: list = []
    bases = np.empty(len(items), dtype=np.int64)
    blocks: dict = {}
    for index, item in enumerate(items):
        style = getattr(item, "style", None)
        key = (item.source, style)
        base = blocks.get(key)
        if base is None:
            item_settings = settings if style is None or styled is None else styled(style)
            wire, fill, materials = item_colors(item.source, item_settings)
            base = len(rows)
            rows.append((*wire, float(len(materials))))
            rows.append((*fill, 0.0))
            rows.extend((*m, 0.0) for m in materials)
            blocks[key] = base
        bases[index] = base
    return np.asarray(rows, dtype=np.float32).reshape(-1, 4), bases
