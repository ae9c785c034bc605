/* Portals: sampling lines through openings, and the density of a line crossing them (portals.h). */
#include "portals.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../core/stats.h"
#include "../core/vecmath.h"

static void corners(const lm_portals *p, uint32_t i, lm_vec3 c[3])
{
    for (int k = 0; k < 3; k++)
        c[k] = lm_v3_load(p->tris + 9 * (size_t)i + 3 * (size_t)k);
}

/* Twice the area times the unit normal of triangle i (its front, counter-clockwise). */
static lm_vec3 front(const lm_portals *p, uint32_t i)
{
    lm_vec3 c[3];
    corners(p, i, c);
    return lm_cross(lm_sub(c[1], c[0]), lm_sub(c[2], c[0]));
}

lm_portals *lm_portals_make(const float *tris, const double *weight, const unsigned char *tagged,
                            const unsigned char *opening, uint32_t n, lm_error *err)
{
    lm_portals *p = calloc(1, sizeof *p);
    if (p) {
        p->count = n;
        p->tagged = calloc((size_t)n + 1, 1);
        p->opening = calloc((size_t)n + 1, 1);
        p->tris = malloc(sizeof *p->tris * 9 * ((size_t)n + 1));
        p->weight = malloc(sizeof *p->weight * ((size_t)n + 1));
        p->area = malloc(sizeof *p->area * ((size_t)n + 1));
        p->density = calloc((size_t)n + 1, sizeof *p->density);
        p->cdf = calloc((size_t)n + 1, sizeof *p->cdf);
        p->normal = malloc(sizeof *p->normal * 3 * ((size_t)n + 1));
    }
    if (!p || !p->tris || !p->weight || !p->tagged || !p->opening || !p->area || !p->density || !p->cdf || !p->normal) {
        lm_portals_free(p);
        lm_fail(err, LM_ERR_NOMEM, "portals: no memory for %u triangles", n);
        return NULL;
    }
    memcpy(p->tris, tris, sizeof *p->tris * 9 * (size_t)n);
    for (uint32_t i = 0; i < n; i++) {
        lm_vec3 f = front(p, i);
        float len = lm_length(f);
        p->area[i] = 0.5 * (double)len;
        lm_v3_store(p->normal + 3 * (size_t)i, len > 0.0f ? lm_scale(f, 1.0f / len) : lm_v3(0, 0, 0));
        p->weight[i] = weight ? weight[i] : p->area[i];
        p->tagged[i] = tagged ? tagged[i] != 0 : 0;
        p->opening[i] = opening ? opening[i] != 0 : 1;
        p->found += !p->tagged[i];
    }
    return p;
}

lm_portals *lm_portals_tagged(const float *tris, uint32_t n, lm_error *err)
{
    unsigned char *all = malloc((size_t)n + 1);
    if (!all) {
        lm_fail(err, LM_ERR_NOMEM, "portals: no memory for %u triangles", n);
        return NULL;
    }
    memset(all, 1, (size_t)n + 1);
    lm_portals *p = lm_portals_make(tris, NULL, all, NULL, n, err);
    free(all);
    return p;
}

void lm_portals_free(lm_portals *p)
{
    if (!p)
        return;
    free(p->tris);
    free(p->weight);
    free(p->tagged);
    free(p->opening);
    free(p->area);
    free(p->density);
    free(p->cdf);
    free(p->normal);
    free(p);
}

/* Sun: a tagged portal is picked by its area across the light (its weight is its area), a found one by
 * its weight; neither where its front does not face the light. Sky: by weight. */
static double pick_weight(const lm_portals *p, uint32_t i, const float *d, double *cosine)
{
    *cosine = 1.0;
    if (!(p->area[i] > 0.0) || !(p->weight[i] > 0.0))
        return 0.0;
    if (!d)
        return p->weight[i];
    *cosine = -lm_dot(lm_v3_load(p->normal + 3 * (size_t)i), lm_v3_load(d));
    if (!(*cosine > 0.0))
        return 0.0;
    return p->tagged[i] ? p->weight[i] * *cosine : p->weight[i];
}

void lm_portals_aim(lm_portals *p, const float d[3])
{
    double sum = 0.0;
    for (uint32_t i = 0; i < p->count; i++) { /* for now: each one's weight in cdf, its line measure in density */
        double cosine;
        sum += p->cdf[i] = pick_weight(p, i, d, &cosine);
        p->density[i] = p->area[i] * (d ? cosine : LM_PI);
    }
    p->usable = sum > 0.0;
    double acc = 0.0;
    for (uint32_t i = 0; i < p->count; i++) {
        double prob = p->usable ? p->cdf[i] / sum : 0.0;
        acc += prob;
        p->cdf[i] = acc;
        p->density[i] = prob > 0.0 ? prob / p->density[i] : 0.0;
    }
    if (p->usable) /* the last pickable one ends the table at 1 exactly */
        for (uint32_t i = p->count; i-- > 0;)
            if (p->density[i] > 0.0) {
                for (uint32_t k = i; k < p->count; k++)
                    p->cdf[k] = 1.0;
                break;
            }
}

/* The pickable triangle whose share of the table holds u, and u's place within that share. */
static uint32_t pick(const lm_portals *p, double u, double *rest)
{
    uint32_t lo = lm_cdf_draw(p->cdf, p->count, u);
    while (!(p->density[lo] > 0.0) && lo > 0) /* u at a share's end rounded onto an empty one */
        lo--;
    double a = lo ? p->cdf[lo - 1] : 0.0, b = p->cdf[lo];
    *rest = b > a ? fmin(fmax((u - a) / (b - a), 0.0), 0x1.fffffep-1) : 0.5;
    return lo;
}

/* Uniform on triangle i from two numbers. */
static lm_vec3 on_triangle(const lm_portals *p, uint32_t i, double a, float b)
{
    lm_vec3 c[3];
    corners(p, i, c);
    float r = sqrtf((float)a);
    return lm_add(lm_scale(c[0], 1.0f - r), lm_add(lm_scale(c[1], r * (1.0f - b)), lm_scale(c[2], r * b)));
}

int lm_portals_sun_point(const lm_portals *p, float u0, float u1, float x[3])
{
    if (!p || !p->usable)
        return 0;
    double rest;
    uint32_t i = pick(p, u0, &rest);
    lm_v3_store(x, on_triangle(p, i, rest, u1));
    return 1;
}

int lm_portals_sky_line(const lm_portals *p, float u_pick, float u_tri, float u0, float u1, float x[3], float w[3])
{
    if (!p || !p->usable)
        return 0;
    double rest;
    uint32_t i = pick(p, u_pick, &rest);
    lm_v3_store(x, on_triangle(p, i, rest, u_tri));
    lm_v3_store(w, lm_cosine_dir(lm_v3_load(p->normal + 3 * (size_t)i), u0, u1));
    return 1;
}

/* Where the line O + t D (t > 0) enters triangle i by its front: t, or -1 where it does not
 * (Moller-Trumbore). */
static float entered(const lm_portals *p, uint32_t i, lm_vec3 O, lm_vec3 D)
{
    lm_vec3 c[3];
    corners(p, i, c);
    lm_vec3 e1 = lm_sub(c[1], c[0]), e2 = lm_sub(c[2], c[0]), q = lm_cross(D, e2);
    float det = lm_dot(e1, q);
    if (!(lm_dot(lm_cross(e1, e2), D) < 0.0f) || fabsf(det) < 1e-30f)
        return -1.0f; /* not entering by its front */
    lm_vec3 tv = lm_sub(O, c[0]), r = lm_cross(tv, e1);
    float a = lm_dot(tv, q) / det, b = lm_dot(D, r) / det, t = lm_dot(e2, r) / det;
    return a >= 0.0f && b >= 0.0f && a + b <= 1.0f && t > 0.0f ? t : -1.0f;
}

double lm_portals_density(const lm_portals *p, const float o[3], const float d[3])
{
    lm_vec3 O = lm_v3_load(o), D = lm_v3_load(d);
    double sum = 0.0;
    for (uint32_t i = 0; p && i < p->count; i++)
        if (p->density[i] > 0.0 && entered(p, i, O, D) > 0.0f)
            sum += p->density[i];
    return sum;
}

/* How much of the cosine-weighted hemisphere at x (unit normal n, the side a bounce leaves by) opening i
 * fills, judged from its centre: A cos_i cos_x / d^2. 0 for a place outside, and where x is behind the
 * opening (inside: its front faces out) or its centre is below x's horizon. */
static double reach(const lm_portals *p, uint32_t i, lm_vec3 x, lm_vec3 n)
{
    if (!p->opening[i] || !(p->area[i] > 0.0))
        return 0.0;
    lm_vec3 c[3];
    corners(p, i, c);
    lm_vec3 v = lm_sub(lm_scale(lm_add(c[0], lm_add(c[1], c[2])), 1.0f / 3.0f), x);
    double d2 = lm_dot(v, v), toward = -lm_dot(lm_v3_load(p->normal + 3 * (size_t)i), v), up = lm_dot(n, v);
    if (!(d2 > 0.0) || !(toward > 0.0) || !(up > 0.0))
        return 0.0;
    return p->area[i] * toward * up / (d2 * d2);
}

double lm_portals_bounce_reach(const lm_portals *p, const float x[3], const float n[3])
{
    lm_vec3 X = lm_v3_load(x), N = lm_v3_load(n);
    double sum = 0.0;
    for (uint32_t i = 0; p && i < p->count; i++)
        sum += reach(p, i, X, N);
    return sum;
}

int lm_portals_bounce_dir(const lm_portals *p, const float x[3], const float n[3], double total, float u0, float u1,
                          float w[3])
{
    lm_vec3 X = lm_v3_load(x), N = lm_v3_load(n);
    double target = (double)u0 * total, acc = 0.0, rest = 0.5;
    uint32_t pick = UINT32_MAX;
    for (uint32_t i = 0; p && i < p->count; i++) {
        double r = reach(p, i, X, N);
        if (!(r > 0.0))
            continue;
        pick = i; /* u0 rounded past the last share lands in the last one */
        rest = fmin(fmax((target - acc) / r, 0.0), 0x1.fffffep-1);
        if (acc + r > target)
            break;
        acc += r;
    }
    if (pick == UINT32_MAX)
        return 0;
    lm_vec3 d = lm_sub(on_triangle(p, pick, rest, u1), X);
    float len = lm_length(d);
    if (!(len > 0.0f))
        return 0;
    lm_v3_store(w, lm_scale(d, 1.0f / len));
    return 1;
}

double lm_portals_bounce_density(const lm_portals *p, const float x[3], const float n[3], double total,
                                 const float w[3])
{
    lm_vec3 X = lm_v3_load(x), N = lm_v3_load(n), W = lm_v3_load(w);
    double sum = 0.0;
    for (uint32_t i = 0; p && total > 0.0 && i < p->count; i++) {
        double r = reach(p, i, X, N);
        float t = r > 0.0 ? entered(p, i, X, W) : -1.0f;
        double facing = -lm_dot(lm_v3_load(p->normal + 3 * (size_t)i), W);
        if (t > 0.0f && facing > 0.0) /* uniform on its area: per solid angle, t^2 / (A cos) */
            sum += r / total * (double)t * t / (p->area[i] * facing);
    }
    return sum;
}
