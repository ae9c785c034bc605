/* The IIM texels' factors after lights changed in power alone (light_scale.h). */
#include "light_scale.h"

#include <math.h>
#include <stdlib.h>

#include "../core/vecmath.h"
#include "../photonmap/hemicube_rim.h"
#include "../scene/sky.h"

/* Texel i's two gathers (header) into e0 and e1 (3 floats each). */
static void gathers(const lm_scene *s, const lm_atlas *a, const lm_hemicube_settings *set, const lm_rim *was,
                    const lm_rim *now, uint32_t i, float *e0, float *e1)
{
    float eye[3], n[3], ng[3], b[3], t[3];
    lm_gather_texel_frame(set, s, a, i, eye, n, ng);
    lm_vec3 tv, bv;
    lm_tangents(lm_v3_load(n), &tv, &bv);
    lm_v3_store(t, tv);
    lm_v3_store(b, bv);
    lm_rim_irradiance_pair(was, now, eye, b, t, n, ng, i, e0, e1);
}

/* Texel i's factor: the ratio of the gathers' sums over the texels of its surface within `spread` of it
 * that gathered (done), a ratio that varies slowly over a surface and is far less noisy summed; 1 where
 * they see no light either way, or where it is within LM_LIGHT_SCALE_KEEP of 1; its surface's where they
 * saw none before, or where none of them gathered. */
static void texel_ratio(const lm_atlas *a, const float *e0, const float *e1, const uint8_t *done, int spread,
                        const float *surface_factor, uint32_t i, float *out)
{
    const lm_texel *t = &a->texels[i];
    double s0[3] = {0, 0, 0}, s1[3] = {0, 0, 0};
    int met = 0;
    for (int dy = -spread; dy <= spread; dy++)
        for (int dx = -spread; dx <= spread; dx++) {
            int x = (int)t->x + dx, y = (int)t->y + dy;
            if (x < 0 || y < 0 || x >= a->width || y >= a->height)
                continue;
            int q = a->texel_index[(size_t)y * a->width + x];
            if (q < 0 || !done[q] || a->texels[q].surface != t->surface)
                continue;
            met++;
            for (int c = 0; c < 3; c++)
                s0[c] += e0[3 * (size_t)q + c], s1[c] += e1[3 * (size_t)q + c];
        }
    const float *own = surface_factor + 3 * t->surface;
    int keep = 1;
    for (int c = 0; c < 3; c++) { /* no neighbour gathered (a large atlas's strides): its surface's */
        float f = !met ? own[c] : s0[c] > 0.0 ? (float)(s1[c] / s0[c]) : s1[c] > 0.0 ? own[c] : 1.0f;
        out[c] = isfinite(f) && f >= 0.0f ? f : own[c];
        keep &= fabsf(out[c] - 1.0f) < LM_LIGHT_SCALE_KEEP;
    }
    for (int c = 0; keep && c < 3; c++)
        out[c] = 1.0f;
}

void lm_light_scale_texels(const lm_scene *s, const lm_atlas *a, const lm_rt *rt, const lm_hemicube_settings *set,
                           const float *before, const float *emissive_before, const float *after,
                           const float *surface_factor, float *texel_factor)
{
    uint32_t T = a->texel_count;
    if (T == 0)
        return;
    uint32_t K = LM_LIGHT_SCALE_WORK / T, stride = 1;
    if (K < 4) /* the fewest rays a texel still reads a ratio from; past that, every stride-th texel */
        K = 4, stride = (4 * T + LM_LIGHT_SCALE_WORK - 1) / LM_LIGHT_SCALE_WORK;
    K = K > 64 ? 64 : K;
    int spread = LM_LIGHT_SCALE_SPREAD; /* wide enough to hold about two texels that gathered */
    while ((uint32_t)((2 * spread + 1) * (2 * spread + 1)) < 2 * stride)
        spread++;
    float *e = before ? malloc(sizeof *e * 6 * (size_t)T) : NULL;
    uint8_t *done = e ? calloc(T, 1) : NULL;
    if (!done) { /* no AIM from before, or no memory: each texel as its surface's hits */
        for (uint32_t i = 0; i < T; i++)
            for (int c = 0; c < 3; c++)
                texel_factor[3 * i + c] = surface_factor[3 * a->texels[i].surface + c];
        free(e);
        return;
    }
    lm_rim was = {s, a, rt, before, 1, {set->sky[0], set->sky[1], set->sky[2]}, 0.0f, (int)K, emissive_before, NULL};
    if (s->has_sky)
        lm_sky_mean(s, was.sky);
    lm_rim now = was;
    now.aim = after;
    now.emissive = NULL;
    for (uint32_t i = 0; i < T; i++) /* a surface's first texel gathers too: its surface then has one */
        done[i] = i % stride == 0 || a->texels[i].surface != a->texels[i - 1].surface;
#pragma omp parallel
    {
        lm_rt_thread_init();
#pragma omp for schedule(dynamic, 16)
        for (long i = 0; i < (long)T; i++)
            if (done[i])
                gathers(s, a, set, &was, &now, (uint32_t)i, e + 3 * (size_t)i, e + 3 * ((size_t)T + (size_t)i));
#pragma omp for schedule(static)
        for (long i = 0; i < (long)T; i++)
            texel_ratio(a, e, e + 3 * (size_t)T, done, spread, surface_factor, (uint32_t)i, texel_factor + 3 * i);
    }
    free(e);
    free(done);
}
