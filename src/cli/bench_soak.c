/* lmgi bench --soak: a long run's memory, time and finiteness (bench_soak.h). */
#include "bench_soak.h"

#include <lmgi.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "order_stats.h"
#include "progress.h"
#include "run_cmd.h"

#define SOAK_SIZE 32 /* frame side unless --size */

/* Resident memory of this process in MB (Linux /proc; -1 where it cannot be read). */
static double resident_mb(void)
{
    FILE *f = fopen("/proc/self/statm", "r");
    long pages = 0, rss = 0;
    int ok = f && fscanf(f, "%ld %ld", &pages, &rss) == 2;
    if (f)
        fclose(f);
    return ok ? (double)rss * (double)sysconf(_SC_PAGESIZE) / 1048576.0 : -1.0;
}

static long non_finite(const float *rgb, int n)
{
    long bad = 0;
    for (int i = 0; i < 3 * n; i++)
        bad += !isfinite(rgb[i]);
    return bad;
}

typedef struct {
    double mb, median, p95;
} block;

static int soak(const lm_cli_args *a, lmgi_scene *sc, lmgi_updater *u, int frames)
{
    lmgi_info in;
    lmgi_get_info(sc, &in);
    int every = frames / 100 < 1000 ? 1000 : frames / 100;
    every = every > frames ? frames : every;
    int blocks = (frames + every - 1) / every;
    double *ms = malloc(sizeof *ms * (size_t)every);
    block *b = calloc((size_t)blocks, sizeof *b);
    if (!ms || !b) {
        fprintf(stderr, "lmgi: error: no memory for %d update times\n", every);
        free(ms), free(b);
        return 1;
    }
    printf("soak: %s, %d updates at %d x %d, the animation (%.3g s) looped at 30 updates a second\n", a->files[0],
           frames, a->width ? a->width : SOAK_SIZE, a->height ? a->height : SOAK_SIZE, (double)in.animation_seconds);
    printf("%10s %12s %12s %12s %12s\n", "updates", "resident MB", "median ms", "p95 ms", "non-finite");
    long bad_total = 0;
    int rc = 0, k = 0;
    for (int f = 0; f < frames && rc == 0; f++) {
        float t = (float)f / 30.0f;
        if (in.animation_seconds > 0.0f)
            t = fmodf(t, in.animation_seconds);
        lmgi_update_stats st;
        lmgi_error e;
        if (lmgi_update(u, t, 0.0f, &st, &e) != LMGI_OK) {
            fprintf(stderr, "lmgi: error: update %d: %s\n", f, e.message);
            rc = 1;
            break;
        }
        int w, h;
        const float *rgb = lmgi_frame(u, &w, &h);
        long bad = rgb ? non_finite(rgb, w * h) : 0;
        bad_total += bad;
        ms[k++] = st.ms_total;
        if (k == every || f + 1 == frames) {
            block *x = &b[f / every];
            x->mb = resident_mb();
            x->p95 = lm_cli_quantile(ms, k, 0.95);
            x->median = lm_cli_median(ms, k);
            printf("%10d %12.1f %12.3f %12.3f %12ld\n", f + 1, x->mb, x->median, x->p95, bad_total);
            fflush(stdout);
            k = 0;
        }
    }
    if (rc == 0 && blocks >= 2) {
        const block *first = &b[1], *last = &b[blocks - 1];
        printf("resident memory %.1f MB after the first block, %.1f MB at the end (%+.1f MB, %+.2f%%)\n", first->mb,
               last->mb, last->mb - first->mb, 100.0 * (last->mb / first->mb - 1.0));
        printf("median update %.3f ms in the second block, %.3f ms in the last (x %.3f)\n", first->median,
               last->median, last->median / first->median);
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
    else
        rc = soak(&run, sc, u, a->soak);
    lmgi_updater_free(u);
    lmgi_context_free(ctx);
    lmgi_free(sc);
    return rc;
}
