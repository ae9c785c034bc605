/* Stored photon hits, listed per surface (a slot array each, a hit knowing its place in it) so that adding
 * and removing a hit is O(1) and a surface's hits are read without chasing links, with
 * the change accumulators the update scheduler reads (Larsen & Christensen, section 2-3):
 *   delta_f: energy of every hit added or removed since the surface's AIM was last refreshed;
 *   delta_i: the same, leaving out first hits from punctual lights and caustic hits (an IIM holds neither:
 *            DESIGN.md, docs/caustics.md), since the surface's IIM was last refreshed.
 * Energy of a hit is the luminance of its flux. */
#ifndef LM_PHOTON_STORE_H
#define LM_PHOTON_STORE_H

#include <stdint.h>

#include "../core/error.h"

#define LM_NONE 0xFFFFFFFFu

/* What a photon came from: emissive triangles, a point or spot light, the sky, or a directional light (a
 * sun: punctual too, told apart for the AIMs' direct light, direct_irradiance.h). */
enum { LM_HIT_FROM_AREA = 0, LM_HIT_FROM_PUNCTUAL = 1, LM_HIT_FROM_SKY = 2, LM_HIT_FROM_SUN = 3 };

typedef struct {
    float pos[3];          /* world position when stored */
    float local[3];        /* position in the hit node's local space (AIM lookups match texel.local) */
    float dir[3];          /* unit direction the photon travelled, towards the surface */
    float flux[3];         /* RGB flux */
    float travelled;       /* distance from the vertex it left (the emission point or the previous hit) to
                            * this one: that vertex lies at pos - travelled dir (0: unknown). The AIM's
                            * visibility test joins it to a texel (docs/aim.md, "Occluders") */
    uint32_t photon;       /* owning photon */
    uint32_t tri;
    int32_t surface;
    uint16_t bounce;       /* 0 = first hit after leaving the emitter */
    uint8_t source;        /* what the photon came from: LM_HIT_FROM_AREA (emissive triangles), _PUNCTUAL
                            * (a point or spot light), _SUN (a directional light) or _SKY */
    uint8_t caustic;       /* it came off mirrors and glass only, straight from its emitter (L S+ D): light
                            * the caustic pass carries, not the receiver's IIM (docs/caustics.md) */
    uint32_t at;           /* its place in its surface's slot list */
    uint32_t next;         /* a free slot's link to the next free one (LM_NONE at the end) */
} lm_hit;

typedef struct {
    uint32_t *slots;       /* its hits' slots, count of them (cap allocated): removing one moves the last into
                            * its place, so the order follows the adds and removes, the same every run. An
                            * array rather than a linked list: a floor lit by 100 lights holds 250,000 hits,
                            * and following links to each took 30-55 ms of its AIM refresh */
    uint32_t count, cap;
    double delta_f, delta_i;
    double energy;         /* the energy of the hits it holds, kept as they come and go (0 when count is 0),
                            * so that the mean hit energy costs a sum over surfaces, not a walk of every
                            * hit (100 lights' photons: ~50 ms an AIM refresh) */
} lm_surface_hits;

typedef struct {
    lm_hit *hits;
    uint32_t capacity, used; /* slots allocated / in use */
    uint32_t free_head;      /* first free slot (chain through next), LM_NONE if none */
    uint32_t free_count;     /* slots on that chain: what a batch's adds take before any slot past used */
    uint32_t mapped;         /* slots [0, mapped) are known to be paged in (lm_photon_store_reserve) */
    int surface_count;
    lm_surface_hits *surfaces;
    uint64_t version;        /* counts hits linked and removed, and clears: what a copy of the store's
                              * contents (the brute-force gather's picture) compares with */
} lm_photon_store;

lm_status lm_photon_store_init(lm_photon_store *ps, int surface_count, lm_error *err);
void lm_photon_store_free(lm_photon_store *ps);
/* Empties the store and zeroes every surface's deltas but keeps the slot array (its capacity, and
 * the memory already mapped in): afterwards it behaves exactly like a freshly initialized store of
 * the same surface count, slot for slot, without growing or page-faulting again. */
void lm_photon_store_clear(lm_photon_store *ps);
/* Copies h into a free slot, links it into its surface's list and adds its energy to the surface's
 * deltas. Returns the slot, or LM_NONE when memory ran out (the store is unchanged then). */
uint32_t lm_photon_store_add(lm_photon_store *ps, const lm_hit *h);
/* lm_photon_store_add in two halves, for a caller that writes the hit straight into its slot (one
 * copy less per stored photon hit): claim takes a free slot for a hit on `surface` (and room in the
 * surface's list) and returns it to be filled (every field but at and next; its surface is set), NULL
 * when the surface is out of range or memory ran out (the store is unchanged then, but for the list's
 * room); link puts the filled hit in its surface's list and adds its energy to the deltas. */
static inline lm_hit *lm_photon_store_claim(lm_photon_store *ps, int surface, uint32_t *slot);
static inline void lm_photon_store_link(lm_photon_store *ps, uint32_t slot);
/* Makes room for n more adds without reallocation, so a bulk update grows the array once. The adds take
 * the free slots first, so only what they leave over counts: a re-trace that replaces a light's hits
 * asked for all of them anew and doubled the array (by 40 MB in the two rooms' soak) with half its slots
 * free. Returns 0 when memory ran out (the store is unchanged then). */
int lm_photon_store_reserve(lm_photon_store *ps, uint64_t n);
/* Unlinks a stored hit, adds its energy to the deltas and frees the slot. A slot that holds no live
 * hit (already removed, or never used) is ignored. */
void lm_photon_store_remove(lm_photon_store *ps, uint32_t slot);
/* Whether a hit's light is what the receiver's IIM holds: not a punctual light's first hit (the direct
 * pass's), not a caustic hit (the caustic pass's). */
static inline int lm_hit_in_iim(const lm_hit *h)
{
    return !(h->bounce == 0 && (h->source == LM_HIT_FROM_PUNCTUAL || h->source == LM_HIT_FROM_SUN)) && !h->caustic;
}
/* Energy of a hit as the deltas count it. */
static inline double lm_hit_energy(const lm_hit *h)
{
    return 0.2126 * h->flux[0] + 0.7152 * h->flux[1] + 0.0722 * h->flux[2];
}
/* The energy of a surface's stored hits that an IIM holds (lm_hit_in_iim, as delta_i counts them): what
 * delta_i is measured against. O(hits on the surface). */
double lm_photon_store_iim_energy(const lm_photon_store *ps, int surface);
/* Multiplies the flux of the live hit in `slot` by s, per channel (a light whose power alone changed:
 * lm_photons_scale_emitter). Both deltas grow by how far its energy moved, and its surface's energy
 * follows. A channel at 0 stays 0 whatever s (no 0 x inf), and none grows past FLT_MAX. */
void lm_photon_store_scale(lm_photon_store *ps, uint32_t slot, const float s[3]);
/* The flux of every live hit summed per surface into out[surface * 3 + c] (surface_count x 3 doubles,
 * overwritten). O(slots). */
void lm_photon_store_surface_flux(const lm_photon_store *ps, double *out);
/* The same over the live hits for which keep(hit, user) is non-zero (keep NULL: all of them). */
void lm_photon_store_surface_flux_of(const lm_photon_store *ps, int (*keep)(const lm_hit *, const void *),
                                     const void *user, double *out);
/* Sets a surface's delta_f (after its AIM refresh) or delta_i (after its IIM refresh) to zero. */
void lm_photon_store_reset_delta_f(lm_photon_store *ps, int surface);
void lm_photon_store_reset_delta_i(lm_photon_store *ps, int surface);
/* 1 when a and b hold the same hits in the same slots, listed in the same order per surface, with the
 * same deltas and energies (what a cleared or reset store is checked against a fresh one with); the
 * lists' spare room may differ. */
int lm_photon_store_same(const lm_photon_store *a, const lm_photon_store *b);
/* Bytes held per stored hit slot (for the memory report). */
size_t lm_photon_store_bytes(const lm_photon_store *ps);

/* The hit in `slot` when it is live (linked on a surface), else NULL: a path vertex's slot may be LM_NONE
 * (specular) or freed since. */
static inline lm_hit *lm_photon_store_live(const lm_photon_store *ps, uint32_t slot)
{
    return slot < ps->used && ps->hits[slot].surface >= 0 ? &ps->hits[slot] : NULL;
}

/* ---- inline: applying a traced batch claims and links every stored hit ---- */

uint32_t lm_photon_store_grow_slot(lm_photon_store *ps); /* take_slot's rare path (photon_store.c) */
int lm_photon_store_grow_list(lm_surface_hits *sh);      /* room for one more in a surface's list */

static inline lm_hit *lm_photon_store_claim(lm_photon_store *ps, int surface, uint32_t *slot)
{
    if (surface < 0 || surface >= ps->surface_count)
        return NULL;
    lm_surface_hits *sh = &ps->surfaces[surface];
    if (sh->count == sh->cap && !lm_photon_store_grow_list(sh))
        return NULL;
    if (ps->free_head != LM_NONE) {
        *slot = ps->free_head;
        ps->free_head = ps->hits[*slot].next;
        ps->free_count--;
    } else if (ps->used < ps->capacity) {
        *slot = ps->used++;
    } else if ((*slot = lm_photon_store_grow_slot(ps)) == LM_NONE) {
        return NULL;
    }
    lm_hit *d = &ps->hits[*slot];
    d->surface = surface;
    return d;
}

/* Both deltas of h's surface grow by its energy, whether it arrives or leaves: they measure change. */
/* sign: +1 a hit linked, -1 one removed (the deltas count both). */
static inline void lm_photon_store_account(lm_photon_store *ps, const lm_hit *h, int sign)
{
    lm_surface_hits *sh = &ps->surfaces[h->surface];
    double e = lm_hit_energy(h);
    ps->version++;
    sh->delta_f += e;
    if (lm_hit_in_iim(h))
        sh->delta_i += e;
    sh->energy = sh->count ? sh->energy + sign * e : 0.0;
}

static inline void lm_photon_store_link(lm_photon_store *ps, uint32_t slot)
{
    lm_hit *d = &ps->hits[slot];
    lm_surface_hits *sh = &ps->surfaces[d->surface];
    d->at = sh->count;
    d->next = LM_NONE;
    sh->slots[sh->count++] = slot; /* claim made the room */
    lm_photon_store_account(ps, d, 1);
}

#endif
