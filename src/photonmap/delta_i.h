/* Delta_i beyond the IIM scheduler (iim_schedule.h picks texels from it and resets it): the one place
 * that reads or writes the photon store's delta_i for anything else.
 *
 *   - Viewers of refreshed AIMs. A surface whose own photons did not change may still see one whose AIM
 *     was refreshed (the cube beside a recoloured wall that no changed photon reached): its hemicube
 *     would show the old light, so its delta_i is raised just over the threshold and it is regathered.
 *     "Sees" is tested with SEE_PAIRS texel pairs spread over both surfaces that face each other and are
 *     joined by an unoccluded segment (each end lifted off its surface along its normal, by 1e-3 of the
 *     scene's size). False negatives are possible through gaps narrower than the pairs' spacing.
 *     Cost: O(surfaces^2 x SEE_PAIRS) shadow rays at worst, when an AIM was refreshed; nothing otherwise.
 *   - A cancelled bake gives back the delta_i it took (lm_delta_i_save / lm_delta_i_restore), so what it
 *     left unfinished is redone by a later bake or step.
 *   - The share of a surface's light not gathered yet (lm_delta_i_pending), for the updater's estimate
 *     of how stale the lightmaps are.
 *
 * Not thread-safe: the photon store must not be updated meanwhile (the stage's worker quiet). */
#ifndef LM_DELTA_I_H
#define LM_DELTA_I_H

#include <stdint.h>

#include "../charts/charts.h"
#include "../scene/scene.h"
#include "../trace/photon_store.h"
#include "../trace/rt_scene.h"
#include "iim_schedule.h"

/* Raises delta_i of each surface not already over the threshold that sees a surface with refreshed[b]
 * set (the scene as it is now: nodes may have moved since load). A surface whose refresh is under way
 * and that sees one is asked to refresh again once it completes (lm_iim_sched_again): the texels it
 * gathered before saw the old AIM, and completing resets its delta_i (in the two rooms with room B's
 * lights removed, the ceiling's first texels kept their light for good). Returns how many were raised
 * or asked again. */
int lm_delta_i_widen_to_viewers(lm_iim_sched *sched, lm_photon_store *ps, const uint8_t *refreshed,
                                const lm_scene *s, const lm_atlas *a, const lm_rt *rt);

/* Whether surface a sees surface b, as above (SEE_PAIRS texel pairs; the scene as it is now). */
int lm_delta_i_sees(const lm_iim_sched *sched, const lm_scene *s, const lm_atlas *a, const lm_rt *rt, int sa, int sb);

/* saved[s] = surface s's delta_i, for every surface of the scheduler. */
void lm_delta_i_save(const lm_iim_sched *sched, const lm_photon_store *ps, double *saved);
/* The surfaces whose refresh completed but was not committed (a cancelled bake) get their saved delta_i
 * back and lose the commit flag. */
void lm_delta_i_restore(lm_iim_sched *sched, lm_photon_store *ps, const double *saved);

/* Surface s's delta_i over its stored IIM energy: an upper bound of the relative change of the light its
 * photons bring since its IIM was refreshed; 1 when that cannot be said (no energy stored), 0 when
 * nothing changed. */
double lm_delta_i_pending(const lm_photon_store *ps, int s);

#endif
