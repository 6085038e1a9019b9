/* Walk-table groups, fragment stage: the group's box into its texel
 * (walk_groups_vert.glsl). */

void main()
{
  frag_color = group_box;
}
