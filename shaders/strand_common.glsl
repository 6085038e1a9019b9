/* SolidWire hair and point clouds: what both stages share
 * (strand_vert.glsl, strand_frag.glsl). */

/* Window pixels per scene unit at clip w = 1, and the object's radius scale. */
#define PX_PER_UNIT strand_view.x
#define RADIUS_SCALE strand_view.y

