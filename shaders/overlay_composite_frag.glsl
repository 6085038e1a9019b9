/* The viewport overlay's deferred surface, composited into Blender's buffer
 * (passes.draw_over_viewport): the resolved colour the overlay keeps, at the
 * record's window depth moved towards the camera by the direct pass's
 * DEPTH_BIAS (z/w - b in NDC is z - b/2 in window depth, biased() in edge_geometry.glsl)
 * and by the allowance for Blender's rounding of the same surface,
 * so that Blender's depth test keeps exactly the pixels it keeps of the
 * direct pass, and the colour blends as that pass's fragment would. Where
 * the record holds no surface (its cleared depth), nothing is drawn. A
 * hidden layer (passes._peel_hidden_regions) is composited the same way. */

void main()
{
  ivec2 pixel = ivec2(gl_FragCoord.xy);
  float depth = texelFetch(record_depth, pixel, 0).r;
  if (depth >= 1.0) {
    discard;
  }
#ifdef LINEAR_RECORD
  /* A hidden layer's record holds view depth / clip end (linear: which of
   * two layers is nearer never depends on the clip range); Blender's test
   * needs window depth: 0.5 z/w + 0.5 of the same point. */
  float z_clip = window_depth_rows.y - window_depth_rows.x * depth;
  float w_clip = window_depth_rows.w - window_depth_rows.z * depth;
  depth = 0.5 * (z_clip / w_clip) + 0.5;
#endif
  /* The allowance for Blender's rounding far from the origin (common.glsl),
   * at the view depth of this window depth. */
  float view_depth = view_depth_of_window_depth(depth, depth_rows);
  gl_FragDepth = depth - 0.5 * DEPTH_BIAS + window_depth_shift(view_depth, blender_depth_allowance, depth_rows);
  frag_color = texelFetch(surface_image, pixel, 0);
}
