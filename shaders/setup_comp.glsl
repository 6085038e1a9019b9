/* SolidWire set-up pre-pass (compute): each triangle's flat edge data,
 * computed once per draw instead of once per corner by the vertex stage.
 *
 * The same code path as the vertex stage (solidwire_vert.glsl main(), the
 * part before `triangle_flags`), so the lines and spans are bit-identical;
 * only the parts that depend on the edge flags are left to the vertex stage,
 * which reads them from its batch. Whether the 4th id is a quad corner is
 * therefore not known here: edges 3 and 4 are always set up (for a triangle
 * the 4th id repeats the first, so the near-plane test is unchanged).
 *
 * Layout: SETUP_ROW_TRIANGLES triangles a row, SETUP_TEXELS texels each
 * (core/shaders.py): line0.xyz span0.x | span0.y line1.xyz | span1 line2.xy |
 * line2.z span2 geometry | line3.xyz span3.x | span3.y line4.xyz | span4 0 0.
 * geometry = 1 (all corners in front of the near plane) + 2 (the quad
 * projects convex). A plain triangle reads only the first 4 texels. */

/* Row of the table and first column of a triangle's texels: a triangle's
 * texels share a row, and the division is by a compile-time constant (a
 * multiply and shift, where a division by the texture's width at run time
 * is a scalar division per SIMD lane on a CPU rasterizer). */
ivec2 setup_texel(int triangle)
{
  int row = triangle / SETUP_ROW_TRIANGLES;
  return ivec2((triangle - row * SETUP_ROW_TRIANGLES) * SETUP_TEXELS, row);
}

void main()
{
  int triangle = int(gl_GlobalInvocationID.y * (gl_NumWorkGroups.x * gl_WorkGroupSize.x) + gl_GlobalInvocationID.x);
  if (triangle >= triangle_count) {
    return;
  }
  vec4 ids = fetch_texel(triangle_vertices, triangle);
  vec4 c0 = vertex_clip(ids.x);
  vec4 c1 = vertex_clip(ids.y);
  vec4 c2 = vertex_clip(ids.z);
  vec4 c3 = vertex_clip(ids.w);
  vec3 line0, line1, line2, line3, line4;
  vec2 span0, span1, span2, span3, span4;
  bool in_front = min(min(c0.z + c0.w, c1.z + c1.w), min(c2.z + c2.w, c3.z + c3.w)) >= 0.0;
  bool convex = false;
  if (in_front) {
    vec2 w0 = c0.xy / c0.w, w1 = c1.xy / c1.w, w2 = c2.xy / c2.w, w3 = c3.xy / c3.w;
    vec2 to_window = 0.5 * params.viewport.zw;
    vec2 origin = params.viewport.xy + to_window;
    w0 = w0 * to_window + origin;
    w1 = w1 * to_window + origin;
    w2 = w2 * to_window + origin;
    w3 = w3 * to_window + origin;
    line_through_from_lower(w0, w1, ids.x, ids.y, line0, span0);
    line_through_from_lower(w1, w2, ids.y, ids.z, line1, span1);
    line_through_from_lower(w2, w0, ids.z, ids.x, line2, span2);
    line_through_from_lower(w2, w3, ids.z, ids.w, line3, span3);
    line_through_from_lower(w3, w0, ids.w, ids.x, line4, span4);
    vec2 d02 = w2 - w0, d13 = w3 - w1;
    float s1 = d02.x * (w1.y - w0.y) - d02.y * (w1.x - w0.x);
    float s3 = d02.x * (w3.y - w0.y) - d02.y * (w3.x - w0.x);
    float t0 = d13.x * (w0.y - w1.y) - d13.y * (w0.x - w1.x);
    float t2 = d13.x * (w2.y - w1.y) - d13.y * (w2.x - w1.x);
    convex = s1 * s3 < 0.0 && t0 * t2 < 0.0;
  }
  else {
    edge_setup_from_lower(c0, c1, ids.x, ids.y, line0, span0);
    edge_setup_from_lower(c1, c2, ids.y, ids.z, line1, span1);
    edge_setup_from_lower(c2, c0, ids.z, ids.x, line2, span2);
    edge_setup_from_lower(c2, c3, ids.z, ids.w, line3, span3);
    edge_setup_from_lower(c3, c0, ids.w, ids.x, line4, span4);
  }
  float geometry = (in_front ? 1.0 : 0.0) + (convex ? 2.0 : 0.0);
  ivec2 at = setup_texel(triangle);
  imageStore(setup_table, at, vec4(line0, span0.x));
  imageStore(setup_table, at + ivec2(1, 0), vec4(span0.y, line1));
  imageStore(setup_table, at + ivec2(2, 0), vec4(span1, line2.xy));
  imageStore(setup_table, at + ivec2(3, 0), vec4(line2.z, span2, geometry));
  imageStore(setup_table, at + ivec2(4, 0), vec4(line3, span3.x));
  imageStore(setup_table, at + ivec2(5, 0), vec4(span3.y, line4));
  imageStore(setup_table, at + ivec2(6, 0), vec4(span4, 0.0, 0.0));
}
