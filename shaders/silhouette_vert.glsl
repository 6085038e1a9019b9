/* SolidWire full-width silhouettes, vertex stage: one screen-space fin
 * (two triangles over four shared corners, draw.indexed_quad_batch) per
 * candidate edge, pulled from `silhouette_edges` by gl_VertexID / 4 (an
 * indexed draw: gl_VertexID is the corner's index). See
 * solidwire_addon/core/silhouettes.py for the definition. Fins of edges that are
 * not silhouettes in this view collapse to nothing here: most fins, whose
 * four corners a software rasteriser shades once each (not six). */

/* Outside the clip volume: the rasteriser drops the triangle. */
const vec4 COLLAPSED = vec4(2.0, 2.0, 2.0, 1.0);

/* Which side of the window line through the edge's ends (homogeneous window
 * points ha, hb) the point ho lies on: the sign of det[ha; hb; ho], which
 * is sigma's (docs/image_model.md §5.5). Taken as w_a w_b w_o times the
 * orientation of the window points, cross2(b - a, o - a): the same sign,
 * but measured against the triangle's own size in window space rather
 * than against |ha| |hb| |ho| of three nearly parallel vectors, whose
 * float32 rounding decides faces a hair off edge-on. 0 where o is one of
 * the ends (a corner folded onto the edge: sigma is exactly 0 there); the
 * homogeneous form where a point lies on the eye's plane (w = 0). */
float line_side(vec3 ha, vec3 hb, vec3 ho)
{
  if (ho == ha || ho == hb) {
    return 0.0;
  }
  if (ha.z == 0.0 || hb.z == 0.0 || ho.z == 0.0) {
    return dot(cross(ha, hb), ho);
  }
  vec2 pa = ha.xy / ha.z, pb = hb.xy / hb.z, po = ho.xy / ho.z;
  vec2 ab = pb - pa, ao = po - pa;
  return sign(ha.z * hb.z * ho.z) * (ab.x * ao.y - ab.y * ao.x);
}

void main()
{
  int edge = gl_VertexID / 4;
  int corner = quad_corner;
  vec4 ids = fetch_texel(silhouette_edges, edge);
  vec4 a = vertex_clip(ids.x);
  vec4 b = vertex_clip(ids.y);
  vec3 ha = window_homogeneous(a), hb = window_homogeneous(b);
  vec3 l = cross(ha, hb);
  float side_f = line_side(ha, hb, window_homogeneous(vertex_clip(ids.z)));
  bool boundary = ids.w < 0.0;
  float side_g = boundary ? 0.0 : line_side(ha, hb, window_homogeneous(vertex_clip(ids.w)));
  bool contour = !boundary && side_f * side_g > 0.0;
  float depth_a = a.z + a.w, depth_b = b.z + b.w;
  if (edge >= edge_count || !(boundary || contour) || side_f == 0.0 || (depth_a < 0.0 && depth_b < 0.0) ||
      dot(l.xy, l.xy) == 0.0)
  {
    gl_Position = COLLAPSED;
    return;
  }
  /* The part in front of the near plane, in clip and window space. */
  vec4 a_front = (depth_a < 0.0) ? near_clipped(a, b, depth_a, depth_b) : a;
  vec4 b_front = (depth_b < 0.0) ? near_clipped(b, a, depth_b, depth_a) : b;
  fin_a = a_front;
  fin_b = b_front;
  edge_setup(a, b, fin_line, fin_span);
  fin_inner_sign = sign(side_f);
  vec3 pa = vec3(fetch_texel(vertex_positions, int(ids.x)).xyz);
  vec3 pb = vec3(fetch_texel(vertex_positions, int(ids.y)).xyz);
  float za = -dot(object_to_view_z, vec4(pa, 1.0)), zb = -dot(object_to_view_z, vec4(pb, 1.0));
  float ta = (depth_a < 0.0) ? depth_a / (depth_a - depth_b) : 0.0;
  float tb = (depth_b < 0.0) ? depth_b / (depth_b - depth_a) : 0.0;
  fin_view_depth = vec2(mix(za, zb, ta), mix(zb, za, tb));

  /* Quad around the window segment, widened by the reach of the profile
   * (plus a pixel so every sample the profile reaches is rasterised). */
  vec2 wa = window_point(a_front), wb = window_point(b_front);
  vec2 dir = wb - wa;
  float len = length(dir);
  dir = (len > 0.0) ? dir / len : vec2(1.0, 0.0);
  vec2 normal = vec2(-dir.y, dir.x);
  float reach = max(params.half_thickness, params.half_thickness_far) + 2.0 * params.softness + 1.0;
#if THICKNESS_MODE == 1
  reach = max(reach, params.world_half_thickness_px / max(min(a_front.w, b_front.w), 1e-6) + 2.0 * params.softness + 1.0);
#endif
  /* corners 0..3: (a,-), (b,-), (b,+), (a,+) */
  bool at_b = (corner == 1 || corner == 2);
  bool plus = (corner >= 2);
  vec2 w = (at_b ? wb + dir * reach : wa - dir * reach) + normal * (plus ? reach : -reach);
  vec2 ndc = (w - params.viewport.xy) / params.viewport.zw * 2.0 - 1.0;
  gl_Position = vec4(ndc, 0.0, 1.0);
}
