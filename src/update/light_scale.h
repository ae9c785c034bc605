/* The lightmap's first guess after lights changed in power alone (issue 32, item 2; docs/tradeoff.md,
 * "Light edits at once"), and its refinement within the update budget (item 4). A light's photons keep
 * their paths when only its colour, intensity or switch changes, so the photon stage scales their hits
 * and each surface's AIM by how much the flux of its hits changed (update/photon_stage.h); a light added
 * or switched on from dark has its photons traced and the AIMs they reach refreshed (under a budget,
 * scaled where they had light) at once, and the same factors follow it, a first guess where it lights other places than the lights
 * there were (docs/tradeoff.md, "Lights added or switched on"). An IIM texel's
 * light is what it sees of those AIMs, so its own factor is the ratio of two small ray gathers from the
 * texel, through the same rays, over the AIM before and after the scaling (and the emitters' emission
 * before and after):
 *
 *     f(texel) = E_after / E_before   per channel (photonmap/hemicube_rim.h with the whole hemisphere)
 *
 * a mean of the seen surfaces' factors weighed by how much light each brings (emitters and the sky, which
 * the edit did not change, weigh in with 1), summed over the texel's neighbours on its surface
 * (LM_LIGHT_SCALE_SPREAD); where only every stride-th texel gathered, each weighed by a tent,
 * (s + 1 - |dx|)(s + 1 - |dy|) for a window of s texels either side: summed flat, a first guess whose few
 * gathers lie apart showed hard-edged squares where one entered or left the window (issue 32, item 3;
 * test_gather: its largest step between neighbours 0.130 flat, 0.047 with the tent). Where every texel
 * gathered the window stays flat: the tent would weigh a texel's own noise more (the Cornell box's red wall
 * recoloured took 33 updates to 2% with it, 22 without, lmgi bench --edits bench/cornell_edits.json).
 * Both gathers meet the same points, so the ratio is far less noisy than either: in a scene lit by one emitter every factor is the light's own and the IIM is exact at once;
 * where several light the seen surfaces in different proportions it is a first guess that the regathers
 * the scaled hits call for refine. How far it may be off is said per texel, its doubt: the ratio
 * estimator's relative standard error over the window, sqrt(sum w^2 (e_after - f e_before)^2) / sum w
 * e_after, 0 where every gather's ratio is f (one light lights what the window sees: exact, whatever the
 * rays), growing with how differently the texels' few rays mix the lights. The texels most in doubt are
 * regathered first (photonmap/texel_change.h, lm_texel_change_doubt): in the two rooms, light_a2 removed
 * left a face it lit to 80% 6.5% off the converged lightmap (up to 21% a texel) while the surfaces' order
 * went elsewhere, for 75 updates; with the doubt first, within 5% in 18 (test_light_edits). A first guess
 * of a few rays doubts nothing: its refinement says it, surface by surface.
 * A texel whose rays met no light before takes its surface's factor (rays
 * that met none either way say nothing of it; its surface's light does, unless the IIM shows it black:
 * scaling 0 would rewrite it for nothing, outside the edit's reach), except after an edit that `adds`
 * light where there may have been none (a light added or switched on: a dark room whose lamp comes on):
 * there a texel whose rays met next to no light before (LM_LIGHT_SCALE_DARK) has no factor that lights
 * it, and takes instead the change the two gathers saw, added (E_after - E_before over the window, what
 * its regather would add). A power edit keeps its factors, which are exact where one light lights the
 * scene, however much it brightens.
 *
 * The full quality: K rays a texel (K = LM_LIGHT_SCALE_WORK / texels rounded down to a square, at most
 * 64: 16 at `run`'s 1,800 texels) for each of the two gathers, each ray with its 16 AIM lookups (34 ms on
 * the shared room at 1,800 texels, 2 cores). Past LM_LIGHT_SCALE_WORK / 4 texels only every stride-th
 * gathers with K = 4, and each texel sums over a window wide enough to hold about two that did (its
 * surface's factor where it holds none): the work stays bounded on any atlas.
 *
 * Within a budget. lm_light_scale_begin is given the rays the update may cast. With enough (or 0: no
 * budget) the full quality is had at once, the IIM scaled once. With fewer (the updater gives it at
 * least LM_LIGHT_SCALE_LEAST), the first guess is the same estimate at
 * K = 4 over every stride-th texel, the stride that fits, each factor summing a window that holds about 64
 * rays, at most 17 x 17 texels (a coarser gather over blocks of texels; with fewer rays than four a
 * surface, a texel whose window holds less than one gather's weight leans on its surface's factor as that
 * weight falls); then each lm_light_scale_refine casts about the rays it is given over the next texels at the
 * full quality, and once a surface's have all gathered, its factors correct what the first guess applied
 * (f_full / f_first, and a_full - a_first f_full / f_first for what was added). A texel
 * regathered since the edit (lm_light_scale_regathered) holds its fresh value and is left alone.
 *
 * Layout: the job owns the AIM and the emissions from before until it ends; per texel its two gathers,
 * what the IIM holds of this edit (the factor and addition applied so far), two flags and a scratch list
 * of the texels one refinement step gathers (55 bytes a texel with the black texels, freed when the
 * refinement ends). Invariants: texels lie in the atlas by surface (charts are ordered by surface), so
 * a surface's texels are a run and a factor, which sums over its own surface's texels alone, is final once
 * its run is gathered. Cost: the rays cast, as above; a refinement step gathers all its texels, over
 * however many surfaces, in one parallel pass. Errors: none (deterministic: each texel's rays are
 * seeded by its index and the gather's seed, lm_gather_texel_seed; no memory: each texel takes its
 * surface's factor at once). Not thread-safe (one job per lightmap path; the gathers themselves run on
 * every OpenMP thread). */
#ifndef LM_LIGHT_SCALE_H
#define LM_LIGHT_SCALE_H

#include "../charts/charts.h"
#include "../gpu/gather/hemicube.h"
#include "../photonmap/hemicube_rim.h"
#include "../scene/scene.h"
#include "../trace/rt_scene.h"

#define LM_LIGHT_SCALE_WORK 32768u /* rays one of the two gathers takes at most */
/* The fewest rays the updater lets a first guess cast, whatever its budget (4 to 6 ms on a 2-core
 * machine), so that an edit shows recognisably at once: on the shared room at an 8 ms budget, whose
 * updates leave about 1 ms, the glass recoloured got 192 rays, fewer than its 500 surfaces, and its
 * lightmap read 18% off the converged one at the edit (2.9% with the full quality at once) and stayed
 * over 5% for 120 updates while the refinement crept on at a few hundred rays an update. */
#define LM_LIGHT_SCALE_LEAST (LM_LIGHT_SCALE_WORK / 8)
/* A texel whose factor is this near 1 in every channel keeps its value: the light it sees barely changed
 * (the edge of a closed door lit from the far room), and rewriting it would cost an engine a re-read and
 * the schedule a regather for nothing visible (lmgi bench --edits, "outside its reach"). */
#define LM_LIGHT_SCALE_KEEP 1e-3f
/* After an edit that adds light (lm_light_scale_begin's `adds`), a texel whose gathers saw more than this
 * times as much light after it as before (none before: a dark room whose lamp is switched on) takes the
 * change they saw added rather than their ratio, which would leave what was dark dark: the two gathers'
 * mean difference over its window estimates what its regather adds, to the gathers' noise (16 rays a
 * texel summed over 3 x 3 at the full quality). */
#define LM_LIGHT_SCALE_DARK 16.0
/* Texels either side a texel's factor sums its surface's gathers over (1: a 3 x 3 window). One texel's 16
 * rays left the factor noisy where a large change fills part of its view: the Cornell box's red wall
 * recoloured blue read 0.050 from a fresh updater's lightmap at the next update, blotched; summed over
 * 3 x 3 texels 0.0215, over 5 x 5 0.024 and 7 x 7 0.031 (the factor's own change across them); the shared
 * room's lamp dimmed 0.018, 0.017, 0.019 and 0.021. */
#define LM_LIGHT_SCALE_SPREAD 1
/* Texels a refinement gathers between looks at the time it was given (lm_light_scale_refine): two of the
 * gather's dynamic chunks of 16 for each of two cores, 1 to 9 ms at 16 rays a texel on the shared room. */
#define LM_LIGHT_SCALE_CHUNK 64u

typedef struct {
    const lm_scene *scene;
    const lm_atlas *atlas;
    const lm_rt *rt;
    const lm_hemicube_settings *set; /* the gather's (offset, sky) */
} lm_light_scale_world;

/* Texel i's ray gather by r (photonmap/hemicube_rim.h) into e, from its frame as the gather sees it, with its
 * seed (lm_gather_texel_seed): the rays every texel gather of this layer casts (a light edit's two,
 * update/ray_estimate.h's). Thread-safe as lm_rim_irradiance is. */
void lm_light_scale_texel_rim(const lm_light_scale_world *w, const lm_rim *r, uint32_t i, float e[3]);


typedef struct {
    float *before, *emissive_before; /* owned: the dilated AIM and per material emission before the edit */
    float *surface_factor;           /* surface_count x 3 */
    float *e;                        /* texel_count x 6: the gathers before (first half) and after */
    uint8_t *done;                   /* per texel: its gathers are in e */
    uint8_t *kept;                   /* per texel: regathered since the edit (no factor applies) */
    uint8_t *black;                  /* owned, may be NULL: per texel, 1 where the IIM was black at the edit */
    float *applied;                  /* texel_count x 3: the factor the IIM holds of this edit */
    float *added;                    /* texel_count x 3: and what it added after it (LM_LIGHT_SCALE_DARK) */
    float least;                     /* the smallest addition applied (light_scale.c, least_add); negative:
                                        the edit adds no light (lm_light_scale_begin's adds), nothing is */
    uint32_t *range;                 /* per surface: its run of texels [range[2 k], range[2 k + 1]) */
    int *order, count;               /* the surfaces with texels, in the refinement's order */
    uint32_t *list;                  /* scratch: the texels one refinement step gathers */
    int at;                          /* order[at]: the surface under way */
    uint32_t next;                   /* its first texel not yet gathered (0: none yet) */
    int active;                      /* a refinement is under way */
} lm_light_scale;

void lm_light_scale_init(lm_light_scale *ls);
/* Ends the job: texels the refinement had not reached keep their first guess (regathers refine them). */
void lm_light_scale_free(lm_light_scale *ls);

/* A new edit's factors into factor and additions into add (a->texel_count x 3 each): the IIM becomes
 * IIM x factor + add now. Ends a job under way first; takes before, emissive_before and black (malloc'd;
 * before NULL: each texel takes its surface's factor; emissive_before NULL: the scene's now; black, per
 * texel 1 where every map the IIM blends is black, NULL: not known). after: the dilated
 * AIM now; surface_factor: surface_count x 3; adds: the edit lit a light where it gave no light (added or
 * switched on), so that texels dark before take the change added (header). rays: the rays of one gather
 * the update may cast (0: no bound, the full quality at once). doubt (a->texel_count): each factor's
 * relative standard error at the full quality (light_scale.c, window_doubt; 0 where a first guess's few
 * rays leave it to the refinement). Returns the rays of one gather cast. */
uint32_t lm_light_scale_begin(lm_light_scale *ls, const lm_light_scale_world *w, float *before,
                              float *emissive_before, uint8_t *black, const float *after, const float *surface_factor,
                              int adds, uint32_t rays, float *factor, float *add, float *doubt);
/* The next texels at the full quality, until about `rays` rays of one gather are cast (at least one
 * texel's; 0: every one left), or, past `ms` milliseconds (> 0), at the end of the chunk of
 * LM_LIGHT_SCALE_CHUNK texels under way (the first chunk always): factor and add (texel_count x 3 each)
 * get the correction of each texel of the surfaces that completed (IIM x factor + add), 1 and 0
 * elsewhere, and doubt (texel_count) their refined factors' relative standard error, 0 elsewhere;
 * *corrected: whether any is not (else the IIM needs no pass). Returns the rays cast (0: no job under
 * way). With ms the texels reached depend on the machine's speed, as any budget's work does. */
uint32_t lm_light_scale_refine(lm_light_scale *ls, const lm_light_scale_world *w, const float *after, uint32_t rays,
                               double ms, float *factor, float *add, float *doubt, int *corrected);
/* The texels (atlas texel indices) regathered this update: they keep their fresh value. */
void lm_light_scale_regathered(lm_light_scale *ls, const uint32_t *texels, uint32_t n);
/* The rays of one gather the refinement has still to cast (0: none under way). */
uint32_t lm_light_scale_waiting(const lm_light_scale *ls, const lm_atlas *a);

#endif
