/* SolidWire line style, shared by every fragment stage (the exact path, the
 * silhouette fins and the benchmark's method variants): the image model (docs/image_model.md §4)
 * intensity profile, the thickness modes, depth fade and the dash mask. */

#ifndef THICKNESS_MODE
#  define THICKNESS_MODE 0 /* constant pixels (the method variants) */
#endif

/* Profile (docs/image_model.md §4.1): 1 inside the core, 2^(-2 x^2) falloff over two softness
 * widths, cut to 0 beyond (the step there is 2^-8, one 8-bit level). */
float line_profile(float d, float half_thickness)
{
  float x = max(d - half_thickness, 0.0) / params.softness;
  return (x < 2.0) ? exp2(-2.0 * x * x) : 0.0;
}

/* Half the core width at a point of view depth `depth` whose clip w is
 * 1 / inv_clip_w (THICKNESS_MODE, docs/image_model.md §4.2):
 *   0 constant in pixels;
 *   1 a width in scene units: pixels per unit there, exact for perspective
 *     and orthographic views;
 *   2 Baerentzen's depth cue, from the near thickness to the far one across
 *     [thickness_depth_start, thickness_depth_end] (a step if that is empty). */
float half_thickness_at(float depth, float inv_clip_w)
{
#if THICKNESS_MODE == 1
  return params.world_half_thickness_px * inv_clip_w;
#elif THICKNESS_MODE == 2
  float range = params.thickness_depth_end - params.thickness_depth_start;
  float t = (range > 0.0) ? clamp((depth - params.thickness_depth_start) / range, 0.0, 1.0) :
                            ((depth <= params.thickness_depth_start) ? 0.0 : 1.0);
  return mix(params.half_thickness, params.half_thickness_far, t);
#else
  return params.half_thickness;
#endif
}

/* Depth fade (docs/image_model.md §4.5) at view depth `depth` (a hard cut at fade_start when
 * the range is empty). */
float depth_fade(float depth)
{
  float range = params.fade_end - params.fade_start;
  return (range > 0.0) ? clamp((params.fade_end - depth) / range, 0.0, 1.0) : ((depth <= params.fade_start) ? 1.0 : 0.0);
}

/* Integral of the on/off square wave (on for the first `duty` of each
 * period) from 0 to t: the box-filtered mask is a difference of two of these,
 * which anti-aliases the dash ends over one pixel exactly. */
float pattern_integral(float t, float period, float duty)
{
  float cycles = floor(t / period);
  return cycles * duty * period + clamp(t - cycles * period, 0.0, duty * period);
}

float pattern_mask(float t, float period, float duty)
{
  return pattern_integral(t + 0.5, period, duty) - pattern_integral(t - 0.5, period, duty);
}
