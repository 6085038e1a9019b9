/* SolidWire vertex stage: vertex pulling plus per-triangle edge set-up.
 *
 * Why vertex pulling: Blender's Python GPU API has no geometry shader, yet
 * every fragment needs the whole triangle (and, for a quad, its 4th corner).
 * Each corner of the non-indexed triangle list reads its triangle's vertex
 * ids from `triangle_vertices` (one texel per triangle, found by
 * gl_VertexID / 3) and the positions from `vertex_positions`, then sets up the
 * same flat edge data the papers compute in the geometry shader. Memory stays
 * at one texel per triangle and one per vertex instead of four positions per
 * corner.
 *
 * Why 2D homogeneous lines: an edge's window-space line is the cross product
 * of its endpoints' homogeneous window coordinates (x*w, y*w, w). No vertex is
 * ever divided by its w, so a vertex behind the camera (w <= 0) needs no
 * special case: the NVIDIA "tricky case" and the near-plane precision glitch
 * do not exist in this path. Only the extent of the segment along its line
 * needs the near plane: it is clipped in clip space (z + w >= 0), which is
 * where only the part of an edge in front of the near plane has a projection. */

#ifdef USE_NGONS
void store_segment(int slot, vec3 line, vec2 span, float style, float chain)
{
  vec4 a = vec4(line, span.x), b = vec4(span.y, style, chain, 0.0);
  switch (slot) {
    case 0: segment_line0 = a; segment_rest0 = b; break;
    case 1: segment_line1 = a; segment_rest1 = b; break;
    case 2: segment_line2 = a; segment_rest2 = b; break;
    case 3: segment_line3 = a; segment_rest3 = b; break;
    case 4: segment_line4 = a; segment_rest4 = b; break;
    default: segment_line5 = a; segment_rest5 = b; break;
  }
}

float point_segment_distance(vec2 p, vec2 a, vec2 b)
{
  vec2 ab = b - a;
  float len2 = dot(ab, ab);
  float t = (len2 > 0.0) ? clamp(dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
  return length(p - (a + t * ab));
}

/* Signed area test: whether segments ab and cd cross. */
bool segments_cross(vec2 a, vec2 b, vec2 c, vec2 d)
{
  vec2 r = b - a, s = d - c;
  float c1 = r.x * (c.y - a.y) - r.y * (c.x - a.x);
  float c2 = r.x * (d.y - a.y) - r.y * (d.x - a.x);
  float c3 = s.x * (a.y - c.y) - s.y * (a.x - c.x);
  float c4 = s.x * (b.y - c.y) - s.y * (b.x - c.x);
  return c1 * c2 <= 0.0 && c3 * c4 <= 0.0;
}

/* Window distance between segment ab and triangle t0 t1 t2 (0 when they
 * meet): conservative only through rounding, which `reach` covers. */
float segment_triangle_distance(vec2 a, vec2 b, vec2 t0, vec2 t1, vec2 t2)
{
  float e0 = (t1.x - t0.x) * (a.y - t0.y) - (t1.y - t0.y) * (a.x - t0.x);
  float e1 = (t2.x - t1.x) * (a.y - t1.y) - (t2.y - t1.y) * (a.x - t1.x);
  float e2 = (t0.x - t2.x) * (a.y - t2.y) - (t0.y - t2.y) * (a.x - t2.x);
  bool inside = (e0 >= 0.0 && e1 >= 0.0 && e2 >= 0.0) || (e0 <= 0.0 && e1 <= 0.0 && e2 <= 0.0);
  if (inside || segments_cross(a, b, t0, t1) || segments_cross(a, b, t1, t2) || segments_cross(a, b, t2, t0)) {
    return 0.0;
  }
  float d = min(min(point_segment_distance(t0, a, b), point_segment_distance(t1, a, b)),
                point_segment_distance(t2, a, b));
  d = min(d, min(point_segment_distance(a, t0, t1), point_segment_distance(b, t0, t1)));
  d = min(d, min(point_segment_distance(a, t1, t2), point_segment_distance(b, t1, t2)));
  d = min(d, min(point_segment_distance(a, t2, t0), point_segment_distance(b, t2, t0)));
  return d;
}

/* A triangle that walks its region's segments: the vertex stage sets up
 * every segment of the block once per corner and keeps those that pass
 * within reach of the triangle's window box, so that each fragment measures
 * a handful of precomputed lines instead of setting up the whole block
 * (docs/image_model.md §3.4: edges beyond h + 2s cannot change a pixel).
 * t0..t2: the triangle's window corners relative to the viewport centre.
 * Returns how many it kept, or -1 when more than SEGMENT_SLOTS are near
 * (the fragment stage then walks the whole block). The walk-table pre-pass
 * returns -2 - n instead where those lie in n groups of the block, n up
 * to SEGMENT_SLOTS, which it keeps in walk_group_picks (the fragment stage
 * then walks those groups alone). */
int select_segments(vec2 t0, vec2 t1, vec2 t2, float reach)
{
  int block = edge_flags >> NGON_SHIFT;
  int kept = 0;
#  ifdef WALK_TABLE_PASS
  /* The pre-pass first tests each group of the block by its window box
   * (walk_groups_vert.glsl): a group whose box lies beyond reach of the
   * triangle's box holds no segment within reach, and its segments are not
   * set up. The same segments are kept, in the same order. Past
   * SEGMENT_SLOTS segments it only counts the groups that pass. */
  vec2 near_low = min(min(t0, t1), t2) - reach, near_high = max(max(t0, t1), t2) + reach;
  int near_groups = 0;
  bool overflow = false;
  for (int group = 0; group < block; group += WALK_GROUP) {
    vec4 box = fetch_texel(walk_group_boxes, ngon_corner_start + SEGMENT_TEXELS * group);
    if (box.x > near_high.x || box.y > near_high.y || box.z < near_low.x || box.w < near_low.y) {
      continue;
    }
    if (near_groups < SEGMENT_SLOTS) {
      walk_group_picks[near_groups] = group;
    }
    near_groups++;
    if (overflow) {
      continue;
    }
    int group_end = min(group + WALK_GROUP, block);
#  else
  {
    const int group = 0;
    int group_end = block;
#  endif
  for (int k = group; k < group_end; k++) {
    int texel = ngon_corner_start + SEGMENT_TEXELS * k;
    vec4 segment = fetch_texel(ngon_corners, texel);
    vec3 line;
    vec2 span;
    edge_setup(vertex_clip(segment.x), vertex_clip(segment.y), line, span);
    if (dot(line.xy, line.xy) == 0.0) {
      continue; /* NO_EDGE: nothing in front of the near plane */
    }
    vec2 dir = vec2(-line.y, line.x);
    vec2 foot = -line.z * line.xy; /* the line's point nearest the centre */
    if (segment_triangle_distance(foot + span.x * dir, foot + span.y * dir, t0, t1, t2) > reach) {
      continue;
    }
    if (kept == SEGMENT_SLOTS) {
#  ifdef WALK_TABLE_PASS
      overflow = true;
      break;
#  else
      return -1;
#  endif
    }
#  ifdef WALK_TABLE_PASS
    walk_picks[kept] = k; /* the pre-pass keeps which (walk_table_frag.glsl) */
#  else
    float chain = span.y - span.x;
#    ifdef USE_DENSITY_FADE
    chain = chain_length(texel + 1, span);
#    endif
    store_segment(kept, line, span, segment.z, chain);
#  endif
    kept++;
  }
  }
#  ifdef WALK_TABLE_PASS
  if (overflow) {
    return (near_groups <= SEGMENT_SLOTS) ? -2 - near_groups : -1;
  }
#  endif
  return kept;
}

#  ifdef WALK_TABLE
/* The segments the walk-table pre-pass picked for this triangle
 * (walk_table_frag.glsl: its count, then two block indices a channel),
 * set up as select_segments() would have: the same segments, the same
 * code, at one corner per triangle instead of three SIMD lanes. */
int read_walk_table(int triangle)
{
  int row = triangle >> WALK_TABLE_SHIFT;
  vec4 picks = texelFetch(walk_table, ivec2(triangle - (row << WALK_TABLE_SHIFT), row), 0);
  int kept = int(picks.x);
#    ifndef WALK_PICKS_ONLY
  /* Groups to walk (a count below -1): the fragment stage reads them. */
  walk_near_groups = (kept < -1) ? picks.yzw : vec3(0.0);
#    endif
  for (int slot = 0; slot < kept; slot++) {
    int k = walk_table_pick(picks.yzw, slot);
    int texel = ngon_corner_start + SEGMENT_TEXELS * k;
    vec4 segment = fetch_texel(ngon_corners, texel);
    vec3 line;
    vec2 span;
    edge_setup(vertex_clip(segment.x), vertex_clip(segment.y), line, span);
    float chain = span.y - span.x;
#    ifdef USE_DENSITY_FADE
    chain = chain_length(texel + 1, span);
#    endif
    store_segment(slot, line, span, segment.z, chain);
  }
  return kept;
}
#  endif

/* The widest reach of any line at this triangle: the largest half width of
 * the wire and of every style at its corners, plus the 2s falloff and a
 * hundredth of a pixel for rounding. */
float line_reach(float w0, float w1, float w2)
{
  float half_width = max(max(half_thickness_at(0.0, 1.0 / w0), half_thickness_at(0.0, 1.0 / w1)),
                         half_thickness_at(0.0, 1.0 / w2));
#  if THICKNESS_MODE == 2
  half_width = max(params.half_thickness, params.half_thickness_far);
#  endif
  for (int k = 1; k < STYLE_COUNT; k++) {
    half_width = max(half_width, style_half_thickness(k, half_width));
  }
  return half_width + 2.0 * params.softness + 0.01;
}
#endif

#ifdef ATTRIBUTE_COLORS
/* The mesh's active colour attribute at a triangle corner (the ATTRIBUTE
 * fill source, image model §5.8): a row per vertex or per triangle corner
 * (attribute_domain; extract.attribute_color_table). */
vec4 attribute_row(int triangle, int corner, float vertex_id)
{
  return fetch_texel(attribute_colors, (attribute_domain == 0) ? int(vertex_id) : 3 * triangle + corner);
}
#endif

/* Corner `corner` of `triangle` (vertex `vertex_id`): the corner table's
 * row for it (extract.corner_table: a row per vertex, triangle or triangle
 * corner, as normal_domain says), and from it the corner's normal in view
 * space with its face's material in w. */
#ifdef USE_CORNERS
vec4 corner_row(int triangle, int corner, float vertex_id)
{
  int row = (normal_domain == 0) ? int(vertex_id) : ((normal_domain == 1) ? triangle : 3 * triangle + corner);
  return fetch_texel(corner_table, row);
}

vec4 corner_shading(int triangle, int corner, float vertex_id)
{
  vec4 corner_data = corner_row(triangle, corner, vertex_id);
  return vec4(mat3(normal_to_view) * corner_data.xyz, corner_data.w);
}
#endif

/* Whether the fragment stage may take line distances for segment
 * distances (SIMPLE_TRIANGLE): a triangle wholly in front of the camera,
 * convex (a quad) or a whole face, whose edges are all drawn. An edge that
 * is not drawn makes a line distance no longer a segment distance for
 * every sample; a triangle walking its region's block takes its lines from
 * there. */
bool simple_triangle(bool in_front, bool is_quad, bool is_ngon, bool convex)
{
  if (!in_front) {
    return false;
  }
  bool simple = is_quad ? convex : !is_ngon;
  int drawn_mask = is_quad ? (EDGE0_REAL | EDGE1_REAL) : (EDGE0_REAL | EDGE1_REAL | EDGE2_REAL);
  return simple && (edge_flags & drawn_mask) == drawn_mask && (edge_flags & (EDGE3_HIDDEN | EDGE4_HIDDEN)) == 0
         && (edge_flags & IN_REGION) == 0;
}

#ifdef SETUP_TABLE
/* A big mesh: the set-up pre-pass (setup_comp.glsl) has set up this
 * triangle's edges once; each corner only reads them and adds what depends
 * on the edge flags. Returns whether the triangle is simple. */
bool read_setup_table(int triangle, vec4 ids, bool is_quad, bool is_ngon)
{
  int row = triangle / SETUP_ROW_TRIANGLES; /* a constant divisor: see setup_texel() in setup_comp.glsl */
  ivec2 at = ivec2((triangle - row * SETUP_ROW_TRIANGLES) * SETUP_TEXELS, row);
  vec4 s0 = texelFetch(setup_table, at, 0);
  vec4 s1 = texelFetch(setup_table, at + ivec2(1, 0), 0);
  vec4 s2 = texelFetch(setup_table, at + ivec2(2, 0), 0);
  vec4 s3 = texelFetch(setup_table, at + ivec2(3, 0), 0);
  edge_line0 = s0.xyz;
  edge_span0 = vec2(s0.w, s1.x);
  edge_line1 = s1.yzw;
  edge_span1 = s2.xy;
  edge_line2 = vec3(s2.zw, s3.x);
  edge_span2 = s3.yz;
  int geometry = int(s3.w);
  bool in_front = (geometry & 1) != 0;
  if (is_quad) {
    vec4 s4 = texelFetch(setup_table, at + ivec2(4, 0), 0);
    vec4 s5 = texelFetch(setup_table, at + ivec2(5, 0), 0);
    vec4 s6 = texelFetch(setup_table, at + ivec2(6, 0), 0);
    edge_line3 = s4.xyz;
    edge_span3 = vec2(s4.w, s5.x);
    edge_line4 = s5.yzw;
    edge_span4 = s6.xy;
  }
#  ifdef RESOLVE_PASS
  sw_triangle_ids = ids;
  sw_corner_clip0 = vertex_clip(ids.x);
  sw_corner_clip1 = vertex_clip(ids.y);
  sw_corner_clip2 = vertex_clip(ids.z);
#  endif
  /* The same test as the per-corner set-up. */
  return simple_triangle(in_front, is_quad, is_ngon, (geometry & 2) != 0);
}
#else
/* The triangle's edges set up at this corner from its clip-space corners
 * c0..c2 (and c3, a quad's 4th); t0..t2 are its window corners relative to
 * the viewport centre (region segments). Returns whether the triangle is
 * simple; `in_front` says whether it lies wholly in front of the camera. */
bool set_up_edges(vec4 ids, bool is_quad, bool is_ngon, out vec4 c0, out vec4 c1, out vec4 c2, out vec2 t0,
                  out vec2 t1, out vec2 t2, out bool in_front)
{
  c0 = vertex_clip(ids.x);
  c1 = vertex_clip(ids.y);
  c2 = vertex_clip(ids.z);

  /* For a quad the 4th id is its 4th corner; for an n-gon triangle (or one
   * that walks its region's segments) it is where its block starts in
   * `ngon_corners`. */
  vec4 c3 = is_quad ? vertex_clip(ids.w) : c2;
#  ifdef RESOLVE_PASS
  /* The resolve pass's barycentrics and corner normals. */
  sw_triangle_ids = ids;
  sw_corner_clip0 = c0;
  sw_corner_clip1 = c1;
  sw_corner_clip2 = c2;
#  endif
  vec2 w0, w1, w2;
  bool convex;
#  if defined(NO_EDGE_SETUP) || defined(WALK_PICKS_ONLY)
  /* Every triangle of this draw takes its lines from the region-lines pass
   * and draws no diagonal (ShaderVariant.no_edge_setup), or from the picks
   * of the walk-table pre-pass alone (ShaderVariant.walk_picks_only, whose
   * triangles are all in front: the pre-pass picks none for another): no
   * edge of its own is measured, so none is set up. */
  edge_line0 = edge_line1 = edge_line2 = edge_line3 = edge_line4 = vec3(0.0, 0.0, NO_EDGE);
  edge_span0 = edge_span1 = edge_span2 = edge_span3 = edge_span4 = vec2(0.0);
  w0 = w1 = w2 = vec2(0.0);
#    ifdef WALK_PICKS_ONLY
  in_front = true;
#    else
  in_front = false;
#    endif
  convex = false;
#  else
  triangle_edges(c0, c1, c2, c3, ids, is_quad, edge_line0, edge_span0, edge_line1, edge_span1, edge_line2,
                 edge_span2, edge_line3, edge_span3, edge_line4, edge_span4, w0, w1, w2, in_front, convex);
#  endif
  t0 = w0 - viewport_centre();
  t1 = w1 - viewport_centre();
  t2 = w2 - viewport_centre();
  return simple_triangle(in_front, is_quad, is_ngon, convex);
}
#endif

#ifdef USE_NGONS
/* The segments of the triangle's region block within reach of it, handed to
 * the fragment stage (segment_count -1: it walks the whole block). Flat
 * outputs come from the provoking corner only: the last one under OpenGL
 * (Blender keeps GL's default), so there the other two skip the selection;
 * other backends may provoke from the first, so both ends select
 * (PROVOKING_CORNERS, core/shaders.py). */
void select_block_segments(int corner, bool in_front, vec2 t0, vec2 t1, vec2 t2, vec3 clip_w)
{
  segment_count = 0;
  for (int k = 0; k < SEGMENT_SLOTS; k++) {
    store_segment(k, vec3(0.0, 0.0, NO_EDGE), vec2(0.0), 0.0, 0.0);
  }
  bool provoking = (corner == 2) || (PROVOKING_CORNERS == 2 && corner == 0);
#  ifdef REGION_LINE_IMAGE
  /* Lines from the region-lines pass: only the block's diagonals are walked. */
  bool lines_elsewhere = (edge_flags & REGION_LINES) != 0;
#  else
  const bool lines_elsewhere = false;
#  endif
  if (lines_elsewhere) {
    segment_count = -1;
  }
  else if ((edge_flags & IN_REGION) != 0 && provoking) {
    /* Behind the near plane a corner has no window position: walk. */
#  ifdef WALK_TABLE
    segment_count = in_front ? read_walk_table(SW_VERTEX_ID / 3) : -1;
#  else
    segment_count = in_front ? select_segments(t0, t1, t2, line_reach(clip_w.x, clip_w.y, clip_w.z)) : -1;
#  endif
  }
}
#endif

#ifdef WRITE_AOVS
/* Normal pass: the triangle's world-space normal (loop order, through the
 * normal matrix); the fragment stage turns it towards the camera. The
 * matrix's sign folds in mirroring, so gl_FrontFacing picks the side. And
 * IndexMA: the pass_index of this triangle's material (draw.py). */
void render_pass_outputs(int triangle, vec4 ids)
{
  vec3 p0 = fetch_texel(vertex_positions, int(ids.x)).xyz;
  vec3 p1 = fetch_texel(vertex_positions, int(ids.y)).xyz;
  vec3 p2 = fetch_texel(vertex_positions, int(ids.z)).xyz;
  mat3 object_to_world_normal = mat3(object_params.normal_matrix0.xyz, object_params.normal_matrix1.xyz,
                                     object_params.normal_matrix2.xyz);
  vec3 n = object_to_world_normal * cross(p1 - p0, p2 - p0);
  float n_length = length(n);
  face_normal = n_length > 0.0 ? n / n_length : vec3(0.0);
  material_pass_index = fetch_texel(triangle_material, triangle).x;
}
#endif

/* The fill's inputs at this corner: the shading normal, the colour
 * attribute and the object's colours from the frame's colour table
 * (core/colors.py), the fill per face material. */
void fill_outputs(int triangle, int corner, float vertex_id)
{
#ifdef USE_CORNERS
  vec4 corner_data = corner_shading(triangle, corner, vertex_id);
  shading_normal = corner_data.xyz;
#endif
#ifdef ATTRIBUTE_COLORS
  attribute_fill = attribute_row(triangle, corner, vertex_id).rgb;
#endif
#ifdef ITEM_COLORS
  int item_base = int(item_info.x);
  vec4 item_head = fetch_texel(item_colors, item_base);
  item_wire = item_head.rgb;
  item_fill = fetch_texel(item_colors, item_base + 1).rgb;
#  ifdef MATERIAL_COLORS
  int material_count = int(item_head.w);
  if (material_count > 0) {
    item_fill = fetch_texel(item_colors, item_base + 2 + clamp(int(corner_data.w), 0, material_count - 1)).rgb;
  }
#  endif
#endif
}

#if defined(HIDDEN_PASS) && !defined(RESOLVE_PASS)
/* The other triangle of this one's quad (quad_partner.glsl), for the
 * fragment stage's test of whether that triangle is the surface
 * (solidwire_frag.glsl, leave_out_the_visible_face); all zero for none.
 * Its window depth as the depth test sees it, with the overlay's bias,
 * times w: 0.5 (z + w) of each corner, which weighted by the corners'
 * barycentrics and divided by their w gives the window depth at a pixel
 * (also where a corner lies behind the camera). */
void partner_outputs(int triangle, vec4 ids)
{
  vec4 a, b, c;
  partner_window_depth = vec3(0.0);
  if (quad_partner_set_up(triangle, ids, edge_flags, partner0, partner2, partner3, a, b, c)) {
    partner_window_depth = 0.5 * (vec3(biased(a).z, biased(b).z, biased(c).z) + vec3(a.w, b.w, c.w));
  }
}
#endif

/* The per-corner work. The resolve pass (resolve_frag.glsl) runs it too,
 * for the provoking corner of the triangle a pixel shows, with
 * SW_VERTEX_ID standing for gl_VertexID and every output a plain global. */
#if defined(RESOLVE_PASS) || defined(WALK_TABLE_PASS)
void solidwire_corner()
#else
void main()
#endif
{
#if defined(REGION_LAYERS_PEELED) && !defined(WALK_TABLE_PASS)
  /* A hidden-line pass whose multi-face regions' layers were drawn by depth
   * peeling (passes.py, docs/image_model.md §2.6): their triangles are
   * dropped before any set-up (outside the clip volume). */
  if ((edge_flags & REGION_LINES) != 0 && (edge_flags & OWN_EDGES_MEASURED) != OWN_EDGES_MEASURED) {
    gl_Position = vec4(2.0, 2.0, 2.0, 1.0);
    return;
  }
#endif
  int triangle = SW_VERTEX_ID / 3;
  int corner = SW_VERTEX_ID - triangle * 3;
  vec4 ids = fetch_texel(triangle_vertices, triangle);
  float vertex_id = (corner == 0) ? ids.x : ((corner == 1) ? ids.y : ids.z);
  bool is_quad = (edge_flags & HAS_QUAD_CORNER) != 0;
  bool is_ngon = (edge_flags & IS_NGON) != 0;
  ngon_corner_start = int(ids.w);
#ifdef OWN_EDGES
  if ((edge_flags & OWN_EDGES_MEASURED) == OWN_EDGES_MEASURED) {
    /* Its face's corners lead its block: its quad's 4th corner is the one
     * that is not its own (a triangle face repeats one of its own, whose
     * two quad edges are marked hidden). */
    vec4 face = fetch_texel(ngon_corners, ngon_corner_start);
    ids.w = face.w;
    if (face.x != ids.x && face.x != ids.y && face.x != ids.z) {
      ids.w = face.x;
    }
    else if (face.y != ids.x && face.y != ids.y && face.y != ids.z) {
      ids.w = face.y;
    }
    else if (face.z != ids.x && face.z != ids.y && face.z != ids.z) {
      ids.w = face.z;
    }
    ngon_corner_start += SEGMENT_TEXELS;
  }
#endif
#ifdef SETUP_TABLE
  bool simple = read_setup_table(triangle, ids, is_quad, is_ngon);
  vec3 local = fetch_texel(vertex_positions, int(vertex_id)).xyz;
  vec4 position = object_to_clip * vec4(local, 1.0); /* as vertex_clip() */
#else
  vec4 c0, c1, c2;
  vec2 t0, t1, t2;
  bool in_front;
  bool simple = set_up_edges(ids, is_quad, is_ngon, c0, c1, c2, t0, t1, t2, in_front);
  vec4 position = (corner == 0) ? c0 : ((corner == 1) ? c1 : c2);
  vec3 local = fetch_texel(vertex_positions, int(vertex_id)).xyz;
#endif
  if (!is_quad) {
    edge_line3 = edge_line4 = vec3(0.0, 0.0, NO_EDGE);
    edge_span3 = edge_span4 = vec2(0.0);
  }
  triangle_flags = edge_flags | (simple ? SIMPLE_TRIANGLE : 0);
#ifdef USE_NGONS
  select_block_segments(corner, in_front, t0, t1, t2, vec3(c0.w, c1.w, c2.w));
#endif
#ifdef WRITE_AOVS
  render_pass_outputs(triangle, ids);
#endif
  view_depth = -dot(object_to_view_z, vec4(local, 1.0));
#if defined(HIDDEN_PASS) && !defined(RESOLVE_PASS)
  partner_outputs(triangle, ids);
#  ifdef NGON_SIBLINGS
  hidden_triangle = triangle;
#  endif
#endif
  fill_outputs(triangle, corner, vertex_id);
#ifdef USE_CLIP_PLANES
  clip_distances(position); /* (before the depth bias, which moves only z) */
#endif
#if !defined(RESOLVE_PASS) && !defined(WALK_TABLE_PASS)
  gl_Position = biased(position);
#endif
}
