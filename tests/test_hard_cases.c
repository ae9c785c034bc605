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

static int all_finite(const float *v, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (!isfinite(v[i]))
            return 0;
    return 1;
}

/* An updater on sc (cheap settings: 100 photons a group, hemicube 16; the defaults with `defaults`),
 * baked to convergence, and its IIM (malloc'd RGBA, *n floats), every value of it finite. */
static lmgi_updater *baked(lmgi_context *ctx, lmgi_scene *sc, int defaults, float **iim, size_t *n)
{
    lmgi_updater_desc d;
    if (defaults)
        memset(&d, 0, sizeof d);
    else
        lmt_room_desc(&d);
    lmgi_updater *u = updater(ctx, sc, &d);
    lmgi_bake_report r;
    lmt_bake(u, &r);
    *iim = lmt_iim(u, sc, n);
    assert_true(all_finite(*iim, *n));
    return u;
}

static float *bake_with(lmgi_context *ctx, lmgi_scene *sc, int defaults, size_t *n)
{
    float *iim;
    lmgi_updater_free(baked(ctx, sc, defaults, &iim, n));
    return iim;
}

static float *baked_iim(lmgi_context *ctx, lmgi_scene *sc, size_t *n) { return bake_with(ctx, sc, 0, n); }

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
    d.aim.nearest = 100000;
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

/* ---------- thin walls and inner corners ---------- */

static double frame_mean(const float *rgb, int pixels)
{
    double sum = 0.0;
    for (int i = 0; i < 3 * pixels; i++) {
        assert_true(isfinite(rgb[i]));
        sum += rgb[i];
    }
    return sum / pixels;
}

/* Two closed rooms side by side, each 4 x 3 x 4 seen from inside; the wall between them is the lit room's
 * face at x = 0 and the dark room's at x = 1e-4, back to back. A lamp 0.1 from that wall and 0.1 below the
 * ceiling, in the lit room's inner corner. No light may reach the dark room: its lightmap and its picture
 * under 1% of the lit side's. What can break: photon and shadow-ray offsets or a shadow-map bias wider than
 * the wall, and hemicubes whose near plane reaches through it from texels in the corners beside it. */
static void test_thin_wall_and_corners(void **state)
{
    (void)state;
    static box_mesh lit, dark;
    const float gap = 1e-4f;
    make_box(&lit, (float[3]){-4, 0, -2}, (float[3]){0, 3, 2}, 1);
    make_box(&dark, (float[3]){gap, 0, -2}, (float[3]){4 + gap, 3, 2}, 1);
    lmgi_mesh_desc meshes[2] = {
        {.name = "lit", .positions = lit.v, .vertex_count = 24, .indices = lit.idx, .triangle_count = 12},
        {.name = "dark", .positions = dark.v, .vertex_count = 24, .indices = dark.idx, .triangle_count = 12}};
    lmgi_material_desc mat = {.name = "plaster", .base_color = {0.7f, 0.7f, 0.7f, 1.0f}};
    lmgi_light_desc lamp = {.name = "lamp", .type = LMGI_LIGHT_POINT, .intensity = 4.0f,
                            .position = {-0.1f, 2.9f, 0.0f}};
    lmgi_scene_desc d = {.name = "thin wall", .meshes = meshes, .mesh_count = 2, .materials = &mat,
                         .material_count = 1, .lights = &lamp, .light_count = 1};
    lmgi_scene *sc = load(&d, 0.0f);
    lmgi_context *ctx = lmt_context();
    size_t n;
    float *iim;
    lmgi_updater *u = baked(ctx, sc, 1, &iim, &n);
    double lit_mean, lit_top, dark_mean, dark_top;
    lmt_triangles_stats(sc, iim, 0, 12, &lit_mean, &lit_top);
    lmt_triangles_stats(sc, iim, 12, 12, &dark_mean, &dark_top);
    print_message("thin wall (1e-4): lit room IIM mean %.4g (largest %.4g), dark room mean %.3g, largest %.3g "
                  "(%.2g%% of the lit mean)\n", lit_mean, lit_top, dark_mean, dark_top, 100.0 * dark_top / lit_mean);
    assert_true(lit_mean > 0.0);
    assert_true(dark_top < 0.01 * lit_mean);

    /* the pictures: from each room's far end at the wall between them, its corners in view */
    enum { SIDE = 48 };
    float *rgb = malloc(3 * SIDE * SIDE * sizeof *rgb);
    assert_non_null(rgb);
    lmgi_camera cam;
    lmgi_error e;
    lmt_look_at((float[3]){-3.8f, 1.5f, 1.8f}, (float[3]){0, 1.5f, -0.5f}, 1.6f, &cam);
    assert_int_equal(lmgi_render(u, &cam, SIDE, SIDE, rgb, &e), LMGI_OK);
    double lit_px = frame_mean(rgb, SIDE * SIDE);
    lmt_look_at((float[3]){3.8f, 1.5f, 1.8f}, (float[3]){0, 1.5f, -0.5f}, 1.6f, &cam);
    assert_int_equal(lmgi_render(u, &cam, SIDE, SIDE, rgb, &e), LMGI_OK);
    double dark_px = frame_mean(rgb, SIDE * SIDE), dark_px_top = 0.0;
    for (int i = 0; i < 3 * SIDE * SIDE; i++)
        dark_px_top = fmax(dark_px_top, rgb[i]);
    print_message("thin wall: lit room's picture mean %.4g, dark room's %.3g (largest pixel %.3g)\n", lit_px, dark_px,
                  dark_px_top);
    assert_true(lit_px > 0.0);
    assert_true(dark_px < 0.01 * lit_px && dark_px_top < 0.01 * lit_px);
    free(rgb), free(iim);
    lmgi_updater_free(u);
    lmgi_free(sc);
    lmgi_context_free(ctx);
}

/* ---------- grazing light ---------- */

/* A 4 x 4 grey floor and a point light 20 from its centre, 0.1 degrees above its horizon: every point of
 * the floor is lit at 89.9 degrees from its normal, E = I h / d^3 with h the light's height. The picture
 * against the path-traced reference (direct light only: nothing else to bounce off) within 2% over the
 * floor and 5% relative RMSE. What can break: shadow acne, where a surface lit this flat shadows itself
 * unless the shadow lookup's bias grows with the angle, and the photons that hardly ever reach it. */
static void test_grazing_light(void **state)
{
    (void)state;
    static const float floor_v[12] = {-2, 0, 2, 2, 0, 2, 2, 0, -2, -2, 0, -2};
    static const uint32_t floor_i[6] = {0, 1, 2, 0, 2, 3};
    lmgi_mesh_desc mesh = {.name = "floor", .positions = floor_v, .vertex_count = 4, .indices = floor_i,
                           .triangle_count = 2};
    lmgi_material_desc mat = {.name = "grey", .base_color = {0.5f, 0.5f, 0.5f, 1.0f}};
    const double elevation = 0.1 * PI / 180.0, dist = 20.0;
    lmgi_light_desc light = {.name = "grazing", .type = LMGI_LIGHT_POINT, .intensity = 1e5f,
                             .position = {0.0f, (float)(dist * sin(elevation)), (float)(-dist * cos(elevation))}};
    lmgi_scene_desc d = {.name = "grazing", .meshes = &mesh, .mesh_count = 1, .materials = &mat, .material_count = 1,
                         .lights = &light, .light_count = 1};
    lmgi_scene *sc = load(&d, 0.0f);
    lmgi_context *ctx = lmt_context();
    size_t n;
    float *iim;
    lmgi_updater *u = baked(ctx, sc, 1, &iim, &n);
    lmgi_error e;
    float *aim = malloc(n * sizeof *aim);
    assert_non_null(aim);
    assert_int_equal(lmgi_get_lightmap(u, LMGI_LIGHTMAP_AIM, aim, n, &e), LMGI_OK);
    assert_true(all_finite(aim, n));

    lmgi_camera cam;
    lmt_look_at((float[3]){0, 3, 3}, (float[3]){0, 0, 0}, 1.2f, &cam);
    lmgi_reference_desc rd = {.target_error = 0.02f, .cache_dir = lmt_tmpdir()};
    lmgi_check_result c;
    assert_int_equal(lmgi_check_updater(u, &cam, 64, 64, &rd, &c, &e), LMGI_OK);
    print_message("grazing light (0.1 degrees): frame / reference %.4f %.4f %.4f over %u pixels, relative RMSE "
                  "%.4f\n", c.ratio[0], c.ratio[1], c.ratio[2], c.pixels, c.rel_rmse);
    assert_true(c.pixels > 1000);
    for (int k = 0; k < 3; k++)
        assert_true(fabs(c.ratio[k] - 1.0) < 0.02);
    assert_true(c.rel_rmse < 0.05);
    lmgi_check_free(&c);
    free(aim), free(iim);
    lmgi_updater_free(u);
    lmgi_free(sc);
    lmgi_context_free(ctx);
}

/* ---------- slivers, zero-area triangles and a surface too small for a texel ---------- */

/* The room with its lamp and one more mesh, `extra` (its triangles after the room's 12), plaster. */
/* The plaster room lit by a lamp with one more mesh, green (meshes: room, extra; *d points at them). */
static void room_desc(const lmgi_mesh_desc *extra, lmgi_mesh_desc meshes[2], lmgi_scene_desc *d)
{
    static box_mesh room;
    static const lmgi_material_desc mats[2] = {{.name = "plaster", .base_color = {0.7f, 0.7f, 0.7f, 1.0f}},
                                               {.name = "green", .base_color = {0.2f, 0.7f, 0.3f, 1.0f}}};
    static const lmgi_light_desc lamp = {.name = "lamp", .type = LMGI_LIGHT_POINT, .intensity = 4.0f,
                                         .position = {-1.2f, 2.5f, -1.0f}};
    make_box(&room, (float[3]){-2, 0, -2}, (float[3]){2, 3, 2}, 1);
    meshes[0] = (lmgi_mesh_desc){.name = "room", .positions = room.v, .vertex_count = 24, .indices = room.idx,
                                 .triangle_count = 12};
    meshes[1] = *extra;
    meshes[1].material = 1;
    *d = (lmgi_scene_desc){.name = "room with one more mesh", .meshes = meshes, .mesh_count = 2, .materials = mats,
                           .material_count = 2, .lights = &lamp, .light_count = 1};
}

static lmgi_scene *room_with(const lmgi_mesh_desc *extra)
{
    lmgi_mesh_desc meshes[2];
    lmgi_scene_desc d;
    room_desc(extra, meshes, &d);
    return load(&d, 0.0f);
}

/* A 2 x 2 carpet 1 cm above the room's floor, as two triangles, and as the same square with one of them
 * cut at a point 1.4e-6 off its long edge (a sliver of aspect 2 x 10^6 along the diagonal) plus two
 * zero-area triangles (a repeated vertex; three collinear points). The lightmaps must be finite and the
 * carpet's and the room's within 1% of the clean carpet's. What can break: normals, chart unwrapping and
 * texel clipping divide by a triangle's area; photons hit the sliver. */
static void test_slivers_and_zero_area(void **state)
{
    (void)state;
    const float y = 0.01f, dlt = 1e-6f;
    const float v[18] = {-1, y, -1, 1, y, -1, 1, y, 1, -1, y, 1, -dlt, y, dlt, 0, y, 0};
    static const uint32_t clean_i[6] = {0, 3, 2, 0, 2, 1};
    /* (0 3 2) cut at vertex 4 into (0 3 4), (3 2 4) and the sliver (2 0 4); (0 1 1) and (0 5 2) have no area */
    static const uint32_t cut_i[18] = {0, 2, 1, 0, 3, 4, 3, 2, 4, 2, 0, 4, 0, 1, 1, 0, 5, 2};
    lmgi_mesh_desc clean = {.name = "carpet", .positions = v, .vertex_count = 6, .indices = clean_i,
                            .triangle_count = 2};
    lmgi_mesh_desc cut = clean;
    cut.indices = cut_i, cut.triangle_count = 6;
    lmgi_context *ctx = lmt_context();
    lmgi_scene *a = room_with(&clean), *b = room_with(&cut);
    size_t n, m;
    float *want = bake_with(ctx, a, 1, &n), *got = bake_with(ctx, b, 1, &m);
    assert_true(all_finite(got, m));
    double w_room, w_carpet, g_room, g_carpet, top;
    lmt_triangles_stats(a, want, 0, 12, &w_room, &top);
    lmt_triangles_stats(a, want, 12, 2, &w_carpet, &top);
    lmt_triangles_stats(b, got, 0, 12, &g_room, &top);
    lmt_triangles_stats(b, got, 12, 6, &g_carpet, &top);
    print_message("sliver and zero-area triangles: carpet %.4f (clean %.4f, %+.2f%%), room %.4f (%+.2f%%)\n", g_carpet,
                  w_carpet, 100.0 * (g_carpet / w_carpet - 1.0), g_room, 100.0 * (g_room / w_room - 1.0));
    assert_true(fabs(g_carpet / w_carpet - 1.0) < 0.01);
    assert_true(fabs(g_room / w_room - 1.0) < 0.01);
    free(want), free(got);
    lmgi_free(a), lmgi_free(b);
    lmgi_context_free(ctx);
}

/* Baked with the defaults, its extra node (node 1) moved 1 to -x and 10 updates run, drawn from a corner:
 * every value finite, the picture lit. Returns the room's IIM mean before the move. */
static double bake_move_and_draw(lmgi_context *ctx, lmgi_scene *sc)
{
    size_t n;
    float *iim;
    lmgi_updater *u = baked(ctx, sc, 1, &iim, &n);
    double room, top;
    lmt_triangles_stats(sc, iim, 0, 12, &room, &top);
    free(iim);
    lmgi_error e;
    float moved[16];
    scale_translate(moved, 1.0f, (float[3]){-1.0f, 0.0f, 0.0f});
    assert_int_equal(lmgi_set_node_transform(sc, 1, moved, &e), LMGI_OK);
    for (int f = 0; f < 10; f++)
        assert_int_equal(lmgi_update(u, 0.0f, 0.0f, NULL, &e), LMGI_OK);
    iim = lmt_iim(u, sc, &n);
    assert_true(all_finite(iim, n));
    enum { SIDE = 48 };
    float rgb[3 * SIDE * SIDE];
    lmgi_camera cam;
    lmt_look_at((float[3]){1.9f, 2.0f, 1.9f}, (float[3]){-0.5f, 1.5f, 0.5f}, 1.6f, &cam);
    assert_int_equal(lmgi_render(u, &cam, SIDE, SIDE, rgb, &e), LMGI_OK);
    assert_true(frame_mean(rgb, SIDE * SIDE) > 0.0);
    free(iim);
    lmgi_updater_free(u);
    return room;
}

/* Two nodes nobody meant to light: a closed box 1 mm a side floating in the room (each face far smaller
 * than a texel, about 0.25 m here), and the same box with all its corners in one point (12 zero-area
 * triangles: a node with no surface and no texel at all). Loading, baking, an edit that moves it,
 * updates and a picture must all work, every value finite, and the room's lightmap the same within 1%
 * either way. What can break: per-surface means, kd-trees and schedules over surfaces with almost no
 * texels or photons, and a node with none. */
static void test_surface_smaller_than_a_texel(void **state)
{
    (void)state;
    static box_mesh speck, point;
    make_box(&speck, (float[3]){0.5f, 1.5f, 0.5f}, (float[3]){0.501f, 1.501f, 0.501f}, 0);
    make_box(&point, (float[3]){0.5f, 1.5f, 0.5f}, (float[3]){0.5f, 1.5f, 0.5f}, 0);
    lmgi_mesh_desc tiny = {.name = "speck", .positions = speck.v, .vertex_count = 24, .indices = speck.idx,
                           .triangle_count = 12, .dynamic = 1};
    lmgi_mesh_desc none = tiny;
    none.positions = point.v;
    lmgi_context *ctx = lmt_context();
    lmgi_scene *a = room_with(&none), *b = room_with(&tiny);
    int texels[2] = {0, 0};
    const lmgi_scene *both[2] = {a, b};
    for (int k = 0; k < 2; k++) {
        lmgi_info in;
        lmgi_get_info(both[k], &in);
        for (uint32_t i = 0; i < in.texels; i++) {
            lmgi_texel t;
            lmgi_get_texel(both[k], i, &t);
            texels[k] += t.triangle >= 12;
        }
    }
    double w_room = bake_move_and_draw(ctx, a), g_room = bake_move_and_draw(ctx, b);
    print_message("a 1 mm box: %d texels on its %d surfaces; its zero-area twin: no surface (%d, the room's "
                  "faces), %d texels; room %.4f and %.4f (%+.3f%%)\n", texels[1],
                  lmgi_surface_count(b) - lmgi_surface_count(a), lmgi_surface_count(a), texels[0], g_room, w_room,
                  100.0 * (g_room / w_room - 1.0));
    assert_int_equal(texels[0], 0);
    assert_int_equal(lmgi_surface_count(a), 6);
    assert_int_equal(lmgi_surface_count(b), 12);
    assert_true(fabs(g_room / w_room - 1.0) < 0.01);
    lmgi_free(a), lmgi_free(b);
    lmgi_context_free(ctx);
}

/* ---------- shading normals that bend across a face ---------- */

/* A hexagonal column, radius 0.5 and 2 high, its side faces with vertex normals pointing straight out
 * from its axis: they bend 60 degrees across each face. */
enum { COLUMN_SIDES = 6 };
typedef struct {
    float v[3 * 4 * COLUMN_SIDES], n[3 * 4 * COLUMN_SIDES];
    uint32_t idx[6 * COLUMN_SIDES];
} column_mesh;

static void make_column(column_mesh *c)
{
    for (int k = 0; k < COLUMN_SIDES; k++) {
        double a0 = 2.0 * PI * k / COLUMN_SIDES, a1 = 2.0 * PI * (k + 1) / COLUMN_SIDES;
        const double ang[4] = {a0, a1, a1, a0}, y[4] = {0, 0, 2, 2};
        for (int j = 0; j < 4; j++) {
            float *p = c->v + 3 * (4 * k + j), *n = c->n + 3 * (4 * k + j);
            p[0] = (float)(0.5 * cos(ang[j])), p[1] = (float)y[j], p[2] = (float)(-0.5 * sin(ang[j]));
            n[0] = (float)cos(ang[j]), n[1] = 0.0f, n[2] = (float)-sin(ang[j]);
        }
        const uint32_t q[6] = {0, 1, 2, 0, 2, 3};
        for (int j = 0; j < 6; j++)
            c->idx[6 * k + j] = (uint32_t)(4 * k) + q[j];
    }
}

/* Issue 33, item 5: a green column whose shading normals bend 60 degrees across each face, in the lamp-lit
 * room (room_with), against the reference at 40 x 40 and a target error of 0.03: each face of the column
 * seen by 50 pixels or more, and the frame, within 2% per channel. The faces' normals turn 24 degrees a
 * texel at the room's budget (1,500), so the column's texels are 0.55 x as wide (lmgi_options.bend_deg,
 * docs/charts.md "Bending normals"; 1,424 texels in all, the room's coarser): measured, the face beside
 * the lamp reads 0.991 0.989 0.991, the other 1.000 0.995 0.999. With one texel size (bend_deg LMGI_OFF,
 * 1,678 texels) the face read 0.979 0.977 0.978, each edge pixel's normal bent past its outer texels'
 * (flat normals: 0.991); since each texel's normal is the mean over what it covers (2026-12-03), 0.984
 * 0.981 0.983. The second half asserts that the finer texels still buy more than half a point. */
/* The column in the room, baked at the defaults with bend_deg as given, against the reference: the frame
 * within 2% per channel; returns the worst channel's |frame / reference - 1| over the column's faces seen
 * by 50 pixels or more (at least two of them). */
static double column_worst_face(float bend_deg)
{
    static column_mesh col;
    make_column(&col);
    const lmgi_mesh_desc column = {.name = "column", .positions = col.v, .normals = col.n,
                                   .vertex_count = 4 * COLUMN_SIDES, .indices = col.idx,
                                   .triangle_count = 2 * COLUMN_SIDES};
    lmgi_mesh_desc meshes[2];
    lmgi_scene_desc d;
    room_desc(&column, meshes, &d);
    lmgi_options o;
    lmgi_options_init(&o);
    o.target_texels = 1500;
    o.bend_deg = bend_deg;
    lmgi_scene *sc = lmt_load_desc_with(&d, &o);
    lmgi_context *ctx = lmt_context();
    size_t n;
    float *iim;
    lmgi_updater *u = baked(ctx, sc, 1, &iim, &n);
    lmgi_camera cam;
    lmt_look_at((float[3]){0.3f, 1.2f, 1.9f}, (float[3]){0, 1.0f, 0}, 1.0f, &cam);
    lmgi_reference_desc rd = {.target_error = 0.03f, .no_cache = 1};
    lmgi_check_result c;
    lmgi_error e;
    assert_int_equal(lmgi_check_updater(u, &cam, 40, 40, &rd, &c, &e), LMGI_OK);
    print_message("column with bending normals, bend_deg %g, %u texels: frame / reference %.4f %.4f %.4f over %u "
                  "pixels\n", (double)bend_deg, lmgi_texel_count(sc), c.ratio[0], c.ratio[1], c.ratio[2], c.pixels);
    int faces = 0;
    double worst = 0.0;
    for (int k = 0; k < c.surface_count; k++) {
        const lmgi_check_surface *f = &c.surfaces[k];
        if (f->node != 1 || f->pixels < 50)
            continue;
        print_message("  column face (surface %d): %u pixels, %.4f %.4f %.4f\n", k, f->pixels, f->ratio[0], f->ratio[1],
                      f->ratio[2]);
        for (int ch = 0; ch < 3; ch++)
            worst = fmax(worst, fabs(f->ratio[ch] - 1.0));
        faces++;
    }
    assert_true(faces >= 2);
    for (int ch = 0; ch < 3; ch++)
        assert_true(fabs(c.ratio[ch] - 1.0) < 0.02);
    lmgi_check_free(&c);
    free(iim);
    lmgi_updater_free(u);
    lmgi_free(sc);
    lmgi_context_free(ctx);
    return worst;
}

static void test_bending_shading_normals(void **state)
{
    (void)state;
    double finer = column_worst_face(0.0f), one_size = column_worst_face((float)LMGI_OFF);
    print_message("column's worst face: %.4f off with finer texels, %.4f with one texel size\n", finer, one_size);
    assert_true(finer < 0.02);
    assert_true(one_size > finer + 0.005);
}

/* ---------- photons on one vertex, along edges and seams ---------- */

/* A 2 x 2 plate 1 cm above the floor under a spot straight down from 2.9 m with a 0.02 rad cone: its
 * photons land within 6 cm of the plate's centre, a quarter of a texel, so to every AIM estimate there
 * they are one point (the smallest radius). The plate is one quad, or four quadrant nodes (four surfaces,
 * their seams along the axes) of two triangles each, all eight meeting at the centre, where the spot's
 * axis hits: the photons lie on that vertex, its edges and the seams. Every value must be finite, the
 * plate's photon energy (its AIM) within 5% of the one quad's and the light the room gets back from the
 * plate (its IIM) within 8%. Each quadrant's estimate sums the hits of the quadrants that continue it
 * (aim.h, seams); with its own only it lost 43% of the energy, and the room 9.4% (docs/hard-cases.md).
 * What is left in the room is the gather's: each quadrant is its own chart, whose bilinear lookups at
 * the centre do not blend with the others'. */
static lmgi_scene *plate_under_spot(int quadrants)
{
    static box_mesh room;
    make_box(&room, (float[3]){-2, 0, -2}, (float[3]){2, 3, 2}, 1);
    const float y = 0.01f;
    static float quad_v[12], quarter_v[4][12];
    static const uint32_t quad_i[6] = {0, 3, 2, 0, 2, 1}, quarter_i[6] = {0, 3, 2, 0, 2, 1};
    const float sq[12] = {-1, y, -1, 1, y, -1, 1, y, 1, -1, y, 1};
    memcpy(quad_v, sq, sizeof quad_v);
    lmgi_mesh_desc meshes[5] = {
        {.name = "room", .positions = room.v, .vertex_count = 24, .indices = room.idx, .triangle_count = 12}};
    int count = 2;
    if (!quadrants) {
        meshes[1] = (lmgi_mesh_desc){.name = "plate", .positions = quad_v, .vertex_count = 4, .indices = quad_i,
                                     .triangle_count = 2, .material = 1};
    } else {
        /* quadrant (sx, sz): corners 0 = the centre, 1 = (sx, 0), 2 = (sx, sz), 3 = (0, sz); wound up */
        static const char *const names[4] = {"plate ++", "plate +-", "plate --", "plate -+"};
        const float sgn[4][2] = {{1, 1}, {1, -1}, {-1, -1}, {-1, 1}};
        for (int q = 0; q < 4; q++) {
            float sx = sgn[q][0], sz = sgn[q][1];
            float c[12] = {0, y, 0, sx, y, 0, sx, y, sz, 0, y, sz};
            if (sx * sz < 0) /* mirrored once: swap 1 and 3 to keep the winding */
                c[3] = 0, c[5] = sz, c[9] = sx, c[11] = 0;
            memcpy(quarter_v[q], c, sizeof c);
            meshes[1 + q] = (lmgi_mesh_desc){.name = names[q], .positions = quarter_v[q], .vertex_count = 4,
                                             .indices = quarter_i, .triangle_count = 2, .material = 1};
        }
        count = 5;
    }
    lmgi_material_desc mats[2] = {{.name = "plaster", .base_color = {0.7f, 0.7f, 0.7f, 1.0f}},
                                  {.name = "white", .base_color = {0.8f, 0.8f, 0.8f, 1.0f}}};
    lmgi_light_desc spot = {.name = "spot", .type = LMGI_LIGHT_SPOT, .intensity = 1e5f, .position = {0, 2.9f, 0},
                            .direction = {0, -1, 0}, .inner_cone = 0.0f, .outer_cone = 0.02f};
    lmgi_scene_desc d = {.name = "plate under a spot", .meshes = meshes, .mesh_count = count, .materials = mats,
                         .material_count = 2, .lights = &spot, .light_count = 1};
    return load(&d, 0.0f);
}

/* The plate's photon energy: sum over its texels of pi / albedo x AIM radiance x area. */
static double plate_energy(const lmgi_scene *sc, const float *aim)
{
    lmgi_info in;
    lmgi_get_info(sc, &in);
    double sum = 0.0;
    for (uint32_t i = 0; i < in.texels; i++) {
        lmgi_texel t;
        lmgi_get_texel(sc, i, &t);
        const float *p = aim + 4 * ((size_t)t.y * in.atlas_width + t.x);
        if (t.triangle >= 12)
            sum += PI / 0.8 * ((double)p[0] + p[1] + p[2]) * t.area;
    }
    return sum;
}

static void test_photons_on_a_vertex_and_seams(void **state)
{
    (void)state;
    lmgi_context *ctx = lmt_context();
    double energy[2], room[2], top;
    for (int k = 0; k < 2; k++) {
        lmgi_scene *sc = plate_under_spot(k);
        size_t n;
        float *iim;
        lmgi_updater *u = baked(ctx, sc, 1, &iim, &n);
        float *aim = malloc(n * sizeof *aim);
        assert_non_null(aim);
        lmgi_error e;
        assert_int_equal(lmgi_get_lightmap(u, LMGI_LIGHTMAP_AIM, aim, n, &e), LMGI_OK);
        assert_true(all_finite(aim, n));
        energy[k] = plate_energy(sc, aim);
        lmt_triangles_stats(sc, iim, 0, 12, &room[k], &top);
        free(iim), free(aim);
        lmgi_updater_free(u);
        lmgi_free(sc);
    }
    print_message("a 0.02 rad spot onto the vertex of 8 triangles and 4 surfaces: plate energy %.4g (one quad "
                  "%.4g, %+.2f%%), room IIM %.4g (%+.2f%%)\n", energy[1], energy[0], 100.0 * (energy[1] / energy[0] - 1.0),
                  room[1], 100.0 * (room[1] / room[0] - 1.0));
    assert_true(energy[0] > 0.0 && room[0] > 0.0);
    assert_true(fabs(energy[1] / energy[0] - 1.0) < 0.05);
    assert_true(fabs(room[1] / room[0] - 1.0) < 0.08);
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

/* ---------- caustics, reflections and glossy surfaces (issue 37) ---------- */

#define SPEC_SIDE 128
#define SPEC_PIXELS (SPEC_SIDE * SPEC_SIDE)

/* A white floor (albedo 0.8) of half-side h at y = 0, facing up. */
static const float *floor_quad(float h)
{
    static float v[12];
    const float q[12] = {-h, 0, h, h, 0, h, h, 0, -h, -h, 0, -h};
    memcpy(v, q, sizeof q);
    return v;
}
static const uint32_t quad_idx[6] = {0, 1, 2, 0, 2, 3};

/* A quad corner, corner + u, corner + u + v, corner + v, wound to face along u x v. */
static void quad(float out[12], const float c[3], const float u[3], const float v[3])
{
    for (int k = 0; k < 3; k++) {
        out[k] = c[k];
        out[3 + k] = c[k] + u[k];
        out[6 + k] = c[k] + u[k] + v[k];
        out[9 + k] = c[k] + v[k];
    }
}

/* A specular case's run: an updater at the defaults with its first update done, and the reference's
 * pixels from cam at `target` (SPEC_SIDE a side; target 0: none, the case checks against its own). */
typedef struct {
    lmgi_context *ctx;
    lmgi_updater *u;
    lmgi_camera cam;
    lmgi_reference ref;
} spec_run;

static void spec_start(spec_run *r, lmgi_scene *sc, const float eye[3], const float at[3], float fov, float target)
{
    lmt_look_at(eye, at, fov, &r->cam);
    r->ctx = lmt_context();
    memset(&r->ref, 0, sizeof r->ref);
    if (target > 0.0f)
        lmt_reference_pixels(sc, &r->cam, SPEC_SIDE, target, &r->ref);
    r->u = updater(r->ctx, sc, NULL);
    lmgi_update_stats st;
    lmgi_error e;
    if (lmgi_update(r->u, 0.0f, 0.0f, &st, &e) != LMGI_OK)
        fail_msg("%s", e.message);
}

static void spec_end(spec_run *r)
{
    lmgi_reference_free(&r->ref);
    lmgi_updater_free(r->u);
    lmgi_context_free(r->ctx);
}

/* The runtime's caustic light (kd / pi x the caustic pass's E, green) against the reference's caustic
 * part over the spot: the pixels where the reference's exceeds `share` of its brightest, grown by 4
 * pixels (the default filter's reach). Returns the ratio of the sums; *pixels the spot's size. The frame and the caustics must be
 * finite everywhere. */
static double caustic_ratio(lmgi_updater *u, const lmgi_camera *cam, const lmgi_reference *ref, double kd,
                            double share, int *pixels)
{
    static float frame[3 * SPEC_PIXELS], E[3 * SPEC_PIXELS];
    static unsigned char spot[SPEC_PIXELS];
    lmgi_error e;
    int w, h;
    assert_int_equal(lmgi_render(u, cam, SPEC_SIDE, SPEC_SIDE, frame, &e), LMGI_OK);
    assert_int_equal(lmgi_get_caustics(u, E, 3 * SPEC_PIXELS, &w, &h, &e), LMGI_OK);
    assert_true(all_finite(frame, 3 * SPEC_PIXELS) && all_finite(E, 3 * SPEC_PIXELS));
    double peak = 0.0;
    for (int i = 0; i < SPEC_PIXELS; i++)
        peak = fmax(peak, ref->caustic[3 * i + 1]);
    memset(spot, 0, sizeof spot);
    for (int y = 0; y < SPEC_SIDE; y++)
        for (int x = 0; x < SPEC_SIDE; x++)
            if (ref->caustic[3 * (y * SPEC_SIDE + x) + 1] > share * peak)
                for (int dy = -4; dy <= 4; dy++)
                    for (int dx = -4; dx <= 4; dx++)
                        if (x + dx >= 0 && x + dx < SPEC_SIDE && y + dy >= 0 && y + dy < SPEC_SIDE)
                            spot[(y + dy) * SPEC_SIDE + x + dx] = 1;
    double run = 0.0, want = 0.0;
    int n = 0;
    for (int i = 0; i < SPEC_PIXELS; i++)
        if (spot[i] && ref->reflections[3 * i + 1] == 0.0f) /* a receiver's pixel, not the generator's */
            run += kd / PI * E[3 * i + 1], want += ref->caustic[3 * i + 1], n++;
    *pixels = n;
    assert_true(want > 0.0);
    return run / want;
}

/* A scene of the floor (white, 0.8) and `extra`, lit by one point lamp, at 800 texels. */
static lmgi_scene *floor_and(const char *name, float half, const lmgi_mesh_desc *extra, int extra_count,
                             const lmgi_material_desc *extra_mat, const lmgi_light_desc *lamp)
{
    lmgi_mesh_desc meshes[4] = {{.name = "floor", .positions = floor_quad(half), .vertex_count = 4,
                                 .indices = quad_idx, .triangle_count = 2}};
    lmgi_material_desc mats[3] = {{.name = "white", .base_color = {0.8f, 0.8f, 0.8f, 1}}};
    for (int k = 0; k < extra_count; k++) {
        meshes[1 + k] = extra[k];
        meshes[1 + k].material = 1 + k;
        mats[1 + k] = extra_mat[k];
    }
    lmgi_scene_desc d = {.name = name, .meshes = meshes, .mesh_count = 1 + extra_count, .materials = mats,
                         .material_count = 1 + extra_count, .lights = lamp, .light_count = 1};
    return lmt_load_desc(&d, 800, 0.0f);
}

static const lmgi_material_desc chrome = {.name = "chrome", .base_color = {0.9f, 0.9f, 0.9f, 1}, .metallic = 1.0f,
                                          .roughness = 0.01f};
static const lmgi_material_desc glass = {.name = "glass", .base_color = {1, 1, 1, 1}, .transmission = 1.0f,
                                         .ior = 1.5f};

/* A caustic at grazing incidence: a lamp 5 cm over the floor beside a 2 x 1 m upright mirror, so the light
 * the mirror throws back reaches the floor at 1 to 3 degrees. The caustic is thin and spread over metres
 * (E = I F h / d^3 from the lamp's image): a fraction of a photon a pixel. Its power over the fan within
 * 15% of the reference's (measured 0.94; 0.69 with the paper's fixed filter and no receiver mask, a field
 * of dots). */
static void test_grazing_caustic(void **state)
{
    (void)state;
    static float mirror[12];
    quad(mirror, (const float[3]){-1, 0, 1}, (const float[3]){0, 0, -2}, (const float[3]){0, 1, 0}); /* faces +x */
    lmgi_mesh_desc m = {.name = "mirror", .positions = mirror, .vertex_count = 4, .indices = quad_idx,
                        .triangle_count = 2};
    lmgi_light_desc lamp = {.name = "lamp", .type = LMGI_LIGHT_POINT, .intensity = 10.0f, .position = {0, 0.05f, 0}};
    lmgi_scene *sc = floor_and("grazing caustic", 4.0f, &m, 1, &chrome, &lamp);
    spec_run run;
    spec_start(&run, sc, (const float[3]){1.5f, 2.0f, 2.0f}, (const float[3]){-0.3f, 0, 0}, 0.9f, 0.2f);
    int n;
    double r = caustic_ratio(run.u, &run.cam, &run.ref, 0.8, 0.1, &n);
    print_message("grazing caustic: %d pixels, power %.4f of the reference's caustic part\n", n, r);
    assert_true(n > 100);
    assert_true(fabs(r - 1.0) < 0.15);
    spec_end(&run);
    lmgi_free(sc);
}

/* A generator touching its receiver: a glass ball (r 0.3) resting on the floor under a lamp at (-1, 3, 0),
 * its focal spot beside the point where it touches (the focus lies under the floor). Photons land at the
 * contact, and the filter reaches across the ball's silhouette: the spot's power within 10% (measured
 * 1.01; 0.85 before the receiver mask, the ball's pixels diluting the light beside them). */
static void test_caustic_generator_touching(void **state)
{
    (void)state;
    enum { SEG = 48, RINGS = 24 };
    static float pos[3 * (SEG + 1) * (RINGS + 1)], nrm[3 * (SEG + 1) * (RINGS + 1)];
    static uint32_t idx[6 * SEG * RINGS];
    uint32_t v, t = lmt_uv_sphere(0.3f, (const float[3]){0, 0.3f, 0}, SEG, RINGS, pos, nrm, idx, &v);
    lmgi_mesh_desc m = {.name = "ball", .positions = pos, .normals = nrm, .vertex_count = v, .indices = idx,
                        .triangle_count = t};
    lmgi_light_desc lamp = {.name = "lamp", .type = LMGI_LIGHT_POINT, .intensity = 10.0f, .position = {-1, 3, 0}};
    lmgi_scene *sc = floor_and("ball on the floor", 4.0f, &m, 1, &glass, &lamp);
    spec_run run;
    spec_start(&run, sc, (const float[3]){1.4f, 1.3f, 0.9f}, (const float[3]){0.1f, 0, 0}, 0.6f, 0.2f);
    int n;
    double r = caustic_ratio(run.u, &run.cam, &run.ref, 0.8, 0.1, &n);
    print_message("glass ball touching the floor: focal spot %d pixels, power %.4f of the reference's caustic part\n",
                  n, r);
    assert_true(n > 20);
    assert_true(fabs(r - 1.0) < 0.10);
    spec_end(&run);
    lmgi_free(sc);
}

/* Total internal reflection: a glass prism (a 45-45-90 triangle, legs 0.6 m, 0.8 m long) whose top leg is
 * lit from a lamp 9 m straight above it. Inside, the light meets the hypotenuse at 45 +- 1 degrees, past
 * glass's critical angle (41.8 degrees), is reflected whole, and leaves through the upright leg level,
 * onto a wall 1.5 m away: a bright band there that only total internal reflection makes. Its power
 * within 10% of the reference's (measured 1.02). */
static void test_caustic_total_internal_reflection(void **state)
{
    (void)state;
    const float A[2] = {0, 1}, B[2] = {0.6f, 1}, C[2] = {0, 0.4f}, z = 0.4f;
    const float *tri2[8][3] = {{A, B, C}, {A, B, C}, {A, B, B}, {A, B, A}, {A, C, C}, {A, C, A}, {B, C, C}, {B, C, B}};
    const int zs[8][3] = {{0, 0, 0}, {1, 1, 1}, {0, 0, 1}, {0, 1, 1}, {0, 0, 1}, {0, 1, 1}, {0, 0, 1}, {0, 1, 1}};
    static float pos[72];
    static uint32_t idx[24];
    const float mid[3] = {0.2f, 0.8f, 0};
    for (int t = 0; t < 8; t++) {
        float *p = pos + 9 * t;
        for (int k = 0; k < 3; k++)
            p[3 * k] = tri2[t][k][0], p[3 * k + 1] = tri2[t][k][1], p[3 * k + 2] = zs[t][k] ? z : -z;
        /* wound to face away from the prism's inside */
        float e1[3], e2[3], c[3];
        for (int k = 0; k < 3; k++)
            e1[k] = p[3 + k] - p[k], e2[k] = p[6 + k] - p[k], c[k] = (p[k] + p[3 + k] + p[6 + k]) / 3.0f - mid[k];
        float n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
        int inward = n[0] * c[0] + n[1] * c[1] + n[2] * c[2] < 0.0f;
        for (int k = 0; k < 3; k++)
            idx[3 * t + k] = (uint32_t)(3 * t + (inward ? (3 - k) % 3 : k));
    }
    static float wall[12];
    quad(wall, (const float[3]){-1.5f, 0, 1.5f}, (const float[3]){0, 0, -3}, (const float[3]){0, 2, 0}); /* faces +x */
    lmgi_mesh_desc m[2] = {{.name = "prism", .positions = pos, .vertex_count = 24, .indices = idx, .triangle_count = 8},
                           {.name = "wall", .positions = wall, .vertex_count = 4, .indices = quad_idx,
                            .triangle_count = 2}};
    const lmgi_material_desc mats[2] = {glass, {.name = "white wall", .base_color = {0.8f, 0.8f, 0.8f, 1}}};
    lmgi_light_desc lamp = {.name = "lamp", .type = LMGI_LIGHT_POINT, .intensity = 1000.0f, .position = {0.3f, 10, 0}};
    lmgi_scene *sc = floor_and("prism", 3.0f, m, 2, mats, &lamp);
    spec_run run;
    spec_start(&run, sc, (const float[3]){1.2f, 1.6f, 2.2f}, (const float[3]){-1.5f, 0.7f, 0}, 0.8f, 0.2f);
    int n;
    double r = caustic_ratio(run.u, &run.cam, &run.ref, 0.8, 0.1, &n);
    print_message("prism, total internal reflection: band %d pixels, power %.4f of the reference's caustic part\n", n,
                  r);
    assert_true(n > 100);
    assert_true(fabs(r - 1.0) < 0.10);
    spec_end(&run);
    lmgi_free(sc);
}

/* The frame's pixels that show a mirror (their eye ray and their 4 neighbours' meet it first: the
 * reference's reflections part is all they show) against that part: the ratio of the sums over the three
 * channels and the relative RMSE; *count the pixels. */
static double mirror_ratio(const float *frame, const lmgi_reference *ref, double *rmse, int *count)
{
    double d2 = 0.0, r2 = 0.0, sa = 0.0, sb = 0.0;
    int n = 0;
    for (int y = 1; y < SPEC_SIDE - 1; y++)
        for (int x = 1; x < SPEC_SIDE - 1; x++) {
            int i = y * SPEC_SIDE + x, inside = 1;
            const int nb[5] = {i, i - 1, i + 1, i - SPEC_SIDE, i + SPEC_SIDE};
            for (int k = 0; k < 5; k++)
                inside &= ref->reflections[3 * nb[k] + 1] > 0.0f &&
                          ref->full[3 * nb[k] + 1] == ref->reflections[3 * nb[k] + 1];
            if (!inside)
                continue;
            for (int c = 0; c < 3; c++) {
                double a = frame[3 * i + c], b = ref->reflections[3 * i + c];
                d2 += (a - b) * (a - b), r2 += b * b, sa += a, sb += b;
            }
            n++;
        }
    *rmse = sqrt(d2 / fmax(r2, 1e-30));
    *count = n;
    return sa / fmax(sb, 1e-30);
}

/* A mirror facing a mirror: two 2 x 2 m mirrors 2 m apart over the floor, a lamp between them. Light goes
 * back and forth (each pass keeps 0.9 of it): the floor's caustic is the lamp's images in both mirrors,
 * and each mirror shows the other. Both passes must stay finite, the caustic photons' paths end (the bounce
 * cap), and the floor's caustic keep its power within 10% (measured 1.00). From this camera the left
 * mirror shows the lamp-lit floor (the other mirror lies beyond its edge) and the floor's caustic. The
 * reference's reflections part has no point light's caustic seen in a mirror (a path of probability 0 for
 * both its estimators: docs/reference.md, "Known gap"), so the mirror's pixels are compared in a frame
 * without caustics: as flat reflectors the mirrors show the view mirrored in their plane (docs/direct.md,
 * "Flat reflectors"), 1.0000 of the reference's reflections, relative RMSE 0.001 (both sides compute a
 * point light's light on the floor exactly); the cube map seen from the mirror's centre, before, showed
 * the floor displaced and read 0.44. Bound: within 3%, relative RMSE under 0.05. With caustics the
 * mirror shows the floor's caustic besides (1.91 of that part): bound, at least 1.2. */
static void test_mirror_facing_mirror(void **state)
{
    (void)state;
    static float left[12], right[12];
    quad(left, (const float[3]){-1, 0, 1}, (const float[3]){0, 0, -2}, (const float[3]){0, 2, 0});  /* faces +x */
    quad(right, (const float[3]){1, 0, -1}, (const float[3]){0, 0, 2}, (const float[3]){0, 2, 0});  /* faces -x */
    lmgi_mesh_desc m[2] = {{.name = "left", .positions = left, .vertex_count = 4, .indices = quad_idx,
                            .triangle_count = 2},
                           {.name = "right", .positions = right, .vertex_count = 4, .indices = quad_idx,
                            .triangle_count = 2}};
    const lmgi_material_desc mats[2] = {chrome, chrome};
    lmgi_light_desc lamp = {.name = "lamp", .type = LMGI_LIGHT_POINT, .intensity = 5.0f, .position = {0.2f, 1.5f, 0.3f}};
    lmgi_scene *sc = floor_and("two mirrors", 3.0f, m, 2, mats, &lamp);
    spec_run run;
    spec_start(&run, sc, (const float[3]){0.3f, 1.4f, 2.8f}, (const float[3]){-1, 0.6f, 0}, 0.8f, 0.1f);
    int n, nm;
    double r = caustic_ratio(run.u, &run.cam, &run.ref, 0.8, 0.1, &n);
    static float frame[3 * SPEC_PIXELS];
    lmgi_error e;
    double rmse, rm[2]; /* with caustics, without */
    assert_int_equal(lmgi_render(run.u, &run.cam, SPEC_SIDE, SPEC_SIDE, frame, &e), LMGI_OK);
    rm[0] = mirror_ratio(frame, &run.ref, &rmse, &nm);
    lmgi_updater_free(run.u); /* one updater a scene */
    lmgi_updater_desc d = {.effects_off = LMGI_EFFECT_CAUSTICS};
    run.u = updater(run.ctx, sc, &d);
    lmgi_update_stats st;
    assert_int_equal(lmgi_update(run.u, 0.0f, 0.0f, &st, &e), LMGI_OK);
    assert_int_equal(lmgi_render(run.u, &run.cam, SPEC_SIDE, SPEC_SIDE, frame, &e), LMGI_OK);
    rm[1] = mirror_ratio(frame, &run.ref, &rmse, &nm);
    print_message("mirror facing a mirror: floor caustic %d pixels, power %.4f of the reference's; mirror %d pixels, "
                  "%.4f of the reference's reflections without caustics (relative RMSE %.3f), %.4f with them\n", n,
                  r, nm, rm[1], rmse, rm[0]);
    assert_true(n > 100 && nm > 300);
    assert_true(fabs(r - 1.0) < 0.10);
    assert_true(fabs(rm[1] - 1.0) < 0.03 && rmse < 0.05);
    assert_true(rm[0] > 1.2);
    spec_end(&run);
    lmgi_free(sc);
}

/* A metal floor (gold, 0.9 0.7 0.3) at roughness 0.01 (a mirror) and 1.0 (glossy) in a closed room (half
 * size 2, the floor y = -2) with a red block and a lamp, seen from above; the floor's maps box-projected
 * onto the room (extras reflection_box, which keeps a flat node on a cube map: docs/direct.md, "Flat
 * reflectors"). The mirror's pixels within 10% of the reference's reflections (measured 0.98; 0.85 with
 * a plain cube map, which a flat node no longer gets); the glossy floor through lmgi_check_updater (its
 * surface's row) within 15% per channel (measured 1.10 1.06 1.09: the lobe is the map's box-filtered mip,
 * not its exact shape) and the frame within 10% (1.02). */
static void test_glossy_floor_roughness(void **state)
{
    (void)state;
    for (int glossy = 0; glossy < 2; glossy++) {
        static lmt_mesh m[3];
        memset(m, 0, sizeof m);
        lmt_mesh_cube_inward(&m[0], 2.0f);
        lmt_mesh_cube(&m[1], 0.4f);
        lmt_mesh_quad(&m[2], (const float[3]){-1.5f, -1.998f, 1.5f}, (const float[3]){3, 0, 0},
                      (const float[3]){0, 0, -3});
        char mats[1024];
        snprintf(mats, sizeof mats,
                 "[" LMT_DIFFUSE(0.7) ", {\"pbrMetallicRoughness\": {\"baseColorFactor\": [0.8, 0.15, 0.1, 1], "
                 "\"metallicFactor\": 0}}, {\"pbrMetallicRoughness\": {\"baseColorFactor\": [0.9, 0.7, 0.3, 1], "
                 "\"metallicFactor\": 1, \"roughnessFactor\": %s}}], " LMT_LIGHTS("{\"type\": \"point\", \"intensity\": 8}"),
                 glossy ? "1.0" : "0.01");
        const char *path = lmt_write_scene(glossy ? "glossy_floor.gltf" : "mirror_floor.gltf", m, 3,
                                           "[{\"mesh\": 0}, {\"mesh\": 1, \"translation\": [-1, -1.6, -1], \"scale\": "
                                           "[1, 1.5, 1]}, {\"mesh\": 2, \"name\": \"metal floor\", \"extras\": {\"lmgi\": "
                                           "{\"reflection_box\": [-2, -2, -2, 2, 2, 2]}}}, {\"translation\": [0.5, 0.5, 0.5], "
                                           "\"extensions\": {\"KHR_lights_punctual\": {\"light\": 0}}}]",
                                           mats);
        lmgi_scene *sc = lmt_load(path, 1500);
        spec_run run; /* the mirror against the reference's reflections; the glossy floor checks its own */
        spec_start(&run, sc, (const float[3]){1.5f, 0.2f, 1.8f}, (const float[3]){-0.3f, -2, -0.3f}, 0.9f,
                   glossy ? 0.0f : 0.05f);
        lmgi_error e;
        if (!glossy) {
            static float frame[3 * SPEC_PIXELS];
            assert_int_equal(lmgi_render(run.u, &run.cam, SPEC_SIDE, SPEC_SIDE, frame, &e), LMGI_OK);
            assert_true(all_finite(frame, 3 * SPEC_PIXELS));
            int n;
            double rmse, r = mirror_ratio(frame, &run.ref, &rmse, &n);
            print_message("metal floor at roughness 0.01 (a mirror): %d pixels, %.4f of the reference's reflections "
                          "(relative RMSE %.3f)\n", n, r, rmse);
            assert_true(n > 1000);
            assert_true(fabs(r - 1.0) < 0.10);
        } else {
            lmgi_reference_desc rd = {.target_error = 0.05f, .no_cache = 1};
            lmgi_check_result c;
            assert_int_equal(lmgi_check_updater(run.u, &run.cam, SPEC_SIDE, SPEC_SIDE, &rd, &c, &e), LMGI_OK);
            assert_true(all_finite(c.frame, 3 * SPEC_PIXELS));
            const lmgi_check_surface *f = NULL;
            int fl = lmgi_find_node(sc, "metal floor");
            for (int k = 0; k < c.surface_count; k++)
                if (c.surfaces[k].node == fl && (!f || c.surfaces[k].pixels > f->pixels))
                    f = &c.surfaces[k];
            assert_non_null(f);
            print_message("metal floor at roughness 1 (glossy): floor %u pixels, %.4f %.4f %.4f of the reference; "
                          "frame %.4f %.4f %.4f\n", f->pixels, f->ratio[0], f->ratio[1], f->ratio[2], c.ratio[0],
                          c.ratio[1], c.ratio[2]);
            assert_true(f->pixels > 1000);
            for (int k = 0; k < 3; k++)
                assert_true(fabs(f->ratio[k] - 1.0) < 0.15 && fabs(c.ratio[k] - 1.0) < 0.10);
            lmgi_check_free(&c);
        }
        spec_end(&run);
        lmgi_free(sc);
    }
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
        cmocka_unit_test(test_thin_wall_and_corners),
        cmocka_unit_test(test_grazing_light),
        cmocka_unit_test(test_slivers_and_zero_area),
        cmocka_unit_test(test_surface_smaller_than_a_texel),
        cmocka_unit_test(test_photons_on_a_vertex_and_seams),
        cmocka_unit_test(test_grazing_caustic),
        cmocka_unit_test(test_caustic_generator_touching),
        cmocka_unit_test(test_caustic_total_internal_reflection),
        cmocka_unit_test(test_mirror_facing_mirror),
        cmocka_unit_test(test_glossy_floor_roughness),
        cmocka_unit_test(test_bending_shading_normals),
    };
    lmt_filter_from_env();
    return cmocka_run_group_tests(tests, NULL, NULL);
}
