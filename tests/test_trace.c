/* trace: Embree hits the expected node, surface and point; a dynamic node's hits follow its transform. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <lmgi_tools.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support.h"

/* A static floor (y = 0, x and z in [-1, 1]) and back wall (z = -1), and a dynamic cube of half-size 0.25
 * at (0, 0.5, 0) that an animation slides to x = 0.5 at t = 1. */
static char scene_path[512]; /* where load_test_scene wrote the scene */

static lmgi_scene *load_test_scene_at(const char *root_translation)
{
    static lmt_mesh mesh[3];
    memset(mesh, 0, sizeof mesh);
    float c0[3] = {-1, 0, 1}, u0[3] = {2, 0, 0}, v0[3] = {0, 0, -2};
    lmt_mesh_quad(&mesh[0], c0, u0, v0);
    float c1[3] = {-1, 0, -1}, u1[3] = {2, 0, 0}, v1[3] = {0, 2, 0};
    lmt_mesh_quad(&mesh[1], c1, u1, v1);
    lmt_mesh_cube(&mesh[2], 0.25f);
    char nodes[512];
    snprintf(nodes, sizeof nodes, "[{\"name\": \"root\", \"children\": [1, 2, 3], \"translation\": [%s]},"
             " {\"name\": \"floor\", \"mesh\": 0}, {\"name\": \"wall\", \"mesh\": 1},"
             " {\"name\": \"cube\", \"mesh\": 2, \"translation\": [0, 0.5, 0]}]", root_translation);
    static const float times[2] = {0, 1}, moves[6] = {0, 0.5f, 0, 0.5f, 0.5f, 0};
    lmt_accessor acc[2] = {{times, 2, "SCALAR"}, {moves, 2, "VEC3"}};
    const char *anim = "\"animations\": [{\"samplers\": [{\"input\": 6, \"output\": 7}],"
                       " \"channels\": [{\"sampler\": 0, \"target\": {\"node\": 3, \"path\": \"translation\"}}]}],";
    char *path = scene_path;
    snprintf(scene_path, sizeof scene_path, "%s/trace.gltf", lmt_tmpdir());
    assert_int_equal(lmt_write_gltf(path, mesh, 3, nodes, acc, 2, anim), 0);
    lmgi_scene *sc = NULL;
    lmgi_error err;
    lmgi_options o;
    lmgi_options_init(&o);
    o.texel_size = 0.05f;
    if (lmgi_load(path, &o, &sc, &err) != LMGI_OK)
        fail_msg("load failed: %s", err.message);
    return sc;
}

static lmgi_scene *load_test_scene(void **state)
{
    (void)state;
    return load_test_scene_at("0, 0, 0");
}

static lmgi_hit shoot(const lmgi_scene *sc, float x, float y, float z, float dx, float dy, float dz)
{
    float o[3] = {x, y, z}, d[3] = {dx, dy, dz};
    lmgi_hit h;
    lmgi_intersect(sc, o, d, 1e30f, &h);
    return h;
}

static void test_hits_expected_surfaces(void **state)
{
    lmgi_scene *sc = load_test_scene(state);
    int floor = lmgi_find_node(sc, "floor"), wall = lmgi_find_node(sc, "wall"), cube = lmgi_find_node(sc, "cube");
    assert_true(floor >= 0 && wall >= 0 && cube >= 0);
    assert_false(lmgi_node_is_dynamic(sc, floor));
    assert_true(lmgi_node_is_dynamic(sc, cube));

    lmgi_hit h = shoot(sc, 0.6f, 2, 0.6f, 0, -1, 0);
    assert_true(h.hit);
    assert_int_equal(h.node, floor);
    assert_float_equal(h.t, 2.0f, 1e-5);
    assert_float_equal(h.normal[1], 1.0f, 1e-5);
    int floor_surface = h.surface;
    assert_true(floor_surface >= 0);

    h = shoot(sc, 0.3f, 1, 1.5f, 0, 0, -1); /* towards the back wall */
    assert_true(h.hit);
    assert_int_equal(h.node, wall);
    assert_float_equal(h.t, 2.5f, 1e-5);
    assert_true(h.surface >= 0 && h.surface != floor_surface);

    h = shoot(sc, 0.1f, 2, 0.1f, 0, -1, 0); /* the cube's top at y = 0.75 */
    assert_true(h.hit);
    assert_int_equal(h.node, cube);
    assert_float_equal(h.t, 1.25f, 1e-5);
    assert_float_equal(h.normal[1], 1.0f, 1e-5);
    int top = h.surface;
    h = shoot(sc, -2, 0.5f, 0.1f, 1, 0, 0); /* the cube's -x face */
    assert_int_equal(h.node, cube);
    assert_float_equal(h.t, 1.75f, 1e-5);
    assert_float_equal(h.normal[0], -1.0f, 1e-5);
    assert_true(h.surface >= 0 && h.surface != top); /* each cube face its own surface */
    lmgi_free(sc);
}

static void test_dynamic_hits_follow_transform(void **state)
{
    lmgi_scene *sc = load_test_scene(state);
    int cube = lmgi_find_node(sc, "cube");
    /* Move the cube to (0.5, 0.5, 0.5), rotated 90 degrees about z and scaled by 2. */
    float m[16] = {0, 2, 0, 0, -2, 0, 0, 0, 0, 0, 2, 0, 0.5f, 0.5f, 0.5f, 1};
    lmgi_error err;
    assert_int_equal(lmgi_set_node_transform(sc, cube, m, &err), LMGI_OK);
    lmgi_hit h = shoot(sc, 0.1f, 2, 0.1f, 0, -1, 0);
    assert_int_equal(h.node, cube); /* the cube now spans x in [0, 1], y in [0, 1] */
    assert_float_equal(h.t, 1.0f, 1e-5);
    assert_float_equal(h.normal[1], 1.0f, 1e-5);
    h = shoot(sc, -0.5f, 2, -0.5f, 0, -1, 0); /* where nothing is now: the floor */
    assert_int_equal(h.node, lmgi_find_node(sc, "floor"));
    assert_float_equal(h.t, 2.0f, 1e-5);

    /* An edit wins over the animation: playing time leaves the cube where it was put ... */
    assert_int_equal(lmgi_set_time(sc, 0.5f, &err), LMGI_OK);
    h = shoot(sc, 0.1f, 2, 0.1f, 0, -1, 0);
    assert_int_equal(h.node, cube);
    assert_float_equal(h.t, 1.0f, 1e-5);
    /* ... until it is handed back: the animation puts it at x = 0.25 (half way) at t = 0.5, original size. */
    assert_int_equal(lmgi_node_resume_animation(sc, cube, &err), LMGI_OK);
    assert_int_equal(lmgi_set_time(sc, 0.5f, &err), LMGI_OK);
    h = shoot(sc, 0.45f, 2, 0.0f, 0, -1, 0);
    assert_int_equal(h.node, cube);
    assert_float_equal(h.t, 1.25f, 1e-5);
    h = shoot(sc, -0.05f, 2, 0.0f, 0, -1, 0); /* x = -0.05 is left of the cube at [0, 0.5] */
    assert_int_equal(h.node, lmgi_find_node(sc, "floor"));
    lmgi_free(sc);
}

/* An edit moves a node's children with it: a carrier without a mesh, a cube under it. */
static void test_children_follow_an_edit(void **state)
{
    (void)state;
    static lmt_mesh mesh[2];
    memset(mesh, 0, sizeof mesh);
    float c0[3] = {-1, 0, 1}, u0[3] = {2, 0, 0}, v0[3] = {0, 0, -2};
    lmt_mesh_quad(&mesh[0], c0, u0, v0);
    lmt_mesh_cube(&mesh[1], 0.25f);
    const char *nodes = "[{\"name\": \"floor\", \"mesh\": 0},"
                        " {\"name\": \"carrier\", \"children\": [2], \"extras\": {\"lmgi\": {\"dynamic\": true}}},"
                        " {\"name\": \"cube\", \"mesh\": 1, \"translation\": [0, 0.5, 0]}]";
    char path[600];
    snprintf(path, sizeof path, "%s/carrier.gltf", lmt_tmpdir());
    assert_int_equal(lmt_write_gltf(path, mesh, 2, nodes, NULL, 0, ""), 0);
    lmgi_scene *sc = NULL;
    lmgi_error err;
    if (lmgi_load(path, NULL, &sc, &err) != LMGI_OK)
        fail_msg("%s", err.message);
    int carrier = lmgi_find_node(sc, "carrier"), cube = lmgi_find_node(sc, "cube");
    assert_true(lmgi_node_is_dynamic(sc, cube)); /* under a dynamic node */
    lmgi_hit h = shoot(sc, 0.6f, 2, 0.0f, 0, -1, 0);
    assert_int_equal(h.node, lmgi_find_node(sc, "floor"));
    const float m[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0.5f, 0, 0, 1};
    assert_int_equal(lmgi_set_node_transform(sc, carrier, m, &err), LMGI_OK);
    h = shoot(sc, 0.6f, 2, 0.0f, 0, -1, 0); /* the cube now spans x in [0.25, 0.75] */
    assert_int_equal(h.node, cube);
    assert_float_equal(h.t, 1.25f, 1e-5);
    lmgi_free(sc);
}

static void test_bad_edits_are_refused(void **state)
{
    lmgi_scene *sc = load_test_scene(state);
    float m[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    lmgi_error err;
    assert_int_equal(lmgi_set_node_transform(sc, lmgi_find_node(sc, "floor"), m, &err), LMGI_ERR_INVALID);
    assert_non_null(strstr(err.message, "floor"));
    assert_int_equal(lmgi_set_node_transform(sc, 99, m, &err), LMGI_ERR_INVALID);
    assert_non_null(strstr(err.message, "99"));
    m[5] = NAN;
    assert_int_equal(lmgi_set_node_transform(sc, lmgi_find_node(sc, "cube"), m, &err), LMGI_ERR_INVALID);
    assert_non_null(strstr(err.message, "cube"));
    m[5] = 0.0f; /* a zero scale: singular, which Embree's instance and every normal would choke on */
    assert_int_equal(lmgi_set_node_transform(sc, lmgi_find_node(sc, "cube"), m, &err), LMGI_ERR_INVALID);
    assert_non_null(strstr(err.message, "singular"));
    m[5] = 1.0f, m[0] = -1.0f; /* a mirror: the cube's sides were decided at load by its sign then */
    assert_int_equal(lmgi_set_node_transform(sc, lmgi_find_node(sc, "cube"), m, &err), LMGI_ERR_INVALID);
    assert_non_null(strstr(err.message, "mirrors"));
    assert_int_equal(lmgi_set_time(sc, INFINITY, &err), LMGI_ERR_INVALID);
    /* Refused edits left the cube where it was. */
    lmgi_hit h = shoot(sc, 0.1f, 2, 0.1f, 0, -1, 0);
    assert_float_equal(h.t, 1.25f, 1e-5);
    lmgi_free(sc);
}

/* A scene 10,000 units from the origin is worked on relative to its centre, and the API speaks the file's
 * coordinates: rays, texel positions, bounds and node matrices are offset by 1e4 (where a float still
 * resolves 0.001), the answers those of the scene at the origin. */
static void test_far_from_origin(void **state)
{
    (void)state;
    const float far = 1e4f;
    lmgi_scene *sc = load_test_scene_at("10000, 10000, 10000");
    lmgi_info in;
    lmgi_get_info(sc, &in);
    assert_float_equal(in.bounds_min[0], far - 1.0f, 1e-3);
    assert_float_equal(in.bounds_max[1], far + 2.0f, 1e-3);
    lmgi_hit h = shoot(sc, far + 0.6f, far + 2, far + 0.6f, 0, -1, 0);
    assert_int_equal(h.node, lmgi_find_node(sc, "floor"));
    assert_float_equal(h.t, 2.0f, 2e-3);
    lmgi_texel t;
    lmgi_get_texel(sc, 0, &t);
    assert_true(fabsf(t.position[0] - far) <= 1.01f && fabsf(t.position[2] - far) <= 1.01f);
    float m[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, far + 0.5f, far + 0.5f, far + 0.5f, 1};
    lmgi_error err;
    assert_int_equal(lmgi_set_node_transform(sc, lmgi_find_node(sc, "cube"), m, &err), LMGI_OK);
    h = shoot(sc, far + 0.6f, far + 2, far + 0.6f, 0, -1, 0); /* the cube's top, now at y = 0.75 */
    assert_int_equal(h.node, lmgi_find_node(sc, "cube"));
    assert_float_equal(h.t, 1.25f, 2e-3);
    lmgi_free(sc);
}

/* Every function of lmgi.h and lmgi_tools.h takes the NULLs it documents without a crash, and refuses the others. */
static void test_null_arguments(void **state)
{
    lmgi_scene *sc = load_test_scene(state);
    lmgi_error err;
    lmgi_scene *out = (lmgi_scene *)1;
    lmgi_options_init(NULL);
    assert_int_equal(lmgi_load(NULL, NULL, &out, &err), LMGI_ERR_INVALID);
    assert_null(out);
    assert_int_equal(lmgi_load(scene_path, NULL, NULL, &err), LMGI_ERR_INVALID);
    assert_non_null(strstr(err.message, "out"));
    assert_int_equal(lmgi_load(NULL, NULL, &out, NULL), LMGI_ERR_INVALID);
    lmgi_free(NULL);
    lmgi_info in;
    lmgi_get_info(NULL, &in);
    assert_int_equal(in.triangles, 0u);
    lmgi_get_info(sc, NULL);
    lmgi_print_info(NULL, stdout);
    lmgi_print_info(sc, NULL);
    assert_int_equal(lmgi_effect_count(NULL), 0);
    lmgi_effect e;
    lmgi_get_effect(NULL, 0, &e);
    assert_null(e.name);
    lmgi_get_effect(sc, 0, NULL);
    assert_int_equal(lmgi_node_count(NULL), 0);
    assert_int_equal(lmgi_find_node(NULL, "cube"), -1);
    assert_int_equal(lmgi_find_node(sc, NULL), -1);
    assert_null(lmgi_node_name(NULL, 0));
    assert_int_equal(lmgi_node_is_dynamic(NULL, 0), 0);
    float m[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    assert_int_equal(lmgi_set_node_transform(NULL, 0, m, &err), LMGI_ERR_INVALID);
    assert_int_equal(lmgi_set_node_transform(sc, lmgi_find_node(sc, "cube"), NULL, &err), LMGI_ERR_INVALID);
    assert_non_null(strstr(err.message, "matrix"));
    assert_int_equal(lmgi_set_time(NULL, 0.0f, &err), LMGI_ERR_INVALID);
    const float o[3] = {0.1f, 2, 0.1f}, d[3] = {0, -1, 0};
    lmgi_hit h;
    lmgi_intersect(NULL, o, d, 10.0f, &h);
    assert_false(h.hit);
    lmgi_intersect(sc, NULL, d, 10.0f, &h);
    assert_false(h.hit);
    lmgi_intersect(sc, o, NULL, 10.0f, &h);
    assert_false(h.hit);
    lmgi_intersect(sc, o, d, 10.0f, NULL);
    assert_int_equal(lmgi_texel_count(NULL), 0u);
    lmgi_texel t;
    lmgi_get_texel(NULL, 0, &t);
    assert_int_equal(t.surface, -1);
    lmgi_get_texel(sc, 0, NULL);
    float uv[6];
    assert_int_equal(lmgi_triangle_lightmap_uv(NULL, 0, uv), 0);
    assert_int_equal(lmgi_triangle_lightmap_uv(sc, 0, NULL), 0);
    assert_int_equal(lmgi_write_charts(NULL, "/tmp", 0, 0, &err), LMGI_ERR_INVALID);
    assert_int_equal(lmgi_write_charts(sc, NULL, 0, 0, &err), LMGI_ERR_INVALID);
    assert_non_null(strstr(err.message, "directory"));
    assert_non_null(lmgi_status_name(LMGI_ERR_INVALID));
    lmgi_free(sc);
}

/* Rays Embree would abort on (NaN, infinite or 1e20 numbers, a zero direction, a NaN or negative range)
 * hit nothing instead: a library must not abort its host. */
static void test_bad_rays_miss(void **state)
{
    lmgi_scene *sc = load_test_scene(state);
    const float good_o[3] = {0.1f, 2, 0.1f}, good_d[3] = {0, -1, 0};
    const float bad[][3] = {{NAN, 0, 0}, {INFINITY, 0, 0}, {0, -1e20f, 0}, {0, 0, 0}};
    lmgi_hit h;
    for (int i = 0; i < 4; i++) {
        lmgi_intersect(sc, good_o, bad[i], 1e30f, &h);
        assert_false(h.hit);
        if (i < 3) {
            lmgi_intersect(sc, bad[i], good_d, 1e30f, &h);
            assert_false(h.hit);
        }
    }
    lmgi_intersect(sc, good_o, good_d, NAN, &h);
    assert_false(h.hit);
    lmgi_intersect(sc, good_o, good_d, -1.0f, &h);
    assert_false(h.hit);
    lmgi_intersect(sc, good_o, good_d, INFINITY, &h); /* an open range is fine */
    assert_true(h.hit);
    lmgi_free(sc);
}

/* A vertex beyond LM_MAX_COORDINATE (1e20: Embree's rays stop at 1.8e18, and the texel size came out
 * infinite) is a load error naming the node, not a scene that runs. */
static void test_far_vertex_refused(void **state)
{
    (void)state;
    static lmt_mesh m;
    memset(&m, 0, sizeof m);
    float c[3] = {-1, 0, 1}, u[3] = {2, 0, 0}, v[3] = {0, 0, -2};
    lmt_mesh_quad(&m, c, u, v);
    m.pos[0] = 1e20f;
    char path[600];
    snprintf(path, sizeof path, "%s/far.gltf", lmt_tmpdir());
    assert_int_equal(lmt_write_gltf(path, &m, 1, "[{\"name\": \"far_plate\", \"mesh\": 0}]", NULL, 0, NULL), 0);
    lmgi_scene *sc = NULL;
    lmgi_error err;
    assert_int_equal(lmgi_load(path, NULL, &sc, &err), LMGI_ERR_INVALID);
    assert_null(sc);
    print_message("far vertex: %s\n", err.message);
    assert_non_null(strstr(err.message, "far_plate"));
    assert_non_null(strstr(err.message, "1e+20"));
}

/* lmgi_options.target_texels: with no texel size the atlas aims at that many texels (0: 65,536); a
 * negative count is refused with a message naming it. */
static void test_target_texels(void **state)
{
    lmgi_scene *sc = load_test_scene(state);
    lmgi_free(sc);
    const char *path = scene_path;
    lmgi_options o;
    lmgi_options_init(&o);
    assert_int_equal(o.target_texels, 0);
    const int targets[3] = {0, 500, 5000};
    for (int k = 0; k < 3; k++) {
        o.target_texels = targets[k];
        lmgi_error err;
        if (lmgi_load(path, &o, &sc, &err) != LMGI_OK)
            fail_msg("load failed: %s", err.message);
        double want = targets[k] ? targets[k] : 65536.0, got = lmgi_texel_count(sc);
        print_message("target %d: %.0f texels\n", targets[k], got);
        assert_true(got > 0.75 * want && got < 1.25 * want);
        lmgi_free(sc);
    }
    o.target_texels = -3;
    lmgi_error err;
    assert_int_equal(lmgi_load(path, &o, &sc, &err), LMGI_ERR_INVALID);
    assert_null(sc);
    assert_non_null(strstr(err.message, "target texel count -3"));
}

/* Two sides (docs/materials.md): an open double-sided quad gets a twin on the same corners wound the
 * other way, normals negated, its material single-sided with split_sides; a closed double-sided cube
 * keeps one sheet. A ray at the back of the quad hits the twin, facing the ray, at the same place. */
static void test_two_sides(void **state)
{
    (void)state;
    lmt_mesh m[2];
    memset(m, 0, sizeof m);
    lmt_mesh_quad(&m[0], (float[3]){-1, 0, 1}, (float[3]){2, 0, 0}, (float[3]){0, 0, -2}); /* y = 0, facing +y */
    lmt_mesh_cube(&m[1], 0.5f);
    const char *path = lmt_write_scene("sides.gltf", m, 2, "[{\"mesh\": 0}, {\"mesh\": 1, \"translation\": [3, 0.5, 0]}]",
                                       "[{\"doubleSided\": true}, {\"doubleSided\": true}]");
    lmt_pipeline p;
    lmt_pipeline_load(&p, path, 0.25f);
    const lm_scene *s = p.s;
    assert_int_equal(s->file_tri_count, 2 + 12);
    assert_int_equal(s->tri_count, 2 + 12 + 2);
    assert_non_null(s->tri_twin);
    assert_int_equal(s->materials[0].split_sides, 1);
    assert_int_equal(s->materials[0].double_sided, 0);
    assert_int_equal(s->materials[1].split_sides, 0); /* the closed cube */
    assert_int_equal(s->materials[1].double_sided, 1);
    const lm_node *quad = &s->nodes[0];
    assert_int_equal(quad->front_tri_count, 2);
    assert_int_equal(quad->tri_count, 4);
    for (uint32_t t = quad->first_tri; t < quad->first_tri + 2; t++) {
        uint32_t b = (uint32_t)s->tri_twin[t];
        assert_int_equal(s->tri_twin[b], (int32_t)t);
        assert_true(lm_tri_is_back(s, b) && !lm_tri_is_back(s, t));
        const uint32_t *f = s->tris + 3 * (size_t)t, *k = s->tris + 3 * (size_t)b;
        const int corner[3] = {0, 2, 1}; /* the twin's corner c is the front's corner[c] */
        for (int c = 0; c < 3; c++) {
            assert_true(k[c] != f[corner[c]]); /* its own vertices */
            for (int a = 0; a < 3; a++) {
                assert_float_equal(s->positions[3 * k[c] + a], s->positions[3 * f[corner[c]] + a], 0.0f);
                assert_float_equal(s->normals[3 * k[c] + a], -s->normals[3 * f[corner[c]] + a], 0.0f);
            }
        }
        assert_true(p.su.tri_surface[b] >= 0 && p.su.tri_surface[b] != p.su.tri_surface[t]);
    }
    for (uint32_t t = s->nodes[1].first_tri; t < s->nodes[1].first_tri + s->nodes[1].tri_count; t++)
        assert_int_equal(s->tri_twin[t], -1);
    /* from above: the file's triangle; from below: its twin, facing down, at the same point */
    const float dirs[2][3] = {{0, -1, 0}, {0, 1, 0}}, orgs[2][3] = {{0.3f, 1, 0.2f}, {0.3f, -1, 0.2f}};
    for (int k = 0; k < 2; k++) {
        lm_rt_hit h;
        assert_true(lm_rt_intersect(p.rt, orgs[k], dirs[k], 0.0f, INFINITY, &h));
        assert_int_equal(lm_tri_is_back(s, h.tri), k);
        assert_float_equal(h.ng[1], k ? -1.0f : 1.0f, 1e-6f);
        assert_float_equal(h.t, 1.0f, 1e-5f);
        float q[3] = {0, 0, 0}, w[3] = {1.0f - h.u - h.v, h.u, h.v};
        for (int c = 0; c < 3; c++)
            for (int a = 0; a < 3; a++)
                q[a] += w[c] * s->positions[3 * s->tris[3 * (size_t)h.tri + c] + a];
        assert_float_equal(q[0], 0.3f, 1e-5f);
        assert_float_equal(q[2], 0.2f, 1e-5f);
    }
    lmt_pipeline_free(&p);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_hits_expected_surfaces),
        cmocka_unit_test(test_dynamic_hits_follow_transform),
        cmocka_unit_test(test_children_follow_an_edit),
        cmocka_unit_test(test_bad_edits_are_refused),
        cmocka_unit_test(test_bad_rays_miss),
        cmocka_unit_test(test_far_from_origin),
        cmocka_unit_test(test_null_arguments),
        cmocka_unit_test(test_far_vertex_refused),
        cmocka_unit_test(test_target_texels),
        cmocka_unit_test(test_two_sides),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
