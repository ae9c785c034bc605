/* Nodes switched between static and dynamic through the public API (lmgi_set_node_dynamic): the switch
 * itself changes no light, a static block made dynamic moves and lights the room as the same block
 * loaded dynamic does, made static again it stays where it was left, and what must stay dynamic (an
 * animated node, a node under a dynamic parent) is refused. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <lmgi.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support.h"

#define SIDE 48

/* A closed room 4 x 3 x 4 (seen from inside) lit by a point light, with a block on its floor, static or
 * dynamic, and a dynamic stool in a corner (so that the direct pass caches the static casters' shadows
 * apart from the dynamic ones'). */
static lmgi_scene *load_room(int block_dynamic)
{
    float room[24], block[24], stool[24];
    for (int v = 0; v < 8; v++) {
        room[3 * v] = v & 1 ? 2.0f : -2.0f, room[3 * v + 1] = v & 2 ? 3.0f : 0.0f, room[3 * v + 2] = v & 4 ? 2.0f : -2.0f;
        block[3 * v] = v & 1 ? 0.4f : -0.4f, block[3 * v + 1] = v & 2 ? 1.0f : 0.0f,
        block[3 * v + 2] = v & 4 ? 0.4f : -0.4f;
        stool[3 * v] = v & 1 ? 1.9f : 1.6f, stool[3 * v + 1] = v & 2 ? 0.3f : 0.0f,
        stool[3 * v + 2] = v & 4 ? -1.6f : -1.9f;
    }
    static const uint32_t inward[36] = {0, 1, 3, 0, 3, 2, 4, 6, 7, 4, 7, 5, 0, 4, 5, 0, 5, 1,
                                        2, 3, 7, 2, 7, 6, 0, 2, 6, 0, 6, 4, 1, 5, 7, 1, 7, 3};
    uint32_t outward[36];
    for (int t = 0; t < 12; t++)
        outward[3 * t] = inward[3 * t], outward[3 * t + 1] = inward[3 * t + 2], outward[3 * t + 2] = inward[3 * t + 1];
    lmgi_mesh_desc meshes[3] = {
        {.name = "room", .positions = room, .vertex_count = 8, .indices = inward, .triangle_count = 12},
        {.name = "block", .positions = block, .vertex_count = 8, .indices = outward, .triangle_count = 12,
         .material = 1, .dynamic = block_dynamic},
        {.name = "stool", .positions = stool, .vertex_count = 8, .indices = outward, .triangle_count = 12,
         .dynamic = 1}};
    lmgi_material_desc mats[2] = {{.name = "plaster", .base_color = {0.7f, 0.7f, 0.7f, 1.0f}},
                                  {.name = "red", .base_color = {0.8f, 0.2f, 0.1f, 1.0f}}};
    lmgi_light_desc lamp = {.name = "lamp", .type = LMGI_LIGHT_POINT, .intensity = 4.0f, .position = {-1.2f, 2.5f, -1.0f}};
    lmgi_scene_desc d = {.name = "room", .meshes = meshes, .mesh_count = 3, .materials = mats, .material_count = 2,
                         .lights = &lamp, .light_count = 1};
    lmgi_options o;
    lmgi_options_init(&o);
    o.target_texels = 1500;
    lmgi_scene *sc = NULL;
    lmgi_error e;
    if (lmgi_load_desc(&d, &o, &sc, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    return sc;
}

static lmgi_updater *make_updater(lmgi_context *ctx, lmgi_scene *sc)
{
    lmgi_updater_desc d;
    memset(&d, 0, sizeof d);
    d.photons_per_group = 100;
    d.hemicube_resolution = 16;
    d.rim_samples = 16;
    lmgi_updater *u = NULL;
    lmgi_error e;
    if (lmgi_updater_create(ctx, sc, &d, &u, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    return u;
}

static float *get_iim(lmgi_updater *u, const lmgi_scene *sc, size_t *n)
{
    lmgi_info in;
    lmgi_get_info(sc, &in);
    *n = 4 * (size_t)in.atlas_width * in.atlas_height;
    float *rgba = malloc(*n * sizeof *rgba);
    lmgi_error e;
    assert_non_null(rgba);
    assert_int_equal(lmgi_get_lightmap(u, LMGI_LIGHTMAP_IIM, rgba, *n, &e), LMGI_OK);
    return rgba;
}

static void bake(lmgi_updater *u, lmgi_bake_report *r)
{
    lmgi_error e;
    if (lmgi_bake(u, NULL, r, &e) != LMGI_OK)
        fail_msg("%s", e.message);
}

/* Sum of the lightmap's valid texels (R + G + B). */
static double iim_sum(const float *iim, size_t n)
{
    double sum = 0.0;
    for (size_t i = 0; i < n; i += 4)
        if (iim[i + 3] > 0.5f)
            sum += iim[i] + iim[i + 1] + iim[i + 2];
    return sum;
}

/* The frame from the room's corner at (1.9, 2, 1.9) looking down the diagonal, 90 degrees wide. */
static float *frame(lmgi_updater *u)
{
    const float eye[3] = {1.9f, 2.0f, 1.9f};
    float f[3] = {-0.6f, -0.4f, -0.6f}, l = sqrtf(0.36f + 0.16f + 0.36f);
    for (int k = 0; k < 3; k++)
        f[k] /= l;
    float r[3] = {-f[2], 0.0f, f[0]}, m = sqrtf(r[0] * r[0] + r[2] * r[2]);
    r[0] /= m, r[2] /= m;
    float up[3] = {r[1] * f[2] - r[2] * f[1], r[2] * f[0] - r[0] * f[2], r[0] * f[1] - r[1] * f[0]};
    lmgi_camera cam;
    memset(&cam, 0, sizeof cam);
    for (int k = 0; k < 3; k++) {
        cam.view[4 * k] = r[k], cam.view[4 * k + 1] = up[k], cam.view[4 * k + 2] = -f[k];
        cam.view[12] -= r[k] * eye[k], cam.view[13] -= up[k] * eye[k], cam.view[14] += f[k] * eye[k];
    }
    cam.view[15] = 1.0f;
    cam.proj[0] = cam.proj[5] = 1.0f;
    cam.proj[10] = -20.05f / 19.95f, cam.proj[11] = -1.0f, cam.proj[14] = -2.0f * 20.0f * 0.05f / 19.95f;
    float *rgb = malloc(3 * SIDE * SIDE * sizeof *rgb);
    lmgi_error e;
    assert_non_null(rgb);
    assert_int_equal(lmgi_render(u, &cam, SIDE, SIDE, rgb, &e), LMGI_OK);
    return rgb;
}

static double relative_l1(const float *a, const float *b, size_t n)
{
    double d = 0.0, s = 0.0;
    for (size_t i = 0; i < n; i++)
        d += fabs((double)a[i] - b[i]), s += fabs((double)b[i]);
    return d / s;
}

static void expect_invalid(lmgi_status st, const lmgi_error *e, const char *words)
{
    assert_int_equal(st, LMGI_ERR_INVALID);
    if (!strstr(e->message, words))
        fail_msg("'%s' does not name '%s'", e->message, words);
}

static void test_static_block_made_dynamic(void **state)
{
    (void)state;
    lmgi_context *ctx = NULL;
    lmgi_error e;
    assert_int_equal(lmgi_context_create(NULL, &ctx, &e), LMGI_OK);
    lmgi_scene *sc = load_room(0), *twin = load_room(1);
    lmgi_updater *u = make_updater(ctx, sc), *ut = make_updater(ctx, twin);
    int block = lmgi_find_node(sc, "block");
    size_t n;
    float *before = get_iim(u, sc, &n), *frame_before = frame(u);
    float world[16];
    assert_true(lmgi_get_node_transform(sc, block, world));
    world[12] = -0.9f, world[14] = 0.8f; /* across the floor */
    expect_invalid(lmgi_set_node_transform(sc, block, world, &e), &e, "static");
    assert_false(lmgi_node_is_dynamic(sc, block));

    /* the switch alone: the same light, to the bit, and no photon changed */
    assert_int_equal(lmgi_set_node_dynamic(sc, block, 1, &e), LMGI_OK);
    assert_true(lmgi_node_is_dynamic(sc, block));
    lmgi_info in;
    lmgi_get_info(sc, &in);
    assert_int_equal(in.dynamic_nodes, 2);
    lmgi_bake_report r;
    bake(u, &r);
    assert_int_equal(r.photons_changed, 0);
    assert_int_equal(r.texels_gathered, 0);
    float *switched = get_iim(u, sc, &n);
    assert_memory_equal(switched, before, n * sizeof *before);
    float *frame_switched = frame(u);
    double d_switch = relative_l1(frame_switched, frame_before, 3 * SIDE * SIDE);

    /* moved, and lit as the block loaded dynamic and moved alike */
    assert_int_equal(lmgi_set_node_transform(sc, block, world, &e), LMGI_OK);
    assert_int_equal(lmgi_set_node_transform(twin, block, world, &e), LMGI_OK);
    bake(u, &r);
    lmgi_bake_report rt;
    bake(ut, &rt);
    float *moved = get_iim(u, sc, &n), *want = get_iim(ut, twin, &n);
    float *frame_moved = frame(u), *frame_want = frame(ut);
    double d_iim = relative_l1(moved, want, n), d_frame = relative_l1(frame_moved, frame_want, 3 * SIDE * SIDE);
    double d_move = relative_l1(frame_moved, frame_before, 3 * SIDE * SIDE);
    print_message("switch alone: frame %.1e; moved: %u of %u photon paths changed (the twin %u), lightmap %.1e and "
                  "frame %.1e from the twin's, frame %.3f from before the move\n", d_switch, r.photons_changed,
                  r.photons_traced, rt.photons_changed, d_iim, d_frame, d_move);
    assert_true(d_switch < 1e-6);
    assert_true(r.photons_changed > 0);
    assert_true(d_iim < 1e-3 && d_frame < 1e-3);
    assert_true(d_move > 0.02); /* the block and its shadow moved */
    lmgi_hit h;
    const float over[3] = {-0.9f, 2.9f, 0.8f}, down[3] = {0.0f, -1.0f, 0.0f};
    lmgi_intersect(sc, over, down, INFINITY, &h);
    assert_true(h.hit && h.node == block);

    /* static again where it was left: it stays there, refuses moves, and nothing changes */
    assert_int_equal(lmgi_set_node_dynamic(sc, block, 0, &e), LMGI_OK);
    assert_false(lmgi_node_is_dynamic(sc, block));
    lmgi_intersect(sc, over, down, INFINITY, &h);
    assert_true(h.hit && h.node == block);
    assert_float_equal(h.t, 1.9f, 1e-5);
    bake(u, &r);
    assert_int_equal(r.photons_changed, 0);
    float *again = get_iim(u, sc, &n), *frame_again = frame(u);
    assert_memory_equal(again, moved, n * sizeof *moved);
    assert_true(relative_l1(frame_again, frame_moved, 3 * SIDE * SIDE) < 1e-6);
    world[12] = 0.0f;
    expect_invalid(lmgi_set_node_transform(sc, block, world, &e), &e, "static");
    assert_int_equal(lmgi_set_node_dynamic(sc, block, 0, &e), LMGI_OK); /* already: nothing to do */
    expect_invalid(lmgi_set_node_dynamic(sc, 99, 1, &e), &e, "out of range");
    expect_invalid(lmgi_set_node_dynamic(sc, block, 2, &e), &e, "0 or 1");
    expect_invalid(lmgi_set_node_dynamic(NULL, block, 1, &e), &e, "NULL");
    assert_true(iim_sum(again, n) > 0.0);

    free(before), free(frame_before), free(switched), free(frame_switched), free(moved), free(want);
    free(frame_moved), free(frame_want), free(again), free(frame_again);
    lmgi_updater_free(u);
    lmgi_updater_free(ut);
    lmgi_free(sc);
    lmgi_free(twin);
    lmgi_context_free(ctx);
}

/* What must stay dynamic: the generated Cornell box's animated cube, and a child of a dynamic node
 * (switching the parent static takes the child with it). */
static void test_what_stays_dynamic(void **state)
{
    (void)state;
    lmgi_options o;
    lmgi_options_init(&o);
    o.target_texels = 800;
    lmgi_scene *sc = NULL;
    lmgi_error e;
    if (lmgi_load(lmt_project_scene("cornell.glb"), &o, &sc, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    expect_invalid(lmgi_set_node_dynamic(sc, lmgi_find_node(sc, "dynamic_cube"), 0, &e), &e, "animated");
    lmgi_free(sc);

    lmt_mesh cube;
    memset(&cube, 0, sizeof cube);
    lmt_mesh_cube(&cube, 0.5f);
    char path[1200];
    snprintf(path, sizeof path, "%s/family.gltf", lmt_tmpdir());
    const char *nodes = "[{\"name\": \"parent\", \"mesh\": 0, \"children\": [1],"
                        "  \"extras\": {\"lmgi\": {\"dynamic\": true}}},"
                        " {\"name\": \"child\", \"mesh\": 0, \"translation\": [2, 0, 0]}]";
    assert_int_equal(lmt_write_gltf(path, &cube, 1, nodes, NULL, 0, ""), 0);
    if (lmgi_load(path, &o, &sc, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    int parent = lmgi_find_node(sc, "parent"), child = lmgi_find_node(sc, "child");
    assert_true(lmgi_node_is_dynamic(sc, child));
    expect_invalid(lmgi_set_node_dynamic(sc, child, 0, &e), &e, "under dynamic node 'parent'");
    assert_int_equal(lmgi_set_node_dynamic(sc, parent, 0, &e), LMGI_OK);
    assert_false(lmgi_node_is_dynamic(sc, child));
    lmgi_info in;
    lmgi_get_info(sc, &in);
    assert_int_equal(in.dynamic_nodes, 0);
    assert_int_equal(lmgi_set_node_dynamic(sc, parent, 1, &e), LMGI_OK);
    assert_true(lmgi_node_is_dynamic(sc, child));
    float world[16];
    assert_true(lmgi_get_node_transform(sc, parent, world));
    world[13] += 3.0f; /* the child follows its parent */
    assert_int_equal(lmgi_set_node_transform(sc, parent, world, &e), LMGI_OK);
    lmgi_hit h;
    const float org[3] = {2.0f, 10.0f, 0.0f}, down[3] = {0.0f, -1.0f, 0.0f};
    lmgi_intersect(sc, org, down, INFINITY, &h);
    assert_true(h.hit && h.node == child);
    assert_float_equal(h.t, 10.0f - 3.5f, 1e-5);
    lmgi_free(sc);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_static_block_made_dynamic),
        cmocka_unit_test(test_what_stays_dynamic),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
