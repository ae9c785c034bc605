/* Order statistics of timings: benchmarks report medians of repeated runs and judge budgets by their
 * 95th percentile. */
#ifndef LM_CLI_ORDER_STATS_H
#define LM_CLI_ORDER_STATS_H

/* Both sort v (n >= 1 values) in place. The quantile q (0..1) is the nearest rank below,
 * v[(int)(q (n - 1))] of the sorted values, as the library's budget model takes it. */
double lm_cli_median(double *v, int n);
double lm_cli_quantile(double *v, int n, double q);

#endif
