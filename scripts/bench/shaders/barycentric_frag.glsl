/* barycentric fragment stage (the blog's final version): the screen-space rate
 * of change of each weight, as the Euclidean length of (dFdx, dFdy) the post
 * recommends over fwidth's Manhattan sum, converts weights to pixels. The post
 * remaps weight w with smoothstep between rate * thickness and
 * rate * (thickness + falloff); that is a profile of w / rate, so here
 * w / rate is the distance estimate and goes through the common SPEC profile
 * instead of smoothstep (same comparison of distances as every variant).
 *
 * The approximation this inherits: the post treats the rate as constant over
 * the triangle, which holds only without perspective, and the derivatives are
 * finite differences over 2x2 pixel quads. */

void main()
{
  vec3 rate = sqrt(dFdx(barycentric) * dFdx(barycentric) + dFdy(barycentric) * dFdy(barycentric));
  vec3 d = barycentric / max(rate, vec3(1e-30));
  float d_min = min(min(((line_mask & 1) != 0) ? d.x : NO_EDGE, ((line_mask & 2) != 0) ? d.y : NO_EDGE),
                    ((line_mask & 4) != 0) ? d.z : NO_EDGE);
  write_output(line_profile(d_min));
}
