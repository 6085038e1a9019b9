"""Published wireframe methods kept for comparison: a developer/benchmark
switch, never user-facing.

The add-on always draws with the "exact" method (shaders/solidwire_*.glsl).
scripts/bench/ and tests/test_stress.py compare it with faithful variants of
the methods in the seed documents, all fed the same inputs (position and
triangle tables, per-corner edge flags, vertex pulling) and the same docs/image_model.md §4
intensity profile, so the comparison is about the distance computation:

- ``nvidia2007``: NVIDIA "Solid Wireframe" whitepaper (2007): window-space
  heights with no-perspective interpolation, and the tricky-case table for
  triangles with corners behind the viewpoint (shaders/methods/nvidia2007_*).
- ``kakadu_clip``: the same plus the Liang-Barsky clipping fix of the Kakadu
  "Optimized Wireframe Rendering, Part III" article.
- ``barycentric``: perspective barycentrics scaled by their screen-space
  derivatives (the barycentric wireframe blog post).
- ``offset_lines``: the classic two passes: filled triangles with depth, then
  1 px line primitives moved towards the camera in depth; ``offset_lines_2x``
  and ``offset_lines_4x`` render 2x / 4x bigger (lines 2 / 4 px, so still
  1 px after filtering) and box-filter down.
- ``fill_only``: the same triangles with a trivial shader (time lower bound).

None of this ships in the extension. Each method is a *program* (a shader
per variant plus the batch it draws) handed to the add-on's own pass,
``solidwire_addon.core.draw.draw(..., program=...)``, so every method is
drawn by the same code apart from its shaders. Select one with
:func:`draw_method` (any method, both offset passes) or :func:`render` (any
method, supersampling included).
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass, replace
from pathlib import Path

import gpu
import numpy as np

from solidwire_addon.core import draw as draw_mod
from solidwire_addon.core import passes, shaders
from solidwire_addon.core.targets import Targets, read_texture
from solidwire_addon.core.view import View

METHOD_SHADER_DIR = Path(__file__).resolve().parent / "shaders"

# Method variants with their own shaders (the vertex-pulling triangle
# variants; "offset_lines" is the line pass of the two-pass method).
METHODS = ("nvidia2007", "kakadu_clip", "barycentric", "fill_only", "offset_lines")

SUPERSAMPLED = {"offset_lines_2x": 2, "offset_lines_4x": 4}
ALL_METHODS = (
    "exact",
    "exact_direct",
    "nvidia2007",
    "kakadu_clip",
    "barycentric",
    "offset_lines",
    "offset_lines_2x",
    "offset_lines_4x",
    "fill_only",
)

# NDC depth offset of the line pass towards the camera (the classic polygon-
# offset trick, done in the vertex stage as z - b w because Blender's gpu
# module exposes no glPolygonOffset). 2^-13 of the [-1, 1] NDC range: large
# enough that lines beat the rasterised depth of their own triangles at
# grazing angles in these scenes, which is also what lets them show through
# nearby surfaces (the offset methods' known fault).
LINE_DEPTH_OFFSET = 2.0**-13

_line_batches: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def base_method(method: str) -> tuple[str, int]:
    """(shader method, supersampling factor) of a benchmark method name."""
    if method in SUPERSAMPLED:
        return "offset_lines", SUPERSAMPLED[method]
    if method not in ("exact", "exact_direct") and method not in METHODS:
        raise ValueError(f"unknown SolidWire method {method!r}; one of {ALL_METHODS}")
    return method, 1


def _line_batch(mesh):
    """LINES batch over every distinct triangle edge of ``mesh`` (each vertex
    carries its vertex id; the shader pulls the position). Built once per GPU
    mesh from its triangle table, so the cache needs no change for a
    benchmark-only method."""
    ids = read_texture(mesh.triangles, 4).reshape(-1, 4)[: mesh.triangle_count, :3].astype(np.int64)
    edges = np.concatenate([ids[:, [0, 1]], ids[:, [1, 2]], ids[:, [2, 0]]])
    edges.sort(axis=1)
    edges = np.unique(edges, axis=0)
    fmt = gpu.types.GPUVertFormat()
    fmt.attr_add(id="line_vertex", comp_type="I32", len=1, fetch_mode="INT")
    vbo = gpu.types.GPUVertBuf(fmt, edges.size)
    vbo.attr_fill("line_vertex", edges.reshape(-1).astype(np.int32))
    return gpu.types.GPUBatch(type="LINES", buf=vbo)


_method_shaders: dict = {}


@dataclass(frozen=True)
class MethodProgram:
    """A published method as a program for core.draw.draw: its shaders and
    the batch it draws (triangles, or lines for offset_lines)."""

    method: str
    supports_ngons = False  # the published methods draw triangles only
    supports_instancing = False

    def shader(self, variant):
        key = (self.method, variant)
        shader = _method_shaders.get(key)
        if shader is None:
            shader = _method_shaders[key] = gpu.shader.create_from_info(_method_create_info(self.method, variant))
        return shader

    def batch(self, mesh):
        if self.method != "offset_lines":
            return mesh.batch
        batch = _line_batches.get(mesh)
        if batch is None:
            batch = _line_batches[mesh] = _line_batch(mesh)
        return batch


def _method_create_info(method: str, variant):
    """Create-info of a method variant (scripts/bench/shaders/<file>_{vert,frag}.glsl).

    Same inputs as the exact path (position and triangle tables, per-corner
    edge flags), same parameter block and outputs; only the varyings and the
    distance computation differ."""
    files = {"kakadu_clip": "nvidia2007"}.get(method, method)  # kakadu_clip = nvidia2007 + KAKADU_CLIP
    iface = gpu.types.GPUStageInterfaceInfo(f"solidwire_{method}_iface")
    if files == "nvidia2007":
        # Whitepaper: heights interpolated without perspective correction;
        # the tricky case's (A, Adir), (B, Bdir) are constant per triangle.
        iface.no_perspective("VEC3", "edge_heights")
        iface.flat("VEC4", "line_a")
        iface.flat("VEC4", "line_b")
        iface.flat("INT", "case_id")
        iface.flat("INT", "line_mask")
    elif files == "barycentric":
        iface.smooth("VEC3", "barycentric")
        iface.flat("INT", "line_mask")
    iface.smooth("FLOAT", "view_depth")

    info = shaders.pulling_info()
    info.sampler(1, "FLOAT_2D", "triangle_vertices")
    if method == "offset_lines":
        info.vertex_in(0, "INT", "line_vertex")
        info.define("LINE_DEPTH_OFFSET", repr(float(variant.depth_bias)))
    else:
        info.vertex_in(0, "INT", "edge_flags")
    info.vertex_out(iface)
    shaders.output_and_feature_defines(info, variant)
    if method == "kakadu_clip":
        info.define("KAKADU_CLIP", "1")

    def own(name):
        return shaders.read_source(name, METHOD_SHADER_DIR)

    common = shaders.read_source("common.glsl")
    info.vertex_source(common + own("pull_vert.glsl") + own(f"{files}_vert.glsl"))
    info.fragment_source(
        common + shaders.read_source("line_style.glsl") + own("output_frag.glsl") + own(f"{files}_frag.glsl")
    )
    return info


def downsample_shader(factor: int):
    """Box filter from a ``factor`` times bigger colour/view-depth pair (the
    supersampled offset_lines variants). Compiled once per factor."""
    key = ("downsample", int(factor))
    shader = _method_shaders.get(key)
    if shader is None:
        info = gpu.types.GPUShaderCreateInfo()
        info.sampler(0, "FLOAT_2D", "source_color")
        info.sampler(1, "FLOAT_2D", "source_depth")
        info.vertex_in(0, "VEC2", "position")
        info.fragment_out(0, "VEC4", "frag_color")
        info.fragment_out(1, "FLOAT", "frag_view_depth")
        info.define("FACTOR", str(int(factor)))
        info.vertex_source(shaders.read_source("downsample_vert.glsl", METHOD_SHADER_DIR))
        info.fragment_source(shaders.read_source("downsample_frag.glsl", METHOD_SHADER_DIR))
        shader = _method_shaders[key] = gpu.shader.create_from_info(info)
    return shader


def _draw(items, view, settings, method: str, target, cull: bool):
    program = draw_mod.EXACT if method in ("exact", "exact_direct") else MethodProgram(method)
    return draw_mod.draw(items, view, settings, target=target, cull=cull, program=program)


def draw_method(
    items, view, settings, method: str, *, write_view_depth: bool = False, cull: bool = True, line_width: float = 1.0
):
    """Draw ``items`` with ``method`` into the bound framebuffer (no
    supersampling here: that is a render-target matter, see Renderer)."""
    base, _factor = base_method(method)
    target = draw_mod.DrawTarget(view_depth=write_view_depth)
    if base != "offset_lines":
        return _draw(items, view, settings, base, target, cull)
    # Pass 1: the filled triangles write depth (and the fill colour, or a
    # transparent film); pass 2: lines, depth-tested against pass 1.
    stats = _draw(items, view, settings, "fill_only", target, cull)
    gpu.state.line_width_set(line_width)
    try:
        _draw(items, view, settings, "offset_lines", replace(target, depth_bias=LINE_DEPTH_OFFSET), cull)
    finally:
        gpu.state.line_width_set(1.0)
    return stats


_fullscreen = None


def _fullscreen_batch():
    global _fullscreen
    if _fullscreen is None:
        fmt = gpu.types.GPUVertFormat()
        fmt.attr_add(id="position", comp_type="F32", len=2, fetch_mode="FLOAT")
        vbo = gpu.types.GPUVertBuf(fmt, 3)
        vbo.attr_fill("position", [(0.0, 0.0)] * 3)
        _fullscreen = gpu.types.GPUBatch(type="TRIS", buf=vbo)
    return _fullscreen


class Renderer:
    """Offscreen targets for one method at one size, reusable across frames
    (the benchmark draws many frames; supersampled methods keep a big target
    and filter down on the GPU, so the timed frame ends on the GPU too)."""

    def __init__(self, method: str, width: int, height: int):
        self.method = method
        self.factor = base_method(method)[1]
        self.size = (width, height)
        self.final = Targets(width, height)
        self.big = Targets(width * self.factor, height * self.factor) if self.factor > 1 else None

    def draw(self, items, view, settings, *, cull: bool = True):
        width, height = self.size
        target = self.big or self.final
        tw, th = target.size
        draw_view = View(view.view_matrix, view.projection, (0, 0, tw, th))
        if self.method == "exact":
            # The add-on's own surface pass: deferred (passes.draw_surface).
            return passes.draw_surface(target, items, draw_view, settings, cull=cull)
        framebuffer = target.framebuffer()
        with framebuffer.bind():
            framebuffer.clear(color=(0.0, 0.0, 0.0, 0.0), depth=1.0)
            target.clear_view_depth()
            gpu.state.viewport_set(0, 0, tw, th)
            stats = draw_method(
                items, draw_view, settings, self.method, write_view_depth=True, cull=cull, line_width=float(self.factor)
            )
            gpu.state.depth_test_set("NONE")
            gpu.state.depth_mask_set(False)
        if self.big is not None:
            shader = downsample_shader(self.factor)
            framebuffer = self.final.framebuffer()
            with framebuffer.bind():
                framebuffer.clear(color=(0.0, 0.0, 0.0, 0.0), depth=1.0)
                gpu.state.viewport_set(0, 0, width, height)
                shader.bind()
                shader.uniform_sampler("source_color", self.big.color)
                shader.uniform_sampler("source_depth", self.big.view_depth)
                _fullscreen_batch().draw(shader)
        return stats

    def sync(self) -> None:
        """Wait for the GPU: read back one pixel of the final image (glFinish
        is not exposed by Blender's gpu module)."""
        framebuffer = self.final.framebuffer()
        with framebuffer.bind():
            framebuffer.read_color(0, 0, 1, 1, 4, 0, "FLOAT")

    def read(self):
        """(rgba, view_depth) of the last frame, as core.passes.render returns them."""
        if self.big is None:
            return self.final.read()
        rgba = read_texture(self.final.color, 4)
        # The downsample pass wrote the filtered view depth (background
        # included) itself: no coverage test against a depth buffer here.
        depth = read_texture(self.final.view_depth, 1)[..., 0]
        return rgba, depth


_renderers: dict = {}


def renderer_for(method: str, width: int, height: int) -> Renderer:
    key = (method, width, height)
    renderer = _renderers.get(key)
    if renderer is None:
        _renderers.clear()  # one size at a time: free the old textures
        renderer = _renderers[key] = Renderer(method, width, height)
    return renderer


def render(items, view, settings, method: str, *, cull: bool = True):
    """core.passes.render for any method: (rgba, view_depth, stats)."""
    renderer = renderer_for(method, view.width, view.height)
    stats = renderer.draw(items, view, settings, cull=cull)
    rgba, depth = renderer.read()
    return rgba, depth, stats


def release() -> None:
    _renderers.clear()
    _line_batches.clear()
    _method_shaders.clear()
    global _fullscreen
    _fullscreen = None
