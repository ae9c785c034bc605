/* The photon hits a per-pixel gather reads (gpu/tiled/photon_gather.h), packed for the GPU the way Mara et al.
 * (2013) pack theirs: 20 bytes a photon, one record per slot of the photon store, so that a hit that
 * changed rewrites its own record and nothing else.
 *
 * Layout (5 uint32 words):
 *   w0..w2  position, the float bits of the hit's world position;
 *   w3      flux, bits 31-24 the shared exponent e + 128 (max channel = f 2^e, f in [0.5, 1)), bits 23-11
 *           red's 13-bit mantissa q (channel = q 2^(e - 13)), bits 10-0 green's top 11 bits;
 *   w4      bits 31-30 green's low 2 bits, 29-17 blue's mantissa, 15-8 and 7-0 the hit's side normal
 *           (lm_hit_side_normal), octahedron-mapped to 8 bits a coordinate.
 * A channel is a multiple of 2^(e - 13), rounded (the largest error is 2^-13 of the brightest channel),
 * and the exponent spans the float's range, so a lamp a million times dimmer than the sun keeps its
 * precision (docs/tiled.md). The side normal (within a degree) decides which receivers a photon may
 * light: those facing the same way, so that it lights neither the other side of a thin wall nor the
 * wall across a corner (the lightmap path keeps photons per surface for the same reason).
 * A record whose w3 is 0 is empty: a free store slot, a hit the gather leaves out (a punctual light's
 * first hit, whose light the direct pass draws, or a caustic hit, the caustic pass's: lm_hit_in_iim), or
 * flux 0 or under 2^-127.
 *
 * Cost: lm_photon_records_update reads every used slot of the store (a few ms for a million) and marks
 * the pages of LM_RECORD_PAGE records whose bytes changed; the caller uploads those. Not thread-safe
 * against store updates: run it when the photon stage is idle. Errors: out of memory (the records are
 * unchanged then). */
#ifndef LM_PHOTON_RECORDS_H
#define LM_PHOTON_RECORDS_H

#include <stdint.h>

#include "../core/error.h"
#include "../scene/scene.h"
#include "../trace/photon_store.h"

#define LM_RECORD_WORDS 5
#define LM_RECORD_PAGE 1024 /* records a dirty mark covers (20 KB) */

typedef struct {
    uint32_t w[LM_RECORD_WORDS];
} lm_photon_record;

typedef struct {
    lm_photon_record *rec;   /* rec[slot] for slot in [0, count) */
    uint32_t count, capacity;
    uint32_t live;           /* records that are not empty */
    int top_exponent;        /* the largest shared exponent e of a record that is not empty (-1000: none) */
    uint8_t *dirty;          /* per page: changed by the last update (pages = ceil(count / LM_RECORD_PAGE)) */
    uint32_t pages, dirty_pages;
    uint64_t store_version;  /* the store's version the records hold */
} lm_photon_records;

/* The geometric normal of the triangle a hit lies on, in world space (its node's matrix now), turned to
 * the side the photon arrived from. Without a scene (s NULL), or for a degenerate triangle, the arrival
 * direction stands in for it. */
void lm_hit_side_normal(const lm_scene *s, const lm_hit *h, float n[3]);
/* h NULL, or a hit the gather leaves out: the empty record. side: lm_hit_side_normal's. */
void lm_photon_record_encode(const lm_hit *h, const float side[3], lm_photon_record *r);
/* Returns 0 for an empty record (outputs zeroed). side: the unit side normal. */
int lm_photon_record_decode(const lm_photon_record *r, float pos[3], float side[3], float flux[3]);

/* Makes r hold the store's hits (r zero-initialised the first time): every used slot encoded, the pages
 * whose records changed marked dirty (all of them when the count changed). Nothing is read when the
 * store's version is the one r holds (dirty_pages 0). s: the scene whose triangles the hits lie on (for
 * the side normals; NULL: lm_hit_side_normal's stand-in). */
lm_status lm_photon_records_update(lm_photon_records *r, const lm_photon_store *ps, const lm_scene *s,
                                   lm_error *err);
void lm_photon_records_free(lm_photon_records *r);

#endif
