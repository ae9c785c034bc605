/* `lmgi reference`: the converged reference for a scene (docs/reference.md).
 *
 * Writes, in --out DIR:
 *   reference_full.exr      atlas-sized RGB float, E_full per texel (0 outside texels)
 *   reference_iim.exr       the same for E_iim (what an IIM holds)
 *   reference_radiance.exr  the same for albedo / pi x E_full (what an AIM approximates)
 *   reference_pixels.exr    the camera's picture, linear radiance
 *   reference_pixels.png    that picture tone-mapped: exposure putting the 99th-percentile luminance at
 *                           0.9, clamp, sRGB (src/core/tonemap.h) */
#include "reference_cmd.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/image.h"
#include "../core/log.h"
#include "../core/timing.h"
#include "../core/tonemap.h"
#include "../gpu/camera.h"
#include "../trace/reference.h"
#include "../api/lmgi_scene.h"
#include "out_dir.h"
#include "scene_load.h"

#define LM_CLI_REF_WIDTH 320
#define LM_CLI_REF_HEIGHT 240

void lm_cli_ref_settings(const lm_cli_args *a, lm_ref_settings *set)
{
    lm_ref_settings_default(set);
    if (a->target_error > 0.0f)
        set->target_error = a->target_error;
    if (a->samples > 0) {
        set->samples = a->samples;
        set->min_samples = 2 * a->samples;
        if (set->max_samples < set->samples)
            set->max_samples = set->samples;
    }
    if (a->seed)
        set->seed = a->seed;
    set->cache_dir = a->cache_dir;
    set->use_cache = !a->no_cache;
    set->progress = !a->quiet;
}

static int write_atlas_exr(const char *dir, const char *name, const lm_atlas *atlas, const float *values)
{
    char path[1200];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    float *img = malloc((size_t)atlas->width * (size_t)atlas->height * 3 * sizeof(float));
    lm_error err;
    if (!img) {
        fprintf(stderr, "lmgi: error: no memory for %s\n", path);
        return 0;
    }
    lm_ref_texels_to_image(atlas, values, img);
    lm_status st = lm_write_exr(path, atlas->width, atlas->height, 3, img, &err);
    free(img);
    if (st != LM_OK)
        fprintf(stderr, "lmgi: error: %s\n", err.msg);
    return st == LM_OK;
}

static int write_pixels(const char *dir, const lm_ref_result *r)
{
    char path[1200];
    lm_error err;
    snprintf(path, sizeof path, "%s/reference_pixels.exr", dir);
    if (lm_write_exr(path, r->width, r->height, 3, r->full, &err) != LM_OK) {
        fprintf(stderr, "lmgi: error: %s\n", err.msg);
        return 0;
    }
    uint8_t *rgba = malloc((size_t)r->count * 4);
    if (!rgba) {
        fprintf(stderr, "lmgi: error: no memory for the tone-mapped picture\n");
        return 0;
    }
    lm_tonemap_srgb8(r->full, r->count, 3, lm_auto_exposure(r->full, r->count, 3), rgba);
    snprintf(path, sizeof path, "%s/reference_pixels.png", dir);
    lm_status st = lm_write_png(path, r->width, r->height, rgba, &err);
    free(rgba);
    if (st != LM_OK)
        fprintf(stderr, "lmgi: error: %s\n", err.msg);
    return st == LM_OK;
}

static void report(const char *what, const lm_ref_result *r, const lm_ref_settings *set, double wall)
{
    printf("%s: %u, %llu samples (%.0f per entry), target error %.4g: reached by %u (%.2f%%), "
           "relative standard error mean %.4f max %.4f, %.1f s%s\n",
           what, r->count, (unsigned long long)r->total_samples, r->count ? (double)r->total_samples / r->count : 0.0,
           (double)set->target_error, r->converged, r->count ? 100.0 * r->converged / r->count : 100.0,
           r->mean_rel_se, r->max_rel_se, r->from_cache ? wall : r->seconds,
           r->from_cache ? " (from the cache)" : "");
    if (r->from_cache)
        printf("  (computing it took %.1f s)\n", r->seconds);
}

static int run_texels(const lm_cli_args *a, const lmgi_scene *sc, const lm_emitters *em, const lm_ref_settings *set)
{
    lm_ref_result r;
    lm_error err;
    double t0 = lm_now();
    if (lm_reference_texels(sc->scene, &sc->atlas, sc->rt, em, set, &r, &err) != LM_OK) {
        fprintf(stderr, "lmgi: error: %s\n", err.msg);
        return 0;
    }
    int ok = write_atlas_exr(a->out_dir, "reference_full.exr", &sc->atlas, r.full) &&
             write_atlas_exr(a->out_dir, "reference_iim.exr", &sc->atlas, r.iim) &&
             write_atlas_exr(a->out_dir, "reference_radiance.exr", &sc->atlas, r.radiance);
    if (ok && !a->quiet) {
        printf("atlas %d x %d, texel size %g\n", sc->atlas.width, sc->atlas.height, (double)sc->atlas.texel_size);
        report("texels", &r, set, lm_now() - t0);
    }
    lm_ref_result_free(&r);
    return ok;
}

static int run_pixels(const lm_cli_args *a, const lmgi_scene *sc, const lm_emitters *em, const lm_ref_settings *set)
{
    lm_ref_camera cam;
    int w = a->width > 0 ? a->width : LM_CLI_REF_WIDTH, h = a->height > 0 ? a->height : LM_CLI_REF_HEIGHT;
    lm_view view;
    lm_error err;
    lm_view_for_scene(sc->scene, a->camera, w, h, &view);
    if (lm_view_ref_camera(&view, w, h, &cam, &err) != LM_OK) {
        fprintf(stderr, "lmgi: reference: %s\n", err.msg);
        return 0;
    }
    lm_ref_result r;
    double t0 = lm_now();
    if (lm_reference_pixels(sc->scene, sc->rt, em, &cam, set, &r, &err) != LM_OK) {
        fprintf(stderr, "lmgi: error: %s\n", err.msg);
        return 0;
    }
    int ok = write_pixels(a->out_dir, &r);
    if (ok && !a->quiet)
        report("pixels", &r, set, lm_now() - t0);
    lm_ref_result_free(&r);
    return ok;
}

int lm_cli_reference(const lm_cli_args *a)
{
    if (a->file_count != 1 || !a->out_dir) {
        fprintf(stderr, "lmgi: usage: lmgi reference SCENE --out DIR [--target-error E] [--samples N] [--seed N]\n"
                        "       [--cache DIR] [--no-cache] [--camera I] [--size WxH] [--texel-size S]\n");
        return 2;
    }
    lmgi_scene *sc = NULL;
    if (!lm_cli_load_scene(a->files[0], &a->options, 1, &sc))
        return 1;
    lm_error err;
    lm_emitters em;
    static const char *const own[] = {"reference_*.exr", "reference_*.png", NULL};
    int ok = lm_cli_claim_out_dir(a->out_dir, a->force, own, &err) == LM_OK &&
             lm_emitters_build(sc->scene, &em, &err) == LM_OK;
    if (!ok) {
        fprintf(stderr, "lmgi: error: %s\n", err.msg);
        lmgi_free(sc);
        return 1;
    }
    if (!a->quiet && lm_log_get_level() < LM_LOG_INFO)
        lm_log_set_level(LM_LOG_INFO); /* progress lines */
    lm_ref_settings set;
    lm_cli_ref_settings(a, &set);
    ok = run_texels(a, sc, &em, &set) && run_pixels(a, sc, &em, &set);
    lm_emitters_free(&em);
    lmgi_free(sc);
    return ok ? 0 : 1;
}
