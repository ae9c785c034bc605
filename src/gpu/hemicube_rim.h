/* The rim of the hemisphere that the single-plane hemicube does not see (docs/gather.md, "The rim").
 *
 * The plane [-a, a]^2 at distance 1 covers F(a) of the cosine-weighted hemisphere (0.831 at a = 2). The
 * paper divides the plane's sum by F(a), which assumes the rim looks like the rest; a bright source near
 * the horizon (the ceiling around a lamp, seen from a wall) or a dark one (the floor, seen from under a
 * table) makes that wrong by up to 30% per surface. Instead the rim's own irradiance is estimated with
 * rays:
 *
 *   E_rim = pi / K * sum over the K stratified cosine-weighted directions that miss the plane of L(hit)
 *
 * (K the samples over the whole hemisphere, so each direction that misses the plane stands for 1 / K of
 * it: an unbiased estimate of the rim's part, and E = pi sum(w L) + E_rim needs no division by F(a)).
 * L(hit) is what the hemicube would show there: the AIM at the hit's lightmap uv (bilinear, from the
 * gather's copy of the dilated AIM), plus the emitted radiance when emitters are drawn rather than in
 * closed form; 0 on the back of a single-sided surface, on mirror and glass; the sky where nothing is hit.
 * The K directions are an n x n stratified grid (K = n^2) shifted per texel (its index seeds the shift),
 * so a texel gets the same estimate whenever it is gathered.
 *
 * Cost: only the directions outside the plane are traced, 1 - F(a) of them (44 of K = 256 at a = 2),
 * about 10 us per texel on this machine, on the gather's calling thread while the GPU rasterizes.
 * Thread-safe (Embree queries and reads only). */
#ifndef LM_HEMICUBE_RIM_H
#define LM_HEMICUBE_RIM_H

#include <stdint.h>

#include "../charts/charts.h"
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
} lm_rim;

/* Irradiance from the rim at eye (lifted off its surface), for the plane's frame: unit b, t (its x and y
 * axes) and n. */
void lm_rim_irradiance(const lm_rim *r, const float eye[3], const float b[3], const float t[3], const float n[3],
                       uint32_t seed, float out[3]);

#endif
