/* Indirect light for the visible picture straight from the photons, without AIMs or a hemicube: the
 * photon density estimate of Mara, McGuire, Nowrouzezahrai & Luebke (2013), eq. 1, at each pixel's
 * visible point X,
 *
 *     L(X) = kd(X) / pi * sum_P Phi_P kappa(|Y_P - X|) / (pi c (1 - c + c^2 / 3) r^2)
 *
 * over the stored photon hits P (position Y_P, flux Phi_P) within r of X that lie on X's surface or on one
 * that continues it smoothly (P's side normal, lm_hit_side_normal, within 60 degrees of X's normal, P
 * within r / 2 of X's tangent plane), with the paper's kernel kappa(s) = min(c, 1 - s / r), c = 1/5 (eq. 2; the denominator is its integral over
 * the disc, eq. 3), the diffuse BSDF kd / pi (kd the diffuse lobe, docs/materials.md) and one radius r
 * for every photon (the paper's constant-radius case, in which every gather order gives the same
 * picture). The paper's sphere alone lets a photon light the other side of a thin wall and the wall
 * across a corner: the outside of the shared Cornell box's ceiling, lit by nothing, read as bright as its
 * inside. The side test keeps each photon to its own surface and those that continue it, as the lightmap
 * path's per-surface photon maps do; where the disc crosses the surface's edge the frame divides by the
 * part of it on the surface (lm_aim_pixel_coverage), as the AIM does (docs/tiled.md).
 * The hits are those an IIM holds (lm_hit_in_iim): every stored hit but the punctual lights'
 * first ones, whose light the direct pass draws per pixel, and the caustic ones (off mirrors and glass
 * only), whose light the caustic pass draws.
 *
 * r: the radius of a disc that holds n photons on average, r = sqrt(n A / (pi H)), A the surfaces' world
 * area and H the hits gathered (the N of the AIM's N-nearest estimate, so that both paths blur alike on
 * average; docs/tiled.md, "The estimate").
 *
 * This is the brute-force iteration (every photon against every pixel: O(pixels x hits), seconds at
 * 512 x 512 and tens of thousands of hits, on the calling thread's OpenMP team), the ground truth for
 * faster gathers. The visible points come from primary rays through the pixel centres (lm_gbuffer).
 * Deterministic: each pixel sums its hits in store order. Not thread-safe against store updates. */
#ifndef LM_PIXEL_GATHER_H
#define LM_PIXEL_GATHER_H

#include <stdint.h>

#include "../charts/charts.h"
#include "../core/camera.h"
#include "../core/error.h"
#include "../scene/scene.h"
#include "../trace/photon_store.h"
#include "../trace/rt_scene.h"

/* What each pixel sees: its visible point, the shading normal on the eye's side, and kd there (0 for
 * mirror, glass, the back of a single-sided surface and the background, which take no indirect term). */
typedef struct {
    int width, height;
    float *pos, *normal, *kd; /* 3 floats per pixel each, row 0 at the top */
} lm_gbuffer;

/* Casts one ray through each pixel's centre of cam's pinhole (core/camera.h, lm_view_pinhole). Grows g's
 * arrays as the size asks (g zero-initialised the first time). */
lm_status lm_gbuffer_trace(lm_gbuffer *g, const lm_scene *s, const lm_rt *rt, const lm_view *cam, lm_error *err);
void lm_gbuffer_free(lm_gbuffer *g);

/* The hits the per-pixel gathers' default radius holds on average: the AIMs' N of 128 they were measured
 * with (docs/tiled.md), kept when the AIMs' default went to 32 (a quarter of those photons per pixel is
 * a quarter of the samples, where an AIM texel's estimate is averaged again by the hemicube). */
#define LM_PIXEL_GATHER_HITS 128

/* r = sqrt(n A / (pi H)) over the store's hits that the gather takes (H) and the surfaces' area (A);
 * 0 when there are none. */
float lm_pixel_gather_radius(const lm_photon_store *ps, const lm_surfaces *su, int n);
/* out (3 floats per pixel): L(X) above for every pixel of g, every gathered hit tested against every
 * pixel. s: the scene the hits lie on (lm_hit_side_normal; NULL: their arrival directions stand in). */
void lm_pixel_gather_bruteforce(const lm_gbuffer *g, const lm_photon_store *ps, const lm_scene *s, float radius,
                                float *out);

#endif
