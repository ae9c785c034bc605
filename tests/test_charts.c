/* Tests of src/charts: surface segmentation, unwrapping, packing and the texel table, on hand-made
 * scenes and on the shared glTF scenes. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "../src/charts/atlas_dilate.h"
#include "../src/charts/charts.h"
#include "../src/core/log.h"
#include "../src/core/vecmath.h"
#include "support.h"

/* ---------- hand-made scenes ---------- */

enum { MAT_DIFFUSE = 0, MAT_MIRROR, MAT_RED, MAT_COUNT };

typedef struct {
    lm_scene s;
    uint32_t vcap, tcap;
} tscene;

static tscene *ts_new(int nodes)
{
    tscene *t = calloc(1, sizeof *t);
    lm_scene *s = &t->s;
    snprintf(s->path, sizeof s->path, "test-scene");
    s->node_count = nodes;
    s->nodes = calloc((size_t)nodes, sizeof *s->nodes);
    for (int i = 0; i < nodes; i++) {
        snprintf(s->nodes[i].name, LM_NAME_MAX, "node%d", i);
        s->nodes[i].parent = -1;
        s->nodes[i].mesh = i;
        lm_mat4_identity(s->nodes[i].world);
    }
    s->material_count = MAT_COUNT;
    s->materials = calloc(MAT_COUNT, sizeof *s->materials);
    s->materials[MAT_MIRROR].cls = LM_MAT_MIRROR;
    return t;
}

static void ts_free(tscene *t)
{
    /* lm_scene_free frees the struct itself, so hand it a heap copy of the embedded one. */
    lm_scene *s = malloc(sizeof *s);
    assert_non_null(s);
    *s = t->s;
    lm_scene_free(s);
    free(t);
}

static uint32_t ts_vertex(tscene *t, int node, float x, float y, float z, float nx, float ny, float nz)
{
    lm_scene *s = &t->s;
    if (s->vertex_count == t->vcap) {
        t->vcap = t->vcap ? 2 * t->vcap : 64;
        s->positions = realloc(s->positions, 3 * (size_t)t->vcap * sizeof(float));
        s->normals = realloc(s->normals, 3 * (size_t)t->vcap * sizeof(float));
        s->uv0 = realloc(s->uv0, 2 * (size_t)t->vcap * sizeof(float));
        s->vertex_node = realloc(s->vertex_node, (size_t)t->vcap * sizeof(uint32_t));
    }
    uint32_t v = s->vertex_count++;
    float p[3] = {x, y, z}, n[3] = {nx, ny, nz};
    memcpy(s->positions + 3 * v, p, sizeof p);
    memcpy(s->normals + 3 * v, n, sizeof n);
    s->uv0[2 * v] = s->uv0[2 * v + 1] = 0.0f;
    s->vertex_node[v] = (uint32_t)node;
    return v;
}

/* Triangles must be added node by node (each node's triangles contiguous). */
static void ts_tri(tscene *t, int node, int mat, uint32_t a, uint32_t b, uint32_t c)
{
    lm_scene *s = &t->s;
    if (s->tri_count == t->tcap) {
        t->tcap = t->tcap ? 2 * t->tcap : 64;
        s->tris = realloc(s->tris, 3 * (size_t)t->tcap * sizeof(uint32_t));
        s->tri_material = realloc(s->tri_material, (size_t)t->tcap * sizeof(int));
        s->tri_node = realloc(s->tri_node, (size_t)t->tcap * sizeof(uint32_t));
    }
    uint32_t i = s->tri_count++;
    s->tris[3 * i] = a;
    s->tris[3 * i + 1] = b;
    s->tris[3 * i + 2] = c;
    s->tri_material[i] = mat;
    s->tri_node[i] = (uint32_t)node;
    if (s->nodes[node].tri_count == 0)
        s->nodes[node].first_tri = i;
    s->nodes[node].tri_count++;
}

/* A quad p + a u + b v, (a, b) in [0,1]^2, split into nu x nv cells with its own (unshared) vertices;
 * height(x, z) displaces along the normal when given. */
static void ts_quad(tscene *t, int node, int mat, const float p[3], const float u[3], const float v[3], int nu,
                    int nv, float (*height)(float, float))
{
    lm_vec3 n = lm_normalize(lm_cross(lm_v3_load(u), lm_v3_load(v)));
    uint32_t base = t->s.vertex_count;
    for (int j = 0; j <= nv; j++)
        for (int i = 0; i <= nu; i++) {
            float a = (float)i / nu, b = (float)j / nv;
            float h = height ? height(a, b) : 0.0f;
            ts_vertex(t, node, p[0] + a * u[0] + b * v[0] + h * n.x, p[1] + a * u[1] + b * v[1] + h * n.y,
                      p[2] + a * u[2] + b * v[2] + h * n.z, n.x, n.y, n.z);
        }
    for (int j = 0; j < nv; j++)
        for (int i = 0; i < nu; i++) {
            uint32_t q = base + (uint32_t)(j * (nu + 1) + i);
            ts_tri(t, node, mat, q, q + 1, q + (uint32_t)nu + 2);
            ts_tri(t, node, mat, q, q + (uint32_t)nu + 2, q + (uint32_t)nu + 1);
        }
}

/* Axis-aligned box [lo, hi] with outward faces, skipping face `skip` (0..5: -x +x -y +y -z +z, -1 none). */
static void ts_box(tscene *t, int node, int mat, const float lo[3], const float hi[3], int skip, int cells)
{
    float d[3] = {hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]};
    for (int f = 0; f < 6; f++) {
        if (f == skip)
            continue;
        int ax = f / 2, a1 = (ax + 1) % 3, a2 = (ax + 2) % 3, pos = f & 1;
        float p[3] = {lo[0], lo[1], lo[2]}, u[3] = {0, 0, 0}, v[3] = {0, 0, 0};
        p[ax] = pos ? hi[ax] : lo[ax];
        /* u x v must point outward: +axis for the high face */
        if (pos) {
            u[a1] = d[a1];
            v[a2] = d[a2];
        } else {
            u[a2] = d[a2];
            v[a1] = d[a1];
        }
        ts_quad(t, node, mat, p, u, v, cells, cells, NULL);
    }
}

static void ts_sphere(tscene *t, int node, int mat, const float c[3], float r, int nu, int nv, int hemi)
{
    uint32_t base = t->s.vertex_count;
    float vmax = hemi ? 0.5f * (float)M_PI : (float)M_PI;
    for (int j = 0; j <= nv; j++)
        for (int i = 0; i <= nu; i++) {
            float th = vmax * j / nv, ph = 2.0f * (float)M_PI * i / nu;
            float n[3] = {sinf(th) * cosf(ph), cosf(th), sinf(th) * sinf(ph)};
            ts_vertex(t, node, c[0] + r * n[0], c[1] + r * n[1], c[2] + r * n[2], n[0], n[1], n[2]);
        }
    for (int j = 0; j < nv; j++)
        for (int i = 0; i < nu; i++) {
            uint32_t q = base + (uint32_t)(j * (nu + 1) + i), w = (uint32_t)nu + 1;
            if (j > 0)
                ts_tri(t, node, mat, q, q + 1, q + w);
            if (!(j == nv - 1 && !hemi))
                ts_tri(t, node, mat, q + 1, q + w + 1, q + w);
        }
}

static float bumps(float a, float b)
{
    return 0.03f * sinf(6.0f * (float)M_PI * a) * cosf(4.0f * (float)M_PI * b);
}

/* ---------- invariants ---------- */

typedef struct {
    double x, y, z;
} d3;

static d3 d3_sub(d3 a, d3 b) { return (d3){a.x - b.x, a.y - b.y, a.z - b.z}; }
static double d3_dot(d3 a, d3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static d3 d3_mad(d3 a, d3 b, double s) { return (d3){a.x + b.x * s, a.y + b.y * s, a.z + b.z * s}; }
static double d3_len(d3 a) { return sqrt(d3_dot(a, a)); }
static d3 d3_load(const float *p) { return (d3){p[0], p[1], p[2]}; }

/* Distance from p to triangle abc: closest point by Voronoi region (vertices, edges, face), in double. */
static double pt_tri_dist(const float *p, const float *a, const float *b, const float *c)
{
    d3 P = d3_load(p), A = d3_load(a), B = d3_load(b), C = d3_load(c);
    d3 ab = d3_sub(B, A), ac = d3_sub(C, A), ap = d3_sub(P, A), bp = d3_sub(P, B), cp = d3_sub(P, C);
    double d1 = d3_dot(ab, ap), d2 = d3_dot(ac, ap), d3v = d3_dot(ab, bp), d4 = d3_dot(ac, bp);
    double d5 = d3_dot(ab, cp), d6 = d3_dot(ac, cp);
    if (d1 <= 0 && d2 <= 0)
        return d3_len(ap);
    if (d3v >= 0 && d4 <= d3v)
        return d3_len(bp);
    if (d6 >= 0 && d5 <= d6)
        return d3_len(cp);
    double vc = d1 * d4 - d3v * d2, vb = d5 * d2 - d1 * d6, va = d3v * d6 - d5 * d4;
    if (vc <= 0 && d1 >= 0 && d3v <= 0)
        return d3_len(d3_sub(P, d3_mad(A, ab, d1 / (d1 - d3v))));
    if (vb <= 0 && d2 >= 0 && d6 <= 0)
        return d3_len(d3_sub(P, d3_mad(A, ac, d2 / (d2 - d6))));
    if (va <= 0 && d4 - d3v >= 0 && d5 - d6 >= 0)
        return d3_len(d3_sub(P, d3_mad(B, d3_sub(C, B), (d4 - d3v) / ((d4 - d3v) + (d5 - d6)))));
    double den = 1.0 / (va + vb + vc);
    return d3_len(d3_sub(P, d3_mad(d3_mad(A, ab, vb * den), ac, vc * den)));
}

static void world_vertex(const lm_scene *s, uint32_t v, float out[3])
{
    lm_v3_store(out, lm_mat4_point(s->nodes[s->vertex_node[v]].world, lm_v3_load(s->positions + 3 * (size_t)v)));
}

static double scene_size(const lm_scene *s)
{
    lm_vec3 lo = lm_v3(1e30f, 1e30f, 1e30f), hi = lm_scale(lo, -1.0f);
    for (uint32_t v = 0; v < s->vertex_count; v++) {
        float p[3];
        world_vertex(s, v, p);
        lo = lm_vmin(lo, lm_v3_load(p));
        hi = lm_vmax(hi, lm_v3_load(p));
    }
    return lm_length(lm_sub(hi, lo));
}

/* Rects disjoint, inside the atlas with a gutter border; every texel claimed once, inside its chart. */
static void check_rects(const lm_atlas *a, int *owner)
{
    for (size_t i = 0; i < (size_t)a->width * a->height; i++)
        owner[i] = -1;
    for (int c = 0; c < a->chart_count; c++) {
        const lm_chart *r = &a->charts[c];
        assert_true(r->x >= a->gutter && r->y >= a->gutter);
        assert_true(r->x + r->w <= a->width - a->gutter && r->y + r->h <= a->height - a->gutter);
        for (int y = r->y; y < r->y + r->h; y++)
            for (int x = r->x; x < r->x + r->w; x++) {
                assert_int_equal(owner[(size_t)y * a->width + x], -1);
                owner[(size_t)y * a->width + x] = c;
            }
    }
    for (uint32_t i = 0; i < a->texel_count; i++) {
        const lm_texel *t = &a->texels[i];
        assert_int_equal(a->texel_index[(size_t)t->y * a->width + t->x], (int)i);
        assert_int_equal(owner[(size_t)t->y * a->width + t->x], a->tri_chart[t->tri]);
    }
    uint32_t covered = 0;
    for (size_t i = 0; i < (size_t)a->width * a->height; i++)
        covered += a->texel_index[i] >= 0;
    assert_int_equal(covered, a->texel_count);
}

/* No covered texel of another chart within `gutter` texels (Chebyshev) of a covered texel. */
static void check_gutters(const lm_atlas *a)
{
    int g = a->gutter;
    for (uint32_t i = 0; i < a->texel_count; i++) {
        const lm_texel *t = &a->texels[i];
        int c = a->tri_chart[t->tri];
        for (int dy = -g; dy <= g; dy++)
            for (int dx = -g; dx <= g; dx++) {
                int x = t->x + dx, y = t->y + dy;
                assert_true(x >= 0 && y >= 0 && x < a->width && y < a->height);
                int j = a->texel_index[(size_t)y * a->width + x];
                if (j >= 0)
                    assert_int_equal(a->tri_chart[a->texels[j].tri], c);
            }
    }
}

static void check_corners(const lm_scene *s, const lm_surfaces *su, const lm_atlas *a)
{
    for (uint32_t t = 0; t < s->tri_count; t++) {
        int c = a->tri_chart[t];
        if (su->tri_surface[t] < 0) {
            assert_int_equal(c, -1);
            assert_true(isnan(a->corner_uv[6 * t]));
            continue;
        }
        assert_true(c >= 0 && c < a->chart_count);
        assert_int_equal(a->charts[c].surface, su->tri_surface[t]);
        const lm_chart *r = &a->charts[c];
        for (int k = 0; k < 3; k++) {
            double x = a->corner_uv[6 * t + 2 * k] * (double)a->width, y = a->corner_uv[6 * t + 2 * k + 1] * (double)a->height;
            double cx = a->coverage_uv[6 * t + 2 * k] * (double)a->width, cy = a->coverage_uv[6 * t + 2 * k + 1] * (double)a->height;
            double in = 0.5 - r->pad; /* a lookup reaches no further than half a texel into the border */
            assert_true(x >= r->x + in - 1e-3 && x <= r->x + r->w - in + 1e-3);
            assert_true(y >= r->y + in - 1e-3 && y <= r->y + r->h - in + 1e-3);
            assert_true(cx >= r->x - 1e-3 && cx <= r->x + r->w + 1e-3);
            assert_true(cy >= r->y - 1e-3 && cy <= r->y + r->h + 1e-3);
            if (r->w > 1 && r->h > 1) /* one texel: its corners all at its centre */
                assert_true(x == cx && y == cy);
        }
    }
}

/* Texel positions on their triangles; texel area per surface equals the surface's area. */
static void check_texels(const lm_scene *s, const lm_surfaces *su, const lm_atlas *a, double area_tol)
{
    double size = scene_size(s);
    double *sum = calloc((size_t)su->surface_count + 1, sizeof *sum);
    for (uint32_t i = 0; i < a->texel_count; i++) {
        const lm_texel *t = &a->texels[i];
        float p[3][3];
        for (int k = 0; k < 3; k++)
            world_vertex(s, s->tris[3 * t->tri + k], p[k]);
        double d = pt_tri_dist(t->pos, p[0], p[1], p[2]);
        if (d > 1e-5 * size)
            fail_msg("texel %u is %g from its triangle %u (size %g)", i, d, t->tri, size);
        assert_int_equal(t->surface, su->tri_surface[t->tri]);
        assert_true(fabsf(lm_length(lm_v3_load(t->normal)) - 1.0f) < 1e-3f);
        /* The local position and barycentrics name the same point. */
        const float *world = s->nodes[s->tri_node[t->tri]].world;
        lm_vec3 back = lm_mat4_point(world, lm_v3_load(t->local)), bp = lm_v3(0, 0, 0);
        assert_true(lm_length(lm_sub(back, lm_v3_load(t->pos))) <= 1e-5 * size);
        for (int k = 0; k < 3; k++)
            bp = lm_add(bp, lm_scale(lm_v3_load(p[k]), t->bary[k]));
        assert_true(lm_length(lm_sub(bp, lm_v3_load(t->pos))) <= 1e-5 * size);
        assert_float_equal(t->bary[0] + t->bary[1] + t->bary[2], 1.0f, 1e-5);
        sum[t->surface] += t->area;
    }
    for (int i = 0; i < su->surface_count; i++) {
        double rel = fabs(sum[i] - su->surfaces[i].area) / su->surfaces[i].area;
        if (rel > area_tol)
            fail_msg("surface %d: texel area %g vs surface area %g", i, sum[i], (double)su->surfaces[i].area);
    }
    free(sum);
}

static void check_atlas(const lm_scene *s, const lm_surfaces *su, const lm_atlas *a, double area_tol)
{
    assert_true(a->width > 0 && a->height > 0 && a->width % 4 == 0 && a->height % 4 == 0);
    int *owner = malloc((size_t)a->width * a->height * sizeof *owner);
    check_rects(a, owner);
    free(owner);
    check_gutters(a);
    check_corners(s, su, a);
    check_texels(s, su, a, area_tol);
    assert_int_equal(a->surface_count, su->surface_count);
    for (int i = 0; i < su->surface_count; i++) {
        int first = a->surface_first_chart[i], count = a->surface_chart_count[i];
        assert_true(count >= 1);
        for (int c = first; c < first + count; c++)
            assert_int_equal(a->charts[c].surface, i);
    }
    assert_true(a->utilization > 0.0f && a->utilization <= 1.0f);
}

/* Surfaces and atlas with default options, checked; returns the surface count. */
static int build_and_check(const lm_scene *s, double area_tol, lm_surfaces *su, lm_atlas *a)
{
    lm_error err = {0};
    assert_int_equal(lm_surfaces_build(s, NULL, su, &err), LM_OK);
    lm_atlas_options o;
    lm_atlas_options_default(&o);
    if (lm_atlas_build(s, su, &o, a, &err) != LM_OK)
        fail_msg("%s", err.msg);
    check_atlas(s, su, a, area_tol);
    return su->surface_count;
}

/* ---------- tests ---------- */

static void test_unit_cube(void **state)
{
    (void)state;
    tscene *t = ts_new(1);
    ts_box(t, 0, MAT_DIFFUSE, (float[3]){0, 0, 0}, (float[3]){1, 1, 1}, -1, 1);
    lm_surfaces su;
    lm_atlas a;
    assert_int_equal(build_and_check(&t->s, 1e-4, &su, &a), 6);
    assert_int_equal(a.chart_count, 6);
    assert_int_equal(su.nonmanifold_edges, 0);
    assert_int_equal(su.degenerate_tris, 0);
    for (int i = 0; i < 6; i++)
        assert_float_equal(su.surfaces[i].area, 1.0f, 1e-5f);
    lm_atlas_free(&a);
    lm_surfaces_free(&su);
    ts_free(t);
}

static void test_flat_grid(void **state)
{
    (void)state;
    tscene *t = ts_new(1);
    ts_quad(t, 0, MAT_DIFFUSE, (float[3]){-1, 0, 2}, (float[3]){0, 0, -3}, (float[3]){2, 0, 0}, 40, 40, NULL);
    lm_surfaces su;
    lm_atlas a;
    assert_int_equal(build_and_check(&t->s, 1e-4, &su, &a), 1);
    assert_int_equal(a.chart_count, 1);
    assert_int_equal(su.surfaces[0].tri_count, 3200);
    double sum = 0.0;
    for (uint32_t i = 0; i < a.texel_count; i++)
        sum += a.texels[i].area;
    assert_true(fabs(sum - 6.0) < 6.0 * 1e-4);
    /* about 64k texels by default, and a near-rectangular chart fills most of the atlas */
    assert_true(a.texel_count > 50000 && a.texel_count < 75000);
    assert_true(a.utilization > 0.7f);
    lm_atlas_free(&a);
    lm_surfaces_free(&su);
    ts_free(t);
}

static void test_bumpy_field(void **state)
{
    (void)state;
    tscene *t = ts_new(1);
    ts_quad(t, 0, MAT_DIFFUSE, (float[3]){0, 0, 1}, (float[3]){1, 0, 0}, (float[3]){0, 0, -1}, 60, 60, bumps);
    lm_surfaces su;
    lm_atlas a;
    assert_int_equal(build_and_check(&t->s, 1e-3, &su, &a), 1);
    assert_int_equal(a.chart_count, 1);
    lm_atlas_free(&a);
    lm_surfaces_free(&su);
    ts_free(t);
}

static void test_l_shape(void **state)
{
    (void)state;
    tscene *t = ts_new(1);
    ts_quad(t, 0, MAT_DIFFUSE, (float[3]){0, 0, 0}, (float[3]){1, 0, 0}, (float[3]){0, 0, -1}, 1, 1, NULL);
    ts_quad(t, 0, MAT_DIFFUSE, (float[3]){0, 0, -1}, (float[3]){1, 0, 0}, (float[3]){0, 1, 0}, 1, 1, NULL);
    lm_surfaces su;
    lm_atlas a;
    assert_int_equal(build_and_check(&t->s, 1e-4, &su, &a), 2);
    assert_int_equal(su.surfaces[0].tri_count, 2);
    assert_int_equal(su.surfaces[0].tris[0], 0);
    assert_float_equal(su.surfaces[0].normal[1], 1.0f, 1e-6f);
    assert_float_equal(su.surfaces[1].normal[2], 1.0f, 1e-6f);
    lm_atlas_free(&a);
    lm_surfaces_free(&su);
    ts_free(t);
}

/* Largest angle between a surface triangle's normal and its surface's mean normal, in degrees. */
static double worst_cone(const lm_scene *s, const lm_surfaces *su)
{
    double worst = 0.0;
    for (int i = 0; i < su->surface_count; i++) {
        const lm_surface *f = &su->surfaces[i];
        for (uint32_t k = 0; k < f->tri_count; k++) {
            const uint32_t *v = s->tris + 3 * f->tris[k];
            lm_vec3 p0 = lm_v3_load(s->positions + 3 * v[0]), p1 = lm_v3_load(s->positions + 3 * v[1]);
            lm_vec3 n = lm_normalize(lm_cross(lm_sub(p1, p0), lm_sub(lm_v3_load(s->positions + 3 * v[2]), p0)));
            worst = fmax(worst, acos(fmin(1.0, lm_dot(n, lm_v3_load(f->normal)))) * 180.0 / M_PI);
        }
    }
    return worst;
}

static void test_hemisphere(void **state)
{
    (void)state;
    tscene *t = ts_new(1);
    ts_sphere(t, 0, MAT_DIFFUSE, (float[3]){0, 0, 0}, 1.0f, 48, 24, 1);
    lm_surfaces su;
    lm_atlas a;
    int n = build_and_check(&t->s, 2e-3, &su, &a);
    double worst = worst_cone(&t->s, &su);
    print_message("hemisphere: %d surfaces, %d charts, worst angle to the surface normal %.1f deg\n", n,
                  a.chart_count, worst);
    assert_true(n >= 6 && n <= 30);
    /* merged tiny fragments may lean a little past the cone */
    assert_true(worst <= 35.0);
    lm_atlas_free(&a);
    lm_surfaces_free(&su);
    /* without fragment merging every triangle is within the cone of its surface's mean */
    lm_surface_options o;
    lm_surface_options_default(&o);
    o.min_fragment_area = 0.0f;
    lm_error err = {0};
    assert_int_equal(lm_surfaces_build(&t->s, &o, &su, &err), LM_OK);
    assert_true(worst_cone(&t->s, &su) <= 30.01);
    lm_surfaces_free(&su);
    ts_free(t);
}

/* A hexagonal column of radius r and height h at (cx, 0, 0) on `node`, its side faces' vertex normals
 * pointing straight out from its axis: they turn 60 degrees across each face, r wide, so 60 / r degrees a
 * unit. */
static void ts_column(tscene *t, int node, float cx, float r, float h)
{
    for (int k = 0; k < 6; k++) {
        uint32_t v[4];
        const double ang[4] = {LM_PI * k / 3, LM_PI * (k + 1) / 3, LM_PI * (k + 1) / 3, LM_PI * k / 3};
        for (int j = 0; j < 4; j++)
            v[j] = ts_vertex(t, node, cx + r * (float)cos(ang[j]), j < 2 ? 0.0f : h, -r * (float)sin(ang[j]),
                             (float)cos(ang[j]), 0.0f, (float)-sin(ang[j]));
        ts_tri(t, node, MAT_DIFFUSE, v[0], v[1], v[2]);
        ts_tri(t, node, MAT_DIFFUSE, v[0], v[2], v[3]);
    }
}

/* lm_atlas_options.bend_deg 15 at 0.2 per texel: a floor keeps the atlas's texels; a column of radius 0.5
 * and height 2, whose normals turn 120 degrees a unit (24 a texel), gets texels of 15 / 120 = 0.125; one
 * of radius 0.2 (60 degrees a texel: more than 2 x finer would need) keeps 0.2, and so does one of radius
 * 0.5 and height 0.4, whose faces (0.2 m^2) are under LM_BEND_MIN_TEXELS texels. With bend_deg 0 every
 * chart keeps 0.2. */
static void test_bending_normals_finer_texels(void **state)
{
    (void)state;
    tscene *t = ts_new(4);
    ts_quad(t, 0, MAT_DIFFUSE, (float[3]){-3, 0, 3}, (float[3]){0, 0, -6}, (float[3]){6, 0, 0}, 4, 4, NULL);
    ts_column(t, 1, -2.0f, 0.5f, 2.0f);
    ts_column(t, 2, 0.0f, 0.2f, 2.0f);
    ts_column(t, 3, 2.0f, 0.5f, 0.4f);
    lm_surfaces su;
    lm_error err = {0};
    assert_int_equal(lm_surfaces_build(&t->s, NULL, &su, &err), LM_OK);
    for (int bend = 0; bend < 2; bend++) {
        lm_atlas_options o;
        lm_atlas_options_default(&o);
        o.texel_size = 0.2f;
        o.bend_deg = bend ? 15.0f : 0.0f;
        lm_atlas a;
        if (lm_atlas_build(&t->s, &su, &o, &a, &err) != LM_OK)
            fail_msg("%s", err.msg);
        check_atlas(&t->s, &su, &a, 1e-4);
        int charts[4] = {0};
        for (int c = 0; c < a.chart_count; c++) {
            int node = su.surfaces[a.charts[c].surface].node;
            float want = bend && node == 1 ? 0.125f : 0.2f;
            assert_float_equal(a.charts[c].texel_size, want, 1e-4);
            charts[node]++;
        }
        print_message("bend_deg %g: %u texels; charts of the floor and the columns %d %d %d %d\n", (double)o.bend_deg,
                      a.texel_count, charts[0], charts[1], charts[2], charts[3]);
        assert_true(charts[1] >= 6 && charts[2] >= 6 && charts[3] >= 6);
        assert_int_equal(a.bent_surfaces, bend ? 6 : 0); /* the wide column's six faces */
        lm_atlas_free(&a);
    }
    lm_atlas_options o;
    lm_atlas_options_default(&o);
    o.bend_deg = -1.0f;
    lm_atlas a;
    assert_int_equal(lm_atlas_build(&t->s, &su, &o, &a, &err), LM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "bend_deg"));
    lm_surfaces_free(&su);
    ts_free(t);
}

/* A texel's shading normal is the mean over the triangles it covers, weighted by area, not the normal at its
 * centre: a hexagonal column whose vertex normals turn 60 degrees across each 0.5 m face, at 1 m texels (a
 * face in one texel), gets each face's texel facing straight out through the face's middle (the normal at
 * the centroid of one of its two triangles leaned 10 degrees off), and lm_texel_world turns it with the
 * node (a dynamic node's texels keep their mean). */
static void test_texel_normal_is_the_mean(void **state)
{
    (void)state;
    tscene *t = ts_new(1);
    ts_column(t, 0, 0.0f, 0.5f, 0.5f);
    lm_surfaces su;
    lm_error err = {0};
    assert_int_equal(lm_surfaces_build(&t->s, NULL, &su, &err), LM_OK);
    lm_atlas_options o;
    lm_atlas_options_default(&o);
    o.texel_size = 1.0f;
    lm_atlas a;
    if (lm_atlas_build(&t->s, &su, &o, &a, &err) != LM_OK)
        fail_msg("%s", err.msg);
    check_atlas(&t->s, &su, &a, 1e-4);
    const float turn[16] = {0, 0, -1, 0, 0, 1, 0, 0, 1, 0, 0, 0, 0, 0, 0, 1}; /* 90 degrees about y */
    double worst = 0.0, worst_turned = 0.0;
    for (uint32_t i = 0; i < a.texel_count; i++) {
        const lm_texel *x = &a.texels[i];
        double ang = atan2(-(double)x->pos[2], (double)x->pos[0]);
        ang = ang < 0.0 ? ang + 2.0 * LM_PI : ang;
        double mid = (floor(ang / (LM_PI / 3.0)) + 0.5) * LM_PI / 3.0; /* the face's middle */
        lm_vec3 want = lm_v3((float)cos(mid), 0.0f, (float)-sin(mid));
        worst = fmax(worst, acos(fmin(1.0, (double)lm_dot(lm_v3_load(x->normal), want))) * 180.0 / LM_PI);
        memcpy(t->s.nodes[0].world, turn, sizeof turn);
        float p[3], n[3];
        lm_texel_world(&t->s, x, p, n);
        lm_mat4_identity(t->s.nodes[0].world);
        lm_vec3 turned = lm_mat4_normal(turn, want);
        worst_turned = fmax(worst_turned, acos(fmin(1.0, (double)lm_dot(lm_v3_load(n), turned))) * 180.0 / LM_PI);
    }
    print_message("column at 1 m texels: %u texels, worst angle to the face's middle %.3f deg, turned %.3f deg\n",
                  a.texel_count, worst, worst_turned);
    assert_true(a.texel_count >= 6);
    assert_true(worst < 0.5);
    assert_true(worst_turned < 0.5);
    lm_atlas_free(&a);
    lm_surfaces_free(&su);
    ts_free(t);
}

/* The flawed scene still gets a valid atlas by default; strict mode refuses it, naming `what`.
 * Frees su and t. */
static void atlas_ok_then_strict_fails(tscene *t, lm_surfaces *su, const char *what)
{
    lm_error err = {0};
    lm_atlas a;
    assert_int_equal(lm_atlas_build(&t->s, su, NULL, &a, &err), LM_OK);
    check_atlas(&t->s, su, &a, 1e-4);
    lm_atlas_free(&a);
    lm_surfaces_free(su);
    lm_surface_options o;
    lm_surface_options_default(&o);
    o.strict = 1;
    assert_int_equal(lm_surfaces_build(&t->s, &o, su, &err), LM_ERR_INVALID);
    assert_non_null(strstr(err.msg, what));
    assert_null(su->surfaces);
    ts_free(t);
}

static void test_degenerate_and_strict(void **state)
{
    (void)state;
    tscene *t = ts_new(1);
    ts_quad(t, 0, MAT_DIFFUSE, (float[3]){0, 0, 0}, (float[3]){1, 0, 0}, (float[3]){0, 0, -1}, 2, 2, NULL);
    uint32_t a0 = ts_vertex(t, 0, 5, 0, 0, 0, 1, 0), a1 = ts_vertex(t, 0, 6, 0, 0, 0, 1, 0),
             a2 = ts_vertex(t, 0, 7, 0, 0, 0, 1, 0);
    ts_tri(t, 0, MAT_DIFFUSE, a0, a1, a2); /* collinear: zero area */
    lm_surfaces su;
    lm_error err = {0};
    lm_log_reset_warning_count();
    lm_log_set_level(LM_LOG_ERROR);
    assert_int_equal(lm_surfaces_build(&t->s, NULL, &su, &err), LM_OK);
    lm_log_set_level(LM_LOG_WARN);
    assert_int_equal(su.degenerate_tris, 1);
    assert_int_equal(su.tri_surface[t->s.tri_count - 1], -1);
    assert_int_equal(su.surface_count, 1);
    assert_true(lm_log_warning_count() >= 1);
    atlas_ok_then_strict_fails(t, &su, "node0");
}

static void test_nonmanifold_fin(void **state)
{
    (void)state;
    tscene *t = ts_new(1);
    /* three triangles on the edge (0,0,0)-(1,0,0) */
    uint32_t e0 = ts_vertex(t, 0, 0, 0, 0, 0, 1, 0), e1 = ts_vertex(t, 0, 1, 0, 0, 0, 1, 0);
    uint32_t p = ts_vertex(t, 0, 0.5f, 0, -1, 0, 1, 0), q = ts_vertex(t, 0, 0.5f, 0, 1, 0, 1, 0),
             r = ts_vertex(t, 0, 0.5f, 1, 0, 0, 0, 1);
    ts_tri(t, 0, MAT_DIFFUSE, e0, e1, p);
    ts_tri(t, 0, MAT_DIFFUSE, e1, e0, q);
    ts_tri(t, 0, MAT_DIFFUSE, e0, e1, r);
    lm_surfaces su;
    lm_error err = {0};
    lm_log_set_level(LM_LOG_ERROR);
    assert_int_equal(lm_surfaces_build(&t->s, NULL, &su, &err), LM_OK);
    lm_log_set_level(LM_LOG_WARN);
    assert_int_equal(su.nonmanifold_edges, 1);
    /* the fin is no neighbour of anything; the two flat ones are not joined across the bad edge */
    for (int k = 0; k < 9; k++)
        assert_int_equal(su.tri_adj[k], -1);
    atlas_ok_then_strict_fails(t, &su, "non-manifold");
}

/* Cornell box with a bumpy floor, a static block (5 faces), a dynamic cube and a mirror sphere. */
static tscene *bumpy_cornell(void)
{
    tscene *t = ts_new(4);
    float o[3] = {0, 0, 0};
    ts_quad(t, 0, MAT_DIFFUSE, (float[3]){0, 0, 1}, (float[3]){1, 0, 0}, (float[3]){0, 0, -1}, 80, 80, bumps);
    ts_quad(t, 0, MAT_DIFFUSE, (float[3]){0, 1, 0}, (float[3]){1, 0, 0}, (float[3]){0, 0, 1}, 1, 1, NULL);
    ts_quad(t, 0, MAT_DIFFUSE, o, (float[3]){1, 0, 0}, (float[3]){0, 1, 0}, 1, 1, NULL);
    ts_quad(t, 0, MAT_RED, o, (float[3]){0, 1, 0}, (float[3]){0, 0, 1}, 1, 1, NULL);
    ts_quad(t, 0, MAT_DIFFUSE, (float[3]){1, 0, 0}, (float[3]){0, 0, 1}, (float[3]){0, 1, 0}, 1, 1, NULL);
    ts_box(t, 1, MAT_DIFFUSE, (float[3]){0.15f, 0.0f, 0.2f}, (float[3]){0.45f, 0.6f, 0.5f}, 2, 2);
    ts_box(t, 2, MAT_DIFFUSE, (float[3]){-0.1f, -0.1f, -0.1f}, (float[3]){0.1f, 0.1f, 0.1f}, -1, 3);
    float tr[3] = {0.7f, 0.2f, 0.7f};
    lm_mat4_from_trs(t->s.nodes[2].world, tr, (float[4]){0, 0.3826834f, 0, 0.9238795f}, (float[3]){1, 1, 1});
    t->s.nodes[2].dynamic = 1;
    ts_sphere(t, 3, MAT_MIRROR, (float[3]){0.7f, 0.25f, 0.3f}, 0.15f, 32, 16, 0);
    return t;
}

static void test_bumpy_cornell(void **state)
{
    (void)state;
    tscene *t = bumpy_cornell();
    assert_true(t->s.tri_count > 13000);
    lm_surfaces su;
    lm_atlas a;
    assert_int_equal(build_and_check(&t->s, 2e-3, &su, &a), 16);
    for (uint32_t i = 0; i < t->s.tri_count; i++)
        if (t->s.tri_node[i] == 3)
            assert_int_equal(su.tri_surface[i], -1);
    assert_int_equal(su.nonmanifold_edges, 0);
    lm_atlas_free(&a);
    lm_surfaces_free(&su);
    ts_free(t);
}

static void test_deterministic(void **state)
{
    (void)state;
    tscene *t = bumpy_cornell();
    lm_surfaces s1, s2;
    lm_atlas a1, a2;
    lm_error err = {0};
    assert_int_equal(lm_surfaces_build(&t->s, NULL, &s1, &err), LM_OK);
    assert_int_equal(lm_surfaces_build(&t->s, NULL, &s2, &err), LM_OK);
    assert_memory_equal(s1.tri_surface, s2.tri_surface, t->s.tri_count * sizeof(int));
    assert_int_equal(lm_atlas_build(&t->s, &s1, NULL, &a1, &err), LM_OK);
    assert_int_equal(lm_atlas_build(&t->s, &s2, NULL, &a2, &err), LM_OK);
    assert_int_equal(a1.texel_count, a2.texel_count);
    assert_memory_equal(a1.texels, a2.texels, a1.texel_count * sizeof *a1.texels);
    assert_memory_equal(a1.corner_uv, a2.corner_uv, 6 * (size_t)t->s.tri_count * sizeof(float));
    lm_atlas_free(&a1);
    lm_atlas_free(&a2);
    lm_surfaces_free(&s1);
    lm_surfaces_free(&s2);
    ts_free(t);
}

/* Pages: each within the page side and a multiple of 4, the grid within LM_ATLAS_MAX_SIDE, every page
 * used; each chart with its border (and gutters) inside its page; each texel on its chart's page; each
 * corner's page UV its atlas UV moved into the page, in [0,1], and on one page the atlas UV to the bit. */
static void check_pages(const lm_scene *s, const lm_atlas *a, int side)
{
    assert_true(a->page_count >= 1 && a->page_width <= side && a->page_height <= side);
    assert_true(a->page_width % 4 == 0 && a->page_height % 4 == 0);
    assert_true(a->width <= LM_ATLAS_MAX_SIDE && a->height <= LM_ATLAS_MAX_SIDE);
    assert_int_equal(a->width, a->page_columns * a->page_width);
    assert_int_equal(a->height, (a->page_count + a->page_columns - 1) / a->page_columns * a->page_height);
    int *charts = calloc((size_t)a->page_count, sizeof *charts), g = a->gutter;
    for (int c = 0; c < a->chart_count; c++) {
        const lm_chart *r = &a->charts[c];
        int x0, y0, x1, y1;
        assert_int_equal(lm_atlas_page_of(a, r->x - r->pad, r->y - r->pad, &x0, &y0), r->page);
        assert_int_equal(lm_atlas_page_of(a, r->x + r->w + r->pad - 1, r->y + r->h + r->pad - 1, &x1, &y1), r->page);
        assert_true(x0 >= g && y0 >= g && x1 < a->page_width - g && y1 < a->page_height - g);
        charts[r->page]++;
    }
    for (int p = 0; p < a->page_count; p++)
        assert_true(charts[p] > 0);
    free(charts);
    for (uint32_t i = 0; i < a->texel_count; i++)
        assert_int_equal(lm_atlas_page_of(a, a->texels[i].x, a->texels[i].y, NULL, NULL),
                         a->charts[a->tri_chart[a->texels[i].tri]].page);
    for (uint32_t t = 0; t < s->tri_count; t++) {
        int p = lm_atlas_tri_page(a, t), rect[4];
        if (p < 0)
            continue;
        lm_atlas_page_rect(a, p, rect);
        for (int k = 0; k < 3; k++) {
            const float *uv = a->corner_uv + 6 * (size_t)t + 2 * k;
            float in[2];
            lm_atlas_page_uv(a, p, uv, in);
            assert_true(in[0] >= 0.0f && in[0] <= 1.0f && in[1] >= 0.0f && in[1] <= 1.0f);
            assert_float_equal(rect[0] + in[0] * rect[2], uv[0] * a->width, 1e-3);
            assert_float_equal(rect[1] + in[1] * rect[3], uv[1] * a->height, 1e-3);
            if (a->page_count == 1)
                assert_memory_equal(in, uv, sizeof in);
        }
    }
    assert_true(a->page_utilization > 0.0f && a->page_utilization <= 1.0f);
}

static void test_max_size_grows_texels(void **state)
{
    (void)state;
    tscene *t = ts_new(1);
    ts_box(t, 0, MAT_DIFFUSE, (float[3]){0, 0, 0}, (float[3]){1, 1, 1}, -1, 2);
    lm_surfaces su;
    lm_atlas a;
    lm_error err = {0};
    assert_int_equal(lm_surfaces_build(&t->s, NULL, &su, &err), LM_OK);
    lm_atlas_options o;
    lm_atlas_options_default(&o);
    o.texel_size = 0.001f;
    o.max_size = 256;
    lm_log_reset_warning_count();
    lm_log_set_level(LM_LOG_ERROR);
    assert_int_equal(lm_atlas_build(&t->s, &su, &o, &a, &err), LM_OK);
    lm_log_set_level(LM_LOG_WARN);
    /* max_size is a page's side: each 1000-texel face shrinks to one page (warned once), the six faces on
     * six pages side by side */
    assert_int_equal(lm_log_warning_count(), 1);
    assert_true(a.page_width <= 256 && a.page_height <= 256);
    assert_int_equal(a.page_count, 6);
    assert_true(a.texel_size > 0.001f);
    check_atlas(&t->s, &su, &a, 1e-4);
    check_pages(&t->s, &a, 256);
    lm_atlas_free(&a);
    o.texel_size = NAN;
    assert_int_equal(lm_atlas_build(&t->s, &su, &o, &a, &err), LM_ERR_INVALID);
    o.texel_size = 0.0f;
    o.use_file_uv1 = 1;
    assert_int_equal(lm_atlas_build(&t->s, &su, &o, &a, &err), LM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "TEXCOORD_1"));
    lm_surfaces_free(&su);
    ts_free(t);
}

static void test_default_texel_size(void **state)
{
    (void)state;
    tscene *t = ts_new(1);
    ts_quad(t, 0, MAT_DIFFUSE, (float[3]){0, 0, 0}, (float[3]){4, 0, 0}, (float[3]){0, 0, -4}, 1, 1, NULL);
    lm_surfaces su;
    lm_error err = {0};
    assert_int_equal(lm_surfaces_build(&t->s, NULL, &su, &err), LM_OK);
    assert_float_equal(lm_atlas_default_texel_size(&t->s, &su, 0), 4.0f / 256.0f, 1e-6f);
    assert_float_equal(lm_atlas_default_texel_size(&t->s, &su, 1600), 4.0f / 40.0f, 1e-6f);
    /* the atlas options' target: the 4 x 4 quad at 0.1 units a texel is 40 x 40 covered texels */
    lm_atlas_options o;
    lm_atlas_options_default(&o);
    assert_int_equal(o.target_texels, LM_ATLAS_DEFAULT_TEXELS);
    o.target_texels = 1600;
    lm_atlas a;
    assert_int_equal(lm_atlas_build(&t->s, &su, &o, &a, &err), LM_OK);
    assert_float_equal(a.texel_size, 0.1f, 1e-6f);
    assert_true(a.texel_count >= 1600 && a.texel_count <= 1700);
    lm_atlas_free(&a);
    o.target_texels = -1;
    assert_int_equal(lm_atlas_build(&t->s, &su, &o, &a, &err), LM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "target_texels"));
    lm_surfaces_free(&su);
    ts_free(t);
}

/* Bilinear lookups never mix two charts, though rects touch: every lookup at a point of a triangle
 * (its corner_uv) reads four texels of its own rect and border, and after lm_atlas_dilate_gutters each of
 * them holds that chart's id, covered or not. */
static void check_dilation(const lm_scene *s, const lm_atlas *a)
{
    size_t n = (size_t)a->width * a->height;
    float *data = calloc(n, sizeof *data);
    assert_non_null(data);
    for (size_t i = 0; i < n; i++)
        if (a->texel_index[i] >= 0)
            data[i] = (float)(a->tri_chart[a->texels[a->texel_index[i]].tri] + 1);
    lm_atlas_dilate_gutters(a, data, 1);
    static const double bary[][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0.5, 0.5, 0}, {0, 0.5, 0.5},
                                     {0.5, 0, 0.5}, {1.0 / 3, 1.0 / 3, 1.0 / 3}, {0.8, 0.1, 0.1}};
    for (uint32_t t = 0; t < s->tri_count; t++) {
        int c = a->tri_chart[t];
        if (c < 0)
            continue;
        const float *uv = a->corner_uv + 6 * (size_t)t;
        const lm_chart *r = &a->charts[c];
        for (size_t b = 0; b < sizeof bary / sizeof *bary; b++) {
            double x = (bary[b][0] * uv[0] + bary[b][1] * uv[2] + bary[b][2] * uv[4]) * a->width - 0.5;
            double y = (bary[b][0] * uv[1] + bary[b][1] * uv[3] + bary[b][2] * uv[5]) * a->height - 0.5;
            int x0 = (int)floor(x + 1e-4), y0 = (int)floor(y + 1e-4);
            int x1 = x - x0 > 1e-4 ? x0 + 1 : x0, y1 = y - y0 > 1e-4 ? y0 + 1 : y0; /* weight 0: not read */
            if (x0 < r->x - r->pad || y0 < r->y - r->pad || x1 >= r->x + r->w + r->pad || y1 >= r->y + r->h + r->pad)
                fail_msg("triangle %u: a lookup at (%g, %g) reads outside its chart %d's rect", t, x, y, c);
            for (int yy = y0; yy <= y1; yy++)
                for (int xx = x0; xx <= x1; xx++)
                    if (data[(size_t)yy * a->width + xx] != (float)(c + 1))
                        fail_msg("texel (%d,%d) read by chart %d holds %g", xx, yy, c + 1,
                                 (double)data[(size_t)yy * a->width + xx]);
        }
    }
    free(data);
}

/* t's surfaces and atlas at texel size ts on pages of `side` texels. */
static void build_paged(tscene *t, float ts, int side, lm_surfaces *su, lm_atlas *a)
{
    lm_error err = {0};
    assert_int_equal(lm_surfaces_build(&t->s, NULL, su, &err), LM_OK);
    lm_atlas_options o;
    lm_atlas_options_default(&o);
    o.texel_size = ts;
    o.max_size = side;
    if (lm_atlas_build(&t->s, su, &o, a, &err) != LM_OK)
        fail_msg("%s", err.msg);
}

/* Boxes of 1 m, each its own node, at 0.1 m texels: six faces of 13 x 13 texels with their borders, two
 * boxes to a page of 64 texels, so that 24 take 12 pages. Every node's charts share a page (a node smaller than a page is never split); the pages
 * are used about as well as one atlas would be; lookups stay in their charts across the pages' edges; a
 * level that fits one page has one page. */
static void test_pages(void **state)
{
    (void)state;
    enum { BOXES = 24 };
    tscene *t = ts_new(BOXES);
    for (int i = 0; i < BOXES; i++) {
        float lo[3] = {2.0f * (i % 6), 0.0f, 2.0f * (i / 6)}, hi[3] = {lo[0] + 1.0f, 1.0f, lo[2] + 1.0f};
        ts_box(t, i, MAT_DIFFUSE, lo, hi, -1, 2);
    }
    lm_surfaces su;
    lm_atlas a;
    build_paged(t, 0.1f, 64, &su, &a);
    print_message("%d boxes at 0.1 texels, pages of 64: %d pages of %dx%d in a %dx%d atlas, %u texels, %.1f%% of "
                  "the pages used\n", BOXES, a.page_count, a.page_width, a.page_height, a.width, a.height,
                  a.texel_count, 100.0 * a.page_utilization);
    assert_float_equal(a.texel_size, 0.1f, 1e-6f); /* pages, not a coarser texel */
    assert_int_equal(a.page_count, 12);
    check_atlas(&t->s, &su, &a, 1e-4);
    check_pages(&t->s, &a, 64);
    check_dilation(&t->s, &a);
    for (int c = 1; c < a.chart_count; c++) {
        int node = su.surfaces[a.charts[c].surface].node;
        for (int d = 0; d < c; d++)
            if (su.surfaces[a.charts[d].surface].node == node)
                assert_int_equal(a.charts[d].page, a.charts[c].page);
    }
    assert_true(a.page_utilization > 0.5f);
    lm_atlas_free(&a);
    lm_surfaces_free(&su);
    build_paged(t, 0.1f, 8192, &su, &a); /* the same level on one page */
    assert_int_equal(a.page_count, 1);
    assert_int_equal(a.page_width, a.width);
    assert_int_equal(a.page_height, a.height);
    check_pages(&t->s, &a, 8192);
    lm_atlas_free(&a);
    lm_surfaces_free(&su);
    ts_free(t);
}

/* A node larger than a page is split by surface: a box of 5 m faces at 0.1 m texels, 52 texels a face
 * with its border, takes one page of 64 for each face, each face whole on its page. A page side outside
 * [4 (gutter + 1), 65536] is refused, naming max_size. */
static void test_pages_split_a_large_node(void **state)
{
    (void)state;
    tscene *t = ts_new(1);
    ts_box(t, 0, MAT_DIFFUSE, (float[3]){0, 0, 0}, (float[3]){5, 5, 5}, -1, 2);
    lm_surfaces su;
    lm_atlas a;
    build_paged(t, 0.1f, 64, &su, &a);
    assert_int_equal(su.surface_count, 6);
    assert_int_equal(a.page_count, 6);
    check_atlas(&t->s, &su, &a, 1e-4);
    check_pages(&t->s, &a, 64);
    for (int f = 0; f < su.surface_count; f++)
        for (int c = a.surface_first_chart[f]; c < a.surface_first_chart[f] + a.surface_chart_count[f]; c++)
            assert_int_equal(a.charts[c].page, a.charts[a.surface_first_chart[f]].page);
    lm_atlas_free(&a);
    lm_atlas_options o;
    lm_atlas_options_default(&o);
    lm_error err = {0};
    static const int bad[] = {3, 65537};
    for (int i = 0; i < 2; i++) {
        o.max_size = bad[i];
        assert_int_equal(lm_atlas_build(&t->s, &su, &o, &a, &err), LM_ERR_INVALID);
        assert_non_null(strstr(err.msg, "max_size"));
    }
    lm_surfaces_free(&su);
    ts_free(t);
}

/* ---------- shared scenes ---------- */

static void shared_scene(const char *rel, int expect_surfaces, int uv1)
{
    LMT_REQUIRE_SCENE(path, lmt_shared_scene(rel));
    lm_scene *s = NULL;
    lm_error err = {0};
    lm_load_options lo = {0};
    if (lm_scene_load_gltf(path, &lo, &s, &err) != LM_OK)
        fail_msg("%s", err.msg);
    lm_surfaces su;
    lm_atlas a;
    lm_log_set_level(LM_LOG_ERROR);
    int n = build_and_check(s, 0.02, &su, &a);
    lm_log_set_level(LM_LOG_WARN);
    print_message("%s: %u triangles, %d surfaces, %d charts, atlas %dx%d, utilization %.2f\n", rel, s->tri_count, n,
                  a.chart_count, a.width, a.height, (double)a.utilization);
    if (expect_surfaces >= 0)
        assert_int_equal(n, expect_surfaces);
    check_dilation(s, &a);
    lm_atlas_free(&a);
    if (uv1) {
        lm_atlas_options o;
        lm_atlas_options_default(&o);
        o.use_file_uv1 = 1;
        if (lm_atlas_build(s, &su, &o, &a, &err) != LM_OK)
            fail_msg("%s", err.msg);
        check_atlas(s, &su, &a, 0.02);
        assert_int_equal(a.chart_count, n);
        lm_atlas_free(&a);
    }
    lm_surfaces_free(&su);
    lm_scene_free(s);
}

/* 5 walls + 6 faces of each box + the light quad, and the back sides of the walls and the light (all
 * double-sided; the boxes are closed, so theirs are not split). */
static void test_cornell_box(void **state)
{
    (void)state;
    shared_scene("cornell-box/CornellBox.glb", 24, 1);
}

static void test_room(void **state)
{
    (void)state;
    shared_scene("room/IrradianceVolumeExample.glb", -1, 0);
}

static void test_depth_of_field(void **state)
{
    (void)state;
    shared_scene("depth-of-field/DepthOfFieldExample.glb", -1, 0);
}

static void test_mixed_lighting(void **state)
{
    (void)state;
    shared_scene("mixed-lighting/MixedLightingExample.gltf", -1, 0);
}

static void test_cornell_suzanne(void **state)
{
    (void)state;
    shared_scene("cornell-suzanne/cornellBox-2.80-Eevee-gltf.gltf", -1, 0);
}

/* Where a chart of several texels turns (a hemisphere of radius 1 at 0.5 m texels, its 30-degree surfaces
 * 2 to 3 texels across), each texel whose interpolated normals spread past LM_FOOTPRINT_SPREAD is gathered
 * at its quarters: 2 to 4 points, each inside its own quarter of the texel's square (its uv through its
 * triangle's coverage uv), their areas summing to the texel's. A flat floor of the same texels has none. */
static void test_quarter_footprints(void **state)
{
    (void)state;
    tscene *t = ts_new(2);
    ts_sphere(t, 0, MAT_DIFFUSE, (float[3]){0, 0, 0}, 1.0f, 16, 8, 1);
    ts_quad(t, 1, MAT_DIFFUSE, (float[3]){-1, -0.5f, 1}, (float[3]){2, 0, 0}, (float[3]){0, 0, -2}, 4, 4, NULL);
    lm_surfaces su;
    lm_error err = {0};
    assert_int_equal(lm_surfaces_build(&t->s, NULL, &su, &err), LM_OK);
    lm_atlas_options o;
    lm_atlas_options_default(&o);
    o.texel_size = 0.5f;
    o.bend_deg = 0.0f;
    lm_atlas a;
    if (lm_atlas_build(&t->s, &su, &o, &a, &err) != LM_OK)
        fail_msg("%s", err.msg);
    int quartered = 0, multi = 0;
    for (uint32_t i = 0; i < a.texel_count; i++) {
        const lm_texel *tx = &a.texels[i], *pts;
        const lm_chart *ch = &a.charts[a.chart_owner[(size_t)tx->y * a.width + tx->x]];
        uint32_t n = lm_texel_footprint(&a, i, &pts);
        int node = t->s.tri_node[tx->tri];
        if (node == 1) { /* the floor */
            assert_int_equal(n, 0);
            continue;
        }
        multi += ch->w > 1 || ch->h > 1;
        if (n == 0 || (ch->w == 1 && ch->h == 1))
            continue;
        assert_true(n >= 2 && n <= 4);
        assert_false(lm_texel_turns(&a, i)); /* its chart is not that texel alone */
        int seen[4] = {0};
        double area = 0.0;
        for (uint32_t k = 0; k < n; k++) {
            const float *uv = a.coverage_uv + 6 * (size_t)pts[k].tri;
            double u = 0.0, v = 0.0;
            for (int c = 0; c < 3; c++)
                u += pts[k].bary[c] * uv[2 * c] * a.width, v += pts[k].bary[c] * uv[2 * c + 1] * a.height;
            assert_true(u >= tx->x - 1e-3 && u <= tx->x + 1 + 1e-3 && v >= tx->y - 1e-3 && v <= tx->y + 1 + 1e-3);
            int q = (v - tx->y >= 0.5) * 2 + (u - tx->x >= 0.5);
            assert_int_equal(seen[q], 0);
            seen[q] = 1;
            area += pts[k].area;
            assert_int_equal(pts[k].surface, tx->surface);
        }
        assert_true(fabs(area / tx->area - 1.0) < 1e-3);
        quartered++;
    }
    print_message("hemisphere at 0.5 m texels: %d texels on charts of several, %d of them at their quarters\n", multi,
                  quartered);
    assert_true(quartered >= 8);
    lm_atlas_free(&a);
    lm_surfaces_free(&su);
    ts_free(t);
}

/* lm_footprint_turn: light that is a plane over the normals, E = a + g . n, comes back as that plane within
 * the ridge's shrink (1% of the normals' spread, which lies in two directions here: 2% of each); a channel
 * of 0, two points with one normal, one point: no turn. */
static void test_footprint_turn_fit(void **state)
{
    (void)state;
    const float n[4][3] = {{0.9f, 0.3f, 0.3f}, {0.9f, -0.3f, 0.3f}, {0.9f, 0.3f, -0.3f}, {0.9f, -0.3f, -0.3f}};
    const double a[3] = {2.0, 1.0, 0.5}, g[3][3] = {{0.0, 1.2, 0.0}, {0.0, 0.4, -0.6}, {0.0, 0.0, 0.0}};
    float e[4][3], turn[LM_TURN_FLOATS];
    for (int k = 0; k < 4; k++)
        for (int c = 0; c < 3; c++)
            e[k][c] = (float)(a[c] + g[c][0] * n[k][0] + g[c][1] * n[k][1] + g[c][2] * n[k][2]);
    lm_footprint_turn(4, n, e, turn);
    for (int c = 0; c < 3; c++) {
        double mean = a[c] + g[c][0] * 0.9;
        for (int k = 0; k < 4; k++) { /* each point's own light from the mean and the turn */
            const float *r = turn + 4 * c;
            double got = mean * (1.0 + r[0] * n[k][0] + r[1] * n[k][1] + r[2] * n[k][2] - r[3]);
            assert_true(fabs(got - e[k][c]) < 0.021 * fabs(e[k][c] - mean) + 1e-6);
        }
        for (int i = 0; i < 3; i++)
            assert_true(fabs(turn[4 * c + i] * mean - g[c][i]) <= 0.021 * fabs(g[c][i]) + 1e-6);
    }
    for (int k = 0; k < 4; k++) /* blue is 0: no turn */
        e[k][2] = 0.0f;
    lm_footprint_turn(4, n, e, turn);
    for (int i = 8; i < 12; i++)
        assert_true(turn[i] == 0.0f);
    const float same[2][3] = {{0.0f, 1.0f, 0.0f}, {0.0f, 1.0f, 0.0f}};
    lm_footprint_turn(2, same, e, turn);
    for (int i = 0; i < LM_TURN_FLOATS; i++)
        assert_true(turn[i] == 0.0f);
    lm_footprint_turn(1, n, e, turn);
    for (int i = 0; i < LM_TURN_FLOATS; i++)
        assert_true(turn[i] == 0.0f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_unit_cube),
        cmocka_unit_test(test_flat_grid),
        cmocka_unit_test(test_bumpy_field),
        cmocka_unit_test(test_l_shape),
        cmocka_unit_test(test_hemisphere),
        cmocka_unit_test(test_bending_normals_finer_texels),
        cmocka_unit_test(test_texel_normal_is_the_mean),
        cmocka_unit_test(test_footprint_turn_fit),
        cmocka_unit_test(test_quarter_footprints),
        cmocka_unit_test(test_degenerate_and_strict),
        cmocka_unit_test(test_nonmanifold_fin),
        cmocka_unit_test(test_bumpy_cornell),
        cmocka_unit_test(test_deterministic),
        cmocka_unit_test(test_max_size_grows_texels),
        cmocka_unit_test(test_pages),
        cmocka_unit_test(test_pages_split_a_large_node),
        cmocka_unit_test(test_default_texel_size),
        cmocka_unit_test(test_cornell_box),
        cmocka_unit_test(test_room),
        cmocka_unit_test(test_depth_of_field),
        cmocka_unit_test(test_mixed_lighting),
        cmocka_unit_test(test_cornell_suzanne),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
