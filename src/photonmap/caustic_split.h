/* Caustic light split between the lightmaps and the screen (docs/caustics.md, "Thin light in the
 * lightmaps"): the screen-space caustic pass filters its photons only on the screen tiles that hold some,
 * but a convex mirror or a glass ball spreads thin light over a whole room, so nearly every tile holds a
 * few and the culling saves nothing. Light that is thin next to a texel's other light is smooth enough
 * for the lightmap: it is estimated per texel here and added to the frame's indirect term
 * (gpu/frame/composite.h), and only the photons where caustics are concentrated go to the screen pass.
 *
 * Each landed caustic photon is placed on the atlas texel under it (its triangle's lightmap uv at the
 * photon's barycentric point, lm_atlas.coverage_uv; a photon on a gutter texel takes the nearest covered
 * texel of its chart within one texel). Per covered texel t (summed-area tables over each chart make
 * every window four reads):
 *
 *     E_c(t) = sum of the flux of the photons on W_r(t) / sum of the world areas of W_r(t)'s texels
 *
 * over W_r(t), the texels of t's chart within r texels of it (a (2r+1)^2 window), r the smallest of 0 ..
 * LM_CAUSTIC_SPLIT_REACH whose window holds LM_CAUSTIC_SPLIT_PHOTONS photons (a focal spot's texel alone
 * is its own window, so its light is not averaged away before it is judged). t is thin when
 *
 *     Y(E_c(t)) < fraction x E_other(surface of t)   and   Y(E_c(t)) < fraction x E_other(t)
 *
 * (Y the luminance), the photon densities of W_r(t)'s halves either side of t (along x, and along y)
 * differ by at most LM_CAUSTIC_SPLIT_SIGMA standard deviations (no structure the texels would blur: a
 * focal spot's rim), and W_r(t)'s middle is not much denser than W_r(t) (LM_CAUSTIC_SPLIT_GATHERED: the
 * window is not wider than the light in it, as for a fan at grazing incidence a few texels across). E_other(surface) is the surface's mean irradiance other than the caustic photons':
 * pi Y(L_aim) / Y(kd) over its texels by area (the AIM's radiance L_aim counts all the light arriving, the
 * global map's caustic photons included) less the caustic photons' flux over its area; E_other(t) the
 * same at t (pi Y(L_aim(t)) / Y(kd(t)) - Y(E_c(t))). The surface's keeps a focal spot, whose light the AIM
 * blurs into its neighbours, from being measured against itself; the texel's keeps a patch as bright as
 * the light around it (a glass block's) on screen. A photon on a thin texel is carried by the lightmap layer: each texel's thin
 * photons are spread evenly over its own window's area (so their power is kept exactly). Every other
 * photon (a concentrated texel, no texel under it, a node whose indirect light is off) stays with the
 * screen pass. No light is lost or counted twice: each photon is in one of the two.
 *
 * Cost: one pass over the photons (three vertex transforms each), one over the texels (their kd) and,
 * per chart, two summed-area tables and up to LM_CAUSTIC_SPLIT_REACH + 7 window reads a texel (OpenMP over
 * charts, each chart's sums in a fixed order, so the result does not depend on the thread count).
 * Memory: the layer (16 bytes an atlas cell), 26 bytes an atlas cell and 8 a surface of scratch, 64 bytes
 * a cell of the largest chart per thread, and a copy of the photons for the screen. Errors: out of memory. */
#ifndef LM_CAUSTIC_SPLIT_H
#define LM_CAUSTIC_SPLIT_H

#include <stdint.h>

#include "../charts/charts.h"
#include "../core/error.h"
#include "../trace/caustics.h"

/* Photons a texel's window should hold: thin light is smooth, so its estimate may be wide (at 32 the
 * Cornell box's layer at 65,536 texels showed the windows' squares; docs/caustics.md) */
#define LM_CAUSTIC_SPLIT_PHOTONS 128
#define LM_CAUSTIC_SPLIT_REACH 16    /* the widest window's half side, texels */
/* Standard deviations between a window's halves that make it structure: at 3 the edges of every reflected
 * patch went to the screen (465 of 1,788 texels of the Cornell box, 127 of 256 tiles lit) for no measured
 * accuracy; at 20 the focal spot's rim does (22 texels, 9 tiles), and without the test it blurs (the
 * caustic part's relative RMSE 0.13 instead of 0.08) */
#define LM_CAUSTIC_SPLIT_SIGMA 20.0
/* How much denser than its whole window a window's middle may be and its light still be thin (over
 * 1 + this times the window's density), and by how many standard deviations (caustic_split.c,
 * gathered_in_middle). At 0.5 the grazing hard case read 1.01 of the reference and the Cornell showcase
 * lit 52 of 256 tiles; at 1, 0.94 and 12; at 2 the fan was thin (0.17). */
#define LM_CAUSTIC_SPLIT_GATHERED 1.0
#define LM_CAUSTIC_SPLIT_GATHERED_SIGMA 4.0
/* The screen filter's widening (gpu/frame/caustic_pass.h widen_levels) when the photons are split: 2x,
 * not 8x, so its reach is 10 pixels, not 40 (a lit tile is filtered with its 8 neighbours, not 24) */
#define LM_CAUSTIC_SPLIT_WIDEN 1
/* The fraction measured best, the default (docs/caustics.md; include/lmgi_knobs.h says it too) */
#define LM_CAUSTIC_THIN_DEFAULT 0.25f

typedef struct {
    float *thin;             /* atlas width x height x 4: rgb E_thin (irradiance), a 1 on covered texels of
                              * nodes that take indirect light, else 0 (gutters hold rgb 0 too) */
    lm_caustic_hit *screen;  /* the photons for the screen pass: the input's, thin ones' flux set to 0 */
    uint32_t count;          /* slots of screen (the input's count) */
    uint32_t landed, thin_photons; /* photons that landed, and of those the ones the lightmaps carry */
    uint32_t texels_lit, texels_concentrated; /* covered texels with caustic light in their window, and of
                                               * those the ones left to the screen */
} lm_caustic_split;

/* Splits hits[0 .. count) (slots of flux 0 hold no photon) over the atlas a of scene s, each by its
 * triangle and barycentrics (so a receiver that moved since the trace keeps them where they fell).
 * aim_rgb: the AIM's radiance (a->width x a->height x 3). fraction > 0 (see above). *out is replaced
 * (lm_caustic_split_free first if it held one); on failure it is left empty. */
lm_status lm_caustic_split_make(const lm_scene *s, const lm_atlas *a, const float *aim_rgb, const lm_caustic_hit *hits,
                                uint32_t count, float fraction, lm_caustic_split *out, lm_error *err);
void lm_caustic_split_free(lm_caustic_split *sp);

#endif
