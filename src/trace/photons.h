/* The photon stage: selective photon emission and tracing (Larsen & Christensen 2004, section 2;
 * DESIGN.md pipeline step 2; docs/photons.md).
 *
 * Each emitter owns a fixed set of photons, P_e = M_e x G, with fixed QMC (Halton) indices. Photon j of
 * emitter e belongs to group j mod G of that emitter; G = 2^a 3^b, so a group's photons share one cell
 * of the 2^a x 3^b stratification of Halton dims 0-1 and leave in similar directions. Every random
 * decision along a path comes from the photon's own QMC dimensions, so an unchanged scene re-traces
 * the identical path. Every photon's path is stored (its (node, triangle) vertices, hit points and the
 * store slots of its hits), and every hit on a non-specular surface is linked into the lm_photon_store.
 *
 * Each frame, k photons per group are re-traced round robin and compared with their stored paths; a
 * difference marks the whole group invalid. Invalid groups are re-traced oldest-invalid first under a
 * per-frame group budget: their photons' old hits are removed and new ones added (photons whose path
 * did not change cause no store change at all). Paths are traced in parallel (OpenMP) into per-photon
 * buffers; store updates are applied serially in photon order, so results do not depend on threads.
 *
 * The scene, surfaces, BVH and emitters are borrowed: the caller keeps them alive and current (moves
 * nodes with lm_rt_set_node_transform, calls lm_emitters_update after light edits). */
#ifndef LM_PHOTONS_H
#define LM_PHOTONS_H

#include <stddef.h>
#include <stdint.h>

#include "../charts/charts.h"
#include "../core/error.h"
#include "../scene/scene.h"
#include "lights.h"
#include "photon_store.h"
#include "rt_scene.h"

typedef struct {
    uint32_t total_photons;    /* photon budget over all emitters; 0 = per_group x groups x emitters */
    uint32_t groups;           /* G, groups per emitter, must be 2^a 3^b (default 72 = 2^3 3^2) */
    uint32_t per_group;        /* mean photons per group when total_photons is 0 (default 160) */
    uint32_t min_total;        /* with total_photons 0, at least this many photons over all emitters
                                * (default LM_PHOTONS_MIN_TOTAL; 0: none, exactly per_group x groups x
                                * emitters) */
    uint32_t retrace_per_group; /* k: photons per group re-traced each frame, round robin (default 1) */
    uint32_t group_budget;     /* invalid groups re-traced per frame, oldest first (default 16; 0 = all) */
    float epsilon;             /* a path vertex that moved more than this (world units) is a change;
                                  <= 0: 1e-4 x scene size (default 0) */
    uint32_t max_bounces;      /* most path vertices per photon, a safety net (default and at most 1024:
                                  Russian roulette ends paths; a white room needs hundreds of bounces) */
    uint32_t seed;             /* selects another, disjoint stretch of the Halton sequence (default 0) */
    float cover_distance;      /* a hit with other geometry closer than this (world units) straight out from
                                * the side it arrived at is not stored (the photon still scatters): its light
                                * lies where nothing sees it, a lamp millimetres under a ceiling or the floor
                                * under a box, and the N-nearest estimate would spread it over the visible
                                * texels around (docs/aim.md). <= 0 (default here): every hit is stored;
                                * the photon stage makes it the atlas's texel size */
    const float *cover_by_surface; /* with cover_distance > 0: the distance per surface id instead (borrowed;
                                * the photon stage gives each surface its own texel width,
                                * lm_atlas.surface_texel_size); NULL: cover_distance everywhere */
    int aim_bounces;           /* a sun's or the sky's photons bouncing outside, in front of its openings: a
                                * quarter of those bounces aimed in through them (portals.h, "Bounces aimed
                                * in"; default 1; 0: every bounce is the BSDF's, to measure against) */
} lm_photon_settings;

/* How far "covered" reaches on surface `surface` (-1: none) under a distance and an optional per-surface
 * table (lm_photon_settings.cover_by_surface): the one rule the photons, the AIM's direct light and its
 * occluder test share. */
static inline float lm_cover_reach(float distance, const float *by_surface, int surface)
{
    return distance > 0.0f && by_surface && surface >= 0 ? by_surface[surface] : distance;
}

/* The scene's default photon floor, 72 groups of 640: one light's photons when the scene has one, 160 a
 * group per light from four lights on. A single light at 160 a group left the shared Cornell box's small
 * box 21-34% too bright (its faces see the floor's contact shadow blurred by the estimate's radius);
 * at 640 with N = 32 they are within 3% (docs/tradeoff.md, "Defaults against the front"). */
#define LM_PHOTONS_MIN_TOTAL 46080u

void lm_photon_settings_default(lm_photon_settings *s);

/* What one call of lm_photons_frame did. */
typedef struct {
    uint32_t rr_photons;        /* photons re-traced round robin to check their paths */
    uint32_t paths_changed;     /* of those, how many differed from the stored path */
    uint32_t groups_invalidated; /* groups newly marked invalid (round robin) this frame */
    uint32_t groups_retraced;   /* invalid groups re-traced this frame */
    uint32_t group_photons;     /* photons traced for those groups */
    uint32_t photons_updated;   /* photons whose stored path and hits were replaced */
    uint32_t hits_added, hits_removed;
    uint32_t pending_groups;    /* invalid groups still waiting after this frame */
    uint32_t box_photons;       /* photons re-traced one by one for meeting a moved node's box
                                 * (lm_photons_retrace_boxes) */
    uint64_t rays;              /* rays cast (every path segment, a final miss included) */
    double seconds;
} lm_photon_frame_stats;

/* One group, for reports and tests. */
typedef struct {
    int emitter;
    uint32_t index;             /* g in 0..G-1: photons j = g, g + G, ... of the emitter */
    uint32_t photons;           /* M_e */
    int invalid;                /* waiting in the re-trace queue */
    uint32_t invalidations;     /* times the round robin found a changed path and marked it invalid */
    uint32_t retraces;          /* times it was re-traced (lm_photons_trace_all included) */
} lm_photon_group_info;

typedef struct lm_photons lm_photons;

/* Sets up photon counts, groups and the empty store; traces nothing. Emitters get photon counts in
 * proportion to their luminance, a lit one's taken as at least half the mean lit emitter's (a lamp beside
 * the sun still gets enough to light its room), at least one photon per group each; so photons carry
 * about equal power where lights are alike. Fails on bad settings (G not 2^a 3^b, zero counts) naming the setting. */
lm_status lm_photons_create(const lm_scene *s, const lm_surfaces *su, const lm_rt *rt, const lm_emitters *em,
                            const lm_photon_settings *settings, lm_photons **out, lm_error *err);
void lm_photons_free(lm_photons *ph);
/* 1 when lm_photons_create would plan other photon counts for ph's emitters as they are now: lights added
 * since creation (they got the photons per weight of creation), removed, or changed in luminance, so that
 * the shares of creation no longer follow the light; else 0. O(emitters). */
int lm_photons_plan_outdated(const lm_photons *ph);
/* Forgets every path and hit (and the queue and the groups' counters) but keeps the memory: slabs,
 * store slots and trace buffers stay allocated. The state is that of a fresh lm_photons_create with
 * the same arguments, and a following lm_photons_trace_all gives bit-identical paths, hits and store
 * slots, without the allocation and page faults of a first trace. */
void lm_photons_reset(lm_photons *ph);

/* A full trace shared among processes (an MPI bake, docs/farm.md). Every process holds the same scene
 * and settings and calls lm_photons_trace_all at the same points; in each, the photons are dealt out in
 * turn in the order they are traced (photon k of the trace to process k mod shares), each process traces
 * its own, and `exchange` gives every process the others' paths, which each then stores in the same order
 * as one process tracing all would: every process ends with the one-process store, to the bit.
 *
 * exchange is collective (every process calls it as often, with its bytes for that batch) and called
 * twice per batch: first with all NULL, to fill sizes[0 .. shares) with each process's byte count, then
 * with `all` holding the sum of them, to fill with every process's bytes back to back in process order.
 * It returns 0 on failure (the trace then fails with LM_ERR_BACKEND). The round robin and re-traces of
 * lm_photons_frame stay each process's own. */
typedef struct {
    uint32_t share, shares;    /* this process and how many; shares 0 or 1: no sharing */
    int (*exchange)(void *user, const void *mine, size_t size, size_t *sizes, void *all);
    void *user;
} lm_photon_split;
/* Sets (or with shares <= 1, ends) the sharing of full traces. */
void lm_photons_set_split(lm_photons *ph, const lm_photon_split *split);

/* Traces every photon and stores its path and hits (initial full trace; also a full refresh: paths
 * that did not change cause no store change). Clears the invalid queue. stats may be NULL. */
lm_status lm_photons_trace_all(lm_photons *ph, lm_photon_frame_stats *stats, lm_error *err);
/* The same, but a path counts as changed when any number of it or of its hits differs in any bit, not
 * beyond epsilon or the flux tolerance: the store then holds what a fresh trace of the scene would, where
 * lm_photons_trace_all keeps a path that moved by float noise (a node switched static holds the same
 * place through another matrix; docs/photons.md). What a bake that must equal a fresh one uses. */
lm_status lm_photons_trace_all_exact(lm_photons *ph, lm_photon_frame_stats *stats, lm_error *err);
/* One frame: round-robin check of k photons per valid group, then re-trace of up to group_budget
 * invalid groups, oldest first. Without anything_moves (no dynamic node with triangles) the round robin
 * is left out: no path can change but by an edit, and the edits that change paths invalidate their
 * groups themselves (a light's placement or power, a material). stats may be NULL. Fails only when
 * memory runs out. */
lm_status lm_photons_frame(lm_photons *ph, int anything_moves, lm_photon_frame_stats *stats, lm_error *err);
/* Re-traces every queued invalid group now, whatever group_budget (an edit's catch-up, update/photon_stage.c),
 * counted in stats (may be NULL) as lm_photons_frame counts its. Fails only when memory runs out. */
lm_status lm_photons_drain_all(lm_photons *ph, lm_photon_frame_stats *stats, lm_error *err);
/* Queues every valid group with a photon whose stored path crosses one of the n boxes (6 floats each: min
 * x, y, z, max x, y, z): where a node an edit moved was and where it is now. The round robin finds such
 * paths one photon a group an update; a box test finds them at once, without a ray (the last leg of a
 * photon that left the scene is not stored and is left to the round robin). O(path vertices x n), on
 * OpenMP threads; the queue's order does not depend on them. Returns how many groups it queued (0 also
 * when memory ran out: the round robin then finds them). */
uint32_t lm_photons_invalidate_boxes(lm_photons *ph, const float *boxes, int n);
/* lm_photons_invalidate_boxes photon by photon, at once: every photon of a valid group whose stored path
 * crosses one of the n boxes is traced again now, and where its path changed its hits are replaced (the
 * group's other photons keep theirs). A path that crosses neither where a node was nor where it is has not
 * changed (but for the unstored last leg, left to the round robin), so the store then holds what
 * re-tracing their whole groups would, for the cost of the paths that met a box: the animated Cornell box's
 * cube and spheres meet 8% of its photons an update, and the 67 groups they touch waited 4 updates each
 * for the group budget (docs/photons.md, "Animated nodes"). When more photons meet the boxes than a
 * frame's group budget re-traces (its groups at the mean photons a group), their groups are queued instead
 * (lm_photons_invalidate_boxes). Counted in stats (may be NULL; box_photons, the hits, photons_updated,
 * rays, pending_groups, seconds). The scene and BVH must be those of the boxes' "now". With no memory to
 * test the paths it does nothing (the round robin finds them later); fails only when the re-trace itself
 * runs out of memory. */
lm_status lm_photons_retrace_boxes(lm_photons *ph, const float *boxes, int n, lm_photon_frame_stats *stats,
                                   lm_error *err);
/* Emitter e changed in power alone (a light's colour or intensity; its place and shape as they were):
 * its photons keep their paths, which follow albedos and never power (photon_trace.c), so instead of
 * re-tracing them the flux of each of its stored hits is multiplied by s, per channel, which gives the
 * hits a re-trace would store up to rounding. Not for a light turned dark (s all 0): a dark light stores
 * no hits (lights.c), so its groups are traced again instead (lm_photons_retrace_emitter). Fails for an
 * out-of-range emitter. */
lm_status lm_photons_scale_emitter(lm_photons *ph, int e, const float s[3], lm_error *err);
/* Traces emitter e's groups now, queued or not, and takes them off the queue: a light turned dark, whose
 * hits are then gone at once (a dark light emits no photon, so no ray is cast), or one lit where it gave
 * no light, whose light then shows at once (update/photon_stage.c). Fails for an out-of-range emitter or
 * when memory runs out. */
lm_status lm_photons_retrace_emitter(lm_photons *ph, int e, lm_error *err);
/* Diffuse materials recoloured (their base colour alone changed, by ratio[3 m + c] per channel for the
 * first `materials` materials; 1 for the others): every stored hit a photon brings after bouncing off one
 * is multiplied by the ratios of the bounces before it, and touched[surface] set for its surface. A path's later decisions follow albedos
 * through the survival probability, which the old colour set: the old path with the new weight is an
 * unbiased estimate of the new light (importance sampling), noisier where a ratio is large, until the
 * groups are traced again (lm_photons_invalidate_materials). A group with a path whose weight left
 * [1e-12, 1e12] (many recolours of a material it bounces off often) is queued for tracing again at once:
 * floats hold its hits' flux, and that far down their digits are gone. O(path vertices), no ray. */
void lm_photons_scale_materials(lm_photons *ph, const float *ratio, int materials, uint8_t *touched);
/* The flux of emitter e's stored hits added per surface into flux[surface * 3 + c] (e in range). */
void lm_photons_emitter_flux(const lm_photons *ph, int e, double *flux);

/* The invalid groups the next frames re-trace at most, in place of group_budget (a time budget's count,
 * update/budget_plan.h); 0: group_budget again. */
void lm_photons_limit_groups(lm_photons *ph, uint32_t most);

/* Marks all groups of emitter e invalid (after it moved or changed: call lm_emitters_update first).
 * Groups already queued keep their place. Fails for an out-of-range emitter. */
lm_status lm_photons_invalidate_emitter(lm_photons *ph, int e, lm_error *err);
/* Takes on the light that lm_emitters_add_light appended to the emitter list (the last one): its
 * photons get the ids after all others (no other photon's numbers change) and a count from the photons
 * per unit of weight at creation (the mean emitter's when it is dark), and its groups are queued for
 * tracing. Fails when the list did not grow by one light (nothing changed), or when memory runs out
 * (the light then has no photons). */
lm_status lm_photons_add_emitter(lm_photons *ph, lm_error *err);
/* Gives back the memory of emitter e's photons (their paths, emission numbers and slabs; its groups keep
 * no photon) once its groups hold no path: for a light removed for good, after the re-trace its removal
 * queued has emptied them. Returns how many of its groups still wait for that re-trace (call again after
 * a frame); 0 when all are released. Its photon ids stay its own, traced no more. */
uint32_t lm_photons_release_emitter(lm_photons *ph, int e);
/* Marks invalid every group with a stored path vertex on a triangle whose material is flagged in
 * `materials` (per scene material): what a material edit reaches. Returns how many groups. */
uint32_t lm_photons_invalidate_materials(lm_photons *ph, const uint8_t *materials);

const lm_photon_store *lm_photons_store(const lm_photons *ph);
/* The same store, writable: the AIM scheduler resets its surfaces' delta_f after a refresh. */
lm_photon_store *lm_photons_store_mutable(lm_photons *ph);
uint32_t lm_photons_count(const lm_photons *ph);         /* all photons */
uint32_t lm_photons_group_count(const lm_photons *ph);   /* emitters x G */
uint32_t lm_photons_groups_per_emitter(const lm_photons *ph);
uint32_t lm_photons_emitter_photons(const lm_photons *ph, int e); /* P_e */
uint32_t lm_photons_stored_hits(const lm_photons *ph);   /* live hits in the store */
uint32_t lm_photons_pending_groups(const lm_photons *ph);
void lm_photons_group_info(const lm_photons *ph, uint32_t group, lm_photon_group_info *out);
/* Group of a photon id (lm_hit.photon), and the emitter that owns it. */
uint32_t lm_photons_group_of(const lm_photons *ph, uint32_t photon);

/* Memory: bytes held by paths (offsets and vertices), by the store (hit slots, spare ones included,
 * and surface lists) and by the rest (groups, queue, trace scratch), summed in total;
 * per_photon = total / photons. live_per_photon counts only what the photons use: 4 bytes of offset,
 * 16 of emission numbers, sizeof(lm_path_vertex) per path vertex and sizeof(lm_hit) per stored hit. */
typedef struct {
    size_t path_bytes, store_bytes, other_bytes, total_bytes;
    double per_photon, live_per_photon;
    double mean_path_vertices;  /* stored vertices per photon */
    double mean_hits;           /* stored hits per photon */
} lm_photon_memory;
void lm_photons_memory(const lm_photons *ph, lm_photon_memory *out);

/* A photon's stored path: vertex count, and each vertex's node, triangle and world position. */
typedef struct {
    int node;
    uint32_t tri;
    float pos[3];
    uint32_t slot;              /* its hit in the store, LM_NONE for a specular vertex */
} lm_path_vertex;
uint32_t lm_photons_path(const lm_photons *ph, uint32_t photon, const lm_path_vertex **vertices);

/* Sum of the flux of stored first hits (bounce 0), per surface, into out[surface * 3 + c]
 * (surface_count x 3 floats as doubles). */
void lm_photons_first_hit_flux(const lm_photons *ph, double *out);

#endif
