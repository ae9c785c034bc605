/* `lmgi reference`: the converged reference for a scene (docs/reference.md), through lmgi_reference_*.
 *
 * Writes, in --out DIR:
 *   reference_full.exr      atlas-sized RGB float, E_full per texel (0 outside texels)
 *   reference_iim.exr       the same for E_iim (what an IIM holds)
 *   reference_radiance.exr  the same for albedo / pi x E_full (what an AIM approximates)
 *   reference_direct.exr, reference_caustic.exr, reference_lost.exr
 *                           the same for the other parts of E_full (docs/reference.md, "Which part carries
 *                           which light")
 *   reference_pixels.exr    the camera's picture, linear radiance
 *   reference_pixels.png    that picture tone-mapped (--tonemap, as lmgi run's frames)
 *   reference_pixels_{emission,direct,indirect,caustic,reflections,lost}.exr
 *                           the picture's parts, which add up to it
 * and prints, per part, its mean luminance over the entries and its share of full's. */
#include "reference_cmd.h"

#include <stdio.h>
#include <string.h>

#include "out_dir.h"
#include "progress.h"
#include "scene_load.h"

#define LM_CLI_REF_WIDTH 320
#define LM_CLI_REF_HEIGHT 240

void lm_cli_reference_desc(const lm_cli_args *a, lmgi_reference_desc *d)
{
    memset(d, 0, sizeof *d);
    d->target_error = a->target_error;
    d->samples = a->samples;
    d->seed = a->seed;
    d->caustic_photons = a->ref_caustic_photons; /* --caustic-photons is the updater's (check) */
    d->cache_dir = a->cache_dir;
    d->no_cache = a->no_cache;
    if (!a->quiet && !a->verbose)
        lmgi_set_verbosity(2); /* the solver's progress lines */
}

/* DIR/NAME written from pixels, or the error printed. */
static int write(const lm_cli_args *a, lmgi_output *o, const char *name, int w, int h, const float *px)
{
    lmgi_image_desc d = {(lmgi_tonemap)a->tonemap, 0.0f, 0};
    lmgi_error err;
    if (lm_cli_write_image(o, name, w, h, 3, px, &d, &err) == LMGI_OK)
        return 1;
    fprintf(stderr, "lmgi: error: %s\n", err.message);
    return 0;
}

static void report(const char *what, const lmgi_reference *r, double wall)
{
    printf("%s: %u, %llu samples (%.0f per entry), target error %.4g: reached by %u (%.2f%%), "
           "relative standard error mean %.4f max %.4f, %.1f s%s\n",
           what, r->entries, (unsigned long long)r->samples, r->entries ? (double)r->samples / r->entries : 0.0,
           (double)r->target_error, r->converged,
           r->entries ? 100.0 * r->converged / r->entries : 100.0, r->mean_rel_se, r->max_rel_se,
           r->from_cache ? wall : r->seconds, r->from_cache ? " (from the cache)" : "");
    if (r->from_cache)
        printf("  (computing it took %.1f s)\n", r->seconds);
    printf("  caustic part: %llu photons, %.1f s%s\n", (unsigned long long)r->caustic_photons, r->caustic_seconds,
           r->caustic_photons ? "" : " (the scene has no mirror or glass, or no light)");
}

/* Sum of the luminance of an image's pixels (0 outside texels for texel images). */
static double luminance_sum(const float *rgb, int w, int h)
{
    double s = 0.0;
    for (size_t i = 0; i < (size_t)w * (size_t)h; i++)
        s += 0.2126 * rgb[3 * i] + 0.7152 * rgb[3 * i + 1] + 0.0722 * rgb[3 * i + 2];
    return s;
}

/* One line per part: mean luminance over the entries and share of full's. */
static void report_parts(const lmgi_reference *r, const char *const *names, const float *const *parts, int n)
{
    double total = luminance_sum(r->full, r->width, r->height), per = r->entries ? 1.0 / r->entries : 0.0;
    printf("  %-12s mean luminance %.6g\n", "full", total * per);
    for (int k = 0; k < n; k++) {
        double sum = luminance_sum(parts[k], r->width, r->height);
        printf("  %-12s mean luminance %.6g (%.2f%%)\n", names[k], sum * per, total > 0.0 ? 100.0 * sum / total : 0.0);
    }
}

static int run_texels(const lm_cli_args *a, lmgi_output *o, const lmgi_scene *sc, const lmgi_reference_desc *d)
{
    lmgi_reference r;
    lmgi_error err;
    double t0 = lm_cli_now();
    if (lmgi_reference_texels(sc, d, &r, &err) != LMGI_OK) {
        fprintf(stderr, "lmgi: error: %s\n", err.message);
        return 0;
    }
    static const char *const names[] = {"direct", "iim", "caustic", "lost"};
    static const char *const files[] = {"reference_direct.exr", "reference_iim.exr", "reference_caustic.exr",
                                        "reference_lost.exr"};
    const float *parts[] = {r.direct, r.iim, r.caustic, r.lost};
    int ok = write(a, o, "reference_full.exr", r.width, r.height, r.full) &&
             write(a, o, "reference_radiance.exr", r.width, r.height, r.radiance);
    for (int k = 0; ok && k < 4; k++)
        ok = write(a, o, files[k], r.width, r.height, parts[k]);
    if (ok && !a->quiet) {
        lmgi_info in;
        lmgi_get_info(sc, &in);
        printf("atlas %d x %d, texel size %g\n", in.atlas_width, in.atlas_height, (double)in.texel_size);
        report("texels", &r, lm_cli_now() - t0);
        report_parts(&r, names, parts, 4);
    }
    lmgi_reference_free(&r);
    return ok;
}

static int run_pixels(const lm_cli_args *a, lmgi_output *o, const lmgi_scene *sc, const lmgi_reference_desc *d)
{
    int w = a->width > 0 ? a->width : LM_CLI_REF_WIDTH, h = a->height > 0 ? a->height : LM_CLI_REF_HEIGHT;
    lmgi_camera cam;
    lmgi_reference r;
    lmgi_error err;
    double t0 = lm_cli_now();
    if (lmgi_scene_camera(sc, a->camera, w, h, &cam, &err) != LMGI_OK ||
        lmgi_reference_pixels(sc, d, &cam, w, h, &r, &err) != LMGI_OK) {
        fprintf(stderr, "lmgi: reference: %s\n", err.message);
        return 0;
    }
    static const char *const names[] = {"emission", "direct", "indirect", "caustic", "reflections", "lost"};
    const float *parts[] = {r.emission, r.direct, r.indirect, r.caustic, r.reflections, r.lost};
    int ok = write(a, o, "reference_pixels.exr", w, h, r.full) && write(a, o, "reference_pixels.png", w, h, r.full);
    for (int k = 0; ok && k < 6; k++) {
        char name[64];
        snprintf(name, sizeof name, "reference_pixels_%s.exr", names[k]);
        ok = write(a, o, name, w, h, parts[k]);
    }
    if (ok && !a->quiet) {
        report("pixels", &r, lm_cli_now() - t0);
        report_parts(&r, names, parts, 6);
    }
    lmgi_reference_free(&r);
    return ok;
}

int lm_cli_reference(const lm_cli_args *a)
{
    if (a->file_count != 1 || !a->out_dir) {
        fprintf(stderr, "lmgi: usage: lmgi reference SCENE --out DIR [--target-error E] [--samples N] [--seed N]\n"
                        "       [--caustic-photons N] [--cache DIR] [--no-cache] [--camera I] [--size WxH]\n"
                        "       [--texel-size S]\n");
        return 2;
    }
    lmgi_scene *sc = NULL;
    if (!lm_cli_load_scene(a->files[0], &a->options, 1, &sc))
        return 1;
    lmgi_output *o = lm_cli_open_out(a, "reference");
    if (!o) {
        lmgi_free(sc);
        return 1;
    }
    lmgi_reference_desc d;
    lm_cli_reference_desc(a, &d);
    if (!d.caustic_photons) /* the reference command has no updater: --caustic-photons is its own */
        d.caustic_photons = a->caustic_photons;
    int ok = run_texels(a, o, sc, &d) && run_pixels(a, o, sc, &d);
    lmgi_free(sc);
    return lm_cli_close_out(o, !ok);
}
