/* Walk-table pre-pass (docs/dev/how-it-works.md, "Walked regions"): one
 * fragment per texel of the table, the texel of triangle t being
 * (t mod 2^WALK_TABLE_SHIFT, t >> WALK_TABLE_SHIFT), drawn by a rectangle
 * over the rows the draw needs (resolve_vert.glsl). Each runs the exact
 * path's corner code as its triangle's provoking corner
 * (solidwire_vert.glsl, compiled as solidwire_corner() with every varying a
 * plain global and SW_VERTEX_ID the provoking corner's number, as the
 * resolve pass does) and writes which segments of its region's block
 * select_segments() kept. The direct draw then reads them
 * (read_walk_table) instead of choosing at every corner: a CPU rasteriser
 * shades corners in SIMD batches, where the provoking corner's loop over
 * the whole block held up the two others of its triangle. (A fragment
 * stage, not a point per triangle: a CPU rasteriser runs fragments on
 * every thread and sets up one rectangle, where it ran a vertex stage on
 * one thread and set up a point per triangle.)
 *
 * x the count (-1: the fragment stage walks the whole block; 0 outside a
 * walked region; -2 - n: it walks n groups of the block, those whose boxes
 * pass, where more than SEGMENT_SLOTS segments are near), y, z, w two
 * picks each (segments, or the groups' first segments), the first plus
 * WALK_PICK_BASE times the second (float32 holds them exactly). */

void main()
{
  ivec2 texel = ivec2(gl_FragCoord.xy);
  int triangle = (texel.y << WALK_TABLE_SHIFT) + texel.x;
  frag_color = vec4(0.0);
  if (triangle >= walk_triangle_count) {
    return;
  }
  edge_flags = TABLE_FLAGS(fetch_texel(triangle_flag_table, triangle));
#ifdef REGION_LAYERS_PEELED
  /* Left out of the draw before any set-up (solidwire_vert.glsl): no picks. */
  if ((edge_flags & REGION_LINES) != 0 && (edge_flags & OWN_EDGES_MEASURED) != OWN_EDGES_MEASURED) {
    return;
  }
#endif
  for (int slot = 0; slot < SEGMENT_SLOTS; slot++) {
    walk_picks[slot] = 0;
    walk_group_picks[slot] = 0;
  }
  sw_vertex_id = 3 * triangle + 2;
  solidwire_corner();
  int kept = segment_count;
  int block = edge_flags >> NGON_SHIFT;
  if (block > WALK_PICK_BASE) {
    kept = -1; /* (picks past the packing's range: walk the whole block) */
  }
  if (kept < -1) {
    for (int slot = 0; slot < SEGMENT_SLOTS; slot++) {
      walk_picks[slot] = walk_group_picks[slot];
    }
  }
  float base = float(WALK_PICK_BASE);
  frag_color = vec4(float(kept),
                    float(walk_picks[0]) + base * float(walk_picks[1]),
                    float(walk_picks[2]) + base * float(walk_picks[3]),
                    float(walk_picks[4]) + base * float(walk_picks[5]));
}
