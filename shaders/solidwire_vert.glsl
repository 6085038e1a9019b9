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

vec4 fetch_texel(sampler2D table, int index)
{
  int width = textureSize(table, 0).x;
  return texelFetch(table, ivec2(index % width, index / width), 0);
}

vec4 vertex_clip(float vertex_index)
{
  vec3 p = fetch_texel(vertex_positions, int(vertex_index)).xyz;
  return object_to_clip * vec4(p, 1.0);
}

/* Homogeneous window coordinates: (x_win * w, y_win * w, w). */
vec3 window_homogeneous(vec4 clip)
{
  return vec3((clip.xy + clip.w) * 0.5 * params.viewport.zw + params.viewport.xy * clip.w, clip.w);
}

vec2 window_point(vec4 clip)
{
  vec3 h = window_homogeneous(clip);
  return h.xy / h.z;
}

/* Edge a->b as a unit-normal window line (n.x, n.y, c) and the interval
 * `span` = (s_a, s_b) its near-clipped segment covers along dir = (-n.y, n.x).
 * s_a belongs to endpoint a, so a pattern can be measured from a chosen end. */
void edge_setup(vec4 a, vec4 b, out vec3 line, out vec2 span)
{
  vec3 l = cross(window_homogeneous(a), window_homogeneous(b));
  float len2 = dot(l.xy, l.xy);
  float depth_a = a.z + a.w; /* >= 0 in front of the near plane */
  float depth_b = b.z + b.w;
  if (len2 == 0.0 || (depth_a < 0.0 && depth_b < 0.0)) {
    /* Projects to a point (edge along a view ray) or lies wholly behind the
     * near plane: it has no visible projection and no distance. */
    line = vec3(0.0, 0.0, NO_EDGE);
    span = vec2(0.0);
    return;
  }
  line = l * inversesqrt(len2);
  vec4 a_front = (depth_a < 0.0) ? mix(a, b, depth_a / (depth_a - depth_b)) : a;
  vec4 b_front = (depth_b < 0.0) ? mix(b, a, depth_b / (depth_b - depth_a)) : b;
  vec2 dir = vec2(-line.y, line.x);
  span = vec2(dot(dir, window_point(a_front)), dot(dir, window_point(b_front)));
}

void main()
{
  int triangle = gl_VertexID / 3;
  int corner = gl_VertexID - triangle * 3;
  vec4 ids = fetch_texel(triangle_vertices, triangle);

  vec4 c0 = vertex_clip(ids.x);
  vec4 c1 = vertex_clip(ids.y);
  vec4 c2 = vertex_clip(ids.z);

  edge_setup(c0, c1, edge_line0, edge_span0);
  edge_setup(c1, c2, edge_line1, edge_span1);
  /* Edge 2 runs from its lower vertex id so both triangles of a quad measure
   * the diagonal pattern from the same end (no seam along the diagonal). */
  if (ids.z < ids.x) {
    edge_setup(c2, c0, edge_line2, edge_span2);
  }
  else {
    edge_setup(c0, c2, edge_line2, edge_span2);
  }

  triangle_flags = edge_flags;
  if ((edge_flags & HAS_QUAD_CORNER) != 0) {
    vec4 c3 = vertex_clip(ids.w);
    edge_setup(c2, c3, edge_line3, edge_span3);
    edge_setup(c3, c0, edge_line4, edge_span4);
  }
  else {
    edge_line3 = edge_line4 = vec3(0.0, 0.0, NO_EDGE);
    edge_span3 = edge_span4 = vec2(0.0);
  }

  vec4 position = (corner == 0) ? c0 : ((corner == 1) ? c1 : c2);
  vec3 local = fetch_texel(vertex_positions,
                           int((corner == 0) ? ids.x : ((corner == 1) ? ids.y : ids.z))).xyz;
  view_depth = -dot(object_to_view_z, vec4(local, 1.0));
  gl_Position = position;
}
