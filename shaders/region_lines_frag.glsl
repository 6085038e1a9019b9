/* Region lines, fragment stage (docs/image_model.md §2.6): where the
 * visible triangle (the deferred surface's visibility record) lies in one
 * of this run's regions, the strongest of the run's lines P(d) m(t) g(l) at
 * the exact window distance of each segment, kept per pixel as the strongest
 * of all lines: written as colour and as depth (1 - intensity, LESS test),
 * since Blender's gpu module has no MAX blend. The resolve pass then reads
 * it in place of walking the region's edges. The run's segments share
 * style, regions and chain; for a solid style the profile falls with d, so
 * the strongest of them is the profile at the nearest one (the same bits
 * as one quad per segment, each kept by the depth test). */
/* A tie between styles goes to the lower style number (image model §3.6):
 * a nudge far below one 16-bit step of intensity. */
#define STYLE_NUDGE 1.0e-6

/* One segment of the run ((line, span start), span end; unused slots are
 * NO_SEGMENT, far away) at the pixel p: the nearest distance so far, and
 * for a patterned style its P m (each segment's dashes run from its own
 * lower-id end). */
void run_segment(vec4 line, float span_end, vec2 p, float half_thickness, inout float nearest, inout float strongest)
{
  float across = dot(line.xyz, vec3(p, 1.0));
  float along = dot(vec2(-line.y, line.x), p);
  float beyond = max(max(line.w - along, along - span_end), 0.0);
  float d2 = across * across + beyond * beyond;
  nearest = min(nearest, d2);
#if STYLE_COUNT > 1
  float duty = style_duty(line_style);
  if (duty < 1.0) {
    strongest = max(strongest, line_profile(sqrt(d2), half_thickness) *
                                   pattern_mask(abs(along - line.w), params.pattern_period, duty));
  }
#endif
}

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
  /* Width at the visible point: its view depth is in the record, its clip
   * w follows from the projection (clip_w_of_depth). */
  float view_depth = visible.w;
  float half_thickness = half_thickness_at(view_depth, 1.0 / (clip_w_of_depth.x * view_depth + clip_w_of_depth.y));
  half_thickness = style_half_thickness(line_style, half_thickness);
  /* nearest: the squared distance to the nearest segment; strongest: the
   * largest P m of a patterned style's segments. */
  float nearest = 1.0e30, strongest = 0.0;
  run_segment(run_line0, run_ends0.x, p, half_thickness, nearest, strongest);
#if RUN_SEGMENTS > 1
  if (run_length > 1) {
    run_segment(run_line1, run_ends0.y, p, half_thickness, nearest, strongest);
#  if RUN_SEGMENTS > 2
    if (run_length > 2) {
      run_segment(run_line2, run_ends0.z, p, half_thickness, nearest, strongest);
      run_segment(run_line3, run_ends0.w, p, half_thickness, nearest, strongest);
#    if RUN_SEGMENTS > 4
      if (run_length > 4) {
        run_segment(run_line4, run_ends1.x, p, half_thickness, nearest, strongest);
        run_segment(run_line5, run_ends1.y, p, half_thickness, nearest, strongest);
        run_segment(run_line6, run_ends1.z, p, half_thickness, nearest, strongest);
        run_segment(run_line7, run_ends1.w, p, half_thickness, nearest, strongest);
      }
#    endif
    }
#  endif
  }
#endif
#if STYLE_COUNT > 1
  float intensity = (style_duty(line_style) < 1.0) ? strongest : line_profile(sqrt(nearest), half_thickness);
#else
  float intensity = line_profile(sqrt(nearest), half_thickness);
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
