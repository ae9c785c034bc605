/* Direct irradiance at a surface point (direct_irradiance.h). */
#include "direct_irradiance.h"

#include "../core/vecmath.h"
#include "photons.h"

#include <math.h>

/* 1 when other geometry lies within the cover distance straight out from p on the side of normal n. */
static int covered(const lm_direct_light *d, float reach, lm_vec3 p, lm_vec3 n)
{
    float at[3], dir[3];
    lm_v3_store(at, p);
    lm_v3_store(dir, n);
    return lm_rt_covered(d->rt, at, dir, d->lift, reach);
}

/* Every punctual light's E = weight cos, where a shadow ray from p (lifted to the side the light is on)
 * reaches it; sides: bit 0 the front (n), bit 1 the back. The side is the geometric normal n's, the cosine
 * the shading normal ns's (on n's side), as the reference's next event takes it; 0 where the two
 * disagree. */
static void punctual(const lm_direct_light *d, lm_vec3 p, lm_vec3 n, lm_vec3 ns, int sides, double e[3])
{
    const float none[3] = {0.0f, 0.0f, 0.0f};
    for (int k = 0; k < d->em->count; k++) {
        const lm_emitter *em = &d->em->e[k];
        if (!em->punctual || (em->radiant[0] == 0.0f && em->radiant[1] == 0.0f && em->radiant[2] == 0.0f) ||
            (d->punctual == LM_DIRECT_SUNS && em->kind != LM_EMIT_DIRECTIONAL))
            continue;
        float at[3];
        lm_v3_store(at, p);
        lm_light_sample ls;
        if (!lm_emitter_sample_toward(d->em, d->scene, k, at, none, &ls))
            continue;
        float cg = lm_dot(n, lm_v3_load(ls.dir)), c = lm_dot(ns, lm_v3_load(ls.dir));
        int front = cg >= 0.0f;
        c = front ? c : -c;
        if (!(sides & (front ? 1 : 2)) || !(c > 0.0f) || cg == 0.0f)
            continue;
        float org[3];
        lm_v3_store(org, lm_add(p, lm_scale(n, front ? d->lift : -d->lift)));
        float far = isinf(ls.dist) ? INFINITY : ls.dist * (1.0f - 1e-4f);
        if (lm_rt_occluded(d->rt, org, ls.dir, 0.0f, far))
            continue;
        for (int ch = 0; ch < 3; ch++)
            e[ch] += (double)ls.weight[ch] * c;
    }
}

/* The emissive triangles' light on the side of geometric normal n, from p lifted to that side: the shading
 * normal ns's cosine (on n's side), as the reference's next event and the photons' arrival weight take it,
 * over what lies above both horizons. Light that grazes a surface whose shading normal leans towards it
 * (a ceiling beside a slab lamp's 1 cm edges, its corner-averaged normals leaning 30 degrees) is many times
 * what the geometric cosine gives: cornell-suzanne's lamp edges lit the room 30% short with it. */
static void area(const lm_direct_light *d, lm_vec3 p, lm_vec3 n, lm_vec3 ns, uint32_t seed, double e[3])
{
    float at[3], nrm[3], geo[3], out[3];
    lm_v3_store(at, lm_add(p, lm_scale(n, d->lift)));
    lm_v3_store(nrm, ns);
    lm_v3_store(geo, n);
    lm_emitter_irradiance(d->area, at, nrm, geo, seed, out);
    for (int c = 0; c < 3; c++)
        e[c] += out[c];
}

/* ns (NULL: n) turned to n's side. */
static lm_vec3 shading_side(const float n[3], const float ns[3])
{
    lm_vec3 nv = lm_v3_load(n), sv = ns ? lm_v3_load(ns) : nv;
    return lm_dot(sv, nv) < 0.0f ? lm_scale(sv, -1.0f) : sv;
}

/* The computed light on the sides asked for (bit 1: n's, bit 2: the back) into out. */
static void computed(const lm_direct_light *d, lm_vec3 p, const float n[3], const float ns[3], int sides,
                     uint32_t seed, float out[3])
{
    double e[3] = {0.0, 0.0, 0.0};
    lm_vec3 nv = lm_v3_load(n), sv = shading_side(n, ns); /* the back's: both turned over */
    if (d->punctual)
        punctual(d, p, nv, sv, sides, e);
    if (d->area && (sides & 1))
        area(d, p, nv, sv, seed, e);
    if (d->area && (sides & 2))
        area(d, p, lm_scale(nv, -1.0f), lm_scale(sv, -1.0f), seed ^ 0x9e3779b9u, e);
    for (int c = 0; c < 3; c++)
        out[c] = (float)e[c];
}

int lm_direct_irradiance(const lm_direct_light *d, int surface, const float p[3], const float n[3], const float ns[3],
                         int two_sided, uint32_t seed, float out[3])
{
    lm_vec3 pv = lm_v3_load(p), nv = lm_v3_load(n);
    float reach = lm_cover_reach(d->cover, d->cover_by_surface, surface);
    int sides = (covered(d, reach, pv, nv) ? 0 : 1) |
                (two_sided && !covered(d, reach, pv, lm_scale(nv, -1.0f)) ? 2 : 0);
    computed(d, pv, n, ns, sides, seed, out);
    return sides != 0;
}

void lm_direct_at_hit(const lm_direct_light *d, const float p[3], const float n[3], const float ns[3], int two_sided,
                      uint32_t seed, float out[3])
{
    computed(d, lm_v3_load(p), n, ns, two_sided ? 3 : 1, seed, out);
}

static int covers(const lm_hit *h, const void *d) { return lm_direct_covers_hit(d, h); }

void lm_direct_covered_flux(const lm_direct_light *d, const lm_photon_store *ps, double *out)
{
    lm_photon_store_surface_flux_of(ps, covers, d, out);
}
