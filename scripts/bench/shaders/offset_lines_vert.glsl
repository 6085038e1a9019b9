/* offset_lines, second pass: the classic wireframe the papers compare
 * against (NVIDIA whitepaper, "Solid Wireframe" introduction; Baerentzen et
 * al., offset methods). Line primitives over the triangle edges, depth-tested
 * against the fill pass, with every vertex moved LINE_DEPTH_OFFSET towards the
 * camera in NDC depth (z - b w) so the lines win the depth tie with the
 * triangles they lie on. Lines are 1 px (or k px when rendered k times bigger
 * and box-filtered down) without anti-aliasing. */

void main()
{
  vec3 local = pulled_position(float(line_vertex));
  vec4 clip = object_to_clip * vec4(local, 1.0);
  clip.z -= LINE_DEPTH_OFFSET * clip.w;
  emit_corner(local, clip);
}
