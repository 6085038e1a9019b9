"""Offscreen targets: float textures a view is drawn into, and their readback.

The colour target is RGBA32F (no 8-bit rounding before Blender's own colour
management), the depth buffer is 32-bit float and a second R32F target
receives the view depth for the Depth pass. One set of targets is kept per
size and reused across frames (:func:`targets_for`).
"""

from __future__ import annotations

import gpu
import numpy as np

# Blender writes this depth where no surface is (what Cycles/EEVEE use).
BACKGROUND_DEPTH = 1.0e10


def read_texture(texture, channels: int, into=None) -> np.ndarray:
    """(H, W, channels) float32 copy of a float texture, bottom row first:
    a new array, or a view of ``into`` (a flat FLOAT ``gpu.types.Buffer`` of
    W * H * channels values, see :meth:`Targets.read`), which is filled."""
    if into is None:
        buf = texture.read()
        # A multi-dimensional gpu Buffer exports wrong strides to numpy: flatten first.
        buf.dimensions = texture.width * texture.height * channels
    else:
        buf = into
        framebuffer = gpu.types.GPUFrameBuffer(color_slots=(texture,))
        with framebuffer.bind():
            framebuffer.read_color(0, 0, texture.width, texture.height, channels, 0, "FLOAT", data=buf)
    # A view of the Buffer's memory, not a copy (the array keeps the Buffer
    # alive; nobody else holds it). np.array(buf) would copy it again:
    # ~17 ms per RGBA read at 1280x720, 40-80 ms at 3840x2160.
    return np.asarray(buf, dtype=np.float32).reshape(texture.height, texture.width, channels)


class Targets:
    """Colour, view-depth and depth textures of one size, reusable across frames."""

    def __init__(self, width: int, height: int):
        self.size = (width, height)
        self.color = gpu.types.GPUTexture((width, height), format="RGBA32F")
        self.view_depth = gpu.types.GPUTexture((width, height), format="R32F")
        self.depth = gpu.types.GPUTexture((width, height), format="DEPTH_COMPONENT32F")
        self.outer = self.outer_depth = None  # silhouette targets, made on first use
        self.lines = None  # the region lines' strongest line per pixel, made on first use
        self.line_distances = None  # their nearest line's distance per pixel (Edge Distance), likewise
        self.lines_key = None  # what the overlay's lines were drawn for (passes._overlay_lines_key)
        self.aov = self.normal = None  # render-pass targets, made on first use
        self.own_layer = None  # a colour layer drawn apart (own_layer_framebuffer), made on first use
        self.wire_layer = None  # the render's visible wire under hidden lines (DrawTarget.wire_layer), likewise
        self.visible = None  # the deferred surface's visibility record, made on first use
        # The hidden layers of multi-face regions (passes._peel_hidden_regions),
        # made on first use: two depth images the layers alternate between,
        # and a layer's lines (colour, and the nearest line's distance as
        # depth).
        self.peel_depths = None
        self.hidden_lines = self.hidden_line_depth = None
        # Images the viewport overlay keeps of a frame it draws directly
        # (passes._overlay_kept_frame), by name, and the key each was last
        # drawn for directly (passes._keeping).
        self.kept: dict[str, KeptImage] = {}
        self.drawn_keys: dict = {}
        # The viewport overlay's resolved surface (premultiplied, as it
        # leaves the display transform) and what it was resolved for
        # (passes._overlay_surface), made on first use.
        self.surface = None
        self.surface_key = None
        self.surface_rect = (-1.0, -1.0, 1.0, 1.0)  # NDC rectangle it covers
        self.surface_counts = (0, 0, 0)  # objects drawn and culled, triangles drawn
        self.kept_readback = None  # [colour, view depth] gpu Buffers, made on first read(keep=True)

    def visibility_framebuffer(self):
        """The deferred surface's first stage: the visibility record
        (RGBA32F: triangle + 1, instance, draw number, view depth) over the
        depth buffer."""
        if self.visible is None:
            self.visible = gpu.types.GPUTexture(self.size, format="RGBA32F")
        return gpu.types.GPUFrameBuffer(depth_slot=self.depth, color_slots=(self.visible,))

    def surface_framebuffer(self):
        """The viewport overlay's resolved surface, no depth: the overlay
        composites it into Blender's buffer at the record's depth. Full
        floats: the composite then blends exactly what the resolve wrote,
        so a kept image draws what a resolve straight into Blender's buffer
        draws (passes._draw_overlay_surface); on llvmpipe a half-float
        target also resolved no faster."""
        if self.surface is None:
            self.surface = gpu.types.GPUTexture(self.size, format="RGBA32F")
        return gpu.types.GPUFrameBuffer(color_slots=(self.surface,))

    def resolve_framebuffer(self, aovs: bool = False, wire_layer: bool = False):
        """The deferred surface's second stage: the colour targets of
        :meth:`framebuffer` over the depth the first stage wrote, which the
        resolve only tests (its rectangle passes where a surface was
        recorded, shaders/resolve_vert.glsl)."""
        return self.framebuffer(aovs, wire_layer)

    def framebuffer(self, aovs: bool = False, wire_layer: bool = False):
        """A framebuffer over the textures. Made per use: textures are shared
        between GL contexts but framebuffer objects are not, and the render
        engine's context differs from the one scripts draw in. With ``aovs``
        the render passes' two targets too (RGBA32F: d_real, I_vis, object
        index; world normal), with ``wire_layer`` the visible wire's own
        layer after them (draw.DrawTarget.wire_layer), each created on first
        use."""
        return gpu.types.GPUFrameBuffer(depth_slot=self.depth, color_slots=self._color_slots(aovs, wire_layer))

    def _color_slots(self, aovs: bool, wire_layer: bool = False) -> tuple:
        # (The shaders' output locations follow this order:
        # shaders.output_and_feature_defines.)
        slots = (self.color, self.view_depth)
        if aovs:
            if self.aov is None:
                self.aov = gpu.types.GPUTexture(self.size, format="RGBA32F")
                self.normal = gpu.types.GPUTexture(self.size, format="RGBA32F")
            slots += (self.aov, self.normal)
        if wire_layer:
            if self.wire_layer is None:
                self.wire_layer = gpu.types.GPUTexture(self.size, format="RGBA32F")
            slots += (self.wire_layer,)
        return slots

    def own_layer_framebuffer(self):
        """A colour layer of its own over the surface depth, blended over the
        image afterwards (passes._blend_layer): the Hidden Wire pass's
        layers."""
        if self.own_layer is None:
            self.own_layer = gpu.types.GPUTexture(self.size, format="RGBA32F")
        return gpu.types.GPUFrameBuffer(depth_slot=self.depth, color_slots=(self.own_layer,))

    def color_framebuffer(self):
        """Colour and depth only, for blended passes that must leave the
        view-depth target alone."""
        return gpu.types.GPUFrameBuffer(depth_slot=self.depth, color_slots=(self.color,))

    def silhouette_framebuffer(self):
        """Outer-half intensity (R32F) with its own depth buffer, in which
        the silhouettes keep their per-pixel maximum, created on first use
        (see silhouettes.py)."""
        if self.outer is None:
            self.outer = gpu.types.GPUTexture(self.size, format="R32F")
            self.outer_depth = gpu.types.GPUTexture(self.size, format="DEPTH_COMPONENT32F")
        return gpu.types.GPUFrameBuffer(depth_slot=self.outer_depth, color_slots=(self.outer,))

    def region_lines_framebuffer(self):
        """The region lines' strongest line per pixel: a depth buffer alone
        whose value packs intensity and style (shaders/edge_styles.glsl
        line_code), created on first use (docs/image_model.md §2.6;
        passes._draw_region_lines). Its own, not the silhouettes': the
        overlay keeps it across redraws."""
        if self.lines is None:
            self.lines = gpu.types.GPUTexture(self.size, format="DEPTH_COMPONENT32F")
        return gpu.types.GPUFrameBuffer(depth_slot=self.lines)

    def line_distance_framebuffer(self):
        """The region lines' nearest line per pixel for the Edge Distance
        pass: a depth buffer alone holding the distance (shaders/
        region_lines_frag.glsl LINE_DISTANCE), created on first use."""
        if self.line_distances is None:
            self.line_distances = gpu.types.GPUTexture(self.size, format="DEPTH_COMPONENT32F")
        return gpu.types.GPUFrameBuffer(depth_slot=self.line_distances)

    def peel_framebuffer(self, layer: int):
        """Hidden region layer ``layer`` (0, 1, ...): its record into the
        visibility record's texture, its depth into one of two depth images
        (the other holds the layer before, which this one reads)."""
        self.visibility_framebuffer()  # the record's texture
        if self.peel_depths is None:
            self.peel_depths = tuple(gpu.types.GPUTexture(self.size, format="DEPTH_COMPONENT32F") for _ in range(2))
        return gpu.types.GPUFrameBuffer(depth_slot=self.peel_depths[layer % 2], color_slots=(self.visible,))

    def hidden_lines_framebuffer(self):
        """A hidden region layer's lines: their colour (RGBA32F, premultiplied)
        and the nearest line's distance as depth, created on first use."""
        if self.hidden_lines is None:
            self.hidden_lines = gpu.types.GPUTexture(self.size, format="RGBA32F")
            self.hidden_line_depth = gpu.types.GPUTexture(self.size, format="DEPTH_COMPONENT32F")
        return gpu.types.GPUFrameBuffer(depth_slot=self.hidden_line_depth, color_slots=(self.hidden_lines,))

    def kept_image(self, name: str) -> KeptImage:
        """The kept image ``name`` (made on first use)."""
        kept = self.kept.get(name)
        if kept is None:
            kept = self.kept[name] = KeptImage(self.size)
        return kept

    def clear_view_depth(self) -> None:
        """The view-depth target to BACKGROUND_DEPTH: where no surface is
        drawn it then already holds what the Depth pass wants there, and
        :meth:`read` needs no depth-buffer read to tell background apart.
        (Through a framebuffer of its own, bound and restored here: a
        texture clear may rebind the one in use.)"""
        framebuffer = gpu.types.GPUFrameBuffer(color_slots=(self.view_depth,))
        with framebuffer.bind():
            framebuffer.clear(color=(BACKGROUND_DEPTH, 0.0, 0.0, 0.0))

    def read(self, *, keep: bool = False, depth: bool = True):
        """(rgba premultiplied (H, W, 4), view depth (H, W) with
        BACKGROUND_DEPTH where nothing was drawn; see clear_view_depth).
        ``depth`` False: the view depth is not read back (None), for a
        frame without a Depth pass.

        ``keep``: read into two buffers these targets keep instead of new
        arrays, and return views of them. A new frame-sized array is fresh
        memory the kernel faults in page by page (~50 ms of a 4K frame on a
        2-core machine); kept buffers are faulted in once. The views are
        overwritten by the next ``read(keep=True)``, so the caller hands them
        on first (the render engine copies them into Blender's result)."""
        color_buffer = depth_buffer = None  # None: read_texture makes new arrays
        if keep:
            width, height = self.size
            if self.kept_readback is None:
                self.kept_readback = [gpu.types.Buffer("FLOAT", width * height * 4), None]
            if depth and self.kept_readback[1] is None:
                self.kept_readback[1] = gpu.types.Buffer("FLOAT", width * height)
            color_buffer, depth_buffer = self.kept_readback
        rgba = read_texture(self.color, 4, color_buffer)
        return rgba, read_texture(self.view_depth, 1, depth_buffer)[..., 0] if depth else None


class KeptImage:
    """An image the viewport overlay keeps between redraws: colour (RGBA32F,
    premultiplied: compositing it blends exactly what drawing straight into
    the viewport's buffer blends) over a depth image, both made on first use, with what it was drawn for (``key``),
    the pixels it covers (``box``: x, y, width, height; None: none) and
    what drawing it counted (``counts``)."""

    def __init__(self, size):
        self.size = size
        self.colour = self.depth = None
        self.key = self.box = self.counts = None

    def framebuffer(self, depth=None):
        """Its colour over its own depth, or over the depth image ``depth``
        (another kept image's; its own is then not made)."""
        if self.colour is None:
            self.colour = gpu.types.GPUTexture(self.size, format="RGBA32F")
        if depth is None and self.depth is None:
            self.depth = gpu.types.GPUTexture(self.size, format="DEPTH_COMPONENT32F")
        return gpu.types.GPUFrameBuffer(depth_slot=self.depth if depth is None else depth, color_slots=(self.colour,))


_targets: Targets | None = None


def targets_for(width: int, height: int) -> Targets:
    global _targets
    if _targets is None or _targets.size != (width, height):
        _targets = None  # free the old textures before allocating new ones
        _targets = Targets(width, height)
    return _targets


# The viewport overlay's own targets (its region lines), apart from the
# render's: what the overlay keeps between redraws (passes.draw_over_viewport)
# must survive an F12 render of the same size. Keyed by size, so a second
# viewport of another size does not evict the first.
_overlay_targets: dict[tuple[int, int], Targets] = {}
OVERLAY_TARGET_SIZES = 4  # viewports kept at once


def overlay_targets_for(width: int, height: int) -> Targets:
    targets = _overlay_targets.pop((width, height), None)
    if targets is None:
        while len(_overlay_targets) >= OVERLAY_TARGET_SIZES:
            _overlay_targets.pop(next(iter(_overlay_targets)))  # the least recently used
        targets = Targets(width, height)
    _overlay_targets[(width, height)] = targets  # most recently used last
    return targets


def release_kept_images(width: int, height: int) -> None:
    """Free the images the overlay of this size keeps of a frame drawn
    directly (a frame that defers its surface has no use for them)."""
    targets = _overlay_targets.get((width, height))
    if targets is not None and targets.kept:
        targets.kept.clear()
        targets.drawn_keys.clear()


def release() -> None:
    global _targets
    _targets = None
    _overlay_targets.clear()
