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

/* A segment of a region block: the nearest line of its style so far, or a
 * diagonal (an n-gon's, DIAGONAL_STYLE). */
void keep_segment(int style, float d, vec3 line, vec2 span, inout float d_style[STYLE_COUNT],
                  inout vec3 line_style[STYLE_COUNT], inout vec2 span_style[STYLE_COUNT], inout float d_diag,
                  inout vec3 diag_line, inout vec2 diag_span)
{
  if (style == DIAGONAL_STYLE) {
#if !defined(HIDDEN_PASS) && DIAGONALS >= 1
    keep_nearest(true, d, line, span, d_diag, diag_line, diag_span);
#endif
    return;
  }
  int k = min(style, STYLE_COUNT - 1);
  keep_nearest(true, d, line, span, d_style[k], line_style[k], span_style[k]);
}

/* A style's intensity is the largest P(d) m(t) g(l) over its lines
 * (docs/image_model.md §3.6-§3.7), not that of its nearest line alone: with
 * the density fade each line has a fade of its own (the nearest line's
 * would jump where two edges of different length meet), and a patterned
 * class style keeps its strongest dash where two of its edges meet, as the
 * region-lines pass's per-pixel maximum does. `chain`: the fade's length l. */
#if defined(USE_DENSITY_FADE) || STYLE_COUNT > 1
#  define USE_LINE_MAXIMUM
#endif
#ifdef USE_LINE_MAXIMUM
float faded_line(int style, float d_sq, vec3 line, vec2 span, vec2 p, float wire_half, float chain)
{
  float value = line_profile(sqrt(d_sq), style_half_thickness(style, wire_half));
  float duty = 1.0;
#  if DIAGONALS == 2
  if (style == DIAGONAL_STYLE) {
    duty = params.pattern_duty;
  }
#  endif
#  if STYLE_COUNT > 1
  if (style != DIAGONAL_STYLE) {
    duty = style_duty(style);
  }
#  endif
  if (duty < 1.0) {
    float along = dot(vec2(-line.y, line.x), p);
    value *= pattern_mask(abs(along - span.x), params.pattern_period, duty);
  }
#  ifdef USE_DENSITY_FADE
  value *= density_fade(chain);
#  endif
  return value;
}

void offer_faded(int style, float d_sq, vec3 line, vec2 span, vec2 p, float wire_half, float chain,
                 inout float faded[STYLE_COUNT], inout float faded_diagonal)
{
  if (style == DIAGONAL_STYLE) {
    faded_diagonal = max(faded_diagonal, faded_line(style, d_sq, line, span, p, wire_half, chain));
  }
  else {
    int k = min(style, STYLE_COUNT - 1);
    faded[k] = max(faded[k], faded_line(k, d_sq, line, span, p, wire_half, chain));
  }
}
/* (Used where `p`, `half_thickness` and the NearLines `found` are in scope.) */
#  define OFFER(style, d_sq, line, span, chain) \
    offer_faded(style, d_sq, line, span, p, half_thickness, chain, found.faded, found.faded_diagonal)
#else
#  define OFFER(style, d_sq, line, span, chain)
#endif

/* The lines near this fragment so far. Per style (image model §3.6: style
 * 0 is the wire, styles 1.. the edge classes) the nearest line with its
 * line and span (for patterns); the nearest diagonal likewise; and with
 * USE_LINE_MAXIMUM each style's strongest faded line (faded_line above,
 * through OFFER). */
struct NearLines {
  float d_style[STYLE_COUNT];
  vec3 line_style[STYLE_COUNT];
  vec2 span_style[STYLE_COUNT];
  float d_diag;
  vec3 diag_line;
  vec2 diag_span;
#ifdef USE_LINE_MAXIMUM
  float faded[STYLE_COUNT];
  float faded_diagonal;
#endif
};

NearLines no_lines()
{
  NearLines found;
  for (int k = 0; k < STYLE_COUNT; k++) {
    found.d_style[k] = NO_EDGE * NO_EDGE;
    found.line_style[k] = vec3(0.0, 0.0, NO_EDGE);
    found.span_style[k] = vec2(0.0);
  }
  found.d_diag = NO_EDGE * NO_EDGE;
  found.diag_line = vec3(0.0, 0.0, NO_EDGE);
  found.diag_span = vec2(0.0);
#ifdef USE_LINE_MAXIMUM
  for (int k = 0; k < STYLE_COUNT; k++) {
    found.faded[k] = 0.0;
  }
  found.faded_diagonal = 0.0;
#endif
  return found;
}

/* The render's own float depth buffer holds view depth / clip end: a float
 * keeps the same relative precision (2^-24) at every depth, so which of two
 * surfaces is nearer never depends on the clip range (docs/image_model.md
 * §2). The GL mapping 0.5 * z/w + 0.5 crowds every far depth into the last
 * few float steps below 1. */
void write_linear_depth()
{
#ifdef LINEAR_DEPTH
  gl_FragDepth = view_depth * params.inv_clip_end;
#endif
}

#if defined(HIDDEN_PASS) && !defined(RESOLVE_PASS)
/* A hidden layer is never the visible face itself (quad_partner.glsl): where
 * the quad's other triangle (solidwire_vert.glsl, partner_outputs), or the
 * nearest of a folded n-gon's other triangles (NGON_SIBLINGS), covers this
 * pixel nearer than this one, this fragment takes its depth there, a hair
 * nearer still, so the GREATER test drops it exactly where that triangle is
 * the surface, and keeps it where something else hides both. */
void leave_out_the_visible_face()
{
#  ifndef LINEAR_DEPTH
  gl_FragDepth = gl_FragCoord.z;
#  endif
  vec3 weights;
  float depth;
  vec4 a = partner0, b = partner2, c = partner3;
  vec3 window_depth_w = partner_window_depth;
  bool covered;
#  ifdef NGON_SIBLINGS
  /* Every other triangle of its face (quad_partner.glsl), but for a plain
   * quad's triangle, whose one other triangle came from the vertex stage. */
  if ((triangle_flags & (HAS_QUAD_CORNER | IN_REGION)) != HAS_QUAD_CORNER) {
    vec4 clip_a, clip_b, clip_c;
    bool level_before;
    covered = nearest_ngon_sibling(hidden_triangle, gl_FragCoord.xy, view_depth, gl_FrontFacing, a, b, c, clip_a,
                                   clip_b, clip_c, weights, depth, level_before);
    if (level_before) {
      discard;
    }
    /* (As partner_outputs sets a quad's other triangle up.) */
    window_depth_w = 0.5 * (vec3(biased(clip_a).z, biased(clip_b).z, biased(clip_c).z) +
                            vec3(clip_a.w, clip_b.w, clip_c.w));
  }
  else
#  endif
  {
    covered = quad_partner_covers(gl_FragCoord.xy, a, b, c, weights, depth) && nearer_or_level(depth, view_depth) &&
              !culled_partner(a, b, c, gl_FrontFacing);
  }
  if (!covered) {
    return;
  }
#  ifdef LINEAR_DEPTH
  float rounding = partner_depth_error(gl_FragCoord.xy, a, b, c, vec3(a.w, b.w, c.w), false);
  gl_FragDepth = (depth * (1.0 - PARTNER_DEPTH_HAIR) - rounding) * params.inv_clip_end;
#  else
  vec3 partner_w = vec3(a.z, b.z, c.z);
  float rounding = partner_depth_error(gl_FragCoord.xy, a, b, c, window_depth_w / partner_w, true);
  gl_FragDepth = min(dot(weights, window_depth_w) / dot(weights, partner_w) - PARTNER_DEPTH_HAIR - rounding,
                     gl_FragCoord.z);
#  endif
}
#endif

/* Squared distances from window point p to the five candidate edges. */
void own_edge_distances(vec2 p, out float d0, out float d1, out float d2, out float d3, out float d4)
{
#ifdef USE_DENSITY_FADE
  /* The argument below needs every line at full strength: with lines of
   * different fade a diagonal's line distance could show where its
   * segment is farther. */
  const bool use_line_distances = false;
#else
  bool use_line_distances = (triangle_flags & SIMPLE_TRIANGLE) != 0;
#endif
  if (use_line_distances) {
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
}

/* The triangle's own edges: which are lines (drawn polygon edges) and
 * which diagonals (added by triangulation). A triangle that walks its
 * region's segments (`listed`, unless it measures its own edges:
 * OWN_EDGES_MEASURED) takes every line from that block instead; its own
 * edges then only give diagonals. Polygon edges that are not drawn (or
 * drawn from the block) are neither. A quad's edges p2-p3, p3-p0 are
 * NO_EDGE unless it has them. */
NearLines own_edge_lines(vec2 p, float half_thickness, bool listed)
{
#ifdef OWN_EDGES
  listed = listed && (triangle_flags & OWN_EDGES_MEASURED) != OWN_EDGES_MEASURED;
#endif
  float d0, d1, d2, d3, d4;
  own_edge_distances(p, d0, d1, d2, d3, d4);
  NearLines found = no_lines();
  /* (Real and hidden: a polygon edge whose line the block draws.) */
  bool hidden0 = (triangle_flags & EDGE0_HIDDEN) != 0;
  bool hidden1 = (triangle_flags & (EDGE0_HIDDEN << 1)) != 0;
  bool hidden2 = (triangle_flags & (EDGE0_HIDDEN << 2)) != 0;
  bool real0 = (triangle_flags & EDGE0_REAL) != 0 && !hidden0;
  bool real1 = (triangle_flags & EDGE1_REAL) != 0 && !hidden1;
  bool real2 = (triangle_flags & EDGE2_REAL) != 0 && !hidden2;
  bool diag0 = (triangle_flags & EDGE0_REAL) == 0 && !hidden0;
  bool diag1 = (triangle_flags & EDGE1_REAL) == 0 && !hidden1;
  bool diag2 = (triangle_flags & EDGE2_REAL) == 0 && !hidden2;

  keep_nearest(real0 && !listed, d0, edge_line0, edge_span0, found.d_style[0], found.line_style[0], found.span_style[0]);
  keep_nearest(real1 && !listed, d1, edge_line1, edge_span1, found.d_style[0], found.line_style[0], found.span_style[0]);
  keep_nearest(real2 && !listed, d2, edge_line2, edge_span2, found.d_style[0], found.line_style[0], found.span_style[0]);
#ifdef USE_LINE_MAXIMUM
  if (!listed) {
    if (real0) OFFER(0, d0, edge_line0, edge_span0, edge_span0.y - edge_span0.x);
    if (real1) OFFER(0, d1, edge_line1, edge_span1, edge_span1.y - edge_span1.x);
    if (real2) OFFER(0, d2, edge_line2, edge_span2, edge_span2.y - edge_span2.x);
  }
#endif
  bool real3 = (triangle_flags & EDGE3_HIDDEN) == 0;
  bool real4 = (triangle_flags & EDGE4_HIDDEN) == 0;
  keep_nearest(real3, d3, edge_line3, edge_span3, found.d_style[0], found.line_style[0], found.span_style[0]);
  keep_nearest(real4, d4, edge_line4, edge_span4, found.d_style[0], found.line_style[0], found.span_style[0]);
#ifdef USE_LINE_MAXIMUM
  if (real3) OFFER(0, d3, edge_line3, edge_span3, edge_span3.y - edge_span3.x);
  if (real4) OFFER(0, d4, edge_line4, edge_span4, edge_span4.y - edge_span4.x);
#endif

  /* The nearest diagonal, with its line and span for the pattern. */
#if !defined(HIDDEN_PASS) && DIAGONALS >= 1
  keep_nearest(diag0, d0, edge_line0, edge_span0, found.d_diag, found.diag_line, found.diag_span);
  keep_nearest(diag1, d1, edge_line1, edge_span1, found.d_diag, found.diag_line, found.diag_span);
  keep_nearest(diag2, d2, edge_line2, edge_span2, found.d_diag, found.diag_line, found.diag_span);
#  ifdef USE_LINE_MAXIMUM
  if (diag0) OFFER(DIAGONAL_STYLE, d0, edge_line0, edge_span0, edge_span0.y - edge_span0.x);
  if (diag1) OFFER(DIAGONAL_STYLE, d1, edge_line1, edge_span1, edge_span1.y - edge_span1.x);
  if (diag2) OFFER(DIAGONAL_STYLE, d2, edge_line2, edge_span2, edge_span2.y - edge_span2.x);
#  endif
#endif
  return found;
}

/* An n-gon's boundary edges may pass near this fragment although they
 * belong to another of its triangles (thin ears, concave outlines): walk
 * the whole outline; a region's lines likewise come from all of its drawn
 * edges. Compiled only into the variant for meshes that have n-gons or
 * regions: llvmpipe pays for these loops on every fragment even when they
 * run zero times. */
#ifdef USE_NGONS
/* A segment of a region block: the nearest line of its style so far, or a
 * diagonal. */
void keep_block_segment(int style, float d, vec3 line, vec2 span, inout NearLines found)
{
  keep_segment(style, d, line, span, found.d_style, found.line_style, found.span_style, found.d_diag,
               found.diag_line, found.diag_span);
}

/* The segments within reach of this triangle, set up by the vertex stage
 * (solidwire_vert.glsl, select_segments). */
void walk_selected_segments(vec2 p, float half_thickness, inout NearLines found)
{
  for (int k = 0; k < SEGMENT_SLOTS; k++) {
    if (k >= segment_count) {
      break;
    }
    vec4 a, b;
    switch (k) {
      case 0: a = segment_line0; b = segment_rest0; break;
      case 1: a = segment_line1; b = segment_rest1; break;
      case 2: a = segment_line2; b = segment_rest2; break;
      case 3: a = segment_line3; b = segment_rest3; break;
      case 4: a = segment_line4; b = segment_rest4; break;
      default: a = segment_line5; b = segment_rest5; break;
    }
    vec3 line = a.xyz;
    vec2 span = vec2(a.w, b.x);
    float d = edge_distance_sq(line, span, p);
    int style = int(b.y);
    OFFER(style, d, line, span, b.z);
    keep_block_segment(style, d, line, span, found);
  }
}

/* Segment `k` of the triangle's region block (`segment`, its first texel),
 * set up here. */
void walk_block_segment(vec2 p, float half_thickness, int k, vec4 segment, inout NearLines found)
{
  int texel = ngon_corner_start + SEGMENT_TEXELS * k;
  vec3 line;
  vec2 span;
  /* Stored lower id first: patterns run from the lower-id end. */
  edge_setup(vertex_clip(segment.x), vertex_clip(segment.y), line, span);
  float d = edge_distance_sq(line, span, p);
  int style = int(segment.z);
#  ifdef USE_DENSITY_FADE
  OFFER(style, d, line, span, chain_length(texel + 1, span));
#  else
  OFFER(style, d, line, span, 0.0);
#  endif
  keep_block_segment(style, d, line, span, found);
}

/* Every segment of the triangle's region block; with `lines_from_image`
 * only its diagonals (its lines are in the region-lines image). */
void walk_region_block(vec2 p, float half_thickness, int block_size, bool lines_from_image, inout NearLines found)
{
  for (int k = 0; k < block_size; k++) {
    vec4 segment = fetch_texel(ngon_corners, ngon_corner_start + SEGMENT_TEXELS * k);
    if (lines_from_image && int(segment.z) != DIAGONAL_STYLE) {
      break; /* the block's diagonals come first; its lines are in the image */
    }
    walk_block_segment(p, half_thickness, k, segment, found);
  }
}

#  if defined(WALK_TABLE) && !defined(WALK_PICKS_ONLY)
/* The `groups` groups of the block that the walk-table pre-pass found near
 * (walk_near_groups: each one's first segment), in the block's order: its
 * other groups hold no segment within reach of the triangle, so the
 * nearest line within reach, and with it the image, is the whole block's. */
void walk_near_block_groups(vec2 p, float half_thickness, int block_size, int groups, inout NearLines found)
{
  for (int slot = 0; slot < groups; slot++) {
    int first = walk_table_pick(walk_near_groups, slot);
    int end = min(first + WALK_GROUP, block_size);
    for (int k = first; k < end; k++) {
      walk_block_segment(p, half_thickness, k, fetch_texel(ngon_corners, ngon_corner_start + SEGMENT_TEXELS * k), found);
    }
  }
}
#  endif

/* The whole outline of the triangle's n-gon and every one of its
 * diagonals, not only this triangle's own. */
void walk_ngon_outline(vec2 p, float half_thickness, int corners, inout NearLines found)
{
  for (int k = 0; k < corners; k++) {
    vec4 slot_a = fetch_texel(ngon_corners, ngon_corner_start + k);
    if (slot_a.y > 0.5) {
      continue; /* an outline edge that is not drawn */
    }
    float id_a = slot_a.x;
    float id_b = fetch_texel(ngon_corners, ngon_corner_start + (k + 1) % corners).x;
    vec3 line;
    vec2 span;
    edge_setup_from_lower(vertex_clip(id_a), vertex_clip(id_b), id_a, id_b, line, span);
    float d = edge_distance_sq(line, span, p);
    keep_nearest(true, d, line, span, found.d_style[0], found.line_style[0], found.span_style[0]);
    OFFER(0, d, line, span, span.y - span.x);
  }
#  if !defined(HIDDEN_PASS) && DIAGONALS >= 1
  for (int k = 0; k < corners - 3; k++) {
    int slot = ngon_corner_start + corners + 2 * k;
    float id_a = fetch_texel(ngon_corners, slot).x;
    float id_b = fetch_texel(ngon_corners, slot + 1).x;
    vec3 line;
    vec2 span;
    edge_setup_from_lower(vertex_clip(id_a), vertex_clip(id_b), id_a, id_b, line, span);
    float d = edge_distance_sq(line, span, p);
    keep_nearest(true, d, line, span, found.d_diag, found.diag_line, found.diag_span);
    OFFER(DIAGONAL_STYLE, d, line, span, span.y - span.x);
  }
#  endif
}
#endif

/* Lines beyond the triangle's own edges: its region's or its n-gon's. */
void walk_blocks(vec2 p, float half_thickness, bool listed, bool lines_from_image, inout NearLines found)
{
#ifdef WALK_PICKS_ONLY
  /* Every triangle of the draw has its lines in its picks (walk_picks_only). */
  walk_selected_segments(p, half_thickness, found);
#elif defined(USE_NGONS)
  int block_size = triangle_flags >> NGON_SHIFT;
  if (listed && segment_count >= 0) {
    walk_selected_segments(p, half_thickness, found);
  }
#  if defined(WALK_TABLE)
  else if (listed && segment_count < -1) {
    walk_near_block_groups(p, half_thickness, block_size, -2 - segment_count, found);
  }
#  endif
  else if (listed) {
    walk_region_block(p, half_thickness, block_size, lines_from_image, found);
  }
  else {
    walk_ngon_outline(p, half_thickness, block_size, found);
  }
#endif
}

/* The nearest line of any style (the Edge Distance pass and hidden lines),
 * its distance returned, its line and span in `line` and `span`. Only a
 * triangle that walks a block has lines of other styles. */
float nearest_line(NearLines found, int styles, out vec3 line, out vec2 span)
{
  float d_real = found.d_style[0];
  line = found.line_style[0];
  span = found.span_style[0];
  for (int k = 1; k < styles; k++) {
    keep_nearest(true, found.d_style[k], found.line_style[k], found.span_style[k], d_real, line, span);
  }
  return sqrt(d_real);
}

#ifdef HIDDEN_PASS
/* Hidden-line style (docs/image_model.md §5.4): this face is behind the
 * visible surface; its lines are drawn dimmed and dashed along the nearest
 * one, from that edge's lower-id end. No diagonals, no styles, no fill. */
float hidden_intensity(vec2 p, float half_thickness, float d_real, vec3 real_line, vec2 real_span)
{
  float intensity = line_profile(d_real, half_thickness);
  float along_real = dot(vec2(-real_line.y, real_line.x), p);
  intensity *= params.hidden_alpha * pattern_mask(abs(along_real - real_span.x), params.hidden_period, params.hidden_duty);
  return intensity;
}
#else
/* Each style's intensity at its nearest line; the pixel takes the style
 * whose intensity is largest (image model §3.6), `winner`, against the
 * region-lines image and the nearest diagonal too. */
float visible_intensity(vec2 p, float half_thickness, NearLines found, int styles, bool lines_from_image,
                        out int winner)
{
  float intensity = 0.0;
  winner = 0;
  for (int k = 0; k < styles; k++) {
#  ifdef USE_LINE_MAXIMUM
    float value = found.faded[k];
#  else
    float value = line_profile(sqrt(found.d_style[k]), style_half_thickness(k, half_thickness));
#  endif
    if (value > intensity) {
      intensity = value;
      winner = k;
    }
  }
#  ifdef REGION_LINE_IMAGE
  if (lines_from_image) {
    vec2 line = line_of_code(texelFetch(region_line_image, ivec2(gl_FragCoord.xy), 0).r);
    if (line.x > intensity) {
      intensity = line.x;
      winner = int(line.y);
    }
  }
#  endif
#  if DIAGONALS >= 1
  float d_diag = sqrt(found.d_diag);
  float diag_intensity = line_profile(d_diag, half_thickness);
#    if DIAGONALS == 2
  /* Position along the nearest diagonal from its lower-id end (stable for a
   * still camera whatever the settings). */
  float along = dot(vec2(-found.diag_line.y, found.diag_line.x), p);
  diag_intensity *= pattern_mask(abs(along - found.diag_span.x), params.pattern_period, params.pattern_duty);
#    endif
#    ifdef USE_DENSITY_FADE
  diag_intensity = found.faded_diagonal;
#    endif
  if (diag_intensity > intensity) {
    intensity = diag_intensity;
    winner = 0;
  }
#  endif
  return intensity;
}
#endif

/* The fragment's colour: the winning style's colour at `intensity` over
 * the fill, or premultiplied wire alone. */
vec4 fragment_colour(float intensity, int winner)
{
  float wire_weight = intensity * params.wire_color.a;
#ifdef ITEM_COLORS
  vec3 wire_rgb = item_wire; /* colour sources (fill_shading.glsl) */
#else
  vec3 wire_rgb = params.wire_color.rgb;
#endif
#if STYLE_COUNT > 1 || defined(STYLE_COLORS)
  if (winner > 0) {
    vec4 class_color = style_color(winner);
    wire_rgb = class_color.rgb;
    wire_weight = intensity * class_color.a;
  }
#endif
#ifdef WIRE_LAYER
  /* The render under hidden lines: the wire in a layer of its own,
   * premultiplied (ShaderVariant.wire_layer); the colour is the fill
   * alone, and the hidden lines go between the two. */
  frag_wire = vec4(wire_rgb * wire_weight, wire_weight);
  wire_weight = 0.0;
#endif
#if defined(USE_FILL) && !defined(HIDDEN_PASS)
#  ifdef ITEM_COLORS
  vec3 fill_rgb = item_fill;
#  else
  vec3 fill_rgb = params.fill_color.rgb;
#  endif
#  ifdef ATTRIBUTE_COLORS
  fill_rgb = attribute_fill; /* interpolated over the triangle */
#  endif
  return vec4(mix(shaded_fill(fill_rgb), wire_rgb, wire_weight), 1.0);
#else
  /* Premultiplied: what the render pass expects and what blending needs. */
  return vec4(wire_rgb * wire_weight, wire_weight);
#endif
}

/* Every output of the variant: the colour (through the display transform
 * over the viewport), the view depth, the render passes' values. */
void write_outputs(vec4 colour, float d_real, float intensity)
{
  frag_color = colour;
#if defined(WRITE_VIEW_DEPTH) && !defined(HIDDEN_PASS)
  frag_view_depth = view_depth;
#endif
#ifdef WRITE_AOVS
  frag_aov = vec4(d_real, intensity, object_params.normal_matrix0.w, material_pass_index);
  frag_normal = vec4(SW_FRONT_FACING ? face_normal : -face_normal, 0.0);
#endif
#ifdef DISPLAY_TRANSFORM
  frag_color = display_transform(frag_color);
#endif
}

/* The resolve pass (resolve_frag.glsl) calls this for the one pixel it
 * resolves, after setting every input as a plain global. */
#ifdef RESOLVE_PASS
void solidwire_fragment()
#else
void main()
#endif
{
  write_linear_depth();
#if defined(HIDDEN_PASS) && !defined(RESOLVE_PASS)
  leave_out_the_visible_face();
#endif
  if (outside_clip_region()) {
    discard;
  }
  /* Window position relative to the viewport centre (edge_geometry.glsl). */
  vec2 p = gl_FragCoord.xy - viewport_centre();
  float half_thickness = half_thickness_at(view_depth, SW_INV_CLIP_W);
  bool listed = (triangle_flags & IN_REGION) != 0;
#ifdef REGION_LINE_IMAGE
  /* The region-lines pass measured this triangle's lines (image model
   * §2.6): the strongest line at this pixel and its style. */
  bool lines_from_image = (triangle_flags & REGION_LINES) != 0;
#else
  const bool lines_from_image = false;
#endif
#if defined(NO_EDGE_SETUP) || defined(WALK_PICKS_ONLY)
  /* No edge of the triangle's own was set up (every line is in the
   * region-lines image, no diagonal drawn; or in the walk's picks, the
   * triangle a region's with no quad corner, whose own edges are in its
   * block): measuring them would find nothing nearer than NO_EDGE. */
  NearLines found = no_lines();
#else
  NearLines found = own_edge_lines(p, half_thickness, listed);
#endif
  walk_blocks(p, half_thickness, listed, lines_from_image, found);
  vec3 real_line;
  vec2 real_span;
  float d_real = nearest_line(found, listed ? STYLE_COUNT : 1, real_line, real_span);
#ifdef REGION_DISTANCE_IMAGE
  /* The region-lines pass measured every line of the region within reach
   * (image model §2.6); beyond it d is what the triangle's own edges give,
   * at least the reach. Only for a triangle whose lines the pass drew: drawn
   * directly, a triangle of another mesh may cover a pixel whose record
   * (of the meshes with regions alone) shows a region behind it. */
  float coded_distance = lines_from_image ?
                             texelFetch(region_distance_image, ivec2(gl_FragCoord.xy), 0).r :
                             1.0;
  if (coded_distance < 1.0) { /* (1.0: no line within reach) */
    d_real = min(d_real, coded_distance / LINE_DISTANCE_SCALE);
  }
#endif
  int winner = 0;
#ifdef HIDDEN_PASS
  float intensity = hidden_intensity(p, half_thickness, d_real, real_line, real_span);
#else
  float intensity = visible_intensity(p, half_thickness, found, listed ? STYLE_COUNT : 1, lines_from_image, winner);
#endif
#ifdef USE_FADE
  intensity *= depth_fade(view_depth);
#endif
  write_outputs(fragment_colour(intensity, winner), d_real, intensity);
}
