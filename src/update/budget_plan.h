/* One time budget for every stage of an update (lm_frame_loop_set_budget; docs/api.md, "The time
 * budget"): how budget_ms is shared by the photon thread's stages (invalid photon groups re-traced, AIM
 * refreshes, caustic photons) and the calling thread's (environment map faces, the IIM gather), each
 * stage's count from a cost model of its own (budget.h) learnt from the updates on this machine.
 *
 * The share. The photon thread's stages take at most half of the budget, in pipeline order: the photons
 * what their invalid groups need, the AIMs what the photons left, the caustic photons the rest of that
 * half. The environment map faces take at most an eighth. A light edit's texel factors take what the
 * rest of recent updates and one texel's gather leave of the whole budget for their first guess in the
 * edit's update (what the edit changed is worth more than an update's regathers), then at most a quarter
 * an update for their refinement. The gather fills what the 95th percentile of
 * everything else in recent updates left (lm_cost_model_units), less what the update already spent
 * waiting for the photon thread's job the last update began (a detached loop: with no frame of the
 * caller's to hide it, all of it; known when the plan is made, so a burst of photon work costs the updates
 * that wait for it, not the LM_COST_WINDOW after), less what the texel factors are planned this update: their work comes in bursts after an edit, and counted into the gather's rest it would
 * starve the gather for LM_COST_WINDOW updates after each. So would the work an edit does at once in
 * its own update (a lit light's photons, AIMs refreshed at once) and the time the photon thread's stages
 * run past their plan while their models learn a new price, which are left out of the rest too. The gather
 * shares its part with the waiting texels' ray estimates (ray_estimate.h), estimates_per_texel of them for
 * each texel gathered, priced as a pair: the texels are the pairs that fit, the estimates what those texels
 * leave (priced into the texel instead, the least unit, a texel and its estimates,
 * cost more than a small budget while a node moved: docs/bench.md). A stage with work waiting gets at least
 * one unit however dear: an update never does nothing while something is stale, and a stage that never
 * fits is not starved (its unit may then pass the budget: one AIM surface's refresh is not split).
 * Without a budget (budget_ms 0) the plan is the settings' fixed counts, the same on every machine.
 *
 * The units: a photon group, a stored hit put in an AIM refresh's kd-trees, a caustic photon (priced by those that
 * cast a ray: a dark light's cost nothing, and a price learnt while a light was off made the first update
 * after it was switched on trace 23,000 photons in 16 ms of a 2 ms plan), a cube
 * face, a texel (its estimate's base included), a ray of a light edit's texel gathers, a waiting texel's
 * estimate. Each model is seeded from the updater's setup (the full trace, every AIM, every caustic
 * photon, every face, the full gather) and learns from every update that did some of its work, so a
 * small batch's fixed costs count into its units' price (the plan errs on the side of less work).
 *
 * Invariants: every model seeded before the first plan. Cost: O(LM_COST_WINDOW log LM_COST_WINDOW) per
 * stage a plan. Not thread-safe: the frame loop's calling thread plans and learns. No errors. */
#ifndef LM_BUDGET_PLAN_H
#define LM_BUDGET_PLAN_H

#include <stdint.h>

#include "budget.h"

/* The stages an update's time goes to; the last, the frame's own passes (blend, direct light, caustic
 * pass, composite), is not planned: it is what the scene and picture cost. */
typedef enum {
    LM_STAGE_PHOTONS,
    LM_STAGE_AIM,
    LM_STAGE_CAUSTICS,
    LM_STAGE_REFLECTIONS,
    LM_STAGE_GATHER,
    LM_STAGE_LIGHT_SCALE,
    LM_STAGE_ESTIMATES,
    LM_STAGE_FRAME,
    LM_STAGE_COUNT
} lm_stage;

#define LM_STAGE_PLANNED LM_STAGE_FRAME /* the stages with a cost model */

/* "photons", "AIM", "caustic photons", "reflections", "gather", "light scale", "estimates", "frame". */
const char *lm_stage_name(lm_stage s);

typedef struct {
    lm_cost_model cost[LM_STAGE_PLANNED];
} lm_budget;

/* The work waiting when an update is planned (what the stages reported last). */
typedef struct {
    uint32_t groups;          /* invalid photon groups queued */
    uint32_t caustic_photons; /* caustic photons queued for whole re-traces */
    int faces;                /* environment map faces (all: an update marks the dirty ones as it goes) */
    int texels;               /* the most texels a step may gather (the atlas) */
    uint32_t scale_rays;      /* rays a light edit's texel factors wait for (an edit's at the full quality) */
    int scale_edit;           /* an edit's first guess waits: it may take what the whole budget leaves */
    int estimates_per_texel;  /* waiting texels' ray estimates an update wants per texel it gathers
                               * (ray_estimate.h; 0: the lightmaps keep none) */
    double ms_spent;          /* what the update spent before its plan that its rest does not hold (the
                               * photon job begun by the last update, waited for): off the budget now */
} lm_budget_work;

/* What the update may do: 0 for groups, aim_hits, caustic_photons or faces means the settings' own
 * count (no budget, or a stage with no model). */
typedef struct {
    uint32_t groups;          /* invalid photon groups re-traced, oldest first */
    uint64_t aim_hits;        /* the AIM refresh's bound on stored hits (its first surface always taken) */
    uint32_t caustic_photons; /* caustic photons traced (whole re-traces first, then the round robin) */
    int faces;                /* environment map faces rendered */
    int texels;               /* IIM texels gathered */
    uint32_t estimates;       /* waiting texels whose ray estimates are brought up to date */
    uint32_t scale_rays;      /* rays a light edit's texel factors cast (update/light_scale.h) */
    double ms[LM_STAGE_PLANNED]; /* the milliseconds the plan expects each to take */
} lm_budget_plan;

/* ms_per_unit: each planned stage's first guess (<= 0: a stage the setup did not measure; 1e-3 ms). */
void lm_budget_seed(lm_budget *b, const double ms_per_unit[LM_STAGE_PLANNED]);
/* The plan of one update within budget_ms (> 0) for the work waiting. */
void lm_budget_plan_step(const lm_budget *b, double budget_ms, const lm_budget_work *w, lm_budget_plan *out);
/* One update's costs: each planned stage's milliseconds over the units it did (0 units: nothing
 * learnt for it), the whole update's milliseconds, and of those the milliseconds set aside: the edits'
 * work done at once (a light traced as it was lit, AIMs refreshed for a light or colour edit) and how far
 * the photon thread's stages ran past their plan (a price their own models learn). The gather's rest is
 * the update less the gather, the estimates, the texel factors and what is set aside: counted into the rest, a burst
 * would starve the gather for up to LM_COST_WINDOW updates after it (three such in the window are its
 * 95th percentile). */
void lm_budget_learn(lm_budget *b, const double ms[LM_STAGE_PLANNED], const uint64_t units[LM_STAGE_PLANNED],
                     double ms_total, double ms_aside);

#endif
