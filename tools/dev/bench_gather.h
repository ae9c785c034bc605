#ifndef LM_DEV_BENCH_GATHER_H
#define LM_DEV_BENCH_GATHER_H
/* Prints the final-gather benchmarks (`lmgi-dev bench`, part of make bench): time per gathered texel for the Cornell box
 * at about 34, 13,000 and 133,000 triangles (big_cornell: the generated 131k-triangle variant, or NULL),
 * with and without the proxy, next to the paper's Table 2; the pass schemes side by side; and an Embree
 * ray-cast gather of the same texels with 1,024 rays. */
void lm_dev_bench_gather(const char *big_cornell);
/* The gather's cost per texel on levels of any size against the first scene given (make bench: the
 * generated Cornell box, the shared levels, generated levels of about 250k and 1M triangles): triangles,
 * the proxy's triangles, ms per texel at the frame loop's defaults, and the ratio to the first. */
void lm_dev_bench_levels(const char *const *paths, int count);
#endif
