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

void main()
{
  int triangle = gl_VertexID / 3;
  int corner = gl_VertexID - triangle * 3;
  vec4 ids = fetch_texel(triangle_vertices, triangle);

  vec4 c0 = vertex_clip(ids.x);
  vec4 c1 = vertex_clip(ids.y);
  vec4 c2 = vertex_clip(ids.z);

  edge_setup_from_lower(c0, c1, ids.x, ids.y, edge_line0, edge_span0);
  edge_setup_from_lower(c1, c2, ids.y, ids.z, edge_line1, edge_span1);
  edge_setup_from_lower(c2, c0, ids.z, ids.x, edge_line2, edge_span2);

  triangle_flags = edge_flags;
  /* For an n-gon triangle the 4th id is where its polygon's corners start
   * in `ngon_corners`. */
  ngon_corner_start = int(ids.w);
  if ((edge_flags & HAS_QUAD_CORNER) != 0) {
    vec4 c3 = vertex_clip(ids.w);
    edge_setup_from_lower(c2, c3, ids.z, ids.w, edge_line3, edge_span3);
    edge_setup_from_lower(c3, c0, ids.w, ids.x, edge_line4, edge_span4);
  }
  else {
    edge_line3 = edge_line4 = vec3(0.0, 0.0, NO_EDGE);
    edge_span3 = edge_span4 = vec2(0.0);
  }

  vec4 position = (corner == 0) ? c0 : ((corner == 1) ? c1 : c2);
  vec3 local = fetch_texel(vertex_positions,
                           int((corner == 0) ? ids.x : ((corner == 1) ? ids.y : ids.z))).xyz;
  view_depth = -dot(object_to_view_z, vec4(local, 1.0));
#ifdef DEPTH_BIAS
  /* Viewport overlay only: Blender's own Solid shading has already written
   * (nearly) the same depth for the same surface, but from its own float32
   * matrices and positions, so ours differs by a few ULPs either way and a
   * LESS_EQUAL test would stipple. Moving every vertex a constant DEPTH_BIAS
   * towards the camera in NDC (z - b*w, i.e. z/w - b after the divide) makes
   * our surface win that tie; NDC bias is the right unit because float32
   * rounding of z/w is relative to |z/w| <= 1. Window x/y and the edge
   * distances are untouched (only z changes). */
  position.z -= DEPTH_BIAS * position.w;
#endif
  gl_Position = position;
}
