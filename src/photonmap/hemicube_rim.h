/* The rim of the hemisphere that the single-plane hemicube does not see (docs/gather.md, "The rim").
 *
 * The plane [-a, a]^2 at distance 1 covers F(a) of the cosine-weighted hemisphere (0.831 at a = 2). The
 * paper divides the plane's sum by F(a), which assumes the rim looks like the rest; a bright source near
 * the horizon (the ceiling around a lamp, seen from a wall) or a dark one (the floor, seen from under a
 * table) makes that wrong by up to 30% per surface. Instead the rim's own irradiance is estimated with
 * rays that all go into the rim:
 *
 *   E_rim = pi / K * sum over K directions of (1 - s_edge(phi)) L(hit)
 *
 * with the azimuth phi uniform and, for each, sin^2(theta) uniform between the plane's edge in that
 * azimuth, s_edge = t^2 / (1 + t^2) with t = a / max(|cos phi|, |sin phi|), and 1: cosine-weighted
 * directions restricted to the rim, each weighted by its azimuth's share of it. E_rim is unbiased, and
 * E = pi sum(w L) + E_rim needs no division by F(a). The K directions are a sqrt(K) x sqrt(K)
 * stratified grid in (phi, sin^2 theta), shifted per texel (its index seeds the shift), so a texel gets
 * the same estimate whenever it is gathered. With enlargement 0 (the rays gather) at a standing texel
 * (|n.y| < 0.05), the grid is upright instead: columns by the angle across the up direction, rows by
 * the elevation against the level, the same cosine-weighted measure, so that a floor seen at grazing
 * angles lies along rows, and each row's rays at its own fraction of their columns, so that a wall seen at
 * grazing angles is not met by a column all or not at all (docs/gather.md, "Upright strata"). Where such
 * a texel stands within 4 texel widths of what lies under it (one ray straight down), the rows within 15
 * degrees under the level are traced as 8 rows each, since the lit floor beyond its contact shadow is a
 * band a fraction of a row high (docs/gather.md, "Contact rows").
 * L(hit) is what the hemicube would show there: the AIM at the hit's lightmap uv (bilinear, from the
 * gather's copy of the dilated AIM), plus the emitted radiance when emitters are drawn rather than in
 * closed form; 0 on the back of a single-sided surface, on mirror and glass; the sky where nothing is hit.
 * With `direct`, the direct part the AIM computes (punctual lights; emissive triangles where direct->area is
 * set) is taken at the hit point itself rather than as its texel's average: a 7 m road texel half in a
 * house's shadow reads as half lit to every wall that sees it, a ray hit reads lit or shadowed as the
 * point is (docs/aim.md, "Suns"); so does the floor at a box's foot in a lamp's contact shadow
 * (docs/gather.md, "Rays"). Only where it matters, with `whole`: a hit a few of its own texels away
 * or nearer, where the eye can tell a point from its texel's average; further hits read the whole AIM,
 * for fewer shadow rays (Jensen's final gather treats its near hits apart for the same reason).
 *
 * Cost: K rays and AIM lookups per texel (about K more at a contact texel, and one ray down at a standing
 * one), on the gather's calling thread while the GPU rasterizes (docs/gather.md, "The rim", for the
 * measured time). Noise: the rim is a band near the horizon; a
 * small bright spot there (the ceiling over a point light, seen from a wall) is what the K rays must
 * resolve, and too few mottle the IIM from texel to texel. Thread-safe (Embree queries and reads only). */
#ifndef LM_HEMICUBE_RIM_H
#define LM_HEMICUBE_RIM_H

#include <stdint.h>

#include "../charts/charts.h"
#include "../trace/direct_irradiance.h"
#include "../trace/rt_scene.h"

typedef struct {
    const lm_scene *scene;
    const lm_atlas *atlas;
    const lm_rt *rt;
    const float *aim;      /* atlas-sized RGBA radiance, dilated into the gutters */
    int emission;          /* add the emitted radiance of what a ray hits */
    float sky[3];
    float enlargement;     /* a */
    int samples;           /* K, rounded down to a square */
    const float *emissive; /* with emission: per material rgb emission in place of the scene's (NULL: the
                              scene's), as a light edit's first gather saw it before (light_scale.h) */
    const lm_direct_light *direct; /* NULL: aim holds all the light. Else aim holds the light besides the
                              direct part the AIM computes (lm_aim_rest_dilated_rgba), and that part is
                              computed where each stratum's ray hits (lm_direct_at_hit, kd / pi times it):
                              one shadow ray per punctual light a stratum, and area->rays per emissive
                              triangle */
    const float *whole;    /* with direct: the whole AIM (lm_aim_dilated_rgba), read where a ray's hit lies
                              further than near x the hit surface's texel width, its direct part then the
                              texel's average as a hemicube reads it (docs/gather.md, "Near and far hits");
                              NULL: every hit takes its direct light at the hit */
    float near;            /* texel widths (with whole) */
    float adapt;           /* > 0 (the rays gather, lm_hemicube_settings.adapt): where the strata's estimate
                              of their mean's relative standard error in the first rim's worst channel
                              exceeds this, 4 x as many strata more, and the mean of all (not with an image
                              sky's own directions); 0: the strata alone */
    int footprint;         /* sub-directions per side of a stratum's footprint (0: 4); 1: each ray reads the
                              AIM at its own hit, for finer strata whose rays are their own footprint (the
                              waiting texels' near rays, update/ray_estimate.h). A rim read beside another
                              (lm_rim_irradiance_pair) takes the first's */
} lm_rim;

/* Irradiance from the rim at eye (lifted off its surface), for the plane's frame: unit b, t (its x and y
 * axes) and n. Directions below the plane of ng, the texel's geometric normal, are blocked by its own
 * surface and bring nothing (the rim of a shading normal tilted off the geometric one dips below it).
 * back (may be NULL): the share of the directions, weighted as the irradiance is, that met the back of a
 * single-sided surface. With enlargement 0 the "rim" is the whole hemisphere: the ray gather
 * (LM_GATHER_RAYS, hemicube.h). */
void lm_rim_irradiance(const lm_rim *r, const float eye[3], const float b[3], const float t[3], const float n[3],
                       const float ng[3], uint32_t seed, float out[3], float *back);

/* lm_rim_irradiance of was and of now, bit for bit, through one set of rays: rims that differ only in what
 * they read where a ray lands (aim, emission, emissive, direct, sky), over the same scene, atlas, tracer,
 * enlargement and samples (was's). About half the time of two calls: the rays, the footprints' uv
 * gradients and the sub-directions are shared; the AIM lookups are not. */
void lm_rim_irradiance_pair(const lm_rim *was, const lm_rim *now, const float eye[3], const float b[3],
                            const float t[3], const float n[3], const float ng[3], uint32_t seed, float out_was[3],
                            float out_now[3]);

/* Bilinear lookup of an atlas-sized RGBA map's rgb at lightmap uv in [0, 1]^2 (texel (x, y) spans
 * [x, x + 1] / width), clamped to the atlas's edge. */
void lm_atlas_sample_rgb(const lm_atlas *a, const float *rgba, float u, float v, float out[3]);
/* The lightmap uv where ray hit h met its triangle (barycentric on the corners' uvs); 0 for a triangle with
 * no chart (mirror, glass). */
int lm_atlas_hit_uv(const lm_atlas *a, const lm_rt_hit *h, float uv[2]);

/* The lightmap uv's gradient over a triangle's plane (world corners p, uv per corner; NULL: none, zero
 * gradient): rows gu, gv with uv(x) = uv0 + (gu.(x - p0), gv.(x - p0)). */
void lm_uv_gradient(const float p[3][3], const float *uv[3], float gu[3], float gv[3]);

#endif
