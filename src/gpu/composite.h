/* The indirect half of a frame's composite (DESIGN.md step 7): the scene from a view, each pixel holding
 * albedo / pi * E_IIM, linear RGB floats. albedo is per lightmap texel (base colour factor x texture at
 * the texel's centre, fixed at creation); E_IIM is the displayed IIM texture. Both are sampled together
 * with a bilinear filter that only weighs covered, valid texels (back-face fraction <= the limit), so
 * gutters and invalid texels never darken a chart's border. Mirror and glass (no lightmap texels) and
 * the background are black. lm_composite_frame adds the direct image on the GPU. Programs, targets and
 * (lm_composite_indirect) the lightmapped vertex buffer, only moved nodes re-uploaded, persist. */
#ifndef LM_COMPOSITE_H
#define LM_COMPOSITE_H

#include "../charts/charts.h"
#include "camera.h"

typedef struct lm_composite lm_composite;

/* Builds the albedo/pi atlas texture and the program. Needs a current GL context. */
lm_status lm_composite_create(const lm_scene *s, const lm_atlas *a, float backface_limit, lm_composite **out,
                              lm_error *err);
void lm_composite_free(lm_composite *c);
/* Renders albedo / pi * E (iim_tex: atlas-sized RGBA32F, a = back-face fraction) under the current node
 * matrices into rgb (width*height*3 floats, row 0 at the top). */
lm_status lm_composite_indirect(lm_composite *c, const lm_scene *s, const lm_atlas *a, unsigned iim_tex,
                                const lm_view *view, int width, int height, float *rgb, lm_error *err);
/* The frame: rgb = direct + albedo / pi * E, summed on the GPU by one full-screen pass and read back as
 * one image. direct_tex and uv_tex: width x height RGBA32F textures of the direct light and of each
 * pixel's lightmap uv ((-1, -1) where none) — lm_direct_texture and lm_direct_uv_texture — so the
 * composite draws no geometry. When indirect is not NULL, the indirect part alone is read back into it
 * too (a second colour attachment). */
lm_status lm_composite_frame(lm_composite *c, unsigned iim_tex, unsigned direct_tex, unsigned uv_tex, int width,
                             int height, float *rgb, float *indirect, lm_error *err);
/* The albedo / pi of texel (x, y) (rgb) and whether it is covered (return 1). For tests. */
int lm_composite_albedo(const lm_composite *c, int x, int y, float out[3]);

#endif
