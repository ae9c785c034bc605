/* Nodes switched between static and dynamic through the public API (lmgi_set_node_dynamic): the switch
 * itself changes no light, a static block made dynamic moves and lights the room as the same block
 * loaded dynamic does, made static again it stays where it was left, and what must stay dynamic (an
 * animated node, a node under a dynamic parent) is refused. Moves are staged: a batch of them reaches the
 * BVH in one commit (lmgi_commit, or the next call that traces rays). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <lmgi.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../src/api/lmgi_scene.h"
#include "edit_room.h"
#include "support.h"

/* The edit room (edit_room.h) lit by a point light, with its block static or dynamic and the dynamic stool
 * (so that the direct pass caches the static casters' shadows apart from the dynamic ones'). */
static lmgi_scene *load_room(int block_dynamic)
{
    static const lmgi_light_desc lamp = {.name = "lamp", .type = LMGI_LIGHT_POINT, .intensity = 4.0f,
                                         .position = {-1.2f, 2.5f, -1.0f}};
    lmt_room_spec spec = {.lights = &lamp, .light_count = 1, .block_dynamic = block_dynamic, .stool = 1};
    return lmt_room(&spec);
}

/* Unit cubes (half side 0.5) placed as the glTF nodes JSON says, written to name and loaded. */
static lmgi_scene *load_cubes(const char *name, const char *nodes)
{
    lmt_mesh cube;
    memset(&cube, 0, sizeof cube);
    lmt_mesh_cube(&cube, 0.5f);
    char path[1200];
    snprintf(path, sizeof path, "%s/%s", lmt_tmpdir(), name);
    assert_int_equal(lmt_write_gltf(path, &cube, 1, nodes, NULL, 0, ""), 0);
    lmgi_options o;
    lmgi_options_init(&o);
    o.target_texels = 800;
    lmgi_scene *sc = NULL;
    lmgi_error e;
    if (lmgi_load(path, &o, &sc, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    return sc;
}

static double iim_sum(const float *iim, size_t n)
{
    double sum = 0.0;
    for (size_t i = 0; i < n; i += 4)
        if (iim[i + 3] > 0.5f)
            sum += iim[i] + iim[i + 1] + iim[i + 2];
    return sum;
}

static void test_static_block_made_dynamic(void **state)
{
    (void)state;
    lmgi_context *ctx = lmt_context();
    lmgi_error e;
    lmgi_scene *sc = load_room(0), *twin = load_room(1);
    lmgi_updater *u = lmt_room_updater(ctx, sc), *ut = lmt_room_updater(ctx, twin);
    int block = lmgi_find_node(sc, "block");
    size_t n;
    float *before = lmt_iim(u, sc, &n), *frame_before = lmt_corner_frame(u);
    float world[16];
    assert_true(lmgi_get_node_transform(sc, block, world));
    world[12] = -0.9f, world[14] = 0.8f; /* across the floor */
    lmt_expect_invalid(lmgi_set_node_transform(sc, block, world, &e), &e, "static");
    assert_false(lmgi_node_is_dynamic(sc, block));

    /* the switch alone: the same light, to the bit, and no photon changed */
    assert_int_equal(lmgi_set_node_dynamic(sc, block, 1, &e), LMGI_OK);
    assert_true(lmgi_node_is_dynamic(sc, block));
    lmgi_info in;
    lmgi_get_info(sc, &in);
    assert_int_equal(in.dynamic_nodes, 2);
    lmgi_bake_report r;
    lmt_bake(u, &r);
    assert_int_equal(r.photons_changed, 0);
    assert_int_equal(r.texels_gathered, 0);
    float *switched = lmt_iim(u, sc, &n);
    assert_memory_equal(switched, before, n * sizeof *before);
    float *frame_switched = lmt_corner_frame(u);
    double d_switch = lmt_relative_l1(frame_switched, frame_before, 3 * LMT_SIDE * LMT_SIDE);

    /* moved, and lit as the block loaded dynamic and moved alike */
    assert_int_equal(lmgi_set_node_transform(sc, block, world, &e), LMGI_OK);
    assert_int_equal(lmgi_set_node_transform(twin, block, world, &e), LMGI_OK);
    lmt_bake(u, &r);
    lmgi_bake_report rt;
    lmt_bake(ut, &rt);
    float *moved = lmt_iim(u, sc, &n), *want = lmt_iim(ut, twin, &n);
    float *frame_moved = lmt_corner_frame(u), *frame_want = lmt_corner_frame(ut);
    double d_iim = lmt_relative_l1(moved, want, n), d_frame = lmt_relative_l1(frame_moved, frame_want, 3 * LMT_SIDE * LMT_SIDE);
    double d_move = lmt_relative_l1(frame_moved, frame_before, 3 * LMT_SIDE * LMT_SIDE);
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
    lmt_bake(u, &r);
    assert_int_equal(r.photons_changed, 0);
    float *again = lmt_iim(u, sc, &n), *frame_again = lmt_corner_frame(u);
    assert_memory_equal(again, moved, n * sizeof *moved);
    assert_true(lmt_relative_l1(frame_again, frame_moved, 3 * LMT_SIDE * LMT_SIDE) < 1e-6);
    world[12] = 0.0f;
    lmt_expect_invalid(lmgi_set_node_transform(sc, block, world, &e), &e, "static");
    assert_int_equal(lmgi_set_node_dynamic(sc, block, 0, &e), LMGI_OK); /* already: nothing to do */
    lmt_expect_invalid(lmgi_set_node_dynamic(sc, 99, 1, &e), &e, "out of range");
    lmt_expect_invalid(lmgi_set_node_dynamic(sc, block, 2, &e), &e, "0 or 1");
    lmt_expect_invalid(lmgi_set_node_dynamic(NULL, block, 1, &e), &e, "NULL");
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
    lmt_expect_invalid(lmgi_set_node_dynamic(sc, lmgi_find_node(sc, "dynamic_cube"), 0, &e), &e, "animated");
    lmgi_free(sc);

    sc = load_cubes("family.gltf", "[{\"name\": \"parent\", \"mesh\": 0, \"children\": [1],"
                                   "  \"extras\": {\"lmgi\": {\"dynamic\": true}}},"
                                   " {\"name\": \"child\", \"mesh\": 0, \"translation\": [2, 0, 0]}]");
    int parent = lmgi_find_node(sc, "parent"), child = lmgi_find_node(sc, "child");
    assert_true(lmgi_node_is_dynamic(sc, child));
    lmt_expect_invalid(lmgi_set_node_dynamic(sc, child, 0, &e), &e, "under dynamic node 'parent'");
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

/* Three dynamic cubes moved: the scene model at once, the BVH not until the commit, which is one top-level
 * commit for the three; rays see every move after it; lmgi_intersect commits first on its own, an update
 * too, and a commit with nothing staged commits nothing. */
static void test_moves_commit_once(void **state)
{
    (void)state;
    const char *nodes = "[{\"name\": \"a\", \"mesh\": 0, \"extras\": {\"lmgi\": {\"dynamic\": true}}},"
                        " {\"name\": \"b\", \"mesh\": 0, \"translation\": [3, 0, 0],"
                        "  \"extras\": {\"lmgi\": {\"dynamic\": true}}},"
                        " {\"name\": \"c\", \"mesh\": 0, \"translation\": [6, 0, 0],"
                        "  \"extras\": {\"lmgi\": {\"dynamic\": true}}}]";
    lmgi_scene *sc = load_cubes("three_cubes.gltf", nodes);
    lmgi_error e;
    uint64_t commits = lm_rt_top_commits(sc->rt);
    for (int k = 0; k < 3; k++) { /* each cube 2 up */
        float world[16];
        assert_true(lmgi_get_node_transform(sc, k, world));
        world[13] += 2.0f;
        assert_int_equal(lmgi_set_node_transform(sc, k, world, &e), LMGI_OK);
        assert_true(lmgi_get_node_transform(sc, k, world)); /* the scene model has it at once */
        assert_float_equal(world[13], 2.0f, 1e-6);
    }
    assert_true(lm_rt_top_commits(sc->rt) == commits); /* staged: the BVH as it was */
    assert_int_equal(lmgi_commit(sc, &e), LMGI_OK);
    assert_true(lm_rt_top_commits(sc->rt) == commits + 1); /* one commit for the three */
    assert_int_equal(lmgi_commit(sc, &e), LMGI_OK);
    assert_true(lm_rt_top_commits(sc->rt) == commits + 1); /* nothing staged: nothing committed */
    const float down[3] = {0.0f, -1.0f, 0.0f};
    for (int k = 0; k < 3; k++) {
        const float org[3] = {3.0f * (float)k, 10.0f, 0.0f};
        lmgi_hit h;
        lmgi_intersect(sc, org, down, INFINITY, &h);
        assert_true(h.hit && h.node == k);
        assert_float_equal(h.t, 10.0f - 2.5f, 1e-5); /* the top face, 2 up */
    }
    float world[16];
    assert_true(lmgi_get_node_transform(sc, 1, world));
    world[13] -= 2.0f;
    assert_int_equal(lmgi_set_node_transform(sc, 1, world, &e), LMGI_OK);
    const float org[3] = {3.0f, 10.0f, 0.0f};
    lmgi_hit h;
    lmgi_intersect(sc, org, down, INFINITY, &h); /* commits first */
    assert_true(h.hit && h.node == 1);
    assert_float_equal(h.t, 10.0f - 0.5f, 1e-5);
    assert_true(lm_rt_top_commits(sc->rt) == commits + 2);
    lmgi_intersect(sc, org, down, INFINITY, &h);
    assert_true(lm_rt_top_commits(sc->rt) == commits + 2);
    lmt_expect_invalid(lmgi_commit(NULL, &e), &e, "NULL");
    lmgi_free(sc);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_static_block_made_dynamic),
        cmocka_unit_test(test_what_stays_dynamic),
        cmocka_unit_test(test_moves_commit_once),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
