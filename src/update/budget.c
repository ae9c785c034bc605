#include "budget.h"

#include <string.h>

#include "../core/stats.h"

void lm_cost_model_seed(lm_cost_model *m, double ms_per_unit)
{
    memset(m, 0, sizeof *m);
    m->per_unit[0] = ms_per_unit;
    m->samples = 1;
}

void lm_cost_model_learn(lm_cost_model *m, double ms_stage, uint32_t units, double ms_rest)
{
    int i = m->samples % LM_COST_WINDOW;
    m->rest[i] = ms_rest;
    m->per_unit[i] = units > 0 ? ms_stage / units : m->per_unit[(m->samples - 1) % LM_COST_WINDOW];
    m->samples++;
}

/* The 95th percentile of the ring's first n samples (sorting a copy). */
static double p95(const double *v, int n)
{
    double sorted[LM_COST_WINDOW];
    memcpy(sorted, v, sizeof *v * (size_t)n);
    return lm_quantile(sorted, n, 0.95);
}

static int window(const lm_cost_model *m) { return m->samples < LM_COST_WINDOW ? m->samples : LM_COST_WINDOW; }

double lm_cost_model_price(const lm_cost_model *m) { return p95(m->per_unit, window(m)); }
double lm_cost_model_rest(const lm_cost_model *m) { return p95(m->rest, window(m)); }

int lm_cost_units(double ms, double per_unit, int most)
{
    double units = ms / (per_unit > 1e-6 ? per_unit : 1e-6);
    double top = most > 0 ? most : 1;
    return units < 1.0 ? 1 : units > top ? (int)top : (int)units;
}

int lm_cost_model_units(const lm_cost_model *m, double budget_ms, int most)
{
    int n = window(m);
    return lm_cost_units(budget_ms - p95(m->rest, n), p95(m->per_unit, n), most);
}
