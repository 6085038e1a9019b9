/* Average of the FACTOR x FACTOR source texels under this pixel (a box
 * filter: the coverage-weighted mean of the supersampled line pixels). */

void main()
{
  ivec2 base = ivec2(gl_FragCoord.xy) * FACTOR;
  vec4 sum = vec4(0.0);
  for (int y = 0; y < FACTOR; y++) {
    for (int x = 0; x < FACTOR; x++) {
      sum += texelFetch(source_color, base + ivec2(x, y), 0);
    }
  }
  frag_color = sum / float(FACTOR * FACTOR);
  frag_view_depth = texelFetch(source_depth, base, 0).r;
}
