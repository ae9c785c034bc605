/* photon_store: O(1) add and remove in per-surface slot lists, free-slot reuse, the change accumulators
 * (delta_f counts every hit, delta_i leaves out first hits from punctual lights) and each surface's
 * energy kept as hits come and go. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "../src/trace/photon_store.h"

static lm_hit make_hit(int surface, uint32_t photon, float power, int bounce, int punctual)
{
    lm_hit h;
    memset(&h, 0, sizeof h);
    h.surface = surface;
    h.photon = photon;
    h.flux[0] = h.flux[1] = h.flux[2] = power; /* luminance = power */
    h.bounce = (uint16_t)bounce;
    h.source = punctual ? LM_HIT_FROM_PUNCTUAL : LM_HIT_FROM_AREA;
    return h;
}

/* Reads a surface's slot list: every hit in it is on the surface and knows its place; returns the count. */
static uint32_t walk(const lm_photon_store *ps, int surface)
{
    const lm_surface_hits *sh = &ps->surfaces[surface];
    for (uint32_t k = 0; k < sh->count; k++) {
        assert_int_equal(ps->hits[sh->slots[k]].surface, surface);
        assert_int_equal(ps->hits[sh->slots[k]].at, k);
    }
    return sh->count;
}

static void test_add_remove(void **state)
{
    (void)state;
    lm_photon_store ps;
    lm_error err;
    assert_int_equal(lm_photon_store_init(&ps, 3, &err), LM_OK);
    uint32_t slot[10];
    for (int i = 0; i < 10; i++) {
        lm_hit h = make_hit(i % 3, (uint32_t)i, 1.0f, 1, 0);
        slot[i] = lm_photon_store_add(&ps, &h);
        assert_int_not_equal(slot[i], LM_NONE);
        assert_int_equal(ps.hits[slot[i]].photon, (uint32_t)i);
    }
    assert_int_equal(walk(&ps, 0), 4);
    assert_int_equal(walk(&ps, 1), 3);
    assert_int_equal(walk(&ps, 2), 3);
    /* Remove the last, a middle and the first of surface 0 (photons 9, 3, 0 of 0, 3, 6, 9): the last in
     * the list takes each one's place. */
    lm_photon_store_remove(&ps, slot[9]);
    lm_photon_store_remove(&ps, slot[3]);
    lm_photon_store_remove(&ps, slot[0]);
    assert_int_equal(walk(&ps, 0), 1);
    assert_int_equal(ps.hits[ps.surfaces[0].slots[0]].photon, 6);
    lm_photon_store_remove(&ps, slot[6]);
    assert_int_equal(walk(&ps, 0), 0);
    assert_int_equal(walk(&ps, 1), 3);
    /* Removing a free or never-used slot changes nothing (the free list stays intact). */
    double df = ps.surfaces[0].delta_f;
    lm_photon_store_remove(&ps, slot[6]);
    lm_photon_store_remove(&ps, 12345);
    assert_float_equal(ps.surfaces[0].delta_f, df, 0.0);
    uint32_t freed = 0;
    for (uint32_t s = ps.free_head; s != LM_NONE; s = ps.hits[s].next)
        freed++;
    assert_int_equal(freed, 4);
    assert_int_equal(ps.free_count, 4);

    /* Out-of-range surfaces are refused and leave the store as it was. */
    lm_hit bad = make_hit(3, 99, 1.0f, 0, 0);
    assert_int_equal(lm_photon_store_add(&ps, &bad), LM_NONE);
    bad.surface = -1;
    assert_int_equal(lm_photon_store_add(&ps, &bad), LM_NONE);
    assert_int_equal(ps.used, 10);
    lm_photon_store_free(&ps);
}

static void test_free_list_reuse(void **state)
{
    (void)state;
    lm_photon_store ps;
    lm_error err;
    assert_int_equal(lm_photon_store_init(&ps, 2, &err), LM_OK);
    uint32_t slot[2000];
    for (int i = 0; i < 2000; i++) { /* more than the first allocation: the array grows */
        lm_hit h = make_hit(i & 1, (uint32_t)i, 0.5f, 2, 0);
        slot[i] = lm_photon_store_add(&ps, &h);
    }
    assert_int_equal(ps.used, 2000);
    assert_true(ps.capacity >= 2000);
    for (int i = 0; i < 2000; i += 2)
        lm_photon_store_remove(&ps, slot[i]);
    assert_int_equal(walk(&ps, 0), 0);
    assert_int_equal(walk(&ps, 1), 1000);
    uint32_t cap = ps.capacity;
    for (int i = 0; i < 1000; i++) { /* freed slots are reused before the array grows */
        lm_hit h = make_hit(0, 5000u + (uint32_t)i, 0.5f, 2, 0);
        uint32_t s = lm_photon_store_add(&ps, &h);
        assert_true(s < 2000);
    }
    assert_int_equal(ps.used, 2000);
    assert_int_equal(ps.capacity, cap);
    assert_int_equal(ps.free_head, LM_NONE);
    assert_int_equal(walk(&ps, 0), 1000);
    lm_hit h = make_hit(1, 9999, 0.5f, 2, 0);
    assert_int_equal(lm_photon_store_add(&ps, &h), 2000);
    lm_photon_store_free(&ps);
}

/* A batch's reservation counts the free slots its adds take first: a re-trace that replaces half the hits
 * must not double the array (it did, by 40 MB in the two rooms' soak, tests/test_soak.c). */
static void test_reserve_counts_free_slots(void **state)
{
    (void)state;
    lm_photon_store ps;
    lm_error err;
    assert_int_equal(lm_photon_store_init(&ps, 1, &err), LM_OK);
    uint32_t slot[2048];
    for (int i = 0; i < 2048; i++) {
        lm_hit h = make_hit(0, (uint32_t)i, 1.0f, 1, 0);
        slot[i] = lm_photon_store_add(&ps, &h);
    }
    assert_int_equal(ps.used, 2048);
    assert_int_equal(ps.capacity, 2048); /* 1024 doubled once: full */
    for (int i = 0; i < 2048; i += 2)
        lm_photon_store_remove(&ps, slot[i]);
    assert_int_equal(ps.free_count, 1024);
    assert_true(lm_photon_store_reserve(&ps, 1024)); /* the free slots hold them all */
    assert_int_equal(ps.capacity, 2048);
    for (int i = 0; i < 1000; i++) {
        lm_hit h = make_hit(0, 5000u + (uint32_t)i, 1.0f, 1, 0);
        assert_true(lm_photon_store_add(&ps, &h) < 2048);
    }
    assert_int_equal(ps.free_count, 24);
    assert_true(lm_photon_store_reserve(&ps, 24));
    assert_int_equal(ps.capacity, 2048);
    assert_true(lm_photon_store_reserve(&ps, 25)); /* one past the free slots: the array grows */
    assert_int_equal(ps.capacity, 4096);
    lm_photon_store_clear(&ps);
    assert_int_equal(ps.free_count, 0);
    lm_photon_store_free(&ps);
}

static void test_deltas(void **state)
{
    (void)state;
    lm_photon_store ps;
    lm_error err;
    assert_int_equal(lm_photon_store_init(&ps, 2, &err), LM_OK);
    lm_hit direct_punctual = make_hit(0, 0, 2.0f, 0, 1); /* per-pixel direct light: not in delta_i */
    lm_hit bounced_punctual = make_hit(0, 1, 3.0f, 1, 1);
    lm_hit direct_area = make_hit(0, 2, 5.0f, 0, 0);     /* emissive direct light is in the IIM */
    uint32_t a = lm_photon_store_add(&ps, &direct_punctual);
    uint32_t b = lm_photon_store_add(&ps, &bounced_punctual);
    lm_photon_store_add(&ps, &direct_area);
    assert_float_equal(ps.surfaces[0].delta_f, 10.0, 1e-9);
    assert_float_equal(ps.surfaces[0].delta_i, 8.0, 1e-9);
    assert_float_equal(ps.surfaces[1].delta_f, 0.0, 0.0);

    lm_photon_store_reset_delta_f(&ps, 0);
    assert_float_equal(ps.surfaces[0].delta_f, 0.0, 0.0);
    assert_float_equal(ps.surfaces[0].delta_i, 8.0, 1e-9);
    /* Removing counts as change too. */
    lm_photon_store_remove(&ps, a);
    lm_photon_store_remove(&ps, b);
    assert_float_equal(ps.surfaces[0].delta_f, 5.0, 1e-9);
    assert_float_equal(ps.surfaces[0].delta_i, 11.0, 1e-9);
    lm_photon_store_reset_delta_i(&ps, 0);
    assert_float_equal(ps.surfaces[0].delta_i, 0.0, 0.0);

    lm_hit coloured = make_hit(1, 3, 0.0f, 1, 0);
    coloured.flux[0] = 1.0f; /* luminance weights: red 0.2126 */
    lm_photon_store_add(&ps, &coloured);
    assert_float_equal(lm_hit_energy(&coloured), 0.2126, 1e-9);
    assert_float_equal(ps.surfaces[1].delta_f, 0.2126, 1e-9);
    assert_true(lm_photon_store_bytes(&ps) >= sizeof(lm_hit));
    lm_photon_store_free(&ps);
}

/* lm_photon_store_clear keeps the slot array but nothing else: after churn (adds, removes, a free
 * list), a cleared store hands out the same slots with the same contents as a fresh one. */
static void test_clear_matches_fresh(void **state)
{
    (void)state;
    lm_photon_store a, b;
    lm_error err;
    assert_int_equal(lm_photon_store_init(&a, 3, &err), LM_OK);
    assert_int_equal(lm_photon_store_init(&b, 3, &err), LM_OK);
    for (int i = 0; i < 3000; i++) {
        lm_hit h = make_hit(i % 3, (uint32_t)i, 1.0f, i % 2, i % 5 == 0);
        uint32_t slot = lm_photon_store_add(&a, &h);
        if (i % 7 == 0)
            lm_photon_store_remove(&a, slot);
    }
    lm_photon_store_remove(&a, 10);
    lm_photon_store_remove(&a, 20);
    assert_int_not_equal(a.free_head, LM_NONE);
    uint32_t cap = a.capacity;
    lm_hit *hits = a.hits;
    lm_photon_store_clear(&a);
    assert_int_equal(a.capacity, cap); /* memory kept */
    assert_ptr_equal(a.hits, hits);
    assert_int_equal(a.used, 0);
    assert_int_equal(a.free_head, LM_NONE);
    for (int s = 0; s < 3; s++) {
        assert_int_equal(walk(&a, s), 0);
        assert_true(a.surfaces[s].delta_f == 0.0 && a.surfaces[s].delta_i == 0.0);
    }
    for (int i = 0; i < 500; i++) {
        lm_hit h = make_hit((i * 7) % 3, (uint32_t)i, 0.5f, i % 3, i % 2);
        assert_int_equal(lm_photon_store_add(&a, &h), lm_photon_store_add(&b, &h));
        if (i % 11 == 0) {
            lm_photon_store_remove(&a, (uint32_t)i / 2);
            lm_photon_store_remove(&b, (uint32_t)i / 2);
        }
    }
    assert_int_equal(a.used, b.used);
    assert_int_equal(a.free_head, b.free_head);
    assert_true(lm_photon_store_same(&a, &b));
    b.surfaces[1].delta_i += 1e-9; /* and it sees a difference */
    assert_false(lm_photon_store_same(&a, &b));
    lm_photon_store_free(&a);
    lm_photon_store_free(&b);
}

/* Each surface's energy is the sum of its hits' as they come and go, whatever the order: within float
 * summation of the walk after thousands of adds and removes of powers over nine decades, and exactly 0
 * once a surface is empty. */
static void test_energy_follows_hits(void **state)
{
    (void)state;
    lm_photon_store ps;
    assert_int_equal(lm_photon_store_init(&ps, 3, NULL), LM_OK);
    uint32_t slots[3000];
    uint32_t x = 12345;
    for (int i = 0; i < 3000; i++) {
        x = x * 1664525u + 1013904223u;
        float power = powf(10.0f, (float)(x >> 8) / (float)(1u << 24) * 9.0f - 4.0f);
        lm_hit h = make_hit(i % 3, (uint32_t)i, power, 1, 0);
        slots[i] = lm_photon_store_add(&ps, &h);
        if (i % 4 == 3) /* every fourth step removes an earlier hit */
            lm_photon_store_remove(&ps, slots[(i * 7) % i]);
    }
    for (int s = 0; s < 3; s++) {
        double walked = 0.0;
        for (uint32_t k = 0; k < ps.surfaces[s].count; k++)
            walked += lm_hit_energy(&ps.hits[ps.surfaces[s].slots[k]]);
        assert_true(walked > 0.0);
        assert_true(fabs(ps.surfaces[s].energy - walked) <= 1e-9 * walked);
    }
    for (int i = 0; i < 3000; i++)
        lm_photon_store_remove(&ps, slots[i]);
    for (int s = 0; s < 3; s++) {
        assert_int_equal(ps.surfaces[s].count, 0);
        assert_true(ps.surfaces[s].energy == 0.0);
    }
    lm_photon_store_free(&ps);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_add_remove),
        cmocka_unit_test(test_free_list_reuse),
        cmocka_unit_test(test_reserve_counts_free_slots),
        cmocka_unit_test(test_deltas),
        cmocka_unit_test(test_clear_matches_fresh),
        cmocka_unit_test(test_energy_follows_hits),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
