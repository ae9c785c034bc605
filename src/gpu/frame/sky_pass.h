/* The sky drawn behind everything (docs/levels.md, "Sky"): a frame's background and an environment map's
 * faces show a gradient or image sky as it is by direction, where the first pass's clear can give only one
 * colour (a uniform sky needs no pass).
 *
 * One full-screen triangle before the geometry, depth untouched, written to colour attachment 0 alone: each
 * pixel's view ray from the inverse of the view's projection, the sky's radiance along it by the rule of
 * scene/sky.h (the image uploaded as an RGB32F texture, wrapped round in azimuth, bilinear). The image is
 * uploaded again only when the scene's image changes (its pointer and size).
 *
 * Errors: LM_ERR_BACKEND when the GL refuses the program. Thread-safety: the GL context's. */
#ifndef LM_SKY_PASS_H
#define LM_SKY_PASS_H

#include "../../core/error.h"
#include "../../scene/scene.h"

typedef struct {
    unsigned prog, vao, image_tex;
    const float *uploaded;  /* the scene image the texture holds */
    int width, height;
} lm_sky_pass;

lm_status lm_sky_pass_init(lm_sky_pass *p, lm_error *err);
void lm_sky_pass_free(lm_sky_pass *p);
/* Draws s's sky behind view (column-major view and projection) into the bound framebuffer's attachment 0,
 * when it is not uniform; nothing otherwise. Leaves depth testing, the depth mask and colour masks as the
 * first pass sets them (on, on, all). */
void lm_sky_pass_draw(lm_sky_pass *p, const lm_scene *s, const float view[16], const float proj[16]);

#endif
