/* SolidWire hair and point clouds: what both stages share
 * (strand_vert.glsl, strand_frag.glsl). */

/* Window pixels per scene unit at clip w = 1, and the object's radius scale. */
#define PX_PER_UNIT strand_view.x
#define RADIUS_SCALE strand_view.y

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
