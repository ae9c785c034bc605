/* The places outside whose reflected light gets in through the openings found (portal_finder.h,
 * portal_looks.h).
 *
 * A sunlit lawn under a window lights the room about as much as the sun's patch on the floor does, through
 * photons that reach the lawn from anywhere on the level: one in a thousand of them bounces in, each
 * carrying a thousand times a portal photon's light, and a room's furniture is then a few such photons'
 * noise. So from each opening found, rays cosine-distributed out of it: each that meets a surface y outside
 * is a place the light should be aimed at, worth the light it lets in (y's albedo times the light at y: a
 * sun's cosine where y sees it; for the sky, its luminance along one cosine-distributed ray from y that
 * leaves the scene; times the opening's area over its rays), in the openings' unit (portal_looks.h). The places
 * are gathered in square cells on their planes, each a rectangle facing the light: cells of a 64th of the
 * level's size by the opening, twice that as far again, and so on (a lawn is seen ever more edge-on
 * through a window the farther it lies, each square metre of it worth less: a portal of the same worth
 * covers more of it). A place is then picked by its worth over the square root of the chance p that light
 * reflected there gets in (chance_in): of the photons aimed at it only p get in, and the noise they make
 * inside, F^2 / (P p) summed over the routes F comes in by, is least for P in proportion to F / sqrt(p)
 * (the openings' p is 1). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../scene/sky.h"
#include "portal_finder.h"
#include "portal_looks.h"

#define CELLS_ACROSS 64.0 /* a cell's side by the opening: the level's size over this */
#define CELL_LEVELS 7     /* and up to 2^6 times that, far from it */
#define ENTER_RAYS 64     /* rays from a place that measure the chance its light gets in */

/* The diffuse albedo of the material at hit h (its base colour's luminance; none for mirror and glass). */
static double albedo(const lm_scene *s, const lm_rt_hit *h)
{
    const lm_material *m = &s->materials[s->tri_material[h->tri]];
    if (lm_material_is_specular(m->cls))
        return 0.0;
    return lm_luminance(m->base_color) * (1.0 - m->metallic);
}

/* The light at y (side n facing where the look came from) per unit of the light's: a sun's cosine where
 * y sees it, the sky's luminance along one cosine-distributed ray from y (u0, u1) that leaves the scene. */
static double light_at(const lm_scene *s, const lm_rt *rt, const lm_emitter *e, lm_vec3 y, lm_vec3 n, float offset,
                       float u0, float u1)
{
    lm_vec3 w = lm_look_direction(e, n, u0, u1);
    float c = lm_dot(n, w), o[3], d[3];
    if (!(c > 0.0f))
        return 0.0;
    lm_v3_store(o, lm_add(y, lm_scale(n, offset)));
    lm_v3_store(d, w);
    if (lm_rt_occluded(rt, o, d, 0.0f, INFINITY))
        return 0.0;
    if (e->kind != LM_EMIT_SKY)
        return c;
    float L[3];
    lm_sky_radiance(s, d, L);
    return lm_luminance(L);
}

/* The places: from each opening, rays cosine-distributed about its face out (a share of LM_FIND_LOOKS each);
 * each that meets a surface y outside is a place whose light, reflected, gets in through the opening, worth
 * y's albedo times the light at y times the opening's area over its rays: an estimate of the flux it lets
 * in (per unit of the light's, over pi for the sky), the unit the openings' worth is in (portal_finder.c).
 * Returns how many. */
static uint32_t places(const lm_scene *s, const lm_rt *rt, const lm_look_draw *d, const lm_emitter *e,
                       const lm_found_rect *open, uint32_t n_open, lm_found_point *out, double *sky_in)
{
    double cell = lm_scene_size(s) / CELLS_ACROSS, plane_step = lm_found_plane_step(s);
    uint32_t n = 0, each = LM_FIND_LOOKS / n_open;
    for (uint32_t k = 0; k < n_open; k++) {
        const lm_found_rect *r = &open[k];
        double area = (r->hi[0] - r->lo[0]) * (r->hi[1] - r->lo[1]);
        lm_vec3 mid = lm_found_rect_point(r, 0.5 * (r->lo[0] + r->hi[0]), 0.5 * (r->lo[1] + r->hi[1]));
        for (uint32_t i = 0; i < each; i++) {
            float u[6], o[3], dir[3];
            lm_look_numbers(1, i, 6, u);
            double x = r->lo[0] + u[0] * (r->hi[0] - r->lo[0]), y0 = r->lo[1] + u[1] * (r->hi[1] - r->lo[1]);
            lm_vec3 at = lm_found_rect_point(r, x, y0);
            lm_vec3 org = lm_add(at, lm_scale(r->n, d->offset)), w = lm_cosine_dir(r->n, u[2], u[3]);
            lm_rt_hit hit;
            lm_v3_store(o, org);
            lm_v3_store(dir, w);
            if (!lm_v3_finite(w))
                continue;
            if (!lm_rt_intersect(rt, o, dir, 0.0f, INFINITY, &hit)) { /* the sky seen through it */
                float L[3];
                lm_sky_radiance(s, dir, L);
                sky_in[k] += e->kind == LM_EMIT_SKY ? lm_luminance(L) * area / each : 0.0;
                continue;
            }
            if (hit.surface < 0)
                continue;
            lm_vec3 ng = lm_v3_load(hit.ng), y = lm_add(org, lm_scale(w, hit.t));
            lm_vec3 lit = lm_dot(ng, w) < 0.0f ? ng : lm_scale(ng, -1.0f), t, b;
            lm_found_point *p = &out[n];
            memset(p, 0, sizeof *p);
            p->worth = albedo(s, &hit) * light_at(s, rt, e, y, lit, d->offset, u[4], u[5]) * area / each;
            if (!(p->worth > 0.0))
                continue;
            lm_v3_store(p->pos, y);
            lm_v3_store(p->normal, lit);
            lm_tangents(lit, &t, &b);
            int level = (int)floor(log2(1.0 + lm_length(lm_sub(y, mid)) / cell));
            double side = cell * (double)(1 << (level < CELL_LEVELS - 1 ? level : CELL_LEVELS - 1));
            lm_found_point_plane(p, plane_step);
            p->key[4] = (int64_t)lround(side / cell);
            p->key[5] = (int64_t)floor(lm_dot(y, t) / side);
            p->key[6] = (int64_t)floor(lm_dot(y, b) / side);
            n++;
        }
    }
    return n;
}

/* The chance that light reflected at the middle of r gets in: the share of ENTER_RAYS rays cosine-distributed
 * about its face that go in through one of the openings before meeting anything; at least half a ray's (a
 * corner of the cell may see in where its middle does not). */
static double chance_in(const lm_rt *rt, const lm_found_rect *r, const lm_found_rect *open, uint32_t n_open,
                        float offset)
{
    lm_vec3 mid = lm_found_rect_point(r, 0.5 * (r->lo[0] + r->hi[0]), 0.5 * (r->lo[1] + r->hi[1]));
    lm_vec3 org = lm_add(mid, lm_scale(r->n, offset));
    int in = 0;
    for (uint32_t i = 0; i < ENTER_RAYS; i++) {
        float u[2], o[3], dir[3];
        lm_look_numbers(2, i, 2, u);
        lm_vec3 w = lm_cosine_dir(r->n, u[0], u[1]);
        lm_rt_hit hit;
        lm_v3_store(o, org);
        lm_v3_store(dir, w);
        float far = lm_rt_intersect(rt, o, dir, 0.0f, INFINITY, &hit) ? hit.t : INFINITY;
        for (uint32_t k = 0; k < n_open; k++)
            if (lm_found_rect_crossed_in(&open[k], org, w, far)) {
                in++;
                break;
            }
    }
    return fmax((double)in, 0.5) / ENTER_RAYS;
}

uint32_t lm_find_bounces(const lm_scene *s, const lm_rt *rt, const lm_look_draw *d, const lm_emitter *e,
                         const lm_found_rect *openings, uint32_t n_openings, lm_found_rect *out, uint32_t cap,
                         double *sky_in, lm_error *err)
{
    if (!n_openings)
        return 0;
    memset(sky_in, 0, sizeof *sky_in * n_openings);
    lm_found_point *p = malloc(sizeof *p * (LM_FIND_LOOKS + 1));
    if (!p) {
        lm_fail(err, LM_ERR_NOMEM, "portals: no memory to look out of the openings");
        return UINT32_MAX;
    }
    uint32_t n = places(s, rt, d, e, openings, n_openings, p, sky_in), k = 0;
    double cell = lm_scene_size(s) / CELLS_ACROSS;
    qsort(p, n, sizeof *p, lm_found_point_order);
    for (uint32_t i = 0, j; i < n && k < cap; i = j) { /* each cell's places in turn: its square on their plane */
        lm_found_rect *r = &out[k++];
        memset(r, 0, sizeof *r);
        r->n = lm_normalize(lm_v3_load(p[i].normal));
        lm_tangents(r->n, &r->t, &r->b);
        for (j = i; j < n && !lm_found_point_order(&p[i], &p[j]); j++) {
            r->worth += p[j].worth;
            r->level += lm_dot(lm_v3_load(p[j].pos), r->n);
        }
        r->level /= (double)(j - i);
        double side = (double)p[i].key[4] * cell;
        for (int a = 0; a < 2; a++) {
            r->lo[a] = (double)p[i].key[5 + a] * side;
            r->hi[a] = r->lo[a] + side;
        }
        r->worth /= sqrt(chance_in(rt, r, openings, n_openings, d->offset));
    }
    free(p);
    return k;
}
