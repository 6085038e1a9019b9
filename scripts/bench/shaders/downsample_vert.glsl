/* Box downsampling of a supersampled render (offset_lines 2x / 4x): one
 * full-screen triangle. */

void main()
{
  vec2 corner = vec2((gl_VertexID == 1) ? 3.0 : -1.0, (gl_VertexID == 2) ? 3.0 : -1.0);
  gl_Position = vec4(corner + 0.0 * position, 0.0, 1.0);
}
