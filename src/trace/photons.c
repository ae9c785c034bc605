/* The photon stage (photons.h): photon counts and groups, the full trace, the per-frame round robin
 * check and the budgeted re-trace of invalid groups (Larsen & Christensen 2004, section 2). */
#include "photons.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/memory.h"
#include "../core/qmc.h"
#include "../core/timing.h"
#include "photons_internal.h"

/* Photons traced per batch in a group re-trace: bounds the trace buffers. */
#define PH_BATCH_PHOTONS 16384u
#define PH_MAX_PHOTONS (1u << 30)
/* A path reweighted by recolours (lm_photons_scale_materials) by less than this, or more than its inverse,
 * is traced again: its hits keep their flux in floats, which a soak's 180 recolours drove below the
 * smallest float and back up by the inverse, 0 x inf (NaN) in the AIMs after 874 updates */
#define PH_SCALE_LEAST 1e-12

void lm_photon_settings_default(lm_photon_settings *s)
{
    memset(s, 0, sizeof *s);
    s->groups = 72;
    /* 160: the paper's box had 77 groups of 40; at 40 the N-nearest estimates left surfaces of the
     * shared scenes 3-4% off the reference at default settings, at 160 within 2% (docs/photons.md,
     * "Photon budget"), for about twice the stage's own work per frame */
    s->per_group = 160;
    s->min_total = LM_PHOTONS_MIN_TOTAL;
    s->retrace_per_group = 1;
    s->group_budget = 16;
    s->max_bounces = 1024;
    s->aim_bounces = 1;
}

static int is_2a3b(uint32_t n)
{
    if (n == 0)
        return 0;
    while (n % 2 == 0)
        n /= 2;
    while (n % 3 == 0)
        n /= 3;
    return n == 1;
}

static lm_status check_settings(const lm_photon_settings *s, lm_error *err)
{
    if (!is_2a3b(s->groups) || s->groups > 1u << 20)
        return lm_fail(err, LM_ERR_INVALID, "photon settings: groups %u must be 2^a 3^b, at most 2^20",
                       s->groups);
    if (s->total_photons == 0 && s->per_group == 0)
        return lm_fail(err, LM_ERR_INVALID, "photon settings: per_group must be > 0 when total_photons is 0");
    if (s->total_photons > PH_MAX_PHOTONS || s->per_group > PH_MAX_PHOTONS)
        return lm_fail(err, LM_ERR_INVALID, "photon settings: at most %u photons", PH_MAX_PHOTONS);
    if (s->max_bounces < 1 || s->max_bounces > 1024)
        return lm_fail(err, LM_ERR_INVALID, "photon settings: max_bounces %u must be in [1, 1024]",
                       s->max_bounces);
    if (!isfinite(s->epsilon))
        return lm_fail(err, LM_ERR_INVALID, "photon settings: epsilon must be finite");
    if (!isfinite(s->cover_distance))
        return lm_fail(err, LM_ERR_INVALID, "photon settings: cover_distance must be finite");
    return LM_OK;
}

/* An emitter's weight in the photon budget: its luminance, but for a lit emitter at least half the mean
 * lit emitter's. In proportion to luminance alone, photons carry equal power, and a lamp a million times
 * dimmer than the sun got one photon a group: where the lamp is all the light (a room the sun does not
 * reach) its lightmap was those 72 photons' noise, 21% off (docs/hard-cases.md). The floor costs the
 * brightest emitters a share of their photons only where others are far dimmer. Dark emitters weigh 0. */
static double emitter_weight(double least, float luminance)
{
    return luminance > 0.0f ? fmax((double)luminance, least) : 0.0;
}

/* The emitters' weights summed, and the least weight of a lit one into *least. */
static double plan_weights(const lm_emitters *em, double *least)
{
    int lit = 0;
    for (int e = 0; e < em->count; e++)
        lit += em->e[e].luminance > 0.0f;
    *least = lit ? 0.5 * em->total_luminance / lit : 0.0;
    double sum = 0.0;
    for (int e = 0; e < em->count; e++)
        sum += emitter_weight(*least, em->e[e].luminance);
    return sum;
}

/* The photons planned over E emitters. */
static uint64_t plan_total(const lm_photons *ph, uint32_t E)
{
    uint64_t total = ph->set.total_photons ? ph->set.total_photons : (uint64_t)ph->set.per_group * ph->G * E;
    return !ph->set.total_photons && total < ph->set.min_total ? ph->set.min_total : total;
}

/* M_e: photons per group of emitter e, in proportion to its weight, at least 1. */
static uint32_t emitter_per_group(const lm_photons *ph, int e, uint64_t total, double weights, double least)
{
    const lm_emitters *em = ph->em;
    double share = weights > 0.0 ? emitter_weight(least, em->e[e].luminance) / weights : 1.0 / em->count;
    double m = floor((double)total * share / ph->G + 0.5);
    return m < 1.0 ? 1u : (uint32_t)fmin(m, (double)PH_MAX_PHOTONS);
}

int lm_photons_plan_outdated(const lm_photons *ph)
{
    uint32_t E = (uint32_t)ph->em->count;
    if (E != ph->emitter_count)
        return 1;
    double least, weights = plan_weights(ph->em, &least);
    uint64_t total = plan_total(ph, E);
    for (uint32_t e = 0; e < E; e++)
        if ((uint64_t)emitter_per_group(ph, (int)e, total, weights, least) * ph->G !=
            ph->emitter_first[e + 1] - ph->emitter_first[e])
            return 1;
    return 0;
}

/* A photon's store entry, its path and its share of the AIM kd-trees: about 240 bytes, measured on the
 * generated Cornell box from 100k to 1M photons (peak RSS of lmgi run). */
#define PH_BYTES_PER_PHOTON 240.0

static lm_status plan_counts(lm_photons *ph, lm_error *err)
{
    uint32_t E = ph->emitter_count;
    uint64_t total = plan_total(ph, E);
    ph->emitter_first = calloc((size_t)E + 1, sizeof *ph->emitter_first);
    if (!ph->emitter_first)
        return lm_fail(err, LM_ERR_NOMEM, "photons: no memory for %u emitters", E);
    double weights = plan_weights(ph->em, &ph->weight_floor);
    uint64_t at = 0;
    for (uint32_t e = 0; e < E; e++) {
        at += (uint64_t)emitter_per_group(ph, (int)e, total, weights, ph->weight_floor) * ph->G;
        if (at > PH_MAX_PHOTONS)
            return lm_fail(err, LM_ERR_INVALID, "photons: %llu photons over %u emitters exceed %u",
                           (unsigned long long)at, E, PH_MAX_PHOTONS);
        ph->emitter_first[e + 1] = (uint32_t)at;
    }
    ph->photon_count = (uint32_t)at;
    ph->per_luminance = weights > 0.0 ? (double)at / weights : 0.0;
    char what[128];
    snprintf(what, sizeof what, "%llu photons over %u lights", (unsigned long long)at, E);
    lm_status st = lm_memory_plan(what, (double)at * PH_BYTES_PER_PHOTON, "fewer photons (--photons, or "
                                  "--per-group) make it smaller", err);
    if (st != LM_OK)
        return st;
    ph->emit_tri_first = calloc((size_t)E + 1, sizeof *ph->emit_tri_first);
    if (!ph->emit_tri_first)
        return lm_fail(err, LM_ERR_NOMEM, "photons: no memory for %u emitters", E);
    for (uint32_t e = 0; e < E; e++)
        ph->emit_tri_first[e + 1] = ph->emit_tri_first[e] + (ph->em->e[e].punctual ? 0 : ph->em->e[e].tri_count);
    if (ph->emit_tri_first[E]) {
        ph->emit_tris = malloc(ph->emit_tri_first[E] * sizeof *ph->emit_tris);
        if (!ph->emit_tris)
            return lm_fail(err, LM_ERR_NOMEM, "photons: no memory for %u emissive triangles", ph->emit_tri_first[E]);
    }
    return LM_OK;
}

/* Groups [from, to), of the emitters emitter_first plans: their photons' fixed emission numbers. */
static lm_status init_groups(lm_photons *ph, uint32_t from, uint32_t to, lm_error *err)
{
    for (uint32_t i = from; i < to; i++) {
        ph_group *g = &ph->groups[i];
        g->emitter = (int)(i / ph->G);
        g->index = i % ph->G;
        g->photons = (ph->emitter_first[g->emitter + 1] - ph->emitter_first[g->emitter]) / ph->G;
        g->first_id = ph->emitter_first[g->emitter] + g->index;
        g->offsets = calloc((size_t)g->photons + 1, sizeof *g->offsets);
        g->emit_u = malloc((size_t)g->photons * 4 * sizeof *g->emit_u); /* photons >= 1 */
        if (!g->offsets || !g->emit_u)
            return lm_fail(err, LM_ERR_NOMEM, "photons: no memory for group %u", i);
        for (uint32_t m = 0; m < g->photons; m++)
            ph_emission_samples(ph, g->first_id + m * ph->G, g->emit_u + 4 * (size_t)m);
    }
    return LM_OK;
}

/* Scratch for rebuilding the largest group's slab. */
static lm_status size_scratch(lm_photons *ph, lm_error *err)
{
    uint32_t most = 0;
    for (uint32_t i = 0; i < ph->group_count; i++)
        most = ph->groups[i].photons > most ? ph->groups[i].photons : most;
    if (ph->tmp_offsets && most <= ph->max_group_photons)
        return LM_OK;
    uint32_t *offsets = realloc(ph->tmp_offsets, ((size_t)most + 1) * sizeof *offsets);
    if (offsets)
        ph->tmp_offsets = offsets;
    uint8_t *changed = realloc(ph->tmp_changed, (size_t)most + 1);
    if (changed)
        ph->tmp_changed = changed;
    if (!offsets || !changed)
        return lm_fail(err, LM_ERR_NOMEM, "photons: no memory for group scratch");
    ph->max_group_photons = most;
    return LM_OK;
}

static lm_status make_groups(lm_photons *ph, lm_error *err)
{
    ph->group_count = ph->emitter_count * ph->G;
    size_t n = ph->group_count ? ph->group_count : 1;
    ph->groups = calloc(n, sizeof *ph->groups);
    ph->queue = malloc(n * sizeof *ph->queue);
    ph->tmp_groups = malloc(n * sizeof *ph->tmp_groups);
    if (!ph->groups || !ph->queue || !ph->tmp_groups)
        return lm_fail(err, LM_ERR_NOMEM, "photons: no memory for %u groups", ph->group_count);
    lm_status st = init_groups(ph, 0, ph->group_count, err);
    return st == LM_OK ? size_scratch(ph, err) : st;
}

static lm_status setup(lm_photons *ph, lm_error *err)
{
    lm_status st = check_settings(&ph->set, err);
    if (st == LM_OK)
        st = plan_counts(ph, err);
    ph->halton_base = (uint64_t)ph->set.seed * ph->photon_count; /* before make_groups draws from it */
    lm_qmc_init(); /* once: the tracer reads the tables without a check */
    if (st == LM_OK)
        st = make_groups(ph, err);
    if (st == LM_OK)
        st = lm_photon_store_init(&ph->store, ph->surfaces ? ph->surfaces->surface_count : 0, err);
    float size = lm_scene_size(ph->scene);
    if (!(size > 0.0f) || !isfinite(size))
        size = 1.0f;
    ph->epsilon = ph->set.epsilon > 0.0f ? ph->set.epsilon : 1e-4f * size;
    ph->ray_offset = 1e-5f * size;
    return st;
}

lm_status lm_photons_create(const lm_scene *s, const lm_surfaces *su, const lm_rt *rt, const lm_emitters *em,
                            const lm_photon_settings *settings, lm_photons **out, lm_error *err)
{
    *out = NULL;
    if (!s || !rt || !em || !settings)
        return lm_fail(err, LM_ERR_INVALID, "photons: scene, BVH, emitters and settings are required");
    /* Aligned as the struct's cache-line-aligned members ask (photons_internal.h); its size is a
     * multiple of 64 because of them, as aligned_alloc wants. */
    lm_photons *ph = aligned_alloc(_Alignof(lm_photons), sizeof *ph);
    if (!ph)
        return lm_fail(err, LM_ERR_NOMEM, "photons: no memory");
    memset(ph, 0, sizeof *ph);
    ph->scene = s;
    ph->surfaces = su;
    ph->rt = rt;
    ph->em = em;
    ph->set = *settings;
    ph->G = settings->groups;
    ph->emitter_count = (uint32_t)(em->count > 0 ? em->count : 0);
    ph->store.free_head = LM_NONE;
    lm_status st = setup(ph, err);
    if (st != LM_OK) {
        lm_photons_free(ph);
        return st;
    }
    *out = ph;
    return LM_OK;
}

void lm_photons_free(lm_photons *ph)
{
    if (!ph)
        return;
    for (uint32_t i = 0; ph->groups && i < ph->group_count; i++)
        ph_group_free(&ph->groups[i]);
    free(ph->groups);
    free(ph->queue);
    free(ph->emitter_first);
    free(ph->emit_tri_first);
    free(ph->emit_tris);
    free(ph->tmp_verts);
    free(ph->tmp_offsets);
    free(ph->tmp_changed);
    free(ph->tmp_groups);
    ph_batch_free(&ph->batches[0]);
    ph_batch_free(&ph->batches[1]);
    lm_photon_store_free(&ph->store);
    free(ph);
}

void lm_photons_reset(lm_photons *ph)
{
    for (uint32_t i = 0; i < ph->group_count; i++) {
        ph_group *g = &ph->groups[i];
        memset(g->offsets, 0, ((size_t)g->photons + 1) * sizeof *g->offsets); /* slab kept: vert_cap */
        g->rr_next = 0;
        g->invalid = 0;
        g->invalidations = g->retraces = 0;
    }
    ph->queue_head = ph->queue_len = 0;
    lm_photon_store_clear(&ph->store);
    ph->live_hits = 0;
}

/* ---- invalid-group queue: FIFO, each group at most once (oldest invalid first) ---- */

static void mark_invalid(lm_photons *ph, uint32_t group)
{
    ph_group *g = &ph->groups[group];
    if (g->invalid)
        return;
    g->invalid = 1;
    ph->queue[(ph->queue_head + ph->queue_len) % ph->group_count] = group;
    ph->queue_len++;
}

static uint32_t pop_invalid(lm_photons *ph)
{
    uint32_t group = ph->queue[ph->queue_head];
    ph->queue_head = (ph->queue_head + 1) % ph->group_count;
    ph->queue_len--;
    ph->groups[group].invalid = 0;
    return group;
}

lm_status lm_photons_invalidate_emitter(lm_photons *ph, int e, lm_error *err)
{
    if (e < 0 || (uint32_t)e >= ph->emitter_count)
        return lm_fail(err, LM_ERR_INVALID, "photons: emitter %d out of range (%u emitters)", e,
                       ph->emitter_count);
    for (uint32_t g = 0; g < ph->G; g++)
        mark_invalid(ph, (uint32_t)e * ph->G + g);
    return LM_OK;
}

/* Every stored hit of emitter e's photons: scaled by s, or (s NULL) its flux added to flux per surface. */
static void emitter_hits(lm_photons *ph, int e, const float s[3], double *flux)
{
    for (uint32_t i = (uint32_t)e * ph->G; i < ((uint32_t)e + 1) * ph->G; i++) {
        const ph_group *g = &ph->groups[i];
        for (uint32_t v = 0; g->offsets && v < g->offsets[g->photons]; v++) {
            uint32_t slot = g->verts[v].slot;
            const lm_hit *h = lm_photon_store_live(&ph->store, slot);
            if (h && s)
                lm_photon_store_scale(&ph->store, slot, s);
            else if (h)
                for (int c = 0; c < 3; c++)
                    flux[3 * h->surface + c] += h->flux[c];
        }
    }
}

lm_status lm_photons_scale_emitter(lm_photons *ph, int e, const float s[3], lm_error *err)
{
    if (e < 0 || (uint32_t)e >= ph->emitter_count)
        return lm_fail(err, LM_ERR_INVALID, "photons: emitter %d out of range (%u emitters)", e,
                       ph->emitter_count);
    emitter_hits(ph, e, s, NULL);
    return LM_OK;
}

/* Emitter e's groups taken off the queue (the others keep their order). */
static void unqueue_emitter(lm_photons *ph, int e)
{
    uint32_t kept = 0, n = ph->group_count;
    for (uint32_t i = 0; i < ph->queue_len; i++) {
        uint32_t group = ph->queue[(ph->queue_head + i) % n];
        if (group / ph->G == (uint32_t)e)
            ph->groups[group].invalid = 0;
        else
            ph->queue[(ph->queue_head + kept++) % n] = group;
    }
    ph->queue_len = kept;
}

lm_status lm_photons_retrace_emitter(lm_photons *ph, int e, lm_error *err)
{
    if (e < 0 || (uint32_t)e >= ph->emitter_count)
        return lm_fail(err, LM_ERR_INVALID, "photons: emitter %d out of range (%u emitters)", e,
                       ph->emitter_count);
    lm_photon_frame_stats st;
    memset(&st, 0, sizeof st);
    for (uint32_t k = 0; k < ph->G; k++)
        ph->tmp_groups[k] = (uint32_t)e * ph->G + k;
    lm_status rc = ph_trace_groups(ph, ph->tmp_groups, ph->G, &st, err);
    if (rc == LM_OK)
        unqueue_emitter(ph, e);
    return rc;
}

void lm_photons_emitter_flux(const lm_photons *ph, int e, double *flux)
{
    if (e >= 0 && (uint32_t)e < ph->emitter_count)
        emitter_hits((lm_photons *)ph, e, NULL, flux);
}

/* M_e of an emitter added after creation: the photons per unit of weight the others got (emitter_weight,
 * with the floor of creation), so that its photons carry about their power; a light added dark (or to a
 * scene with none lit) gets the mean emitter's count. */
static uint32_t added_per_group(const lm_photons *ph, const lm_emitter *e)
{
    double m = e->luminance > 0.0f && ph->per_luminance > 0.0
                   ? floor(emitter_weight(ph->weight_floor, e->luminance) * ph->per_luminance / ph->G + 0.5)
             : ph->emitter_count ? (double)ph->photon_count / ph->emitter_count / ph->G
             : ph->set.total_photons ? (double)ph->set.total_photons / ph->G
                                     : (double)ph->set.per_group;
    return m < 1.0 ? 1u : (uint32_t)fmin(m, (double)PH_MAX_PHOTONS);
}

lm_status lm_photons_add_emitter(lm_photons *ph, lm_error *err)
{
    uint32_t E = ph->emitter_count, G = ph->G, old = ph->group_count;
    if (ph->em->count != (int)E + 1 || !(ph->em->e[E].punctual || ph->em->e[E].kind == LM_EMIT_SKY))
        return lm_fail(err, LM_ERR_INVALID, "photons: expected one light or the sky appended to the %u emitters (have %d)", E,
                       ph->em->count);
    uint64_t at = ph->photon_count + (uint64_t)added_per_group(ph, &ph->em->e[E]) * G;
    if (at > PH_MAX_PHOTONS)
        return lm_fail(err, LM_ERR_INVALID, "photons: another light would make %llu photons, over %u",
                       (unsigned long long)at, PH_MAX_PHOTONS);
    uint32_t *first = realloc(ph->emitter_first, ((size_t)E + 2) * sizeof *first);
    if (first)
        ph->emitter_first = first;
    uint32_t *tri_first = realloc(ph->emit_tri_first, ((size_t)E + 2) * sizeof *tri_first);
    if (tri_first)
        ph->emit_tri_first = tri_first;
    ph_group *groups = realloc(ph->groups, ((size_t)old + G) * sizeof *groups);
    if (groups)
        ph->groups = groups;
    uint32_t *tmp = realloc(ph->tmp_groups, ((size_t)old + G) * sizeof *tmp);
    if (tmp)
        ph->tmp_groups = tmp;
    uint32_t *queue = malloc(((size_t)old + G) * sizeof *queue);
    if (!first || !tri_first || !groups || !tmp || !queue) {
        free(queue);
        return lm_fail(err, LM_ERR_NOMEM, "photons: no memory for another light's %u groups", G);
    }
    for (uint32_t i = 0; i < ph->queue_len; i++) /* the ring laid out afresh for its new length */
        queue[i] = ph->queue[(ph->queue_head + i) % old];
    free(ph->queue);
    ph->queue = queue;
    ph->queue_head = 0;
    memset(ph->groups + old, 0, G * sizeof *ph->groups);
    ph->emitter_first[E + 1] = (uint32_t)at;
    ph->emit_tri_first[E + 1] = ph->emit_tri_first[E];
    ph->emitter_count = E + 1;
    ph->group_count = old + G;
    ph->photon_count = (uint32_t)at;
    lm_status st = init_groups(ph, old, old + G, err);
    if (st == LM_OK)
        st = size_scratch(ph, err);
    if (st != LM_OK) { /* the new groups trace nothing: no photons */
        for (uint32_t i = old; i < old + G; i++)
            ph->groups[i].photons = 0;
        return st;
    }
    return lm_photons_invalidate_emitter(ph, (int)E, err);
}

void lm_photons_scale_materials(lm_photons *ph, const float *ratio, int materials, uint8_t *touched)
{
    const int *tri_material = ph->scene->tri_material;
    for (uint32_t gi = 0; gi < ph->group_count; gi++) {
        const ph_group *g = &ph->groups[gi];
        int extreme = 0;
        for (uint32_t m = 0; g->offsets && m < g->photons; m++) {
            double w[3] = {1.0, 1.0, 1.0}; /* what the bounces so far on recoloured materials multiply */
            int any = 0;
            for (uint32_t i = g->offsets[m]; i < g->offsets[m + 1]; i++) {
                const lm_path_vertex *v = &g->verts[i];
                const lm_hit *h = any ? lm_photon_store_live(&ph->store, v->slot) : NULL;
                if (h) { /* a double past FLT_MAX has no float: clamped before the conversion */
                    float s[3] = {(float)fmin(w[0], FLT_MAX), (float)fmin(w[1], FLT_MAX), (float)fmin(w[2], FLT_MAX)};
                    touched[h->surface] = 1;
                    lm_photon_store_scale(&ph->store, v->slot, s);
                }
                int mat = tri_material[v->tri];
                const float *r = mat >= 0 && mat < materials ? ratio + 3 * (size_t)mat : NULL;
                if (!r || (r[0] == 1.0f && r[1] == 1.0f && r[2] == 1.0f))
                    continue;
                any = 1;
                for (int c = 0; c < 3; c++) {
                    w[c] *= r[c];
                    extreme |= w[c] > 0.0 && !(w[c] >= PH_SCALE_LEAST && w[c] <= 1.0 / PH_SCALE_LEAST);
                }
            }
        }
        if (extreme) /* its hits' flux has lost its digits, or soon would: traced again from the colours */
            mark_invalid(ph, gi);
    }
}

uint32_t lm_photons_invalidate_materials(lm_photons *ph, const uint8_t *materials)
{
    uint32_t n = 0;
    for (uint32_t gi = 0; gi < ph->group_count; gi++) {
        const ph_group *g = &ph->groups[gi];
        uint32_t end = g->photons && g->offsets ? g->offsets[g->photons] : 0;
        for (uint32_t i = 0; i < end; i++)
            if (materials[ph->scene->tri_material[g->verts[i].tri]]) {
                mark_invalid(ph, gi);
                n++;
                break;
            }
    }
    return n;
}

static void finish_stats(const lm_photons *ph, lm_photon_frame_stats *st, double t0)
{
    st->pending_groups = ph->queue_len;
    st->seconds = lm_now() - t0;
}

/* Which photons' stored paths cross one of the n boxes, in valid groups: met[first[g] + m] for photon m of
 * group g (first: group_count + 1 offsets, computed here); with `whole`, a group's test stops at its first
 * such photon (all its photons are re-traced anyway). Returns how many met one (with whole, at most one a
 * group), or UINT32_MAX when memory ran out (then nothing is allocated). */
static uint32_t paths_meeting(const lm_photons *ph, const float *boxes, int n, int whole, uint8_t **met,
                              uint32_t **first)
{
    *first = malloc(sizeof **first * ((size_t)ph->group_count + 1));
    float *padded = malloc(sizeof *padded * 6 * (size_t)n);
    uint64_t photons = 0;
    for (uint32_t gi = 0; *first && gi < ph->group_count; gi++)
        (*first)[gi] = (uint32_t)photons, photons += ph->groups[gi].photons;
    *met = *first ? calloc(photons ? photons : 1, 1) : NULL;
    if (!*met || !padded) {
        free(*met);
        free(*first);
        free(padded);
        return UINT32_MAX;
    }
    (*first)[ph->group_count] = (uint32_t)photons;
    for (int k = 0; k < 6 * n; k++) /* a hit on the node's face lies on its box: rounding must not lose it */
        padded[k] = boxes[k] + (k % 6 < 3 ? -ph->epsilon : ph->epsilon);
    uint32_t count = 0;
#pragma omp parallel for schedule(dynamic, 1) reduction(+ : count)
    for (uint32_t gi = 0; gi < ph->group_count; gi++) {
        const ph_group *g = &ph->groups[gi];
        uint8_t *mine = *met + (*first)[gi];
        int found = 0;
        for (uint32_t m = 0; !g->invalid && g->offsets && m < g->photons && !(whole && found); m++)
            found |= mine[m] = (uint8_t)ph_path_meets_boxes(ph, g, m, padded, n);
        for (uint32_t m = 0; m < g->photons; m++)
            count += mine[m];
    }
    free(padded);
    return count;
}

/* Queues, in group order, every group with a photon flagged in met; returns how many. */
static uint32_t queue_met(lm_photons *ph, const uint8_t *met, const uint32_t *first)
{
    uint32_t count = 0;
    for (uint32_t gi = 0; gi < ph->group_count; gi++) /* in group order: the queue's order is the same */
        for (uint32_t i = first[gi]; i < first[gi + 1]; i++)
            if (met[i]) { /* not counted in the group's invalidations: those are the round robin's */
                mark_invalid(ph, gi);
                count++;
                break;
            }
    return count;
}

uint32_t lm_photons_invalidate_boxes(lm_photons *ph, const float *boxes, int n)
{
    uint8_t *met;
    uint32_t *first;
    if (n <= 0 || paths_meeting(ph, boxes, n, 1, &met, &first) == UINT32_MAX)
        return 0; /* out of memory: the round robin still finds them, later */
    uint32_t count = queue_met(ph, met, first);
    free(met);
    free(first);
    return count;
}

/* The photons a frame's group budget re-traces: the budget's groups at the mean photons a group (every
 * photon without a budget). */
static uint64_t budget_photons(const lm_photons *ph)
{
    uint32_t groups = ph->frame_groups ? ph->frame_groups : ph->set.group_budget;
    return groups && ph->group_count ? (uint64_t)groups * ph->photon_count / ph->group_count : ph->photon_count;
}

/* Traces the flagged photons and applies them group by group, in group and photon order. */
static lm_status retrace_met(lm_photons *ph, const uint8_t *met, const uint32_t *first, lm_photon_frame_stats *st,
                             lm_error *err)
{
    ph_batch *b = &ph->batches[0];
    ph_batch_clear(b);
    for (uint32_t gi = 0; gi < ph->group_count; gi++)
        for (uint32_t i = first[gi]; i < first[gi + 1]; i++)
            if (met[i] && !ph_batch_push(b, gi, i - first[gi]))
                return lm_fail(err, LM_ERR_NOMEM, "photons: no memory for the trace list");
    lm_status s = ph_trace_batch(ph, b, err);
    st->rays += b->rays;
    st->box_photons += b->count;
    if (s != LM_OK)
        return s;
    uint64_t stored = 0;
    for (uint32_t k = 0; k < b->count; k++)
        stored += b->jobs[k].stored;
    lm_photon_store_reserve(&ph->store, stored); /* one growth (if it fails, adds fail one by one) */
    for (uint32_t k = 0; k < b->count && s == LM_OK;) {
        uint32_t end = k;
        while (end < b->count && b->jobs[end].group == b->jobs[k].group)
            end++;
        s = ph_group_apply_some(ph, &ph->groups[b->jobs[k].group], b, &b->jobs[k], end - k, st, err);
        k = end;
    }
    return s;
}

lm_status lm_photons_retrace_boxes(lm_photons *ph, const float *boxes, int n, lm_photon_frame_stats *stats,
                                   lm_error *err)
{
    lm_photon_frame_stats local;
    lm_photon_frame_stats *st = stats ? stats : &local;
    memset(st, 0, sizeof *st);
    double t0 = lm_now();
    uint8_t *met;
    uint32_t *first;
    lm_status s = LM_OK;
    uint32_t count = n > 0 ? paths_meeting(ph, boxes, n, 0, &met, &first) : UINT32_MAX;
    if (count != UINT32_MAX) { /* else none met, or no memory to test them: the round robin finds them later */
        if (count > budget_photons(ph)) {
            queue_met(ph, met, first); /* more than a frame's budget: their groups wait their turn */
        } else if (count > 0) {
            s = retrace_met(ph, met, first, st, err);
            ph->box_groups += (uint32_t)(((uint64_t)count * ph->group_count + ph->photon_count - 1) /
                                         ph->photon_count); /* whole groups' worth, rounded up */
        }
        free(met);
        free(first);
    }
    finish_stats(ph, st, t0);
    return s;
}

/* ---- re-tracing groups: trace in parallel, apply serially in group and photon order ---- */

/* 1 if group g fits in batch b (a batch always takes at least one group). */
static int batch_fits(const lm_photons *ph, const ph_batch *b, uint32_t g)
{
    return b->count == 0 || b->count + ph->groups[g].photons <= PH_BATCH_PHOTONS;
}

lm_status ph_fill_batch(lm_photons *ph, ph_batch *b, const uint32_t *list, uint32_t n, uint32_t *i,
                        lm_photon_frame_stats *st, lm_error *err)
{
    ph_batch_clear(b);
    for (; *i < n && batch_fits(ph, b, list[*i]); ++*i) {
        ph_group *g = &ph->groups[list[*i]];
        if (!ph_batch_push_group(b, list[*i], g->photons))
            return lm_fail(err, LM_ERR_NOMEM, "photons: no memory for the trace list");
        g->retraces++;
        st->groups_retraced++;
        st->group_photons += g->photons;
    }
    return LM_OK;
}

lm_status lm_photons_trace_all(lm_photons *ph, lm_photon_frame_stats *stats, lm_error *err)
{
    lm_photon_frame_stats local;
    lm_photon_frame_stats *st = stats ? stats : &local;
    memset(st, 0, sizeof *st);
    double t0 = lm_now();
    while (ph->queue_len)
        pop_invalid(ph);
    for (uint32_t g = 0; g < ph->group_count; g++)
        ph->tmp_groups[g] = g;
    lm_status s = ph->split.shares > 1 ? ph_trace_groups_split(ph, ph->tmp_groups, ph->group_count, st, err)
                                       : ph_trace_groups(ph, ph->tmp_groups, ph->group_count, st, err);
    finish_stats(ph, st, t0);
    return s;
}

lm_status lm_photons_trace_all_exact(lm_photons *ph, lm_photon_frame_stats *stats, lm_error *err)
{
    ph->exact = 1;
    lm_status s = lm_photons_trace_all(ph, stats, err);
    ph->exact = 0;
    return s;
}

uint32_t lm_photons_release_emitter(lm_photons *ph, int e)
{
    uint32_t waiting = 0;
    if (e < 0 || (uint32_t)e >= ph->emitter_count)
        return 0;
    for (uint32_t k = 0; k < ph->G; k++) {
        ph_group *g = &ph->groups[(uint32_t)e * ph->G + k];
        if (g->photons == 0) /* released before, or never had any */
            continue;
        if (g->invalid || g->offsets[g->photons] != 0) { /* its dark re-trace has not emptied it yet */
            waiting += g->photons > 0;
            continue;
        }
        uint32_t *none = calloc(1, sizeof *none); /* offsets[0] = 0: a group of no photons */
        if (!none)
            return waiting + 1;
        ph_group_free(g);
        g->offsets = none;
        g->photons = 0;
        g->rr_next = 0;
    }
    return waiting;
}

void lm_photons_set_split(lm_photons *ph, const lm_photon_split *split)
{
    memset(&ph->split, 0, sizeof ph->split);
    if (split && split->shares > 1 && split->share < split->shares && split->exchange)
        ph->split = *split;
}

/* Round robin (section 2): k photons of every valid group are re-traced and compared with their
 * stored paths; any difference marks the group invalid. */
static lm_status round_robin(lm_photons *ph, lm_photon_frame_stats *st, lm_error *err)
{
    ph_batch *b = &ph->batches[0];
    ph_batch_clear(b);
    for (uint32_t i = 0; i < ph->group_count; i++) {
        ph_group *g = &ph->groups[i];
        if (g->invalid || g->photons == 0)
            continue;
        uint32_t k = ph->set.retrace_per_group < g->photons ? ph->set.retrace_per_group : g->photons;
        for (uint32_t r = 0; r < k; r++)
            if (!ph_batch_push(b, i, (g->rr_next + r) % g->photons))
                return lm_fail(err, LM_ERR_NOMEM, "photons: no memory for the trace list");
        g->rr_next = (g->rr_next + k) % g->photons;
    }
    st->rr_photons = b->count;
    lm_status s = ph_trace_batch(ph, b, err);
    st->rays += b->rays;
    if (s != LM_OK)
        return s;
    for (uint32_t k = 0; k < b->count; k++) {
        const ph_job *j = &b->jobs[k];
        ph_group *g = &ph->groups[j->group];
        if (!ph_path_changed(ph, g, j->m, ph_job_vertices(b, j), j->count))
            continue;
        st->paths_changed++;
        if (!g->invalid) {
            mark_invalid(ph, j->group);
            g->invalidations++;
            st->groups_invalidated++;
        }
    }
    return LM_OK;
}

/* Re-traces up to `most` invalid groups (0: all), oldest first. */
static lm_status drain(lm_photons *ph, uint32_t most, lm_photon_frame_stats *st, lm_error *err)
{
    uint32_t n = ph->queue_len;
    if (most && most < n)
        n = most;
    for (uint32_t i = 0; i < n; i++)
        ph->tmp_groups[i] = pop_invalid(ph);
    return ph_trace_groups(ph, ph->tmp_groups, n, st, err);
}

/* The round robin (with anything_moves), then up to `most` queued groups (0: all), counted in stats. */
static lm_status step(lm_photons *ph, int anything_moves, uint32_t most, lm_photon_frame_stats *stats,
                      lm_error *err)
{
    lm_photon_frame_stats local;
    lm_photon_frame_stats *st = stats ? stats : &local;
    memset(st, 0, sizeof *st);
    double t0 = lm_now();
    lm_status s = anything_moves ? round_robin(ph, st, err) : LM_OK;
    if (s == LM_OK)
        s = drain(ph, most, st, err);
    finish_stats(ph, st, t0);
    return s;
}

lm_status lm_photons_frame(lm_photons *ph, int anything_moves, lm_photon_frame_stats *stats, lm_error *err)
{
    uint32_t most = ph->set.group_budget;
    if (ph->frame_groups) /* a time budget's count, less what the boxes' photons took of it (at least one) */
        most = ph->frame_groups > ph->box_groups ? ph->frame_groups - ph->box_groups : 1;
    ph->box_groups = 0;
    return step(ph, anything_moves, most, stats, err);
}

lm_status lm_photons_drain_all(lm_photons *ph, lm_photon_frame_stats *stats, lm_error *err)
{
    return step(ph, 0, 0, stats, err);
}

void lm_photons_limit_groups(lm_photons *ph, uint32_t most) { ph->frame_groups = most; }

/* ---- accessors ---- */

const lm_photon_store *lm_photons_store(const lm_photons *ph) { return &ph->store; }
lm_photon_store *lm_photons_store_mutable(lm_photons *ph) { return &ph->store; }
uint32_t lm_photons_count(const lm_photons *ph) { return ph->photon_count; }
uint32_t lm_photons_group_count(const lm_photons *ph) { return ph->group_count; }
uint32_t lm_photons_groups_per_emitter(const lm_photons *ph) { return ph->G; }
uint32_t lm_photons_stored_hits(const lm_photons *ph) { return ph->live_hits; }
uint32_t lm_photons_pending_groups(const lm_photons *ph) { return ph->queue_len; }

uint32_t lm_photons_emitter_photons(const lm_photons *ph, int e)
{
    if (e < 0 || (uint32_t)e >= ph->emitter_count)
        return 0;
    return ph->emitter_first[e + 1] - ph->emitter_first[e];
}

void lm_photons_group_info(const lm_photons *ph, uint32_t group, lm_photon_group_info *out)
{
    memset(out, 0, sizeof *out);
    out->emitter = -1;
    if (group >= ph->group_count)
        return;
    const ph_group *g = &ph->groups[group];
    out->emitter = g->emitter;
    out->index = g->index;
    out->photons = g->photons;
    out->invalid = g->invalid;
    out->invalidations = g->invalidations;
    out->retraces = g->retraces;
}

/* Emitter owning photon id (binary search over the first ids), or -1. */
static int emitter_of(const lm_photons *ph, uint32_t photon)
{
    if (photon >= ph->photon_count)
        return -1;
    uint32_t lo = 0, hi = ph->emitter_count;
    while (hi - lo > 1) {
        uint32_t mid = (lo + hi) / 2;
        if (ph->emitter_first[mid] <= photon)
            lo = mid;
        else
            hi = mid;
    }
    return (int)lo;
}

uint32_t lm_photons_group_of(const lm_photons *ph, uint32_t photon)
{
    int e = emitter_of(ph, photon);
    if (e < 0)
        return LM_NONE;
    return (uint32_t)e * ph->G + (photon - ph->emitter_first[e]) % ph->G;
}

uint32_t lm_photons_path(const lm_photons *ph, uint32_t photon, const lm_path_vertex **vertices)
{
    *vertices = NULL;
    int e = emitter_of(ph, photon);
    if (e < 0)
        return 0;
    uint32_t j = photon - ph->emitter_first[e];
    const ph_group *g = &ph->groups[(uint32_t)e * ph->G + j % ph->G];
    uint32_t m = j / ph->G;
    if (m >= g->photons) /* a released emitter's (lm_photons_release_emitter) */
        return 0;
    *vertices = g->verts ? g->verts + g->offsets[m] : NULL;
    return g->offsets[m + 1] - g->offsets[m];
}

void lm_photons_first_hit_flux(const lm_photons *ph, double *out)
{
    const lm_photon_store *ps = &ph->store;
    for (int s = 0; s < ps->surface_count; s++) {
        double sum[3] = {0, 0, 0};
        for (uint32_t k = 0; k < ps->surfaces[s].count; k++) {
            const lm_hit *h = &ps->hits[ps->surfaces[s].slots[k]];
            if (h->bounce == 0)
                for (int c = 0; c < 3; c++)
                    sum[c] += h->flux[c];
        }
        for (int c = 0; c < 3; c++)
            out[3 * s + c] = sum[c];
    }
}

void lm_photons_memory(const lm_photons *ph, lm_photon_memory *out)
{
    memset(out, 0, sizeof *out);
    uint64_t verts = 0;
    for (uint32_t i = 0; i < ph->group_count; i++) {
        out->path_bytes += ph_group_bytes(&ph->groups[i]);
        verts += ph->groups[i].offsets[ph->groups[i].photons];
    }
    out->store_bytes = (size_t)ph->store.capacity * lm_photon_store_bytes(&ph->store) +
                       (size_t)ph->store.surface_count * sizeof *ph->store.surfaces;
    size_t scratch = (size_t)ph->tmp_cap * sizeof *ph->tmp_verts;
    for (int k = 0; k < 2; k++) {
        const ph_batch *b = &ph->batches[k];
        scratch += (size_t)b->cap * sizeof(ph_job);
        for (int t = 0; t < b->buffer_count; t++)
            scratch += b->buffers[t].cap * sizeof(ph_vertex);
    }
    out->other_bytes = sizeof *ph + (size_t)ph->group_count * (sizeof(ph_group) + 2 * sizeof(uint32_t)) +
                       ((size_t)ph->emitter_count + 1) * sizeof(uint32_t) + scratch;
    out->total_bytes = out->path_bytes + out->store_bytes + out->other_bytes;
    double n = ph->photon_count ? ph->photon_count : 1;
    out->per_photon = out->total_bytes / n;
    out->mean_path_vertices = verts / n;
    out->mean_hits = ph->live_hits / n;
    out->live_per_photon = sizeof(uint32_t) + 4 * sizeof(float) /* offset, emission numbers */ +
                           out->mean_path_vertices * sizeof(lm_path_vertex) + out->mean_hits * sizeof(lm_hit);
}
