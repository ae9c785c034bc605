/* The IIM texels' factors after lights changed in power alone, at once or refined within the budget
 * (light_scale.h). */
#include "light_scale.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../core/timing.h"
#include "../core/vecmath.h"
#include "../photonmap/hemicube_rim.h"
#include "../scene/sky.h"

/* The fewest rays a texel still reads a ratio from, and the first guess's count. */
#define FEWEST_RAYS 4u
/* The rays the first guess's window sums, about: on the Cornell box at an 8 ms budget (lmgi bench --edits,
 * the red wall recoloured, a first guess of 2 ms: 4 rays for every 4th texel), a window of 8 read 8.3% off
 * at the edit, of 32 6.1%, 64 5.8%, 128 6.2% (the factor's own change across a wider window). */
#define FIRST_GUESS_SUMMED 64u

/* One pass's quality: K rays for every stride-th texel (and, with firsts, each surface's first), the
 * window summed. */
typedef struct {
    uint32_t K, stride;
    int spread, firsts;
} quality;

/* The widest window a factor sums (17 x 17 texels): what the full quality needs past a million texels,
 * and a bound on a first guess's, whose few rays would otherwise ask for windows that cost more to sum
 * than the rays to cast (a 171 x 171 window a texel, 44 ms on the shared room at 192 rays). */
#define MOST_SPREAD 8

/* K rays (at most 64, rounded down to a square as the rim casts them) for every stride-th texel and each
 * surface's first, with the window that holds about two of them. */
static quality quality_of(uint32_t K, uint32_t stride)
{
    uint32_t side = (uint32_t)sqrt((double)(K > 64 ? 64 : K));
    quality q = {side * side, stride, LM_LIGHT_SCALE_SPREAD, 1};
    while ((uint32_t)((2 * q.spread + 1) * (2 * q.spread + 1)) < 2 * q.stride && q.spread < MOST_SPREAD)
        q.spread++;
    return q;
}

/* The full quality on T texels (header). */
static quality full_quality(uint32_t T)
{
    uint32_t K = LM_LIGHT_SCALE_WORK / T, stride = 1;
    if (K < FEWEST_RAYS) /* past that, every stride-th texel */
        K = FEWEST_RAYS, stride = (FEWEST_RAYS * T + LM_LIGHT_SCALE_WORK - 1) / LM_LIGHT_SCALE_WORK;
    return quality_of(K, stride);
}

/* Whether texel i is its surface's first (texels lie in the atlas by surface). */
static int run_start(const lm_atlas *a, uint32_t i)
{
    return i == 0 || a->texels[i].surface != a->texels[i - 1].surface;
}

/* Whether texel i gathers at q: every stride-th, and with firsts a surface's first (its surface then has
 * one). */
static int gathers_at(const lm_atlas *a, uint32_t i, quality q)
{
    return i % q.stride == 0 || (q.firsts && run_start(a, i));
}

/* Rays of one gather that texels [lo, hi) cast at quality q. */
static uint32_t rays_of(const lm_atlas *a, uint32_t lo, uint32_t hi, quality q)
{
    uint32_t n = 0;
    for (uint32_t i = lo; i < hi; i++)
        n += gathers_at(a, i, q);
    return n * q.K;
}

/* Texel i's frame as the gather sees it: its eye, the plane's axes b and t, its normals n and ng. */
static void texel_frame(const lm_light_scale_world *w, uint32_t i, float eye[3], float b[3], float t[3], float n[3],
                        float ng[3])
{
    lm_gather_texel_frame(w->set, w->scene, w->atlas, i, eye, n, ng);
    lm_vec3 tv, bv;
    lm_tangents(lm_v3_load(n), &tv, &bv);
    lm_v3_store(t, tv);
    lm_v3_store(b, bv);
}

/* Texel i's two gathers (header) into e0 and e1 (3 floats each). */
static void gathers(const lm_light_scale_world *w, const lm_rim *was, const lm_rim *now, uint32_t i, float *e0,
                    float *e1)
{
    float eye[3], n[3], ng[3], b[3], t[3];
    texel_frame(w, i, eye, b, t, n, ng);
    lm_rim_irradiance_pair(was, now, eye, b, t, n, ng, lm_gather_texel_seed(w->set, i), e0, e1);
}

void lm_light_scale_texel_rim(const lm_light_scale_world *w, const lm_rim *r, uint32_t i, float e[3])
{
    float eye[3], n[3], ng[3], b[3], t[3];
    texel_frame(w, i, eye, b, t, n, ng);
    lm_rim_irradiance(r, eye, b, t, n, ng, lm_gather_texel_seed(w->set, i), e, NULL);
}

/* Whether texel i's window at `at` holds the texel dx, dy from it: on its surface and gathered (done).
 * Gives its index and its weight: where few texels gathered, a tent, so that a gather entering the window
 * as it moves by one texel weighs little and the sums, and the factors, change smoothly from texel to
 * texel; where all did, flat (the tent would weigh a texel's own noise more). */
static int in_window(const lm_atlas *a, const uint8_t *done, quality at, uint32_t i, int dx, int dy, int *q,
                     double *w)
{
    const lm_texel *t = &a->texels[i];
    int x = (int)t->x + dx, y = (int)t->y + dy;
    if (x < 0 || y < 0 || x >= a->width || y >= a->height)
        return 0;
    *q = a->texel_index[(size_t)y * a->width + x];
    if (*q < 0 || !done[*q] || a->texels[*q].surface != t->surface)
        return 0;
    *w = at.stride > 1 ? (double)(at.spread + 1 - abs(dx)) * (at.spread + 1 - abs(dy)) : 1.0;
    return 1;
}

/* The relative standard error of texel i's factors f (the channels with use[c] set), as a ratio estimator
 * over its window: sqrt(sum w^2 (e1 - f e0)^2) / sum w e1 per channel, the largest (the channels' residuals
 * added together in quadrature over their summed light read a channel's own error over sqrt 3 where they
 * change alike, over 3 where one changes). 0 where every texel of the window saw its light change by the
 * same factor: one light lights them, and the factor is exact whatever rays the gathers cast. Where
 * several lights light the window in different shares, the gathers' few rays per texel each see a
 * different mix, and the spread of their ratios says how far the sum's ratio may be off (the two rooms'
 * light_a2 removed: a face it lit to 80% read -21..+20% per texel, 10% over the face, and kept it for the
 * 75 updates the surfaces' order spent elsewhere). */
static float window_doubt(const lm_atlas *a, const float *e0, const float *e1, const uint8_t *done, quality at,
                          uint32_t i, const float *f, const int *use)
{
    double r2[3] = {0, 0, 0}, sum[3] = {0, 0, 0};
    for (int dy = -at.spread; dy <= at.spread; dy++)
        for (int dx = -at.spread; dx <= at.spread; dx++) {
            int q;
            double w;
            if (!in_window(a, done, at, i, dx, dy, &q, &w))
                continue;
            for (int c = 0; c < 3; c++)
                if (use[c]) {
                    double r = e1[3 * (size_t)q + c] - f[c] * e0[3 * (size_t)q + c];
                    r2[c] += w * w * r * r, sum[c] += w * e1[3 * (size_t)q + c];
                }
        }
    double u = 0.0;
    for (int c = 0; c < 3; c++)
        if (sum[c] > 0.0)
            u = fmax(u, sqrt(r2[c]) / sum[c]);
    return isfinite(u) ? (float)u : 0.0f;
}

/* Texel i's factor: the ratio of the gathers' sums over the texels of its surface within at.spread of it
 * that gathered (done), a ratio that varies slowly over a surface and is far less noisy summed; 1 where
 * they see no light either way, or where it is within LM_LIGHT_SCALE_KEEP of 1; its surface's where none
 * of them gathered. After an edit that adds light, where they saw next to no light before
 * (LM_LIGHT_SCALE_DARK), no factor can light the texel: its factor is 1 and *add the gathers' mean change,
 * what a regather would add to it to first order (the gathers estimate the IIM's irradiance itself),
 * unless that is under `least` (a negative `least`: no edit that adds, nothing added). *doubt: the
 * factor's relative standard error (window_doubt), 0 where it is not the window's ratio (NULL: not wanted). */
static void texel_ratio(const lm_atlas *a, const float *e0, const float *e1, const uint8_t *done, quality at,
                        const float *surface_factor, const uint8_t *black, float least, uint32_t i, float *out,
                        float *add, float *doubt)
{
    const lm_texel *t = &a->texels[i];
    const int spread = at.spread;
    double s0[3] = {0, 0, 0}, s1[3] = {0, 0, 0}, met = 0.0;
    for (int dy = -spread; dy <= spread; dy++)
        for (int dx = -spread; dx <= spread; dx++) {
            int q;
            double w;
            if (!in_window(a, done, at, i, dx, dy, &q, &w))
                continue;
            met += w;
            for (int c = 0; c < 3; c++)
                s0[c] += w * e0[3 * (size_t)q + c], s1[c] += w * e1[3 * (size_t)q + c];
        }
    const float *own = surface_factor + 3 * t->surface;
    const double full = (double)(spread + 1) * (spread + 1); /* one gather's weight at the window's centre */
    int keep = 1, use[3] = {0, 0, 0};
    float ratio[3] = {1.0f, 1.0f, 1.0f};
    for (int c = 0; c < 3; c++) { /* no neighbour gathered (a large atlas's strides): its surface's */
        int dark = met > 0.0 && least >= 0.0f && s1[c] > LM_LIGHT_SCALE_DARK * s0[c];
        /* rays that met no light either way say nothing of the factor: the surface's own says what its
         * light did (a dark corner of truck-town whose 36 rays all missed the sunlit AIM took 1 and, at the
         * refinement, went back to its light before the sun was dimmed, twice the converged lightmap); a
         * texel the IIM shows black keeps 1, as where no neighbour gathered */
        float none = black && black[i] ? 1.0f : own[c]; /* a black texel: nothing to scale, nothing rewritten */
        float f = !(met > 0.0) || dark ? (met > 0.0 ? 1.0f : none) : s0[c] > 0.0 ? (float)(s1[c] / s0[c]) : none;
        float d = dark ? (float)((s1[c] - s0[c]) / met) : 0.0f;
        out[c] = isfinite(f) && f >= 0.0f ? f : own[c];
        use[c] = met > 0.0 && !dark && s0[c] > 0.0 && out[c] == f;
        ratio[c] = out[c];
        /* where only every stride-th texel gathered, not each surface's first (fewer rays than surfaces), a
         * texel whose window holds less than one gather's weight at its centre leans on its surface's
         * factor as that weight falls: else the factor jumped where the last gather left the window
         * (test_gather's 40-ray first guess: its largest step 0.61, now 0.30) */
        if (!at.firsts && !dark && met > 0.0 && met < full) {
            float alpha = (float)(met / full);
            out[c] = alpha * out[c] + (1.0f - alpha) * own[c];
        }
        add[c] = isfinite(d) && d >= least ? d : 0.0f;
        keep &= fabsf(out[c] - 1.0f) < LM_LIGHT_SCALE_KEEP && add[c] == 0.0f;
    }
    if (doubt)
        *doubt = keep ? 0.0f : window_doubt(a, e0, e1, done, at, i, ratio, use);
    for (int c = 0; keep && c < 3; c++)
        out[c] = 1.0f;
}

/* Texels list[0 .. n) (list NULL: 0 .. n) gathered at quality q into ls->e (those that gather at it,
 * flagged done), in one parallel pass. */
static void gather_texels(lm_light_scale *ls, const lm_light_scale_world *w, const float *after, quality q,
                          const uint32_t *list, uint32_t n)
{
    const lm_atlas *a = w->atlas;
    size_t T = a->texel_count;
    lm_rim was = {w->scene, a, w->rt, ls->before, 1, {w->set->sky[0], w->set->sky[1], w->set->sky[2]}, 0.0f,
                  (int)q.K, ls->emissive_before, NULL, NULL, 0.0f, 0.0f, 0};
    if (w->scene->has_sky)
        lm_sky_mean(w->scene, was.sky);
    lm_rim now = was;
    now.aim = after;
    now.emissive = NULL;
    for (uint32_t j = 0; j < n; j++) {
        uint32_t i = list ? list[j] : j;
        ls->done[i] = (uint8_t)gathers_at(a, i, q);
    }
#pragma omp parallel
    {
        lm_rt_thread_init();
#pragma omp for schedule(dynamic, 16)
        for (long j = 0; j < (long)n; j++) {
            uint32_t i = list ? list[j] : (uint32_t)j;
            if (ls->done[i])
                gathers(w, &was, &now, i, ls->e + 3 * (size_t)i, ls->e + 3 * (T + (size_t)i));
        }
    }
}

/* The factors, additions and doubts of texels [lo, hi), whole surfaces gathered, into f and d (3 per texel)
 * and u (1 per texel; NULL: no doubts), texel lo's first. */
static void ratios(const lm_light_scale *ls, const lm_atlas *a, quality q, uint32_t lo, uint32_t hi, float *f,
                   float *d, float *u)
{
    const float *e0 = ls->e, *e1 = ls->e + 3 * (size_t)a->texel_count;
    /* one thread for a small surface: the refinement's surfaces of a few texels each, a parallel region
     * apiece, took 4-18 ms an update on the shared room where their sums took microseconds */
#pragma omp parallel for schedule(static) if (hi - lo > 1024)
    for (long i = (long)lo; i < (long)hi; i++)
        texel_ratio(a, e0, e1, ls->done, q, ls->surface_factor, ls->black, ls->least, (uint32_t)i,
                    f + 3 * (i - (long)lo), d + 3 * (i - (long)lo), u ? u + (i - (long)lo) : NULL);
}

/* The smallest addition worth a rewrite: LM_LIGHT_SCALE_KEEP of the mean irradiance the gathers of the
 * first pass saw after the edit (the few photons a closed door lets into a dark room rewrite nothing). */
static float least_add(const lm_light_scale *ls, const lm_atlas *a)
{
    const float *e1 = ls->e + 3 * (size_t)a->texel_count;
    double sum = 0.0;
    uint32_t n = 0;
    for (uint32_t i = 0; i < a->texel_count; i++)
        if (ls->done[i])
            sum += e1[3 * (size_t)i] + e1[3 * (size_t)i + 1] + e1[3 * (size_t)i + 2], n++;
    return n ? (float)(LM_LIGHT_SCALE_KEEP * sum / (3.0 * n)) : 0.0f;
}

void lm_light_scale_init(lm_light_scale *ls) { memset(ls, 0, sizeof *ls); }

void lm_light_scale_free(lm_light_scale *ls)
{
    free(ls->before);
    free(ls->emissive_before);
    free(ls->surface_factor);
    free(ls->e);
    free(ls->done);
    free(ls->kept);
    free(ls->black);
    free(ls->applied);
    free(ls->added);
    free(ls->range);
    free(ls->order);
    free(ls->list);
    lm_light_scale_init(ls);
}

/* Every texel its surface's factor, nothing added: no AIM from before, or no memory. */
static void surface_factors(const lm_atlas *a, const float *surface_factor, float *factor, float *add)
{
    for (uint32_t i = 0; i < a->texel_count; i++)
        memcpy(factor + 3 * (size_t)i, surface_factor + 3 * a->texels[i].surface, 3 * sizeof *factor);
    memset(add, 0, sizeof *add * 3 * (size_t)a->texel_count);
}

/* How far surface k's first guess moved its texels: the sum of |f - 1| over them and their channels, a
 * texel given an addition counting as moved all the way. */
static double moved_by(const lm_light_scale *ls, int k)
{
    double m = 0.0;
    for (uint32_t i = ls->range[2 * k]; i < ls->range[2 * k + 1]; i++)
        for (int c = 0; c < 3; c++)
            m += ls->added[3 * (size_t)i + c] > 0.0f ? 1.0 : fabs((double)ls->applied[3 * (size_t)i + c] - 1.0);
    return m;
}

/* The refinement's order: each surface's run of texels (range), the surfaces the first guess moved most
 * first (what the edit changed most is right soonest), ties by id. 0: no memory. */
static int plan_order(lm_light_scale *ls, const lm_atlas *a)
{
    int S = a->surface_count;
    ls->range = calloc(2 * (size_t)S + 1, sizeof *ls->range);
    ls->order = malloc(sizeof *ls->order * (size_t)(S ? S : 1));
    ls->list = malloc(sizeof *ls->list * ((size_t)a->texel_count + 1));
    double *moved = malloc(sizeof *moved * (size_t)(S ? S : 1));
    if (!ls->range || !ls->order || !ls->list || !moved) {
        free(moved);
        return 0;
    }
    ls->count = 0;
    for (uint32_t i = 0; i < a->texel_count; i++) {
        int k = a->texels[i].surface;
        if (run_start(a, i))
            ls->range[2 * k] = i, ls->order[ls->count++] = k;
        ls->range[2 * k + 1] = i + 1;
    }
    for (int j = 0; j < ls->count; j++)
        moved[ls->order[j]] = moved_by(ls, ls->order[j]);
    for (int j = 1; j < ls->count; j++) { /* insertion sort: a handful to thousands of surfaces, once */
        int k = ls->order[j], at = j;
        for (; at > 0 && moved[ls->order[at - 1]] < moved[k]; at--)
            ls->order[at] = ls->order[at - 1];
        ls->order[at] = k;
    }
    free(moved);
    ls->at = 0;
    ls->next = 0;
    return 1;
}

uint32_t lm_light_scale_begin(lm_light_scale *ls, const lm_light_scale_world *w, float *before,
                              float *emissive_before, uint8_t *black, const float *after, const float *surface_factor,
                              int adds, uint32_t rays, float *factor, float *add, float *doubt)
{
    const lm_atlas *a = w->atlas;
    size_t T = a->texel_count, S = (size_t)a->surface_count;
    lm_light_scale_free(ls);
    ls->before = before;
    ls->emissive_before = emissive_before;
    ls->black = black;
    ls->surface_factor = malloc(sizeof *ls->surface_factor * 3 * (S ? S : 1));
    ls->e = before && T ? malloc(sizeof *ls->e * 6 * T) : NULL;
    ls->done = ls->e ? calloc(T, 1) : NULL;
    ls->kept = ls->done ? calloc(T, 1) : NULL;
    ls->applied = ls->kept ? malloc(sizeof *ls->applied * 3 * T) : NULL;
    ls->added = ls->applied ? malloc(sizeof *ls->added * 3 * T) : NULL;
    if (!ls->added || !ls->surface_factor) {
        surface_factors(a, surface_factor, factor, add);
        memset(doubt, 0, sizeof *doubt * T);
        lm_light_scale_free(ls);
        return 0;
    }
    memcpy(ls->surface_factor, surface_factor, sizeof *ls->surface_factor * 3 * S);
    quality full = full_quality((uint32_t)T), q = full;
    int coarse = rays > 0 && rays < rays_of(a, 0, (uint32_t)T, full);
    if (coarse) { /* the first guess: FEWEST_RAYS for every stride-th, the stride that fits */
        uint32_t runs = 0; /* each surface's first texel, if that fits */
        for (uint32_t i = 0; i < T; i++)
            runs += run_start(a, i);
        runs *= FEWEST_RAYS;
        int firsts = rays >= runs + FEWEST_RAYS;
        uint32_t strided = firsts ? rays - runs : rays;
        uint32_t stride = (uint32_t)((FEWEST_RAYS * T + strided - 1) / strided);
        q = quality_of(FEWEST_RAYS, stride > full.stride ? stride : full.stride);
        q.firsts = firsts; /* else a surface none of whose texels gathers takes its surface's factor */
        while ((uint32_t)((2 * q.spread + 1) * (2 * q.spread + 1)) * q.K < FIRST_GUESS_SUMMED * q.stride &&
               q.spread < MOST_SPREAD)
            q.spread++;
    }
    gather_texels(ls, w, after, q, NULL, (uint32_t)T);
    ls->least = adds ? least_add(ls, a) : -1.0f;
    ratios(ls, a, q, 0, (uint32_t)T, factor, add, coarse ? NULL : doubt);
    uint32_t cast = rays_of(a, 0, (uint32_t)T, q);
    if (!coarse) { /* the full quality: nothing to refine */
        lm_light_scale_free(ls);
        return cast;
    }
    memset(doubt, 0, sizeof *doubt * T); /* a first guess's few rays doubt all that is mixed: the refinement's say */
    memcpy(ls->applied, factor, sizeof *factor * 3 * T);
    memcpy(ls->added, add, sizeof *add * 3 * T);
    ls->active = plan_order(ls, a);
    if (!ls->active) /* no memory: the first guess stays, which regathers refine */
        lm_light_scale_free(ls);
    return cast;
}

/* The refinement's next texels from surface order[*at], texel *next on, in its order, until about `rays`
 * rays (at least one texel that gathers) or `most` texels: into list (may be NULL), *at and *next moved past
 * them. Returns how many; *cast the rays. */
static uint32_t walk(const lm_light_scale *ls, const lm_atlas *a, quality q, uint32_t rays, uint32_t most,
                     uint32_t *list, int *at, uint32_t *next, uint32_t *cast)
{
    uint32_t n = 0;
    *cast = 0;
    while (*at < ls->count && (*cast == 0 || *cast < rays) && n < most) {
        int k = ls->order[*at];
        uint32_t start = ls->range[2 * k], end = ls->range[2 * k + 1];
        uint32_t hi = *next > start ? *next : start;
        while (hi < end && (*cast == 0 || *cast < rays) && n < most) {
            *cast += gathers_at(a, hi, q) ? q.K : 0;
            if (list)
                list[n] = hi;
            n++, hi++;
        }
        *next = hi;
        if (hi < end)
            break;
        (*at)++;
        *next = 0; /* the next surface's run starts anywhere */
    }
    return n;
}

uint32_t lm_light_scale_refine(lm_light_scale *ls, const lm_light_scale_world *w, const float *after, uint32_t rays,
                               double ms, float *factor, float *add, float *doubt, int *corrected)
{
    *corrected = 0;
    if (!ls->active)
        return 0;
    const lm_atlas *a = w->atlas;
    quality q = full_quality(a->texel_count);
    rays = rays ? rays : UINT32_MAX; /* no bound (the budget switched off): the rest at once */
    for (size_t c = 0; c < 3 * (size_t)a->texel_count; c++)
        factor[c] = 1.0f, add[c] = 0.0f;
    memset(doubt, 0, sizeof *doubt * a->texel_count);
    /* this update's texels, over every surface the rays reach, gathered together: a surface at a time, the
     * shared room's surfaces of a few texels each kept one core busy and the other idle, and a
     * refinement's ray cost 3 to 9 times the first guess's, past its plan. In chunks, so that `ms` can
     * stop it: the same rays cost 0.9 ms in one update and 22 ms in another (which texels they are) */
    int at = ls->at;
    uint32_t next = ls->next, cast, n = walk(ls, a, q, rays, UINT32_MAX, ls->list, &at, &next, &cast), done = 0;
    double t0 = lm_now();
    while (done < n && (done == 0 || !(ms > 0.0) || 1e3 * (lm_now() - t0) < ms)) {
        uint32_t m = n - done < LM_LIGHT_SCALE_CHUNK ? n - done : LM_LIGHT_SCALE_CHUNK;
        gather_texels(ls, w, after, q, ls->list + done, m);
        done += m;
    }
    if (done < n) { /* stopped by the time: where the gathers got to */
        at = ls->at, next = ls->next;
        walk(ls, a, q, UINT32_MAX, done, NULL, &at, &next, &cast);
    }
    for (; ls->at < at; ls->at++) { /* the surfaces whose texels have all gathered: their factors */
        int k = ls->order[ls->at];
        uint32_t start = ls->range[2 * k], end = ls->range[2 * k + 1];
        float *f = malloc(sizeof *f * 7 * (size_t)(end - start)), *d = f ? f + 3 * (size_t)(end - start) : NULL;
        if (!f) { /* the rest keeps its first guess, which regathers refine */
            lm_light_scale_free(ls);
            return cast;
        }
        ratios(ls, a, q, start, end, f, d, d + 3 * (size_t)(end - start));
        for (uint32_t i = start; i < end; i++) {
            doubt[i] = ls->kept[i] ? 0.0f : d[3 * (size_t)(end - start) + (i - start)];
            for (int c = 0; c < 3; c++) {
                size_t j = 3 * (size_t)i + c, o = 3 * (size_t)(i - start) + c;
                float was = ls->applied[j], now = f[o], had = ls->added[j], adds = d[o];
                /* from v f1 + a1 to v f2 + a2: times f2 / f1, plus a2 - a1 f2 / f1. A channel the first guess
                 * took to 0 cannot be scaled back: its regather brings it */
                if (ls->kept[i] || !(was > 1e-6f) || (now == was && adds == had))
                    continue;
                factor[j] = now / was, add[j] = adds - had * factor[j], *corrected = 1;
            }
        }
        free(f);
    }
    ls->next = next;
    if (ls->at >= ls->count)
        lm_light_scale_free(ls);
    return cast;
}

void lm_light_scale_regathered(lm_light_scale *ls, const uint32_t *texels, uint32_t n)
{
    for (uint32_t i = 0; ls->active && i < n; i++)
        ls->kept[texels[i]] = 1;
}

uint32_t lm_light_scale_waiting(const lm_light_scale *ls, const lm_atlas *a)
{
    if (!ls->active) /* none under way (an atlas without texels never starts one) */
        return 0;
    quality q = full_quality(a->texel_count);
    uint32_t n = 0;
    for (int j = ls->at; j < ls->count; j++) {
        int k = ls->order[j];
        uint32_t lo = ls->range[2 * k];
        n += rays_of(a, j == ls->at && ls->next > lo ? ls->next : lo, ls->range[2 * k + 1], q);
    }
    return n;
}
