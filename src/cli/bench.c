#include "bench.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "order_stats.h"
#include "bench_budget.h"
#include "bench_edits.h"
#include "bench_soak.h"
#include "out_dir.h"
#include "bench_scenes.h"

/* Scenes timed when none are named: ours first, then the shared ones (skipped when absent). */
static const char *DEFAULT_SCENES[] = {
    "scenes/cornell.glb",
    "scenes/two_rooms.glb",
    "scenes/many_rooms.glb",
    "../shared/scenes/cornell-box/CornellBox.glb",
    "../shared/scenes/room/IrradianceVolumeExample.glb",
    "../shared/scenes/depth-of-field/DepthOfFieldExample.glb",
    "../shared/scenes/mixed-lighting/MixedLightingExample.gltf",
    "../shared/scenes/cornell-suzanne/cornellBox-2.80-Eevee-gltf.gltf",
};

typedef struct {
    const char *path;
    lmgi_info info;   /* counts of the last run, timings = medians */
} result;


/* Loads `path` a->repeats times; fills r with the median of each stage. Returns 0 on success. */
static int time_scene(const lm_cli_args *a, const char *path, result *r)
{
    enum { STAGES = 8 };
    double t[STAGES][100];
    memset(r, 0, sizeof *r);
    r->path = path;
    for (int k = 0; k < a->repeats; k++) {
        lmgi_scene *sc = NULL;
        lmgi_error err;
        if (lmgi_load(path, &a->options, &sc, &err) != LMGI_OK) {
            fprintf(stderr, "lmgi: bench: %s\n", err.message);
            return 1;
        }
        lmgi_get_info(sc, &r->info);
        const lmgi_timings *tm = &r->info.timings;
        double v[STAGES] = {tm->load, tm->surfaces, tm->unwrap, tm->pack, tm->texels, tm->atlas, tm->bvh, tm->total};
        for (int s = 0; s < STAGES; s++)
            t[s][k] = v[s];
        lmgi_free(sc);
    }
    lmgi_timings *m = &r->info.timings;
    double *fields[STAGES] = {&m->load, &m->surfaces, &m->unwrap, &m->pack, &m->texels, &m->atlas, &m->bvh, &m->total};
    for (int s = 0; s < STAGES; s++)
        *fields[s] = lm_cli_median(t[s], a->repeats);
    return 0;
}

const char *lm_cli_base_name(const char *p)
{
    const char *s = strrchr(p, '/');
    return s ? s + 1 : p;
}

static void print_header(void)
{
    printf("%-34s %9s %8s %8s %8s %8s %8s %8s %8s %8s %9s %6s\n", "scene", "triangles", "load", "surfaces",
           "unwrap", "pack", "texels", "atlas", "BVH", "total", "texels#", "util%");
}

static void print_row(const result *r)
{
    const lmgi_timings *t = &r->info.timings;
    printf("%-34s %9u %7.1fms %7.1fms %7.1fms %7.1fms %7.1fms %7.1fms %7.1fms %7.1fms %9u %6.1f\n",
           lm_cli_base_name(r->path), r->info.triangles, 1e3 * t->load, 1e3 * t->surfaces, 1e3 * t->unwrap,
           1e3 * t->pack, 1e3 * t->texels, 1e3 * t->atlas, 1e3 * t->bvh, 1e3 * t->total, r->info.texels,
           100.0 * (double)r->info.utilization);
}

/* Growth table: time / (n log2 n) relative to the smallest scene. A ratio that stays near or below 1
 * as n grows means the cost grows no faster than n log n. */
static void print_scaling(const result *r, int n)
{
    printf("\nscaling (file to atlas and BVH; time / (n log2 n), relative to the first):\n");
    printf("%-34s %9s %9s %10s %8s\n", "scene", "triangles", "total", "per tri", "ratio");
    double base = 0.0;
    for (int i = 0; i < n; i++) {
        double tri = r[i].info.triangles > 1 ? r[i].info.triangles : 2;
        double norm = r[i].info.timings.total / (tri * log2(tri));
        if (i == 0)
            base = norm;
        printf("%-34s %9u %8.3fs %8.2fus %8.2f\n", lm_cli_base_name(r[i].path), r[i].info.triangles,
               r[i].info.timings.total, 1e6 * r[i].info.timings.total / tri, norm / base);
    }
}

static int write_json(const lm_cli_args *a, const result *r, int n, const result *sr, int sn)
{
    lm_cli_single out;
    if (!lm_cli_single_open(&out))
        return 0;
    FILE *f = out.f;
    fprintf(f, "{\n  \"scenes\": [\n");
    for (int pass = 0; pass < 2; pass++) {
        const result *list = pass ? sr : r;
        int count = pass ? sn : n;
        if (pass)
            fprintf(f, "  ],\n  \"scaling\": [\n");
        for (int i = 0; i < count; i++) {
            const lmgi_timings *t = &list[i].info.timings;
            fprintf(f, "    {\"scene\": \"%s\", \"triangles\": %u, \"texels\": %u, \"surfaces\": %d, \"charts\": %d, "
                    "\"utilization\": %.4f, \"load_s\": %.6f, \"surfaces_s\": %.6f, \"unwrap_s\": %.6f, "
                    "\"pack_s\": %.6f, \"texels_s\": %.6f, \"atlas_s\": %.6f, \"bvh_s\": %.6f, \"total_s\": %.6f}%s\n",
                    list[i].path, list[i].info.triangles, list[i].info.texels, list[i].info.surfaces,
                    list[i].info.charts, (double)list[i].info.utilization, t->load, t->surfaces, t->unwrap, t->pack,
                    t->texels, t->atlas, t->bvh, t->total, i + 1 < count ? "," : "");
        }
    }
    fprintf(f, "  ]\n}\n");
    return lm_cli_single_close(a, a->json_path, &out);
}

/* A scene named on the command line must be there: it is skipped only in the default list, whose shared
 * scenes may be absent (a named one that is not there ended a bench with nothing timed and exit 0). */
static int named_scenes_readable(const lm_cli_args *a)
{
    for (int i = 0; i < a->file_count; i++)
        if (access(a->files[i], R_OK) != 0) {
            fprintf(stderr, "lmgi: error: %s: cannot open file: %s\n", a->files[i], strerror(errno));
            return 0;
        }
    return 1;
}

int lm_cli_bench(const lm_cli_args *a)
{
    if (!named_scenes_readable(a))
        return 1;
    if (a->edits_path)
        return lm_cli_bench_edits(a);
    if (a->soak)
        return lm_cli_bench_soak(a);
    const char *const *files = a->files;
    int count = a->file_count;
    if (count == 0) {
        files = DEFAULT_SCENES;
        count = (int)(sizeof DEFAULT_SCENES / sizeof *DEFAULT_SCENES);
    }
    if (a->json_path && !lm_cli_single_allowed(a, a->json_path))
        return 1;
    result *res = calloc((size_t)count + (size_t)a->scaling_count + 1, sizeof *res);
    if (!res)
        return 1;
    int n = 0, rc = 0;
    printf("lmgi bench: medians of %d runs per scene\n", a->repeats);
    print_header();
    for (int i = 0; i < count; i++) {
        if (access(files[i], R_OK) != 0) {
            printf("%-34s skipped (not found: %s)\n", lm_cli_base_name(files[i]), files[i]);
            continue;
        }
        if (time_scene(a, files[i], &res[n]) != 0) {
            rc = 1;
            continue;
        }
        print_row(&res[n]);
        fflush(stdout);
        n++;
    }
    result *sr = res + n;
    int sn = 0;
    for (int i = 0; i < a->scaling_count; i++) {
        if (time_scene(a, a->scaling[i], &sr[sn]) != 0) {
            rc = 1;
            continue;
        }
        sn++;
    }
    if (sn > 0)
        print_scaling(sr, sn);
    if (a->json_path && !write_json(a, res, n, sr, sn))
        rc = 1;
    free(res);
    if (a->file_count == 0) {
        lm_cli_bench_budget();
        lm_cli_bench_scenes();
    }
    return rc;
}
