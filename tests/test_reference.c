/* reference solver: analytic irradiance (point light over a plane, furnace box), the furnace's pixel
 * parts, determinism, cache, pixels, relative RMSE (the split by light path: test_reference_split.c). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../src/core/log.h"
#include "../src/core/timing.h"
#include "../src/reference/reference.h"
#include "support.h"

#define PI 3.14159265358979323846

/* A closed box of half-size 1 seen from inside: every wall faces in, albedo rho, emits radiance 1. */
static const char *furnace_scene_of(double rho)
{
    static char path[512];
    static lmt_mesh m;
    memset(&m, 0, sizeof m);
    lmt_mesh_cube_inward(&m, 1.0f);
    char mat[400];
    snprintf(mat, sizeof mat, "\"materials\": [{\"pbrMetallicRoughness\": {\"baseColorFactor\": [%.17g, %.17g, "
             "%.17g, 1], \"metallicFactor\": 0, \"roughnessFactor\": 1}, \"emissiveFactor\": [1, 1, 1]}],", rho, rho,
             rho);
    snprintf(path, sizeof path, "%s/furnace.gltf", lmt_tmpdir());
    assert_int_equal(lmt_write_gltf(path, &m, 1, "[{\"mesh\": 0}]", NULL, 0, mat), 0);
    lmt_use_material_0(path);
    return path;
}

static const char *furnace_scene(void) { return furnace_scene_of(0.5); }

static lm_ref_settings quick_settings(float target, int samples)
{
    lm_ref_settings set;
    lm_ref_settings_default(&set);
    set.target_error = target;
    set.samples = samples;
    set.min_samples = samples;
    set.use_cache = 0;
    set.progress = 0;
    return set;
}

static void test_point_light_over_plane(void **state)
{
    (void)state;
    lmt_pipeline p;
    lmt_pipeline_load(&p, lmt_plane_scene(), 0.5f);
    assert_true(p.atlas.texel_count >= 1000);
    lm_ref_settings set = quick_settings(0.02f, 4);
    lm_ref_result r;
    lm_error err;
    assert_int_equal(lm_reference_texels(p.s, &p.atlas, p.rt, &p.em, &set, &r, &err), LM_OK);
    assert_int_equal(r.count, p.atlas.texel_count);
    int checked = 0;
    for (uint32_t i = 0; i < r.count; i++) {
        const lm_texel *t = &p.atlas.texels[i];
        assert_float_equal(r.iim[3 * i], 0.0, 0.0); /* nothing to bounce from: exactly 0 */
        assert_float_equal(r.iim[3 * i + 2], 0.0, 0.0);
        if (fabsf(t->pos[0]) > 8.0f || fabsf(t->pos[2]) > 8.0f)
            continue;
        double d2 = t->pos[0] * t->pos[0] + 4.0 + t->pos[2] * t->pos[2], e = 10.0 * (2.0 / sqrt(d2)) / d2;
        assert_float_equal(r.full[3 * i + 1], e, 0.02 * e);
        assert_float_equal(r.radiance[3 * i], 0.8 / PI * r.full[3 * i], 1e-6 * r.full[3 * i]);
        checked++;
    }
    assert_true(checked > 500);
    assert_int_equal(r.converged, r.count);
    lm_ref_result_free(&r);
    lmt_pipeline_free(&p);
}

/* A texel that stands for a curved piece (lm_atlas.footprints) is referenced as the gather takes it: its
 * samples at its footprint points in turn, the mean of their light. A spherical cap of half-angle 25
 * degrees (radius 0.5, smooth normals) under a point light 0.5 over its top, alone, at 2 m texels: at each
 * point E = I (n . l) / d^2 and nothing bounces (one shadow ray a sample: no noise). The texel's own point
 * (on one of the cap's triangles, facing its mean normal) reads 2.2% less than the points' mean. */
static void test_footprint_texel(void **state)
{
    (void)state;
    const double alpha = 25.0 * PI / 180.0, r = 0.5, I = 10.0, light_y = 1.0;
    static lmt_mesh m;
    lmt_mesh_cap(&m, alpha, r, 0.0);
    char path[512], ext[400];
    snprintf(path, sizeof path, "%s/cap.gltf", lmt_tmpdir());
    snprintf(ext, sizeof ext, "\"extensionsUsed\": [\"KHR_lights_punctual\"], \"extensions\": {\"KHR_lights_punctual\": "
             "{\"lights\": [{\"type\": \"point\", \"intensity\": %g}]}},", I);
    assert_int_equal(lmt_write_gltf(path, &m, 1, "[{\"children\": [1, 2]}, {\"mesh\": 0}, {\"translation\": [0, 1, 0], "
                                    "\"extensions\": {\"KHR_lights_punctual\": {\"light\": 0}}}]", NULL, 0, ext), 0);
    lmt_pipeline p;
    lmt_pipeline_load(&p, path, 2.0f);
    for (uint32_t v = 0; v < p.s->vertex_count; v++) { /* the sphere's own normals */
        const float *q = p.s->positions + 3 * (size_t)v;
        double l = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
        for (int a = 0; a < 3; a++)
            p.s->normals[3 * (size_t)v + a] = (float)(q[a] / l);
    }
    lm_atlas_options ao;
    lm_atlas_options_default(&ao);
    ao.texel_size = 2.0f;
    lm_error err;
    lm_atlas_free(&p.atlas);
    assert_int_equal(lm_atlas_build(p.s, &p.su, &ao, &p.atlas, &err), LM_OK);
    assert_int_equal(p.atlas.texel_count, 1);
    const lm_texel *pts;
    uint32_t n = lm_texel_footprint(&p.atlas, 0, &pts);
    assert_int_equal(n, LM_FOOTPRINT_POINTS);
    double want = 0.0, own = 0.0;
    for (uint32_t k = 0; k <= n; k++) {
        const lm_texel *t = k < n ? &pts[k] : &p.atlas.texels[0];
        double l[3] = {-t->pos[0], light_y - t->pos[1], -t->pos[2]}, d2 = l[0] * l[0] + l[1] * l[1] + l[2] * l[2];
        double e = I * (t->normal[0] * l[0] + t->normal[1] * l[1] + t->normal[2] * l[2]) / sqrt(d2) / d2;
        if (k < n)
            want += e / n;
        else
            own = e;
    }
    lm_ref_settings set = quick_settings(0.01f, 8);
    lm_ref_result res;
    assert_int_equal(lm_reference_texels(p.s, &p.atlas, p.rt, &p.em, &set, &res, &err), LM_OK);
    print_message("cap texel: reference %.4f, its points' mean %.4f, its own point %.4f\n", (double)res.full[1], want, own);
    assert_true(fabs(own / want - 1.0) > 0.015);
    assert_float_equal(res.full[1], want, 0.002 * want);
    lm_ref_result_free(&res);
    lmt_pipeline_free(&p);
}

/* Furnace: radiance Le / (1 - rho) everywhere, so E = pi Le / (1 - rho) = 2 pi; E_iim = E_full. */
static void test_furnace(void **state)
{
    (void)state;
    lmt_pipeline p;
    lmt_pipeline_load(&p, furnace_scene(), 0.25f);
    assert_int_equal(p.em.count, 1);
    lm_ref_settings set = quick_settings(0.006f, 64);
    lm_ref_result r;
    lm_error err;
    double t0 = lm_now();
    assert_int_equal(lm_reference_texels(p.s, &p.atlas, p.rt, &p.em, &set, &r, &err), LM_OK);
    double expect = 2.0 * PI, worst = 0.0, mean = 0.0;
    for (uint32_t i = 0; i < r.count; i++) {
        for (int c = 0; c < 3; c++) {
            assert_float_equal(r.full[3 * i + c], expect, 0.03 * expect);
            assert_float_equal(r.iim[3 * i + c], r.full[3 * i + c], 0.0);
        }
        worst = fmax(worst, fabs(r.full[3 * i] / expect - 1.0));
        mean += r.full[3 * i] / expect / r.count;
    }
    assert_float_equal(mean, 1.0, 0.002); /* unbiased: the average over texels is much tighter */
    print_message("furnace: %u texels, %llu paths, error: mean %.4f max %.4f; mean E / expected %.5f, worst texel "
                  "off by %.4f; %.2f s\n", r.count, (unsigned long long)r.total_samples, r.mean_rel_se, r.max_rel_se,
                  mean, worst, lm_now() - t0);
    assert_true(r.max_rel_se <= 0.006 || r.converged < r.count);
    lm_ref_result_free(&r);
    lmt_pipeline_free(&p);
}

/* Bright rooms: at albedo 0.9, 0.99 and 0.999 light lives for 10, 100 and 1,000 bounces; E = pi / (1 -
 * rho) must come out whole (a fixed depth of 64 gave 0.47 of it at 0.99), within the error the reference
 * states, and no path is cut. At albedo 1 the answer is infinite: the reference says so. */
static void test_bright_furnaces(void **state)
{
    (void)state;
    static const double rhos[3] = {0.9, 0.99, 0.999};
    for (int k = 0; k < 3; k++) {
        lmt_pipeline p;
        lmt_pipeline_load(&p, furnace_scene_of(rhos[k]), 1.0f);
        lm_ref_settings set = quick_settings(0.05f, 64);
        lm_ref_result r;
        lm_error err;
        double t0 = lm_now();
        assert_int_equal(lm_reference_texels(p.s, &p.atlas, p.rt, &p.em, &set, &r, &err), LM_OK);
        /* the albedo as the scene holds it (a float): the analytic answer for that */
        double rho = p.s->materials[0].base_color[0], expect = PI / (1.0 - rho), mean = 0.0, worst = 0.0;
        for (uint32_t i = 0; i < r.count; i++) {
            double ratio = r.full[3 * i] / expect;
            mean += ratio / r.count;
            worst = fmax(worst, fabs(ratio - 1.0) / fmax(r.rel_se[i], 1e-6)); /* in standard errors */
        }
        double stated = r.mean_rel_se / sqrt((double)r.count); /* the mean's standard error */
        print_message("furnace rho %.3f: %u texels, %llu paths (%.0f per texel), mean E / expected %.4f (stated "
                      "error of the mean %.4f), worst texel %.1f standard errors off, %llu paths cut; %.1f s\n", rho,
                      r.count, (unsigned long long)r.total_samples, (double)r.total_samples / r.count, mean, stated,
                      worst, (unsigned long long)r.paths_cut, lm_now() - t0);
        assert_int_equal(r.paths_cut, 0);
        assert_true(fabs(mean - 1.0) <= 4.0 * stated);
        assert_true(worst < 5.0);
        lm_ref_result_free(&r);
        lmt_pipeline_free(&p);
    }
    lmt_pipeline p;
    lmt_pipeline_load(&p, furnace_scene_of(1.0), 1.0f);
    lm_ref_settings set = quick_settings(0.2f, 8);
    set.max_samples = 16;
    set.max_depth = 2000; /* here paths live 1,000 bounces on average: some meet the guard */
    lm_ref_result r;
    lm_error err;
    lm_log_level was = lm_log_get_level();
    lm_log_set_level(LM_LOG_ERROR); /* counted, not printed */
    lm_log_reset_warning_count();
    assert_int_equal(lm_reference_texels(p.s, &p.atlas, p.rt, &p.em, &set, &r, &err), LM_OK);
    lm_log_set_level(was);
    print_message("furnace rho 1: %llu of %llu paths cut at %d bounces, %d warnings\n",
                  (unsigned long long)r.paths_cut, (unsigned long long)r.total_samples, set.max_depth,
                  lm_log_warning_count());
    assert_true(r.paths_cut > 0);
    assert_int_equal(lm_log_warning_count(), 2); /* the albedo, and the cut paths */
    lm_ref_result_free(&r);
    lmt_pipeline_free(&p);
}

/* The furnace from inside: every pixel sees radiance 2, its own emission 1 exactly (the receiver's part)
 * and 1 more from the walls it lights (the indirect part); no direct, caustic, lost or reflected light. */
static void test_furnace_pixel_parts(void **state)
{
    (void)state;
    lmt_pipeline p;
    lmt_pipeline_load(&p, furnace_scene(), 0.5f);
    lm_view cam = {.eye = {0, 0, 0}, .forward = {0, 0, -1}, .up = {0, 1, 0},
                   .yfov = 1.0f, .width = 8, .height = 8, .znear = 0.0f};
    lm_ref_settings set = quick_settings(0.01f, 64);
    lm_ref_result r;
    lm_error err;
    assert_int_equal(lm_reference_pixels(p.s, p.rt, &p.em, &cam, &set, &r, &err), LM_OK);
    for (uint32_t i = 0; i < 3 * r.count; i++) {
        assert_float_equal(r.emission[i], 1.0, 0.0);
        assert_float_equal(r.indirect[i], 1.0, 0.05);
        assert_float_equal(r.full[i], r.emission[i] + r.indirect[i], 1e-6);
        assert_true(r.direct[i] == 0.0f && r.caustic[i] == 0.0f && r.lost[i] == 0.0f && r.reflections[i] == 0.0f);
    }
    lm_ref_result_free(&r);
    lmt_pipeline_free(&p);
}

static void test_deterministic_across_threads(void **state)
{
    (void)state;
    lmt_pipeline p;
    lmt_pipeline_load(&p, furnace_scene(), 0.5f);
    lm_ref_settings set = quick_settings(0.05f, 16);
    lm_ref_result a, b;
    lm_error err;
    int threads = omp_get_max_threads();
    omp_set_num_threads(1);
    assert_int_equal(lm_reference_texels(p.s, &p.atlas, p.rt, &p.em, &set, &a, &err), LM_OK);
    omp_set_num_threads(threads > 1 ? threads : 2);
    assert_int_equal(lm_reference_texels(p.s, &p.atlas, p.rt, &p.em, &set, &b, &err), LM_OK);
    omp_set_num_threads(threads);
    assert_int_equal(a.count, b.count);
    assert_memory_equal(a.full, b.full, a.count * 3 * sizeof(float));
    assert_memory_equal(a.iim, b.iim, a.count * 3 * sizeof(float));
    assert_memory_equal(a.lost, b.lost, a.count * 3 * sizeof(float));
    assert_memory_equal(a.samples, b.samples, a.count * sizeof(uint32_t));
    lm_ref_result_free(&a);
    lm_ref_result_free(&b);
    lmt_pipeline_free(&p);
}

static void corrupt(const char *path, long offset, int cut)
{
    FILE *f = fopen(path, "r+b");
    assert_non_null(f);
    fseek(f, 0, SEEK_END);
    long size = ftell(f);
    fclose(f);
    if (cut) {
        assert_int_equal(truncate(path, size / 2), 0);
        return;
    }
    f = fopen(path, "r+b");
    fseek(f, offset < size ? offset : size / 2, SEEK_SET);
    fputc(0x5a, f);
    fputc(0xa5, f);
    fclose(f);
}

static void test_cache_hit_and_corruption(void **state)
{
    (void)state;
    lmt_pipeline p;
    lmt_pipeline_load(&p, furnace_scene(), 0.5f);
    char dir[600];
    snprintf(dir, sizeof dir, "%s/cache", lmt_tmpdir());
    lm_ref_settings set = quick_settings(0.03f, 32);
    set.use_cache = 1;
    set.cache_dir = dir;
    lm_ref_result a, b, c;
    lm_error err;
    double t0 = lm_now();
    assert_int_equal(lm_reference_texels(p.s, &p.atlas, p.rt, &p.em, &set, &a, &err), LM_OK);
    double t1 = lm_now();
    assert_false(a.from_cache);
    assert_int_equal(lm_reference_texels(p.s, &p.atlas, p.rt, &p.em, &set, &b, &err), LM_OK);
    double t2 = lm_now();
    assert_true(b.from_cache);
    assert_true(t2 - t1 < t1 - t0);
    assert_int_equal(a.key, b.key);
    assert_memory_equal(a.full, b.full, a.count * 3 * sizeof(float));
    assert_memory_equal(a.iim, b.iim, a.count * 3 * sizeof(float));
    assert_memory_equal(a.radiance, b.radiance, a.count * 3 * sizeof(float));
    assert_memory_equal(a.rel_se, b.rel_se, a.count * sizeof(float));
    assert_int_equal(a.total_samples, b.total_samples);
    lm_ref_result_free(&b);
    /* a damaged file (a flipped byte, then a truncated one) is ignored with a warning and recomputed */
    char file[1300];
    snprintf(file, sizeof file, "%s/texels-%016llx.lmref", dir, (unsigned long long)a.key);
    for (int k = 0; k < 2; k++) {
        corrupt(file, 200, k);
        int warnings = lm_log_warning_count();
        assert_int_equal(lm_reference_texels(p.s, &p.atlas, p.rt, &p.em, &set, &c, &err), LM_OK);
        assert_false(c.from_cache);
        assert_true(lm_log_warning_count() > warnings);
        assert_memory_equal(a.full, c.full, a.count * 3 * sizeof(float));
        lm_ref_result_free(&c);
    }
    /* another setting is another key */
    set.seed = 7;
    assert_int_equal(lm_reference_texels(p.s, &p.atlas, p.rt, &p.em, &set, &c, &err), LM_OK);
    assert_false(c.from_cache);
    assert_true(c.key != a.key);
    lm_ref_result_free(&c);
    lm_ref_result_free(&a);
    lmt_pipeline_free(&p);
}

static void test_pixels_see_lit_plane(void **state)
{
    (void)state;
    lmt_pipeline p;
    lmt_pipeline_load(&p, lmt_plane_scene(), 1.0f);
    lm_view cam = {.eye = {0, 5, 0}, .forward = {0, -1, 0}, .up = {0, 0, -1},
                   .yfov = 0.2f, .width = 16, .height = 16, .znear = 0.0f};
    lm_ref_settings set = quick_settings(0.01f, 16);
    lm_ref_result r;
    lm_error err;
    assert_int_equal(lm_reference_pixels(p.s, p.rt, &p.em, &cam, &set, &r, &err), LM_OK);
    assert_int_equal(r.count, 256);
    assert_null(r.iim);
    /* pixels around the centre look at the origin: L = rho / pi x I / h^2 */
    double expect = 0.8 / PI * 10.0 / 4.0;
    for (int y = 7; y <= 8; y++)
        for (int x = 7; x <= 8; x++)
            assert_float_equal(r.full[3 * (y * 16 + x)], expect, 0.01 * expect);
    lm_ref_result_free(&r);
    cam.yfov = 0.0f;
    assert_int_equal(lm_reference_pixels(p.s, p.rt, &p.em, &cam, &set, &r, &err), LM_ERR_INVALID);
    lmt_pipeline_free(&p);
}

/* A hot spot that bounces: a dark floor (albedo 0.1) under a 4 x 4 white ceiling 2 m up, a point light 10 cm
 * under the ceiling (as the generated Cornell box's lamp). The floor's light is half the ceiling's spot, met
 * by a bounce in few paths: a pixel that has not met it yet has the direct light's small variance and looks
 * converged. Each pixel's own variance alone read the floor at a target of 0.1 13.2% dark against the same
 * paths run to 4,096 samples a pixel; pooled with its neighbours' (reference.c, entry_errors) 1.0%. At 0.03
 * both read 0.1%. */
static void test_rare_bright_paths_keep_pixels_going(void **state)
{
    (void)state;
    lmt_mesh m[2];
    memset(m, 0, sizeof m);
    lmt_mesh_quad(&m[0], (float[3]){-10, 0, 10}, (float[3]){20, 0, 0}, (float[3]){0, 0, -20});
    lmt_mesh_quad(&m[1], (float[3]){-2, 2, -2}, (float[3]){4, 0, 0}, (float[3]){0, 0, 4});
    const char *mats = "[{\"pbrMetallicRoughness\": {\"baseColorFactor\": [0.1, 0.1, 0.1, 1], \"metallicFactor\": 0}},"
                       " {\"pbrMetallicRoughness\": {\"baseColorFactor\": [0.9, 0.9, 0.9, 1], \"metallicFactor\": 0}}],"
                       " \"extensionsUsed\": [\"KHR_lights_punctual\"], \"extensions\": {\"KHR_lights_punctual\":"
                       " {\"lights\": [{\"type\": \"point\", \"intensity\": 10}]}}"; /* lmt_write_scene's text */
    const char *nodes = "[{\"children\": [1, 2, 3]}, {\"mesh\": 0}, {\"mesh\": 1},"
                        " {\"translation\": [0, 1.9, 0], \"extensions\": {\"KHR_lights_punctual\": {\"light\": 0}}}]";
    const char *path = lmt_write_scene("hot_spot.gltf", m, 2, nodes, mats);
    lmt_pipeline p;
    lmt_pipeline_load(&p, path, 1.0f);
    lm_view cam = {.eye = {0, 1.5f, 0}, .forward = {0, -1, 0}, .up = {0, 0, -1},
                   .yfov = 1.0f, .width = 16, .height = 16, .znear = 0.0f};
    double sum[3] = {0.0, 0.0, 0.0};
    const float targets[2] = {0.1f, 0.03f};
    for (int k = 0; k < 3; k++) {
        lm_ref_settings set = quick_settings(k < 2 ? targets[k] : 1e-6f, 64);
        if (k == 2) /* every pixel to the same count: no stopping rule at all */
            set.min_samples = set.max_samples = 4096;
        lm_ref_result r;
        lm_error err;
        assert_int_equal(lm_reference_pixels(p.s, p.rt, &p.em, &cam, &set, &r, &err), LM_OK);
        for (uint32_t i = 0; i < r.count; i++)
            sum[k] += r.full[3 * i + 1];
        lm_ref_result_free(&r);
    }
    print_message("the floor under a hot spot, pixels' sum at a target of 0.1 / 0.03 against 4,096 samples a pixel: "
                  "%.3f / %.3f\n", sum[0] / sum[2], sum[1] / sum[2]);
    assert_true(fabs(sum[0] / sum[2] - 1.0) < 0.05);
    assert_true(fabs(sum[1] / sum[2] - 1.0) < 0.02);
    lmt_pipeline_free(&p);
}

/* A camera whose eye lies just above a tile (a camera placed on a wall or in a room's corner) sees past
 * it, as the rasterised frame does that clips at the near plane: eye rays start on the near plane. */
static void test_pixels_start_at_near_plane(void **state)
{
    (void)state;
    static lmt_mesh m[2];
    memset(m, 0, sizeof m);
    lmt_mesh_quad(&m[0], (float[3]){-10, 0, 10}, (float[3]){20, 0, 0}, (float[3]){0, 0, -20});
    lmt_mesh_quad(&m[1], (float[3]){-1, 4.9f, 1}, (float[3]){2, 0, 0}, (float[3]){0, 0, -2}); /* the tile */
    const char *nodes = "[{\"children\": [1, 2, 3]}, {\"mesh\": 0}, {\"mesh\": 1},"
                        " {\"translation\": [0, 2, 0], \"extensions\": {\"KHR_lights_punctual\": {\"light\": 0}}}]";
    const char *ext = "\"extensionsUsed\": [\"KHR_lights_punctual\"], \"extensions\": {\"KHR_lights_punctual\":"
                      " {\"lights\": [{\"type\": \"point\", \"intensity\": 10}]}},";
    char path[512];
    snprintf(path, sizeof path, "%s/tile_over_plane.gltf", lmt_tmpdir());
    assert_int_equal(lmt_write_gltf(path, m, 2, nodes, NULL, 0, ext), 0);
    lmt_pipeline p;
    lmt_pipeline_load(&p, path, 1.0f);
    lm_view cam = {.eye = {0, 5, 0}, .forward = {0, -1, 0}, .up = {0, 0, -1},
                   .yfov = 0.2f, .width = 8, .height = 8, .znear = 0.0f};
    lm_ref_settings set = quick_settings(0.01f, 16);
    lm_ref_result r;
    lm_error err;
    assert_int_equal(lm_reference_pixels(p.s, p.rt, &p.em, &cam, &set, &r, &err), LM_OK);
    assert_float_equal(r.full[3 * (4 * 8 + 4)], 0.0, 0.0); /* the tile's unlit top */
    lm_ref_result_free(&r);
    cam.znear = 0.2f;
    assert_int_equal(lm_reference_pixels(p.s, p.rt, &p.em, &cam, &set, &r, &err), LM_OK);
    double expect = 0.8 / PI * 10.0 / 4.0; /* the plane below, as in test_pixels_see_lit_plane */
    for (int y = 3; y <= 4; y++)
        for (int x = 3; x <= 4; x++)
            assert_float_equal(r.full[3 * (y * 8 + x)], expect, 0.01 * expect);
    lm_ref_result_free(&r);
    lmt_pipeline_free(&p);
}

static void test_invalid_settings(void **state)
{
    (void)state;
    lmt_pipeline p;
    lmt_pipeline_load(&p, lmt_plane_scene(), 2.0f);
    lm_ref_settings set = quick_settings(0.0f, 4);
    lm_ref_result r;
    lm_error err;
    assert_int_equal(lm_reference_texels(p.s, &p.atlas, p.rt, &p.em, &set, &r, &err), LM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "target error"));
    lmt_pipeline_free(&p);
}

static void test_relative_rmse(void **state)
{
    (void)state;
    const float ref[6] = {1, 2, 3, 4, 5, 6}, est[6] = {1, 2, 3, 4, 5, 9};
    const uint8_t mask[2] = {1, 0};
    assert_float_equal(lm_ref_relative_rmse(ref, ref, NULL, 2, 3), 0.0, 0.0);
    assert_float_equal(lm_ref_relative_rmse(est, ref, NULL, 2, 3), 3.0 / sqrt(91.0), 1e-9);
    assert_float_equal(lm_ref_relative_rmse(est, ref, mask, 2, 3), 0.0, 0.0);
    const float zero[3] = {0, 0, 0};
    assert_true(isinf(lm_ref_relative_rmse(ref, zero, NULL, 1, 3)));
    assert_float_equal(lm_ref_relative_rmse(zero, zero, NULL, 1, 3), 0.0, 0.0);
}

static void test_texels_to_image(void **state)
{
    (void)state;
    lm_texel tx[2] = {{.x = 1, .y = 0}, {.x = 0, .y = 1}};
    lm_atlas a = {.width = 2, .height = 2, .texel_count = 2, .texels = tx};
    const float v[6] = {1, 2, 3, 4, 5, 6};
    float img[12];
    lm_ref_texels_to_image(&a, v, img);
    const float want[12] = {0, 0, 0, 1, 2, 3, 4, 5, 6, 0, 0, 0};
    assert_memory_equal(img, want, sizeof want);
}

int main(void)
{
    lm_log_set_level(LM_LOG_ERROR);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_point_light_over_plane),
        cmocka_unit_test(test_footprint_texel),
        cmocka_unit_test(test_furnace),
        cmocka_unit_test(test_bright_furnaces),
        cmocka_unit_test(test_furnace_pixel_parts),
        cmocka_unit_test(test_deterministic_across_threads),
        cmocka_unit_test(test_cache_hit_and_corruption),
        cmocka_unit_test(test_pixels_see_lit_plane),
        cmocka_unit_test(test_pixels_start_at_near_plane),
        cmocka_unit_test(test_rare_bright_paths_keep_pixels_going),
        cmocka_unit_test(test_invalid_settings),
        cmocka_unit_test(test_relative_rmse),
        cmocka_unit_test(test_texels_to_image),
    };
    lmt_filter_from_env();
    return cmocka_run_group_tests(tests, NULL, NULL);
}
