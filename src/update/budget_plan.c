#include "budget_plan.h"

#include <limits.h>
#include <string.h>

const char *lm_stage_name(lm_stage s)
{
    static const char *names[LM_STAGE_COUNT] = {"photons", "AIM", "caustic photons", "reflections", "gather",
                                                "light scale", "estimates", "frame"};
    return s >= 0 && s < LM_STAGE_COUNT ? names[s] : "none";
}

void lm_budget_seed(lm_budget *b, const double ms_per_unit[LM_STAGE_PLANNED])
{
    for (int s = 0; s < LM_STAGE_PLANNED; s++)
        lm_cost_model_seed(&b->cost[s], ms_per_unit[s] > 0.0 ? ms_per_unit[s] : 1e-3);
}

/* The units of stage s that fit in ms (at least 1, at most `most`) and what they are expected to take. */
static int take(const lm_budget *b, lm_stage s, double ms, long most, double *expected)
{
    int n = lm_cost_model_units(&b->cost[s], ms, most > INT_MAX ? INT_MAX : (int)most);
    *expected = n * lm_cost_model_price(&b->cost[s]);
    return n;
}

/* The gather's ms less its rest, shared by texels and the waiting texels' estimates (header): the
 * (texel, estimates_per_texel estimates) pairs that fit, then the estimates those texels leave room for,
 * the pairs' and what is left short of another pair (at most one a texel of the atlas). */
static void gather_and_estimates(const lm_budget *b, double ms, const lm_budget_work *w, lm_budget_plan *out)
{
    const lm_cost_model *g = &b->cost[LM_STAGE_GATHER];
    double room = ms - lm_cost_model_rest(g), texel = lm_cost_model_price(g);
    double estimate = w->estimates_per_texel > 0 ? lm_cost_model_price(&b->cost[LM_STAGE_ESTIMATES]) : 0.0;
    out->texels = lm_cost_units(room, texel + w->estimates_per_texel * estimate, w->texels);
    out->ms[LM_STAGE_GATHER] = out->texels * texel;
    if (w->estimates_per_texel > 0)
        out->estimates = (uint32_t)take(b, LM_STAGE_ESTIMATES, room - out->ms[LM_STAGE_GATHER], w->texels,
                                        &out->ms[LM_STAGE_ESTIMATES]);
}

void lm_budget_plan_step(const lm_budget *b, double budget_ms, const lm_budget_work *w, lm_budget_plan *out)
{
    memset(out, 0, sizeof *out);
    double *ms = out->ms;
    double left = 0.5 * budget_ms; /* the photon thread's half, in pipeline order */
    if (w->groups > 0) {
        out->groups = (uint32_t)take(b, LM_STAGE_PHOTONS, left, w->groups, &ms[LM_STAGE_PHOTONS]);
        left -= ms[LM_STAGE_PHOTONS];
    }
    /* the AIMs cannot know the hits they will want before the photons are traced: with caustics to keep,
     * half of what is left, else all of it */
    double aim = w->caustic_photons > 0 ? 0.5 * left : left;
    out->aim_hits = (uint64_t)take(b, LM_STAGE_AIM, aim, INT_MAX, &ms[LM_STAGE_AIM]);
    left -= ms[LM_STAGE_AIM];
    if (w->caustic_photons > 0)
        out->caustic_photons = (uint32_t)take(b, LM_STAGE_CAUSTICS, left, w->caustic_photons, &ms[LM_STAGE_CAUSTICS]);
    if (w->faces > 0)
        out->faces = take(b, LM_STAGE_REFLECTIONS, 0.125 * budget_ms, w->faces, &ms[LM_STAGE_REFLECTIONS]);
    /* what the rest of recent updates and one texel's gather leave, at most a quarter but for an edit's
     * first guess; planned with no work waiting too: an edit the photon stage takes after this plan (in
     * order, its update follows the plan) is bounded */
    const lm_cost_model *g = &b->cost[LM_STAGE_GATHER];
    double spare = budget_ms - w->ms_spent - lm_cost_model_rest(g) - lm_cost_model_price(g);
    if (!w->scale_edit && spare > 0.25 * budget_ms)
        spare = 0.25 * budget_ms;
    out->scale_rays = (uint32_t)take(b, LM_STAGE_LIGHT_SCALE, spare, w->scale_rays > 0 ? w->scale_rays : INT_MAX,
                                     &ms[LM_STAGE_LIGHT_SCALE]);
    double gather = (w->scale_rays > 0 ? budget_ms - ms[LM_STAGE_LIGHT_SCALE] : budget_ms) - w->ms_spent;
    gather_and_estimates(b, gather, w, out);
}

void lm_budget_learn(lm_budget *b, const double ms[LM_STAGE_PLANNED], const uint64_t units[LM_STAGE_PLANNED],
                     double ms_total, double ms_aside)
{
    for (int s = 0; s < LM_STAGE_PLANNED; s++) {
        uint32_t n = units[s] > UINT32_MAX ? UINT32_MAX : (uint32_t)units[s];
        if (s == LM_STAGE_GATHER) { /* its rest: everything else the update did but the estimates, the texel
                                    * factors and what is aside */
            double rest = ms_total - ms[s] - ms[LM_STAGE_ESTIMATES] - ms[LM_STAGE_LIGHT_SCALE] - ms_aside;
            lm_cost_model_learn(&b->cost[s], ms[s], n, rest > 0.0 ? rest : 0.0);
        }
        else if (n > 0)
            lm_cost_model_learn(&b->cost[s], ms[s], n, 0.0);
    }
}
