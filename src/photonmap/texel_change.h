/* How much each IIM texel's hemisphere changed since the texel was last gathered (issue 32, item 1): the
 * texel-level priority beside the scheduler's surface order (iim_schedule.h), so that the texels next to a
 * moved object or a changed AIM are regathered first instead of waiting behind their whole surface.
 *
 * Units: a texel's change estimates |dE| / E_mean, the change of its irradiance as a fraction of the
 * scene's mean irradiance (pi times the AIM's mean radiance) since it was last gathered, as two sums:
 *   - A moved node (its world matrix differs from the one last seen): its bounding sphere at the old and at
 *     the new place each give the sphere's form factor from the texel, min(1, r^2/d^2) * clamp(cos + r/d,
 *     0, 1) (a point to a sphere of radius r at distance d, widened near the horizon), and their sum times
 *     min(1, |dc| / r) (the share of the sphere's disc that moved off itself) is added: what that share
 *     covers went from background to object or back, both of about the mean radiance. The node's own
 *     texels add min(1, |dx| / r + (1 - n_old . n_new)): their whole hemisphere shifted.
 *   - A refreshed AIM: each 4 x 4 atlas block of the surface adds, at every texel of other surfaces,
 *     dL A cos_t cos_b / (d^2 + A / pi) / E_mean (the disc approximation of the form factor), dL the
 *     block's mean change of radiance since the AIM was last seen, to a signed sum (the irradiance's
 *     change to first order: photon noise and changes undone cancel; `lit`),
 *     at the texels of the surfaces that see the block's (lm_delta_i_sees); occlusion within is ignored:
 *     an over-estimate, which only orders the work. When blocks x texels would exceed LM_TEXEL_CHANGE_WORK,
 *     whole surfaces are the emitters instead; past that too, the surface order alone carries it (a change
 *     that reaches everything is not local).
 *   - A light's edit whose factor (update/light_scale.h) is in doubt: twice the factor's relative standard
 *     error (lm_texel_change_doubt), kept apart, since it is the texel's own error and not a change that
 *     reached everything alike.
 * A texel's change is the motion sum plus the magnitude of the signed sum plus the doubt. Picking takes the
 * texels whose change is over the threshold and, less the doubt, over 4 times the atlas's median change (a
 * change that reaches everything alike, a light dimmed, is the surfaces' order's to follow; the median, not
 * the mean, so that the large sums of a moved node's own faces do not lift the bar over the texels around
 * it) or whose doubt alone is over the threshold, most changed first, then by index, and zeroes them.
 * A texel gathered for a move right after it saw the AIMs around as the move's photons had yet to change
 * them (the moved cube's faces saw the floor without its new shadow, 40% too bright, and the AIMs' later
 * refreshes lent them too little change to pass the bar: 200 updates until the surfaces' order came
 * round). So the motion sum is also kept aside, unsettled, and added to the change again once the photon
 * stage has caught up (lm_texel_change_settle): the moved texels are gathered once more, from AIMs that
 * have caught up. Unless the stage caught up before the move's first gather (a placement after a still
 * update, update/photon_stage.c catch_up): a second pass then only doubled the move's work, and the
 * texels it changed least waited behind it.
 *
 * Layout: per atlas texel (lm_atlas.texels order) change, world position and normal (kept current for
 * moved nodes), the unsettled motion sum, the doubt and the AIM radiance last looked at; per node its last
 * world matrix and local bounding sphere. Memory: 44 bytes a texel, 80 a node.
 * Cost: O(texels of moved nodes + moved nodes x texels) per moved frame; O(blocks x texels) for AIM
 * changes, bounded as said (a few ms); O(texels log budget) to pick, the median over at most 8,192 texels
 * (every stride-th) with a scratch copy of them. Nothing when nothing changed.
 * Deterministic (fixed order, no threads). Not thread-safe: the scene and AIM must not change meanwhile. */
#ifndef LM_TEXEL_CHANGE_H
#define LM_TEXEL_CHANGE_H

#include <stdint.h>

#include "../charts/charts.h"
#include "../core/error.h"
#include "../scene/scene.h"
#include "../trace/rt_scene.h"
#include "iim_schedule.h"

#define LM_TEXEL_CHANGE_WORK 2000000.0 /* emitter x texel pairs a frame before emitters are coarsened */

typedef struct {
    uint32_t texel_count;
    float threshold;      /* a texel is picked when its change exceeds this */
    float *change;        /* per texel: what moved nodes changed (unsigned, summed) */
    float *lit;           /* per texel: what changed AIMs changed, signed (first order in their change) */
    float *unsettled;     /* per texel: the motion sum since the last lm_texel_change_settle */
    float *doubt;         /* per texel: how far a light edit's factor may be off (lm_texel_change_doubt) */
    int any_unsettled;    /* a move since then (else settling has nothing to scan) */
    float *pos, *nrm;     /* per texel, 3 each, world space as last seen */
    float *aim_seen;      /* per texel, 3: AIM radiance as last looked at */
    int node_count;
    float *node_world;    /* per node, 16: world matrix as last seen */
    float *node_sphere;   /* per node, 4: local centre and radius of its vertices (radius < 0: none) */
    int *texel_node;      /* per texel */
    double mean_e;        /* pi x the AIM's mean radiance when last looked at */
} lm_texel_change;

/* aim_rgb: the AIM as it is now (atlas width x height x 3). */
lm_status lm_texel_change_init(lm_texel_change *tc, const lm_scene *s, const lm_atlas *a, const float *aim_rgb,
                               float threshold, lm_error *err);
void lm_texel_change_free(lm_texel_change *tc);

/* Adds the change of every node whose world matrix moved since the last call (or the init). Returns how
 * many nodes moved. `settled`: the photons and AIMs already hold the moves (the photon stage caught up with
 * them before this gather), so the texels gathered from here on see them and none is kept unsettled. */
int lm_texel_change_moved(lm_texel_change *tc, const lm_scene *s, const lm_atlas *a, int settled);
/* The photon stage has no work of a move waiting (no photon group to re-trace, no AIM over its threshold):
 * every texel's unsettled motion sum is added to its change (header) and cleared. Returns how many texels
 * had one. */
uint32_t lm_texel_change_settle(lm_texel_change *tc);
/* Adds the change of the surfaces with refreshed[k] set, comparing aim_rgb with what was last seen, at the
 * texels of the surfaces that see them (lm_delta_i_sees: a few shadow rays per pair of surfaces). */
void lm_texel_change_aim(lm_texel_change *tc, const lm_iim_sched *sched, const lm_scene *s, const lm_atlas *a,
                         const lm_rt *rt, const float *aim_rgb, const uint8_t *refreshed);
/* The AIM radiance last looked at, of every texel of surface k, multiplied by factor[3 k + c]: a light's
 * power edit changed its surface's light so (update/photon_stage.h, lm_photon_stage_take_scale), and the
 * IIM texels that saw it were scaled alike, so a later refresh counts only what came after. */
void lm_texel_change_scale(lm_texel_change *tc, const lm_atlas *a, const float *factor);
/* A material's edit moved every IIM texel to factor x IIM + add at once (update/light_scale.h; texel_count x
 * 3 each): right to first order only, so the texels it moved most are regathered first. Each texel's change
 * grows by its largest channel's |factor - 1| + |add| / E_mean; an edit that moves every texel alike stays
 * under the bar of 4 times the median and is left to the surfaces' order. (The Cornell box's red wall turned
 * blue: the tall block's face toward it kept the first guess's 8.5% for 80 updates, until its surface's
 * refresh came round.) */
void lm_texel_change_first_guess(lm_texel_change *tc, const float *factor, const float *add);
/* A light's edit scaled every IIM texel by a factor whose relative standard error is doubt[texel]
 * (update/light_scale.h): 0 where one light lights what the texel sees, larger where several do in
 * different shares. Each texel's change grows by twice it, kept apart from the rest: a doubted texel goes
 * ahead once that passes the threshold, whatever the atlas's median change (its error is its own, not a
 * change that reached everything alike), so that the texels whose factor may be furthest off are
 * regathered first. */
void lm_texel_change_doubt(lm_texel_change *tc, const float *doubt);
/* At most budget texels over the threshold (and, unless `all`, over 4 times the median or doubted past the
 * threshold: header), not on surfaces with off[k] set, most changed first, written to out (texel indices)
 * and zeroed. A bake asks for all. Returns how many. */
uint32_t lm_texel_change_pick(lm_texel_change *tc, const lm_atlas *a, const uint8_t *off, uint32_t budget, int all,
                              uint32_t *out);
/* The texels over the threshold, not on surfaces with off[k] set, in texel order, into out: those still
 * waiting to be picked. Returns how many. */
uint32_t lm_texel_change_waiting(const lm_texel_change *tc, const lm_atlas *a, const uint8_t *off, uint32_t *out);
/* The texels gathered otherwise (their surfaces' refreshes) start from no change again: left, they kept
 * the atlas's typical change up, and with it the bar a texel must pass to go ahead (a moved cube's face
 * stayed 28% too bright for 120 updates below it). */
void lm_texel_change_gathered(lm_texel_change *tc, const uint32_t *texels, uint32_t count);
/* The largest share of texel's hemisphere (its form factor, widened near the horizon as the changes' are)
 * that the bounding sphere of a node that moves (lm_node_moves), other than its own, fills where it was last
 * seen (lm_texel_change_moved). O(nodes). */
float lm_texel_change_node_near(const lm_texel_change *tc, const lm_scene *s, uint32_t texel);
/* Texel t's change (header). */
float lm_texel_change_of(const lm_texel_change *tc, uint32_t texel);
/* saved (LM_TEXEL_CHANGE_SAVED x texel_count floats) = every texel's change, for a bake that may be
 * cancelled; restore gives it back (what the cancelled bake picked is picked again). */
#define LM_TEXEL_CHANGE_SAVED 4
void lm_texel_change_save(const lm_texel_change *tc, float *saved);
void lm_texel_change_restore(lm_texel_change *tc, const float *saved);

#endif
