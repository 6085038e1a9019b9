/* SolidWire method variants: the shared intensity profile and output.
 *
 * Every variant feeds its own distance estimate into the same SPEC 1.4
 * profile, fade and colour rules as the exact path (solidwire_frag.glsl), so
 * a benchmark difference between variants is a difference in the distance
 * computation only. */

/* The constant-width profile (line_style.glsl): the variants draw in px. */
float line_profile(float d)
{
  return line_profile(d, params.half_thickness);
}

void write_output(float intensity)
{
#ifdef USE_FADE
  intensity *= depth_fade(view_depth);
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
