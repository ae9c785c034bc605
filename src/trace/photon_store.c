#include "photon_store.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../core/prefault.h"

lm_status lm_photon_store_init(lm_photon_store *ps, int surface_count, lm_error *err)
{
    memset(ps, 0, sizeof *ps);
    ps->free_head = LM_NONE;
    ps->surface_count = surface_count;
    ps->surfaces = calloc((size_t)(surface_count > 0 ? surface_count : 1), sizeof *ps->surfaces);
    if (!ps->surfaces)
        return lm_fail(err, LM_ERR_NOMEM, "photon store: no memory for %d surfaces", surface_count);
    lm_photon_store_clear(ps);
    return LM_OK;
}

void lm_photon_store_clear(lm_photon_store *ps)
{
    ps->version++;
    ps->used = 0;
    ps->free_head = LM_NONE;
    ps->free_count = 0;
    for (int i = 0; i < ps->surface_count; i++) {
        ps->surfaces[i].count = 0;
        ps->surfaces[i].delta_f = ps->surfaces[i].delta_i = ps->surfaces[i].energy = 0.0;
    }
}

void lm_photon_store_free(lm_photon_store *ps)
{
    for (int i = 0; ps->surfaces && i < ps->surface_count; i++)
        free(ps->surfaces[i].slots);
    free(ps->hits);
    free(ps->surfaces);
    memset(ps, 0, sizeof *ps);
    ps->free_head = LM_NONE;
}

/* Grows the slot array to at least `need` slots, doubling so that one-by-one adds stay O(1). */
static int grow(lm_photon_store *ps, uint64_t need)
{
    if (need <= ps->capacity)
        return 1;
    if (need > LM_NONE / 2) /* slot ids must stay below LM_NONE */
        return 0;
    uint64_t cap = ps->capacity ? ps->capacity : 1024;
    while (cap < need)
        cap *= 2;
    lm_hit *grown = realloc(ps->hits, sizeof *grown * cap);
    if (!grown)
        return 0;
    ps->hits = grown;
    ps->capacity = (uint32_t)cap;
    return 1;
}

int lm_photon_store_reserve(lm_photon_store *ps, uint64_t n)
{
    uint64_t past = n > ps->free_count ? n - ps->free_count : 0; /* the adds the free slots do not take */
    if (!grow(ps, ps->used + past))
        return 0;
    /* The batch's adds fill these next: fault them in at once, but only those never touched yet
     * (after lm_photon_store_clear the slots stay mapped, and asking the kernel again for pages it
     * already has walks the page tables for nothing, once per batch of a warm re-trace). */
    uint32_t from = ps->used > ps->mapped ? ps->used : ps->mapped, to = ps->used + (uint32_t)past;
    if (to > from) {
        lm_prefault(ps->hits + from, sizeof *ps->hits * (to - from));
        ps->mapped = to;
    }
    return 1;
}

uint32_t lm_photon_store_grow_slot(lm_photon_store *ps)
{
    if (!grow(ps, (uint64_t)ps->used + 1))
        return LM_NONE;
    return ps->used++;
}

int lm_photon_store_grow_list(lm_surface_hits *sh)
{
    uint32_t cap = sh->cap ? 2 * sh->cap : 64;
    if (cap <= sh->cap) /* past 2^32 slots: the store has no more slot ids anyway */
        return 0;
    uint32_t *grown = realloc(sh->slots, sizeof *grown * cap);
    if (!grown)
        return 0;
    sh->slots = grown;
    sh->cap = cap;
    return 1;
}

uint32_t lm_photon_store_add(lm_photon_store *ps, const lm_hit *h)
{
    uint32_t slot;
    lm_hit *d = lm_photon_store_claim(ps, h->surface, &slot);
    if (!d)
        return LM_NONE;
    *d = *h;
    lm_photon_store_link(ps, slot);
    return slot;
}

void lm_photon_store_remove(lm_photon_store *ps, uint32_t slot)
{
    lm_hit *d = lm_photon_store_live(ps, slot);
    if (!d) /* not a live hit: nothing to unlink */
        return;
    lm_surface_hits *sh = &ps->surfaces[d->surface];
    uint32_t last = sh->slots[--sh->count]; /* the last takes its place */
    sh->slots[d->at] = last;
    ps->hits[last].at = d->at;
    lm_photon_store_account(ps, d, -1);
    d->surface = -1;
    d->at = LM_NONE;
    d->next = ps->free_head;
    ps->free_head = slot;
    ps->free_count++;
}

void lm_photon_store_scale(lm_photon_store *ps, uint32_t slot, const float s[3])
{
    lm_hit *h = lm_photon_store_live(ps, slot);
    if (!h)
        return;
    double before = lm_hit_energy(h);
    for (int c = 0; c < 3; c++) /* a channel at 0 stays 0 (never 0 x inf), the rest at most FLT_MAX */
        h->flux[c] = h->flux[c] > 0.0f ? (float)fmin((double)h->flux[c] * s[c], FLT_MAX) : 0.0f;
    double moved = lm_hit_energy(h) - before;
    lm_surface_hits *sh = &ps->surfaces[h->surface];
    ps->version++;
    sh->delta_f += fabs(moved);
    if (lm_hit_in_iim(h))
        sh->delta_i += fabs(moved);
    sh->energy += moved;
}

void lm_photon_store_surface_flux_of(const lm_photon_store *ps, int (*keep)(const lm_hit *, const void *),
                                     const void *user, double *out)
{
    memset(out, 0, sizeof *out * 3 * (size_t)ps->surface_count);
    for (uint32_t i = 0; i < ps->used; i++) {
        const lm_hit *h = &ps->hits[i];
        if (h->surface >= 0 && (!keep || keep(h, user)))
            for (int c = 0; c < 3; c++)
                out[3 * h->surface + c] += h->flux[c];
    }
}

void lm_photon_store_surface_flux(const lm_photon_store *ps, double *out)
{
    lm_photon_store_surface_flux_of(ps, NULL, NULL, out);
}

void lm_photon_store_reset_delta_f(lm_photon_store *ps, int surface) { ps->surfaces[surface].delta_f = 0.0; }
void lm_photon_store_reset_delta_i(lm_photon_store *ps, int surface) { ps->surfaces[surface].delta_i = 0.0; }
int lm_photon_store_same(const lm_photon_store *a, const lm_photon_store *b)
{
    if (a->used != b->used || a->free_head != b->free_head || a->free_count != b->free_count ||
        a->surface_count != b->surface_count ||
        memcmp(a->hits, b->hits, sizeof *a->hits * a->used) != 0)
        return 0;
    for (int i = 0; i < a->surface_count; i++) {
        const lm_surface_hits *x = &a->surfaces[i], *y = &b->surfaces[i];
        if (x->count != y->count || memcmp(&x->delta_f, &y->delta_f, sizeof x->delta_f) != 0 ||
            memcmp(&x->delta_i, &y->delta_i, sizeof x->delta_i) != 0 ||
            memcmp(&x->energy, &y->energy, sizeof x->energy) != 0 ||
            (x->count && memcmp(x->slots, y->slots, sizeof *x->slots * x->count) != 0))
            return 0;
    }
    return 1;
}

size_t lm_photon_store_bytes(const lm_photon_store *ps) { (void)ps; return sizeof(lm_hit) + sizeof(uint32_t); }

double lm_photon_store_iim_energy(const lm_photon_store *ps, int surface)
{
    double e = 0.0;
    const lm_surface_hits *sh = &ps->surfaces[surface];
    for (uint32_t k = 0; k < sh->count; k++)
        if (lm_hit_in_iim(&ps->hits[sh->slots[k]]))
            e += lm_hit_energy(&ps->hits[sh->slots[k]]);
    return e;
}
