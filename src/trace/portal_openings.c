/* The openings a light gets in by, found backwards from the surfaces (portal_finder.h, portal_looks.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../scene/sky.h"
#include "portal_finder.h"
#include "portal_looks.h"

#define RING 8 /* rays round a ray that left the scene */

/* The ring of rays round a ray that left the scene, and what each hit. */
typedef struct {
    int hit[RING];
    lm_vec3 at[RING], n[RING];
} ring_hits;

/* Whether the ring's rays that hit the plane through p with normal n lie all round the ray: no run of half
 * the ring in a row misses it (a wall on one side only is not an opening's edge). */
static int round_the_ray(const ring_hits *r, lm_vec3 p, lm_vec3 n, float tol)
{
    int on[RING], any = 0;
    for (int k = 0; k < RING; k++) {
        on[k] = r->hit[k] && lm_dot(r->n[k], n) > 0.99f && fabsf(lm_dot(lm_sub(r->at[k], p), n)) < tol;
        any += on[k];
    }
    for (int k = 0; any >= 2 && k < RING; k++) {
        int run = 0;
        while (run < RING && !on[(k + run) % RING])
            run++;
        if (run >= RING / 2)
            return 0;
    }
    return any >= 2;
}

static void ring_cast(const lm_rt *rt, lm_vec3 org, lm_vec3 w, float sn, ring_hits *rh)
{
    lm_vec3 t, b;
    lm_onb(w, &t, &b);
    float cs = sqrtf(1.0f - sn * sn);
    for (int k = 0; k < RING; k++) {
        float ks, kc, o[3], d[3];
        lm_sincos_turn((float)k / RING, &ks, &kc);
        lm_vec3 dir = lm_add(lm_scale(w, cs), lm_scale(lm_add(lm_scale(t, kc), lm_scale(b, ks)), sn));
        lm_v3_store(o, org);
        lm_v3_store(d, dir);
        lm_rt_hit hit;
        rh->hit[k] = lm_rt_intersect(rt, o, d, 0.0f, INFINITY, &hit);
        rh->n[k] = rh->hit[k] ? lm_v3_load(hit.ng) : lm_v3(0, 0, 0);
        rh->at[k] = lm_add(org, lm_scale(dir, rh->hit[k] ? hit.t : 0.0f));
    }
}

/* Where a ray from org along unit w that leaves the scene passes through the opening it leaves by: the rays
 * around it (a ring at 15, then 30, then 60 degrees) hit the wall round the opening, and the ray crosses the
 * wall's plane there. A plane that the ring's hits lie on all round the ray (round_the_ray) is the
 * opening's wall; of those, the one whose hit lies nearest its own plane's crossing gives the crossing point
 * and the wall's normal, turned to face out along w. Returns 0 when no ring finds one: the ray left from the
 * open (a lawn, a roof), or through an opening wider than 120 degrees from where it began. */
static int opening_crossing(const lm_rt *rt, lm_vec3 org, lm_vec3 w, float pos[3], float normal[3])
{
    static const float ring[3] = {0.2588f, 0.5f, 0.866f}; /* sin 15, 30, 60 degrees */
    for (int r = 0; r < 3; r++) {
        ring_hits rh;
        float best = INFINITY;
        ring_cast(rt, org, w, ring[r], &rh);
        for (int k = 0; k < RING; k++) {
            if (!rh.hit[k])
                continue;
            float across = lm_dot(w, rh.n[k]);
            if (fabsf(across) < 0.2f)
                continue; /* a wall along the ray (a window's jamb) says nothing of where it crosses */
            float at = lm_dot(lm_sub(rh.at[k], org), rh.n[k]) / across;
            lm_vec3 p = lm_add(org, lm_scale(w, at));
            float miss = lm_length(lm_sub(p, rh.at[k])) / at;
            if (!(at > 0.0f) || !(miss < best) || !round_the_ray(&rh, p, rh.n[k], 0.01f * at))
                continue;
            best = miss;
            lm_v3_store(pos, p);
            lm_v3_store(normal, across > 0.0f ? rh.n[k] : lm_scale(rh.n[k], -1.0f));
        }
        if (best < INFINITY)
            return 1;
    }
    return 0;
}

/* The light's crossings: each look that leaves the scene from inside (opening_crossing) is light that gets
 * in, worth the light there (a sun's cosine at the surface; the sky's luminance from there, the look's
 * draw having the cosine already). Returns how many. */
static uint32_t crossings(const lm_scene *s, const lm_rt *rt, const lm_look_draw *d, const lm_emitter *e,
                          lm_found_point *out)
{
    uint32_t n = 0;
    double plane_step = lm_found_plane_step(s);
    int sky = e->kind == LM_EMIT_SKY;
    for (uint32_t i = 0; d->count > 0 && i < LM_FIND_LOOKS; i++) {
        float u[5], o[3], dir[3];
        lm_look_numbers(0, i, 5, u);
        lm_vec3 x, front, org;
        lm_look_point(d, s, u, &x, &front, &org);
        lm_vec3 w = lm_look_direction(e, front, u[3], u[4]);
        float facing = lm_dot(front, w);
        lm_rt_hit hit;
        lm_v3_store(o, org);
        lm_v3_store(dir, w);
        if (!(facing > 0.0f) || !lm_v3_finite(w) || lm_rt_intersect(rt, o, dir, 0.0f, INFINITY, &hit))
            continue;
        lm_found_point *c = &out[n];
        memset(c, 0, sizeof *c);
        float L[3];
        if (sky)
            lm_sky_radiance(s, dir, L);
        c->worth = sky ? lm_luminance(L) : facing;
        if (!(c->worth > 0.0) || !opening_crossing(rt, org, w, c->pos, c->normal))
            continue;
        lm_found_point_plane(c, plane_step);
        n++;
    }
    return n;
}

/* Whether the point q of a wall's plane (normal n) lies in an opening: a short segment across the plane
 * there meets nothing. */
static int open_at(const lm_rt *rt, lm_vec3 q, lm_vec3 n, float depth)
{
    float o[3], d[3];
    lm_v3_store(o, lm_sub(q, lm_scale(n, depth)));
    lm_v3_store(d, n);
    return !lm_rt_occluded(rt, o, d, 0.0f, 2.0f * depth);
}

/* Whether side `side` (0, 1: low and high along t; 2, 3: along b) of r, moved out to `at`, lies in the
 * opening: its ends (a tenth in) and middle are open. */
static int side_open(const lm_rt *rt, const lm_found_rect *r, int side, double at, float depth)
{
    int a = side / 2, o = 1 - a;
    for (int k = 0; k < 3; k++) {
        double along = r->lo[o] + (r->hi[o] - r->lo[o]) * (0.1 + 0.4 * k), x = a ? along : at, y = a ? at : along;
        if (!open_at(rt, lm_found_rect_point(r, x, y), r->n, depth))
            return 0;
    }
    return 1;
}

/* Each side of r moved out to the opening's edge (steps of `reach` / 32, then halved 8 times) and a little
 * beyond: the crossings found lie inside the opening, and a portal that overlaps the wall only sends a few
 * photons onto the wall's outside. */
static void grow_to_edges(const lm_rt *rt, lm_found_rect *r, double reach, float depth)
{
    for (int side = 0; side < 4; side++) {
        int a = side / 2;
        double dir = side % 2 ? 1.0 : -1.0, from = side % 2 ? r->hi[a] : r->lo[a], step = reach / 32.0, open = 0.0;
        while (open < reach && side_open(rt, r, side, from + dir * (open + step), depth))
            open += step;
        for (double half = step / 2.0; half > step / 512.0; half /= 2.0)
            if (side_open(rt, r, side, from + dir * (open + half), depth))
                open += half;
        double at = from + dir * (open + step / 256.0 + 0.01 * (r->hi[a] - r->lo[a]));
        if (side % 2)
            r->hi[a] = at;
        else
            r->lo[a] = at;
    }
}

static int by_x(const void *x, const void *y)
{
    const double *a = x, *b = y;
    return (a[0] > b[0]) - (a[0] < b[0]);
}

static int by_y(const void *x, const void *y)
{
    const double *a = x, *b = y;
    return (a[1] > b[1]) - (a[1] < b[1]);
}

/* The openings of one wall plane: its crossings (x, y in the plane, worth: 3 doubles each) split where they
 * leave a gap of more than `gap` along t, then along b (two windows of one wall), each part's rectangle
 * grown to the opening's edges. Appends at most cap of them to out; returns how many. */
static uint32_t plane_openings(const lm_rt *rt, const lm_found_rect *plane, double *xyw, uint32_t n, double gap,
                               double reach, float depth, lm_found_rect *out, uint32_t cap)
{
    uint32_t made = 0;
    qsort(xyw, n, 3 * sizeof *xyw, by_x);
    for (uint32_t i = 0, j; i < n; i = j) {
        for (j = i + 1; j < n && xyw[3 * j] - xyw[3 * (j - 1)] <= gap;)
            j++;
        qsort(xyw + 3 * i, j - i, 3 * sizeof *xyw, by_y);
        for (uint32_t a = i, z; a < j && made < cap; a = z) {
            for (z = a + 1; z < j && xyw[3 * z + 1] - xyw[3 * (z - 1) + 1] <= gap;)
                z++;
            lm_found_rect r = *plane;
            r.lo[0] = r.lo[1] = INFINITY, r.hi[0] = r.hi[1] = -INFINITY, r.worth = 0.0;
            for (uint32_t q = a; q < z; q++) {
                r.lo[0] = fmin(r.lo[0], xyw[3 * q]), r.hi[0] = fmax(r.hi[0], xyw[3 * q]);
                r.lo[1] = fmin(r.lo[1], xyw[3 * q + 1]), r.hi[1] = fmax(r.hi[1], xyw[3 * q + 1]);
                r.worth += xyw[3 * q + 2];
            }
            grow_to_edges(rt, &r, fmax(reach, fmax(r.hi[0] - r.lo[0], r.hi[1] - r.lo[1])), depth);
            out[made++] = r;
        }
    }
    return made;
}

uint32_t lm_find_openings(const lm_scene *s, const lm_rt *rt, const lm_look_draw *d, const lm_emitter *e,
                          lm_found_rect *out, uint32_t cap, lm_error *err)
{
    lm_found_point *c = malloc(sizeof *c * (LM_FIND_LOOKS + 1));
    double *xyw = malloc(sizeof *xyw * 3 * (LM_FIND_LOOKS + 1));
    if (!c || !xyw) {
        free(c), free(xyw);
        lm_fail(err, LM_ERR_NOMEM, "portals: no memory to look for openings");
        return UINT32_MAX;
    }
    uint32_t n = crossings(s, rt, d, e, c), k = 0;
    double size = lm_scene_size(s);
    qsort(c, n, sizeof *c, lm_found_point_order);
    for (uint32_t i = 0, j; i < n && k < cap; i = j) { /* each wall plane's crossings in turn */
        for (j = i + 1; j < n && !lm_found_point_order(&c[i], &c[j]);)
            j++;
        lm_found_rect plane;
        memset(&plane, 0, sizeof plane);
        plane.n = lm_normalize(lm_v3_load(c[i].normal));
        lm_tangents(plane.n, &plane.t, &plane.b);
        for (uint32_t q = i; q < j; q++) {
            lm_vec3 pq = lm_v3_load(c[q].pos);
            xyw[3 * (q - i)] = lm_dot(pq, plane.t), xyw[3 * (q - i) + 1] = lm_dot(pq, plane.b);
            xyw[3 * (q - i) + 2] = c[q].worth;
            plane.level += lm_dot(pq, plane.n) / (double)(j - i);
        }
        k += plane_openings(rt, &plane, xyw, j - i, size / 256.0, size / 64.0, (float)(1e-3 * size), out + k, cap - k);
    }
    free(c);
    free(xyw);
    return k;
}
