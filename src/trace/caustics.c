/* Caustic photons: emission towards the generators, specular paths, the per-pair photon lists and
 * their updates (caustics.h). */
#include "caustics.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "../core/qmc.h"
#include "../core/timing.h"
#include "../core/vecmath.h"
#include "bsdf.h"
#include "shading.h"

#define CAUSTIC_EMIT_DIMS 4u
#define CAUSTIC_RAY_OFFSET 1e-5f /* x scene size, as the photon stage's */
/* Fewer photons than this are traced on the calling thread (a thread team costs more). */
#define CAUSTIC_PARALLEL_MIN 512u
#define CAUSTIC_PACKET 16u /* photons traced together (lm_rt_intersect16) */
/* Slots whose Halton index is the same modulo 2^a 3^b have their first two numbers in the same 2^-a x 3^-b
 * cell: leaving the light together, they travel together */
#define CAUSTIC_CELLS 432u

void lm_caustic_settings_default(lm_caustic_settings *s)
{
    s->photons = 16384;
    s->retrace = 0.25f;
    s->max_bounces = 32;
    s->seed = 0;
}

/* ---- emission ---- */

/* A direction uniform in the cone of half-angle acos(cos_max) about unit axis a (cos_max -1: the whole
 * sphere); returns the cone's solid angle. */
static float cone_dir(lm_vec3 a, float cos_max, float u0, float u1, lm_vec3 *d)
{
    float z = 1.0f - u0 * (1.0f - cos_max), r = sqrtf(fmaxf(0.0f, 1.0f - z * z)), sn, cs;
    lm_sincos_turn(u1, &sn, &cs);
    *d = lm_normalize(lm_onb_dir(a, r * cs, r * sn, z));
    return (float)(2.0 * LM_PI) * (1.0f - cos_max);
}

/* The cone from point o around sphere g: its unit axis and the cosine of its half-angle (-1 when o is
 * inside the sphere: every direction may reach it). */
static void cone_to(const lm_caustic_generator *g, lm_vec3 o, lm_vec3 *axis, float *cos_max)
{
    lm_vec3 to = lm_sub(lm_v3_load(g->centre), o);
    float d = lm_length(to);
    if (!(d > g->radius * 1.0001f)) {
        *axis = lm_v3(0, 0, 1);
        *cos_max = -1.0f;
        return;
    }
    *axis = lm_scale(to, 1.0f / d);
    float s = g->radius / d;
    *cos_max = sqrtf(fmaxf(0.0f, 1.0f - s * s));
}

static int set_flux(float flux[3], const float radiant[3], float scale)
{
    for (int c = 0; c < 3; c++)
        flux[c] = radiant[c] * scale;
    return scale > 0.0f && (radiant[0] > 0.0f || radiant[1] > 0.0f || radiant[2] > 0.0f);
}

int lm_caustic_emit(const lm_emitters *em, const lm_scene *s, int e, const lm_emit_tri *tris,
                    const lm_caustic_generator *g, const float u[4], uint32_t count, float org[3], float dir[3],
                    float flux[3])
{
    const lm_emitter *em_e = &em->e[e];
    memset(flux, 0, 3 * sizeof *flux);
    if (!(g->radius > 0.0f) || count == 0 || em_e->kind == LM_EMIT_SKY) /* the sky throws no caustic photons */
        return 0;
    float inv = 1.0f / (float)count;
    lm_vec3 axis, d;
    float cos_max;
    if (em_e->kind == LM_EMIT_DIRECTIONAL) {
        lm_vec3 L = lm_normalize(lm_v3_load(em_e->dir)), c = lm_v3_load(g->centre), t, b;
        lm_tangents(L, &t, &b);
        float r = g->radius * sqrtf(u[0]), sn, cs;
        lm_sincos_turn(u[1], &sn, &cs);
        /* started upstream of everything: past the scene's bounding sphere and the generator's */
        float back = lm_length(lm_sub(c, lm_v3_load(em->disk_center))) + 1.001f * em->disk_radius + g->radius;
        lm_vec3 o = lm_add(c, lm_add(lm_scale(t, r * cs), lm_scale(b, r * sn)));
        lm_v3_store(org, lm_sub(o, lm_scale(L, back)));
        lm_v3_store(dir, L);
        return set_flux(flux, em_e->radiant, (float)LM_PI * g->radius * g->radius * inv);
    }
    if (em_e->kind == LM_EMIT_AREA) {
        float n[3], w[3];
        if (!lm_emitter_area_point(em, s, e, tris, u + 2, org, n, w))
            return 0;
        cone_to(g, lm_v3_load(org), &axis, &cos_max);
        float omega = cone_dir(axis, cos_max, u[0], u[1], &d);
        float cos_e = lm_dot(lm_v3_load(n), d);
        lm_v3_store(dir, d);
        return cos_e > 0.0f && set_flux(flux, w, cos_e * omega * inv);
    }
    lm_vec3 o = lm_v3_load(em_e->pos);
    cone_to(g, o, &axis, &cos_max);
    float omega = cone_dir(axis, cos_max, u[0], u[1], &d), att = 1.0f;
    if (em_e->kind == LM_EMIT_SPOT)
        att = lm_spot_attenuation(&s->lights[em_e->light], lm_dot(d, lm_normalize(lm_v3_load(em_e->dir))));
    lm_v3_store(org, o);
    lm_v3_store(dir, d);
    return set_flux(flux, em_e->radiant, att * omega * inv);
}

/* ---- paths ---- */

/* A photon's path between bounces: where its next ray starts and goes, what it carries, the bounce it is
 * at and the rays cast; done once it has landed or ended (fate). */
typedef struct {
    float org[3], dir[3], flux[3];
    uint32_t bounce, rays;
    lm_caustic_fate fate;
    int done;
} follow_state;

/* What a path follows: the scene, its emitter and generator, and where its numbers come from. */
typedef struct {
    const lm_scene *s;
    const lm_emitter *source;
    int generator;
    uint32_t max_bounces;
    lm_caustic_numbers next;
    void *user;
    float offset;
} follow_rules;

static void follow_begin(follow_state *f, const float org[3], const float dir[3], const float flux[3])
{
    memcpy(f->org, org, sizeof f->org);
    memcpy(f->dir, dir, sizeof f->dir);
    memcpy(f->flux, flux, sizeof f->flux);
    f->bounce = f->rays = 0;
    f->fate = LM_CAUSTIC_CAPPED;
    f->done = 0;
}

/* The path's ray met h (NULL: nothing): it lands (hit filled), ends, or goes on from the specular surface. */
static void follow_step(follow_state *f, const follow_rules *r, const lm_rt_hit *h, lm_caustic_hit *hit)
{
    uint32_t b = f->bounce;
    f->rays++;
    f->done = 1;
    if (!h) {
        f->fate = b == 0 ? LM_CAUSTIC_MISSED : LM_CAUSTIC_ESCAPED;
        return;
    }
    if (b == 0) {
        float w = lm_emitter_range_window(r->s, r->source, h->t);
        f->flux[0] *= w, f->flux[1] *= w, f->flux[2] *= w;
    }
    lm_shading sh;
    lm_shading_from_hit(r->s, h, f->org, f->dir, &sh);
    int specular = lm_material_is_specular(sh.material->cls);
    if (b == 0 && (!specular || (r->generator >= 0 && sh.node != r->generator))) {
        f->fate = LM_CAUSTIC_MISSED;
        return;
    }
    if (!specular) {
        lm_vec3 ng = lm_v3_load(sh.ng);
        if (lm_dot(ng, lm_v3_load(f->dir)) > 0.0f)
            ng = lm_scale(ng, -1.0f);
        memcpy(hit->pos, sh.pos, sizeof hit->pos);
        lm_v3_store(hit->ng, ng);
        memcpy(hit->flux, f->flux, sizeof hit->flux);
        memcpy(hit->dir, f->dir, sizeof hit->dir);
        hit->node = sh.node;
        hit->tri = sh.tri;
        hit->bary[0] = h->u, hit->bary[1] = h->v;
        hit->bounces = (uint16_t)b;
        f->fate = LM_CAUSTIC_LANDED;
        return;
    }
    if (b == r->max_bounces) /* one more specular bounce than allowed */
        return;
    float u[3] = {r->next(r->user, b), 0.0f, 0.0f};
    lm_bsdf_sample_t bs;
    if (!lm_bsdf_sample(&sh, f->dir, u, &bs)) {
        f->fate = LM_CAUSTIC_ABSORBED;
        return;
    }
    for (int c = 0; c < 3; c++)
        f->flux[c] *= bs.weight[c];
    if (!lm_v3_finite(lm_v3_load(f->flux))) {
        f->fate = LM_CAUSTIC_ABSORBED;
        return;
    }
    lm_vec3 ng = lm_v3_load(sh.ng), wo = lm_v3_load(bs.wo);
    float side = lm_dot(ng, wo) >= 0.0f ? r->offset : -r->offset;
    lm_v3_store(f->org, lm_add(lm_v3_load(sh.pos), lm_scale(ng, side)));
    memcpy(f->dir, bs.wo, sizeof f->dir);
    f->bounce = b + 1;
    f->done = 0;
}

lm_caustic_fate lm_caustic_follow(const lm_scene *s, const lm_rt *rt, const lm_emitter *source, int generator,
                                  const float org[3], const float dir[3], const float flux[3], uint32_t max_bounces,
                                  lm_caustic_numbers next, void *user, lm_caustic_hit *hit, uint32_t *rays)
{
    follow_rules r = {s, source, generator, max_bounces, next, user, CAUSTIC_RAY_OFFSET * lm_scene_size(s)};
    follow_state f;
    follow_begin(&f, org, dir, flux);
    while (!f.done) {
        lm_rt_hit h;
        int got = lm_rt_intersect(rt, f.org, f.dir, 0.0f, INFINITY, &h);
        follow_step(&f, &r, got ? &h : NULL, hit);
    }
    if (rays)
        *rays = f.rays;
    return f.fate;
}

/* ---- generators ---- */

/* Calls fn for every world corner of node n's specular triangles. */
static void specular_corners(const lm_scene *s, int n, void (*fn)(void *, lm_vec3), void *user)
{
    const lm_node *node = &s->nodes[n];
    for (uint32_t t = node->first_tri; t < node->first_tri + node->tri_count; t++) {
        if (!lm_material_is_specular(s->materials[s->tri_material[t]].cls))
            continue;
        for (int k = 0; k < 3; k++) {
            float p[3];
            lm_scene_vertex_world(s, s->tris[3 * (size_t)t + (size_t)k], p);
            fn(user, lm_v3_load(p));
        }
    }
}

typedef struct {
    lm_vec3 lo, hi, c;
    float r2;
} sphere_fit;

static void grow_box(void *user, lm_vec3 p)
{
    sphere_fit *f = user;
    f->lo = lm_vmin(f->lo, p);
    f->hi = lm_vmax(f->hi, p);
}

static void grow_radius(void *user, lm_vec3 p)
{
    sphere_fit *f = user;
    lm_vec3 d = lm_sub(p, f->c);
    f->r2 = fmaxf(f->r2, lm_dot(d, d));
}

/* The sphere about the centre of node n's specular triangles' world bounds through their farthest corner
 * (a sphere's own for a sphere; the box's half diagonal would aim 3^(3/2) times the photons at it);
 * radius 0 when they have no extent. */
static void generator_sphere(const lm_scene *s, int n, lm_caustic_generator *g)
{
    sphere_fit f = {lm_v3(INFINITY, INFINITY, INFINITY), lm_v3(-INFINITY, -INFINITY, -INFINITY), lm_v3(0, 0, 0), 0.0f};
    specular_corners(s, n, grow_box, &f);
    f.c = lm_scale(lm_add(f.lo, f.hi), 0.5f);
    specular_corners(s, n, grow_radius, &f);
    g->node = n;
    lm_vec3 c = f.c;
    float r = sqrtf(f.r2);
    int ok = lm_v3_finite(c) && isfinite(r) && r > 0.0f;
    lm_v3_store(g->centre, ok ? c : lm_v3(0, 0, 0));
    g->radius = ok ? r : 0.0f;
}

static int has_specular(const lm_scene *s, int n)
{
    const lm_node *node = &s->nodes[n];
    for (uint32_t t = node->first_tri; t < node->first_tri + node->tri_count; t++)
        if (lm_material_is_specular(s->materials[s->tri_material[t]].cls))
            return 1;
    return 0;
}

lm_status lm_caustic_generators(const lm_scene *s, lm_caustic_generator **out, int *count, lm_error *err)
{
    *out = NULL;
    *count = 0;
    int n = 0;
    for (int i = 0; i < s->node_count; i++)
        n += s->nodes[i].settings.caustics && has_specular(s, i);
    if (!n)
        return LM_OK;
    lm_caustic_generator *g = calloc((size_t)n, sizeof *g);
    if (!g)
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for the caustic generators", s->path);
    int k = 0;
    for (int i = 0; i < s->node_count; i++)
        if (s->nodes[i].settings.caustics && has_specular(s, i)) {
            generator_sphere(s, i, &g[k]);
            k += g[k].radius > 0.0f; /* no extent: nothing to aim at */
        }
    if (!k) {
        free(g);
        return LM_OK;
    }
    *out = g;
    *count = k;
    return LM_OK;
}

/* ---- the photon lists ---- */

typedef struct {
    int emitter, generator;
    uint32_t first;        /* first slot */
    uint32_t cursor;       /* next photon of the round robin */
    uint32_t remaining;    /* photons still to re-trace in the round robin's current turn */
    int whole;             /* 1: re-trace every photon, from the next frame on */
    uint32_t whole_done;   /* photons of that re-trace done (it may span frames: frame_cap) */
} pair;

/* What an emitter's placement was when its photons were last traced: a change re-traces its pairs. */
typedef struct {
    float pos[3], dir[3], radiant[3], power[3];
    float world[16];
} emitter_state;

struct lm_caustics {
    const lm_scene *scene;
    const lm_rt *rt;
    const lm_emitters *em;
    lm_caustic_settings set;
    lm_caustic_generator *gen;
    float (*gen_world)[16];  /* generator node matrices when their spheres were made */
    int gen_count;
    emitter_state *em_state;
    int em_count;
    int *em_pair;            /* per emitter, its column k of the pairs (g * live_count + k), -1 for a removed
                              * light's: a removed light keeps no photon slots */
    int live_count;
    pair *pairs;
    int pair_count;
    uint32_t slots;
    lm_caustic_hit *hits;
    double *emitted;         /* 3 per slot: a photon's emitted flux when it reached its generator, else 0 */
    uint32_t landed;
    uint64_t version;
    uint64_t world_hash;     /* of every node matrix: a change starts a round-robin turn */
    uint32_t frame_cap;      /* most photons a frame traces: what the pairs at creation took when all moved
                              * at once and the round robin ran, so lights added later spread their work */
    uint32_t frame_limit;    /* lm_caustics_limit_frame's (0: frame_cap) */
    /* scratch: the frame's jobs (slot numbers) and their fates */
    uint32_t *jobs;
    uint32_t *order;           /* scratch for ordering the jobs by cell (order_by_cell) */
    uint8_t *fates;            /* per job its fate, and whether its hit differs from the slot's before */
    uint8_t *changed;
    uint32_t *job_rays;
    lm_emit_tri *tris;       /* area emitters' placed triangles: em_tri_first[e] .. */
    uint32_t *em_tri_first;
};

static void emitter_snapshot(const lm_caustics *c, int e, emitter_state *out)
{
    const lm_emitter *em = &c->em->e[e];
    memset(out, 0, sizeof *out);
    memcpy(out->pos, em->pos, sizeof out->pos);
    memcpy(out->dir, em->dir, sizeof out->dir);
    memcpy(out->radiant, em->radiant, sizeof out->radiant);
    memcpy(out->power, em->power, sizeof out->power);
    if (em->node >= 0 && em->node < c->scene->node_count)
        memcpy(out->world, c->scene->nodes[em->node].world, sizeof out->world);
}

/* QMC number for slot `slot`'s photon, dimension dim (a pure function of the photon). */
static float caustic_number(const lm_caustics *c, uint32_t slot, uint32_t dim)
{
    uint64_t index = (uint64_t)c->set.seed * c->slots + slot;
    if (dim < LM_QMC_MAX_DIMS && index <= UINT32_MAX)
        return lm_halton_float(dim, (uint32_t)index);
    uint64_t h = index * 0x9E3779B97F4A7C15ull + (uint64_t)(dim + 1) * 0xBF58476D1CE4E5B9ull;
    h ^= h >> 31;
    h *= 0x94D049BB133111EBull;
    h ^= h >> 29;
    return (float)(h >> 40) * (1.0f / 16777216.0f);
}

typedef struct {
    const lm_caustics *c;
    uint32_t slot;
} numbers_user;

static float bounce_number(void *user, uint32_t bounce)
{
    const numbers_user *n = user;
    return caustic_number(n->c, n->slot, CAUSTIC_EMIT_DIMS + bounce);
}

static const pair *pair_of(const lm_caustics *c, uint32_t slot)
{
    return &c->pairs[slot / c->set.photons];
}

/* A photon of one slot while its packet traces: its path, the rules it follows, the numbers' source and
 * what it emitted. */
typedef struct {
    follow_state f;
    follow_rules r;
    numbers_user nu;
    float emitted[3];
} slot_path;

/* Emits the photon of `slot` (its hit cleared): 0 if its emission missed (the path is then done). */
static int slot_begin(const lm_caustics *c, uint32_t slot, slot_path *sp, lm_caustic_hit *hit)
{
    const pair *p = pair_of(c, slot);
    float u[4], org[3], dir[3];
    for (uint32_t k = 0; k < CAUSTIC_EMIT_DIMS; k++)
        u[k] = caustic_number(c, slot, k);
    memset(hit, 0, sizeof *hit);
    sp->nu = (numbers_user){c, slot};
    sp->r = (follow_rules){c->scene, &c->em->e[p->emitter], c->gen[p->generator].node, c->set.max_bounces,
                           bounce_number, &sp->nu, CAUSTIC_RAY_OFFSET * lm_scene_size(c->scene)};
    const lm_emit_tri *tris = c->em->e[p->emitter].punctual ? NULL : c->tris + c->em_tri_first[p->emitter];
    int emitted = lm_caustic_emit(c->em, c->scene, p->emitter, tris, &c->gen[p->generator], u, c->set.photons, org,
                                  dir, sp->emitted);
    follow_begin(&sp->f, org, dir, sp->emitted);
    if (!emitted) {
        sp->f.done = 1;
        sp->f.fate = LM_CAUSTIC_MISSED;
    }
    return emitted;
}

/* The slot's hit and emitted flux once its path is done (a photon that did not land keeps none). */
static void slot_end(const lm_caustics *c, uint32_t slot, const slot_path *sp, lm_caustic_hit *hit, double emitted[3])
{
    for (int k = 0; k < 3; k++)
        emitted[k] = sp->f.fate != LM_CAUSTIC_MISSED ? sp->emitted[k] : 0.0;
    hit->emitter = (uint16_t)pair_of(c, slot)->emitter;
    if (sp->f.fate != LM_CAUSTIC_LANDED)
        memset(hit, 0, sizeof *hit);
}

/* Traces slots[0 .. n) (n <= CAUSTIC_PACKET) together: each round casts the rays of the paths still going
 * as one Embree packet (a light's photons towards one generator start together and mostly stay so through
 * it), then takes each path one bounce on. Each path meets what lm_caustic_follow would give it. */
static void trace_packet(const lm_caustics *c, const uint32_t *slots, uint32_t n, lm_caustic_hit *hits,
                         slot_path *sp)
{
    for (uint32_t i = 0; i < n; i++)
        slot_begin(c, slots[i], &sp[i], &hits[i]);
    for (;;) {
        float org[3 * CAUSTIC_PACKET], dir[3 * CAUSTIC_PACKET];
        uint32_t lane[CAUSTIC_PACKET];
        int m = 0;
        for (uint32_t i = 0; i < n; i++)
            if (!sp[i].f.done) {
                memcpy(org + 3 * m, sp[i].f.org, sizeof sp[i].f.org);
                memcpy(dir + 3 * m, sp[i].f.dir, sizeof sp[i].f.dir);
                lane[m++] = i;
            }
        if (!m)
            return;
        lm_rt_hit h[CAUSTIC_PACKET];
        int got[CAUSTIC_PACKET];
        lm_rt_intersect16(c->rt, org, dir, m, h, got);
        for (int k = 0; k < m; k++)
            follow_step(&sp[lane[k]].f, &sp[lane[k]].r, got[k] ? &h[k] : NULL, &hits[lane[k]]);
    }
}

lm_caustic_fate lm_caustics_trace_one(const lm_caustics *c, uint32_t slot, lm_caustic_hit *hit)
{
    slot_path sp;
    double emitted[3];
    slot_begin(c, slot, &sp, hit);
    while (!sp.f.done) {
        lm_rt_hit h;
        int got = lm_rt_intersect(c->rt, sp.f.org, sp.f.dir, 0.0f, INFINITY, &h);
        follow_step(&sp.f, &sp.r, got ? &h : NULL, hit);
    }
    slot_end(c, slot, &sp, hit, emitted);
    return sp.f.fate;
}

/* Places the area emitters' triangles for this frame's traces. */
static void place_emitters(lm_caustics *c)
{
    for (int e = 0; e < c->em_count; e++)
        if (!c->em->e[e].punctual)
            lm_emitter_place(c->em, c->scene, e, c->tris + c->em_tri_first[e]);
}

/* The slots holding a landed photon (a flux not 0). */
static uint32_t count_landed(const lm_caustics *c)
{
    uint32_t landed = 0;
    for (uint32_t s = 0; s < c->slots; s++)
        landed += c->hits[s].flux[0] != 0.0f || c->hits[s].flux[1] != 0.0f || c->hits[s].flux[2] != 0.0f;
    return landed;
}

/* Orders jobs[0 .. n) so that each run of consecutive slots of one pair is taken cell by cell
 * (CAUSTIC_CELLS): the photons a packet traces together then leave the light in nearby directions. Only
 * the order changes: each slot's path is its own. */
static void order_by_cell(lm_caustics *c, uint32_t n)
{
    uint32_t w = 0, per = c->set.photons;
    for (uint32_t i = 0, len; i < n; i += len) {
        uint32_t s0 = c->jobs[i];
        for (len = 1; i + len < n && c->jobs[i + len] == s0 + len && (s0 + len) / per == s0 / per; len++)
            ;
        for (uint32_t r = 0; r < CAUSTIC_CELLS && r < len; r++)
            for (uint32_t k = r; k < len; k += CAUSTIC_CELLS)
                c->order[w++] = s0 + k;
    }
    memcpy(c->jobs, c->order, sizeof *c->jobs * n);
}

/* Traces jobs[0 .. n) (slots), in parallel, then counts. */
static void trace_jobs(lm_caustics *c, uint32_t n, lm_caustic_frame_stats *st)
{
    if (!n)
        return;
    place_emitters(c);
    order_by_cell(c, n);
    const lm_caustics *cc = c;
#pragma omp parallel if (n >= CAUSTIC_PARALLEL_MIN)
    {
        lm_rt_thread_init();
#pragma omp for schedule(dynamic, 4)
        for (long first = 0; first < (long)n; first += CAUSTIC_PACKET) {
            uint32_t m = n - (uint32_t)first < CAUSTIC_PACKET ? n - (uint32_t)first : CAUSTIC_PACKET;
            lm_caustic_hit h[CAUSTIC_PACKET];
            slot_path sp[CAUSTIC_PACKET];
            trace_packet(cc, c->jobs + first, m, h, sp);
            for (uint32_t k = 0; k < m; k++) {
                uint32_t i = (uint32_t)first + k, slot = c->jobs[i];
                double em[3];
                slot_end(cc, slot, &sp[k], &h[k], em);
                c->fates[i] = (uint8_t)sp[k].f.fate;
                c->job_rays[i] = sp[k].f.rays;
                c->changed[i] = memcmp(&c->hits[slot], &h[k], sizeof h[k]) != 0;
                c->hits[slot] = h[k];
                memcpy(c->emitted + 3 * (size_t)slot, em, sizeof em);
            }
        }
    }
    uint32_t *fate_count[5] = {&st->landed, &st->missed, &st->escaped, &st->absorbed, &st->capped};
    int changed = 0;
    for (uint32_t i = 0; i < n; i++) {
        (*fate_count[c->fates[i]])++;
        st->rays += c->job_rays[i];
        st->cast += c->job_rays[i] > 0;
        changed |= c->changed[i];
    }
    st->traced += n;
    c->landed = count_landed(c);
    c->version += changed; /* a re-trace that found every path as it was changes nothing downstream */
}

/* Whether emitter e lights anything for good: a removed light never comes back. */
static int emitter_live(const lm_caustics *c, int e) { return !lm_emitter_removed(c->scene, &c->em->e[e]); }

static lm_status alloc_lists(lm_caustics *c, lm_error *err)
{
    c->em_pair = malloc(sizeof *c->em_pair * (size_t)(c->em_count ? c->em_count : 1));
    if (!c->em_pair)
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for the caustic emitters", c->scene->path);
    c->live_count = 0;
    for (int e = 0; e < c->em_count; e++)
        c->em_pair[e] = emitter_live(c, e) ? c->live_count++ : -1;
    c->pair_count = c->gen_count * c->live_count;
    c->pairs = calloc((size_t)(c->pair_count ? c->pair_count : 1), sizeof *c->pairs);
    c->gen_world = calloc((size_t)(c->gen_count ? c->gen_count : 1), sizeof *c->gen_world);
    c->em_state = calloc((size_t)(c->em_count ? c->em_count : 1), sizeof *c->em_state);
    c->em_tri_first = calloc((size_t)c->em_count + 1, sizeof *c->em_tri_first);
    uint64_t slots = (uint64_t)c->pair_count * c->set.photons;
    if (slots > UINT32_MAX / 2)
        return lm_fail(err, LM_ERR_INVALID, "%s: %d caustic pairs of %u photons are too many", c->scene->path,
                       c->pair_count, c->set.photons);
    c->slots = (uint32_t)slots;
    size_t n = slots ? (size_t)slots : 1;
    c->hits = calloc(n, sizeof *c->hits);
    c->emitted = calloc(3 * n, sizeof *c->emitted);
    c->jobs = malloc(n * sizeof *c->jobs);
    c->order = malloc(n * sizeof *c->order);
    c->fates = malloc(n);
    c->changed = malloc(n);
    c->job_rays = malloc(n * sizeof *c->job_rays);
    if (!c->pairs || !c->gen_world || !c->em_state || !c->em_tri_first || !c->hits || !c->emitted || !c->jobs || !c->order ||
        !c->fates || !c->changed || !c->job_rays)
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for %llu caustic photons", c->scene->path,
                       (unsigned long long)slots);
    for (int e = 0; e < c->em_count; e++)
        c->em_tri_first[e + 1] = c->em_tri_first[e] + (c->em->e[e].punctual ? 0 : c->em->e[e].tri_count);
    c->tris = malloc(sizeof *c->tris * (c->em_tri_first[c->em_count] ? c->em_tri_first[c->em_count] : 1));
    if (!c->tris)
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for the caustic emitters", c->scene->path);
    for (int g = 0; g < c->gen_count; g++)
        for (int e = 0; e < c->em_count; e++) {
            if (c->em_pair[e] < 0)
                continue;
            int i = g * c->live_count + c->em_pair[e];
            pair *p = &c->pairs[i];
            p->emitter = e;
            p->generator = g;
            p->first = (uint32_t)i * c->set.photons;
        }
    return LM_OK;
}

static lm_status check_settings(const lm_scene *s, const lm_caustic_settings *set, lm_error *err)
{
    if (set->photons < 1 || set->photons > (1u << 24))
        return lm_fail(err, LM_ERR_INVALID, "%s: caustic photons per pair must be 1 to 16777216, not %u", s->path,
                       set->photons);
    if (!(set->retrace > 0.0f && set->retrace <= 1.0f))
        return lm_fail(err, LM_ERR_INVALID, "%s: the caustic re-trace fraction must be in (0, 1], not %g", s->path,
                       (double)set->retrace);
    if (set->max_bounces < 1 || set->max_bounces > 1024)
        return lm_fail(err, LM_ERR_INVALID, "%s: caustic bounces must be 1 to 1024, not %u", s->path,
                       set->max_bounces);
    return LM_OK;
}

static void snapshot_all(lm_caustics *c)
{
    for (int g = 0; g < c->gen_count; g++)
        memcpy(c->gen_world[g], c->scene->nodes[c->gen[g].node].world, sizeof c->gen_world[g]);
    for (int e = 0; e < c->em_count; e++)
        emitter_snapshot(c, e, &c->em_state[e]);
    c->world_hash = lm_scene_world_hash(c->scene);
}

lm_status lm_caustics_trace_all(lm_caustics *c, lm_caustic_frame_stats *stats, lm_error *err)
{
    (void)err;
    lm_caustic_frame_stats st;
    memset(&st, 0, sizeof st);
    double t0 = lm_now();
    for (int g = 0; g < c->gen_count; g++) /* spheres as the scene is now */
        generator_sphere(c->scene, c->gen[g].node, &c->gen[g]);
    snapshot_all(c);
    for (uint32_t s = 0; s < c->slots; s++)
        c->jobs[s] = s;
    for (int p = 0; p < c->pair_count; p++)
        c->pairs[p].remaining = 0, c->pairs[p].whole = 0, c->pairs[p].whole_done = 0;
    trace_jobs(c, c->slots, &st);
    st.seconds = lm_now() - t0;
    if (stats)
        *stats = st;
    return LM_OK;
}

lm_status lm_caustics_create(const lm_scene *s, const lm_rt *rt, const lm_emitters *em,
                             const lm_caustic_settings *set, lm_caustics **out, lm_caustic_frame_stats *stats,
                             lm_error *err)
{
    *out = NULL;
    lm_caustic_settings def;
    if (!set) {
        lm_caustic_settings_default(&def);
        set = &def;
    }
    lm_status st = check_settings(s, set, err);
    if (st != LM_OK)
        return st;
    lm_caustics *c = calloc(1, sizeof *c);
    if (!c)
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for the caustic photons", s->path);
    c->scene = s, c->rt = rt, c->em = em, c->set = *set;
    c->em_count = em->count;
    lm_qmc_init();
    st = lm_caustic_generators(s, &c->gen, &c->gen_count, err);
    if (st == LM_OK)
        st = alloc_lists(c, err);
    uint32_t N = set->photons, pairs = c->pair_count > 1 ? (uint32_t)c->pair_count : 1;
    uint64_t cap = (uint64_t)pairs * N + (uint64_t)pairs * (uint64_t)ceil((double)set->retrace * N);
    c->frame_cap = cap > UINT32_MAX / 2 ? UINT32_MAX / 2 : (uint32_t)cap;
    if (st == LM_OK)
        st = lm_caustics_trace_all(c, stats, err);
    if (st != LM_OK) {
        lm_caustics_free(c);
        return st;
    }
    *out = c;
    return LM_OK;
}

void lm_caustics_free(lm_caustics *c)
{
    if (!c)
        return;
    free(c->gen);
    free(c->gen_world);
    free(c->em_state);
    free(c->em_pair);
    free(c->pairs);
    free(c->hits);
    free(c->emitted);
    free(c->jobs);
    free(c->order);
    free(c->fates);
    free(c->changed);
    free(c->job_rays);
    free(c->tris);
    free(c->em_tri_first);
    free(c);
}

/* Marks whole the pairs whose generator moved or whose emitter changed; returns how many. */
static uint32_t mark_moved(lm_caustics *c)
{
    uint32_t n = 0;
    for (int g = 0; g < c->gen_count; g++) {
        const float *w = c->scene->nodes[c->gen[g].node].world;
        if (!memcmp(w, c->gen_world[g], sizeof c->gen_world[g]))
            continue;
        memcpy(c->gen_world[g], w, sizeof c->gen_world[g]);
        generator_sphere(c->scene, c->gen[g].node, &c->gen[g]);
        for (int k = 0; k < c->live_count; k++)
            c->pairs[g * c->live_count + k].whole = 1;
    }
    for (int e = 0; e < c->em_count; e++) {
        emitter_state now;
        emitter_snapshot(c, e, &now);
        if (!memcmp(&now, &c->em_state[e], sizeof now))
            continue;
        c->em_state[e] = now;
        for (int g = 0; c->em_pair[e] >= 0 && g < c->gen_count; g++)
            c->pairs[g * c->live_count + c->em_pair[e]].whole = 1;
    }
    for (int p = 0; p < c->pair_count; p++)
        n += c->pairs[p].whole;
    return n;
}

#define DONE_THIS_FRAME 2 /* pair.whole: its whole re-trace was finished by this frame's jobs */

/* Queues pair p's photons from the round robin's cursor, at most *left of them. */
static uint32_t queue_round_robin(lm_caustics *c, pair *p, uint32_t per_frame, uint32_t n, uint32_t *left)
{
    uint32_t N = c->set.photons, take = p->remaining < per_frame ? p->remaining : per_frame;
    take = take < *left ? take : *left;
    for (uint32_t k = 0; k < take; k++) {
        c->jobs[n++] = p->first + p->cursor;
        p->cursor = (p->cursor + 1) % N;
    }
    p->remaining -= take;
    *left -= take;
    return n;
}

/* The photons of a pair a round-robin frame re-traces: its share `retrace` of them, 1 to all. */
static uint32_t round_robin_turn(const lm_caustics *c)
{
    uint32_t N = c->set.photons, turn = (uint32_t)ceil((double)c->set.retrace * N);
    return turn < 1 ? 1 : turn > N ? N : turn;
}

lm_status lm_caustics_frame(lm_caustics *c, lm_caustic_frame_stats *stats, lm_error *err)
{
    (void)err;
    lm_caustic_frame_stats st;
    memset(&st, 0, sizeof st);
    double t0 = lm_now();
    if (c->pair_count) {
        st.pairs_moved = mark_moved(c);
        uint64_t h = lm_scene_world_hash(c->scene);
        int moved = h != c->world_hash;
        c->world_hash = h;
        uint32_t N = c->set.photons, per_frame = round_robin_turn(c), n = 0;
        uint32_t left = c->frame_limit ? c->frame_limit : c->frame_cap;
        /* first the pairs whose generator or emitter changed, whole (over several frames when more of them
         * than frame_cap allows), then the round robin of the others with what is left */
        for (int i = 0; i < c->pair_count && left > 0; i++) {
            pair *p = &c->pairs[i];
            if (!p->whole)
                continue;
            uint32_t take = N - p->whole_done < left ? N - p->whole_done : left;
            for (uint32_t k = 0; k < take; k++)
                c->jobs[n++] = p->first + p->whole_done + k;
            p->whole_done += take, left -= take;
            if (p->whole_done == N)
                p->whole = DONE_THIS_FRAME, p->whole_done = 0;
        }
        for (int i = 0; i < c->pair_count; i++) {
            pair *p = &c->pairs[i];
            if (p->whole == DONE_THIS_FRAME) /* its slots are in jobs once: no round robin this frame */
                p->whole = 0, p->remaining = moved ? N : 0;
            else if (!p->whole) {
                p->remaining = moved ? N : p->remaining; /* the turn begins again after the scene moved */
                n = queue_round_robin(c, p, per_frame, n, &left);
            }
        }
        trace_jobs(c, n, &st);
    }
    st.seconds = lm_now() - t0;
    if (stats)
        *stats = st;
    return LM_OK;
}

void lm_caustics_retrace_all_later(lm_caustics *c)
{
    for (int i = 0; i < c->pair_count; i++)
        if (!c->pairs[i].whole)
            c->pairs[i].whole = 1, c->pairs[i].whole_done = 0;
}

void lm_caustics_limit_frame(lm_caustics *c, uint32_t most) { c->frame_limit = most; }

uint32_t lm_caustics_wanted(const lm_caustics *c)
{
    uint64_t n = lm_caustics_pending(c) + (uint64_t)c->pair_count * round_robin_turn(c);
    return n < c->frame_cap ? (uint32_t)n : c->frame_cap;
}

uint32_t lm_caustics_pending(const lm_caustics *c)
{
    uint32_t n = 0;
    for (int i = 0; i < c->pair_count; i++)
        n += c->pairs[i].whole ? c->set.photons - c->pairs[i].whole_done : 0;
    return n;
}

/* Whether the emitters, or which of them are removed lights, changed since c's pairs were laid out. */
static int emitters_changed(const lm_caustics *c)
{
    if (c->em->count != c->em_count)
        return 1;
    for (int e = 0; e < c->em_count; e++)
        if ((c->em_pair[e] >= 0) != emitter_live(c, e))
            return 1;
    return 0;
}

/* Pair (g, e) of n takes over c's: its state, hits and emitted flux. */
static void carry_pair(lm_caustics *n, const lm_caustics *c, int g, int e)
{
    pair *to = &n->pairs[g * n->live_count + n->em_pair[e]];
    const pair *from = &c->pairs[g * c->live_count + c->em_pair[e]];
    uint32_t first = to->first, N = c->set.photons;
    *to = *from;
    to->first = first;
    memcpy(n->hits + first, c->hits + from->first, sizeof *n->hits * N);
    memcpy(n->emitted + 3 * (size_t)first, c->emitted + 3 * (size_t)from->first, sizeof *n->emitted * 3 * N);
}

/* The pairs laid out again for the emitters as they are: a new light's queued whole, a removed light's
 * dropped with their slots, the others carried over. */
lm_status lm_caustics_follow_emitters(lm_caustics *c, lm_error *err)
{
    if (!emitters_changed(c))
        return LM_OK;
    lm_caustics *n = calloc(1, sizeof *n);
    if (!n)
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for the caustic photons", c->scene->path);
    n->scene = c->scene, n->rt = c->rt, n->em = c->em, n->set = c->set;
    n->em_count = c->em->count;
    n->gen = c->gen, n->gen_count = c->gen_count;
    c->gen = NULL;
    lm_status st = alloc_lists(n, err);
    if (st != LM_OK) {
        c->gen = n->gen, n->gen = NULL;
        lm_caustics_free(n);
        return st;
    }
    memcpy(n->gen_world, c->gen_world, sizeof *c->gen_world * (size_t)c->gen_count);
    memcpy(n->em_state, c->em_state, sizeof *c->em_state * (size_t)c->em_count);
    for (int e = c->em_count; e < n->em_count; e++)
        emitter_snapshot(n, e, &n->em_state[e]);
    for (int g = 0; g < n->gen_count; g++)
        for (int e = 0; e < n->em_count; e++) {
            if (n->em_pair[e] < 0)
                continue;
            if (e < c->em_count && c->em_pair[e] >= 0)
                carry_pair(n, c, g, e);
            else
                n->pairs[g * n->live_count + n->em_pair[e]].whole = 1;
        }
    n->landed = count_landed(n), n->version = c->version + 1;
    n->world_hash = c->world_hash, n->frame_cap = c->frame_cap;
    lm_caustics old = *c;
    *c = *n;
    *n = old;
    lm_caustics_free(n);
    return LM_OK;
}

int lm_caustics_pair_count(const lm_caustics *c) { return c->pair_count; }
int lm_caustics_generator_count(const lm_caustics *c) { return c->gen_count; }
const lm_caustic_generator *lm_caustics_generator(const lm_caustics *c, int i) { return &c->gen[i]; }
uint32_t lm_caustics_photon_count(const lm_caustics *c) { return c->slots; }
const lm_caustic_hit *lm_caustics_hits(const lm_caustics *c) { return c->hits; }
uint32_t lm_caustics_landed(const lm_caustics *c) { return c->landed; }
uint64_t lm_caustics_version(const lm_caustics *c) { return c->version; }

void lm_caustics_flux(const lm_caustics *c, double stored[3], double emitted[3])
{
    for (int k = 0; k < 3; k++)
        stored[k] = emitted[k] = 0.0;
    for (uint32_t s = 0; s < c->slots; s++)
        for (int k = 0; k < 3; k++) {
            stored[k] += c->hits[s].flux[k];
            emitted[k] += c->emitted[3 * (size_t)s + k];
        }
}
