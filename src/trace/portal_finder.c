/* Portals found where a sun's or the sky's light gets in (portal_finder.h): the looks, and the portals made
 * of the openings and the places outside that they find. */
#include "portal_finder.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../core/log.h"
#include "../core/qmc.h"
#include "../core/stats.h"
#include "portal_looks.h"

int lm_portals_guide(const lm_emitter *e) { return e->kind == LM_EMIT_DIRECTIONAL || e->kind == LM_EMIT_SKY; }

lm_status lm_look_draw_init(lm_look_draw *d, const lm_scene *s, const lm_surfaces *su, lm_error *err)
{
    memset(d, 0, sizeof *d);
    uint32_t total = 0;
    for (int k = 0; k < su->surface_count; k++)
        total += su->surfaces[k].tri_count;
    d->tri = malloc(sizeof *d->tri * ((size_t)total + 1));
    d->cdf = malloc(sizeof *d->cdf * ((size_t)total + 1));
    if (!d->tri || !d->cdf) {
        lm_look_draw_free(d);
        return lm_fail(err, LM_ERR_NOMEM, "portals: no memory for %u triangles", total);
    }
    double acc = 0.0;
    for (int k = 0; k < su->surface_count; k++)
        for (uint32_t i = 0; i < su->surfaces[k].tri_count; i++) {
            uint32_t t = su->surfaces[k].tris[i];
            double a = lm_scene_tri_area_world(s, t);
            if (!(a > 0.0))
                continue;
            acc += a;
            d->tri[d->count] = t;
            d->cdf[d->count++] = acc;
        }
    for (uint32_t i = 0; i < d->count; i++)
        d->cdf[i] /= acc;
    d->area = acc;
    float size = lm_scene_size(s);
    d->offset = 1e-5f * (size > 0.0f ? size : 1.0f);
    lm_qmc_init(); /* the tables lm_look_numbers reads */
    lm_rt_thread_init();
    return LM_OK;
}

void lm_look_draw_free(lm_look_draw *d)
{
    free(d->tri);
    free(d->cdf);
    memset(d, 0, sizeof *d);
}

void lm_look_point(const lm_look_draw *d, const lm_scene *s, const float u[3], lm_vec3 *x, lm_vec3 *front,
                   lm_vec3 *org)
{
    uint32_t lo = lm_cdf_draw(d->cdf, d->count, u[0]);
    float c[3][3];
    for (int k = 0; k < 3; k++)
        lm_scene_vertex_world(s, s->tris[3 * (size_t)d->tri[lo] + (size_t)k], c[k]);
    lm_vec3 p0 = lm_v3_load(c[0]), e1 = lm_sub(lm_v3_load(c[1]), p0), e2 = lm_sub(lm_v3_load(c[2]), p0);
    float r = sqrtf(u[1]);
    *front = lm_normalize(lm_cross(e1, e2));
    *x = lm_add(p0, lm_add(lm_scale(e1, r * (1.0f - u[2])), lm_scale(e2, r * u[2])));
    *org = lm_add(*x, lm_scale(*front, d->offset));
}

void lm_look_numbers(uint32_t stretch, uint32_t index, int n, float *u)
{
    for (int k = 0; k < n; k++)
        u[k] = lm_halton_float((uint32_t)k, stretch * LM_FIND_LOOKS + index + 1);
}

lm_vec3 lm_look_direction(const lm_emitter *e, lm_vec3 front, float u0, float u1)
{
    if (e->kind != LM_EMIT_SKY)
        return lm_scale(lm_normalize(lm_v3_load(e->dir)), -1.0f);
    return lm_cosine_dir(front, u0, u1);
}

double lm_found_plane_step(const lm_scene *s) { return lm_scene_size(s) / 4096.0; }

void lm_found_point_plane(lm_found_point *p, double step)
{
    for (int k = 0; k < 3; k++)
        p->key[k] = (int64_t)lround(100.0 * p->normal[k]);
    p->key[3] = (int64_t)floor(lm_dot(lm_v3_load(p->pos), lm_v3_load(p->normal)) / step);
}

int lm_found_point_order(const void *x, const void *y)
{
    const lm_found_point *a = x, *b = y;
    for (int k = 0; k < 7; k++)
        if (a->key[k] != b->key[k])
            return a->key[k] < b->key[k] ? -1 : 1;
    return 0;
}

lm_vec3 lm_found_rect_point(const lm_found_rect *r, double x, double y)
{
    return lm_add(lm_add(lm_scale(r->t, (float)x), lm_scale(r->b, (float)y)), lm_scale(r->n, (float)r->level));
}

/* Whether the ray org + s w, 0 < s < far, crosses r going along (out > 0) or against its normal. */
static int crosses(const lm_found_rect *r, lm_vec3 org, lm_vec3 w, float far, int out)
{
    double across = lm_dot(w, r->n);
    if (!(out ? across > 0.0 : across < 0.0))
        return 0;
    double s = (r->level - lm_dot(org, r->n)) / across;
    if (!(s > 0.0 && s < far))
        return 0;
    lm_vec3 q = lm_add(org, lm_scale(w, (float)s));
    double x = lm_dot(q, r->t), y = lm_dot(q, r->b);
    return x >= r->lo[0] && x <= r->hi[0] && y >= r->lo[1] && y <= r->hi[1];
}

int lm_found_rect_crossed_out(const lm_found_rect *r, lm_vec3 org, lm_vec3 w, float far)
{
    return crosses(r, org, w, far, 1);
}

int lm_found_rect_crossed_in(const lm_found_rect *r, lm_vec3 org, lm_vec3 w, float far)
{
    return crosses(r, org, w, far, 0);
}


/* The LM_FOUND_PORTALS rectangles of r[0 .. n) worth most, first in r. Returns how many. */
static uint32_t worthiest(lm_found_rect *r, uint32_t n)
{
    uint32_t keep = 0;
    for (; keep < n && keep < LM_FOUND_PORTALS; keep++) {
        uint32_t best = keep;
        for (uint32_t q = keep + 1; q < n; q++)
            best = r[q].worth > r[best].worth ? q : best;
        lm_found_rect f = r[best];
        r[best] = r[keep], r[keep] = f;
    }
    return keep;
}

/* Tagged triangle i's corners and unit front normal; returns its area. */
static double tagged_tri(const lm_scene *s, uint32_t i, lm_vec3 c[3], lm_vec3 *n)
{
    for (int k = 0; k < 3; k++)
        c[k] = lm_v3_load(s->portal_tris + 9 * (size_t)i + 3 * (size_t)k);
    lm_vec3 cr = lm_cross(lm_sub(c[1], c[0]), lm_sub(c[2], c[0]));
    *n = lm_normalize(cr);
    return 0.5 * lm_length(cr);
}

/* Which of the rectangles r[0 .. n) lies in the plane of tagged triangle i (corner c0, unit normal nn): the
 * first facing its way within a plane step (lm_found_plane_step) of it; n when none does. */
static uint32_t tagged_plane(const lm_scene *s, const lm_found_rect *r, uint32_t n, lm_vec3 c0, lm_vec3 nn)
{
    double step = lm_found_plane_step(s);
    uint32_t k = 0;
    while (k < n && !(lm_dot(r[k].n, nn) > 0.9999f && fabs(lm_dot(c0, nn) - r[k].level) < step))
        k++;
    return k;
}

/* The light tagged triangle i lets in, per unit of the light's: a sun's, its area (its cosine comes with
 * the aim, portals.h); the sky's, what its plane's rectangle (tagged_openings) lets in (lm_find_bounces'
 * sky_in, the sky it sees from where it is), its share by area. */
static double tagged_worth(const lm_scene *s, const lm_emitter *e, uint32_t i, const lm_found_rect *r,
                           const double *sky_in, uint32_t n_open)
{
    lm_vec3 c[3], n;
    double area = tagged_tri(s, i, c, &n);
    if (e->kind != LM_EMIT_SKY)
        return area;
    uint32_t k = tagged_plane(s, r, n_open, c[0], n);
    return k < n_open ? sky_in[k] * area / r[k].worth : 0.0;
}

/* The file's portals as openings for the places to be looked for through: the rectangle round the
 * triangles of each plane (a window's two), facing their fronts, worth their area. Returns how many. */
static uint32_t tagged_openings(const lm_scene *s, lm_found_rect *out)
{
    uint32_t n = 0;
    for (uint32_t i = 0; i < s->portal_tri_count; i++) {
        lm_vec3 c[3], nn;
        double area = tagged_tri(s, i, c, &nn);
        uint32_t k = tagged_plane(s, out, n, c[0], nn); /* the rectangle of its plane so far, or a new one */
        lm_found_rect *r = &out[k];
        if (k == n) {
            memset(r, 0, sizeof *r);
            r->n = nn;
            lm_tangents(nn, &r->t, &r->b);
            r->level = lm_dot(c[0], nn);
            r->lo[0] = r->lo[1] = INFINITY, r->hi[0] = r->hi[1] = -INFINITY;
            n++;
        }
        for (int v = 0; v < 3; v++) {
            double x = lm_dot(c[v], r->t), y = lm_dot(c[v], r->b);
            r->lo[0] = fmin(r->lo[0], x), r->hi[0] = fmax(r->hi[0], x);
            r->lo[1] = fmin(r->lo[1], y), r->hi[1] = fmax(r->hi[1], y);
        }
        r->worth += area; /* for now: tagged_worth shares its plane's light by it */
    }
    return n;
}

/* The portals: the file's triangles (tagged) and the worthiest places r[n_open .. n), or the worthiest of
 * the openings found r[0 .. n_open) and the places together; a rectangle two triangles; each picked by its
 * worth. */
static lm_portals *portals_of(const lm_scene *s, const lm_emitter *e, lm_found_rect *r, uint32_t n_open, uint32_t n,
                              int tagged, const double *sky_in, lm_error *err)
{
    for (uint32_t i = 0; i < n; i++)
        r[i].opening = i < n_open;
    uint32_t kept = tagged ? worthiest(r + n_open, n - n_open) : worthiest(r, n);
    uint32_t count = (tagged ? s->portal_tri_count : 0) + 2 * kept;
    float *tris = malloc(sizeof *tris * 9 * ((size_t)count + 1));
    double *weight = malloc(sizeof *weight * ((size_t)count + 1));
    unsigned char *flag = calloc((size_t)count + 1, 1), *opening = calloc((size_t)count + 1, 1);
    lm_portals *p = NULL;
    if (tris && weight && flag && opening) {
        uint32_t t = 0;
        for (uint32_t i = 0; tagged && i < s->portal_tri_count; i++, t++) {
            memcpy(tris + 9 * t, s->portal_tris + 9 * (size_t)i, sizeof *tris * 9);
            weight[t] = tagged_worth(s, e, i, r, sky_in, n_open);
            flag[t] = opening[t] = 1;
        }
        for (uint32_t i = tagged ? n_open : 0; i < (tagged ? n_open : 0) + kept; i++) {
            const lm_found_rect *f = &r[i];
            lm_vec3 v[4] = {lm_found_rect_point(f, f->lo[0], f->lo[1]), lm_found_rect_point(f, f->hi[0], f->lo[1]),
                            lm_found_rect_point(f, f->hi[0], f->hi[1]), lm_found_rect_point(f, f->lo[0], f->hi[1])};
            static const int order[6] = {0, 1, 2, 0, 2, 3}; /* t x b = n: facing the light */
            for (int q = 0; q < 6; q++)
                lm_v3_store(tris + 9 * t + 3 * q, v[order[q]]);
            weight[t] = weight[t + 1] = 0.5 * f->worth;
            opening[t] = opening[t + 1] = (unsigned char)f->opening;
            t += 2;
        }
        p = lm_portals_make(tris, weight, flag, opening, t, err);
    } else {
        lm_fail(err, LM_ERR_NOMEM, "portals: no memory for %u triangles", count);
    }
    free(tris);
    free(weight);
    free(flag);
    free(opening);
    return p;
}

static const char *emitter_name(const lm_scene *s, const lm_emitter *e)
{
    return e->kind == LM_EMIT_SKY ? "the sky" : s->lights[e->light].name;
}

lm_status lm_portals_find(const lm_scene *s, const lm_surfaces *su, const lm_rt *rt, const lm_emitter *e,
                          lm_portals **out, lm_error *err)
{
    *out = NULL;
    if (!lm_portals_guide(e))
        return LM_OK;
    int tagged = s->portal_tri_count > 0;
    if (!(e->luminance > 0.0f)) /* a dark light: its photons carry nothing, aimed or not */
        return tagged && !(*out = lm_portals_tagged(s->portal_tris, s->portal_tri_count, err)) ? LM_ERR_NOMEM : LM_OK;
    uint32_t cap = 4 * LM_FOUND_PORTALS + s->portal_tri_count;
    lm_look_draw d;
    lm_status st = lm_look_draw_init(&d, s, su, err);
    lm_found_rect *r = st == LM_OK ? malloc(sizeof *r * 2 * cap) : NULL;
    if (st == LM_OK && !r)
        st = lm_fail(err, LM_ERR_NOMEM, "portals: no memory for openings");
    uint32_t open = st != LM_OK ? 0 : tagged ? tagged_openings(s, r) : lm_find_openings(s, rt, &d, e, r, cap, err);
    uint32_t places = 0;
    double *sky_in = st == LM_OK ? calloc((size_t)cap + 1, sizeof *sky_in) : NULL;
    if (st == LM_OK && !sky_in)
        st = lm_fail(err, LM_ERR_NOMEM, "portals: no memory for openings");
    if (open == UINT32_MAX)
        st = LM_ERR_NOMEM;
    for (uint32_t k = 0; st == LM_OK && !tagged && k < open; k++) /* a look stands for its share of the area */
        r[k].worth *= d.area / LM_FIND_LOOKS;
    if (st == LM_OK && open > 0)
        places = lm_find_bounces(s, rt, &d, e, r, open, r + open, cap, sky_in, err);
    if (places == UINT32_MAX)
        st = LM_ERR_NOMEM;
    if (st == LM_OK && open > 0)
        st = (*out = portals_of(s, e, r, open, open + places, tagged, sky_in, err)) ? LM_OK : LM_ERR_NOMEM;
    if (*out)
        lm_info("photons: %s gets in through %u %s; %u places outside light them too (%u portal triangles)",
                emitter_name(s, e), open, tagged ? "planes of portals tagged in the file" : "openings found", places,
                (*out)->count);
    free(r);
    free(sky_in);
    lm_look_draw_free(&d);
    return st;
}

int lm_portals_same(const lm_portals *a, const lm_portals *b)
{
    if (!a || !b)
        return a == b;
    return a->count == b->count && !memcmp(a->tagged, b->tagged, a->count) &&
           !memcmp(a->opening, b->opening, a->count) && !memcmp(a->tris, b->tris, sizeof *a->tris * 9 * a->count) &&
           !memcmp(a->weight, b->weight, sizeof *a->weight * a->count);
}
