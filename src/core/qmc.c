/* Scrambled Halton sequences (qmc.h).
 *
 * Dimension d uses the d-th prime b and one random digit permutation pi_d of {0..b-1} that fixes 0
 * (Fisher-Yates over 1..b-1 from a fixed-seed splitmix64 stream, in the spirit of Braaten-Weller),
 * applied to every digit: x = sum_k pi_d(digit_k(i)) b^-k. Fixing 0 keeps the zero digits above the
 * index's top digit zero, so x is a finite sum exactly like the plain radical inverse (no tail that
 * could round up to a cell boundary). A digit permutation keeps the low-digit structure: the first a
 * digits of x depend only on i mod b^a, so the 2^a x 3^b strata of dims 0-1 are exactly those of the
 * plain Halton sequence. (Base 2 has no such permutation but the identity: dim 0 is van der Corput.)
 *
 * Speed: digits are processed in chunks of k digits (b^k <= LM_QMC_CHUNK_MAX), one table lookup per
 * chunk; for 32-bit indices the chunk quotient is a multiply by a precomputed reciprocal (split). The
 * photon tracer's float path has its own tables, chunks of at most 256 entries stored as floats: more
 * lookups, but the tables of the few dozen dimensions a path uses fit in L1, where the 4096-entry
 * doubles missed it on most lookups (the first load was over half of the QMC time; 11.8 -> 8.8% of a
 * warm two_rooms trace). */
#include "qmc.h"

#include <pthread.h>
#include <stdatomic.h>

#define LM_QMC_CHUNK_MAX 4096u
#define LM_QMC_SEED 0x6c6d6769514d4321ull /* fixed: sequences are identical on every run */
#define LM_QMC_TABLE_TOTAL 226691u /* sum of the 256 chunk sizes: recompute if CHUNK_MAX or MAX_DIMS change */
#define LM_QMC_LAST_PRIME 1619u

typedef struct {
    uint32_t base;
    uint32_t chunk;          /* b^k */
    double inv_chunk;        /* 1 / chunk */
    uint64_t magic;          /* ceil(2^64 / chunk): exact 32-bit division by chunk (split) */
    double *table;           /* chunk entries: permuted radical inverse of k digits */
} qmc_dim;

static qmc_dim g_dims[LM_QMC_MAX_DIMS];
static double g_storage[LM_QMC_TABLE_TOTAL];

/* The float path's tables (lm_halton_float, qmc.h): chunks of at most LM_QMC_FCHUNK_MAX entries,
 * stored as floats, so that the tables a photon path touches (its first few dozen dimensions) stay
 * in L1. */
#define LM_QMC_FCHUNK_MAX 256u
#define LM_QMC_FTABLE_TOTAL 192677u /* sum of the 256 chunk sizes at FCHUNK_MAX */
lm_qmc_fdim lm_qmc_fdims[LM_QMC_MAX_DIMS];
static float g_fstorage[LM_QMC_FTABLE_TOTAL];
static pthread_once_t g_once = PTHREAD_ONCE_INIT;
static _Atomic int g_ready; /* set once the tables are built: later calls skip pthread_once */

static uint64_t splitmix64(uint64_t *state)
{
    uint64_t z = (*state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

static int is_prime(uint32_t n)
{
    for (uint32_t q = 2; q * q <= n; q++)
        if (n % q == 0)
            return 0;
    return n >= 2;
}

uint32_t lm_qmc_prime(uint32_t dim)
{
    uint32_t found = 0;
    for (uint32_t n = 2;; n++)
        if (is_prime(n) && found++ == dim)
            return n;
}

/* Permutation of {0..b-1} with perm[0] = 0: Fisher-Yates over 1..b-1 from the dimension's own stream. */
static void make_permutation(uint32_t dim, uint32_t b, uint32_t *perm)
{
    uint64_t state = LM_QMC_SEED ^ ((uint64_t)dim * 0xD1B54A32D192ED03ull);
    for (uint32_t i = 0; i < b; i++)
        perm[i] = i;
    for (uint32_t i = b - 1; i > 1; i--) {
        uint32_t j = 1 + (uint32_t)(splitmix64(&state) % i);
        uint32_t t = perm[i];
        perm[i] = perm[j];
        perm[j] = t;
    }
}

static void chunk_shape(uint32_t b, uint32_t max, uint32_t *chunk, uint32_t *digits)
{
    uint32_t c = b, k = 1;
    while ((uint64_t)c * b <= max) {
        c *= b;
        k++;
    }
    *chunk = c;
    *digits = k;
}

/* sum_{j=1..k} perm(digit_j(x)) b^-j, digit_1 the lowest digit of x. */
static double chunk_value(uint32_t x, uint32_t b, uint32_t digits, const uint32_t *perm)
{
    double v = 0.0, scale = 1.0 / b;
    for (uint32_t j = 0; j < digits; j++) {
        v += perm[x % b] * scale;
        x /= b;
        scale /= b;
    }
    return v;
}

static void init_once(void)
{
    static uint32_t perm[LM_QMC_LAST_PRIME];
    size_t at = 0, fat = 0;
    for (uint32_t i = 0, n = 2; i < LM_QMC_MAX_DIMS; n++) {
        if (!is_prime(n))
            continue;
        qmc_dim *d = &g_dims[i];
        lm_qmc_fdim *f = &lm_qmc_fdims[i];
        uint32_t digits, fdigits;
        d->base = n;
        chunk_shape(n, LM_QMC_CHUNK_MAX, &d->chunk, &digits);
        d->inv_chunk = 1.0 / d->chunk;
        d->magic = UINT64_MAX / d->chunk + 1;
        d->table = g_storage + at;
        at += d->chunk;
        chunk_shape(n, LM_QMC_FCHUNK_MAX, &f->chunk, &fdigits);
        f->inv_chunk = 1.0 / f->chunk;
        f->magic = UINT64_MAX / f->chunk + 1;
        float *ftable = g_fstorage + fat;
        f->table = ftable;
        fat += f->chunk;
        make_permutation(i, n, perm);
        for (uint32_t x = 0; x < d->chunk; x++)
            d->table[x] = chunk_value(x, n, digits, perm);
        for (uint32_t x = 0; x < f->chunk; x++)
            ftable[x] = (float)chunk_value(x, n, fdigits, perm);
        i++;
    }
    atomic_store_explicit(&g_ready, 1, memory_order_release);
}

void lm_qmc_init(void) { pthread_once(&g_once, init_once); }

/* lm_qmc_init for the per-number calls: one acquire load once the tables exist. */
static inline void qmc_ready(void)
{
    if (!atomic_load_explicit(&g_ready, memory_order_acquire))
        lm_qmc_init();
}

static inline uint32_t split(const qmc_dim *d, uint32_t i, uint32_t *r) { return lm_qmc_split(d->magic, d->chunk, i, r); }

/* radical for a 32-bit index (the same operations in the same order: the same value bit for bit). */
static inline double radical32(const qmc_dim *d, uint32_t i)
{
    if (i == 0)
        return 0.0;
    /* The first chunk peeled off: the loop's 0 + table[r] x 1 is table[r] exactly (entries are >= 0)
     * and its next scale 1 x inv_chunk is inv_chunk, so the value is the same bit for bit, with two
     * fewer dependent floating-point operations. */
    uint32_t r;
    i = split(d, i, &r);
    double v = d->table[r], scale = d->inv_chunk;
    while (i != 0) {
        i = split(d, i, &r);
        v += d->table[r] * scale;
        scale *= d->inv_chunk;
    }
    return v < 1.0 ? v : 0x1.fffffffffffffp-1;
}

static double radical(const qmc_dim *d, uint64_t index)
{
    double v = 0.0, scale = 1.0;
    if (index <= UINT32_MAX) /* photon indices fit */
        return radical32(d, (uint32_t)index);
    else {
        for (; index != 0; index /= d->chunk) {
            v += d->table[index % d->chunk] * scale;
            scale *= d->inv_chunk;
        }
    }
    return v < 1.0 ? v : 0x1.fffffffffffffp-1;
}

double lm_halton(uint32_t dim, uint64_t index)
{
    qmc_ready();
    return radical(&g_dims[dim % LM_QMC_MAX_DIMS], index);
}

void lm_halton_dims(uint32_t dim, uint32_t n, uint64_t index, double *out)
{
    qmc_ready();
    for (uint32_t k = 0; k < n; k++)
        out[k] = radical(&g_dims[(dim + k) % LM_QMC_MAX_DIMS], index);
}

void lm_halton_dims_float(uint32_t dim, uint32_t n, uint32_t index, float *out)
{
    qmc_ready();
    for (uint32_t k = 0; k < n; k++)
        out[k] = lm_halton_float(dim + k, index);
}
