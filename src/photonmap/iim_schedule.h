/* Which IIM texels to regather, and when a surface's refresh is complete (Larsen & Christensen section 4;
 * the IIMs themselves, their GPU textures and blending, are gpu/gather/iim.h).
 *
 * Each frame at most texels_per_frame texels are handed to the gather. Surfaces are taken in order of
 * their delta_i (photon store: energy of hits added or removed since the surface's IIM was refreshed,
 * first hits of punctual lights left out), largest first, then by age (frames since the surface's last
 * completed refresh, oldest first), then by id. Only surfaces with delta_i > delta_threshold, or with a
 * refresh under way, are candidates: nothing changed means no IIM work. A surface's texels are handed out
 * in atlas order from a cursor that survives across frames, skipping those gathered since the refresh
 * began (picked ahead of their surface: lm_iim_sched_gathered), so that work is not done twice; when the
 * last one is out the refresh is
 * complete: the surface's delta_i is reset (the scheduler is what writes it, beside the AIM scheduler's
 * delta_f) and its commit flag is raised for the blend to consume.
 *
 * Cost: O(surfaces^2) per frame for the ordering (insertion sort; surface counts are small) plus the
 * texels handed out. Not thread-safe; the photon store must not be updated meanwhile. */
#ifndef LM_IIM_SCHEDULE_H
#define LM_IIM_SCHEDULE_H

#include <stdint.h>

#include "../charts/charts.h"
#include "../core/error.h"
#include "../trace/photon_store.h"

typedef struct {
    int texels_per_frame;  /* gather budget per frame (>= 0) */
    double delta_threshold; /* a surface is refreshed when its delta_i exceeds this */
    int surface_count;
    uint32_t *surf_first;  /* surface_count + 1 offsets into surf_texels */
    uint32_t *surf_texels; /* texel indices (into lm_atlas.texels) grouped by surface, atlas order */
    uint32_t *cursor;      /* per surface: next texel of a refresh under way (0: none under way) */
    int *last_done;        /* per surface: frame its last refresh completed (-1: never) */
    uint8_t *commit;       /* per surface: refresh completed, for the blend to commit (and clear) */
    uint8_t *off;          /* per surface: not gathered at all (its node's indirect switched off) */
    uint8_t *again;        /* per surface: what its refresh under way gathered is stale: refreshed again
                            * once it completes (lm_delta_i_widen_to_viewers) */
    int *started;          /* per surface: frame its refresh under way began */
    int *texel_frame;      /* per atlas texel: frame it was last handed out (INT_MIN: never) */
    int frame;             /* advanced once a frame by lm_iim_sched_end_frame */
} lm_iim_sched;

lm_status lm_iim_sched_init(lm_iim_sched *s, const lm_atlas *a, int texels_per_frame, double delta_threshold,
                            lm_error *err);
void lm_iim_sched_free(lm_iim_sched *s);
/* Picks this frame's texels (at most texels_per_frame, written to out) and resets delta_i of surfaces
 * whose refresh completes. Returns how many. */
uint32_t lm_iim_sched_pick(lm_iim_sched *s, lm_photon_store *ps, uint32_t *out);
/* The same with `budget` texels in place of texels_per_frame (a bake: the whole atlas). */
uint32_t lm_iim_sched_pick_up_to(lm_iim_sched *s, lm_photon_store *ps, uint32_t budget, uint32_t *out);
/* Every refresh under way starts again from its surface's first texel, which stays a candidate (its
 * delta_i set over any threshold): a bake regathers whole surfaces, since the texels a refresh gathered
 * before the bake saw AIMs the bake's photons have changed since (a light edited and restored left them
 * 100 times too bright). */
void lm_iim_sched_restart(lm_iim_sched *s, lm_photon_store *ps);
/* Every texel of every surface, for the first full gather; completes every surface. Returns the count
 * (out must hold the atlas's texel_count). */
uint32_t lm_iim_sched_pick_all(lm_iim_sched *s, lm_photon_store *ps, uint32_t *out);
void lm_iim_sched_end_frame(lm_iim_sched *s);
/* gathered: the texels were gathered this frame outside the surfaces' order (photonmap/texel_change.h): a
 * refresh under way, or one begun this frame, skips them. 0: they were handed out but not gathered after
 * all (a cancelled bake): any refresh hands them out again. */
void lm_iim_sched_gathered(lm_iim_sched *s, const uint32_t *texels, uint32_t n, int gathered);
/* Surface k's delta_i just over the threshold, whatever its size: a candidate, behind every surface
 * whose light changed more. */
void lm_iim_sched_raise(const lm_iim_sched *s, lm_photon_store *ps, int k);
/* Switches surface k's gather off (a refresh under way is dropped) or on again; a surface switched on is
 * refreshed in full next, as if all its light had changed (its delta_i set over any threshold). */
void lm_iim_sched_set_off(lm_iim_sched *s, lm_photon_store *ps, int k, int off);

#endif
