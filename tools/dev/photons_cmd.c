/* lmgi-dev photons: plays the scene's animations with the photon stage only (photons + AIMs) and writes
 * the AIM atlas (EXR and PNG), a picture of the scene with its AIMs, and per-frame statistics (CSV). */
#include "photons_cmd.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../../src/charts/atlas_dilate.h"
#include "../../src/core/image.h"
#include "../../src/core/tonemap.h"
#include "../../src/scene/scene_view.h"
#include "../../src/gpu/gl/gl_context.h"
#include "../../src/gpu/frame/lightmap_view.h"
#include "../../src/api/lmgi_scene.h"
#include "../../src/update/photon_stage.h"
#include "../../src/cli/out_dir.h"
#include "../../src/cli/progress.h"
#include "../../src/cli/scene_load.h"

#define FRAME_RATE 30.0f /* frames are played at 30 per second of animation time */

void lm_dev_photon_settings(const lm_cli_args *a, lm_photon_stage_settings *s)
{
    lm_photon_stage_settings_default(s);
    const lmgi_photon_knobs *ph = &a->desc.photons;
    if (ph->count)
        s->photons.total_photons = ph->count;
    if (ph->groups)
        s->photons.groups = ph->groups;
    if (ph->per_group)
        s->photons.per_group = ph->per_group, s->photons.min_total = 0;
    if (ph->retrace_per_group)
        s->photons.retrace_per_group = ph->retrace_per_group;
    if (ph->group_budget) /* given: LMGI_OFF is every invalid group, lm_photons' 0 */
        s->photons.group_budget = ph->group_budget == LMGI_OFF ? 0 : (uint32_t)ph->group_budget;
    if (a->seed)
        s->photons.seed = a->seed;
    if (a->desc.aim.nearest)
        s->aim.n_nearest = a->desc.aim.nearest;
    if (a->desc.aim.surfaces_per_frame)
        s->surfaces_per_frame = a->desc.aim.surfaces_per_frame;
    s->exact_direct = lm_exact_direct_of(a->desc.aim.direct);
}

static void csv_header(FILE *f)
{
    fprintf(f, "frame,time_s,emitters_moved,photons_retraced,paths_changed,groups_invalidated,groups_retraced,"
               "group_photons,hits_added,hits_removed,groups_pending,surfaces_refreshed,surfaces_pending,"
               "texels_written,animate_ms,photons_ms,aim_ms,frame_ms\n");
}

static void csv_row(FILE *f, const lm_photon_stage_frame *r)
{
    const lm_photon_frame_stats *p = &r->photons;
    fprintf(f, "%d,%.4f,%d,%u,%u,%u,%u,%u,%u,%u,%u,%d,%d,%u,%.3f,%.3f,%.3f,%.3f\n", r->frame, (double)r->time,
            r->emitters_moved, p->rr_photons, p->paths_changed, p->groups_invalidated, p->groups_retraced,
            p->group_photons, p->hits_added, p->hits_removed, p->pending_groups, r->aim.surfaces_refreshed,
            r->aim.surfaces_pending, r->aim.texels_written, 1e3 * r->t_animate, 1e3 * r->t_photons,
            1e3 * r->t_aim, 1e3 * r->t_total);
}

/* DIR/aim.exr (linear), DIR/aim.png (tone-mapped) and DIR/view.png (the scene with its AIMs). */
static lm_status write_pictures(const lmgi_scene *sc, const lm_aim *aim, const lm_cli_args *a, lmgi_output *out,
                                float *exposure, lm_error *err)
{
    const lm_atlas *at = &sc->atlas;
    size_t n = (size_t)at->width * at->height;
    float *rgb = malloc(n * 3 * sizeof *rgb);
    uint8_t *img = malloc(n * 4);
    int w = a->width ? a->width : 640, h = a->height ? a->height : 480;
    uint8_t *view_img = malloc((size_t)w * h * 4);
    char path[4200];
    lm_status st = rgb && img && view_img ? LM_OK : lm_fail(err, LM_ERR_NOMEM, "no memory for the pictures");
    if (st == LM_OK) {
        memcpy(rgb, lm_aim_rgb(aim), n * 3 * sizeof *rgb);
        snprintf(path, sizeof path, "%s/aim.exr", lmgi_output_folder(out));
        st = lm_write_exr(path, at->width, at->height, 3, rgb, err);
    }
    if (st == LM_OK) {
        lm_atlas_dilate_gutters(at, rgb, 3);
        *exposure = lm_auto_exposure(rgb, n, 3);
        lm_tonemap_srgb8(rgb, n, 3, *exposure, img);
        snprintf(path, sizeof path, "%s/aim.png", lmgi_output_folder(out));
        st = lm_write_png(path, at->width, at->height, img, err);
    }
    lm_gl_context *gl = NULL;
    if (st == LM_OK)
        st = lm_gl_context_create(&gl, err);
    if (st == LM_OK) {
        lm_view view;
        lm_view_for_scene(sc->scene, a->camera, w, h, &view);
        st = lm_render_lightmap(sc->scene, at, rgb, *exposure, &view, w, h, view_img, err);
        snprintf(path, sizeof path, "%s/view.png", lmgi_output_folder(out));
        if (st == LM_OK)
            st = lm_write_png(path, w, h, view_img, err);
    }
    lm_gl_context_destroy(gl);
    free(rgb);
    free(img);
    free(view_img);
    return st;
}

static lm_status play(lmgi_scene *sc, const lm_cli_args *a, lm_photon_stage *stage, FILE *csv, double *sum_ms,
                      lm_error *err)
{
    int frames = a->frames ? a->frames : 60;
    *sum_ms = 0.0;
    for (int f = 0; f < frames; f++) {
        lm_photon_stage_frame r;
        lm_status st = lm_photon_stage_step(stage, (float)f / FRAME_RATE, &r, err);
        if (st != LM_OK)
            return st;
        csv_row(csv, &r);
        *sum_ms += 1e3 * r.t_total;
        lm_progress("photons", f + 1, frames);
    }
    (void)sc;
    return LM_OK;
}

static void summary(const lm_photon_stage *stage, const lm_photon_stage_frame *setup, int frames, double sum_ms,
                    float exposure, const char *dir)
{
    const lm_photons *ph = lm_photon_stage_photons(stage);
    lm_photon_memory mem;
    lm_photons_memory(ph, &mem);
    printf("photons     %u in %u groups (%u per emitter, %d emitters), %u hits stored\n", lm_photons_count(ph),
           lm_photons_group_count(ph), lm_photons_groups_per_emitter(ph), lm_photon_stage_emitters(stage)->count,
           lm_photons_stored_hits(ph));
    printf("memory      %.0f bytes per photon (%.0f in use; %.2f path vertices, %.2f hits per photon)\n",
           mem.per_photon, mem.live_per_photon, mem.mean_path_vertices, mem.mean_hits);
    printf("setup       full trace %.1f ms, all AIMs %.1f ms\n", 1e3 * setup->t_photons, 1e3 * setup->t_aim);
    printf("frames      %d, mean photon-stage frame %.3f ms\n", frames, frames ? sum_ms / frames : 0.0);
    printf("wrote       %s/aim.exr, %s/aim.png, %s/view.png (exposure %.4g), %s/stats.csv\n", dir, dir, dir,
           (double)exposure, dir);
}

int lm_dev_photons(const lm_cli_args *a)
{
    if (a->file_count != 1 || !a->out_dir) {
        fprintf(stderr, "lmgi-dev: photons needs one scene file and --out DIR\n");
        return 2;
    }
    lmgi_scene *sc = NULL;
    if (!lm_cli_load_scene(a->files[0], &a->options, 1, &sc))
        return 1;
    lm_error err;
    lm_error_clear(&err);
    lm_photon_stage_settings set;
    lm_dev_photon_settings(a, &set);
    lm_photon_stage *stage = NULL;
    lm_photon_stage_frame setup;
    memset(&setup, 0, sizeof setup);
    char path[4200];
    FILE *csv = NULL;
    double sum_ms = 0.0;
    float exposure = 1.0f;
    lmgi_output *out = lm_cli_open_out(a, "photons");
    if (!out || !lm_cli_out_path(out, "stats.csv", path, sizeof path)) {
        lm_cli_close_out(out, 1);
        lmgi_free(sc);
        return 1;
    }
    csv = fopen(path, "wx");
    lm_status st = csv ? LM_OK : lm_fail(&err, LM_ERR_IO, "%s: cannot write", path);
    if (st == LM_OK)
        st = lm_photon_stage_create(&sc->world, &set, &stage, &setup, &err);
    if (st == LM_OK) {
        csv_header(csv);
        st = play(sc, a, stage, csv, &sum_ms, &err);
    }
    if (csv && fclose(csv) != 0 && st == LM_OK)
        st = lm_fail(&err, LM_ERR_IO, "%s/stats.csv: write failed", a->out_dir);
    if (st == LM_OK)
        st = write_pictures(sc, lm_photon_stage_aim(stage), a, out, &exposure, &err);
    if (st == LM_OK && !a->quiet)
        summary(stage, &setup, a->frames ? a->frames : 60, sum_ms, exposure, a->out_dir);
    if (st != LM_OK)
        fprintf(stderr, "lmgi-dev: error: %s\n", err.msg);
    lm_photon_stage_free(stage);
    lmgi_free(sc);
    return lm_cli_close_out(out, st != LM_OK);
}
