/* Region lines, fragment stage (docs/image_model.md §2.6): where the
 * visible triangle (the deferred surface's visibility record) lies in one
 * of this edge's regions, the line's intensity P(d) m(t) g(l) at the exact
 * window distance, kept per pixel as the strongest of all lines: written as
 * colour and as depth (1 - intensity, LESS test), since Blender's gpu
 * module has no MAX blend. The resolve pass then reads it in place of
 * walking the region's edges. */

/* A tie between styles goes to the lower style number (image model §3.6):
 * a nudge far below one 16-bit step of intensity. */
#define STYLE_NUDGE 1.0e-6

void main()
{
  vec4 visible = texelFetch(visibility, ivec2(gl_FragCoord.xy), 0);
  if (visible.z != float(draw_number)) {
    discard; /* nothing, or another draw's triangle */
  }
#ifdef SW_INSTANCED
  if (visible.y != line_instance) {
    discard;
  }
#endif
  float region = fetch_texel(triangle_regions, int(visible.x) - 1).x;
  if (region < 0.0 || (region != line_regions.x && region != line_regions.y)) {
    discard; /* the visible face is not bounded by this line */
  }
  vec2 p = gl_FragCoord.xy - viewport_centre();
  float across = dot(line_equation, vec3(p, 1.0));
  float along = dot(vec2(-line_equation.y, line_equation.x), p);
  float beyond = max(max(line_span.x - along, along - line_span.y), 0.0);
  float d = sqrt(across * across + beyond * beyond);
  /* Width at the visible point: its view depth is in the record, its clip
   * w follows from the projection (clip_w_of_depth). */
  float view_depth = visible.w;
  float half_thickness = half_thickness_at(view_depth, 1.0 / (clip_w_of_depth.x * view_depth + clip_w_of_depth.y));
  float intensity = line_profile(d, style_half_thickness(line_style, half_thickness));
#if STYLE_COUNT > 1
  float duty = style_duty(line_style);
  if (duty < 1.0) {
    intensity *= pattern_mask(abs(along - line_span.x), params.pattern_period, duty);
  }
#endif
#ifdef USE_DENSITY_FADE
  intensity *= density_fade(line_chain);
#endif
  if (intensity <= 0.0) {
    discard;
  }
  frag_line = vec2(intensity, float(line_style));
  gl_FragDepth = clamp(1.0 - intensity + STYLE_NUDGE * float(line_style), 0.0, 1.0);
}
