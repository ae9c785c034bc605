/* A picture of the scene with each surface in its own flat colour (specular triangles grey), rendered
 * with OpenGL into an offscreen framebuffer: how a user checks the automatic surface split. */
#ifndef LM_SURFACE_VIEW_H
#define LM_SURFACE_VIEW_H

#include <stdint.h>

#include "../charts/charts.h"
#include "camera.h"

/* Renders into rgba8 (width*height*4 bytes, row 0 at the top). Needs a current GL context. */
lm_status lm_render_surface_ids(const lm_scene *s, const lm_surfaces *su, const lm_view *view, int width,
                                int height, uint8_t *rgba8, lm_error *err);

#endif
