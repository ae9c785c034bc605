/* The waiting texels' first estimate from a few rays (ray_estimate.h). */
#include "ray_estimate.h"

#include <stdlib.h>
#include <string.h>

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
    if (re->base && re->delta && re->has && re->stamp)
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
    memset(re, 0, sizeof *re);
}

/* The rim over the whole hemisphere reading aim, as the header says. */
static lm_rim rays_over(const lm_ray_estimate *re, const lm_light_scale_world *w, const float *aim)
{
    lm_rim r = {w->scene, w->atlas, w->rt, aim, 1, {w->set->sky[0], w->set->sky[1], w->set->sky[2]}, 0.0f, re->K,
                NULL, NULL, NULL, 0.0f, 0.0f};
    if (w->scene->has_sky)
        lm_sky_mean(w->scene, r.sky);
    return r;
}

/* Texels list[0 .. m) gathered by r into out (3 floats a texel, by texel index), less minus's (NULL: none),
 * on every core. */
static void ray_gathers(const lm_light_scale_world *w, const lm_rim *r, const uint32_t *list, uint32_t m, float *out,
                        const float *minus)
{
#pragma omp parallel
    {
        lm_rt_thread_init();
#pragma omp for schedule(dynamic, 16)
        for (long j = 0; j < (long)m; j++) {
            size_t i = list[j];
            float e[3];
            lm_light_scale_texel_rim(w, r, (uint32_t)i, e);
            for (int c = 0; c < 3; c++)
                out[3 * i + c] = e[c] - (minus ? minus[3 * i + c] : 0.0f);
        }
    }
}

void lm_ray_estimate_gathered(lm_ray_estimate *re, const lm_light_scale_world *w, const float *aim,
                              const uint32_t *texels, uint32_t n)
{
    if (n == 0 || re->K <= 0)
        return;
    lm_rim r = rays_over(re, w, aim);
    ray_gathers(w, &r, texels, n, re->base, NULL);
    for (uint32_t j = 0; j < n; j++) {
        re->has[texels[j]] = 1;
        re->stamp[texels[j]] = re->frame;
    }
}

/* A waiting texel's claim to be brought up to date: how much its hemisphere changed (texel_change.h) times
 * the updates since it last was (or was gathered), or that wait alone. Ties by texel index: the choice is
 * the same on every run. */
typedef struct {
    double key;
    uint32_t texel;
} claim;

static int before(const claim *a, const claim *b) { return a->key > b->key || (a->key == b->key && a->texel < b->texel); }

/* Reorders c[0 .. n) so that its first k are the k greatest claims (quickselect, middle pivot). */
static void select_first(claim *c, uint32_t n, uint32_t k)
{
    uint32_t lo = 0, hi = n;
    while (hi - lo > 1) {
        claim pivot = c[lo + (hi - lo) / 2];
        uint32_t i = lo, j = hi - 1;
        while (i <= j) {
            while (before(&c[i], &pivot))
                i++;
            while (before(&pivot, &c[j]))
                j--;
            if (i <= j) {
                claim t = c[i];
                c[i] = c[j], c[j] = t;
                i++;
                if (j == 0)
                    break;
                j--;
            }
        }
        if (k <= j + 1 && j + 1 > lo)
            hi = j + 1;
        else if (k >= i)
            lo = i;
        else
            return;
    }
}

uint32_t lm_ray_estimate_update(lm_ray_estimate *re, const lm_light_scale_world *w, const float *aim,
                                const uint32_t *waiting, const float *change, uint32_t n, uint32_t budget,
                                uint32_t *out)
{
    re->frame++;
    if (n == 0 || budget == 0 || re->K <= 0)
        return 0;
    claim *c = malloc(sizeof *c * n);
    if (!c) /* no estimate this update: the texels show their neighbours' loans */
        return 0;
    uint32_t m = 0;
    for (uint32_t k = 0; k < n; k++)
        if (re->has[waiting[k]])
            c[m++] = (claim){(double)change[k] * (double)(re->frame - re->stamp[waiting[k]]), waiting[k]};
    if (m > budget) { /* half by change times wait, the other half by wait alone (header) */
        uint32_t most = budget - budget / 2;
        select_first(c, m, most);
        for (uint32_t j = most; j < m; j++)
            c[j].key = (double)(re->frame - re->stamp[c[j].texel]);
        select_first(c + most, m - most, budget - most);
        m = budget;
    }
    for (uint32_t j = 0; j < m; j++)
        out[j] = c[j].texel, re->stamp[c[j].texel] = re->frame;
    free(c);
    lm_rim r = rays_over(re, w, aim);
    ray_gathers(w, &r, out, m, re->delta, re->base);
    return m;
}

void lm_ray_estimate_scale(lm_ray_estimate *re, const float *factor, const float *add)
{
    for (size_t k = 0; k < 3 * (size_t)re->texel_count; k++)
        re->base[k] = re->base[k] * factor[k] + (add ? add[k] : 0.0f);
}

void lm_ray_estimate_forget(lm_ray_estimate *re)
{
    memset(re->has, 0, re->texel_count ? re->texel_count : 1);
}
