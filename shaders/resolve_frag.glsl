/* Resolve pass of the deferred surface (docs/image_model.md §2.5): for each
 * pixel whose visible triangle belongs to this draw, rebuild what the
 * exact path's fragment stage would have received for that triangle, then
 * run that fragment stage unchanged.
 *
 * - Flat inputs: the vertex stage's own code for the triangle's provoking
 *   corner (solidwire_corner(), the last corner as under OpenGL), so the
 *   edge set-up is the same code, computed once per pixel.
 * - View depth: the rasteriser's own value, stored by the visibility pass.
 * - 1/w, facing and the smooth shading normal: from the triangle's clip-space
 *   corners. With h_k = (x_k, y_k, w_k) and r = (ndc, 1), the weights
 *   mu_k ~ det(r, h_k+1, h_k+2) are the perspective-correct barycentrics of
 *   the pixel (2D homogeneous rasterisation: no division by a corner's w,
 *   so triangles crossing the near plane need no special case); w at the
 *   pixel is sum(mu_k w_k) after normalising; the triangle faces the camera
 *   (counter-clockwise in the window) where det(h_0, h_1, h_2) > 0, the sign
 *   of the projection's Jacobian wherever w > 0. */

void main()
{
  vec4 visible = texelFetch(visibility, ivec2(gl_FragCoord.xy), 0);
  if (visible.z != float(draw_number)) {
    discard; /* nothing, or another draw's triangle */
  }
#ifdef RECORD_DEPTH
  /* Straight into Blender's buffer (viewport overlay): the record's window
   * depth less the bias and Blender's allowance, as overlay_composite_frag.glsl
   * writes it. */
  gl_FragDepth = texelFetch(record_depth, ivec2(gl_FragCoord.xy), 0).r - 0.5 * DEPTH_BIAS +
                 window_depth_shift(visible.w, params.blender_depth_allowance, params.depth_rows);
#endif
  int triangle = int(visible.x) - 1;
  sw_instance_id = int(visible.y);
#ifdef NO_EDGE_SETUP
  /* Every triangle of the draw takes its lines from the region-lines image
   * (ShaderVariant.no_edge_setup): of its flags only these two are read
   * (the rest describe its own edges, which are not set up). */
  edge_flags = IN_REGION | REGION_LINES;
#else
  edge_flags = TABLE_FLAGS(fetch_texel(triangle_flag_table, triangle));
#endif
  sw_vertex_id = 3 * triangle + 2;
  solidwire_corner();

  vec4 c0 = sw_corner_clip0, c1 = sw_corner_clip1, c2 = sw_corner_clip2;
  vec2 ndc = (gl_FragCoord.xy - params.viewport.xy) / params.viewport.zw * 2.0 - 1.0;
  vec3 r = vec3(ndc, 1.0);
  vec3 h0 = c0.xyw, h1 = c1.xyw, h2 = c2.xyw;
  vec3 mu = vec3(dot(cross(h1, h2), r), dot(cross(h2, h0), r), dot(cross(h0, h1), r));
  float mu_sum = mu.x + mu.y + mu.z;
  mu = (mu_sum != 0.0) ? mu / mu_sum : vec3(1.0 / 3.0);
  sw_inv_clip_w = 1.0 / dot(mu, vec3(c0.w, c1.w, c2.w));
  sw_front_facing = dot(h0, cross(h1, h2)) > 0.0;
  view_depth = visible.w;
#ifdef USE_CORNERS
  vec4 ids = sw_triangle_ids; /* fetched by solidwire_corner() */
  /* Interpolated in object space, then turned once (the map is linear). */
  shading_normal = mat3(normal_to_view) * (mu.x * corner_row(triangle, 0, ids.x).xyz
                                           + mu.y * corner_row(triangle, 1, ids.y).xyz
                                           + mu.z * corner_row(triangle, 2, ids.z).xyz);
#endif
#ifdef ATTRIBUTE_COLORS
  /* Interpolated with the same perspective-correct weights. */
  vec4 corner_ids = sw_triangle_ids;
  attribute_fill = mu.x * attribute_row(triangle, 0, corner_ids.x).rgb
                   + mu.y * attribute_row(triangle, 1, corner_ids.y).rgb
                   + mu.z * attribute_row(triangle, 2, corner_ids.z).rgb;
#endif
  solidwire_fragment();
}
