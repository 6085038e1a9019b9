/* SolidWire hair and point clouds, vertex stage: one screen-space quad (two
 * triangles over four shared corners, draw.indexed_quad_batch) per strand
 * segment or per point, pulled from the tables by gl_VertexID / 4 (an indexed
 * draw: gl_VertexID is the corner's index; core/strands.py). The quad covers every pixel
 * the fragment stage can give a non-zero value: the segment (or disc) widened
 * by its half-width, two softness widths and a pixel of slack. Primitives
 * wholly behind the near plane or with a non-finite position collapse to
 * nothing. */

/* Outside the clip volume: the rasteriser drops the triangle. */
const vec4 COLLAPSED = vec4(2.0, 2.0, 2.0, 1.0);

/* Window pixels per scene unit at clip w = 1, and the object's radius scale. */
#define PX_PER_UNIT strand_view.x
#define RADIUS_SCALE strand_view.y

float view_depth_of(vec3 p)
{
  return -dot(object_to_view_z, vec4(p, 1.0));
}

/* The quad corner `corner` (0..3: (a,-), (b,-), (b,+), (a,+))
 * around window points wa -> wb, `reach` px on every side. */
vec4 quad_corner_position(vec2 wa, vec2 wb, float reach, int corner)
{
  vec2 dir = wb - wa;
  float len = length(dir);
  dir = (len > 0.0) ? dir / len : vec2(1.0, 0.0);
  vec2 normal = vec2(-dir.y, dir.x);
  bool at_b = (corner == 1 || corner == 2);
  bool plus = (corner >= 2);
  vec2 w = (at_b ? wb + dir * reach : wa - dir * reach) + normal * (plus ? reach : -reach);
  vec2 ndc = (w - params.viewport.xy) / params.viewport.zw * 2.0 - 1.0;
  return vec4(ndc, 0.0, 1.0);
}

#if defined(STRAND_OVERLAY) && !defined(STRAND_POINTS)
/* The overlay blends segments "over" each other, so at a joint two
 * segments would both paint the pixels they share. Each segment keeps only
 * its side of the bisector of the joint: the plane through the joint whose
 * normal is the sum of the two unit directions (the pixels nearer its own
 * segment's line). (0, 0): no split (no neighbour, the end is near-clipped,
 * the neighbour is behind the camera, or the strand turns back on itself). */
vec2 joint_normal(float neighbour, vec2 win_a, vec2 win_b, bool clipped, bool at_a)
{
  if (neighbour < 0.0 || clipped) {
    return vec2(0.0);
  }
  vec4 n = object_to_clip * vec4(fetch_texel(vertex_positions, int(neighbour)).xyz, 1.0);
  if (!(n.z + n.w >= 0.0) || !(n.w > 0.0)) {
    return vec2(0.0);
  }
  vec2 win_n = window_point(n);
  vec2 along = win_b - win_a;
  vec2 other = at_a ? win_a - win_n : win_n - win_b;
  if (dot(along, along) == 0.0 || dot(other, other) == 0.0) {
    return vec2(0.0);
  }
  return normalize(along) + normalize(other);
}
#endif

void main()
{
  int prim = gl_VertexID / 4;
  int corner = quad_corner;
#ifdef STRAND_POINTS
  vec4 point = fetch_texel(vertex_positions, prim);
  vec4 c = object_to_clip * vec4(point.xyz, 1.0);
  float radius = max(point.w, 0.0) * RADIUS_SCALE;
  /* A point whose centre is behind the near plane is not drawn (its disc
   * has no projection). */
  if (!(c.z + c.w >= 0.0) || !(c.w > 0.0) || !(radius == radius)) {
    gl_Position = COLLAPSED;
    return;
  }
  vec2 centre = window_point(c);
  float radius_px = radius * PX_PER_UNIT / c.w;
  float depth = view_depth_of(point.xyz);
  disc = vec4(centre, radius_px, depth);
#  ifdef USE_CLIP_PLANES
  disc_clip = c;
#  endif
  disc_extra = vec2(radius, 1.0 / c.w);
  float reach = radius_px + max(half_thickness_at(depth, 1.0 / c.w), 0.0) + 2.0 * params.softness + 1.0;
  gl_Position = quad_corner_position(centre, centre, reach, corner);
#else
  vec4 ids = fetch_texel(strand_segments, prim);
  vec4 pa = fetch_texel(vertex_positions, int(ids.x));
  vec4 pb = fetch_texel(vertex_positions, int(ids.y));
  vec4 a = object_to_clip * vec4(pa.xyz, 1.0);
  vec4 b = object_to_clip * vec4(pb.xyz, 1.0);
  float depth_a = a.z + a.w, depth_b = b.z + b.w;
  if (!(depth_a >= 0.0 || depth_b >= 0.0)) {
    gl_Position = COLLAPSED; /* wholly behind the near plane (or NaN) */
    return;
  }
  /* The part in front of the near plane (docs/image_model.md §3.2), its
   * view depths and radii cut at the same parameters. */
  float ta = (depth_a < 0.0) ? depth_a / (depth_a - depth_b) : 0.0;
  float tb = (depth_b < 0.0) ? depth_b / (depth_b - depth_a) : 0.0;
  vec4 a_front = (depth_a < 0.0) ? near_clipped(a, b, depth_a, depth_b) : a;
  vec4 b_front = (depth_b < 0.0) ? near_clipped(b, a, depth_b, depth_a) : b;
  float za = view_depth_of(pa.xyz), zb = view_depth_of(pb.xyz);
  float ra = max(pa.w, 0.0) * RADIUS_SCALE, rb = max(pb.w, 0.0) * RADIUS_SCALE;
  seg_a = a_front;
  seg_b = b_front;
  edge_setup(a, b, seg_line, seg_span);
  seg_depth = vec2(mix(za, zb, ta), mix(zb, za, tb));
  seg_radius = vec2(mix(ra, rb, ta), mix(rb, ra, tb));
  /* The widest half-width is at an end: r / w is monotonic along a segment. */
  float wa_inv = 1.0 / max(a_front.w, 1e-6), wb_inv = 1.0 / max(b_front.w, 1e-6);
  float half_a = max(half_thickness_at(seg_depth.x, wa_inv), seg_radius.x * PX_PER_UNIT * wa_inv);
  float half_b = max(half_thickness_at(seg_depth.y, wb_inv), seg_radius.y * PX_PER_UNIT * wb_inv);
  float reach = min(max(half_a, half_b), 16384.0) + 2.0 * params.softness + 1.0;
  vec2 win_a = window_point(a_front), win_b = window_point(b_front);
#  ifdef STRAND_OVERLAY
  seg_split = vec4(joint_normal(ids.z, win_a, win_b, ta > 0.0, true),
                   joint_normal(ids.w, win_a, win_b, tb > 0.0, false));
#  endif
  gl_Position = quad_corner_position(win_a, win_b, reach, corner);
#endif
}
