/* SolidWire: definitions shared by the vertex and fragment stages.
 *
 * Window space is Blender's/GL's: pixel (i, j) covers [i, i+1] x [j, j+1] and
 * is sampled at its centre, which is what gl_FragCoord.xy holds. */

/* A distance that stands for "this edge does not exist here" (an edge wholly
 * behind the near plane, a diagonal that is not drawn). Its square still fits
 * in a float, so length() never overflows to inf/NaN. */
#define NO_EDGE 1.0e17

/* Bits of the per-corner `edge_flags` attribute (see extract.py). */
#define EDGE0_REAL 1  /* edge p0-p1 is a polygon boundary edge */
#define EDGE1_REAL 2  /* edge p1-p2 */
#define EDGE2_REAL 4  /* edge p2-p0 */
#define HAS_QUAD_CORNER 8 /* p3 is the 4th corner of a quad: p2-p3, p3-p0 are real */
#define IS_NGON 16 /* part of a polygon with more than 4 corners; see NGON_SHIFT */
#define NGON_SHIFT 13 /* edge_flags >> NGON_SHIFT: the n-gon's corner count, or a block's segment count */
#define EDGE3_HIDDEN 64 /* a quad's p2-p3 is not drawn (edge angle, cage): no line, no diagonal */
#define EDGE4_HIDDEN 128 /* a quad's p3-p0 likewise */
#define EDGE0_HIDDEN 256 /* the triangle's own edge k is a polygon edge that is not drawn: 256 << k */
/* The triangle walks a block of segments (its region's drawn edges, each
 * with its line style, and the diagonals of n-gons in it) starting at
 * ngon_corner_start; see core/edge_select.py. */
#define IN_REGION 2048
/* The triangle's lines come from the region-lines pass where one ran
 * (REGION_LINES variant); its block then starts with its diagonals. */
#define REGION_LINES 4096
/* IN_REGION with HAS_QUAD_CORNER: a face of its own with a classed edge
 * (core/edge_select.py OWN_EDGES_MEASURED). It measures its own edges as a
 * plain triangle does, all but the classed ones (marked hidden), which its
 * block holds; the block starts with the face's corners (a segment's
 * texels), the quad's 4th among them. */
#define OWN_EDGES_MEASURED (IN_REGION | HAS_QUAD_CORNER)
/* triangle_regions of a plain face: in no region (core/edge_select.py). */
#define NO_REGION -1.0
#define SEGMENT_TEXELS 2 /* (lower id, upper id, style, 0), (chain end, chain end, 0, 0) */
#define DIAGONAL_STYLE 15
/* Set by the vertex stage: the whole triangle (and a quad's 4th corner) is in
 * front of the near plane and its polygon projects convex, so line
 * distances are segment distances for every sample inside it. */
#define SIMPLE_TRIANGLE 32
/* The region lines' distance image (the Edge Distance pass over regions,
 * LINE_DISTANCE in region_lines_frag.glsl): a window distance d is kept as
 * the depth d * LINE_DISTANCE_SCALE, below the cleared 1.0 that means "no
 * line within reach". */
#define LINE_DISTANCE_SCALE (1.0 / 65536.0)
/* The largest float below 1.0: the nearest a written depth may come to the
 * cleared background. */
#define BELOW_ONE 0.99999994

/* Texel `index` of a table. A table longer than TABLE_WIDTH (4096) texels
 * is 4096 wide, a shorter one is a single row (core/cache.py, table_shape),
 * so texel i is at (i & 4095, i >> 12) in every table: no size query and no
 * integer division (a CPU rasteriser runs those lane by lane), with GLSL
 * every Blender backend translates. */
#define TABLE_ROW_SHIFT 12
vec4 fetch_texel(sampler2D table, int index)
{
  return texelFetch(table, ivec2(index & ((1 << TABLE_ROW_SHIFT) - 1), index >> TABLE_ROW_SHIFT), 0);
}

/* A triangle's edge flags from its texel of the flag table, which holds
 * them as two 12-bit halves (core/cache.py, GPUMesh.flag_table). */
#define TABLE_FLAGS(texel) (int((texel).x) | (int((texel).y) << 12))

/* Viewport overlay (docs/image_model.md §5.6): the change of window depth
 * that moves the point at view depth `view_depth` towards the camera by
 * min(allowance.x + allowance.y |d|, allowance.z + allowance.w |d|) scene
 * units (core/view.py, blender_depth_allowance: how far Blender's float32
 * depth of the same surface may stray, and the most a point may move),
 * for a projection whose depth `rows` are P22, P23, P32, P33 (clip
 * z = P23 - P22 d, clip w = P33 - P32 d). Exact for the projection:
 * window depth 0.5 z/w + 0.5 changes by
 * 0.5 s (P22 P33 - P23 P32) / (w(d - s) w(d)) when d becomes d - s. 0
 * where there is no allowance or the point is not in front of the eye. */
float window_depth_shift(float view_depth, vec4 allowance, vec4 rows)
{
  float slack = min(allowance.x + allowance.y * abs(view_depth), allowance.z + allowance.w * abs(view_depth));
  if (!(slack > 0.0)) { /* (also where the view depth is not a number) */
    return 0.0;
  }
  float w_here = rows.w - rows.z * view_depth;
  float w_moved = w_here + rows.z * slack;
  if (w_here <= 0.0 || w_moved <= 0.0) {
    return 0.0;
  }
  return 0.5 * slack * (rows.x * rows.w - rows.y * rows.z) / (w_moved * w_here);
}

/* The view depth of a point from its clip z (P22 is never 0). */
float view_depth_of_clip_z(float clip_z, vec4 rows)
{
  return (rows.y - clip_z) / rows.x;
}

/* The view depth of a point from its window depth (0.5 z/w + 0.5): with
 * n = z/w, n (P33 - P32 d) = P23 - P22 d. */
float view_depth_of_window_depth(float window_depth, vec4 rows)
{
  float ndc = 2.0 * window_depth - 1.0;
  return (rows.y - ndc * rows.w) / (rows.x - ndc * rows.z);
}

#ifdef WALK_PICK_BASE
/* Pick `slot` (0 to 5) of a walk-table texel's last three channels
 * (`pairs`; walk_table_frag.glsl): two a channel, the first plus
 * WALK_PICK_BASE times the second. */
int walk_table_pick(vec3 pairs, int slot)
{
  float pair = (slot < 2) ? pairs.x : ((slot < 4) ? pairs.y : pairs.z);
  float high = floor(pair / float(WALK_PICK_BASE));
  return int(((slot & 1) == 0) ? pair - high * float(WALK_PICK_BASE) : high);
}
#endif
