/* Hard cases (issue 15, docs/hard-cases.md): scenes built to break a lightmapper's numbers, each through
 * the public API as a user meets it, each asserting finite values and a stated bound. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "edit_room.h"
#include "support.h"

#define PI 3.14159265358979323846

/* A box's vertices and triangles (lmt_box). */
typedef struct {
    float v[72];
    uint32_t idx[36];
} box_mesh;

static void make_box(box_mesh *b, const float lo[3], const float hi[3], int inward) { lmt_box(lo, hi, inward, b->v, b->idx); }

/* The matrix x -> s x + t, column-major. */
static void scale_translate(float m[16], float s, const float t[3])
{
    memset(m, 0, 16 * sizeof *m);
    m[0] = m[5] = m[10] = s;
    m[12] = t[0], m[13] = t[1], m[14] = t[2];
    m[15] = 1.0f;
}

static lmgi_scene *load(const lmgi_scene_desc *d, float texel_size) { return lmt_load_desc(d, 1500, texel_size); }

/* ---------- the room with a lamp, and an updater on it ---------- */

/* The edit room (edit_room.h) lit by a 4 cd point lamp. */
static lmgi_scene *lamp_room(void)
{
    static const lmgi_light_desc lamp = {.name = "lamp", .type = LMGI_LIGHT_POINT, .intensity = 4.0f,
                                         .position = {-1.2f, 2.5f, -1.0f}};
    lmt_room_spec spec = {.lights = &lamp, .light_count = 1};
    return lmt_room(&spec);
}

static lmgi_updater *updater(lmgi_context *ctx, lmgi_scene *sc, const lmgi_updater_desc *d)
{
    lmgi_updater *u = NULL;
    lmgi_error e;
    if (lmgi_updater_create(ctx, sc, d, &u, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    return u;
}

/* A converged bake of sc (cheap settings: 100 photons a group, hemicube 16; defaults with `defaults`) and
 * its IIM (malloc'd RGBA, *n floats). */
static float *bake_with(lmgi_context *ctx, lmgi_scene *sc, int defaults, size_t *n)
{
    lmgi_updater_desc d;
    if (defaults)
        memset(&d, 0, sizeof d);
    else
        lmt_room_desc(&d);
    lmgi_updater *u = updater(ctx, sc, &d);
    lmgi_bake_report r;
    lmt_bake(u, &r);
    float *iim = lmt_iim(u, sc, n);
    lmgi_updater_free(u);
    return iim;
}

static float *baked_iim(lmgi_context *ctx, lmgi_scene *sc, size_t *n) { return bake_with(ctx, sc, 0, n); }

static int all_finite(const float *v, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (!isfinite(v[i]))
            return 0;
    return 1;
}

/* ---------- scale and distance from the origin ---------- */

/* The 4 x 3 x 4 room with a block, lit by a point light, every mesh and the light placed by x -> s x + t. */
static lmgi_scene *room_at(float s, const float t[3])
{
    static box_mesh room, block;
    make_box(&room, (float[3]){-2, 0, -2}, (float[3]){2, 3, 2}, 1);
    make_box(&block, (float[3]){-0.4f, 0, -0.4f}, (float[3]){0.4f, 1, 0.4f}, 0);
    lmgi_mesh_desc meshes[2] = {
        {.name = "room", .positions = room.v, .vertex_count = 24, .indices = room.idx, .triangle_count = 12},
        {.name = "block", .positions = block.v, .vertex_count = 24, .indices = block.idx, .triangle_count = 12,
         .material = 1}};
    scale_translate(meshes[0].transform, s, t);
    scale_translate(meshes[1].transform, s, t);
    lmgi_material_desc mats[2] = {{.name = "plaster", .base_color = {0.7f, 0.7f, 0.7f, 1.0f}},
                                  {.name = "red", .base_color = {0.8f, 0.2f, 0.1f, 1.0f}}};
    /* intensity s^2: irradiance at the scaled distances stays the same */
    lmgi_light_desc lamp = {.name = "lamp", .type = LMGI_LIGHT_POINT, .intensity = 4.0f * s * s,
                            .position = {-1.2f * s + t[0], 2.5f * s + t[1], -1.0f * s + t[2]}};
    lmgi_scene_desc d = {.name = "scaled room", .meshes = meshes, .mesh_count = 2, .materials = mats,
                         .material_count = 2, .lights = &lamp, .light_count = 1};
    return load(&d, 0.0f);
}

/* The same room at scales 1e-3, 1 and 1e4, and at scale 1 moved 1e5 from the origin, with the light's
 * intensity scaled by s^2: the same irradiance in every texel, within 1% relative L1 of scale 1. What can
 * break: ray offsets and epsilons tied to absolute units, float precision far from the origin. */
static void test_scale_and_offset(void **state)
{
    (void)state;
    lmgi_context *ctx = lmt_context();
    const float origin[3] = {0, 0, 0}, far[3] = {1e5f, 0, 0};
    lmgi_scene *base = room_at(1.0f, origin);
    size_t n;
    float *want = baked_iim(ctx, base, &n);
    assert_true(all_finite(want, n));
    const struct {
        float s;
        const float *t;
        const char *what;
    } cases[3] = {{1e-3f, origin, "scale 1e-3"}, {1e4f, origin, "scale 1e4"}, {1.0f, far, "1e5 from the origin"}};
    for (int c = 0; c < 3; c++) {
        lmgi_scene *sc = room_at(cases[c].s, cases[c].t);
        size_t m;
        float *got = baked_iim(ctx, sc, &m);
        assert_int_equal(m, n);
        assert_true(all_finite(got, m));
        double l1 = lmt_relative_l1(got, want, n);
        print_message("%s: IIM %.4f relative L1 from scale 1 at the origin\n", cases[c].what, l1);
        assert_true(l1 < 0.01);
        free(got);
        lmgi_free(sc);
    }
    free(want);
    lmgi_free(base);
    lmgi_context_free(ctx);
}

/* ---------- lights nobody should have placed ---------- */

/* Only the room's lightmap: the largest texel of the IIM of the room node and of everything else. */
static void maxima(const lmgi_scene *sc, const float *iim, size_t n, double *room_max, double *all_max)
{
    (void)sc;
    *room_max = lmt_node_mean(sc, iim, "room");
    *all_max = 0.0;
    for (size_t i = 0; i < n; i += 4)
        *all_max = fmax(*all_max, (double)iim[i] + iim[i + 1] + iim[i + 2]);
}

/* A light of zero power, and a strong one sealed inside the closed block: nothing lights the room (every
 * texel exactly 0, none NaN). Then a light 1e-6 above the floor: finite everywhere, and the room lit. */
static void test_dark_sealed_and_touching_lights(void **state)
{
    (void)state;
    lmgi_context *ctx = lmt_context();
    const lmgi_light_desc sealed[2] = {
        {.name = "off", .type = LMGI_LIGHT_POINT, .intensity = 0.0f, .position = {1, 2, 1}},
        {.name = "sealed", .type = LMGI_LIGHT_POINT, .intensity = 1000.0f, .position = {0, 0.5f, 0}}};
    lmt_room_spec spec = {.lights = sealed, .light_count = 2};
    lmgi_scene *sc = lmt_room(&spec);
    size_t n;
    float *iim = baked_iim(ctx, sc, &n);
    double room, all;
    maxima(sc, iim, n, &room, &all);
    print_message("zero-power and sealed lights: largest texel %g, room mean %g\n", all, room);
    assert_true(all_finite(iim, n));
    assert_true(all == 0.0);
    free(iim);
    lmgi_free(sc);

    const lmgi_light_desc touching = {.name = "touching", .type = LMGI_LIGHT_POINT, .intensity = 4.0f,
                                      .position = {1.0f, 1e-6f, 1.0f}};
    spec = (lmt_room_spec){.lights = &touching, .light_count = 1};
    sc = lmt_room(&spec);
    iim = baked_iim(ctx, sc, &n);
    maxima(sc, iim, n, &room, &all);
    print_message("a light 1e-6 above the floor: largest texel %g, room mean %g\n", all, room);
    assert_true(all_finite(iim, n));
    assert_true(room > 0.0 && isfinite(all));
    free(iim);
    lmgi_free(sc);
    lmgi_context_free(ctx);
}

/* ---------- many bounces ---------- */

/* The white furnace: a closed room whose every wall emits Le = 1 and reflects rho = 0.99 (diffuse). Every
 * point sees radiance L = Le + rho L, so L = Le / (1 - rho) = 100 everywhere, and every texel's irradiance
 * is pi L = 314: within 3%. A photon carries light through a hundred bounces on average here; a path cut
 * at a fixed depth loses the rest (32 vertices kept 27% of it). */
static void test_furnace(void **state)
{
    (void)state;
    const float rho = 0.99f;
    static box_mesh room;
    make_box(&room, (float[3]){-2, 0, -2}, (float[3]){2, 3, 2}, 1);
    lmgi_mesh_desc mesh = {.name = "room", .positions = room.v, .vertex_count = 24, .indices = room.idx,
                           .triangle_count = 12};
    lmgi_material_desc mat = {.name = "furnace", .base_color = {rho, rho, rho, 1.0f}, .emissive = {1, 1, 1}};
    lmgi_scene_desc d = {.name = "furnace", .meshes = &mesh, .mesh_count = 1, .materials = &mat, .material_count = 1};
    lmgi_scene *sc = load(&d, 0.0f);
    lmgi_context *ctx = lmt_context();
    size_t n;
    float *iim = bake_with(ctx, sc, 1, &n);
    assert_true(all_finite(iim, n));
    double want = PI / (1.0 - rho), lo = INFINITY, hi = 0.0, sum = 0.0;
    int count = 0;
    for (size_t i = 0; i < n; i += 4) {
        if (iim[i + 3] <= 0.0f) /* not a valid texel */
            continue;
        double e = iim[i + 1];
        lo = fmin(lo, e), hi = fmax(hi, e), sum += e;
        count++;
    }
    print_message("furnace, rho %.2f: %d texels, irradiance %.1f .. %.1f, mean %.1f (want %.1f)\n", (double)rho,
                  count, lo, hi, sum / count, want);
    assert_true(count > 100);
    assert_true(fabs(sum / count / want - 1.0) < 0.03);
    assert_true(lo > 0.9 * want && hi < 1.1 * want);
    free(iim);
    lmgi_free(sc);
    lmgi_context_free(ctx);
}

/* ---------- a light a million times dimmer than another ---------- */

/* The closed room with its block and a lamp inside, and outside it a ground plane under a sun 10^6 times
 * brighter (4e6 lux against the lamp's 4 cd at about 2 m): no sunlight gets in (the room's walls are
 * opaque from outside). Inside, where the lamp is all there is, the lightmap must be the one the room gets
 * without the sun: within 5% per node. Photons are shared out by power, so the lamp gets what is left. */
static lmgi_scene *room_and_sun(float sun)
{
    static box_mesh room, block;
    static const float ground_v[12] = {-5, -0.01f, -5, -5, -0.01f, 5, 5, -0.01f, 5, 5, -0.01f, -5};
    static const uint32_t ground_i[6] = {0, 1, 2, 0, 2, 3};
    make_box(&room, (float[3]){-2, 0, -2}, (float[3]){2, 3, 2}, 1);
    make_box(&block, (float[3]){-0.4f, 0, -0.4f}, (float[3]){0.4f, 1, 0.4f}, 0);
    lmgi_mesh_desc meshes[3] = {
        {.name = "room", .positions = room.v, .vertex_count = 24, .indices = room.idx, .triangle_count = 12},
        {.name = "block", .positions = block.v, .vertex_count = 24, .indices = block.idx, .triangle_count = 12,
         .material = 1},
        {.name = "ground", .positions = ground_v, .vertex_count = 4, .indices = ground_i, .triangle_count = 2}};
    lmgi_material_desc mats[2] = {{.name = "plaster", .base_color = {0.7f, 0.7f, 0.7f, 1.0f}},
                                  {.name = "red", .base_color = {0.8f, 0.2f, 0.1f, 1.0f}}};
    lmgi_light_desc lights[2] = {
        {.name = "lamp", .type = LMGI_LIGHT_POINT, .intensity = 4.0f, .position = {-1.2f, 2.5f, -1.0f}},
        {.name = "sun", .type = LMGI_LIGHT_DIRECTIONAL, .intensity = sun, .direction = {0.3f, -1.0f, 0.2f}}};
    lmgi_scene_desc d = {.name = "room under the sun", .meshes = meshes, .mesh_count = 3, .materials = mats,
                         .material_count = 2, .lights = lights, .light_count = sun > 0.0f ? 2 : 1};
    return load(&d, 0.15f); /* the block's faces get 200 texels beside the ground's 4,400 */
}

static void test_dim_lamp_beside_the_sun(void **state)
{
    (void)state;
    lmgi_context *ctx = lmt_context();
    lmgi_scene *alone = room_and_sun(0.0f), *both = room_and_sun(4e6f);
    size_t n, m;
    float *want = bake_with(ctx, alone, 1, &n), *got = bake_with(ctx, both, 1, &m);
    assert_int_equal(n, m);
    assert_true(all_finite(got, m));
    const char *nodes[2] = {"room", "block"};
    for (int k = 0; k < 2; k++) {
        double w = lmt_node_mean(alone, want, nodes[k]), g = lmt_node_mean(both, got, nodes[k]);
        print_message("%s: %.5f with the sun outside, %.5f without (%+.2f%%)\n", nodes[k], g, w, 100.0 * (g / w - 1.0));
        assert_true(fabs(g / w - 1.0) < 0.05);
    }
    free(want), free(got);
    lmgi_free(alone), lmgi_free(both);
    lmgi_context_free(ctx);
}

/* ---------- N larger than any surface's photon count ---------- */

/* photons_per_estimate at its largest (100,000) in the room, whose surfaces hold a few thousand hits each:
 * every estimate takes all of a surface's hits, so each AIM is its surface's mean, the same energy
 * spread flat. Finite everywhere, and the room's and the block's lightmaps within 10% of N = 128's. */
static void test_n_beyond_the_hits(void **state)
{
    (void)state;
    lmgi_context *ctx = lmt_context();
    lmgi_scene *sc = lamp_room();
    size_t n;
    float *usual = baked_iim(ctx, sc, &n);
    lmgi_updater_desc d;
    lmt_room_desc(&d);
    d.photons_per_estimate = 100000;
    lmgi_updater *u = updater(ctx, sc, &d);
    lmgi_bake_report r;
    lmt_bake(u, &r);
    float *all = lmt_iim(u, sc, &n);
    assert_true(all_finite(all, n));
    const char *nodes[2] = {"room", "block"};
    for (int k = 0; k < 2; k++) {
        double a = lmt_node_mean(sc, all, nodes[k]), b = lmt_node_mean(sc, usual, nodes[k]);
        print_message("%s: N = 100000 %.4f, N = 128 %.4f (%+.1f%%)\n", nodes[k], a, b, 100.0 * (a / b - 1.0));
        assert_true(fabs(a / b - 1.0) < 0.1);
    }
    free(all), free(usual);
    lmgi_updater_free(u);
    lmgi_free(sc);
    lmgi_context_free(ctx);
}

/* ---------- an edit every frame ---------- */

/* The room's lamp switched between intensity 4 and 8 at every update, 1,000 updates, in_order (the photon
 * work before the gather, so each update sees its own edit): every displayed texel stays finite and
 * within the envelope of the two converged lightmaps (between the room baked at 4 and at 8, 1% slack for
 * the photon noise of partly re-traced groups), whatever the blends in flight when the next edit lands. */
static void test_blend_under_constant_edits(void **state)
{
    (void)state;
    lmgi_context *ctx = lmt_context();
    lmgi_scene *sc = lamp_room();
    size_t n;
    float *lo = baked_iim(ctx, sc, &n);
    lmgi_light l;
    lmgi_error e;
    assert_int_equal(lmgi_get_light(sc, 0, &l, &e), LMGI_OK);
    l.intensity = 8.0f;
    assert_int_equal(lmgi_set_light(sc, 0, &l, &e), LMGI_OK);
    float *hi = baked_iim(ctx, sc, &n);
    l.intensity = 4.0f;
    assert_int_equal(lmgi_set_light(sc, 0, &l, &e), LMGI_OK);

    lmgi_updater_desc d;
    lmt_room_desc(&d);
    d.in_order = 1;
    lmgi_updater *u = updater(ctx, sc, &d);
    float *now = malloc(n * sizeof *now);
    assert_non_null(now);
    double worst = 0.0, moved = 0.0; /* how far any texel went from the lamp at 4 towards 8 */
    int updates = 1000;
    for (int f = 0; f < updates; f++) {
        l.intensity = f % 2 ? 4.0f : 8.0f;
        assert_int_equal(lmgi_set_light(sc, 0, &l, &e), LMGI_OK);
        lmgi_update_stats st;
        assert_int_equal(lmgi_update(u, 0.0f, 0.0f, &st, &e), LMGI_OK);
        assert_int_equal(lmgi_get_lightmap(u, LMGI_LIGHTMAP_IIM, now, n, &e), LMGI_OK);
        for (size_t i = 0; i < n; i += 4) {
            if (lo[i + 3] < 0.5f)
                continue;
            for (int c = 0; c < 3; c++) {
                float v = now[i + c], a = fminf(lo[i + c], hi[i + c]), b = fmaxf(lo[i + c], hi[i + c]);
                assert_true(isfinite(v));
                double out = v < a ? a - v : v > b ? v - b : 0.0;
                worst = fmax(worst, out / fmax(b, 1e-3));
                moved = fmax(moved, (v - lo[i + c]) / fmax(b - a, 1e-3));
            }
        }
    }
    print_message("%d updates, an edit each: worst texel outside [lamp at 4, lamp at 8] by %.4f of its value; "
                  "texels moved up to %.2f of the way\n", updates, worst, moved);
    assert_true(worst < 0.01);
    assert_true(moved > 0.2); /* the edits did reach the lightmap */
    free(now), free(lo), free(hi);
    lmgi_updater_free(u);
    lmgi_free(sc);
    lmgi_context_free(ctx);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_scale_and_offset),
        cmocka_unit_test(test_dark_sealed_and_touching_lights),
        cmocka_unit_test(test_furnace),
        cmocka_unit_test(test_dim_lamp_beside_the_sun),
        cmocka_unit_test(test_n_beyond_the_hits),
        cmocka_unit_test(test_blend_under_constant_edits),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
