/* Walk-table pre-pass, fragment stage: the point's picks into its texel
 * (walk_table_vert.glsl). */

void main()
{
  frag_color = walk_pick;
}
