/* A full photon trace shared among processes (photons.h, lm_photon_split; docs/farm.md).
 *
 * Why it gives every process the one-process store: a photon's path depends on its QMC numbers and the
 * scene alone, never on which process or thread traced it, and the store changes only when a batch is
 * applied, in batch order (ph_apply_batch). So each process traces its share of a batch, the shares are
 * exchanged, and every process applies the whole batch as one process would have. The batches are the
 * one-process trace's (ph_fill_batch over the same list), so the store slots come out the same too.
 *
 * A process's bytes for a batch: for each job it traced, in batch order, a record (job index, vertex
 * count, rays, stored hits: four u32) and its vertices (ph_vertex, as this build lays them out: every
 * process runs the same build). */
#include <stdlib.h>
#include <string.h>

#include "photons_internal.h"

typedef struct {
    uint32_t job, count, rays, stored;
} record;

/* The jobs this process traced in b, packed; *size their bytes. NULL: no memory. */
static unsigned char *pack_own(const ph_batch *b, size_t *size)
{
    size_t n = 0;
    for (uint32_t i = 0; i < b->count; i++)
        if ((b->first_photon + i) % b->shares == b->share)
            n += sizeof(record) + b->jobs[i].count * sizeof(ph_vertex);
    unsigned char *out = malloc(n ? n : 1), *at = out;
    for (uint32_t i = 0; out && i < b->count; i++) {
        const ph_job *j = &b->jobs[i];
        if ((b->first_photon + i) % b->shares != b->share)
            continue;
        record r = {i, j->count, j->rays, j->stored};
        memcpy(at, &r, sizeof r);
        memcpy(at + sizeof r, ph_job_vertices(b, j), j->count * sizeof(ph_vertex));
        at += sizeof r + j->count * sizeof(ph_vertex);
    }
    *size = n;
    return out;
}

/* Appends n vertices to buffer 0 of b; returns their first index, or -1 without memory. */
static long append_vertices(ph_batch *b, const unsigned char *v, uint32_t n)
{
    ph_buffer *buf = &b->buffers[0];
    if (buf->len + n > buf->cap) {
        size_t cap = buf->cap ? buf->cap : 1024;
        while (cap < buf->len + n)
            cap *= 2;
        ph_vertex *grown = realloc(buf->v, cap * sizeof *grown);
        if (!grown)
            return -1;
        buf->v = grown, buf->cap = cap;
    }
    if (n) /* a path of no vertices: the buffer may not exist yet, and memcpy takes no NULL even for 0 bytes */
        memcpy(buf->v + buf->len, v, n * sizeof(ph_vertex));
    buf->len += n;
    return (long)(buf->len - n);
}

/* The other processes' records of `all` (process p's sizes[p] bytes back to back) put into b's jobs. */
static lm_status unpack_others(ph_batch *b, const unsigned char *all, const size_t *sizes, lm_error *err)
{
    const unsigned char *at = all;
    for (uint32_t p = 0; p < b->shares; at += sizes[p], p++) {
        if (p == b->share)
            continue;
        for (size_t used = 0; used < sizes[p];) {
            record r;
            memcpy(&r, at + used, sizeof r);
            size_t bytes = sizeof r + (size_t)r.count * sizeof(ph_vertex);
            if (r.job >= b->count || (b->first_photon + r.job) % b->shares != p || used + bytes > sizes[p])
                return lm_fail(err, LM_ERR_BACKEND, "photons: process %u sent paths that are not its share", p);
            long first = append_vertices(b, at + used + sizeof r, r.count);
            if (first < 0)
                return lm_fail(err, LM_ERR_NOMEM, "photons: no memory for the exchanged paths");
            ph_job *j = &b->jobs[r.job];
            j->buffer = 0, j->first = (uint32_t)first, j->count = r.count, j->rays = r.rays, j->stored = r.stored;
            used += bytes;
        }
    }
    return LM_OK;
}

/* Every process's share of b exchanged, and the others' put into b. */
static lm_status exchange(lm_photons *ph, ph_batch *b, lm_error *err)
{
    const lm_photon_split *sp = &ph->split;
    size_t size = 0, total = 0;
    size_t *sizes = calloc(sp->shares, sizeof *sizes);
    unsigned char *mine = pack_own(b, &size), *all = NULL;
    lm_status st = sizes && mine ? LM_OK : lm_fail(err, LM_ERR_NOMEM, "photons: no memory for the exchange");
    if (st == LM_OK && !sp->exchange(sp->user, mine, size, sizes, NULL))
        st = lm_fail(err, LM_ERR_BACKEND, "photons: the exchange of path sizes among %u processes failed", sp->shares);
    for (uint32_t p = 0; st == LM_OK && p < sp->shares; p++)
        total += sizes[p];
    if (st == LM_OK && !(all = malloc(total ? total : 1)))
        st = lm_fail(err, LM_ERR_NOMEM, "photons: no memory for %zu bytes of exchanged paths", total);
    if (st == LM_OK && !sp->exchange(sp->user, mine, size, sizes, all))
        st = lm_fail(err, LM_ERR_BACKEND, "photons: the exchange of paths among %u processes failed", sp->shares);
    if (st == LM_OK)
        st = unpack_others(b, all, sizes, err);
    free(sizes);
    free(mine);
    free(all);
    return st;
}

lm_status ph_trace_groups_split(lm_photons *ph, const uint32_t *list, uint32_t n, lm_photon_frame_stats *st,
                                lm_error *err)
{
    ph_batch *b = &ph->batches[0];
    uint64_t photon = 0; /* photon k of the trace is process k mod shares' */
    lm_status s = LM_OK;
    for (uint32_t i = 0; s == LM_OK && i < n;) {
        s = ph_fill_batch(ph, b, list, n, &i, st, err);
        if (s != LM_OK || b->count == 0)
            break;
        b->share = ph->split.share, b->shares = ph->split.shares, b->first_photon = photon;
        s = ph_trace_batch(ph, b, err);
        if (s == LM_OK)
            s = exchange(ph, b, err);
        b->rays = 0;
        for (uint32_t k = 0; k < b->count; k++)
            b->rays += b->jobs[k].rays;
        st->rays += b->rays;
        if (s == LM_OK)
            s = ph_apply_batch(ph, b, st, err);
        photon += b->count;
    }
    b->shares = 0;
    return s;
}
