"""The one shader loader: GLSL files in ``shaders/`` -> compiled GPU shaders.

The interface (samplers, push constants, the parameter block and the flat
varyings) is declared here once; the GLSL bodies live in files so they can be
read, diffed and linted as GLSL. Variants are compiled on first use and kept
for the life of the process (or until :func:`clear` at unregister), keyed by
the feature flags that change the generated code, so a feature that is off
costs nothing at run time.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

SHADER_DIR = Path(__file__).resolve().parent.parent / "shaders"

# std140 layout of the per-frame parameter block; keep in sync with
# draw.pack_params (which asserts the size).
PARAMS_TYPEDEF = """
struct SolidWireParams {
  vec4 wire_color;
  vec4 fill_color;
  vec4 viewport;
  float half_thickness;
  float softness;
  float fade_start;
  float fade_end;
  float pattern_period;
  float pattern_duty;
  float _pad0;
  float _pad1;
};
"""
PARAMS_FLOATS = 20

EDGE_COUNT = 5  # three triangle edges + two edges to a quad's 4th corner

DIAGONALS_HIDDEN, DIAGONALS_SOLID, DIAGONALS_PATTERN = 0, 1, 2


@dataclass(frozen=True)
class ShaderVariant:
    """Everything that changes the compiled code (and nothing else)."""

    diagonals: int = DIAGONALS_HIDDEN
    use_fill: bool = False
    use_fade: bool = False
    write_view_depth: bool = False
    # Viewport overlay: NDC depth bias towards the camera (0 = none); see
    # DEPTH_BIAS in solidwire_vert.glsl and draw.OVERLAY_DEPTH_BIAS.
    depth_bias: float = 0.0


_cache: dict[ShaderVariant, object] = {}


def read_source(name: str) -> str:
    path = SHADER_DIR / name
    try:
        return path.read_text(encoding="utf-8")
    except OSError as exc:  # a broken install: say which file is missing
        raise RuntimeError(f"SolidWire shader file missing: {path.name} ({exc.strerror})") from None


def _create_info(variant: ShaderVariant):
    import gpu

    iface = gpu.types.GPUStageInterfaceInfo("solidwire_iface")
    for i in range(EDGE_COUNT):
        iface.flat("VEC3", f"edge_line{i}")
        iface.flat("VEC2", f"edge_span{i}")
    iface.flat("INT", "triangle_flags")
    iface.flat("INT", "ngon_corner_start")
    iface.smooth("FLOAT", "view_depth")

    info = gpu.types.GPUShaderCreateInfo()
    info.typedef_source(PARAMS_TYPEDEF)
    info.uniform_buf(0, "SolidWireParams", "params")
    info.push_constant("MAT4", "object_to_clip")
    info.push_constant("VEC4", "object_to_view_z")
    info.sampler(0, "FLOAT_2D", "vertex_positions")
    info.sampler(1, "FLOAT_2D", "triangle_vertices")
    info.sampler(2, "FLOAT_2D", "ngon_corners")
    info.vertex_in(0, "INT", "edge_flags")
    info.vertex_out(iface)
    info.fragment_out(0, "VEC4", "frag_color")
    if variant.write_view_depth:
        info.fragment_out(1, "FLOAT", "frag_view_depth")
        info.define("WRITE_VIEW_DEPTH", "1")
    info.define("DIAGONALS", str(variant.diagonals))
    if variant.use_fill:
        info.define("USE_FILL", "1")
    if variant.use_fade:
        info.define("USE_FADE", "1")
    if variant.depth_bias:
        info.define("DEPTH_BIAS", repr(float(variant.depth_bias)))

    common = read_source("common.glsl") + read_source("edge_geometry.glsl")
    info.vertex_source(common + read_source("solidwire_vert.glsl"))
    info.fragment_source(common + read_source("solidwire_frag.glsl"))
    return info


def get(variant: ShaderVariant):
    """The compiled shader for ``variant`` (compiled once, then cached)."""
    shader = _cache.get(variant)
    if shader is None:
        import gpu

        shader = gpu.shader.create_from_info(_create_info(variant))
        _cache[variant] = shader
    return shader


def clear() -> None:
    _cache.clear()
