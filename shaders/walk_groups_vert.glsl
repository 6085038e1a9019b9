/* Walk-table groups, vertex stage (docs/dev/how-it-works.md, "Walked
 * regions"): one point per group of up to WALK_GROUP consecutive segments
 * of a region block (core/cache.py, GPUMesh.walk_groups) writes the window
 * box of their ends, relative to the viewport centre as the walk's
 * triangles are, at the texel of the group's first segment. The walk-table
 * pre-pass then sets up no segment of a group whose box lies beyond reach
 * of a triangle's box. The box is a pixel wider on every side than the
 * ends: the walk measures the ends as the set-up rebuilds them, a rounding
 * away. Where an end lies behind the near plane (its clipped end may be
 * anywhere on its line) the box is the whole plane. */

void main()
{
  vec2 low = vec2(1.0e30), high = vec2(-1.0e30);
  vec2 centre = viewport_centre();
  for (int k = 0; k < WALK_GROUP; k++) {
    if (k >= group_size) {
      break;
    }
    vec4 segment = fetch_texel(ngon_corners, group_texel + SEGMENT_TEXELS * k);
    vec4 a = vertex_clip(segment.x), b = vertex_clip(segment.y);
#ifndef ALL_IN_FRONT
    if (!(a.z + a.w >= 0.0 && b.z + b.w >= 0.0)) {
      low = vec2(-1.0e30);
      high = vec2(1.0e30);
      break;
    }
#endif
    vec2 wa = window_point(a) - centre, wb = window_point(b) - centre;
    low = min(low, min(wa, wb));
    high = max(high, max(wa, wb));
  }
  group_box = vec4(low - 1.0, high + 1.0);
  int row = group_texel >> TABLE_ROW_SHIFT;
  vec2 texel = vec2(float(group_texel - (row << TABLE_ROW_SHIFT)), float(row)) + 0.5;
  gl_Position = vec4(texel / vec2(group_table_size) * 2.0 - 1.0, 0.0, 1.0);
  gl_PointSize = 1.0;
}
