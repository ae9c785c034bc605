/* photonmap/aim: approximated illumination maps from hand-made photon stores on hand-made scenes:
 * the analytic point-light plane, uniform light up to the plane's borders and corners, hard cases,
 * the delta_f / area refresh schedule under a budget, and determinism. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <math.h>
#include <omp.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../src/charts/charts.h"
#include "../src/photonmap/aim.h"
#include "support.h"

#define PI_F 3.14159265f

typedef struct {
    lm_scene *s;
    lm_surfaces su;
    lm_atlas a;
} tscene;

static void ts_load(tscene *t, const lmt_mesh *meshes, int count, const char *nodes, float texel_size)
{
    char path[512];
    snprintf(path, sizeof path, "%s/aim.gltf", lmt_tmpdir());
    assert_int_equal(lmt_write_gltf(path, meshes, count, nodes, NULL, 0, NULL), 0);
    lm_error err;
    lm_load_options lo = {0};
    if (lm_scene_load_gltf(path, &lo, &t->s, &err) != LM_OK)
        fail_msg("load: %s", err.msg);
    for (int m = 0; m < t->s->material_count; m++) { /* albedo per channel, to check rho */
        t->s->materials[m].base_color[0] = 0.5f;
        t->s->materials[m].base_color[1] = 0.6f;
        t->s->materials[m].base_color[2] = 0.7f;
    }
    lm_surface_options so;
    lm_surface_options_default(&so);
    assert_int_equal(lm_surfaces_build(t->s, &so, &t->su, &err), LM_OK);
    lm_atlas_options ao;
    lm_atlas_options_default(&ao);
    ao.texel_size = texel_size;
    assert_int_equal(lm_atlas_build(t->s, &t->su, &ao, &t->a, &err), LM_OK);
}

static void ts_free(tscene *t)
{
    lm_atlas_free(&t->a);
    lm_surfaces_free(&t->su);
    lm_scene_free(t->s);
}

/* One horizontal square (y = 0, facing +y) per node: x in [cx - h, cx + h], z in [cz - h, cz + h]. */
static void square_mesh(lmt_mesh *m, float h)
{
    memset(m, 0, sizeof *m);
    float c[3] = {-h, 0, h}, u[3] = {2 * h, 0, 0}, v[3] = {0, 0, -2 * h};
    lmt_mesh_quad(m, c, u, v);
}

static uint64_t g_rng;
static float rnd(void)
{
    g_rng = g_rng * 6364136223846793005ull + 1442695040888963407ull;
    return (float)(g_rng >> 40) / 16777216.0f;
}

/* Point light of intensity I at lp: irradiance on the plane y = 0 (normal +y), E = I cos(theta) / d^2. */
static float point_E(const float lp[3], float I, float x, float z)
{
    float dx = x - lp[0], dy = -lp[1], dz = z - lp[2], d2 = dx * dx + dy * dy + dz * dz;
    return I * (lp[1] / sqrtf(d2)) / d2;
}

typedef float (*density_fn)(const float *param, float x, float z);

static float density_point(const float *p, float x, float z) { return point_E(p, p[3], x, z); }
static float density_const(const float *p, float x, float z)
{
    (void)x;
    (void)z;
    return p[0];
}

/* g x g jittered-stratified hits on the square [x0, x0 + w] x [z0, z0 + w] of surface `surface`, each
 * carrying flux E(x_i) * area / count, so the hits' flux density is E. Local = world (scale `scale`
 * maps local to world: local = world / scale). */
static void add_hits(lm_photon_store *ps, const tscene *t, int surface, float x0, float z0, float w, int g,
                     density_fn E, const float *param, float scale, const float from[3])
{
    float area = w * w;
    for (int j = 0; j < g; j++)
        for (int i = 0; i < g; i++) {
            float x = x0 + (i + rnd()) / g * w, z = z0 + (j + rnd()) / g * w;
            lm_hit h;
            memset(&h, 0, sizeof h);
            h.pos[0] = x;
            h.pos[2] = z;
            h.local[0] = x / scale;
            h.local[2] = z / scale;
            float d[3] = {x - from[0], -from[1], z - from[2]}, l = sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            for (int k = 0; k < 3; k++)
                h.dir[k] = d[k] / l;
            h.travelled = l; /* the photon left `from` */
            float phi = E(param, x, z) * area / (float)(g * g);
            h.flux[0] = h.flux[1] = h.flux[2] = phi;
            h.surface = surface;
            h.tri = t->su.surfaces[surface].tris[0];
            assert_true(lm_photon_store_add(ps, &h) != LM_NONE);
        }
}

static const float *aim_px(const lm_aim *aim, const lm_texel *tx)
{
    return lm_aim_rgb(aim) + 3 * ((size_t)tx->y * (size_t)aim->width + (size_t)tx->x);
}

static void init_aim(lm_aim *aim, const tscene *t, const lm_aim_settings *set)
{
    lm_error err;
    if (lm_aim_init(aim, t->s, &t->su, &t->a, set, &err) != LM_OK)
        fail_msg("aim init: %s", err.msg);
}

/* (a) A point light over a large plane: the AIM's radiance is rho / pi * E(x) within `worst_bound` away
 * from the plane's edges, `mean_bound` on average, with N = n (0: the default). */
static void point_light_plane(int n, double worst_bound, double mean_bound)
{
    lmt_mesh m;
    square_mesh(&m, 2.0f);
    tscene t;
    ts_load(&t, &m, 1, "[{\"name\": \"plane\", \"mesh\": 0}]", 0.05f);
    assert_int_equal(t.su.surface_count, 1);
    lm_photon_store ps;
    assert_int_equal(lm_photon_store_init(&ps, 1, NULL), LM_OK);
    const float light[4] = {0.3f, 1.5f, -0.2f, 10.0f};
    g_rng = 1;
    add_hits(&ps, &t, 0, -2.0f, -2.0f, 4.0f, 300, density_point, light, 1.0f, light);
    lm_aim aim;
    lm_aim_settings set;
    lm_aim_settings_default(&set);
    if (n)
        set.n_nearest = n;
    init_aim(&aim, &t, &set);
    lm_aim_stats st;
    assert_int_equal(lm_aim_refresh_all(&aim, t.s, &t.su, &t.a, &ps, &st, NULL), LM_OK);
    assert_int_equal(st.surfaces_refreshed, 1);
    assert_int_equal(st.texels_written, t.a.texel_count);
    assert_int_equal(st.hits_used, 300 * 300);
    double worst = 0.0, sum = 0.0;
    int checked = 0;
    const float rho[3] = {0.5f, 0.6f, 0.7f};
    for (uint32_t i = 0; i < t.a.texel_count; i++) {
        const lm_texel *tx = &t.a.texels[i];
        if (fabsf(tx->pos[0]) > 1.7f || fabsf(tx->pos[2]) > 1.7f)
            continue;
        float E = point_E(light, light[3], tx->pos[0], tx->pos[2]);
        for (int c = 0; c < 3; c++) {
            double want = rho[c] / PI_F * E, err = fabs(aim_px(&aim, tx)[c] - want) / want;
            worst = fmax(worst, err);
            sum += err;
        }
        checked++;
    }
    print_message("point light, N = %d: %d texels, mean error %.2f%%, worst %.2f%% (refresh of %u texels from %llu hits: "
                  "%.1f ms)\n", set.n_nearest, checked, 100.0 * sum / (3 * checked), 100.0 * worst, st.texels_written,
                  (unsigned long long)st.hits_used, 1e3 * st.seconds);
    assert_true(checked > 4000);
    assert_true(worst < worst_bound);
    assert_true(sum / (3 * checked) < mean_bound);
    assert_true(ps.surfaces[0].delta_f == 0.0);
    lm_aim_free(&aim);
    lm_photon_store_free(&ps);
    ts_free(&t);
}

/* N = 128 (the default until issue 15) within 5% everywhere; the default N = 32 has the noise of a quarter
 * of the hits (worst 11.5%, mean 2.4% when written), which the hemicube gather averages over many texels. */
static void test_point_light_plane(void **state)
{
    (void)state;
    point_light_plane(128, 0.05, 0.015);
    point_light_plane(0, 0.15, 0.03);
}

/* Interior mean and the worst deviation of any texel (edges and corners included) from it. */
static void uniform_check(const lm_aim *aim, const tscene *t, float half, float expect, double tol)
{
    double sum = 0.0, worst = 0.0, worst_corner = 0.0;
    int n = 0;
    for (uint32_t i = 0; i < t->a.texel_count; i++) {
        const lm_texel *tx = &t->a.texels[i];
        if (fabsf(tx->pos[0]) < 0.6f * half && fabsf(tx->pos[2]) < 0.6f * half) {
            sum += aim_px(aim, tx)[1];
            n++;
        }
    }
    double interior = sum / n;
    assert_true(fabs(interior - expect) / expect < 0.02);
    for (uint32_t i = 0; i < t->a.texel_count; i++) {
        const lm_texel *tx = &t->a.texels[i];
        double dev = fabs(aim_px(aim, tx)[1] - interior) / interior;
        worst = fmax(worst, dev);
        if (fabsf(tx->pos[0]) > half - t->a.texel_size && fabsf(tx->pos[2]) > half - t->a.texel_size)
            worst_corner = fmax(worst_corner, dev);
    }
    print_message("uniform: interior %.5f (expect %.5f), worst texel %.2f%%, worst corner %.2f%%\n", interior,
                  (double)expect, 100.0 * worst, 100.0 * worst_corner);
    assert_true(worst < tol);
}

/* (b) Uniform flux density: constant radiance, and texels on the plane's borders and corners are not
 * outliers against the interior (the disc's area is cut at the surface's boundary). Also under a
 * scaled node: distances are node-local, areas world. */
static void run_uniform(float scale, float texel)
{
    lmt_mesh m;
    square_mesh(&m, 1.0f);
    char nodes[128];
    snprintf(nodes, sizeof nodes, "[{\"name\": \"plane\", \"mesh\": 0, \"scale\": [%g, %g, %g]}]", (double)scale,
             (double)scale, (double)scale);
    tscene t;
    ts_load(&t, &m, 1, nodes, texel);
    lm_photon_store ps;
    assert_int_equal(lm_photon_store_init(&ps, 1, NULL), LM_OK);
    const float E[1] = {2.0f}, above[3] = {0.0f, 5.0f, 0.0f};
    g_rng = 7;
    add_hits(&ps, &t, 0, -scale, -scale, 2.0f * scale, 160, density_const, E, scale, above);
    lm_aim_settings set;
    lm_aim_settings_default(&set);
    set.n_nearest = 150;
    lm_aim aim;
    init_aim(&aim, &t, &set);
    assert_int_equal(lm_aim_refresh_all(&aim, t.s, &t.su, &t.a, &ps, NULL, NULL), LM_OK);
    uniform_check(&aim, &t, scale, 0.6f / PI_F * E[0], 0.05);
    lm_aim_free(&aim);
    lm_photon_store_free(&ps);
    ts_free(&t);
}

static void test_uniform_borders_and_corners(void **state)
{
    (void)state;
    run_uniform(1.0f, 0.025f);
    run_uniform(2.0f, 0.05f);
}

/* The square of square_mesh(h) as a g x g grid of quads sharing their vertices (g <= 5). */
static void grid_mesh(lmt_mesh *m, float h, int g)
{
    memset(m, 0, sizeof *m);
    for (int j = 0; j <= g; j++)
        for (int i = 0; i <= g; i++) {
            float *p = m->pos + 3 * m->vertex_count++;
            p[0] = -h + 2 * h * (float)i / (float)g;
            p[1] = 0.0f;
            p[2] = h - 2 * h * (float)j / (float)g;
        }
    for (int j = 0; j < g; j++)
        for (int i = 0; i < g; i++) {
            uint16_t a = (uint16_t)(j * (g + 1) + i), b = (uint16_t)(a + 1), c = (uint16_t)(b + g + 1),
                     d = (uint16_t)(a + g + 1);
            uint16_t t[6] = {a, b, c, a, c, d};
            memcpy(m->idx + m->index_count, t, sizeof t);
            m->index_count += 6;
        }
}

/* A plane tessellated into a grid: its 16 collinear boundary edges are joined into the square's 4, and
 * borders and corners still come out right. */
static void test_collinear_edges_joined(void **state)
{
    (void)state;
    lmt_mesh m;
    grid_mesh(&m, 1.0f, 4);
    tscene t;
    ts_load(&t, &m, 1, "[{\"name\": \"plane\", \"mesh\": 0}]", 0.025f);
    assert_int_equal(t.su.surface_count, 1);
    lm_photon_store ps;
    assert_int_equal(lm_photon_store_init(&ps, 1, NULL), LM_OK);
    const float E[1] = {2.0f}, above[3] = {0.0f, 5.0f, 0.0f};
    g_rng = 7;
    add_hits(&ps, &t, 0, -1.0f, -1.0f, 2.0f, 160, density_const, E, 1.0f, above);
    lm_aim_settings set;
    lm_aim_settings_default(&set);
    set.n_nearest = 150;
    lm_aim aim;
    init_aim(&aim, &t, &set);
    assert_int_equal(aim.edge_first[1] - aim.edge_first[0], 4);
    assert_int_equal(lm_aim_refresh_all(&aim, t.s, &t.su, &t.a, &ps, NULL, NULL), LM_OK);
    uniform_check(&aim, &t, 1.0f, 0.6f / PI_F * E[0], 0.05);
    lm_aim_free(&aim);
    lm_photon_store_free(&ps);
    ts_free(&t);
}

/* Without the boundary correction the corner texels are visibly dark: the correction is what keeps them
 * in line (guards against it silently doing nothing). */
static void test_boundary_correction_matters(void **state)
{
    (void)state;
    lmt_mesh m;
    square_mesh(&m, 1.0f);
    tscene t;
    ts_load(&t, &m, 1, "[{\"name\": \"plane\", \"mesh\": 0}]", 0.025f);
    lm_photon_store ps;
    assert_int_equal(lm_photon_store_init(&ps, 1, NULL), LM_OK);
    const float E[1] = {1.0f}, above[3] = {0.0f, 5.0f, 0.0f};
    g_rng = 3;
    add_hits(&ps, &t, 0, -1.0f, -1.0f, 2.0f, 100, density_const, E, 1.0f, above);
    lm_aim_settings set;
    lm_aim_settings_default(&set);
    set.boundary_correction = 0;
    lm_aim aim;
    init_aim(&aim, &t, &set);
    assert_int_equal(lm_aim_refresh_all(&aim, t.s, &t.su, &t.a, &ps, NULL, NULL), LM_OK);
    float lo = 1e30f;
    for (uint32_t i = 0; i < t.a.texel_count; i++)
        lo = fminf(lo, aim_px(&aim, &t.a.texels[i])[1]);
    assert_true(lo < 0.5f * 0.6f / PI_F * E[0]);
    lm_aim_free(&aim);
    lm_photon_store_free(&ps);
    ts_free(&t);
}

/* (c) Hard cases: no hits, fewer hits than N, all hits at one point, hits arriving from behind. */
static void test_hard_cases(void **state)
{
    (void)state;
    lmt_mesh m;
    square_mesh(&m, 1.0f);
    tscene t;
    ts_load(&t, &m, 1, "[{\"name\": \"plane\", \"mesh\": 0}]", 0.05f);
    lm_photon_store ps;
    assert_int_equal(lm_photon_store_init(&ps, 1, NULL), LM_OK);
    lm_aim_settings set;
    lm_aim_settings_default(&set);
    set.n_nearest = 50;
    lm_aim aim;
    init_aim(&aim, &t, &set);

    /* No hits: 0 everywhere (also in the gutters). */
    assert_int_equal(lm_aim_refresh_all(&aim, t.s, &t.su, &t.a, &ps, NULL, NULL), LM_OK);
    for (size_t i = 0; i < (size_t)aim.width * aim.height * 3; i++)
        assert_true(lm_aim_rgb(&aim)[i] == 0.0f);

    /* Three hits with N = 50: finite, positive, largest near them. */
    lm_hit h;
    memset(&h, 0, sizeof h);
    h.dir[1] = -1.0f;
    h.flux[0] = h.flux[1] = h.flux[2] = 1.0f;
    h.tri = t.su.surfaces[0].tris[0];
    uint32_t slots[3];
    for (int i = 0; i < 3; i++) {
        h.pos[0] = h.local[0] = 0.1f * (float)i;
        slots[i] = lm_photon_store_add(&ps, &h);
    }
    assert_int_equal(lm_aim_refresh_all(&aim, t.s, &t.su, &t.a, &ps, NULL, NULL), LM_OK);
    for (uint32_t i = 0; i < t.a.texel_count; i++) {
        const float *px = aim_px(&aim, &t.a.texels[i]);
        for (int c = 0; c < 3; c++)
            assert_true(isfinite(px[c]) && px[c] > 0.0f);
    }
    for (int i = 0; i < 3; i++)
        lm_photon_store_remove(&ps, slots[i]);

    /* 1000 hits at one point: bounded by the smallest radius, rho/pi * sum / (pi rmin^2 / 2) (the
     * Epanechnikov kernel's normalisation; its weight is at most 1). */
    h.pos[0] = h.local[0] = 0.013f;
    h.pos[2] = h.local[2] = -0.021f;
    for (int i = 0; i < 1000; i++)
        assert_true(lm_photon_store_add(&ps, &h) != LM_NONE);
    assert_int_equal(lm_aim_refresh_all(&aim, t.s, &t.su, &t.a, &ps, NULL, NULL), LM_OK);
    float rmin = t.a.texel_size, bound = 0.7f / PI_F * 1000.0f / (0.5f * PI_F * rmin * rmin), top = 0.0f;
    for (uint32_t i = 0; i < t.a.texel_count; i++) {
        const float *px = aim_px(&aim, &t.a.texels[i]);
        for (int c = 0; c < 3; c++)
            assert_true(isfinite(px[c]) && px[c] >= 0.0f);
        top = fmaxf(top, px[2]);
    }
    assert_true(top > 0.25f * bound && top <= bound * 1.001f);

    /* The same hits arriving from below a single-sided plane are not counted; double-sided, they are. */
    for (uint32_t i = 0; i < ps.used; i++)
        if (ps.hits[i].surface >= 0)
            ps.hits[i].dir[1] = 1.0f;
    assert_int_equal(lm_aim_refresh_all(&aim, t.s, &t.su, &t.a, &ps, NULL, NULL), LM_OK);
    for (uint32_t i = 0; i < t.a.texel_count; i++)
        assert_true(aim_px(&aim, &t.a.texels[i])[0] == 0.0f);
    t.s->materials[t.s->tri_material[h.tri]].double_sided = 1;
    assert_int_equal(lm_aim_refresh_all(&aim, t.s, &t.su, &t.a, &ps, NULL, NULL), LM_OK);
    top = 0.0f;
    for (uint32_t i = 0; i < t.a.texel_count; i++)
        top = fmaxf(top, aim_px(&aim, &t.a.texels[i])[2]);
    assert_true(top > 0.25f * bound && top <= bound * 1.001f);

    lm_aim_free(&aim);
    lm_photon_store_free(&ps);
    ts_free(&t);
}

/* Three squares of areas 1, 4 and 9 as separate surfaces. */
static void load_three(tscene *t)
{
    static lmt_mesh m[3];
    square_mesh(&m[0], 0.5f);
    square_mesh(&m[1], 1.0f);
    square_mesh(&m[2], 1.5f);
    ts_load(t, m, 3,
            "[{\"name\": \"root\", \"children\": [1, 2, 3]}, {\"name\": \"a\", \"mesh\": 0, \"translation\": [-5, 0, 0]},"
            " {\"name\": \"b\", \"mesh\": 1}, {\"name\": \"c\", \"mesh\": 2, \"translation\": [6, 0, 0]}]",
            0.1f);
    assert_int_equal(t->su.surface_count, 3);
}

/* Surface of node `name`. */
static int surface_of(const tscene *t, const char *name)
{
    for (int i = 0; i < t->su.surface_count; i++)
        if (!strcmp(t->s->nodes[t->su.surfaces[i].node].name, name))
            return i;
    fail_msg("no surface for node %s", name);
    return -1;
}

static void add_uniform(lm_photon_store *ps, const tscene *t, int surface, float offset_x, float half, int g)
{
    const float E[1] = {1.0f}, above[3] = {offset_x, 5.0f, 0.0f};
    add_hits(ps, t, surface, offset_x - half, -half, 2.0f * half, g, density_const, E, 1.0f, above);
}

/* Snapshot of one surface's texels. */
static float *snapshot(const lm_aim *aim, const tscene *t, int surface, uint32_t *count)
{
    uint32_t first = aim->texel_first[surface], end = aim->texel_first[surface + 1];
    float *v = malloc(sizeof *v * 3 * (end - first));
    assert_non_null(v);
    for (uint32_t i = first; i < end; i++)
        memcpy(v + 3 * (i - first), aim_px(aim, &t->a.texels[aim->texel_list[i]]), 3 * sizeof *v);
    *count = 3 * (end - first);
    return v;
}

/* A wall 0.5 high standing on the plane along x = 0, lit by a point light at (-1, 1, 0): the plane is in
 * its shadow for 0 < x < 1, and no photon lands there. */
#define WALL_LIGHT_X -1.0f
static float density_beside_wall(const float *p, float x, float z)
{
    return x > 0.0f && x < 1.0f ? 0.0f : point_E(p, p[3], x, z);
}

/* The AIM of the plane beside the wall with and without the visibility test (aim_sight.h): every texel
 * centre of the plane (x, z) into xz and its radiance into rgb; returns the texel count. */
static uint32_t aim_beside_wall(int occluders, int threads, float **xz_out, float **rgb_out)
{
    static lmt_mesh m[2];
    square_mesh(&m[0], 2.0f);
    memset(&m[1], 0, sizeof m[1]);
    const float c[3] = {0.0f, 0.0f, 2.0f}, u[3] = {0.0f, 0.0f, -4.0f}, v[3] = {0.0f, 0.5f, 0.0f};
    lmt_mesh_quad(&m[1], c, u, v);
    tscene t;
    ts_load(&t, m, 2, "[{\"name\": \"root\", \"children\": [1, 2]}, {\"name\": \"plane\", \"mesh\": 0},"
                      " {\"name\": \"wall\", \"mesh\": 1}]", 0.05f);
    int plane = surface_of(&t, "plane");
    lm_photon_store ps;
    assert_int_equal(lm_photon_store_init(&ps, t.su.surface_count, NULL), LM_OK);
    const float light[4] = {WALL_LIGHT_X, 1.0f, 0.0f, 10.0f};
    g_rng = 7;
    add_hits(&ps, &t, plane, -2.0f, -2.0f, 4.0f, 300, density_beside_wall, light, 1.0f, light);
    lm_rt *rt = NULL;
    lm_error err;
    assert_int_equal(lm_rt_build(t.s, &t.su, &rt, &err), LM_OK);
    lm_aim aim;
    lm_aim_settings set;
    lm_aim_settings_default(&set);
    init_aim(&aim, &t, &set);
    if (occluders)
        lm_aim_set_occluders(&aim, rt, 1e-4f * 4.0f, 0.05f, NULL);
    int before = omp_get_max_threads();
    omp_set_num_threads(threads);
    assert_int_equal(lm_aim_refresh_all(&aim, t.s, &t.su, &t.a, &ps, NULL, NULL), LM_OK);
    omp_set_num_threads(before);
    uint32_t first = aim.texel_first[plane], n = aim.texel_first[plane + 1] - first;
    float *xz = malloc(sizeof *xz * 2 * n), *rgb = malloc(sizeof *rgb * 3 * n);
    assert_true(xz && rgb);
    for (uint32_t i = 0; i < n; i++) {
        const lm_texel *tx = &t.a.texels[aim.texel_list[first + i]];
        xz[2 * i] = tx->pos[0];
        xz[2 * i + 1] = tx->pos[2];
        memcpy(rgb + 3 * i, aim_px(&aim, tx), 3 * sizeof *rgb);
    }
    *xz_out = xz;
    *rgb_out = rgb;
    lm_aim_free(&aim);
    lm_rt_free(rt);
    lm_photon_store_free(&ps);
    ts_free(&t);
    return n;
}

/* The visibility test (issue 33, item 1): photons that landed beside the wall's shadow no longer light the
 * texels inside it, and the texels beside the shadow and beside the wall, whose discs reach where no photon
 * lands, read the light they see instead of its share of the disc. Away from both the estimate is the
 * paper's. The same bits on 1 and 2 threads. */
static void test_occluders_keep_shadow_edges(void **state)
{
    (void)state;
    float *p0, *v0, *p1, *v1, *p2, *v2;
    uint32_t n = aim_beside_wall(0, 2, &p0, &v0);
    assert_int_equal(aim_beside_wall(1, 2, &p1, &v1), n);
    assert_int_equal(aim_beside_wall(1, 1, &p2, &v2), n);
    assert_memory_equal(v1, v2, sizeof *v1 * 3 * n);
    const float light[4] = {WALL_LIGHT_X, 1.0f, 0.0f, 10.0f}, rho = 0.5f;
    double shadow_max[2] = {0.0, 0.0}, edge_err[2] = {0.0, 0.0}, far_diff = 0.0;
    int edges = 0, shadowed = 0, far = 0;
    for (uint32_t i = 0; i < n; i++) {
        float x = p0[2 * i], z = p0[2 * i + 1], lit = rho / PI_F * point_E(light, light[3], x, z);
        const float *v[2] = {v0 + 3 * i, v1 + 3 * i};
        if (fabsf(z) > 1.8f)
            continue; /* the plane's own edges */
        if (x > 0.0f && x < 0.99f) { /* in the shadow (`lit`: what the light would give there) */
            for (int k = 0; k < 2; k++)
                shadow_max[k] = fmax(shadow_max[k], v[k][0] / lit);
            shadowed++;
        } else if (x > 0.99f && x < 1.01f) { /* lit, on the shadow's edge: half the disc has no hits */
            for (int k = 0; k < 2; k++)
                edge_err[k] += fabs(v[k][0] / lit - 1.0);
            edges++;
        } else if (x < -0.3f || x > 1.3f) {
            far_diff = fmax(far_diff, fabs(v[1][0] - v[0][0]) / v[0][0]);
            far++;
        }
    }
    print_message("beside a wall: in its shadow (%d texels) at most %.3f (paper's) / %.3f (tested) of the light "
                  "beside it; lit on the shadow's edge (%d texels) mean error %.1f%% / %.1f%%; elsewhere (%d) "
                  "at most %.2e apart\n", shadowed, shadow_max[0], shadow_max[1], edges, 100.0 * edge_err[0] / edges,
                  100.0 * edge_err[1] / edges, far, far_diff);
    assert_true(shadowed > 500 && edges > 50 && far > 2000);
    assert_true(shadow_max[0] > 0.2);  /* the paper's blurs light into the shadow ... */
    assert_true(shadow_max[1] == 0.0); /* ... the test keeps it out */
    assert_true(edge_err[0] / edges > 0.15);
    assert_true(edge_err[1] / edges < 0.12);
    assert_true(far_diff < 1e-5);
    free(p0), free(v0), free(p1), free(v1), free(p2), free(v2);
}

/* (d) Refresh order delta_f / area under a budget, delta_f reset, untouched surfaces unchanged, small
 * changes below the threshold left alone. */
static void test_schedule(void **state)
{
    (void)state;
    tscene t;
    load_three(&t);
    int A = surface_of(&t, "a"), B = surface_of(&t, "b"), C = surface_of(&t, "c");
    lm_photon_store ps;
    assert_int_equal(lm_photon_store_init(&ps, 3, NULL), LM_OK);
    g_rng = 11;
    /* Each hit has energy E * area / g^2: delta_f = area on each; per area the same, so vary E by g. */
    add_uniform(&ps, &t, A, -5.0f, 0.5f, 10);
    add_uniform(&ps, &t, B, 0.0f, 1.0f, 20);
    add_uniform(&ps, &t, C, 6.0f, 1.5f, 30);
    ps.surfaces[A].delta_f = 3.0;  /* delta_f / area: A 3, B 0.5, C 1 */
    ps.surfaces[B].delta_f = 2.0;
    ps.surfaces[C].delta_f = 9.0;
    lm_aim aim;
    init_aim(&aim, &t, NULL);
    lm_aim_stats st;
    assert_int_equal(lm_aim_refresh(&aim, t.s, &t.su, &t.a, &ps, 2, &st, NULL), LM_OK);
    assert_int_equal(st.surfaces_refreshed, 2);
    assert_int_equal(st.surfaces_pending, 1);
    assert_int_equal(aim.refresh_count[A], 1);
    assert_int_equal(aim.refresh_count[C], 1);
    assert_int_equal(aim.refresh_count[B], 0);
    assert_true(ps.surfaces[A].delta_f == 0.0 && ps.surfaces[C].delta_f == 0.0);
    assert_true(ps.surfaces[B].delta_f == 2.0);
    uint32_t nb;
    float *b0 = snapshot(&aim, &t, B, &nb);
    for (uint32_t i = 0; i < nb; i++)
        assert_true(b0[i] == 0.0f);
    free(b0);

    /* Budget 1: B is next. Then nothing is left. */
    assert_int_equal(lm_aim_refresh(&aim, t.s, &t.su, &t.a, &ps, 1, &st, NULL), LM_OK);
    assert_int_equal(st.surfaces_refreshed, 1);
    assert_int_equal(aim.refresh_count[B], 1);
    assert_true(st.texels_written == aim.texel_first[B + 1] - aim.texel_first[B]);
    assert_int_equal(lm_aim_refresh(&aim, t.s, &t.su, &t.a, &ps, -1, &st, NULL), LM_OK);
    assert_int_equal(st.surfaces_refreshed, 0);
    assert_int_equal(st.surfaces_pending, 0);

    /* A change below the threshold (0.01 x mean hit energy) waits; once it adds up, it is refreshed. */
    uint32_t na, nc;
    float *a0 = snapshot(&aim, &t, A, &na), *c0 = snapshot(&aim, &t, C, &nc);
    ps.surfaces[B].delta_f = 1e-3 * aim.mean_hit_energy;
    assert_int_equal(lm_aim_refresh(&aim, t.s, &t.su, &t.a, &ps, -1, &st, NULL), LM_OK);
    assert_int_equal(st.surfaces_refreshed, 0);
    add_uniform(&ps, &t, B, 0.0f, 1.0f, 20); /* B doubles */
    assert_int_equal(lm_aim_refresh(&aim, t.s, &t.su, &t.a, &ps, -1, &st, NULL), LM_OK);
    assert_int_equal(st.surfaces_refreshed, 1);
    assert_int_equal(aim.refresh_count[B], 2);
    uint32_t n2;
    float *a1 = snapshot(&aim, &t, A, &n2), *c1 = snapshot(&aim, &t, C, &n2);
    assert_memory_equal(a0, a1, sizeof *a0 * na);
    assert_memory_equal(c0, c1, sizeof *c0 * nc);
    float *b1 = snapshot(&aim, &t, B, &nb);
    double mean = 0.0;
    for (uint32_t i = 1; i < nb; i += 3)
        mean += b1[i];
    mean /= nb / 3;
    assert_true(fabs(mean - 2.0 * 0.6 / PI_F) / (2.0 * 0.6 / PI_F) < 0.03);
    free(a0);
    free(a1);
    free(b1);
    free(c0);
    free(c1);

    /* Removing every hit of A is a change too: A goes dark. */
    for (uint32_t i = 0; i < ps.used; i++)
        if (ps.hits[i].surface == A)
            lm_photon_store_remove(&ps, i);
    assert_int_equal(lm_aim_refresh(&aim, t.s, &t.su, &t.a, &ps, -1, &st, NULL), LM_OK);
    assert_int_equal(st.surfaces_refreshed, 1);
    a0 = snapshot(&aim, &t, A, &na);
    for (uint32_t i = 0; i < na; i++)
        assert_true(a0[i] == 0.0f);
    free(a0);

    lm_error err;
    assert_int_equal(lm_aim_refresh_surface(&aim, t.s, &t.su, &t.a, &ps, 3, NULL, &err), LM_ERR_INVALID);
    lm_aim_free(&aim);
    lm_photon_store_free(&ps);
    ts_free(&t);
}

/* (e) Same store, same map: across runs and thread counts, bit for bit. */
static void test_deterministic(void **state)
{
    (void)state;
    tscene t;
    load_three(&t);
    lm_photon_store ps;
    assert_int_equal(lm_photon_store_init(&ps, 3, NULL), LM_OK);
    const float light[4] = {0.0f, 1.0f, 0.0f, 5.0f};
    g_rng = 5;
    for (int s = 0; s < 3; s++) {
        float cx = t.s->nodes[t.su.surfaces[s].node].translation[0], h = sqrtf(t.su.surfaces[s].area) / 2;
        add_hits(&ps, &t, s, cx - h, -h, 2 * h, 40, density_point, light, 1.0f, light);
    }
    lm_aim a1, a2;
    init_aim(&a1, &t, NULL);
    init_aim(&a2, &t, NULL);
    int threads = omp_get_max_threads();
    omp_set_num_threads(1);
    assert_int_equal(lm_aim_refresh_all(&a1, t.s, &t.su, &t.a, &ps, NULL, NULL), LM_OK);
    omp_set_num_threads(threads > 1 ? threads : 2);
    assert_int_equal(lm_aim_refresh_all(&a2, t.s, &t.su, &t.a, &ps, NULL, NULL), LM_OK);
    omp_set_num_threads(threads);
    assert_memory_equal(lm_aim_rgb(&a1), lm_aim_rgb(&a2), sizeof(float) * 3 * (size_t)a1.width * a1.height);
    lm_aim_free(&a1);
    lm_aim_free(&a2);
    lm_photon_store_free(&ps);
    ts_free(&t);
}

/* Refreshing every surface in one call (built and estimated together) gives the same map as refreshing
 * them one at a time, in another order. */
static void test_batch_matches_single(void **state)
{
    (void)state;
    tscene t;
    load_three(&t);
    lm_photon_store ps;
    assert_int_equal(lm_photon_store_init(&ps, 3, NULL), LM_OK);
    const float light[4] = {0.5f, 1.2f, 0.3f, 4.0f};
    g_rng = 9;
    for (int s = 0; s < 3; s++) {
        float cx = t.s->nodes[t.su.surfaces[s].node].translation[0], h = sqrtf(t.su.surfaces[s].area) / 2;
        add_hits(&ps, &t, s, cx - h, -h, 2 * h, 30 + 5 * s, density_point, light, 1.0f, light);
    }
    lm_aim a1, a2;
    init_aim(&a1, &t, NULL);
    init_aim(&a2, &t, NULL);
    lm_aim_stats st;
    assert_int_equal(lm_aim_refresh_all(&a1, t.s, &t.su, &t.a, &ps, &st, NULL), LM_OK);
    assert_int_equal(st.surfaces_refreshed, 3);
    for (int s = 2; s >= 0; s--)
        assert_int_equal(lm_aim_refresh_surface(&a2, t.s, &t.su, &t.a, &ps, s, NULL, NULL), LM_OK);
    assert_memory_equal(lm_aim_rgb(&a1), lm_aim_rgb(&a2), sizeof(float) * 3 * (size_t)a1.width * a1.height);
    lm_aim_free(&a1);
    lm_aim_free(&a2);
    lm_photon_store_free(&ps);
    ts_free(&t);
}

/* A dense surface (every texel with N hits within its smallest radius: 90,000 hits on 400 texels) is
 * estimated without a kd-tree, from the same hits: its radiance and error estimate equal the kd-tree's to
 * float rounding, for both kernels. With hits on a quarter of the plane only it is not dense (the other
 * texels have fewer than N): the kd-tree's estimate, to the bit. */
static void test_dense_surface_without_kdtree(void **state)
{
    (void)state;
    lmt_mesh m;
    square_mesh(&m, 2.0f);
    tscene t;
    ts_load(&t, &m, 1, "[{\"name\": \"plane\", \"mesh\": 0}]", 0.2f);
    const float E[1] = {2.0f}, above[3] = {0.0f, 5.0f, 0.0f};
    for (int half = 0; half < 2; half++)
        for (int kernel = 0; kernel < 2; kernel++) {
            lm_photon_store ps;
            assert_int_equal(lm_photon_store_init(&ps, 1, NULL), LM_OK);
            g_rng = 3;
            add_hits(&ps, &t, 0, -2.0f, -2.0f, half ? 2.0f : 4.0f, 300, density_const, E, 1.0f, above);
            lm_aim aim[2];
            lm_aim_stats st[2];
            for (int dense = 0; dense < 2; dense++) {
                lm_aim_settings set;
                lm_aim_settings_default(&set);
                set.kernel = kernel;
                set.error_estimate = 1;
                set.dense = dense;
                init_aim(&aim[dense], &t, &set);
                assert_int_equal(lm_aim_refresh_all(&aim[dense], t.s, &t.su, &t.a, &ps, &st[dense], NULL), LM_OK);
            }
            assert_int_equal(st[0].surfaces_binned, 0);
            assert_int_equal(st[1].surfaces_binned, half ? 0 : 1);
            double worst = 0.0, worst_error = 0.0;
            for (uint32_t i = 0; i < t.a.texel_count; i++) {
                const lm_texel *tx = &t.a.texels[i];
                size_t at = (size_t)tx->y * (size_t)aim[0].width + (size_t)tx->x;
                for (int c = 0; c < 3; c++) {
                    double a = aim_px(&aim[0], tx)[c], b = aim_px(&aim[1], tx)[c];
                    worst = fmax(worst, fabs(a - b) / fmax(fabs(a), 1e-30));
                }
                double ea = aim[0].error[2 * at], eb = aim[1].error[2 * at];
                worst_error = fmax(worst_error, fabs(ea - eb) / fmax(ea, 1e-30));
                assert_true(aim[0].error[2 * at + 1] == aim[1].error[2 * at + 1]); /* the radius */
            }
            print_message("%s plane, kernel %d: kd-tree %.1f ms, %s %.1f ms; radiance within %.2g, error within "
                          "%.2g\n", half ? "quarter-lit" : "lit", kernel, 1e3 * st[0].seconds,
                          half ? "again the kd-tree" : "binned", 1e3 * st[1].seconds, worst, worst_error);
            if (half)
                assert_true(worst == 0.0 && worst_error == 0.0);
            else
                assert_true(worst < 1e-6 && worst_error < 1e-6);
            for (int k = 0; k < 2; k++)
                lm_aim_free(&aim[k]);
            lm_photon_store_free(&ps);
        }
    ts_free(&t);
}

/* N and the smallest radius (docs/aim.md, "N against the smallest radius"): 100 hits a texel under a point
 * light, as dense as at `lmgi run`'s atlas. The smallest radius is min_radius_texels texels at N = 32 and
 * grows with sqrt(N), so N sets the disc however dense the hits: every texel's radius (the error
 * estimate's) is 1, 1/sqrt(2) and 2 texels at N = 32, 16 and 128, and the maps of N = 16 and 128 differ.
 * Before, the radius was 1 texel at every N, N = 16 and 128 gave the same map, and the tradeoff sweep's N
 * line was flat at `run`'s density. */
static void test_n_acts_at_any_density(void **state)
{
    (void)state;
    lmt_mesh m;
    square_mesh(&m, 2.0f);
    tscene t;
    ts_load(&t, &m, 1, "[{\"name\": \"plane\", \"mesh\": 0}]", 0.2f);
    lm_photon_store ps;
    assert_int_equal(lm_photon_store_init(&ps, 1, NULL), LM_OK);
    const float light[4] = {0.3f, 1.0f, -0.2f, 10.0f};
    g_rng = 7;
    add_hits(&ps, &t, 0, -2.0f, -2.0f, 4.0f, 200, density_point, light, 1.0f, light);
    const int n[3] = {32, 16, 128};
    const double texels[3] = {1.0, sqrt(0.5), 2.0};
    lm_aim aim[3];
    for (int k = 0; k < 3; k++) {
        lm_aim_settings set;
        lm_aim_settings_default(&set);
        set.n_nearest = n[k];
        set.error_estimate = 1;
        init_aim(&aim[k], &t, &set);
        assert_int_equal(lm_aim_refresh_all(&aim[k], t.s, &t.su, &t.a, &ps, NULL, NULL), LM_OK);
        int at_floor = 0;
        for (uint32_t i = 0; i < t.a.texel_count; i++) {
            const lm_texel *tx = &t.a.texels[i];
            float r = aim[k].error[2 * ((size_t)tx->y * t.a.width + tx->x) + 1];
            at_floor += fabs(r / (texels[k] * t.a.texel_size) - 1.0) < 1e-5;
        }
        print_message("N = %d: %d of %u texels estimated over %.3f texels\n", n[k], at_floor, t.a.texel_count,
                      texels[k]);
        assert_true(at_floor > (int)(0.9 * t.a.texel_count)); /* the hits are dense everywhere */
    }
    double sum = 0.0;
    for (uint32_t i = 0; i < t.a.texel_count; i++) {
        double a = aim_px(&aim[1], &t.a.texels[i])[1], b = aim_px(&aim[2], &t.a.texels[i])[1];
        sum += fabs(a - b) / fmax(fabs(b), 1e-30);
    }
    print_message("N = 16 and N = 128 differ by %.3g%% per texel on average\n", 100.0 * sum / t.a.texel_count);
    assert_true(sum / t.a.texel_count > 0.01);
    for (int k = 0; k < 3; k++)
        lm_aim_free(&aim[k]);
    lm_photon_store_free(&ps);
    ts_free(&t);
}

/* (f) Seams: four square nodes meet at the origin (one of them half the size and scaled 2x, so its local
 * space is not the others'), and a point light 0.15 above that vertex puts the light's peak on the seams.
 * With seams every texel near the vertex sums the hits of the whole disc around it, across the four
 * surfaces, and reads what one plane under the same hits reads; with each surface's own hits only, the
 * boundary correction's even-light assumption reads the corners dark. Each surface continues the three
 * others (two across an edge, one across the vertex). */
static void seam_quadrants(tscene *t, int one_plane)
{
    lmt_mesh m[2];
    square_mesh(&m[0], one_plane ? 2.0f : 1.0f);
    square_mesh(&m[1], 0.5f);
    if (one_plane)
        ts_load(t, m, 1, "[{\"name\": \"plane\", \"mesh\": 0}]", 0.05f);
    else
        ts_load(t, m, 2,
                "[{\"name\": \"a\", \"mesh\": 0, \"translation\": [1, 0, 1]},"
                " {\"name\": \"b\", \"mesh\": 0, \"translation\": [-1, 0, 1]},"
                " {\"name\": \"c\", \"mesh\": 0, \"translation\": [-1, 0, -1]},"
                " {\"name\": \"d\", \"mesh\": 1, \"translation\": [1, 0, -1], \"scale\": [2, 2, 2]}]",
                0.05f);
    assert_int_equal(t->su.surface_count, one_plane ? 1 : 4);
}

/* g x g stratified hits over each quadrant (on surface 0 for the one plane), flux density E of the
 * light, local = (world - T) / scale. */
static void seam_hits(lm_photon_store *ps, const tscene *t, const float light[4], int g)
{
    const float corner[4][2] = {{0, 0}, {-2, 0}, {-2, -2}, {0, -2}};
    for (int q = 0; q < 4; q++) {
        int k = t->su.surface_count == 1 ? 0 : q;
        const float *w = t->s->nodes[t->su.surfaces[k].node].world;
        for (int j = 0; j < g; j++)
            for (int i = 0; i < g; i++) {
                lm_hit h;
                memset(&h, 0, sizeof h);
                h.pos[0] = corner[q][0] + 2.0f * (i + rnd()) / g;
                h.pos[2] = corner[q][1] + 2.0f * (j + rnd()) / g;
                h.local[0] = (h.pos[0] - w[12]) / w[0];
                h.local[2] = (h.pos[2] - w[14]) / w[0];
                h.dir[1] = -1.0f;
                float phi = point_E(light, light[3], h.pos[0], h.pos[2]) * 4.0f / (float)(g * g);
                h.flux[0] = h.flux[1] = h.flux[2] = phi;
                h.surface = k;
                h.tri = t->su.surfaces[k].tris[0];
                assert_true(lm_photon_store_add(ps, &h) != LM_NONE);
            }
    }
}

/* The mean signed error of the texels within 0.15 of the vertex against rho / pi E. */
static double seam_error(const tscene *t, int one_plane, int seams)
{
    lm_photon_store ps;
    assert_int_equal(lm_photon_store_init(&ps, t->su.surface_count, NULL), LM_OK);
    const float light[4] = {0.0f, 0.15f, 0.0f, 1.0f};
    g_rng = 5;
    seam_hits(&ps, t, light, 80);
    lm_aim aim;
    lm_aim_settings set;
    lm_aim_settings_default(&set);
    set.seams = seams;
    init_aim(&aim, t, &set);
    for (int k = 0; !one_plane && seams && k < 4; k++)
        assert_int_equal(aim.seams.first[k + 1] - aim.seams.first[k], 3);
    lm_aim_stats st;
    assert_int_equal(lm_aim_refresh_all(&aim, t->s, &t->su, &t->a, &ps, &st, NULL), LM_OK);
    double sum = 0.0;
    int n = 0;
    for (uint32_t i = 0; i < t->a.texel_count; i++) {
        const lm_texel *tx = &t->a.texels[i];
        if (hypotf(tx->pos[0], tx->pos[2]) > 0.15f)
            continue;
        double want = 0.6 / PI_F * point_E(light, light[3], tx->pos[0], tx->pos[2]);
        sum += aim_px(&aim, tx)[1] / want - 1.0;
        n++;
    }
    print_message("light on the vertex of %s: %d texels within 0.15, mean %+.2f%% (%llu hits used)\n",
                  one_plane ? "one plane" : seams ? "four nodes, seams" : "four nodes, no seams", n,
                  100.0 * sum / n, (unsigned long long)st.hits_used);
    assert_true(n > 20);
    lm_aim_free(&aim);
    lm_photon_store_free(&ps);
    return sum / n;
}

static void test_seams(void **state)
{
    (void)state;
    tscene one, four;
    seam_quadrants(&one, 1);
    seam_quadrants(&four, 0);
    double plane = seam_error(&one, 1, 1), off = seam_error(&four, 0, 0), on = seam_error(&four, 0, 1);
    assert_true(fabs(on - plane) < 0.025);
    assert_true(off < plane - 0.05); /* without seams: dark, so the test sees what seams do */
    ts_free(&one);
    ts_free(&four);
}

/* A refresh owes its surface's change to the surfaces that continue it across a seam: their texels near the
 * seam sum its hits too. After hits are added on one quadrant only, a refresh with a budget of one surface
 * takes that quadrant, and the next takes the three others although their own hits did not change; a
 * refresh without a budget takes all four at once. Either way the map is what a refresh of everything
 * gives, to the bit (a bake after a box moved on one floor tile differed from a fresh one's by 3% along the
 * next tile's seam). */
static void test_seam_change_is_owed(void **state)
{
    (void)state;
    tscene t;
    seam_quadrants(&t, 0);
    const float light[4] = {0.0f, 0.15f, 0.0f, 1.0f}, spot[4] = {0.05f, 0.1f, 0.05f, 1.0f};
    size_t floats = 3 * (size_t)t.a.width * (size_t)t.a.height;
    float *want = malloc(sizeof *want * floats);
    assert_non_null(want);
    for (int budget = 1; budget >= -1; budget -= 2) {
        lm_photon_store ps;
        assert_int_equal(lm_photon_store_init(&ps, t.su.surface_count, NULL), LM_OK);
        g_rng = 5;
        seam_hits(&ps, &t, light, 40);
        lm_aim aim;
        lm_aim_settings set;
        lm_aim_settings_default(&set);
        init_aim(&aim, &t, &set);
        lm_aim_stats st;
        assert_int_equal(lm_aim_refresh_all(&aim, t.s, &t.su, &t.a, &ps, &st, NULL), LM_OK);
        lm_photon_store more; /* a second light's hits on quadrant a alone, moved into the store */
        assert_int_equal(lm_photon_store_init(&more, t.su.surface_count, NULL), LM_OK);
        seam_hits(&more, &t, spot, 20);
        for (uint32_t k = 0; k < more.surfaces[0].count; k++)
            assert_true(lm_photon_store_add(&ps, &more.hits[more.surfaces[0].slots[k]]) != LM_NONE);
        lm_photon_store_free(&more);
        assert_int_equal(lm_aim_refresh(&aim, t.s, &t.su, &t.a, &ps, budget, &st, NULL), LM_OK);
        assert_int_equal(st.surfaces_refreshed, budget < 0 ? 4 : 1);
        if (budget > 0) {
            assert_true(aim.owed[1] > 0.0 && aim.owed[2] > 0.0 && aim.owed[3] > 0.0 && aim.owed[0] == 0.0);
            assert_int_equal(lm_aim_refresh(&aim, t.s, &t.su, &t.a, &ps, 3, &st, NULL), LM_OK);
            assert_int_equal(st.surfaces_refreshed, 3);
        }
        for (int k = 0; k < 4; k++)
            assert_true(aim.owed[k] == 0.0);
        memcpy(want, aim.rgb, sizeof *want * floats);
        assert_int_equal(lm_aim_refresh_all(&aim, t.s, &t.su, &t.a, &ps, &st, NULL), LM_OK);
        assert_memory_equal(want, aim.rgb, sizeof *want * floats);
        lm_aim_free(&aim);
        lm_photon_store_free(&ps);
    }
    free(want);
    ts_free(&t);
}

static void test_bad_settings(void **state)
{
    (void)state;
    tscene t;
    load_three(&t);
    lm_aim_settings set;
    lm_aim_settings_default(&set);
    set.n_nearest = 0;
    lm_aim aim;
    lm_error err;
    assert_int_equal(lm_aim_init(&aim, t.s, &t.su, &t.a, &set, &err), LM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "n_nearest"));
    lm_photon_store ps;
    assert_int_equal(lm_photon_store_init(&ps, 2, NULL), LM_OK);
    init_aim(&aim, &t, NULL);
    assert_int_equal(lm_aim_refresh(&aim, t.s, &t.su, &t.a, &ps, 1, NULL, &err), LM_ERR_INVALID);
    lm_aim_free(&aim);
    lm_photon_store_free(&ps);
    ts_free(&t);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_point_light_plane),
        cmocka_unit_test(test_uniform_borders_and_corners),
        cmocka_unit_test(test_boundary_correction_matters),
        cmocka_unit_test(test_collinear_edges_joined),
        cmocka_unit_test(test_hard_cases),
        cmocka_unit_test(test_schedule),
        cmocka_unit_test(test_deterministic),
        cmocka_unit_test(test_batch_matches_single),
        cmocka_unit_test(test_dense_surface_without_kdtree),
        cmocka_unit_test(test_n_acts_at_any_density),
        cmocka_unit_test(test_seams),
        cmocka_unit_test(test_seam_change_is_owed),
        cmocka_unit_test(test_occluders_keep_shadow_edges),
        cmocka_unit_test(test_bad_settings),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
