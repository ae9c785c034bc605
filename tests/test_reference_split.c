/* The reference split by light path (docs/reference.md, "Which part carries which light"): a point light
 * under a tilted square mirror over a diffuse floor, where the caustic on the floor is the image of the
 * light in the mirror (analytic, texels and pixels); the parts adding up to full; scenes without mirror
 * or glass giving no caustic or lost light; the same bits for 1 and 2 threads; the cache. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../src/core/log.h"
#include "../src/core/timing.h"
#include "../src/reference/reference.h"
#include "support.h"

#define PI 3.14159265358979323846
#define INTENSITY 10.0   /* the point light, candela, at (0, LIGHT_Y, 0) */
#define LIGHT_Y 1.0
#define MIRROR_Y 3.0     /* the mirror's centre (0, MIRROR_Y, 0) */
#define HALF 0.75        /* the mirror's half side */
#define TILT 0.2617994   /* 15 degrees about z: its normal (sin, -cos, 0) faces down, towards +x */
#define RHO_MIRROR 0.9
#define RHO_FLOOR 0.5
#define TEXEL 0.25       /* floor texels 0.25 x 0.25: the caustic patch (about 4.6 x 4.2) spans ~300 */

/* A 12 x 12 floor (y = 0, facing up), the mirror (mirror 1: metallic 1 roughness 0, else diffuse of the
 * same colour) and the light; nothing else, so little light bounces. */
static const char *mirror_scene(int mirror)
{
    static lmt_mesh m[2];
    memset(m, 0, sizeof m);
    lmt_mesh_quad(&m[0], (float[3]){-6, 0, 6}, (float[3]){12, 0, 0}, (float[3]){0, 0, -12});
    /* u x v = -y: the mirror's front faces down, towards the light and the floor */
    lmt_mesh_quad(&m[1], (float[3]){-HALF, 0, -HALF}, (float[3]){2 * HALF, 0, 0}, (float[3]){0, 0, 2 * HALF});
    char nodes[512], materials[1024];
    snprintf(nodes, sizeof nodes,
             "[{\"mesh\": 0}, {\"mesh\": 1, \"translation\": [0, %g, 0], \"rotation\": [0, 0, %.9f, %.9f]},"
             " {\"translation\": [0, %g, 0], \"extensions\": {\"KHR_lights_punctual\": {\"light\": 0}}}]",
             MIRROR_Y, sin(0.5 * TILT), cos(0.5 * TILT), LIGHT_Y);
    snprintf(materials, sizeof materials,
             "[{\"pbrMetallicRoughness\": {\"baseColorFactor\": [%g, %g, %g, 1], \"metallicFactor\": 0,"
             " \"roughnessFactor\": 1}},"
             " {\"pbrMetallicRoughness\": {\"baseColorFactor\": [%g, %g, %g, 1], \"metallicFactor\": %d,"
             " \"roughnessFactor\": %d}}],"
             " \"extensionsUsed\": [\"KHR_lights_punctual\"], \"extensions\": {\"KHR_lights_punctual\":"
             " {\"lights\": [{\"type\": \"point\", \"intensity\": %g}]}}",
             RHO_FLOOR, RHO_FLOOR, RHO_FLOOR, RHO_MIRROR, RHO_MIRROR, RHO_MIRROR, mirror, !mirror, INTENSITY);
    return lmt_write_scene(mirror ? "mirror.gltf" : "matte.gltf", m, 2, nodes, materials);
}

/* ---- the analytic caustic ---- */

typedef struct {
    double x, y, z;
} v3;

static v3 v3_sub(v3 a, v3 b) { return (v3){a.x - b.x, a.y - b.y, a.z - b.z}; }
static double v3_dot(v3 a, v3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

static v3 mirror_normal(void) { return (v3){sin(TILT), -cos(TILT), 0.0}; }

/* The light mirrored in the mirror's plane: where the caustic seems to come from. */
static v3 virtual_light(void)
{
    v3 l = {0, LIGHT_Y, 0}, n = mirror_normal();
    double d = v3_dot(v3_sub(l, (v3){0, MIRROR_Y, 0}), n);
    return (v3){l.x - 2 * d * n.x, l.y - 2 * d * n.y, l.z - 2 * d * n.z};
}

/* Where the line from the virtual light to floor point p crosses the mirror's plane, in the mirror's
 * own coordinates (along its tilted x and along z): inside the square when both are within HALF. */
static void mirror_coords(v3 p, double *s, double *t)
{
    v3 vl = virtual_light(), m = {0, MIRROR_Y, 0}, n = mirror_normal(), d = v3_sub(p, vl);
    double k = v3_dot(v3_sub(m, vl), n) / v3_dot(d, n);
    v3 x = v3_sub((v3){vl.x + k * d.x, vl.y + k * d.y, vl.z + k * d.z}, m);
    *s = v3_dot(x, (v3){cos(TILT), sin(TILT), 0});
    *t = x.z;
}

/* 1: p lies in the caustic patch, margin (mirror units) away from its edges; -1: margin outside it; 0: in
 * between. */
static int in_patch(v3 p, double margin)
{
    double s, t;
    mirror_coords(p, &s, &t);
    if (fabs(s) < HALF - margin && fabs(t) < HALF - margin)
        return 1;
    return fabs(s) > HALF + margin || fabs(t) > HALF + margin ? -1 : 0;
}

/* E = F I cos(theta) / d^2 from the virtual light at floor point p, F the mirror's reflectance (a metal's
 * Fresnel, Schlick's with F0 = rho) at the angle the ray through p meets it. */
static double caustic_irradiance(v3 p)
{
    v3 to = v3_sub(virtual_light(), p);
    double d2 = v3_dot(to, to), cos_i = fabs(v3_dot(to, mirror_normal())) / sqrt(d2);
    return lmt_mirror_fresnel(RHO_MIRROR, 1.0 - cos_i) * INTENSITY * (to.y / sqrt(d2)) / d2;
}

static lm_ref_settings quick_settings(uint32_t caustic_photons)
{
    lm_ref_settings set;
    lm_ref_settings_default(&set);
    set.target_error = 0.2f; /* the path-traced parts matter little here */
    set.samples = 16;
    set.min_samples = 16;
    set.max_samples = 64;
    set.caustic_photons = caustic_photons;
    set.use_cache = 0;
    set.progress = 0;
    return set;
}

/* Texels well inside the patch get the analytic caustic (each within 10%, their mean within 3%); texels
 * clearly outside it get none: every photon the mirror returns lands inside. */
static void test_mirror_caustic_texels(void **state)
{
    (void)state;
    lmt_pipeline p;
    lmt_pipeline_load(&p, mirror_scene(1), TEXEL);
    lm_ref_settings set = quick_settings(LM_REF_CAUSTIC_PHOTONS);
    lm_ref_result r;
    lm_error err;
    double t0 = lm_now();
    assert_int_equal(lm_reference_texels(p.s, &p.atlas, p.rt, &p.em, &set, &r, &err), LM_OK);
    double seconds = lm_now() - t0, sum = 0.0, sum_want = 0.0, worst = 0.0, outside = 0.0;
    int inside = 0, out = 0;
    for (uint32_t i = 0; i < r.count; i++) {
        const lm_texel *t = &p.atlas.texels[i];
        if (p.s->tri_node[t->tri] != 0)
            continue; /* the floor's texels only */
        v3 q = {t->pos[0], t->pos[1], t->pos[2]};
        int where = in_patch(q, 0.15);
        double got = r.caustic[3 * i + 1], want = caustic_irradiance(q);
        if (where > 0) {
            worst = fmax(worst, fabs(got / want - 1.0));
            sum += got, sum_want += want, inside++;
        } else if (where < 0) {
            outside = fmax(outside, got);
            out++;
        }
    }
    print_message("mirror caustic, texels: %d inside the patch, measured / analytic %.4f (E %.4f / %.4f), worst "
                  "texel off by %.4f; %d outside, largest %.3g; %llu photons, caustic %.2f s of %.2f s\n",
                  inside, sum / sum_want, sum / inside, sum_want / inside, worst, out, outside,
                  (unsigned long long)r.caustic_photons, r.caustic_seconds, seconds);
    assert_true(inside > 150 && out > 1000);
    assert_int_equal(r.caustic_photons, LM_REF_CAUSTIC_PHOTONS); /* one light, one mirror node */
    assert_float_equal(sum / sum_want, 1.0, 0.03);
    assert_true(worst < 0.10);
    assert_true(outside <= 1e-3 * sum / inside);
    lm_ref_result_free(&r);
    lmt_pipeline_free(&p);
}

/* A camera over the floor: the caustic radiance summed over the patch's pixels against rho_floor / pi x E
 * at the points their centres see (the floor is Lambertian). */
static void test_mirror_caustic_pixels(void **state)
{
    (void)state;
    enum { SIDE = 48 };
    lmt_pipeline p;
    lmt_pipeline_load(&p, mirror_scene(1), 1.0f);
    v3 eye = {2, 7, 5}, fwd = {0, -7, -5};
    double len = sqrt(v3_dot(fwd, fwd));
    fwd = (v3){fwd.x / len, fwd.y / len, fwd.z / len};
    lm_view cam = {.eye = {2, 7, 5}, .forward = {(float)fwd.x, (float)fwd.y, (float)fwd.z}, .up = {0, 1, 0},
                   .yfov = 0.9f, .width = SIDE, .height = SIDE, .znear = 0.0f};
    lm_ref_settings set = quick_settings(LM_REF_CAUSTIC_PHOTONS);
    lm_ref_result r;
    lm_error err;
    assert_int_equal(lm_reference_pixels(p.s, p.rt, &p.em, &cam, &set, &r, &err), LM_OK);
    /* the camera's frame as the solver builds it: right = fwd x up, up' = right x fwd */
    v3 right = {-fwd.z, 0, fwd.x};
    double rl = sqrt(v3_dot(right, right));
    right = (v3){right.x / rl, right.y / rl, right.z / rl};
    v3 up = {right.y * fwd.z - right.z * fwd.y, right.z * fwd.x - right.x * fwd.z, right.x * fwd.y - right.y * fwd.x};
    double th = tan(0.45), got = 0.0, want = 0.0, outside = 0.0;
    int pixels = 0;
    for (int y = 0; y < SIDE; y++)
        for (int x = 0; x < SIDE; x++) {
            double sx = (2.0 * (x + 0.5) / SIDE - 1.0) * th, sy = (1.0 - 2.0 * (y + 0.5) / SIDE) * th;
            v3 d = {fwd.x + sx * right.x + sy * up.x, fwd.y + sx * right.y + sy * up.y, fwd.z + sx * right.z + sy * up.z};
            if (d.y >= 0.0)
                continue;
            double k = -eye.y / d.y;
            v3 q = {eye.x + k * d.x, 0.0, eye.z + k * d.z};
            int where = fabs(q.x) < 6.0 && fabs(q.z) < 6.0 ? in_patch(q, 0.15) : 0;
            double c = r.caustic[3 * (y * SIDE + x) + 1];
            if (where > 0) {
                got += c;
                want += RHO_FLOOR / PI * caustic_irradiance(q);
                pixels++;
            } else if (where < 0) {
                outside = fmax(outside, c);
            }
        }
    print_message("mirror caustic, pixels: %d inside the patch, measured / analytic %.4f; largest outside %.3g\n",
                  pixels, got / want, outside);
    assert_true(pixels > 100);
    assert_float_equal(got / want, 1.0, 0.10);
    assert_true(outside <= 1e-3 * got / pixels);
    lm_ref_result_free(&r);
    lmt_pipeline_free(&p);
}

/* ---- the parts ---- */

/* Texels: direct + iim + caustic + lost = full; pixels: the six parts = full (float rounding). */
static void assert_parts_add_up(const lm_ref_result *r, int texels)
{
    const float *parts[6] = {r->direct, r->caustic, r->lost, texels ? r->iim : r->emission,
                             texels ? NULL : r->indirect, texels ? NULL : r->reflections};
    double worst = 0.0;
    for (size_t i = 0; i < 3 * (size_t)r->count; i++) {
        double sum = 0.0;
        for (int k = 0; k < 6; k++)
            sum += parts[k] ? parts[k][i] : 0.0;
        worst = fmax(worst, fabs(sum - r->full[i]) / fmax(fabs(r->full[i]), 1e-6));
    }
    assert_true(worst < 1e-5);
}

static int all_zero(const float *v, uint32_t count)
{
    for (size_t i = 0; i < 3 * (size_t)count; i++)
        if (v[i] != 0.0f)
            return 0;
    return 1;
}

/* In the mirror scene the parts add up; the floor under the mirror sees the lit floor in it (lost light:
 * about rho_m x rho_f / pi x E(the floor it sees, ~1.25) x the mirror's 0.24 sr = 0.04); made diffuse,
 * the same square gives no caustic and no lost light at all, and what it reflects is the IIM's. The
 * stopping rule reads E_full, which the direct light dominates here, so every texel takes 256 paths:
 * the mirror is a 1-in-13 hit for a cosine-sampled direction. */
static void test_parts_and_lost_light(void **state)
{
    (void)state;
    for (int mirror = 1; mirror >= 0; mirror--) {
        lmt_pipeline p;
        lmt_pipeline_load(&p, mirror_scene(mirror), 0.5f);
        lm_ref_settings set = quick_settings(1u << 16);
        set.min_samples = set.max_samples = 256;
        lm_ref_result t, px;
        lm_error err;
        lm_view cam = {.eye = {2, 7, 5}, .forward = {0, -0.813733f, -0.581238f}, .up = {0, 1, 0},
                       .yfov = 0.9f, .width = 24, .height = 24, .znear = 0.0f};
        assert_int_equal(lm_reference_texels(p.s, &p.atlas, p.rt, &p.em, &set, &t, &err), LM_OK);
        assert_int_equal(lm_reference_pixels(p.s, p.rt, &p.em, &cam, &set, &px, &err), LM_OK);
        assert_parts_add_up(&t, 1);
        assert_parts_add_up(&px, 0);
        assert_null(t.emission);
        assert_null(px.iim);
        double lost = 0.0, iim = 0.0;
        int under = 0;
        for (uint32_t i = 0; i < t.count; i++) {
            const lm_texel *x = &p.atlas.texels[i];
            if (p.s->tri_node[x->tri] == 0 && fabsf(x->pos[0]) < 1.5f && fabsf(x->pos[2]) < 1.5f)
                lost += t.lost[3 * i + 1], iim += t.iim[3 * i + 1], under++;
        }
        print_message("%s: under it, mean E_lost %.4f, E_iim %.4f (%d texels)\n", mirror ? "mirror" : "diffuse",
                      lost / under, iim / under, under);
        assert_true(under > 0);
        if (mirror) {
            assert_true(under >= 16 && lost / under > 0.01);
            assert_false(all_zero(px.lost, px.count));
            assert_int_equal(t.caustic_photons, 1u << 16);
        } else {
            assert_true(all_zero(t.caustic, t.count) && all_zero(t.lost, t.count));
            assert_true(all_zero(px.caustic, px.count) && all_zero(px.lost, px.count));
            assert_true(all_zero(px.reflections, px.count));
            assert_true(iim / under > 0.1); /* what the mirror lost, the diffuse square reflects into the IIM */
            assert_int_equal(t.caustic_photons, 0);
        }
        lm_ref_result_free(&t);
        lm_ref_result_free(&px);
        lmt_pipeline_free(&p);
    }
}

/* No mirror or glass: E_iim is exactly E_full minus the punctual direct light (0 over a lone plane), the
 * picture exactly its direct part; caustic and lost exactly 0. */
static void test_no_specular_no_split(void **state)
{
    (void)state;
    lmt_pipeline p;
    lmt_pipeline_load(&p, lmt_plane_scene(), 1.0f);
    lm_ref_settings set = quick_settings(1u << 16);
    lm_view cam = {.eye = {0, 5, 0}, .forward = {0, -1, 0}, .up = {0, 0, -1},
                   .yfov = 0.5f, .width = 16, .height = 16, .znear = 0.0f};
    lm_ref_result t, px;
    lm_error err;
    assert_int_equal(lm_reference_texels(p.s, &p.atlas, p.rt, &p.em, &set, &t, &err), LM_OK);
    assert_int_equal(lm_reference_pixels(p.s, p.rt, &p.em, &cam, &set, &px, &err), LM_OK);
    size_t bytes = 3 * (size_t)t.count * sizeof(float);
    assert_memory_equal(t.full, t.direct, bytes);
    assert_true(all_zero(t.iim, t.count) && all_zero(t.caustic, t.count) && all_zero(t.lost, t.count));
    assert_memory_equal(px.full, px.direct, 3 * (size_t)px.count * sizeof(float));
    assert_true(all_zero(px.caustic, px.count) && all_zero(px.lost, px.count) && all_zero(px.indirect, px.count));
    assert_true(all_zero(px.emission, px.count) && all_zero(px.reflections, px.count));
    assert_int_equal(t.caustic_photons, 0);
    lm_ref_result_free(&t);
    lm_ref_result_free(&px);
    lmt_pipeline_free(&p);
}

/* ---- determinism, cache, settings ---- */

static void assert_same(const lm_ref_result *a, const lm_ref_result *b)
{
    const float *fa[9] = {a->full, a->iim, a->radiance, a->direct, a->caustic, a->lost, a->emission, a->indirect,
                          a->reflections};
    const float *fb[9] = {b->full, b->iim, b->radiance, b->direct, b->caustic, b->lost, b->emission, b->indirect,
                          b->reflections};
    assert_int_equal(a->count, b->count);
    for (int k = 0; k < 9; k++) {
        assert_true((fa[k] == NULL) == (fb[k] == NULL));
        if (fa[k])
            assert_memory_equal(fa[k], fb[k], 3 * (size_t)a->count * sizeof(float));
    }
    assert_memory_equal(a->samples, b->samples, a->count * sizeof(uint32_t));
    assert_int_equal(a->caustic_photons, b->caustic_photons);
}

static void test_deterministic_across_threads(void **state)
{
    (void)state;
    lmt_pipeline p;
    lmt_pipeline_load(&p, mirror_scene(1), 0.5f);
    lm_ref_settings set = quick_settings(1u << 16);
    lm_view cam = {.eye = {2, 7, 5}, .forward = {0, -0.813733f, -0.581238f}, .up = {0, 1, 0},
                   .yfov = 0.9f, .width = 16, .height = 16, .znear = 0.0f};
    lm_ref_result t[2], px[2];
    lm_error err;
    int threads = omp_get_max_threads();
    for (int k = 0; k < 2; k++) {
        omp_set_num_threads(k == 0 ? 1 : threads > 1 ? threads : 2);
        assert_int_equal(lm_reference_texels(p.s, &p.atlas, p.rt, &p.em, &set, &t[k], &err), LM_OK);
        assert_int_equal(lm_reference_pixels(p.s, p.rt, &p.em, &cam, &set, &px[k], &err), LM_OK);
    }
    omp_set_num_threads(threads);
    assert_false(all_zero(t[0].caustic, t[0].count));
    assert_same(&t[0], &t[1]);
    assert_same(&px[0], &px[1]);
    for (int k = 0; k < 2; k++) {
        lm_ref_result_free(&t[k]);
        lm_ref_result_free(&px[k]);
    }
    lmt_pipeline_free(&p);
}

/* Every part comes back from the cache; the photon count is part of the key; out of range is refused. */
static void test_cache_and_settings(void **state)
{
    (void)state;
    lmt_pipeline p;
    lmt_pipeline_load(&p, mirror_scene(1), 0.5f);
    char dir[600];
    snprintf(dir, sizeof dir, "%s/cache", lmt_tmpdir());
    lm_ref_settings set = quick_settings(1u << 14);
    set.use_cache = 1;
    set.cache_dir = dir;
    lm_view cam = {.eye = {2, 7, 5}, .forward = {0, -0.813733f, -0.581238f}, .up = {0, 1, 0},
                   .yfov = 0.9f, .width = 12, .height = 12, .znear = 0.0f};
    lm_ref_result a, b;
    lm_error err;
    for (int pixels = 0; pixels < 2; pixels++) {
        for (int k = 0; k < 2; k++) {
            lm_ref_result *r = k ? &b : &a;
            lm_status st = pixels ? lm_reference_pixels(p.s, p.rt, &p.em, &cam, &set, r, &err)
                                  : lm_reference_texels(p.s, &p.atlas, p.rt, &p.em, &set, r, &err);
            assert_int_equal(st, LM_OK);
            assert_int_equal(r->from_cache, k); /* computed, then read back */
        }
        assert_same(&a, &b);
        assert_float_equal(a.caustic_seconds, b.caustic_seconds, 0.0);
        lm_ref_result_free(&b);
        if (!pixels) {
            set.caustic_photons = 1u << 15;
            assert_int_equal(lm_reference_texels(p.s, &p.atlas, p.rt, &p.em, &set, &b, &err), LM_OK);
            assert_false(b.from_cache);
            assert_true(b.key != a.key);
            lm_ref_result_free(&b);
            set.caustic_photons = 1u << 14;
        }
        lm_ref_result_free(&a);
    }
    set.caustic_photons = 0;
    assert_int_equal(lm_reference_texels(p.s, &p.atlas, p.rt, &p.em, &set, &a, &err), LM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "caustic photons"));
    lmt_pipeline_free(&p);
}

int main(void)
{
    lm_log_set_level(LM_LOG_ERROR);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_mirror_caustic_texels),
        cmocka_unit_test(test_mirror_caustic_pixels),
        cmocka_unit_test(test_parts_and_lost_light),
        cmocka_unit_test(test_no_specular_no_split),
        cmocka_unit_test(test_deterministic_across_threads),
        cmocka_unit_test(test_cache_and_settings),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
