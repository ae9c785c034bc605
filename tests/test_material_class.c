/* Material classes changed through the public API (lmgi_set_material's metallic, roughness, transmission):
 * a diffuse block made a mirror lights and shows the room as the same block loaded as a mirror does (its
 * reflection map made at the next frame), made diffuse again it gives back the lightmap from before, a
 * glossy one reads as glossy, and the classes a material cannot take are refused naming why. */
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

static const lmgi_light_desc LAMP = {.name = "lamp", .type = LMGI_LIGHT_POINT, .intensity = 4.0f,
                                     .position = {-1.2f, 2.5f, -1.0f}};

/* The texel size of the room with a diffuse block: a twin whose block is a mirror at load (its triangles
 * without texels) is loaded at the same texel size, so that both sample the room on the same grid. */
static lmgi_scene *load_room(const lmgi_material_desc *block, float texel_size)
{
    lmt_room_spec spec = {.lights = &LAMP, .light_count = 1, .block = block, .texel_size = texel_size};
    return lmt_room(&spec);
}

static void test_diffuse_to_mirror_and_back(void **state)
{
    (void)state;
    lmgi_context *ctx = lmt_context();
    lmgi_error e;
    const lmgi_material_desc chrome = {.name = "red", .base_color = {0.8f, 0.2f, 0.1f, 1.0f}, .metallic = 1.0f,
                                       .roughness = 0.05f};
    lmgi_scene *sc = load_room(NULL, 0.0f);
    lmgi_info in;
    lmgi_get_info(sc, &in);
    lmgi_scene *twin = load_room(&chrome, in.texel_size);
    lmgi_updater *u = lmt_room_updater(ctx, sc), *ut = lmt_room_updater(ctx, twin);
    size_t n, nt;
    float *before = lmt_iim(u, sc, &n), *frame_before = lmt_corner_frame(u);
    int red = lmt_material_named(sc, "red");
    lmgi_material m;
    assert_int_equal(lmgi_get_material(sc, red, &m, &e), LMGI_OK);
    assert_int_equal(m.cls, LMGI_MATERIAL_DIFFUSE);

    m.metallic = 1.0f, m.roughness = 0.05f; /* cls left as it was: the parameters decide */
    assert_int_equal(lmgi_set_material(sc, red, &m, &e), LMGI_OK);
    assert_int_equal(lmgi_get_material(sc, red, &m, &e), LMGI_OK);
    assert_int_equal(m.cls, LMGI_MATERIAL_MIRROR);
    lmgi_get_info(sc, &in);
    assert_int_equal(in.materials_by_class[LMGI_MATERIAL_MIRROR], 1);
    lmgi_bake_report r;
    lmt_bake(u, &r);
    float *mirror = lmt_iim(u, sc, &n), *want = lmt_iim(ut, twin, &nt);
    float *frame_mirror = lmt_corner_frame(u), *frame_want = lmt_corner_frame(ut);
    double room = lmt_node_mean(sc, mirror, "room"), room_want = lmt_node_mean(twin, want, "room");
    double d_frame = lmt_relative_l1(frame_mirror, frame_want, 3 * LMT_SIDE * LMT_SIDE);
    double d_change = lmt_relative_l1(frame_mirror, frame_before, 3 * LMT_SIDE * LMT_SIDE);
    print_message("block made a mirror: %u of %u photon paths changed; room's lightmap %.4f, loaded as a mirror "
                  "%.4f (%+.2f%%), before %.4f; frame %.2e from the twin's, %.3f from before\n", r.photons_changed,
                  r.photons_traced, room, room_want, 100.0 * (room / room_want - 1.0),
                  lmt_node_mean(sc, before, "room"), d_frame, d_change);
    assert_true(r.photons_changed > 0);
    assert_true(fabs(room / room_want - 1.0) < 1e-4);
    assert_true(d_frame < 1e-4); /* the mirror shows the room, as the one loaded a mirror */
    assert_true(d_change > 0.01);

    m.metallic = 0.0f, m.roughness = 1.0f; /* diffuse again: its texels kept, the lightmap as before */
    assert_int_equal(lmgi_set_material(sc, red, &m, &e), LMGI_OK);
    assert_int_equal(lmgi_get_material(sc, red, &m, &e), LMGI_OK);
    assert_int_equal(m.cls, LMGI_MATERIAL_DIFFUSE);
    lmt_bake(u, &r);
    float *back = lmt_iim(u, sc, &n), *frame_back = lmt_corner_frame(u);
    double d_iim = lmt_relative_l1(back, before, n), d_back = lmt_relative_l1(frame_back, frame_before, 3 * LMT_SIDE * LMT_SIDE);
    print_message("diffuse again: lightmap %.2e, frame %.2e from before\n", d_iim, d_back);
    assert_true(d_iim < 1e-4 && d_back < 1e-4);

    m.metallic = 0.9f, m.roughness = 0.15f; /* a glossy metal: the frame brightens where the lamp glints */
    assert_int_equal(lmgi_set_material(sc, red, &m, &e), LMGI_OK);
    assert_int_equal(lmgi_get_material(sc, red, &m, &e), LMGI_OK);
    assert_int_equal(m.cls, LMGI_MATERIAL_GLOSSY);
    lmt_bake(u, &r);
    float *glossy = lmt_iim(u, sc, &n), *frame_glossy = lmt_corner_frame(u);
    assert_true(lmt_relative_l1(frame_glossy, frame_before, 3 * LMT_SIDE * LMT_SIDE) > 0.01);

    /* refused, nothing changed */
    lmgi_material bad = m;
    bad.cls = LMGI_MATERIAL_GLASS;
    lmt_expect_invalid(lmgi_set_material(sc, red, &bad, &e), &e, "read only");
    bad = m;
    bad.roughness = NAN;
    lmt_expect_invalid(lmgi_set_material(sc, red, &bad, &e), &e, "roughness");
    bad = m;
    bad.transmission = 1.5f;
    lmt_expect_invalid(lmgi_set_material(sc, red, &bad, &e), &e, "transmission");
    bad = m;
    bad.ior = 0.5f;
    lmt_expect_invalid(lmgi_set_material(sc, red, &bad, &e), &e, "ior");
    assert_int_equal(lmgi_get_material(sc, red, &m, &e), LMGI_OK);
    assert_int_equal(m.cls, LMGI_MATERIAL_GLOSSY);

    /* the twin's block was a mirror at load: no lightmap texels; glass it may become, diffuse not */
    int tred = lmt_material_named(twin, "red");
    assert_int_equal(lmgi_get_material(twin, tred, &m, &e), LMGI_OK);
    m.metallic = 0.0f, m.roughness = 1.0f;
    lmt_expect_invalid(lmgi_set_material(twin, tred, &m, &e), &e, "no lightmap texels");
    m.transmission = 1.0f, m.ior = 1.5f;
    assert_int_equal(lmgi_set_material(twin, tred, &m, &e), LMGI_OK);
    assert_int_equal(lmgi_get_material(twin, tred, &m, &e), LMGI_OK);
    assert_int_equal(m.cls, LMGI_MATERIAL_GLASS);
    lmt_bake(ut, &r);

    free(before), free(frame_before), free(mirror), free(want), free(frame_mirror), free(frame_want);
    free(back), free(frame_back), free(glossy), free(frame_glossy);
    lmgi_updater_free(u);
    lmgi_updater_free(ut);
    lmgi_free(sc);
    lmgi_free(twin);
    lmgi_context_free(ctx);
}

/* An emitter (emissive at load) keeps its class: its emission may change, its metallic may not. */
static void test_emitter_keeps_its_class(void **state)
{
    (void)state;
    const lmgi_material_desc panel = {.name = "panel", .base_color = {1, 1, 1, 1}, .emissive = {2, 2, 2}};
    lmgi_scene *sc = load_room(&panel, 0.0f);
    lmgi_error e;
    int p = lmt_material_named(sc, "panel");
    lmgi_material m;
    assert_int_equal(lmgi_get_material(sc, p, &m, &e), LMGI_OK);
    assert_int_equal(m.cls, LMGI_MATERIAL_EMITTER);
    m.emissive[0] = m.emissive[1] = m.emissive[2] = 0.0f;
    assert_int_equal(lmgi_set_material(sc, p, &m, &e), LMGI_OK);
    assert_int_equal(lmgi_get_material(sc, p, &m, &e), LMGI_OK);
    assert_int_equal(m.cls, LMGI_MATERIAL_EMITTER); /* dark, still its triangles emit when lit again */
    m.metallic = 1.0f;
    lmt_expect_invalid(lmgi_set_material(sc, p, &m, &e), &e, "emitter");
    lmgi_free(sc);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_diffuse_to_mirror_and_back),
        cmocka_unit_test(test_emitter_keeps_its_class),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
