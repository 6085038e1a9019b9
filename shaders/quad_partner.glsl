/* The other triangle of a quad. A hidden layer is a face behind the visible
 * face F, never F itself (docs/image_model.md §5.4), and only a folded
 * quad's two triangles can both cover one pixel: a triangle behind the
 * surface whose other triangle covers the same pixel nearer takes that
 * triangle's depth there, a hair nearer still, so a test against the
 * surface (the direct hidden-line pass, solidwire_frag.glsl) or against
 * the layer before (the peeled layers' record, visibility_frag.glsl) drops
 * it exactly where that triangle is the surface. Needs common.glsl and
 * edge_geometry.glsl. */

/* The corner ids of the other triangle of `triangle` (corner ids `ids`,
 * edge flags `flags`), or false where it has none. A plain quad's triangle
 * has the 4th corner in ids.w (the diagonal is edge 2); one listed with its
 * region has its block's start there instead, and finds the other triangle
 * beside it in the triangle table: the one that also has its diagonal (its
 * one edge that is no polygon edge, which no other face has). An n-gon's
 * triangles have none. The corners come in the face's winding (the other
 * triangle runs along the shared diagonal the other way), as
 * culled_partner needs. */
bool quad_partner_corners(int triangle, vec4 ids, int flags, out vec3 corners)
{
  corners = ids.xzw;
  if ((flags & HAS_QUAD_CORNER) != 0) {
    return true;
  }
  if ((flags & IS_NGON) != 0 || (flags & IN_REGION) == 0) {
    return false;
  }
  /* Its polygon's edges, drawn (real) or not (hidden); the diagonal is neither. */
  int polygon_edges = (flags | (flags / EDGE0_HIDDEN)) & (EDGE0_REAL | EDGE1_REAL | EDGE2_REAL);
  vec2 diagonal;
  if (polygon_edges == (EDGE0_REAL | EDGE1_REAL)) {
    diagonal = ids.zx;
  }
  else if (polygon_edges == (EDGE1_REAL | EDGE2_REAL)) {
    diagonal = ids.xy;
  }
  else if (polygon_edges == (EDGE2_REAL | EDGE0_REAL)) {
    diagonal = ids.yz;
  }
  else {
    return false; /* a triangle face */
  }
  float fourth = -1.0;
  for (int step = -1; step <= 1; step += 2) {
    int beside = triangle + step;
    if (beside < 0 || fourth >= 0.0) {
      continue;
    }
    vec3 other = fetch_texel(triangle_vertices, beside).xyz;
    bvec3 on_a = equal(other, vec3(diagonal.x)), on_b = equal(other, vec3(diagonal.y));
    if (any(on_a) && any(on_b)) {
      bvec3 rest = not(bvec3(on_a.x || on_b.x, on_a.y || on_b.y, on_a.z || on_b.z));
      fourth = rest.x ? other.x : (rest.y ? other.y : other.z);
    }
  }
  if (fourth < 0.0) {
    return false;
  }
  corners = vec3(diagonal.y, diagonal.x, fourth);
  return true;
}

/* Whether the other triangle (corners a, b, c of quad_partner_corner, in
 * the face's winding) is culled: with back faces culled a triangle seen
 * from behind is no surface (image model §2.3) and hides nothing, so a
 * folded face's triangle behind the surface is a layer of its own there.
 * The sign of det[h_a; h_b; h_c] is its window orientation (also for a
 * triangle through the near plane, for the part in front of the eye), and
 * `drawn_front` (gl_FrontFacing of the triangle being drawn, which the
 * culling kept) the orientation the culling keeps. */
bool culled_partner(vec4 a, vec4 b, vec4 c, bool drawn_front)
{
  return params.backface_culling != 0.0 && (dot(a.xyz, cross(b.xyz, c.xyz)) > 0.0) != drawn_front;
}

/* How near two depths count as level: relative, far above float32's
 * rounding of one depth. */
const float LEVEL_DEPTH = 1.0e-5;

/* Whether the face's other triangle, at view depth `other` where it covers
 * a pixel, lies in front of this one there (view depth `depth`), or level
 * with it: a face that is flat but overlaps itself on screen (a
 * self-intersecting outline) has two triangles at one depth, and the
 * rasteriser's choice between them is the surface. */
bool nearer_or_level(float other, float depth)
{
  return other < depth * (1.0 + LEVEL_DEPTH);
}

/* The view depth of vertex `id` (as the vertex stage's own view_depth). */
float corner_view_depth(float id)
{
  return -dot(object_to_view_z, vec4(fetch_texel(vertex_positions, int(id)).xyz, 1.0));
}

/* A corner of the other triangle as the test at a pixel needs it: its
 * homogeneous window point (x_win w, y_win w, w), finite also behind the
 * eye, and its view depth. */
vec4 quad_partner_corner(vec4 clip, float view_depth_of_corner)
{
  return vec4(window_homogeneous(clip), view_depth_of_corner);
}

/* Corner h (a homogeneous window point, x_win w, y_win w, w) with window
 * point p as the origin: (h.xy - p h.z, h.z). Its edge functions then need
 * no p: (h_j x h_k) . (p, 1) is perp_dot of the two moved corners. */
vec3 around(vec3 h, vec2 p)
{
  return vec3(h.xy - p * h.z, h.z);
}

float perp_dot(vec3 u, vec3 v)
{
  return u.x * v.y - u.y * v.x;
}

/* Whether a triangle (corners a, b, c of quad_partner_corner) lies wholly
 * in front of the near plane, where its window points exist. */
bool wholly_in_front(vec4 a, vec4 b, vec4 c)
{
  return min(min(a.w, b.w), c.w) >= near_plane_depth() && min(min(a.z, b.z), c.z) > 0.0;
}

/* Whether the part of the other triangle (corners a, b, c of
 * quad_partner_corner; all zero for none) in front of the near plane
 * covers window point p, and there the weights of its corners in the
 * triangle itself (perspective-correct barycentrics) and its view depth.
 * A triangle wholly in front of the near plane is tested in window space;
 * one through it (a corner behind the camera, as a quad that crosses the
 * near plane has) by its edge functions in homogeneous window space,
 * (h_j x h_k) . (p, 1), which share det[h_a; h_b; h_c]'s sign exactly
 * where a point of the triangle in front of the eye projects to p. They are
 * taken with p as the origin (around): the same values (the shift has
 * determinant 1), from products of the corners' offsets from p, which
 * float32 keeps far better than those of the corners' own coordinates
 * (large beside their differences where a corner is behind the eye). */
bool quad_partner_covers(vec2 p, vec4 a, vec4 b, vec4 c, out vec3 weights, out float depth)
{
  weights = vec3(0.0);
  depth = 0.0;
  vec3 w = vec3(a.z, b.z, c.z);
  float near = near_plane_depth();
  if (wholly_in_front(a, b, c)) {
    vec2 pa = a.xy / w.x, pb = b.xy / w.y, pc = c.xy / w.z;
    vec2 ab = pb - pa, ac = pc - pa;
    float area = ab.x * ac.y - ab.y * ac.x;
    if (area == 0.0) {
      return false;
    }
    vec2 ap = p - pa;
    float u = (ap.x * ac.y - ap.y * ac.x) / area, v = (ab.x * ap.y - ab.y * ap.x) / area;
    if (u < 0.0 || v < 0.0 || u + v > 1.0) {
      return false;
    }
    vec3 window_weights = vec3(1.0 - u - v, u, v) / w;
    weights = window_weights / (window_weights.x + window_weights.y + window_weights.z);
  }
  else {
    vec3 ta = around(a.xyz, p), tb = around(b.xyz, p), tc = around(c.xyz, p);
    float det = dot(ta, cross(tb, tc));
    if (det == 0.0) {
      return false; /* none, or a triangle seen edge-on */
    }
    vec3 e = vec3(perp_dot(tb, tc), perp_dot(tc, ta), perp_dot(ta, tb)) * sign(det);
    float sum = e.x + e.y + e.z;
    if (min(min(e.x, e.y), e.z) < 0.0 || !(sum > 0.0)) {
      return false;
    }
    weights = e / sum;
  }
  depth = dot(weights, vec3(a.w, b.w, c.w));
  return depth >= near; /* (a part the near plane clips is no surface) */
}

const float FLOAT_STEP = 1.1920929e-7;

/* The magnitudes of perp_dot(u, v)'s two products. */
float perp_dot_magnitude(vec3 u, vec3 v)
{
  return abs(u.x * v.y) + abs(u.y * v.x);
}

/* How far perp_dot(u, v) may move when its moved corners u and v are each
 * off by their rounding ru and rv (in float32 steps) per coordinate. */
float moved_rounding(vec3 u, vec2 ru, vec3 v, vec2 rv)
{
  return dot(ru, abs(v.yx)) + dot(abs(u.xy), rv.yx);
}

/* How far float32 may move the weights quad_partner_covers found for p
 * (corners a, b, c as there), as a bound on each weight. The rasteriser
 * interpolates the surface's own depth with errors of the same size, and
 * both grow where the weights cancel: a long thin triangle, or one corner
 * far off screen, gives window products of hundreds of pixels squared for
 * an area of a few. A partner's depth taken a hair nearer (PARTNER_DEPTH_HAIR)
 * must also be taken this much nearer (times its corners' depth span), or
 * the surface's own triangle behind the hair shows as a layer behind
 * itself. Four float32 steps per product: one for the partner's products,
 * one for the rasteriser's, and room for the corners' own rounding. */
float partner_weight_error(vec2 p, vec4 a, vec4 b, vec4 c)
{
  const float STEPS = 4.0 * FLOAT_STEP;
  vec3 w = vec3(a.z, b.z, c.z);
  if (wholly_in_front(a, b, c)) {
    vec2 pa = a.xy / w.x, pb = b.xy / w.y, pc = c.xy / w.z;
    vec2 ab = pb - pa, ac = pc - pa, ap = p - pa;
    float area = abs(ab.x * ac.y - ab.y * ac.x);
    float spread = abs(ab.x * ac.y) + abs(ab.y * ac.x);
    float products = abs(ap.x * ac.y) + abs(ap.y * ac.x) + abs(ab.x * ap.y) + abs(ab.y * ap.x);
    return area > 0.0 ? STEPS * (products + 2.0 * spread) / area : 1.0;
  }
  /* Through the near plane: the edge functions of quad_partner_covers, as
   * products of the corners moved to p as the origin, and the rounding of
   * that move (one step of each corner's coordinate and of p times its w,
   * twice) carried through the products. */
  vec3 ta = around(a.xyz, p), tb = around(b.xyz, p), tc = around(c.xyz, p);
  vec2 ra = abs(a.xy) + 2.0 * abs(p * a.z), rb = abs(b.xy) + 2.0 * abs(p * b.z), rc = abs(c.xy) + 2.0 * abs(p * c.z);
  float sum = abs(perp_dot(tb, tc) + perp_dot(tc, ta) + perp_dot(ta, tb));
  float products = perp_dot_magnitude(tb, tc) + perp_dot_magnitude(tc, ta) + perp_dot_magnitude(ta, tb);
  float moved = moved_rounding(tb, rb, tc, rc) + moved_rounding(tc, rc, ta, ra) + moved_rounding(ta, ra, tb, rb);
  return sum > 0.0 ? 2.0 * (STEPS * products + FLOAT_STEP * moved) / sum : 1.0;
}

/* partner_weight_error where the layer is tested against a depth that
 * another renderer drew (Blender's Solid shading depth under the overlay):
 * that one rounds the corners' own window coordinates, not their offsets
 * from p, so through the near plane the bound keeps the products of those
 * coordinates, (h_j x h_k) . (p, 1) taken as it stands. */
float foreign_weight_error(vec2 p, vec4 a, vec4 b, vec4 c)
{
  if (wholly_in_front(a, b, c)) {
    return partner_weight_error(p, a, b, c);
  }
  vec3 q = vec3(p, 1.0);
  float sum = abs(dot(cross(b.xyz, c.xyz) + cross(c.xyz, a.xyz) + cross(a.xyz, b.xyz), q));
  float products = (length(b.xyz) * length(c.xyz) + length(c.xyz) * length(a.xyz) + length(a.xyz) * length(b.xyz)) *
                   length(q);
  return sum > 0.0 ? 4.0 * FLOAT_STEP * 2.0 * products / sum : 1.0;
}

/* How far float32 may move the depth `values` (one per corner: view
 * depths, or window depths where `window` is set) that weights of
 * partner_weight_error interpolate. Only the part in front of the near
 * plane is drawn, so a corner behind it counts as the near plane's depth
 * (a corner behind the eye has no window depth of its own). Window depths
 * are those of the overlay, tested against Blender's depth
 * (foreign_weight_error). */
float partner_depth_error(vec2 p, vec4 a, vec4 b, vec4 c, vec3 values, bool window)
{
  bvec3 in_front = greaterThanEqual(vec3(a.w, b.w, c.w), vec3(near_plane_depth()));
  vec3 nearest = vec3(window ? 0.0 : near_plane_depth());
  values = mix(nearest, values, in_front);
  float span = max(max(values.x, values.y), values.z) - min(min(values.x, values.y), values.z);
  return (window ? foreign_weight_error(p, a, b, c) : partner_weight_error(p, a, b, c)) * span;
}

/* The corners (quad_partner_corner) of the other triangle of `triangle`
 * (corner ids `ids`, edge flags `flags`) and their clip positions, where it
 * has one; else false, with every corner zero. */
bool quad_partner_set_up(
    int triangle, vec4 ids, int flags, out vec4 a, out vec4 b, out vec4 c, out vec4 clip_a, out vec4 clip_b, out vec4 clip_c)
{
  a = b = c = vec4(0.0);
  vec3 corners;
  if (!quad_partner_corners(triangle, ids, flags, corners)) {
    clip_a = clip_b = clip_c = vec4(0.0);
    return false;
  }
  clip_a = vertex_clip(corners.x);
  clip_b = vertex_clip(corners.y);
  clip_c = vertex_clip(corners.z);
  a = quad_partner_corner(clip_a, corner_view_depth(corners.x));
  b = quad_partner_corner(clip_b, corner_view_depth(corners.y));
  c = quad_partner_corner(clip_c, corner_view_depth(corners.z));
  return true;
}

#ifdef REGION_LAYERS
/* quad_partner_set_up for a region triangle of a peeled layer's record
 * (visibility_frag.glsl), its flags from the flag table. */
void quad_partner_window_corners(int triangle, out vec4 a, out vec4 b, out vec4 c)
{
  a = b = c = vec4(0.0);
  if (triangle < 0) {
    return; /* (a corner that provokes no triangle) */
  }
  int flags = TABLE_FLAGS(fetch_texel(triangle_flag_table, triangle));
  vec4 clip_a, clip_b, clip_c;
  quad_partner_set_up(triangle, fetch_texel(triangle_vertices, triangle), flags, a, b, c, clip_a, clip_b, clip_c);
}
#endif

#ifdef NGON_SIBLINGS
/* The other triangles of an n-gon. Its triangles can overlap on screen as
 * a folded quad's two can (a face that is not flat), and a hidden layer is
 * never the visible face itself, so a triangle of an n-gon behind the
 * surface takes the depth of the nearest of its face's other triangles
 * that covers the pixel nearer than it, a hair nearer still, as a quad's
 * triangle takes its other triangle's: dropped exactly where that
 * triangle is the surface. An n-gon's triangles are consecutive in the
 * triangle table (Blender's order), and the face table
 * (cache.GPUMesh.face_table) names each triangle's polygon; the walk from
 * a triangle stops at the first of another face. In such a mesh this
 * takes the place of the quad test: the walk finds a quad's one other
 * triangle too, and a listed n-gon's ear finds a "quad partner" beside it
 * (the triangle sharing its one diagonal), which need not be the nearest.
 * It goes at most NGON_SIBLINGS_MOST triangles each way: past that (an
 * n-gon of more corners whose far triangles fold back over this one) the
 * layer shows. */
const int NGON_SIBLINGS_MOST = 64;

/* Whether triangle `other` (of a table of `rows` texels) is of `face`. */
bool is_same_face(int other, int rows, float face)
{
  return other >= 0 && other < rows && fetch_texel(triangle_faces, other).x == face;
}

/* Of the other triangles of `triangle`'s face, the nearest that covers
 * window point p in front of view depth `depth` (or level with it,
 * nearer_or_level): its corners
 * (quad_partner_corner), their clip positions, the weights of
 * quad_partner_covers and that view depth; false where none does.
 * `level_before`: one of them that comes before `triangle` in the table
 * lies level with it there (then this one is no layer of its own).
 * `drawn_front`: as culled_partner's (a culled one covers nothing). */
bool nearest_ngon_sibling(int triangle,
                          vec2 p,
                          float depth,
                          bool drawn_front,
                          out vec4 a,
                          out vec4 b,
                          out vec4 c,
                          out vec4 clip_a,
                          out vec4 clip_b,
                          out vec4 clip_c,
                          out vec3 weights,
                          out float sibling_depth,
                          out bool level_before)
{
  a = b = c = clip_a = clip_b = clip_c = vec4(0.0);
  weights = vec3(0.0);
  sibling_depth = 0.0;
  level_before = false;
  bool found = false;
  float face = fetch_texel(triangle_faces, triangle).x;
  ivec2 size = textureSize(triangle_faces, 0);
  int rows = size.x * size.y;
  for (int step = -1; step <= 1; step += 2) {
    for (int k = 1; k <= NGON_SIBLINGS_MOST; k++) {
      int other = triangle + step * k;
      if (!is_same_face(other, rows, face)) {
        break;
      }
      vec3 ids = fetch_texel(triangle_vertices, other).xyz;
      vec4 ca = vertex_clip(ids.x), cb = vertex_clip(ids.y), cc = vertex_clip(ids.z);
      vec4 qa = quad_partner_corner(ca, corner_view_depth(ids.x));
      vec4 qb = quad_partner_corner(cb, corner_view_depth(ids.y));
      vec4 qc = quad_partner_corner(cc, corner_view_depth(ids.z));
      vec3 w;
      float d;
      if (!quad_partner_covers(p, qa, qb, qc, w, d) || !nearer_or_level(d, depth) ||
          culled_partner(qa, qb, qc, drawn_front)) {
        continue;
      }
      /* Two triangles of the face level with each other at the pixel are
       * one layer (image model §5.4): the one later in the table leaves it
       * to the earlier. */
      level_before = level_before || (step < 0 && abs(d - depth) <= depth * LEVEL_DEPTH);
      if (!found || d < sibling_depth) {
        found = true;
        sibling_depth = d;
        a = qa;
        b = qb;
        c = qc;
        clip_a = ca;
        clip_b = cb;
        clip_c = cc;
        weights = w;
      }
    }
  }
  return found;
}
#endif
