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
#endif
#ifdef PEEL_LAYER
  /* Strictly behind: the depth in `peel_depth` was written by this same
   * code for the layer before (or by the surface pass, for the first), so
   * that layer itself never passes. */
  if (depth <= texelFetch(peel_depth, ivec2(gl_FragCoord.xy), 0).r) {
    discard;
  }
#endif
  frag_visible = vec4(triangle_number, instance, float(draw_number), view_depth);
}
