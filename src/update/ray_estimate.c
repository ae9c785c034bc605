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
    re->near_base = calloc(3 * n, sizeof *re->near_base);
    re->rate = calloc(n, sizeof *re->rate);
    re->rated = calloc(n, 1);
    if (re->base && re->delta && re->has && re->stamp && re->fine && re->near_base && re->rate && re->rated)
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
    free(re->near_base);
    free(re->rate);
    free(re->rated);
    memset(re, 0, sizeof *re);
}

/* The rim over the whole hemisphere reading aim, as the header says. */
static lm_rim rays_over(const lm_ray_estimate *re, const lm_light_scale_world *w, const float *aim)
{
    lm_rim r = {w->scene, w->atlas, w->rt, aim, !re->emitted, {w->set->sky[0], w->set->sky[1], w->set->sky[2]},
                0.0f, re->K, NULL, NULL, NULL, 0.0f, 0.0f, 0};
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

/* Whether the gathers watch for nodes beside their texels: nodes are known, and some move. */
static int watching(const lm_ray_estimate *re, const lm_light_scale_world *w)
{
    return re->nodes && lm_scene_any_node_moves(w->scene);
}

/* Whether a node that moves stands beside texel i (header); watch: watching(). */
static int node_near(const lm_ray_estimate *re, const lm_light_scale_world *w, int watch, uint32_t i)
{
    return watch && lm_texel_change_node_near(re->nodes, w->scene, i) > LM_RAY_ESTIMATE_NEAR;
}

/* Texel i's base into e (its emitter light em left out), by the rays rims[re->fine[i]] that it sets: the
 * near rays where a node stands beside it, else the fine ones where the K rays misjudge it, else the K;
 * with watch, also its near rays' gather (em in) into near_base, for a node that comes later. */
static void base_of(lm_ray_estimate *re, const lm_light_scale_world *w, const lm_rim *rims, int watch, uint32_t i,
                    const float em[3], float e[3])
{
    float ef[3], en[3];
    lm_light_scale_texel_rim(w, &rims[0], i, e);
    lm_light_scale_texel_rim(w, &rims[1], i, ef);
    re->fine[i] = (uint8_t)misjudged(e, ef, em);
    if (watch) {
        lm_light_scale_texel_rim(w, &rims[LM_RAY_ESTIMATE_NEAR_RAYS], i, en);
        for (int c = 0; c < 3; c++)
            re->near_base[3 * (size_t)i + c] = en[c] + em[c];
        if (node_near(re, w, watch, i))
            re->fine[i] = LM_RAY_ESTIMATE_NEAR_RAYS;
    }
    if (re->fine[i] == 1)
        memcpy(e, ef, sizeof ef);
    else if (re->fine[i] == LM_RAY_ESTIMATE_NEAR_RAYS)
        memcpy(e, en, sizeof en);
}

/* Texel i's gather now into e (em left out), by the rays its base took; a node come beside it since its
 * gather turns it to the near rays against the near base it took then (LM_RAY_ESTIMATE_NEW_NEAR), if it took
 * one (no node moved then: it keeps its rays). */
static void now_of(lm_ray_estimate *re, const lm_light_scale_world *w, const lm_rim *rims, int watch, uint32_t i,
                   float e[3])
{
    if (re->has[i] == LM_RAY_ESTIMATE_NEAR_BASED && re->fine[i] < LM_RAY_ESTIMATE_NEAR_RAYS &&
        node_near(re, w, watch, i)) {
        memcpy(re->base + 3 * (size_t)i, re->near_base + 3 * (size_t)i, 3 * sizeof *re->base);
        re->fine[i] = LM_RAY_ESTIMATE_NEW_NEAR;
    }
    int level = re->fine[i] == LM_RAY_ESTIMATE_NEW_NEAR ? LM_RAY_ESTIMATE_NEAR_RAYS : re->fine[i];
    lm_light_scale_texel_rim(w, &rims[level], i, e);
}

/* The bases of texels list[0 .. m) (base_of), or with `minus` their changes since (re->delta: now_of less
 * the base), each with its emitter light (emitted_at); on every core. */
static void ray_gathers(lm_ray_estimate *re, const lm_light_scale_world *w, const lm_rim *rims,
                        const uint32_t *list, uint32_t m, float *out, const float *minus)
{
    int watch = watching(re, w);
#pragma omp parallel
    {
        lm_rt_thread_init();
#pragma omp for schedule(dynamic, 16)
        for (long j = 0; j < (long)m; j++) {
            uint32_t i = list[j];
            float e[3], em[3];
            emitted_at(re, w, i, em);
            if (minus)
                now_of(re, w, rims, watch, i, e);
            else
                base_of(re, w, rims, watch, i, em, e);
            for (int c = 0; c < 3; c++)
                out[3 * (size_t)i + c] = e[c] + em[c] - (minus ? minus[3 * (size_t)i + c] : 0.0f);
        }
    }
}

/* The rims over aim (rays_over) by fine level: K rays, LM_RAY_ESTIMATE_FINE x K, and the near rays,
 * LM_RAY_ESTIMATE_NEAR_FINE x K each read at its own hit (header). */
static void rims_over(const lm_ray_estimate *re, const lm_light_scale_world *w, const float *aim, lm_rim rims[3])
{
    rims[0] = rims[1] = rims[2] = rays_over(re, w, aim);
    rims[1].samples = LM_RAY_ESTIMATE_FINE * re->K;
    rims[LM_RAY_ESTIMATE_NEAR_RAYS].samples = LM_RAY_ESTIMATE_NEAR_FINE * re->K;
    rims[LM_RAY_ESTIMATE_NEAR_RAYS].footprint = 1;
}

void lm_ray_estimate_gathered(lm_ray_estimate *re, const lm_light_scale_world *w, const float *aim,
                              const uint32_t *texels, uint32_t n)
{
    if (n == 0 || re->K <= 0)
        return;
    lm_rim rims[3];
    rims_over(re, w, aim, rims);
    ray_gathers(re, w, rims, texels, n, re->base, NULL);
    uint8_t has = watching(re, w) ? LM_RAY_ESTIMATE_NEAR_BASED : 1;
    for (uint32_t j = 0; j < n; j++) { /* its change starts again from 0, and its rate is unknown */
        re->has[texels[j]] = has;
        re->stamp[texels[j]] = re->frame;
        re->rated[texels[j]] = 0;
        memset(re->delta + 3 * (size_t)texels[j], 0, 3 * sizeof *re->delta);
    }
}

/* A texel's light as its estimate has it, the channels summed. */
static double light_of(const lm_ray_estimate *re, uint32_t i)
{
    const float *b = re->base + 3 * (size_t)i, *d = re->delta + 3 * (size_t)i;
    return (double)b[0] + b[1] + b[2] + d[0] + d[1] + d[2];
}

/* How fast texel i's light changes, as a share of it (at least `least`) an update: the largest such rate of
 * its own and of its surface's texels within LM_RAY_ESTIMATE_REACH that have one (header), or -1 where none
 * has. A shadow's edge coming onto a texel whose light held so far shows first in the texels beside it. */
static double rate_near(const lm_ray_estimate *re, const lm_atlas *a, uint32_t i, double least)
{
    const lm_texel *t = &a->texels[i];
    double most = -1.0;
    for (int dy = -LM_RAY_ESTIMATE_REACH; dy <= LM_RAY_ESTIMATE_REACH; dy++)
        for (int dx = -LM_RAY_ESTIMATE_REACH; dx <= LM_RAY_ESTIMATE_REACH; dx++) {
            int x = t->x + dx, y = t->y + dy;
            int q = x < 0 || y < 0 || x >= a->width || y >= a->height ? -1 : a->texel_index[(size_t)y * a->width + x];
            if (q >= 0 && a->texels[q].surface == t->surface && re->rated[q])
                most = fmax(most, (double)re->rate[q] / fmax(light_of(re, (uint32_t)q), least));
        }
    return most;
}

/* How far texel i's estimate is likely off by now, as a share of its light (at least `least`): rate_near
 * times the updates since its last estimate, or where there is none its prior (the change since its gather,
 * from what moved, channels summed) over its light. */
static double stale(const lm_ray_estimate *re, const lm_atlas *a, uint32_t i, float prior, double least)
{
    double rate = rate_near(re, a, i, least);
    return rate >= 0.0 ? rate * (double)(re->frame - re->stamp[i]) : (double)prior / fmax(light_of(re, i), least);
}

/* The texels taken so far this update (out[0 .. m), stamped with the frame) with their stamp and change
 * before, for their rates; then at most `quota` more of waiting's with a base, by `key`: 0 change times the
 * updates since each was last brought up to date, 1 stale, 2 those updates alone. Ties by texel index, the
 * same on every run. Returns the new m. */
static uint32_t take(lm_ray_estimate *re, const lm_atlas *a, const uint32_t *waiting, const float *change,
                     float change_unit, uint32_t n, int key, uint32_t quota, double least, lm_ranked *h, uint32_t *out,
                     uint32_t m, uint32_t *was, float *sum)
{
    uint32_t got = 0;
    for (uint32_t k = 0; k < n && quota > 0; k++) {
        uint32_t i = waiting[k];
        if (!re->has[i] || re->stamp[i] == re->frame)
            continue;
        double since = (double)(re->frame - re->stamp[i]);
        double v = key == 0   ? (double)change[k] * since
                   : key == 1 ? stale(re, a, i, change[k] * change_unit, least)
                              : since;
        lm_top_k_offer(h, &got, quota, (lm_ranked){v, i});
    }
    for (uint32_t j = 0; j < got; j++) {
        uint32_t i = h[j].id;
        const float *d = re->delta + 3 * (size_t)i;
        was[m] = re->stamp[i], sum[m] = d[0] + d[1] + d[2];
        out[m++] = i;
        re->stamp[i] = re->frame; /* out of the later keys' running */
    }
    return m;
}

uint32_t lm_ray_estimate_update(lm_ray_estimate *re, const lm_light_scale_world *w, const float *aim,
                                const uint32_t *waiting, const float *change, float change_unit, uint32_t n,
                                uint32_t budget, uint32_t *out)
{
    re->frame++;
    if (n == 0 || budget == 0 || re->K <= 0)
        return 0;
    uint32_t cap = budget < n ? budget : n;
    lm_ranked *h = malloc(sizeof *h * cap);
    uint32_t *was = malloc(sizeof *was * cap);
    float *sum = malloc(sizeof *sum * cap);
    if (!h || !was || !sum) { /* no estimate this update: the texels show their neighbours' loans */
        free(h), free(was), free(sum);
        return 0;
    }
    double mean = 0.0;
    uint32_t based = 0;
    for (uint32_t k = 0; k < n; k++)
        if (re->has[waiting[k]])
            mean += light_of(re, waiting[k]), based++;
    double least = LM_RAY_ESTIMATE_DIM * (based ? mean / based : 0.0) + 1e-30;
    /* a third each by change times wait, by expected staleness, by wait alone (header) */
    uint32_t third = budget / 3, m = 0;
    m = take(re, w->atlas, waiting, change, change_unit, n, 0, third, least, h, out, m, was, sum);
    m = take(re, w->atlas, waiting, change, change_unit, n, 1, third, least, h, out, m, was, sum);
    m = take(re, w->atlas, waiting, change, change_unit, n, 2, budget - 2 * third, least, h, out, m, was, sum);
    lm_rim rims[3];
    rims_over(re, w, aim, rims);
    ray_gathers(re, w, rims, out, m, re->delta, re->base);
    for (uint32_t j = 0; j < m; j++) { /* the rate each change went at since the texel's last estimate */
        const float *d = re->delta + 3 * (size_t)out[j];
        if (re->fine[out[j]] == LM_RAY_ESTIMATE_NEW_NEAR) { /* its change, now through other rays: no rate */
            re->fine[out[j]] = LM_RAY_ESTIMATE_NEAR_RAYS;
            re->rated[out[j]] = 0;
            continue;
        }
        uint32_t since = re->frame - was[j];
        re->rate[out[j]] = fabsf(d[0] + d[1] + d[2] - sum[j]) / (float)(since ? since : 1);
        re->rated[out[j]] = 1;
    }
    free(h), free(was), free(sum);
    return m;
}

void lm_ray_estimate_scale(lm_ray_estimate *re, const float *factor, const float *add)
{
    for (size_t k = 0; k < 3 * (size_t)re->texel_count; k++)
        re->base[k] = re->base[k] * factor[k] + (add ? add[k] : 0.0f),
        re->near_base[k] = re->near_base[k] * factor[k] + (add ? add[k] : 0.0f);
    memset(re->rated, 0, re->texel_count ? re->texel_count : 1); /* the rates came before the edit */
}

void lm_ray_estimate_emitters(lm_ray_estimate *re, const lm_gather *g) { re->emitted = g; }

void lm_ray_estimate_nodes(lm_ray_estimate *re, const lm_texel_change *tc) { re->nodes = tc; }

void lm_ray_estimate_forget(lm_ray_estimate *re)
{
    memset(re->has, 0, re->texel_count ? re->texel_count : 1);
}
