/* Caustics and reflections in the running updater, through the public API (docs/caustics.md): no work in a
 * scene without mirror or glass, switches per node and per run, what a moving generator or node re-traces
 * and how soon its caustic follows, the environment maps' dirty faces, a mirror sphere in a uniform box,
 * determinism. */
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

#define SIDE 64
#define PIXELS (3 * SIDE * SIDE)

static const lmgi_light_desc lamp = {.name = "lamp", .type = LMGI_LIGHT_POINT, .intensity = 20.0f,
                                     .position = {0.2f, 2.6f, 0.1f}};
static const lmgi_material_desc glass = {.name = "glass", .base_color = {1, 1, 1, 1}, .transmission = 1.0f,
                                         .ior = 1.5f};
static const lmgi_material_desc mirror = {.name = "mirror", .base_color = {0.9f, 0.9f, 0.9f, 1}, .metallic = 1.0f,
                                          .roughness = 0.01f}; /* (0 would be the default, 1) */

/* The edit room with a floating block of material m (NULL: the red diffuse one), a dynamic stool and the
 * lamp. */
static lmgi_scene *room(const lmgi_material_desc *m, int block_dynamic)
{
    lmt_room_spec spec = {.lights = &lamp, .light_count = 1, .block = m, .block_lo = {-0.3f, 0.6f, -0.3f},
                          .block_hi = {0.3f, 1.0f, 0.3f}, .block_dynamic = block_dynamic, .stool = 1};
    return lmt_room(&spec);
}

/* The room's updater with 8192 caustic photons a pair, 32^2 environment maps re-rendered `faces` an
 * update, and a frame of its own (`own`: an automatic camera outside the room, for the work it counts) or
 * none (lmgi_render draws the corner camera's). */
static lmgi_updater *updater(lmgi_context *ctx, lmgi_scene *sc, unsigned effects_off, int in_order, int faces, int own)
{
    lmgi_updater_desc d;
    lmt_room_desc(&d);
    d.frame.width = d.frame.height = own ? SIDE : 0;
    d.effects_off = effects_off;
    d.in_order = in_order;
    d.caustics.photons = 8192;
    d.frame.reflection_size = 32;
    d.frame.reflection_faces = faces;
    lmgi_updater *u = NULL;
    lmgi_error e;
    if (lmgi_updater_create(ctx, sc, &d, &u, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    return u;
}

static void update(lmgi_updater *u, lmgi_update_stats *st)
{
    lmgi_error e;
    if (lmgi_update(u, 0.0f, 0.0f, st, &e) != LMGI_OK)
        fail_msg("%s", e.message);
}

/* The caustics of the corner camera's picture (lmgi_render), and their sum; frame (may be NULL) gets the
 * picture. */
static double caustics(lmgi_updater *u, float *rgb, float *frame)
{
    static float scratch[PIXELS];
    lmgi_camera cam;
    lmt_corner_camera(&cam);
    lmgi_error e;
    assert_int_equal(lmgi_render(u, &cam, SIDE, SIDE, frame ? frame : scratch, &e), LMGI_OK);
    int w, h;
    assert_int_equal(lmgi_get_caustics(u, rgb, PIXELS, &w, &h, &e), LMGI_OK);
    assert_int_equal(w, SIDE);
    double sum = 0.0;
    for (int i = 0; i < PIXELS; i++)
        sum += rgb[i];
    return sum;
}

static void move_node(lmgi_scene *sc, const char *name, float dx)
{
    int n = lmgi_find_node(sc, name);
    float m[16];
    lmgi_error e;
    assert_true(lmgi_get_node_transform(sc, n, m));
    m[12] += dx;
    assert_int_equal(lmgi_set_node_transform(sc, n, m, &e), LMGI_OK);
}

/* A level without mirror or glass: no caustic photon, no caustic tile, no environment map face, ever. */
static void test_no_specular_no_work(void **state)
{
    (void)state;
    lmgi_context *ctx = lmt_context();
    lmgi_scene *sc = room(NULL, 0);
    lmgi_updater *u = updater(ctx, sc, 0, 0, 6, 1);
    static float rgb[PIXELS];
    uint64_t work = 0;
    for (int f = 0; f < 4; f++) {
        lmgi_update_stats st;
        if (f == 2)
            move_node(sc, "stool", 0.05f);
        update(u, &st);
        work += st.caustic_photons_retraced + (uint64_t)st.caustic_tiles + st.caustic_pixels_filtered +
                (uint64_t)st.cube_faces_rendered;
    }
    double E = caustics(u, rgb, NULL);
    print_message("no specular: caustic and cube-map work in 4 updates %llu, caustics %g\n", (unsigned long long)work, E);
    assert_int_equal(work, 0);
    assert_true(E == 0.0);
    lmgi_updater_free(u);
    lmgi_free(sc);
    lmgi_context_free(ctx);
}

/* The mirror scene (support.h) seen from its camera, the cube dynamic: the first update draws the caustic;
 * a still one runs no splat, query or filter (its composite alone, over the same irradiance: the same
 * frame to the bit); the cube moving (its photons round robin, the depth) runs the pass again. */
static void test_still_frame_reuses_caustics(void **state)
{
    (void)state;
    lmgi_context *ctx = lmt_context();
    lmgi_scene *sc = lmt_load(lmt_mirror_scene("still.gltf", NULL, "{\"lmgi\": {\"dynamic\": true}}"), 800);
    lmgi_error e;
    lmgi_updater_desc d;
    lmt_room_desc(&d);
    d.frame.width = d.frame.height = SIDE;
    d.in_order = 1;
    lmgi_updater *u = NULL;
    if (lmgi_updater_create(ctx, sc, &d, &u, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    static float first[PIXELS];
    lmgi_update_stats st[3];
    int w, h;
    update(u, &st[0]);
    memcpy(first, lmgi_frame(u, &w, &h), sizeof first);
    update(u, &st[1]);
    int same = !memcmp(first, lmgi_frame(u, &w, &h), sizeof first);
    move_node(sc, "cube", 0.1f);
    update(u, &st[2]);
    print_message("caustic tiles lit / queried: first %d / %d, still %d / %d (frame the same: %d), cube moved %d / %d\n",
                  st[0].caustic_tiles_lit, st[0].caustic_tiles, st[1].caustic_tiles_lit, st[1].caustic_tiles, same,
                  st[2].caustic_tiles_lit, st[2].caustic_tiles);
    assert_true(st[0].caustic_tiles_lit > 0);
    assert_int_equal(st[1].caustic_tiles, 0);
    assert_true(same);
    assert_true(st[2].caustic_tiles > 0);
    lmgi_updater_free(u);
    lmgi_free(sc);
    lmgi_context_free(ctx);
}

/* A floating glass block under the lamp throws a caustic on the floor; a still room traces no caustic
 * photon; the stool moving re-traces a quarter of them an update for four updates (one turn), then none. */
static void test_glass_block(void **state)
{
    (void)state;
    lmgi_context *ctx = lmt_context();
    lmgi_scene *sc = room(&glass, 0);
    lmgi_updater *u = updater(ctx, sc, 0, 1, 1, 0);
    static float rgb[PIXELS];
    lmgi_update_stats st;
    update(u, &st);
    double E = caustics(u, rgb, NULL);
    print_message("glass block: caustic sum %.3f, %u photons re-traced\n", E, st.caustic_photons_retraced);
    assert_true(E > 0.0);
    assert_int_equal(st.caustic_photons_retraced, 0);
    move_node(sc, "stool", 0.05f);
    uint32_t traced[6];
    for (int f = 0; f < 6; f++) {
        update(u, &st);
        traced[f] = st.caustic_photons_retraced;
    }
    print_message("stool moved: %u %u %u %u %u %u caustic photons re-traced\n", traced[0], traced[1], traced[2],
                  traced[3], traced[4], traced[5]);
    for (int f = 0; f < 4; f++)
        assert_int_equal(traced[f], 8192 / 4);
    assert_int_equal(traced[4], 0);
    lmgi_updater_free(u);
    lmgi_free(sc);
    lmgi_context_free(ctx);
}

/* The caustic light split (docs/caustics.md, "Thin light in the lightmaps"): by default (caustics.thin 0.25)
 * the photons whose light is thin next to the floor's other light are carried by the lightmaps, the rest by
 * the screen pass; with it off every photon is the screen's. The same photons land; the caustics a picture shows (lmgi_get_caustics:
 * the screen's plus the lightmaps' at each pixel) and the frame agree. (The tiles it spares: test_cli's
 * test_run_caustic_tiles.) */
static void test_thin_light_in_the_lightmaps(void **state)
{
    (void)state;
    lmgi_context *ctx = lmt_context();
    lmgi_scene *sc[2] = {room(&glass, 0), room(&glass, 0)}; /* an updater each */
    lmgi_updater *u[2];
    lmgi_update_stats st[2];
    static float rgb[2][PIXELS], frame[2][PIXELS];
    double E[2];
    for (int k = 0; k < 2; k++) {
        lmgi_updater_desc d;
        lmt_room_desc(&d);
        d.frame.width = d.frame.height = SIDE;
        d.in_order = 1;
        d.caustics.photons = 8192;
        d.caustics.thin = k ? LMGI_OFF : 0.0f; /* the default (0.25) for k = 0 */
        lmgi_error e;
        if (lmgi_updater_create(ctx, sc[k], &d, &u[k], &e) != LMGI_OK)
            fail_msg("%s", e.message);
        update(u[k], &st[k]);
        E[k] = caustics(u[k], rgb[k], frame[k]);
    }
    double diff = 0.0, total = 0.0;
    for (int i = 0; i < PIXELS; i++)
        diff += fabs(frame[0][i] - frame[1][i]), total += frame[1][i];
    print_message("glass block, thin light in the lightmaps / all on screen: photons landed %u / %u, of them thin "
                  "%u / %u; caustic sum %.4f / %.4f; frame's relative L1 %.4f\n", st[0].caustic_photons_landed,
                  st[1].caustic_photons_landed, st[0].caustic_photons_thin, st[1].caustic_photons_thin, E[0], E[1],
                  diff / total);
    assert_true(st[0].caustic_photons_landed > 0);
    assert_int_equal(st[0].caustic_photons_landed, st[1].caustic_photons_landed);
    assert_true(st[0].caustic_photons_thin > 0); /* the patch under the block is as bright as the floor's light:
                                                  * most of it stays on screen */
    assert_int_equal(st[1].caustic_photons_thin, 0);
    assert_true(fabs(E[0] / E[1] - 1.0) < 0.03);
    assert_true(diff / total < 0.01);
    for (int k = 0; k < 2; k++) {
        lmgi_updater_free(u[k]);
        lmgi_free(sc[k]);
    }
    lmgi_context_free(ctx);
}

/* The block's caustics switched off (lmgi_set_node_effects) give, to the bit, the frame of a run without
 * caustics (effects_off), with no caustic work; switched on again, the caustic returns. */
static void test_switches(void **state)
{
    (void)state;
    lmgi_context *ctx = lmt_context();
    lmgi_scene *sc = room(&glass, 0), *plain = room(&glass, 0);
    lmgi_updater *u = updater(ctx, sc, 0, 1, 1, 0), *un = updater(ctx, plain, LMGI_EFFECT_CAUSTICS, 1, 1, 0);
    lmgi_error e;
    int block = lmgi_find_node(sc, "block");
    lmgi_node_effects fx;
    assert_int_equal(lmgi_get_node_effects(sc, block, &fx, &e), LMGI_OK);
    assert_int_equal(fx.caustics, 1);
    fx.caustics = 0;
    assert_int_equal(lmgi_set_node_effects(sc, block, &fx, &e), LMGI_OK);
    lmgi_update_stats st, stn;
    for (int f = 0; f < 2; f++) {
        update(u, &st);
        update(un, &stn);
    }
    static float a[PIXELS], b[PIXELS], rgb[PIXELS];
    double off = caustics(u, rgb, a);
    caustics(un, rgb, b);
    double d = lmt_relative_l1(a, b, PIXELS);
    print_message("caustics off on the block: frame %.1e from a run without caustics; caustics %g, photons %u\n", d,
                  off, st.caustic_photons_retraced);
    assert_true(d == 0.0);
    assert_true(off == 0.0);
    fx.caustics = 1;
    assert_int_equal(lmgi_set_node_effects(sc, block, &fx, &e), LMGI_OK);
    update(u, &st);
    assert_true(caustics(u, rgb, NULL) > 0.0);
    fx.caustics = 2;
    lmt_expect_invalid(lmgi_set_node_effects(sc, block, &fx, &e), &e, "caustics");
    lmgi_updater_free(u);
    lmgi_updater_free(un);
    lmgi_free(sc);
    lmgi_free(plain);
    lmgi_context_free(ctx);
}

/* A moved glass block re-traces all its caustic photons at once: the next picture shows the caustic where a
 * fresh updater on the moved block shows it (to the bit), in order and with the photon work left running
 * beside the application's frame (lmgi_render waits for it: it reads the caustic photons); the latter
 * reports the work at the update after. */
static void test_moved_generator(void **state)
{
    (void)state;
    lmgi_context *ctx = lmt_context();
    static float moved[PIXELS], fresh[PIXELS];
    lmgi_scene *there = room(&glass, 1);
    move_node(there, "block", 0.4f);
    lmgi_updater *uf = updater(ctx, there, 0, 1, 1, 0);
    lmgi_update_stats st;
    update(uf, &st);
    caustics(uf, fresh, NULL);
    lmgi_updater_free(uf);
    for (int in_order = 1; in_order >= 0; in_order--) {
        lmgi_scene *sc = room(&glass, 1);
        lmgi_updater *u = updater(ctx, sc, 0, in_order, 1, 0);
        update(u, &st);
        move_node(sc, "block", 0.4f);
        double d[3];
        for (int f = 0; f < 3; f++) {
            update(u, &st);
            if (f == !in_order)
                assert_int_equal(st.caustic_photons_retraced, 8192); /* the whole pair at once */
            caustics(u, moved, NULL);
            d[f] = lmt_relative_l1(moved, fresh, PIXELS);
        }
        print_message("%s: caustics after the move %.2e %.2e %.2e from a fresh updater's\n",
                      in_order ? "in order" : "beside the frame", d[0], d[1], d[2]);
        assert_true(d[0] == 0.0 && d[1] == 0.0 && d[2] == 0.0);
        lmgi_updater_free(u);
        lmgi_free(sc);
    }
    lmgi_free(there);
    lmgi_context_free(ctx);
}

/* Environment map faces are rendered when what they see changed: all six at the first update, none while
 * nothing moves, only those that see the stool when it moves, all six when the mirror block moves. */
static void test_dirty_faces(void **state)
{
    (void)state;
    lmgi_context *ctx = lmt_context();
    lmgi_scene *sc = room(&mirror, 1);
    lmgi_updater *u = updater(ctx, sc, LMGI_EFFECT_INDIRECT, 1, 6, 1); /* no lightmap blends: only motion */
    lmgi_update_stats st;
    int faces[5];
    update(u, &st);
    faces[0] = st.cube_faces_rendered;
    update(u, &st);
    faces[1] = st.cube_faces_rendered;
    move_node(sc, "stool", 0.05f);
    update(u, &st);
    faces[2] = st.cube_faces_rendered;
    update(u, &st);
    faces[3] = st.cube_faces_rendered;
    move_node(sc, "block", 0.05f);
    update(u, &st);
    faces[4] = st.cube_faces_rendered;
    print_message("faces rendered: first %d, still %d, stool moved %d, still %d, mirror moved %d\n", faces[0],
                  faces[1], faces[2], faces[3], faces[4]);
    assert_int_equal(faces[0], 6);
    assert_int_equal(faces[1], 0);
    assert_true(faces[2] >= 1 && faces[2] <= 2); /* the stool at (1.75, 0.15, -1.75) seen from (0, 0.8, 0): +x, -z */
    assert_int_equal(faces[3], 0);
    assert_int_equal(faces[4], 6);
    lmgi_updater_free(u);
    lmgi_free(sc);
    lmgi_context_free(ctx);
}

/* A mirror sphere (albedo 0.8) inside a closed box whose walls emit radiance 1 shows 0.8 at every pixel
 * of it (what it reflects is the same everywhere). */
static void test_mirror_sphere_in_uniform_box(void **state)
{
    (void)state;
    enum { SEG = 32, RINGS = 16, SV = (SEG + 1) * (RINGS + 1), ST = 2 * SEG * RINGS };
    static float spos[3 * SV], snrm[3 * SV], box[72];
    static uint32_t sidx[3 * ST], bidx[36];
    uint32_t sv;
    uint32_t tris = lmt_uv_sphere(0.5f, (const float[3]){0, 0, 0}, SEG, RINGS, spos, snrm, sidx, &sv);
    lmt_box((const float[3]){-3, -3, -3}, (const float[3]){3, 3, 3}, 1, box, bidx);
    lmgi_mesh_desc meshes[2] = {
        {.name = "box", .positions = box, .vertex_count = 24, .indices = bidx, .triangle_count = 12},
        {.name = "ball", .positions = spos, .normals = snrm, .vertex_count = sv, .indices = sidx, .triangle_count = tris,
         .material = 1}};
    lmgi_material_desc mats[2] = {{.name = "glow", .base_color = {0, 0, 0, 1}, .emissive = {1, 1, 1}},
                                  {.name = "chrome", .base_color = {0.8f, 0.8f, 0.8f, 1}, .metallic = 1.0f,
                                   .roughness = 0.01f}};
    lmgi_scene_desc d = {.name = "uniform box", .meshes = meshes, .mesh_count = 2, .materials = mats,
                         .material_count = 2};
    lmgi_scene *sc = lmt_load_desc(&d, 600, 0.0f);
    lmgi_error e;
    lmgi_context *ctx = lmt_context();
    lmgi_updater_desc ud;
    lmt_room_desc(&ud);
    ud.frame.reflection_size = 64;
    lmgi_updater *u = NULL;
    if (lmgi_updater_create(ctx, sc, &ud, &u, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    lmgi_update_stats st;
    update(u, &st);
    /* from (0, 0, 2.5) towards the ball, 40 degrees: it fills the middle of the picture */
    lmgi_camera cam;
    lmt_look_at((const float[3]){0, 0, 2.5f}, (const float[3]){0, 0, 0}, 0.7f, &cam);
    float t = cam.proj[5];
    static float rgb[PIXELS];
    assert_int_equal(lmgi_render(u, &cam, SIDE, SIDE, rgb, &e), LMGI_OK);
    double worst = 0.0, sum = 0.0;
    int count = 0;
    for (int y = 0; y < SIDE; y++)
        for (int x = 0; x < SIDE; x++) {
            /* pixels well inside the ball's outline (radius 0.5 at 2.5: tan = 0.2 / 0.364 of the half side) */
            double sx = (2.0 * (x + 0.5) / SIDE - 1.0) / t, sy = (2.0 * (y + 0.5) / SIDE - 1.0) / t;
            if (sx * sx + sy * sy > 0.8 * 0.8 * 0.2 * 0.2 / (1.0 - 0.04))
                continue;
            for (int c = 0; c < 3; c++) {
                double v = rgb[3 * (y * SIDE + x) + c];
                worst = fmax(worst, fabs(v - 0.8));
                sum += v, count++;
            }
        }
    print_message("mirror sphere in a uniform box: %d pixel values, mean %.4f (want 0.8), worst off by %.4f\n",
                  count, sum / count, worst);
    assert_true(count > 300);
    assert_true(fabs(sum / count - 0.8) < 0.01);
    assert_true(worst < 0.02);
    lmgi_updater_free(u);
    lmgi_free(sc);
    lmgi_context_free(ctx);
}

/* Two updaters on the generated Cornell box (mirror and glass, moving): the same frames and caustics. */
static void test_deterministic(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(path, lmt_project_scene("cornell.glb"));
    lmgi_context *ctx = lmt_context();
    lmgi_options o;
    lmgi_options_init(&o);
    o.target_texels = 1500;
    lmgi_scene *sc[2];
    lmgi_updater *u[2];
    lmgi_error e;
    static float c[2][PIXELS];
    for (int k = 0; k < 2; k++) {
        if (lmgi_load(path, &o, &sc[k], &e) != LMGI_OK)
            fail_msg("%s", e.message);
        lmgi_updater_desc d;
        lmt_room_desc(&d);
        d.frame.width = d.frame.height = SIDE;
        d.caustics.photons = 4096;
        d.frame.reflection_size = 32;
        if (lmgi_updater_create(ctx, sc[k], &d, &u[k], &e) != LMGI_OK)
            fail_msg("%s", e.message);
    }
    uint64_t traced = 0;
    for (int f = 0; f < 4; f++)
        for (int k = 0; k < 2; k++) {
            lmgi_update_stats st;
            assert_int_equal(lmgi_update(u[k], 0.25f * (float)f, 0.0f, &st, &e), LMGI_OK);
            traced += st.caustic_photons_retraced;
        }
    int w, h;
    const float *a = lmgi_frame(u[0], &w, &h), *b = lmgi_frame(u[1], &w, &h);
    for (int k = 0; k < 2; k++)
        assert_int_equal(lmgi_get_caustics(u[k], c[k], PIXELS, &w, &h, &e), LMGI_OK);
    print_message("cornell.glb: %llu caustic photons traced; frames equal %d, caustics equal %d\n",
                  (unsigned long long)traced, !memcmp(a, b, sizeof(float) * PIXELS),
                  !memcmp(c[0], c[1], sizeof c[0]));
    assert_true(traced > 0);
    assert_memory_equal(a, b, sizeof(float) * PIXELS);
    assert_memory_equal(c[0], c[1], sizeof c[0]);
    for (int k = 0; k < 2; k++) {
        lmgi_updater_free(u[k]);
        lmgi_free(sc[k]);
    }
    lmgi_context_free(ctx);
}

/* Bad desc values are refused naming them. */
static void test_bad_desc(void **state)
{
    (void)state;
    lmgi_context *ctx = lmt_context();
    lmgi_scene *sc = room(&glass, 0);
    lmgi_updater_desc d;
    lmgi_updater *u = NULL;
    lmgi_error e;
    static const char *const fields[4] = {"caustics.retrace", "caustics.filter", "caustics.tile", "caustics.world_filter"};
    for (int k = 0; k < 4; k++) {
        lmt_room_desc(&d);
        if (k == 0)
            d.caustics.retrace = 1.5f;
        else if (k == 1)
            d.caustics.filter = 9;
        else if (k == 2)
            d.caustics.tile = 2;
        else
            d.caustics.world_filter = 2;
        lmt_expect_invalid(lmgi_updater_create(ctx, sc, &d, &u, &e), &e, fields[k]);
        assert_null(u);
    }
    lmt_room_desc(&d);
    d.caustics.retrace = NAN;
    lmt_expect_invalid(lmgi_updater_create(ctx, sc, &d, &u, &e), &e, "caustics.retrace");
    lmgi_free(sc);
    lmgi_context_free(ctx);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_no_specular_no_work),
        cmocka_unit_test(test_glass_block),
        cmocka_unit_test(test_still_frame_reuses_caustics),
        cmocka_unit_test(test_thin_light_in_the_lightmaps),
        cmocka_unit_test(test_switches),
        cmocka_unit_test(test_moved_generator),
        cmocka_unit_test(test_dirty_faces),
        cmocka_unit_test(test_mirror_sphere_in_uniform_box),
        cmocka_unit_test(test_deterministic),
        cmocka_unit_test(test_bad_desc),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
