#include "surface_need.h"

#include <math.h>
#include <stdlib.h>

#include "../core/qmc.h"
#include "../core/vecmath.h"

/* Halton dimensions: the point's place inside its triangle (2), then its rays' directions (2). */
enum { DIM_TRI = 0, DIM_RAY = 2 };

/* (1 / R)^2 at p (world), unit geometric normal n: R the harmonic mean of LM_NEED_RAYS rays' hit distances,
 * each at least r_min, misses infinitely far; the misses added to *misses. index: the point's number in its
 * sequence. */
static double inverse_r2(const lm_rt *rt, lm_vec3 p, lm_vec3 n, float lift, float r_min, uint64_t index,
                         int *misses)
{
    float org[3];
    lm_v3_store(org, lm_add(p, lm_scale(n, lift)));
    double inv = 0.0;
    for (int k = 0; k < LM_NEED_RAYS; k++) {
        double u[2];
        lm_halton_dims(DIM_RAY, 2, index * LM_NEED_RAYS + (uint64_t)k, u);
        float dir[3];
        lm_v3_store(dir, lm_cosine_dir(n, (float)u[0], (float)u[1]));
        lm_rt_hit h;
        if (lm_rt_intersect(rt, org, dir, 0.0f, INFINITY, &h))
            inv += 1.0 / fmax((double)h.t, (double)r_min);
        else
            ++*misses;
    }
    inv /= LM_NEED_RAYS;
    return inv * inv;
}

/* One surface's need, and in *sky its rays' share that hit nothing; its triangles' cumulative areas in cdf
 * (tri_count entries). */
static double surface_need(const lm_rt *rt, const lm_scene *s, const lm_surface *f, double *cdf, float lift,
                           float texel, double *sky)
{
    double area = 0.0;
    *sky = 0.0;
    for (uint32_t i = 0; i < f->tri_count; i++)
        cdf[i] = area += lm_scene_tri_area_world(s, f->tris[i]);
    if (!(area > 0.0))
        return 0.0;
    int misses = 0, points = (int)fmin(fmax(ceil(area / ((double)texel * texel)), LM_NEED_MIN_POINTS), LM_NEED_POINTS);
    double sum = 0.0;
    uint32_t t = 0;
    for (int j = 0; j < points; j++) {
        double at = (j + 0.5) / points * area; /* one stratum of the area each, in order */
        while (t + 1 < f->tri_count && cdf[t] <= at)
            t++;
        double lo = t ? cdf[t - 1] : 0.0, a = cdf[t] - lo;
        double su = a > 0.0 ? fmin(fmax((at - lo) / a, 0.0), 1.0) : 0.5, sv = lm_halton(DIM_TRI + 1, (uint64_t)j);
        double r = sqrt(su); /* uniform on the triangle */
        const uint32_t *v = s->tris + 3 * (size_t)f->tris[t];
        float c[3][3];
        for (int k = 0; k < 3; k++)
            lm_scene_vertex_world(s, v[k], c[k]);
        double w[3] = {1.0 - r, r * (1.0 - sv), r * sv};
        lm_vec3 p = lm_v3((float)(w[0] * c[0][0] + w[1] * c[1][0] + w[2] * c[2][0]),
                          (float)(w[0] * c[0][1] + w[1] * c[1][1] + w[2] * c[2][1]),
                          (float)(w[0] * c[0][2] + w[1] * c[1][2] + w[2] * c[2][2]));
        sum += inverse_r2(rt, p, lm_scene_tri_normal_world(s, f->tris[t]), lift, texel, (uint64_t)j, &misses);
    }
    *sky = (double)misses / (points * LM_NEED_RAYS);
    return area * sum / points;
}

lm_status lm_surface_need(const lm_rt *rt, const lm_scene *s, const lm_surfaces *su, float texel, double *need,
                          double *sky, lm_error *err)
{
    if (!(texel > 0.0f) || !isfinite(texel))
        return lm_fail(err, LM_ERR_INVALID, "surface need: texel %g must be positive", (double)texel);
    lm_qmc_init();
    float lift = lm_scene_ray_lift(s);
    int failed = 0;
#pragma omp parallel
    {
        lm_rt_thread_init();
#pragma omp for schedule(dynamic, 4)
        for (int f = 0; f < su->surface_count; f++) {
            const lm_surface *sf = &su->surfaces[f];
            double *cdf = malloc(((size_t)sf->tri_count + 1) * sizeof *cdf);
            if (!cdf) {
#pragma omp atomic write
                failed = 1;
                continue;
            }
            need[f] = surface_need(rt, s, sf, cdf, lift, texel, &sky[f]);
            free(cdf);
        }
    }
    return failed ? lm_fail(err, LM_ERR_NOMEM, "surface need: out of memory") : LM_OK;
}
