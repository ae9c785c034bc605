/* Texels ahead of their surfaces (issue 32, item 1; photonmap/texel_change.h): in the animated Cornell box
 * at `lmgi run`'s density (1,800 texels, 20 a frame), the lightmap is compared every 6 updates with a fresh
 * updater's bake at the same time, per 4 x 4 block of atlas texels. In the paper's order alone (whole
 * surfaces by their photons' change) the moving cube's own faces, whose photons hardly change, wait
 * behind the floor for good: a block of them is 2.1 times off after 60 updates and growing (the mean of
 * the samples' worst blocks 1.11). With texels picked by the change of what they see, the worst block is
 * 0.46 off and that mean 0.30 (0.55 and 0.32 before animated nodes' paths were queued by their boxes and a
 * texel recommitted soon after its last commit blended over fewer updates); with the texels still waiting
 * shown from an estimate (progressive refinement, item 3; gpu/gather/iim.h), 0.20 and 0.10 (0.27 and 0.11
 * before a third of the estimates went by their expected staleness, ray_estimate.h; 0.35 and 0.12
 * before a texel's estimate took finer rays where its 36 misjudged it; 0.39 and 0.14
 * before the animated nodes' photons were re-traced at once and 8 AIMs refreshed an update; their
 * neighbours' changes alone: 0.46 and 0.27; 0.62 / 0.35 and 0.47 / 0.29 while a commit's own frame showed
 * none of its step, iim.h). The updaters run side by side on the
 * same scene and times, so the test shows the difference it guards. */
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

static lmgi_updater *updater_with(lmgi_context *ctx, lmgi_scene *sc, const lmgi_updater_desc *d)
{
    lmgi_updater *u = NULL;
    lmgi_error e;
    if (lmgi_updater_create(ctx, sc, d, &u, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    return u;
}

static lmgi_updater *updater(lmgi_context *ctx, lmgi_scene *sc, float texel_change, int spread)
{
    lmgi_updater_desc d;
    memset(&d, 0, sizeof d);
    d.gather.texel_change = texel_change;
    d.gather.spread = spread;
    return updater_with(ctx, sc, &d);
}

/* The lightmap a fresh updater bakes at time t. */
static float *converged(lmgi_context *ctx, float t)
{
    lmgi_scene *sc = lmt_load(lmt_project_scene("cornell.glb"), TEXELS);
    lmgi_updater *u = updater(ctx, sc, 0.0f, 0);
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

/* The mean texel's summed rgb of want (its valid texels). */
static double mean_texel(const lmgi_info *in, const float *want)
{
    double mean = 0.0;
    int valid = 0;
    for (size_t i = 0; i < 4 * (size_t)in->atlas_width * in->atlas_height; i += 4)
        if (want[i + 3] > 0.0f)
            mean += want[i] + want[i + 1] + want[i + 2], valid++;
    return mean / (valid ? valid : 1);
}

/* The relative difference of the 4 x 4 block at (bx, by)'s summed rgb (texels valid in both), against a floor
 * of 5% of the mean texel so that nearly black blocks do not dominate; 0 for a block with no such texel. */
static double block_error(const lmgi_info *in, const float *shown, const float *want, int bx, int by, double mean)
{
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
    return c ? fabs(a - b) / fmax(b, 0.05 * mean * c) : 0.0;
}

/* The largest block_error. */
static double worst_block(const lmgi_info *in, const float *shown, const float *want)
{
    double mean = mean_texel(in, want), worst = 0.0;
    for (int by = 0; by < in->atlas_height; by += 4)
        for (int bx = 0; bx < in->atlas_width; bx += 4)
            worst = fmax(worst, block_error(in, shown, want, bx, by, mean));
    return worst;
}

/* The largest step between two neighbouring texels (valid in both) that the fresh bake does not have:
 * |(shown_a - shown_b) - (want_a - want_b)| of the summed rgb over the mean texel; with `before` (the
 * lightmap before an edit), how far the step lies outside those of every mix of the two. A texel gathered
 * among stale neighbours is such a step on all four sides, the hard-edged square of issue 32, item 3, where
 * a stale region's own edges, or a region part way from one to the other, are not. */
static double worst_step(const lmgi_info *in, const float *shown, const float *want, const float *before)
{
    const int W = in->atlas_width, H = in->atlas_height;
    double mean = mean_texel(in, want), worst = 0.0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            for (int d = 0; d < 2; d++) {
                int xx = x + (d == 0), yy = y + (d == 1);
                if (xx >= W || yy >= H)
                    continue;
                size_t a = 4 * ((size_t)y * W + x), b = 4 * ((size_t)yy * W + xx);
                if (!(want[a + 3] > 0.0f) || !(want[b + 3] > 0.0f) || !(shown[a + 3] > 0.0f) || !(shown[b + 3] > 0.0f))
                    continue;
                double ds = 0.0, dw = 0.0, db = 0.0;
                for (int c = 0; c < 3; c++) {
                    ds += shown[a + c] - shown[b + c], dw += want[a + c] - want[b + c];
                    if (before)
                        db += before[a + c] - before[b + c];
                }
                double err = fabs(ds - dw);
                if (before && before[a + 3] > 0.0f && before[b + 3] > 0.0f) /* outside every mix of the two */
                    err = fmax(0.0, fmax(ds - fmax(dw, db), fmin(dw, db) - ds));
                worst = fmax(worst, err / mean);
            }
    return worst;
}

static void test_moving_cube_followed_texel_by_texel(void **state)
{
    (void)state;
    lmgi_context *ctx = lmt_context();
    lmgi_scene *sc[3];
    for (int k = 0; k < 3; k++)
        sc[k] = lmt_load(lmt_project_scene("cornell.glb"), TEXELS);
    /* whole surfaces only; texels ahead, each shown alone; texels ahead, those waiting shown from them */
    lmgi_updater *u[3] = {updater(ctx, sc[0], (float)LMGI_OFF, 0), updater(ctx, sc[1], 0.0f, LMGI_OFF),
                          updater(ctx, sc[2], 0.0f, 0)};
    lmgi_info in;
    lmgi_get_info(sc[0], &in);
    double worst[3] = {0}, sum[3] = {0}, step[3] = {0}, step_sum[3] = {0};
    int samples = 0;
    lmgi_error e;
    for (int f = 0; f < FRAMES; f++) {
        for (int k = 0; k < 3; k++)
            if (lmgi_update(u[k], (float)f / 30.0f, 0.0f, NULL, &e) != LMGI_OK)
                fail_msg("%s", e.message);
        if (f % EVERY != EVERY - 1)
            continue;
        float *want = converged(ctx, (float)f / 30.0f);
        for (int k = 0; k < 3; k++) {
            size_t n;
            float *shown = lmt_iim(u[k], sc[k], &n);
            double w = worst_block(&in, shown, want), st = worst_step(&in, shown, want, NULL);
            worst[k] = fmax(worst[k], w);
            sum[k] += w;
            step[k] = fmax(step[k], st);
            step_sum[k] += st;
            free(shown);
        }
        samples++;
        free(want);
    }
    static const char *const name[3] = {"whole surfaces only", "texels ahead, each alone",
                                        "texels ahead, those waiting from them"};
    for (int k = 0; k < 3; k++)
        print_message("animated Cornell box, %d updates, %s: worst 4x4 block off the fresh bake by %.2f (mean of "
                      "the samples' worst %.2f); worst step between neighbours %.2f of the mean texel (mean %.2f)\n",
                      FRAMES, name[k], worst[k], sum[k] / samples, step[k], step_sum[k] / samples);
    assert_true(worst[0] > 1.5);  /* the stall this guards against (2.06 measured) */
    /* each alone: 0.43 and 0.28 measured (0.46 and 0.30 with 4 AIMs an update; 0.55 and 0.32 before the boxes and the shorter blends; 0.62 and 0.35 while a commit's frame showed none of it; 0.66 and 0.43 with the bar to go ahead at 4 times the atlas's mean
     * change, not its median) (the frame budget, 20 texels, is spent every update); 0.86 and 0.50
     * while the texels a surface's refresh gathered kept their change, and the bar to go ahead with it */
    assert_true(worst[1] < 0.8);
    assert_true(sum[1] / samples < 0.45 * sum[0] / samples); /* 0.32 against 1.11 */
    /* those waiting shown from an estimate (progressive refinement, issue 32 item 3): their own rays' */
    assert_true(worst[2] < 0.58); /* 0.20 measured (0.27 with halves by change and by wait; 0.35 with 36 rays
                                   * a texel throughout; 0.39 with 4 AIMs an update; 0.46 from their
                                   * neighbours' changes alone) */
    assert_true(sum[2] / samples < 0.85 * sum[1] / samples); /* 0.10 against 0.28 (0.14 against 0.30) */
    for (int k = 0; k < 3; k++) {
        lmgi_updater_free(u[k]);
        lmgi_free(sc[k]);
    }
    lmgi_context_free(ctx);
}

/* The animated box updated with every photon re-traced, every AIM refreshed and every texel regathered
 * each update, in the paper's order, and no blend (blend_frames 1): its lightmap is then a fresh bake's at the same time, update
 * after update, within 2% per 4 x 4 block (0.000 measured). Before the blend's commit frame showed 1 /
 * blend_frames of the step, a texel committed every update showed its first value for good: the floor
 * under the cube 1.4 while its gathers went 1.41, 1.46, ... 1.78, blocks 0.55 to 2.4 times off and 18 of
 * them over 10% after 40 updates. */
static void test_full_work_follows_animation(void **state)
{
    (void)state;
    lmgi_context *ctx = lmt_context();
    lmgi_scene *sc = lmt_load(lmt_project_scene("cornell.glb"), TEXELS);
    lmgi_updater_desc d;
    memset(&d, 0, sizeof d);
    d.gather.texels_per_frame = 100000;
    d.gather.blend_frames = 1;
    d.photons.group_budget = 1 << 20;
    d.photons.retrace_per_group = 1000000;
    d.aim.surfaces_per_frame = 100000;
    d.in_order = 1; /* the gather over this update's photons, as a bake's */
    lmgi_updater *u = NULL;
    lmgi_error e;
    if (lmgi_updater_create(ctx, sc, &d, &u, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    lmgi_info in;
    lmgi_get_info(sc, &in);
    double worst = 0.0;
    for (int f = 0; f < 12; f++) {
        if (lmgi_update(u, (float)f / 30.0f, 0.0f, NULL, &e) != LMGI_OK)
            fail_msg("%s", e.message);
        float *want = converged(ctx, (float)f / 30.0f);
        size_t n;
        float *shown = lmt_iim(u, sc, &n);
        worst = fmax(worst, worst_block(&in, shown, want));
        free(shown);
        free(want);
    }
    print_message("every texel regathered every update, no blend: worst 4x4 block off a fresh bake %.4f\n", worst);
    assert_true(worst < 0.02);
    lmgi_updater_free(u);
    lmgi_free(sc);
    lmgi_context_free(ctx);
}

/* The cube moved along x by dx. */
static void move_cube_by(lmgi_scene *sc, float dx)
{
    int node = lmgi_find_node(sc, "dynamic_cube");
    float m[16];
    lmgi_error e;
    assert_true(node >= 0 && lmgi_get_node_transform(sc, node, m));
    m[12] += dx;
    if (lmgi_set_node_transform(sc, node, m, &e) != LMGI_OK)
        fail_msg("%s", e.message);
}

/* The cube moved once, as bench/cornell_edits.json's edit does. */
static void move_cube(lmgi_scene *sc) { move_cube_by(sc, -1.1f); }

/* The cube's transform committed again where it is: an edit that moves nothing (a drag held still). */
static void hold_cube(lmgi_scene *sc) { move_cube_by(sc, 0.0f); }

/* A fresh updater's lightmap of the box with its cube moved (move_cube), and that scene's info. */
static float *moved_bake(lmgi_context *ctx, lmgi_info *in)
{
    lmgi_scene *moved = lmt_load(lmt_project_scene("cornell.glb"), TEXELS);
    move_cube(moved);
    lmgi_updater *fresh = updater(ctx, moved, 0.0f, 0);
    size_t n;
    float *want = lmt_iim(fresh, moved, &n);
    lmgi_get_info(moved, in);
    lmgi_updater_free(fresh);
    lmgi_free(moved);
    return want;
}

/* An engine re-reads only the surfaces whose lmgi_surface_version moved: every texel of the others must be
 * as it was (the estimates of texels that wait move versions too). version[] is brought up to date. */
static void unchanged_where_version_stayed(lmgi_updater *u, const lmgi_scene *sc, uint32_t *version,
                                           const float *prev, const float *now)
{
    lmgi_info in;
    lmgi_get_info(sc, &in);
    for (uint32_t i = 0; i < in.texels; i++) {
        lmgi_texel t;
        lmgi_get_texel(sc, i, &t);
        size_t k = 4 * ((size_t)t.y * in.atlas_width + t.x);
        if (lmgi_surface_version(u, t.surface) == version[t.surface])
            assert_memory_equal(prev + k, now + k, 4 * sizeof *now);
    }
    for (int j = 0; j < in.surfaces; j++)
        version[j] = lmgi_surface_version(u, j);
}

typedef struct {
    double step, step_sum, block, block_sum, last;
    int within; /* the updates after which every 4 x 4 block stays within 10% of the fresh bake (0: at once) */
} move_lag;

/* The cube moved once in a fresh updater's scene (`spread`: texels that wait shown from their gathered
 * neighbours, or not), its lightmap compared with `want` at each of `updates` updates. `held`: the update
 * before the move nudged the cube and every update after it commits the cube's transform again (a drag
 * under way, held still), so the move is never caught up at once (update/photon_stage.c catch_up) and
 * follows at 20 texels an update. */
static move_lag one_move(lmgi_context *ctx, const lmgi_info *in, const float *want, int spread, int held,
                         int updates)
{
    move_lag r = {0};
    lmgi_scene *sc = lmt_load(lmt_project_scene("cornell.glb"), TEXELS);
    lmgi_updater *u = updater(ctx, sc, 0.0f, spread ? 0 : LMGI_OFF);
    size_t n;
    if (held) {
        move_cube_by(sc, -0.001f);
        lmt_update(u);
    }
    float *before = lmt_iim(u, sc, &n), *prev = lmt_iim(u, sc, &n);
    uint32_t *version = malloc(sizeof *version * (size_t)in->surfaces);
    assert_non_null(version);
    for (int j = 0; j < in->surfaces; j++)
        version[j] = lmgi_surface_version(u, j);
    move_cube_by(sc, held ? -1.099f : -1.1f);
    lmgi_error e;
    for (int f = 0; f < updates; f++) {
        if (held && f > 0)
            hold_cube(sc);
        if (lmgi_update(u, 0.0f, 0.0f, NULL, &e) != LMGI_OK)
            fail_msg("%s", e.message);
        float *shown = lmt_iim(u, sc, &n);
        unchanged_where_version_stayed(u, sc, version, prev, shown);
        memcpy(prev, shown, sizeof *prev * n);
        double st = worst_step(in, shown, want, before), b = worst_block(in, shown, want);
        r.step = fmax(r.step, st), r.step_sum += st;
        r.block = fmax(r.block, b), r.block_sum += b;
        r.last = b;
        r.within = b > 0.1 ? f + 1 : r.within;
        free(shown);
    }
    print_message("the cube moved once%s, %d updates, %s: worst step between neighbours %.2f of the mean texel (mean "
                  "over the updates %.2f), worst 4x4 block %.2f (mean %.2f, last %.2f; every block within 10%% after "
                  "%d updates)\n",
                  held ? " in a drag held still" : " after a still update", updates,
                  spread ? "those waiting shown from their neighbours" : "each texel alone", r.step,
                  r.step_sum / updates, r.block, r.block_sum / updates, r.last, r.within);
    free(before);
    free(prev);
    free(version);
    lmgi_updater_free(u);
    lmgi_free(sc);
    return r;
}

/* Issue 32, item 6 (no trail: no 4 x 4 block more than 10% off for more than 10 updates after a node
 * passes) and item 3 (progressive refinement): after one move of the cube, every update's lightmap against a
 * fresh bake of the moved scene, at `lmgi run`'s 20 texels an update.
 * - After a still update (an artist's drag released) the move is caught up in its own update: its photons
 *   and AIMs (photon_stage.c), then its texels, LM_CATCH_UP_UPDATES updates' worth gathered and shown at once
 *   (lightmap_path.c). Every block is within 10% from the first update on (0.03 measured); before, the
 *   texels went 15 an update, blended over 8, and the last blocks (the walls by the floor beside the cube's
 *   new and old places, 17% off) waited 17 updates behind a bar of 4 times the atlas's mean change, which the
 *   cube's own faces had lifted over them (texel_change.c, typical_change).
 * - In a drag held still (a nudge before it, its transform committed again every update after: no update
 *   without edits, so never caught up) the move follows at 20 texels an update. Texels gathered ahead
 *   among stale neighbours showed as steps (squares in the frame); with the texels that wait shown from their
 *   gathered neighbours' changes, the steps and the blocks' error are smaller at every moment, and both
 *   converge: the moved texels are gathered again once the photon stage has caught up with the move. */
static void test_one_move_refined(void **state)
{
    (void)state;
    lmgi_context *ctx = lmt_context();
    lmgi_info in;
    float *want = moved_bake(ctx, &in);
    enum { UPDATES = 40 };
    for (int k = 0; k < 2; k++) {
        move_lag r = one_move(ctx, &in, want, k, 0, UPDATES);
        assert_int_equal(r.within, 0); /* every block within 10% at once: 0.03 measured, both */
        assert_true(r.step < 0.15);    /* no square: 0.05 measured */
    }
    move_lag r[2];
    for (int k = 0; k < 2; k++) {
        r[k] = one_move(ctx, &in, want, k, 1, UPDATES);
        assert_true(r[k].last < 0.1);
        /* 24 and 6 measured (26 and 7 with 4 AIMs an update; 24 from the neighbours' changes alone, before update/ray_estimate.h): the move's 66 photon groups re-traced 16 an update and its AIMs refreshed 4 an
         * update (photon_stage.c), its texels 15 an update, blended over 8. Before, 0.44 and 0.46 after 40
         * updates, never within 10%: the moved cube's paths were found one photon a group an update, its faces
         * were gathered from AIMs that had not caught up and not again, and a floor texel by its old place held
         * its old contact shadow while the floor's refresh lasted (photons.h lm_photons_invalidate_boxes,
         * texel_change.h lm_texel_change_settle, lightmap_path.c commit_waiting) */
        assert_true(r[k].within <= (k ? 12 : 30));
    }
    /* the steps a texel gathered among stale ones makes: 0.26 of the mean texel on average over the updates
     * alone, 0.08 with those waiting shown from their own rays' estimate (0.11 with 36 rays a texel
     * throughout, 0.17 from their neighbours' changes alone); the worst, 0.78 alone, in the first update (a
     * texel gathered beside those that came out of the cube's old place, which show at once, blending in from
     * the old contact shadow), 0.28 (0.34, 0.46) */
    assert_true(r[1].step_sum < 0.7 * r[0].step_sum);
    assert_true(r[1].step < 0.6 * r[0].step);
    assert_true(r[1].block_sum < 1.1 * r[0].block_sum); /* and the blocks no worse (0.06 and 0.21) */
    free(want);
    lmgi_context_free(ctx);
}

enum { AIM_BUDGET = 8 }; /* aim.surfaces_per_frame's default (docs/aim.md, "How many an update") */

/* A move after a still update is caught up as the edit's own work: every group it queued re-traced and
 * every AIM it changed refreshed in its update, whatever the fixed counts (16 groups, AIM_BUDGET AIMs an update),
 * then nothing is left. Moves repeated every update stay within those counts: an engine that drives a
 * node through edits pays the round robin's cost, not a full catch-up every frame. */
static void test_move_after_stillness_caught_up(void **state)
{
    (void)state;
    lmgi_context *ctx = lmt_context();
    lmgi_scene *sc = lmt_load(lmt_project_scene("cornell.glb"), TEXELS);
    lmgi_updater *u = updater(ctx, sc, 0.0f, 0);
    lmt_update(u);
    move_cube(sc);
    lmgi_update_stats w[2] = {lmt_update(u), lmt_update(u)};
    print_message("the cube moved after a still update: %u groups and %d AIMs at once, then %u groups\n",
                  w[0].groups_at_once, w[0].aim_surfaces_at_once, w[1].groups_retraced);
    assert_true(w[0].groups_at_once > 16); /* 66 measured */
    assert_true(w[0].groups_retraced >= w[0].groups_at_once);
    assert_true(w[0].aim_surfaces_at_once > AIM_BUDGET); /* 15 */
    assert_int_equal(w[1].groups_retraced, 0);
    int node = lmgi_find_node(sc, "dynamic_cube");
    for (int f = 0; f < 8; f++) { /* a step every update: the first follows a still one and is caught up */
        float m[16];
        lmgi_error e;
        assert_true(lmgi_get_node_transform(sc, node, m));
        m[12] += 0.02f;
        assert_int_equal(lmgi_set_node_transform(sc, node, m, &e), LMGI_OK);
        lmgi_update_stats s = lmt_update(u);
        if (f == 0) {
            assert_true(s.groups_at_once > 0);
        } else {
            assert_int_equal(s.groups_at_once, 0);
            assert_true(s.groups_retraced <= 16);
            assert_true(s.aim_surfaces_refreshed - s.aim_surfaces_at_once <= AIM_BUDGET);
            assert_int_equal(s.aim_surfaces_at_once, 0);
        }
    }
    lmgi_updater_free(u);
    lmgi_free(sc);
    lmgi_context_free(ctx);
}

/* A drag committed every frame (issue 32, item 6): the cube dragged 1.1 m in 10 steps, one an update, then
 * released. Its first step follows a still update and is caught up at once; the steps after it keep to the
 * round robin's counts (an engine driving a node pays no more), and the first update without edits after
 * the last step catches them all up: every group they queued re-traced, every AIM refreshed, then
 * LM_CATCH_UP_UPDATES updates' worth of texels gathered and shown (update/lightmap_path.c). */
static void test_drag_released_caught_up(void **state)
{
    (void)state;
    lmgi_context *ctx = lmt_context();
    lmgi_info in;
    float *want = moved_bake(ctx, &in);
    lmgi_scene *sc = lmt_load(lmt_project_scene("cornell.glb"), TEXELS);
    lmgi_updater *u = updater(ctx, sc, 0.0f, 0);
    lmt_update(u);
    enum { STEPS = 10, UPDATES = 30 };
    unsigned queued = 0;
    for (int f = 0; f < STEPS; f++) {
        move_cube_by(sc, -1.1f / STEPS);
        lmgi_update_stats s = lmt_update(u);
        assert_int_equal(s.placements_caught_up, f == 0);
        if (f > 0) {
            assert_int_equal(s.groups_at_once, 0);
            assert_true(s.groups_retraced <= 16);
        }
    }
    int within = 0;
    double first = 0.0, worst_after = 0.0;
    size_t n;
    for (int f = 0; f < UPDATES; f++) {
        lmgi_update_stats s = lmt_update(u);
        assert_int_equal(s.placements_caught_up, f == 0);
        if (f == 0)
            queued = s.groups_at_once;
        else
            assert_int_equal(s.groups_at_once, 0);
        float *shown = lmt_iim(u, sc, &n);
        double b = worst_block(&in, shown, want);
        first = f == 0 ? b : first;
        worst_after = f > 0 ? fmax(worst_after, b) : worst_after;
        within = b > 0.1 ? f + 1 : within;
        free(shown);
    }
    print_message("the cube dragged in %d steps, then released: %u groups caught up at the release, the worst 4x4 "
                  "block %.3f off a fresh bake at that update, at most %.3f after it (every block within 10%% after "
                  "%d updates)\n", STEPS, queued, first, worst_after, within);
    assert_true(queued > 16);
    assert_int_equal(within, 0);
    free(want);
    lmgi_updater_free(u);
    lmgi_free(sc);
    lmgi_context_free(ctx);
}

/* A drag under a time budget (an editor's window: lmgi view) is not caught up while the budget holds, nor
 * at the first update without edits under it; the first update without a budget catches it up, whatever
 * the budgeted update before it planned (update/photon_stage.h lm_photon_stage_set_budgeted). */
static void test_drag_released_under_budget(void **state)
{
    (void)state;
    lmgi_context *ctx = lmt_context();
    lmgi_scene *sc = lmt_load(lmt_project_scene("cornell.glb"), TEXELS);
    lmgi_updater *u = updater(ctx, sc, 0.0f, 0);
    lmgi_update_stats s;
    lmgi_error e;
    for (int f = 0; f < 6; f++) { /* three steps, each after an update without edits */
        if (f % 2 == 0)
            move_cube_by(sc, -0.2f);
        assert_int_equal(lmgi_update(u, 0.0f, 8.0f, &s, &e), LMGI_OK);
        assert_int_equal(s.placements_caught_up, 0);
        assert_int_equal(s.groups_at_once, 0);
    }
    assert_int_equal(lmgi_update(u, 0.0f, 0.0f, &s, &e), LMGI_OK);
    print_message("a drag under an 8 ms budget, then an update without it: caught up %d, %u groups at once, %u "
                  "texels\n", s.placements_caught_up, s.groups_at_once, s.texels_gathered);
    assert_int_equal(s.placements_caught_up, 1);
    assert_int_equal(lmgi_update(u, 0.0f, 0.0f, &s, &e), LMGI_OK);
    assert_int_equal(s.placements_caught_up, 0); /* once */
    lmgi_updater_free(u);
    lmgi_free(sc);
    lmgi_context_free(ctx);
}

/* The box's cube dragged and held still for 6 updates, then at the 7th update its only light's intensity
 * times `scale`: the IIM after that update into *iim (lmt_iim), the estimates before and in it. */
static lmgi_update_stats drag_then_light(lmgi_context *ctx, float scale, float **iim, uint32_t *estimated)
{
    lmgi_scene *sc = lmt_load(lmt_project_scene("cornell.glb"), TEXELS);
    lmgi_updater *u = updater(ctx, sc, 0.0f, 0);
    move_cube_by(sc, -0.001f); /* a drag under way: never caught up */
    lmt_update(u);
    move_cube_by(sc, -0.5f);
    *estimated = 0;
    for (int f = 0; f < 6; f++) {
        hold_cube(sc);
        *estimated += lmt_update(u).texels_estimated;
    }
    lmgi_light l;
    lmgi_error e;
    assert_int_equal(lmgi_get_light(sc, 0, &l, &e), LMGI_OK);
    l.intensity *= scale;
    assert_int_equal(lmgi_set_light(sc, 0, &l, &e), LMGI_OK);
    hold_cube(sc);
    lmgi_update_stats s = lmt_update(u);
    size_t n;
    *iim = lmt_iim(u, sc, &n);
    lmgi_updater_free(u);
    lmgi_free(sc);
    return s;
}

/* A light's power edit while texels wait with estimates of their own (update/ray_estimate.h): the only light
 * of the box halved during a drag held still, so that hundreds of texels show their own estimate at the
 * edit. The light edit multiplies every map of the IIM by the texels' factors, exactly 1/2 here (one light),
 * and the estimates with them (gpu/gather/iim.c, lm_iim_scale; ray_estimate.h, lm_ray_estimate_scale): the
 * lightmap is half of the same drag's with the light as it was, its own gathers and estimates included
 * (indirect light is linear in the light's power). Left unscaled, a waiting texel would show half its
 * value plus its whole change: 517 texels more than 5% off, when the test compared with the lightmap
 * before the edit. */
static void test_estimates_follow_a_light_edit(void **state)
{
    (void)state;
    lmgi_context *ctx = lmt_context();
    float *kept, *halved;
    uint32_t estimated, estimated_kept;
    drag_then_light(ctx, 1.0f, &kept, &estimated_kept);
    lmgi_update_stats s = drag_then_light(ctx, 0.5f, &halved, &estimated);
    lmgi_scene *sc = lmt_load(lmt_project_scene("cornell.glb"), TEXELS);
    lmgi_info in;
    lmgi_get_info(sc, &in);
    uint32_t compared = 0, off = 0;
    double worst = 0.0;
    for (uint32_t i = 0; i < in.texels; i++) {
        lmgi_texel t;
        lmgi_get_texel(sc, i, &t);
        size_t k = 4 * ((size_t)t.y * in.atlas_width + t.x);
        double a = kept[k] + kept[k + 1] + kept[k + 2], b = halved[k] + halved[k + 1] + halved[k + 2];
        if (!(kept[k + 3] > 0.0f) || !(halved[k + 3] > 0.0f) || a <= 0.0)
            continue;
        double r = fabs(b / a / 0.5 - 1.0);
        compared++;
        off += r > 0.05;
        worst = fmax(worst, r);
    }
    print_message("the light halved in a drag held still, %u estimates in the 6 updates before, %u in the edit's: "
                  "%u of %u texels more than 5%% off half the same drag's with the light kept (worst %.3f)\n",
                  estimated, s.texels_estimated, off, compared, worst);
    assert_int_equal(estimated, estimated_kept);
    assert_true(estimated > 300);
    assert_true(s.lights_scaled == 1);
    assert_true(off < compared / 200);
    free(kept);
    free(halved);
    lmgi_free(sc);
    lmgi_context_free(ctx);
}

/* Material `name` of sc recoloured as bench/cornell_edits.json does the red wall. */
static void recolour(lmgi_scene *sc, const char *name)
{
    int k = lmt_material_named(sc, name);
    lmgi_material m;
    lmgi_error e;
    assert_int_equal(lmgi_get_material(sc, k, &m, &e), LMGI_OK);
    m.base_color[0] = 0.1f, m.base_color[1] = 0.2f, m.base_color[2] = 0.63f;
    assert_int_equal(lmgi_set_material(sc, k, &m, &e), LMGI_OK);
}

/* The red wall recoloured blue (issue 32, items 2 and 6): its first guess (update/light_scale.h) is right
 * to first order only, and the texels it moved most are regathered first (texel_change.h,
 * lm_texel_change_first_guess). Against a fresh bake of the recoloured box, the lightmap's worst surface is
 * 8.1% off at the next update and within 5% from the 30th on (0.5 s; issue 32 asks 1 s), at 20 texels an
 * update; with the first guess left to the surfaces' order, the tall block's face toward the wall was still
 * 8.9% off after 40. Which update it is, is a draw: one surface's first guess sits at 4.9-5.1% until its
 * texels' turn (about update 30), on one side of 5% or the other. Over gather patterns 0-5 (the texels'
 * seeds offset in a probe, not kept) it came within 5% at updates 5, 4, 33, 4, 6, 31 with every ray at
 * its column's middle alpha, and 30, 4, 30, 5, 31, 5 with each row's own (hemicube_rim.c). */
static void test_recolour_worst_surface_first(void **state)
{
    (void)state;
    lmgi_context *ctx = lmt_context();
    lmgi_scene *edited = lmt_load(lmt_project_scene("cornell.glb"), TEXELS);
    recolour(edited, "red");
    lmgi_updater *fresh = updater(ctx, edited, 0.0f, 0);
    size_t n;
    float *want = lmt_iim(fresh, edited, &n);
    lmgi_scene *sc = lmt_load(lmt_project_scene("cornell.glb"), TEXELS);
    lmgi_updater *u = updater(ctx, sc, 0.0f, 0);
    recolour(sc, "red");
    enum { UPDATES = 40 };
    double first = 0.0, last = 0.0;
    int within = lmt_worst_surface_lag(u, sc, want, UPDATES, &first, &last);
    print_message("red wall recoloured, 20 texels an update: the worst surface %.3f off a fresh bake at the next "
                  "update, within 5%% from update %d on, %.3f after %d\n", first, within, last, UPDATES);
    assert_true(first > 0.05);
    assert_true(within > 0 && within <= 35);
    free(want);
    lmgi_updater_free(u);
    lmgi_free(sc);
    lmgi_updater_free(fresh);
    lmgi_free(edited);
    lmgi_context_free(ctx);
}

/* Which 4 x 4 atlas blocks are over 10% off `want` (block_error) into over[]; returns how many. */
static int blocks_over(const lmgi_info *in, const float *shown, const float *want, uint8_t *over)
{
    double mean = mean_texel(in, want);
    int n = 0, bw = (in->atlas_width + 3) / 4;
    for (int by = 0; by < in->atlas_height; by += 4)
        for (int bx = 0; bx < in->atlas_width; bx += 4) {
            int o = block_error(in, shown, want, bx, by, mean) > 0.1;
            over[(by / 4) * bw + bx / 4] = (uint8_t)o;
            n += o;
        }
    return n;
}

/* Per 4 x 4 block of sc's atlas, 1 where a texel of it lies on a dynamic node (a short ray from the texel
 * into its surface meets one). */
static uint8_t *moving_blocks(const lmgi_scene *sc, const lmgi_info *in)
{
    int bw = (in->atlas_width + 3) / 4;
    uint8_t *moving = calloc((size_t)bw * ((in->atlas_height + 3) / 4), 1);
    assert_non_null(moving);
    for (uint32_t i = 0; i < in->texels; i++) {
        lmgi_texel t;
        lmgi_get_texel(sc, i, &t);
        float o[3], dir[3];
        for (int k = 0; k < 3; k++)
            o[k] = t.position[k] + 0.01f * t.normal[k], dir[k] = -t.normal[k];
        lmgi_hit h;
        lmgi_intersect(sc, o, dir, 0.05f, &h);
        if (h.hit && lmgi_node_is_dynamic(sc, h.node))
            moving[(t.y / 4) * bw + t.x / 4] = 1;
    }
    return moving;
}

typedef struct {
    double over;       /* blocks over 10%, mean over the samples */
    int trail, moving; /* the longest run of updates a block stayed over 10%: of the static surfaces (the trail
                        * a node leaves), and of the moving nodes' own */
    double ms;         /* mean update */
} trail_stats;

enum { TRAIL_UPDATES = 120, TRAIL_EVERY = 3 };

/* The animated box updated with estimate_rays (0: the default), each TRAIL_EVERY-th update against want. */
static trail_stats trail_of(lmgi_context *ctx, float *const *want, int estimate_rays)
{
    lmgi_scene *sc = lmt_load(lmt_project_scene("cornell.glb"), TEXELS);
    lmgi_updater_desc d;
    memset(&d, 0, sizeof d);
    d.gather.estimate_rays = estimate_rays;
    lmgi_updater *u = updater_with(ctx, sc, &d);
    lmgi_error e;
    lmgi_info in;
    lmgi_get_info(sc, &in);
    int nb = ((in.atlas_width + 3) / 4) * ((in.atlas_height + 3) / 4), samples = 0, total = 0;
    int *run = calloc((size_t)nb, sizeof *run);
    uint8_t *over = calloc((size_t)nb, 1), *moving = moving_blocks(sc, &in);
    assert_non_null(run);
    assert_non_null(over);
    trail_stats r = {0};
    for (int f = 0; f < TRAIL_UPDATES; f++) {
        lmgi_update_stats s;
        if (lmgi_update(u, (float)f / 30.0f, 0.0f, &s, &e) != LMGI_OK)
            fail_msg("%s", e.message);
        r.ms += s.ms_total / TRAIL_UPDATES;
        if (!want[f])
            continue;
        size_t n;
        float *shown = lmt_iim(u, sc, &n);
        total += blocks_over(&in, shown, want[f], over);
        samples++;
        for (int b = 0; b < nb; b++) {
            run[b] = over[b] ? run[b] + TRAIL_EVERY : 0;
            int *longest = moving[b] ? &r.moving : &r.trail;
            *longest = run[b] > *longest ? run[b] : *longest;
        }
        free(shown);
    }
    r.over = (double)total / samples;
    free(run);
    free(over);
    free(moving);
    lmgi_updater_free(u);
    lmgi_free(sc);
    return r;
}

/* Issue 32, item 6 (no trail behind moving objects): the animated Cornell box at `run`'s density, every 3rd of
 * 120 updates (4 s of its 8 s loop) against a fresh updater's bake at that time, per 4 x 4 block of atlas
 * texels: how many blocks are over 10% off, and the longest run of updates one stayed so, apart for the
 * static surfaces (the trail a node leaves) and the moving nodes' own faces. The texels that wait show the
 * change their own rays see (update/ray_estimate.h), against their neighbours' loans alone (estimate_rays
 * off). Measured: 0.15 blocks over 10% against 9.28, the trail's longest run 3 updates against 72, the moving
 * nodes' own 3 against 78; 0.57, 9 and 6 before the near rays beside moving nodes (ray_estimate.h), shown
 * alone (iim.h). Before a waiting texel's change averaged with neighbours committed near it in time (iim.h,
 * LM_IIM_SIGHT_APART) and a third of the estimates went by their expected staleness (ray_estimate.h), 0.97,
 * 15 and 18. Over the whole loop (240 updates, seeds 0 to 4; probes, not kept) the trail 3, 6, 6, 6 and 6:
 * docs/tradeoff.md, "Nodes that keep moving". */
static void test_animated_box_trail(void **state)
{
    (void)state;
    lmgi_context *ctx = lmt_context();
    float *want[TRAIL_UPDATES] = {0};
    for (int f = TRAIL_EVERY - 1; f < TRAIL_UPDATES; f += TRAIL_EVERY)
        want[f] = converged(ctx, (float)f / 30.0f);
    trail_stats r[2] = {trail_of(ctx, want, 0), trail_of(ctx, want, LMGI_OFF)};
    static const char *const name[2] = {"rays for the texels that wait", "neighbours' loans alone"};
    for (int k = 0; k < 2; k++)
        print_message("animated Cornell box, %d updates, %s: %.2f blocks over 10%% off a fresh bake (mean), the "
                      "longest run %d updates on static surfaces, %d on the moving nodes' own; mean update %.1f ms\n",
                      TRAIL_UPDATES, name[k], r[k].over, r[k].trail, r[k].moving, r[k].ms);
    assert_true(r[1].trail >= 24); /* the trail this guards against */
    assert_true(r[0].over < 0.4 * r[1].over);
    assert_true(r[0].trail <= 9); /* the 10 updates, in samples 3 updates apart */
    assert_true(r[0].moving <= 9);
    for (int f = 0; f < TRAIL_UPDATES; f++)
        free(want[f]);
    lmgi_context_free(ctx);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_moving_cube_followed_texel_by_texel),
        cmocka_unit_test(test_full_work_follows_animation),
        cmocka_unit_test(test_one_move_refined),
        cmocka_unit_test(test_move_after_stillness_caught_up),
        cmocka_unit_test(test_drag_released_caught_up),
        cmocka_unit_test(test_drag_released_under_budget),
        cmocka_unit_test(test_recolour_worst_surface_first),
        cmocka_unit_test(test_animated_box_trail),
        cmocka_unit_test(test_estimates_follow_a_light_edit),
    };
    lmt_filter_from_env();
    return cmocka_run_group_tests(tests, NULL, NULL);
}
