/* The AIM estimate's visibility test: aim_sight.h. */
#include "aim_sight.h"

#include <math.h>
#include <string.h>

#include "../core/vecmath.h"

#define GOLDEN_ANGLE 2.39996323f

/* Whether the point p, lifted off the surface of normal n by side (signed lift), sees q. */
static int segment_clear(const lm_aim_sight *s, const float p[3], const float n[3], const float q[3], float side)
{
    float org[3], dir[3], len = 0.0f;
    for (int c = 0; c < 3; c++) {
        org[c] = p[c] + side * n[c];
        dir[c] = q[c] - org[c];
        len += dir[c] * dir[c];
    }
    len = sqrtf(len);
    if (!(len > 4.0f * s->lift))
        return 1;
    for (int c = 0; c < 3; c++)
        dir[c] /= len;
    return !lm_rt_occluded(s->rt, org, dir, 0.0f, len - 2.0f * s->lift);
}

/* Geometry closer than the cover distance straight out from p, on the side `side` points to. */
static int is_covered(const lm_aim_sight *s, const float p[3], const float n[3], float side)
{
    float out[3];
    for (int c = 0; c < 3; c++)
        out[c] = side < 0.0f ? -n[c] : n[c];
    return lm_rt_covered(s->rt, p, out, s->lift, s->cover);
}

typedef struct {
    float p[LM_AIM_SIGHT_POINTS][3];
    int count;
} disc_points;

/* The disc's points that lie on a surface facing the texel's way (each dropped from 2 lift above the
 * disc's plane onto what lies there within 4 lift) and are not covered. They are spread as the kernel
 * weighs the disc, so that each counts the same: uniform over the disc for the box; for Epanechnikov, whose
 * weight within radius u is 2 u^2 - u^4, at u^2 = 1 - sqrt(1 - F). */
static void place_points(const lm_aim_sight *s, const lm_aim_sight_texel *t, disc_points *d)
{
    const float *n = t->n;
    lm_vec3 tv, bv;
    lm_tangents(lm_v3_load(n), &tv, &bv);
    float t1[3], t2[3];
    lm_v3_store(t1, tv);
    lm_v3_store(t2, bv);
    float turn = (float)(t->index % 1024u) * GOLDEN_ANGLE;
    d->count = 0;
    for (int m = 0; m < LM_AIM_SIGHT_POINTS; m++) {
        float f = ((float)m + 0.5f) / (float)LM_AIM_SIGHT_POINTS, u = sqrtf(s->kernel ? 1.0f - sqrtf(1.0f - f) : f);
        float ang = turn + (float)m * GOLDEN_ANGLE, cu = cosf(ang) * u * t->r, su = sinf(ang) * u * t->r;
        float org[3], down[3];
        for (int c = 0; c < 3; c++) {
            org[c] = t->x[c] + cu * t1[c] + su * t2[c] + 2.0f * s->lift * n[c];
            down[c] = -n[c];
        }
        lm_rt_hit h;
        if (!lm_rt_intersect(s->rt, org, down, 0.0f, 4.0f * s->lift, &h) ||
            h.ng[0] * n[0] + h.ng[1] * n[1] + h.ng[2] * n[2] < 0.9f)
            continue; /* past the surface's edge: not part of the disc */
        float *p = d->p[d->count];
        for (int c = 0; c < 3; c++)
            p[c] = org[c] - (2.0f * s->lift) * n[c];
        if (is_covered(s, p, n, s->lift))
            continue; /* under a box: no photon lands there, whatever it would see */
        d->count++;
    }
}

/* How many of the points (lifted off the surface to q's side) see q: one packet of rays from q, moved off
 * q's own surface towards the texel, to the points. */
static int points_seeing(const lm_aim_sight *s, const disc_points *d, const lm_aim_sight_texel *t, const float q[3],
                         float side)
{
    float u[3], lu = 0.0f;
    for (int c = 0; c < 3; c++) {
        u[c] = t->x[c] + side * t->n[c] - q[c];
        lu += u[c] * u[c];
    }
    lu = sqrtf(lu);
    if (!(lu > 4.0f * s->lift))
        return d->count; /* q at the texel itself */
    float org[3], dir[3 * LM_AIM_SIGHT_POINTS], tfar[LM_AIM_SIGHT_POINTS];
    int blocked[LM_AIM_SIGHT_POINTS], seen = 0;
    for (int c = 0; c < 3; c++)
        org[c] = q[c] + 2.0f * s->lift * u[c] / lu;
    for (int m = 0; m < d->count; m++) {
        float len = 0.0f, *v = dir + 3 * m;
        for (int c = 0; c < 3; c++) {
            v[c] = d->p[m][c] + side * t->n[c] - org[c];
            len += v[c] * v[c];
        }
        len = sqrtf(len);
        for (int c = 0; c < 3; c++)
            v[c] = len > 0.0f ? v[c] / len : t->n[c];
        tfar[m] = len;
    }
    if (d->count)
        lm_rt_occluded8(s->rt, org, dir, tfar, d->count, blocked);
    for (int m = 0; m < d->count; m++)
        seen += !blocked[m];
    return seen;
}

void lm_aim_sight_weigh(const lm_aim_sight *s, const lm_aim_sight_texel *t, const float *ends, const uint32_t *idx,
                        uint32_t k, float *weight)
{
    int covered[2] = {-1, -1}, placed = 0; /* front, back: not yet known */
    disc_points d;
    float last_q[3] = {NAN, NAN, NAN}, last_w = 1.0f;
    for (uint32_t i = 0; i < k; i++) {
        const float *q = ends + 6 * (size_t)idx[i] + 3;
        weight[i] = 1.0f;
        if (!s->rt || isnan(q[0]))
            continue;
        int back = (q[0] - t->x[0]) * t->n[0] + (q[1] - t->x[1]) * t->n[1] + (q[2] - t->x[2]) * t->n[2] < 0.0f;
        float side = back ? -s->lift : s->lift;
        if (covered[back] < 0)
            covered[back] = is_covered(s, t->x, t->n, side);
        if (covered[back])
            continue;
        if (!memcmp(q, last_q, sizeof last_q)) { /* a point light's first hits: the same q */
            weight[i] = last_w;
            continue;
        }
        memcpy(last_q, q, sizeof last_q);
        if (!segment_clear(s, t->x, t->n, q, side)) {
            weight[i] = last_w = 0.0f;
            continue;
        }
        if (!placed) {
            place_points(s, t, &d);
            placed = 1;
        }
        int seen = points_seeing(s, &d, t, q, side);
        /* The hit's own point saw q: at least one point's worth. */
        weight[i] = last_w = d.count ? (float)d.count / (float)(seen > 0 ? seen : 1) : 1.0f;
    }
}
