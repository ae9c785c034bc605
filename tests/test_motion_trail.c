/* Texels ahead of their surfaces (issue 32, item 1; photonmap/texel_change.h): in the animated Cornell box
 * at `lmgi run`'s density (1,800 texels, 20 a frame), the lightmap is compared every 6 updates with a fresh
 * updater's bake at the same time, per 4 x 4 block of atlas texels. In the paper's order alone (whole
 * surfaces by their photons' change) the moving cube's own faces, whose photons hardly change, wait
 * behind the floor for good: a block of them is 2.1 times off after 60 updates and growing (the mean of
 * the samples' worst blocks 1.11). With texels picked by the change of what they see, the worst block is
 * 0.66 off and that mean 0.43. Both updaters run side by side on the same scene and times, so the test
 * shows the difference it guards. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <lmgi.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "edit_room.h"
#include "support.h"

#define TEXELS 1800
#define FRAMES 60
#define EVERY 6

static lmgi_updater *updater(lmgi_context *ctx, lmgi_scene *sc, float texel_change)
{
    lmgi_updater_desc d;
    memset(&d, 0, sizeof d);
    d.frame.width = d.frame.height = 0;
    d.gather.texel_change = texel_change;
    lmgi_updater *u = NULL;
    lmgi_error e;
    if (lmgi_updater_create(ctx, sc, &d, &u, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    return u;
}

/* The lightmap a fresh updater bakes at time t. */
static float *converged(lmgi_context *ctx, float t)
{
    lmgi_scene *sc = lmt_load(lmt_project_scene("cornell.glb"), TEXELS);
    lmgi_updater *u = updater(ctx, sc, 0.0f);
    lmgi_bake_desc bd = {.time = t};
    lmgi_error e;
    if (lmgi_bake(u, &bd, NULL, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    size_t n;
    float *iim = lmt_iim(u, sc, &n);
    lmgi_updater_free(u);
    lmgi_free(sc);
    return iim;
}

/* The largest relative difference of a 4 x 4 block's summed rgb (texels valid in both), against a floor
 * of 5% of the mean texel so that nearly black blocks do not dominate. */
static double worst_block(const lmgi_info *in, const float *shown, const float *want)
{
    double mean = 0.0;
    int valid = 0;
    for (size_t i = 0; i < 4 * (size_t)in->atlas_width * in->atlas_height; i += 4)
        if (want[i + 3] > 0.0f)
            mean += want[i] + want[i + 1] + want[i + 2], valid++;
    mean /= valid ? valid : 1;
    double worst = 0.0;
    for (int by = 0; by < in->atlas_height; by += 4)
        for (int bx = 0; bx < in->atlas_width; bx += 4) {
            double a = 0.0, b = 0.0;
            int c = 0;
            for (int y = by; y < by + 4 && y < in->atlas_height; y++)
                for (int x = bx; x < bx + 4 && x < in->atlas_width; x++) {
                    size_t k = 4 * ((size_t)y * in->atlas_width + x);
                    if (!(want[k + 3] > 0.0f) || !(shown[k + 3] > 0.0f))
                        continue;
                    a += shown[k] + shown[k + 1] + shown[k + 2];
                    b += want[k] + want[k + 1] + want[k + 2];
                    c++;
                }
            if (c)
                worst = fmax(worst, fabs(a - b) / fmax(b, 0.05 * mean * c));
        }
    return worst;
}

static void test_moving_cube_followed_texel_by_texel(void **state)
{
    (void)state;
    lmgi_context *ctx = lmt_context();
    lmgi_scene *sc[2] = {lmt_load(lmt_project_scene("cornell.glb"), TEXELS),
                         lmt_load(lmt_project_scene("cornell.glb"), TEXELS)};
    lmgi_updater *u[2] = {updater(ctx, sc[0], (float)LMGI_OFF), updater(ctx, sc[1], 0.0f)};
    lmgi_info in;
    lmgi_get_info(sc[0], &in);
    double worst[2] = {0.0, 0.0}, sum[2] = {0.0, 0.0};
    int samples = 0;
    lmgi_error e;
    for (int f = 0; f < FRAMES; f++) {
        for (int k = 0; k < 2; k++)
            if (lmgi_update(u[k], (float)f / 30.0f, 0.0f, NULL, &e) != LMGI_OK)
                fail_msg("%s", e.message);
        if (f % EVERY != EVERY - 1)
            continue;
        float *want = converged(ctx, (float)f / 30.0f);
        for (int k = 0; k < 2; k++) {
            size_t n;
            float *shown = lmt_iim(u[k], sc[k], &n);
            double w = worst_block(&in, shown, want);
            worst[k] = fmax(worst[k], w);
            sum[k] += w;
            free(shown);
        }
        samples++;
        free(want);
    }
    print_message("animated Cornell box, %d updates: worst 4x4 block off the fresh bake by %.2f (mean of the "
                  "samples' worst %.2f) with whole surfaces only, %.2f (%.2f) with texels ahead\n",
                  FRAMES, worst[0], sum[0] / samples, worst[1], sum[1] / samples);
    assert_true(worst[0] > 1.5);  /* the stall this guards against (2.06 measured) */
    /* 0.66 and 0.43 measured (the frame budget, 20 texels, is spent every update); 0.86 and 0.50 while the
     * texels a surface's refresh gathered kept their change, and the bar to go ahead with it */
    assert_true(worst[1] < 0.8);
    assert_true(sum[1] / samples < 0.45 * sum[0] / samples); /* 0.43 against 1.11 */
    for (int k = 0; k < 2; k++) {
        lmgi_updater_free(u[k]);
        lmgi_free(sc[k]);
    }
    lmgi_context_free(ctx);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_moving_cube_followed_texel_by_texel),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
