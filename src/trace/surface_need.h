/* How much each surface's lightmap texels are worth, from what its points see.
 *
 * A point's irradiance changes over about the distance R to what it sees: Ward, Rubinstein and Clear's
 * split-sphere model (1988) takes R as the harmonic mean of the hit distances of its hemisphere's rays,
 * and a texel of size t then errs by about t / R. Texels spread so that every one errs alike have a
 * density proportional to (1 / R)^2, so a surface is worth
 *
 *     need = integral over its area of (1 / R)^2 dA        (dimensionless)
 *
 * A ray that hits nothing counts as infinitely far: a level's open ground, whose points see mostly sky,
 * is worth little however large (truck-town's outer ground holds 99.3% of the level's area and 0.2% of
 * its need), and a room's corner much. R is clamped to at least the texel size the budget gives by area
 * alone, since (1 / R)^2 grows without bound towards a contact line and no texel resolves it.
 *
 * Sampling: each surface takes a point per texel of its area (at that texel size), LM_NEED_MIN_POINTS to
 * LM_NEED_POINTS, stratified over its area (by triangle area, one stratum each), and LM_NEED_RAYS
 * cosine-distributed rays from each, from scrambled Halton sequences:
 * deterministic and the same for any thread count. Geometric normals, node transforms as the BVH has
 * them; a ray hitting a back face counts like any other hit.
 *
 * Cost: up to LM_NEED_POINTS x LM_NEED_RAYS closest-hit rays a surface, in parallel over surfaces (OpenMP):
 * 0.04 s for truck-town's 594 surfaces, 0.24 s for a level of 994k triangles and 7,817 surfaces.
 * Thread-safety: reads rt and s only. Errors: out of memory. */
#ifndef LM_SURFACE_NEED_H
#define LM_SURFACE_NEED_H

#include "../charts/charts.h"
#include "../core/error.h"
#include "../scene/scene.h"
#include "rt_scene.h"

#define LM_NEED_POINTS 64
#define LM_NEED_MIN_POINTS 4
#define LM_NEED_RAYS 16

/* need[f] as above and sky[f], the fraction of its rays that hit nothing (su->surface_count entries each,
 * the caller's arrays); texel > 0 in world units. Errors: a texel that is not, out of memory. */
lm_status lm_surface_need(const lm_rt *rt, const lm_scene *s, const lm_surfaces *su, float texel, double *need,
                          double *sky, lm_error *err);

#endif
