/* SolidWire method variants: the shared intensity profile and output.
 *
 * Every variant feeds its own distance estimate into the same SPEC 1.4
 * profile, fade and colour rules as the exact path (solidwire_frag.glsl), so
 * a benchmark difference between variants is a difference in the distance
 * computation only. */

float line_profile(float d)
{
  float x = max(d - params.half_thickness, 0.0) / params.softness;
  return (x < 2.0) ? exp2(-2.0 * x * x) : 0.0;
}

void write_output(float intensity)
{
#ifdef USE_FADE
  float fade_range = params.fade_end - params.fade_start;
  float fade = (fade_range > 0.0) ? clamp((params.fade_end - view_depth) / fade_range, 0.0, 1.0) :
                                    ((view_depth <= params.fade_start) ? 1.0 : 0.0);
  intensity *= fade;
#endif
  float wire_weight = intensity * params.wire_color.a;
#ifdef USE_FILL
  frag_color = vec4(mix(params.fill_color.rgb, params.wire_color.rgb, wire_weight), 1.0);
#else
  frag_color = vec4(params.wire_color.rgb * wire_weight, wire_weight);
#endif
#ifdef WRITE_VIEW_DEPTH
  frag_view_depth = view_depth;
#endif
}
