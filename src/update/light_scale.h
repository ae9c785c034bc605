/* The lightmap's first guess after lights changed in power alone (issue 32, item 2; docs/tradeoff.md,
 * "Light edits at once"). A light's photons keep their paths when only its colour, intensity or switch
 * changes, so the photon stage scales their hits and each surface's AIM by how much the flux of its hits
 * changed (update/photon_stage.h). An IIM texel's light is what it sees of those AIMs, so its own factor
 * is the ratio of two small ray gathers from the texel, through the same rays, over the AIM before and
 * after the scaling (and the emitters' emission before and after):
 *
 *     f(texel) = E_after / E_before   per channel (photonmap/hemicube_rim.h with the whole hemisphere)
 *
 * a mean of the seen surfaces' factors weighed by how much light each brings (emitters and the sky, which
 * the edit did not change, weigh in with 1), summed over the texel's neighbours on its surface
 * (LM_LIGHT_SCALE_SPREAD). Both gathers meet the same points, so the ratio is far less
 * noisy than either: in a scene lit by one emitter every factor is the light's own and the IIM is
 * exact at once; where several light the seen surfaces in different proportions it is a first guess
 * that the regathers the scaled hits call for refine. A texel whose rays met no light before takes its
 * surface's factor (1 where they meet none after either).
 *
 * Cost: two gathers of K rays a texel, each ray with its 16 AIM lookups (K = LM_LIGHT_SCALE_WORK / texels
 * rounded down to a square, at most 64: 16 at `run`'s 1,800 texels), on every OpenMP thread, once, in the
 * update that sees the edit (34 ms on the shared room at 1,800 texels, 2 cores). Past LM_LIGHT_SCALE_WORK / 4
 * texels only every stride-th gathers with K = 4, and each texel sums over a window wide enough to hold
 * about two that did (its surface's factor where it holds none): the work stays bounded on any atlas. Errors: none (deterministic: each
 * texel's rays are seeded by its index). Thread-safe as the tracer is. */
#ifndef LM_LIGHT_SCALE_H
#define LM_LIGHT_SCALE_H

#include "../charts/charts.h"
#include "../gpu/gather/hemicube.h"
#include "../scene/scene.h"
#include "../trace/rt_scene.h"

#define LM_LIGHT_SCALE_WORK 32768u /* rays one of the two gathers takes at most */
/* A texel whose factor is this near 1 in every channel keeps its value: the light it sees barely changed
 * (the edge of a closed door lit from the far room), and rewriting it would cost an engine a re-read and
 * the schedule a regather for nothing visible (lmgi bench --edits, "outside its reach"). */
#define LM_LIGHT_SCALE_KEEP 1e-3f
/* Texels either side a texel's factor sums its surface's gathers over (1: a 3 x 3 window). One texel's 16
 * rays left the factor noisy where a large change fills part of its view: the Cornell box's red wall
 * recoloured blue read 0.050 from a fresh updater's lightmap at the next update, blotched; summed over
 * 3 x 3 texels 0.0215, over 5 x 5 0.024 and 7 x 7 0.031 (the factor's own change across them); the shared
 * room's lamp dimmed 0.018, 0.017, 0.019 and 0.021. */
#define LM_LIGHT_SCALE_SPREAD 1

/* before, after: atlas-sized RGBA AIMs, dilated (lm_aim_dilated_rgba; before NULL: each texel takes its
 * surface's factor); emissive_before: per material rgb emission before (NULL: the scene's now);
 * surface_factor: surface_count x 3. texel_factor: a->texel_count x 3, written. set: the gather's (offset,
 * sky). */
void lm_light_scale_texels(const lm_scene *s, const lm_atlas *a, const lm_rt *rt, const lm_hemicube_settings *set,
                           const float *before, const float *emissive_before, const float *after,
                           const float *surface_factor, float *texel_factor);

#endif
