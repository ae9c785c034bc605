/* lmgi-dev bench, the per-pixel photon gathers (bench_tiled.h). Each figure is the median of REPEATS runs
 * after one untimed run (its shaders compiled, its buffers grown); every run is timed to the end of its
 * GPU work (lm_photon_gather_run's own glFinish). */
#include "bench_tiled.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../../src/api/lmgi_scene.h"
#include "../../src/core/qmc.h"
#include "../../src/core/stats.h"
#include "../../src/gpu/frame/direct.h"
#include "../../src/gpu/gl/gl_context.h"
#include "../../src/gpu/tiled/photon_gather.h"
#include "../../src/photonmap/pixel_gather.h"
#include "../../src/scene/scene_view.h"
#include "../../src/update/photon_stage.h"
#include "dev_scene.h"

#define REPEATS 3
#define BIG_PHOTONS 200000u /* photons traced for the large set (it stores more hits than that) */

/* One photon set of a scene: its stage, its records and the default kernel radius for them. */
typedef struct {
    lm_photon_stage *stage;
    lm_photon_records rec;
    float radius;
} photon_set;

static int make_set(lmgi_scene *sc, uint32_t photons, photon_set *p, lm_error *err)
{
    memset(p, 0, sizeof *p);
    lm_photon_stage_settings set;
    lm_photon_stage_settings_default(&set);
    set.photons.total_photons = photons; /* 0: the default */
    set.aims = 0;                        /* the per-pixel paths fill no AIM */
    if (lm_photon_stage_create(&sc->world, &set, &p->stage, NULL, err) != LM_OK)
        return 0;
    const lm_photon_store *ps = lm_photon_stage_store(p->stage);
    p->radius = lm_pixel_gather_radius(ps, &sc->surfaces, set.aim.n_nearest);
    return lm_photon_records_update(&p->rec, ps, sc->scene, err) == LM_OK;
}

static void free_set(photon_set *p)
{
    lm_photon_records_free(&p->rec);
    lm_photon_stage_free(p->stage);
}

typedef struct {
    double insert, gather, total; /* ms, medians */
    uint64_t entries;
} gather_time;

static int time_gather(int kind, int tile, int k, const photon_set *p, const lm_direct *d, const lm_view *v, int w, int h,
                       gather_time *out, lm_error *err)
{
    lm_photon_gather_settings s;
    lm_photon_gather_settings_default(&s);
    s.kind = kind;
    s.tile = tile;
    s.stochastic = k;
    lm_photon_gather *g = NULL;
    lm_photon_gather_stats st;
    double t[3][REPEATS];
    int ok = lm_photon_gather_create(&s, &g, err) == LM_OK && lm_photon_gather_set_records(g, &p->rec, &st, err) == LM_OK;
    for (int r = -1; ok && r < REPEATS; r++) {
        ok = lm_photon_gather_run(g, v, w, h, lm_direct_kd_texture(d, 0), lm_direct_gbuffer_texture(d), p->radius,
                                  (unsigned)(r + 1), &st, err) == LM_OK;
        if (ok && r >= 0)
            t[0][r] = 1e3 * st.t_insert, t[1][r] = 1e3 * st.t_gather, t[2][r] = 1e3 * (st.t_insert + st.t_gather);
    }
    lm_photon_gather_free(g);
    if (!ok)
        return 0;
    out->insert = lm_median(t[0], REPEATS), out->gather = lm_median(t[1], REPEATS);
    out->total = lm_median(t[2], REPEATS);
    out->entries = st.entries;
    return 1;
}

/* The four gathers (brute force only at small sizes) at w x h from the scene's own camera. */
static void print_size(lmgi_scene *sc, const photon_set *p, lm_direct *d, int w, int h, const char *paper_tiled,
                       const char *paper_hash)
{
    lm_view v;
    lm_error err;
    lm_view_for_scene(sc->scene, -1, w, h, &v);
    const lm_emitters *em = lm_photon_stage_emitters(p->stage);
    if (lm_direct_draw(d, sc->scene, em, &v, w, h, &err) != LM_OK) {
        printf("  %d x %d: skipped (%s)\n", w, h, err.msg);
        return;
    }
    static const struct {
        const char *name;
        int kind, tile, k;
    } runs[8] = {{"tiled", LM_PHOTON_GATHER_TILED, 16, 1},
                 {"tiled, stochastic k = 2", LM_PHOTON_GATHER_TILED, 16, 2},
                 {"hash grid", LM_PHOTON_GATHER_HASHGRID, 16, 1},
                 {"brute force", LM_PHOTON_GATHER_BRUTEFORCE, 16, 1},
                 {"tiled, stochastic k = 4", LM_PHOTON_GATHER_TILED, 16, 4},
                 {"tiled, 4 px tiles", LM_PHOTON_GATHER_TILED, 4, 1},
                 {"tiled, 8 px tiles", LM_PHOTON_GATHER_TILED, 8, 1},
                 {"tiled, 32 px tiles", LM_PHOTON_GATHER_TILED, 32, 1}};
    double tiled = 0.0, hash = 0.0, pixels = (double)w * h;
    for (int i = 0; i < (w == 512 ? 8 : 5); i++) {
        if (runs[i].kind == LM_PHOTON_GATHER_BRUTEFORCE && pixels * p->rec.live > 1e9) {
            printf("  %4d x %-4d  %-24s %9s %9s %9s  (pixels x photons %.2g: not run)\n", w, h, runs[i].name, "-",
                   "-", "-", pixels * p->rec.live);
            continue;
        }
        gather_time t;
        if (!time_gather(runs[i].kind, runs[i].tile, runs[i].k, p, d, &v, w, h, &t, &err)) {
            printf("  %d x %d %s: %s\n", w, h, runs[i].name, err.msg);
            continue;
        }
        /* candidates per pixel: the records a tiled pixel tests (its tile's list, its class's share) */
        double cand = runs[i].kind == LM_PHOTON_GATHER_TILED
                          ? (double)t.entries * runs[i].tile * runs[i].tile / pixels / (runs[i].k * runs[i].k)
                          : 0.0;
        printf("  %4d x %-4d  %-24s %9.1f %9.1f %9.1f", w, h, runs[i].name, t.insert, t.gather, t.total);
        if (cand > 0.0)
            printf("  %7.0f candidates/px, %.2f ns per pixel x candidate", cand, 1e6 * t.total / (pixels * cand));
        if (i == 4 && *paper_tiled)
            printf("  (paper: %s)", paper_tiled);
        if (i == 2 && *paper_hash)
            printf("  (paper: %s)", paper_hash);
        printf("\n");
        tiled = i == 0 ? t.total : tiled;
        hash = i == 2 ? t.total : hash;
    }
    if (tiled > 0.0 && hash > 0.0)
        printf("  %4d x %-4d  hash grid / tiled: %.2f (target >= 3)\n", w, h, hash / tiled);
}

static void print_scene(lmgi_scene *sc, const char *path, uint32_t photons)
{
    photon_set p;
    lm_direct *d = NULL;
    lm_error err;
    if (!make_set(sc, photons, &p, &err) || lm_direct_create(sc->scene, &sc->atlas, NULL, &d, &err) != LM_OK) {
        printf("photon gathers on %s: skipped (%s)\n", path, err.msg);
        free_set(&p);
        return;
    }
    printf("\n%s, %u photon hits gathered (records of 20 bytes), radius %.4g; ms, median of %d:\n", path, p.rec.live,
           (double)p.radius, REPEATS);
    printf("  %-11s  %-24s %9s %9s %9s\n", "size", "gather", "insert", "gather", "total");
    print_size(sc, &p, d, 128, 128, "", "");
    print_size(sc, &p, d, 512, 512, "", "");
    print_size(sc, &p, d, 1920, 1080, "11-28, k = 4, 262k-815k photons", "36-79");
    lm_direct_free(d);
    free_set(&p);
}

void lm_dev_bench_tiled(void)
{
    lm_gl_context *gl = NULL;
    lm_error err;
    if (lm_gl_context_create(&gl, &err) != LM_OK) {
        printf("\nphoton gathers: skipped (%s)\n", err.msg);
        return;
    }
    lm_qmc_init();
    const char *path = "scenes/cornell.glb";
    lmgi_scene *sc = lm_dev_load(path, lmgi_atlas_texels_for(0));
    if (sc) {
        printf("\nper-pixel photon gathers (docs/tiled.md) on %s, the scene's own camera; the paper: Mara et al. "
               "2013, GTX 670\n", lm_gl_context_description(gl));
        print_scene(sc, path, 0);
        print_scene(sc, path, BIG_PHOTONS);
        lmgi_free(sc);
    } else {
        printf("\nphoton gathers on %s: skipped (not loaded)\n", path);
    }
    lm_gl_context_destroy(gl);
}
