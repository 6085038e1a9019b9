/* Region lines, vertex stage (docs/image_model.md §2.6): one screen-space
 * quad (two triangles, six corners) per entry of `region_lines` around the
 * window segment of its near-clipped edge, widened by the reach of the
 * entry's line style. The entry is gl_VertexID / 6; an instanced draw
 * repeats every entry for each instance. */

/* Outside the clip volume: the rasteriser drops the triangle. */
const vec4 COLLAPSED = vec4(2.0, 2.0, 2.0, 1.0);

/* The window length of an edge's near-clipped projection (the density
 * fade's chain length). */
float projected_length(float id_a, float id_b)
{
  vec3 line;
  vec2 span;
  edge_setup(vertex_clip(id_a), vertex_clip(id_b), line, span);
  return span.y - span.x;
}

void main()
{
  int entry = gl_VertexID / 6;
  int corner = quad_corner;
  if (entry >= line_count) {
    /* The batch's padding (an instanced draw draws all of it): read no
     * table past its end. */
    gl_Position = COLLAPSED;
    return;
  }
  vec4 head = fetch_texel(region_lines, 2 * entry);
  vec4 tail = fetch_texel(region_lines, 2 * entry + 1);
  vec4 a = vertex_clip(head.x), b = vertex_clip(head.y);
  vec3 line;
  vec2 span;
  /* The surface's own set-up (lower id first, so patterns run from the
   * lower-id end): the same bits as a block walk would compute. */
  edge_setup(a, b, line, span);
  if (dot(line.xy, line.xy) == 0.0) {
    gl_Position = COLLAPSED; /* wholly behind the near plane, or a point */
    return;
  }
  line_equation = line;
  line_span = span;
  line_style = int(head.z);
  line_regions = vec2(head.w, tail.z);
#ifdef USE_DENSITY_FADE
  line_chain = projected_length(tail.x, tail.y);
#else
  line_chain = 0.0;
#endif
#ifdef SW_INSTANCED
  line_instance = float(gl_InstanceID);
#endif

  /* The widest the style's line can be here, plus its 2s fall-off (the
   * profile is 0 beyond it) and a hundredth of a pixel for rounding: every
   * sample the profile reaches lies inside the quad, and no more. */
  float depth_a = a.z + a.w, depth_b = b.z + b.w;
  vec4 a_front = (depth_a < 0.0) ? mix(a, b, depth_a / (depth_a - depth_b)) : a;
  vec4 b_front = (depth_b < 0.0) ? mix(b, a, depth_b / (depth_b - depth_a)) : b;
  float half_width = max(params.half_thickness, params.half_thickness_far);
#if THICKNESS_MODE == 1
  half_width = params.world_half_thickness_px / max(min(a_front.w, b_front.w), 1e-6);
#endif
  half_width = style_half_thickness(line_style, half_width);
  float reach = half_width + 2.0 * params.softness + 0.01;

  vec2 dir = vec2(-line.y, line.x);
  vec2 foot = -line.z * line.xy + viewport_centre(); /* the line's point nearest the centre */
  vec2 wa = foot + span.x * dir, wb = foot + span.y * dir;
  vec2 normal = line.xy;
  /* corners 0..5: (a,-), (b,-), (b,+), (a,-), (b,+), (a,+) */
  bool at_b = (corner == 1 || corner == 2 || corner == 4);
  bool plus = (corner == 2 || corner == 4 || corner == 5);
  vec2 w = (at_b ? wb + dir * reach : wa - dir * reach) + normal * (plus ? reach : -reach);
  gl_Position = vec4((w - params.viewport.xy) / params.viewport.zw * 2.0 - 1.0, 0.0, 1.0);
}
