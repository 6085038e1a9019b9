/* nvidia2007 / kakadu_clip vertex stage: the NVIDIA "Solid Wireframe"
 * whitepaper (WP-03014-001, 2007), with its geometry-shader work moved into
 * the vertex stage by vertex pulling.
 *
 * Whitepaper, "The General Case": project the three corners to viewport
 * space, take the triangle's three heights there (each corner's distance to
 * the opposite edge) and give each corner its distances to the three edge
 * lines, which are (0, 0, 0) except its own height. Interpolated with no
 * perspective correction they are the fragment's window-space distances to the
 * three edge lines.
 *
 * Whitepaper, "The Tricky Case" and Table 1: when some corner is behind the
 * viewpoint (view-space depth <= 0 in the paper's frame; here clip w <= 0),
 * heights make no sense. A 3-bit case id (corner 0 behind -> 4, corner 1 ->
 * 2, corner 2 -> 1) selects from the table the projectable corners A and B
 * (A = B when only one is) and the unprojectable corners A' and B' that give
 * the directions of the two edges leaving A and B. The direction is taken, as
 * the whitepaper prints it, from the window position of the homogeneous sum
 * A + A' to the window position of A, normalised. The fragment stage then
 * measures distances to the lines (A, Adir), (B, Bdir) and, when A != B, AB.
 *
 * Everything is float32, as on the GPU the paper targets: that is the point
 * of this variant (it reproduces the paper's behaviour, glitches included).
 *
 * Platform note (measured on Mesa llvmpipe 15, not on hardware): when the
 * rasteriser has to clip a triangle because a corner projects far outside
 * the viewport (a corner just in front of the viewpoint), llvmpipe
 * interpolates `noperspective` varyings wrongly (tens of pixels off, NaN in
 * extreme cases), so the general case's heights break there too. The exact
 * path uses only flat varyings and is not affected. */

/* Table 1 of the whitepaper, by case id: (A, B, A', B') corner indices.
 * Case 0 is the general case and case 7 (all corners behind) is not visible;
 * their rows are unused. */
const ivec4 TRICKY_TABLE[8] = ivec4[8](ivec4(0, 0, 0, 0),
                                      ivec4(0, 1, 2, 2),
                                      ivec4(0, 2, 1, 1),
                                      ivec4(0, 0, 1, 2),
                                      ivec4(1, 2, 0, 0),
                                      ivec4(1, 1, 0, 2),
                                      ivec4(2, 2, 0, 1),
                                      ivec4(0, 0, 0, 0));

void main()
{
  int triangle = gl_VertexID / 3;
  int corner = gl_VertexID - triangle * 3;
  vec4 ids = fetch_texel(triangle_vertices, triangle);

  vec3 local[3] = vec3[3](pulled_position(ids.x), pulled_position(ids.y), pulled_position(ids.z));
  vec4 clip[3];
  for (int k = 0; k < 3; k++) {
    clip[k] = object_to_clip * vec4(local[k], 1.0);
  }
  int drawn = drawn_edges();

  int case_index = ((clip[0].w > 0.0) ? 0 : 4) + ((clip[1].w > 0.0) ? 0 : 2) + ((clip[2].w > 0.0) ? 0 : 1);
  case_id = case_index;

  if (case_index == 0) {
    /* General case: heights in window space. heights[k] is corner k's
     * distance to the opposite edge (twice the area over that edge's length). */
    vec2 p0 = window_of(clip[0]);
    vec2 p1 = window_of(clip[1]);
    vec2 p2 = window_of(clip[2]);
    vec2 e01 = p1 - p0, e02 = p2 - p0;
    float area2 = abs(e01.x * e02.y - e01.y * e02.x);
    vec3 heights = vec3(area2 / length(p2 - p1), area2 / length(e02), area2 / length(e01));
    /* Component k: the distance to the edge opposite corner k. */
    vec3 dis = vec3(0.0);
    dis[corner] = heights[corner];
    edge_heights = dis;
    /* Which components belong to drawn edges: opposite corner 0 is edge 1-2,
     * opposite 1 is edge 2-0, opposite 2 is edge 0-1. */
    line_mask = (((drawn & EDGE1_REAL) != 0) ? 1 : 0) | (((drawn & EDGE2_REAL) != 0) ? 2 : 0) |
                (((drawn & EDGE0_REAL) != 0) ? 4 : 0);
    line_a = line_b = vec4(0.0);
  }
  else {
    ivec4 row = TRICKY_TABLE[case_index];
    vec2 a = window_of(clip[row.x]);
    vec2 b = window_of(clip[row.y]);
    vec2 a_dir = normalize(a - window_of(clip[row.x] + clip[row.z]));
    vec2 b_dir = normalize(b - window_of(clip[row.y] + clip[row.w]));
    line_a = vec4(a, a_dir);
    line_b = vec4(b, b_dir);
    edge_heights = vec3(0.0);
    /* Bit 0: line (A, Adir) = edge A-A'; bit 1: (B, Bdir) = edge B-B';
     * bit 2: edge AB (exists when A != B: cases 1, 2, 4). */
    bool has_ab = row.x != row.y;
    line_mask = (((drawn & edge_bit(row.x, row.z)) != 0) ? 1 : 0) |
                (((drawn & edge_bit(row.y, row.w)) != 0) ? 2 : 0) |
                ((has_ab && (drawn & edge_bit(row.x, row.y)) != 0) ? 4 : 0);
  }

  emit_corner(local[corner], clip[corner]);
}
