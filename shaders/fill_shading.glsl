/* Fill shading and per-object colours (docs/image_model.md §5.8).
 *
 *   SHADING 0  flat: the base colour as is (§5.2)
 *   SHADING 1  STUDIO: Lambert from three lights fixed to the camera plus
 *              ambient; the constants are §5.8's, and the float64 reference
 *              (tests/support/reference.py) uses the same numbers
 *   SHADING 2  MATCAP: base * diffuse(uv) + specular(uv), each pass
 *              sampled at uv = n.xy / 2 + 1/2, bilinear between texel
 *              centres, clamped at the border (matcap_image holds the
 *              diffuse pass in its lower half, the specular in the upper)
 * n is the interpolated corner normal in view space, normalised, and turned
 * towards the camera where the back side of the face is seen. */

#if SHADING == 1
#  define STUDIO_AMBIENT 0.25
#  define STUDIO_KEY vec3(-0.35, 0.55, 0.75)
#  define STUDIO_KEY_POWER 0.6
#  define STUDIO_FILL vec3(0.6, 0.1, 0.8)
#  define STUDIO_FILL_POWER 0.2
#  define STUDIO_RIM vec3(0.0, 0.8, -0.6)
#  define STUDIO_RIM_POWER 0.15

float studio_light(vec3 n)
{
  return STUDIO_AMBIENT + STUDIO_KEY_POWER * max(dot(n, normalize(STUDIO_KEY)), 0.0) +
         STUDIO_FILL_POWER * max(dot(n, normalize(STUDIO_FILL)), 0.0) +
         STUDIO_RIM_POWER * max(dot(n, normalize(STUDIO_RIM)), 0.0);
}
#endif

#if SHADING == 2
vec3 matcap_sample(vec2 uv, int row0)
{
  /* Explicit bilinear filter (texel centres at (i + 1/2) / size, clamped to
   * the border texels of the pass), so the result does not depend on
   * sampler state. */
  ivec2 size = textureSize(matcap_image, 0);
  size.y /= 2;
  vec2 x = uv * vec2(size) - 0.5;
  vec2 base = floor(x);
  vec2 t = x - base;
  ivec2 i0 = clamp(ivec2(base), ivec2(0), size - 1);
  ivec2 i1 = clamp(ivec2(base) + 1, ivec2(0), size - 1);
  i0.y += row0;
  i1.y += row0;
  vec3 c00 = texelFetch(matcap_image, i0, 0).rgb;
  vec3 c10 = texelFetch(matcap_image, ivec2(i1.x, i0.y), 0).rgb;
  vec3 c01 = texelFetch(matcap_image, ivec2(i0.x, i1.y), 0).rgb;
  vec3 c11 = texelFetch(matcap_image, i1, 0).rgb;
  return mix(mix(c00, c10, t.x), mix(c01, c11, t.x), t.y);
}
#endif

vec3 shaded_fill(vec3 base)
{
#if SHADING == 0
  return base;
#else
  vec3 n = shading_normal;
  float len = length(n);
  n = len > 1e-20 ? n / len : vec3(0.0, 0.0, 1.0);
  /* item_info.y: the object (with the view) mirrors, so GL's facing is the
   * opposite of the face's own front side (see draw.py). */
  bool front = SW_FRONT_FACING != (item_info.y > 0.5);
  if (!front) {
    n = -n;
  }
#  if SHADING == 1
  return base * studio_light(n);
#  else
  vec2 uv = n.xy * 0.5 + 0.5;
  return base * matcap_sample(uv, 0) + matcap_sample(uv, textureSize(matcap_image, 0).y / 2);
#  endif
#endif
}
