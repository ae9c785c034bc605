/* The public reference, check and output-directory calls through include/lmgi_tools.h alone: texels and pixels
 * against the analytic irradiance of a point light over a plane, its parts (and a mirror's caustic),
 * determinism and the cache, a frame checked against the reference, and every bad argument refused. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <lmgi_tools.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "edit_room.h"
#include "support.h"

#define PI 3.14159265358979323846
#define INTENSITY 10.0f /* candela, 2 units over the floor */
#define HEIGHT 2.0f
#define ALBEDO 0.8f

/* A 16 x 16 floor of albedo 0.8 at y = 0 under a point light: nothing else, so nothing bounces. */
static lmgi_scene *lamp_over_floor(void)
{
    static const float pos[12] = {-8, 0, 8, 8, 0, 8, 8, 0, -8, -8, 0, -8};
    static const uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
    lmgi_mesh_desc floor = {.name = "floor", .positions = pos, .vertex_count = 4, .indices = idx, .triangle_count = 2};
    lmgi_material_desc grey = {.name = "grey", .base_color = {ALBEDO, ALBEDO, ALBEDO, 1.0f}};
    lmgi_light_desc lamp = {.name = "lamp", .type = LMGI_LIGHT_POINT, .intensity = INTENSITY,
                            .position = {0, HEIGHT, 0}};
    lmgi_scene_desc d = {.name = "lamp over floor", .meshes = &floor, .mesh_count = 1, .materials = &grey,
                         .material_count = 1, .lights = &lamp, .light_count = 1};
    return lmt_load_desc(&d, 1500, 0.0f);
}

static void expect_invalid(lmgi_status st, const lmgi_error *e, const char *words)
{
    assert_int_equal(st, LMGI_ERR_INVALID);
    if (!strstr(e->message, words))
        fail_msg("'%s' does not name '%s'", e->message, words);
}

static lmgi_reference_desc quick(void)
{
    lmgi_reference_desc d;
    memset(&d, 0, sizeof d);
    d.target_error = 0.02f;
    d.samples = 4;
    d.no_cache = 1;
    return d;
}

/* E = I cos(theta) / d^2 at every texel (the images hold it at the texel's atlas position), E_iim exactly 0
 * (no surface to bounce from), radiance = albedo / pi x E; the same again, bit for bit; and from the cache. */
static void test_reference_texels(void **state)
{
    (void)state;
    lmgi_scene *sc = lamp_over_floor();
    lmgi_reference_desc d = quick();
    lmgi_reference r, again;
    lmgi_error e;
    assert_int_equal(lmgi_reference_texels(sc, &d, &r, &e), LMGI_OK);
    lmgi_info in;
    lmgi_get_info(sc, &in);
    assert_int_equal(r.width, in.atlas_width);
    assert_int_equal(r.height, in.atlas_height);
    assert_int_equal(r.entries, lmgi_texel_count(sc));
    assert_int_equal(r.converged, r.entries);
    assert_float_equal(r.target_error, 0.02f, 0.0f); /* the desc's */
    assert_false(r.from_cache);
    int checked = 0;
    for (uint32_t i = 0; i < r.entries; i++) {
        lmgi_texel t;
        lmgi_get_texel(sc, i, &t);
        size_t at = 3 * ((size_t)t.y * (size_t)r.width + (size_t)t.x);
        assert_float_equal(r.iim[at], 0.0, 0.0);
        double x = t.position[0], z = t.position[2], d2 = x * x + HEIGHT * HEIGHT + z * z;
        double expect = INTENSITY * (HEIGHT / sqrt(d2)) / d2;
        assert_float_equal(r.full[at + 1], expect, 0.03 * expect);
        assert_float_equal(r.radiance[at], ALBEDO / PI * r.full[at], 1e-5 * r.full[at]);
        checked++;
    }
    assert_true(checked > 1000);
    size_t bytes = (size_t)r.width * (size_t)r.height * 3 * sizeof(float);
    /* no mirror or glass: all of it is direct light, no caustic, nothing lost; no pixel parts */
    assert_memory_equal(r.full, r.direct, bytes);
    for (size_t i = 0; i < bytes / sizeof(float); i++)
        assert_true(r.caustic[i] == 0.0f && r.lost[i] == 0.0f);
    assert_true(!r.emission && !r.indirect && !r.reflections);
    assert_int_equal(r.caustic_photons, 0);
    assert_int_equal(lmgi_reference_texels(sc, &d, &again, &e), LMGI_OK);
    assert_memory_equal(r.full, again.full, bytes); /* deterministic */
    lmgi_reference_free(&again);
    char cache[1024];
    snprintf(cache, sizeof cache, "%s/ref-cache", lmt_tmpdir()); /* a new directory: nothing cached yet */
    d.no_cache = 0;
    d.cache_dir = cache;
    for (int k = 0; k < 2; k++) {
        assert_int_equal(lmgi_reference_texels(sc, &d, &again, &e), LMGI_OK);
        assert_int_equal(again.from_cache, k); /* computed, then read back */
        assert_memory_equal(r.iim, again.iim, bytes);
        assert_memory_equal(r.full, again.full, bytes);
        assert_memory_equal(r.direct, again.direct, bytes);
        assert_memory_equal(r.lost, again.lost, bytes);
        lmgi_reference_free(&again);
    }
    assert_null(again.full);
    lmgi_reference_free(&r);
    lmgi_free(sc);
}

/* The picture: every pixel that sees the floor shows albedo / pi x E of the point it sees; the check's
 * frame (direct light, no indirect to add) within a few percent of it over the floor. */
static void test_reference_pixels_and_check(void **state)
{
    (void)state;
    enum { SIDE = 48 };
    lmgi_scene *sc = lamp_over_floor();
    lmgi_camera cam;
    lmgi_error e;
    assert_int_equal(lmgi_scene_camera(sc, -1, SIDE, SIDE, &cam, &e), LMGI_OK);
    lmgi_reference_desc d = quick();
    lmgi_reference px;
    assert_int_equal(lmgi_reference_pixels(sc, &d, &cam, SIDE, SIDE, &px, &e), LMGI_OK);
    assert_int_equal(px.width, SIDE);
    assert_int_equal(px.entries, SIDE * SIDE);
    assert_null(px.iim);
    assert_null(px.radiance);
    for (int i = 0; i < 3 * SIDE * SIDE; i++) { /* all of it is the floor's direct light */
        assert_true(px.emission[i] == 0.0f && px.indirect[i] == 0.0f && px.caustic[i] == 0.0f);
        assert_true(px.reflections[i] == 0.0f && px.lost[i] == 0.0f);
        assert_float_equal(px.direct[i], px.full[i], 0.0);
    }
    double sum_ref = 0.0;
    int seen = 0;
    for (int i = 0; i < SIDE * SIDE; i++)
        if (px.full[3 * i] > 0.0f)
            sum_ref += px.full[3 * i], seen++;
    assert_true(seen > SIDE * SIDE / 8); /* the automatic camera looks down at the lit floor */

    lmgi_context *ctx = NULL;
    assert_int_equal(lmgi_context_create(NULL, &ctx, &e), LMGI_OK);
    lmgi_updater_desc ud;
    memset(&ud, 0, sizeof ud);
    ud.photons.count = 4000;
    ud.gather.resolution = 16;
    ud.frame.width = ud.frame.height = SIDE;
    lmgi_check_result c;
    assert_int_equal(lmgi_check(ctx, sc, &ud, &d, 1, &c, &e), LMGI_OK);
    assert_int_equal(c.width, SIDE);
    assert_float_equal(c.reference_target_error, 0.02f, 0.0f);
    assert_int_equal(c.surface_count, lmgi_surface_count(sc));
    assert_true(c.pixels > (uint32_t)seen / 2); /* the floor's interior pixels */
    double sum_check = 0.0;
    for (int i = 0; i < SIDE * SIDE; i++)
        sum_check += c.reference[3 * i] > 0.0f ? c.reference[3 * i] : 0.0;
    print_message("lamp over floor: frame / reference %.4f %.4f %.4f over %u pixels, relative RMSE %.4f; "
                  "the check's reference / lmgi_reference_pixels %.4f\n", c.ratio[0], c.ratio[1], c.ratio[2],
                  c.pixels, c.rel_rmse, sum_check / sum_ref);
    assert_float_equal(sum_check / sum_ref, 1.0, 0.01); /* the same camera, the same picture */
    for (int k = 0; k < 3; k++) {
        assert_float_equal(c.ratio[k], 1.0, 0.03);
        assert_float_equal(c.ratio[k], c.frame_mean[k] / c.reference_mean[k], 1e-9);
    }
    int floor_row = -1;
    for (int s = 0; s < c.surface_count; s++)
        if (c.surfaces[s].pixels)
            floor_row = s;
    assert_true(floor_row >= 0);
    assert_int_equal(c.surfaces[floor_row].node, lmgi_find_node(sc, "floor"));
    assert_int_equal(c.surfaces[floor_row].pixels, c.pixels); /* the only surface, not emissive */

    /* an updater of the same desc, one update in: lmgi_check_updater draws its lighting from the same
     * camera and compares it with the same reference (from the cache) */
    ud.frame.width = ud.frame.height = 0;
    lmgi_updater *u = NULL;
    assert_int_equal(lmgi_updater_create(ctx, sc, &ud, &u, &e), LMGI_OK);
    assert_int_equal(lmgi_update(u, 0.0f, 0.0f, NULL, &e), LMGI_OK);
    lmgi_check_result cu;
    assert_int_equal(lmgi_check_updater(u, &cam, SIDE, SIDE, &d, &cu, &e), LMGI_OK);
    print_message("the updater's check: frame / reference %.4f %.4f %.4f over %u pixels (lmgi_check's %.4f)\n",
                  cu.ratio[0], cu.ratio[1], cu.ratio[2], cu.pixels, c.ratio[0]);
    assert_int_equal(cu.pixels, c.pixels);
    double sum_updater = 0.0; /* the same view, to float rounding: the same picture */
    for (int i = 0; i < SIDE * SIDE; i++)
        sum_updater += cu.reference[3 * i] > 0.0f ? cu.reference[3 * i] : 0.0;
    assert_float_equal(sum_updater / sum_check, 1.0, 0.01);
    for (int k = 0; k < 3; k++)
        assert_float_equal(cu.ratio[k], c.ratio[k], 1e-3);
    lmgi_check_free(&cu);
    expect_invalid(lmgi_check_updater(NULL, &cam, SIDE, SIDE, &d, &cu, &e), &e, "updater is NULL");
    expect_invalid(lmgi_check_updater(u, NULL, SIDE, SIDE, &d, &cu, &e), &e, "cam is NULL");
    expect_invalid(lmgi_check_updater(u, &cam, 0, SIDE, &d, &cu, &e), &e, "0 x");
    lmgi_updater_free(u);
    lmgi_check_free(&c);
    assert_null(c.frame);
    lmgi_reference_free(&px);
    lmgi_context_free(ctx);
    lmgi_free(sc);
}

/* The lamp over the floor with a 1.5 x 1.5 mirror 1 unit above it, facing down: the floor (the only
 * surface with texels) gets the light's image, E = rho I cos / d^2 from the virtual light at (0, 4, 0),
 * over the mirror scaled 4 times from it (|x|, |z| < 3); the pixel parts add up to the picture. */
static void test_reference_parts_with_mirror(void **state)
{
    (void)state;
    static const float floor_pos[12] = {-8, 0, 8, 8, 0, 8, 8, 0, -8, -8, 0, -8};
    static const float mirror_pos[12] = {-0.75f, 3, -0.75f, 0.75f, 3, -0.75f, 0.75f, 3, 0.75f, -0.75f, 3, 0.75f};
    static const uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
    lmgi_mesh_desc meshes[2] = {
        {.name = "floor", .positions = floor_pos, .vertex_count = 4, .indices = idx, .triangle_count = 2},
        {.name = "mirror", .positions = mirror_pos, .vertex_count = 4, .indices = idx, .triangle_count = 2,
         .material = 1}};
    lmgi_material_desc mats[2] = {{.name = "grey", .base_color = {ALBEDO, ALBEDO, ALBEDO, 1.0f}},
                                  {.name = "mirror", .base_color = {0.9f, 0.9f, 0.9f, 1.0f}, .metallic = 1.0f,
                                   .roughness = 0.01f}};
    lmgi_light_desc lamp = {.name = "lamp", .type = LMGI_LIGHT_POINT, .intensity = INTENSITY,
                            .position = {0, HEIGHT, 0}};
    lmgi_scene_desc sd = {.name = "lamp, mirror and floor", .meshes = meshes, .mesh_count = 2, .materials = mats,
                          .material_count = 2, .lights = &lamp, .light_count = 1};
    lmgi_scene *sc = lmt_load_desc(&sd, 1500, 0.0f);
    lmgi_error e;
    lmgi_reference_desc d = quick();
    d.target_error = 0.2f;
    d.caustic_photons = 1 << 18;
    lmgi_reference r;
    assert_int_equal(lmgi_reference_texels(sc, &d, &r, &e), LMGI_OK);
    assert_int_equal(r.caustic_photons, 1 << 18);
    double got = 0.0, want = 0.0;
    for (uint32_t i = 0; i < r.entries; i++) {
        lmgi_texel t;
        lmgi_get_texel(sc, i, &t);
        double x = t.position[0], z = t.position[2], d2 = x * x + 16.0 + z * z;
        if (fabs(x) > 2.5 || fabs(z) > 2.5)
            continue;
        got += r.caustic[3 * ((size_t)t.y * (size_t)r.width + (size_t)t.x)];
        want += 0.9 * INTENSITY * (4.0 / sqrt(d2)) / d2;
    }
    print_message("mirror over the lamp: texels' caustic / analytic %.4f\n", got / want);
    assert_float_equal(got / want, 1.0, 0.05);
    lmgi_reference_free(&r);
    enum { SIDE = 24 };
    lmgi_camera cam;
    assert_int_equal(lmgi_scene_camera(sc, -1, SIDE, SIDE, &cam, &e), LMGI_OK);
    assert_int_equal(lmgi_reference_pixels(sc, &d, &cam, SIDE, SIDE, &r, &e), LMGI_OK);
    double caustic = 0.0;
    for (int i = 0; i < 3 * SIDE * SIDE; i++) {
        double sum = (double)r.emission[i] + r.direct[i] + r.indirect[i] + r.caustic[i] + r.reflections[i] + r.lost[i];
        assert_float_equal(sum, r.full[i], 1e-5 * fmax(r.full[i], 1e-6));
        caustic += r.caustic[i];
    }
    assert_true(caustic > 0.0);
    lmgi_reference_free(&r);
    lmgi_free(sc);
}

static void test_bad_arguments(void **state)
{
    (void)state;
    lmgi_scene *sc = lamp_over_floor();
    lmgi_reference_desc d = quick();
    lmgi_reference r;
    lmgi_error e;
    memset(&r, 0x5a, sizeof r);
    expect_invalid(lmgi_reference_texels(NULL, &d, &r, &e), &e, "scene is NULL");
    assert_null(r.full); /* zeroed */
    expect_invalid(lmgi_reference_texels(sc, &d, NULL, &e), &e, "out is NULL");
    d.target_error = NAN;
    expect_invalid(lmgi_reference_texels(sc, &d, &r, &e), &e, "target_error");
    d.target_error = 2.0f;
    expect_invalid(lmgi_reference_texels(sc, &d, &r, &e), &e, "target_error 2");
    d = quick();
    d.samples = -3;
    expect_invalid(lmgi_reference_texels(sc, &d, &r, &e), &e, "samples -3");
    d = quick();
    d.caustic_photons = -1;
    expect_invalid(lmgi_reference_texels(sc, &d, &r, &e), &e, "caustic_photons -1");
    d.caustic_photons = (1 << 24) + 1;
    expect_invalid(lmgi_reference_texels(sc, &d, &r, &e), &e, "caustic_photons 16777217");
    d = quick();
    lmgi_camera cam;
    assert_int_equal(lmgi_scene_camera(sc, -1, 8, 8, &cam, &e), LMGI_OK);
    expect_invalid(lmgi_reference_pixels(sc, &d, NULL, 8, 8, &r, &e), &e, "cam is NULL");
    expect_invalid(lmgi_reference_pixels(sc, &d, &cam, 0, 8, &r, &e), &e, "0 x 8");
    lmgi_camera flat = cam;
    memset(flat.view, 0, sizeof flat.view);
    expect_invalid(lmgi_reference_pixels(sc, &d, &flat, 8, 8, &r, &e), &e, "not invertible");
    flat = cam; /* an orthographic projection: the solver takes pinhole cameras only */
    memset(flat.proj, 0, sizeof flat.proj);
    flat.proj[0] = flat.proj[5] = flat.proj[15] = 1.0f, flat.proj[10] = -1.0f;
    expect_invalid(lmgi_reference_pixels(sc, &d, &flat, 8, 8, &r, &e), &e, "orthographic");
    lmgi_reference_free(NULL);

    lmgi_context *ctx = NULL;
    assert_int_equal(lmgi_context_create(NULL, &ctx, &e), LMGI_OK);
    lmgi_check_result c;
    expect_invalid(lmgi_check(NULL, sc, NULL, &d, 1, &c, &e), &e, "context is NULL");
    expect_invalid(lmgi_check(ctx, NULL, NULL, &d, 1, &c, &e), &e, "scene is NULL");
    expect_invalid(lmgi_check(ctx, sc, NULL, &d, 1, NULL, &e), &e, "out is NULL");
    expect_invalid(lmgi_check(ctx, sc, NULL, &d, 0, &c, &e), &e, "0 frames");
    lmgi_updater_desc ud;
    memset(&ud, 0, sizeof ud);
    ud.gather.samples = 3;
    expect_invalid(lmgi_check(ctx, sc, &ud, &d, 1, &c, &e), &e, "gather.samples 3");
    d.target_error = -1.0f;
    expect_invalid(lmgi_check(ctx, sc, NULL, &d, 1, &c, &e), &e, "target_error");
    d = quick();
    ud.gather.samples = 0;
    ud.photons.count = 2000;
    ud.gather.resolution = 8;
    ud.frame.width = ud.frame.height = 0;
    lmgi_updater *u = NULL;
    assert_int_equal(lmgi_updater_create(ctx, sc, &ud, &u, &e), LMGI_OK);
    expect_invalid(lmgi_check(ctx, sc, NULL, &d, 1, &c, &e), &e, "has an updater");
    lmgi_updater_free(u);
    lmgi_check_free(NULL);
    lmgi_context_free(ctx);
    lmgi_free(sc);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_reference_texels),
        cmocka_unit_test(test_reference_pixels_and_check),
        cmocka_unit_test(test_reference_parts_with_mirror),
        cmocka_unit_test(test_bad_arguments),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
