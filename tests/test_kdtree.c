/* photonmap/kdtree: N-nearest and radius queries agree with brute force on random sets with many
 * duplicates, with N larger than the set, on empty and all-coincident sets; builds are deterministic;
 * ties go to the lowest indices; bounded queries (lm_kdtree_nearest_within) match. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../src/photonmap/kdtree.h"

static uint32_t rng_next(uint64_t *s)
{
    *s = *s * 6364136223846793005ull + 1442695040888963407ull;
    return (uint32_t)(*s >> 33);
}

/* Points on a coarse grid (values k / levels) so that exact duplicates and distance ties are common. */
static float *grid_points(uint32_t n, int levels, int planar, uint64_t seed)
{
    float *p = malloc(sizeof *p * 3 * (n ? n : 1));
    assert_non_null(p);
    for (uint32_t i = 0; i < 3 * n; i++)
        p[i] = (planar && i % 3 == 1) ? 0.25f : (float)(rng_next(&seed) % (uint32_t)levels) / (float)levels;
    return p;
}

static float d2_of(const float *a, const float *b)
{
    float dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
    return dx * dx + dy * dy + dz * dz;
}

static int cmp_float(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

/* Checks one query against brute force: same sorted distances, same n-th radius, distinct valid
 * indices whose reported distances are their true distances. */
static void check_query(const lm_kdtree *t, const float *pts, uint32_t count, const float q[3], uint32_t n)
{
    uint32_t *idx = malloc(sizeof *idx * (n ? n : 1));
    float *d2 = malloc(sizeof *d2 * (n ? n : 1)), *all = malloc(sizeof *all * (count ? count : 1));
    uint8_t *seen = calloc(count ? count : 1, 1);
    assert_true(idx && d2 && all && seen);
    float r2 = -1.0f;
    uint32_t got = lm_kdtree_nearest(t, q, n, idx, d2, &r2);
    uint32_t want = n < count ? n : count;
    assert_int_equal(got, want);
    for (uint32_t i = 0; i < got; i++) {
        assert_true(idx[i] < count);
        assert_false(seen[idx[i]]);
        seen[idx[i]] = 1;
        assert_true(d2[i] == d2_of(pts + 3 * idx[i], q));
    }
    for (uint32_t i = 0; i < count; i++)
        all[i] = d2_of(pts + 3 * i, q);
    qsort(all, count, sizeof *all, cmp_float);
    qsort(d2, got, sizeof *d2, cmp_float);
    for (uint32_t i = 0; i < got; i++)
        assert_true(d2[i] == all[i]);
    assert_true(r2 == (got ? all[got - 1] : 0.0f));
    free(idx);
    free(d2);
    free(all);
    free(seen);
}

static void check_set(const float *pts, uint32_t count, const uint32_t *ns, int n_count, uint64_t seed)
{
    lm_kdtree t;
    lm_kdtree_init(&t);
    lm_error err;
    assert_int_equal(lm_kdtree_build(&t, pts, 3, count, &err), LM_OK);
    for (int q = 0; q < 60; q++) {
        float qp[3];
        if (count && q % 3 == 0) /* on a stored point */
            memcpy(qp, pts + 3 * (rng_next(&seed) % count), sizeof qp);
        else
            for (int a = 0; a < 3; a++)
                qp[a] = (float)(rng_next(&seed) % 1000) / 800.0f - 0.1f;
        for (int k = 0; k < n_count; k++)
            check_query(&t, pts, count, qp, ns[k]);
    }
    lm_kdtree_free(&t);
}

static void test_matches_brute_force_with_duplicates(void **state)
{
    (void)state;
    static const uint32_t ns[] = {1, 2, 7, 50, 100};
    static const uint32_t sizes[] = {1, 5, 6, 7, 13, 100, 300, 1000, 2000};
    for (size_t s = 0; s < sizeof sizes / sizeof *sizes; s++)
        for (int levels = 3; levels <= 300; levels *= 10)
            for (int planar = 0; planar <= 1; planar++) {
                float *p = grid_points(sizes[s], levels, planar, 17 + s * 31 + (uint64_t)levels);
                check_set(p, sizes[s], ns, 5, 99 + s);
                free(p);
            }
}

static void test_n_larger_than_count_returns_all(void **state)
{
    (void)state;
    static const uint32_t ns[] = {10, 50, 1000};
    float *p = grid_points(9, 100, 0, 5);
    check_set(p, 9, ns, 3, 1);
    free(p);
}

static void test_empty_set(void **state)
{
    (void)state;
    lm_kdtree t;
    lm_kdtree_init(&t);
    assert_int_equal(lm_kdtree_build(&t, NULL, 3, 0, NULL), LM_OK);
    float q[3] = {0, 0, 0}, d2[4], r2 = -1.0f;
    uint32_t idx[4];
    assert_int_equal(lm_kdtree_nearest(&t, q, 4, idx, d2, &r2), 0);
    assert_true(r2 == 0.0f);
    assert_int_equal(lm_kdtree_nearest(&t, q, 0, idx, d2, &r2), 0);
    lm_kdtree_free(&t);
}

static void count_visit(void *ctx, uint32_t index, float d2)
{
    (void)index;
    (void)d2;
    (*(uint32_t *)ctx)++;
}

static void test_all_coincident(void **state)
{
    (void)state;
    enum { N = 5000 };
    float *p = malloc(sizeof *p * 3 * N);
    assert_non_null(p);
    for (int i = 0; i < 3 * N; i++)
        p[i] = (float)(i % 3) * 0.5f;
    static const uint32_t ns[] = {1, 100, N, N + 1};
    check_set(p, N, ns, 4, 3);
    lm_kdtree t;
    lm_kdtree_init(&t);
    assert_int_equal(lm_kdtree_build(&t, p, 3, N, NULL), LM_OK);
    uint32_t visited = 0;
    assert_int_equal(lm_kdtree_radius(&t, p, 0.0f, count_visit, &visited), N);
    assert_int_equal(visited, N);
    lm_kdtree_free(&t);
    free(p);
}

typedef struct {
    uint8_t *mark;
    uint32_t n;
} radius_ctx;

static void mark_visit(void *ctx, uint32_t index, float d2)
{
    (void)d2;
    radius_ctx *c = ctx;
    assert_true(index < c->n);
    assert_int_equal(c->mark[index], 0);
    c->mark[index] = 1;
}

static void test_radius_matches_brute_force(void **state)
{
    (void)state;
    enum { N = 1500 };
    float *p = grid_points(N, 30, 0, 77);
    lm_kdtree t;
    lm_kdtree_init(&t);
    assert_int_equal(lm_kdtree_build(&t, p, 3, N, NULL), LM_OK);
    uint8_t mark[N];
    uint64_t seed = 8;
    for (int q = 0; q < 50; q++) {
        float qp[3] = {(float)(rng_next(&seed) % 100) / 100.0f, (float)(rng_next(&seed) % 100) / 100.0f, 0.5f};
        float r2 = (float)(q % 10) * 0.01f;
        memset(mark, 0, sizeof mark);
        radius_ctx c = {mark, N};
        uint32_t got = lm_kdtree_radius(&t, qp, r2, mark_visit, &c), want = 0;
        for (uint32_t i = 0; i < N; i++) {
            int in = d2_of(p + 3 * i, qp) <= r2;
            want += (uint32_t)in;
            assert_int_equal(mark[i], in);
        }
        assert_int_equal(got, want);
    }
    lm_kdtree_free(&t);
    free(p);
}

static void test_deterministic_and_strided(void **state)
{
    (void)state;
    enum { N = 777, K = 40 };
    float *p = grid_points(N, 20, 0, 4), *wide = malloc(sizeof *wide * 5 * N);
    assert_non_null(wide);
    for (int i = 0; i < N; i++) {
        memcpy(wide + 5 * i, p + 3 * i, 3 * sizeof *p);
        wide[5 * i + 3] = wide[5 * i + 4] = NAN; /* padding the tree must not read */
    }
    lm_kdtree a, b;
    lm_kdtree_init(&a);
    lm_kdtree_init(&b);
    assert_int_equal(lm_kdtree_build(&a, p, 3, N, NULL), LM_OK);
    assert_int_equal(lm_kdtree_build(&b, wide, 5, N, NULL), LM_OK);
    assert_memory_equal(a.nodes, b.nodes, sizeof *a.nodes * N);
    uint32_t ia[K], ib[K];
    float da[K], db[K];
    float q[3] = {0.5f, 0.5f, 0.5f};
    assert_int_equal(lm_kdtree_nearest(&a, q, K, ia, da, NULL), K);
    assert_int_equal(lm_kdtree_nearest(&b, q, K, ib, db, NULL), K);
    assert_memory_equal(ia, ib, sizeof ia);
    /* Rebuilding into the same tree (reused storage) gives the same tree. */
    assert_int_equal(lm_kdtree_build(&b, p, 3, N, NULL), LM_OK);
    assert_memory_equal(a.nodes, b.nodes, sizeof *a.nodes * N);
    lm_kdtree_free(&a);
    lm_kdtree_free(&b);
    free(p);
    free(wide);
}

/* N above the candidate buffer's limit (the heap mode) still matches brute force. */
static void test_large_n(void **state)
{
    (void)state;
    static const uint32_t ns[] = {257, 300, 600, 1999};
    float *p = grid_points(2000, 30, 1, 21);
    check_set(p, 2000, ns, 4, 5);
    free(p);
}

/* Sorted copy of the first n indices. */
static void sorted_indices(const uint32_t *idx, uint32_t n, uint32_t *out)
{
    memcpy(out, idx, sizeof *out * n);
    for (uint32_t i = 1; i < n; i++)
        for (uint32_t j = i; j > 0 && out[j - 1] > out[j]; j--) {
            uint32_t t = out[j];
            out[j] = out[j - 1];
            out[j - 1] = t;
        }
}

/* Ties at the n-th distance go to the lowest indices (so answers do not depend on the tree's shape). */
static void test_ties_take_lowest_indices(void **state)
{
    (void)state;
    enum { N = 300 };
    float *p = grid_points(N, 3, 0, 8);
    lm_kdtree t;
    lm_kdtree_init(&t);
    assert_int_equal(lm_kdtree_build(&t, p, 3, N, NULL), LM_OK);
    static const uint32_t ns[] = {1, 10, 100, 299};
    for (int k = 0; k < 4; k++) {
        uint32_t n = ns[k], idx[N], got[N];
        float d2[N], q[3] = {0.3f, 0.6f, 0.1f}, r2;
        assert_int_equal(lm_kdtree_nearest(&t, q, n, idx, d2, &r2), n);
        sorted_indices(idx, n, got);
        uint32_t m = 0; /* brute force: every point below r2, then the lowest indices at r2 */
        for (uint32_t i = 0; i < N; i++)
            m += d2_of(p + 3 * i, q) < r2;
        for (uint32_t i = 0, w = 0, at = 0; i < N; i++) {
            float d = d2_of(p + 3 * i, q);
            if (d < r2 || (d == r2 && at++ < n - m))
                assert_int_equal(got[w++], i);
        }
    }
    lm_kdtree_free(&t);
    free(p);
}

/* lm_kdtree_nearest_within: with a bound that holds the n nearest, exactly lm_kdtree_nearest's answer;
 * with a smaller one, every point within it. */
static void test_nearest_within(void **state)
{
    (void)state;
    enum { N = 1500, K = 100 };
    float *p = grid_points(N, 40, 1, 31);
    lm_kdtree t;
    lm_kdtree_init(&t);
    assert_int_equal(lm_kdtree_build(&t, p, 3, N, NULL), LM_OK);
    uint64_t seed = 12;
    for (int qi = 0; qi < 40; qi++) {
        float q[3] = {(float)(rng_next(&seed) % 100) / 100.0f, 0.25f, (float)(rng_next(&seed) % 100) / 100.0f};
        uint32_t ia[K], ib[K], sa[K], sb[K];
        float da[K], db[K], ra, rb;
        assert_int_equal(lm_kdtree_nearest(&t, q, K, ia, da, &ra), K);
        float bound = ra * (1.0f + (float)(qi % 4));
        assert_int_equal(lm_kdtree_nearest_within(&t, q, K, bound, ib, db, &rb), K);
        assert_true(rb == ra);
        sorted_indices(ia, K, sa);
        sorted_indices(ib, K, sb);
        assert_memory_equal(sa, sb, sizeof sa);
        uint32_t inside = 0;
        float small = ra * 0.5f;
        for (uint32_t i = 0; i < N; i++)
            inside += d2_of(p + 3 * i, q) <= small;
        uint32_t got = lm_kdtree_nearest_within(&t, q, K, small, ib, db, &rb);
        assert_int_equal(got, inside);
        for (uint32_t i = 0; i < got; i++)
            assert_true(db[i] <= small && db[i] == d2_of(p + 3 * ib[i], q));
        assert_int_equal(lm_kdtree_nearest_within(&t, q, K, -1.0f, ib, db, &rb), 0);
    }
    lm_kdtree_free(&t);
    free(p);
}

static void test_rejects_non_finite(void **state)
{
    (void)state;
    float p[6] = {0, 0, 0, 1, NAN, 0};
    lm_kdtree t;
    lm_kdtree_init(&t);
    lm_error err;
    assert_int_equal(lm_kdtree_build(&t, p, 3, 2, &err), LM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "point 1"));
    assert_int_equal(t.count, 0);
    lm_kdtree_free(&t);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_matches_brute_force_with_duplicates),
        cmocka_unit_test(test_n_larger_than_count_returns_all),
        cmocka_unit_test(test_empty_set),
        cmocka_unit_test(test_all_coincident),
        cmocka_unit_test(test_radius_matches_brute_force),
        cmocka_unit_test(test_deterministic_and_strided),
        cmocka_unit_test(test_rejects_non_finite),
        cmocka_unit_test(test_large_n),
        cmocka_unit_test(test_ties_take_lowest_indices),
        cmocka_unit_test(test_nearest_within),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
