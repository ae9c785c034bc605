/* End to end, the way a user meets the lighting: `lmgi run`'s frame at its default settings against the
 * reference's pixels (api/frame_check.h), per visible surface and over the frame, on the shared Cornell
 * box as shipped (its double-sided lamp 0.9 mm under the ceiling), the generated Cornell box and the
 * two-room scene, each surface of 100+ pixels within 5% per channel (issue 33, item 4); and the displayed IIM
 * against the reference's E_iim per surface on the shared Cornell box, at `lmgi run`'s lightmap density and
 * as `lmgi bake` solves it (64k texels, its photons and bounce pass).
 *
 * The shared Cornell box once rendered 1.64x too bright here while every other test passed; these would
 * have caught it (docs/reference.md, "Frame against reference").
 *
 * The references: kept only in this program's own folder (lmt_reference_cache: a test must not lean on what
 * an earlier run left; a view checked under several settings shares one), at a relative standard error of
 * 0.03 per pixel, the generated Cornell box's at 0.05: its light, 10 cm under the ceiling, makes a few rare,
 * bright paths, and its reference is most of this program's time. Since a pixel's error pools its
 * neighbours' variance (docs/reference.md, "Stopping rule") 0.05 reads it as 0.03 does (frame 0.988 and
 * 0.987 of it); with each pixel's own variance alone 0.05 and 0.1 read it 2% and 4% dark. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../src/api/frame_check.h"
#include "../src/api/lmgi_updater.h"
#include "../src/cli/bake_options.h"
#include "../src/cli/run_options.h"
#include "../src/cli/surface_error.h"
#include "../src/reference/reference.h"
#include "support.h"

#define SIZE 96           /* frame side: about 100 to 1,800 compared pixels per surface */
#define REF_ERROR 0.03f   /* the reference's target relative standard error per pixel */
#define REF_ERROR_RARE 0.05f /* the generated Cornell box's (the header) */
#define SURFACE_TOL 0.03  /* per surface: |frame - reference| <= tol x max(reference, frame mean), tol this
                           * unless a scene says otherwise */
#define BLOCK_RMSE 0.1   /* cornell-suzanne's textured block, per pixel (test_cornell_suzanne) */
#define MIN_PIXELS 100    /* surfaces with fewer compared pixels are reported, not asserted */
#define CHANNEL_TOL 0.05  /* issue 33's per-surface criterion, per channel (lm_cli_channel_off), asserted against
                           * references of REF_ERROR or finer: at REF_ERROR_RARE the generated box's dynamic cube
                           * face (100 pixels) reads G +6.0% within its reference's own noise */

static lmgi_scene *load_with(const char *path, const lmgi_options *o)
{
    lmgi_scene *sc = NULL;
    lmgi_error err;
    if (lmgi_load(path, o, &sc, &err) != LMGI_OK)
        fail_msg("%s", err.message);
    return sc;
}

/* A scene loaded as `lmgi run` loads it (lm_cli_run_options): the lightmap density its default texel budget
 * keeps up with and 16 texels at least on a wall, or target_texels (> 0) as `--texels` asks; open surfaces
 * coarser either way. */
static lmgi_scene *load_as_run(const char *path, int target_texels)
{
    lmgi_options o;
    lmgi_options_init(&o);
    o.target_texels = target_texels;
    lm_cli_run_options(&o, 0);
    return load_with(path, &o);
}

/* A scene lit by its emissive triangles alone, loaded as `lmgi check` loads it (as `lmgi run` does:
 * load_as_run), and the settings it resolves for it from the defaults (lm_updater_settings): the rays
 * gather, the emitters' light at its near hits, asserted. */
static lmgi_scene *load_as_check(const char *path, lm_frame_loop_settings *ls)
{
    lmgi_scene *sc = load_as_run(path, 0);
    lmgi_updater_desc d;
    memset(&d, 0, sizeof d);
    lm_error err;
    if (lm_updater_settings(sc->scene, &d, NULL, ls, &err) != LM_OK)
        fail_msg("%s", err.msg);
    assert_int_equal(ls->gather.scheme, LM_GATHER_RAYS);
    assert_int_equal(ls->stage.exact_direct, LM_EXACT_EMITTERS);
    return sc;
}

static void ref_settings(lm_ref_settings *rs, float target_error)
{
    lm_ref_settings_default(rs);
    rs->target_error = target_error;
    rs->use_cache = 1;
    rs->cache_dir = lmt_reference_cache();
    rs->progress = 0;
}

static double lum(const double c[3]) { return c[0] + c[1] + c[2]; }

/* Every surface with MIN_PIXELS compared pixels within SURFACE_TOL (of its own mean, or of the frame's
 * for surfaces darker than that: a dim face's few percent are a sliver of the picture) and, with channel_tol
 * > 0, within that in each channel as `lmgi check` judges it (lm_cli_channel_off: issue 33, item 4); the
 * frame within `frame_tol` per channel, the relative RMSE under `rmse_bound`. */
static void assert_frame(const char *name, const lmgi_scene *sc, const lm_frame_check *c, double frame_tol,
                         double surface_tol, double rmse_bound, double channel_tol)
{
    double mean = lum(c->lit.ref) / (c->lit.pixels ? c->lit.pixels : 1);
    print_message("%s: frame / reference %.3f %.3f %.3f over %u pixels, relative RMSE %.4f (reference se %.3f, "
                  "%.1f s)\n", name, lm_check_ratio(&c->lit, 0), lm_check_ratio(&c->lit, 1),
                  lm_check_ratio(&c->lit, 2), c->lit.pixels, c->rel_rmse, c->ref_rel_se, c->ref_seconds);
    for (int s = 0; s < c->surface_count; s++) {
        const lm_check_sum *sum = &c->surface[s];
        if (!sum->pixels)
            continue;
        double f = lum(sum->frame) / sum->pixels, r = lum(sum->ref) / sum->pixels;
        int asserted = sum->pixels >= MIN_PIXELS;
        print_message("  surface %2d (%s, %s): %4u pixels, frame %.4g, reference %.4g (%+.1f%%; per channel %.3f "
                      "%.3f %.3f)%s\n", s, sc->scene->nodes[sc->surfaces.surfaces[s].node].name,
                      sc->scene->materials[sc->surfaces.surfaces[s].material].name, sum->pixels, f, r,
                      r > 0.0 ? 100.0 * (f / r - 1.0) : 0.0, lm_check_ratio(sum, 0), lm_check_ratio(sum, 1),
                      lm_check_ratio(sum, 2), asserted ? "" : " (few pixels: not asserted)");
        if (asserted) {
            assert_true(fabs(f - r) <= surface_tol * fmax(r, mean));
            /* issue 33, item 4 */
            assert_true(!(channel_tol > 0.0) || lm_cli_channel_off(sum->frame, sum->ref, NULL) <= channel_tol);
        }
    }
    for (int k = 0; k < 3; k++)
        if (c->lit.ref[k] > 0.05 * fmax(c->lit.ref[0], fmax(c->lit.ref[1], c->lit.ref[2])))
            assert_true(fabs(lm_check_ratio(&c->lit, k) - 1.0) < frame_tol);
    assert_true(c->rel_rmse < rmse_bound);
}

/* One default frame of the scene at SIZE against the reference, asserted: frame within 3% per channel,
 * surfaces within surface_tol, relative RMSE under rmse_bound. The caller frees c and the scene. */
static lmgi_scene *run_check(const char *name, const char *path, double surface_tol, double rmse_bound,
                             float ref_error, lm_frame_check *c)
{
    lmgi_scene *sc = load_as_run(path, 0);
    lm_frame_loop_settings ls;
    lm_frame_loop_settings_default(&ls);
    ls.width = ls.height = SIZE;
    lm_ref_settings rs;
    ref_settings(&rs, ref_error);
    lm_error err;
    if (lm_frame_check_run(sc, &ls, &rs, 1, c, &err) != LM_OK)
        fail_msg("%s: %s", name, err.msg);
    assert_frame(name, sc, c, 0.03, surface_tol, rmse_bound, ref_error <= REF_ERROR ? CHANNEL_TOL : 0.0);
    return sc;
}

static void check_scene_tol(const char *name, const char *path, double surface_tol, double rmse_bound,
                            float ref_error)
{
    lm_frame_check c;
    lmgi_scene *sc = run_check(name, path, surface_tol, rmse_bound, ref_error, &c);
    lm_frame_check_free(&c);
    lmgi_free(sc);
}

static void check_scene(const char *name, const char *path, double rmse_bound)
{
    check_scene_tol(name, path, SURFACE_TOL, rmse_bound, REF_ERROR);
}

/* Measured at 96 x 96 at the defaults (frame / reference; relative RMSE, of which the reference's own
 * noise is ~0.03): shared Cornell box 0.997 0.998 0.999, 0.038 (0.996 0.997 0.998 with the emitters'
 * light computed in the AIMs; before two sides, the hidden light and the traced rim: 2.45 3.06 2.98 over
 * every pixel of a surface at 128 x 128, the outside of the box lit with the inside's lightmap; 1.64 over
 * the pixels both light); generated Cornell box 0.993 0.992 0.993, 0.053; two rooms 0.993 0.994 0.995,
 * 0.032 (its door -1.8%). The RMSE bounds leave room for the reference's noise. */
/* The small box's faces of min_pixels compared pixels or more, each relative to its own reference (they are
 * dim: SURFACE_TOL measures them against the frame's mean), within CONTACT_TOL on the sum of the channels
 * (channel_tol 0), or within channel_tol in each channel; at least two of them. From SMALL_FACE_PIXELS, on
 * the sum: at the old defaults (160 photons a group, N = 128) the face towards the camera read +21..34% per
 * channel: the estimate's radius blurred the floor's contact shadow at the box's foot into the light. The scene's
 * photon floor (72 x 640 for one light) and N = 32 bring the two faces to +1.3% and +2.7% (+2.1%, +1.7%
 * with the emitters' light computed in the AIMs); docs/tradeoff.md, "Defaults against the front". */
#define CONTACT_TOL 0.05
#define SMALL_FACE_PIXELS 50
static void assert_small_box(const lmgi_scene *sc, const lm_frame_check *c, uint32_t min_pixels, double channel_tol)
{
    int faces = 0;
    for (int s = 0; s < c->surface_count; s++) {
        const lm_check_sum *sum = &c->surface[s];
        if (sum->pixels < min_pixels || strcmp(sc->scene->nodes[sc->surfaces.surfaces[s].node].name, "small.box"))
            continue;
        faces++;
        print_message("  small box face %d: %.3f %.3f %.3f\n", s, lm_check_ratio(sum, 0), lm_check_ratio(sum, 1),
                      lm_check_ratio(sum, 2));
        if (!channel_tol)
            assert_true(fabs(lum(sum->frame) / lum(sum->ref) - 1.0) < CONTACT_TOL);
        for (int k = 0; channel_tol && k < 3; k++)
            assert_true(fabs(lm_check_ratio(sum, k) - 1.0) < channel_tol);
    }
    assert_true(faces >= 2);
}

/* sc's frame under ls against the reference (REF_ERROR): the frame (assert_frame's bounds for the shared box)
 * and the small box's faces (assert_small_box). */
static void check_small_box(const char *name, lmgi_scene *sc, const lm_frame_loop_settings *ls,
                            uint32_t min_pixels, double channel_tol)
{
    lm_ref_settings rs;
    ref_settings(&rs, REF_ERROR);
    lm_frame_check c;
    lm_error err;
    if (lm_frame_check_run(sc, ls, &rs, 1, &c, &err) != LM_OK)
        fail_msg("%s", err.msg);
    assert_frame(name, sc, &c, 0.03, SURFACE_TOL, 0.06, CHANNEL_TOL);
    assert_small_box(sc, &c, min_pixels, channel_tol);
    lm_frame_check_free(&c);
}

static void test_shared_cornell_box(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(path, lmt_shared_scene("cornell-box/CornellBox.glb"));
    lm_frame_check c;
    lmgi_scene *sc = run_check("shared Cornell box", path, SURFACE_TOL, 0.06, REF_ERROR, &c);
    assert_small_box(sc, &c, SMALL_FACE_PIXELS, 0);
    lm_frame_check_free(&c);
    lm_frame_loop_settings ls;
    lm_frame_loop_settings_default(&ls);
    ls.width = ls.height = SIZE;
    ls.stage.exact_direct = LM_EXACT_EMITTERS;
    check_small_box("shared Cornell box, emitters' light computed in the AIMs", sc, &ls, SMALL_FACE_PIXELS, 0);
    lmgi_free(sc);
}

/* The same as `lmgi check` runs it at its defaults: the box is lit by its emissive triangles alone, so the
 * gather on auto is the rays', which take the light the AIMs compute at each ray's hit instead of as the
 * AIM texel's average (lmgi_updater.c, choose_gather): the floor at the small box's foot, in the lamp's
 * contact shadow, reads dark where the rays meet it, not as its 46 mm texels' mean. At `lmgi check`'s size,
 * every face of the small box of 100+ pixels within 5% per channel (issue 33's per-surface criterion); the
 * hemicube, the default before, failed it (face 8 1.103 1.011 1.107). Measured
 * (frame / reference R G B, the side face 8 and the front face 12): at the hits 0.980 1.014 0.978 and
 * 0.991 0.984 1.029; read from the AIM texels (direct_at_hits 0) face 8 1.099 1.024 1.101, failing. At other
 * photon seeds face 8 moves by +-5% either way (docs/aim.md). After a bounce pass, which takes the
 * emitters at its hits too, reading its map without them where the first gather added them
 * (lm_gather_emitted_at): face 8 0.973 1.011 0.965, 12 1.013 1.024 1.044; when the pass read the
 * emitters' light from its map texel by texel (as before), face 8 failed (`lmgi check`: 1.054 1.007 1.051).
 * With 1,600 strata and the bounce pass, issue 33 item 1's setting, every face within 2% per channel at
 * seed 0 (`lmgi check --gather-rays 1600 --bounce-passes 1`: face 8 B -1.5%); over seeds 0-7, each its own
 * strata too, at 6 of 8 (seed 7: face 8 R -2.5%; docs/gather.md, "Strata"). */
#define CHECK_SIZE 128
#define ITEM_1_TOL 0.02
static void test_shared_cornell_box_direct_at_hits(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(path, lmt_shared_scene("cornell-box/CornellBox.glb"));
    lm_frame_loop_settings ls;
    lmgi_scene *sc = load_as_check(path, &ls);
    ls.width = ls.height = CHECK_SIZE;
    check_small_box("shared Cornell box at lmgi check's defaults: the rays gather, emitters' light at its hits", sc,
                    &ls, MIN_PIXELS, CONTACT_TOL);
    ls.bounce_passes = 1; /* as lmgi bake gathers: the pass takes the emitters at its hits too */
    check_small_box("the same after a bounce pass", sc, &ls, MIN_PIXELS, CONTACT_TOL);
    ls.gather.ray_samples = 1600; /* issue 33 item 1's setting: 2% per channel (and test_contact_texels_strata) */
    check_small_box("the same with 1,600 strata", sc, &ls, MIN_PIXELS, ITEM_1_TOL);
    lmgi_free(sc);
}

/* The displayed IIM after a frame loop's first full solution under ls (its picture 16 x 16: none is looked
 * at), read back as lm_frame_loop_read_iim gives it (caller frees). */
static float *first_iim(lmgi_scene *sc, lm_frame_loop_settings *ls)
{
    ls->width = ls->height = 16;
    lm_frame_loop *fl = NULL;
    lm_error err;
    if (lm_frame_loop_create(&sc->world, ls, &fl, NULL, NULL, &err) != LM_OK)
        fail_msg("%s", err.msg);
    float *rgba = NULL;
    assert_int_equal(lm_frame_loop_read_iim(fl, &rgba, &err), LM_OK);
    lm_frame_loop_free(fl);
    return rgba;
}

/* The IIM the frame loop's first full gather makes of the shared box with the rays gather and the emitters'
 * light computed in the AIMs, read back (caller frees). direct_near: ls.gather.direct_near; at_hits 0: every
 * hit reads the AIM's texels. */
static float *box_iim(lmgi_scene *sc, int at_hits, float direct_near)
{
    lm_frame_loop_settings ls;
    lm_frame_loop_settings_default(&ls);
    ls.stage.exact_direct = LM_EXACT_EMITTERS;
    ls.gather.scheme = LM_GATHER_RAYS;
    ls.gather.direct_at_hits = at_hits;
    ls.gather.direct_near = direct_near;
    return first_iim(sc, &ls);
}

/* Near and far hits through the frame loop (docs/gather.md): at the default split only the hits within 16
 * texel widths take the emitters' light at the hit, the others read the whole AIM, which the lightmap path
 * hands the gather beside the rest. The small box's texels, whose contact shadow the hits are for, stay with
 * every hit's values: per face (rgb summed over its texels), where reading every hit from the texels moves
 * it by over 1%, within a fifth of the way there, elsewhere within 0.5%; and not equal to them (the whole
 * AIM reached the gather). Measured on `lmgi run`'s atlas: every face within 0.03% (1-2% of the way). At 4
 * texel widths the top face read -0.61%, as far as every hit read from the texels (this test, loaded with
 * the library's atlas instead of run's until 2026-12-05, had measured 4 with 0.25% there). */
static void test_near_and_far_hits(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(path, lmt_shared_scene("cornell-box/CornellBox.glb"));
    lmgi_scene *sc = load_as_run(path, 0);
    float *every = box_iim(sc, 1, 0.0f), *split = box_iim(sc, 1, 16.0f), *texels = box_iim(sc, 0, 0.0f);
    const lm_atlas *a = &sc->atlas;
    int faces = 0, differ = 0;
    for (int s = 0; s < sc->surfaces.surface_count; s++) {
        if (strcmp(sc->scene->nodes[sc->surfaces.surfaces[s].node].name, "small.box"))
            continue;
        double e = 0.0, p = 0.0, t = 0.0;
        for (uint32_t i = 0; i < a->texel_count; i++) {
            size_t k = 4 * ((size_t)a->texels[i].y * a->width + a->texels[i].x);
            for (int c = 0; a->texels[i].surface == s && c < 3; c++)
                e += every[k + c], p += split[k + c], t += texels[k + c];
        }
        if (!(e > 0.0))
            continue;
        faces++;
        differ += p != e;
        print_message("  small box face %d: every hit %.4f, near hits %.4f (%+.2f%%), texels %.4f (%+.2f%%)\n", s, e,
                      p, 100.0 * (p / e - 1.0), t, 100.0 * (t / e - 1.0));
        if (fabs(t - e) > 0.01 * e) /* where the hits matter */
            assert_true(fabs(p - e) <= 0.2 * fabs(t - e));
        else
            assert_true(fabs(p - e) <= 0.005 * e);
    }
    assert_true(faces >= 4 && differ > 0);
    free(every);
    free(split);
    free(texels);
    lmgi_free(sc);
}

/* Of sc's atlas, the texels of the small box's side faces whose centres lie in the first 20 mm above the floor
 * (its units are millimetres): an atlas of those alone, for a reference of them (caller frees its texels). */
static lm_atlas contact_texels(const lmgi_scene *sc, uint32_t **index)
{
    const lm_atlas *a = &sc->atlas;
    lm_atlas sub = *a;
    sub.texels = malloc(sizeof *sub.texels * (a->texel_count ? a->texel_count : 1));
    *index = malloc(sizeof **index * (a->texel_count ? a->texel_count : 1));
    assert_true(sub.texels && *index);
    sub.texel_count = 0;
    sub.footprint_first = NULL, sub.footprints = NULL, sub.footprint_count = 0; /* flat faces: none */
    for (uint32_t i = 0; i < a->texel_count; i++) {
        const lm_texel *t = &a->texels[i];
        if (strcmp(sc->scene->nodes[sc->surfaces.surfaces[t->surface].node].name, "small.box") ||
            fabsf(t->normal[1]) > 0.5f || t->pos[1] > 20.0f)
            continue;
        (*index)[sub.texel_count] = i;
        sub.texels[sub.texel_count++] = *t;
    }
    return sub;
}

/* The luminance of iim (RGBA, sc's displayed IIM) over the reference's E_iim at texel j of sub (from
 * contact_texels: index maps its texels to sc's). */
static double contact_ratio(const lmgi_scene *sc, const float *iim, const uint32_t *index, const lm_ref_result *ref,
                            uint32_t j)
{
    const lm_texel *t = &sc->atlas.texels[index[j]];
    const float *v = iim + 4 * ((size_t)t->y * sc->atlas.width + t->x), *r = ref->iim + 3 * (size_t)j;
    return (0.2126 * v[0] + 0.7152 * v[1] + 0.0722 * v[2]) / (0.2126 * r[0] + 0.7152 * r[1] + 0.0722 * r[2]);
}

/* Of contact_ratio over every texel of sub, the least and the most, in *lo and *hi. */
static void contact_range(const lmgi_scene *sc, const float *iim, const lm_atlas *sub, const uint32_t *index,
                          const lm_ref_result *ref, double *lo, double *hi)
{
    *lo = INFINITY, *hi = 0.0;
    for (uint32_t j = 0; j < sub->texel_count; j++) {
        double q = contact_ratio(sc, iim, index, ref, j);
        *lo = fmin(*lo, q), *hi = fmax(*hi, q);
    }
}

/* The reference's texels of sub (contact_texels) at target error e and at most max_paths paths a texel (0: the
 * reference's default), not cached (caller frees). */
static void contact_reference(const lmgi_scene *sc, const lm_atlas *sub, float e, int max_paths, lm_ref_result *ref)
{
    lm_ref_settings rs;
    lm_ref_settings_default(&rs);
    rs.target_error = e;
    if (max_paths)
        rs.max_samples = max_paths;
    rs.use_cache = 0;
    rs.progress = 0;
    lm_emitters em;
    lm_error err;
    assert_int_equal(lm_emitters_build(sc->scene, &em, &err), LM_OK);
    assert_int_equal(lm_reference_texels(sc->scene, sub, sc->rt, &em, &rs, ref, &err), LM_OK);
    lm_emitters_free(&em);
}

/* Issue 33 item 1's per-texel bound: the shared box's small box, its side faces' texels in the first 20 mm
 * above the floor, against the reference's texels (luminance; those texels alone, at 0.01), loaded as `lmgi
 * run` and `lmgi check` load it (load_as_check). Their error is the rays gather's noise, fixed per texel by
 * its strata's pattern, and the photons'. Over the four side faces' 18 such texels at the default seed: in
 * the polar strata 0.80-1.23 of the reference with 400 strata, 0.90-1.03 with 1,600, 0.95-1.01 with a bounce
 * pass as well; in the upright strata (hemicube_rim.c, since 2026-12-06) 0.92-1.02, 0.90-1.01 and 0.95-1.00,
 * and with each row's rays at their own alpha in their columns 0.88-1.02, 0.90-1.02 and 0.95-1.00.
 * Within 10% at 400 there is this seed's draw: gather seeds 1-4 read 0.79-1.14 with 400 upright strata (the
 * polar ones 0.86-1.16), so 400 is asserted within 15%; 1,600 with a bounce pass within 10% (docs/gather.md,
 * "Strata"; as baked, where 69 texels a face show the spread, test_iim_bake_density). With the contact rows
 * split (hemicube_rim.c): 0.915-1.020, 0.910-1.020 and 0.960-1.020. */
static void test_contact_texels_strata(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(path, lmt_shared_scene("cornell-box/CornellBox.glb"));
    lm_frame_loop_settings ls;
    lmgi_scene *sc = load_as_check(path, &ls);
    float *iim[3];
    iim[0] = first_iim(sc, &ls);
    ls.gather.ray_samples = 1600;
    iim[1] = first_iim(sc, &ls);
    ls.bounce_passes = 1; /* issue 33 item 1's setting (its faces: test_shared_cornell_box_direct_at_hits) */
    iim[2] = first_iim(sc, &ls);
    uint32_t *index;
    lm_atlas sub = contact_texels(sc, &index);
    lm_ref_result ref;
    contact_reference(sc, &sub, 0.01f, 0, &ref);
    double lo[3], hi[3];
    for (int k = 0; k < 3; k++)
        contact_range(sc, iim[k], &sub, index, &ref, &lo[k], &hi[k]);
    print_message("the small box's %u texels in the first 20 mm: %.3f-%.3f of the reference with 400 strata, "
                  "%.3f-%.3f with 1,600, %.3f-%.3f with 1,600 and a bounce pass\n", sub.texel_count, lo[0], hi[0],
                  lo[1], hi[1], lo[2], hi[2]);
    assert_true(sub.texel_count >= 8);
    assert_true(lo[0] > 0.85 && hi[0] < 1.15); /* 0.915-1.020 measured (the polar strata: 0.80-1.23) */
    assert_true(lo[1] > 0.85 && hi[1] < 1.15); /* 1,600 strata: 0.910-1.020 */
    assert_true(lo[2] > 0.9 && hi[2] < 1.1);   /* and the bounce pass: 0.960-1.020 */
    lm_ref_result_free(&ref);
    free(sub.texels);
    free(index);
    for (int k = 0; k < 3; k++)
        free(iim[k]);
    lmgi_free(sc);
}

static void test_generated_cornell_box(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(path, lmt_project_scene("cornell.glb"));
    check_scene_tol("generated Cornell box", path, SURFACE_TOL, 0.07, REF_ERROR_RARE);
}

static void test_two_rooms(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(path, lmt_project_scene("two_rooms.glb"));
    lm_frame_check c;
    lmgi_scene *sc = run_check("two rooms", path, SURFACE_TOL, 0.05, REF_ERROR, &c);
    /* no mirror or glass: no caustic part on either side, and its error 0 */
    for (int k = 0; k < 3; k++)
        assert_true(c.caustic_lit.frame[k] == 0.0 && c.caustic_lit.ref[k] == 0.0);
    assert_true(c.caustic_rel_rmse == 0.0);
    lm_frame_check_free(&c);
    lmgi_free(sc);
}

/* The mixed-lighting interior: a directional sun through a window onto a textured floor, with the Sheen
 * chair (its KHR_materials_sheen ignored: docs/loading.md). Measured at 96 x 96: frame 0.997 0.999 1.000, the floor
 * 0.997 0.999 1.000 (1,492 pixels), relative RMSE 0.027 (the reference's own noise ~0.03). */
static void test_mixed_lighting(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(path, lmt_shared_scene("mixed-lighting/MixedLightingExample.gltf"));
    check_scene("mixed lighting", path, 0.05);
}

/* The depth-of-field scene's circuit board is a glossy metal (metallic 0.89, roughness 0.15): its lightmap
 * carries only the diffuse lobe, kd / pi x E (docs/materials.md). With the whole albedo there, as before,
 * the frame read 1.31 1.29 1.06 and the board 1.26 1.19 1.14 (the board seen by the hemicube as a
 * diffuse reflector also lit the cubes' shadowed faces 4-7x). Its glossy lobe reflects the lava spheres
 * and the lit cubes standing on it: a cube map seen from the board's centre saw mostly black sky (the
 * frame 0.980 0.974 0.978, the board -2.1%, and 0.07 of the reference with the sun off); as a flat
 * reflector it shows the view mirrored in its plane (docs/direct.md, "Flat reflectors"). Measured at
 * 96 x 96: frame 0.994 0.985 0.979, board +0.0%, relative RMSE 0.074 (against the old stopping rule's
 * reference, which read the board dark: frame 1.000 0.994 0.982, board +1.0%). */
static void test_depth_of_field(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(path, lmt_shared_scene("depth-of-field/DepthOfFieldExample.glb"));
    check_scene("depth of field", path, 0.1);
}

/* Relative RMSE of one surface's compared pixels (channel sums), frame against reference. */
static double surface_rmse(const lm_frame_check *c, int surface)
{
    double se = 0.0, sum = 0.0;
    uint32_t n = 0;
    for (int i = 0; i < c->width * c->height; i++) {
        if (!c->compared[i] || c->surface_at[i] != surface)
            continue;
        const float *f = c->frame + 3 * (size_t)i, *r = c->ref + 3 * (size_t)i;
        double d = (f[0] + f[1] + f[2]) - (r[0] + r[1] + r[2]);
        se += d * d;
        sum += r[0] + r[1] + r[2];
        n++;
    }
    return n && sum > 0.0 ? sqrt(se / n) / (sum / n) : 0.0;
}

/* cornell-suzanne: a loose box with averaged corner normals (the gather no longer sees below a texel's
 * own plane: floor 1.071 -> 0.989) and a glossy Suzanne too small at this size to be asserted. Measured
 * at 128 x 128: frame 0.992 0.991 0.986, relative RMSE 0.072; at 96 x 96 the back wall (surface 107) read
 * -3.4%, 5% per surface here, the bound every scene is held to (issue 17). That was the lamp's light taken
 * with the geometric normal's cosine where it grazes the ceiling (docs/aim.md, "Beside an emitter"); since
 * 2026-12-06 the frame reads 1.004 1.002 0.999 against this reference at 0.03, which itself reads about 2%
 * dark here (0.996 0.994 0.994 against one at 0.01).
 * The block (surface 0) wears a checker texture finer than its lightmap, and is lit only by its IIM: with
 * the albedo taken per pixel its pixels read a relative RMSE of 0.050 against the reference (the frame's
 * 0.049); with the albedo at each texel's centre, as before, 0.180 (the frame's 0.063). */
static void test_cornell_suzanne(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(path, lmt_shared_scene("cornell-suzanne/cornellBox-2.80-Eevee-gltf.gltf"));
    lm_frame_check c;
    lmgi_scene *sc = run_check("cornell-suzanne", path, 0.05, 0.1, REF_ERROR, &c);
    double block = surface_rmse(&c, 0);
    print_message("  textured block: relative RMSE over its pixels %.4f\n", block);
    assert_true(block < BLOCK_RMSE);
    lm_frame_check_free(&c);
    lmgi_free(sc);
}

/* cornell-suzanne as `lmgi check` resolves its defaults (lit by its lamp alone: the rays gather, the lamp's
 * light at the near hits), after the bounce pass `lmgi bake` makes, against the same reference: the frame
 * within 3% per channel, as without the pass. Its lamp, a slab 1 cm thick with smoothed normals and no base
 * colour (albedo 1), gathered its own emission where a shading normal leant over its plane (its bottom's IIM
 * 0.34 where the floor's is 0.048), and the pass reflected that into the room: the frame read 1.042 1.040
 * 1.054 (1.050 1.050 1.066 at a bake's density) until the closed form kept to the geometric horizon too
 * (trace/emitter_light.h); 0.978 0.976 0.977 since, and 1.016 1.014 1.016 since the emitters' light at the
 * hits takes the shading normal's cosine (2026-12-06; the reference at 0.03 reads about 2% dark here). */
static void test_cornell_suzanne_bounce_pass(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(path, lmt_shared_scene("cornell-suzanne/cornellBox-2.80-Eevee-gltf.gltf"));
    lm_frame_loop_settings ls;
    lmgi_scene *sc = load_as_check(path, &ls);
    ls.width = ls.height = SIZE;
    ls.bounce_passes = 1;
    lm_ref_settings rs;
    ref_settings(&rs, REF_ERROR);
    lm_frame_check c;
    lm_error err;
    if (lm_frame_check_run(sc, &ls, &rs, 1, &c, &err) != LM_OK)
        fail_msg("%s", err.msg);
    assert_frame("cornell-suzanne after a bounce pass", sc, &c, 0.03, 0.06, 0.1, CHANNEL_TOL);
    lm_frame_check_free(&c);
    lmgi_free(sc);
}

/* Per surface of sc's atlas, over its valid texels of iim (RGBA, the displayed IIM) and the reference's E_iim:
 * the means per channel, the texel count (caller frees the three). */
static void surface_means(const lmgi_scene *sc, const float *iim, const uint8_t *valid, const lm_ref_result *ref,
                          double **est_mean, double **ref_mean, uint32_t **count)
{
    const lm_atlas *a = &sc->atlas;
    int S = sc->surfaces.surface_count;
    *est_mean = calloc(3 * (size_t)S, sizeof(double));
    *ref_mean = calloc(3 * (size_t)S, sizeof(double));
    *count = calloc((size_t)S, sizeof(uint32_t));
    assert_true(*est_mean && *ref_mean && *count);
    for (uint32_t i = 0; i < a->texel_count; i++) {
        int s = a->texels[i].surface;
        if (!valid[i] || s < 0)
            continue;
        const float *v = iim + 4 * ((size_t)a->texels[i].y * a->width + a->texels[i].x);
        for (int k = 0; k < 3; k++)
            (*est_mean)[3 * s + k] += v[k], (*ref_mean)[3 * s + k] += ref->iim[3 * i + k];
        (*count)[s]++;
    }
    for (int s = 0; s < S; s++)
        for (int k = 0; (*count)[s] && k < 3; k++)
            (*est_mean)[3 * s + k] /= (*count)[s], (*ref_mean)[3 * s + k] /= (*count)[s];
}

/* The displayed IIM (what `lmgi run` exports as iim.exr, before invalid texels are filled) of sc's first full
 * solution under ls against the reference's E_iim: per surface over its valid texels, asserted for surfaces of
 * at least min_texels; with box_tol > 0, every face of the small box of 100+ texels per channel within box_tol
 * too (issue 33, item 1). The IIM into *iim (caller frees) unless iim is NULL. */
static void check_iim(lmgi_scene *sc, lm_frame_loop_settings *ls, float ref_error, uint32_t min_texels,
                      double box_tol, float **iim)
{
    float *rgba = first_iim(sc, ls);
    lm_error err;
    lm_ref_settings rs;
    ref_settings(&rs, ref_error);
    lm_emitters em;
    assert_int_equal(lm_emitters_build(sc->scene, &em, &err), LM_OK);
    lm_ref_result ref;
    assert_int_equal(lm_reference_texels(sc->scene, &sc->atlas, sc->rt, &em, &rs, &ref, &err), LM_OK);
    const lm_atlas *a = &sc->atlas;
    uint8_t *valid = malloc(a->texel_count);
    float *est = malloc(sizeof(float) * 3 * a->texel_count);
    assert_true(valid && est);
    double all = 0.0;
    uint32_t n_valid = 0;
    for (uint32_t i = 0; i < a->texel_count; i++) {
        const float *v = rgba + 4 * ((size_t)a->texels[i].y * a->width + a->texels[i].x);
        valid[i] = !(v[3] > ls->gather.backface_limit);
        memcpy(est + 3 * i, v, 3 * sizeof(float));
        if (valid[i])
            all += ref.iim[3 * i] + ref.iim[3 * i + 1] + ref.iim[3 * i + 2], n_valid++;
    }
    all /= n_valid ? n_valid : 1;
    double rmse = lm_ref_relative_rmse(est, ref.iim, valid, a->texel_count, 3);
    print_message("IIM at %u texels: %u valid, relative RMSE %.4f (reference se %.3f, %.1f s)\n", a->texel_count,
                  n_valid, rmse, ref.mean_rel_se, ref.seconds);
    double *e, *r;
    uint32_t *n;
    surface_means(sc, rgba, valid, &ref, &e, &r, &n);
    int box_faces = 0;
    for (int s = 0; s < sc->surfaces.surface_count; s++) {
        if (n[s] < 100)
            continue;
        double es = e[3 * s] + e[3 * s + 1] + e[3 * s + 2], rs3 = r[3 * s] + r[3 * s + 1] + r[3 * s + 2];
        int box = !strcmp(sc->scene->nodes[sc->surfaces.surfaces[s].node].name, "small.box");
        print_message("  surface %2d (%s): %5u texels, E %.4g, reference %.4g (%+.1f%%; per channel %.3f %.3f %.3f)%s\n",
                      s, sc->scene->nodes[sc->surfaces.surfaces[s].node].name, n[s], es / 3, rs3 / 3,
                      rs3 > 0.0 ? 100.0 * (es / rs3 - 1.0) : 0.0, e[3 * s] / r[3 * s], e[3 * s + 1] / r[3 * s + 1],
                      e[3 * s + 2] / r[3 * s + 2], n[s] >= min_texels ? "" : " (not asserted)");
        if (n[s] >= min_texels)
            assert_true(fabs(es - rs3) / 3 <= SURFACE_TOL * fmax(rs3 / 3, all / 3));
        if (box && box_tol > 0.0 && rs3 > 0.0) /* lit: the face under the box is not */
            assert_true(lm_cli_channel_off(e + 3 * s, r + 3 * s, NULL) <= box_tol), box_faces++;
    }
    assert_true(box_tol == 0.0 || box_faces >= 4);
    assert_true(rmse < 0.1);
    free(e);
    free(r);
    free(n);
    free(valid);
    free(est);
    if (iim)
        *iim = rgba;
    else
        free(rgba);
    lm_ref_result_free(&ref);
    lm_emitters_free(&em);
}

/* Measured: run density (1,964 texels) every surface of 100 texels or more (walls, floor, ceiling) within
 * 2.6%, relative RMSE 0.035. */
static void test_iim_run_density(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(path, lmt_shared_scene("cornell-box/CornellBox.glb"));
    lmgi_scene *sc = load_as_run(path, 0);
    lm_frame_loop_settings ls;
    lm_frame_loop_settings_default(&ls);
    check_iim(sc, &ls, REF_ERROR, 100, 0.0, NULL);
    lmgi_free(sc);
}

/* A scene loaded as `lmgi bake` loads it (the loader's own density) and the settings its first full solution
 * resolves from a bake's (src/cli/bake_options.h: 16 photons a texel, a bounce pass). */
static lmgi_scene *load_as_bake(const char *path, lm_frame_loop_settings *ls)
{
    lmgi_options o;
    lmgi_options_init(&o);
    lmgi_scene *sc = load_with(path, &o);
    lmgi_info in;
    lmgi_get_info(sc, &in);
    lmgi_updater_desc d;
    memset(&d, 0, sizeof d);
    lm_cli_bake_solution(&in, 1, &d);
    lm_error err;
    if (lm_updater_settings(sc->scene, &d, NULL, ls, &err) != LM_OK)
        fail_msg("%s", err.msg);
    assert_int_equal(ls->bounce_passes, LM_CLI_BAKE_BOUNCE_PASSES);
    return sc;
}

/* As baked, the small box's side faces' texels in the first 20 mm above the floor (69 a face) against the
 * reference's texels (those alone, at CONTACT_REF_ERROR, at most CONTACT_REF_PATHS paths a texel): per face
 * the spread (standard deviation) of the luminance ratios, the most at the face towards the open front (12),
 * whose light comes mostly from a band of lit floor 1-2 degrees below the level (docs/gather.md, "Strata").
 * Issue 33, item 1: every such texel within 10%. The history, each step's spread and range of face 12:
 * polar strata 16.7%, 0.76-1.95; upright strata 11.5%, 0.84-1.41; each row's rays at their own alpha 5.8%,
 * 0.855-1.196 (those three against the reference at 0.02 and 65,536 paths, whose own error on face 12 was up
 * to 10%: its paths reach the band by chance). Against a reference of a million paths a texel, gather seeds
 * 0-3: that last 4.3-4.8%, 0.89-1.15; with the contact rows split in 8 (hemicube_rim.c) and a bake's 16
 * photons a texel (the kernel no longer smears the floor's contact shadow) 1.9-2.0%, 0.949-1.058, every
 * face's texels. Against this test's reference at seeds 0-3: spread 2.1-2.3%, 0.945-1.066 (its error on
 * face 12: 1.0% a texel, the most 1.6%). */
#define CONTACT_REF_ERROR 0.01f /* face 12's texels all stop at CONTACT_REF_PATHS, about 1.0% then */
#define CONTACT_REF_PATHS 262144
static void contact_faces(const lmgi_scene *sc, const float *iim)
{
    uint32_t *index;
    lm_atlas sub = contact_texels(sc, &index);
    lm_ref_result ref;
    contact_reference(sc, &sub, CONTACT_REF_ERROR, CONTACT_REF_PATHS, &ref);
    print_message("  their reference: relative standard error %.4f, the most %.4f\n", ref.mean_rel_se, ref.max_rel_se);
    double sum[64] = {0}, sq[64] = {0}, lo = INFINITY, hi = 0.0;
    int n[64] = {0};
    for (uint32_t j = 0; j < sub.texel_count; j++) {
        int f = sc->atlas.texels[index[j]].surface;
        double q = contact_ratio(sc, iim, index, &ref, j);
        assert_true(f >= 0 && f < 64);
        sum[f] += q, sq[f] += q * q, n[f]++;
        lo = fmin(lo, q), hi = fmax(hi, q);
    }
    double worst = 0.0;
    int faces = 0;
    for (int f = 0; f < 64; f++) {
        if (n[f] < 20)
            continue;
        double m = sum[f] / n[f], sd = sqrt(fmax(0.0, sq[f] / n[f] - m * m));
        print_message("  small box face %d, its %d texels in the first 20 mm: mean %.3f of the reference, "
                      "spread %.3f\n", f, n[f], m, sd);
        assert_true(fabs(m - 1.0) < 0.03);
        worst = fmax(worst, sd), faces++;
    }
    print_message("as baked, the small box's %u texels in the first 20 mm: %.3f-%.3f of the reference, the worst "
                  "face's spread %.3f\n", sub.texel_count, lo, hi, worst);
    assert_true(faces == 4);
    assert_true(worst < 0.035);         /* 0.021 measured; 0.043-0.048 before the contact rows (seeds 0-3) */
    assert_true(lo > 0.9 && hi < 1.1);  /* 0.955-1.057; 0.89-1.15 so */
    lm_ref_result_free(&ref);
    free(sub.texels);
    free(index);
}

/* At 66,816 texels, with the photon count `lmgi run` took before the scene's floor (11,520): walls, floor
 * and ceiling within 2%, relative RMSE 0.053; the boxes' faces (529 to 1,035 texels) read -6% to +10%,
 * the AIM's photon noise where they meet the floor (within 2% with 200k photons). Loaded and solved as
 * `lmgi bake` solves it (load_as_bake: 16 photons a texel, a bounce pass, 4 x 4 direct parts), the small
 * box's lit faces are issue 33's item 1 at a bake's density: each within 2% per channel (measured within
 * 0.4%, 0.9% at 4 photons a texel; `lmgi check --as-bake`'s frame at 8 of 8 seeds, docs/gather.md,
 * "Strata"). The reference's 0.05 is enough for means over hundreds of texels (this scene has no rare
 * bright paths: its light is an area light). */
static void test_iim_bake_density(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(path, lmt_shared_scene("cornell-box/CornellBox.glb"));
    lm_frame_loop_settings ls;
    lmgi_scene *sc = load_as_bake(path, &ls);
    float *iim;
    check_iim(sc, &ls, 0.05f, 2000, ITEM_1_TOL, &iim);
    contact_faces(sc, iim);
    free(iim);
    lmgi_free(sc);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_shared_cornell_box),
        cmocka_unit_test(test_shared_cornell_box_direct_at_hits),
        cmocka_unit_test(test_near_and_far_hits),
        cmocka_unit_test(test_contact_texels_strata),
        cmocka_unit_test(test_mixed_lighting),
        cmocka_unit_test(test_generated_cornell_box),
        cmocka_unit_test(test_two_rooms),
        cmocka_unit_test(test_depth_of_field),
        cmocka_unit_test(test_cornell_suzanne),
        cmocka_unit_test(test_cornell_suzanne_bounce_pass),
        cmocka_unit_test(test_iim_run_density),
        cmocka_unit_test(test_iim_bake_density),
    };
    lmt_filter_from_env();
    return cmocka_run_group_tests(tests, NULL, NULL);
}
