/* SolidWire line styles of the exact path (docs/image_model.md §3.6-§3.7):
 * style 0 is the wire; styles 1..5 are the edge classes in the order of
 * core/edge_select.py EDGE_CLASSES (boundary, sharp, crease, seam,
 * Freestyle), each with its own colour, width (relative to the wire's)
 * and pattern duty from the parameter block. */

/* A class's half width where the wire's is `wire_half_thickness`: its own
 * width scaled as the wire's is scaled from the Thickness in the parameter
 * block (the thickness mode's factor; an object's override is already in
 * both, draw.styled); unscaled where that Thickness is 0. */
float style_half_thickness(int style, float wire_half_thickness)
{
#if STYLE_COUNT > 1
  float own = 0.0;
  switch (style) {
    case 1: own = params.boundary_half_thickness; break;
    case 2: own = params.sharp_half_thickness; break;
    case 3: own = params.crease_half_thickness; break;
    case 4: own = params.seam_half_thickness; break;
    case 5: own = params.freestyle_half_thickness; break;
    default: return wire_half_thickness;
  }
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

#if STYLE_COUNT > 1 || defined(STYLE_COLORS)
float style_duty(int style)
{
  switch (style) {
    case 1: return params.boundary_duty;
    case 2: return params.sharp_duty;
    case 3: return params.crease_duty;
    case 4: return params.seam_duty;
    case 5: return params.freestyle_duty;
  }
  return 1.0;
}

vec4 style_color(int style)
{
  switch (style) {
    case 1: return params.boundary_color;
    case 2: return params.sharp_color;
    case 3: return params.crease_color;
    case 4: return params.seam_color;
    case 5: return params.freestyle_color;
  }
  return params.wire_color;
}
#endif

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
