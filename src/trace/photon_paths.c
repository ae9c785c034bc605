/* Stored photon paths (Larsen & Christensen 2004, section 2): every photon's (node, triangle)
 * vertices, hit points and the store slots of its hits, so a changed path is found by comparison
 * and its hits are removed in O(1) each. A group's paths lie back to back in one slab, rebuilt when
 * the group is re-traced (only re-traced groups change paths). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../core/prefault.h"
#include "../core/vecmath.h"
#include "photons_internal.h"

/* Relative flux change that counts as a different path (a light or material edit). */
#define PH_FLUX_TOLERANCE 1e-4f

const ph_vertex *ph_job_vertices(const ph_batch *b, const ph_job *j)
{
    return b->buffers[j->buffer].v + j->first;
}

static float dist2(const float a[3], const float b[3])
{
    float dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
    return dx * dx + dy * dy + dz * dz;
}

static int flux_changed(const float a[3], const float b[3])
{
    float scale = 0.0f;
    for (int c = 0; c < 3; c++)
        scale = fmaxf(scale, fmaxf(fabsf(a[c]), fabsf(b[c])));
    for (int c = 0; c < 3; c++)
        if (fabsf(a[c] - b[c]) > PH_FLUX_TOLERANCE * scale)
            return 1;
    return 0;
}

/* A stored hit still matches a new vertex if its node-local point, placed by the node's current
 * matrix, lies within epsilon (a moved node carries its hits along) and its flux is the same. */
static int hit_changed(const lm_photons *ph, const lm_hit *h, const ph_vertex *v, float eps2)
{
    lm_vec3 p = lm_mat4_point(ph->scene->nodes[v->node].world, lm_v3_load(h->local));
    float placed[3];
    lm_v3_store(placed, p);
    return dist2(placed, v->pos) > eps2 || flux_changed(h->flux, v->flux);
}

/* The stored hit is the new vertex's to the bit. */
static int hit_differs(const lm_hit *h, const ph_vertex *v)
{
    return memcmp(h->pos, v->pos, sizeof h->pos) || memcmp(h->local, v->local, sizeof h->local) ||
           memcmp(h->dir, v->dir, sizeof h->dir) || memcmp(h->flux, v->flux, sizeof h->flux) ||
           memcmp(&h->travelled, &v->travelled, sizeof h->travelled) || h->tri != v->tri || h->bounce != v->bounce ||
           h->caustic != v->caustic;
}

int ph_path_changed(const lm_photons *ph, const ph_group *g, uint32_t m, const ph_vertex *v, uint32_t n)
{
    uint32_t first = g->offsets[m];
    if (g->offsets[m + 1] - first != n)
        return 1;
    float eps2 = ph->epsilon * ph->epsilon;
    for (uint32_t i = 0; i < n; i++) {
        const lm_path_vertex *p = &g->verts[first + i];
        if (p->node != v[i].node || p->tri != v[i].tri || dist2(p->pos, v[i].pos) > eps2 ||
            (ph->exact && memcmp(p->pos, v[i].pos, sizeof p->pos)))
            return 1;
        int stored = v[i].surface >= 0;
        if (stored != (p->slot != LM_NONE))
            return 1;
        const lm_hit *h = stored ? &ph->store.hits[p->slot] : NULL;
        if (h && (ph->exact ? hit_differs(h, &v[i]) : hit_changed(ph, h, &v[i], eps2)))
            return 1;
    }
    return 0;
}

/* Whether the segment a -> b crosses the box (slabs clipped to the segment's [0, 1]). */
static int segment_meets_box(const float a[3], const float b[3], const float box[6])
{
    float t0 = 0.0f, t1 = 1.0f;
    for (int k = 0; k < 3; k++) {
        float d = b[k] - a[k];
        if (d == 0.0f) {
            if (a[k] < box[k] || a[k] > box[3 + k])
                return 0;
            continue;
        }
        float n = (box[k] - a[k]) / d, f = (box[3 + k] - a[k]) / d;
        if (n > f) {
            float x = n;
            n = f, f = x;
        }
        t0 = n > t0 ? n : t0;
        t1 = f < t1 ? f : t1;
        if (t0 > t1)
            return 0;
    }
    return 1;
}

int ph_path_meets_boxes(const lm_photons *ph, const ph_group *g, uint32_t m, const float *boxes, int n)
{
    uint32_t first = g->offsets[m], end = g->offsets[m + 1];
    if (first == end)
        return 0;
    lm_emission emi;
    uint32_t count = ph->emitter_first[g->emitter + 1] - ph->emitter_first[g->emitter];
    lm_emitter_emit_placed(ph->em, ph->scene, g->emitter, NULL, g->emit_u + PH_EMIT_DIMS * (size_t)m, count, &emi);
    const float *from = emi.org;
    for (uint32_t i = first; i < end; i++) {
        const float *to = g->verts[i].pos;
        for (int k = 0; k < n; k++)
            if (segment_meets_box(from, to, boxes + 6 * k))
                return 1;
        from = to;
    }
    return 0;
}

/* Grows *verts to hold need vertices: doubling for scratch, exactly for a group's slab (rebuilt
 * only when the group is re-traced, so slack would just be kept memory). */
static int reserve_verts(lm_path_vertex **verts, uint32_t *cap, uint32_t need, int exact)
{
    if (need <= *cap)
        return 1;
    uint32_t n = exact ? need : (*cap ? *cap : 64);
    while (n < need)
        n *= 2;
    lm_path_vertex *v = realloc(*verts, (size_t)n * sizeof *v);
    if (!v)
        return 0;
    lm_prefault(v + *cap, (size_t)(n - *cap) * sizeof *v); /* about to be written: map it in at once */
    *verts = v;
    *cap = n;
    return 1;
}

static uint32_t store_vertex(lm_photons *ph, const ph_vertex *v, uint32_t photon, int source)
{
    uint32_t slot;
    lm_hit *h = lm_photon_store_claim(&ph->store, v->surface, &slot); /* filled in place */
    if (!h)
        return LM_NONE;
    memcpy(h->pos, v->pos, sizeof h->pos);
    memcpy(h->local, v->local, sizeof h->local);
    memcpy(h->dir, v->dir, sizeof h->dir);
    memcpy(h->flux, v->flux, sizeof h->flux);
    h->travelled = v->travelled;
    h->photon = photon;
    h->tri = v->tri;
    h->bounce = v->bounce;
    h->source = (uint8_t)source;
    h->caustic = v->caustic;
    lm_photon_store_link(&ph->store, slot);
    return slot;
}

/* Removes photon m's old hits and writes its new path (with new hits) at out. Returns 0 if a hit
 * could not be stored (that vertex then keeps no slot, so the next check re-traces it). */
static int replace_path(lm_photons *ph, const ph_group *g, uint32_t m, const ph_vertex *v, uint32_t n,
                        lm_path_vertex *out, lm_photon_frame_stats *st)
{
    for (uint32_t i = g->offsets[m]; i < g->offsets[m + 1]; i++)
        if (g->verts[i].slot != LM_NONE) {
            lm_photon_store_remove(&ph->store, g->verts[i].slot);
            ph->live_hits--;
            st->hits_removed++;
        }
    uint32_t photon = g->first_id + m * ph->G;
    const lm_emitter *em = &ph->em->e[g->emitter];
    int source = em->kind == LM_EMIT_DIRECTIONAL ? LM_HIT_FROM_SUN
                 : em->punctual                  ? LM_HIT_FROM_PUNCTUAL
                 : em->kind == LM_EMIT_SKY       ? LM_HIT_FROM_SKY
                                                 : LM_HIT_FROM_AREA,
        ok = 1;
    for (uint32_t i = 0; i < n; i++) {
        out[i].node = v[i].node;
        out[i].tri = v[i].tri;
        memcpy(out[i].pos, v[i].pos, sizeof out[i].pos);
        out[i].slot = LM_NONE;
        if (v[i].surface < 0)
            continue;
        out[i].slot = store_vertex(ph, &v[i], photon, source);
        if (out[i].slot == LM_NONE) {
            ok = 0;
            continue;
        }
        ph->live_hits++;
        st->hits_added++;
    }
    st->photons_updated++;
    return ok;
}

/* Flags changed photons and sizes the new slab; reserves all memory before the store is touched. */
static int prepare_apply(lm_photons *ph, ph_group *g, const ph_batch *b, const ph_job *jobs, uint32_t *total)
{
    *total = 0;
    for (uint32_t m = 0; m < g->photons; m++) {
        const ph_job *j = &jobs[m];
        ph->tmp_changed[m] = (uint8_t)ph_path_changed(ph, g, m, ph_job_vertices(b, j), j->count);
        *total += j->count; /* an unchanged path has the same length */
    }
    return reserve_verts(&ph->tmp_verts, &ph->tmp_cap, *total, 0) &&
           reserve_verts(&g->verts, &g->vert_cap, *total, 1);
}

static lm_status fail_store(const ph_group *g, lm_error *err)
{
    return lm_fail(err, LM_ERR_NOMEM, "photons: no memory to store the hits of group %u of emitter %d",
                   g->index, g->emitter);
}

static lm_status fail_paths(const ph_group *g, lm_error *err)
{
    return lm_fail(err, LM_ERR_NOMEM, "photons: no memory for the paths of group %u of emitter %d", g->index,
                   g->emitter);
}

/* A group that holds no vertices (never traced, or every path empty) has nothing to compare with and
 * no hits to remove: every non-empty path is new (as ph_path_changed would say) and goes straight
 * into the slab, with no scratch copy. */
static lm_status apply_fresh(lm_photons *ph, ph_group *g, const ph_batch *b, const ph_job *jobs,
                             lm_photon_frame_stats *st, lm_error *err)
{
    uint32_t total = 0;
    for (uint32_t m = 0; m < g->photons; m++)
        total += jobs[m].count;
    if (!reserve_verts(&g->verts, &g->vert_cap, total, 1))
        return fail_paths(g, err);
    int ok = 1;
    uint32_t at = 0;
    for (uint32_t m = 0; m < g->photons; m++) {
        const ph_job *j = &jobs[m];
        g->offsets[m] = at;
        if (j->count) /* replace_path reads only offsets[m .. m + 1], both still 0 */
            ok &= replace_path(ph, g, m, ph_job_vertices(b, j), j->count, g->verts + at, st);
        at += j->count;
    }
    g->offsets[g->photons] = at;
    return ok ? LM_OK : fail_store(g, err);
}

lm_status ph_group_apply(lm_photons *ph, ph_group *g, const ph_batch *b, const ph_job *jobs,
                         lm_photon_frame_stats *st, lm_error *err)
{
    if (g->offsets[g->photons] == 0)
        return apply_fresh(ph, g, b, jobs, st, err);
    uint32_t total;
    if (!prepare_apply(ph, g, b, jobs, &total))
        return fail_paths(g, err);
    int ok = 1;
    uint32_t at = 0;
    for (uint32_t m = 0; m < g->photons; m++) {
        ph->tmp_offsets[m] = at;
        const ph_job *j = &jobs[m];
        if (ph->tmp_changed[m])
            ok &= replace_path(ph, g, m, ph_job_vertices(b, j), j->count, ph->tmp_verts + at, st);
        else if (j->count) /* an empty path may have no slab at all */
            memcpy(ph->tmp_verts + at, g->verts + g->offsets[m], (size_t)j->count * sizeof *g->verts);
        at += j->count;
    }
    ph->tmp_offsets[g->photons] = at;
    if (total)
        memcpy(g->verts, ph->tmp_verts, (size_t)total * sizeof *g->verts);
    memcpy(g->offsets, ph->tmp_offsets, ((size_t)g->photons + 1) * sizeof *g->offsets);
    return ok ? LM_OK : fail_store(g, err);
}

/* The job of photon m among jobs[*k ..] (sorted by m), advancing *k; NULL when m has none. */
static const ph_job *job_of(const ph_job *jobs, uint32_t n, uint32_t *k, uint32_t m)
{
    while (*k < n && jobs[*k].m < m)
        ++*k;
    return *k < n && jobs[*k].m == m ? &jobs[*k] : NULL;
}

lm_status ph_group_apply_some(lm_photons *ph, ph_group *g, const ph_batch *b, const ph_job *jobs, uint32_t n,
                              lm_photon_frame_stats *st, lm_error *err)
{
    memset(ph->tmp_changed, 0, g->photons);
    uint32_t changed = 0;
    for (uint32_t k = 0; k < n; k++) {
        const ph_job *j = &jobs[k];
        ph->tmp_changed[j->m] = (uint8_t)ph_path_changed(ph, g, j->m, ph_job_vertices(b, j), j->count);
        changed += ph->tmp_changed[j->m];
    }
    if (!changed) /* the slab stays as it is */
        return LM_OK;
    uint32_t total = 0, k = 0;
    for (uint32_t m = 0; m < g->photons; m++) {
        const ph_job *j = job_of(jobs, n, &k, m);
        total += ph->tmp_changed[m] ? j->count : g->offsets[m + 1] - g->offsets[m];
    }
    if (!reserve_verts(&ph->tmp_verts, &ph->tmp_cap, total, 0) || !reserve_verts(&g->verts, &g->vert_cap, total, 1))
        return fail_paths(g, err);
    int ok = 1;
    uint32_t at = 0;
    k = 0;
    for (uint32_t m = 0; m < g->photons; m++) {
        const ph_job *j = job_of(jobs, n, &k, m);
        uint32_t len = ph->tmp_changed[m] ? j->count : g->offsets[m + 1] - g->offsets[m];
        ph->tmp_offsets[m] = at;
        if (ph->tmp_changed[m])
            ok &= replace_path(ph, g, m, ph_job_vertices(b, j), j->count, ph->tmp_verts + at, st);
        else if (len)
            memcpy(ph->tmp_verts + at, g->verts + g->offsets[m], (size_t)len * sizeof *g->verts);
        at += len;
    }
    ph->tmp_offsets[g->photons] = at;
    if (total)
        memcpy(g->verts, ph->tmp_verts, (size_t)total * sizeof *g->verts);
    memcpy(g->offsets, ph->tmp_offsets, ((size_t)g->photons + 1) * sizeof *g->offsets);
    return ok ? LM_OK : fail_store(g, err);
}

lm_status ph_apply_batch(lm_photons *ph, const ph_batch *b, lm_photon_frame_stats *st, lm_error *err)
{
    uint64_t stored = 0;
    for (uint32_t k = 0; k < b->count; k++)
        stored += b->jobs[k].stored;
    /* One growth for the whole batch instead of many doublings (if it fails, adds fail one by one). */
    lm_photon_store_reserve(&ph->store, stored);
    for (uint32_t k = 0; k < b->count;) {
        ph_group *g = &ph->groups[b->jobs[k].group];
        lm_status s = ph_group_apply(ph, g, b, &b->jobs[k], st, err);
        if (s != LM_OK)
            return s;
        k += g->photons;
    }
    return LM_OK;
}

void ph_group_free(ph_group *g)
{
    free(g->offsets);
    free(g->verts);
    free(g->emit_u);
    g->emit_u = NULL;
    g->offsets = NULL;
    g->verts = NULL;
    g->vert_cap = 0;
}

size_t ph_group_bytes(const ph_group *g)
{
    return ((size_t)g->photons + 1) * sizeof *g->offsets + (size_t)g->photons * 4 * sizeof *g->emit_u +
           (size_t)g->vert_cap * sizeof *g->verts;
}
