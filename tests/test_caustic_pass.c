/* The screen-space caustic pass (gpu/frame/caustic_pass.h): the caustic a mirror throws on the floor, as the
 * pass filters it on screen, against the analytic image of the light; the tiles the occlusion queries
 * find against a count of the splatted photons; the power on screen against the photons'; both filters;
 * nothing read outside the photons' neighbourhood. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../src/core/vecmath.h"
#include "../src/gpu/frame/caustic_pass.h"
#include "support.h"

#define W 256
#define H 256

typedef struct {
    lmt_pipeline p;
    lm_caustics *c;
    lm_direct *d;
    lm_view view;
} fixture;

/* The mirror scene (support.h) seen from 4 m straight above (-0.15, 0, 0), 60 degrees. */
static void setup(fixture *f, uint32_t photons)
{
    lmt_pipeline_load(&f->p, lmt_mirror_scene("pass.gltf", NULL, NULL), 0.25f);
    lm_caustic_settings cs;
    lm_caustic_settings_default(&cs);
    cs.photons = photons;
    lm_error err;
    if (lm_caustics_create(f->p.s, f->p.rt, &f->p.em, &cs, &f->c, NULL, &err) != LM_OK ||
        lm_direct_create(f->p.s, &f->p.atlas, NULL, &f->d, &err) != LM_OK)
        fail_msg("%s", err.msg);
    float view[16], proj[16];
    lm_mat4_look_at(view, lm_v3(-0.15f, 4.0f, 0.0f), lm_v3(-0.15f, 0.0f, 0.0f), lm_v3(0.0f, 0.0f, -1.0f));
    lm_mat4_perspective(proj, (float)(M_PI / 3.0), 1.0f, 0.1f, 20.0f);
    assert_true(lm_view_from_matrices(view, proj, &f->view));
    if (lm_direct_draw(f->d, f->p.s, &f->p.em, &f->view, W, H, &err) != LM_OK)
        fail_msg("%s", err.msg);
}

static void teardown(fixture *f)
{
    lm_direct_free(f->d);
    lm_caustics_free(f->c);
    lmt_pipeline_free(&f->p);
}

static lm_caustic_pass *run(fixture *f, const lm_caustic_pass_settings *set, lm_caustic_pass_stats *st)
{
    lm_caustic_pass *cp = NULL;
    lm_error err;
    if (lm_caustic_pass_create(set, &cp, &err) != LM_OK ||
        lm_caustic_pass_set_photons(cp, lm_caustics_hits(f->c), lm_caustics_photon_count(f->c), &err) != LM_OK ||
        lm_caustic_pass_run(cp, 0, &f->view, lm_direct_depth_texture(f->d, 0), W, H, NULL, st, &err) != LM_OK)
        fail_msg("%s", err.msg);
    return cp;
}

/* The pass's irradiance E (W x H x 3) for set over the fixture's photons, the pass freed. */
static void irradiance(fixture *f, const lm_caustic_pass_settings *set, lm_caustic_pass_stats *st, float *E)
{
    lm_caustic_pass *cp = run(f, set, st);
    lm_error err;
    assert_int_equal(lm_caustic_pass_read_irradiance(cp, 0, E, &err), LM_OK);
    lm_caustic_pass_free(cp);
}

/* The floor point pixel (x, y) (row 0 at the top) sees: the camera looks straight down from y = 4. */
static void floor_point(int x, int y, double *wx, double *wz)
{
    double t = tan(M_PI / 6.0), sx = (2.0 * (x + 0.5) / W - 1.0) * t, sy = (1.0 - 2.0 * (y + 0.5) / H) * t;
    /* right = forward x up = (0, -1, 0) x (0, 0, -1) = (1, 0, 0); up on screen is -z */
    *wx = -0.15 + 4.0 * sx;
    *wz = -4.0 * sy;
}

/* Pixels whose filter footprint (k pixels and a margin) lies inside the lit patch read the analytic image
 * within 10% each (their mean within 2%); those whose footprint at its widest (reach pixels and a margin)
 * lies outside read 0. */
static void check_image(const float *E, int k, int reach, const char *what)
{
    double sum = 0.0, want = 0.0, worst = 0.0, outside = 0.0;
    int n_in = 0, n_out = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            int all_in = 1, all_out = 1, in;
            for (int dy = -k - 1; dy <= k + 1; dy += k + 1)
                for (int dx = -k - 1; dx <= k + 1; dx += k + 1) {
                    double wx, wz;
                    floor_point(x + dx, y + dy, &wx, &wz);
                    lmt_mirror_image(wx, wz, &in);
                    all_in &= in;
                }
            for (int dy = -reach - 1; dy <= reach + 1; dy += 1 + (reach + 1) / 4)
                for (int dx = -reach - 1; dx <= reach + 1; dx += 1 + (reach + 1) / 4) {
                    double wx, wz;
                    floor_point(x + dx, y + dy, &wx, &wz);
                    lmt_mirror_image(wx, wz, &in);
                    all_out &= !in;
                }
            double wx, wz, e = E[3 * (y * W + x) + 1];
            floor_point(x, y, &wx, &wz);
            double a = lmt_mirror_image(wx, wz, &in);
            if (all_in) {
                sum += e, want += a, n_in++;
                worst = fmax(worst, fabs(e / a - 1.0));
            } else if (all_out) {
                outside = fmax(outside, e), n_out++;
            }
        }
    print_message("%s: %d pixels inside, mean %.4f of the image, worst pixel %.3f; %d outside, brightest %.3g\n", what,
                  n_in, sum / want, worst, n_out, outside);
    assert_true(n_in > 1000);
    assert_true(fabs(sum / want - 1.0) < 0.02);
    assert_true(worst < 0.10);
    assert_true(outside == 0.0);
}

static void test_mirror_caustic(void **state)
{
    (void)state;
    fixture f;
    setup(&f, 1u << 16);
    lm_caustic_pass_settings set;
    lm_caustic_pass_settings_default(&set);
    const int default_k = set.filter_k;
    for (int sized = 0; sized < 2; sized++) /* the paper's fixed filter, and sized by density (the default) */
        for (int world = 0; world < 2; world++) {
            set.world_space = world;
            set.filter_photons = sized ? 32 : 0;
            /* the paper's filter at its 7 x 7, and the world filter at k = 3: at k = 2 its cone, k footprints
             * wide, holds too few photons where the light is dense (it never narrows below s = 1): worst pixel
             * 13.8% off; sized by density in screen space, the default k */
            set.filter_k = sized && !world ? default_k : 3;
            lm_caustic_pass_stats st;
            static float E[3 * W * H];
            irradiance(&f, &set, &st, E);
            char what[64];
            snprintf(what, sizeof what, "%s, %s filter", sized ? "sized" : "fixed", world ? "world-space" : "screen-space");
            print_message("%s: %u photons (%u points), %llu splatted, %d of %d tiles lit, %llu pixels filtered\n", what, st.photons, st.points,
                          (unsigned long long)st.splatted, st.tiles_lit, st.tiles, (unsigned long long)st.pixels_filtered);
            check_image(E, set.filter_k, sized ? LM_CAUSTIC_FILTER_REACH(set.filter_k) : set.filter_k, what);
        }
    teardown(&f);
}

/* The tiles the queries call lit are exactly those a count of the splat's photons finds (a point a photon,
 * so that the query counts photons). */
static void test_tiles_match_splat(void **state)
{
    (void)state;
    fixture f;
    setup(&f, 1u << 14);
    lm_caustic_pass_settings set;
    lm_caustic_pass_settings_default(&set);
    set.merge = 0;
    for (int tile = 8; tile <= 64; tile *= 2) {
        set.tile = tile;
        lm_caustic_pass_stats st;
        lm_caustic_pass *cp = run(&f, &set, &st);
        static float splat[4 * W * H];
        lm_error err;
        assert_int_equal(lm_caustic_pass_read_splat(cp, 0, splat, &err), LM_OK);
        int tx, ty;
        const uint8_t *lit = lm_caustic_pass_tiles(cp, 0, &tx, &ty);
        assert_int_equal(tx, (W + tile - 1) / tile);
        int n_lit = 0, mismatched = 0;
        double photons = 0.0;
        for (int j = 0; j < ty; j++)
            for (int i = 0; i < tx; i++) {
                double count = 0.0;
                for (int y = j * tile; y < (j + 1) * tile && y < H; y++)
                    for (int x = i * tile; x < (i + 1) * tile && x < W; x++)
                        count += splat[4 * (y * W + x) + 3];
                photons += count;
                mismatched += (count > 0.0) != (lit[j * tx + i] != 0);
                n_lit += lit[j * tx + i] != 0;
            }
        print_message("tile %d: %d of %d lit, %d mismatched; %.0f photons counted, %llu splatted\n", tile, n_lit, tx * ty,
                      mismatched, photons, (unsigned long long)st.splatted);
        assert_int_equal(mismatched, 0);
        assert_int_equal(n_lit, st.tiles_lit);
        assert_true(n_lit > 0 && n_lit < tx * ty / 2);
        assert_true(fabs(photons - (double)st.splatted) < 0.5);
        lm_caustic_pass_free(cp);
    }
    teardown(&f);
}

/* The photons of one pixel, receiver triangle and side drawn as one point (the default) splat what a point
 * each splats: every pixel's photon count the same, its Phi / A_pix and the irradiance within float
 * rounding; with several times fewer points. */
static void test_points_merge_photons(void **state)
{
    (void)state;
    fixture f;
    setup(&f, 1u << 14);
    lm_caustic_pass_settings set;
    lm_caustic_pass_settings_default(&set);
    assert_int_equal(set.merge, 1);
    static float splat[2][4 * W * H], E[2][3 * W * H];
    lm_caustic_pass_stats st[2];
    lm_error err;
    for (int merge = 0; merge < 2; merge++) {
        set.merge = merge;
        lm_caustic_pass *cp = run(&f, &set, &st[merge]);
        assert_int_equal(lm_caustic_pass_read_splat(cp, 0, splat[merge], &err), LM_OK);
        assert_int_equal(lm_caustic_pass_read_irradiance(cp, 0, E[merge], &err), LM_OK);
        lm_caustic_pass_free(cp);
    }
    int counts_differ = 0;
    double irr_max = 0.0, irr_diff = 0.0, e_max = 0.0, e_diff = 0.0;
    for (int i = 0; i < W * H; i++) {
        counts_differ += splat[0][4 * i + 3] != splat[1][4 * i + 3];
        for (int c = 0; c < 3; c++) {
            irr_max = fmax(irr_max, splat[0][4 * i + c]);
            irr_diff = fmax(irr_diff, fabs(splat[0][4 * i + c] - splat[1][4 * i + c]));
            e_max = fmax(e_max, E[0][3 * i + c]);
            e_diff = fmax(e_diff, fabs(E[0][3 * i + c] - E[1][3 * i + c]));
        }
    }
    print_message("%u photons as %u points (a point each: %u); pixels whose count differs %d; largest difference "
                  "of Phi / A_pix %.2e and of E %.2e of their largest\n", st[1].photons, st[1].points, st[0].points,
                  counts_differ, irr_diff / irr_max, e_diff / e_max);
    assert_int_equal(st[0].points, st[0].photons);
    assert_int_equal(st[1].photons, st[0].photons);
    assert_true(st[1].points < 0.6 * st[1].photons); /* 3,429 of 7,307 */
    assert_int_equal(counts_differ, 0);
    assert_true(irr_max > 0.0 && irr_diff < 1e-4 * irr_max);
    assert_true(e_max > 0.0 && e_diff < 1e-4 * e_max);
    teardown(&f);
}

/* Without photons nothing is drawn and the irradiance is 0; bad settings are refused naming them. */
static void test_empty_and_bad(void **state)
{
    (void)state;
    fixture f;
    setup(&f, 256);
    lm_caustic_pass *cp = NULL;
    lm_error err;
    lm_caustic_pass_settings set;
    lm_caustic_pass_settings_default(&set);
    assert_int_equal(lm_caustic_pass_create(&set, &cp, &err), LM_OK);
    lm_caustic_pass_stats st;
    assert_int_equal(lm_caustic_pass_run(cp, 0, &f.view, lm_direct_depth_texture(f.d, 0), W, H, f.d, &st, &err), LM_OK);
    assert_int_equal(st.photons, 0);
    assert_int_equal(st.tiles_lit, 0);
    static float E[3 * W * H];
    assert_int_equal(lm_caustic_pass_read_irradiance(cp, 0, E, &err), LM_OK);
    for (int i = 0; i < 3 * W * H; i++)
        assert_true(E[i] == 0.0f);
    lm_caustic_pass_free(cp);
    set.filter_k = 9;
    assert_int_equal(lm_caustic_pass_create(&set, &cp, &err), LM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "k must be"));
    lm_caustic_pass_settings_default(&set);
    set.tile = 2;
    assert_int_equal(lm_caustic_pass_create(&set, &cp, &err), LM_ERR_INVALID);
    assert_null(cp);
    lm_caustic_pass_settings_default(&set);
    set.filter_photons = -1;
    assert_int_equal(lm_caustic_pass_create(&set, &cp, &err), LM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "photons"));
    teardown(&f);
}

/* Thin light: the same patch lit by 1,024 photons, about 0.15 a pixel, so the paper's 7 x 7 filter holds
 * 7 photons and shows each as a dot. The filter sized by density (32 photons) must read the analytic
 * image over the patch's inside (pixels 10 or more from its edge) with under half the fixed filter's
 * per-pixel error, and both keep the light's mean within 10%. */
static void test_thin_light(void **state)
{
    (void)state;
    fixture f;
    setup(&f, 1u << 10);
    double rmse[2], mean[2];
    for (int sized = 0; sized < 2; sized++) {
        lm_caustic_pass_settings set;
        lm_caustic_pass_settings_default(&set);
        set.filter_photons = sized ? 32 : 0;
        lm_caustic_pass_stats st;
        static float E[3 * W * H];
        irradiance(&f, &set, &st, E);
        double d2 = 0.0, a2 = 0.0, sum = 0.0, want = 0.0;
        int n = 0;
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++) {
                int all_in = 1, in;
                for (int dy = -10; dy <= 10; dy += 5)
                    for (int dx = -10; dx <= 10; dx += 5) {
                        double wx, wz;
                        floor_point(x + dx, y + dy, &wx, &wz);
                        lmt_mirror_image(wx, wz, &in);
                        all_in &= in;
                    }
                if (!all_in)
                    continue;
                double wx, wz, e = E[3 * (y * W + x) + 1];
                floor_point(x, y, &wx, &wz);
                double a = lmt_mirror_image(wx, wz, &in);
                d2 += (e - a) * (e - a), a2 += a * a, sum += e, want += a, n++;
            }
        rmse[sized] = sqrt(d2 / a2), mean[sized] = sum / want;
        print_message("%s filter, %llu photons splatted: %d pixels inside, mean %.4f of the image, relative RMSE "
                      "%.3f\n", sized ? "sized" : "fixed", (unsigned long long)st.splatted, n, mean[sized], rmse[sized]);
        assert_true(n > 500);
        assert_true(fabs(mean[sized] - 1.0) < 0.10);
    }
    assert_true(rmse[1] < 0.5 * rmse[0]);
    teardown(&f);
}

/* The receiver mask and the mipmaps are made only near the tiles a photon projects into: a run reads
 * nothing outside them. After a run over the whole patch, a run over the photons of its left quarter reads
 * the same bits whatever the first run left elsewhere (the patch's photons at 1 or 3 times their flux),
 * at the widest filter and at the split's 2x. A view that sees no photon then reads 0 everywhere. */
static void test_reads_only_near_photons(void **state)
{
    (void)state;
    fixture f;
    setup(&f, 1u << 14);
    const lm_caustic_hit *hits = lm_caustics_hits(f.c);
    uint32_t n = lm_caustics_photon_count(f.c), left = 0;
    lm_caustic_hit *some = malloc(n * sizeof *some), *bright = malloc(n * sizeof *bright);
    assert_true(some && bright);
    float lo = INFINITY, hi = -INFINITY; /* the patch's extent along x; its left quarter */
    for (uint32_t i = 0; i < n; i++)
        if (hits[i].flux[1] > 0.0f)
            lo = fminf(lo, hits[i].pos[0]), hi = fmaxf(hi, hits[i].pos[0]);
    for (uint32_t i = 0; i < n; i++) {
        some[i] = bright[i] = hits[i];
        for (int c = 0; c < 3; c++)
            bright[i].flux[c] *= 3.0f;
        if (hits[i].pos[0] > lo + 0.25f * (hi - lo))
            memset(some[i].flux, 0, sizeof some[i].flux);
        else
            left += hits[i].flux[1] > 0.0f;
    }
    static float E[2][3 * W * H];
    lm_error err;
    for (int widen = 1; widen <= LM_CAUSTIC_FILTER_LEVELS; widen += LM_CAUSTIC_FILTER_LEVELS - 1) {
        lm_caustic_pass_stats st[2];
        for (int k = 0; k < 2; k++) {
            lm_caustic_pass *cp = NULL;
            assert_int_equal(lm_caustic_pass_create(NULL, &cp, &err), LM_OK);
            lm_caustic_pass_set_widening(cp, widen);
            unsigned depth = lm_direct_depth_texture(f.d, 0);
            assert_int_equal(lm_caustic_pass_set_photons(cp, k ? bright : hits, n, &err), LM_OK);
            assert_int_equal(lm_caustic_pass_run(cp, 0, &f.view, depth, W, H, NULL, &st[k], &err), LM_OK);
            assert_int_equal(lm_caustic_pass_set_photons(cp, some, n, &err), LM_OK);
            assert_int_equal(lm_caustic_pass_run(cp, 0, &f.view, depth, W, H, NULL, &st[k], &err), LM_OK);
            assert_int_equal(lm_caustic_pass_read_irradiance(cp, 0, E[k], &err), LM_OK);
            if (k == 1) { /* looking up, away from the floor: no photon in view */
                lm_view up;
                float view[16], proj[16];
                lm_mat4_look_at(view, lm_v3(-0.15f, 4.0f, 0.0f), lm_v3(-0.15f, 8.0f, 0.0f), lm_v3(0.0f, 0.0f, -1.0f));
                lm_mat4_perspective(proj, (float)(M_PI / 3.0), 1.0f, 0.1f, 20.0f);
                assert_true(lm_view_from_matrices(view, proj, &up));
                lm_caustic_pass_stats none;
                static float Z[3 * W * H];
                assert_int_equal(lm_caustic_pass_run(cp, 0, &up, depth, W, H, NULL, &none, &err), LM_OK);
                assert_int_equal(lm_caustic_pass_read_irradiance(cp, 0, Z, &err), LM_OK);
                assert_int_equal(none.tiles_lit, 0);
                for (int i = 0; i < 3 * W * H; i++)
                    assert_true(Z[i] == 0.0f);
            }
            lm_caustic_pass_free(cp);
        }
        double sum = 0.0;
        for (int i = 0; i < 3 * W * H; i++)
            sum += E[0][i];
        print_message("widening %dx: %u photons on the left, %d of %d tiles lit, E summed %.4g; after the bright "
                      "patch the same to the bit: %s\n", 1 << widen, left, st[0].tiles_lit, st[0].tiles, sum,
                      memcmp(E[0], E[1], sizeof E[0]) ? "no" : "yes");
        assert_true(st[0].tiles_lit > 0 && st[0].tiles_lit < st[0].tiles / 2);
        assert_true(sum > 0.0);
        assert_memory_equal(E[0], E[1], sizeof E[0]);
    }
    free(some);
    free(bright);
    teardown(&f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_mirror_caustic),
        cmocka_unit_test(test_tiles_match_splat),
        cmocka_unit_test(test_points_merge_photons),
        cmocka_unit_test(test_empty_and_bad),
        cmocka_unit_test(test_thin_light),
        cmocka_unit_test(test_reads_only_near_photons),
    };
    return cmocka_run_group_tests(tests, lmt_gl_setup, lmt_gl_teardown);
}
