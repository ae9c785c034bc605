/* A picture of the scene with a lightmap atlas on its surfaces (an AIM or IIM holding outgoing
 * radiance), rendered with OpenGL and tone-mapped (core/tonemap.h). Triangles without lightmap texels
 * (mirror, glass) are drawn mid-grey. */
#ifndef LM_LIGHTMAP_VIEW_H
#define LM_LIGHTMAP_VIEW_H

#include <stdint.h>

#include "../../charts/charts.h"
#include "../../core/camera.h"

/* Three unshared corners per triangle, 5 floats each: world position (current node matrices) and
 * lightmap UV, with UV (-1, -1) for triangles without lightmap texels. The caller frees it; NULL when
 * memory ran out. */
float *lm_lightmapped_vertices(const lm_scene *s, const lm_atlas *a);

/* rgb: atlas-sized RGB floats (dilated into the gutters by the caller). exposure: the tone map's k.
 * Writes rgba8 (width*height*4, row 0 at the top). Needs a current GL context. */
lm_status lm_render_lightmap(const lm_scene *s, const lm_atlas *a, const float *rgb, float exposure,
                             const lm_view *view, int width, int height, uint8_t *rgba8, lm_error *err);

/* What an atlas texture of irradiance holds (rgb E, a each texel's weight, rgb 0 where a is: the composite's
 * caustics, composite.h) at each pixel of view, the bilinear filter's rgb / a (tex must sample linearly),
 * added into rgb (width x height x 3 floats, row 0 at the top); nothing where a triangle without lightmap
 * texels or the background is seen. Depth-tested as the frame is, so only visible surfaces add. Needs a
 * current GL context. Errors: out of memory, a GL error. */
lm_status lm_render_atlas_irradiance(const lm_scene *s, const lm_atlas *a, unsigned tex, const lm_view *view,
                                     int width, int height, float *rgb, lm_error *err);

#endif
