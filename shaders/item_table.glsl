/* Per-object shading data of the non-instanced path (see shaders.py),
 * prepended to both stages of variants that shade the fill or take colour
 * sources: `normal_to_view` and `item_info` are read from `item_table`
 * (ITEM_TEXELS = 4 texels per drawn object: the normal matrix's three
 * columns, then (colour-table base, mirrored, 0, 0)) at the object's
 * `item_slot`, so the push constants stay within the 128 bytes every GPU
 * backend guarantees. The instanced path keeps the same values in its
 * instance table (instancing.glsl). */

#define normal_to_view sw_item_normal_to_view()
#define item_info sw_item_info()

vec4 fetch_texel(sampler2D table, int index);

mat4 sw_item_normal_to_view()
{
  int slot = 4 * item_slot;
  return mat4(fetch_texel(item_table, slot),
              fetch_texel(item_table, slot + 1),
              fetch_texel(item_table, slot + 2),
              vec4(0.0, 0.0, 0.0, 1.0));
}

vec4 sw_item_info()
{
  return fetch_texel(item_table, 4 * item_slot + 3);
}
