/* fill_only: the same triangles, pulled the same way, with no edge set-up.
 * The time lower bound of any single-pass wireframe over these triangles. */

void main()
{
  int triangle = gl_VertexID / 3;
  int corner = gl_VertexID - triangle * 3;
  vec4 ids = fetch_texel(triangle_vertices, triangle);
  vec3 local = pulled_position((corner == 0) ? ids.x : ((corner == 1) ? ids.y : ids.z));
  emit_corner(local, object_to_clip * vec4(local, 1.0));
}
