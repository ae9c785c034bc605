/* core: matrices, quaternions, a view's part of a box, sRGB, images, palette. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "../src/core/camera.h"
#include "../src/core/image.h"
#include "../src/core/memory.h"
#include "../src/core/palette.h"
#include "../src/core/tonemap.h"
#include "../src/core/vecmath.h"
#include "support.h"

static void test_trs_matches_composition(void **state)
{
    (void)state;
    /* 90 degrees about Y: x -> -z. Then scale 2 and translate (1,2,3). */
    float q[4] = {0, sinf((float)M_PI / 4), 0, cosf((float)M_PI / 4)};
    float t[3] = {1, 2, 3}, s[3] = {2, 2, 2}, m[16];
    lm_mat4_from_trs(m, t, q, s);
    lm_vec3 p = lm_mat4_point(m, lm_v3(1, 0, 0));
    assert_float_equal(p.x, 1.0f, 1e-5);
    assert_float_equal(p.y, 2.0f, 1e-5);
    assert_float_equal(p.z, 3.0f - 2.0f, 1e-5);
}

static void test_affine_inverse(void **state)
{
    (void)state;
    float q[4] = {0.1f, 0.7f, -0.3f, 0.6f};
    lm_quat_normalize(q);
    float t[3] = {-4, 5, 0.5f}, s[3] = {0.5f, 3, 1.5f}, m[16], inv[16], id[16];
    lm_mat4_from_trs(m, t, q, s);
    assert_true(lm_mat4_invert_affine(inv, m));
    lm_mat4_mul(id, m, inv);
    for (int i = 0; i < 16; i++)
        assert_float_equal(id[i], (i % 5 == 0) ? 1.0f : 0.0f, 1e-5);
    float sing[16] = {0};
    assert_false(lm_mat4_invert_affine(inv, sing));
}

/* A projection (not affine) times its inverse is the identity; a singular matrix has none. */
static void test_general_inverse(void **state)
{
    (void)state;
    float p[16], v[16], m[16], inv[16], id[16];
    lm_mat4_perspective(p, 0.9f, 1.5f, 0.1f, 500.0f);
    lm_mat4_look_at(v, lm_v3(3, 4, 5), lm_v3(0, 1, -2), lm_v3(0, 1, 0));
    lm_mat4_mul(m, p, v);
    assert_true(lm_mat4_invert(inv, m));
    lm_mat4_mul(id, m, inv);
    for (int i = 0; i < 16; i++)
        assert_float_equal(id[i], (i % 5 == 0) ? 1.0f : 0.0f, 1e-4);
    float sing[16] = {1, 2, 3, 4, 2, 4, 6, 8, 0, 0, 1, 0, 0, 0, 0, 1};
    assert_false(lm_mat4_invert(inv, sing));
}

/* lm_view_box_part(v, lo, hi, max_depth): at least 8 points (a slice of the frustum), every one in lo..hi
 * and inside v's clip volume (to eps), their bounds want0..want1 (to tol). */
static void check_part(const lm_view *v, const float lo[3], const float hi[3], float max_depth, const float want0[3],
                       const float want1[3], double tol)
{
    float pts[LM_VIEW_BOX_POINTS][3], vp[16], b0[3], b1[3];
    int n = lm_view_box_part(v, lo, hi, max_depth, pts);
    assert_true(n >= 8);
    lm_mat4_mul(vp, v->proj, v->view);
    for (int k = 0; k < 3; k++)
        b0[k] = INFINITY, b1[k] = -INFINITY;
    for (int i = 0; i < n; i++) {
        float c[4];
        for (int r = 0; r < 4; r++)
            c[r] = vp[r] * pts[i][0] + vp[4 + r] * pts[i][1] + vp[8 + r] * pts[i][2] + vp[12 + r];
        for (int k = 0; k < 3; k++) {
            b0[k] = fminf(b0[k], pts[i][k]), b1[k] = fmaxf(b1[k], pts[i][k]);
            assert_true(pts[i][k] >= lo[k] - 1e-3f && pts[i][k] <= hi[k] + 1e-3f);
            assert_true(fabsf(c[k]) <= c[3] * (1.0f + 1e-4f) + 1e-4f);
        }
    }
    for (int k = 0; k < 3; k++) {
        assert_float_equal(b0[k], want0[k], tol);
        assert_float_equal(b1[k], want1[k], tol);
    }
}

/* lm_view_box_part: a 90-degree camera at the origin looking down -z (near 1, far 100). A slab z in
 * [-10, -5] wider than the view: the frustum's slice, corners (+-5, +-5, -5) and (+-10, +-10, -10); no
 * deeper than 7.5: (+-7.5, +-7.5, -7.5) the far ones. A box holding the whole frustum: its 8 corners. A
 * box behind the camera: nothing. lm_view_box_reach: the slab's 10, the far plane's 100. */
static void test_view_box_part(void **state)
{
    (void)state;
    lm_view v;
    memset(&v, 0, sizeof v);
    lm_mat4_identity(v.view);
    lm_mat4_perspective(v.proj, (float)M_PI / 2, 1.0f, 1.0f, 100.0f);
    const float lo[3] = {-100, -100, -10}, hi[3] = {100, 100, -5};
    check_part(&v, lo, hi, 0.0f, (const float[3]){-10, -10, -10}, (const float[3]){10, 10, -5}, 1e-3);
    assert_float_equal(lm_view_box_reach(&v, lo, hi), 10.0f, 1e-3);
    check_part(&v, lo, hi, 7.5f, (const float[3]){-7.5f, -7.5f, -7.5f}, (const float[3]){7.5f, 7.5f, -5}, 1e-3);
    const float big0[3] = {-200, -200, -200}, big1[3] = {200, 200, 200};
    assert_float_equal(lm_view_box_reach(&v, big0, big1), 100.0f, 1e-2);
    check_part(&v, big0, big1, 0.0f, (const float[3]){-100, -100, -100}, (const float[3]){100, 100, -1}, 1e-2);
    float pts[LM_VIEW_BOX_POINTS][3];
    const float back0[3] = {-5, -5, 2}, back1[3] = {5, 5, 8};
    assert_int_equal(lm_view_box_part(&v, back0, back1, 0.0f, pts), 0);
}

static void test_normal_transform_non_uniform_scale(void **state)
{
    (void)state;
    /* Scaling x by 4 tilts a 45-degree normal toward y: n' ~ (1/4, 1, 0). */
    float m[16];
    lm_mat4_identity(m);
    m[0] = 4.0f;
    lm_vec3 n = lm_mat4_normal(m, lm_normalize(lm_v3(1, 1, 0)));
    lm_vec3 want = lm_normalize(lm_v3(0.25f, 1, 0));
    assert_float_equal(n.x, want.x, 1e-5);
    assert_float_equal(n.y, want.y, 1e-5);
    /* A mirror in x leaves the plane z = c and its normal +z alone (glTF flips the winding instead). */
    m[0] = -1.0f;
    n = lm_mat4_normal(m, lm_v3(0, 0, 1));
    assert_float_equal(n.z, 1.0f, 1e-6);
}

/* lm_sincos_turn against double-precision sin and cos of 2 pi u over a fine sweep of [0, 1) (every
 * quadrant and its seams), and the values of its quarter turns exactly. */
static void test_sincos_turn(void **state)
{
    (void)state;
    double worst = 0.0;
    for (int i = 0; i < 1 << 20; i++) {
        float u = (float)i / (float)(1 << 20), s, c;
        lm_sincos_turn(u, &s, &c);
        double a = 2.0 * M_PI * (double)u;
        worst = fmax(worst, fmax(fabs(s - sin(a)), fabs(c - cos(a))));
    }
    float s, c;
    lm_sincos_turn(0x1.fffffep-1f, &s, &c); /* the largest u below 1 */
    worst = fmax(worst, fmax(fabs(s - sin(2.0 * M_PI * 0x1.fffffep-1)), fabs(c - 1.0)));
    assert_true(worst < 2e-7);
    const float quarter[4][2] = {{0, 1}, {1, 0}, {0, -1}, {-1, 0}};
    for (int q = 0; q < 4; q++) {
        lm_sincos_turn(0.25f * (float)q, &s, &c);
        assert_true(s == quarter[q][0] && c == quarter[q][1]);
    }
}

/* lm_onb gives an orthonormal right-handed frame around unit normals all over the sphere, including
 * both poles (its one seam is the sign of n.z). */
static void test_onb(void **state)
{
    (void)state;
    for (int i = 0; i <= 64; i++)
        for (int j = 0; j < 64; j++) {
            float th = (float)M_PI * (float)i / 64.0f, ph = 2.0f * (float)M_PI * (float)j / 64.0f;
            lm_vec3 n = lm_v3(sinf(th) * cosf(ph), sinf(th) * sinf(ph), cosf(th)), t, b;
            lm_onb(n, &t, &b);
            assert_float_equal(lm_dot(t, t), 1.0f, 1e-5);
            assert_float_equal(lm_dot(b, b), 1.0f, 1e-5);
            assert_float_equal(lm_dot(t, b), 0.0f, 1e-5);
            assert_float_equal(lm_dot(t, n), 0.0f, 1e-5);
            assert_float_equal(lm_dot(b, n), 0.0f, 1e-5);
            assert_float_equal(lm_dot(lm_cross(t, b), n), 1.0f, 1e-5);
        }
}

static void test_slerp(void **state)
{
    (void)state;
    float a[4] = {0, 0, 0, 1}, b[4] = {0, 1, 0, 0}, q[4]; /* 0 and 180 degrees about Y */
    lm_quat_slerp(q, a, b, 0.5f);
    assert_float_equal(q[1], sinf((float)M_PI / 4), 1e-5);
    assert_float_equal(q[3], cosf((float)M_PI / 4), 1e-5);
    /* Opposite-sign quaternions are the same rotation: slerp takes the short way. */
    float nb[4] = {0, -sinf(0.1f), 0, -cosf(0.1f)};
    lm_quat_slerp(q, a, nb, 1.0f);
    assert_float_equal(fabsf(q[3]), cosf(0.1f), 1e-5);
}

static void test_srgb_round_trip(void **state)
{
    (void)state;
    for (int i = 0; i <= 100; i++) {
        float c = i / 100.0f;
        assert_float_equal(lm_srgb_to_linear(lm_linear_to_srgb(c)), c, 1e-5);
    }
    assert_float_equal(lm_srgb_to_linear(0.5f), 0.21404f, 1e-4);
    assert_float_equal(lm_linear_to_srgb(NAN), 0.0f, 0.0);
}

static void test_exr_round_trip(void **state)
{
    (void)state;
    const char *dir = lmt_tmpdir();
    char path[512];
    snprintf(path, sizeof path, "%s/x.exr", dir);
    float data[4 * 3 * 3];
    for (int i = 0; i < 36; i++)
        data[i] = 0.01f * (float)(i * i) - 1.0f;
    lm_error err;
    assert_int_equal(lm_write_exr(path, 4, 3, 3, data, &err), LM_OK);
    int w, h;
    float *back = NULL;
    assert_int_equal(lm_read_exr(path, &w, &h, &back, &err), LM_OK);
    assert_int_equal(w, 4);
    assert_int_equal(h, 3);
    for (int i = 0; i < 12; i++)
        for (int c = 0; c < 3; c++)
            assert_float_equal(back[4 * i + c], data[3 * i + c], 1e-6);
    free(back);
    remove(path);
    /* Unwritable path: an error naming it. */
    assert_int_equal(lm_write_exr("/nonexistent-dir/x.exr", 4, 3, 3, data, &err), LM_ERR_IO);
    assert_non_null(strstr(err.msg, "/nonexistent-dir/x.exr"));
    assert_int_equal(lm_write_png("/nonexistent-dir/x.png", 1, 1, (const uint8_t *)"abcd", &err), LM_ERR_IO);
    assert_non_null(strstr(err.msg, "x.png"));
}

static void test_png_round_trip(void **state)
{
    (void)state;
    char path[512];
    snprintf(path, sizeof path, "%s/x.png", lmt_tmpdir());
    uint8_t px[2 * 2 * 4] = {255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 10, 20, 30, 255};
    lm_error err;
    assert_int_equal(lm_write_png(path, 2, 2, px, &err), LM_OK);
    int w, h;
    uint8_t *back = NULL;
    assert_int_equal(lm_read_image8(path, &w, &h, &back, &err), LM_OK);
    assert_memory_equal(back, px, sizeof px);
    free(back);
    remove(path);
}

/* In a child under a 4 KB file-size limit (as a full disk: writes fail part way), whether a PNG (png = 1)
 * or EXR of noise fails with an error naming the file, leaves no NAME.partial and keeps what the file
 * held before. Returns 0 when all three hold, else which one failed. */
static int write_past_limit(const char *dir, int png)
{
    char path[600], partial[620];
    snprintf(path, sizeof path, "%s/old.%s", dir, png ? "png" : "exr");
    snprintf(partial, sizeof partial, "%s.partial", path);
    FILE *f = fopen(path, "wb");
    if (!f || fputs("earlier output", f) < 0 || fclose(f) != 0)
        return 10;
    enum { N = 64 };
    static uint8_t px[N * N * 4];
    static float fx[N * N * 3];
    unsigned r = 12345u;
    for (int i = 0; i < N * N * 4; i++)
        r = r * 1664525u + 1013904223u, px[i] = (uint8_t)(r >> 24);
    for (int i = 0; i < N * N * 3; i++)
        fx[i] = (float)px[i] / 255.0f;
    signal(SIGXFSZ, SIG_IGN);
    struct rlimit lim = {4096, 4096};
    if (setrlimit(RLIMIT_FSIZE, &lim) != 0)
        return 11;
    lm_error err;
    lm_status st = png ? lm_write_png(path, N, N, px, &err) : lm_write_exr(path, N, N, 3, fx, &err);
    if (st != LM_ERR_IO || !strstr(err.msg, path) || !strstr(err.msg, "write failed"))
        return 1;
    if (access(partial, F_OK) == 0)
        return 2;
    char back[32] = {0};
    f = fopen(path, "rb");
    if (!f || fread(back, 1, sizeof back - 1, f) != 14 || strcmp(back, "earlier output") != 0)
        return 3;
    fclose(f);
    return 0;
}

/* A full disk wrote 133 zero-byte PNGs and 13 zero-byte EXRs without an error (stb's PNG writer does
 * not check its writes): now every write is checked and a file is whole or absent. */
static void test_write_past_limit(void **state)
{
    (void)state;
    const char *dir = lmt_tmpdir();
    for (int png = 0; png < 2; png++) {
        fflush(NULL);
        pid_t pid = fork();
        assert_true(pid >= 0);
        if (pid == 0)
            _exit(write_past_limit(dir, png));
        int status;
        assert_int_equal(waitpid(pid, &status, 0), pid);
        assert_true(WIFEXITED(status));
        if (WEXITSTATUS(status) != 0)
            fail_msg("%s past the file-size limit: check %d failed", png ? "PNG" : "EXR", WEXITSTATUS(status));
    }
}

/* A plan larger than the machine is refused naming what and the advice; a large one is allowed (warned). */
static void test_memory_plan(void **state)
{
    (void)state;
    double have = (double)lm_memory_physical();
    assert_true(have > 0.0);
    lm_error err;
    assert_int_equal(lm_memory_plan("a test atlas", 2.0 * have, "use fewer texels", &err), LM_ERR_NOMEM);
    assert_non_null(strstr(err.msg, "a test atlas"));
    assert_non_null(strstr(err.msg, "use fewer texels"));
    assert_int_equal(lm_memory_plan("a test atlas", 0.5 * have, "use fewer texels", &err), LM_OK);
    assert_int_equal(lm_memory_plan("a test atlas", 1e6, "use fewer texels", &err), LM_OK);
}

static void test_palette_distinct(void **state)
{
    (void)state;
    /* The first 64 ids (more surfaces than most single rooms) all get different colours. */
    uint8_t c[64][3];
    for (int i = 0; i < 64; i++)
        lm_id_color(i, c[i]);
    for (int i = 0; i < 64; i++)
        for (int j = 0; j < i; j++)
            assert_true(memcmp(c[i], c[j], 3) != 0);
}

static void test_mkdir_p(void **state)
{
    (void)state;
    char path[512];
    snprintf(path, sizeof path, "%s/a/b/c", lmt_tmpdir());
    lm_error err;
    assert_int_equal(lm_mkdir_p(path, &err), LM_OK);
    assert_int_equal(lm_mkdir_p(path, &err), LM_OK); /* exists: fine */
    assert_int_equal(lm_mkdir_p("/proc/lmgi-cannot-be-here", &err), LM_ERR_IO);
}

static void test_tonemap(void **state)
{
    (void)state;
    /* 100 grey values 1..99 and a hot 1000: the 99th percentile (99) maps to 0.9; 1000 clips to 1. */
    float rgb[100 * 3];
    for (int i = 0; i < 100; i++)
        rgb[3 * i] = rgb[3 * i + 1] = rgb[3 * i + 2] = i < 99 ? (float)(i + 1) : 1000.0f;
    float k = lm_auto_exposure(rgb, 100, 3);
    assert_float_equal(k, 0.9f / 99.0f, 1e-6);
    uint8_t out[100 * 4];
    lm_tonemap_srgb8(rgb, 100, 3, k, out);
    assert_int_equal(out[4 * 99], 255);
    assert_int_equal(out[4 * 98], (int)(255.0f * lm_linear_to_srgb(0.9f) + 0.5f));
    assert_int_equal(out[3], 255);
    float zero[3] = {0, 0, 0};
    assert_float_equal(lm_auto_exposure(zero, 1, 3), 1.0f, 0.0); /* nothing lit: no scaling */
}

/* Khronos PBR Neutral against its formula worked by hand: grey 0.5 loses the 0.04 offset and is
 * otherwise untouched (below the 0.76 shoulder); grey 2 compresses to 1 - 0.24^2 / 1.44 = 0.96 exactly
 * (the desaturation mixes grey with grey); colours keep their order; nothing passes 1. Automatic
 * exposure puts the median lit luminance at 0.18. */
static void test_tonemap_neutral(void **state)
{
    (void)state;
    float rgb[6 * 3] = {0.5f, 0.5f, 0.5f, 2.0f, 2.0f, 2.0f, 0.6f, 0.3f, 0.1f, 1e6f, 1e6f, 1e6f, 0, 0, 0, 40, 2, 1};
    uint8_t out[6 * 4];
    lm_tonemap(LM_TONEMAP_NEUTRAL, rgb, 6, 3, 1.0f, out);
    assert_int_equal(out[0], (int)(255.0f * lm_linear_to_srgb(0.46f) + 0.5f));
    assert_int_equal(out[4], (int)(255.0f * lm_linear_to_srgb(0.96f) + 0.5f));
    assert_int_equal(out[4], out[6]);
    assert_int_equal(out[8], (int)(255.0f * lm_linear_to_srgb(0.56f) + 0.5f)); /* 0.6 - 0.04 */
    assert_int_equal(out[9], (int)(255.0f * lm_linear_to_srgb(0.26f) + 0.5f));
    assert_int_equal(out[12], 255); /* a hot pixel goes to white, not past it */
    assert_int_equal(out[16], 0);
    assert_true(out[20] == 255 && out[21] < out[20] && out[22] <= out[21]); /* a bright red stays reddish */
    float grey[5 * 3];
    for (int i = 0; i < 5; i++) /* lit luminances 1, 2, 3, 4 and one unlit: median 2 (the unlit left out) */
        grey[3 * i] = grey[3 * i + 1] = grey[3 * i + 2] = (float)i;
    assert_float_equal(lm_tonemap_exposure(LM_TONEMAP_NEUTRAL, grey, 5, 3), 0.18f / 2.0f, 1e-6);
    assert_float_equal(lm_tonemap_exposure(LM_TONEMAP_CLAMP, grey, 5, 3), lm_auto_exposure(grey, 5, 3), 0.0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_trs_matches_composition),
        cmocka_unit_test(test_affine_inverse),
        cmocka_unit_test(test_normal_transform_non_uniform_scale),
        cmocka_unit_test(test_sincos_turn),
        cmocka_unit_test(test_onb),
        cmocka_unit_test(test_slerp),
        cmocka_unit_test(test_srgb_round_trip),
        cmocka_unit_test(test_exr_round_trip),
        cmocka_unit_test(test_png_round_trip),
        cmocka_unit_test(test_write_past_limit),
        cmocka_unit_test(test_memory_plan),
        cmocka_unit_test(test_palette_distinct),
        cmocka_unit_test(test_mkdir_p), cmocka_unit_test(test_general_inverse), cmocka_unit_test(test_view_box_part),
        cmocka_unit_test(test_tonemap),
        cmocka_unit_test(test_tonemap_neutral),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
