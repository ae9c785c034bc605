/* The frame's composite (DESIGN.md step 7): linear RGB = direct + albedo / pi * E_IIM. albedo is per
 * lightmap texel (base colour factor x texture at the texel's centre, fixed at creation); E_IIM is the
 * displayed IIM texture. Both are sampled together with a bilinear filter that only weighs covered, valid
 * texels (back-face fraction <= the limit), so gutters and invalid texels never darken a chart's border.
 * Mirror and glass (no lightmap texels) and the background get no indirect light. Programs and targets
 * persist. */
#ifndef LM_COMPOSITE_H
#define LM_COMPOSITE_H

#include "../charts/charts.h"

typedef struct lm_composite lm_composite;

/* Builds the albedo/pi atlas texture and the program. Needs a current GL context. */
lm_status lm_composite_create(const lm_scene *s, const lm_atlas *a, float backface_limit, lm_composite **out,
                              lm_error *err);
void lm_composite_free(lm_composite *c);
/* The frame: rgb = direct + albedo / pi * E (iim_tex: atlas-sized RGBA32F, a = back-face fraction),
 * summed on the GPU by one full-screen pass and read back as one image (width*height*3 floats, row 0 at
 * the top). direct_tex and uv_tex: width x height RGBA32F textures of the direct light and of each
 * pixel's lightmap uv ((-1, -1) where none) — lm_direct_texture and lm_direct_uv_texture — so the
 * composite draws no geometry. */
lm_status lm_composite_frame(lm_composite *c, unsigned iim_tex, unsigned direct_tex, unsigned uv_tex, int width,
                             int height, float *rgb, lm_error *err);
/* The albedo / pi of texel (x, y) (rgb) and whether it is covered (return 1). For tests. */
int lm_composite_albedo(const lm_composite *c, int x, int y, float out[3]);

#endif
