/* SolidWire line styles of the exact path (docs/image_model.md §3.6-§3.7):
 * style 0 is the wire; styles 1.. are the edge classes in the order of
 * core/schema.py EDGE_CLASS_STYLES, each with its own colour, width
 * (relative to the wire's) and pattern duty from the parameter block; the
 * loader puts the per-style lookups (schema.style_lookup_glsl) before this
 * file. */

/* A class's half width where the wire's is `wire_half_thickness`: its own
 * width scaled as the wire's is scaled from the Thickness in the parameter
 * block (the thickness mode's factor; an object's override is already in
 * both, draw.styled); unscaled where that Thickness is 0. */
float style_half_thickness(int style, float wire_half_thickness)
{
#if STYLE_COUNT > 1
  if (style < 1 || style > CLASS_STYLE_COUNT) {
    return wire_half_thickness;
  }
  float own = style_own_half_thickness(style);
#  if THICKNESS_MODE != 0
  if (params.half_thickness > 0.0) {
    own *= wire_half_thickness / params.half_thickness;
  }
#  endif
  return own;
#else
  return wire_half_thickness;
#endif
}

#ifdef USE_DENSITY_FADE
/* Density fade: full above the length L, nothing below L / 2, linear in
 * between; `length` is the window length of the near-clipped projection of
 * the straight line between the ends of the line's edge chain. */
float density_fade(float length)
{
  float full = params.density_fade_length;
  return (full > 0.0) ? clamp(2.0 * length / full - 1.0, 0.0, 1.0) : 1.0;
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
