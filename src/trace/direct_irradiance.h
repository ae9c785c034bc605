/* Direct irradiance at a surface point from the scene's emitters, computed rather than estimated from
 * photon hits: what an AIM texel gets in place of its first hits (photonmap/aim.h).
 *
 * Why: an N-nearest photon estimate is a blur of radius r (the N-th hit's distance). Across a hard
 * shadow edge, such as the floor where it meets a box, the lit side's hits spread into the shadow, and
 * every receiver that sees that floor up close (the box's own faces) gathers too much (the shared Cornell
 * box's small box read 21-34% bright per face, docs/aim.md). Direct light computed per point has no
 * such blur; photons are then left with the smooth part, light that bounced at least once.
 *
 *   point, spot, directional light (when `punctual` is set): E = I att cos / d^2 (or E_sun cos) times one
 *   shadow ray;
 *   emissive triangles: trace/emitter_light.h (Lambert's closed form, visibility sampled), when
 *   lm_emitter_light_suits the scene; otherwise (`area` NULL) their direct light stays with the photons.
 *
 * Which photon hits that replaces: lm_direct_covers_hit. Cost per point: one shadow ray per punctual light
 * plus the emitter light's rays per emissive triangle. Thread-safe (Embree queries and reads only);
 * deterministic for a given seed. Lights and scene are read as they are at the call (current node
 * matrices and emitter placement, lm_emitters_update). */
#ifndef LM_DIRECT_IRRADIANCE_H
#define LM_DIRECT_IRRADIANCE_H

#include <stdint.h>

#include "../scene/scene.h"
#include "emitter_light.h"
#include "lights.h"
#include "photon_store.h"
#include "rt_scene.h"

/* lm_direct_light.punctual: none, every point, spot and directional light, or directional lights alone (a
 * sun's photons are spread over the whole scene, so its sharp, strong light is the first to starve). */
enum { LM_DIRECT_NONE = 0, LM_DIRECT_PUNCTUAL = 1, LM_DIRECT_SUNS = 2 };

typedef struct {
    const lm_scene *scene;
    const lm_rt *rt;
    const lm_emitters *em;            /* punctual lights: every one whose radiant is non-zero */
    const lm_emitter_light *area;     /* NULL: emissive triangles are left to the photons */
    int punctual;                     /* which punctual lights are computed (LM_DIRECT_*); the rest are left to
                                       * the photons */
    float lift;                       /* ray origins this far off the surface (world units) */
    float cover;                      /* a side with other geometry closer than this straight out from it
                                       * gets nothing, as photons store no hit there (trace/photons.h's
                                       * cover_distance: a lamp millimetres under a ceiling); <= 0: off */
    const float *cover_by_surface;    /* with cover > 0: per surface id instead (trace/photons.h's
                                       * cover_by_surface); NULL: cover everywhere */
} lm_direct_light;

/* Irradiance at world point p of a surface with unit geometric normal n, from the front side only, or
 * from both sides added (two_sided: a double-sided material, whose photon estimate counts both). A
 * punctual light's cosine, and an emissive triangle's, is taken with the unit shading normal ns (NULL: n;
 * either side, it is turned to n's), as the reference, the photons' arrival weight and the frame's direct
 * pass take it: on a terrain of smooth normals over coarse triangles the two differ by tens of degrees
 * (truck-town's grass beside the retaining wall: half the light), light that grazes a surface differs by
 * ten times (a ceiling beside a slab lamp's 1 cm edges), and a light on the other side of either gives
 * nothing. seed picks the emitter light's sample pattern (pass the same one for the same point: no
 * flicker). Returns 0 when every side asked for is covered (d->cover on `surface`: out is 0, and the point
 * is hidden, not dark), else 1. */
int lm_direct_irradiance(const lm_direct_light *d, int surface, const float p[3], const float n[3], const float ns[3],
                         int two_sided, uint32_t seed, float out[3]);
/* What lm_direct_irradiance computes, at a point known to be seen (a gather ray's hit,
 * photonmap/hemicube_rim.h): no cover test; one shadow ray per punctual light facing the side(s) (d->punctual
 * says which), and the emissive triangles' light where d->area is set (its rays per triangle, seed as
 * above). */
void lm_direct_at_hit(const lm_direct_light *d, const float p[3], const float n[3], const float ns[3], int two_sided,
                      uint32_t seed, float out[3]);

/* 1 when hit h carries light that lm_direct_irradiance computes (a first hit of a punctual light, or of
 * an emissive triangle when d->area is set; never the sky's): an estimate that adds lm_direct_irradiance
 * leaves it out. */
static inline int lm_direct_covers_hit(const lm_direct_light *d, const lm_hit *h)
{
    return h->bounce == 0 && (h->source == LM_HIT_FROM_PUNCTUAL ? d->punctual == LM_DIRECT_PUNCTUAL
                              : h->source == LM_HIT_FROM_SUN ? d->punctual != LM_DIRECT_NONE
                              : h->source == LM_HIT_FROM_AREA && d->area != NULL);
}
/* 1 when emitter em's first hits are ones lm_direct_covers_hit leaves out: an edit of its power changes
 * the direct light computed, not only the photons an estimate sums. */
static inline int lm_direct_covers_emitter(const lm_direct_light *d, const lm_emitter *em)
{
    return em->kind == LM_EMIT_DIRECTIONAL ? d->punctual != LM_DIRECT_NONE
           : em->kind == LM_EMIT_AREA      ? d->area != NULL
           : em->kind == LM_EMIT_SKY       ? 0
                                           : d->punctual == LM_DIRECT_PUNCTUAL;
}
/* The flux of the live hits lm_direct_covers_hit leaves out, summed per surface into
 * out[surface * 3 + c] (surface_count x 3 doubles, overwritten). O(slots). */
void lm_direct_covered_flux(const lm_direct_light *d, const lm_photon_store *ps, double *out);

#endif
