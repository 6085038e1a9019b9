/* Visibility pass (visibility_vert.glsl): depth exactly as the exact path
 * writes it (the render's linear depth, or the rasteriser's window depth for
 * the viewport overlay's record), and per pixel (triangle + 1, instance, draw number, view
 * depth). Whole numbers below 2^24 are exact in float32; bigger meshes stay
 * on the direct path (passes.deferred_surface). */

void main()
{
  if (outside_clip_region()) {
    discard;
  }
#ifdef LINEAR_DEPTH
  /* See LINEAR_DEPTH in solidwire_frag.glsl. Kept below 1.0, the cleared
   * background: a surface right at the far clip plane is recorded as one,
   * and the resolve, tested GREATER at 1.0, finds it (resolve_vert.glsl). */
  gl_FragDepth = min(view_depth * params.inv_clip_end, BELOW_ONE);
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
  frag_visible = vec4(triangle_number, instance, float(draw_number), view_depth);
}
