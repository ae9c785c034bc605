/* lmgi check: `lmgi run`'s frame against the reference, per visible surface and over the frame. */
#include "check_cmd.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "../core/image.h"
#include "../core/log.h"
#include "../api/frame_check.h"
#include "../api/lmgi_updater.h"
#include "out_dir.h"
#include "reference_cmd.h"
#include "run_cmd.h"

#define CHECK_SIZE 128 /* default picture side: the reference's pixels take seconds, not minutes */

static void print_row(const char *name, const char *material, const lm_check_sum *c)
{
    printf("  %-24s %-24s %7u   %6.3f %6.3f %6.3f\n", name, material, c->pixels, lm_check_ratio(c, 0),
           lm_check_ratio(c, 1), lm_check_ratio(c, 2));
}

static void report(const lmgi_scene *sc, const lm_frame_check *c, const lm_ref_settings *rs)
{
    printf("frame %dx%d against the reference (target error %.3g: mean relative standard error per pixel %.3f, "
           "%.1f s)\n", c->width, c->height, (double)rs->target_error, c->ref_rel_se, c->ref_seconds);
    printf("  %-24s %-24s %7s   frame / reference (R G B)\n", "surface (node)", "material", "pixels");
    for (int s = 0; s < c->surface_count; s++) {
        if (!c->surface[s].pixels)
            continue;
        const lm_surface *sf = &sc->surfaces.surfaces[s];
        char name[96];
        snprintf(name, sizeof name, "%d (%.14s)", s, sc->scene->nodes[sf->node].name);
        print_row(name, sc->scene->materials[sf->material].name, &c->surface[s]);
    }
    print_row("frame (not emitters)", "", &c->lit);
    printf("relative RMSE over those pixels %.4f\n", c->rel_rmse);
}

/* frame / reference per compared pixel as a colour: grey at 1, red where the frame is brighter, blue where
 * it is darker, full at +-10%; black where nothing is compared. */
static void ratio_picture(const lm_frame_check *c, uint8_t *rgba)
{
    size_t n = (size_t)c->width * (size_t)c->height;
    for (size_t i = 0; i < n; i++) {
        const float *f = c->frame + 3 * i, *r = c->ref + 3 * i;
        double lf = f[0] + f[1] + f[2], lr = r[0] + r[1] + r[2];
        double t = c->compared[i] && lr > 0.0 ? fmax(-1.0, fmin(1.0, (lf / lr - 1.0) / 0.1)) : 0.0;
        uint8_t *o = rgba + 4 * i;
        o[0] = (uint8_t)(c->compared[i] ? 128 + (t > 0 ? 127 * t : 0) - (t < 0 ? -100 * t : 0) : 0);
        o[1] = (uint8_t)(c->compared[i] ? 128 - 100 * fabs(t) : 0);
        o[2] = (uint8_t)(c->compared[i] ? 128 + (t < 0 ? -127 * t : 0) - (t > 0 ? 100 * t : 0) : 0);
        o[3] = 255;
    }
}

static int write_images(const char *dir, const lm_frame_check *c)
{
    lm_error err;
    char path[4096];
    snprintf(path, sizeof path, "%s/check_frame.exr", dir);
    lm_status st = lm_write_exr(path, c->width, c->height, 3, c->frame, &err);
    if (st == LM_OK) {
        snprintf(path, sizeof path, "%s/check_reference.exr", dir);
        st = lm_write_exr(path, c->width, c->height, 3, c->ref, &err);
    }
    uint8_t *rgba = st == LM_OK ? malloc((size_t)c->width * (size_t)c->height * 4) : NULL;
    if (st == LM_OK && !rgba)
        st = lm_fail(&err, LM_ERR_NOMEM, "no memory for the ratio picture");
    if (st == LM_OK) {
        ratio_picture(c, rgba);
        snprintf(path, sizeof path, "%s/check_ratio.png", dir);
        st = lm_write_png(path, c->width, c->height, rgba, &err);
    }
    free(rgba);
    if (st != LM_OK)
        fprintf(stderr, "lmgi: error: %s\n", err.msg);
    return st == LM_OK;
}

int lm_cli_check(const lm_cli_args *a)
{
    if (a->file_count != 1) {
        fprintf(stderr, "lmgi: usage: lmgi check SCENE [--size WxH] [--frames N] [run options] [--target-error E]\n"
                        "       [--samples N] [--cache DIR] [--no-cache] [--out DIR]\n");
        return 2;
    }
    static const char *const own[] = {"check_*.exr", "check_*.png", NULL};
    lm_error err;
    if (a->out_dir && lm_cli_claim_out_dir(a->out_dir, a->force, own, &err) != LM_OK) {
        fprintf(stderr, "lmgi: error: %s\n", err.msg);
        return 1;
    }
    lmgi_scene *sc = NULL;
    if (!lm_cli_run_load(a, &sc))
        return 1;
    lmgi_updater_desc d;
    lm_cli_updater_desc(a, &d);
    d.progress = NULL;
    if (!a->width)
        d.frame_width = d.frame_height = CHECK_SIZE;
    lm_frame_loop_settings ls;
    if (lm_updater_settings(sc->scene, &d, &ls, &err) != LM_OK) {
        fprintf(stderr, "lmgi: error: %s\n", err.msg);
        lmgi_free(sc);
        return 1;
    }
    lm_ref_settings rs;
    lm_cli_ref_settings(a, &rs);
    if (!a->quiet && lm_log_get_level() < LM_LOG_INFO)
        lm_log_set_level(LM_LOG_INFO); /* the reference's progress lines */
    lm_frame_check c;
    int rc = 0;
    if (lm_frame_check_run(sc, &ls, &rs, a->frames ? a->frames : 1, &c, &err) != LM_OK) {
        fprintf(stderr, "lmgi: error: %s\n", err.msg);
        rc = 1;
    } else {
        report(sc, &c, &rs);
        if (a->out_dir && !write_images(a->out_dir, &c))
            rc = 1;
        lm_frame_check_free(&c);
    }
    lmgi_free(sc);
    return rc;
}
