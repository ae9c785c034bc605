#ifndef LM_STATS_H
#define LM_STATS_H
/* Median of n values (n >= 1); sorts v in place. Benchmarks report medians of repeated runs. */
double lm_median(double *v, int n);
/* The q-quantile (0..1) of n values by the nearest rank below, v[(int)(q (n - 1))] once sorted; sorts v
 * in place. Budgets are judged by their 95th percentile. */
double lm_quantile(double *v, int n, double q);
#endif
