/* Visibility pass (visibility_vert.glsl): depth exactly as the exact path
 * writes it (the render's linear depth, or the rasteriser's window depth for
 * the viewport overlay's record), and per pixel (triangle + 1, instance, draw number, view
 * depth). Whole numbers below 2^24 are exact in float32; bigger meshes stay
 * on the direct path (passes.deferred_surface).
 *
 * The hidden layers of multi-face regions (docs/image_model.md §2.6) use it
 * too, on those regions' triangles alone (REGION_LAYERS): PEEL_LAYER
 * records the nearest of them strictly behind the depth in `peel_depth`
 * (the surface, or the layer recorded before), one layer per draw. */

#ifdef REGION_LAYERS
/* A layer is never the visible face itself (quad_partner.glsl): where the
 * quad's other triangle (or the nearest of a folded n-gon's other
 * triangles, NGON_SIBLINGS) covers this pixel nearer than this one, this
 * fragment takes that depth, a hair nearer still, so the test against the
 * layer before drops it exactly where that triangle is the surface (the
 * render's first layer lies behind the surface; over the viewport the
 * surface's own layer, peeled first from the front, is this one now, and
 * Blender's depth test leaves it out). Where something else hides both it
 * comes just before the other: each is a layer of their face. */
float nearer_than_the_other_triangle(int triangle, float depth)
{
  vec4 a, b, c;
  vec3 weights;
  float partner_view_depth;
#  ifdef NGON_SIBLINGS
  /* Every other triangle of its face (quad_partner.glsl). */
  vec4 clip_a, clip_b, clip_c;
  bool level_before;
  bool covered = nearest_ngon_sibling(triangle, gl_FragCoord.xy, view_depth, gl_FrontFacing, a, b, c, clip_a, clip_b,
                                      clip_c, weights, partner_view_depth, level_before);
  if (level_before) {
    discard;
  }
#  else
#    ifdef SW_TRIANGLE_BY_VERTEX
  /* Set up once per triangle by its provoking corner (visibility_vert.glsl). */
  a = partner0;
  b = partner2;
  c = partner3;
#    else
  quad_partner_window_corners(triangle, a, b, c);
#    endif
  bool covered = quad_partner_covers(gl_FragCoord.xy, a, b, c, weights, partner_view_depth) &&
                 nearer_or_level(partner_view_depth, view_depth) && !culled_partner(a, b, c, gl_FrontFacing);
#  endif
  if (!covered) {
    return depth;
  }
  /* (The layers are recorded in linear depth: shaders.py.) */
  float rounding = partner_depth_error(gl_FragCoord.xy, a, b, c, vec3(a.w, b.w, c.w), false);
  return min((partner_view_depth * (1.0 - PARTNER_DEPTH_HAIR) - rounding) * params.inv_clip_end, depth);
}
#endif

void main()
{
  if (outside_clip_region()) {
    discard;
  }
#ifdef LINEAR_DEPTH
  /* See LINEAR_DEPTH in solidwire_frag.glsl. Kept below 1.0, the cleared
   * background: a surface right at the far clip plane is recorded as one,
   * and the resolve, tested GREATER at 1.0, finds it (resolve_vert.glsl). */
  float depth = min(view_depth * params.inv_clip_end, BELOW_ONE);
  gl_FragDepth = depth;
#else
  float depth = gl_FragCoord.z;
#endif
#ifdef SW_INSTANCED
  float instance = visible_instance;
#else
  float instance = 0.0;
#endif
#ifdef SW_TRIANGLE_BY_VERTEX
  float triangle_number = visible_triangle; /* triangle + 1 */
#else
  float triangle_number = float(gl_PrimitiveID + 1);
#endif
#ifdef REGION_LAYERS
  if (fetch_texel(triangle_regions, int(triangle_number) - 1).x < 0.0) {
    discard; /* a face that is its own region: the direct hidden-line pass draws it */
  }
#  ifdef PEEL_LAYER
  /* Strictly behind: the depth in `peel_depth` was written by this same
   * code for the layer before (or by the surface pass, for the first), so
   * that layer itself never passes. Tested first with the fragment's own
   * depth, which the other triangle only ever moves nearer: most fragments
   * lie in front of the layer before and skip that triangle's set-up. */
  float previous = texelFetch(peel_depth, ivec2(gl_FragCoord.xy), 0).r;
  if (depth <= previous) {
    discard;
  }
#  endif
  depth = nearer_than_the_other_triangle(int(triangle_number) - 1, depth);
  gl_FragDepth = depth;
#  ifdef PEEL_LAYER
  if (depth <= previous) {
    discard;
  }
#  endif
#endif
  frag_visible = vec4(triangle_number, instance, float(draw_number), view_depth);
}
