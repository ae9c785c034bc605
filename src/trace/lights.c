/* Light emitters: flux, photon emission and next-event estimation (lights.h).
 *
 * Emission (lm_emitter_emit, u[0], u[1] always pick the direction or its stand-in):
 *   point        uniform direction on the sphere; flux = 4 pi I / count.
 *   spot         cos uniform in [cos outer, 1] (uniform over the outer cone's solid angle 2 pi (1 - cos
 *                outer)); flux = I att(cos) 2 pi (1 - cos outer) / count, so its mean is I x the
 *                attenuation-weighted solid angle.
 *   directional  origin uniform (u[0], u[1]) on the rectangle across the light's direction that covers
 *                the scene's bounds box as the light sees it (the box's corners projected on the plane
 *                across the light: fitted, where the bounding sphere's disk sent a third to a half of
 *                a flat level's sun photons past it), moved back by 1.001 R (R half the bounds'
 *                diagonal) against the light's direction from the bounds' centre: outside the bounding
 *                sphere; flux = E area / count. Where it has a guide (sun_guide.h: a level with open
 *                ground) the origin is drawn from the guide's density instead, flux divided by it.
 *   area         u[2] picks a triangle by its flux (CDF), its leftover the side (double-sided
 *                materials) and then one barycentric coordinate, u[3] the other (uniform on the
 *                triangle); u[0], u[1] a cosine-weighted direction about the emitting side's normal;
 *                flux = flux of the triangle / (its probability x count). The origin is lifted off the
 *                surface by 1e-5 x the scene size.
 * Next-event estimation (lm_emitter_sample_toward): the delta lights are evaluated exactly (weight =
 * I att / d^2, or E for directional); an area emitter gets a point chosen by u[0] (triangle, by flux)
 * and u[1], u[2] (uniform on it), weight = Le cos_l / (d^2 pdf_area). A point or spot light's glTF
 * `range` windows its inverse square (lm_light_range_window); emissive textures are not used. */
#include "lights.h"
#include "portals.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../core/vecmath.h"
#include "../scene/sky.h"

#define LM_SPOT_MIN_WIDTH 1e-3f   /* the extension's max(0.001, cos inner - cos outer) */
#define LM_EMIT_LIFT 1e-5f        /* area photon origins are lifted by this x scene size */


/* ---- spot falloff ---- */

static float spot_width(const lm_light *l)
{
    return fmaxf(LM_SPOT_MIN_WIDTH, cosf(l->inner_cone) - cosf(l->outer_cone));
}

float lm_spot_attenuation(const lm_light *l, float cos_angle)
{
    float t = (cos_angle - cosf(l->outer_cone)) / spot_width(l);
    t = t < 0.0f ? 0.0f : t > 1.0f ? 1.0f : t;
    return t * t;
}

/* 2 pi int_{-1}^{1} att(c) dc = 2 pi [ (up - co)^3 / (3 w^2) + (1 - up) ], up = min(1, co + w). */
float lm_spot_solid_angle(const lm_light *l)
{
    double co = cos((double)l->outer_cone), w = (double)spot_width(l), up = fmin(1.0, co + w);
    double ramp = (up - co) * (up - co) * (up - co) / (3.0 * w * w);
    return (float)(2.0 * LM_PI * (ramp + (1.0 - up)));
}

/* The window KHR_lights_punctual recommends for `range` (its reference implementation's
 * attenuation is clamp(1 - (d / range)^4, 0, 1) / d^2): smooth, 1 near the light, 0 from range on.
 * Range 0 (absent in the file) is no window. */
float lm_light_range_window(const lm_light *l, float dist)
{
    if (!(l->range > 0.0f) || l->type == LM_LIGHT_DIRECTIONAL)
        return 1.0f;
    float r = dist / l->range, r2 = r * r;
    return fminf(fmaxf(1.0f - r2 * r2, 0.0f), 1.0f);
}

float lm_emitter_range_window(const lm_scene *s, const lm_emitter *e, float dist)
{
    return e->kind == LM_EMIT_POINT || e->kind == LM_EMIT_SPOT ? lm_light_range_window(&s->lights[e->light], dist)
                                                               : 1.0f;
}

/* ---- building and placement ---- */

static int count_emissive(const lm_scene *s, const lm_node *n)
{
    int c = 0;
    for (uint32_t t = n->first_tri; t < n->first_tri + n->tri_count; t++)
        c += s->materials[s->tri_material[t]].cls == LM_MAT_EMITTER;
    return c;
}

static lm_status add_area(const lm_scene *s, int node, lm_emitter *e, lm_error *err)
{
    const lm_node *n = &s->nodes[node];
    memset(e, 0, sizeof *e);
    e->kind = LM_EMIT_AREA;
    e->light = -1;
    e->node = node;
    e->tri_count = (uint32_t)count_emissive(s, n);
    e->tris = malloc(e->tri_count * sizeof *e->tris);
    e->cdf = malloc(e->tri_count * sizeof *e->cdf);
    if (!e->tris || !e->cdf)
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for the emissive triangles of node '%s'", s->path, n->name);
    uint32_t k = 0;
    for (uint32_t t = n->first_tri; t < n->first_tri + n->tri_count; t++)
        if (s->materials[s->tri_material[t]].cls == LM_MAT_EMITTER)
            e->tris[k++] = t;
    return LM_OK;
}

static void set_punctual(const lm_scene *s, int light, lm_emitter *e)
{
    memset(e, 0, sizeof *e);
    lm_light_type t = s->lights[light].type;
    e->kind = t == LM_LIGHT_POINT ? LM_EMIT_POINT : t == LM_LIGHT_SPOT ? LM_EMIT_SPOT : LM_EMIT_DIRECTIONAL;
    e->light = light;
    e->node = s->lights[light].node;
    e->punctual = 1;
}

static void set_sky(lm_emitter *e)
{
    memset(e, 0, sizeof *e);
    e->kind = LM_EMIT_SKY;
    e->light = e->node = -1;
}

/* A sun or the sky takes the file's portals, if it has any (each emitter its own copy: a sun aims them
 * along its direction). */
static lm_status tag_portals(const lm_scene *s, lm_emitter *e, lm_error *err)
{
    if (!s->portal_tri_count || !(e->kind == LM_EMIT_DIRECTIONAL || e->kind == LM_EMIT_SKY))
        return LM_OK;
    e->portals = lm_portals_tagged(s->portal_tris, s->portal_tri_count, err);
    return e->portals ? LM_OK : LM_ERR_NOMEM;
}

/* Order: the file's lights, the emissive nodes, then the lights added by edits in the order they came,
 * the order lm_emitters_add_light gives an emitter list built before the edits. */
lm_status lm_emitters_build(const lm_scene *s, lm_emitters *out, lm_error *err)
{
    memset(out, 0, sizeof *out);
    int n = s->light_count + (s->has_sky != 0);
    for (int i = 0; i < s->node_count; i++)
        n += count_emissive(s, &s->nodes[i]) > 0;
    out->e = calloc(n > 0 ? (size_t)n : 1, sizeof *out->e);
    if (!out->e)
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for %d emitters", s->path, n);
    lm_status st = LM_OK;
    for (int i = 0; st == LM_OK && i < s->light_count; i++)
        if (!s->lights[i].added) {
            set_punctual(s, i, &out->e[out->count]);
            st = tag_portals(s, &out->e[out->count++], err);
        }
    for (int i = 0; st == LM_OK && i < s->node_count; i++)
        if (count_emissive(s, &s->nodes[i]) > 0)
            st = add_area(s, i, &out->e[out->count++], err);
    for (int i = 0; st == LM_OK && i < s->light_count; i++)
        if (s->lights[i].added) {
            set_punctual(s, i, &out->e[out->count]);
            st = tag_portals(s, &out->e[out->count++], err);
        }
    if (st == LM_OK && s->has_sky) {
        set_sky(&out->e[out->count]);
        st = tag_portals(s, &out->e[out->count++], err);
    }
    if (st != LM_OK) {
        lm_emitters_free(out);
        return st;
    }
    lm_emitters_update(out, s);
    return LM_OK;
}

/* Room for one more emitter at the end of em: its slot, or NULL when memory ran out. */
static lm_emitter *append(lm_emitters *em)
{
    lm_emitter *e = realloc(em->e, sizeof *e * ((size_t)em->count + 1));
    if (!e)
        return NULL;
    em->e = e;
    return &em->e[em->count++];
}

lm_status lm_emitters_add_sky(lm_emitters *em, const lm_scene *s, lm_error *err)
{
    lm_emitter *e = append(em);
    if (!e)
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for the sky", s->path);
    set_sky(e);
    if (tag_portals(s, e, err) != LM_OK) {
        em->count--;
        return LM_ERR_NOMEM;
    }
    lm_emitters_update(em, s);
    return LM_OK;
}

int lm_emitters_sky(const lm_emitters *em)
{
    for (int i = 0; i < em->count; i++)
        if (em->e[i].kind == LM_EMIT_SKY)
            return i;
    return -1;
}

lm_status lm_emitters_add_light(lm_emitters *em, const lm_scene *s, int light, lm_error *err)
{
    lm_emitter *e = append(em);
    if (!e)
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for light '%s'", s->path, s->lights[light].name);
    set_punctual(s, light, e);
    if (tag_portals(s, e, err) != LM_OK) {
        em->count--;
        return LM_ERR_NOMEM;
    }
    lm_emitters_update(em, s);
    return LM_OK;
}

int lm_emitter_removed(const lm_scene *s, const lm_emitter *e)
{
    return e->light >= 0 && e->light < s->light_count && s->lights[e->light].removed;
}

int lm_emitters_light_count(const lm_emitters *em)
{
    int n = 0;
    for (int i = 0; i < em->count; i++)
        n += em->e[i].punctual;
    return n;
}

void lm_emitters_free(lm_emitters *em)
{
    for (int i = 0; em->e && i < em->count; i++) {
        free(em->e[i].tris);
        free(em->e[i].cdf);
        lm_portals_free(em->e[i].portals);
        lm_sun_guide_free(em->e[i].guide);
    }
    free(em->e);
    memset(em, 0, sizeof *em);
}

/* A directional light's rectangle (lm_emitter.rect): the bounds' 8 corners projected on the plane across
 * the light, their extent there, upstream by 1.001 R; returns its area. */
static float fit_rectangle(lm_emitter *e, const lm_emitters *em, const lm_scene *s)
{
    lm_vec3 axis = lm_normalize(lm_v3_load(e->dir)), t, b, c = lm_v3_load(em->disk_center);
    lm_tangents(axis, &t, &b);
    float lo[2] = {0.0f, 0.0f}, hi[2] = {0.0f, 0.0f};
    for (int k = 0; em->disk_radius > 0.0f && k < 8; k++) {
        lm_vec3 p = lm_v3(k & 1 ? s->bounds_max[0] : s->bounds_min[0], k & 2 ? s->bounds_max[1] : s->bounds_min[1],
                          k & 4 ? s->bounds_max[2] : s->bounds_min[2]);
        lm_vec3 d = lm_sub(p, c);
        float x = lm_dot(d, t), y = lm_dot(d, b);
        lo[0] = fminf(lo[0], x), hi[0] = fmaxf(hi[0], x), lo[1] = fminf(lo[1], y), hi[1] = fmaxf(hi[1], y);
    }
    lm_vec3 corner = lm_add(lm_sub(c, lm_scale(axis, 1.001f * em->disk_radius)),
                            lm_add(lm_scale(t, lo[0]), lm_scale(b, lo[1])));
    lm_v3_store(e->rect[0], corner);
    lm_v3_store(e->rect[1], lm_scale(t, hi[0] - lo[0]));
    lm_v3_store(e->rect[2], lm_scale(b, hi[1] - lo[1]));
    return (hi[0] - lo[0]) * (hi[1] - lo[1]);
}

static void place_punctual(lm_emitter *e, const lm_emitters *em, const lm_scene *s)
{
    const lm_light *l = &s->lights[e->light];
    lm_light_place(s, l, e->pos, e->dir);
    int dark = l->off || l->removed;
    float scale = e->kind == LM_EMIT_POINT ? (float)(4.0 * LM_PI)
                : e->kind == LM_EMIT_SPOT  ? lm_spot_solid_angle(l)
                                           : fit_rectangle(e, em, s);
    if (e->portals)
        lm_portals_aim(e->portals, e->dir);
    for (int c = 0; c < 3; c++) {
        e->radiant[c] = dark ? 0.0f : l->color[c] * l->intensity;
        e->power[c] = e->radiant[c] * scale;
    }
}

/* Radiance L from every direction through a disk of radius R facing it: L pi R^2 per steradian, 4 pi of them
 * (L the sky's mean over the sphere; radiant keeps it). */
static void place_sky(lm_emitter *e, const lm_scene *s, float disk_radius)
{
    if (e->portals)
        lm_portals_aim(e->portals, NULL);
    lm_sky_mean(s, e->radiant);
    for (int c = 0; c < 3; c++)
        e->power[c] = e->radiant[c] * (float)(4.0 * LM_PI * LM_PI) * disk_radius * disk_radius;
}

/* Triangle corners and (unnormalized) geometric normal in world space. */
static lm_vec3 tri_world(const lm_scene *s, uint32_t t, lm_vec3 p[3])
{
    for (int k = 0; k < 3; k++) {
        float q[3];
        lm_scene_vertex_world(s, s->tris[3 * (size_t)t + (size_t)k], q);
        p[k] = lm_v3_load(q);
    }
    return lm_cross(lm_sub(p[1], p[0]), lm_sub(p[2], p[0]));
}

/* Flux of one emissive triangle of world area `area`: pi Le A per emitting side. */
static void tri_flux_of_area(const lm_scene *s, uint32_t t, float area, float out[3])
{
    const lm_material *m = &s->materials[s->tri_material[t]];
    float f = (float)LM_PI * area * (m->double_sided ? 2.0f : 1.0f);
    for (int c = 0; c < 3; c++)
        out[c] = m->emissive[c] * f;
}

static void tri_flux(const lm_scene *s, uint32_t t, float out[3])
{
    tri_flux_of_area(s, t, lm_scene_tri_area_world(s, t), out);
}

static void place_area(lm_emitter *e, const lm_scene *s)
{
    double acc = 0.0, area = 0.0, pw[3] = {0, 0, 0};
    for (uint32_t k = 0; k < e->tri_count; k++) {
        float f[3];
        tri_flux(s, e->tris[k], f);
        for (int c = 0; c < 3; c++)
            pw[c] += f[c];
        area += lm_scene_tri_area_world(s, e->tris[k]);
        acc += lm_luminance(f);
        e->cdf[k] = (float)acc;
    }
    for (uint32_t k = 0; k < e->tri_count; k++) /* normalize; a flux-less emitter picks nothing */
        e->cdf[k] = acc > 0.0 ? (float)(e->cdf[k] / acc) : 0.0f;
    if (e->tri_count && acc > 0.0)
        e->cdf[e->tri_count - 1] = 1.0f;
    e->area = (float)area;
    for (int c = 0; c < 3; c++)
        e->power[c] = (float)pw[c];
}

void lm_emitter_set_portals(lm_emitters *em, int e, lm_portals *p)
{
    lm_portals_free(em->e[e].portals);
    em->e[e].portals = p;
    if (p)
        lm_portals_aim(p, em->e[e].kind == LM_EMIT_DIRECTIONAL ? em->e[e].dir : NULL);
}

void lm_emitter_set_guide(lm_emitters *em, int e, lm_sun_guide *g)
{
    lm_sun_guide_free(em->e[e].guide);
    em->e[e].guide = g;
}

void lm_emitters_update(lm_emitters *em, const lm_scene *s)
{
    lm_vec3 lo = lm_v3_load(s->bounds_min), hi = lm_v3_load(s->bounds_max);
    int empty = !(lo.x <= hi.x && lo.y <= hi.y && lo.z <= hi.z);
    lm_v3_store(em->disk_center, empty ? lm_v3(0, 0, 0) : lm_scale(lm_add(lo, hi), 0.5f));
    em->disk_radius = empty ? 0.0f : 0.5f * lm_length(lm_sub(hi, lo));
    em->total_luminance = 0.0f;
    for (int i = 0; i < em->count; i++) {
        lm_emitter *e = &em->e[i];
        if (e->punctual)
            place_punctual(e, em, s);
        else if (e->kind == LM_EMIT_SKY)
            place_sky(e, s, em->disk_radius);
        else
            place_area(e, s);
        e->luminance = lm_luminance(e->power);
        em->total_luminance += e->luminance;
    }
}

/* ---- sampling helpers ---- */

/* Index of the triangle u falls on in the CDF; *rest = u's position inside that triangle's interval. */
static inline uint32_t pick_tri(const lm_emitter *e, float u, float *rest, float *prob)
{
    uint32_t lo = 0, hi = e->tri_count - 1;
    while (lo < hi) {
        uint32_t mid = (lo + hi) / 2;
        if (e->cdf[mid] > u)
            hi = mid;
        else
            lo = mid + 1;
    }
    float a = lo ? e->cdf[lo - 1] : 0.0f, b = e->cdf[lo];
    *prob = b - a;
    float r = (u - a) / (b - a); /* clamped by comparisons: fminf and fmaxf are calls here */
    *rest = b > a ? (r > 0.0f ? (r < 0.99999994f ? r : 0.99999994f) : 0.0f) : 0.5f;
    return lo;
}

/* Uniform point on the triangle from two numbers: b = (1 - sqrt a, sqrt a (1 - c), sqrt a c). */
static inline lm_vec3 tri_point(const lm_vec3 p[3], float a, float c)
{
    float r = sqrtf(a);
    return lm_add(lm_add(lm_scale(p[0], 1.0f - r), lm_scale(p[1], r * (1.0f - c))), lm_scale(p[2], r * c));
}

/* ---- emission ---- */

static void place_tri(const lm_scene *s, uint32_t t, float lift, lm_emit_tri *out)
{
    /* The area comes from the same cross product as the normal (lm_scene_tri_area_world's formula). */
    lm_vec3 p[3], cr = tri_world(s, t, p);
    for (int k = 0; k < 3; k++)
        lm_v3_store(out->p[k], p[k]);
    lm_vec3 n = lm_normalize(cr), tan, bit;
    lm_onb(n, &tan, &bit);
    lm_v3_store(out->n, n);
    lm_v3_store(out->t, tan);
    lm_v3_store(out->b, bit);
    tri_flux_of_area(s, t, 0.5f * lm_length(cr), out->flux);
    out->lift = lift;
    out->double_sided = s->materials[s->tri_material[t]].double_sided != 0;
}

void lm_emitter_place(const lm_emitters *em, const lm_scene *s, int e, lm_emit_tri *out)
{
    const lm_emitter *em_e = &em->e[e];
    if (em_e->punctual)
        return;
    float lift = LM_EMIT_LIFT * lm_scene_size(s);
    for (uint32_t k = 0; k < em_e->tri_count; k++)
        place_tri(s, em_e->tris[k], lift, &out[k]);
}

static void emit_area(const lm_emitter *e, const lm_emit_tri *placed, const lm_scene *s, const float u[4],
                      uint32_t count, lm_emission *out)
{
    float rest, prob;
    uint32_t k = pick_tri(e, u[2], &rest, &prob);
    lm_emit_tri own; /* placed here unless the caller placed them all (lm_emitter_place) */
    const lm_emit_tri *tri = placed ? &placed[k] : &own;
    if (!placed)
        place_tri(s, e->tris[k], LM_EMIT_LIFT * lm_scene_size(s), &own);
    lm_vec3 p[3] = {lm_v3_load(tri->p[0]), lm_v3_load(tri->p[1]), lm_v3_load(tri->p[2])};
    lm_vec3 n = lm_v3_load(tri->n);
    if (tri->double_sided) { /* leftover picks the side */
        int back = rest >= 0.5f;
        rest = back ? 2.0f * rest - 1.0f : 2.0f * rest;
        n = back ? lm_scale(n, -1.0f) : n; /* (t, b, -n) is a frame as good as (t, b, n) */
    }
    lm_vec3 x = tri_point(p, rest, u[3]);
    float r = sqrtf(u[0]), sn, cs;
    lm_sincos_turn(u[1], &sn, &cs);
    lm_vec3 d = lm_frame_dir(lm_v3_load(tri->t), lm_v3_load(tri->b), n, r * cs, r * sn, sqrtf(1.0f - u[0]));
    lm_v3_store(out->org, lm_add(x, lm_scale(n, tri->lift)));
    lm_v3_store(out->dir, d);
    float w = prob > 0.0f ? 1.0f / (prob * (float)count) : 0.0f;
    for (int c = 0; c < 3; c++)
        out->flux[c] = tri->flux[c] * w;
}

int lm_emitter_area_point(const lm_emitters *em, const lm_scene *s, int e, const lm_emit_tri *tris, const float u[2],
                          float pos[3], float n[3], float weight[3])
{
    const lm_emitter *em_e = &em->e[e];
    if (em_e->punctual || !em_e->tri_count || !(em_e->luminance > 0.0f))
        return 0;
    float rest, prob;
    uint32_t k = pick_tri(em_e, u[0], &rest, &prob);
    lm_emit_tri own;
    const lm_emit_tri *tri = tris ? &tris[k] : &own;
    if (!tris)
        place_tri(s, em_e->tris[k], LM_EMIT_LIFT * lm_scene_size(s), &own);
    lm_vec3 p[3] = {lm_v3_load(tri->p[0]), lm_v3_load(tri->p[1]), lm_v3_load(tri->p[2])}, nn = lm_v3_load(tri->n);
    if (tri->double_sided) {
        int back = rest >= 0.5f;
        rest = back ? 2.0f * rest - 1.0f : 2.0f * rest;
        nn = back ? lm_scale(nn, -1.0f) : nn;
    }
    if (!(prob > 0.0f))
        return 0;
    lm_v3_store(pos, lm_add(tri_point(p, rest, u[1]), lm_scale(nn, tri->lift)));
    lm_v3_store(n, nn);
    /* Le / pdf = Le A sides / prob, and the triangle's flux is pi Le A sides */
    for (int c = 0; c < 3; c++)
        weight[c] = tri->flux[c] / ((float)LM_PI * prob);
    return 1;
}

static void emit_punctual(const lm_scene *s, const lm_emitter *e, const float u[4],
                          uint32_t count, lm_emission *out)
{
    float scale = 1.0f / (float)count, sn, cs;
    lm_sincos_turn(u[1], &sn, &cs);
    lm_vec3 axis = lm_v3_load(e->dir), d, o = lm_v3_load(e->pos);
    if (e->kind == LM_EMIT_POINT) {
        float z = 1.0f - 2.0f * u[0], r = sqrtf(fmaxf(0.0f, 1.0f - z * z));
        d = lm_v3(r * cs, r * sn, z);
        scale *= (float)(4.0 * LM_PI);
    } else if (e->kind == LM_EMIT_SPOT) {
        const lm_light *l = &s->lights[e->light];
        float co = cosf(l->outer_cone), z = 1.0f - u[0] * (1.0f - co), r = sqrtf(fmaxf(0.0f, 1.0f - z * z));
        d = lm_onb_dir(axis, r * cs, r * sn, z);
        scale *= lm_spot_attenuation(l, z) * (float)(2.0 * LM_PI) * (1.0f - co);
    } else { /* the fitted rectangle (fit_rectangle), its area the power's; or through a portal */
        lm_vec3 eu = lm_v3_load(e->rect[1]), ev = lm_v3_load(e->rect[2]), r0 = lm_v3_load(e->rect[0]);
        float area = lm_length(eu) * lm_length(ev), x[3];
        int guided = e->portals && e->portals->usable;
        d = axis;
        o = lm_add(r0, lm_add(lm_scale(eu, u[0]), lm_scale(ev, u[1])));
        if (guided && u[2] < LM_PORTAL_SHARE && lm_portals_sun_point(e->portals, u[0], u[1], x)) {
            lm_vec3 p = lm_v3_load(x); /* moved back along the light onto the rectangle's plane */
            o = lm_sub(p, lm_scale(d, lm_dot(lm_sub(p, r0), d)));
        }
        if (guided) { /* the mixture's density at this line (portals.h) */
            float so[3], ua = lm_dot(lm_sub(o, r0), eu) / lm_dot(eu, eu), va = lm_dot(lm_sub(o, r0), ev) / lm_dot(ev, ev);
            lm_v3_store(so, o);
            double in_rect = ua >= 0.0f && ua <= 1.0f && va >= 0.0f && va <= 1.0f;
            double pdf = (1.0 - LM_PORTAL_SHARE) * in_rect / area +
                         LM_PORTAL_SHARE * lm_portals_density(e->portals, so, e->dir);
            scale *= pdf > 0.0 ? (float)(1.0 / pdf) : 0.0f;
        } else if (e->guide && !memcmp(e->guide->rect, e->rect, sizeof e->rect)) { /* sun_guide.h */
            float g[2] = {u[0], u[1]};
            double density = lm_sun_guide_draw(e->guide, g);
            o = lm_add(r0, lm_add(lm_scale(eu, g[0]), lm_scale(ev, g[1])));
            scale *= (float)(area / density);
        } else {
            scale *= area;
        }
    }
    lm_v3_store(out->org, o);
    lm_v3_store(out->dir, d);
    for (int c = 0; c < 3; c++)
        out->flux[c] = e->radiant[c] * scale;
}

/* A sky photon: its direction of travel uniform on the sphere, or an image sky's drawn by brightness
 * (lm_sky_sample) (u[0], u[1]: similar directions for QMC strata of those two), its origin uniform on the disk
 * (u[2] radius, u[3] angle) of the scene's bounding sphere across that direction, moved back outside the
 * sphere; flux L(-d) / (p(-d) pi R^2 count), L the sky's radiance from where it comes (lm_sky_radiance),
 * p its density per steradian (1 / 4 pi when uniform). With portals (portals.h), u[2] below
 * LM_PORTAL_SHARE draws the line through a portal instead (u[2] rescaled picks it, u[3] the point, u[0],
 * u[1] the direction about its front), u[2] above it the line as before (u[2] rescaled the radius), the
 * origin on the same plane across d either way, and the flux is L(-d) over count times the mixture's
 * density. */
static void emit_sky(const lm_emitter *e, const lm_emitters *em, const lm_scene *s, const float u[4], uint32_t count,
                     lm_emission *out)
{
    const double disk = LM_PI * (double)em->disk_radius * em->disk_radius;
    const int image = lm_sky_by_brightness(s);
    int guided = e->portals && e->portals->usable;
    float u2 = guided ? (u[2] - LM_PORTAL_SHARE) / (1.0f - LM_PORTAL_SHARE) : u[2], x[3], w[3], from[3];
    lm_vec3 c = lm_v3_load(em->disk_center), d, o;
    float back = 1.001f * em->disk_radius, sn, cs;
    if (guided && u[2] < LM_PORTAL_SHARE && lm_portals_sky_line(e->portals, u[2] / LM_PORTAL_SHARE, u[3], u[0], u[1], x, w)) {
        d = lm_scale(lm_v3_load(w), -1.0f); /* onto the uniform lines' plane across d, through x */
        lm_vec3 p = lm_v3_load(x);
        o = lm_sub(p, lm_scale(d, lm_dot(lm_sub(p, c), d) + back));
    } else {
        if (image) {
            lm_sky_sample(s, u[0], u[1], from);
            d = lm_scale(lm_v3_load(from), -1.0f);
        } else {
            float z = 1.0f - 2.0f * u[0], r = sqrtf(fmaxf(0.0f, 1.0f - z * z));
            lm_sincos_turn(u[1], &sn, &cs);
            d = lm_v3(r * cs, r * sn, z);
        }
        float rad = em->disk_radius * sqrtf(fminf(fmaxf(u2, 0.0f), 1.0f));
        lm_sincos_turn(u[3], &sn, &cs);
        o = lm_add(lm_sub(c, lm_scale(d, back)), lm_onb_dir(d, rad * cs, rad * sn, 0.0f));
    }
    lm_v3_store(out->org, o);
    lm_v3_store(out->dir, d);
    lm_v3_store(from, lm_scale(d, -1.0f));
    /* the disk's lines' density at this one (uniform directions: as before, 1 / (4 pi pi R^2)) */
    float L[3];
    double dir_pdf = 0.0;
    if (image)
        lm_sky_radiance_pdf(s, from, L, &dir_pdf);
    else
        lm_sky_radiance(s, from, L);
    double lines = image ? dir_pdf / disk : 1.0 / (4.0 * LM_PI * LM_PI * (double)em->disk_radius * em->disk_radius);
    double pdf = lines;
    if (guided) { /* the mixture's density at this line: the disk's lines' where it crosses their disk */
        lm_vec3 off = lm_sub(lm_sub(o, c), lm_scale(d, lm_dot(lm_sub(o, c), d)));
        double in_disk = lm_dot(off, off) <= em->disk_radius * em->disk_radius * 1.0001f;
        pdf = (1.0 - LM_PORTAL_SHARE) * in_disk * lines +
              LM_PORTAL_SHARE * lm_portals_density(e->portals, out->org, out->dir);
    }
    float scale = pdf > 0.0 ? (float)(1.0 / (pdf * (double)count)) : 0.0f;
    for (int k = 0; k < 3; k++)
        out->flux[k] = L[k] * scale;
}

void lm_emitter_emit_placed(const lm_emitters *em, const lm_scene *s, int e, const lm_emit_tri *tris,
                            const float u[4], uint32_t count, lm_emission *out)
{
    const lm_emitter *em_e = &em->e[e];
    memset(out, 0, sizeof *out);
    if (count == 0)
        return;
    if (em_e->punctual && em_e->luminance > 0.0f) /* a light switched off or removed: no photon */
        emit_punctual(s, em_e, u, count, out);
    else if (em_e->kind == LM_EMIT_SKY && em_e->luminance > 0.0f)
        emit_sky(em_e, em, s, u, count, out);
    else if (em_e->tri_count > 0 && em_e->cdf[em_e->tri_count - 1] > 0.0f)
        emit_area(em_e, tris, s, u, count, out);
}

void lm_emitter_emit(const lm_emitters *em, const lm_scene *s, int e, const float u[4], uint32_t count,
                     lm_emission *out)
{
    lm_emitter_emit_placed(em, s, e, NULL, u, count, out);
}

/* ---- next-event estimation ---- */

int lm_emitted_radiance(const lm_material *m, const float ng[3], const float wo[3], float out[3])
{
    out[0] = out[1] = out[2] = 0.0f;
    if (m->cls != LM_MAT_EMITTER)
        return 0;
    if (!m->double_sided && lm_dot(lm_v3_load(ng), lm_v3_load(wo)) <= 0.0f)
        return 0;
    for (int c = 0; c < 3; c++)
        out[c] = m->emissive[c];
    return out[0] > 0.0f || out[1] > 0.0f || out[2] > 0.0f;
}

static int toward_punctual(const lm_scene *s, const lm_emitter *e, lm_vec3 p, lm_light_sample *out)
{
    if (e->kind == LM_EMIT_DIRECTIONAL) {
        lm_v3_store(out->dir, lm_scale(lm_v3_load(e->dir), -1.0f));
        out->dist = INFINITY;
        memcpy(out->weight, e->radiant, sizeof out->weight);
        return 1;
    }
    lm_vec3 d = lm_sub(lm_v3_load(e->pos), p);
    float d2 = lm_dot(d, d);
    if (!(d2 > 0.0f))
        return 0;
    float dist = sqrtf(d2), att = 1.0f;
    lm_vec3 dir = lm_scale(d, 1.0f / dist);
    if (e->kind == LM_EMIT_SPOT)
        att = lm_spot_attenuation(&s->lights[e->light], -lm_dot(dir, lm_v3_load(e->dir)));
    att *= lm_light_range_window(&s->lights[e->light], dist);
    lm_v3_store(out->dir, dir);
    out->dist = dist;
    for (int c = 0; c < 3; c++)
        out->weight[c] = e->radiant[c] * att / d2; /* E = I att cos / d^2 */
    return att > 0.0f;
}

/* Solid-angle density of picking x (on triangle k of e, normal n unnormalized) from p. */
static float area_pdf(const lm_scene *s, const lm_emitter *e, uint32_t k, lm_vec3 p, lm_vec3 x, lm_vec3 n,
                      float *cos_l)
{
    lm_vec3 d = lm_sub(x, p);
    float d2 = lm_dot(d, d), nl = lm_length(n);
    if (!(d2 > 0.0f) || !(nl > 0.0f))
        return 0.0f;
    float c = -lm_dot(n, d) / (nl * sqrtf(d2)); /* cosine at the light, towards p */
    if (c <= 0.0f && !s->materials[s->tri_material[e->tris[k]]].double_sided)
        return 0.0f;
    *cos_l = fabsf(c);
    float prob = e->cdf[k] - (k ? e->cdf[k - 1] : 0.0f), area = 0.5f * nl;
    if (!(*cos_l > 1e-7f) || !(prob > 0.0f))
        return 0.0f;
    return prob / area * d2 / *cos_l; /* pdf_area d^2 / cos */
}

static int toward_area(const lm_scene *s, const lm_emitter *e, lm_vec3 p, const float u[3], lm_light_sample *out)
{
    if (e->tri_count == 0 || !(e->cdf[e->tri_count - 1] > 0.0f))
        return 0;
    float rest, prob, cos_l = 0.0f;
    uint32_t k = pick_tri(e, u[0], &rest, &prob);
    lm_vec3 c[3], n = tri_world(s, e->tris[k], c);
    lm_vec3 x = tri_point(c, u[1], u[2]);
    float pdf = area_pdf(s, e, k, p, x, n, &cos_l);
    if (!(pdf > 0.0f) || !isfinite(pdf))
        return 0;
    lm_vec3 d = lm_sub(x, p);
    float dist = lm_length(d);
    const float *le = s->materials[s->tri_material[e->tris[k]]].emissive;
    lm_v3_store(out->dir, lm_scale(d, 1.0f / dist));
    out->dist = dist;
    out->pdf = pdf;
    for (int ch = 0; ch < 3; ch++)
        out->weight[ch] = le[ch] / pdf;
    return 1;
}

/* A direction towards an image sky drawn by brightness (lm_sky_sample), for MIS against the rays that
 * leave the scene and meet it (which weigh themselves by lm_sky_radiance_pdf's density). */
static int toward_sky(const lm_scene *s, const float u[3], lm_light_sample *out)
{
    float L[3];
    double pdf;
    lm_sky_sample(s, u[0], u[1], out->dir);
    lm_sky_radiance_pdf(s, out->dir, L, &pdf);
    if (!(pdf > 0.0))
        return 0;
    out->dist = INFINITY;
    out->pdf = (float)pdf;
    for (int c = 0; c < 3; c++)
        out->weight[c] = (float)(L[c] / pdf);
    return L[0] > 0.0f || L[1] > 0.0f || L[2] > 0.0f;
}

int lm_emitter_sample_toward(const lm_emitters *em, const lm_scene *s, int e, const float p[3],
                             const float u[3], lm_light_sample *out)
{
    memset(out, 0, sizeof *out);
    const lm_emitter *em_e = &em->e[e];
    if (em_e->punctual)
        return toward_punctual(s, em_e, lm_v3_load(p), out);
    if (em_e->kind == LM_EMIT_SKY) /* an image sky drawn by brightness; the others found by the rays that
                                    * leave the scene alone */
        return em_e->luminance > 0.0f && lm_sky_by_brightness(s) ? toward_sky(s, u, out) : 0;
    return toward_area(s, em_e, lm_v3_load(p), u, out);
}

float lm_emitter_pdf(const lm_emitters *em, const lm_scene *s, int e, uint32_t tri, const float p[3],
                     const float x[3])
{
    const lm_emitter *em_e = &em->e[e];
    if (em_e->punctual || em_e->tri_count == 0)
        return 0.0f;
    uint32_t lo = 0, hi = em_e->tri_count; /* tris are ascending */
    while (lo < hi) {
        uint32_t mid = (lo + hi) / 2;
        if (em_e->tris[mid] < tri)
            lo = mid + 1;
        else
            hi = mid;
    }
    if (lo >= em_e->tri_count || em_e->tris[lo] != tri)
        return 0.0f;
    lm_vec3 c[3], n = tri_world(s, tri, c);
    float cos_l = 0.0f;
    return area_pdf(s, em_e, lo, lm_v3_load(p), lm_v3_load(x), n, &cos_l);
}
