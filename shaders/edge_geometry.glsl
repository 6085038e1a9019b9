/* SolidWire edge geometry, shared by both stages of the exact path: vertex
 * pulling and the set-up of an edge as a window-space line plus the interval
 * its near-clipped segment covers. The vertex stage sets up the triangle's
 * own edges once per corner; the fragment stage uses the same code for the
 * boundary of an n-gon, which no fixed number of varyings can carry. */

vec4 vertex_clip(float vertex_index)
{
  vec3 p = fetch_texel(vertex_positions, int(vertex_index)).xyz;
  return object_to_clip * vec4(p, 1.0);
}

/* Viewport overlay only: Blender's own Solid shading has already written
 * (nearly) the same depth for the same surface, but from its own float32
 * matrices and positions, so ours differs by a few ULPs either way and a
 * LESS_EQUAL test would stipple. Moving every vertex a constant DEPTH_BIAS
 * towards the camera in NDC (z - b*w, i.e. z/w - b after the divide) makes
 * our surface win that tie; NDC bias is the right unit because float32
 * rounding of z/w is relative to |z/w| <= 1. Far from the world origin
 * Blender's rounding of the positions themselves dominates: the vertex
 * moves towards the camera by that allowance too, in scene units
 * (window_depth_shift, common.glsl). Window x/y and the edge distances are
 * untouched (only z changes). */
vec4 biased(vec4 position)
{
#ifdef DEPTH_BIAS
  float view_depth_here = view_depth_of_clip_z(position.z, params.depth_rows);
  position.z += 2.0 * window_depth_shift(view_depth_here, params.blender_depth_allowance, params.depth_rows) *
                position.w;
  position.z -= DEPTH_BIAS * position.w;
#endif
  return position;
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

/* The view depth of the near plane (z + w = 0), from the projection's rows
 * P22, P23, P32, P33 in params.depth_rows. */
float near_plane_depth()
{
  vec4 rows = params.depth_rows;
  return (rows.y + rows.w) / (rows.x + rows.z);
}

/* The clip w of every point of the near plane: its view depth n for a
 * perspective projection, 1 for an orthographic one. */
float near_plane_w()
{
  vec4 rows = params.depth_rows;
  return rows.w - rows.z * near_plane_depth();
}

/* Where the segment from `behind` (depth, z + w, below 0) to `front`
 * (depth at least 0) crosses the near plane. Measured from the front end:
 * the behind end can lie far away, and its clip coordinates carry a
 * rounding error in proportion, which a step from the front end scales
 * down by the fraction it takes. Its w is the near plane's own, not an
 * interpolated one: that w (about n) would be the small difference of large
 * numbers, and an end that projects thousands of pixels off-screen carried
 * its relative error into its window point, so into the span and the phase
 * of a dashed line's pattern. */
vec4 near_clipped(vec4 behind, vec4 front, float depth_behind, float depth_front)
{
  vec4 point = front + (depth_front / (depth_front - depth_behind)) * (behind - front);
  float w = near_plane_w();
  return vec4(point.xyz, (w > 0.0) ? w : point.w);
}

/* Lines and spans are stored relative to the viewport centre: the fragment
 * stage evaluates them at gl_FragCoord.xy - viewport_centre(), an exact
 * subtraction that halves the size of the numbers it rounds. */
vec2 viewport_centre()
{
  return params.viewport.xy + 0.5 * params.viewport.zw;
}

/* The window line through a -> b (window points) and the interval the
 * segment covers along it; see edge_setup for the conventions and why the
 * line is anchored where it is. */
void line_through(vec2 window_a, vec2 window_b, out vec3 line, out vec2 span)
{
  vec2 centre = viewport_centre();
  vec2 wa = window_a - centre;
  vec2 wb = window_b - centre;
  vec2 ab = wb - wa;
  float len2 = dot(ab, ab);
  if (len2 == 0.0) {
    /* A single point (coincident ends, or an edge along a view ray) is a
     * segment too (image model §3.2): any unit line through it, with an
     * empty span, measures the distance to it. */
    line = vec3(1.0, 0.0, -wa.x);
    span = vec2(wa.y);
    return;
  }
  if (!(len2 > 0.0)) {
    /* A non-finite end: no projection, no distance. */
    line = vec3(0.0, 0.0, NO_EDGE);
    span = vec2(0.0);
    return;
  }
  vec2 dir = ab * inversesqrt(len2);
  vec2 normal = vec2(dir.y, -dir.x); /* so that dir == (-normal.y, normal.x) */
  vec2 anchor = (dot(wa, wa) <= dot(wb, wb)) ? wa : wb;
  line = vec3(normal, -dot(normal, anchor));
  span = vec2(dot(dir, wa), dot(dir, wb));
}

/* Edge a->b as a unit-normal window line (n.x, n.y, c) and the interval
 * `span` = (s_a, s_b) its near-clipped segment covers along dir = (-n.y, n.x).
 * s_a belongs to endpoint a, so a pattern can be measured from a chosen end.
 *
 * Only the part in front of the near plane (clip z + w >= 0) has a
 * projection, so the segment is clipped in clip space first; its ends then
 * have w > 0 and project to finite window points, whatever side of the
 * camera the original vertices were on: no special case for vertices behind
 * the viewpoint.
 *
 * Precision: an edge wholly in front is anchored at its end nearer the
 * viewport centre, in coordinates relative to that centre (line_through;
 * `line` and `span` are relative to it, see viewport_centre()).
 * The cross product of the two homogeneous window points gives the same
 * line, but for a short edge it subtracts two nearly equal products of
 * window coordinates: about 0.03 px / (edge length in px), which small
 * triangles of dense meshes showed. For an edge that crosses the near plane
 * the cross product is the better-conditioned choice (see below). */
void edge_setup(vec4 a, vec4 b, out vec3 line, out vec2 span)
{
#ifdef ALL_IN_FRONT
  /* The draw lies wholly in front of the near plane (shaders.py): no
   * clipping code at all (a CPU rasteriser runs every side of a branch). */
  line_through(window_point(a), window_point(b), line, span);
#else
  float depth_a = a.z + a.w; /* >= 0 in front of the near plane */
  float depth_b = b.z + b.w;
  if (depth_a < 0.0 && depth_b < 0.0) {
    /* Wholly behind the near plane: no projection, no distance. */
    line = vec3(0.0, 0.0, NO_EDGE);
    span = vec2(0.0);
    return;
  }
  if (depth_a >= 0.0 && depth_b >= 0.0) {
    line_through(window_point(a), window_point(b), line, span);
    return;
  }
  /* The edge crosses the near plane. Its clipped end is interpolated between
   * two possibly far-apart points, so its position can carry a large
   * rounding error: take the line itself from the unclipped ends instead, as
   * the cross product of their homogeneous window coordinates (no division,
   * valid on either side of the camera; long edges are well conditioned
   * there). Only the span uses the clipped end. */
  vec3 l = cross(window_homogeneous(a), window_homogeneous(b));
  float len2 = dot(l.xy, l.xy);
  if (len2 == 0.0) {
    /* Along a view ray: the front part projects to its front end's point. */
    vec2 point = window_point((depth_a >= 0.0) ? a : b);
    line_through(point, point, line, span);
    return;
  }
  if (!(len2 > 0.0)) {
    line = vec3(0.0, 0.0, NO_EDGE);
    span = vec2(0.0);
    return;
  }
  vec2 centre = viewport_centre();
  line = l * inversesqrt(len2);
  line.z += dot(line.xy, centre); /* relative to the viewport centre, like line_through */
  vec4 a_front = (depth_a < 0.0) ? near_clipped(a, b, depth_a, depth_b) : a;
  vec4 b_front = (depth_b < 0.0) ? near_clipped(b, a, depth_b, depth_a) : b;
  vec2 wa = window_point(a_front) - centre, wb = window_point(b_front) - centre;
  vec2 dir = vec2(-line.y, line.x);
  if (dot(dir, wb - wa) < 0.0) {
    line = -line; /* dir runs from a to b, so span.x < span.y */
    dir = -dir;
  }
  span = vec2(dot(dir, wa), dot(dir, wb));
#endif
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

/* The same for two ends already known to be in front of the near plane,
 * from their window points (no clipping, no second division). */
void line_through_from_lower(vec2 window_a, vec2 window_b, float id_a, float id_b, out vec3 line, out vec2 span)
{
  if (id_b < id_a) {
    line_through(window_b, window_a, line, span);
  }
  else {
    line_through(window_a, window_b, line, span);
  }
}

/* The edges of triangle c0 c1 c2 (clip positions; `ids` their vertex ids)
 * and, with `quad`, the two edges to a quad's 4th corner c3 (c3 = c0 or c2
 * for a triangle), as window lines and spans. `in_front`: every corner is in
 * front of the near plane, so the lines come from one division per corner
 * (w0..w2 are then the window corners), else each edge is clipped;
 * `convex`: the quad projects convex (each diagonal separates the other two
 * corners). One function for the vertex stage and the set-up pre-pass, so
 * both give the same bits. */
void triangle_edges(vec4 c0, vec4 c1, vec4 c2, vec4 c3, vec4 ids, bool quad, out vec3 line0, out vec2 span0,
                    out vec3 line1, out vec2 span1, out vec3 line2, out vec2 span2, out vec3 line3, out vec2 span3,
                    out vec3 line4, out vec2 span4, out vec2 w0, out vec2 w1, out vec2 w2, out bool in_front,
                    out bool convex)
{
#ifdef ALL_IN_FRONT
  in_front = true;
#else
  in_front = min(min(c0.z + c0.w, c1.z + c1.w), min(c2.z + c2.w, c3.z + c3.w)) >= 0.0;
#endif
  convex = false;
  line3 = line4 = vec3(0.0, 0.0, NO_EDGE);
  span3 = span4 = vec2(0.0);
  w0 = w1 = w2 = vec2(0.0);
  if (in_front) {
    vec2 w3 = c3.xy / c3.w;
    w0 = c0.xy / c0.w;
    w1 = c1.xy / c1.w;
    w2 = c2.xy / c2.w;
    vec2 to_window = 0.5 * params.viewport.zw;
    vec2 origin = params.viewport.xy + to_window;
    w0 = w0 * to_window + origin;
    w1 = w1 * to_window + origin;
    w2 = w2 * to_window + origin;
    w3 = w3 * to_window + origin;
    line_through_from_lower(w0, w1, ids.x, ids.y, line0, span0);
    line_through_from_lower(w1, w2, ids.y, ids.z, line1, span1);
    line_through_from_lower(w2, w0, ids.z, ids.x, line2, span2);
    if (quad) {
      line_through_from_lower(w2, w3, ids.z, ids.w, line3, span3);
      line_through_from_lower(w3, w0, ids.w, ids.x, line4, span4);
      vec2 d02 = w2 - w0, d13 = w3 - w1;
      float s1 = d02.x * (w1.y - w0.y) - d02.y * (w1.x - w0.x);
      float s3 = d02.x * (w3.y - w0.y) - d02.y * (w3.x - w0.x);
      float t0 = d13.x * (w0.y - w1.y) - d13.y * (w0.x - w1.x);
      float t2 = d13.x * (w2.y - w1.y) - d13.y * (w2.x - w1.x);
      convex = s1 * s3 < 0.0 && t0 * t2 < 0.0;
    }
  }
#ifndef ALL_IN_FRONT
  else {
    edge_setup_from_lower(c0, c1, ids.x, ids.y, line0, span0);
    edge_setup_from_lower(c1, c2, ids.y, ids.z, line1, span1);
    edge_setup_from_lower(c2, c0, ids.z, ids.x, line2, span2);
    if (quad) {
      edge_setup_from_lower(c2, c3, ids.z, ids.w, line3, span3);
      edge_setup_from_lower(c3, c0, ids.w, ids.x, line4, span4);
    }
  }
#endif
}
