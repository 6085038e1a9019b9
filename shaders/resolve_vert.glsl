/* Resolve pass: one rectangle over the window box of the draw being
 * resolved (two triangles; corner bits x = 1, y = 2). Other passes over a
 * rectangle use it too (the overlay's composite). */

void main()
{
  vec2 corner = vec2(float(rect_corner & 1), float(rect_corner >> 1));
#ifdef RESOLVE_PASS
  /* At the far end of the depth range: tested GREATER against the
   * visibility record's depth (draw.py), the rectangle passes only where a
   * surface was recorded (the visibility pass keeps its depth below 1.0),
   * and a rasteriser drops the rest before shading it. */
  float depth = 1.0;
#else
  float depth = 0.0;
#endif
  gl_Position = vec4(mix(resolve_rect.xy, resolve_rect.zw, corner), depth, 1.0);
}
