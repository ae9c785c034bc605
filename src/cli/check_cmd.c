/* lmgi check: `lmgi run`'s frame against the reference, per visible surface and over the frame
 * (lmgi_check). */
#include "check_cmd.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "bake_options.h"
#include "out_dir.h"
#include "reference_cmd.h"
#include "run_cmd.h"
#include "scene_load.h"
#include "surface_error.h"

#define CHANNEL_TOLERANCE 0.05 /* issue 33's bound on every channel of every surface of 100+ pixels */

static void print_row(const char *name, const char *material, uint32_t pixels, const double ratio[3])
{
    printf("  %-24s %-24s %7u   %6.3f %6.3f %6.3f\n", name, material, pixels, ratio[0], ratio[1], ratio[2]);
}

static int has_caustics(const lmgi_check_result *c)
{
    return c->caustic_reference_mean[0] + c->caustic_reference_mean[1] + c->caustic_reference_mean[2] > 0.0;
}

static void report(const lmgi_scene *sc, const lmgi_check_result *c)
{
    printf("frame %dx%d against the reference (target error %.3g: mean relative standard error per pixel %.3f, "
           "%.1f s)\n", c->width, c->height, (double)c->reference_target_error,
           c->reference_rel_se, c->reference_seconds);
    printf("  %-24s %-24s %7s   frame / reference (R G B)\n", "surface (node)", "material", "pixels");
    for (int s = 0; s < c->surface_count; s++) {
        const lmgi_check_surface *f = &c->surfaces[s];
        if (!f->pixels)
            continue;
        char name[96];
        snprintf(name, sizeof name, "%d (%.14s)", s, lmgi_node_name(sc, f->node));
        print_row(name, lmgi_material_name(sc, f->material), f->pixels, f->ratio);
    }
    print_row("frame (not emitters)", "", c->pixels, c->ratio);
    printf("relative RMSE over those pixels %.4f\n", c->rel_rmse);
    if (has_caustics(c))
        printf("caustic part (light off mirrors and glass, L S+ D) over those pixels: frame / reference %.3f %.3f "
               "%.3f, relative RMSE %.4f\n", c->caustic_ratio[0], c->caustic_ratio[1], c->caustic_ratio[2],
               c->caustic_rel_rmse);
    lm_cli_channel_check ch;
    lm_cli_surface_channels(sc, c, CHANNEL_TOLERANCE, &ch);
    printf("per channel: %d of %d surfaces of 100+ pixels within %.0f%% of the reference", ch.within, ch.surfaces,
           100.0 * CHANNEL_TOLERANCE);
    if (ch.worst_surface >= 0)
        printf("; furthest off: %d (%.14s) %c %+.1f%%", ch.worst_surface,
               lmgi_node_name(sc, c->surfaces[ch.worst_surface].node), "RGB"[ch.worst_channel], 100.0 * ch.worst_ratio);
    printf("\n");
}

/* frame / reference per compared pixel as a colour: grey at 1, red where the frame is brighter, blue where
 * it is darker, full at +-10%; black where nothing is compared. Written as linear values that the clamp
 * tone map at exposure 1 turns into these sRGB levels. */
static void ratio_picture(const lmgi_check_result *c, float *rgb)
{
    size_t n = (size_t)c->width * (size_t)c->height;
    for (size_t i = 0; i < n; i++) {
        const float *f = c->frame + 3 * i, *r = c->reference + 3 * i;
        double lf = f[0] + f[1] + f[2], lr = r[0] + r[1] + r[2];
        double t = c->compared[i] && lr > 0.0 ? fmax(-1.0, fmin(1.0, (lf / lr - 1.0) / 0.1)) : 0.0;
        double srgb[3] = {128 + (t > 0 ? 127 * t : 0) - (t < 0 ? -100 * t : 0), 128 - 100 * fabs(t),
                          128 + (t < 0 ? -127 * t : 0) - (t > 0 ? 100 * t : 0)};
        for (int k = 0; k < 3; k++) {
            double v = c->compared[i] ? srgb[k] / 255.0 : 0.0;
            rgb[3 * i + k] = (float)(v <= 0.04045 ? v / 12.92 : pow((v + 0.055) / 1.055, 2.4));
        }
    }
}

static int write_images(lmgi_output *dir, const lmgi_check_result *c)
{
    lmgi_error err;
    lmgi_status st = lm_cli_write_image(dir, "check_frame.exr", c->width, c->height, 3, c->frame, NULL, &err);
    if (st == LMGI_OK)
        st = lm_cli_write_image(dir, "check_reference.exr", c->width, c->height, 3, c->reference, NULL, &err);
    if (st == LMGI_OK && has_caustics(c))
        st = lm_cli_write_image(dir, "check_caustic.exr", c->width, c->height, 3, c->caustic_frame, NULL, &err);
    if (st == LMGI_OK && has_caustics(c))
        st = lm_cli_write_image(dir, "check_reference_caustic.exr", c->width, c->height, 3, c->caustic_reference,
                                NULL, &err);
    float *rgb = st == LMGI_OK ? malloc((size_t)c->width * (size_t)c->height * 3 * sizeof *rgb) : NULL;
    if (st == LMGI_OK && !rgb) {
        fprintf(stderr, "lmgi: error: no memory for the ratio picture\n");
        return 0;
    }
    if (st == LMGI_OK) {
        ratio_picture(c, rgb);
        lmgi_image_desc as_is = {LMGI_TONEMAP_CLAMP, 1.0f, 0};
        st = lm_cli_write_image(dir, "check_ratio.png", c->width, c->height, 3, rgb, &as_is, &err);
    }
    free(rgb);
    if (st != LMGI_OK)
        fprintf(stderr, "lmgi: error: %s\n", err.message);
    return st == LMGI_OK;
}

/* --as-bake: the updater's desc as lmgi bake makes it (bake_options.h), said in a line above the table. */
static void bake_desc(const lm_cli_args *a, const lmgi_scene *sc, lmgi_updater_desc *d)
{
    lmgi_info in;
    lmgi_get_info(sc, &in);
    lm_cli_updater_desc(a, d);
    lm_cli_bake_solution(&in, 1, d);
    printf("the lightmap as lmgi bake makes it: %u texels, ", in.texels);
    if (d->photons.count)
        printf("%u photons, ", d->photons.count);
    else
        printf("%u photons a group, ", d->photons.per_group);
    int passes = d->gather.bounce_passes == LMGI_OFF ? 0 : d->gather.bounce_passes;
    if (passes)
        printf("%d bounce pass%s, ", passes, passes == 1 ? "" : "es");
    else
        printf("no bounce pass, ");
    printf("direct light over %d x %d parts a texel\n", d->aim.direct_parts, d->aim.direct_parts);
}

int lm_cli_check(const lm_cli_args *a)
{
    if (a->file_count != 1) {
        fprintf(stderr, "lmgi: usage: lmgi check SCENE [--size WxH] [--frames N] [run options] [--target-error E]\n"
                        "       [--samples N] [--cache DIR] [--no-cache] [--out DIR]\n");
        return 2;
    }
    lmgi_scene *sc = NULL;
    /* --as-bake: the loader's own density, as bake loads */
    if (a->as_bake ? !lm_cli_load_scene(a->files[0], &a->options, 1, &sc) : !lm_cli_run_load(a, &sc))
        return 1;
    if (lm_cli_scene_unlit(sc)) { /* black against black reads 1.000 everywhere: a check of nothing */
        fprintf(stderr, "lmgi: error: %s: nothing to check: the scene has no light, so frame and reference are "
                "both black\n", a->files[0]);
        lmgi_free(sc);
        return 1;
    }
    lmgi_output *out = NULL; /* opened before the long work, so a bad path fails at once */
    if (a->out_dir && !(out = lm_cli_open_out(a, "check"))) {
        lmgi_free(sc);
        return 1;
    }
    lmgi_updater_desc d;
    if (a->as_bake)
        bake_desc(a, sc, &d);
    else
        lm_cli_run_desc(a, sc, &d);
    d.progress = NULL;
    if (!a->width)
        d.frame.width = d.frame.height = 0; /* lmgi_check's picture: the reference's pixels take seconds */
    lmgi_reference_desc rd;
    lm_cli_reference_desc(a, &rd);
    lmgi_context *ctx = NULL;
    lmgi_check_result c;
    lmgi_error err;
    int rc = 0;
    if (lmgi_context_create(NULL, &ctx, &err) != LMGI_OK ||
        lmgi_check(ctx, sc, &d, &rd, a->frames ? a->frames : 1, &c, &err) != LMGI_OK) {
        fprintf(stderr, "lmgi: error: %s\n", err.message);
        rc = 1;
    } else {
        report(sc, &c);
        if (out && !write_images(out, &c))
            rc = 1;
        lmgi_check_free(&c);
    }
    rc = lm_cli_close_out(out, rc);
    lmgi_context_free(ctx);
    lmgi_free(sc);
    return rc;
}
