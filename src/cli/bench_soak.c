/* lmgi bench --soak: a long run's memory, time and finiteness (bench_soak.h). */
#include "bench_soak.h"

#include <lmgi.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "order_stats.h"
#include "progress.h"
#include "random_edits.h"
#include "resident_memory.h"
#include "run_cmd.h"

#define SOAK_SIZE 32 /* frame side unless --size */

static long non_finite(const float *rgb, int n)
{
    long bad = 0;
    for (int i = 0; i < 3 * n; i++)
        bad += !isfinite(rgb[i]);
    return bad;
}

typedef struct {
    double mb, median, p95, worst;
    int lights;
} block;

/* What the soak plays and measures. With random edits, an update's time is the caller's: the edit (which
 * waits for the photon work the last update left running) and lmgi_update, by the wall clock. */
typedef struct {
    lm_random_edits edits; /* used when random */
    int random;
    float budget_ms;
    double worst_ms;        /* the slowest update after the first, and the edit before it */
    int worst_at;
    lm_edit_kind worst_kind;
    lmgi_update_stats worst_stats;
    int over;               /* updates after the first over 10x the budget */
} soak_play;

static int soak(const lm_cli_args *a, lmgi_scene *sc, lmgi_updater *u, int frames, soak_play *p)
{
    lmgi_info in;
    lmgi_get_info(sc, &in);
    int every = p->random ? frames / 10 : frames / 100 < 1000 ? 1000 : frames / 100;
    every = every > frames ? frames : every < 1 ? 1 : every;
    int blocks = (frames + every - 1) / every;
    double *ms = malloc(sizeof *ms * (size_t)every);
    block *b = calloc((size_t)blocks, sizeof *b);
    if (!ms || !b) {
        fprintf(stderr, "lmgi: error: no memory for %d update times\n", every);
        free(ms), free(b);
        return 1;
    }
    if (p->random)
        printf("soak: %s, %d updates at %d x %d, each after a random edit (seed %u; up to %d lights), budget "
               "%.3g ms\n", a->files[0], frames, a->width, a->height, a->seed, a->random_edits,
               (double)p->budget_ms);
    else
        printf("soak: %s, %d updates at %d x %d, the animation (%.3g s) looped at 30 updates a second\n",
               a->files[0], frames, a->width, a->height, (double)in.animation_seconds);
    printf("%10s %12s %8s %12s %12s %12s %12s\n", "updates", "resident MB", "lights", "median ms", "p95 ms",
           "worst ms", "non-finite");
    long bad_total = 0;
    int rc = 0, k = 0;
    for (int f = 0; f < frames && rc == 0; f++) {
        float t = (float)f / 30.0f;
        if (in.animation_seconds > 0.0f)
            t = fmodf(t, in.animation_seconds);
        lmgi_update_stats st;
        lmgi_error e;
        lm_edit_kind kind = LM_EDIT_KINDS;
        double t0 = lm_cli_now();
        if (p->random && lm_random_edit(&p->edits, sc, &kind, &e) != LMGI_OK) {
            fprintf(stderr, "lmgi: error: the random edit before update %d (%s): %s\n", f, lm_edit_kind_name(kind),
                    e.message);
            rc = 1;
            break;
        }
        if (lmgi_update(u, p->random ? 0.0f : t, p->budget_ms, &st, &e) != LMGI_OK) {
            fprintf(stderr, "lmgi: error: update %d: %s\n", f, e.message);
            rc = 1;
            break;
        }
        double took = p->random ? 1e3 * (lm_cli_now() - t0) : st.ms_total;
        if (f > 0 && took > p->worst_ms)
            p->worst_ms = took, p->worst_at = f, p->worst_kind = kind, p->worst_stats = st;
        p->over += f > 0 && p->budget_ms > 0.0f && took > 10.0 * p->budget_ms;
        int w, h;
        const float *rgb = lmgi_frame(u, &w, &h);
        long bad = rgb ? non_finite(rgb, w * h) : 0;
        bad_total += bad;
        ms[k++] = took;
        if (k == every || f + 1 == frames) {
            block *x = &b[f / every];
            x->mb = lm_cli_resident_mb();
            x->lights = lm_random_edits_lights(sc);
            x->p95 = lm_cli_quantile(ms, k, 0.95);
            x->worst = lm_cli_quantile(ms, k, 1.0);
            x->median = lm_cli_median(ms, k);
            printf("%10d %12.1f %8d %12.3f %12.3f %12.3f %12ld\n", f + 1, x->mb, x->lights, x->median, x->p95,
                   x->worst, bad_total);
            fflush(stdout);
            k = 0;
        }
    }
    if (rc == 0 && blocks >= 2) {
        const block *first = &b[1], *last = &b[blocks - 1];
        printf("resident memory %.1f MB after the second block, %.1f MB at the end (%+.1f MB, %+.2f%%)\n",
               first->mb, last->mb, last->mb - first->mb, 100.0 * (last->mb / first->mb - 1.0));
        printf("median update %.3f ms in the second block, %.3f ms in the last (x %.3f)\n", first->median,
               last->median, last->median / first->median);
    }
    if (rc == 0 && p->random) {
        printf("slowest update after the first: %.1f ms (update %d, after: %s)", p->worst_ms, p->worst_at,
               lm_edit_kind_name(p->worst_kind));
        if (p->budget_ms > 0.0f)
            printf(", %.1fx the budget; %d updates over 10x the budget", p->worst_ms / p->budget_ms, p->over);
        const lmgi_update_stats *w = &p->worst_stats;
        printf("\n  its stages (ms): edit and wait %.1f, photons %.1f (of which trace %.1f, AIMs %.1f, caustic "
               "photons %.1f), gather %.1f, blend %.1f, direct %.1f, caustics %.1f, reflections %.1f, composite "
               "%.1f\n  its work: %u texels, %u photons and %u caustic photons traced, %d AIMs refreshed, %d shadow "
               "maps (%d left stale), %d reflection faces\n", p->worst_ms - w->ms_total, w->ms_photons, w->ms_trace,
               w->ms_aim, w->ms_caustic_trace, w->ms_gather, w->ms_blend, w->ms_direct, w->ms_caustics,
               w->ms_reflections, w->ms_composite, w->texels_gathered, w->photons_retraced,
               w->caustic_photons_retraced, w->aim_surfaces_refreshed, w->shadow_maps_rendered, w->shadow_maps_stale,
               w->cube_faces_rendered);
        printf("edits:");
        for (int i = 0; i < LM_EDIT_KINDS; i++)
            printf(" %ld %s%s", p->edits.made[i], lm_edit_kind_name((lm_edit_kind)i), i + 1 < LM_EDIT_KINDS ? "," : "\n");
    }
    printf("non-finite frame values: %ld\n", bad_total);
    free(ms);
    free(b);
    return rc != 0 || bad_total != 0;
}

int lm_cli_bench_soak(const lm_cli_args *a)
{
    lm_cli_args run = *a;
    if (run.file_count == 0)
        run.files[0] = "scenes/cornell.glb", run.file_count = 1;
    if (!run.width)
        run.width = run.height = SOAK_SIZE;
    lmgi_scene *sc = NULL;
    if (!lm_cli_run_load(&run, &sc))
        return 1;
    lmgi_updater_desc d;
    lm_cli_updater_desc(&run, &d);
    lmgi_context *ctx = NULL;
    lmgi_updater *u = NULL;
    lmgi_error e;
    int rc = 1;
    if (lmgi_context_create(NULL, &ctx, &e) != LMGI_OK || lmgi_updater_create(ctx, sc, &d, &u, &e) != LMGI_OK)
        fprintf(stderr, "lmgi: error: %s\n", e.message);
    else {
        soak_play p = {.random = run.random_edits > 0, .budget_ms = run.budget_ms};
        if (p.random && lm_random_edits_init(&p.edits, sc, run.random_edits, run.seed) != 0)
            fprintf(stderr, "lmgi: error: no memory for the random edits\n");
        else
            rc = soak(&run, sc, u, a->soak, &p);
        lm_random_edits_free(&p.edits);
    }
    lmgi_updater_free(u);
    lmgi_context_free(ctx);
    lmgi_free(sc);
    return rc;
}
