/* SolidWire edge geometry, shared by both stages of the exact path: vertex
 * pulling and the set-up of an edge as a window-space line plus the interval
 * its near-clipped segment covers. The vertex stage sets up the triangle's
 * own edges once per corner; the fragment stage uses the same code for the
 * boundary of an n-gon, which no fixed number of varyings can carry. */

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

/* Edges run from their lower vertex id: the two triangles sharing a diagonal
 * then measure its pattern from the same end (no seam along the diagonal). */
void edge_setup_from_lower(vec4 a, vec4 b, float id_a, float id_b, out vec3 line, out vec2 span)
{
  if (id_b < id_a) {
    edge_setup(b, a, line, span);
  }
  else {
    edge_setup(a, b, line, span);
  }
}
