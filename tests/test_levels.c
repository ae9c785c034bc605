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
#include <lmgi_tools.h>

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

/* At `lmgi run`'s density (1,800 texels and lmgi_options.wall_texels, 16 as run sets it): every surface of
 * 2 m^2 or more gets at least `least` texels (one texel of 50 m each before, on the town), and the texels
 * the walls add stay within `most` in all. */
static void walls_at_density(const char *path, int wall_texels, uint32_t least, uint32_t most)
{
    lmgi_options o;
    lmgi_options_init(&o);
    o.target_texels = lmgi_atlas_texels_for(0);
    o.wall_texels = wall_texels;
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
    rd.cache_dir = lmt_reference_cache();
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
/* A scene in centimetres makes every surface a wall (the shared Cornell box: 24 surfaces of 0.7 to 30 m^2
 * in its units): all its texels come on top of the budget, the budget had nothing left to meet, and the
 * texel size it scaled by 0 became 0 and then NaN; packing at that size wrote outside the atlas (heap
 * corruption at wall_texels 256 to 65,536). Each surface now gets its wall texels and the load succeeds. */
static void test_every_surface_a_wall(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(path, lmt_shared_scene("cornell-box/CornellBox.glb"));
    walls_at_density(path, 16, 12, 4000);
    walls_at_density(path, 1024, 900, 40000); /* measured 25,592 */
}

static void test_occlusion_room(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(path, lmt_shared_scene("occlusion-room/room_lit.glb"));
    atlas_every_budget(path);
    walls_at_density(path, 16, 12, 4000); /* measured 1,964 */
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
    walls_at_density(path, 16, 12, 40000); /* measured 30,219: 1,800 + 587 walls and roofs */
    bake_and_check(path, 20000, NULL);
}

/* The generated level of many rooms (354,112 triangles, 13,246 surfaces at the fragment merge): at 2,000
 * texels its small surfaces merge (docs/levels.md, "Atlas"), at 1,000,000 its 19,220 charts pack. */
static void test_many_rooms(void **state)
{
    (void)state;
    atlas_every_budget("scenes/many_rooms.glb");
}

/* Pages (docs/levels.md, "Atlas"): the level of many rooms at 200,000 texels on pages of 256 texels (one
 * page would be 616 x 516). The budget met within 15% as on one page; every page within 256 a side and
 * holding texels, the atlas that holds them within 16,384; every texel inside its page, on its triangle's
 * page, whose page UVs lie in [0,1] (no chart crosses a page's edge); at least as many pages as the
 * texels need and the pages at least half used (measured: 6 pages, 55.1%). */
static void test_many_rooms_pages(void **state)
{
    (void)state;
    const int budget = 200000, side = 256;
    lmgi_scene *sc = lmt_load_paged("scenes/many_rooms.glb", budget, side);
    lmgi_info in;
    lmgi_get_info(sc, &in);
    print_message("many_rooms at %d texels on pages of %d: %d pages of %d x %d in a %d x %d atlas, %u texels, %.1f%% "
                  "of the pages used\n", budget, side, in.pages, in.page_width, in.page_height, in.atlas_width,
                  in.atlas_height, in.texels, 100.0 * in.utilization);
    assert_true(fabs((double)in.texels / budget - 1.0) <= 0.15);
    assert_true(in.page_width <= side && in.page_height <= side);
    assert_true(in.atlas_width <= 16384 && in.atlas_height <= 16384);
    assert_true(in.pages >= (int)(in.texels / ((uint32_t)side * side)) + 1);
    assert_true(in.utilization >= 0.5f);
    char *used = calloc((size_t)in.pages, 1);
    assert_non_null(used);
    for (uint32_t i = 0; i < in.texels; i++) {
        lmgi_texel t;
        lmgi_get_texel(sc, i, &t);
        int r[4];
        float uv[6];
        assert_int_equal(lmgi_page_rect(sc, t.page, r), 1);
        assert_true(t.x >= r[0] && t.x < r[0] + r[2] && t.y >= r[1] && t.y < r[1] + r[3]);
        assert_int_equal(lmgi_triangle_lightmap_page(sc, t.triangle, uv), t.page);
        for (int k = 0; k < 6; k++)
            assert_true(uv[k] >= 0.0f && uv[k] <= 1.0f);
        used[t.page] = 1;
    }
    for (int p = 0; p < in.pages; p++)
        assert_true(used[p]);
    free(used);
    lmgi_free(sc);
}

/* The level baked whole at `side` (0: one page), its updater and its IIM and AIM read whole. */
typedef struct {
    lmgi_scene *sc;
    lmgi_updater *u;
    lmgi_info in;
    float *iim, *aim;
} baked;

static void bake_on_pages(lmgi_context *ctx, const char *path, int texels, int side, baked *b)
{
    b->sc = lmt_load_paged(path, texels, side);
    lmgi_get_info(b->sc, &b->in);
    lmgi_updater_desc d;
    memset(&d, 0, sizeof d);
    d.photons.count = 20000;
    lmgi_error e;
    if (lmgi_updater_create(ctx, b->sc, &d, &b->u, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    size_t n = 4 * (size_t)b->in.atlas_width * b->in.atlas_height;
    b->iim = malloc(n * sizeof *b->iim), b->aim = malloc(n * sizeof *b->aim);
    assert_true(b->iim && b->aim);
    assert_int_equal(lmgi_get_lightmap(b->u, LMGI_LIGHTMAP_IIM, b->iim, n, &e), LMGI_OK);
    assert_int_equal(lmgi_get_lightmap(b->u, LMGI_LIGHTMAP_AIM, b->aim, n, &e), LMGI_OK);
}

/* The largest difference between the two bakes' values of texel i, relative to the larger (1e-3 of the
 * level's brightest where darker). */
static double texel_difference(const baked *a, const lmgi_texel *ta, const float *ma, const baked *b,
                               const lmgi_texel *tb, const float *mb, float bright)
{
    const float *x = ma + 4 * ((size_t)ta->y * a->in.atlas_width + ta->x);
    const float *y = mb + 4 * ((size_t)tb->y * b->in.atlas_width + tb->x);
    assert_true(x[3] == y[3]); /* validity */
    double worst = 0.0;
    for (int c = 0; c < 3; c++)
        worst = fmax(worst, fabs((double)x[c] - y[c]) / fmax(fmax(fabs(x[c]), fabs(y[c])), 1e-3 * bright));
    return worst;
}

/* The same bake on pages and on one page: the two rooms at 6,000 texels on pages of 64 texels and in
 * one atlas have the same texels, texel for texel the same surface at the same world place (only placed
 * elsewhere in the atlas), and each texel's AIM and IIM agree: a texel's gather does not depend on where
 * its chart lies, each chart's bilinear lookups staying inside its own texels. The AIM is the same to the
 * bit; the IIM within 1e-3 (measured 3.0e-4, 656 of 6,388 texels over 1e-5): the hemicube looks the AIM
 * up at a chart's UVs, which are other floats in another atlas, rounded otherwise. */
static void test_pages_bake_as_one_page(void **state)
{
    (void)state;
    lmgi_context *ctx = NULL;
    lmgi_error e;
    assert_int_equal(lmgi_context_create(NULL, &ctx, &e), LMGI_OK);
    baked one, paged;
    bake_on_pages(ctx, "scenes/two_rooms.glb", 6000, 0, &one);
    bake_on_pages(ctx, "scenes/two_rooms.glb", 6000, 64, &paged);
    print_message("two rooms at 6,000 texels: one page of %d x %d, or %d pages of %d x %d\n", one.in.atlas_width,
                  one.in.atlas_height, paged.in.pages, paged.in.page_width, paged.in.page_height);
    assert_int_equal(one.in.pages, 1);
    assert_true(paged.in.pages > 1);
    assert_int_equal(one.in.texels, paged.in.texels);
    float bright = 0.0f;
    for (size_t i = 0; i < 4 * (size_t)one.in.atlas_width * one.in.atlas_height; i++)
        bright = i % 4 != 3 && one.iim[i] > bright ? one.iim[i] : bright;
    double iim = 0.0, aim = 0.0;
    for (uint32_t i = 0; i < one.in.texels; i++) {
        lmgi_texel a, b;
        lmgi_get_texel(one.sc, i, &a);
        lmgi_get_texel(paged.sc, i, &b);
        assert_int_equal(a.surface, b.surface);
        assert_int_equal(a.triangle, b.triangle);
        assert_memory_equal(a.position, b.position, sizeof a.position);
        iim = fmax(iim, texel_difference(&one, &a, one.iim, &paged, &b, paged.iim, bright));
        aim = fmax(aim, texel_difference(&one, &a, one.aim, &paged, &b, paged.aim, bright));
    }
    print_message("per texel, pages against one page: IIM within %.2e, AIM within %.2e (relative)\n", iim, aim);
    assert_true(iim <= 1e-3);
    assert_true(aim <= 1e-3);
    baked *both[2] = {&one, &paged};
    for (int k = 0; k < 2; k++) {
        free(both[k]->iim);
        free(both[k]->aim);
        lmgi_updater_free(both[k]->u);
        lmgi_free(both[k]->sc);
    }
    lmgi_context_free(ctx);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_every_surface_a_wall),
        cmocka_unit_test(test_occlusion_room),
        cmocka_unit_test(test_truck_town),
        cmocka_unit_test(test_many_rooms),
        cmocka_unit_test(test_many_rooms_pages),
        cmocka_unit_test(test_pages_bake_as_one_page),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
