/* Quasi-Monte Carlo numbers: scrambled Halton sequences.
 *
 * Dimension d of point i is the radical inverse of i in the d-th prime base with a fixed digit
 * permutation per dimension (from a fixed seed), so sequences are identical on every run. Photon i's
 * random decisions use its own dimensions: dims 0-1 the initial direction (bases 2 and 3, which makes
 * `index mod 2^a 3^b` a stratum of the first two coordinates), the rest per bounce. */
#ifndef LM_QMC_H
#define LM_QMC_H

#include <stdint.h>

#define LM_QMC_MAX_DIMS 256

/* Scrambled radical inverse, in [0, 1). dim < LM_QMC_MAX_DIMS. Thread-safe after lm_qmc_init. */
double lm_halton(uint32_t dim, uint64_t index);
/* lm_halton for the n dimensions dim .. dim + n - 1 of one point, into out[0 .. n - 1] (one
 * initialization check for all of them: a photon needs several numbers at a time). */
void lm_halton_dims(uint32_t dim, uint32_t n, uint64_t index, double *out);
/* lm_halton_dims as floats for dims dim .. dim + n - 1 < LM_QMC_MAX_DIMS: out[k] within one float ulp
 * of (float)lm_halton (its own tables hold fewer digits per lookup, as floats, so that the ones a
 * photon path touches stay in the L1 cache), lowered to the largest float below 1 where rounding
 * reached 1, so every value is in [0, 1). The photon tracer's form (a photon takes its numbers 1 to 4
 * at a time). */
void lm_halton_dims_float(uint32_t dim, uint32_t n, uint32_t index, float *out);
/* Builds the permutation tables (idempotent; called by lm_halton on first use in a single thread). */
void lm_qmc_init(void);
/* The d-th prime (d = 0 -> 2). */
uint32_t lm_qmc_prime(uint32_t dim);

#endif
