/* lmgi-dev bench, photon part: photon tracing against raw Embree on the same scene, the kd-tree next to
 * the paper's Table 1, and the photon stage's frame time on the animated Cornell box. */
#include "bench_photons.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <omp.h>
#include <unistd.h>

#include "../../src/core/qmc.h"
#include "../../src/core/stats.h"
#include "../../src/core/timing.h"
#include "../../src/core/vecmath.h"
#include "../../src/photonmap/kdtree.h"
#include "../../src/api/lmgi_scene.h"
#include "../../src/update/photon_stage.h"

#define REPEATS 5


/* Rays leaving the emitters as photons do (emitter chosen in proportion to its luminance), for the
 * raw-Embree baseline. */
static void emitter_rays(const lmgi_scene *sc, const lm_emitters *em, uint32_t n, float *org, float *dir)
{
    for (uint32_t i = 0; i < n; i++) {
        float u[4];
        for (int k = 0; k < 4; k++)
            u[k] = (float)lm_halton((uint32_t)k, i);
        float pick = (float)lm_halton(4, i) * em->total_luminance, acc = 0.0f;
        int e = 0;
        while (e + 1 < em->count && (acc += em->e[e].luminance) < pick)
            e++;
        lm_emission out;
        lm_emitter_emit(em, sc->scene, e, u, n, &out);
        memcpy(org + 3 * (size_t)i, out.org, sizeof out.org);
        memcpy(dir + 3 * (size_t)i, out.dir, sizeof out.dir);
    }
}

/* The photons' own bounce segments (stored vertex i to vertex i + 1), appended to org/dir from slot
 * `at`; returns the new count. With the emitter rays before them, the baseline casts what the photon
 * tracer casts: coherent rays from the lights and incoherent bounce rays. */
static uint32_t bounce_rays(const lm_photons *ph, float *org, float *dir, uint32_t at, uint32_t cap)
{
    for (uint32_t p = 0; p < lm_photons_count(ph); p++) {
        const lm_path_vertex *v = NULL;
        uint32_t n = lm_photons_path(ph, p, &v);
        for (uint32_t i = 0; i + 1 < n && at < cap; i++, at++) {
            lm_vec3 a = lm_v3_load(v[i].pos), d = lm_normalize(lm_sub(lm_v3_load(v[i + 1].pos), a));
            lm_v3_store(org + 3 * (size_t)at, lm_add(a, lm_scale(d, 1e-4f)));
            lm_v3_store(dir + 3 * (size_t)at, d);
        }
    }
    return at;
}

/* A warm photon set: created and traced once, which also yields the rays to replay (*raw of them,
 * *rays cast per trace). NULL on failure. */
static lm_photons *warm_set(const lmgi_scene *sc, const lm_emitters *em, const lm_photon_settings *set,
                            uint64_t *rays, float **org, float **dir, uint32_t *raw)
{
    lm_photons *ph = NULL;
    lm_photon_frame_stats st;
    lm_error err;
    if (lm_photons_create(sc->scene, &sc->surfaces, sc->rt, em, set, &ph, &err) != LM_OK ||
        lm_photons_trace_all(ph, &st, &err) != LM_OK) {
        printf("failed: %s\n", err.msg);
        lm_photons_free(ph);
        return NULL;
    }
    *rays = st.rays;
    *org = malloc(sizeof(float) * 3 * st.rays);
    *dir = malloc(sizeof(float) * 3 * st.rays);
    if (!*org || !*dir) {
        lm_photons_free(ph);
        return NULL;
    }
    emitter_rays(sc, em, lm_photons_count(ph), *org, *dir);
    *raw = bounce_rays(ph, *org, *dir, lm_photons_count(ph), (uint32_t)st.rays);
    return ph;
}

/* Cold: lm_photons_trace_all of a freshly created photon set (every slab, store slot and trace
 * buffer allocated and page-faulted in during the trace). Returns its seconds, < 0 on failure. */
static double trace_cold(const lmgi_scene *sc, const lm_emitters *em, const lm_photon_settings *set)
{
    lm_photons *ph = NULL;
    lm_photon_frame_stats st;
    lm_error err;
    int ok = lm_photons_create(sc->scene, &sc->surfaces, sc->rt, em, set, &ph, &err) == LM_OK &&
             lm_photons_trace_all(ph, &st, &err) == LM_OK;
    lm_photons_free(ph);
    return ok ? st.seconds : -1.0;
}

/* Warm: lm_photons_reset and a full trace into the memory the set already has, as the runtime
 * re-traces photons (round robin, invalid groups) into a store that keeps its slots. */
static double trace_warm(lm_photons *ph)
{
    lm_photon_frame_stats st;
    lm_error err;
    double t0 = lm_now();
    lm_photons_reset(ph);
    int ok = lm_photons_trace_all(ph, &st, &err) == LM_OK;
    double t = lm_now() - t0;
    return ok ? t : -1.0;
}

/* Full traces of `photons` photons against raw rtcIntersect1 on the same rays (one from an emitter
 * per photon, then the photons' bounce segments): warm (reset, memory kept) and cold (fresh set,
 * creation included). The three alternate, so load on the shared machine hits them alike; each
 * figure is the median of REPEATS. */
static void photon_throughput(const char *path, uint32_t photons)
{
    lmgi_scene *sc = NULL;
    lmgi_error perr;
    if (lmgi_load(path, NULL, &sc, &perr) != LMGI_OK) {
        printf("%-26s skipped (%s)\n", path, perr.message);
        return;
    }
    lm_error err;
    lm_emitters em;
    if (lm_emitters_build(sc->scene, &em, &err) != LM_OK || em.count == 0) {
        printf("%-26s skipped (no emitters)\n", path);
        lmgi_free(sc);
        return;
    }
    lm_photon_settings set;
    lm_photon_settings_default(&set);
    set.total_photons = photons;
    double t_warm[REPEATS], t_cold[REPEATS], t_raw[REPEATS];
    uint64_t rays = 0;
    uint32_t raw = 0;
    float *org = NULL, *dir = NULL;
    lm_photons *ph = warm_set(sc, &em, &set, &rays, &org, &dir, &raw);
    int ok = ph != NULL;
    for (int r = 0; r < REPEATS && ok; r++) {
        t_warm[r] = trace_warm(ph);
        t_cold[r] = trace_cold(sc, &em, &set);
        ok = t_warm[r] >= 0.0 && t_cold[r] >= 0.0;
        double t0 = lm_now();
        if (ok)
            lm_rt_raw_intersect(sc->rt, org, dir, raw);
        t_raw[r] = lm_now() - t0;
    }
    if (ok) {
        double tw = lm_median(t_warm, REPEATS), tc = lm_median(t_cold, REPEATS), tr = lm_median(t_raw, REPEATS);
        uint32_t traced = lm_photons_count(ph);
        const char *name = strrchr(path, '/') ? strrchr(path, '/') + 1 : path;
        printf("%-26s %8u %8.1f %8.1f %9.2f %9.2f %9.2f %7.0f%% %7.0f%%\n", name, traced, 1e3 * tw, 1e3 * tc,
               traced / tw / 1e6, rays / tw / 1e6, raw / tr / 1e6, 100.0 * (rays / tw) / (raw / tr),
               100.0 * (rays / tc) / (raw / tr));
    }
    lm_photons_free(ph);
    free(org);
    free(dir);
    lm_emitters_free(&em);
    lmgi_free(sc);
}

/* The photon stage alone on the animated Cornell box: median frame time and its split. */
static void photon_stage_frames(const char *path, int frames)
{
    lmgi_scene *sc = NULL;
    lmgi_error perr;
    if (lmgi_load(path, NULL, &sc, &perr) != LMGI_OK) {
        printf("photon stage: skipped (%s)\n", perr.message);
        return;
    }
    lm_error err;
    lm_photon_stage *stage = NULL;
    lm_photon_stage_frame setup;
    if (lm_photon_stage_create(&sc->world, NULL, &stage, &setup, &err) != LM_OK) {
        printf("photon stage: failed: %s\n", err.msg);
        lmgi_free(sc);
        return;
    }
    double *t[4];
    for (int k = 0; k < 4; k++)
        t[k] = malloc(sizeof(double) * (size_t)frames);
    uint64_t retraced = 0, refreshed = 0;
    for (int f = 0; f < frames && t[0] && t[1] && t[2] && t[3]; f++) {
        lm_photon_stage_frame r;
        if (lm_photon_stage_step(stage, (float)f / 30.0f, &r, &err) != LM_OK)
            break;
        t[0][f] = r.t_total;
        t[1][f] = r.t_animate;
        t[2][f] = r.t_photons;
        t[3][f] = r.t_aim;
        retraced += r.photons.rr_photons + r.photons.group_photons;
        refreshed += (uint64_t)r.aim.surfaces_refreshed;
    }
    printf("photon stage on %s (%u photons, %u texels, %d frames at 30 fps of animation):\n", path,
           lm_photons_count(lm_photon_stage_photons(stage)), sc->atlas.texel_count, frames);
    printf("  setup: full trace %.1f ms, all AIMs %.1f ms\n", 1e3 * setup.t_photons, 1e3 * setup.t_aim);
    printf("  median frame %.2f ms = animate + BVH %.2f, photons %.2f, AIMs %.2f "
           "(%.1f photons re-traced, %.1f AIM surfaces refreshed per frame)\n",
           1e3 * lm_median(t[0], frames), 1e3 * lm_median(t[1], frames), 1e3 * lm_median(t[2], frames),
           1e3 * lm_median(t[3], frames), (double)retraced / frames, (double)refreshed / frames);
    for (int k = 0; k < 4; k++)
        free(t[k]);
    lm_photon_stage_free(stage);
    lmgi_free(sc);
}

/* Moving a dynamic node: one instance transform and one top-level commit, whatever the scene size. */
static void node_moves(const char *path)
{
    lmgi_scene *sc = NULL;
    lmgi_error perr;
    if (lmgi_load(path, NULL, &sc, &perr) != LMGI_OK)
        return;
    int node = -1;
    for (int i = 0; i < sc->scene->node_count && node < 0; i++)
        if (sc->scene->nodes[i].dynamic && sc->scene->nodes[i].tri_count > 0)
            node = i;
    if (node >= 0) {
        enum { MOVES = 1000 };
        float m[16];
        memcpy(m, sc->scene->nodes[node].world, sizeof m);
        double t0 = lm_now();
        for (int k = 0; k < MOVES; k++) {
            m[12] += 1e-6f;
            lmgi_set_node_transform(sc, node, m, NULL);
        }
        const char *name = strrchr(path, '/') ? strrchr(path, '/') + 1 : path;
        printf("%-26s %9u static triangles, node '%s': %.2f us per move\n", name,
               lm_rt_static_triangle_count(sc->rt), sc->scene->nodes[node].name, 1e6 * (lm_now() - t0) / MOVES);
    }
    lmgi_free(sc);
}

void lm_dev_bench_photons(void)
{
    printf("\nmoving a dynamic node (instance transform + top-level commit), mean of 1000:\n");
    const char *moving[] = {"scenes/cornell.glb", "scenes/two_rooms.glb"};
    for (size_t i = 0; i < sizeof moving / sizeof *moving; i++)
        if (access(moving[i], R_OK) == 0)
            node_moves(moving[i]);
    printf("\nphoton tracing vs raw Embree rtcIntersect1 on the same scene (medians of %d, %d threads):\n", REPEATS,
           omp_get_max_threads());
    printf("warm: reset and re-trace into the set's own memory (what the runtime does); cold: a fresh set\n");
    printf("%-26s %8s %8s %8s %9s %9s %9s %8s %8s\n", "scene", "photons", "warm ms", "cold ms", "Mphot/s",
           "Mrays/s", "raw Mr/s", "warm/raw", "cold/raw");
    const char *scenes[] = {"scenes/cornell.glb", "../shared/scenes/cornell-box/CornellBox.glb",
                            "scenes/two_rooms.glb"};
    for (size_t i = 0; i < sizeof scenes / sizeof *scenes; i++)
        if (access(scenes[i], R_OK) == 0)
            photon_throughput(scenes[i], 200000);
    printf("\nkd-tree (build and 100-nearest query) next to Larsen & Christensen 2004, Table 1:\n");
    lm_kdtree_bench(stdout);
    printf("\n");
    if (access("scenes/cornell.glb", R_OK) == 0)
        photon_stage_frames("scenes/cornell.glb", 120);
}
