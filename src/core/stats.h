#ifndef LM_STATS_H
#define LM_STATS_H
/* Median of n values (n >= 1); sorts v in place. Benchmarks report medians of repeated runs. */
double lm_median(double *v, int n);
/* The q-quantile (0..1) of n values by the nearest rank below, v[(int)(q (n - 1))] once sorted; sorts v
 * in place. Budgets are judged by their 95th percentile. */
double lm_quantile(double *v, int n, double q);
/* The first of n (>= 1) cumulative shares cdf[] (non-decreasing, the last 1) above u in [0, 1): the entry u
 * draws from the table; the last when none is (u rounded up to 1). */
static inline unsigned lm_cdf_draw(const double *cdf, unsigned n, double u)
{
    unsigned lo = 0, hi = n - 1;
    while (lo < hi) {
        unsigned mid = (lo + hi) / 2;
        if (cdf[mid] > u)
            hi = mid;
        else
            lo = mid + 1;
    }
    return lo;
}
#endif
