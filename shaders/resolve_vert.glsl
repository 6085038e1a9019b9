/* Resolve pass: one rectangle over the window box of the draw being
 * resolved (two triangles; corner bits x = 1, y = 2). */

void main()
{
  vec2 corner = vec2(float(rect_corner & 1), float(rect_corner >> 1));
  gl_Position = vec4(mix(resolve_rect.xy, resolve_rect.zw, corner), 0.0, 1.0);
}
