/* Region lines, vertex stage (docs/image_model.md §2.6): one screen-space
 * quad (two triangles over four shared corners, draw.indexed_quad_batch)
 * per *run* of the `region_lines` table:
 * up to RUN_SEGMENTS (1, 2, 4 or 8) consecutive entries of one chain (a
 * cage edge cut by subdivision), one style and one pair of regions. The
 * quad covers every entry's window segment widened by the reach of the
 * style's line; each segment's own set-up goes to the fragment stage, which
 * takes the strongest of the run's lines. A rasteriser then pays for one
 * primitive per run instead of one per segment, and the overlapping caps of
 * a chain's short segments are shaded once. The run is gl_VertexID / 4 (an
 * indexed draw: gl_VertexID is the corner's index);
 * its texel (first entry's texel, entries) leads the table. An instanced
 * draw repeats every run for each instance. */

/* Outside the clip volume: the rasteriser drops the triangle. */
const vec4 COLLAPSED = vec4(2.0, 2.0, 2.0, 1.0);
/* An unused slot of the run: a line so far away that its profile is 0. */
const vec4 NO_SEGMENT = vec4(0.0, 0.0, 1.0e6, 0.0);

/* The window length of an edge's near-clipped projection (the density
 * fade's chain length). */
float projected_length(float id_a, float id_b)
{
  vec3 line;
  vec2 span;
  edge_setup(vertex_clip(id_a), vertex_clip(id_b), line, span);
  return span.y - span.x;
}

#if THICKNESS_MODE == 1
/* The least clip w of a point of run `run`'s regions in front of the near
 * plane: a line in world widths is as wide as the visible point it lies on
 * is near (image model §4.2), and that point may be any point of its
 * regions, not just of its edge. From the sphere around them
 * (core/edge_select.py run_bounds): clip w is linear in the position, so
 * it falls from the centre's by the radius times the length of its
 * gradient. */
float regions_nearest_w(int run)
{
  vec4 sphere = fetch_texel(run_bounds, run);
  mat4 to_clip = object_to_clip;
  vec4 w_row = vec4(to_clip[0][3], to_clip[1][3], to_clip[2][3], to_clip[3][3]);
  return max(dot(w_row, vec4(sphere.xyz, 1.0)) - sphere.w * length(w_row.xyz), near_plane_w());
}

float run_nearest_w; /* regions_nearest_w of the run, set by main() */
#endif

/* What the quad of a run is built from, segment by segment. */
struct RunBox {
  vec2 along;    /* the frame: the run's chord (or its first drawn segment) ... */
  vec2 across;   /* ... and its normal */
  vec2 low;      /* (along, across) bounds of the segments' window points */
  vec2 high;
  float reach;   /* the widest reach of the run's segments */
  bool oriented; /* the frame is set */
  bool drawn;    /* a segment was drawn */
};

/* Set up the segment of the entry at `texel` (`used`: the run has it) into
 * `line_out` (line, span start) and `end_out` (span end), and widen `box`
 * by it. */
void run_segment(int texel, bool used, float half_width, inout RunBox box, out vec4 line_out, out float end_out)
{
  line_out = NO_SEGMENT;
  end_out = 0.0;
  if (!used) {
    return;
  }
  vec4 entry = fetch_texel(region_lines, texel);
  vec4 a = vertex_clip(entry.x), b = vertex_clip(entry.y);
  vec3 line;
  vec2 span;
  /* The surface's own set-up (lower id first, so patterns run from the
   * lower-id end): the same bits as a block walk would compute. */
  edge_setup(a, b, line, span);
  if (dot(line.xy, line.xy) == 0.0) {
    return; /* wholly behind the near plane */
  }
  line_out = vec4(line, span.x);
  end_out = span.y;
  /* The widest the style's line can be here, plus its 2s fall-off (the
   * profile is 0 beyond it) and a hundredth of a pixel for rounding: every
   * sample the profile reaches lies inside the quad. */
#if THICKNESS_MODE == 1
  /* (The segment's own nearer end too: its regions' spheres hold it, but
   * not through float32 rounding.) */
  float depth_a = a.z + a.w, depth_b = b.z + b.w;
  vec4 a_front = (depth_a < 0.0) ? near_clipped(a, b, depth_a, depth_b) : a;
  vec4 b_front = (depth_b < 0.0) ? near_clipped(b, a, depth_b, depth_a) : b;
  float nearest_w = min(min(a_front.w, b_front.w), run_nearest_w);
  half_width = style_half_thickness(line_style, params.world_half_thickness_px / max(nearest_w, 1e-6));
#endif
  box.reach = max(box.reach, half_width + 2.0 * params.softness + 0.01);
  vec2 dir = vec2(-line.y, line.x);
  vec2 foot = -line.z * line.xy; /* the line's point nearest the centre */
  if (!box.oriented) {
    box.along = dir;
    box.across = line.xy;
    box.oriented = true;
  }
  box.drawn = true;
  vec2 wa = foot + span.x * dir, wb = foot + span.y * dir;
  vec2 qa = vec2(dot(wa, box.along), dot(wa, box.across));
  vec2 qb = vec2(dot(wb, box.along), dot(wb, box.across));
  box.low = min(box.low, min(qa, qb));
  box.high = max(box.high, max(qa, qb));
}

void main()
{
  int run = gl_VertexID / 4;
  int corner = quad_corner;
  if (run < line_first || run >= line_count) {
    /* Runs this draw leaves to another (draw.ALL_RUNS...) and the batch's
     * padding (an instanced draw draws all of it): read no table past its
     * end. */
    gl_Position = COLLAPSED;
    return;
  }
  vec4 run_texel = fetch_texel(region_lines, run);
  int first = int(run_texel.x);
  int count = int(run_texel.y);
  vec4 head = fetch_texel(region_lines, first);
  vec4 tail = fetch_texel(region_lines, first + 1);
  line_style = int(head.z);
  line_regions = vec2(head.w, tail.z);
#ifdef USE_DENSITY_FADE
  line_chain = projected_length(tail.x, tail.y); /* one chain per run */
#else
  line_chain = 0.0;
#endif
#ifdef SW_INSTANCED
  line_instance = float(gl_InstanceID);
#endif
#ifdef ITEM_COLORS
  /* A hidden layer's colour: its object's wire colour (core/colors.py). */
  item_wire = fetch_texel(item_colors, int(item_info.x)).rgb;
#endif
  run_length = count;

  float half_width = style_half_thickness(line_style, max(params.half_thickness, params.half_thickness_far));
#if THICKNESS_MODE == 1
  run_nearest_w = regions_nearest_w(run);
#endif
  RunBox box = RunBox(vec2(1.0, 0.0), vec2(0.0, 1.0), vec2(1e30), vec2(-1e30), 0.0, false, false);
  /* The frame along the chord from the first segment's middle to the
   * last's: a chain's box is then as narrow as its bend (the first
   * segment's direction, where the chord is not in front of the camera or
   * is too short to say). */
#if RUN_SEGMENTS > 1
  if (count > 1) {
    vec4 last = fetch_texel(region_lines, first + 2 * (count - 1));
    vec4 from = vertex_clip(head.x) + vertex_clip(head.y), to = vertex_clip(last.x) + vertex_clip(last.y);
    if (from.w > 0.0 && to.w > 0.0) {
      vec2 chord = window_point(to) - window_point(from);
      if (dot(chord, chord) > 1.0) {
        box.along = normalize(chord);
        box.across = vec2(-box.along.y, box.along.x);
        box.oriented = true;
      }
    }
  }
#endif
  /* RUN_SEGMENTS (1, 2, 4 or 8): the most a run of this mesh holds. */
  run_segment(first, count > 0, half_width, box, run_line0, run_ends0.x);
#if RUN_SEGMENTS > 1
  run_segment(first + 2, count > 1, half_width, box, run_line1, run_ends0.y);
#endif
#if RUN_SEGMENTS > 2
  run_segment(first + 4, count > 2, half_width, box, run_line2, run_ends0.z);
  run_segment(first + 6, count > 3, half_width, box, run_line3, run_ends0.w);
#endif
#if RUN_SEGMENTS > 4
  run_segment(first + 8, count > 4, half_width, box, run_line4, run_ends1.x);
  run_segment(first + 10, count > 5, half_width, box, run_line5, run_ends1.y);
  run_segment(first + 12, count > 6, half_width, box, run_line6, run_ends1.z);
  run_segment(first + 14, count > 7, half_width, box, run_line7, run_ends1.w);
#endif
  if (!box.drawn) {
    gl_Position = COLLAPSED;
    return;
  }

  /* The box around every segment's window points, widened by the reach,
   * holds every segment's reach. */
  vec2 low = box.low - box.reach, high = box.high + box.reach;
  /* The window lies within its half diagonal of the centre, in this frame
   * as in any: past that the box covers no more of it. So a reach beyond
   * any rasteriser's range (a class thousands of times the wire's width,
   * image model §3.6, at a Thickness near 0) stays drawable, and a box
   * wholly outside draws nothing. */
  float window_radius = 0.5 * length(params.viewport.zw) + 1.0;
  low = max(low, vec2(-window_radius));
  high = min(high, vec2(window_radius));
  if (low.x > high.x || low.y > high.y) {
    gl_Position = COLLAPSED;
    return;
  }
  /* corners 0..3: (low,low), (high,low), (high,high), (low,high) */
  bool at_high = (corner == 1 || corner == 2);
  bool plus = (corner >= 2);
  vec2 w = viewport_centre() + box.along * (at_high ? high.x : low.x) + box.across * (plus ? high.y : low.y);
  gl_Position = vec4((w - params.viewport.xy) / params.viewport.zw * 2.0 - 1.0, 0.0, 1.0);
}
