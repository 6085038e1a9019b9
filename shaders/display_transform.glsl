/* SolidWire viewport colour management (docs/image_model.md §9): the
 * scene's view transform, look, exposure, gamma and display, applied to the
 * overlay's colour as the last step of its fragment stages, so that the
 * viewport shows the colours of the F12 render.
 *
 * Compiled only into the overlay's variants (DISPLAY_TRANSFORM); the render
 * stays scene-linear (Blender colour-manages renders itself).
 *
 *   display_lut      N^3 RGBA16F texture: the display-encoded colour (what a
 *                    saved render holds) of each grid node, red along x
 *                    (core/display_transform.py builds it with Blender)
 *   display_shaper   (k, n): a node coordinate is log2(1 + k x) * n * (N - 1)
 *                    (exposure is in k; inputs beyond the grid are clamped)
 *   OVERLAY_MERGE_GAMMA  Blender merges the overlay buffer in a 2.2-power
 *                    space: writing display^2.2 puts display on the screen
 *
 * Interpolation is tetrahedral with texelFetch: 4 texels (trilinear needs 8
 * and measured no more accurate; on llvmpipe the transform costs about a
 * third of the overlay's fill time with it, twice that with trilinear), exact
 * along the grey axis, and independent of sampler state or a GPU's filtering
 * precision. */

vec3 display_lut_texel(ivec3 node)
{
  return texelFetch(display_lut, node, 0).rgb;
}

/* Premultiplied colour in, premultiplied colour out: the colour is
 * un-premultiplied, transformed and multiplied by alpha again (a partly
 * covered wire pixel gets the wire's transformed colour at its coverage). */
vec4 display_transform(vec4 premultiplied)
{
  float alpha = premultiplied.a;
  if (alpha <= 0.0) {
    return vec4(0.0);
  }
  vec3 colour = max(premultiplied.rgb / alpha, vec3(0.0));
  int last = textureSize(display_lut, 0).x - 1;
  vec3 u = clamp(log2(1.0 + colour * display_shaper.x) * display_shaper.y, 0.0, 1.0) * float(last);
  ivec3 i = min(ivec3(u), ivec3(last - 1));
  vec3 f = u - vec3(i);
  /* Tetrahedral: the cell's tetrahedron that holds f runs from its corner 0
   * along the axis of the largest fraction, then the middle one, to corner
   * (1, 1, 1); 4 texels. (A tie leaves a zero weight on the ambiguous
   * corner, so which of the tied axes is picked does not matter.) */
  vec3 largest = step(f.yzx, f) * (vec3(1.0) - step(f, f.zxy));
  vec3 smallest = step(f, f.yzx) * (vec3(1.0) - step(f.zxy, f));
  float f_max = max(max(f.x, f.y), f.z);
  float f_min = min(min(f.x, f.y), f.z);
  float f_mid = f.x + f.y + f.z - f_max - f_min;
  vec3 display = (1.0 - f_max) * display_lut_texel(i) +
                 (f_max - f_mid) * display_lut_texel(i + ivec3(largest)) +
                 (f_mid - f_min) * display_lut_texel(i + ivec3(1) - ivec3(smallest)) +
                 f_min * display_lut_texel(i + ivec3(1));
  vec3 merged = pow(max(display, vec3(0.0)), vec3(OVERLAY_MERGE_GAMMA));
  return vec4(merged * alpha, alpha);
}
