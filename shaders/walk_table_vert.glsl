/* Walk-table pre-pass, vertex stage (docs/dev/how-it-works.md, "Walked
 * regions"): one point per triangle runs the exact path's corner code as
 * the triangle's provoking corner (solidwire_vert.glsl, compiled as
 * solidwire_corner() with every varying a plain global, SW_VERTEX_ID the
 * provoking corner's number) and hands on which segments of its region's
 * block select_segments() kept. The direct draw then reads them
 * (read_walk_table) instead of choosing at every corner: a CPU rasteriser
 * shades corners in SIMD batches, where the provoking corner's loop over
 * the whole block held up the two others of its triangle.
 *
 * The table's texel of triangle t is (t mod 2^WALK_TABLE_SHIFT, t >>
 * WALK_TABLE_SHIFT): x the count (-1: the fragment stage walks the whole
 * block; 0 outside a walked region), y, z, w two picks each, the first
 * plus WALK_PICK_BASE times the second (float32 holds them exactly). */

void main()
{
  for (int slot = 0; slot < SEGMENT_SLOTS; slot++) {
    walk_picks[slot] = 0;
  }
  solidwire_corner();
  int kept = segment_count;
  int block = edge_flags >> NGON_SHIFT;
  if (block > WALK_PICK_BASE) {
    kept = min(kept, -1); /* (picks past the packing's range: walk the whole block) */
  }
  float base = float(WALK_PICK_BASE);
  walk_pick = vec4(float(kept),
                   float(walk_picks[0]) + base * float(walk_picks[1]),
                   float(walk_picks[2]) + base * float(walk_picks[3]),
                   float(walk_picks[4]) + base * float(walk_picks[5]));
  int triangle = gl_VertexID;
  int row = triangle >> WALK_TABLE_SHIFT;
  vec2 texel = vec2(float(triangle - (row << WALK_TABLE_SHIFT)), float(row)) + 0.5;
  gl_Position = vec4(texel / vec2(walk_table_size) * 2.0 - 1.0, 0.0, 1.0);
  gl_PointSize = 1.0;
}
