/* lmgi run: plays the scene's animations through the public updater (include/lmgi.h) and writes
 * DIR/frame_NNNN.png (every K-th also .exr), the final IIM and AIM atlases and DIR/frames.csv.
 * The tone map's exposure is fixed from frame 0 so that the frames do not flicker. */
#include "run_cmd.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "bake_cmd.h"
#include "order_stats.h"
#include "fail.h"
#include "out_dir.h"
#include "page_files.h"
#include "progress.h"
#include "scene_load.h"

#define FRAME_RATE 30.0f /* frames are played at 30 per second of animation time */

typedef struct {
    const lm_cli_args *a;
    lmgi_scene *sc;
    lmgi_context *ctx;
    lmgi_updater *u;
    lmgi_output *out;      /* --out, committed when the run succeeds */
    FILE *csv;
    float exposure;        /* fixed from frame 0 */
    double sum_ms[8];      /* photons, gather, blend, direct, caustics, reflections, composite, total */
    uint64_t caustic_photons, cube_faces, planar_maps; /* over all frames */
    uint64_t photon_gathers, photon_entries;
    int caustic_frames;    /* frames that had caustic photons to draw */
    double *frame_ms;      /* each frame's total, for the median */
    uint32_t texels;
} run_state;

static void gather_progress(void *user, float fraction, const char *stage)
{
    lm_progress_fraction("first full solution", fraction, stage, *(const double *)user);
}

void lm_cli_updater_desc(const lm_cli_args *a, lmgi_updater_desc *d)
{
    *d = a->desc; /* the knobs as the options gave them (0: the defaults) */
    d->photons.seed = a->seed;
    d->caustics.photons = (uint32_t)a->caustic_photons;
    d->frame.width = a->width ? a->width : LM_CLI_FRAME_SIZE;
    d->frame.height = a->width ? a->height : LM_CLI_FRAME_SIZE;
    d->frame.camera = a->camera;
    if (!a->quiet) {
        static double started;
        started = lm_cli_now();
        d->progress = gather_progress;
        d->progress_user = &started;
    }
}

uint32_t lm_cli_run_photons(const lmgi_scene *sc)
{
    uint32_t n = lm_cli_photons_for(lmgi_texel_count(sc), LM_CLI_RUN_PHOTONS_PER_TEXEL);
    return n > LM_CLI_BAKE_PHOTONS_MIN ? n : 0; /* 0: the updater's own default, split among the lights */
}

void lm_cli_run_desc(const lm_cli_args *a, lmgi_scene *sc, lmgi_updater_desc *d)
{
    lm_cli_updater_desc(a, d);
    if (!a->desc.photons.count && !a->desc.photons.per_group)
        d->photons.count = lm_cli_run_photons(sc);
}

/* Every pass's work and milliseconds: the photon work (and its parts), the gather, the blend, the direct
 * light, the caustics (photons traced, tiles queried and lit, pixels filtered, photons landed and of those
 * in the lightmaps), the reflections (cube
 * faces rendered), the per-pixel photon gathers (run, list entries, record pages sent), the composite, a
 * light edit's texel factors (of the photon work or the gather);
 * the texels the update was allowed, the stage that took its longest time and why (its time budget), and the
 * waiting texels whose ray estimates it brought up to date, with their milliseconds (of the gather's). */
static void csv_header(FILE *f)
{
    fprintf(f, "frame,time_s,photons_retraced,groups_invalidated,groups_retraced,aim_surfaces_refreshed,"
               "texels_gathered,caustic_photons_retraced,caustic_tiles,caustic_tiles_lit,caustic_pixels_filtered,"
               "caustic_photons_landed,caustic_photons_thin,"
               "cube_faces_rendered,planar_maps_rendered,photon_gathers,photon_entries,photon_pages_uploaded,"
               "animate_ms,trace_ms,aim_ms,"
               "caustic_trace_ms,photons_ms,gather_ms,blend_ms,direct_ms,caustics_ms,reflections_ms,composite_ms,frame_ms,"
               "light_scale_ms,texels_budget,busiest_stage,why,texels_estimated,estimates_ms\n");
}

/* Flushed row by row: a full disk stops the run at the row it hits, not after the last frame. */
static int csv_row(FILE *f, const lmgi_update_stats *s)
{
    fprintf(f, "%d,%.4f,%u,%u,%u,%d,%u,%u,%d,%d,%llu,%u,%u,%d,%d,%d,%llu,%u,"
               "%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%d,%s,\"%s\",%u,%.3f\n",
            s->frame, (double)s->time, s->photons_retraced, s->groups_invalidated, s->groups_retraced,
            s->aim_surfaces_refreshed, s->texels_gathered, s->caustic_photons_retraced, s->caustic_tiles,
            s->caustic_tiles_lit, (unsigned long long)s->caustic_pixels_filtered, s->caustic_photons_landed,
            s->caustic_photons_thin, s->cube_faces_rendered, s->planar_maps_rendered,
            s->photon_gathers, (unsigned long long)s->photon_entries, s->photon_pages_uploaded, s->ms_animate,
            s->ms_trace, s->ms_aim, s->ms_caustic_trace, s->ms_photons, s->ms_gather, s->ms_blend, s->ms_direct, s->ms_caustics, s->ms_reflections, s->ms_composite, s->ms_total,
            s->ms_light_scale, s->texels_budget, s->busiest_stage, s->why, s->texels_estimated, s->ms_estimates);
    return fflush(f) == 0 && !ferror(f);
}

/* DIR/NAME.exr (linear) and DIR/NAME.png (tone-mapped with exposure k, or automatic when k <= 0). */
static lmgi_status write_pair(const run_state *r, const char *name, int w, int h, int channels, const float *px,
                            float k, int exr, lmgi_error *err)
{
    char file[80];
    snprintf(file, sizeof file, "%s.exr", name);
    if (exr && lm_cli_write_image(r->out, file, w, h, channels, px, NULL, err) != LMGI_OK)
        return err->status;
    snprintf(file, sizeof file, "%s.png", name);
    lmgi_image_desc png = {(lmgi_tonemap)r->a->tonemap, k > 0.0f ? k : 0.0f, 0};
    return lm_cli_write_image(r->out, file, w, h, channels, px, &png, err);
}

static lmgi_status play_frame(run_state *r, int f, int every, lmgi_error *err)
{
    lmgi_update_stats fs;
    if (lmgi_update(r->u, (float)f / FRAME_RATE, r->a->budget_ms, &fs, err) != LMGI_OK)
        return err->status;
    int w, h;
    const float *img = lmgi_frame(r->u, &w, &h);
    lmgi_status st;
    if (f == 0)
        r->exposure = lmgi_auto_exposure((lmgi_tonemap)r->a->tonemap, img, (size_t)w * h);
    char name[64];
    snprintf(name, sizeof name, "frame_%04d", f);
    st = write_pair(r, name, w, h, 3, img, r->exposure, f % every == 0, err);
    if (st == LMGI_OK && !csv_row(r->csv, &fs))
        st = lm_cli_fail(err, LMGI_ERR_IO, "%s/frames.csv: write failed (%s)", r->a->out_dir, strerror(errno));
    const double ms[8] = {fs.ms_photons, fs.ms_gather, fs.ms_blend, fs.ms_direct, fs.ms_caustics, fs.ms_reflections,
                          fs.ms_composite, fs.ms_total};
    for (int i = 0; i < 8; i++)
        r->sum_ms[i] += ms[i];
    r->caustic_photons += fs.caustic_photons_retraced;
    r->caustic_frames += fs.caustic_tiles > 0;
    r->cube_faces += (uint64_t)fs.cube_faces_rendered;
    r->planar_maps += (uint64_t)fs.planar_maps_rendered;
    r->photon_gathers += (uint64_t)fs.photon_gathers;
    r->photon_entries += fs.photon_entries;
    r->frame_ms[f] = fs.ms_total;
    r->texels += fs.texels_gathered;
    return st;
}

/* The IIM's E (invalid texels filled, gutters dilated) and the AIM's radiance, each with validity as alpha
 * (lmgi_get_lightmap): iim.exr/png and aim.exr/png, or those of each page (page_files.h). */
static lmgi_status write_atlases(run_state *r, lmgi_error *err)
{
    lmgi_info in;
    lmgi_get_info(r->sc, &in);
    int w, h;
    lm_cli_page_size(&in, &w, &h);
    size_t n = (size_t)w * h;
    float *rgba = malloc(n * 4 * sizeof *rgba);
    lmgi_status st = rgba ? LMGI_OK : lm_cli_fail(err, LMGI_ERR_NOMEM, "no memory for the atlases");
    static const char *const names[2] = {"iim", "aim"};
    static const lmgi_lightmap kinds[2] = {LMGI_LIGHTMAP_IIM, LMGI_LIGHTMAP_AIM};
    for (int p = 0; p < in.pages && st == LMGI_OK; p++)
        for (int k = 0; k < 2 && st == LMGI_OK; k++) {
            char name[32];
            lm_cli_page_file(name, sizeof name, names[k], in.pages, p, "");
            st = lm_cli_get_page(r->u, &in, kinds[k], p, rgba, n * 4, err);
            if (st == LMGI_OK)
                st = write_pair(r, name, w, h, 4, rgba, 0.0f, 1, err);
        }
    free(rgba);
    return st;
}

/* What the scene calls for and why, with what this run left out (--effects). */
static void print_effects(const run_state *r)
{
    static const struct { const char *name; unsigned bit; } run_off[4] = {
        {"shadows", LMGI_EFFECT_SHADOWS}, {"indirect", LMGI_EFFECT_INDIRECT}, {"reflections", LMGI_EFFECT_REFLECTIONS},
        {"caustics", LMGI_EFFECT_CAUSTICS}};
    for (int i = 0; i < lmgi_effect_count(r->sc); i++) {
        lmgi_effect e;
        lmgi_get_effect(r->sc, i, &e);
        int off = 0;
        for (int k = 0; k < 4; k++)
            off |= !strcmp(e.name, run_off[k].name) && (r->a->desc.effects_off & run_off[k].bit);
        printf("%-11s %s: %s\n", i ? "" : "effects", e.name, off ? "off (left out by --effects)" : e.on ? "on" : "off");
        if (!off)
            printf("%-11s   %s\n", "", e.reason);
    }
}

/* The last frame's caustic irradiance (lmgi_get_caustics), when the run drew caustics: caustics.exr and
 * caustics.png (its own exposure). */
static lmgi_status write_caustics(run_state *r, lmgi_error *err)
{
    if (!r->caustic_frames)
        return LMGI_OK;
    int w, h;
    lmgi_frame(r->u, &w, &h);
    size_t n = 3 * (size_t)w * (size_t)h;
    float *rgb = malloc((n ? n : 1) * sizeof *rgb);
    lmgi_status st = rgb ? lmgi_get_caustics(r->u, rgb, n, NULL, NULL, err)
                         : lm_cli_fail(err, LMGI_ERR_NOMEM, "no memory for the caustics");
    if (st == LMGI_OK)
        st = write_pair(r, "caustics", w, h, 3, rgb, 0.0f, 1, err);
    free(rgb);
    return st;
}

/* The --aim-direct name of a resolved value. */
static const char *aim_direct_name(lmgi_aim_direct v)
{
#define AIM_DIRECT_NAME(name, value) v == value ? name:
    return LMGI_AIM_DIRECT_CHOICES(AIM_DIRECT_NAME) "?";
#undef AIM_DIRECT_NAME
}

static void summary(const run_state *r, int frames)
{
    const double *s = r->sum_ms;
    lmgi_updater_info ui;
    lmgi_get_updater_info(r->u, &ui);
    printf("gl          %s\n", lmgi_context_gl_description(r->ctx));
    print_effects(r);
    int lightmap = !strcmp(ui.indirect, "lightmap");
    if (lightmap) { /* the hemicube gather's settings; the photon paths have none */
        printf("gather      R %d, a %g, %d AIM lookup%s and %d coverage sample%s per pixel, %s scheme; ",
               ui.gather.resolution, (double)ui.gather.enlargement, ui.gather.samples,
               ui.gather.samples > 1 ? "s" : "", ui.gather.coverage, ui.gather.coverage > 1 ? "s" : "",
               ui.gather_scheme);
        if (!ui.emissive_triangles)
            printf("no emissive triangles\n");
        else if (ui.emitters_closed_form)
            printf("%u emissive triangles in closed form (%d shadow rays each)\n", ui.emissive_triangles,
                   ui.gather.emitter_rays);
        else
            printf("%u emissive triangles drawn\n", ui.emissive_triangles);
        printf("aims        N %d, direct light: %s (--aim-direct)\n", ui.aim.nearest, aim_direct_name(ui.aim.direct));
    }
    lmgi_info in;
    lmgi_get_info(r->sc, &in);
    int per_frame = ui.gather.texels_per_frame;
    if (!lightmap)
        printf("indirect    %s photon gather per pixel: radius %.4g, tile %d, chunk %d, k %d; %llu gathers, "
               "%llu list entries\n", ui.indirect, (double)ui.tiled.radius, ui.tiled.tile, ui.tiled.chunk,
               ui.tiled.stochastic, (unsigned long long)r->photon_gathers, (unsigned long long)r->photon_entries);
    char atlas[96];
    lm_cli_atlas_size(atlas, sizeof atlas, &in);
    printf("atlas       %s, %u texels of %.4g units: regathered in full every %u frames at %d a frame\n", atlas,
           in.texels, (double)in.texel_size, (in.texels + (uint32_t)per_frame - 1) / (uint32_t)per_frame, per_frame);
    printf("setup       full trace %.1f ms, all AIMs %.1f ms, full gather %.1f ms\n", ui.ms_setup_trace,
           ui.ms_setup_aim, ui.ms_setup_gather);
    printf("frames      %d, %u texels gathered, exposure %.4g (from frame 0)\n", frames, r->texels,
           (double)r->exposure);
    printf("mean frame  %.2f ms (%.1f fps): photons %.2f, gather %.2f, blend %.2f, direct %.2f, caustics %.2f, "
           "reflections %.2f, composite %.2f\n", s[7] / frames, s[7] > 0 ? 1e3 * frames / s[7] : 0.0, s[0] / frames,
           s[1] / frames, s[2] / frames, s[3] / frames, s[4] / frames, s[5] / frames, s[6] / frames);
    printf("work        %llu caustic photons traced, %llu environment map faces rendered, %llu flat reflectors' "
           "pictures drawn\n", (unsigned long long)r->caustic_photons, (unsigned long long)r->cube_faces,
           (unsigned long long)r->planar_maps);
    double median = lm_cli_median(r->frame_ms, frames);
    printf("median      %.2f ms (%.1f fps; the mean includes frame 0, which uploads everything)\n", median,
           median > 0.0 ? 1e3 / median : 0.0);
    char iim[48], aim[48];
    lm_cli_page_files(iim, sizeof iim, "iim", in.pages, ".exr/png");
    lm_cli_page_files(aim, sizeof aim, "aim", in.pages, ".exr/png");
    printf("wrote       %s/frame_*.png (.exr every %d), %s, %s, %sframes.csv\n", r->a->out_dir,
           r->a->exr_every ? r->a->exr_every : 10, iim, aim,
           r->caustic_frames ? "caustics.exr/png (the last frame's), " : "");
}

static lmgi_status play(run_state *r, lmgi_error *err)
{
    int frames = r->a->frames ? r->a->frames : 60, every = r->a->exr_every ? r->a->exr_every : 10;
    r->frame_ms = malloc(sizeof *r->frame_ms * (size_t)frames);
    if (!r->frame_ms)
        return lm_cli_fail(err, LMGI_ERR_NOMEM, "no memory for %d frame times", frames);
    lmgi_status st = LMGI_OK;
    csv_header(r->csv);
    for (int f = 0; f < frames && st == LMGI_OK; f++) {
        st = play_frame(r, f, every, err);
        if (!r->a->quiet)
            lm_progress("run", f + 1, frames);
    }
    return st;
}

/* Files are created only once the frame loop exists: a run refused for its settings writes nothing. */
static lmgi_status open_outputs(run_state *r, lmgi_error *err)
{
    char path[4200];
    lmgi_status st = lmgi_output_file(r->out, "frames.csv", path, sizeof path, err);
    if (st == LMGI_OK)
        r->csv = fopen(path, "wx"); /* created, never opened through what is there */
    return st != LMGI_OK || r->csv ? st : lm_cli_fail(err, LMGI_ERR_IO, "%s: cannot write (%s)", path, strerror(errno));
}

static lmgi_status run(run_state *r, lmgi_error *err)
{
    lmgi_updater_desc desc;
    lm_cli_run_desc(r->a, r->sc, &desc);
    lmgi_status st = lmgi_context_create(NULL, &r->ctx, err);
    if (st == LMGI_OK)
        st = lmgi_updater_create(r->ctx, r->sc, &desc, &r->u, err);
    if (st == LMGI_OK)
        st = open_outputs(r, err);
    if (st == LMGI_OK)
        st = play(r, err);
    if (r->csv && fclose(r->csv) != 0 && st == LMGI_OK)
        st = lm_cli_fail(err, LMGI_ERR_IO, "%s/frames.csv: write failed", r->a->out_dir);
    r->csv = NULL;
    if (st == LMGI_OK)
        st = write_atlases(r, err);
    if (st == LMGI_OK)
        st = write_caustics(r, err);
    return st;
}

int lm_cli_run_load(const lm_cli_args *a, lmgi_scene **sc)
{
    lmgi_options o = a->options;
    lm_cli_run_options(&o, a->desc.gather.texels_per_frame);
    return lm_cli_load_scene(a->files[0], &o, 1, sc);
}

int lm_cli_run(const lm_cli_args *a)
{
    if (a->file_count != 1 || !a->out_dir) {
        fprintf(stderr, "lmgi: run needs one scene file and --out DIR\n");
        return 2;
    }
    run_state r;
    memset(&r, 0, sizeof r);
    r.a = a;
    if (!lm_cli_run_load(a, &r.sc))
        return 1;
    /* the output directory, opened before the long setup, so a bad path fails at once; the earlier run's
     * files stay until this one has succeeded */
    r.out = lm_cli_open_out(a, "run");
    lmgi_error err;
    lmgi_status st = r.out ? run(&r, &err) : LMGI_ERR_IO;
    if (st != LMGI_OK && r.out)
        fprintf(stderr, "lmgi: error: %s\n", err.message);
    if (r.out && lm_cli_close_out(r.out, st != LMGI_OK) != 0)
        st = LMGI_ERR_IO;
    if (st == LMGI_OK && !a->quiet)
        summary(&r, a->frames ? a->frames : 60);
    lmgi_updater_free(r.u);
    lmgi_context_free(r.ctx);
    free(r.frame_ms);
    lmgi_free(r.sc);
    return st == LMGI_OK ? 0 : 1;
}
