/* trace: emitter flux and emission, next-event estimation against analytic irradiance, BSDF sampling. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../src/core/vecmath.h"
#include "../src/trace/bsdf.h"
#include "../src/trace/lights.h"
#include "../src/trace/shading.h"
#include "support.h"

#define PI 3.14159265358979323846

/* A hand-built scene: one node holding one square (two triangles) of half-size h in the plane y = y0,
 * facing up or down, with material 0; plus up to two lights on nodes 1 and 2. */
typedef struct {
    lm_scene s;
    lm_node nodes[3];
    lm_material mat[1];
    lm_light lights[2];
    float pos[12], nrm[12], uv[8];
    uint32_t vnode[4], tris[6], tnode[2];
    int tmat[2];
} tscene;

static void node_at(lm_node *n, float x, float y, float z)
{
    memset(n, 0, sizeof *n);
    lm_mat4_identity(n->world);
    n->world[12] = x, n->world[13] = y, n->world[14] = z;
    n->parent = -1, n->mesh = -1, n->camera = -1, n->light = -1;
}

static void make_scene(tscene *t, float h, float y0, int facing_up)
{
    memset(t, 0, sizeof *t);
    const float xz[4][2] = {{-h, -h}, {h, -h}, {h, h}, {-h, h}};
    for (int v = 0; v < 4; v++) {
        t->pos[3 * v] = xz[v][0], t->pos[3 * v + 1] = y0, t->pos[3 * v + 2] = xz[v][1];
        t->nrm[3 * v + 1] = facing_up ? 1.0f : -1.0f;
        t->uv[2 * v] = (float)(v == 1 || v == 2), t->uv[2 * v + 1] = (float)(v >= 2);
    }
    /* (0,1,2) winds to -y; reversed to +y */
    const uint32_t down[6] = {0, 1, 2, 0, 2, 3}, up[6] = {0, 2, 1, 0, 3, 2};
    memcpy(t->tris, facing_up ? up : down, sizeof t->tris);
    for (int i = 0; i < 3; i++)
        node_at(&t->nodes[i], 0, 0, 0);
    t->nodes[0].tri_count = 2;
    lm_material *m = &t->mat[0];
    snprintf(m->name, sizeof m->name, "m");
    for (int c = 0; c < 4; c++)
        m->base_color[c] = 0.5f;
    m->base_color_tex = m->emissive_tex = -1;
    m->uv_scale[0] = m->uv_scale[1] = 1.0f;
    m->roughness = 1.0f;
    m->ior = 1.5f;
    lm_material_classify(m);
    lm_scene *s = &t->s;
    s->node_count = 1, s->nodes = t->nodes;
    s->material_count = 1, s->materials = t->mat;
    s->lights = t->lights;
    s->vertex_count = 4, s->positions = t->pos, s->normals = t->nrm, s->uv0 = t->uv, s->vertex_node = t->vnode;
    s->tri_count = 2, s->tris = t->tris, s->tri_material = t->tmat, s->tri_node = t->tnode;
    lm_scene_update_bounds(s);
}

static void set_emissive(tscene *t, float r, float g, float b, int double_sided)
{
    t->mat[0].emissive[0] = r, t->mat[0].emissive[1] = g, t->mat[0].emissive[2] = b;
    t->mat[0].double_sided = double_sided;
    lm_material_classify(&t->mat[0]);
}

static void add_light(tscene *t, lm_light_type type, float intensity, const float pos[3])
{
    int i = t->s.light_count++;
    lm_light *l = &t->lights[i];
    memset(l, 0, sizeof *l);
    l->type = type;
    l->color[0] = 1.0f, l->color[1] = 0.5f, l->color[2] = 0.25f;
    l->intensity = intensity;
    l->inner_cone = 0.3f, l->outer_cone = 0.7f;
    l->node = 1 + i;
    t->s.node_count = 2 + i;
    node_at(&t->nodes[1 + i], pos[0], pos[1], pos[2]);
    /* no rotation: the light shines down -Z; turn it to -Y (90 degrees about X) */
    float *w = t->nodes[1 + i].world;
    w[4] = 0, w[5] = 0, w[6] = -1, w[8] = 0, w[9] = 1, w[10] = 0;
    t->nodes[1 + i].light = i;
}

/* Sum of emitted flux over an n x n stratified grid of (u0, u1), with u2, u3 from a second grid. */
static void emitted_total(const lm_emitters *em, const lm_scene *s, int e, int n, double out[3])
{
    out[0] = out[1] = out[2] = 0.0;
    uint32_t count = (uint32_t)(n * n);
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) {
            float u[4] = {(i + 0.5f) / n, (j + 0.5f) / n, ((i * 7 + j * 3) % n + 0.5f) / n, ((j * 5 + i) % n + 0.5f) / n};
            lm_emission ph;
            lm_emitter_emit(em, s, e, u, count, &ph);
            for (int c = 0; c < 3; c++)
                out[c] += ph.flux[c];
        }
}

static void test_point_flux_and_emission(void **state)
{
    (void)state;
    tscene t;
    make_scene(&t, 1.0f, 0.0f, 1);
    add_light(&t, LM_LIGHT_POINT, 2.0f, (float[3]){0, 1, 0});
    lm_emitters em;
    lm_error err;
    assert_int_equal(lm_emitters_build(&t.s, &em, &err), LM_OK);
    assert_int_equal(em.count, 1);
    assert_true(em.e[0].punctual);
    assert_float_equal(em.e[0].power[0], 4.0 * PI * 2.0, 1e-4);
    assert_float_equal(em.e[0].power[2], 4.0 * PI * 2.0 * 0.25, 1e-4);
    double tot[3];
    emitted_total(&em, &t.s, 0, 64, tot);
    for (int c = 0; c < 3; c++)
        assert_float_equal(tot[c], em.e[0].power[c], 1e-4 * em.e[0].power[c]);
    /* directions are uniform: the mean direction is ~0 */
    double mean[3] = {0, 0, 0};
    for (int i = 0; i < 64; i++)
        for (int j = 0; j < 64; j++) {
            lm_emission ph;
            lm_emitter_emit(&em, &t.s, 0, (float[4]){(i + 0.5f) / 64, (j + 0.5f) / 64, 0, 0}, 4096, &ph);
            assert_float_equal(lm_length(lm_v3_load(ph.dir)), 1.0, 1e-5);
            for (int c = 0; c < 3; c++)
                mean[c] += ph.dir[c] / 4096.0;
        }
    assert_true(fabs(mean[0]) < 1e-3 && fabs(mean[1]) < 1e-3 && fabs(mean[2]) < 1e-3);
    lm_emitters_free(&em);
}

static void test_spot_flux_matches_integration(void **state)
{
    (void)state;
    tscene t;
    make_scene(&t, 1.0f, 0.0f, 1);
    add_light(&t, LM_LIGHT_SPOT, 3.0f, (float[3]){0, 1, 0});
    const lm_light *l = &t.lights[0];
    /* 2 pi int att(cos) dcos by the midpoint rule */
    double num = 0.0;
    const int n = 200000;
    for (int i = 0; i < n; i++)
        num += lm_spot_attenuation(l, (float)(-1.0 + (i + 0.5) * 2.0 / n)) * 2.0 / n;
    num *= 2.0 * PI;
    assert_float_equal(lm_spot_solid_angle(l), num, 1e-4 * num);
    /* full intensity inside the inner cone, none outside the outer one, t^2 between */
    assert_float_equal(lm_spot_attenuation(l, cosf(0.2f)), 1.0, 1e-6);
    assert_float_equal(lm_spot_attenuation(l, cosf(0.8f)), 0.0, 1e-6);
    float cm = 0.5f * (cosf(0.3f) + cosf(0.7f));
    assert_float_equal(lm_spot_attenuation(l, cm), 0.25, 1e-5);
    lm_emitters em;
    lm_error err;
    assert_int_equal(lm_emitters_build(&t.s, &em, &err), LM_OK);
    assert_float_equal(em.e[0].power[0], 3.0 * num, 1e-4 * 3.0 * num);
    double tot[3];
    emitted_total(&em, &t.s, 0, 256, tot);
    assert_float_equal(tot[0], em.e[0].power[0], 2e-3 * em.e[0].power[0]);
    /* every photon leaves inside the outer cone around -Y */
    lm_emission ph;
    lm_emitter_emit(&em, &t.s, 0, (float[4]){0.999f, 0.3f, 0, 0}, 1, &ph);
    assert_true(-ph.dir[1] >= cosf(0.7f) - 1e-5f);
    lm_emitters_free(&em);
}

static void test_area_flux_and_emission(void **state)
{
    (void)state;
    for (int ds = 0; ds < 2; ds++) {
        tscene t;
        make_scene(&t, 0.5f, 2.0f, 0); /* area 1, facing down */
        set_emissive(&t, 1.0f, 2.0f, 3.0f, ds);
        lm_emitters em;
        lm_error err;
        assert_int_equal(lm_emitters_build(&t.s, &em, &err), LM_OK);
        assert_int_equal(em.count, 1);
        const lm_emitter *e = &em.e[0];
        assert_int_equal(e->kind, LM_EMIT_AREA);
        assert_false(e->punctual);
        assert_int_equal(e->tri_count, 2);
        assert_float_equal(e->area, 1.0, 1e-5);
        for (int c = 0; c < 3; c++)
            assert_float_equal(e->power[c], PI * (c + 1) * (ds ? 2 : 1), 1e-4);
        double tot[3], mean_cos = 0.0;
        emitted_total(&em, &t.s, 0, 64, tot);
        for (int c = 0; c < 3; c++)
            assert_float_equal(tot[c], e->power[c], 1e-4 * e->power[c]);
        int down = 0;
        for (int i = 0; i < 4096; i++) {
            float u[4] = {(i % 64 + 0.5f) / 64, (i / 64 + 0.5f) / 64, (i * 37 % 4096 + 0.5f) / 4096, (i * 11 % 97 + 0.5f) / 97};
            lm_emission ph;
            lm_emitter_emit(&em, &t.s, 0, u, 4096, &ph);
            assert_true(fabsf(ph.org[0]) <= 0.5f + 1e-4f && fabsf(ph.org[2]) <= 0.5f + 1e-4f);
            mean_cos += fabs(ph.dir[1]) / 4096.0; /* cosine-weighted: E[cos] = 2/3 */
            down += ph.dir[1] < 0.0f;
        }
        assert_float_equal(mean_cos, 2.0 / 3.0, 2e-3);
        if (ds)
            assert_true(abs(down - 2048) < 64); /* both sides, half each */
        else
            assert_int_equal(down, 4096);
        lm_emitters_free(&em);
    }
}

static void test_directional_flux(void **state)
{
    (void)state;
    tscene t;
    make_scene(&t, 1.0f, 0.0f, 1);
    add_light(&t, LM_LIGHT_DIRECTIONAL, 5.0f, (float[3]){0, 3, 0});
    lm_emitters em;
    lm_error err;
    assert_int_equal(lm_emitters_build(&t.s, &em, &err), LM_OK);
    float r = sqrtf(8.0f) / 2.0f; /* bounds are [-1,1] x 0 x [-1,1] */
    assert_float_equal(em.disk_radius, r, 1e-5);
    /* the sun straight down sees the bounds as the 2 x 2 square: E x 4, where the bounding sphere's disk
     * (E pi r^2 = 2 pi E) sent a third of its photons past the plane */
    assert_float_equal(em.e[0].power[0], 5.0 * 4.0, 1e-3);
    double tot[3];
    emitted_total(&em, &t.s, 0, 32, tot);
    assert_float_equal(tot[0], em.e[0].power[0], 1e-4 * em.e[0].power[0]);
    lm_emission ph;
    lm_emitter_emit(&em, &t.s, 0, (float[4]){0.7f, 0.2f, 0, 0}, 1, &ph);
    assert_float_equal(ph.dir[1], -1.0, 1e-6);
    assert_true(ph.org[1] > r); /* starts above the scene's bounding sphere */
    for (int i = 0; i < 32; i++) /* every photon meets the plane */
        for (int j = 0; j < 32; j++) {
            lm_emitter_emit(&em, &t.s, 0, (float[4]){(i + 0.5f) / 32, (j + 0.5f) / 32, 0, 0}, 1024, &ph);
            float s = ph.org[1] / -ph.dir[1], x = ph.org[0] + s * ph.dir[0], z = ph.org[2] + s * ph.dir[2];
            assert_true(fabsf(x) <= 1.0f + 1e-5f && fabsf(z) <= 1.0f + 1e-5f);
        }
    lm_light_sample ls;
    assert_true(lm_emitter_sample_toward(&em, &t.s, 0, (float[3]){0, 0, 0}, (float[3]){0, 0, 0}, &ls));
    assert_true(isinf(ls.dist));
    assert_float_equal(ls.dir[1], 1.0, 1e-6);
    assert_float_equal(ls.weight[0], 5.0, 1e-6);
    lm_emitters_free(&em);
}

/* E = I cos(theta) / d^2 from a point light at (0, 1, 0) at points of the plane y = 0. */
static void test_nee_point_light_irradiance(void **state)
{
    (void)state;
    tscene t;
    make_scene(&t, 1.0f, 0.0f, 1);
    add_light(&t, LM_LIGHT_POINT, 2.0f, (float[3]){0, 1, 0});
    lm_emitters em;
    lm_error err;
    assert_int_equal(lm_emitters_build(&t.s, &em, &err), LM_OK);
    for (int i = 0; i < 5; i++) {
        float x = 0.4f * (float)i, p[3] = {x, 0, 0.3f};
        lm_light_sample ls;
        assert_true(lm_emitter_sample_toward(&em, &t.s, 0, p, (float[3]){0.5f, 0.5f, 0.5f}, &ls));
        double d2 = x * x + 1.0 + 0.09, cos = 1.0 / sqrt(d2);
        assert_float_equal(ls.dist, sqrt(d2), 1e-5);
        assert_float_equal(ls.weight[0] * ls.dir[1], 2.0 * cos / d2, 1e-5);
        assert_float_equal(ls.pdf, 0.0, 0.0);
    }
    lm_emitters_free(&em);
}

/* KHR_lights_punctual range 1.5 on that light: its inverse square times clamp(1 - (d / range)^4, 0, 1), the
 * extension's recommended window; no light at all from 1.5 on; directional lights have no range. */
static void test_nee_point_light_range(void **state)
{
    (void)state;
    tscene t;
    make_scene(&t, 1.0f, 0.0f, 1);
    add_light(&t, LM_LIGHT_POINT, 2.0f, (float[3]){0, 1, 0});
    t.lights[0].range = 1.5f;
    lm_emitters em;
    lm_error err;
    assert_int_equal(lm_emitters_build(&t.s, &em, &err), LM_OK);
    for (int i = 0; i < 8; i++) {
        float x = 0.25f * (float)i, p[3] = {x, 0, 0};
        double d2 = x * x + 1.0, r = sqrt(d2) / 1.5, window = fmax(0.0, 1.0 - r * r * r * r);
        lm_light_sample ls;
        int lit = lm_emitter_sample_toward(&em, &t.s, 0, p, (float[3]){0.5f, 0.5f, 0.5f}, &ls);
        assert_int_equal(lit, window > 0.0);
        if (lit)
            assert_float_equal(ls.weight[0], 2.0 * window / d2, 1e-5);
    }
    assert_float_equal(lm_light_range_window(&t.lights[0], 0.0f), 1.0f, 0.0f);
    t.lights[0].type = LM_LIGHT_DIRECTIONAL;
    assert_float_equal(lm_light_range_window(&t.lights[0], 100.0f), 1.0f, 0.0f);
    t.lights[0].type = LM_LIGHT_POINT, t.lights[0].range = 0.0f; /* absent: no window */
    assert_float_equal(lm_light_range_window(&t.lights[0], 1e6f), 1.0f, 0.0f);
    lm_emitters_free(&em);
}

/* Irradiance under a square Lambertian emitter: E = pi Le F, F the point-to-rectangle form factor
 * summed over the four corner rectangles (a x a at height h):
 * F = 1/(2 pi) [X/sqrt(1+X^2) atan(Y/sqrt(1+X^2)) + Y/sqrt(1+Y^2) atan(X/sqrt(1+Y^2))], X = Y = a/h. */
static void test_nee_area_light_irradiance(void **state)
{
    (void)state;
    tscene t;
    make_scene(&t, 0.5f, 1.0f, 0); /* side 1 at height 1, facing down */
    set_emissive(&t, 2.0f, 2.0f, 2.0f, 0);
    lm_emitters em;
    lm_error err;
    assert_int_equal(lm_emitters_build(&t.s, &em, &err), LM_OK);
    double X = 0.5, F = 4.0 / (2.0 * PI) * 2.0 * X / sqrt(1 + X * X) * atan(X / sqrt(1 + X * X));
    double expect = PI * 2.0 * F, sum = 0.0;
    const int n = 64;
    float p[3] = {0, 0, 0};
    for (int i = 0; i < n * n; i++) {
        float u[3] = {(i * 13 % 101 + 0.5f) / 101, (i % n + 0.5f) / n, (i / n + 0.5f) / n};
        lm_light_sample ls;
        if (!lm_emitter_sample_toward(&em, &t.s, 0, p, u, &ls))
            continue;
        sum += ls.weight[0] * ls.dir[1];
        float x[3] = {p[0] + ls.dir[0] * ls.dist, p[1] + ls.dir[1] * ls.dist, p[2] + ls.dir[2] * ls.dist};
        float pdf = fmaxf(lm_emitter_pdf(&em, &t.s, 0, 0, p, x), lm_emitter_pdf(&em, &t.s, 0, 1, p, x));
        assert_float_equal(pdf, ls.pdf, 1e-3 * ls.pdf);
    }
    assert_float_equal(sum / (n * n), expect, 0.01 * expect);
    /* the back of a single-sided emitter gives nothing */
    lm_light_sample ls;
    assert_false(lm_emitter_sample_toward(&em, &t.s, 0, (float[3]){0, 2, 0}, (float[3]){0.5f, 0.5f, 0.5f}, &ls));
    lm_emitters_free(&em);
}

static void test_shading_from_hit(void **state)
{
    (void)state;
    tscene t;
    make_scene(&t, 1.0f, 0.5f, 1);
    t.nodes[0].world[12] = 0.25f; /* moved: positions are world, local stays local */
    lm_scene_update_bounds(&t.s);
    lm_rt *rt = NULL;
    lm_error err;
    assert_int_equal(lm_rt_build(&t.s, NULL, &rt, &err), LM_OK);
    float org[3] = {0.5f, 2.0f, 0.25f}, dir[3] = {0, -1, 0};
    lm_rt_hit hit;
    assert_true(lm_rt_intersect(rt, org, dir, 0.0f, 1e30f, &hit));
    lm_shading sh;
    lm_shading_from_hit(&t.s, &hit, org, dir, &sh);
    assert_float_equal(sh.pos[0], 0.5, 1e-5);
    assert_float_equal(sh.pos[1], 0.5, 1e-5);
    assert_float_equal(sh.pos[2], 0.25, 1e-5);
    assert_float_equal(sh.local[0], 0.25, 1e-5);
    assert_float_equal(sh.ng[1], 1.0, 1e-5);
    assert_float_equal(sh.ns[1], 1.0, 1e-5);
    assert_float_equal(sh.albedo[0], 0.5, 1e-6);
    assert_ptr_equal(sh.material, &t.mat[0]);
    assert_int_equal(sh.node, 0);
    /* A textured material: the albedo is the texture at the hit's interpolated uv, (0.625, 0.625)
     * (u = (x_local + 1) / 2), and the 2 x 2 texture differs a quarter of a unit away. */
    float texels[16] = {0.9f, 0.5f, 0.2f, 1, 0.1f, 0.1f, 0.1f, 1, 0.3f, 0.3f, 0.3f, 1, 0.2f, 0.2f, 0.2f, 1};
    lm_texture tex = {.width = 2, .height = 2, .rgba = texels};
    t.s.textures = &tex;
    t.s.texture_count = 1;
    t.mat[0].base_color_tex = 0;
    lm_shading_from_hit(&t.s, &hit, org, dir, &sh);
    float want[3], aside[3];
    lm_material_albedo(&t.s, &t.mat[0], 0.625f, 0.625f, want);
    lm_material_albedo(&t.s, &t.mat[0], 0.375f, 0.625f, aside);
    for (int c = 0; c < 3; c++)
        assert_float_equal(sh.albedo[c], want[c], 1e-5);
    assert_true(fabsf(want[0] - aside[0]) > 0.01f);
    lm_rt_free(rt);
}

/* Shading normals of a static triangle: a flat one's the BVH makes once and hands out with the hit
 * (hit.ns) equals the one shading computes per hit for the same plane as a dynamic node; a smooth one
 * (vertex normals tilted apart) is interpolated at the hit. */
static void test_static_shading_normals(void **state)
{
    (void)state;
    float org[3] = {0.3f, 2.0f, -0.2f}, dir[3] = {0, -1, 0}, ns[2][3];
    for (int dynamic = 0; dynamic < 2; dynamic++) {
        tscene t;
        make_scene(&t, 1.0f, 0.5f, 1);
        for (int v = 0; v < 4; v++) { /* flat, but not along the face: (0.6, 0.8, 0) */
            t.nrm[3 * v] = 0.6f;
            t.nrm[3 * v + 1] = 0.8f;
        }
        t.nodes[0].dynamic = dynamic;
        lm_rt *rt = NULL;
        lm_error err;
        assert_int_equal(lm_rt_build(&t.s, NULL, &rt, &err), LM_OK);
        lm_rt_hit hit;
        assert_true(lm_rt_intersect(rt, org, dir, 0.0f, 1e30f, &hit));
        assert_true(dynamic ? hit.ns == NULL : hit.ns != NULL);
        lm_shading sh;
        lm_shading_from_hit(&t.s, &hit, org, dir, &sh);
        memcpy(ns[dynamic], sh.ns, sizeof sh.ns);
        lm_rt_free(rt);
    }
    for (int c = 0; c < 3; c++)
        assert_float_equal(ns[0][c], ns[1][c], 1e-6);
    assert_float_equal(ns[0][0], 0.6, 1e-5);
    tscene t;
    make_scene(&t, 1.0f, 0.5f, 1);
    t.nrm[0] = 1.0f, t.nrm[1] = 0.0f; /* vertex 0 tilted all the way to +x: not flat */
    lm_rt *rt = NULL;
    lm_error err;
    assert_int_equal(lm_rt_build(&t.s, NULL, &rt, &err), LM_OK);
    float at[3] = {-0.9f, 2.0f, -0.9f}; /* near vertex 0 (-1, y, -1) */
    lm_rt_hit hit;
    assert_true(lm_rt_intersect(rt, at, dir, 0.0f, 1e30f, &hit));
    assert_null(hit.ns);
    lm_shading sh;
    lm_shading_from_hit(&t.s, &hit, at, dir, &sh);
    assert_true(sh.ns[0] > 0.5f && sh.ns[1] > 0.0f); /* leans far towards vertex 0's +x */
    lm_rt_free(rt);
}

/* The hit's geometric normal is the winding's, cross(v1 - v0, v2 - v0) of the world corners, on every
 * triangle of the two-room scene (single-sided: a flipped normal makes photons die on the walls' fronts)
 * static and dynamic (the door) alike: a ray from just off each triangle's centroid along that normal,
 * turned back, must hit the triangle with ng along the same normal. */
static void test_hit_normals_follow_winding(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(path, lmt_project_scene("two_rooms.glb"));
    lmt_pipeline p;
    lmt_pipeline_load(&p, path, 0.0f);
    uint32_t checked = 0;
    for (uint32_t t = 0; t < p.s->tri_count; t++) {
        float v[3][3];
        for (int k = 0; k < 3; k++)
            lm_scene_vertex_world(p.s, p.s->tris[3 * (size_t)t + k], v[k]);
        lm_vec3 a = lm_v3_load(v[0]), b = lm_v3_load(v[1]), c = lm_v3_load(v[2]);
        lm_vec3 n = lm_cross(lm_sub(b, a), lm_sub(c, a));
        if (!(lm_length(n) > 1e-6f))
            continue;
        n = lm_normalize(n);
        lm_vec3 centre = lm_scale(lm_add(lm_add(a, b), c), 1.0f / 3.0f);
        float org[3], dir[3];
        lm_v3_store(org, lm_add(centre, lm_scale(n, 1e-3f)));
        lm_v3_store(dir, lm_scale(n, -1.0f));
        lm_rt_hit hit;
        assert_true(lm_rt_intersect(p.rt, org, dir, 0.0f, 1e-2f, &hit));
        if (hit.tri != t) /* a coplanar neighbour in front of it */
            continue;
        assert_true(lm_dot(lm_v3_load(hit.ng), n) > 0.999f);
        checked++;
    }
    assert_true(checked >= p.s->tri_count / 2);
    lmt_pipeline_free(&p);
}

/* A dynamic node turned by a quarter turn about z after the BVH was built: the hit's geometric normal
 * and the shading normal follow the new matrix (the normal matrix the BVH keeps for the node), and a
 * mirroring matrix keeps the normals on the side the winding gives. */
static void test_shading_moved_node(void **state)
{
    (void)state;
    tscene t;
    make_scene(&t, 1.0f, 0.5f, 1); /* the plane y = 0.5, facing +y */
    t.nodes[0].dynamic = 1;
    lm_rt *rt = NULL;
    lm_error err;
    assert_int_equal(lm_rt_build(&t.s, NULL, &rt, &err), LM_OK);
    float turn[16] = {0, 1, 0, 0, -1, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}; /* (x, y) -> (-y, x) */
    assert_int_equal(lm_rt_set_node_transform(rt, 0, turn, &err), LM_OK);
    memcpy(t.nodes[0].world, turn, sizeof turn);
    float org[3] = {-2.0f, 0.25f, 0.1f}, dir[3] = {1, 0, 0}; /* the plane is now x = -0.5, facing -x */
    lm_rt_hit hit;
    assert_true(lm_rt_intersect(rt, org, dir, 0.0f, 1e30f, &hit));
    lm_shading sh;
    lm_shading_from_hit(&t.s, &hit, org, dir, &sh);
    assert_float_equal(sh.pos[0], -0.5, 1e-5);
    assert_float_equal(sh.ng[0], -1.0, 1e-5);
    assert_float_equal(sh.ns[0], -1.0, 1e-5);
    assert_float_equal(sh.ns[1], 0.0, 1e-5);
    float mirror[16] = {1, 0, 0, 0, 0, -1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}; /* y -> -y: plane y = -0.5 */
    assert_int_equal(lm_rt_set_node_transform(rt, 0, mirror, &err), LM_OK);
    memcpy(t.nodes[0].world, mirror, sizeof mirror);
    float org2[3] = {0.1f, -2.0f, 0.2f}, up[3] = {0, 1, 0};
    assert_true(lm_rt_intersect(rt, org2, up, 0.0f, 1e30f, &hit));
    lm_shading_from_hit(&t.s, &hit, org2, up, &sh);
    float want[3];
    lm_v3_store(want, lm_mat4_normal(mirror, lm_v3(0, 1, 0)));
    assert_float_equal(sh.pos[1], -0.5, 1e-5);
    assert_float_equal(hit.ng[1], want[1], 1e-5);
    assert_float_equal(sh.ns[1], want[1], 1e-5);
    lm_rt_free(rt);
}

/* ---- BSDFs ---- */

static lm_material g_mat;

static void shading_up(lm_shading *sh, lm_material_class cls, float albedo)
{
    memset(sh, 0, sizeof *sh);
    memset(&g_mat, 0, sizeof g_mat);
    g_mat.cls = cls;
    g_mat.ior = 1.5f;
    g_mat.roughness = cls == LM_MAT_GLOSSY ? 0.4f : 1.0f;
    g_mat.metallic = 0.0f;
    sh->ng[1] = sh->ns[1] = 1.0f;
    sh->albedo[0] = sh->albedo[1] = sh->albedo[2] = albedo;
    sh->material = &g_mat;
}

/* A photon at a diffuse face whose shading normal leans 40 degrees (shading.h, Veach 1997 section 5.3):
 * arriving 30 degrees off the face's normal, 10 off the shading normal, its weight is cos 10 / cos 30;
 * arriving behind the shading normal, 0; on a flat face, exactly 1. Its bounce (lm_shading_for_bounce)
 * leaves with the geometric cosine and the albedo as its weight: mean weight 0.6 and mean cos(ng) 2/3 over
 * a stratified hemisphere. Drawn about the leaning normal, the directions below the face were lost:
 * measured mean weight 0.530, 12% of the albedo, (1 - cos 40) / 2 of the lobe. Glossy faces keep theirs. */
static void test_photons_on_leaning_normals(void **state)
{
    (void)state;
    lm_shading sh, flat;
    shading_up(&sh, LM_MAT_DIFFUSE, 0.6f);
    float in30[3] = {(float)-sin(PI / 6), (float)-cos(PI / 6), 0.0f}, in_behind[3] = {0.9f, -0.43589f, 0.0f};
    assert_true(lm_shading_arrival_weight(&sh, in30) == 1.0f);
    assert_true(lm_shading_for_bounce(&sh, &flat) == &sh);
    sh.ns[0] = (float)sin(40.0 * PI / 180.0), sh.ns[1] = (float)cos(40.0 * PI / 180.0);
    assert_float_equal(lm_shading_arrival_weight(&sh, in30), cos(PI / 18) / cos(PI / 6), 1e-5);
    assert_true(lm_shading_arrival_weight(&sh, in_behind) == 0.0f);
    double mean[2] = {0.0, 0.0}, cos_g = 0.0;
    const int n = 128;
    for (int k = 0; k < 2; k++) {
        const lm_shading *b = k ? lm_shading_for_bounce(&sh, &flat) : &sh;
        for (int i = 0; i < n * n; i++) {
            float u[3] = {(i % n + 0.5f) / n, (i / n + 0.5f) / n, 0.5f};
            lm_bsdf_sample_t bs;
            if (!lm_bsdf_sample(b, in30, u, &bs))
                continue;
            mean[k] += bs.weight[0] / (n * n);
            if (k)
                cos_g += bs.wo[1] / (n * n);
        }
    }
    print_message("leaning 40 degrees: bounce weight %.4f about the shading normal, %.4f about the face's (mean "
                  "cos %.4f)\n", mean[0], mean[1], cos_g);
    assert_float_equal(mean[1], 0.6, 1e-3);
    assert_float_equal(cos_g, 2.0 / 3.0, 2e-3);
    assert_true(mean[0] < 0.6 * 0.9);
    shading_up(&sh, LM_MAT_GLOSSY, 0.6f);
    sh.ns[0] = (float)sin(40.0 * PI / 180.0), sh.ns[1] = (float)cos(40.0 * PI / 180.0);
    assert_true(lm_shading_for_bounce(&sh, &flat) == &sh);
}

static void test_diffuse_energy_and_cosine(void **state)
{
    (void)state;
    lm_shading sh;
    shading_up(&sh, LM_MAT_DIFFUSE, 0.6f);
    float wi[3] = {0.3f, -0.8f, 0.2f};
    lm_v3_store(wi, lm_normalize(lm_v3_load(wi)));
    double w = 0.0, c1 = 0.0, c2 = 0.0;
    const int n = 128;
    for (int i = 0; i < n * n; i++) {
        float u[3] = {(i % n + 0.5f) / n, (i / n + 0.5f) / n, 0.5f};
        lm_bsdf_sample_t bs;
        assert_true(lm_bsdf_sample(&sh, wi, u, &bs));
        assert_false(bs.specular);
        w += bs.weight[0];
        c1 += bs.wo[1];
        c2 += bs.wo[1] * bs.wo[1];
        /* consistency: weight = eval / pdf, eval = albedo / pi cos */
        float f[3];
        lm_bsdf_eval(&sh, wi, bs.wo, f);
        assert_float_equal(f[0], 0.6 / PI * bs.wo[1], 1e-5);
        assert_float_equal(f[0] / lm_bsdf_pdf(&sh, wi, bs.wo), bs.weight[0], 1e-4);
        /* reciprocity: f(wi -> wo) = f(-wo -> -wi) */
        float rwi[3] = {-bs.wo[0], -bs.wo[1], -bs.wo[2]}, rwo[3] = {-wi[0], -wi[1], -wi[2]}, g[3];
        lm_bsdf_eval(&sh, rwi, rwo, g);
        assert_float_equal(f[0] / bs.wo[1], g[0] / rwo[1], 1e-5);
    }
    assert_float_equal(w / (n * n), 0.6, 1e-5);
    assert_float_equal(c1 / (n * n), 2.0 / 3.0, 1e-3); /* cos-weighted: E[cos] = 2/3, E[cos^2] = 1/2 */
    assert_float_equal(c2 / (n * n), 0.5, 1e-3);
    assert_float_equal(lm_bsdf_survival(&sh), 0.6, 1e-5);
    sh.albedo[0] = sh.albedo[1] = sh.albedo[2] = 0.0f;
    assert_float_equal(lm_bsdf_survival(&sh), 0.05, 1e-6);
}

static void test_single_sided_back_absorbs(void **state)
{
    (void)state;
    lm_shading sh;
    shading_up(&sh, LM_MAT_DIFFUSE, 0.6f);
    float wi[3] = {0, 1, 0}, u[3] = {0.3f, 0.3f, 0.3f};
    lm_bsdf_sample_t bs;
    assert_false(lm_bsdf_sample(&sh, wi, u, &bs));
    g_mat.double_sided = 1;
    assert_true(lm_bsdf_sample(&sh, wi, u, &bs));
    assert_true(bs.wo[1] < 0.0f); /* scattered back to the side the ray came from */
}

static void test_glossy_energy_and_consistency(void **state)
{
    (void)state;
    lm_shading sh;
    shading_up(&sh, LM_MAT_GLOSSY, 0.9f);
    g_mat.metallic = 1.0f;
    float wi[3] = {0.5f, -0.8f, 0.0f};
    lm_v3_store(wi, lm_normalize(lm_v3_load(wi)));
    const int n = 256;
    double w = 0.0, ref = 0.0;
    for (int i = 0; i < n * n; i++) {
        float u[3] = {(i % n + 0.5f) / n, (i / n + 0.5f) / n, (i * 7919 % 1000 + 0.5f) / 1000};
        lm_bsdf_sample_t bs;
        if (lm_bsdf_sample(&sh, wi, u, &bs)) {
            w += bs.weight[0];
            float f[3];
            lm_bsdf_eval(&sh, wi, bs.wo, f);
            assert_float_equal(f[0] / lm_bsdf_pdf(&sh, wi, bs.wo), bs.weight[0], 1e-3 * bs.weight[0] + 1e-6);
        }
        /* the same integral with cosine-weighted directions: int f cos = E[f cos / (cos / pi)] */
        float c = sqrtf(1.0f - u[0]), s = sqrtf(u[0]), phi = 2.0f * (float)PI * u[1];
        float wo[3] = {s * cosf(phi), c, s * sinf(phi)}, f[3];
        lm_bsdf_eval(&sh, wi, wo, f);
        ref += f[0] * PI / c;
    }
    w /= n * n;
    ref /= n * n;
    assert_true(w <= 1.0 && w > 0.3);
    assert_float_equal(w, ref, 0.03 * ref);
}

/* What a lightmap turns irradiance into (kd / pi x E, docs/materials.md): the diffuse lobe of the BSDF the
 * photons and the reference use. Away from a sharp glossy lobe f = kd / pi exactly; kd and ks follow the
 * metallic mix; a diffuse surface's kd is its albedo, a mirror's nothing. */
static void test_lobes_diffuse_part(void **state)
{
    (void)state;
    lm_shading sh;
    shading_up(&sh, LM_MAT_GLOSSY, 0.5f);
    sh.albedo[1] = 0.6f, sh.albedo[2] = 0.7f;
    g_mat.metallic = 0.89f, g_mat.roughness = 0.15f;
    float kd[3], ks[3];
    lm_material_lobes(&g_mat, sh.albedo, kd, ks);
    for (int c = 0; c < 3; c++) {
        assert_float_equal(ks[c], 0.04f * 0.11f + 0.89f * sh.albedo[c], 1e-6);
        assert_float_equal(kd[c], sh.albedo[c] * 0.11f * (1.0f - ks[2]), 1e-6);
    }
    float wi[3] = {0.6f, -0.8f, 0.0f}, wo[3] = {0.0f, 0.6f, 0.8f}, f[3]; /* 64 degrees off the mirror */
    lm_bsdf_eval(&sh, wi, wo, f);
    for (int c = 0; c < 3; c++)
        assert_float_equal(f[c] / 0.6f, kd[c] / PI, 1e-6);
    g_mat.cls = LM_MAT_DIFFUSE;
    lm_material_lobes(&g_mat, sh.albedo, kd, ks);
    assert_true(kd[0] == 0.5f && kd[1] == 0.6f && kd[2] == 0.7f && ks[0] == 0.0f && ks[2] == 0.0f);
    g_mat.cls = LM_MAT_MIRROR;
    lm_material_lobes(&g_mat, sh.albedo, kd, ks);
    assert_true(kd[0] == 0.0f && ks[0] == 0.0f);
}

static void test_mirror_reflects_exactly(void **state)
{
    (void)state;
    lm_shading sh;
    shading_up(&sh, LM_MAT_MIRROR, 0.8f);
    float wi[3] = {0.6f, -0.8f, 0.0f}, u[3] = {0.1f, 0.2f, 0.3f};
    lm_bsdf_sample_t bs;
    assert_true(lm_bsdf_sample(&sh, wi, u, &bs));
    assert_true(bs.specular);
    assert_false(bs.transmitted);
    assert_float_equal(bs.wo[0], 0.6, 1e-6);
    assert_float_equal(bs.wo[1], 0.8, 1e-6);
    assert_float_equal(bs.wo[2], 0.0, 1e-6);
    /* a metal's Fresnel (Schlick's, F0 the albedo): cos 0.8, 0.8 + 0.2 (1 - 0.8)^5 */
    assert_float_equal(bs.weight[1], 0.8 + 0.2 * 0.00032, 1e-6);
    float grazing[3], face_on[3], albedo[3] = {0.8f, 0.5f, 0.2f};
    lm_mirror_fresnel(albedo, 0.0f, grazing);
    lm_mirror_fresnel(albedo, -1.0f, face_on);
    for (int c = 0; c < 3; c++) {
        assert_float_equal(grazing[c], 1.0, 1e-6);
        assert_float_equal(face_on[c], albedo[c], 1e-6);
    }
    float f[3];
    lm_bsdf_eval(&sh, wi, bs.wo, f);
    assert_float_equal(f[0], 0.0, 0.0);
    assert_float_equal(lm_bsdf_survival(&sh), 1.0, 0.0);
    assert_false(lm_material_stores_hits(LM_MAT_MIRROR));
    assert_false(lm_material_stores_hits(LM_MAT_GLASS));
    assert_true(lm_material_stores_hits(LM_MAT_DIFFUSE) && lm_material_stores_hits(LM_MAT_GLOSSY) &&
                lm_material_stores_hits(LM_MAT_EMITTER));
}

static void test_glass_fresnel_and_tir(void **state)
{
    (void)state;
    assert_float_equal(lm_fresnel_dielectric(1.0f, 1.0f, 1.5f), 0.04, 1e-6); /* ((n-1)/(n+1))^2 */
    assert_float_equal(lm_fresnel_dielectric(1.0f, 1.5f, 1.0f), 0.04, 1e-6);
    assert_float_equal(lm_fresnel_dielectric(0.0f, 1.0f, 1.5f), 1.0, 1e-6);   /* grazing */
    lm_shading sh;
    shading_up(&sh, LM_MAT_GLASS, 1.0f);
    /* entering at normal incidence: reflect with probability 0.04 */
    float wi[3] = {0, -1, 0};
    int refl = 0;
    for (int i = 0; i < 1000; i++) {
        lm_bsdf_sample_t bs;
        assert_true(lm_bsdf_sample(&sh, wi, (float[3]){(i + 0.5f) / 1000, 0.5f, 0.5f}, &bs));
        assert_true(bs.specular);
        refl += !bs.transmitted;
        if (bs.transmitted)
            assert_float_equal(bs.wo[1], -1.0, 1e-6);
    }
    assert_int_equal(refl, 40);
    /* entering at 60 degrees: Snell sin t = sin i / 1.5 */
    float s60 = sinf(60.0f * (float)PI / 180.0f), wi2[3] = {s60, -0.5f, 0};
    lm_bsdf_sample_t bs;
    assert_true(lm_bsdf_sample(&sh, wi2, (float[3]){0.999f, 0.5f, 0.5f}, &bs));
    assert_true(bs.transmitted);
    assert_float_equal(bs.wo[0], s60 / 1.5, 1e-5);
    /* leaving (wi along ng) beyond the critical angle asin(1/1.5) = 41.8 degrees: always reflected */
    float a = 50.0f * (float)PI / 180.0f, wi3[3] = {sinf(a), cosf(a), 0};
    for (int i = 0; i < 100; i++) {
        assert_true(lm_bsdf_sample(&sh, wi3, (float[3]){(i + 0.5f) / 100, 0.5f, 0.5f}, &bs));
        assert_false(bs.transmitted);
        assert_float_equal(bs.wo[1], -cosf(a), 1e-5); /* back inside */
    }
    /* leaving below the critical angle: transmits out with sin t = 1.5 sin i */
    float b = 20.0f * (float)PI / 180.0f, wi4[3] = {sinf(b), cosf(b), 0};
    assert_true(lm_bsdf_sample(&sh, wi4, (float[3]){0.999f, 0.5f, 0.5f}, &bs));
    assert_true(bs.transmitted);
    assert_float_equal(bs.wo[0], 1.5 * sinf(b), 1e-5);
    assert_true(bs.wo[1] > 0.0f);
}

static void test_phong_exponent(void **state)
{
    (void)state;
    assert_float_equal(lm_phong_exponent(1.0f), 1.0, 0.0);
    assert_float_equal(lm_phong_exponent(0.5f), 30.0, 1e-3);
    assert_float_equal(lm_phong_exponent(0.0f), 1e4, 0.0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_point_flux_and_emission),
        cmocka_unit_test(test_spot_flux_matches_integration),
        cmocka_unit_test(test_area_flux_and_emission),
        cmocka_unit_test(test_directional_flux),
        cmocka_unit_test(test_nee_point_light_irradiance),
        cmocka_unit_test(test_nee_point_light_range),
        cmocka_unit_test(test_nee_area_light_irradiance),
        cmocka_unit_test(test_shading_from_hit),
        cmocka_unit_test(test_shading_moved_node),
        cmocka_unit_test(test_hit_normals_follow_winding),
        cmocka_unit_test(test_static_shading_normals),
        cmocka_unit_test(test_photons_on_leaning_normals),
        cmocka_unit_test(test_diffuse_energy_and_cosine),
        cmocka_unit_test(test_single_sided_back_absorbs),
        cmocka_unit_test(test_glossy_energy_and_consistency),
        cmocka_unit_test(test_lobes_diffuse_part),
        cmocka_unit_test(test_mirror_reflects_exactly),
        cmocka_unit_test(test_glass_fresnel_and_tir),
        cmocka_unit_test(test_phong_exponent),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
