#ifndef LM_DEV_BENCH_GATHER_H
#define LM_DEV_BENCH_GATHER_H
/* Prints the final-gather benchmarks (`lmgi-dev bench`, part of make bench): time per gathered texel for the Cornell box
 * at about 34, 13,000 and 133,000 triangles (big_cornell: the generated 131k-triangle variant, or NULL),
 * with and without the proxy, next to the paper's Table 2; the pass schemes side by side; and an Embree
 * ray-cast gather of the same texels with 1,024 rays. */
void lm_dev_bench_gather(const char *big_cornell);
#endif
