/* Tracing one photon from its own QMC dimensions, and tracing batches of photons in parallel
 * (Larsen & Christensen 2004, section 2: fixed QMC photons, Russian roulette).
 *
 * Dimensions of photon id (Halton index halton_base + id): 0-3 emission (0-1 the direction, so groups
 * of equal id mod G leave in similar directions), then 4 per path vertex b: 4 + 4b .. 4 + 4b + 2 sample
 * the BSDF, 4 + 4b + 3 decides Russian roulette. Past LM_QMC_MAX_DIMS a hash of (seed, id, dim) takes
 * over, still a pure function of the photon; so is the hash of (seed, id, b) that decides whether a bounce
 * outside is aimed in through the light's openings (portals.h, "Bounces aimed in"). */
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "../core/prefault.h"
#include "../core/qmc.h"
#include "../core/vecmath.h"
#include "bsdf.h"
#include "photons_internal.h"
#include "shading.h"

/* Smaller batches (a round-robin frame) run on the calling thread: waking a thread team costs more
 * than tracing a few hundred photons, and much more when the cores are shared. */
#define PH_PARALLEL_MIN_JOBS 1024u
#define PH_DIMS_PER_BOUNCE 4u

static uint64_t mix64(uint64_t z)
{
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/* n uniform numbers in [0, 1) as floats (never rounded up to 1): dims dim .. dim + n - 1. The
 * tables exist: lm_photons_create built them (lm_qmc_init) before drawing the emission numbers. */
static inline void photon_samples(const lm_photons *ph, uint32_t id, uint32_t dim, uint32_t n, float *out)
{
    uint64_t index = ph->halton_base + id;
    if (dim + n <= LM_QMC_MAX_DIMS && index <= UINT32_MAX) { /* every photon of seed 0 and most others */
        for (uint32_t k = 0; k < n; k++)
            out[k] = lm_halton_float(dim + k, (uint32_t)index);
        return;
    }
    double u[PH_DIMS_PER_BOUNCE];
    uint32_t q = dim < LM_QMC_MAX_DIMS ? LM_QMC_MAX_DIMS - dim : 0; /* how many are Halton dims */
    q = q < n ? q : n;
    lm_halton_dims(dim, q, index, u);
    for (uint32_t k = q; k < n; k++) {
        uint64_t h = mix64(((uint64_t)ph->set.seed << 32 | id) + 0x9E3779B97F4A7C15ull * (dim + k + 1));
        u[k] = (double)(h >> 11) * 0x1.0p-53;
    }
    for (uint32_t k = 0; k < n; k++) {
        float f = (float)u[k];
        out[k] = f < 1.0f ? f : 0x1.fffffep-1f;
    }
}

/* Russian roulette: photon_samples(dim) < p, decided by lm_halton_float_below where the Halton tables
 * serve the number (the same answer, mostly from one lookup). */
static inline int survives(const lm_photons *ph, uint32_t id, uint32_t dim, float p)
{
    uint64_t index = ph->halton_base + id;
    if (dim < LM_QMC_MAX_DIMS && index <= UINT32_MAX)
        return lm_halton_float_below(dim, (uint32_t)index, p);
    float u;
    photon_samples(ph, id, dim, 1, &u);
    return u < p;
}

static int buffer_reserve(ph_buffer *buf)
{
    if (buf->len < buf->cap)
        return 1;
    size_t cap = buf->cap ? buf->cap * 2 : 256;
    ph_vertex *v = realloc(buf->v, cap * sizeof *v);
    if (!v)
        return 0;
    lm_prefault(v + buf->cap, (cap - buf->cap) * sizeof *v); /* a batch fills what it grew for */
    buf->v = v;
    buf->cap = cap;
    return 1;
}

/* Whether other geometry lies within cover_distance straight out from the side of the hit that dir
 * arrived at (lm_photon_settings.cover_distance). */
static int covered(const lm_photons *ph, const lm_shading *sh, const float dir[3])
{
    lm_vec3 n = lm_v3_load(sh->ng);
    if (lm_dot(n, lm_v3_load(dir)) > 0.0f)
        n = lm_scale(n, -1.0f);
    float out[3];
    lm_v3_store(out, n);
    return lm_rt_covered(ph->rt, sh->pos, out, ph->ray_offset,
                         lm_cover_reach(ph->set.cover_distance, ph->set.cover_by_surface, sh->surface));
}

static int push_vertex(const lm_photons *ph, ph_buffer *buf, const lm_shading *sh, const float dir[3],
                       const float flux[3], float travelled, uint32_t b, int caustic)
{
    if (!buffer_reserve(buf))
        return 0;
    ph_vertex *v = &buf->v[buf->len++];
    v->node = sh->node;
    v->tri = sh->tri;
    int store = sh->surface >= 0 && lm_material_stores_hits(sh->material->cls);
    v->surface = store && !(ph->set.cover_distance > 0.0f && covered(ph, sh, dir)) ? sh->surface : -1;
    v->bounce = (uint16_t)b;
    v->caustic = (uint8_t)caustic;
    memcpy(v->pos, sh->pos, sizeof v->pos);
    memcpy(v->local, sh->local, sizeof v->local);
    memcpy(v->dir, dir, sizeof v->dir);
    memcpy(v->flux, flux, sizeof v->flux);
    v->travelled = travelled;
    return 1;
}

/* The number that decides whether bounce b is aimed in through the openings (portals.h): a hash of the
 * photon and the bounce, not a Halton dimension (the bounce's four are taken). */
static float aim_number(const lm_photons *ph, uint32_t id, uint32_t b)
{
    uint64_t h = mix64(((uint64_t)ph->set.seed << 32 | id) ^ 0xD1B54A32D192ED03ull * (b + 1));
    return (float)(h >> 40) * 0x1.0p-24f;
}

/* A bounce at a place outside that sees openings of the photon's light (reach > 0, n the side wi came
 * from): aimed at them or drawn from the BSDF, weighed by the mixture's density (portals.h, "Bounces
 * aimed in"). bs as lm_bsdf_sample fills it; 0: absorbed. */
static int aimed_sample(const lm_photons *ph, const lm_portals *aim, double reach, uint32_t id, uint32_t b,
                        const lm_shading *sh, const float wi[3], const float n[3], const float u[3],
                        lm_bsdf_sample_t *bs)
{
    const double share = LM_PORTAL_BOUNCE_SHARE;
    if (aim_number(ph, id, b) < share) {
        if (!lm_portals_bounce_dir(aim, sh->pos, n, reach, u[0], u[1], bs->wo))
            return 0;
    } else if (!lm_bsdf_sample(sh, wi, u, bs)) {
        return 0;
    }
    float f[3], pdf;
    lm_bsdf_eval_pdf(sh, wi, bs->wo, f, &pdf);
    double mix = (1.0 - share) * pdf + share * lm_portals_bounce_density(aim, sh->pos, n, reach, bs->wo);
    if (!(mix > 0.0) || !(f[0] + f[1] + f[2] > 0.0f))
        return 0;
    for (int c = 0; c < 3; c++)
        bs->weight[c] = (float)(f[c] / mix);
    bs->specular = bs->transmitted = 0;
    return 1;
}

/* What the openings of the photon's light fill at its hit (lm_portals_bounce_reach), n the side its
 * bounce leaves by; 0 where the bounce is the BSDF's alone: no openings, mirror, glass or an emitter. */
static double aim_reach(const lm_portals *aim, const lm_shading *sh, const float wi[3], float n[3])
{
    lm_material_class c = sh->material->cls;
    if (!aim || (c != LM_MAT_DIFFUSE && c != LM_MAT_GLOSSY))
        return 0.0;
    lm_vec3 ng = lm_v3_load(sh->ng);
    lm_v3_store(n, lm_dot(ng, lm_v3_load(wi)) > 0.0f ? lm_scale(ng, -1.0f) : ng);
    return lm_portals_bounce_reach(aim, sh->pos, n);
}

/* Russian roulette on the albedo, then a BSDF sample (or one aimed in through the openings of aim, the
 * photon's light's portals); flux *= weight / p_survive. Returns 0 when the photon is absorbed. On
 * success org and dir hold the next ray. */
static int scatter(const lm_photons *ph, const lm_portals *aim, uint32_t id, uint32_t b, const lm_shading *sh,
                   float org[3], float dir[3], float flux[3])
{
    uint32_t d = PH_EMIT_DIMS + PH_DIMS_PER_BOUNCE * b;
    float p = lm_bsdf_photon_survival(sh), u[3] = {0.0f, 0.0f, 0.0f};
    /* Only the numbers that decide something are computed (QMC is a large share of a trace): no
     * roulette draw where survival is certain (u < 1 always), no BSDF number the material ignores,
     * and the roulette's number only as far as it decides u < p. */
    if (p < 1.0f && !survives(ph, id, d + 3, p))
        return 0;
    uint32_t n = (uint32_t)lm_bsdf_sample_dims(sh);
    if (n)
        photon_samples(ph, id, d, n, u);
    lm_shading flat;
    sh = lm_shading_for_bounce(sh, &flat); /* a diffuse bounce leaves with the geometric cosine */
    lm_bsdf_sample_t bs;
    float n_out[3];
    double reach = aim_reach(aim, sh, dir, n_out);
    if (reach > 0.0 ? !aimed_sample(ph, aim, reach, id, b, sh, dir, n_out, u, &bs) : !lm_bsdf_sample(sh, dir, u, &bs))
        return 0;
    float inv_p = 1.0f / p;
    for (int c = 0; c < 3; c++)
        flux[c] *= bs.weight[c] * inv_p;
    if (!lm_v3_finite(lm_v3_load(flux)))
        return 0;
    lm_vec3 ng = lm_v3_load(sh->ng), wo = lm_v3_load(bs.wo);
    float side = lm_dot(ng, wo) >= 0.0f ? ph->ray_offset : -ph->ray_offset;
    lm_v3_store(org, lm_add(lm_v3_load(sh->pos), lm_scale(ng, side)));
    memcpy(dir, bs.wo, sizeof bs.wo);
    return 1;
}

void ph_emission_samples(const lm_photons *ph, uint32_t id, float u[4])
{
    photon_samples(ph, id, 0, PH_EMIT_DIMS, u);
}

int ph_trace_photon(const lm_photons *ph, ph_job *j, ph_buffer *buf)
{
    const ph_group *g = &ph->groups[j->group];
    uint32_t id = g->first_id + j->m * ph->G;
    const float *u = g->emit_u + PH_EMIT_DIMS * (size_t)j->m;
    uint32_t emitter_photons = ph->emitter_first[g->emitter + 1] - ph->emitter_first[g->emitter];
    lm_emission emi;
    const lm_emit_tri *placed = ph->emit_placed ? ph->emit_placed + ph->emit_tri_first[g->emitter] : NULL;
    lm_emitter_emit_placed(ph->em, ph->scene, g->emitter, placed, u, emitter_photons, &emi);
    /* The ray lives in emi itself: copying the values just stored there stalled on wide loads of
     * narrow stores (no store-to-load forwarding). */
    float *org = emi.org, *dir = emi.dir, *flux = emi.flux;
    /* its bounces outside aimed in (portals.h) */
    const lm_portals *aim = ph->set.aim_bounces ? ph->em->e[g->emitter].portals : NULL;
    j->count = j->rays = j->stored = 0;
    if (dir[0] == 0.0f && dir[1] == 0.0f && dir[2] == 0.0f) /* an emitter that emits nothing */
        return 1;
    /* Counted in locals, written once: j lies in the batch's job array, beside other threads' jobs. */
    uint32_t rays = 0, count = 0, stored = 0;
    int ok = 1, specular_so_far = 1; /* every vertex before this one was mirror or glass */
    uint32_t specular_run = 0;       /* mirror or glass vertices in a row */
    for (uint32_t b = 0; b < ph->set.max_bounces; b++) {
        lm_rt_hit hit;
        rays++;
        if (!lm_rt_intersect(ph->rt, org, dir, 0.0f, INFINITY, &hit))
            break;
        if (b == 0) { /* a point or spot light's range: its light at the first hit, carried on from there */
            float w = lm_emitter_range_window(ph->scene, &ph->em->e[g->emitter], hit.t);
            flux[0] *= w, flux[1] *= w, flux[2] *= w;
        }
        lm_shading sh;
        lm_shading_from_hit(ph->scene, &hit, org, dir, &sh);
        float w = lm_shading_arrival_weight(&sh, dir); /* shading normals: what the reference receives */
        flux[0] *= w, flux[1] *= w, flux[2] *= w;
        /* The vertex is recorded after the scatter (with the direction and flux it arrived with): by
         * then the shading's stores have left the store buffer, and copying them does not stall. */
        float in_dir[3] = {dir[0], dir[1], dir[2]}, in_flux[3] = {flux[0], flux[1], flux[2]};
        int scattered = w > 0.0f && scatter(ph, aim, id, b, &sh, org, dir, flux);
        if (!push_vertex(ph, buf, &sh, in_dir, in_flux, hit.t, b, b > 0 && specular_so_far)) {
            ok = 0;
            break;
        }
        if (!(w > 0.0f)) /* arrived behind its shading normal: recorded (a node moving into its path must
                          * find it) but holds nothing */
            buf->v[buf->len - 1].surface = -1;
        int specular = lm_material_is_specular(sh.material->cls);
        specular_so_far = specular_so_far && specular;
        specular_run = specular ? specular_run + 1 : 0;
        count++;
        stored += buf->v[buf->len - 1].surface >= 0;
        if (!scattered || specular_run >= PH_SPECULAR_RUN)
            break;
    }
    j->count = count;
    j->rays = rays;
    j->stored = stored;
    return ok;
}

void ph_batch_clear(ph_batch *b) { b->count = 0; }

/* Room for n more jobs. 0: no memory. */
static int batch_reserve(ph_batch *b, uint32_t n)
{
    if (b->count + n <= b->cap)
        return 1;
    uint32_t cap = b->cap ? b->cap : 1024;
    while (cap < b->count + n)
        cap *= 2;
    ph_job *jobs = realloc(b->jobs, cap * sizeof *jobs);
    if (!jobs)
        return 0;
    b->jobs = jobs;
    b->cap = cap;
    return 1;
}

static inline void batch_append(ph_batch *b, uint32_t group, uint32_t m)
{
    b->jobs[b->count++] = (ph_job){.group = group, .m = m};
}

int ph_batch_push(ph_batch *b, uint32_t group, uint32_t m)
{
    if (!batch_reserve(b, 1))
        return 0;
    batch_append(b, group, m);
    return 1;
}

int ph_batch_push_group(ph_batch *b, uint32_t group, uint32_t photons)
{
    if (!batch_reserve(b, photons))
        return 0;
    for (uint32_t m = 0; m < photons; m++)
        batch_append(b, group, m);
    return 1;
}

void ph_batch_free(ph_batch *b)
{
    for (int t = 0; t < b->buffer_count; t++)
        free(b->buffers[t].v);
    free(b->buffers);
    free(b->jobs);
    memset(b, 0, sizeof *b);
}

static int ensure_buffers(ph_batch *b, int threads)
{
    if (b->buffer_count >= threads)
        return 1;
    ph_buffer *bufs = realloc(b->buffers, (size_t)threads * sizeof *bufs);
    if (!bufs)
        return 0;
    memset(bufs + b->buffer_count, 0, (size_t)(threads - b->buffer_count) * sizeof *bufs);
    b->buffers = bufs;
    b->buffer_count = threads;
    return 1;
}

/* The jobs of b, shared out among the threads of the enclosing team (dynamic: path lengths vary).
 * Each job writes only its own record and its thread's buffer; what a job traces depends on the
 * photon alone, so results are the same whatever thread ran it. */
static void trace_jobs(const lm_photons *ph, ph_batch *b, int *failed)
{
    /* The thread's buffer is worked on in a local copy: the buffers' headers lie side by side, and a
     * length written back per vertex made the threads fight over one cache line (false sharing). */
    int t = omp_get_thread_num();
    ph_buffer buf = b->buffers[t];
    ph_job *jobs = b->jobs;
#pragma omp for schedule(dynamic, 16) nowait
    for (long i = 0; i < (long)b->count; i++) {
        ph_job *j = &jobs[i];
        j->buffer = (uint32_t)t;
        j->first = (uint32_t)buf.len;
        if (b->shares > 1 && (b->first_photon + (uint64_t)i) % b->shares != b->share) {
            j->count = j->rays = j->stored = 0; /* another process's: the exchange brings it */
            continue;
        }
        if (!ph_trace_photon(ph, j, &buf)) {
#pragma omp atomic write
            *failed = 1;
        }
    }
    b->buffers[t] = buf; /* before the barrier: after it, the calling thread applies the batch */
#pragma omp barrier
}

/* Area emitters' triangles placed once for a trace of `photons` photons, unless there are more of
 * them than photons (each photon then places its own: the same bits either way). */
static void place_emitters(lm_photons *ph, uint64_t photons)
{
    uint32_t etris = ph->emit_tri_first[ph->emitter_count];
    ph->emit_placed = NULL;
    if (etris && etris <= photons) {
        for (uint32_t e = 0; e < ph->emitter_count; e++)
            lm_emitter_place(ph->em, ph->scene, (int)e, ph->emit_tris + ph->emit_tri_first[e]);
        ph->emit_placed = ph->emit_tris;
    }
}

/* One emptied vertex buffer for each of `threads` threads. 0: no memory. */
static int batch_buffers(ph_batch *b, int threads)
{
    if (!ensure_buffers(b, threads))
        return 0;
    for (int t = 0; t < b->buffer_count; t++)
        b->buffers[t].len = 0;
    return 1;
}

static void batch_rays(ph_batch *b)
{
    b->rays = 0;
    for (uint32_t i = 0; i < b->count; i++)
        b->rays += b->jobs[i].rays;
}

static lm_status fail_buffers(int threads, lm_error *err)
{
    return lm_fail(err, LM_ERR_NOMEM, "photons: no memory for %d trace buffers", threads);
}

static lm_status fail_traced(const ph_batch *b, lm_error *err)
{
    return lm_fail(err, LM_ERR_NOMEM, "photons: no memory for the paths of %u photons", b->count);
}

lm_status ph_trace_batch(lm_photons *ph, ph_batch *b, lm_error *err)
{
    int threads = omp_get_max_threads();
    if (!batch_buffers(b, threads))
        return fail_buffers(threads, err);
    place_emitters(ph, b->count);
    int failed = 0;
#pragma omp parallel num_threads(threads) if (b->count >= PH_PARALLEL_MIN_JOBS)
    {
        lm_rt_thread_init();
        trace_jobs(ph, b, &failed);
    }
    if (failed)
        return fail_traced(b, err);
    batch_rays(b);
    return LM_OK;
}

/* A re-trace of a list of groups, batch by batch (ph_trace_groups). */
typedef struct {
    const uint32_t *list;
    uint32_t n, next;          /* the groups, and the next one to put in a batch */
    int threads;
    lm_photon_frame_stats *st;
    lm_error *err;
    lm_status status;          /* the first failure to fill or apply a batch */
    int failed;                /* a thread ran out of memory tracing (set by any thread) */
    ph_batch *last;            /* the batch traced last, applied after the parallel region */
} ph_pipe;

static lm_status apply_traced(lm_photons *ph, ph_batch *b, lm_photon_frame_stats *st, lm_error *err)
{
    batch_rays(b);
    st->rays += b->rays;
    return ph_apply_batch(ph, b, st, err);
}

/* The calling thread's turn before it joins a batch's trace: applies `done` (the batch traced
 * before, NULL for none), then fills `next` with the following groups. Stops the pipeline by
 * leaving `next` empty: when the list is used up or anything failed. */
static void pipe_turn(lm_photons *ph, ph_pipe *p, ph_batch *done, ph_batch *next)
{
    int failed;
#pragma omp atomic read
    failed = p->failed;
    if (done && !failed && p->status == LM_OK)
        p->status = apply_traced(ph, done, p->st, p->err);
    ph_batch_clear(next);
    if (failed || p->status != LM_OK || p->next >= p->n)
        return;
    p->status = ph_fill_batch(ph, next, p->list, p->n, &p->next, p->st, p->err);
    if (p->status == LM_OK && !batch_buffers(next, p->threads))
        p->status = fail_buffers(p->threads, p->err);
    if (p->status != LM_OK)
        ph_batch_clear(next);
}

lm_status ph_trace_groups(lm_photons *ph, const uint32_t *list, uint32_t n, lm_photon_frame_stats *st,
                          lm_error *err)
{
    ph_pipe p = {.list = list, .n = n, .threads = omp_get_max_threads(), .st = st, .err = err, .status = LM_OK};
    uint64_t total = 0;
    for (uint32_t i = 0; i < n; i++)
        total += ph->groups[list[i]].photons;
    place_emitters(ph, total); /* before the team starts: tracing only reads them */
    pipe_turn(ph, &p, NULL, &ph->batches[0]);
    /* Batch i is traced from batches[i & 1] while the calling thread first applies batch i - 1 and
     * refills its slot with batch i + 1. One barrier per batch (the end of its trace): each is a
     * scheduler tick of waiting when a thread of the team has lost its core on a loaded machine.
     * Every thread reads batch i's count only after the barrier that follows its filling, and the
     * slot is not refilled before the next barrier, so all threads leave the loop together. */
#pragma omp parallel num_threads(p.threads) if (total >= PH_PARALLEL_MIN_JOBS)
    {
        lm_rt_thread_init();
        for (uint32_t i = 0; ph->batches[i & 1].count; i++) {
            ph_batch *cur = &ph->batches[i & 1], *other = &ph->batches[(i + 1) & 1];
#pragma omp master
            {
                pipe_turn(ph, &p, i ? other : NULL, other);
                p.last = cur;
            }
            trace_jobs(ph, cur, &p.failed);
        }
    }
    if (p.last && !p.failed && p.status == LM_OK)
        p.status = apply_traced(ph, p.last, st, err);
    if (p.status != LM_OK)
        return p.status;
    if (p.failed)
        return fail_traced(p.last, err);
    return LM_OK;
}
