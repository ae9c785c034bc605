#include "order_stats.h"

#include <stdlib.h>

static int ascending(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

double lm_cli_quantile(double *v, int n, double q)
{
    qsort(v, (size_t)n, sizeof *v, ascending);
    return v[(int)(q * (n - 1))];
}

double lm_cli_median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, ascending);
    int h = n / 2;
    return n & 1 ? v[h] : (v[h - 1] + v[h]) / 2.0;
}
