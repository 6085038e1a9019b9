/* The per-frame parameter block (std140), shared by every SolidWire shader.
 * Keep in sync with draw.pack_params, which asserts the size
 * (shaders.PARAMS_FLOATS floats). */
struct SolidWireParams {
  vec4 wire_color;
  vec4 fill_color;
  vec4 viewport;
  float half_thickness;
  float softness;
  float fade_start;
  float fade_end;
  float pattern_period;
  float pattern_duty;
  float hidden_alpha;
  float hidden_duty;
  float half_thickness_far;
  float thickness_depth_start;
  float thickness_depth_end;
  float world_half_thickness_px;
  float hidden_period;
  float _pad0;
  float _pad1;
  float _pad2;
};
