/* nvidia2007 / kakadu_clip fragment stage.
 *
 * General case (whitepaper, "The General Case"): the minimum of the three
 * no-perspective interpolated heights.
 *
 * Tricky case (whitepaper, "The Tricky Case", fragment shader): the distance
 * from the fragment F to a line through point A with unit direction Adir, by
 * Pythagoras on the vector AF: |AF|^2 minus the square of its projection on
 * Adir. (The whitepaper's printed formula drops the square on the projection;
 * the NVIDIA SDK sample and the Kakadu article square it, and take abs() of
 * the difference before the root. We follow them.) In float32 this difference
 * cancels catastrophically when A is far from F -- the glitch the Kakadu
 * article (part III, "In Practice") analyses.
 *
 * KAKADU_CLIP (Kakadu part III, "Full Measure"): a point outside the viewport
 * is replaced by the midpoint of its line clipped to the viewport rectangle
 * with Liang-Barsky (infinite lines for (A, Adir) and (B, Bdir), the segment
 * for AB), so AF stays short and the cancellation disappears. Done per
 * fragment, where the article does it. */

#ifdef KAKADU_CLIP
bool inside_viewport(vec2 p)
{
  vec2 lo = params.viewport.xy, hi = params.viewport.xy + params.viewport.zw;
  return all(greaterThanEqual(p, lo)) && all(lessThanEqual(p, hi));
}

/* Liang-Barsky: the parameter interval of p1 + t (p2 - p1) inside the
 * viewport (t unbounded for an infinite line, [0, 1] for the segment).
 * `hit` is false when the line misses the viewport. */
vec2 clip_to_viewport(vec2 p1, vec2 p2, bool infinite_line, out bool hit)
{
  float t_enter = infinite_line ? -3.0e38 : 0.0;
  float t_exit = infinite_line ? 3.0e38 : 1.0;
  vec2 lo = params.viewport.xy, hi = params.viewport.xy + params.viewport.zw;
  float p_values[4] = float[4](p1.x - p2.x, p2.x - p1.x, p1.y - p2.y, p2.y - p1.y);
  float q_values[4] = float[4](p1.x - lo.x, hi.x - p1.x, p1.y - lo.y, hi.y - p1.y);
  hit = true;
  for (int i = 0; i < 4; i++) {
    float pk = p_values[i], qk = q_values[i];
    if (abs(pk) < 1e-8) {
      if (qk < 0.0) {
        hit = false; /* parallel to this border and outside it */
      }
      continue;
    }
    float t = qk / pk;
    if (pk < 0.0) {
      t_enter = max(t_enter, t);
    }
    else {
      t_exit = min(t_exit, t);
    }
  }
  if (t_enter > t_exit) {
    hit = false;
  }
  return vec2(t_enter, t_exit);
}

/* The article's MidpointOfClippedLine. A line that misses the viewport has no
 * visible pixel; the article returns infinity there, we report `hit` = false
 * so the caller can drop the edge instead of producing inf - inf = NaN. */
vec2 clipped_midpoint(vec2 p1, vec2 p2, bool infinite_line, out bool hit)
{
  vec2 t = clip_to_viewport(p1, p2, infinite_line, hit);
  return p1 + 0.5 * (t.x + t.y) * (p2 - p1);
}
#endif

/* Squared distance from F to the line through `origin` along unit `dir`
 * (Pythagoras on origin->F, as in the whitepaper). */
float squared_line_distance(vec2 to_fragment, vec2 dir)
{
  float along = dot(dir, to_fragment);
  return abs(dot(to_fragment, to_fragment) - along * along);
}

void main()
{
  vec2 f = gl_FragCoord.xy;
  float d;
  if (case_id == 0) {
    d = min(min(((line_mask & 1) != 0) ? edge_heights.x : NO_EDGE, ((line_mask & 2) != 0) ? edge_heights.y : NO_EDGE),
            ((line_mask & 4) != 0) ? edge_heights.z : NO_EDGE);
  }
  else {
    vec2 a = line_a.xy, a_dir = line_a.zw;
    vec2 b = line_b.xy, b_dir = line_b.zw;
    bool keep_a = true, keep_b = true, keep_ab = true;
#ifdef KAKADU_CLIP
    bool a_in = inside_viewport(a), b_in = inside_viewport(b);
    vec2 af = f - (a_in ? a : clipped_midpoint(a, a + a_dir, true, keep_a));
    vec2 bf = f - (b_in ? b : clipped_midpoint(b, b + b_dir, true, keep_b));
    vec2 xf = a_in ? af : (b_in ? bf : f - clipped_midpoint(a, b, false, keep_ab));
#else
    vec2 af = f - a;
    vec2 bf = f - b;
    vec2 xf = af;
#endif
    float d2 = NO_EDGE * NO_EDGE;
    if ((line_mask & 1) != 0 && keep_a) {
      d2 = min(d2, squared_line_distance(af, a_dir));
    }
    if ((line_mask & 2) != 0 && keep_b) {
      d2 = min(d2, squared_line_distance(bf, b_dir));
    }
    if ((line_mask & 4) != 0 && keep_ab) {
      d2 = min(d2, squared_line_distance(xf, normalize(b - a)));
    }
    d = sqrt(d2);
  }
  write_output(line_profile(d));
}
