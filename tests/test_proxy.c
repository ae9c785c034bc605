/* charts/proxy + gpu/gather/hemicube: the gather proxy. On the generated Cornell box (scenes/cornell.glb,
 * 13,790 triangles, a bumpy floor of 12,800) the proxy is much smaller, stays within its error bound
 * of the original surface, keeps lightmap UVs inside their charts, and gathers the same IIM within a
 * few percent. A tiny scene's proxy is the scene itself. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../src/charts/proxy.h"
#include "../src/core/vecmath.h"
#include "../src/gpu/gl/gl_context.h"
#include "../src/gpu/gather/hemicube.h"
#include "../src/reference/reference.h"
#include "../src/update/photon_stage.h"
#include "support.h"

/* Measured on scenes/cornell.glb at the default error 0.005 (see docs/gather.md). */
#define PROXY_RATIO_BOUND 0.25
#define PROXY_GATHER_RMSE_BOUND 0.03
/* meshopt's error is a quadric estimate, not a distance bound: the largest distance between points
 * on the proxy and the original (either way) measured 1.83x the target. */
#define PROXY_HAUSDORFF_FACTOR 2.0f


/* Distance from q to the segment [a, b]. */
static float seg_dist(lm_vec3 q, lm_vec3 a, lm_vec3 b)
{
    lm_vec3 ab = lm_sub(b, a);
    float l2 = lm_dot(ab, ab), t = l2 > 0.0f ? lm_dot(lm_sub(q, a), ab) / l2 : 0.0f;
    t = fminf(1.0f, fmaxf(0.0f, t));
    return lm_length(lm_sub(q, lm_add(a, lm_scale(ab, t))));
}

/* Distance from q to the triangle (p0, p1, p2): the plane when q projects inside, else the nearest edge. */
static float tri_dist(lm_vec3 q, const lm_vec3 p[3])
{
    lm_vec3 n = lm_cross(lm_sub(p[1], p[0]), lm_sub(p[2], p[0]));
    float len = lm_length(n);
    if (len > 0.0f) {
        n = lm_scale(n, 1.0f / len);
        int inside = 1;
        for (int k = 0; k < 3; k++)
            inside &= lm_dot(lm_cross(lm_sub(p[(k + 1) % 3], p[k]), lm_sub(q, p[k])), n) >= 0.0f;
        if (inside)
            return fabsf(lm_dot(lm_sub(q, p[0]), n));
    }
    return fminf(seg_dist(q, p[0], p[1]), fminf(seg_dist(q, p[1], p[2]), seg_dist(q, p[2], p[0])));
}

static void scene_tri(const lm_scene *s, uint32_t t, lm_vec3 p[3])
{
    for (int k = 0; k < 3; k++) {
        float v[3];
        lm_scene_vertex_world(s, s->tris[3 * (size_t)t + k], v);
        p[k] = lm_v3_load(v);
    }
}

static void proxy_tri(const lm_scene *s, const lm_proxy *px, uint32_t t, lm_vec3 p[3])
{
    for (int k = 0; k < 3; k++) {
        float v[3];
        lm_proxy_vertex_world(s, px, px->tri_node[t], px->tris[3 * (size_t)t + k], v);
        p[k] = lm_v3_load(v);
    }
}

/* Distance from q to the nearest original triangle of node `node`. */
static float dist_to_scene(const lm_scene *s, uint32_t node, lm_vec3 q)
{
    float best = INFINITY;
    const lm_node *n = &s->nodes[node];
    for (uint32_t t = n->first_tri; t < n->first_tri + n->tri_count; t++) {
        lm_vec3 p[3];
        scene_tri(s, t, p);
        best = fminf(best, tri_dist(q, p));
    }
    return best;
}

/* Distance from q to the nearest proxy triangle of node `node`. */
static float dist_to_proxy(const lm_scene *s, const lm_proxy *px, uint32_t node, lm_vec3 q)
{
    float best = INFINITY;
    for (uint32_t t = 0; t < px->tri_count; t++) {
        if (px->tri_node[t] != node)
            continue;
        lm_vec3 p[3];
        proxy_tri(s, px, t, p);
        best = fminf(best, tri_dist(q, p));
    }
    return best;
}

/* Largest distance from points on the proxy (corners, edge midpoints, centroid) to the original. */
static float proxy_to_scene(const lm_scene *s, const lm_proxy *px)
{
    static const float w[7][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {.5f, .5f, 0}, {0, .5f, .5f}, {.5f, 0, .5f},
                                  {1 / 3.f, 1 / 3.f, 1 / 3.f}};
    float worst = 0.0f;
#pragma omp parallel for schedule(dynamic, 16) reduction(max : worst)
    for (uint32_t t = 0; t < px->tri_count; t++) {
        lm_vec3 p[3];
        proxy_tri(s, px, t, p);
        for (int i = 0; i < 7; i++) {
            lm_vec3 q = lm_add(lm_add(lm_scale(p[0], w[i][0]), lm_scale(p[1], w[i][1])), lm_scale(p[2], w[i][2]));
            worst = fmaxf(worst, dist_to_scene(s, px->tri_node[t], q));
        }
    }
    return worst;
}

/* Largest distance from an original triangle's centroid to the proxy of its node. */
static float scene_to_proxy(const lm_scene *s, const lm_proxy *px)
{
    float worst = 0.0f;
#pragma omp parallel for schedule(dynamic, 64) reduction(max : worst)
    for (uint32_t t = 0; t < s->tri_count; t++) {
        lm_vec3 p[3];
        scene_tri(s, t, p);
        lm_vec3 c = lm_scale(lm_add(lm_add(p[0], p[1]), p[2]), 1.0f / 3.0f);
        worst = fmaxf(worst, dist_to_proxy(s, px, s->tri_node[t], c));
    }
    return worst;
}

/* Every proxy triangle has corners of one chart (or none), UVs inside that chart's rectangle. */
static void check_uvs(const lm_atlas *a, const lm_proxy *px)
{
    for (uint32_t t = 0; t < px->tri_count; t++) {
        const lm_proxy_vertex *v0 = &px->vertices[px->tris[3 * (size_t)t]];
        for (int k = 0; k < 3; k++) {
            const lm_proxy_vertex *v = &px->vertices[px->tris[3 * (size_t)t + k]];
            assert_int_equal(v->chart, v0->chart);
            assert_int_equal(v->material, v0->material);
            if (v->chart < 0)
                continue;
            const lm_chart *c = &a->charts[v->chart];
            float eps = 1e-6f;
            assert_true(v->uv[0] >= (float)c->x / a->width - eps && v->uv[0] <= (float)(c->x + c->w) / a->width + eps);
            assert_true(v->uv[1] >= (float)c->y / a->height - eps && v->uv[1] <= (float)(c->y + c->h) / a->height + eps);
        }
    }
}

/* A 2-triangle plane: the proxy is the scene. */
static void test_tiny_scene_unchanged(void **state)
{
    (void)state;
    lmt_pipeline p;
    lmt_pipeline_load(&p, lmt_plane_scene(), 0.0f);
    lm_proxy px;
    lm_error err;
    assert_int_equal(lm_proxy_build(p.s, &p.atlas, LM_PROXY_DEFAULT_ERROR, &px, &err), LM_OK);
    assert_int_equal(px.tri_count, p.s->tri_count);
    assert_true(px.max_error == 0.0f);
    lm_proxy_free(&px);
    lmt_pipeline_free(&p);
}

/* Proxy size, geometric error both ways and UVs on the Cornell box. */
static void test_cornell_proxy(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(path, lmt_project_scene("cornell.glb"));
    lmt_pipeline p;
    lmt_pipeline_load(&p, path, 0.0f);
    lm_proxy px, full;
    lm_error err;
    assert_int_equal(lm_proxy_build(p.s, &p.atlas, LM_PROXY_DEFAULT_ERROR, &px, &err), LM_OK);
    assert_int_equal(lm_proxy_build(p.s, &p.atlas, 0.0f, &full, &err), LM_OK);
    assert_int_equal(full.tri_count, p.s->tri_count);
    float bound = LM_PROXY_DEFAULT_ERROR * lm_scene_size(p.s);
    float fwd = proxy_to_scene(p.s, &px), back = scene_to_proxy(p.s, &px);
    for (int n = 0; n < p.s->node_count; n++) {
        uint32_t c = 0;
        for (uint32_t t = 0; t < px.tri_count; t++)
            c += px.tri_node[t] == (uint32_t)n;
        if (p.s->nodes[n].tri_count)
            print_message("node %s: %u -> %u triangles\n", p.s->nodes[n].name, p.s->nodes[n].tri_count, c);
    }
    print_message("proxy: %u -> %u triangles (%.1f%%), %u vertices; bound %.4f, meshopt error %.4f, "
                  "proxy->scene %.4f, scene->proxy %.4f\n", p.s->tri_count, px.tri_count,
                  100.0 * px.tri_count / p.s->tri_count, px.vertex_count, (double)bound, (double)px.max_error,
                  (double)fwd, (double)back);
    assert_true(px.tri_count < PROXY_RATIO_BOUND * p.s->tri_count);
    assert_true(px.max_error <= bound);
    assert_true(fwd <= PROXY_HAUSDORFF_FACTOR * bound);
    assert_true(back <= PROXY_HAUSDORFF_FACTOR * bound);
    check_uvs(&p.atlas, &px);
    lm_proxy_free(&px);
    lm_proxy_free(&full);
    lmt_pipeline_free(&p);
}

/* Gathers `count` texels over the AIM; returns E (rgb) and validity per texel; *ms = ms per texel. */
static void gather_rgb(const lmt_pipeline *p, const float *aim, float proxy_error, const uint32_t *texels,
                       uint32_t count, float *rgb, uint8_t *valid, double *ms)
{
    lm_hemicube_settings set;
    lm_hemicube_settings_default(&set);
    set.proxy_error = proxy_error;
    lm_gather *g = NULL;
    lm_error err;
    if (lm_gather_create(&set, &g, &err) != LM_OK)
        fail_msg("gather: %s", err.msg);
    unsigned tex = lm_iim_texture_create(p->atlas.width, p->atlas.height);
    float *rgba = malloc(4 * sizeof(float) * (size_t)p->atlas.width * (size_t)p->atlas.height);
    assert_true(tex && rgba);
    assert_int_equal(lm_gather_set_scene(g, p->s, &p->atlas, &err), LM_OK);
    assert_true((lm_gather_proxy(g) != NULL) == (proxy_error > 0.0f));
    assert_int_equal(lm_gather_set_aim(g, &p->atlas, aim, &err), LM_OK);
    lm_gather_stats gs;
    assert_int_equal(lm_gather_texels(g, p->s, &p->atlas, texels, count, tex, &gs, &err), LM_OK);
    assert_int_equal(lm_iim_texture_read(tex, p->atlas.width, p->atlas.height, rgba, &err), LM_OK);
    for (uint32_t i = 0; i < count; i++) {
        const lm_texel *tx = &p->atlas.texels[texels[i]];
        const float *v = rgba + 4 * ((size_t)tx->y * p->atlas.width + tx->x);
        memcpy(rgb + 3 * i, v, 3 * sizeof(float));
        valid[i] = !(v[3] > set.backface_limit);
    }
    *ms = 1e3 * gs.seconds / count;
    free(rgba);
    lm_iim_texture_free(tex);
    lm_gather_free(g);
}

/* A gather through the proxy matches the full-scene gather on a sample of texels. */
static void test_cornell_gather_with_proxy(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(path, lmt_project_scene("cornell.glb"));
    lmt_pipeline p;
    lmt_pipeline_load(&p, path, 0.0f);
    lm_photon_stage_settings ss;
    lm_photon_stage_settings_default(&ss);
    ss.photons.total_photons = 100000;
    lm_photon_stage *st = NULL;
    lm_error err;
    if (lm_photon_stage_create(&p.w, &ss, &st, NULL, &err) != LM_OK)
        fail_msg("%s", err.msg);
    enum { N = 1024 };
    uint32_t texels[N];
    for (uint32_t i = 0; i < N; i++)
        texels[i] = (uint32_t)((uint64_t)i * p.atlas.texel_count / N);
    float *full = malloc(sizeof(float) * 3 * N), *prox = malloc(sizeof(float) * 3 * N);
    uint8_t vf[N], vp[N];
    assert_true(full && prox);
    const float *aim = lm_aim_rgb(lm_photon_stage_aim(st));
    double ms_full, ms_proxy;
    gather_rgb(&p, aim, 0.0f, texels, N, full, vf, &ms_full);
    gather_rgb(&p, aim, LM_PROXY_DEFAULT_ERROR, texels, N, prox, vp, &ms_proxy);
    uint32_t differ = 0;
    for (uint32_t i = 0; i < N; i++)
        differ += vf[i] != vp[i], vf[i] = vf[i] && vp[i];
    double rmse = lm_ref_relative_rmse(prox, full, vf, N, 3);
    print_message("gather with proxy vs full scene: relative RMSE %.4f over %d texels (%u change validity); "
                  "%.3f ms per texel full (%u tris), %.3f ms with the proxy\n", rmse, N, differ, ms_full,
                  p.s->tri_count, ms_proxy);
    assert_true(rmse < PROXY_GATHER_RMSE_BOUND);
    assert_true(differ <= N / 100);
    free(full);
    free(prox);
    lm_photon_stage_free(st);
    lmt_pipeline_free(&p);
}

/* Largest distance from an original triangle's corner to the proxy of its node (a bump's top). */
static float corners_to_proxy(const lm_scene *s, const lm_proxy *px)
{
    float worst = 0.0f;
    for (uint32_t t = 0; t < s->tri_count; t++) {
        lm_vec3 p[3];
        scene_tri(s, t, p);
        for (int k = 0; k < 3; k++)
            worst = fmaxf(worst, dist_to_proxy(s, px, s->tri_node[t], p[k]));
    }
    return worst;
}

/* A bumpy 100 x 100 m patch (6 x 6 vertices, the inner ones 6 m up or down in a checker) on a 2 km ground, at
 * the default budget's texel (7.8 m): 0.005 of the scene's size is 14 m, which flattens the patch; the error
 * stays within a quarter of the texel (LM_PROXY_TEXEL_ERROR), and the patch keeps its bumps. */
static void test_proxy_within_a_texel(void **state)
{
    (void)state;
    static lmt_mesh m[2];
    memset(m, 0, sizeof m);
    for (int j = 0; j < 6; j++)
        for (int i = 0; i < 6; i++) {
            float *v = m[0].pos + 3 * (j * 6 + i);
            int inner = i > 0 && i < 5 && j > 0 && j < 5;
            v[0] = 20.0f * i, v[1] = inner ? ((i + j) % 2 ? 6.0f : -6.0f) + 10.0f : 10.0f, v[2] = 20.0f * j;
        }
    m[0].vertex_count = 36;
    for (int j = 0; j < 5; j++)
        for (int i = 0; i < 5; i++) {
            uint16_t a = (uint16_t)(j * 6 + i), b = (uint16_t)(a + 1), c = (uint16_t)(a + 6), d = (uint16_t)(a + 7);
            uint16_t quad[6] = {a, c, b, b, c, d};
            memcpy(m[0].idx + m[0].index_count, quad, sizeof quad);
            m[0].index_count += 6;
        }
    lmt_mesh_quad(&m[1], (float[3]){-1000, 0, -1000}, (float[3]){0, 0, 2000}, (float[3]){2000, 0, 0});
    const char *path = lmt_write_scene("proxy_patch.gltf", m, 2, "[{\"mesh\": 0}, {\"mesh\": 1}]",
                                       "[" LMT_DIFFUSE(0.5) ", " LMT_DIFFUSE(0.5) "]");
    lmt_pipeline p;
    lmt_pipeline_load(&p, path, 0.0f);
    lm_proxy px, coarse;
    lm_error err;
    assert_int_equal(lm_proxy_build(p.s, &p.atlas, LM_PROXY_DEFAULT_ERROR, &px, &err), LM_OK);
    lm_atlas huge = p.atlas; /* the texel's bound out of the way: the scene size's alone */
    huge.texel_size = 1e30f;
    assert_int_equal(lm_proxy_build(p.s, &huge, LM_PROXY_DEFAULT_ERROR, &coarse, &err), LM_OK);
    float bound = LM_PROXY_TEXEL_ERROR * p.atlas.texel_size, back = corners_to_proxy(p.s, &px);
    float was = corners_to_proxy(p.s, &coarse);
    print_message("patch on a 2 km ground, texel %.2f: %u -> %u proxy triangles, meshopt error %.3f, corners->proxy "
                  "%.3f (bound %.3f); by the scene's size alone %u triangles, corners->proxy %.3f\n",
                  (double)p.atlas.texel_size, p.s->tri_count, px.tri_count, (double)px.max_error, (double)back,
                  (double)bound, coarse.tri_count, (double)was);
    assert_true(px.max_error <= bound);
    assert_true(back <= PROXY_HAUSDORFF_FACTOR * bound);
    assert_true(was > PROXY_HAUSDORFF_FACTOR * bound); /* the bumps flattened */
    check_uvs(&p.atlas, &px);
    lm_proxy_free(&px);
    lm_proxy_free(&coarse);
    lmt_pipeline_free(&p);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_tiny_scene_unchanged),
        cmocka_unit_test(test_cornell_proxy),
        cmocka_unit_test(test_cornell_gather_with_proxy),
        cmocka_unit_test(test_proxy_within_a_texel),
    };
    return cmocka_run_group_tests(tests, lmt_gl_setup, lmt_gl_teardown);
}
