/* SolidWire fragment stage: exact window-space distance to the face's edges,
 * prefiltered intensity profile, diagonal pattern, depth fade, colour.
 *
 * Variant defines (set by shaders.py; a feature that is off is not compiled):
 *   USE_FILL           opaque fill colour under the wire
 *   USE_FADE           depth fade
 *   DIAGONALS          0 hidden, 1 solid, 2 patterned (dotted/dashed)
 *   WRITE_VIEW_DEPTH   second colour target receives the view depth (render)
 *   SHADING, ITEM_COLORS, MATERIAL_COLORS   fill shading and colour sources
 *                      (fill_shading.glsl)
 *   USE_CLIP_PLANES    viewport clipping region: discard outside its planes
 *   WRITE_AOVS         third and fourth targets: (d_real, I_vis, object
 *                      index, material index) and the camera-facing world normal (render
 *                      passes, docs/image_model.md §6)
 */

/* Squared distance from window point p to the segment stored as (line,
 * span); span.x < span.y always (edge_geometry.glsl orients dir from the
 * segment's first end to its second). Squared, so that only the nearest edge
 * of each kind pays for a square root. */
float edge_distance_sq(vec3 line, vec2 span, vec2 p)
{
  float across = dot(line, vec3(p, 1.0));
  float along = dot(vec2(-line.y, line.x), p);
  float beyond = max(max(span.x - along, along - span.y), 0.0);
  return across * across + beyond * beyond;
}

void keep_nearest(bool candidate, float d, vec3 line, vec2 span, inout float best, inout vec3 best_line, inout vec2 best_span)
{
  if (candidate && d < best) {
    best = d;
    best_line = line;
    best_span = span;
  }
}

void main()
{
#ifdef LINEAR_DEPTH
  /* The render's own float depth buffer holds view depth / clip end: a float
   * keeps the same relative precision (2^-24) at every depth, so which of two
   * surfaces is nearer never depends on the clip range (docs/image_model.md
   * §2). The GL mapping 0.5 * z/w + 0.5 crowds every far depth into the last
   * few float steps below 1. */
  gl_FragDepth = view_depth * params.inv_clip_end;
#endif
#ifdef USE_CLIP_PLANES
  /* Outside the viewport's clipping region: nothing of this face exists
   * here (docs/image_model.md §5.6). */
  if (min(min(min(clip_distance_a.x, clip_distance_a.y), min(clip_distance_a.z, clip_distance_a.w)),
          min(clip_distance_b.x, clip_distance_b.y)) < 0.0)
  {
    discard;
  }
#endif
  /* Window position relative to the viewport centre (edge_geometry.glsl). */
  vec2 p = gl_FragCoord.xy - viewport_centre();
  /* Squared distances to the five candidate edges. */
  float d0, d1, d2, d3, d4;
  if ((triangle_flags & SIMPLE_TRIANGLE) != 0) {
    /* Inside a convex polygon wholly in front of the camera the nearest
     * boundary point of the nearest edge line lies on that edge's segment,
     * so the line distance is exact and the segment ends need no test.
     * (Diagonals too: where an obtuse corner puts the foot of a diagonal's
     * line outside its segment, a real edge is nearer still.) On a GPU this
     * branch is coherent per triangle; llvmpipe runs both sides. */
    vec3 P = vec3(p, 1.0);
    d0 = dot(edge_line0, P);
    d1 = dot(edge_line1, P);
    d2 = dot(edge_line2, P);
    d3 = dot(edge_line3, P);
    d4 = dot(edge_line4, P);
    d0 *= d0;
    d1 *= d1;
    d2 *= d2;
    d3 *= d3;
    d4 *= d4;
  }
  else {
    d0 = edge_distance_sq(edge_line0, edge_span0, p);
    d1 = edge_distance_sq(edge_line1, edge_span1, p);
    d2 = edge_distance_sq(edge_line2, edge_span2, p);
    d3 = edge_distance_sq(edge_line3, edge_span3, p);
    d4 = edge_distance_sq(edge_line4, edge_span4, p);
  }

  bool real0 = (triangle_flags & EDGE0_REAL) != 0;
  bool real1 = (triangle_flags & EDGE1_REAL) != 0;
  bool real2 = (triangle_flags & EDGE2_REAL) != 0;

  /* The nearest real edge, with its line and span (for the hidden-line
   * dashes; unused otherwise and compiled away). Quad edges p2-p3 and p3-p0
   * are NO_EDGE unless the triangle has them. */
  float d_real = NO_EDGE * NO_EDGE;
  vec3 real_line = vec3(0.0, 0.0, NO_EDGE);
  vec2 real_span = vec2(0.0);
  keep_nearest(real0, d0, edge_line0, edge_span0, d_real, real_line, real_span);
  keep_nearest(real1, d1, edge_line1, edge_span1, d_real, real_line, real_span);
  keep_nearest(real2, d2, edge_line2, edge_span2, d_real, real_line, real_span);
  /* A quad's edges to its 4th corner, unless not drawn (edge angle). */
  bool real3 = (triangle_flags & EDGE3_HIDDEN) == 0;
  bool real4 = (triangle_flags & EDGE4_HIDDEN) == 0;
  keep_nearest(real3, d3, edge_line3, edge_span3, d_real, real_line, real_span);
  keep_nearest(real4, d4, edge_line4, edge_span4, d_real, real_line, real_span);
  /* An n-gon's boundary edges may pass near this fragment although they
   * belong to another of its triangles (thin ears, concave outlines): walk
   * the whole outline. Compiled only into the variant for meshes that have
   * n-gons: llvmpipe pays for this loop on every fragment even when it runs
   * zero times. */
#ifdef USE_NGONS
  int corners = triangle_flags >> NGON_SHIFT;
  for (int k = 0; k < corners; k++) {
    vec4 slot_a = fetch_texel(ngon_corners, ngon_corner_start + k);
    float id_a = slot_a.x;
    float id_b = fetch_texel(ngon_corners, ngon_corner_start + (k + 1) % corners).x;
    vec3 line;
    vec2 span;
    edge_setup_from_lower(vertex_clip(id_a), vertex_clip(id_b), id_a, id_b, line, span);
    /* .y: this outline edge is not drawn (edge angle); see the diagonals. */
    keep_nearest(slot_a.y < 0.5, edge_distance_sq(line, span, p), line, span, d_real, real_line, real_span);
  }
#endif
  d_real = sqrt(d_real);
  float half_thickness = half_thickness_at(view_depth, gl_FragCoord.w);
  float intensity = line_profile(d_real, half_thickness);

#ifdef HIDDEN_PASS
  /* Hidden-line style (docs/image_model.md §5.4): this face is behind the visible surface;
   * its real edges are drawn dimmed and dashed along the nearest edge, from
   * that edge's lower-id end. No diagonals, no fill. */
  float along_real = dot(vec2(-real_line.y, real_line.x), p);
  intensity *= params.hidden_alpha * pattern_mask(abs(along_real - real_span.x), params.hidden_period, params.hidden_duty);
#elif DIAGONALS >= 1
  /* The nearest diagonal, with its line and span for the pattern. */
  float d_diag = NO_EDGE * NO_EDGE;
  vec3 diag_line = vec3(0.0, 0.0, NO_EDGE);
  vec2 diag_span = vec2(0.0);
  keep_nearest(!real0, d0, edge_line0, edge_span0, d_diag, diag_line, diag_span);
  keep_nearest(!real1, d1, edge_line1, edge_span1, d_diag, diag_line, diag_span);
  keep_nearest(!real2, d2, edge_line2, edge_span2, d_diag, diag_line, diag_span);
  keep_nearest(!real3, d3, edge_line3, edge_span3, d_diag, diag_line, diag_span);
  keep_nearest(!real4, d4, edge_line4, edge_span4, d_diag, diag_line, diag_span);
  /* Every diagonal of an n-gon, not only this triangle's own. */
#ifdef USE_NGONS
  for (int k = 0; k < corners - 3; k++) {
    int slot = ngon_corner_start + corners + 2 * k;
    float id_a = fetch_texel(ngon_corners, slot).x;
    float id_b = fetch_texel(ngon_corners, slot + 1).x;
    vec3 line;
    vec2 span;
    edge_setup_from_lower(vertex_clip(id_a), vertex_clip(id_b), id_a, id_b, line, span);
    keep_nearest(true, edge_distance_sq(line, span, p), line, span, d_diag, diag_line, diag_span);
  }
  /* Outline edges that are not drawn (edge angle) count as diagonals. */
  for (int k = 0; k < corners; k++) {
    vec4 slot_a = fetch_texel(ngon_corners, ngon_corner_start + k);
    if (slot_a.y > 0.5) {
      float id_a = slot_a.x;
      float id_b = fetch_texel(ngon_corners, ngon_corner_start + (k + 1) % corners).x;
      vec3 line;
      vec2 span;
      edge_setup_from_lower(vertex_clip(id_a), vertex_clip(id_b), id_a, id_b, line, span);
      keep_nearest(true, edge_distance_sq(line, span, p), line, span, d_diag, diag_line, diag_span);
    }
  }
#endif
  d_diag = sqrt(d_diag);
  float diag_intensity = line_profile(d_diag, half_thickness);
#  if DIAGONALS == 2
  /* Position along the nearest diagonal from its lower-id end (stable for a
   * still camera whatever the settings). */
  float along = dot(vec2(-diag_line.y, diag_line.x), p);
  diag_intensity *= pattern_mask(abs(along - diag_span.x), params.pattern_period, params.pattern_duty);
#  endif
  intensity = max(intensity, diag_intensity);
#endif

#ifdef USE_FADE
  intensity *= depth_fade(view_depth);
#endif

  float wire_weight = intensity * params.wire_color.a;
#ifdef ITEM_COLORS
  vec3 wire_rgb = item_wire; /* colour sources (fill_shading.glsl) */
#else
  vec3 wire_rgb = params.wire_color.rgb;
#endif
#if defined(USE_FILL) && !defined(HIDDEN_PASS)
#  ifdef ITEM_COLORS
  vec3 fill_rgb = item_fill;
#  else
  vec3 fill_rgb = params.fill_color.rgb;
#  endif
  frag_color = vec4(mix(shaded_fill(fill_rgb), wire_rgb, wire_weight), 1.0);
#else
  /* Premultiplied: what the render pass expects and what blending needs. */
  frag_color = vec4(wire_rgb * wire_weight, wire_weight);
#endif
#if defined(WRITE_VIEW_DEPTH) && !defined(HIDDEN_PASS)
  frag_view_depth = view_depth;
#endif
#ifdef WRITE_AOVS
  frag_aov = vec4(d_real, intensity, object_params.normal_matrix0.w, material_pass_index);
  frag_normal = vec4(gl_FrontFacing ? face_normal : -face_normal, 0.0);
#endif
#ifdef DISPLAY_TRANSFORM
  frag_color = display_transform(frag_color);
#endif
}
