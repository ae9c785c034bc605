/* The reference's caustic part by light tracing (ref_caustic.h). */
#include "ref_caustic.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../core/vecmath.h"
#include "../trace/bsdf.h"
#include "../trace/caustics.h"
#include "../trace/shading.h"

#define CHUNK 65536u      /* photons traced per parallel batch (their slots: 1 MiB) */
#define LANDING_BACK 16.0f /* x eps: how far back along its ray a landing point is found again */

/* A landed photon's share: what it adds to which entry. */
typedef struct {
    int32_t entry;         /* texel or pixel; -1: nothing */
    float value[3];
} deposit;

typedef struct pass pass;
struct pass {
    const lm_ref_ctx *c;
    uint32_t photons, seed;
    int (*land)(const pass *p, const lm_caustic_hit *h, deposit *d);
    lm_emit_tri **tris;    /* per emitter: its placed triangles, NULL for punctual lights */
    const lm_atlas *atlas; /* texels */
    /* pixels: the camera's frame, as lm_ref_pixel_sample builds it */
    lm_vec3 eye, fwd, right, up;
    float znear; /* points nearer the eye are clipped (reference.h) */
    float th, aspect, pixel_area; /* tan(yfov / 2), width / height, a pixel's area at distance 1 */
    int width, height;
};

/* ---- generators ---- */

/* The sphere around node n's specular triangles' world bounds; 0 when it has none or they have no
 * extent. */
static int node_sphere(const lm_scene *s, int n, lm_caustic_generator *g)
{
    const lm_node *node = &s->nodes[n];
    lm_vec3 lo = lm_v3(INFINITY, INFINITY, INFINITY), hi = lm_scale(lo, -1.0f);
    for (uint32_t t = node->first_tri; t < node->first_tri + node->tri_count; t++) {
        if (!lm_material_is_specular(s->materials[s->tri_material[t]].cls))
            continue;
        for (int k = 0; k < 3; k++) {
            float q[3];
            lm_scene_vertex_world(s, s->tris[3 * (size_t)t + (size_t)k], q);
            lo = lm_vmin(lo, lm_v3_load(q));
            hi = lm_vmax(hi, lm_v3_load(q));
        }
    }
    lm_vec3 centre = lm_scale(lm_add(lo, hi), 0.5f);
    float r = 0.5f * lm_length(lm_sub(hi, lo));
    if (!lm_v3_finite(centre) || !isfinite(r) || !(r > 0.0f))
        return 0;
    g->node = n;
    lm_v3_store(g->centre, centre);
    g->radius = r;
    return 1;
}

/* Every node with specular triangles, switches ignored. *out (caller frees) may be NULL when none. */
static lm_status generators(const lm_scene *s, lm_caustic_generator **out, int *count, lm_error *err)
{
    *count = 0;
    *out = malloc((size_t)(s->node_count > 0 ? s->node_count : 1) * sizeof **out);
    if (!*out)
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for the reference's caustic generators", s->path);
    for (int n = 0; n < s->node_count; n++)
        *count += node_sphere(s, n, &(*out)[*count]);
    return LM_OK;
}

static void free_tris(pass *p)
{
    for (int e = 0; p->tris && e < p->c->em->count; e++)
        free(p->tris[e]);
    free(p->tris);
    p->tris = NULL;
}

/* Places the area emitters' triangles once for the whole pass. */
static lm_status place_emitters(pass *p, lm_error *err)
{
    const lm_emitters *em = p->c->em;
    p->tris = calloc((size_t)(em->count > 0 ? em->count : 1), sizeof *p->tris);
    for (int e = 0; p->tris && e < em->count; e++) {
        if (em->e[e].punctual)
            continue;
        if (!(p->tris[e] = malloc((em->e[e].tri_count ? em->e[e].tri_count : 1) * sizeof *p->tris[e]))) {
            free_tris(p);
            break;
        }
        lm_emitter_place(em, p->c->s, e, p->tris[e]);
    }
    return p->tris ? LM_OK : lm_fail(err, LM_ERR_NOMEM, "%s: no memory for the caustic emitters", p->c->s->path);
}

/* ---- landing on texels ---- */

static int land_texel(const pass *p, const lm_caustic_hit *h, deposit *d)
{
    const lm_scene *s = p->c->s;
    const lm_atlas *a = p->atlas;
    int chart = a->tri_chart[h->tri];
    if (chart < 0)
        return 0;
    lm_vec3 q[3];
    for (int k = 0; k < 3; k++) {
        float w[3];
        lm_scene_vertex_world(s, s->tris[3 * (size_t)h->tri + (size_t)k], w);
        q[k] = lm_v3_load(w);
    }
    lm_vec3 front = lm_cross(lm_sub(q[1], q[0]), lm_sub(q[2], q[0])); /* as wound: the lit side */
    if (!(lm_dot(front, lm_v3_load(h->dir)) < 0.0f))
        return 0;
    const float b[3] = {1.0f - h->bary[0] - h->bary[1], h->bary[0], h->bary[1]}; /* where its hit fell */
    const float *uv = a->coverage_uv + 6 * (size_t)h->tri; /* the texel the point lies in */
    float fx = (b[0] * uv[0] + b[1] * uv[2] + b[2] * uv[4]) * (float)a->width;
    float fy = (b[0] * uv[1] + b[1] * uv[3] + b[2] * uv[5]) * (float)a->height;
    if (!(fx >= 0.0f && fx < (float)a->width && fy >= 0.0f && fy < (float)a->height))
        return 0;
    int i = a->texel_index[(size_t)fy * (size_t)a->width + (size_t)fx];
    if (i < 0 || a->texels[i].surface != a->charts[chart].surface || !(a->texels[i].area > 0.0f))
        return 0;
    d->entry = i;
    for (int k = 0; k < 3; k++)
        d->value[k] = h->flux[k] / a->texels[i].area;
    return 1;
}

/* ---- landing on pixels ---- */

/* The pixel that the point at rel (from the eye; z along forward, > 0) projects into. */
static int project(const pass *p, lm_vec3 rel, float z, int *x, int *y)
{
    float sx = lm_dot(rel, p->right) / z / (p->th * p->aspect), sy = lm_dot(rel, p->up) / z / p->th;
    float fx = 0.5f * (sx + 1.0f) * (float)p->width, fy = 0.5f * (1.0f - sy) * (float)p->height;
    if (!(fx >= 0.0f && fx < (float)p->width && fy >= 0.0f && fy < (float)p->height))
        return 0;
    *x = (int)fx < p->width ? (int)fx : p->width - 1;
    *y = (int)fy < p->height ? (int)fy : p->height - 1;
    return 1;
}

/* f(wi, wo) |cos(ns, wo)| where the photon landed. Its shading record comes from casting the ray that
 * brought it again over the last stretch, which is the photon's own free path; hits farther than half
 * that stretch from the landing point (a mirror it just left) do not count. */
static int landing_eval(const pass *p, const lm_caustic_hit *h, lm_vec3 wo, float f[3])
{
    const lm_ref_ctx *c = p->c;
    float back = LANDING_BACK * c->eps, org[3], w[3];
    lm_v3_store(org, lm_sub(lm_v3_load(h->pos), lm_scale(lm_v3_load(h->dir), back)));
    lm_rt_hit hit;
    if (!lm_rt_intersect(c->rt, org, h->dir, 0.5f * back, 1.5f * back, &hit))
        return 0;
    lm_shading sh;
    lm_shading_from_hit(c->s, &hit, org, h->dir, &sh);
    if (lm_material_is_specular(sh.material->cls))
        return 0;
    lm_v3_store(w, wo);
    lm_bsdf_eval(&sh, h->dir, w, f);
    return f[0] > 0.0f || f[1] > 0.0f || f[2] > 0.0f;
}

static int eye_blocked(const lm_ref_ctx *c, lm_vec3 pos, lm_vec3 ng, lm_vec3 wo, float dist)
{
    float org[3], dir[3];
    lm_v3_store(org, lm_add(pos, lm_scale(ng, c->eps)));
    lm_v3_store(dir, wo);
    return lm_rt_occluded(c->rt, org, dir, 0.0f, dist);
}

static int land_pixel(const pass *p, const lm_caustic_hit *h, deposit *d)
{
    lm_vec3 pos = lm_v3_load(h->pos), ng = lm_v3_load(h->ng), rel = lm_sub(pos, p->eye);
    float dist = lm_length(rel), z = lm_dot(rel, p->fwd), f[3];
    int x, y;
    if (!(z > p->znear && z > 0.0f && dist > 0.0f))
        return 0;
    lm_vec3 wo = lm_scale(rel, -1.0f / dist);
    if (!(lm_dot(ng, wo) > 0.0f) || !project(p, rel, z, &x, &y) || !landing_eval(p, h, wo, f) ||
        eye_blocked(p->c, pos, ng, wo, dist * (1.0f - p->znear / z))) /* only up to the near plane */
        return 0;
    float cos_a = z / dist, scale = 1.0f / (dist * dist * p->pixel_area * cos_a * cos_a * cos_a);
    d->entry = y * p->width + x;
    for (int k = 0; k < 3; k++)
        d->value[k] = h->flux[k] * f[k] * scale;
    return 1;
}

/* ---- photons ---- */

static float next_number(void *user, uint32_t bounce)
{
    (void)bounce;
    return lm_ref_rng_float(user);
}

static void trace_photon(const pass *p, int e, const lm_caustic_generator *g, uint64_t pair, uint32_t k, deposit *d)
{
    const lm_ref_ctx *c = p->c;
    lm_ref_rng r;
    float u[4], org[3], dir[3], flux[3];
    d->entry = -1;
    lm_ref_rng_seed(&r, p->seed, LM_REF_CAUSTIC_STREAM + pair, k);
    for (int i = 0; i < 4; i++) /* in order: an initializer list's calls are unsequenced */
        u[i] = lm_ref_rng_float(&r);
    if (!lm_caustic_emit(c->em, c->s, e, p->tris[e], g, u, p->photons, org, dir, flux))
        return;
    lm_caustic_hit h;
    if (lm_caustic_follow(c->s, c->rt, &c->em->e[e], g->node, org, dir, flux, (uint32_t)LM_REF_CAUSTIC_DEPTH, next_number, &r, &h, NULL) ==
        LM_CAUSTIC_LANDED)
        p->land(p, &h, d);
}

/* Photons [first, first + n) of a pair into their slots, in parallel. */
static void trace_chunk(const pass *p, int e, const lm_caustic_generator *g, uint64_t pair, uint32_t first,
                        uint32_t n, deposit *slots)
{
#pragma omp parallel
    {
        lm_rt_thread_init();
#pragma omp for schedule(dynamic, 256)
        for (long i = 0; i < (long)n; i++)
            trace_photon(p, e, g, pair, first + (uint32_t)i, &slots[i]);
    }
}

/* Every pair's photons, added up per entry in photon order (the same sums for any thread count). */
static void trace_pairs(const pass *p, const lm_caustic_generator *gen, int gen_count, deposit *slots, double *acc)
{
    for (int e = 0; e < p->c->em->count; e++)
        for (int g = 0; g < gen_count; g++) {
            uint64_t pair = (uint64_t)e * (uint64_t)gen_count + (uint64_t)g;
            for (uint32_t first = 0; first < p->photons; first += CHUNK) {
                uint32_t n = p->photons - first < CHUNK ? p->photons - first : CHUNK;
                trace_chunk(p, e, &gen[g], pair, first, n, slots);
                for (uint32_t i = 0; i < n; i++)
                    for (int k = 0; slots[i].entry >= 0 && k < 3; k++)
                        acc[3 * (size_t)slots[i].entry + (size_t)k] += slots[i].value[k];
            }
        }
}

static lm_status run(pass *p, uint32_t entries, float *out, uint64_t *photons, lm_error *err)
{
    const lm_scene *s = p->c->s;
    memset(out, 0, (size_t)entries * 3 * sizeof *out);
    *photons = 0;
    lm_caustic_generator *gen = NULL;
    int gen_count = 0;
    lm_status st = generators(s, &gen, &gen_count, err);
    if (st != LM_OK || gen_count == 0 || p->c->em->count == 0 || p->photons == 0) {
        free(gen);
        return st;
    }
    double *acc = calloc((size_t)(entries ? entries : 1) * 3, sizeof *acc);
    deposit *slots = malloc(CHUNK * sizeof *slots);
    st = acc && slots ? place_emitters(p, err) : lm_fail(err, LM_ERR_NOMEM, "%s: no memory for caustic photons", s->path);
    if (st == LM_OK) {
        trace_pairs(p, gen, gen_count, slots, acc);
        for (size_t i = 0; i < (size_t)entries * 3; i++)
            out[i] = (float)acc[i];
        *photons = (uint64_t)p->c->em->count * (uint64_t)gen_count * p->photons;
    }
    free_tris(p);
    free(slots);
    free(acc);
    free(gen);
    return st;
}

lm_status lm_ref_caustic_texels(const lm_ref_ctx *c, const lm_atlas *a, const lm_ref_settings *set, float *out,
                                uint64_t *photons, lm_error *err)
{
    pass p;
    memset(&p, 0, sizeof p);
    p.c = c, p.photons = set->caustic_photons, p.seed = set->seed;
    p.land = land_texel;
    p.atlas = a;
    return run(&p, a->texel_count, out, photons, err);
}

lm_status lm_ref_caustic_pixels(const lm_ref_ctx *c, const lm_view *cam, const lm_ref_settings *set,
                                float *out, uint64_t *photons, lm_error *err)
{
    pass p;
    memset(&p, 0, sizeof p);
    p.c = c, p.photons = set->caustic_photons, p.seed = set->seed;
    p.land = land_pixel;
    p.eye = lm_v3_load(cam->eye);
    p.znear = cam->znear;
    p.fwd = lm_normalize(lm_v3_load(cam->forward));
    p.right = lm_normalize(lm_cross(p.fwd, lm_v3_load(cam->up)));
    p.up = lm_cross(p.right, p.fwd);
    p.width = cam->width, p.height = cam->height;
    p.th = tanf(0.5f * cam->yfov);
    p.aspect = (float)cam->width / (float)cam->height;
    p.pixel_area = (2.0f * p.th * p.aspect / (float)cam->width) * (2.0f * p.th / (float)cam->height);
    return run(&p, (uint32_t)cam->width * (uint32_t)cam->height, out, photons, err);
}
