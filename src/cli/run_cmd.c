/* lmgi run: plays the scene's animations through the whole frame loop (update/frame_loop.h) and writes
 * DIR/frame_NNNN.png (every K-th also .exr), the final IIM and AIM atlases and DIR/frames.csv.
 * The tone map's exposure is fixed from frame 0 so that the frames do not flicker. */
#include "run_cmd.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../charts/atlas_dilate.h"
#include "../core/image.h"
#include "../core/stats.h"
#include "../core/tonemap.h"
#include "../update/frame_loop.h"
#include "../update/lmgi_scene.h"
#include "out_dir.h"
#include "photons_cmd.h"
#include "progress.h"
#include "scene_load.h"

#define FRAME_RATE 30.0f /* frames are played at 30 per second of animation time */

typedef struct {
    const lm_cli_args *a;
    lmgi_scene *sc;
    lm_frame_loop *loop;
    FILE *csv;
    float exposure;        /* fixed from frame 0 */
    uint8_t *png;          /* scratch, frame-sized RGBA8 */
    double sum_ms[6];      /* photons, gather, blend, direct, composite, total */
    double *frame_ms;      /* each frame's total, for the median */
    uint32_t texels;
} run_state;

static void gather_progress(void *user, uint32_t done, uint32_t total)
{
    (void)user;
    lm_progress("first full gather", (int)done, (int)total);
}

void lm_cli_run_settings(const lm_cli_args *a, lm_frame_loop_settings *s)
{
    lm_frame_loop_settings_default(s);
    lm_cli_photon_settings(a, &s->stage);
    if (a->texels_per_frame)
        s->iim.texels_per_frame = a->texels_per_frame;
    if (a->hemicube)
        s->gather.resolution = a->hemicube;
    if (!a->quiet)
        s->progress = gather_progress;
    if (a->hemicube_samples)
        s->gather.samples = a->hemicube_samples;
    if (a->enlargement > 0.0f)
        s->gather.enlargement = a->enlargement;
    if (a->rim_samples >= 0)
        s->gather.rim_samples = a->rim_samples;
    if (a->reflection_size >= 0)
        s->reflection_size = a->reflection_size;
    if (a->reflection_faces > 0)
        s->reflection_faces = a->reflection_faces;
    if (a->gather_scheme >= 0)
        s->gather.scheme = (lm_gather_scheme)a->gather_scheme;
    s->emitter_light = a->emitter_light;
    s->overlap = !a->in_order;
    if (a->emitter_rays)
        s->emitter_rays = a->emitter_rays;
    if (a->hemicube_coverage)
        s->gather.coverage_samples = a->hemicube_coverage; /* else chosen per scene by the frame loop */
    if (a->width) {
        s->width = a->width;
        s->height = a->height;
    }
    s->camera = a->camera;
}

static void csv_header(FILE *f)
{
    fprintf(f, "frame,time_s,photons_retraced,groups_invalidated,groups_retraced,aim_surfaces_refreshed,"
               "texels_gathered,animate_ms,trace_ms,aim_ms,photons_ms,gather_ms,blend_ms,direct_ms,composite_ms,"
               "frame_ms\n");
}

/* Flushed row by row: a full disk stops the run at the row it hits, not after the last frame. */
static int csv_row(FILE *f, const lm_frame_stats *r)
{
    const lm_photon_stage_frame *s = &r->stage;
    fprintf(f, "%d,%.4f,%u,%u,%u,%d,%u,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f\n", s->frame, (double)s->time,
            s->photons.rr_photons + s->photons.group_photons, s->photons.groups_invalidated,
            s->photons.groups_retraced, s->aim.surfaces_refreshed, r->texels_gathered, 1e3 * s->t_animate,
            1e3 * s->t_photons, 1e3 * s->t_aim, 1e3 * r->t_photons, 1e3 * r->t_gather, 1e3 * r->t_blend,
            1e3 * r->t_direct, 1e3 * r->t_composite, 1e3 * r->t_total);
    return fflush(f) == 0 && !ferror(f);
}

/* DIR/NAME.exr (linear) and DIR/NAME.png (tone-mapped with exposure k, or automatic when k <= 0). */
static lm_status write_pair(const char *dir, const char *name, int w, int h, const float *rgb, float k, int exr,
                            uint8_t *png, lm_error *err)
{
    char path[4096];
    lm_status st = LM_OK;
    if (exr) {
        snprintf(path, sizeof path, "%s/%s.exr", dir, name);
        st = lm_write_exr(path, w, h, 3, rgb, err);
    }
    size_t n = (size_t)w * h;
    lm_tonemap_srgb8(rgb, n, 3, k > 0.0f ? k : lm_auto_exposure(rgb, n, 3), png);
    snprintf(path, sizeof path, "%s/%s.png", dir, name);
    return st == LM_OK ? lm_write_png(path, w, h, png, err) : st;
}

static lm_status play_frame(run_state *r, int f, int every, lm_error *err)
{
    lm_frame_stats fs;
    lm_status st = lm_frame_loop_step(r->loop, (float)f / FRAME_RATE, &fs, err);
    if (st != LM_OK)
        return st;
    const float *img = lm_frame_loop_image(r->loop);
    int w = lm_frame_loop_get_settings(r->loop)->width, h = lm_frame_loop_get_settings(r->loop)->height;
    if (f == 0)
        r->exposure = lm_auto_exposure(img, (size_t)w * h, 3);
    char name[64];
    snprintf(name, sizeof name, "frame_%04d", f);
    st = write_pair(r->a->out_dir, name, w, h, img, r->exposure, f % every == 0, r->png, err);
    if (st == LM_OK && !csv_row(r->csv, &fs))
        st = lm_fail(err, LM_ERR_IO, "%s/frames.csv: write failed (%s)", r->a->out_dir, strerror(errno));
    const double ms[6] = {fs.t_photons, fs.t_gather, fs.t_blend, fs.t_direct, fs.t_composite, fs.t_total};
    for (int i = 0; i < 6; i++)
        r->sum_ms[i] += 1e3 * ms[i];
    r->frame_ms[f] = 1e3 * fs.t_total;
    r->texels += fs.texels_gathered;
    return st;
}

/* Each IIM texel's E (invalid ones filled, gutters dilated) and each AIM texel's radiance. */
static lm_status write_atlases(run_state *r, lm_error *err)
{
    const lm_atlas *at = &r->sc->atlas;
    size_t n = (size_t)at->width * at->height;
    float *rgba = NULL, *rgb = malloc(n * 3 * sizeof *rgb);
    uint8_t *png = malloc(n * 4);
    lm_status st = rgb && png ? lm_frame_loop_read_iim(r->loop, &rgba, err)
                              : lm_fail(err, LM_ERR_NOMEM, "no memory for the atlases");
    if (st == LM_OK) {
        /* alpha: 1 on valid texels, 0 on invalid ones (inside or under geometry: filled from their
         * neighbours so that bilinear filtering stays smooth, but not light anyone sees) and gutters */
        float limit = lm_frame_loop_get_settings(r->loop)->gather.backface_limit;
        uint8_t *valid = png; /* scratch until the pictures are written */
        for (size_t i = 0; i < n; i++)
            valid[i] = at->texel_index[i] >= 0 && !(rgba[4 * i + 3] > limit);
        lm_iim_fill_invalid(at, rgba, limit);
        for (size_t i = 0; i < n; i++) {
            memcpy(rgb + 3 * i, rgba + 4 * i, 3 * sizeof *rgb);
            rgba[4 * i + 3] = valid[i];
        }
        char path[4096];
        snprintf(path, sizeof path, "%s/iim.exr", r->a->out_dir);
        st = lm_write_exr(path, at->width, at->height, 4, rgba, err);
        if (st == LM_OK)
            st = write_pair(r->a->out_dir, "iim", at->width, at->height, rgb, 0.0f, 0, png, err);
    }
    if (st == LM_OK) { /* the AIM with the IIM's validity as alpha: its texels under geometry hold only
                        * the N-nearest estimate's spill from around them */
        memcpy(rgb, lm_aim_rgb(lm_photon_stage_aim(lm_frame_loop_stage(r->loop))), n * 3 * sizeof *rgb);
        lm_atlas_dilate_gutters(at, rgb, 3);
        for (size_t i = 0; i < n; i++)
            memcpy(rgba + 4 * i, rgb + 3 * i, 3 * sizeof *rgb);
        char path[4096];
        snprintf(path, sizeof path, "%s/aim.exr", r->a->out_dir);
        st = lm_write_exr(path, at->width, at->height, 4, rgba, err);
        if (st == LM_OK)
            st = write_pair(r->a->out_dir, "aim", at->width, at->height, rgb, 0.0f, 0, png, err);
    }
    free(rgba);
    free(rgb);
    free(png);
    return st;
}

static void summary(const run_state *r, int frames, const lm_photon_stage_frame *setup, double t_gather)
{
    const double *s = r->sum_ms;
    printf("gl          %s\n", lm_frame_loop_gl_description(r->loop));
    const lm_frame_loop_settings *fs = lm_frame_loop_get_settings(r->loop);
    uint32_t emissive = lm_emissive_triangle_count(r->sc->scene);
    printf("gather      R %d, a %g, %d AIM lookup%s and %d coverage sample%s per pixel, %s scheme; ",
           fs->gather.resolution, (double)fs->gather.enlargement, fs->gather.samples, fs->gather.samples > 1 ? "s" : "",
           fs->gather.coverage_samples, fs->gather.coverage_samples > 1 ? "s" : "", lm_gather_scheme_name(fs->gather.scheme));
    if (!emissive)
        printf("no emissive triangles\n");
    else if (fs->emitter_light)
        printf("%u emissive triangles in closed form (%d shadow rays each)\n", emissive, fs->emitter_rays);
    else
        printf("%u emissive triangles drawn\n", emissive);
    const lm_atlas *at = &r->sc->atlas;
    int per_frame = fs->iim.texels_per_frame;
    printf("atlas       %d x %d, %u texels of %.4g units: regathered in full every %u frames at %d a frame\n",
           at->width, at->height, at->texel_count, (double)at->texel_size,
           (at->texel_count + (uint32_t)per_frame - 1) / (uint32_t)per_frame, per_frame);
    printf("setup       full trace %.1f ms, all AIMs %.1f ms, full gather %.1f ms\n", 1e3 * setup->t_photons,
           1e3 * setup->t_aim, 1e3 * t_gather);
    printf("frames      %d, %u texels gathered, exposure %.4g (from frame 0)\n", frames, r->texels,
           (double)r->exposure);
    printf("mean frame  %.2f ms (%.1f fps): photons %.2f, gather %.2f, blend %.2f, direct %.2f, composite %.2f\n",
           s[5] / frames, s[5] > 0 ? 1e3 * frames / s[5] : 0.0, s[0] / frames, s[1] / frames, s[2] / frames,
           s[3] / frames, s[4] / frames);
    double median = lm_median(r->frame_ms, frames);
    printf("median      %.2f ms (%.1f fps; the mean includes frame 0, which uploads everything)\n", median,
           median > 0.0 ? 1e3 / median : 0.0);
    printf("wrote       %s/frame_*.png (.exr every %d), iim.exr/png, aim.exr/png, frames.csv\n", r->a->out_dir,
           r->a->exr_every ? r->a->exr_every : 10);
}

static lm_status play(run_state *r, lm_error *err)
{
    int frames = r->a->frames ? r->a->frames : 60, every = r->a->exr_every ? r->a->exr_every : 10;
    r->frame_ms = malloc(sizeof *r->frame_ms * (size_t)frames);
    if (!r->frame_ms)
        return lm_fail(err, LM_ERR_NOMEM, "no memory for %d frame times", frames);
    lm_status st = LM_OK;
    csv_header(r->csv);
    for (int f = 0; f < frames && st == LM_OK; f++) {
        st = play_frame(r, f, every, err);
        if (!r->a->quiet)
            lm_progress("run", f + 1, frames);
    }
    return st;
}

/* The output directory, claimed before the long setup, so a bad path fails at once. */
static lm_status check_out_dir(const run_state *r, lm_error *err)
{
    static const char *const own[] = {"frame_*.png", "frame_*.exr", "frames.csv", "iim.exr", "iim.png", "aim.exr",
                                      "aim.png", NULL};
    return lm_cli_claim_out_dir(r->a->out_dir, r->a->force, own, err);
}

/* Files are created only once the frame loop exists: a run refused for its settings writes nothing. */
static lm_status open_outputs(run_state *r, lm_error *err)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/frames.csv", r->a->out_dir);
    r->csv = fopen(path, "w");
    return r->csv ? LM_OK : lm_fail(err, LM_ERR_IO, "%s: cannot write", path);
}

static lm_status run(run_state *r, lm_error *err)
{
    lm_frame_loop_settings set;
    lm_cli_run_settings(r->a, &set);
    r->png = malloc((size_t)set.width * set.height * 4);
    if (!r->png)
        return lm_fail(err, LM_ERR_NOMEM, "no memory for the frames");
    lm_photon_stage_frame setup;
    memset(&setup, 0, sizeof setup);
    double t_gather = 0.0;
    lmgi_scene *sc = r->sc;
    lm_status st = check_out_dir(r, err);
    if (st == LM_OK)
        st = lm_frame_loop_create(sc->scene, &sc->surfaces, &sc->atlas, sc->rt, &set, &r->loop, &setup, &t_gather,
                                  err);
    if (st == LM_OK)
        st = open_outputs(r, err);
    if (st == LM_OK)
        st = play(r, err);
    if (r->csv && fclose(r->csv) != 0 && st == LM_OK)
        st = lm_fail(err, LM_ERR_IO, "%s/frames.csv: write failed", r->a->out_dir);
    r->csv = NULL;
    if (st == LM_OK)
        st = write_atlases(r, err);
    if (st == LM_OK && !r->a->quiet)
        summary(r, r->a->frames ? r->a->frames : 60, &setup, t_gather);
    return st;
}

int lm_cli_run_load(const lm_cli_args *a, lmgi_scene **sc)
{
    lmgi_options o = a->options;
    int per_frame = a->texels_per_frame ? a->texels_per_frame : LM_IIM_DEFAULT_TEXELS_PER_FRAME;
    if (o.texel_size <= 0.0f && o.target_texels <= 0) /* a density the texel budget keeps up with */
        o.target_texels = lm_frame_loop_atlas_texels(per_frame);
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
    lm_error err;
    lm_error_clear(&err);
    lm_status st = run(&r, &err);
    if (st != LM_OK)
        fprintf(stderr, "lmgi: error: %s\n", err.msg);
    lm_frame_loop_free(r.loop);
    free(r.frame_ms);
    free(r.png);
    lmgi_free(r.sc);
    return st == LM_OK ? 0 : 1;
}
