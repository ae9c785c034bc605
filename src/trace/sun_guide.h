/* A sun's photons drawn where the lightmap's texels are (docs/photons.md, "Where a sun's photons go").
 *
 * A sun's photons leave a rectangle across its direction that covers the level (lights.c), uniformly, so
 * they land in proportion to the area the sun sees. On a level whose open ground has texels up to 64 times
 * coarser than its town's (charts.h, lm_atlas_options.open_need) that spends them where no texel needs
 * them: 1% of truck-town's landed in the town. The guide draws a photon's origin on the rectangle from a
 * density that is constant over each of LM_GUIDE_CELLS x LM_GUIDE_CELLS cells:
 *
 *     p(cell) = (1 - LM_GUIDE_UNIFORM) w(cell) / sum w  +  LM_GUIDE_UNIFORM / cells
 *
 * w(cell) what its lines are worth: the texel density where each first lands, relative to the atlas's,
 * (atlas texel size / the surface's)^2, at most 1, so that only open surfaces' lines lose photons (1 on
 * mirrors and glass, where the light passes on; 0 where the line hits nothing); on an open surface at least
 * the share of LM_GUIDE_BOUNCES cosine bounces from where it lands that reach texels at the atlas's density
 * (with the sun's direct light computed exactly a photon is worth its bounces: the open ground at a town's
 * edge keeps the photons that light its walls). Each cell takes the largest w of its own and its eight
 * neighbours', so that no cell whose lines all missed a house's edge draws that edge's photons seldom and
 * heavy. Each photon's flux is divided by the density at its origin (over the uniform one's), so the estimate
 * is the uniform rectangle's; the uniform share bounds a photon's flux at 1 / LM_GUIDE_UNIFORM times a
 * uniform photon's. w is read from LM_GUIDE_LINES lines a cell, through the scene as it is when the guide is
 * made; lines of nodes moved since still draw from it, unbiased.
 *
 * Cost: LM_GUIDE_CELLS^2 x LM_GUIDE_LINES rays to make, and LM_GUIDE_BOUNCES more for each that lands on an
 * open surface (at most 81,920: milliseconds); two binary searches a photon. Thread-safety: read-only once made. */
#ifndef LM_SUN_GUIDE_H
#define LM_SUN_GUIDE_H

#include "../charts/charts.h"
#include "../core/error.h"
#include "../scene/scene.h"
#include "rt_scene.h"

#define LM_GUIDE_CELLS 64
#define LM_GUIDE_LINES 4     /* a 2 x 2 grid in each cell */
#define LM_GUIDE_BOUNCES 4
#define LM_GUIDE_UNIFORM 0.1

typedef struct {
    float rect[3][3];   /* the rectangle it was made for (lm_emitter.rect): a sun whose rectangle moved since
                         * draws uniformly until its guide is made again */
    double *row_cdf;    /* LM_GUIDE_CELLS + 1: the mixture's cumulative over rows (v, the rectangle's 2nd edge) */
    double *col_cdf;    /* LM_GUIDE_CELLS x (LM_GUIDE_CELLS + 1): over each row's cells (u, its 1st edge) */
    double *density;    /* LM_GUIDE_CELLS^2, row-major: p(cell) x cells, the density over the uniform one */
} lm_sun_guide;

/* The guide for a sun of unit direction of travel dir whose photons leave rect (lm_emitter.rect), over atlas
 * a's texels: *out, or NULL where no line lands on an open surface (every w 1 or 0: the uniform rectangle
 * serves, to the bit). Errors: out of memory. */
lm_status lm_sun_guide_make(const lm_rt *rt, const lm_scene *s, const lm_atlas *a, const float rect[3][3],
                            const float dir[3], lm_sun_guide **out, lm_error *err);
void lm_sun_guide_free(lm_sun_guide *g);
/* 1 if a and b would draw the same photons (both NULL, or the same rectangle and densities). */
int lm_sun_guide_same(const lm_sun_guide *a, const lm_sun_guide *b);
/* Maps u (two uniform numbers in [0, 1)) to a point of the rectangle drawn from the guide, in u itself as
 * (u, v) in [0, 1)^2 along its edges, and returns the density there over the uniform one's (> 0). */
double lm_sun_guide_draw(const lm_sun_guide *g, float u[2]);

#endif
