/* SolidWire method variants (benchmark/developer switch): vertex pulling.
 *
 * Blender's Python GPU API has no geometry shader, so every variant does its
 * per-triangle work in the vertex stage exactly as the exact path does: each
 * corner of the non-indexed triangle list finds its triangle (gl_VertexID / 3),
 * reads the triangle's vertex ids from `triangle_vertices` and the positions
 * from `vertex_positions`. The three corners repeat the same arithmetic on the
 * same inputs, so they compute bit-identical per-triangle values; those are
 * passed `flat` where the papers pass constants over the triangle. */

/* (fetch_texel: shaders/common.glsl, which every variant includes.) */

vec3 pulled_position(float vertex_index)
{
  return fetch_texel(vertex_positions, int(vertex_index)).xyz;
}

/* Window ("viewport space" in the whitepaper) position of a clip-space point:
 * the ordinary perspective divide followed by the viewport transform. For a
 * point behind the viewpoint (w <= 0) this is the meaningless mirrored point
 * the NVIDIA paper warns about; the variants that use it do so on purpose. */
vec2 window_of(vec4 clip)
{
  return (clip.xy / clip.w * 0.5 + 0.5) * params.viewport.zw + params.viewport.xy;
}

/* Edge k joins corners k and k+1 (mod 3): the bit of edge (i, j) in
 * `edge_flags` (EDGE0_REAL, EDGE1_REAL, EDGE2_REAL). */
int edge_bit(int i, int j)
{
  return 1 << ((((i + 1) % 3) == j) ? i : j);
}

/* Which triangle edges a variant draws: polygon boundary edges only when
 * diagonals are hidden, every triangle edge otherwise (the variants have no
 * patterned diagonals and ignore a quad's 4th corner: they are per-triangle
 * methods, as published). */
#ifndef LINE_DEPTH_OFFSET /* the line pass has no per-corner edge flags */
int drawn_edges()
{
#if DIAGONALS == 0
  return edge_flags & (EDGE0_REAL | EDGE1_REAL | EDGE2_REAL);
#else
  return EDGE0_REAL | EDGE1_REAL | EDGE2_REAL;
#endif
}
#endif

/* gl_Position and view_depth of this corner. */
void emit_corner(vec3 local, vec4 clip)
{
  view_depth = -dot(object_to_view_z, vec4(local, 1.0));
  gl_Position = clip;
}
