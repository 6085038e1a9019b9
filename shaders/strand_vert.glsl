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

float view_depth_of(vec3 p)
{
  return -dot(object_to_view_z, vec4(p, 1.0));
}

/* The part in front of the near plane (docs/image_model.md §3.2) of the
 * segment between table points pa and pb (position, radius): the clip
 * positions `a`, `b` of its ends and `a_front`, `b_front` of the part's,
 * the fraction `cut` cut off at each end, and the view depths and radii
 * (scene units) at the part's ends, cut at the same parameters; false
 * where it lies wholly behind the near plane (or a coordinate is NaN). */
bool front_part(vec4 pa,
                vec4 pb,
                out vec4 a,
                out vec4 b,
                out vec4 a_front,
                out vec4 b_front,
                out vec2 cut,
                out vec2 depths,
                out vec2 radii)
{
  a = object_to_clip * vec4(pa.xyz, 1.0);
  b = object_to_clip * vec4(pb.xyz, 1.0);
  float depth_a = a.z + a.w, depth_b = b.z + b.w;
  a_front = a;
  b_front = b;
  cut = depths = radii = vec2(0.0);
  if (!(depth_a >= 0.0 || depth_b >= 0.0)) {
    return false;
  }
  cut = vec2((depth_a < 0.0) ? depth_a / (depth_a - depth_b) : 0.0, (depth_b < 0.0) ? depth_b / (depth_b - depth_a) : 0.0);
  if (depth_a < 0.0) {
    a_front = near_clipped(a, b, depth_a, depth_b);
  }
  if (depth_b < 0.0) {
    b_front = near_clipped(b, a, depth_b, depth_a);
  }
  float za = view_depth_of(pa.xyz), zb = view_depth_of(pb.xyz);
  float ra = max(pa.w, 0.0) * RADIUS_SCALE, rb = max(pb.w, 0.0) * RADIUS_SCALE;
  depths = vec2(mix(za, zb, cut.x), mix(zb, za, cut.y));
  radii = vec2(mix(ra, rb, cut.x), mix(rb, ra, cut.y));
  return true;
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
 * segments would both paint the pixels they share: one of them keeps each
 * such pixel (strand_frag.glsl, keeps_joint_pixel), by the larger
 * intensity there, and where the two tie, by the side of the bisector of
 * the joint: the plane through the joint whose normal is the sum of the
 * two unit directions (the pixels nearer its own segment's line). (0, 0):
 * no split (no neighbour, the joint is behind the near plane, or the
 * strand turns back on itself). A neighbour behind the near plane counts
 * by the part of its segment in front, as that segment draws itself, so
 * the two segments of a joint always find the same bisector. */
vec2 joint_normal(float neighbour, vec4 joint, vec2 win_a, vec2 win_b, bool clipped, bool at_a)
{
  if (neighbour < 0.0 || clipped) {
    return vec2(0.0);
  }
  vec4 n = object_to_clip * vec4(fetch_texel(vertex_positions, int(neighbour)).xyz, 1.0);
  float depth_n = n.z + n.w, depth_joint = joint.z + joint.w;
  if (!(depth_n >= 0.0)) {
    if (!(depth_n < 0.0)) {
      return vec2(0.0); /* (NaN) */
    }
    n = near_clipped(n, joint, depth_n, depth_joint);
  }
  vec2 win_n = window_point(n);
  vec2 along = win_b - win_a;
  vec2 other = at_a ? win_a - win_n : win_n - win_b;
  if (dot(along, along) == 0.0 || dot(other, other) == 0.0) {
    return vec2(0.0);
  }
  return normalize(along) + normalize(other);
}

/* The segment from point `joint` to point `neighbour` (the one the
 * joint shares with this segment), as the fragment stage's joint_sample
 * reads it: its front part's window points from the joint's end
 * (`window`: joint xy, far xy), their clip w and view depths (`depth`:
 * w joint, w far, depth joint, depth far; w -1: no neighbour, or it lies
 * wholly behind the near plane) and radii. */
void neighbour_from_joint(float joint, float neighbour, out vec4 window, out vec4 depth, out vec2 radii)
{
  window = vec4(0.0);
  depth = vec4(-1.0, -1.0, 0.0, 0.0);
  radii = vec2(0.0);
  vec4 a, b, a_front, b_front;
  vec2 cut, depths;
  if (neighbour < 0.0 || !front_part(fetch_texel(vertex_positions, int(joint)),
                                     fetch_texel(vertex_positions, int(neighbour)),
                                     a,
                                     b,
                                     a_front,
                                     b_front,
                                     cut,
                                     depths,
                                     radii))
  {
    return;
  }
  window = vec4(window_point(a_front), window_point(b_front));
  depth = vec4(a_front.w, b_front.w, depths);
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
  vec4 a, b, a_front, b_front;
  vec2 cut, depths, radii;
  if (!front_part(fetch_texel(vertex_positions, int(ids.x)),
                  fetch_texel(vertex_positions, int(ids.y)),
                  a,
                  b,
                  a_front,
                  b_front,
                  cut,
                  depths,
                  radii))
  {
    gl_Position = COLLAPSED; /* wholly behind the near plane (or NaN) */
    return;
  }
  seg_a = a_front;
  seg_b = b_front;
  seg_depth = depths;
  seg_radius = radii;
  edge_setup(a, b, seg_line, seg_span);
  /* The widest half-width is at an end: r / w is monotonic along a segment. */
  float wa_inv = 1.0 / max(a_front.w, 1e-6), wb_inv = 1.0 / max(b_front.w, 1e-6);
  float half_a = max(half_thickness_at(seg_depth.x, wa_inv), seg_radius.x * PX_PER_UNIT * wa_inv);
  float half_b = max(half_thickness_at(seg_depth.y, wb_inv), seg_radius.y * PX_PER_UNIT * wb_inv);
  float reach = min(max(half_a, half_b), 16384.0) + 2.0 * params.softness + 1.0;
  vec2 win_a = window_point(a_front), win_b = window_point(b_front);
#  ifdef STRAND_OVERLAY
  seg_split = vec4(joint_normal(ids.z, a, win_a, win_b, cut.x > 0.0, true),
                   joint_normal(ids.w, b, win_a, win_b, cut.y > 0.0, false));
  seg_points = ids;
  vec4 window_a, depth_a, window_b, depth_b;
  vec2 radii_a, radii_b;
  neighbour_from_joint(ids.x, ids.z, window_a, depth_a, radii_a);
  neighbour_from_joint(ids.y, ids.w, window_b, depth_b, radii_b);
  neighbour_a_window = window_a;
  neighbour_a_depth = depth_a;
  neighbour_b_window = window_b;
  neighbour_b_depth = depth_b;
  neighbour_radii = vec4(radii_a, radii_b);
#  endif
  gl_Position = quad_corner_position(win_a, win_b, reach, corner);
#endif
}
