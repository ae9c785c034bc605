#ifndef LM_CLI_BENCH_PHOTONS_H
#define LM_CLI_BENCH_PHOTONS_H
/* Prints the photon-stage benchmarks (part of `lmgi bench`). */
void lm_cli_bench_photons(void);
#endif
