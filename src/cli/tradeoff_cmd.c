/* lmgi tradeoff: every knob setting measured for time and error (tradeoff_cmd.h, docs/tradeoff.md). */
#include "tradeoff_cmd.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "order_stats.h"
#include "out_dir.h"
#include "reference_cmd.h"
#include "run_cmd.h"
#include "edit_script.h"
#include "surface_error.h"
#include "scene_load.h"
#include "tradeoff_knobs.h"
#include "tradeoff_write.h"

/* Updates timed after each creation (the first, which uploads everything, is not counted). */
#define UPDATES_QUICK 3
#define UPDATES_FULL 6

/* The frame's side and the references' relative standard error unless --size / --target-error say. The
 * quick sweep's are smaller and looser so that it ends within 3 minutes on the generated Cornell box with
 * nothing cached (its references were 4 of 6 minutes at the full sweep's 96 x 96 and 0.03). At 64 x 64 a
 * few of that box's reference pixels hold rare bright paths, at 0.03 as at 0.04: the per-pixel frame error
 * reads 0.21 (0.05 at 96 x 96), the per-surface one 0.020 (0.013). The full sweep's 0.03 is looser than
 * the reference's own default, 0.02. */
#define FRAME_SIDE_QUICK 64
#define FRAME_SIDE_FULL 96
#define TARGET_ERROR_QUICK 0.04f
#define TARGET_ERROR_FULL 0.03f

/* One setting on one scene's atlas: its scene, texel reference and what it measured. */
typedef struct {
    lmgi_scene *sc;
    lmgi_reference texels;
    int target_texels;
} atlas_state;

static void free_atlas(atlas_state *s)
{
    lmgi_reference_free(&s->texels);
    lmgi_free(s->sc);
    memset(s, 0, sizeof *s);
}

static int load_atlas(const lm_cli_args *a, const char *path, int target_texels, const lmgi_reference_desc *rd,
                      atlas_state *s)
{
    memset(s, 0, sizeof *s);
    lmgi_options o = a->options;
    o.texel_size = 0.0f;
    o.target_texels = target_texels;
    if (!lm_cli_load_scene(path, &o, 1, &s->sc))
        return 0;
    lmgi_error err;
    if (lmgi_reference_texels(s->sc, rd, &s->texels, &err) != LMGI_OK) {
        fprintf(stderr, "lmgi: error: %s\n", err.message);
        free_atlas(s);
        return 0;
    }
    s->target_texels = target_texels;
    return 1;
}

/* Error of est (stride `stride` floats a texel or pixel) against ref (3 a texel) over the entries where
 * mask is set, on the sum of the channels: relative RMSE (RMSE over the mean reference), and each entry's
 * |est - ref| / max(ref, 5% of the mean reference) at the 99th percentile and worst. signed_err (may be
 * NULL) gets est / ref - 1 per entry with the same floor, NAN where not compared. */
static lm_tradeoff_error error_of(const float *est, int stride, const float *ref, const unsigned char *mask,
                                  size_t n, float *signed_err)
{
    lm_tradeoff_error e = {NAN, NAN, NAN, 0};
    double sum_r = 0.0, se = 0.0;
    uint32_t m = 0;
    for (size_t i = 0; i < n; i++)
        if (mask[i]) {
            double f = est[stride * i] + est[stride * i + 1] + est[stride * i + 2];
            double r = ref[3 * i] + ref[3 * i + 1] + ref[3 * i + 2];
            sum_r += r, se += (f - r) * (f - r), m++;
        }
    for (size_t i = 0; signed_err && i < n; i++)
        signed_err[i] = NAN;
    if (m == 0 || !(sum_r > 0.0))
        return e;
    double mean = sum_r / m, floor = 0.05 * mean;
    double *rel = malloc(sizeof *rel * m);
    if (!rel)
        return e;
    uint32_t k = 0;
    for (size_t i = 0; i < n; i++)
        if (mask[i]) {
            double f = est[stride * i] + est[stride * i + 1] + est[stride * i + 2];
            double r = ref[3 * i] + ref[3 * i + 1] + ref[3 * i + 2];
            double d = (f - r) / fmax(r, floor);
            rel[k++] = fabs(d);
            if (signed_err)
                signed_err[i] = (float)d;
        }
    e.rmse = sqrt(se / m) / mean;
    e.p99 = lm_cli_quantile(rel, (int)m, 0.99);
    e.worst = rel[m - 1]; /* sorted by the quantile */
    e.count = m;
    free(rel);
    return e;
}

/* The AIM and IIM of a new updater (the converged solution at time 0) against the texel reference, over
 * the texels the IIM marks valid. The IIM's signed error map goes to m->iim_map. */
static int lightmap_errors(lmgi_updater *u, const atlas_state *as, lm_tradeoff_row *m, lmgi_error *err)
{
    size_t n = (size_t)as->texels.width * (size_t)as->texels.height;
    float *iim = malloc(sizeof *iim * 4 * n), *aim = malloc(sizeof *aim * 4 * n);
    unsigned char *valid = malloc(n);
    m->iim_map = malloc(sizeof *m->iim_map * n);
    int ok = iim && aim && valid && m->iim_map;
    if (!ok)
        fprintf(stderr, "lmgi: error: no memory for the lightmaps' errors\n");
    ok = ok && lmgi_get_lightmap(u, LMGI_LIGHTMAP_IIM, iim, 4 * n, err) == LMGI_OK &&
         lmgi_get_lightmap(u, LMGI_LIGHTMAP_AIM, aim, 4 * n, err) == LMGI_OK;
    if (ok) {
        for (size_t i = 0; i < n; i++)
            valid[i] = iim[4 * i + 3] > 0.5f;
        m->map_width = as->texels.width, m->map_height = as->texels.height;
        m->iim = error_of(iim, 4, as->texels.iim, valid, n, m->iim_map);
        m->aim = error_of(aim, 4, as->texels.radiance, valid, n, NULL);
    }
    free(iim);
    free(aim);
    free(valid);
    return ok;
}

/* The frame the way `lmgi check` compares it (lmgi_check: one update at time 0 against the reference
 * pixels of the same camera). */
static int frame_errors(lmgi_context *ctx, const atlas_state *as, const lmgi_updater_desc *d,
                        const lmgi_reference_desc *rd, lm_tradeoff_row *m, lmgi_error *err)
{
    lmgi_check_result c;
    if (lmgi_set_time(as->sc, 0.0f, err) != LMGI_OK || lmgi_check(ctx, as->sc, d, rd, 1, &c, err) != LMGI_OK)
        return 0;
    size_t n = (size_t)c.width * (size_t)c.height;
    m->frame_map = malloc(sizeof *m->frame_map * n);
    int ok = m->frame_map != NULL;
    if (ok) {
        m->frame = error_of(c.frame, 3, c.reference, c.compared, n, m->frame_map);
        m->frame.rmse = c.rel_rmse; /* the library's figure, emitters left out as `lmgi check` does */
        m->frame_width = c.width, m->frame_height = c.height;
        m->frame_bias = 0.0;
        for (int k = 0; k < 3; k++) {
            m->frame_ratio[k] = c.ratio[k];
            m->frame_bias = fmax(m->frame_bias, fabs(c.ratio[k] - 1.0));
        }
        m->reference_rel_se = c.reference_rel_se;
        m->frame_surface_rms = lm_cli_surface_error(as->sc, &c, &m->frame_surface_worst);
        /* the caustic part, judged like the frame (the library's relative RMSE); none without caustics */
        m->caustic = error_of(c.caustic_frame, 3, c.caustic_reference, c.compared, n, NULL);
        if (m->caustic.count)
            m->caustic.rmse = c.caustic_rel_rmse;
        for (int k = 0; k < 3; k++)
            m->caustic_ratio[k] = m->caustic.count ? c.caustic_ratio[k] : NAN;
    } else
        fprintf(stderr, "lmgi: error: no memory for the frame's error\n");
    lmgi_check_free(&c);
    return ok;
}

/* Stage times: `repeats` updaters created at time 0 (the full solution: trace, AIMs, gather), each then
 * updated `updates` + 1 times at 30 per second; medians. The first updater's lightmaps give the AIM and
 * IIM errors. */
static int time_and_lightmaps(lmgi_context *ctx, const atlas_state *as, const lm_tradeoff_setting *s,
                              int repeats, int updates, int width, int height, lm_tradeoff_row *m,
                              lmgi_error *err)
{
    lmgi_updater_desc d = s->desc;
    d.frame.width = width, d.frame.height = height;
    int nu = repeats * updates;
    double *v = malloc(sizeof *v * (size_t)(12 * (repeats + nu)));
    if (!v) {
        fprintf(stderr, "lmgi: error: no memory for the timings\n");
        return 0;
    }
    double *trace = v, *aim = trace + repeats, *gather = aim + repeats, *solution = gather + repeats;
    double *up[8];
    for (int k = 0; k < 8; k++)
        up[k] = solution + repeats + (size_t)k * nu;
    int ok = 1;
    for (int r = 0; r < repeats && ok; r++) {
        lmgi_updater *u = NULL;
        ok = lmgi_set_time(as->sc, 0.0f, err) == LMGI_OK && lmgi_updater_create(ctx, as->sc, &d, &u, err) == LMGI_OK;
        if (!ok)
            break;
        lmgi_updater_info info;
        lmgi_get_updater_info(u, &info);
        trace[r] = info.ms_setup_trace, aim[r] = info.ms_setup_aim, gather[r] = info.ms_setup_gather;
        solution[r] = trace[r] + aim[r] + gather[r];
        m->photons = info.stored_photons;
        m->coverage = info.gather.coverage;
        if (r == 0 && s->desc.indirect == LMGI_INDIRECT_LIGHTMAP)
            ok = lightmap_errors(u, as, m, err);
        for (int f = 0; f <= updates && ok; f++) {
            lmgi_update_stats st;
            ok = lmgi_update(u, (float)f / 30.0f, 0.0f, &st, err) == LMGI_OK;
            if (!ok || f == 0)
                continue;
            int i = r * updates + f - 1;
            up[0][i] = st.ms_total, up[1][i] = st.ms_photons, up[2][i] = st.ms_gather, up[3][i] = st.ms_direct;
            up[4][i] = st.ms_caustics, up[5][i] = st.ms_reflections, up[6][i] = st.ms_composite;
            up[7][i] = st.ms_blend;
        }
        if (ok && r == 0) {
            lmgi_get_updater_info(u, &info);
            m->photon_radius = info.tiled.radius;
        }
        lmgi_updater_free(u);
    }
    if (ok) {
        m->ms_trace = lm_cli_median(trace, repeats), m->ms_aim = lm_cli_median(aim, repeats);
        m->ms_gather = lm_cli_median(gather, repeats), m->ms_solution = lm_cli_median(solution, repeats);
        for (int k = 0; k < 8; k++)
            m->ms_update[k] = updates ? lm_cli_median(up[k], nu) : 0.0;
    }
    free(v);
    return ok;
}

static void fail_row(lm_tradeoff_row *m)
{
    m->aim = m->iim = m->frame = m->caustic = (lm_tradeoff_error){NAN, NAN, NAN, 0};
    for (int k = 0; k < 3; k++)
        m->caustic_ratio[k] = NAN;
    m->ms_trace = m->ms_aim = m->ms_gather = m->ms_solution = NAN;
    for (int k = 0; k < 8; k++)
        m->ms_update[k] = NAN;
    m->frame_bias = m->frame_surface_rms = m->frame_surface_worst = NAN;
    free(m->iim_map), free(m->frame_map);
    m->iim_map = m->frame_map = NULL;
}

static int measure(lmgi_context *ctx, const atlas_state *as, const lm_tradeoff_setting *s,
                   const lmgi_reference_desc *rd, int repeats, int updates, int width, int height,
                   lm_tradeoff_row *m)
{
    m->aim = m->iim = m->frame = m->caustic = (lm_tradeoff_error){NAN, NAN, NAN, 0};
    lmgi_error err;
    lmgi_updater_desc d = s->desc;
    d.frame.width = width, d.frame.height = height;
    if (!time_and_lightmaps(ctx, as, s, repeats, updates, width, height, m, &err) ||
        !frame_errors(ctx, as, &d, rd, m, &err)) {
        fprintf(stderr, "lmgi: error: %s = %s: %s\n", s->knob, s->value, err.message);
        return 0;
    }
    return 1;
}

/* The tiled gather's default radius on this scene: what an updater resolves at its first frame. */
static float tiled_radius(lmgi_context *ctx, lmgi_scene *sc, int width, int height)
{
    lmgi_updater_desc d;
    memset(&d, 0, sizeof d);
    d.indirect = LMGI_INDIRECT_TILED;
    d.frame.width = width, d.frame.height = height;
    lmgi_updater *u = NULL;
    lmgi_error err;
    float r = 0.0f;
    if (lmgi_set_time(sc, 0.0f, &err) == LMGI_OK && lmgi_updater_create(ctx, sc, &d, &u, &err) == LMGI_OK &&
        lmgi_update(u, 0.0f, 0.0f, NULL, &err) == LMGI_OK) {
        lmgi_updater_info info;
        lmgi_get_updater_info(u, &info);
        r = info.tiled.radius;
    }
    lmgi_updater_free(u);
    return r;
}

static int scene_calls_for(const lmgi_scene *sc, const char *effect)
{
    for (int i = 0; i < lmgi_effect_count(sc); i++) {
        lmgi_effect e;
        lmgi_get_effect(sc, i, &e);
        if (e.name && !strcmp(e.name, effect))
            return e.on;
    }
    return 0;
}

/* The update budgets the lag study moves, one at a time around their defaults. lmgi_update runs with
 * budget_ms 0, so that texels_per_frame is what each update gathers. texel_change is a switch here: 1 its
 * default, 0 off (whole surfaces only, the paper's order). */
static const struct {
    const char *knob;
    int n, values[3], def;
} BUDGETS[] = {{"texels_per_frame", 3, {5, 20, 80}, 20},
               {"group_budget", 3, {4, 16, 64}, 16},
               {"surfaces_per_frame", 3, {2, 8, 32}, 8},
               {"texel_change", 2, {0, 1}, 1}};
#define BUDGET_COUNT ((int)(sizeof BUDGETS / sizeof *BUDGETS))

/* The plays: the default once, and every other value of every budget. */
static int play_total(void)
{
    int n = 1;
    for (int b = 0; b < BUDGET_COUNT; b++)
        n += BUDGETS[b].n - 1;
    return n;
}

/* Budget b at value v into d (0 leaves the default). */
static void set_budget(int b, int v, lmgi_updater_desc *d)
{
    if (b == 0)
        d->gather.texels_per_frame = v;
    else if (b == 1)
        d->photons.group_budget = v;
    else if (b == 2)
        d->aim.surfaces_per_frame = v;
    else
        d->gather.texel_change = v ? 0.0f : (float)LMGI_OFF;
}

/* The scene's edit script played once per budget setting (the default once); plays into sr. A play the
 * library refuses counts as a failed setting. */
static int lag_sweep(const lm_cli_args *a, const char *path, const lm_edit_script *script,
                     const lmgi_reference_desc *rd, lm_tradeoff_scene *sr)
{
    /* --frame-lag: the default play's frame against the path-traced reference after every update, at 64 x 64
     * (a reference per edited state: 64^2 costs under half of 96^2, and per-surface means need few pixels) */
    lm_edit_frame_check fc = {rd, LM_TRADEOFF_LAG_SIDE, LM_TRADEOFF_LAG_SIDE};
    sr->script = script;
    int total = play_total();
    sr->plays = calloc((size_t)total, sizeof *sr->plays);
    if (!sr->plays)
        return fprintf(stderr, "lmgi: error: no memory for the plays\n"), 0;
    for (int b = 0; b < BUDGET_COUNT; b++)
        for (int k = 0; k < BUDGETS[b].n; k++) {
            int v = BUDGETS[b].values[k], is_default = v == BUDGETS[b].def;
            if (is_default && b > 0)
                continue; /* the default is played once, with the first budget */
            lm_tradeoff_play *p = &sr->plays[sr->play_count++];
            p->knob = BUDGETS[b].knob, p->value = v, p->is_default = is_default;
            lmgi_updater_desc d;
            memset(&d, 0, sizeof d);
            if (!is_default)
                set_budget(b, v, &d);
            p->frames = calloc((size_t)script->frames, sizeof *p->frames);
            p->frame_lag = is_default && a->frame_lag;
            if (!p->frames || !lm_edit_script_play(script, path, &d, 0.0f, p->frame_lag ? &fc : NULL, p->frames)) {
                free(p->frames);
                p->frames = NULL;
                sr->failed++;
                continue;
            }
            if (!a->quiet) {
                int from, to, f5;
                double ms5;
                lm_edit_span(script, 0, &from, &to);
                lm_edit_lag(p->frames, from, to, 0.05, LM_LAG_WORST_SURFACE, &f5, &ms5);
                fprintf(stderr, "lmgi: tradeoff %s update lag [%d/%d] %s = %d: the first edit's worst surface %s %d "
                        "updates (%.0f ms)\n", sr->name, sr->play_count, total, p->knob, v,
                        f5 < 0 ? "still 5% off after" : "within 5% after", f5 < 0 ? to - from : f5, ms5);
            }
        }
    return 1;
}

/* Every setting of one scene, measured; rows (one per setting) into sr. */
static int sweep_scene(const lm_cli_args *a, lmgi_context *ctx, const char *path, const lmgi_reference_desc *rd,
                       lm_tradeoff_scene *sr)
{
    int quick = a->quick, width = a->width ? a->width : quick ? FRAME_SIDE_QUICK : FRAME_SIDE_FULL;
    int height = a->height ? a->height : width;
    int texels = a->options.target_texels > 0 ? a->options.target_texels : lmgi_atlas_texels_for(0);
    lm_tradeoff_plan plan = {quick, texels, 0, 0.0f, a->knobs};
    atlas_state def;
    if (!load_atlas(a, path, plan.default_texels, rd, &def))
        return 0;
    if (!a->verbose) /* each updater's "ready" line and the cached references' would bury the progress */
        lmgi_set_verbosity(0);
    plan.caustics = scene_calls_for(def.sc, "caustics");
    plan.photon_radius = scene_calls_for(def.sc, "indirect") ? tiled_radius(ctx, def.sc, width, height) : 0.0f;
    sr->reference_texels_seconds = def.texels.seconds;
    sr->reference_texels_rel_se = def.texels.mean_rel_se;
    lm_tradeoff_setting *set = NULL;
    int n = 0, ok = lm_tradeoff_settings(&plan, &set, &n);
    sr->rows = ok ? calloc((size_t)(n ? n : 1), sizeof *sr->rows) : NULL;
    if (!sr->rows) {
        fprintf(stderr, "lmgi: error: no memory for the settings\n");
        free(set);
        free_atlas(&def);
        return 0;
    }
    int updates = quick ? UPDATES_QUICK : UPDATES_FULL;
    for (int i = 0; i < n && ok; i++) {
        lm_tradeoff_row *m = &sr->rows[i];
        m->setting = set[i];
        m->is_default = set[i].target_texels == plan.default_texels &&
                        !memcmp(&set[i].desc, &(lmgi_updater_desc){0}, sizeof set[i].desc);
        int same = -1;
        for (int j = 0; j < i && same < 0; j++)
            if (lm_tradeoff_same(&set[j], &set[i]))
                same = j;
        int measured = 1;
        if (same >= 0) {
            lm_tradeoff_row_copy(m, &sr->rows[same]);
        } else if (set[i].target_texels == def.target_texels) {
            measured = measure(ctx, &def, &set[i], rd, a->repeats, updates, width, height, m);
        } else {
            atlas_state other;
            ok = load_atlas(a, path, set[i].target_texels, rd, &other);
            measured = ok && measure(ctx, &other, &set[i], rd, a->repeats, updates, width, height, m);
            if (other.sc)
                free_atlas(&other);
        }
        sr->count = i + 1;
        /* a setting the library refuses (a limit of this GL) is a row without numbers; the sweep goes on
         * and the command ends with exit status 1 */
        if (!measured)
            fail_row(m), sr->failed++;
        if (measured && !a->quiet) {
            fprintf(stderr, "lmgi: tradeoff %s [%d/%d] %s = %s%s: solution %.1f ms, update %.1f ms; relative RMSE "
                    "AIM %.4f, IIM %.4f, frame %.4f (per surface %.4f)", sr->name, i + 1, n, set[i].knob,
                    set[i].value, same >= 0 ? " (measured above)" : "", m->ms_solution, m->ms_update[0], m->aim.rmse,
                    m->iim.rmse, m->frame.rmse, m->frame_surface_rms);
            if (m->caustic.count)
                fprintf(stderr, ", caustic part %.4f", m->caustic.rmse);
            fputc('\n', stderr);
        }
    }
    free(set);
    free_atlas(&def);
    lmgi_set_verbosity(a->quiet ? 0 : a->verbose ? 2 : 1);
    return ok;
}

/* --edits LIST: up to 8 edit scripts, each for the scene on the command line its "scene" key names (by
 * file name), or for the only scene when it names none. */
#define MAX_SCRIPTS 8
typedef struct {
    char paths[4096];      /* --edits, split in place: the scripts' paths point into it */
    lm_edit_script s[MAX_SCRIPTS];
    int count;
    const lm_edit_script *of_scene[LM_CLI_MAX_FILES];
} edit_scripts;

static void free_scripts(edit_scripts *e)
{
    for (int i = 0; i < e->count; i++)
        lm_edit_script_free(&e->s[i]);
    e->count = 0;
}

static const char *base_name(const char *path)
{
    const char *b = strrchr(path, '/');
    return b ? b + 1 : path;
}

static int read_scripts(const lm_cli_args *a, edit_scripts *e)
{
    memset(e, 0, sizeof *e);
    snprintf(e->paths, sizeof e->paths, "%s", a->edits_path ? a->edits_path : "");
    for (char *save = NULL, *p = strtok_r(e->paths, ",", &save); p; p = strtok_r(NULL, ",", &save)) {
        if (e->count == MAX_SCRIPTS)
            return fprintf(stderr, "lmgi: --edits: at most %d scripts\n", MAX_SCRIPTS), free_scripts(e), 0;
        lm_edit_script *s = &e->s[e->count];
        if (!lm_edit_script_read(p, s))
            return free_scripts(e), 0;
        e->count++;
        int found = -1;
        for (int i = 0; i < a->file_count && found < 0; i++)
            if (s->scene ? !strcmp(base_name(s->scene), base_name(a->files[i])) : a->file_count == 1)
                found = i;
        if (found < 0 || e->of_scene[found]) {
            fprintf(stderr, "lmgi: --edits %s: %s\n", p,
                    found >= 0 ? "a second script for the same scene"
                    : s->scene ? "its \"scene\" is not on the command line"
                               : "names no \"scene\" (the file it edits), and there are several scenes");
            return free_scripts(e), 0;
        }
        e->of_scene[found] = s;
    }
    return 1;
}

int lm_cli_tradeoff(const lm_cli_args *a)
{
    if (a->file_count < 1 || !a->out_dir) {
        fprintf(stderr, "lmgi: usage: lmgi tradeoff SCENE... --out DIR [--quick] [--knobs LIST] [--size WxH]\n"
                        "       [--repeats N] [--target-error E]\n");
        return 2;
    }
    char bad[64];
    if (a->knobs && !lm_tradeoff_knobs_known(a->knobs, bad, sizeof bad)) {
        fprintf(stderr, "lmgi: --knobs: unknown knob '%s' (knobs: %s)\n", bad, lm_tradeoff_knob_keys());
        return 2;
    }
    edit_scripts scripts;
    if (!read_scripts(a, &scripts))
        return 2;
    lmgi_output *out = lm_cli_open_out(a, "tradeoff");
    if (!out) {
        free_scripts(&scripts);
        return 1;
    }
    lmgi_reference_desc rd;
    lm_cli_reference_desc(a, &rd);
    if (!(a->target_error > 0.0f))
        rd.target_error = a->quick ? TARGET_ERROR_QUICK : TARGET_ERROR_FULL;
    lmgi_context *ctx = NULL;
    lmgi_error err;
    if (lmgi_context_create(NULL, &ctx, &err) != LMGI_OK) {
        fprintf(stderr, "lmgi: error: %s\n", err.message);
        free_scripts(&scripts);
        return lm_cli_close_out(out, 1);
    }
    lm_tradeoff_scene *scenes = calloc((size_t)a->file_count, sizeof *scenes);
    int ok = scenes != NULL, done = 0;
    for (int i = 0; i < a->file_count && ok; i++) {
        scenes[i].path = a->files[i];
        lm_tradeoff_scene_name(a->files[i], scenes[i].name, sizeof scenes[i].name);
        ok = sweep_scene(a, ctx, a->files[i], &rd, &scenes[i]);
        if (ok && scripts.of_scene[i])
            ok = lag_sweep(a, a->files[i], scripts.of_scene[i], &rd, &scenes[i]);
        done = i + 1;
    }
    lm_tradeoff_run run = {a->quick, a->repeats, rd.target_error, scenes, done};
    /* what was measured is written even when a later scene failed */
    int wrote = scenes && lm_tradeoff_write(lmgi_output_folder(out), &run);
    int reported = wrote && ok && lm_tradeoff_report(lmgi_output_folder(out), a->out_dir);
    if (lm_cli_close_out(out, !wrote) != 0)
        reported = 0;
    else if (reported && !a->quiet)
        printf("wrote %s/report.html\n", a->out_dir);
    for (int i = 0; i < done; i++)
        if (scenes[i].failed) {
            fprintf(stderr, "lmgi: tradeoff: %d setting(s) of %s could not be measured (above); their rows are "
                    "empty\n", scenes[i].failed, scenes[i].name);
            reported = 0;
        }
    for (int i = 0; i < done; i++)
        lm_tradeoff_scene_free(&scenes[i]);
    free(scenes);
    free_scripts(&scripts);
    lmgi_context_free(ctx);
    return reported ? 0 : 1;
}
