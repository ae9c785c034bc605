/* A time budget turned into work (DESIGN.md: budgets are update/'s): the cost model of one stage whose
 * work comes in units (the IIM gather's texels, photon groups, AIM hits, caustic photons, environment
 * map faces: each stage a model of its own, budget_plan.h shares the budget among them).
 *
 * Layout: the last LM_COST_WINDOW steps' milliseconds per unit of the stage and the milliseconds of the
 * rest of each step, a ring. Units that fit in budget_ms = (budget - p95(rest)) / p95(ms per unit): the
 * 95th percentiles, so that the 95th percentile step keeps within the budget (a mean would let half of
 * them run over: a gather's cost per texel varies by a third with the surfaces it draws; docs/bench.md).
 * The cost per unit includes the stage's per-pass and upload costs, so a small batch looks dearer per
 * unit; n = (budget - rest) / (cost / n) still settles where the stage fills what the rest leaves.
 *
 * Invariants: samples >= 1 once seeded (the first guess); a step that did no unit of work keeps the last
 * cost per unit. Cost: O(LM_COST_WINDOW log LM_COST_WINDOW) a query (sorting a copy). Not thread-safe:
 * one model per stage, used by the thread that steps it. No errors. */
#ifndef LM_BUDGET_H
#define LM_BUDGET_H

#include <stdint.h>

#define LM_COST_WINDOW 32

typedef struct {
    double per_unit[LM_COST_WINDOW]; /* ms per unit of the stage */
    double rest[LM_COST_WINDOW];     /* ms of the rest of the step */
    int samples;                     /* taken (the ring holds the last min(samples, LM_COST_WINDOW)) */
} lm_cost_model;

/* The first guess, before any step: ms_per_unit (e.g. the first full gather's cost per texel; small
 * per-step batches cost more per unit, which the model learns from the first step on), no other work. */
void lm_cost_model_seed(lm_cost_model *m, double ms_per_unit);
/* One step's costs: ms_stage over `units` units (0: the cost per unit stays the last one), ms_rest the
 * rest of the step. */
void lm_cost_model_learn(lm_cost_model *m, double ms_stage, uint32_t units, double ms_rest);
/* The units that fit in budget_ms, at least 1, at most `most`. */
int lm_cost_model_units(const lm_cost_model *m, double budget_ms, int most);
/* The units at per_unit ms each (at least 1e-6) that fit in ms, at least 1, at most `most` (1 if most <= 0):
 * lm_cost_model_units' rule, for a unit priced from several models (budget_plan.c: a texel and its
 * estimates). */
int lm_cost_units(double ms, double per_unit, int most);
/* The 95th percentile of the milliseconds per unit (what lm_cost_model_units prices a unit at). */
double lm_cost_model_price(const lm_cost_model *m);
/* The 95th percentile of the milliseconds of the rest of the step. */
double lm_cost_model_rest(const lm_cost_model *m);

#endif
