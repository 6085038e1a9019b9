/* Instanced variant of the exact path (see shaders.py): prepended to both
 * stage sources, with SW_INSTANCE_SLOT defined per stage by the loader.
 *
 * `object_to_clip` / `object_to_view_z` become calls that read the
 * instance's values from `instance_table` (INSTANCE_TEXELS = 9 texels per
 * instance: the four columns of the float64-composed object -> clip matrix
 * rounded to float32, the view-z row, then the normal matrix's three
 * columns and the item info (colour-table base, mirrored); exactly the values the
 * per-object path passes as push constants, so both paths draw the same
 * image). They are fetched once per invocation and kept in globals. The
 * vertex stage finds its instance by gl_InstanceID and hands it to the
 * fragment stage (n-gon outlines are set up there) in `instance_slot`. */

#define object_to_clip sw_instance_to_clip()
#define object_to_view_z sw_instance_to_view_z()
#define normal_to_view sw_instance_normal_to_view()
#define item_info sw_instance_item_info()

vec4 fetch_texel(sampler2D table, int index);

mat4 sw_clip_matrix;
vec4 sw_view_z;
mat4 sw_normal_matrix;
vec4 sw_item_info;
bool sw_loaded = false;

void sw_load_instance()
{
  if (sw_loaded) {
    return;
  }
  sw_loaded = true;
  int slot = SW_INSTANCE_SLOT;
  sw_clip_matrix = mat4(fetch_texel(instance_table, slot),
                        fetch_texel(instance_table, slot + 1),
                        fetch_texel(instance_table, slot + 2),
                        fetch_texel(instance_table, slot + 3));
  sw_view_z = fetch_texel(instance_table, slot + 4);
  sw_normal_matrix = mat4(fetch_texel(instance_table, slot + 5),
                          fetch_texel(instance_table, slot + 6),
                          fetch_texel(instance_table, slot + 7),
                          vec4(0.0, 0.0, 0.0, 1.0));
  sw_item_info = fetch_texel(instance_table, slot + 8);
}

mat4 sw_instance_normal_to_view()
{
  sw_load_instance();
  return sw_normal_matrix;
}

vec4 sw_instance_item_info()
{
  sw_load_instance();
  return sw_item_info;
}

mat4 sw_instance_to_clip()
{
  sw_load_instance();
  return sw_clip_matrix;
}

vec4 sw_instance_to_view_z()
{
  sw_load_instance();
  return sw_view_z;
}
