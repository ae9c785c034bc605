/* The lightmap path of indirect light (Larsen & Christensen sections 3-4): the photon stage's AIMs
 * gathered by hemicubes into double-buffered IIMs, texels chosen by delta_i, blended into the displayed
 * lightmap. The frame loop (frame_loop.h) conducts it: per step schedule, gather, then blend; a bake
 * regathers every texel whose light changed and shows it at once.
 *
 * It owns the gather (gpu/gather/hemicube.h), the IIMs and their scheduler (gpu/gather/iim.h), the closed-form emitter
 * light the gather adds (trace/emitter_light.h), the AIM upload and the waiting texels' estimates from a few
 * rays (ray_estimate.h: every texel's base before the scene first changes, lm_lightmap_path_before_change,
 * each gathered texel's again as it is). It exists on every loop (a loop on a
 * photon path, or one with indirect light off, has every surface switched off: nothing is gathered and
 * the lightmaps stay 0), and follows the scene's light: a scene with no light gathers nothing, and the
 * IIM is cleared when the last light goes; a light that comes back regathers every surface in full.
 *
 * Reads the photon stage's AIMs, store and refreshed surfaces: only while its worker is quiet (the loop
 * calls schedule before it starts the worker and after it joins). GL calls: on the thread whose context
 * is current. The settings are the loop's, borrowed: the path resolves gather.coverage_samples and
 * emitter_light in them. */
#ifndef LM_LIGHTMAP_PATH_H
#define LM_LIGHTMAP_PATH_H

/* A node placed after a still update is caught up in its own update (photon_stage.c catch_up), and nodes
 * placed by edits in a row (a drag) at the first update without edits after them: their photons and AIMs,
 * then their texels, this many updates' worth of those picked ahead (texel_change.h), gathered and shown
 * at once, without the blend. At 16 the Cornell box's cube move left two blocks 10-11% off for 3 updates; at
 * 32 every block was within 10% at once (tests/test_motion_trail.c). */
#define LM_CATCH_UP_UPDATES 32

#include "frame_settings.h"
#include "world.h"

typedef struct lm_lightmap_path lm_lightmap_path;

/* The gather, emitters and IIMs (GL context current); no texel gathered yet. */
lm_status lm_lightmap_path_create(const lm_world *w, lm_photon_stage *stage, lm_frame_loop_settings *set,
                                  lm_lightmap_path **out, lm_error *err);
void lm_lightmap_path_free(lm_lightmap_path *lp);
/* The first full gather of every texel (checkpointed, resumed, sharded or put together from parts as the
 * settings say: gather_passes.h), shown at once; then the settings' progress, cancel and checkpoint are
 * cleared (per-step gathers are small). *t_gather (may be NULL): its seconds. */
lm_status lm_lightmap_path_first(lm_lightmap_path *lp, double *t_gather, lm_error *err);
/* Called before anything changes the scene (an edit, a node moved, an animation evaluated): where waiting
 * texels show ray estimates and none were begun, every texel's base is taken now, over the scene and AIMs
 * the gathers so far read (ray_estimate.h). lm_lightmap_path_first takes them at once in a scene with a
 * dynamic node or an animation, so that a drag's first step does not wait for them; a level without
 * either pays for them at its first edit, and one that is never edited never does (on truck-town they
 * were a fifth of the setup). Cheap after the first call. No GL needed; the photon work must be waited
 * for (lm_frame_loop_sync). Fails only for want of memory. */
lm_status lm_lightmap_path_before_change(lm_lightmap_path *lp, lm_error *err);

/* Follows the scene's light and its nodes' indirect switches (lm_scene.pass_version): surfaces switched
 * on or off in the scheduler, the IIM cleared when the scene lost its last light. */
lm_status lm_lightmap_path_follow(lm_lightmap_path *lp, lm_error *err);
/* The AIMs changed (the stage refreshed some): uploaded again before the next gather. */
void lm_lightmap_path_aim_changed(lm_lightmap_path *lp);
/* As aim_changed, from a placement's catch-up in this step's animate (photon_stage.h placed): the
 * step's gather sees the moves, so their texels are not gathered a second time (texel_change.h). */
void lm_lightmap_path_caught_up(lm_lightmap_path *lp);
/* Surfaces that see a refreshed AIM marked for regathering (photonmap/delta_i.h); returns how many. */
int lm_lightmap_path_widen(lm_lightmap_path *lp);
/* This step's texels: viewers widened, then picked by the scheduler (*count of them), and the scene and
 * AIM uploaded when any is to be gathered. After it the stage may run again. */
lm_status lm_lightmap_path_schedule(lm_lightmap_path *lp, uint32_t *count, lm_error *err);
/* Gathers the count texels schedule picked into the fresh IIM. */
lm_status lm_lightmap_path_gather(lm_lightmap_path *lp, uint32_t count, lm_error *err);
/* Blends what completed into the displayed IIM (instant: shown at once). */
lm_status lm_lightmap_path_blend(lm_lightmap_path *lp, int instant, lm_error *err);
/* Every texel of every surface whose light changed gathered a pass at a time and committed at once. A
 * cancel gives the scheduled surfaces their delta_i back and commits nothing of them. Fills out's
 * texels_gathered and surfaces_changed; progress (may be NULL) hears 0.3 to 1 of the whole bake. */
lm_status lm_lightmap_path_bake(lm_lightmap_path *lp, lm_bake_progress progress, void *user,
                                const volatile int *cancel, uint32_t *texels, int *surfaces_changed,
                                lm_error *err);

lm_iim *lm_lightmap_path_iim(lm_lightmap_path *lp);
const lm_iim *lm_lightmap_path_iim_const(const lm_lightmap_path *lp);
void lm_lightmap_path_set_texels_per_frame(lm_lightmap_path *lp, int texels);
/* The waiting texels an update brings their ray estimates up to date for (ray_estimate.h; 0: none), and how
 * many the last schedule did, with their bases, in *seconds (may be NULL): the gather's work, wherever the
 * step times its schedule; of those, the waiting texels' estimates alone in *waiting_seconds (may be NULL;
 * the budget's stage of their own, budget_plan.h). Whether the lightmaps keep ray estimates now. */
void lm_lightmap_path_set_ray_budget(lm_lightmap_path *lp, uint32_t texels);
uint32_t lm_lightmap_path_estimated(const lm_lightmap_path *lp, double *seconds, double *waiting_seconds);
int lm_lightmap_path_has_rays(const lm_lightmap_path *lp);
/* The texels whose ray estimate's base was taken (those gathered, every texel at the start) since the last
 * call, which zeroes it; the setup's are not counted. */
uint32_t lm_lightmap_path_take_based(lm_lightmap_path *lp);
/* The rays a light edit's texel factors may cast an update (update/light_scale.h; 0: no bound, the full
 * quality in the edit's update) and the milliseconds its refinement may take (0: no bound), what its
 * refinement still has to cast, and the rays it cast and the milliseconds it took since the last take
 * (then zeroed). */
void lm_lightmap_path_set_scale_rays(lm_lightmap_path *lp, uint32_t rays, double ms);
uint32_t lm_lightmap_path_scale_waiting(const lm_lightmap_path *lp);
uint64_t lm_lightmap_path_take_scale_work(lm_lightmap_path *lp, double *ms);
/* The displayed IIM's atlas window win = {x, y, w, h} read back (w*h RGBA floats; caller frees). */
lm_status lm_lightmap_path_read_window(const lm_lightmap_path *lp, const int win[4], float **rgba, lm_error *err);
/* How stale the displayed IIM is per atlas pixel (lm_frame_loop_iim_error says what it measures). */
lm_status lm_lightmap_path_staleness(const lm_lightmap_path *lp, const float *shown, float *error, lm_error *err);
/* The lightmaps' estimate of their own accuracy (lm_frame_loop_accuracy). */
lm_status lm_lightmap_path_accuracy(const lm_lightmap_path *lp, const float *shown, float *out, lm_error *err);

#endif
