/* lmgi bench --edits SCRIPT.json SCENE: a scripted edit sequence through the public updater (lmgi.h
 * only), timed per update, with each edit's update lag against the converged lightmap of the edited
 * scene (a twin scene given the same edits and baked). docs/bench.md describes the script. */
#include "bench_edits.h"

#include <lmgi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "edit_script.h"
#include "order_stats.h"
#include "out_dir.h"
#include "run_cmd.h"

/* The lightmap to an engine after each update: the whole atlas read against the rectangles of the
 * surfaces that update changed (docs/api.md, "Lightmaps to an engine"), over the updates that changed any. */
static void report_reads(const lm_edit_script *s, const lm_edit_frame *rows)
{
    double *whole = malloc(sizeof *whole * (size_t)s->frames), *rects = malloc(sizeof *rects * (size_t)s->frames);
    double *texels = malloc(sizeof *texels * (size_t)s->frames), *tex = malloc(sizeof *tex * (size_t)s->frames);
    int n = 0;
    for (int f = 0; whole && rects && texels && tex && f < s->frames; f++)
        if (rows[f].rect_texels > 0)
            whole[n] = rows[f].ms_read_whole, rects[n] = rows[f].ms_read_rects, tex[n] = rows[f].ms_texture,
            texels[n++] = rows[f].rect_texels;
    if (n > 0)
        printf("lightmap reads after the %d updates that changed surfaces: whole atlas median %.3f ms, the changed "
               "surfaces' rectangles median %.3f ms (%.0f texels, median), into lmgi's GL texture median %.3f ms\n",
               n, lm_cli_quantile(whole, n, 0.5), lm_cli_quantile(rects, n, 0.5), lm_cli_quantile(texels, n, 0.5),
               lm_cli_quantile(tex, n, 0.5));
    free(whole);
    free(rects);
    free(texels);
    free(tex);
}


/* How often each stage took an update's longest time (lmgi_update_stats.busiest_stage), most first. */
static void print_busiest(const lm_edit_script *s, const lm_edit_frame *rows)
{
    const char *names[8];
    int count[8], kinds = 0;
    for (int f = 0; f < s->frames; f++) {
        int k = 0;
        while (k < kinds && strcmp(names[k], rows[f].busiest) != 0)
            k++;
        if (k == kinds)
            names[kinds] = rows[f].busiest, count[kinds++] = 0; /* at most the 6 stage names */
        count[k]++;
    }
    printf("the stage that took the most time:");
    for (int done = 0; done < kinds; done++) {
        int best = -1;
        for (int k = 0; k < kinds; k++)
            best = count[k] >= 0 && (best < 0 || count[k] > count[best]) ? k : best; /* -1: printed */
        printf("%s %s in %d", done ? "," : "", names[best], count[best]);
        count[best] = -1;
    }
    printf(" of %d updates\n", s->frames);
}

static int report(const lm_cli_args *a, const lm_edit_script *s, const lm_edit_frame *rows)
{
    printf("lmgi bench --edits %s %s: %d updates, budget %.1f ms, %d fps, %d texels\n", a->edits_path, a->files[0],
           s->frames, (double)s->budget_ms, s->fps, s->texels);
    printf("%-28s %6s %10s %14s %14s %14s %20s\n", "edit", "frame", "error", "to 5%", "to 2%", "rewrites",
           "outside its reach");
    lm_cli_single out = {0};
    if (a->json_path && !lm_cli_single_open(&out))
        return 0;
    FILE *json = out.f;
    if (json)
        fprintf(json, "{\n  \"script\": \"%s\", \"scene\": \"%s\", \"budget_ms\": %g,\n  \"edits\": [\n",
                a->edits_path, a->files[0], (double)s->budget_ms);
    for (int i = 0; i < s->edit_count; i++) {
        int from, to;
        if (!lm_edit_span(s, i, &from, &to))
            continue; /* several edits in one frame: the last one reports */
        int f5, f2;
        double ms5, ms2;
        lm_edit_lag(rows, from, to, 0.05, LM_LAG_ATLAS, &f5, &ms5);
        lm_edit_lag(rows, from, to, 0.02, LM_LAG_ATLAS, &f2, &ms2);
        char what[128], l5[48], l2[48];
        lm_edit_describe(s->edits[i].v, what, sizeof what);
        snprintf(l5, sizeof l5, f5 < 0 ? "not in %d fr" : "%d fr %.0f ms", f5 < 0 ? to - from : f5, ms5);
        snprintf(l2, sizeof l2, f2 < 0 ? "not in %d fr" : "%d fr %.0f ms", f2 < 0 ? to - from : f2, ms2);
        int reached = 0, outside = 0; /* surface rewrites in its reach, and where its light does not reach */
        uint32_t outside_texels = 0;
        for (int f = from; f < to; f++)
            reached += rows[f].reached, outside += rows[f].outside, outside_texels += rows[f].outside_texels;
        char in[32], out[48];
        snprintf(in, sizeof in, "%d surf", reached);
        snprintf(out, sizeof out, "%d surf, %u tx", outside, outside_texels);
        printf("%-28s %6d %9.1f%% %14s %14s %14s %20s\n", what, from, 100.0 * rows[from].error, l5, l2, in, out);
        if (json)
            fprintf(json, "    {\"edit\": \"%s\", \"frame\": %d, \"error\": %.5f, \"frames_to_5\": %d, \"ms_to_5\": %.2f, "
                    "\"frames_to_2\": %d, \"ms_to_2\": %.2f, \"reach_surfaces\": %d, \"rewritten_in_reach\": %d, "
                    "\"outside_surfaces\": %d, \"outside_texels\": %u}%s\n", what, from, rows[from].error, f5, ms5, f2,
                    ms2, rows[from].reach, reached, outside, outside_texels, i + 1 < s->edit_count ? "," : "");
    }
    double *ms = malloc(sizeof *ms * (size_t)s->frames);
    int over = 0;
    double texels = 0.0;
    for (int f = 0; ms && f < s->frames; f++) {
        ms[f] = rows[f].ms_total;
        over += s->budget_ms > 0.0f && rows[f].ms_total > 1.1 * s->budget_ms;
        texels += rows[f].texels;
    }
    if (ms) {
        double p95 = lm_cli_quantile(ms, s->frames, 0.95); /* sorts ms */
        printf("updates: median %.2f ms, 95th percentile %.2f ms, worst %.2f ms; %d of %d over the budget by more "
               "than 10%%; %.1f texels an update\n", ms[s->frames / 2], p95,
               ms[s->frames - 1], over, s->frames, texels / s->frames);
        print_busiest(s, rows);
        int n = 0; /* the edits' own calls: staged, they wait for no photon work (update/edits.h) */
        for (int f = 0; f < s->frames; f++)
            if (rows[f].ms_edit > 0.0)
                ms[n++] = rows[f].ms_edit;
        if (n > 0)
            printf("edit calls before %d updates: median %.3f ms, worst %.3f ms\n", n, lm_cli_quantile(ms, n, 0.5),
                   lm_cli_quantile(ms, n, 1.0));
    }
    report_reads(s, rows);
    if (json) {
        fprintf(json, "  ],\n  \"frames\": [\n");
        for (int f = 0; f < s->frames; f++)
            fprintf(json, "    {\"ms\": %.3f, \"photons_ms\": %.3f, \"gather_ms\": %.3f, \"blend_ms\": %.3f, "
                    "\"texels\": %u, \"photons\": %u, \"aim_surfaces\": %d, \"surfaces_changed\": %d, "
                    "\"error\": %.5f, \"read_whole_ms\": %.3f, \"read_rects_ms\": %.3f, \"rect_texels\": %u, "
                    "\"texture_ms\": %.3f, \"edit_ms\": %.3f, \"light_scale_ms\": %.3f, \"busiest\": \"%s\"}%s\n",
                    rows[f].ms_total, rows[f].ms_photons, rows[f].ms_gather, rows[f].ms_blend,
                    rows[f].texels, rows[f].photons, rows[f].aim, rows[f].changed, rows[f].error,
                    rows[f].ms_read_whole, rows[f].ms_read_rects, rows[f].rect_texels, rows[f].ms_texture,
                    rows[f].ms_edit, rows[f].ms_light_scale, rows[f].busiest, f + 1 < s->frames ? "," : "");
        fprintf(json, "  ]\n}\n");
    }
    free(ms);
    return !json || lm_cli_single_close(a, a->json_path, &out);
}

int lm_cli_bench_edits(const lm_cli_args *a)
{
    if (a->file_count != 1) {
        fprintf(stderr, "lmgi: bench --edits SCRIPT.json takes one scene\n");
        return 2;
    }
    lm_edit_script s;
    if ((a->json_path && !lm_cli_single_allowed(a, a->json_path)) || !lm_edit_script_read(a->edits_path, &s))
        return 1;
    lm_edit_frame *rows = calloc((size_t)s.frames, sizeof *rows);
    lmgi_updater_desc d; /* the photon and gather options given; the frame and progress as the zero desc's */
    lm_cli_updater_desc(a, &d);
    d.frame.width = d.frame.height = 0;
    d.progress = NULL;
    d.progress_user = NULL;
    int ok = rows && lm_edit_script_play(&s, a->files[0], &d, s.budget_ms, NULL, rows);
    if (ok)
        ok = report(a, &s, rows);
    free(rows);
    lm_edit_script_free(&s);
    return ok ? 0 : 1;
}
