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

#define PX_PER_UNIT strand_view.x

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
/* A strand segment at p: the intensity at its nearest point q, with the
 * depth of the tube's front there and q in clip space. */
float segment_sample(vec2 p, out float depth, out vec4 clip_position)
{
  vec2 wa = window_point(seg_a), wb = window_point(seg_b);
#  ifdef STRAND_OVERLAY
  /* This segment's side of each joint (strand_vert.glsl, joint_normal). */
  if (dot(p - wa, seg_split.xy) < 0.0 || dot(p - wb, seg_split.zw) > 0.0) {
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
 * Blender drew; blended "over". */
void write_overlay(vec4 color, float depth)
{
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
