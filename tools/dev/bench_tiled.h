#ifndef LM_DEV_BENCH_TILED_H
#define LM_DEV_BENCH_TILED_H
/* Prints the per-pixel photon gather benchmarks (`lmgi-dev bench`, part of make bench; docs/tiled.md,
 * "What it costs"): on the same photons and the same frame, tiled (16-pixel tiles), stochastic tiled
 * (k = 2 and the paper's k = 4), hash grid and brute force, ms per frame at 512 x 512 and 1920 x 1080, on the generated
 * Cornell box at its default photon count and at at least 200,000 stored photons; beside the paper's
 * GTX 670 figures (1080p: tiled 11-28 ms, hash grid 36-79 ms), with the hash grid / tiled ratio and the
 * cost per pixel and candidate photon. The brute force runs at 128 x 128 only (O(pixels x photons)). */
void lm_dev_bench_tiled(void);
#endif
