/* Region lines, fragment stage (docs/image_model.md §2.6): where the
 * visible triangle (the deferred surface's visibility record) lies in one
 * of this run's regions, the strongest of the run's lines P(d) m(t) g(l) at
 * the exact window distance of each segment, kept per pixel as the strongest
 * of all lines: written as depth alone (line_code, edge_styles.glsl: the
 * intensity and style packed so that a LESS test keeps the strongest, since
 * Blender's gpu module has no MAX blend). The resolve pass then reads it in
 * place of walking the region's edges. The run's segments share
 * style, regions and chain; for a solid style the profile falls with d, so
 * the strongest of them is the profile at the nearest one (the same bits
 * as one quad per segment, each kept by the depth test).
 *
 * Two other uses keep the *nearest* line instead, its distance as depth:
 * LINE_DISTANCE (the Edge Distance pass) writes nothing else, HIDDEN_PASS
 * (a hidden layer of §5.4, recorded by depth peeling) writes the layer's
 * premultiplied colour, dashed along that nearest line, which the depth
 * test keeps with it. */
/* The squared distance from the pixel p to one segment of the run ((line,
 * span start), span end; unused slots are NO_SEGMENT, far away) and its
 * position along the line, from the segment's own lower-id end. */
float segment_distance_sq(vec4 line, float span_end, vec2 p, out float along_from_start)
{
  float across = dot(line.xyz, vec3(p, 1.0));
  float along = dot(vec2(-line.y, line.x), p);
  float beyond = max(max(line.w - along, along - span_end), 0.0);
  along_from_start = abs(along - line.w);
  return across * across + beyond * beyond;
}

/* One segment at p: the nearest squared distance so far and the position
 * along that nearest segment, and, for a patterned style, its P m in
 * `strongest` (each segment's dashes run from its own lower-id end);
 * `patterned` says whether to take it. */
void run_segment(vec4 line, float span_end, vec2 p, float half_thickness, bool patterned, inout float nearest,
                 inout float nearest_along, inout float strongest)
{
  float along_from_start;
  float d2 = segment_distance_sq(line, span_end, p, along_from_start);
  if (d2 < nearest) {
    nearest = d2;
    nearest_along = along_from_start;
  }
#if STYLE_COUNT > 1
  if (patterned) {
    strongest = max(strongest, line_profile(sqrt(d2), half_thickness) *
                                   pattern_mask(along_from_start, params.pattern_period, style_duty(line_style)));
  }
#endif
}

/* Every segment of the run at p (RUN_SEGMENTS slots, run_length used). */
void run_segments(vec2 p, float half_thickness, bool patterned, inout float nearest, inout float nearest_along,
                  inout float strongest)
{
  run_segment(run_line0, run_ends0.x, p, half_thickness, patterned, nearest, nearest_along, strongest);
#if RUN_SEGMENTS > 1
  if (run_length > 1) {
    run_segment(run_line1, run_ends0.y, p, half_thickness, patterned, nearest, nearest_along, strongest);
#  if RUN_SEGMENTS > 2
    if (run_length > 2) {
      run_segment(run_line2, run_ends0.z, p, half_thickness, patterned, nearest, nearest_along, strongest);
      run_segment(run_line3, run_ends0.w, p, half_thickness, patterned, nearest, nearest_along, strongest);
#    if RUN_SEGMENTS > 4
      if (run_length > 4) {
        run_segment(run_line4, run_ends1.x, p, half_thickness, patterned, nearest, nearest_along, strongest);
        run_segment(run_line5, run_ends1.y, p, half_thickness, patterned, nearest, nearest_along, strongest);
        run_segment(run_line6, run_ends1.z, p, half_thickness, patterned, nearest, nearest_along, strongest);
        run_segment(run_line7, run_ends1.w, p, half_thickness, patterned, nearest, nearest_along, strongest);
      }
#    endif
    }
#  endif
  }
#endif
}

void main()
{
  vec2 p = gl_FragCoord.xy - viewport_centre();
#if STYLE_COUNT > 1
  bool patterned = style_duty(line_style) < 1.0;
#else
  const bool patterned = false;
#endif
  /* nearest: the squared distance to the nearest segment; strongest: the
   * largest P m of a patterned style's segments. */
  float nearest = 1.0e30, nearest_along = 0.0, strongest = 0.0;
#if THICKNESS_MODE != 1
  /* The width does not depend on the visible point's clip w: the distances
   * come first, and a pixel beyond the reach the vertex stage gave the quad
   * (the widest the style can be, its 2s fall-off and a hundredth of a
   * pixel: the profile is 0 there) is dropped before it reads the record. */
  run_segments(p, 0.0, false, nearest, nearest_along, strongest);
  float widest = style_half_thickness(line_style, max(params.half_thickness, params.half_thickness_far));
  if (sqrt(nearest) >= widest + 2.0 * params.softness + 0.01) {
    discard;
  }
#endif
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
  if (region == NO_REGION || (region != line_regions.x && region != line_regions.y)) {
    discard; /* the visible face is not bounded by this line */
  }
#ifdef LINE_DISTANCE
  /* The Edge Distance pass: the nearest line's distance, kept per pixel by
   * the LESS test as the strongest line is otherwise. */
#  if THICKNESS_MODE == 1
  run_segments(p, 0.0, false, nearest, nearest_along, strongest);
#  endif
  gl_FragDepth = min(sqrt(nearest) * LINE_DISTANCE_SCALE, BELOW_ONE);
  return;
#endif
  /* Width at the visible point: its view depth is in the record, its clip
   * w follows from the projection (clip_w_of_depth). */
  float view_depth = visible.w;
  float half_thickness = half_thickness_at(view_depth, 1.0 / (clip_w_of_depth.x * view_depth + clip_w_of_depth.y));
#ifdef HIDDEN_PASS
  /* A hidden layer (image model §5.4): the wire's width (no classes), the
   * profile at the nearest line, dashed along it from its lower-id end,
   * dimmed, faded at the layer's depth. Written even where that is 0 (a
   * gap between dashes): the nearest line decides, not the strongest. */
#  if THICKNESS_MODE == 1
  run_segments(p, 0.0, false, nearest, nearest_along, strongest);
#  endif
  float d = sqrt(nearest);
  float layer = line_profile(d, half_thickness) * params.hidden_alpha *
                pattern_mask(nearest_along, params.hidden_period, params.hidden_duty);
#  ifdef USE_FADE
  layer *= depth_fade(view_depth);
#  endif
#  ifdef ITEM_COLORS
  vec3 wire_rgb = item_wire;
#  else
  vec3 wire_rgb = params.wire_color.rgb;
#  endif
  float weight = layer * params.wire_color.a;
  frag_color = vec4(wire_rgb * weight, weight);
#  ifdef DISPLAY_TRANSFORM
  frag_color = display_transform(frag_color);
#  endif
  gl_FragDepth = min(d * LINE_DISTANCE_SCALE, BELOW_ONE);
  return;
#endif
  half_thickness = style_half_thickness(line_style, half_thickness);
#if THICKNESS_MODE == 1
  run_segments(p, half_thickness, patterned, nearest, nearest_along, strongest);
#else
  if (patterned) {
    run_segments(p, half_thickness, true, nearest, nearest_along, strongest);
  }
#endif
  float intensity = patterned ? strongest : line_profile(sqrt(nearest), half_thickness);
#ifdef USE_DENSITY_FADE
  intensity *= density_fade(line_chain);
#endif
  if (intensity <= 0.0) {
    discard;
  }
  /* A tie between styles goes to the lower style number (image model
   * §3.6): line_code orders equal intensities by style. */
  gl_FragDepth = line_code(intensity, line_style);
}
