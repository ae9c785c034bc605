/* qmc: scrambled Halton values lie in [0, 1), keep the 2^a x 3^b strata of dims 0-1, are well spread,
 * and the float path is within one ulp of the double one. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <math.h>
#include <stdint.h>
#include <string.h>

#include "../src/core/qmc.h"

static void test_primes(void **state)
{
    (void)state;
    assert_int_equal(lm_qmc_prime(0), 2);
    assert_int_equal(lm_qmc_prime(1), 3);
    assert_int_equal(lm_qmc_prime(2), 5);
    assert_int_equal(lm_qmc_prime(9), 29);
    assert_int_equal(lm_qmc_prime(LM_QMC_MAX_DIMS - 1), 1619);
}

static void test_range(void **state)
{
    (void)state;
    lm_qmc_init();
    static const uint64_t big[] = {1ull << 32, (1ull << 40) + 12345, UINT64_MAX - 1, UINT64_MAX};
    for (uint32_t d = 0; d < LM_QMC_MAX_DIMS; d++) {
        for (uint64_t i = 0; i < 2000; i++) {
            double v = lm_halton(d, i);
            assert_true(v >= 0.0 && v < 1.0);
        }
        for (size_t k = 0; k < sizeof big / sizeof big[0]; k++) {
            double v = lm_halton(d, big[k]);
            assert_true(v >= 0.0 && v < 1.0);
        }
    }
}

/* Distinct indices give distinct values (a digit permutation is a bijection). */
static void test_distinct(void **state)
{
    (void)state;
    static double seen[3125];
    static const uint32_t count[3] = {2048, 2187, 3125}; /* 2^11, 3^7, 5^5 */
    for (uint32_t d = 0; d < 3; d++) {
        uint32_t n = count[d];
        for (uint32_t i = 0; i < n; i++)
            seen[i] = lm_halton(d, i);
        for (uint32_t i = 0; i < n; i++)
            for (uint32_t j = i + 1; j < n; j++)
                assert_true(seen[i] != seen[j]);
    }
}

/* Points of few digits lie exactly on a cell's lower edge, which doubles cannot hold for thirds: a
 * nudge far below 3^-17 (indices here stay below 3^17) assigns them as exact arithmetic would. */
static int cell(uint64_t i)
{
    int x = (int)(lm_halton(0, i) * 8.0 + 1e-10), y = (int)(lm_halton(1, i) * 9.0 + 1e-10);
    return y * 8 + x;
}

/* G = 2^3 * 3^2 = 72: indices congruent mod 72 share a cell of the 8 x 9 grid of dims 0-1, and any
 * 72 consecutive indices from a multiple of 72 fill every cell once. */
static void test_stratification(void **state)
{
    (void)state;
    for (uint64_t r = 0; r < 72; r++) {
        int c = cell(r);
        for (uint64_t k = 1; k < 2000; k++)
            assert_int_equal(cell(r + 72 * k), c);
        assert_int_equal(cell(r + 72 * 1000003ull), c);
    }
    for (uint64_t start = 0; start < 72 * 50; start += 72) {
        int count[72];
        memset(count, 0, sizeof count);
        for (uint64_t i = start; i < start + 72; i++)
            count[cell(i)]++;
        for (int c = 0; c < 72; c++)
            assert_int_equal(count[c], 1);
    }
}

/* The scramble changes the sequence (it is not the plain radical inverse) for bases above 3 (base 2
 * has only the identity among permutations fixing 0, base 3 may draw it too). */
static void test_scrambled(void **state)
{
    (void)state;
    int differ = 0;
    for (uint32_t d = 2; d < 9; d++) {
        uint32_t b = lm_qmc_prime(d);
        for (uint64_t i = 1; i < 50; i++) {
            double plain = 0.0, scale = 1.0 / b;
            for (uint64_t n = i; n; n /= b, scale /= b)
                plain += (double)(n % b) * scale;
            differ += fabs(plain - lm_halton(d, i)) > 1e-9;
        }
    }
    print_message("%d of 343 values differ from the plain radical inverse\n", differ);
    assert_true(differ > 250);
}

static void test_mean_and_spread(void **state)
{
    (void)state;
    static const uint32_t dims[] = {0, 1, 2, 3, 7, 31, 100, 200, 255};
    for (size_t k = 0; k < sizeof dims / sizeof dims[0]; k++) {
        double sum = 0.0;
        int bins[10] = {0};
        for (uint64_t i = 0; i < 10000; i++) {
            double v = lm_halton(dims[k], i);
            sum += v;
            bins[(int)(v * 10.0)]++;
        }
        assert_float_equal(sum / 10000.0, 0.5, 0.01);
        for (int b = 0; b < 10; b++)
            assert_in_range(bins[b], 900, 1100);
    }
}

/* Pairs of higher dimensions are spread too (no strong correlation after scrambling). */
static void test_pairs(void **state)
{
    (void)state;
    for (uint32_t d = 4; d < 240; d += 17) {
        int bins[16] = {0};
        for (uint64_t i = 0; i < 4096; i++) {
            int x = (int)(lm_halton(d, i) * 4.0), y = (int)(lm_halton(d + 1, i) * 4.0);
            bins[y * 4 + x]++;
        }
        for (int b = 0; b < 16; b++)
            assert_in_range(bins[b], 160, 352);
    }
}

/* The float path (its own tables, fewer digits per lookup) is within one ulp of (float)lm_halton and in
 * [0, 1), in every dimension, for small, large and the largest 32-bit indices. */
static void test_float_path(void **state)
{
    (void)state;
    static const uint32_t big[] = {1u << 31, 4000000000u, UINT32_MAX - 1, UINT32_MAX};
    int worst = 0;
    for (uint32_t d = 0; d < LM_QMC_MAX_DIMS; d++)
        for (uint32_t k = 0; k < 3000 + 4; k++) {
            uint32_t i = k < 3000 ? k * 7919u : big[k - 3000];
            float f, want = (float)lm_halton(d, i);
            want = want < 1.0f ? want : 0x1.fffffep-1f;
            lm_halton_dims_float(d, 1, i, &f);
            assert_true(f >= 0.0f && f < 1.0f);
            if (f != want) { /* one float step above or below */
                assert_true(f == nextafterf(want, 2.0f) || f == nextafterf(want, -1.0f));
                worst = 1;
            }
        }
    print_message("float path: %s\n", worst ? "some values one ulp from (float)lm_halton" : "all equal");
}

/* lm_halton_float_below answers lm_halton_float(d, i) < p exactly: for thresholds across [0, 1], and
 * at the number itself and one float step either side (where the first lookup cannot decide), over all
 * dimensions and indices of every size. */
static void test_float_below(void **state)
{
    (void)state;
    lm_qmc_init(); /* lm_halton_float reads the tables unchecked */
    static const uint32_t big[] = {1u << 31, 4000000000u, UINT32_MAX - 1, UINT32_MAX};
    for (uint32_t d = 0; d < LM_QMC_MAX_DIMS; d++)
        for (uint32_t k = 0; k < 600 + 4; k++) {
            uint32_t i = k < 600 ? k * 104729u : big[k - 600];
            float f = lm_halton_float(d, i);
            const float ps[] = {0.0f, 0.05f, 0.3f, 0.5f, 0.77f, 0.95f, 1.0f, f, nextafterf(f, 2.0f), nextafterf(f, -1.0f)};
            for (size_t j = 0; j < sizeof ps / sizeof *ps; j++)
                assert_int_equal(lm_halton_float_below(d, i, ps[j]), f < ps[j]);
        }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_primes),          cmocka_unit_test(test_range),
        cmocka_unit_test(test_distinct),        cmocka_unit_test(test_stratification),
        cmocka_unit_test(test_scrambled),       cmocka_unit_test(test_mean_and_spread),
        cmocka_unit_test(test_pairs),           cmocka_unit_test(test_float_path),
        cmocka_unit_test(test_float_below),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
