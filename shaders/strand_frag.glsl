/* SolidWire hair and point clouds, fragment stage (docs/user/hair-and-points.md):
 *
 *   strand segment: d = window distance to the near-clipped segment, q its
 *     nearest point; I = P(d) with half-width max(h, projected radius at q);
 *   point: a disc of the projected radius around the centre's window
 *     position; the outline is P(|distance to the rim|), the inside is
 *     covered (fill colour with Fill on, shaded as a sphere by the fill
 *     shading).
 *
 * Occlusion: the primitive's depth (the front of the tube at q, the front of
 * the sphere for a point) against the surface depth at this pixel.
 * Render form: premultiplied colour plus (view depth, weight) in a second
 * target, and a depth key that lets the fragment with the largest weight win
 * (nearest on ties), so overlapping segments of one strand meet without a
 * seam. Overlay form: premultiplied "over" into the viewport, occluded by
 * the viewport's depth buffer. */

#ifdef STRAND_POINTS
/* A point's disc at p: the outline's intensity, with the depth of the
 * sphere's front, whether p is inside the disc and (for the clipping
 * region) the centre in clip space. */
float disc_sample(vec2 p, out float depth, out bool inside, out vec4 clip_position)
{
  float rim = length(p - disc.xy) - disc.z;
  inside = rim <= 0.0;
  float inv_w = disc_extra.y;
  /* The sphere's nearest point along the view axis: a point resting on a
   * surface is not cut in half by it. */
  depth = disc.w - disc_extra.x;
  float intensity = line_profile(abs(rim), half_thickness_at(disc.w, inv_w));
#  ifdef USE_FADE
  intensity *= depth_fade(disc.w);
#  endif
#  ifdef USE_CLIP_PLANES
  clip_position = disc_clip;
#  else
  clip_position = vec4(0.0);
#  endif
  return intensity;
}
#else
#  ifdef STRAND_OVERLAY
/* Intensities, and front depths relative to their size, closer than this
 * are a tie at a joint: well above float32's rounding, which may differ
 * between the two segments' evaluations of one sample (a compiler may
 * contract their arithmetic differently), and far below a visible step. */
const float JOINT_TIE = 1e-5;

/* The intensity at window point p of a segment measured from one of its
 * ends, the joint (`window`: the front part's window points, joint end
 * first; `depth`: their clip w and view depths; `radii`), and the depth of
 * the tube's front there: the render's measure from plain window points.
 * Both segments of a joint evaluate both of them this way, from the same
 * numbers (strand_vert.glsl, neighbour_from_joint, and their own), so
 * they agree up to JOINT_TIE. */
vec2 joint_sample(vec2 p, vec4 window, vec4 depth, vec2 radii)
{
  vec2 wa = window.xy, ab = window.zw - window.xy;
  float len2 = dot(ab, ab);
  float s = (len2 > 0.0) ? clamp(dot(p - wa, ab) / len2, 0.0, 1.0) : 0.0;
  float d = length(p - wa - s * ab);
  float u = s * depth.x / (s * depth.x + (1.0 - s) * depth.y);
  float inv_w = 1.0 / mix(depth.x, depth.y, u);
  float z = mix(depth.z, depth.w, u);
  float radius = mix(radii.x, radii.y, u);
  float intensity = line_profile(d, max(half_thickness_at(z, inv_w), radius * PX_PER_UNIT * inv_w));
#    ifdef USE_FADE
  intensity *= depth_fade(z);
#    endif
  return vec2(intensity, z - radius);
}

/* Whether this segment paints p near its joint with the neighbour
 * segment (`neighbour_*`: joint_sample's numbers, w -1: none), this one's
 * numbers from the same joint in `own_*`; `normal`: the joint's bisector
 * (strand_vert.glsl, joint_normal; (0, 0): none), the neighbour's side
 * where dot(p - joint_window, normal) * side < 0. As the render's winner:
 * the larger intensity (write_render's key), then the nearer front; where
 * both tie (JOINT_TIE), the bisector decides, and without one (a segment
 * of no length, a joint behind the near plane) the lower point number of
 * the two segments' other ends. (The render picks among the segments the
 * surface leaves visible; the overlay cannot see the viewport's depth
 * here, so where the winner is hidden, nothing of the two shows.) */
bool keeps_joint_pixel(vec2 p,
                       vec2 normal,
                       float side,
                       vec4 own_window,
                       vec4 own_depth,
                       vec2 own_radii,
                       vec4 neighbour_window,
                       vec4 neighbour_depth,
                       vec2 neighbour_radii,
                       float other,
                       float neighbour)
{
  if (neighbour_depth.x < 0.0) {
    return true; /* (no neighbour, or it draws nothing) */
  }
  vec2 theirs = joint_sample(p, neighbour_window, neighbour_depth, neighbour_radii);
  if (theirs.x <= 0.0) {
    return true; /* (the neighbour does not reach p) */
  }
  vec2 mine = joint_sample(p, own_window, own_depth, own_radii);
  if (abs(mine.x - theirs.x) > JOINT_TIE) {
    return mine.x > theirs.x;
  }
  if (abs(mine.y - theirs.y) > JOINT_TIE * max(abs(mine.y), abs(theirs.y))) {
    return mine.y < theirs.y;
  }
  if (normal == vec2(0.0)) {
    return other <= neighbour; /* (both where the strand turns back onto itself) */
  }
  return dot(p - own_window.xy, normal) * side >= 0.0;
}
#  endif

/* A strand segment at p: the intensity at its nearest point q, with the
 * depth of the tube's front there and q in clip space. */
float segment_sample(vec2 p, out float depth, out vec4 clip_position)
{
  vec2 wa = window_point(seg_a), wb = window_point(seg_b);
#  ifdef STRAND_OVERLAY
  /* The pixels of each joint this segment paints (keeps_joint_pixel). */
  vec4 own_depth = vec4(seg_a.w, seg_b.w, seg_depth);
  if (!keeps_joint_pixel(p,
                         seg_split.xy,
                         1.0,
                         vec4(wa, wb),
                         own_depth,
                         seg_radius,
                         neighbour_a_window,
                         neighbour_a_depth,
                         neighbour_radii.xy,
                         seg_points.y,
                         seg_points.z) ||
      !keeps_joint_pixel(p,
                         seg_split.zw,
                         -1.0,
                         vec4(wb, wa),
                         own_depth.yxwz,
                         seg_radius.yx,
                         neighbour_b_window,
                         neighbour_b_depth,
                         neighbour_radii.zw,
                         seg_points.x,
                         seg_points.w))
  {
    discard;
  }
#  endif
  /* The distance from the segment's window line and span (edge_setup):
   * a near-clipped end can lie 10^5 px off-screen, and measuring from that
   * window point would carry its float32 rounding (about 0.01 px there)
   * into every pixel's distance. A segment along a view ray has no line:
   * it is the disc around its window point. */
  float d, s = 0.0;
  if (seg_line.z == NO_EDGE) {
    d = length(p - wa);
  }
  else {
    vec2 pc = p - viewport_centre();
    float across = dot(seg_line, vec3(pc, 1.0));
    float along = dot(vec2(-seg_line.y, seg_line.x), pc);
    float beyond = max(max(seg_span.x - along, along - seg_span.y), 0.0);
    d = sqrt(across * across + beyond * beyond);
    float span_length = seg_span.y - seg_span.x;
    s = (span_length > 0.0) ? clamp((along - seg_span.x) / span_length, 0.0, 1.0) : 0.0;
  }
  /* Window parameter s -> parameter u along the clip-space segment
   * (perspective-correct). */
  float u = s * seg_a.w / (s * seg_a.w + (1.0 - s) * seg_b.w);
  float inv_w = 1.0 / mix(seg_a.w, seg_b.w, u);
  float q_depth = mix(seg_depth.x, seg_depth.y, u);
  float radius = mix(seg_radius.x, seg_radius.y, u);
  depth = q_depth - radius;
  float intensity = line_profile(d, max(half_thickness_at(q_depth, inv_w), radius * PX_PER_UNIT * inv_w));
#  ifdef USE_FADE
  intensity *= depth_fade(q_depth);
#  endif
  clip_position = mix(seg_a, seg_b, u);
  return intensity;
}
#endif

/* Outside the viewport's clipping region (docs/image_model.md §5.6): a
 * point by its centre, a strand at its nearest point q. */
bool outside_clip_region(vec4 clip_position)
{
#ifdef USE_CLIP_PLANES
  for (int k = 0; k < 6; k++) {
    if (dot(clip_params.planes[k], clip_position) < 0.0) {
      return true;
    }
  }
#endif
  return false;
}

/* Premultiplied wire colour at `intensity`; a filled point's inside is
 * the fill (shaded as the sphere it stands for) under it. */
vec4 strand_colour(vec2 p, float intensity, bool inside)
{
  float a = intensity * params.wire_color.a;
  vec4 color = vec4(params.wire_color.rgb * a, a);
#if defined(STRAND_POINTS) && defined(USE_FILL)
  if (inside) {
    vec3 fill = params.fill_color.rgb;
#  if defined(SHADING) && SHADING != 0
    /* The sphere's normal under this pixel (view space, +z to the camera;
     * the disc's window offset over its radius). */
    vec2 offset = clamp((p - disc.xy) / max(disc.z, 1e-6), -1.0, 1.0);
    shading_normal = vec3(offset, sqrt(max(1.0 - dot(offset, offset), 0.0)));
    item_info = vec4(0.0);
    fill = shaded_fill(fill);
#  endif
    color = vec4(params.wire_color.rgb * a + fill * (1.0 - a), 1.0);
  }
#endif
  return color;
}

#ifdef STRAND_OVERLAY
/* Viewport: the window depth of `depth`, moved towards the camera by the
 * overlay's depth bias (as the mesh wire), tested LESS_EQUAL against what
 * Blender drew; blended "over". A front nearer than the near plane (the
 * camera inside a wide tube or sphere) is at the near plane: it hides
 * nothing of ours there, and nothing of Blender's can lie nearer. */
void write_overlay(vec4 color, float depth)
{
  depth = max(depth, near_plane_depth());
  float clip_z = -params.depth_rows.x * depth + params.depth_rows.y;
  float clip_w = -params.depth_rows.z * depth + params.depth_rows.w;
  float shift = window_depth_shift(depth, params.blender_depth_allowance, params.depth_rows);
  gl_FragDepth = clamp(0.5 * (clip_z / clip_w) + 0.5 - 0.5 * STRAND_OVERLAY + shift, 0.0, 1.0);
  frag_color = color;
#  ifdef DISPLAY_TRANSFORM
  frag_color = display_transform(frag_color);
#  endif
}
#else
/* Render: hidden where the surface depth at p is nearer; the depth key
 * lets the largest weight win, the nearest next: the weight in 1/1024
 * steps, the depth within a step (float32 keeps ~6e-5 of the clip range
 * there). */
void write_render(vec2 p, vec4 color, float depth, float weight)
{
  float key_depth = depth * params.inv_clip_end;
  float scene = texelFetch(scene_depth, ivec2(p), 0).r;
  if (key_depth > scene) {
    discard; /* a nearer surface (or the far plane) hides it here */
  }
  gl_FragDepth = (floor((1.0 - weight) * 1023.0) + clamp(key_depth, 0.0, 0.999)) / 1024.0;
  frag_color = color;
  frag_info = vec4(depth, weight, 0.0, 0.0);
}
#endif

void main()
{
  vec2 p = gl_FragCoord.xy;
  float depth;
  bool inside = false;
  vec4 clip_position;
#ifdef STRAND_POINTS
  float intensity = disc_sample(p, depth, inside, clip_position);
#else
  float intensity = segment_sample(p, depth, clip_position);
#endif
  if (outside_clip_region(clip_position)) {
    discard;
  }
  float weight = inside ? 1.0 : intensity;
  if (weight <= 0.0) {
    discard;
  }
  vec4 color = strand_colour(p, intensity, inside);
#ifdef STRAND_OVERLAY
  write_overlay(color, depth);
#else
  write_render(p, color, depth, weight);
#endif
}
