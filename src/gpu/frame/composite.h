/* The frame's composite (DESIGN.md step 7): linear RGB = direct + kd / pi * E_IIM, kd the diffuse lobe
 * per pixel (base colour factor x texture at the pixel, docs/materials.md); E_IIM is the displayed IIM
 * texture. This module makes the indirect term's texture: an atlas-sized RGBA32F of
 * (E / pi * w, w), w = 1 on covered, valid texels (back-face fraction <= the limit), else 0,
 * with a bilinear filter; sampled at a visible point's lightmap uv, rgb / a is then the filter over the
 * four nearest texels that weighs only covered, valid ones, so gutters and invalid texels never darken a
 * chart's border. Where none of the four is valid (a floor under a ball hovering less than a texel over
 * it, whose texels are covered: docs/gather.md), the pixel would be black: the same pass gives each
 * invalid texel the mean colour of the valid texels of its surface on the nearest diamond around it
 * (|dx| + |dy| = d <= LM_COMPOSITE_FILL_REACH) at a weight of 1/1024, so such a pixel shows its surface's
 * light around the hole and a valid texel in the footprint still decides the rest. Holes wider than twice
 * the reach stay black at their centre; only hole texels pay for the search. The direct light's first pass
 * multiplies it by kd and adds it (gpu/frame/direct.h, lm_direct_set_indirect): the sum needs no pass of
 * its own. Mirror and glass (no lightmap texels) and the background get no indirect
 * light, nor do nodes whose indirect light is switched off (extras "indirect": false, lmgi_set_node_effects).
 * The caustics' thin light (lm_composite_set_caustics) is added to E_IIM texel by texel in the same pass.
 * Program and target persist. */
#ifndef LM_COMPOSITE_H
#define LM_COMPOSITE_H

#include "../../charts/charts.h"

typedef struct lm_composite lm_composite;

#define LM_COMPOSITE_FILL_REACH 4 /* texels (|dx| + |dy|) a hole texel looks for its surface's light */

/* Builds the coverage texture and the program. Needs a current GL context. */
lm_status lm_composite_create(const lm_scene *s, const lm_atlas *a, float backface_limit, lm_composite **out,
                              lm_error *err);
void lm_composite_free(lm_composite *c);
/* Builds the coverage again after nodes switched their indirect light on or off (lm_node_settings). */
lm_status lm_composite_update_coverage(lm_composite *c, const lm_scene *s, const lm_atlas *a, lm_error *err);
/* The indirect term from iim_tex (atlas-sized RGBA32F, a = back-face fraction) into *lit_tex (owned by c,
 * valid until the next call). One atlas-sized pass. */
lm_status lm_composite_indirect(lm_composite *c, unsigned iim_tex, unsigned *lit_tex, lm_error *err);
/* The caustics' thin light the lightmaps carry (photonmap/caustic_split.h): atlas-sized RGBA floats, rgb
 * the irradiance each texel adds to E_IIM in the indirect term from the next lm_composite_indirect on.
 * NULL: none (the default). Copied to a texture c owns. Errors: a GL error. */
lm_status lm_composite_set_caustics(lm_composite *c, const float *thin, lm_error *err);
/* That texture (rgb E, a 1 on texels that show indirect light), 0: none. */
unsigned lm_composite_caustics_texture(const lm_composite *c);

#endif
