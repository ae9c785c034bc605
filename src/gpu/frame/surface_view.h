/* A picture of the scene with each surface in its own flat colour (specular triangles grey), rendered
 * with OpenGL into an offscreen framebuffer: how a user checks the automatic surface split. */
#ifndef LM_SURFACE_VIEW_H
#define LM_SURFACE_VIEW_H

#include <stdint.h>

#include "../../charts/charts.h"
#include "../../core/camera.h"

/* Renders into rgba8 (width*height*4 bytes, row 0 at the top). Needs a current GL context. */
lm_status lm_render_surface_ids(const lm_scene *s, const lm_surfaces *su, const lm_view *view, int width,
                                int height, uint8_t *rgba8, lm_error *err);

/* The same picture as surface indices (width*height, row 0 at the top): the surface seen at each pixel
 * centre, -1 for a specular triangle, -2 for nothing. No blending or filtering: the colour channels carry
 * the index exactly (up to 2^24 - 2 surfaces). Needs a current GL context. */
lm_status lm_render_surface_index(const lm_scene *s, const lm_surfaces *su, const lm_view *view, int width,
                                  int height, int32_t *ids, lm_error *err);

#endif
