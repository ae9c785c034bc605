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

#endif
