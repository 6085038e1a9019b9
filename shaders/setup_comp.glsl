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
  vec2 w0, w1, w2;
  bool in_front, convex;
  triangle_edges(c0, c1, c2, c3, ids, true, line0, span0, line1, span1, line2, span2, line3, span3, line4, span4,
                 w0, w1, w2, in_front, convex);
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
