/* SolidWire full-width silhouettes, fragment stage: exact distance to the
 * fin's near-clipped edge, outer-side test, occlusion against the main
 * pass's depth at this pixel, and the intensity written both as colour and
 * as depth (1 - I) so that a LESS test keeps the maximum over fins. */

void main()
{
  /* The distance from the edge's window line and span (edge_setup): a
   * near-clipped end can lie 10^5 px off-screen, and measuring from that
   * window point would carry its float32 rounding (about 0.01 px there)
   * into every pixel's distance. */
  vec2 p = gl_FragCoord.xy - viewport_centre();
  float across = dot(fin_line, vec3(p, 1.0));
  /* Only the side away from the face: the face draws its own inner half. */
  if (across * fin_inner_sign < 0.0) {
    discard;
  }
  float along = dot(vec2(-fin_line.y, fin_line.x), p);
  float beyond = max(max(fin_span.x - along, along - fin_span.y), 0.0);
  float d = sqrt(across * across + beyond * beyond);
  float span_length = fin_span.y - fin_span.x;
  float s = (span_length > 0.0) ? clamp((along - fin_span.x) / span_length, 0.0, 1.0) : 0.0;
  /* Window parameter s -> parameter u along the clip-space segment
   * (perspective-correct), then q's depth in NDC and view space. */
  float u = s * fin_a.w / (s * fin_a.w + (1.0 - s) * fin_b.w);
  vec4 q = mix(fin_a, fin_b, u);
  float q_view_depth = mix(fin_view_depth.x, fin_view_depth.y, u);
#ifdef LINEAR_DEPTH
  float q_depth = q_view_depth * params.inv_clip_end; /* the main pass's encoding */
#else
  float q_depth = 0.5 * (q.z / q.w) + 0.5;
#endif
#ifndef OVERLAY_FINS
  float scene = texelFetch(scene_depth, ivec2(gl_FragCoord.xy), 0).r;
  /* A nearer surface hides this part of the outer half; the background
   * (the depth's clear value, 1) hides nothing, also where q lies beyond
   * the far clip (image model §5.5: z_vis is infinite there). */
  if (scene < 1.0 && scene < q_depth) {
    discard;
  }
#endif

  float intensity = line_profile(d, half_thickness_at(q_view_depth, 1.0 / q.w));
#ifdef USE_FADE
  intensity *= depth_fade(q_view_depth);
#endif
  if (intensity <= 0.0) {
    discard;
  }
#ifdef OVERLAY_FINS
  /* Viewport: the fixed-function depth test against the viewport's depth
   * (every object Blender drew) does the occlusion; q is moved towards the
   * camera by the overlay's depth bias (view.OVERLAY_DEPTH_BIAS, NDC, so half
   * of it in window depth) so the surface beyond the outline never wins a
   * tie. Fins blend "over", so two fins meeting at a convex corner compound
   * slightly there; the render keeps the exact maximum. */
  float weight = intensity * params.wire_color.a;
  frag_color = vec4(params.wire_color.rgb * weight, weight);
  gl_FragDepth = q_depth - 0.5 * OVERLAY_FINS +
                 window_depth_shift(q_view_depth, params.blender_depth_allowance, params.depth_rows);
#else
  frag_intensity = intensity;
  gl_FragDepth = 1.0 - intensity;
#endif
#ifdef DISPLAY_TRANSFORM
  frag_color = display_transform(frag_color);
#endif
}
