/* The closed-form emitter light (trace/emitter_light.h): Lambert's formula against analytic irradiance,
 * clipping at the horizon (the shading normal's and the geometric one's), single- and double-sided
 * emitters, and the sampled visibility against exact half and full shadows. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "../src/gpu/gather/hemicube.h"
#include "../src/trace/emitter_light.h"
#include "support.h"

#define PI 3.14159265358979323846

/* Quad a, b, c, d (in order) as two triangles' irradiance factors summed. */
static double quad_factor(const float q[4][3], int double_sided, const float p[3], const float n[3])
{
    const float t1[3][3] = {{q[0][0], q[0][1], q[0][2]}, {q[1][0], q[1][1], q[1][2]}, {q[2][0], q[2][1], q[2][2]}};
    const float t2[3][3] = {{q[0][0], q[0][1], q[0][2]}, {q[2][0], q[2][1], q[2][2]}, {q[3][0], q[3][1], q[3][2]}};
    return lm_triangle_irradiance_factor(t1, double_sided, p, n) + lm_triangle_irradiance_factor(t2, double_sided, p, n);
}

/* A square of half-side h at height d above the point, facing it: pi times the closed-form form factor
 * of a parallel rectangle (lm_form_factor_rect), centred and off-centre. */
static void test_parallel_square(void **state)
{
    (void)state;
    const float n[3] = {0, 1, 0};
    const float offsets[3][2] = {{0, 0}, {0.7f, -0.2f}, {3, 1}};
    for (int k = 0; k < 3; k++) {
        float h = 0.5f, d = 2.0f, x = offsets[k][0], z = offsets[k][1];
        /* facing down (-y): wound clockwise seen from above */
        const float q[4][3] = {{x - h, d, z - h}, {x + h, d, z - h}, {x + h, d, z + h}, {x - h, d, z + h}};
        const float p[3] = {0, 0, 0};
        double got = quad_factor(q, 0, p, n);
        double want = PI * lm_form_factor_rect(x - h, x + h, z - h, z + h, d);
        print_message("square at (%g, %g): %.9f, closed form %.9f\n", (double)x, (double)z, got, want);
        assert_true(fabs(got / want - 1.0) < 1e-6);
    }
}

/* A vertical 2 x 2 square at x = 1 centred on the point's horizon: only its upper half counts,
 * E = int_0^1 int_-1^1 y / (1 + y^2 + z^2)^2 dz dy = pi/4 - atan(1/sqrt 2)/sqrt 2. Facing away from the
 * point, a single-sided square gives nothing and a double-sided one the same. */
static void test_horizon_and_sides(void **state)
{
    (void)state;
    const float p[3] = {0, 0, 0}, n[3] = {0, 1, 0};
    const float towards[4][3] = {{1, -1, -1}, {1, -1, 1}, {1, 1, 1}, {1, 1, -1}}; /* normal -x */
    const float away[4][3] = {{1, -1, -1}, {1, 1, -1}, {1, 1, 1}, {1, -1, 1}};    /* normal +x */
    double want = PI / 4.0 - atan(1.0 / sqrt(2.0)) / sqrt(2.0);
    double front = quad_factor(towards, 0, p, n), back = quad_factor(away, 0, p, n), both = quad_factor(away, 1, p, n);
    print_message("half-set square: %.9f (want %.9f), behind it %.3g, double-sided %.9f\n", front, want, back, both);
    assert_true(fabs(front / want - 1.0) < 1e-6);
    assert_true(back == 0.0);
    assert_true(fabs(both / want - 1.0) < 1e-6);
    const float below[4][3] = {{1, -2, -1}, {1, -2, 1}, {1, -1, 1}, {1, -1, -1}};
    assert_true(quad_factor(below, 1, p, n) == 0.0); /* wholly under the horizon */
}

/* An emitter square (half-side 0.5) at y = 2 facing down over a floor, and an opaque sheet at y = 1
 * over x < 0. From (0, 0, 0) the sheet's edge cuts the emitter exactly in half (the integrand is even in
 * x): E = half the unoccluded value. From (3, 0, 0) nothing blocks it (exact, no sampling error); from
 * (-3, 0, 0) the sheet hides all of it. */
static void test_sampled_visibility(void **state)
{
    (void)state;
    lmt_mesh m[3];
    memset(m, 0, sizeof m);
    lmt_mesh_quad(&m[0], (float[3]){-0.5f, 2, -0.5f}, (float[3]){1, 0, 0}, (float[3]){0, 0, 1});
    lmt_mesh_quad(&m[1], (float[3]){-5, 1, -5}, (float[3]){5, 0, 0}, (float[3]){0, 0, 10});
    lmt_mesh_quad(&m[2], (float[3]){-5, 0, 5}, (float[3]){10, 0, 0}, (float[3]){0, 0, -10});
    const char *path = lmt_write_scene(
        "emitter_light.gltf", m, 3, "[{\"mesh\": 0}, {\"mesh\": 1}, {\"mesh\": 2}]",
        "[{\"pbrMetallicRoughness\": {\"baseColorFactor\": [0, 0, 0, 1]}, \"emissiveFactor\": [1, 0.5, 0.25]},"
        " {\"pbrMetallicRoughness\": {\"baseColorFactor\": [0.5, 0.5, 0.5, 1]}, \"doubleSided\": true},"
        " {\"pbrMetallicRoughness\": {\"baseColorFactor\": [0.5, 0.5, 0.5, 1]}}]");
    lmt_pipeline p;
    lmt_pipeline_load(&p, path, 0.25f);
    assert_int_equal(lm_emissive_triangle_count(p.s), 2);
    assert_true(lm_emitter_light_suits(p.s));
    lm_emitter_light el;
    lm_error err;
    assert_int_equal(lm_emitter_light_init(&el, p.s, p.rt, 0, &err), LM_ERR_INVALID);
    assert_int_equal(lm_emitter_light_init(&el, p.s, p.rt, LM_EMITTER_LIGHT_DEFAULT_RAYS, &err), LM_OK);
    const float n[3] = {0, 1, 0};
    const float xs[3] = {0.0f, 3.0f, -3.0f};
    for (int k = 0; k < 3; k++) {
        const float at[3] = {xs[k], 1e-4f, 0.0f};
        double open = PI * lm_form_factor_rect(-0.5 - xs[k], 0.5 - xs[k], -0.5, 0.5, 2.0 - 1e-4);
        float e[3], again[3];
        lm_emitter_irradiance(&el, at, n, NULL, 7u, e);
        lm_emitter_irradiance(&el, at, n, n, 7u, again);
        assert_memory_equal(e, again, sizeof e); /* same seed, same samples; ng = n cuts nothing */
        const double want[3] = {0.5 * open, open, 0.0};
        print_message("x = %+g: E %.6f (%.6f, %.6f), want %.6f\n", (double)xs[k], (double)e[0], (double)e[1],
                      (double)e[2], want[k]);
        if (k == 0)
            assert_true(fabs(e[0] / want[0] - 1.0) < 0.05);
        else if (k == 1)
            assert_true(fabs(e[0] / want[1] - 1.0) < 1e-5);
        else
            assert_true(e[0] == 0.0f);
        assert_true(fabs(e[1] - 0.5 * e[0]) <= 1e-6 * e[0] && fabs(e[2] - 0.25 * e[0]) <= 1e-6 * e[0]);
    }
    /* A point of the emitter itself, lifted 1e-4 off its face (down, its front), whose shading normal leans
     * 55 degrees from the face's (a slab lamp's smoothed edge): above the shading normal's horizon lies
     * half the emitter's plane, at the lift's distance, and it read as lighting the point (cornell-suzanne's
     * lamp gathered 7 times what its room gives it); above the geometric horizon too, none of it. */
    const float on[3] = {0.2f, 2.0f - 1e-4f, 0.0f}, ng[3] = {0, -1, 0};
    const float lean[3] = {sinf(55.0f * (float)PI / 180.0f), -cosf(55.0f * (float)PI / 180.0f), 0};
    float self[3], kept[3];
    lm_emitter_irradiance(&el, on, lean, NULL, 7u, self);
    lm_emitter_irradiance(&el, on, lean, ng, 7u, kept);
    print_message("a point of the emitter, shading normal leaning 55 degrees: E %.4f by the shading normal's "
                  "horizon alone, %.4f by both\n", (double)self[0], (double)kept[0]);
    assert_true(self[0] > 0.3f);
    assert_true(kept[0] == 0.0f);
    /* on the floor beside it, a shading normal leaning 30 degrees away: the emitter lies above the geometric
     * horizon, which then changes nothing, to the bit */
    const float floor_at[3] = {3.0f, 1e-4f, 0.0f}, up[3] = {0, 1, 0};
    const float away[3] = {sinf(30.0f * (float)PI / 180.0f), cosf(30.0f * (float)PI / 180.0f), 0};
    lm_emitter_irradiance(&el, floor_at, away, NULL, 7u, self);
    lm_emitter_irradiance(&el, floor_at, away, up, 7u, kept);
    assert_true(self[0] > 0.0f);
    assert_memory_equal(self, kept, sizeof self);
    lm_emitter_light_free(&el);
    lmt_pipeline_free(&p);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_parallel_square),
        cmocka_unit_test(test_horizon_and_sides),
        cmocka_unit_test(test_sampled_visibility),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
