#include "photon_store.h"

#include <stdlib.h>
#include <string.h>

#include "../core/prefault.h"

lm_status lm_photon_store_init(lm_photon_store *ps, int surface_count, lm_error *err)
{
    memset(ps, 0, sizeof *ps);
    ps->free_head = LM_NONE;
    ps->surface_count = surface_count;
    ps->surfaces = malloc(sizeof *ps->surfaces * (size_t)(surface_count > 0 ? surface_count : 1));
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
    for (int i = 0; i < ps->surface_count; i++) {
        ps->surfaces[i].head = LM_NONE;
        ps->surfaces[i].count = 0;
        ps->surfaces[i].delta_f = ps->surfaces[i].delta_i = ps->surfaces[i].energy = 0.0;
    }
}

void lm_photon_store_free(lm_photon_store *ps)
{
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
    if (!grow(ps, ps->used + n))
        return 0;
    /* The batch's adds fill these next: fault them in at once, but only those never touched yet
     * (after lm_photon_store_clear the slots stay mapped, and asking the kernel again for pages it
     * already has walks the page tables for nothing, once per batch of a warm re-trace). */
    uint32_t from = ps->used > ps->mapped ? ps->used : ps->mapped, to = ps->used + (uint32_t)n;
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
    if (slot >= ps->used || ps->hits[slot].surface < 0) /* not a live hit: nothing to unlink */
        return;
    lm_hit *d = &ps->hits[slot];
    lm_surface_hits *sh = &ps->surfaces[d->surface];
    if (d->prev != LM_NONE)
        ps->hits[d->prev].next = d->next;
    else
        sh->head = d->next;
    if (d->next != LM_NONE)
        ps->hits[d->next].prev = d->prev;
    sh->count--;
    lm_photon_store_account(ps, d, -1);
    d->surface = -1;
    d->prev = LM_NONE;
    d->next = ps->free_head;
    ps->free_head = slot;
}

void lm_photon_store_reset_delta_f(lm_photon_store *ps, int surface) { ps->surfaces[surface].delta_f = 0.0; }
void lm_photon_store_reset_delta_i(lm_photon_store *ps, int surface) { ps->surfaces[surface].delta_i = 0.0; }
size_t lm_photon_store_bytes(const lm_photon_store *ps) { (void)ps; return sizeof(lm_hit); }

double lm_photon_store_iim_energy(const lm_photon_store *ps, int surface)
{
    double e = 0.0;
    for (uint32_t h = ps->surfaces[surface].head; h != LM_NONE; h = ps->hits[h].next)
        if (lm_hit_in_iim(&ps->hits[h]))
            e += lm_hit_energy(&ps->hits[h]);
    return e;
}
