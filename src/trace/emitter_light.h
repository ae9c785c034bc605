/* Irradiance from the scene's emissive triangles at a point, for the final gather (gpu/gather/hemicube.h).
 *
 * A small emitter covers only a few hemicube pixels, and which pixels it covers changes from texel to
 * texel: the gathered irradiance steps between neighbours (plaid). Here each emissive triangle's light
 * is instead computed in closed form and only its visibility is sampled:
 *
 *     E = sum_j Le_j * E_j * V_j
 *
 * E_j: the triangle's unoccluded irradiance per unit radiance, Lambert's polygon formula
 *      E_j = 1/2 |sum_i theta_i (n . g_i)| (theta_i the angle an edge subtends, g_i the unit normal of
 *      the plane through the point and that edge) over the triangle clipped to the point's upper
 *      hemisphere; zero behind a single-sided emitter.
 * V_j: the fraction of it the point sees, sum(f v) / sum(f) over `rays` stratified points on the clipped
 *      triangle, f the unoccluded integrand cos cos' / r^2 and v = 1 where a shadow ray (Embree) reaches
 *      the point. The sample pattern is shifted per `seed` (the texel), so it is the same every time a
 *      texel is gathered (deterministic, no flicker) but differs between neighbours.
 *
 * Fully visible emitters are exact (no sampling error at all); only penumbrae carry sampling noise,
 * which falls as 1/sqrt(rays). Cost per point: the emissive triangle count times `rays` shadow rays, so
 * lm_emitter_light_suits limits it to scenes with few emissive triangles (big emissive meshes cover
 * many pixels and are gathered by rasterization). */
#ifndef LM_EMITTER_LIGHT_H
#define LM_EMITTER_LIGHT_H

#include <stdint.h>

#include "../core/error.h"
#include "../scene/scene.h"
#include "rt_scene.h"

/* At most this many emissive triangles for the closed form (lm_emitter_light_suits). */
#define LM_EMITTER_LIGHT_MAX_TRIANGLES 64
/* Default shadow rays per emissive triangle. */
#define LM_EMITTER_LIGHT_DEFAULT_RAYS 32

typedef struct {
    const lm_scene *scene; /* borrowed: vertices are read under the current node matrices at each call */
    const lm_rt *rt;       /* borrowed: must follow the same node matrices */
    uint32_t *tris;        /* the emissive triangles */
    int count;
    int rays;              /* shadow rays per triangle */
} lm_emitter_light;

/* Emissive triangles in s (a material with a non-zero emissive factor). */
uint32_t lm_emissive_triangle_count(const lm_scene *s);
/* 1 when s has emissive triangles, at most LM_EMITTER_LIGHT_MAX_TRIANGLES of them. */
int lm_emitter_light_suits(const lm_scene *s);
/* Lists s's emissive triangles. rays: shadow rays per triangle, >= 1. */
lm_status lm_emitter_light_init(lm_emitter_light *el, const lm_scene *s, const lm_rt *rt, int rays, lm_error *err);
void lm_emitter_light_free(lm_emitter_light *el);
/* Irradiance at p (world), surface normal n (unit), from every emissive triangle; rays leave from p, so
 * lift p off its surface first. ng (unit, or NULL: n): the surface's geometric normal, where n is a
 * shading normal that may lean away from it. Only what lies above both horizons lights p: a shading normal
 * leaning over the surface's own plane (a slab lamp's smoothed edges) would otherwise see the emitter the
 * point lies on, at the lift's distance; where no corner lies below the geometric horizon by more than a
 * float normal's rounding, the polygon is left as it was. Thread-safe (Embree queries only). */
void lm_emitter_irradiance(const lm_emitter_light *el, const float p[3], const float n[3], const float ng[3],
                           uint32_t seed, float out[3]);
/* The unoccluded part alone for one triangle (world corners v[3][3]): E_j above, 0 when p is behind a
 * single-sided emitter or the triangle lies below p's horizon. */
double lm_triangle_irradiance_factor(const float v[3][3], int double_sided, const float p[3], const float n[3]);

#endif
