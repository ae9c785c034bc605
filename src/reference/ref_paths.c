/* Path-traced samples for the reference solver (ref_paths.h, reference.h).
 *
 * A path carries throughput beta. At each hit: emitted radiance Le (MIS-weighted against the light
 * sample the previous vertex took, unless that vertex was specular or the camera); at a non-specular
 * vertex, next-event estimation to every emitter (area lights MIS-weighted, power heuristic); then a
 * BSDF sample, beta *= f cos / pdf; Russian roulette from rr_depth on, beta /= survival.
 *
 * Each contribution goes to the part the path's route so far says (docs/reference.md, "Which part
 * carries which light"); the route only sorts, it draws no numbers, so the paths and their sum are
 * those of the solver before the split. Emission met after a chain of only specular vertices from the
 * receiver is dropped: the light tracer's caustic part carries it, for every kind of emitter alike (the
 * sky's, which the light tracer does not emit, is then left out of both). A ray that leaves the scene
 * meets the sky (lm_scene.sky). */
#include "ref_paths.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../core/log.h"
#include "../core/vecmath.h"
#include "../scene/sky.h"
#include "../trace/bsdf.h"
#include "../trace/shading.h"

#define LM_REF_EPS_REL 1e-5f /* ray offsets, relative to the scene size */

/* ---- random numbers ---- */

static uint64_t mix64(uint64_t z)
{
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

void lm_ref_rng_seed(lm_ref_rng *r, uint32_t seed, uint64_t entry, uint64_t sample)
{
    r->state = mix64(mix64(mix64((uint64_t)seed + 0x9e3779b97f4a7c15ull) ^ entry) ^ (sample * 0x632be59bd9b4e019ull));
}

float lm_ref_rng_float(lm_ref_rng *r)
{
    r->state += 0x9e3779b97f4a7c15ull; /* splitmix64 */
    return (float)(mix64(r->state) >> 40) * (1.0f / 16777216.0f);
}

/* ---- context ---- */

/* A surface that reflects all the light it gets (an untextured albedo of 1 in some channel): paths off
 * it end only by roulette at 0.999 a bounce, and where nothing else absorbs or lets light out, the true
 * answer is infinite; neither lmgi nor the reference then converges (docs/reference.md). */
static void warn_lossless(const lm_scene *s)
{
    for (int i = 0; i < s->material_count; i++) {
        const lm_material *m = &s->materials[i];
        const float *a = m->base_color;
        if (m->base_color_tex < 0 && !lm_material_is_specular(m->cls) && fmaxf(a[0], fmaxf(a[1], a[2])) >= 1.0f) {
            lm_warn("reference: material '%s' reflects all the light it receives (albedo %.3g %.3g %.3g): if light "
                    "cannot leave the scene, it never dies out and no estimate converges; real surfaces reflect at "
                    "most about 0.95", m->name, (double)a[0], (double)a[1], (double)a[2]);
            return;
        }
    }
}

lm_status lm_ref_ctx_init(lm_ref_ctx *c, const lm_scene *s, const lm_rt *rt, const lm_emitters *em,
                          const lm_ref_settings *set, lm_error *err)
{
    memset(c, 0, sizeof *c);
    c->s = s, c->rt = rt, c->em = em;
    c->max_depth = set->max_depth > 0 ? set->max_depth : LM_REF_MAX_DEPTH;
    c->rr_depth = set->rr_depth >= 0 ? set->rr_depth : 3;
    float size = lm_scene_size(s);
    c->eps = LM_REF_EPS_REL * (size > 0.0f ? size : 1.0f);
    c->tri_emitter = malloc((s->tri_count ? s->tri_count : 1) * sizeof *c->tri_emitter);
    if (!c->tri_emitter)
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for the reference solver", s->path);
    for (uint32_t t = 0; t < s->tri_count; t++)
        c->tri_emitter[t] = -1;
    for (int e = 0; e < em->count; e++)
        for (uint32_t k = 0; k < em->e[e].tri_count; k++)
            c->tri_emitter[em->e[e].tris[k]] = e;
    warn_lossless(s);
    return LM_OK;
}

void lm_ref_ctx_free(lm_ref_ctx *c)
{
    free(c->tri_emitter);
    c->tri_emitter = NULL;
}

/* ---- helpers ---- */

static float power_heuristic(float a, float b) { return a * a / (a * a + b * b); }

static lm_vec3 cosine_dir(lm_vec3 n, float u0, float u1)
{
    float r = sqrtf(u0), phi = 2.0f * LM_PI_F * u1;
    return lm_normalize(lm_onb_dir(n, r * cosf(phi), r * sinf(phi), sqrtf(1.0f - u0)));
}

/* Origin for a ray leaving a surface point towards d: lifted along ng to d's side. */
static lm_vec3 lift(const lm_ref_ctx *c, lm_vec3 p, lm_vec3 ng, lm_vec3 d)
{
    return lm_add(p, lm_scale(ng, lm_dot(ng, d) >= 0.0f ? c->eps : -c->eps));
}

static int visible(const lm_ref_ctx *c, lm_vec3 org, const lm_light_sample *ls)
{
    float o[3];
    lm_v3_store(o, org);
    float far = isinf(ls->dist) ? INFINITY : ls->dist - 2.0f * c->eps;
    if (!(far > 0.0f))
        return 0;
    return !lm_rt_occluded(c->rt, o, ls->dir, 0.0f, far);
}

static void add_scaled(float acc[3], const float a[3], const float b[3], float s)
{
    for (int k = 0; k < 3; k++)
        acc[k] += a[k] * b[k] * s;
}

/* Light-sample density that emitter hit (tri at x) had from o, for MIS. */
static float light_pdf(const lm_ref_ctx *c, uint32_t tri, lm_vec3 o, lm_vec3 x)
{
    int e = c->tri_emitter[tri];
    if (e < 0)
        return 0.0f;
    float of[3], xf[3];
    lm_v3_store(of, o);
    lm_v3_store(xf, x);
    return lm_emitter_pdf(c->em, c->s, e, tri, of, xf);
}

/* NEE at a surface vertex: sum over emitters of f cos x Le / pdf, MIS-weighted for area lights, into
 * `all` (in emitter order, as the sum of every part) and split into `punct` and `area`. */
static void direct_at_vertex(const lm_ref_ctx *c, const lm_shading *sh, const float wi[3], lm_ref_rng *r,
                             float all[3], float punct[3], float area[3])
{
    lm_vec3 p = lm_v3_load(sh->pos), ng = lm_v3_load(sh->ng);
    for (int e = 0; e < c->em->count; e++) {
        float u[3] = {lm_ref_rng_float(r), lm_ref_rng_float(r), lm_ref_rng_float(r)}, f[3];
        lm_light_sample ls;
        if (!lm_emitter_sample_toward(c->em, c->s, e, sh->pos, u, &ls))
            continue;
        lm_bsdf_eval(sh, wi, ls.dir, f);
        if (f[0] <= 0.0f && f[1] <= 0.0f && f[2] <= 0.0f)
            continue;
        if (!visible(c, lift(c, p, ng, lm_v3_load(ls.dir)), &ls))
            continue;
        float w = ls.pdf > 0.0f ? power_heuristic(ls.pdf, lm_bsdf_pdf(sh, wi, ls.dir)) : 1.0f;
        add_scaled(all, f, ls.weight, w);
        add_scaled(c->em->e[e].punctual ? punct : area, f, ls.weight, w);
    }
}

/* ---- routes: which part a contribution belongs to ---- */

typedef enum {
    ROUTE_EYE,        /* a camera ray before its first hit */
    ROUTE_RECEIVER,   /* at the receiver (a pixel's first hit, not specular) */
    ROUTE_LEFT,       /* just left the receiver: the next hit decides */
    ROUTE_CHAIN,      /* only mirror and glass since the receiver */
    ROUTE_SETTLED     /* everything from here on goes to one part */
} route_state;

typedef struct {
    route_state state;
    int part;         /* ROUTE_SETTLED: the part */
} route;

#define DROPPED (-1)  /* emission the caustic part carries */

static int settle(route *rt, int part)
{
    rt->state = ROUTE_SETTLED;
    rt->part = part;
    return part;
}

/* Moves the route past a hit (specular or not); returns the part the hit's emission belongs to. */
static int route_hit(route *rt, int specular)
{
    switch (rt->state) {
    case ROUTE_EYE:
        if (specular)
            return settle(rt, LM_REF_REFLECTIONS);
        rt->state = ROUTE_RECEIVER;
        return LM_REF_EMISSION;
    case ROUTE_LEFT:
        if (specular) {
            rt->state = ROUTE_CHAIN;
            return DROPPED;
        }
        return settle(rt, LM_REF_INDIRECT);
    case ROUTE_CHAIN: /* an emitter at the chain's end is a caustic; what gathers past it is lost */
        if (!specular)
            settle(rt, LM_REF_LOST);
        return DROPPED;
    case ROUTE_RECEIVER: /* the bounce leaves it: never met at a hit */
    case ROUTE_SETTLED:
        break;
    }
    return rt->part;
}

/* What one path gathers: every kept contribution in path order, and the same by part. */
typedef struct {
    float total[3];
    float part[LM_REF_BACKWARD_PARTS][3];
    int cut;
} tally;

static void tally_add(tally *t, int part, const float beta[3], const float v[3], float w)
{
    add_scaled(t->total, beta, v, w);
    add_scaled(t->part[part], beta, v, w);
}

/* NEE at a non-specular vertex: at the receiver the punctual lights are the direct part and emissive
 * surfaces the indirect one; elsewhere all of it goes to the route's part. */
static void tally_direct(const lm_ref_ctx *c, const route *rt, const lm_shading *sh, const float wi[3], lm_ref_rng *r,
                         const float beta[3], tally *t)
{
    float all[3] = {0, 0, 0}, punct[3] = {0, 0, 0}, area[3] = {0, 0, 0};
    direct_at_vertex(c, sh, wi, r, all, punct, area);
    add_scaled(t->total, beta, all, 1.0f);
    if (rt->state != ROUTE_RECEIVER) {
        add_scaled(t->part[rt->part], beta, all, 1.0f);
        return;
    }
    add_scaled(t->part[LM_REF_DIRECT], beta, punct, 1.0f);
    add_scaled(t->part[LM_REF_INDIRECT], beta, area, 1.0f);
}

/* ---- paths ---- */

/* Radiance arriving at org from direction dir, tallied by part from route state `from` (ROUTE_EYE for a
 * camera ray, ROUTE_LEFT for a ray leaving a texel). prev_pdf: solid-angle density dir was sampled with
 * at a vertex that also took light samples (0: camera or specular, no MIS). */
static void trace(const lm_ref_ctx *c, lm_ref_rng *r, lm_vec3 org, lm_vec3 dir, float prev_pdf, route_state from,
                  tally *out)
{
    float beta[3] = {1, 1, 1};
    route rt = {from, LM_REF_INDIRECT};
    memset(out, 0, sizeof *out);
    for (int depth = 0; depth < c->max_depth; depth++) {
        lm_rt_hit hit;
        float of[3], df[3];
        lm_v3_store(of, org);
        lm_v3_store(df, dir);
        if (!lm_rt_intersect(c->rt, of, df, 0.0f, INFINITY, &hit)) {
            /* the sky where the ray leaves: met like an emitter, weighed against its light samples where
             * an image sky is drawn by brightness (lm_emitter_sample_toward) and the vertex took them;
             * seen from the receiver it is the IIM's part, from the eye the background's */
            int part = route_hit(&rt, 0);
            float sky[3], w = 1.0f;
            double pl;
            lm_sky_radiance_pdf(c->s, df, sky, &pl);
            if (prev_pdf > 0.0f && lm_sky_by_brightness(c->s))
                w = power_heuristic(prev_pdf, (float)pl);
            if (part != DROPPED && c->s->has_sky)
                tally_add(out, part, beta, sky, w);
            return;
        }
        lm_shading sh;
        lm_shading_from_hit(c->s, &hit, of, df, &sh);
        int specular = lm_material_is_specular(sh.material->cls), part = route_hit(&rt, specular);
        float wo_back[3] = {-df[0], -df[1], -df[2]}, le[3];
        if (part != DROPPED && lm_emitted_radiance(sh.material, sh.ng, wo_back, le)) {
            float pl = prev_pdf > 0.0f ? light_pdf(c, sh.tri, org, lm_v3_load(sh.pos)) : 0.0f;
            tally_add(out, part, beta, le, prev_pdf > 0.0f ? power_heuristic(prev_pdf, pl) : 1.0f);
        }
        if (!specular)
            tally_direct(c, &rt, &sh, df, r, beta, out);
        if (rt.state == ROUTE_RECEIVER)
            rt.state = ROUTE_LEFT;
        float u[3] = {lm_ref_rng_float(r), lm_ref_rng_float(r), lm_ref_rng_float(r)};
        lm_bsdf_sample_t bs;
        if (!lm_bsdf_sample(&sh, df, u, &bs))
            return;
        prev_pdf = bs.specular ? 0.0f : lm_bsdf_pdf(&sh, df, bs.wo);
        for (int k = 0; k < 3; k++)
            beta[k] *= bs.weight[k];
        if (depth + 1 >= c->rr_depth) {
            float q = lm_bsdf_survival(&sh);
            if (q >= 1.0f && depth + 1 >= LM_REF_SPECULAR_RR_DEPTH) { /* a mirror box: by throughput */
                float m = fmaxf(beta[0], fmaxf(beta[1], beta[2]));
                q = m < 0.05f ? 0.05f : m > 0.999f ? 0.999f : m;
            }
            if (lm_ref_rng_float(r) >= q)
                return;
            for (int k = 0; k < 3; k++)
                beta[k] /= q;
        }
        dir = lm_v3_load(bs.wo);
        org = lift(c, lm_v3_load(sh.pos), lm_v3_load(sh.ng), dir);
    }
    out->cut = 1; /* still going at max_depth: the rest of its light is missing */
}

/* ---- texels ---- */

void lm_ref_texel_frame(const lm_ref_ctx *c, const lm_texel *t, lm_ref_frame *f)
{
    const lm_scene *s = c->s;
    const uint32_t *idx = s->tris + 3 * (size_t)t->tri;
    lm_vec3 p[3];
    float uv[2] = {0, 0};
    const lm_material *m = &s->materials[s->tri_material[t->tri]];
    const float *uvs = m->base_color_uv == 1 && s->uv1 ? s->uv1 : s->uv0;
    for (int k = 0; k < 3; k++) {
        float q[3];
        lm_scene_vertex_world(s, idx[k], q);
        p[k] = lm_v3_load(q);
        uv[0] += t->bary[k] * uvs[2 * (size_t)idx[k]];
        uv[1] += t->bary[k] * uvs[2 * (size_t)idx[k] + 1];
    }
    lm_vec3 n = lm_normalize(lm_v3_load(t->normal));
    lm_vec3 ng = lm_normalize(lm_cross(lm_sub(p[1], p[0]), lm_sub(p[2], p[0])));
    if (lm_dot(ng, n) < 0.0f)
        ng = lm_scale(ng, -1.0f);
    if (!(lm_dot(n, n) > 0.5f))
        n = ng;
    lm_v3_store(f->n, n);
    lm_v3_store(f->ng, ng);
    lm_v3_store(f->org, lm_add(lm_v3_load(t->pos), lm_scale(ng, c->eps)));
    lm_material_albedo(s, m, uv[0], uv[1], f->albedo);
}

/* Direct light at the texel: punctual lights into `punct`, emissive surfaces (MIS with the cosine
 * lobe, pdf cos / pi) into `area`. */
static void texel_direct(const lm_ref_ctx *c, const lm_ref_frame *f, lm_ref_rng *r, float punct[3], float area[3])
{
    lm_vec3 n = lm_v3_load(f->n), ng = lm_v3_load(f->ng), o = lm_v3_load(f->org);
    for (int e = 0; e < c->em->count; e++) {
        float u[3] = {lm_ref_rng_float(r), lm_ref_rng_float(r), lm_ref_rng_float(r)};
        lm_light_sample ls;
        if (!lm_emitter_sample_toward(c->em, c->s, e, f->org, u, &ls))
            continue;
        lm_vec3 d = lm_v3_load(ls.dir);
        float cos = lm_dot(n, d);
        if (cos <= 0.0f || lm_dot(ng, d) <= 0.0f || !visible(c, o, &ls))
            continue;
        float *acc = c->em->e[e].punctual ? punct : area;
        float w = ls.pdf > 0.0f ? power_heuristic(ls.pdf, cos / LM_PI_F) : 1.0f;
        for (int k = 0; k < 3; k++)
            acc[k] += ls.weight[k] * cos * w;
    }
}

void lm_ref_texel_sample(const lm_ref_ctx *c, const lm_ref_frame *f, lm_ref_rng *r, lm_ref_sample *out)
{
    float punct[3] = {0, 0, 0}, area[3] = {0, 0, 0};
    tally li;
    memset(&li, 0, sizeof li);
    texel_direct(c, f, r, punct, area);
    float u0 = lm_ref_rng_float(r), u1 = lm_ref_rng_float(r);
    lm_vec3 n = lm_v3_load(f->n), d = cosine_dir(n, u0, u1);
    float cos = lm_dot(n, d);
    if (lm_dot(d, lm_v3_load(f->ng)) > 0.0f && cos > 0.0f)
        trace(c, r, lm_v3_load(f->org), d, cos / LM_PI_F, ROUTE_LEFT, &li); /* E += L cos / (cos / pi) = pi L */
    memset(out, 0, sizeof *out);
    for (int k = 0; k < 3; k++) {
        float all = area[k] + LM_PI_F * li.total[k]; /* the old E_iim expression: full stays bit for bit */
        out->full[k] = all + punct[k];
        out->part[LM_REF_DIRECT][k] = punct[k];
        out->part[LM_REF_INDIRECT][k] = area[k] + LM_PI_F * li.part[LM_REF_INDIRECT][k];
        out->part[LM_REF_LOST][k] = LM_PI_F * li.part[LM_REF_LOST][k];
    }
    out->cut = li.cut;
}

/* ---- pixels ---- */

void lm_ref_pixel_sample(const lm_ref_ctx *c, const lm_view *cam, int x, int y, lm_ref_rng *r,
                         lm_ref_sample *out)
{
    lm_vec3 fwd = lm_normalize(lm_v3_load(cam->forward));
    lm_vec3 right = lm_normalize(lm_cross(fwd, lm_v3_load(cam->up)));
    lm_vec3 up = lm_cross(right, fwd);
    float th = tanf(0.5f * cam->yfov), aspect = (float)cam->width / (float)cam->height;
    float sx = (2.0f * ((float)x + lm_ref_rng_float(r)) / (float)cam->width - 1.0f) * th * aspect;
    float sy = (1.0f - 2.0f * ((float)y + lm_ref_rng_float(r)) / (float)cam->height) * th;
    lm_vec3 d = lm_normalize(lm_add(fwd, lm_add(lm_scale(right, sx), lm_scale(up, sy))));
    tally t; /* from the near plane on, as the rasterised frame sees (reference.h) */
    lm_vec3 org = lm_add(lm_v3_load(cam->eye), lm_scale(d, cam->znear / lm_dot(d, fwd)));
    trace(c, r, org, d, 0.0f, ROUTE_EYE, &t);
    memcpy(out->full, t.total, sizeof out->full);
    memcpy(out->part, t.part, sizeof out->part);
    out->cut = t.cut;
}
