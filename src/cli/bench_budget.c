#include "bench_budget.h"

#include <lmgi_tools.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "order_stats.h"
#include "progress.h"

#define UPDATES 160
#define SETTLE 10

/* One budget: UPDATES paced updates, the cube sliding; ms[] gets each update's time after SETTLE. */
static int play(lmgi_context *ctx, lmgi_scene *sc, float budget, double *ms, double *texels)
{
    lmgi_updater_desc d = {0};
    lmgi_updater *u = NULL;
    lmgi_error e;
    if (lmgi_updater_create(ctx, sc, &d, &u, &e) != LMGI_OK) {
        fprintf(stderr, "lmgi: bench: %s\n", e.message);
        return 1;
    }
    int cube = lmgi_find_node(sc, "dynamic_cube");
    float start[16], m[16];
    lmgi_get_node_transform(sc, cube, start);
    *texels = 0.0;
    int rc = 0;
    for (int f = 0; f < UPDATES && rc == 0; f++) {
        double t0 = 1e3 * lm_cli_now();
        memcpy(m, start, sizeof m);
        m[12] += 0.3f * sinf(0.1f * (float)f);
        lmgi_update_stats st;
        if (lmgi_set_node_transform(sc, cube, m, &e) != LMGI_OK || lmgi_update(u, 0.0f, budget, &st, &e) != LMGI_OK)
            rc = 1, fprintf(stderr, "lmgi: bench: %s\n", e.message);
        if (f >= SETTLE) {
            ms[f - SETTLE] = st.ms_total;
            *texels += st.texels_gathered;
        }
        struct timespec rest = {0, (long)(1e6 * fmax(0.0, 1e3 / 60.0 - (1e3 * lm_cli_now() - t0)))};
        nanosleep(&rest, NULL);
    }
    lmgi_set_node_transform(sc, cube, start, NULL);
    lmgi_updater_free(u);
    return rc;
}

void lm_cli_bench_budget(void)
{
    static const float budgets[] = {4.0f, 8.0f, 16.0f};
    printf("\nupdate time budget (lmgi_update, scenes/cornell.glb, no frame, the cube moved every update, 60 "
           "updates a second, %d updates):\n", UPDATES - SETTLE);
    printf("%10s %10s %10s %10s %10s %12s\n", "budget", "median", "p95", "worst", "p95/budget", "texels/upd");
    lmgi_context *ctx = NULL;
    lmgi_scene *sc = NULL;
    lmgi_error e;
    lmgi_options o;
    lmgi_options_init(&o);
    o.target_texels = lmgi_atlas_texels_for(0); /* lmgi run's density */
    if (lmgi_context_create(NULL, &ctx, &e) != LMGI_OK || lmgi_load("scenes/cornell.glb", &o, &sc, &e) != LMGI_OK) {
        printf("skipped: %s\n", e.message);
        lmgi_context_free(ctx);
        return;
    }
    double ms[UPDATES], texels;
    const int n = UPDATES - SETTLE;
    for (size_t b = 0; b < sizeof budgets / sizeof *budgets; b++) {
        if (play(ctx, sc, budgets[b], ms, &texels) != 0)
            break;
        double p95 = lm_cli_quantile(ms, n, 0.95); /* sorts ms */
        printf("%8.1fms %8.2fms %8.2fms %8.2fms %10.2f %12.1f\n", (double)budgets[b], ms[n / 2], p95, ms[n - 1],
               p95 / budgets[b], texels / n);
        fflush(stdout);
    }
    lmgi_free(sc);
    lmgi_context_free(ctx);
}
