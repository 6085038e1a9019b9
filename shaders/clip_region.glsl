/* The viewport's clipping region (Alt+B; docs/image_model.md §5.6,
 * USE_CLIP_PLANES): signed distances to its clip-space planes
 * (draw.clip_space_planes), linear in clip space so that the interpolated
 * values are exact; a fragment where one is negative lies outside and is
 * discarded. clip_distances() writes them, so a stage that reads them as
 * inputs (a fragment stage) defines SW_CLIP_DISTANCES_IN before this file. */

#if defined(USE_CLIP_PLANES) && !defined(SW_CLIP_DISTANCES_IN)
void clip_distances(vec4 position)
{
  clip_distance_a = vec4(dot(clip_params.planes[0], position),
                         dot(clip_params.planes[1], position),
                         dot(clip_params.planes[2], position),
                         dot(clip_params.planes[3], position));
  clip_distance_b = vec2(dot(clip_params.planes[4], position), dot(clip_params.planes[5], position));
}
#endif

/* Outside the clipping region nothing of the face exists. */
bool outside_clip_region()
{
#ifdef USE_CLIP_PLANES
  return min(min(min(clip_distance_a.x, clip_distance_a.y), min(clip_distance_a.z, clip_distance_a.w)),
             min(clip_distance_b.x, clip_distance_b.y)) < 0.0;
#else
  return false;
#endif
}
