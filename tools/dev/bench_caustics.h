#ifndef LM_DEV_BENCH_CAUSTICS_H
#define LM_DEV_BENCH_CAUSTICS_H
/* Prints the caustics and reflections benchmarks (`lmgi-dev bench`, part of make bench; docs/bench.md,
 * "Caustics and reflections"): the screen-space caustic pass at 512 x 512 with its photons covering about
 * 1, 5, 25 and 100% of the screen, split into splat, tile queries, filter and composite, next to the
 * paper's 37.6 ms (full screen), 0.38 ms (1%) and 0.33 ms (100 queries); the caustic photons' tracing
 * against raw Embree rays on the same scene; an environment map face's cost; and the whole frame on the
 * generated Cornell box with every effect, split by pass. */
void lm_dev_bench_caustics(void);
#endif
