/* Visibility pass of the deferred surface (docs/image_model.md §2.5): the
 * rasteriser only decides which triangle each pixel shows. An indexed batch
 * (cache.GPUMesh.visibility_batch): each vertex is transformed once, read
 * from the position table and transformed with the exact path's own
 * expression (so the same coverage and depth; a move re-uploads that table
 * alone), and hands on nothing but the view depth (and its instance); gl_PrimitiveID
 * numbers the triangle, or on a software rasteriser the provoking vertex
 * does (SW_TRIANGLE_BY_VERTEX, shaders.triangle_ids_by_vertex). The per-triangle edge set-up, which dominates a
 * dense mesh's frame on a software rasteriser, moves to the resolve pass
 * and runs once per pixel instead of at every corner. */

void main()
{
  vec3 position = fetch_texel(vertex_positions, source_vertex).xyz;
  view_depth = -dot(object_to_view_z, vec4(position, 1.0));
#ifdef SW_TRIANGLE_BY_VERTEX
  /* Only the provoking (last) corner's value reaches the fragments: the
   * batch gives every triangle a last corner of its own. */
  visible_triangle = triangle;
#  if defined(REGION_LAYERS) && !defined(NGON_SIBLINGS)
  /* So the quad's other triangle (visibility_frag.glsl) is set up once per
   * triangle, by that corner, not at every pixel. (A mesh whose n-gons may
   * fold walks its face's triangles per pixel instead.) */
  quad_partner_window_corners(int(triangle) - 1, partner0, partner2, partner3);
#  endif
#endif
#ifdef SW_INSTANCED
  visible_instance = float(gl_InstanceID);
#endif
  gl_Position = object_to_clip * vec4(position, 1.0); /* as vertex_clip() */
#ifdef USE_CLIP_PLANES
  clip_distances(gl_Position);
#endif
}
