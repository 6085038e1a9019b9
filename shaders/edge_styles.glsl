/* SolidWire line styles of the exact path (docs/image_model.md §3.6-§3.7):
 * style 0 is the wire; styles 1.. are the edge classes in the order of
 * core/schema.py EDGE_CLASS_STYLES, each with its own colour, width
 * (relative to the wire's) and pattern duty from the parameter block; the
 * loader puts the per-style lookups (schema.style_lookup_glsl) before this
 * file. */

/* A class's half width where the wire's is `wire_half_thickness`: its own
 * width scaled as the wire's is scaled from the scene's Thickness (image
 * model §3.6: the thickness mode's factor, and an object's own Thickness,
 * which is in the wire's width but not in class_width_scale); unscaled
 * where the scene's Thickness is 0. */
float style_half_thickness(int style, float wire_half_thickness)
{
#if STYLE_COUNT > 1
  if (style < 1 || style > CLASS_STYLE_COUNT) {
    return wire_half_thickness;
  }
  float own = style_own_half_thickness(style);
  if (params.class_width_scale > 0.0) {
    own *= wire_half_thickness * params.class_width_scale;
  }
  return own;
#else
  return wire_half_thickness;
#endif
}

#ifdef USE_DENSITY_FADE
/* Density fade: full above the length L, nothing below L / 2, linear in
 * between; `length` is the window length of the near-clipped projection of
 * the straight line between the ends of the line's edge chain. Compiled
 * only with L > 0 (draw.density_fade_of: 0 px is the fade switched off). */
float density_fade(float length)
{
  return clamp(2.0 * length / params.density_fade_length - 1.0, 0.0, 1.0);
}

/* That length for a line whose chain ends are in texel `chain_texel` of the
 * segment table (a cage edge cut by subdivision), or its own span (-1). */
float chain_length(int chain_texel, vec2 own_span)
{
#  ifdef USE_NGONS
  if (chain_texel >= 0) {
    vec4 ends = fetch_texel(ngon_corners, chain_texel);
    vec3 line;
    vec2 span;
    edge_setup(vertex_clip(ends.x), vertex_clip(ends.y), line, span);
    return span.y - span.x;
  }
#  endif
  return own_span.y - own_span.x;
}
#endif

/* The region-lines image (docs/image_model.md §2.6) keeps the strongest line
 * per pixel in a depth buffer alone, one value per pixel for its intensity
 * and style: a LESS test then keeps the larger intensity and, of two equal
 * ones, the lower style. The intensity keeps LINE_LEVELS steps (2^-19, far
 * below one step of a 16-bit image); the value is a whole multiple of 2^-22
 * below 1.0, which a 32-bit float depth buffer stores exactly, and the
 * cleared 1.0 means no line. Without a colour target the pass writes a
 * third of the bytes per pixel it wrote with (intensity, style) beside its
 * depth, which a software rasteriser pays at every covered pixel. */
#define LINE_STYLE_SLOTS 8
#define LINE_LEVELS 524288.0      /* 2^19 */
#define LINE_CODE_SCALE 4194304.0 /* LINE_LEVELS * LINE_STYLE_SLOTS */
#if CLASS_STYLE_COUNT >= LINE_STYLE_SLOTS
#  error "more line styles than the region-lines image packs"
#endif

/* The depth that keeps `intensity` (0 to 1) of line style `style`: 1.0 (no
 * line) where it rounds to no step. */
float line_code(float intensity, int style)
{
  float levels = floor(min(intensity, 1.0) * LINE_LEVELS + 0.5);
  if (levels < 1.0) {
    return 1.0;
  }
  return ((LINE_LEVELS - levels) * float(LINE_STYLE_SLOTS) + float(style)) / LINE_CODE_SCALE;
}

/* (intensity, style) of a texel of the region-lines image (0 intensity:
 * no line). Exact: every step is a product by a power of two. */
vec2 line_of_code(float code)
{
  if (code >= 1.0) {
    return vec2(0.0);
  }
  float whole = code * LINE_CODE_SCALE;
  float rank = floor(whole * (1.0 / float(LINE_STYLE_SLOTS)));
  return vec2((LINE_LEVELS - rank) * (1.0 / LINE_LEVELS), whole - rank * float(LINE_STYLE_SLOTS));
}
