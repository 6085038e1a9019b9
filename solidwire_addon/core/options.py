"""How a frame is drawn, apart from what it shows: one frozen value handed
down from the entry points (render engine, overlay, command line) to the
passes, the draw calls and the mesh cache.

Every option changes speed or memory, never the image (the benchmarks and
tests switch them to measure or cross-check the two ways); each default is
what the add-on ships. Nothing below the entry points keeps a switch of its
own.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class DrawOptions:
    # Meshes dense on screen draw their surface in two stages
    # (docs/image_model.md §2.5, draw.split_deferred); False draws every mesh
    # directly, the same image (a mesh's region lines still come from the
    # region-lines pass, over a record of its own: §2.6).
    deferred_surface: bool = True
    # How the deferred surface's visibility stage numbers triangles: by their
    # provoking vertex (True) or with gl_PrimitiveID (False); None lets
    # shaders.triangle_ids_by_vertex decide for this GPU. The same frame
    # either way.
    triangle_ids_by_vertex: bool | None = None
    # A hidden-line draw whose triangles walk their regions (the walk-table
    # pre-pass picked each one's lines) leaves out the region triangles
    # that no drawn edge comes within reach of: they show nothing there,
    # and a software rasteriser otherwise runs the vertex stage for them in
    # the same SIMD batches as the rest. It reads the table back, which
    # costs a GPU a round trip for little gain. None lets the backend
    # decide (shaders.software_rasteriser); the same frame either way.
    drop_lineless_triangles: bool | None = None
    # A frame starts from the GPU meshes of the last one, re-extracting only
    # what changed (blender/runtime.py); False starts every frame from an
    # empty cache.
    reuse_meshes: bool = True
    # A mesh whose shape alone changed uploads new positions only
    # (cache.MeshCache.get_validated); False extracts it again in full.
    reposition_meshes: bool = True


DEFAULT = DrawOptions()
