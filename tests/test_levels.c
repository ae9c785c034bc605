/* The two shared levels (issue 30, item 6; docs/levels.md): Godot's occlusion-culling room (63,720
 * triangles, a sun and a point light with a range) and Godot 4's truck-town export (WebP textures behind
 * a required extension, percent-encoded URIs, 2 km of ground). Each loads, keeps its texel budget, bakes
 * at a small budget under a sky with no valid texel exactly 0, and its frame matches the path-traced
 * reference within 5% over the frame (with the gather this machine picks for them: rays on a software
 * GL). Skipped, saying so, where ../shared is absent. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>
#include <lmgi.h>

#include "edit_room.h"
#include "support.h"

static const float k_sky[3] = {0.2f, 0.25f, 0.35f}; /* a pale blue sky, a tenth of the room's lamp-lit walls */

/* The budget met within 15%, and the atlas at least `utilization` full. */
static void atlas_within(const char *path, int texels, double utilization)
{
    lmgi_scene *sc = lmt_load(path, texels);
    lmgi_info in;
    lmgi_get_info(sc, &in);
    print_message("%s at %d texels: %u texels, utilization %.1f%%\n", path, texels, in.texels,
                  100.0 * in.utilization);
    assert_true(fabs((double)in.texels / texels - 1.0) <= 0.15);
    assert_true(in.utilization >= utilization);
    lmgi_free(sc);
}

/* The budgets item 2 of issue 30 names, from 2,000 to 1,000,000 texels: each met within 15%, the atlas at
 * least 60% used (measured: 66-99%, docs/levels.md, "Atlas"). */
static void atlas_every_budget(const char *path)
{
    static const int budgets[] = {2000, 20000, 200000, 1000000};
    for (size_t i = 0; i < sizeof budgets / sizeof *budgets; i++)
        atlas_within(path, budgets[i], 0.6);
}

/* At `lmgi run`'s density (1,800 texels and lmgi_options.wall_texels 16): every surface of 2 m^2 or more
 * gets at least `least` texels (one texel of 50 m each before, on the town), and the texels the walls add
 * stay within `most` in all. */
static void walls_at_run_density(const char *path, uint32_t least, uint32_t most)
{
    lmgi_options o;
    lmgi_options_init(&o);
    o.target_texels = lmgi_atlas_texels_for(0);
    o.wall_texels = 16;
    lmgi_scene *sc = NULL;
    lmgi_error e;
    if (lmgi_load(path, &o, &sc, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    int n = lmgi_surface_count(sc);
    uint32_t *count = calloc((size_t)n, sizeof *count), fewest = UINT32_MAX;
    double *area = calloc((size_t)n, sizeof *area);
    assert_non_null(count);
    assert_non_null(area);
    for (uint32_t i = 0; i < lmgi_texel_count(sc); i++) {
        lmgi_texel t;
        lmgi_get_texel(sc, i, &t);
        count[t.surface]++;
        area[t.surface] += t.area;
    }
    int walls = 0;
    for (int f = 0; f < n; f++)
        if (area[f] >= 2.0) {
            walls++;
            fewest = count[f] < fewest ? count[f] : fewest;
        }
    print_message("%s at run's density: %u texels, %d surfaces of 2 m^2 or more, the fewest texels of one %u\n",
                  path, lmgi_texel_count(sc), walls, fewest);
    assert_true(walls > 0);
    assert_true(fewest >= least);
    assert_true(lmgi_texel_count(sc) <= most);
    free(count);
    free(area);
    lmgi_free(sc);
}

/* Bakes the level at `texels` under the sky: no valid texel of the lightmap exactly 0; then its frame from
 * cam (NULL: the file's camera) against the reference at 64 x 64, within 5% per channel over the frame. */
static void bake_and_check(const char *path, int texels, const lmgi_camera *cam)
{
    lmgi_scene *sc = lmt_load(path, texels);
    lmgi_error e;
    assert_int_equal(lmgi_set_environment(sc, k_sky, &e), LMGI_OK);
    lmgi_context *ctx = NULL;
    assert_int_equal(lmgi_context_create(NULL, &ctx, &e), LMGI_OK);
    lmgi_updater_desc d;
    memset(&d, 0, sizeof d);
    lmgi_updater *u = NULL;
    if (lmgi_updater_create(ctx, sc, &d, &u, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    lmgi_info in;
    lmgi_get_info(sc, &in);
    lmgi_updater_info ui;
    lmgi_get_updater_info(u, &ui);
    print_message("%s: %s gather, %.1f s\n", path, ui.gather_scheme, 1e-3 * ui.ms_setup_gather);
    size_t n = 4 * (size_t)in.atlas_width * in.atlas_height;
    float *rgba = malloc(n * sizeof *rgba);
    assert_non_null(rgba);
    assert_int_equal(lmgi_get_lightmap(u, LMGI_LIGHTMAP_IIM, rgba, n, &e), LMGI_OK);
    uint32_t valid = 0, black = 0;
    for (size_t i = 0; i < n / 4; i++) {
        if (!(rgba[4 * i + 3] > 0.0f))
            continue;
        valid++;
        black += rgba[4 * i] == 0.0f && rgba[4 * i + 1] == 0.0f && rgba[4 * i + 2] == 0.0f;
        for (int c = 0; c < 3; c++)
            assert_true(isfinite(rgba[4 * i + c]) && rgba[4 * i + c] >= 0.0f);
    }
    free(rgba);
    lmgi_camera own;
    if (!cam) {
        assert_int_equal(lmgi_scene_camera(sc, -1, 64, 64, &own, &e), LMGI_OK);
        cam = &own;
    }
    lmgi_reference_desc rd;
    memset(&rd, 0, sizeof rd);
    rd.target_error = 0.03f;
    lmgi_check_result c;
    assert_int_equal(lmgi_check_updater(u, cam, 64, 64, &rd, &c, &e), LMGI_OK);
    print_message("%s at %d texels under the sky: %u of %u valid texels exactly 0; frame / reference %.4f %.4f "
                  "%.4f over %u pixels, relative RMSE %.3f\n", path, texels, black, valid, c.ratio[0], c.ratio[1],
                  c.ratio[2], c.pixels, c.rel_rmse);
    assert_true(valid > 0.5 * texels);
    assert_int_equal(black, 0);
    assert_true(c.pixels > 64 * 64 / 4);
    for (int k = 0; k < 3; k++)
        assert_float_equal(c.ratio[k], 1.0, 0.05);
    lmgi_check_free(&c);
    lmgi_updater_free(u);
    lmgi_free(sc);
    lmgi_context_free(ctx);
}

/* The room: its file's camera stands in the walls' corner (every reference ray from it starts on a wall's
 * back), so the frame is checked from inside, near that corner, looking at the far pillars. */
static void test_occlusion_room(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(path, lmt_shared_scene("occlusion-room/room_lit.glb"));
    atlas_every_budget(path);
    walls_at_run_density(path, 12, 4000); /* measured 1,964 */
    lmgi_camera cam;
    lmt_look_at((const float[3]){4.0f, 2.5f, 4.0f}, (const float[3]){-2.0f, 1.5f, -2.0f}, 1.1f, &cam);
    bake_and_check(path, 8000, &cam);
}

/* The town: 30,477 triangles drawn (its OMI physics meshes are not), two WebP textures; its 2 km of
 * ground takes most of any budget, so the frame is checked at 20,000 texels (at 8,000 it reads 7-10% dark:
 * 30 m texels under the houses; docs/levels.md). */
static void test_truck_town(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(path, lmt_shared_scene("truck-town/town_lit.gltf"));
    atlas_every_budget(path);
    walls_at_run_density(path, 12, 40000); /* measured 30,219: 1,800 + 587 walls and roofs */
    bake_and_check(path, 20000, NULL);
}

/* The generated level of many rooms (354,112 triangles, 13,246 surfaces at the fragment merge): at 2,000
 * texels its small surfaces merge (docs/levels.md, "Atlas"), at 1,000,000 its 19,220 charts pack. */
static void test_many_rooms(void **state)
{
    (void)state;
    atlas_every_budget("scenes/many_rooms.glb");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_occlusion_room),
        cmocka_unit_test(test_truck_town),
        cmocka_unit_test(test_many_rooms),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
