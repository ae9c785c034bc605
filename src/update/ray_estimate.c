/* The waiting texels' first estimate from a few rays (ray_estimate.h). */
#include "ray_estimate.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../core/top_k.h"
#include "../photonmap/hemicube_rim.h"
#include "../scene/sky.h"

lm_status lm_ray_estimate_init(lm_ray_estimate *re, uint32_t texel_count, int K, lm_error *err)
{
    memset(re, 0, sizeof *re);
    size_t n = texel_count ? texel_count : 1;
    re->texel_count = texel_count;
    re->K = K;
    re->base = calloc(3 * n, sizeof *re->base);
    re->delta = calloc(3 * n, sizeof *re->delta);
    re->has = calloc(n, 1);
    re->stamp = calloc(n, sizeof *re->stamp);
    re->fine = calloc(n, 1);
    if (re->base && re->delta && re->has && re->stamp && re->fine)
        return LM_OK;
    lm_ray_estimate_free(re);
    return lm_fail(err, LM_ERR_NOMEM, "ray estimate: no memory for %u texels", texel_count);
}

void lm_ray_estimate_free(lm_ray_estimate *re)
{
    free(re->base);
    free(re->delta);
    free(re->has);
    free(re->stamp);
    free(re->fine);
    memset(re, 0, sizeof *re);
}

/* The rim over the whole hemisphere reading aim, as the header says. */
static lm_rim rays_over(const lm_ray_estimate *re, const lm_light_scale_world *w, const float *aim)
{
    lm_rim r = {w->scene, w->atlas, w->rt, aim, !re->emitted, {w->set->sky[0], w->set->sky[1], w->set->sky[2]},
                0.0f, re->K, NULL, NULL, NULL, 0.0f, 0.0f};
    if (w->scene->has_sky)
        lm_sky_mean(w->scene, r.sky);
    return r;
}

/* The emissive triangles' light re->emitted's gather adds to texel i, into em (0 without one). */
static void emitted_at(const lm_ray_estimate *re, const lm_light_scale_world *w, uint32_t i, float em[3])
{
    em[0] = em[1] = em[2] = 0.0f;
    if (re->emitted)
        lm_gather_emitted_at(re->emitted, w->scene, w->atlas, i, em);
}

/* Whether K rays misjudge a texel whose K-ray gather is e and whose LM_RAY_ESTIMATE_FINE x K-ray gather is
 * ef, both with its emitter light em: they differ by more than LM_RAY_ESTIMATE_SPLIT of its light (the
 * channels summed). */
static int misjudged(const float e[3], const float ef[3], const float em[3])
{
    double a = 0.0, b = 0.0;
    for (int c = 0; c < 3; c++)
        a += e[c] + em[c], b += ef[c] + em[c];
    return fabs(a - b) > LM_RAY_ESTIMATE_SPLIT * b;
}

/* The bases of texels list[0 .. m) (their gathers now, by r, and where r misjudges one, by rf: re->fine), or
 * with `minus` their changes since (re->delta), each by the rays its base took, with its emitter light
 * (emitted_at); on every core. */
static void ray_gathers(lm_ray_estimate *re, const lm_light_scale_world *w, const lm_rim *r, const lm_rim *rf,
                        const uint32_t *list, uint32_t m, float *out, const float *minus)
{
#pragma omp parallel
    {
        lm_rt_thread_init();
#pragma omp for schedule(dynamic, 16)
        for (long j = 0; j < (long)m; j++) {
            uint32_t i = list[j];
            float e[3], em[3];
            emitted_at(re, w, i, em);
            if (minus) {
                lm_light_scale_texel_rim(w, re->fine[i] ? rf : r, i, e);
            } else {
                float ef[3];
                lm_light_scale_texel_rim(w, r, i, e);
                lm_light_scale_texel_rim(w, rf, i, ef);
                re->fine[i] = (uint8_t)misjudged(e, ef, em);
                if (re->fine[i])
                    memcpy(e, ef, sizeof e);
            }
            for (int c = 0; c < 3; c++)
                out[3 * (size_t)i + c] = e[c] + em[c] - (minus ? minus[3 * (size_t)i + c] : 0.0f);
        }
    }
}

/* The rims of K and of LM_RAY_ESTIMATE_FINE x K rays over aim (rays_over). */
static void rims_over(const lm_ray_estimate *re, const lm_light_scale_world *w, const float *aim, lm_rim *r,
                      lm_rim *rf)
{
    *r = rays_over(re, w, aim);
    *rf = *r;
    rf->samples = LM_RAY_ESTIMATE_FINE * re->K;
}

void lm_ray_estimate_gathered(lm_ray_estimate *re, const lm_light_scale_world *w, const float *aim,
                              const uint32_t *texels, uint32_t n)
{
    if (n == 0 || re->K <= 0)
        return;
    lm_rim r, rf;
    rims_over(re, w, aim, &r, &rf);
    ray_gathers(re, w, &r, &rf, texels, n, re->base, NULL);
    for (uint32_t j = 0; j < n; j++) {
        re->has[texels[j]] = 1;
        re->stamp[texels[j]] = re->frame;
    }
}

uint32_t lm_ray_estimate_update(lm_ray_estimate *re, const lm_light_scale_world *w, const float *aim,
                                const uint32_t *waiting, const float *change, uint32_t n, uint32_t budget,
                                uint32_t *out)
{
    re->frame++;
    if (n == 0 || budget == 0 || re->K <= 0)
        return 0;
    lm_ranked *h = malloc(sizeof *h * (budget < n ? budget : n));
    if (!h) /* no estimate this update: the texels show their neighbours' loans */
        return 0;
    /* half by change times the updates since each was last brought up to date (or gathered), then the other
     * half by those updates alone among the rest (header); ties by texel index, the same on every run */
    uint32_t most = budget - budget / 2, m = 0, got = 0;
    for (uint32_t k = 0; k < n; k++)
        if (re->has[waiting[k]])
            lm_top_k_offer(h, &got, most,
                           (lm_ranked){(double)change[k] * (double)(re->frame - re->stamp[waiting[k]]), waiting[k]});
    for (uint32_t j = 0; j < got; j++) /* stamped now: out of the second half's running */
        out[m++] = h[j].id, re->stamp[h[j].id] = re->frame;
    got = 0;
    for (uint32_t k = 0; k < n && budget > most; k++)
        if (re->has[waiting[k]] && re->stamp[waiting[k]] != re->frame)
            lm_top_k_offer(h, &got, budget - most, (lm_ranked){(double)(re->frame - re->stamp[waiting[k]]), waiting[k]});
    for (uint32_t j = 0; j < got; j++)
        out[m++] = h[j].id, re->stamp[h[j].id] = re->frame;
    free(h);
    lm_rim r, rf;
    rims_over(re, w, aim, &r, &rf);
    ray_gathers(re, w, &r, &rf, out, m, re->delta, re->base);
    return m;
}

void lm_ray_estimate_scale(lm_ray_estimate *re, const float *factor, const float *add)
{
    for (size_t k = 0; k < 3 * (size_t)re->texel_count; k++)
        re->base[k] = re->base[k] * factor[k] + (add ? add[k] : 0.0f);
}

void lm_ray_estimate_emitters(lm_ray_estimate *re, const lm_gather *g) { re->emitted = g; }

void lm_ray_estimate_forget(lm_ray_estimate *re)
{
    memset(re->has, 0, re->texel_count ? re->texel_count : 1);
}
