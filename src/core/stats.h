#ifndef LM_STATS_H
#define LM_STATS_H
/* Median of n values (n >= 1); sorts v in place. Benchmarks report medians of repeated runs. */
double lm_median(double *v, int n);
#endif
