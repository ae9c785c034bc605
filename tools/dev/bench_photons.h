#ifndef LM_DEV_BENCH_PHOTONS_H
#define LM_DEV_BENCH_PHOTONS_H
/* Prints the photon-stage benchmarks (`lmgi-dev bench`, part of make bench). */
void lm_dev_bench_photons(void);
#endif
