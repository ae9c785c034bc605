/* Effects switched per node through the public API (lmgi_set_node_effects): a block's shadows off only
 * brighten the frame, where its shadow was; its indirect light off takes its lightmap out of the frame
 * and out of the gather's work, and back on regathers it to what it would have been; a mirror's
 * reflections off drop its environment map; each switched back gives the frame from before. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <lmgi.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "edit_room.h"
#include "support.h"

#define PIXELS (3 * LMT_SIDE * LMT_SIDE)

static const lmgi_light_desc LAMP = {.name = "lamp", .type = LMGI_LIGHT_POINT, .intensity = 4.0f,
                                     .position = {-1.2f, 2.5f, -1.0f}};

static lmgi_scene *load_room(const lmgi_material_desc *block)
{
    lmt_room_spec spec = {.lights = &LAMP, .light_count = 1, .block = block, .stool = 1};
    return lmt_room(&spec);
}

static double sum(const float *v, size_t n)
{
    double s = 0.0;
    for (size_t i = 0; i < n; i++)
        s += v[i];
    return s;
}

/* Texels of the room's node `name` (12 triangles per node: room, block, stool). */
static uint32_t node_texels(const lmgi_scene *sc, int first_tri)
{
    lmgi_info in;
    lmgi_get_info(sc, &in);
    uint32_t n = 0;
    for (uint32_t i = 0; i < in.texels; i++) {
        lmgi_texel t;
        lmgi_get_texel(sc, i, &t);
        n += t.triangle >= (uint32_t)first_tri && t.triangle < (uint32_t)first_tri + 12;
    }
    return n;
}

static void test_shadows_and_indirect(void **state)
{
    (void)state;
    lmgi_context *ctx = lmt_context();
    lmgi_error e;
    lmgi_scene *sc = load_room(NULL), *twin = load_room(NULL);
    lmgi_updater *u = lmt_room_updater(ctx, sc), *ut = lmt_room_updater(ctx, twin);
    int block = lmgi_find_node(sc, "block"), lamp = lmgi_find_node(sc, "lamp");
    float *before = lmt_corner_frame(u);
    lmgi_node_effects fx;
    assert_int_equal(lmgi_get_node_effects(sc, block, &fx, &e), LMGI_OK);
    assert_true(fx.shadows && fx.indirect && fx.reflections);

    /* shadows off: light only added, where the block's shadow was */
    fx.shadows = 0;
    assert_int_equal(lmgi_set_node_effects(sc, block, &fx, &e), LMGI_OK);
    lmgi_update_stats st;
    assert_int_equal(lmgi_update(u, 0.0f, 0.0f, &st, &e), LMGI_OK);
    float *unshadowed = lmt_corner_frame(u);
    int darker = 0;
    for (int i = 0; i < PIXELS; i++)
        darker += unshadowed[i] < before[i] - 1e-6f * (1.0f + before[i]);
    double gain = sum(unshadowed, PIXELS) / sum(before, PIXELS) - 1.0;
    print_message("the block's shadows off: frame +%.1f%%, %d channels darker\n", 100.0 * gain, darker);
    assert_int_equal(darker, 0);
    assert_true(gain > 0.01);
    fx.shadows = 1;
    assert_int_equal(lmgi_set_node_effects(sc, block, &fx, &e), LMGI_OK);
    assert_int_equal(lmgi_update(u, 0.0f, 0.0f, &st, &e), LMGI_OK);
    float *again = lmt_corner_frame(u);
    assert_true(lmt_relative_l1(again, before, PIXELS) < 1e-6);

    /* indirect off: the block's lightmap leaves the frame and the gather */
    fx.indirect = 0;
    assert_int_equal(lmgi_set_node_effects(sc, block, &fx, &e), LMGI_OK);
    lmgi_bake_report r;
    lmt_bake(u, &r);
    assert_int_equal(r.texels_gathered, 0); /* nothing moved */
    float *no_indirect = lmt_corner_frame(u);
    double loss = 1.0 - sum(no_indirect, PIXELS) / sum(before, PIXELS);
    print_message("the block's indirect light off: frame -%.1f%%\n", 100.0 * loss);
    assert_true(loss > 0.005);
    for (int i = 0; i < PIXELS; i++)
        assert_true(no_indirect[i] <= before[i] + 1e-6f * (1.0f + before[i]));
    lmgi_effect eff;
    float world[16]; /* the lamp moves: every surface but the block's is regathered */
    assert_true(lmgi_get_node_transform(sc, lamp, world));
    world[12] += 0.8f;
    assert_int_equal(lmgi_set_node_transform(sc, lamp, world, &e), LMGI_OK);
    assert_int_equal(lmgi_set_node_transform(twin, lamp, world, &e), LMGI_OK);
    lmt_bake(u, &r);
    lmgi_bake_report rt;
    lmt_bake(ut, &rt);
    uint32_t block_texels = node_texels(sc, 12);
    print_message("the lamp moved: %u texels regathered, the twin with the block's indirect on %u (the block has "
                  "%u)\n", r.texels_gathered, rt.texels_gathered, block_texels);
    /* the twin's extra work is the block's (its face on the floor sees no change, and is not regathered) */
    assert_true(r.texels_gathered < rt.texels_gathered && rt.texels_gathered <= r.texels_gathered + block_texels);
    fx.indirect = 1; /* back on: the block regathered in full, as the twin's */
    assert_int_equal(lmgi_set_node_effects(sc, block, &fx, &e), LMGI_OK);
    lmt_bake(u, &r);
    assert_int_equal(r.texels_gathered, block_texels);
    size_t n;
    float *iim = lmt_iim(u, sc, &n), *want = lmt_iim(ut, twin, &n);
    float *frame = lmt_corner_frame(u), *frame_want = lmt_corner_frame(ut);
    double d_iim = lmt_relative_l1(iim, want, n), d_frame = lmt_relative_l1(frame, frame_want, PIXELS);
    print_message("back on: lightmap %.1e, frame %.1e from the twin's\n", d_iim, d_frame);
    assert_true(d_iim < 1e-6 && d_frame < 1e-6);
    lmgi_get_effect(sc, 0, &eff);
    assert_true(eff.on);

    /* refused, nothing changed */
    lmgi_node_effects bad = fx;
    bad.indirect = 2;
    lmt_expect_invalid(lmgi_set_node_effects(sc, block, &bad, &e), &e, "indirect is 0 or 1");
    lmt_expect_invalid(lmgi_set_node_effects(sc, 99, &fx, &e), &e, "out of range");
    lmt_expect_invalid(lmgi_set_node_effects(sc, block, NULL, &e), &e, "NULL");
    lmt_expect_invalid(lmgi_set_node_effects(NULL, block, &fx, &e), &e, "NULL");
    lmt_expect_invalid(lmgi_get_node_effects(NULL, block, &bad, &e), &e, "NULL");
    lmt_expect_invalid(lmgi_get_node_effects(sc, block, NULL, &e), &e, "NULL");
    lmt_expect_invalid(lmgi_get_node_effects(sc, -1, &bad, &e), &e, "out of range");
    assert_int_equal(lmgi_get_node_effects(sc, block, &bad, &e), LMGI_OK);
    assert_true(bad.shadows && bad.indirect && bad.reflections);

    free(before), free(unshadowed), free(again), free(no_indirect), free(iim), free(want), free(frame);
    free(frame_want);
    lmgi_updater_free(u);
    lmgi_updater_free(ut);
    lmgi_free(sc);
    lmgi_free(twin);
    lmgi_context_free(ctx);
}

/* The effect named `name` of sc. */
static lmgi_effect effect(const lmgi_scene *sc, const char *name)
{
    lmgi_effect eff;
    for (int i = 0;; i++) {
        lmgi_get_effect(sc, i, &eff);
        if (!eff.name || !strcmp(eff.name, name))
            break;
    }
    assert_non_null(eff.name);
    return eff;
}

static void test_reflections(void **state)
{
    (void)state;
    lmgi_context *ctx = lmt_context();
    lmgi_error e;
    const lmgi_material_desc chrome = {.name = "chrome", .base_color = {0.9f, 0.9f, 0.9f, 1.0f}, .metallic = 1.0f,
                                       .roughness = 0.05f};
    lmgi_scene *sc = load_room(&chrome);
    lmgi_updater *u = lmt_room_updater(ctx, sc);
    int block = lmgi_find_node(sc, "block");
    assert_true(effect(sc, "reflections").on);
    float *before = lmt_corner_frame(u);
    lmgi_node_effects fx;
    assert_int_equal(lmgi_get_node_effects(sc, block, &fx, &e), LMGI_OK);
    fx.reflections = 0;
    assert_int_equal(lmgi_set_node_effects(sc, block, &fx, &e), LMGI_OK);
    lmgi_effect off = effect(sc, "reflections");
    print_message("reflections: %s (%s)\n", off.on ? "on" : "off", off.reason);
    assert_false(off.on);
    assert_non_null(strstr(off.reason, "switched off"));
    lmgi_update_stats st;
    assert_int_equal(lmgi_update(u, 0.0f, 0.0f, &st, &e), LMGI_OK);
    float *black = lmt_corner_frame(u);
    double loss = 1.0 - sum(black, PIXELS) / sum(before, PIXELS);
    print_message("the mirror's reflections off: frame -%.1f%%\n", 100.0 * loss);
    assert_true(loss > 0.005);
    fx.reflections = 1;
    assert_int_equal(lmgi_set_node_effects(sc, block, &fx, &e), LMGI_OK);
    assert_int_equal(lmgi_update(u, 0.0f, 0.0f, &st, &e), LMGI_OK);
    float *back = lmt_corner_frame(u);
    assert_true(lmt_relative_l1(back, before, PIXELS) < 1e-6);
    free(before), free(black), free(back);
    lmgi_updater_free(u);
    lmgi_free(sc);
    lmgi_context_free(ctx);
}

/* Every root of the room (room, block, stool, lamp) with the switches fx. */
static void switch_all(lmgi_scene *sc, const lmgi_node_effects *fx)
{
    lmgi_error e;
    for (int n = 0; n < lmgi_node_count(sc); n++)
        assert_int_equal(lmgi_set_node_effects(sc, n, fx, &e), LMGI_OK);
}

/* The run's switches (lmgi_updater_desc.effects_off) give the frame of the same scene with every node's
 * switch off, and a run without indirect light does no photon, AIM or gather work at all. */
static void test_run_effects(void **state)
{
    (void)state;
    lmgi_context *ctx = lmt_context();
    lmgi_error e;
    const lmgi_material_desc chrome = {.name = "chrome", .base_color = {0.9f, 0.9f, 0.9f, 1.0f}, .metallic = 1.0f,
                                       .roughness = 0.05f};
    static const unsigned bits[4] = {LMGI_EFFECT_SHADOWS, LMGI_EFFECT_INDIRECT, LMGI_EFFECT_REFLECTIONS,
                                     LMGI_EFFECT_CAUSTICS};
    static const char *const names[4] = {"shadows", "indirect", "reflections", "caustics"};
    for (int k = 0; k < 4; k++) {
        lmgi_scene *run = load_room(&chrome), *nodes = load_room(&chrome);
        lmgi_updater *u = lmt_room_updater_without(ctx, run, bits[k]);
        lmgi_node_effects fx = {1, 1, 1, 1};
        *(k == 0 ? &fx.shadows : k == 1 ? &fx.indirect : k == 2 ? &fx.reflections : &fx.caustics) = 0;
        switch_all(nodes, &fx);
        lmgi_updater *un = lmt_room_updater(ctx, nodes);
        lmgi_update_stats st, stn;
        uint32_t work = 0;
        for (int f = 0; f < 3; f++) {
            assert_int_equal(lmgi_update(u, 0.0f, 0.0f, &st, &e), LMGI_OK);
            assert_int_equal(lmgi_update(un, 0.0f, 0.0f, &stn, &e), LMGI_OK);
            work += st.photons_retraced + st.texels_gathered + (uint32_t)st.aim_surfaces_refreshed;
        }
        float *a = lmt_corner_frame(u), *b = lmt_corner_frame(un);
        double d = lmt_relative_l1(a, b, PIXELS);
        lmgi_updater_info info;
        lmgi_get_updater_info(u, &info);
        print_message("-%s: frame %.1e from every node's %s off; photons %u, photon and gather work in 3 updates "
                      "%u\n", names[k], d, names[k], info.stored_photons, work);
        assert_true(d < 1e-6);
        if (bits[k] == LMGI_EFFECT_INDIRECT) {
            assert_int_equal(info.stored_photons, 0);
            assert_int_equal(work, 0);
            size_t n;
            float *iim = lmt_iim(u, run, &n);
            for (size_t i = 0; i < n; i += 4)
                assert_true(iim[i] == 0.0f && iim[i + 1] == 0.0f && iim[i + 2] == 0.0f);
            free(iim);
        }
        free(a), free(b);
        lmgi_updater_free(u);
        lmgi_updater_free(un);
        lmgi_free(run);
        lmgi_free(nodes);
    }
    lmgi_scene *sc = load_room(NULL);
    lmgi_updater_desc d;
    memset(&d, 0, sizeof d);
    d.effects_off = 16;
    lmgi_updater *u = NULL;
    lmt_expect_invalid(lmgi_updater_create(ctx, sc, &d, &u, &e), &e, "effects_off");
    lmgi_free(sc);
    lmgi_context_free(ctx);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_shadows_and_indirect),
        cmocka_unit_test(test_reflections),
        cmocka_unit_test(test_run_effects),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
