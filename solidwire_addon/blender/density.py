"""Fade Dense Objects (``use_object_density_fade``, docs/image_model.md §3.8):
the wire of an object or instance whose edges are short on screen fades as
a whole, so a crowd of small objects (a thousand spheres, a scatter of
instances) shows its shaded fill instead of a black mass of lines.

Why per object and not per edge (Density Fade, §3.7): an edge seen nearly
end-on is short on screen on any mesh, however sparse, and fading those
cuts holes in the outline of every smooth object; an object's typical edge
length says whether the object as a whole is dense. So a scene of readable
objects draws exactly as without the rule, and the rule can be on by
default.

The measure, per drawn item:

* ``length``: the median 3D length of its mesh's edges in object space
  (the cage's edges when cage edges are drawn: they are the lines shown),
  times the item's scale (mean length of its matrix's axes);
* ``pixels``: that length in window pixels at the nearest point of the
  item's bound box (perspective: at that view depth; orthographic: at any
  depth), so an object that is sparse anywhere on screen is never faded;
* ``g = clamp(2 pixels / L - 1, 0, 1)`` with L = ``density_fade_length``
  (the same ramp as Density Fade), rounded down to 1/64 so nearby
  instances share one style; the item's wire opacity is multiplied by g.

Edge classes with their own colour (boundary, sharp, ...) keep their
opacity: they are chosen on purpose. The Wire render pass holds the line
intensity without opacity, so it is not faded either.
"""

from __future__ import annotations

import math

import numpy as np

from ..core.view import Style, View
from .mesh_reading import read_edge_verts, read_positions

# Edges sampled per mesh for the median (evenly spread; enough for a median).
SAMPLE_EDGES = 20000
# g is rounded down to this step: items with nearly the same fade share a
# style (one draw per mesh and style).
STEP = 1.0 / 64.0


def typical_edge_length(mesh) -> float:
    """Median 3D length of ``mesh``'s edges in its own space (0.0: none)."""
    count = len(mesh.edges)
    if count == 0:
        return 0.0
    positions = read_positions(mesh).astype(np.float64)
    ends = read_edge_verts(mesh)[:: max(count // SAMPLE_EDGES, 1)]
    if len(positions) == 0 or ends.max(initial=0) >= len(positions):
        return 0.0
    lengths = np.linalg.norm(positions[ends[:, 0]] - positions[ends[:, 1]], axis=1)
    lengths = lengths[np.isfinite(lengths) & (lengths > 0.0)]
    return float(np.median(lengths)) if len(lengths) else 0.0


def fade_factor(pixels: float, full: float) -> float:
    """g of §3.7 for a line ``pixels`` long, full at ``full`` px."""
    if not full > 0.0:
        return 1.0
    return min(max(2.0 * pixels / full - 1.0, 0.0), 1.0)


def on_screen_lengths(items, view: View) -> np.ndarray:
    """(N,) window pixels of each item's typical edge at its nearest point
    (inf where unknown or where the item reaches the camera plane)."""
    count = len(items)
    result = np.full(count, np.inf)
    if count == 0:
        return result
    # Per distinct mesh once (instances share theirs), then by index.
    index_of: dict = {}
    mesh_list: list = []
    which = np.empty(count, np.int64)
    for number, item in enumerate(items):
        index = index_of.get(id(item.mesh))
        if index is None:
            index = index_of[id(item.mesh)] = len(mesh_list)
            mesh_list.append(item.mesh)
        which[number] = index
    lengths = np.array([float(getattr(mesh, "edge_length", 0.0) or 0.0) for mesh in mesh_list])[which]
    matrices = np.stack([item.matrix for item in items])  # (N, 4, 4) object -> world
    scale = np.linalg.norm(matrices[:, :3, :3], axis=1).mean(axis=1)
    world_length = lengths * scale
    projection = view.projection
    height = float(view.viewport[3])
    px_per_unit = 0.5 * height * abs(float(projection[1][1]))
    if float(projection[3][3]) == 1.0:  # orthographic: the same size at any depth
        pixels = world_length * px_per_unit
    else:
        lo = np.stack([mesh.centre + mesh.bounds_min for mesh in mesh_list])[which]  # (N, 3)
        hi = np.stack([mesh.centre + mesh.bounds_max for mesh in mesh_list])[which]
        corners = np.stack(
            [np.where(np.array(bits, dtype=bool), hi, lo) for bits in np.ndindex(2, 2, 2)], axis=1
        )  # (N, 8, 3)
        to_view_z = np.einsum("j,njk->nk", view.view_matrix[2], matrices)  # (N, 4): view z row
        depth = -(np.einsum("nk,nck->nc", to_view_z[:, :3], corners) + to_view_z[:, 3:4])  # (N, 8)
        nearest = depth.min(axis=1)
        with np.errstate(divide="ignore", invalid="ignore"):
            pixels = np.where(nearest > 1e-9, world_length * px_per_unit / nearest, np.inf)
    known = (lengths > 0.0) & np.isfinite(pixels)
    result[known] = pixels[known]
    return result


def fade_dense_items(items, view: View, settings) -> int:
    """Give each item whose typical edge is short on screen a style with
    its wire opacity times g; returns how many items were faded. Items
    keep their own style override (its opacity is faded the same way)."""
    if not getattr(settings, "use_object_density_fade", False) or not items:
        return 0
    full = float(settings.density_fade_length)
    if not full > 0.0:
        return 0
    pixels = on_screen_lengths(items, view)
    fades = np.clip(2.0 * pixels / full - 1.0, 0.0, 1.0)
    fades = np.floor(np.where(np.isfinite(fades), fades, 1.0) / STEP) * STEP
    scene_style = Style(tuple(settings.wire_color), float(settings.thickness), tuple(settings.fill_color))
    faded = 0
    styles: dict = {}
    for item, g in zip(items, fades):
        if g >= 1.0:
            continue
        base = item.style or scene_style
        key = (base, g)
        style = styles.get(key)
        if style is None:
            wire = tuple(base.wire_color)
            style = styles[key] = Style((*wire[:3], wire[3] * float(g)), base.thickness, base.fill_color)
        item.style = style
        faded += 1
    return faded


def needs_lengths(settings) -> bool:
    return (
        bool(getattr(settings, "use_object_density_fade", False))
        and math.isfinite(float(settings.density_fade_length))
        and float(settings.density_fade_length) > 0.0
    )
