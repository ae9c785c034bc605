/* The IIM texels' factors after lights changed in power alone (light_scale.h). */
#include "light_scale.h"

#include <math.h>

#include "../core/vecmath.h"
#include "../photonmap/hemicube_rim.h"
#include "../scene/sky.h"

/* Texel i's factor from the two gathers (header): 1 where it sees no light either way, its surface's where
 * it saw none before. */
static void texel_ratio(const lm_scene *s, const lm_atlas *a, const lm_hemicube_settings *set, const lm_rim *was,
                        const lm_rim *now, const float *surface_factor, uint32_t i, float *out)
{
    float eye[3], n[3], ng[3], b[3], t[3], e0[3], e1[3];
    lm_gather_texel_frame(set, s, a, i, eye, n, ng);
    lm_vec3 tv, bv;
    lm_tangents(lm_v3_load(n), &tv, &bv);
    lm_v3_store(t, tv);
    lm_v3_store(b, bv);
    lm_rim_irradiance(was, eye, b, t, n, ng, i, e0, NULL);
    lm_rim_irradiance(now, eye, b, t, n, ng, i, e1, NULL);
    const float *own = surface_factor + 3 * a->texels[i].surface;
    int keep = 1;
    for (int c = 0; c < 3; c++) { /* seeing no light either way: nothing to scale */
        float f = e0[c] > 0.0f ? e1[c] / e0[c] : e1[c] > 0.0f ? own[c] : 1.0f;
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
    lm_rim was = {s, a, rt, before, 1, {set->sky[0], set->sky[1], set->sky[2]}, 0.0f, (int)K, emissive_before};
    if (s->has_sky)
        lm_sky_mean(s, was.sky);
    lm_rim now = was;
    now.aim = after;
    now.emissive = NULL;
#pragma omp parallel
    {
        lm_rt_thread_init();
#pragma omp for schedule(dynamic, 16)
        for (long i = 0; i < (long)T; i++) /* a surface's first texel too: the others of it may copy it */
            if (i % stride == 0 || a->texels[i].surface != a->texels[i - 1].surface)
                texel_ratio(s, a, set, &was, &now, surface_factor, (uint32_t)i, texel_factor + 3 * i);
    }
    for (uint32_t i = 1; stride > 1 && i < T; i++) /* in order: the nearest computed one before, of its surface */
        if (i % stride != 0 && a->texels[i].surface == a->texels[i - 1].surface)
            for (int c = 0; c < 3; c++)
                texel_factor[3 * i + c] = texel_factor[3 * (i - 1) + c];
}
