/* lmgi bake: through the public API only. */
#include "bake_cmd.h"

#include <lmgi_tools.h>
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "merge_cmd.h"
#include "order_stats.h"
#include "out_dir.h"
#include "page_files.h"
#include "progress.h"
#include "run_cmd.h"
#include "scene_load.h"

static volatile sig_atomic_t g_interrupted;
static volatile int g_cancel; /* what the library polls; set from the signal handler */

static void on_interrupt(int sig)
{
    (void)sig;
    g_interrupted = 1;
    g_cancel = 1;
}

/* Ctrl-C while the scene loads: loading polls no cancel (a level's can take seconds), and no lightmap has
 * been written, so the command says so and leaves at once, with write and _exit alone (what a handler may
 * call). Without it the signal's default killed the command without a word. */
static char g_loading_said[160];
static size_t g_loading_len;

static void on_interrupt_loading(int sig)
{
    (void)sig;
    ssize_t written = write(STDERR_FILENO, g_loading_said, g_loading_len);
    (void)written;
    _exit(130);
}

static void interrupts_as(void (*handler)(int))
{
    signal(SIGINT, handler);
    signal(SIGTERM, handler); /* a scheduler's stop, as Ctrl-C */
}

static void show(void *user, float fraction, const char *stage)
{
    lm_progress_fraction("bake", fraction, stage, *(const double *)user);
}

/* The files of a bake: lightmap.exr, lightmap.png and aim.exr, or those of each page (page_files.h). */
static const char *const g_maps[3][2] = {{"lightmap", ".exr"}, {"lightmap", ".png"}, {"aim", ".exr"}};

static int write_maps(lmgi_scene *sc, lmgi_updater *u, lmgi_output *dir, int half)
{
    const lmgi_image_desc exr = {.half = half};
    lmgi_info in;
    lmgi_get_info(sc, &in);
    int w, h;
    lm_cli_page_size(&in, &w, &h);
    size_t n = 4 * (size_t)w * h;
    float *rgba = malloc(n * sizeof *rgba);
    lmgi_error e;
    int rc = 0;
    if (!rgba)
        rc = 1, fprintf(stderr, "lmgi: error: no memory for the %d x %d lightmap\n", w, h);
    for (int p = 0; p < in.pages && rc == 0; p++)
        for (int k = 0; k < 3 && rc == 0; k++) {
            lmgi_lightmap kind = k < 2 ? LMGI_LIGHTMAP_IIM : LMGI_LIGHTMAP_AIM;
            char file[64];
            lm_cli_page_file(file, sizeof file, g_maps[k][0], in.pages, p, g_maps[k][1]);
            if ((k != 1 && lm_cli_get_page(u, &in, kind, p, rgba, n, &e) != LMGI_OK) ||
                lm_cli_write_image(dir, file, w, h, 4, rgba, &exr, &e))
                rc = 1, fprintf(stderr, "lmgi: error: %s\n", e.message);
        }
    free(rgba);
    return rc;
}

/* The picture of the lightmap's estimated error: 0 dark blue, ACCURACY_SCALE / 2 red, ACCURACY_SCALE and
 * over yellow; black where the texel is invalid or unlit. */
#define ACCURACY_SCALE 0.1f
static void heat(float v, float rgb[3])
{
    static const float stops[3][3] = {{0.0f, 0.0f, 0.3f}, {0.9f, 0.1f, 0.1f}, {1.0f, 1.0f, 0.2f}};
    float x = fminf(fmaxf(v / ACCURACY_SCALE, 0.0f), 1.0f) * 2.0f;
    int k = x < 1.0f ? 0 : 1;
    float f = x - (float)k;
    for (int c = 0; c < 3; c++)
        rgb[c] = (1.0f - f) * stops[k][c] + f * stops[k + 1][c];
}

/* --accuracy: DIR/accuracy.exr (LMGI_LIGHTMAP_ACCURACY), accuracy.png (its lightmap channel as a heat map)
 * and the estimate's median and 95th percentile over the valid texels that receive indirect light,
 * printed. */
static int write_accuracy(lmgi_scene *sc, lmgi_updater *u, lmgi_output *dir, int half, int quiet)
{
    const lmgi_image_desc exr = {.half = half};
    lmgi_info in;
    lmgi_get_info(sc, &in);
    size_t n = (size_t)in.atlas_width * in.atlas_height;
    float *rgba = malloc(4 * n * sizeof *rgba), *lit = malloc(4 * n * sizeof *lit);
    double *iim = malloc(n * sizeof *iim), *aim = malloc(n * sizeof *aim);
    lmgi_error e;
    int rc = 0;
    double started = lm_cli_now();
    if (!rgba || !lit || !iim || !aim)
        rc = 1, fprintf(stderr, "lmgi: error: no memory for the %d x %d accuracy map\n", in.atlas_width,
                        in.atlas_height);
    else if (lmgi_get_lightmap(u, LMGI_LIGHTMAP_ACCURACY, rgba, 4 * n, &e) != LMGI_OK)
        rc = 1, fprintf(stderr, "lmgi: error: %s\n", e.message);
    double seconds = lm_cli_now() - started;
    if (rc == 0 && (lmgi_get_lightmap(u, LMGI_LIGHTMAP_IIM, lit, 4 * n, &e) != LMGI_OK ||
                    lm_cli_write_image(dir, "accuracy.exr", in.atlas_width, in.atlas_height, 4, rgba, &exr, &e)))
        rc = 1, fprintf(stderr, "lmgi: error: %s\n", e.message);
    size_t m = 0;
    for (uint32_t t = 0; rc == 0 && t < in.texels; t++) {
        lmgi_texel tx;
        lmgi_get_texel(sc, t, &tx);
        size_t at = 4 * ((size_t)tx.y * in.atlas_width + tx.x);
        if (rgba[at + 3] > 0.5f && lit[at] + lit[at + 1] + lit[at + 2] > 0.0f)
            iim[m] = rgba[at], aim[m++] = rgba[at + 1];
    }
    if (rc == 0) { /* the picture, in the IIM read's buffer: black but where a lit texel is */
        for (size_t i = 0; i < n; i++) {
            int shown = rgba[4 * i + 3] > 0.5f && lit[4 * i] + lit[4 * i + 1] + lit[4 * i + 2] > 0.0f;
            if (shown)
                heat(rgba[4 * i], lit + 3 * i);
            else
                lit[3 * i] = lit[3 * i + 1] = lit[3 * i + 2] = 0.0f;
        }
        const lmgi_image_desc png = {LMGI_TONEMAP_CLAMP, 1.0f, 0};
        if (lm_cli_write_image(dir, "accuracy.png", in.atlas_width, in.atlas_height, 3, lit, &png, &e))
            rc = 1, fprintf(stderr, "lmgi: error: %s\n", e.message);
    }
    if (rc == 0 && m && !quiet) {
        double median = lm_cli_median(iim, (int)m), p95 = lm_cli_quantile(iim, (int)m, 0.95);
        printf("accuracy    estimated relative standard error over %zu lit texels: lightmap median %.3f, 95th "
               "percentile %.3f; AIM median %.3f (photon noise only: docs/gather.md, \"Error estimate\"; %.1f s)\n",
               m, median, p95, lm_cli_median(aim, (int)m), seconds);
    }
    free(rgba);
    free(lit);
    free(iim);
    free(aim);
    return rc;
}

/* DIR/NAME.gltf and its lightmap, NAME the scene file's name without its extension (other characters
 * than a-z A-Z 0-9 - _ made '_'). */
static int write_gltf(const lm_cli_args *a, lmgi_updater *u, lmgi_output *out, char *name, size_t size)
{
    const char *base = strrchr(a->files[0], '/');
    snprintf(name, size, "%s", base ? base + 1 : a->files[0]);
    char *dot = strrchr(name, '.');
    if (dot && dot != name)
        *dot = '\0';
    for (char *c = name; *c; c++)
        if (!isalnum((unsigned char)*c) && *c != '-' && *c != '_')
            *c = '_';
    lmgi_export_desc d = {.name = name, .half = a->half, .output = out};
    lmgi_error e;
    if (lmgi_export_gltf(u, a->out_dir, &d, &e) == LMGI_OK)
        return 0;
    fprintf(stderr, "lmgi: error: %s\n", e.message);
    return 1;
}

/* The scene loads before --out is touched, and the earlier bake stays until this one has succeeded
 * (lmgi_output_commit): a mistyped scene, a cancel or a kill leaves the last good lightmaps. What the
 * gather finished survives a cancel, a kill or a failure in DIR/bake.checkpoint (docs/levels.md, "Long
 * bakes"), which the commit removes. A shard's bake writes DIR/part.checkpoint and part.json alone. */
static lmgi_output *open_out(const lm_cli_args *a, const char *command, int pages, char *checkpoint,
                             size_t size)
{
    lmgi_output *out = lm_cli_open_out(a, command);
    char probe[4200];
    lmgi_error e;
    static const char *const part[] = {"part.checkpoint", "part.json", NULL};
    for (const char *const *f = part; a->shards && out && *f; f++)
        if (!lm_cli_out_path(out, *f, probe, sizeof probe))
            return lm_cli_close_out(out, 1), NULL;
    for (int p = 0; !a->shards && out && p < pages; p++) /* each page's lightmap.exr and .png */
        for (int k = 0; k < 2; k++) {
            char file[64];
            lm_cli_page_file(file, sizeof file, g_maps[k][0], pages, p, g_maps[k][1]);
            if (!lm_cli_out_path(out, file, probe, sizeof probe))
                return lm_cli_close_out(out, 1), NULL;
        }
    if (out && lmgi_output_work_file(out, "bake.checkpoint", checkpoint, size, &e) != LMGI_OK) {
        fprintf(stderr, "lmgi: error: %s\n", e.message);
        return lm_cli_close_out(out, 1), NULL;
    }
    return out;
}

/* A shard's part: the checkpoint its gather finished, moved into the result as part.checkpoint. */
static int keep_part(lmgi_output *out, const char *checkpoint)
{
    char part[4200];
    if (!lm_cli_out_path(out, "part.checkpoint", part, sizeof part))
        return 1;
    if (rename(checkpoint, part) != 0) {
        fprintf(stderr, "lmgi: error: cannot move %s to %s: %s\n", checkpoint, part, strerror(errno));
        return 1;
    }
    return 0;
}

static void report(const lm_cli_args *a, lmgi_scene *sc, lmgi_updater *u, double started, const char *name)
{
    lmgi_info in;
    lmgi_updater_info ui;
    lmgi_get_info(sc, &in);
    lmgi_get_updater_info(u, &ui);
    char what[64];
    if (a->shards)
        snprintf(what, sizeof what, "baked       share %d of %d of", a->shard, a->shards);
    else
        snprintf(what, sizeof what, "%s     ", a->file_count > 1 ? "merged" : "baked ");
    char atlas[96], exr[320], png[64], aim[64];
    lm_cli_atlas_size(atlas, sizeof atlas, &in);
    printf("%s %u texels (%s%s) from %u photons in %.1f s (trace %.0f ms, AIMs %.0f ms, gather %.0f ms)\n", what,
           in.texels, atlas, in.pages > 1 ? "" : " atlas", ui.stored_photons, lm_cli_now() - started, ui.ms_setup_trace, ui.ms_setup_aim,
           ui.ms_setup_gather);
    if (ui.portals_found)
        printf("portals     %d found where the sun's or the sky's light gets in (docs/levels.md, \"Portals\")\n",
               ui.portals_found);
    lm_cli_page_files(exr, sizeof exr, "lightmap", in.pages, ".exr");
    lm_cli_page_files(png, sizeof png, "lightmap", in.pages, ".png");
    lm_cli_page_files(aim, sizeof aim, "aim", in.pages, ".exr");
    if (a->shards)
        printf("wrote       %s/part.checkpoint (lmgi merge puts the parts together)\n", a->out_dir);
    else
        printf("wrote       %s/%s (irradiance, alpha = valid%s), %s, %s\n", a->out_dir, exr,
               in.pages > 1 ? ", a file a page" : "", png, aim);
    if (a->gltf) {
        char base[300];
        snprintf(base, sizeof base, "%s_lightmap", name);
        lm_cli_page_files(exr, sizeof exr, base, in.pages, ".exr");
        printf("            %s/%s.gltf (TEXCOORD_1: the lightmap's UVs) with %s and .png\n", a->out_dir, name, exr);
    }
}

/* bake (parts NULL) and merge (the parts' checkpoint files): the updater's first full solution, then the
 * lightmaps, or a shard's part. */
static int bake(const lm_cli_args *a, const char *command, const char *const *parts, int part_count,
                const lm_cli_share *share, lm_cli_bake_times *times)
{
    lmgi_scene *sc = NULL;
    lmgi_options o = a->options; /* a bake's density: lmgi_options' own default, not run's */
    snprintf(g_loading_said, sizeof g_loading_said,
             "\nlmgi: %s cancelled while loading the scene; no lightmap written (an earlier bake's kept)\n", command);
    g_loading_len = strlen(g_loading_said);
    interrupts_as(on_interrupt_loading);
    int loaded = lm_cli_load_scene(a->files[0], &o, 1, &sc);
    /* from here a stop is polled: the output folder's files are never left half written */
    interrupts_as(loaded ? on_interrupt : SIG_DFL);
    if (!loaded)
        return 1;
    char checkpoint[4200];
    lmgi_info in;
    lmgi_get_info(sc, &in);
    lmgi_output *out = open_out(a, command, in.pages, checkpoint, sizeof checkpoint);
    if (!out) {
        interrupts_as(SIG_DFL);
        lmgi_free(sc);
        return 1;
    }
    lmgi_updater_desc d;
    lm_cli_updater_desc(a, &d);
    lm_cli_bake_solution(&in, parts || !a->shards, &d);
    d.frame.width = d.frame.height = 0;
    d.aim.error_estimate = a->accuracy ? LMGI_ON : 0;
    double started = lm_cli_now();
    d.progress = a->quiet && !(share && share->progress) ? NULL : show;
    d.progress_user = &started;
    d.cancel = &g_cancel;
    if (parts) {
        d.parts = parts;
        d.part_count = part_count;
    } else {
        d.checkpoint = checkpoint;
        d.checkpoint_seconds = a->checkpoint_seconds;
        d.resume = a->resume;
        d.shard = a->shards ? a->shard - 1 : 0;
        d.shards = a->shards;
        if (share)
            d.photon_exchange = share->photon_exchange, d.claim_pass = share->claim_pass, d.share_user = share->user;
    }
    lmgi_context *ctx = NULL;
    lmgi_updater *u = NULL;
    lmgi_error e;
    int rc = 0;
    if (lmgi_context_create(NULL, &ctx, &e) != LMGI_OK || lmgi_updater_create(ctx, sc, &d, &u, &e) != LMGI_OK) {
        if (e.status == LMGI_ERR_CANCELLED)
            fprintf(stderr, "\nlmgi: %s cancelled after %.1f s (%s); no lightmap written (an earlier bake's kept)%s\n",
                    command, lm_cli_now() - started, e.message,
                    parts || share ? "" : "; the same command with --resume continues it"); /* merge, MPI: none */
        else
            fprintf(stderr, "lmgi: error: %s\n", e.message);
        rc = e.status == LMGI_ERR_CANCELLED ? 130 : 1;
    }
    interrupts_as(SIG_DFL);
    char name[256] = "";
    if (rc == 0 && a->shards) {
        rc = keep_part(out, checkpoint);
        if (rc == 0)
            rc = lm_cli_write_part_json(out, a);
    } else {
        if (rc == 0)
            rc = write_maps(sc, u, out, a->half);
        if (rc == 0 && a->accuracy)
            rc = write_accuracy(sc, u, out, a->half, a->quiet);
        if (rc == 0 && a->gltf)
            rc = write_gltf(a, u, out, name, sizeof name);
    }
    rc = lm_cli_close_out(out, rc);
    if (rc == 0 && !a->quiet)
        report(a, sc, u, started, name);
    if (times) {
        lmgi_updater_info ui;
        lmgi_get_updater_info(u, &ui);
        *times = (lm_cli_bake_times){lm_cli_now() - started, ui.ms_setup_trace, ui.ms_setup_aim, ui.ms_setup_gather};
    }
    lmgi_updater_free(u);
    lmgi_free(sc);
    lmgi_context_free(ctx);
    return rc;
}

int lm_cli_bake(const lm_cli_args *a) { return lm_cli_bake_shared(a, NULL, NULL); }

int lm_cli_bake_shared(const lm_cli_args *a, const lm_cli_share *share, lm_cli_bake_times *t)
{
    if (a->file_count != 1 || !a->out_dir) {
        fprintf(stderr, "lmgi: bake needs one scene file and --out DIR\n");
        return 2;
    }
    if (a->shards && (a->gltf || a->accuracy || a->half)) {
        fprintf(stderr, "lmgi: bake --shard writes its part alone; give --gltf, --accuracy and --half to lmgi merge\n");
        return 2;
    }
    return bake(a, "bake", NULL, 0, share, t);
}

int lm_cli_bake_merge(const lm_cli_args *a, const char *const *parts, int part_count)
{
    return bake(a, "merge", parts, part_count, NULL, NULL);
}
