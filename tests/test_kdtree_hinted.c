/* photonmap/kdtree: runs of nearby queries (lm_kdtree_nearest_hinted) give lm_kdtree_nearest's answer, the
 * same list in the same order for N <= 256 (so sums over it do not depend on the run), with steps small and
 * large, on sets with many duplicates and ties; the bounded search lists its answer in that order too. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "../src/photonmap/kdtree.h"

static uint32_t rng_next(uint64_t *s)
{
    *s = *s * 6364136223846793005ull + 1442695040888963407ull;
    return (uint32_t)(*s >> 33);
}

/* Points on a coarse grid of a plane (values k / levels), so that duplicates and distance ties are common. */
static float *plane_points(uint32_t n, int levels, uint64_t seed)
{
    float *p = malloc(sizeof *p * 3 * (n ? n : 1));
    assert_non_null(p);
    for (uint32_t i = 0; i < n; i++) {
        p[3 * i] = (float)(rng_next(&seed) % (uint32_t)levels) / (float)levels;
        p[3 * i + 1] = 0.25f;
        p[3 * i + 2] = (float)(rng_next(&seed) % (uint32_t)levels) / (float)levels;
    }
    return p;
}

static int cmp_u32(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return (x > y) - (x < y);
}

/* Walks rows of queries (steps of 1/rows of the plane, then a jump to the next row's start) and compares
 * every hinted answer with lm_kdtree_nearest's: same count and r2; for n <= 256 the same arrays, above it
 * the same set. */
static void check_run(const float *pts, uint32_t count, uint32_t n, int rows)
{
    lm_kdtree t;
    lm_kdtree_init(&t);
    assert_int_equal(lm_kdtree_build(&t, pts, 3, count, NULL), LM_OK);
    uint32_t *ia = malloc(sizeof *ia * n), *ib = malloc(sizeof *ib * n);
    float *da = malloc(sizeof *da * n), *db = malloc(sizeof *db * n);
    assert_true(ia && ib && da && db);
    lm_kdtree_hint h = {0};
    for (int r = 0; r < rows; r++)
        for (int c = 0; c < rows; c++) {
            float q[3] = {(float)c / (float)rows, 0.25f + (float)(c % 3) * 0.01f, (float)r / (float)rows};
            float ra = -1.0f, rb = -2.0f;
            uint32_t ka = lm_kdtree_nearest(&t, q, n, ia, da, &ra);
            uint32_t kb = lm_kdtree_nearest_hinted(&t, &h, q, n, ib, db, &rb);
            assert_int_equal(ka, kb);
            assert_true(ra == rb);
            assert_true(h.valid && h.r2 == ra);
            if (n <= 256) {
                assert_memory_equal(ia, ib, sizeof *ia * ka);
                assert_memory_equal(da, db, sizeof *da * ka);
            } else {
                qsort(ia, ka, sizeof *ia, cmp_u32);
                qsort(ib, kb, sizeof *ib, cmp_u32);
                assert_memory_equal(ia, ib, sizeof *ia * ka);
            }
        }
    free(ia);
    free(ib);
    free(da);
    free(db);
    lm_kdtree_free(&t);
}

static void test_runs_match_nearest(void **state)
{
    (void)state;
    static const uint32_t ns[] = {1, 7, 100, 128, 256, 300};
    static const uint32_t sizes[] = {5, 200, 1700};
    for (size_t s = 0; s < sizeof sizes / sizeof *sizes; s++)
        for (int levels = 4; levels <= 400; levels *= 10) {
            float *p = plane_points(sizes[s], levels, 3 + s * 17 + (uint64_t)levels);
            for (size_t k = 0; k < sizeof ns / sizeof *ns; k++)
                check_run(p, sizes[s], ns[k], 12);
            free(p);
        }
}

/* All points coincident: every distance ties, the answer is the lowest indices wherever the run goes. */
static void test_runs_on_coincident_points(void **state)
{
    (void)state;
    enum { N = 600 };
    float *p = malloc(sizeof *p * 3 * N);
    assert_non_null(p);
    for (int i = 0; i < 3 * N; i++)
        p[i] = 0.5f;
    check_run(p, N, 128, 5);
    free(p);
}

/* A bound that holds the n nearest gives lm_kdtree_nearest's list, in its order. */
static void test_within_keeps_order(void **state)
{
    (void)state;
    enum { N = 1500, K = 100 };
    float *p = plane_points(N, 40, 31);
    lm_kdtree t;
    lm_kdtree_init(&t);
    assert_int_equal(lm_kdtree_build(&t, p, 3, N, NULL), LM_OK);
    uint64_t seed = 5;
    for (int qi = 0; qi < 40; qi++) {
        float q[3] = {(float)(rng_next(&seed) % 100) / 100.0f, 0.25f, (float)(rng_next(&seed) % 100) / 100.0f};
        uint32_t ia[K], ib[K];
        float da[K], db[K], ra, rb;
        assert_int_equal(lm_kdtree_nearest(&t, q, K, ia, da, &ra), K);
        assert_int_equal(lm_kdtree_nearest_within(&t, q, K, ra * (1.0f + (float)(qi % 3)), ib, db, &rb), K);
        assert_true(ra == rb);
        assert_memory_equal(ia, ib, sizeof ia);
        assert_memory_equal(da, db, sizeof da);
    }
    lm_kdtree_free(&t);
    free(p);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_runs_match_nearest),
        cmocka_unit_test(test_runs_on_coincident_points),
        cmocka_unit_test(test_within_keeps_order),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
