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

/* The float path's tables, for lm_halton_float (inline: a photon bounce takes its numbers one or
 * two at a time, and a call per number cost a third of the number). Built by lm_qmc_init. */
typedef struct {
    uint32_t chunk;       /* b^k <= 256 */
    double inv_chunk;     /* 1 / chunk */
    uint64_t magic;       /* ceil(2^64 / chunk): i / chunk as one multiply (qmc.c) */
    const float *table;   /* chunk entries: permuted radical inverse of k digits */
} lm_qmc_fdim;
extern lm_qmc_fdim lm_qmc_fdims[LM_QMC_MAX_DIMS];

/* Index i split as i = q chunk + r with one 64 x 64 -> 128-bit multiply: q = floor(i magic / 2^64),
 * magic = ceil(2^64 / chunk), which is exact for every 32-bit i and chunk < 2^32 (Lemire, Kaser and
 * Kurz 2019, "Faster remainder by direct computation"). No division, no rounding correction. */
static inline uint32_t lm_qmc_split(uint64_t magic, uint32_t chunk, uint32_t i, uint32_t *r)
{
    uint32_t q = (uint32_t)(((unsigned __int128)magic * i) >> 64);
    *r = i - q * chunk;
    return q;
}

/* One number of lm_halton_dims_float (the same value bit for bit), without the initialization
 * check: call lm_qmc_init (or any other function here) once before. dim < LM_QMC_MAX_DIMS. */
static inline float lm_halton_float(uint32_t dim, uint32_t index)
{
    const lm_qmc_fdim *d = &lm_qmc_fdims[dim];
    uint32_t r, q = lm_qmc_split(d->magic, d->chunk, index, &r);
    double v = d->table[r], scale = d->inv_chunk;
    while (q != 0) {
        q = lm_qmc_split(d->magic, d->chunk, q, &r);
        v += d->table[r] * scale;
        scale *= d->inv_chunk;
    }
    float f = (float)v;
    return f < 1.0f ? f : 0x1.fffffep-1f;
}

/* lm_halton_float(dim, index) < p, exactly, mostly from the first table lookup alone: the digits after
 * the first chunk add less than 1 / chunk, so unless p lies within that (widened by a float step) above
 * the first chunk's value, the answer is known. A photon's Russian roulette asks only this. */
static inline int lm_halton_float_below(uint32_t dim, uint32_t index, float p)
{
    const lm_qmc_fdim *d = &lm_qmc_fdims[dim];
    uint32_t r;
    lm_qmc_split(d->magic, d->chunk, index, &r);
    double v = d->table[r], margin = 1e-6; /* > a float step of values near 1 */
    if (p > v + d->inv_chunk + margin)
        return 1;
    if (p <= v - margin)
        return 0;
    return lm_halton_float(dim, index) < p;
}
/* The d-th prime (d = 0 -> 2). */
uint32_t lm_qmc_prime(uint32_t dim);

/* Two numbers in [0, 1) from a seed: a per-entry (texel) Cranley-Patterson shift of a fixed sample
 * pattern, so an entry gets the same samples whenever it is computed and neighbours get different ones. */
static inline void lm_seed_shift(uint32_t seed, double s[2])
{
    for (int k = 0; k < 2; k++) {
        uint32_t h = seed * 0x9e3779b1u + (uint32_t)k * 0x85ebca77u;
        h ^= h >> 16;
        h *= 0x7feb352du;
        h ^= h >> 15;
        h *= 0x846ca68bu;
        h ^= h >> 16;
        s[k] = (double)h * (1.0 / 4294967296.0);
    }
}

#endif
