/* One time budget for every stage (update/budget_plan.h; issue 32, item 4): the plan's arithmetic
 * against hand-made cost models, and through the public API, lmgi_update's budget governing each stage's
 * count (photon groups, AIM refreshes, caustic photons, environment map faces, texels, the waiting texels'
 * estimates): one unit of each
 * stage with work waiting at a budget too small for anything, everything waiting at a generous one, the
 * settings' fixed counts without one; and the stage that took the time named with why. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <lmgi.h>
#include <stdio.h>
#include <string.h>

#include "../src/update/budget_plan.h"
#include "edit_room.h"
#include "support.h"

/* Models seeded at these prices (ms per unit, powers of two so that the divisions are exact): a group, a
 * hit, a caustic photon, a face, a texel. */
static void seeded(lm_budget *b)
{
    const double ms[LM_STAGE_PLANNED] = {2.0, 1.0 / 8192, 1.0 / 1024, 1.0, 0.125};
    lm_budget_seed(b, ms);
}

/* The photon thread's half in pipeline order, the faces' eighth, the gather the whole budget less the
 * rest it has seen; at least one unit for a stage with work waiting. */
static void test_plan_shares(void **state)
{
    (void)state;
    lm_budget b;
    seeded(&b);
    lm_budget_plan p;
    lm_budget_work w = {.groups = 40, .caustic_photons = 100000, .faces = 6, .texels = 5000};
    lm_budget_plan_step(&b, 16.0, &w, &p);
    assert_int_equal(p.groups, 4);        /* 8 ms of the photon thread at 2 ms a group */
    assert_true(p.aim_hits == 1);         /* nothing left for the AIMs: their first surface only */
    assert_int_equal(p.caustic_photons, 1);
    assert_int_equal(p.faces, 2);         /* 16 / 8 ms at 1 ms a face */
    assert_int_equal(p.texels, 128);      /* no rest seen yet */
    assert_true(p.ms[LM_STAGE_PHOTONS] <= 8.0 + 1e-9);

    w.groups = 2; /* the photons need 4 ms: the AIMs get half of the other 4, the caustics the rest */
    lm_budget_plan_step(&b, 16.0, &w, &p);
    assert_int_equal(p.groups, 2);
    assert_true(p.aim_hits == 16384);     /* 2 ms at 1/8192 ms a hit */
    assert_int_equal(p.caustic_photons, 2048);

    lm_budget_work none = {.texels = 5000}; /* nothing waits: the settings' own counts (0) */
    lm_budget_plan_step(&b, 16.0, &none, &p);
    assert_int_equal(p.groups, 0);
    assert_int_equal(p.caustic_photons, 0);
    assert_int_equal(p.faces, 0);
    assert_true(p.aim_hits == 65536);     /* without caustics the AIMs take the whole half */

    lm_budget_plan_step(&b, 1e-3, &w, &p); /* a budget too small for anything: one unit each */
    assert_int_equal(p.groups, 1);
    assert_true(p.aim_hits == 1);
    assert_int_equal(p.caustic_photons, 1);
    assert_int_equal(p.faces, 1);
    assert_int_equal(p.texels, 1);
}

/* What the models learn: the gather's rest (the update less the gather) comes off its budget; a stage's
 * price follows what it measured; a stage that did nothing learns nothing. */
static void test_plan_learns(void **state)
{
    (void)state;
    lm_budget b;
    seeded(&b);
    const double ms[LM_STAGE_PLANNED] = {12.0, 0.0, 0.0, 0.0, 7.5};
    const uint64_t units[LM_STAGE_PLANNED] = {3, 0, 0, 0, 30};
    for (int i = 0; i < LM_COST_WINDOW; i++)
        lm_budget_learn(&b, ms, units, 11.5, 0.0);
    lm_budget_plan p;
    lm_budget_work w = {.groups = 40, .caustic_photons = 100000, .texels = 5000};
    lm_budget_plan_step(&b, 16.0, &w, &p);
    assert_int_equal(p.texels, 48);       /* (16 - 4 ms of rest) at 0.25 ms a texel */
    assert_int_equal(p.groups, 2);        /* 8 ms at 4 ms a group */
    assert_true(p.aim_hits == 1);         /* its price kept: nothing left after the photons */
    assert_string_equal(lm_stage_name(LM_STAGE_CAUSTICS), "caustic photons");
    assert_string_equal(lm_stage_name(LM_STAGE_FRAME), "frame");

    /* three edits in the window (a light switched off and on, a lamp added) whose updates did 40 ms of
     * work at once (a lit light's photons, AIMs refreshed at once): their cost is their own, and the gather
     * keeps its share; counted into its rest, they would make its 95th percentile 44 ms, and the gather
     * would get one texel an update for the next 29 */
    lm_budget edits = b, counted = b;
    for (int i = 0; i < 3; i++) {
        lm_budget_learn(&edits, ms, units, 51.5, 40.0);
        lm_budget_learn(&counted, ms, units, 51.5, 0.0);
    }
    lm_budget_plan_step(&edits, 16.0, &w, &p);
    assert_int_equal(p.texels, 48);
    lm_budget_plan_step(&counted, 16.0, &w, &p);
    assert_int_equal(p.texels, 1);
    w.ms_spent = 4.0; /* the update waited 4 ms for the photon job the last one began: off its budget */
    lm_budget_plan_step(&edits, 16.0, &w, &p);
    assert_int_equal(p.texels, 32);
}

/* A light edit's texel factors (update/light_scale.h): at most a quarter of the budget an update for
 * their refinement, what the rest leaves of the whole budget for an edit's first guess, and what is
 * planned for them comes off the gather's share this update, not off its rest in the updates after. */
static void test_plan_light_scale(void **state)
{
    (void)state;
    lm_budget b;
    const double price[LM_STAGE_PLANNED] = {2.0, 1.0 / 8192, 1.0 / 1024, 1.0, 0.125, 1.0 / 1024};
    lm_budget_seed(&b, price);
    lm_budget_plan p;
    lm_budget_work w = {.texels = 5000};
    lm_budget_plan_step(&b, 16.0, &w, &p); /* nothing waits: bounded all the same, the gather unchanged */
    assert_int_equal(p.scale_rays, 4096); /* 4 ms at 1/1024 ms a ray */
    assert_int_equal(p.texels, 128);
    w.scale_rays = 100000; /* a refinement under way */
    lm_budget_plan_step(&b, 16.0, &w, &p);
    assert_int_equal(p.scale_rays, 4096);
    assert_int_equal(p.texels, 96);       /* (16 - 4) ms at 0.125 ms a texel */
    w.scale_rays = 100;                   /* its last rays */
    lm_budget_plan_step(&b, 16.0, &w, &p);
    assert_int_equal(p.scale_rays, 100);
    assert_int_equal(p.texels, 127);
    w.scale_rays = 32768, w.scale_edit = 1; /* an edit's first guess: all but one texel's gather */
    lm_budget_plan_step(&b, 16.0, &w, &p);
    assert_int_equal(p.scale_rays, 16256); /* 15.875 ms */
    assert_int_equal(p.texels, 1);

    const double ms[LM_STAGE_PLANNED] = {12.0, 0.0, 0.0, 0.0, 7.5, 2.0};
    const uint64_t units[LM_STAGE_PLANNED] = {3, 0, 0, 0, 30, 2048};
    for (int i = 0; i < LM_COST_WINDOW; i++)
        lm_budget_learn(&b, ms, units, 13.5, 0.0);
    w.scale_rays = 0, w.scale_edit = 0;
    lm_budget_plan_step(&b, 16.0, &w, &p);
    assert_int_equal(p.texels, 48);       /* (16 - 4 ms of rest, the 2 ms of factors not in it) at 0.25 ms */
    assert_int_equal(p.scale_rays, 4096); /* a quarter: less than the 11.75 ms the rest and a texel leave */
    lm_budget_plan_step(&b, 5.0, &w, &p);
    assert_int_equal(p.scale_rays, 768);  /* 5 - 4 - 0.25 ms: less than a quarter */
    assert_int_equal(p.texels, 4);
    assert_string_equal(lm_stage_name(LM_STAGE_LIGHT_SCALE), "light scale");
}

/* The waiting texels' ray estimates (update/ray_estimate.h), a stage of their own: the gather's share goes
 * to pairs of a texel and its 16 estimates, the estimates get what those texels leave short of another
 * pair, at least one of each; what they take is neither the texels' price nor the gather's rest. */
static void test_plan_estimates(void **state)
{
    (void)state;
    lm_budget b;
    const double price[LM_STAGE_PLANNED] = {2.0, 1.0 / 8192, 1.0 / 1024, 1.0, 0.125, 1.0 / 1024, 1.0 / 64};
    lm_budget_seed(&b, price);
    lm_budget_plan p;
    lm_budget_work w = {.texels = 5000, .estimates_per_texel = 16};
    lm_budget_plan_step(&b, 16.0, &w, &p);
    assert_int_equal(p.texels, 42);       /* 16 ms at 0.125 + 16 / 64 ms a pair */
    assert_int_equal(p.estimates, 688);   /* 16 x 42, and 16 more in the 0.25 ms short of a 43rd pair */
    assert_true(p.ms[LM_STAGE_GATHER] + p.ms[LM_STAGE_ESTIMATES] <= 16.0);
    lm_budget_plan_step(&b, 1e-3, &w, &p); /* too small for anything: one of each */
    assert_int_equal(p.texels, 1);
    assert_int_equal(p.estimates, 1);
    w.estimates_per_texel = 0;            /* the lightmaps keep no estimates: the gather's share is the texels' */
    lm_budget_plan_step(&b, 16.0, &w, &p);
    assert_int_equal(p.texels, 128);
    assert_int_equal(p.estimates, 0);

    const double ms[LM_STAGE_PLANNED] = {12.0, 0.0, 0.0, 0.0, 7.5, 0.0, 4.0};
    const uint64_t units[LM_STAGE_PLANNED] = {3, 0, 0, 0, 30, 0, 256};
    for (int i = 0; i < LM_COST_WINDOW; i++)
        lm_budget_learn(&b, ms, units, 15.5, 0.0);
    w.estimates_per_texel = 16;
    lm_budget_plan_step(&b, 16.0, &w, &p);
    assert_int_equal(p.texels, 24);       /* (16 - 4 ms of rest, the estimates' 4 not in it) at 0.5 ms a pair */
    assert_int_equal(p.estimates, 384);
    assert_string_equal(lm_stage_name(LM_STAGE_ESTIMATES), "estimates");
}

static void update(lmgi_updater *u, float budget, lmgi_update_stats *st)
{
    lmgi_error e;
    if (lmgi_update(u, 0.0f, budget, st, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    const char *stages[] = {"photons", "AIM", "caustic photons", "reflections", "gather", "light scale", "estimates",
                            "frame"};
    int known = 0;
    for (int i = 0; i < 8; i++)
        known |= st->busiest_stage && strcmp(st->busiest_stage, stages[i]) == 0;
    assert_true(known);
    assert_true(strlen(st->why) > 10);
    if (budget > 0.0f && strcmp(st->busiest_stage, "frame") != 0) {
        char words[64];
        snprintf(words, sizeof words, "budget %g ms", (double)budget);
        if (!strstr(st->why, words))
            fail_msg("why \"%s\" does not say its budget (%s)", st->why, words);
    }
}

/* A small updater whose photon work runs in order, so that the counts an update reports are its own; a
 * frame of side x side (0: none) with small environment maps and caustics. */
static lmgi_updater *in_order_updater(lmgi_context *ctx, lmgi_scene *sc, int side)
{
    lmgi_updater_desc d;
    lmt_room_desc(&d);
    d.in_order = 1;
    d.frame.width = d.frame.height = side;
    d.frame.reflection_size = 16;
    d.caustics.photons = 4096;
    lmgi_updater *u = NULL;
    lmgi_error e;
    if (lmgi_updater_create(ctx, sc, &d, &u, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    return u;
}

/* A light's reach cut short (its range): its 72 groups wait. Without a budget an update re-traces group_budget (16) of them; at
 * a budget too small for anything one, and one AIM surface, one texel; at a generous one all that wait.
 * (The first such edit after still updates is caught up at once, without a budget: all 72 in its update,
 * lmgi_update_stats.groups_at_once; the counts hold for the edits that follow it update after update.) */
static void test_budget_governs_photons_and_aims(void **state)
{
    (void)state;
    lmgi_context *ctx = lmt_context();
    lmgi_scene *sc = lmt_load(lmt_project_scene("two_rooms.glb"), 1500);
    lmgi_updater *u = in_order_updater(ctx, sc, 0);
    lmgi_error e;
    lmgi_update_stats st;
    for (int i = 0; i < 3; i++)
        update(u, 0.0f, &st);
    lmgi_light l;
    assert_int_equal(lmgi_get_light(sc, 0, &l, &e), LMGI_OK);

    l.range = 6.5f; /* a light dimmed alone keeps its photons (test_light_edits): nothing would wait */
    assert_int_equal(lmgi_set_light(sc, 0, &l, &e), LMGI_OK);
    update(u, 0.0f, &st);
    assert_int_equal(st.groups_at_once, 72);
    assert_int_equal(st.groups_retraced, 72);
    l.range = 6.0f;
    assert_int_equal(lmgi_set_light(sc, 0, &l, &e), LMGI_OK);
    update(u, 0.0f, &st);
    assert_int_equal(st.groups_at_once, 0);
    print_message("no budget: %u groups, %d AIMs, %d texels; busiest %s: %s\n", st.groups_retraced,
                  st.aim_surfaces_refreshed, st.texels_budget, st.busiest_stage, st.why);
    assert_int_equal(st.groups_retraced, 16);
    assert_int_equal(st.texels_budget, 20);

    l.range = 5.0f;
    assert_int_equal(lmgi_set_light(sc, 0, &l, &e), LMGI_OK);
    int refreshed = 0;
    for (int i = 0; i < 4; i++) {
        update(u, 1e-3f, &st);
        print_message("1 us: %u groups, %d AIMs, %d texels; busiest %s: %s\n", st.groups_retraced,
                      st.aim_surfaces_refreshed, st.texels_budget, st.busiest_stage, st.why);
        assert_int_equal(st.groups_retraced, 1);
        assert_true(st.aim_surfaces_refreshed <= 1);
        assert_int_equal(st.texels_budget, 1);
        refreshed += st.aim_surfaces_refreshed;
    }
    assert_true(refreshed >= 1);          /* the AIMs are not starved behind the photons */

    update(u, 5000.0f, &st);
    print_message("5 s: %u groups, %d AIMs, %d texels; busiest %s: %s\n", st.groups_retraced,
                  st.aim_surfaces_refreshed, st.texels_budget, st.busiest_stage, st.why);
    assert_true(st.groups_retraced > 16); /* every group still waiting, past group_budget */
    update(u, 5000.0f, &st);
    assert_int_equal(st.groups_retraced, 0);
    lmgi_updater_free(u);
    lmgi_free(sc);
    lmgi_context_free(ctx);
}

/* The Cornell box's cube moved every update, with a frame: its mirror's and glass's faces, the caustic
 * photons and the waiting texels' estimates follow the budget too. */
static void test_budget_governs_faces_and_caustics(void **state)
{
    (void)state;
    lmgi_context *ctx = lmt_context();
    lmgi_scene *sc = lmt_load(lmt_project_scene("cornell.glb"), 1500);
    lmgi_updater *u = in_order_updater(ctx, sc, 32);
    lmgi_error e;
    int cube = lmgi_find_node(sc, "dynamic_cube");
    float m[16];
    lmgi_get_node_transform(sc, cube, m);
    lmgi_update_stats st;
    update(u, 0.0f, &st);
    int faces_tiny = 0, faces_big = 0;
    uint32_t caustic_tiny = 0, caustic_big = 0, estimated_tiny = 0, estimated_none = UINT32_MAX;
    for (int f = 0; f < 12; f++) {
        m[12] += 0.01f;
        assert_int_equal(lmgi_set_node_transform(sc, cube, m, &e), LMGI_OK);
        float budget = f < 6 ? 1e-3f : 5000.0f;
        update(u, budget, &st);
        print_message("%g ms: %d faces, %u caustic photons, %u estimates in %.2f ms; busiest %s: %s\n",
                      (double)budget, st.cube_faces_rendered, st.caustic_photons_retraced, st.texels_estimated,
                      st.ms_estimates, st.busiest_stage, st.why);
        assert_true(st.ms_estimates <= st.ms_gather);
        if (f > 0 && f < 6) { /* the first update after a change of budget was planned for the work before */
            faces_tiny = st.cube_faces_rendered > faces_tiny ? st.cube_faces_rendered : faces_tiny;
            caustic_tiny = st.caustic_photons_retraced > caustic_tiny ? st.caustic_photons_retraced : caustic_tiny;
            estimated_tiny = st.texels_estimated > estimated_tiny ? st.texels_estimated : estimated_tiny;
            estimated_none = st.texels_estimated < estimated_none ? st.texels_estimated : estimated_none;
        } else if (f > 6) {
            faces_big = st.cube_faces_rendered > faces_big ? st.cube_faces_rendered : faces_big;
            caustic_big = st.caustic_photons_retraced > caustic_big ? st.caustic_photons_retraced : caustic_big;
        }
    }
    assert_int_equal(faces_tiny, 1);
    assert_true(faces_big > 1);
    assert_int_equal(caustic_tiny, 1);
    assert_true(caustic_big > 1000);      /* a round robin turn of every pair: 1,024 a pair */
    /* the waiting texels' estimates: one, not the 16 that came with the least texel before they were a
     * stage of their own (4 ms budgets took 7 ms while a node moved: docs/bench.md) */
    assert_int_equal(estimated_tiny, 1);
    assert_int_equal(estimated_none, 1);
    lmgi_updater_free(u);
    lmgi_free(sc);
    lmgi_context_free(ctx);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_plan_shares),
        cmocka_unit_test(test_plan_learns),
        cmocka_unit_test(test_plan_light_scale),
        cmocka_unit_test(test_plan_estimates),
        cmocka_unit_test(test_budget_governs_photons_and_aims),
        cmocka_unit_test(test_budget_governs_faces_and_caustics),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
