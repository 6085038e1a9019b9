/* barycentric: the barycentric/fwidth wireframe of the blog post in the seeds
 * ("barycentric-wireframe-blog"). The post reads gl_BaryCoordEXT (perspective
 * corrected barycentrics); Blender's GPU API has no such built-in, so each
 * corner outputs its one-hot weight and the rasteriser's ordinary
 * perspective-correct interpolation produces the same weights. */

void main()
{
  int triangle = gl_VertexID / 3;
  int corner = gl_VertexID - triangle * 3;
  vec4 ids = fetch_texel(triangle_vertices, triangle);
  vec3 local = pulled_position((corner == 0) ? ids.x : ((corner == 1) ? ids.y : ids.z));
  barycentric = vec3(0.0);
  barycentric[corner] = 1.0;
  /* Weight k is zero on the edge opposite corner k: opposite 0 is edge 1-2,
   * opposite 1 is edge 2-0, opposite 2 is edge 0-1. */
  int drawn = drawn_edges();
  line_mask = (((drawn & EDGE1_REAL) != 0) ? 1 : 0) | (((drawn & EDGE2_REAL) != 0) ? 2 : 0) |
              (((drawn & EDGE0_REAL) != 0) ? 4 : 0);
  emit_corner(local, object_to_clip * vec4(local, 1.0));
}
