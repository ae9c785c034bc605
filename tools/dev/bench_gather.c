/* lmgi-dev bench, gather part (bench_gather.h). Each figure is the median over REPEATS alternating runs
 * of one full pass (PASS texels spread over the atlas), glFinish included. */
#include "bench_gather.h"

#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../../src/core/stats.h"
#include "../../src/core/timing.h"
#include "../../src/core/vecmath.h"
#include "../../src/gpu/gl/gl_context.h"
#include "../../src/gpu/gather/hemicube.h"
#include "../../src/photonmap/aim.h"
#include "../../src/api/lmgi_scene.h"
#include "../../src/update/frame_loop.h"
#include "../../src/update/photon_stage.h"
#include "dev_scene.h"

#define REPEATS 5
#define LM_DEV_RAY_STRATA 400 /* lm_hemicube_settings_default's ray_samples */
#define PASS 256
#define RAYS_SIDE 32 /* 32 x 32 = 1,024 rays, the paper's ray-traced alternative */

typedef struct {
    const char *label;
    int paper_row;         /* Table 2 row group: 34, 13,000, 133,000 polygons */
    lmgi_scene *sc;
    lm_photon_stage *stage;
    const float *aim;      /* dilated AIM (atlas RGBA, the photon stage's) */
    const float *rest;     /* the same less the suns' direct part, for the rays with the sun at their hits
                              (NULL: the AIMs compute no sun) */
    lm_emitter_light el;   /* with has_el: the closed-form emitter light the frame loop would take */
    int has_el;
    uint32_t texels[PASS];
    uint32_t count;
} bench_scene;

static int open_scene(const char *label, int paper_row, const char *path, bench_scene *b)
{
    memset(b, 0, sizeof *b);
    b->label = label;
    b->paper_row = paper_row;
    if (!(b->sc = lm_dev_load(path, 0)))
        return 0;
    lm_photon_stage_settings set;
    lm_photon_stage_settings_default(&set);
    set.direct_at_hits = 1; /* as the frame loop's rays scheme sets it */
    lm_error err;
    const lm_atlas *a = &b->sc->atlas;
    if (lm_photon_stage_create(&b->sc->world, &set, &b->stage, NULL, &err) != LM_OK) {
        printf("%s: %s\n", label, err.msg);
        return 0;
    }
    b->aim = lm_aim_dilated_rgba(lm_photon_stage_aim(b->stage));
    b->rest = lm_aim_rest_dilated_rgba(lm_photon_stage_aim(b->stage));
    b->has_el = lm_emitter_light_suits(b->sc->scene) &&
                lm_emitter_light_init(&b->el, b->sc->scene, b->sc->rt, LM_EMITTER_LIGHT_DEFAULT_RAYS, &err) == LM_OK;
    /* a pass of a ~100k-triangle scene without the proxy takes seconds: a quarter pass there */
    uint32_t pass = b->sc->scene->tri_count > 50000 ? PASS / 4 : PASS;
    b->count = a->texel_count < pass ? a->texel_count : pass;
    for (uint32_t i = 0; i < b->count; i++) /* spread over the atlas */
        b->texels[i] = (uint32_t)(((uint64_t)i * a->texel_count) / b->count);
    return 1;
}

static void close_scene(bench_scene *b)
{
    if (b->has_el)
        lm_emitter_light_free(&b->el);
    lm_photon_stage_free(b->stage);
    lmgi_free(b->sc);
}

/* A gather set up for one configuration (NULL on failure, with the reason printed). single: one AIM
 * lookup and one coverage sample per pixel, emitters drawn (the paper's hemicube), else what the frame
 * loop takes for the scene: 4 AIM lookups, the emitters' light in closed form where it suits the scene
 * and then 1 coverage sample, else as lm_gather_coverage_for says. */
static lm_gather *gather_traced(const bench_scene *b, int R, int proxy, lm_gather_scheme scheme, int single,
                                int traced, int *tris);
static lm_gather *gather_for(const bench_scene *b, int R, int proxy, lm_gather_scheme scheme, int single, int *tris)
{
    return gather_traced(b, R, proxy, scheme, single, scheme == LM_GATHER_RAYS, tris);
}

/* As gather_for; traced: the rim (and the rays scheme) traced with the scene's Embree scene, as the frame
 * loop does. */
static lm_gather *gather_traced(const bench_scene *b, int R, int proxy, lm_gather_scheme scheme, int single,
                                int traced, int *tris)
{
    lm_hemicube_settings set;
    lm_hemicube_settings_default(&set);
    set.resolution = R;
    set.scheme = scheme;
    if (single)
        set.samples = set.coverage_samples = 1;
    else
        set.coverage_samples = lm_gather_coverage_for(b->sc->scene, b->has_el);
    if (!proxy)
        set.proxy_error = 0.0f;
    lm_gather *g = NULL;
    lm_error err;
    if (lm_gather_create(&set, &g, &err) == LM_OK && !single && b->has_el)
        lm_gather_set_emitter_light(g, &b->el);
    if (g && traced)
        lm_gather_set_tracer(g, b->sc->rt);
    if (!g || lm_gather_set_scene(g, b->sc->scene, &b->sc->atlas, &err) != LM_OK ||
        lm_gather_set_aim_dilated(g, &b->sc->atlas, b->aim, &err) != LM_OK) {
        printf("  %s: %s\n", b->label, err.msg);
        lm_gather_free(g);
        return NULL;
    }
    *tris = lm_gather_proxy(g) ? (int)lm_gather_proxy(g)->tri_count : (int)b->sc->scene->tri_count;
    return g;
}

/* The rays gather g with the sun's light taken at its hits, as the frame loop's (docs/gather.md, "Rays"),
 * where the AIMs compute a sun; g is freed and NULL returned on failure. */
static lm_gather *sun_at_hits(lm_gather *g, const bench_scene *b)
{
    lm_error err;
    if (!g || !b->rest)
        return g;
    lm_gather_set_direct_at_hits(g, lm_photon_stage_direct(b->stage));
    if (lm_gather_set_aim_dilated(g, &b->sc->atlas, b->rest, &err) == LM_OK)
        return g;
    printf("  %s: %s\n", b->label, err.msg);
    lm_gather_free(g);
    return NULL;
}

/* Seconds for one pass of b's texels. */
static double time_pass(lm_gather *g, const bench_scene *b, unsigned iim)
{
    lm_gather_stats gs;
    lm_error err;
    if (lm_gather_texels(g, b->sc->scene, &b->sc->atlas, b->texels, b->count, iim, &gs, &err) != LM_OK) {
        printf("  gather failed: %s\n", err.msg);
        return NAN;
    }
    return gs.seconds;
}

/* Median ms per texel of each of n configurations, their runs alternating. */
static void time_configs(lm_gather **g, int n, const bench_scene *b, double *ms_per_texel)
{
    unsigned iim = lm_iim_texture_create(b->sc->atlas.width, b->sc->atlas.height);
    double runs[8][REPEATS];
    for (int k = 0; k < n; k++)
        if (g[k])
            time_pass(g[k], b, iim); /* warm-up: shader variants, caches */
    for (int r = 0; r < REPEATS; r++)
        for (int k = 0; k < n; k++)
            runs[k][r] = g[k] ? time_pass(g[k], b, iim) : NAN;
    for (int k = 0; k < n; k++)
        ms_per_texel[k] = g[k] ? 1e3 * lm_median(runs[k], REPEATS) / b->count : NAN;
    lm_iim_texture_free(iim);
}

/* Bilinear AIM lookup at a lightmap UV (the dilated atlas, as the GPU samples it). */
static lm_vec3 aim_at(const lm_atlas *a, const float *aim, float u, float v)
{
    float x = u * a->width - 0.5f, y = v * a->height - 0.5f;
    int x0 = (int)floorf(x), y0 = (int)floorf(y);
    float fx = x - x0, fy = y - y0;
    lm_vec3 s = lm_v3(0, 0, 0);
    for (int j = 0; j < 2; j++)
        for (int i = 0; i < 2; i++) {
            int xi = x0 + i < 0 ? 0 : x0 + i >= a->width ? a->width - 1 : x0 + i;
            int yj = y0 + j < 0 ? 0 : y0 + j >= a->height ? a->height - 1 : y0 + j;
            float w = (i ? fx : 1 - fx) * (j ? fy : 1 - fy);
            s = lm_add(s, lm_scale(lm_v3_load(aim + 4 * ((size_t)yj * a->width + xi)), w));
        }
    return s;
}

/* The paper's alternative: 1,024 stratified cosine-distributed rays from the texel, each hit's AIM
 * radiance (plus emission) averaged: E = pi / N * sum L. Returns E's green channel (kept so the work
 * is not optimized away). */
static double ray_gather(const bench_scene *b, uint32_t texel)
{
    const lm_atlas *a = &b->sc->atlas;
    const lm_scene *s = b->sc->scene;
    const lm_texel *t = &a->texels[texel];
    lm_vec3 n = lm_normalize(lm_v3_load(t->normal));
    lm_vec3 tx, ty;
    lm_tangents(n, &tx, &ty);
    lm_vec3 org = lm_add(lm_v3_load(t->pos), lm_scale(n, 1e-4f * lm_scene_size(s)));
    double sum = 0.0;
    for (int j = 0; j < RAYS_SIDE; j++)
        for (int i = 0; i < RAYS_SIDE; i++) {
            float u1 = (i + 0.5f) / RAYS_SIDE, u2 = (j + 0.5f) / RAYS_SIDE, r = sqrtf(u1), phi = 6.2831853f * u2;
            lm_vec3 d = lm_add(lm_add(lm_scale(tx, r * cosf(phi)), lm_scale(ty, r * sinf(phi))),
                               lm_scale(n, sqrtf(fmaxf(0.0f, 1.0f - u1))));
            float o[3], dv[3];
            lm_v3_store(o, org);
            lm_v3_store(dv, d);
            lm_rt_hit h;
            if (!lm_rt_intersect(b->sc->rt, o, dv, 0.0f, INFINITY, &h))
                continue;
            const float *uv = a->corner_uv + 6 * (size_t)h.tri;
            float w0 = 1.0f - h.u - h.v;
            lm_vec3 L = lm_v3(0, 0, 0);
            if (a->tri_chart[h.tri] >= 0)
                L = aim_at(a, b->aim, w0 * uv[0] + h.u * uv[2] + h.v * uv[4], w0 * uv[1] + h.u * uv[3] + h.v * uv[5]);
            sum += L.y + s->materials[s->tri_material[h.tri]].emissive[1];
        }
    return LM_PI * sum / (RAYS_SIDE * RAYS_SIDE);
}

/* ms per texel for the ray-cast gather of b's texels: one thread, and spread over the OpenMP threads. */
static void time_rays(const bench_scene *b, double *one, double *all)
{
    double r1[REPEATS], r2[REPEATS], sink = 0.0;
    for (int r = 0; r < REPEATS; r++) {
        double t0 = lm_now();
        for (uint32_t i = 0; i < b->count; i++)
            sink += ray_gather(b, b->texels[i]);
        double t1 = lm_now();
#pragma omp parallel for reduction(+ : sink) schedule(dynamic, 8)
        for (uint32_t i = 0; i < b->count; i++)
            sink += ray_gather(b, b->texels[i]);
        r1[r] = t1 - t0;
        r2[r] = lm_now() - t1;
    }
    *one = 1e3 * lm_median(r1, REPEATS) / b->count;
    *all = 1e3 * lm_median(r2, REPEATS) / b->count + 0.0 * sink;
}

/* A second GL context on a second thread: each of `threads` contexts gathers its share of the pass (the
 * scene, AIM and IIM of its own), all at once. Seconds per repetition, median. */
typedef struct {
    const bench_scene *b;
    uint32_t first, count;
    double seconds[REPEATS];
    int ok;
} context_job;

static void *context_worker(void *arg)
{
    context_job *j = arg;
    lm_gl_context *gl = NULL;
    lm_error err;
    int tris;
    if (lm_gl_context_create(&gl, &err) != LM_OK)
        return NULL;
    lm_hemicube_settings def;
    lm_hemicube_settings_default(&def);
    lm_gather *g = gather_for(j->b, 32, 1, def.scheme, 0, &tris);
    unsigned iim = lm_iim_texture_create(j->b->sc->atlas.width, j->b->sc->atlas.height);
    lm_gather_stats gs;
    for (int r = 0; g && r <= REPEATS; r++) { /* r = 0 warms up */
        if (lm_gather_texels(g, j->b->sc->scene, &j->b->sc->atlas, j->b->texels + j->first, j->count, iim, &gs,
                             &err) != LM_OK)
            break;
        if (r > 0)
            j->seconds[r - 1] = gs.seconds;
        j->ok = r == REPEATS;
    }
    lm_iim_texture_free(iim);
    lm_gather_free(g);
    lm_gl_context_destroy(gl);
    return NULL;
}

/* Wall ms per texel with `threads` contexts splitting the pass (each thread's runs paired by index). */
static double time_contexts(const bench_scene *b, int threads)
{
    context_job jobs[2];
    pthread_t tid[2];
    double wall[REPEATS];
    for (int k = 0; k < threads; k++) {
        memset(&jobs[k], 0, sizeof jobs[k]);
        jobs[k].b = b;
        jobs[k].first = b->count * (uint32_t)k / (uint32_t)threads;
        jobs[k].count = b->count * (uint32_t)(k + 1) / (uint32_t)threads - jobs[k].first;
        pthread_create(&tid[k], NULL, context_worker, &jobs[k]);
    }
    for (int k = 0; k < threads; k++)
        pthread_join(tid[k], NULL);
    int all_ok = 1;
    for (int k = 0; k < threads; k++)
        all_ok &= jobs[k].ok;
    for (int r = 0; r < REPEATS; r++) { /* the slower context sets the wall time; a failed one: none */
        wall[r] = all_ok ? 0.0 : NAN;
        for (int k = 0; all_ok && k < threads; k++)
            wall[r] = fmax(wall[r], jobs[k].seconds[r]);
    }
    return 1e3 * lm_median(wall, REPEATS) / b->count;
}

static void print_contexts(bench_scene *sc, int n)
{
    printf("\ncontexts, R = 32 with the proxy, the defaults, ms per texel of wall time (median of %d):\n", REPEATS);
    printf("%-24s %12s %12s\n", "scene", "1 context", "2 contexts");
    for (int s = 0; s < n; s++)
        printf("%-24s %12.3f %12.3f\n", sc[s].label, time_contexts(&sc[s], 1), time_contexts(&sc[s], 2));
}

static void print_table2(bench_scene *sc, int n)
{
    /* Larsen & Christensen 2004, Table 2 (ms per texel) for 34, 13,000, 133,000 polygons, R = 8, 16, 32 */
    static const double PAPER[3][3] = {{0.75, 0.76, 0.78}, {0.90, 0.91, 0.97}, {1.55, 1.57, 1.59}};
    printf("\nfinal gather, ms per texel (median of %d passes of %d texels, %d above 50k triangles; def = the frame "
           "loop's defaults for the scene: 4 AIM lookups per pixel, a small emitter's light in closed form with 1 "
           "coverage sample, else 4 coverage samples where the scene has emitters; 1x1 = one AIM lookup and one "
           "coverage sample, emitters drawn: the paper's hemicube; paper = Larsen & Christensen 2004, Table 2):\n",
           REPEATS, PASS, PASS / 4);
    printf("%-24s %9s %4s %11s %11s %11s %10s %11s %11s %7s\n", "scene", "triangles", "R", "full def", "proxy def",
           "proxy 1x1", "proxy tris", "def tex/s", "1x1 tex/s", "paper");
    for (int s = 0; s < n; s++) {
        for (int r = 0; r < 3; r++) {
            int R = 8 << r, tris[3] = {0, 0, 0};
            lm_gather *g[3] = {gather_for(&sc[s], R, 0, LM_GATHER_VIEWPORTS, 0, &tris[0]),
                               gather_for(&sc[s], R, 1, LM_GATHER_VIEWPORTS, 0, &tris[1]),
                               gather_for(&sc[s], R, 1, LM_GATHER_VIEWPORTS, 1, &tris[2])};
            double ms[3];
            time_configs(g, 3, &sc[s], ms);
            printf("%-24s %9d %4d %11.3f %11.3f %11.3f %10d %11.0f %11.0f %7.2f\n", sc[s].label, tris[0], R, ms[0],
                   ms[1], ms[2], tris[1], 1e3 / ms[1], 1e3 / ms[2], PAPER[sc[s].paper_row][r]);
            fflush(stdout);
            for (int k = 0; k < 3; k++)
                lm_gather_free(g[k]);
        }
    }
}

static void print_schemes(bench_scene *sc, int n)
{
    printf("\npass schemes, R = 32 with the proxy, one AIM lookup and one coverage sample per pixel (the layered "
           "scheme has no multisampled target), ms per texel (median of %d passes of %d texels):\n", REPEATS, PASS);
    printf("%-24s %12s %12s %12s\n", "scene", "viewports", "instanced", "layered");
    for (int s = 0; s < n; s++) {
        lm_gather *g[3];
        int tris;
        for (int k = 0; k < 3; k++)
            g[k] = gather_for(&sc[s], 32, 1, (lm_gather_scheme)k, 1, &tris);
        double ms[3];
        time_configs(g, 3, &sc[s], ms);
        printf("%-24s %12.3f %12.3f %12.3f\n", sc[s].label, ms[0], ms[1], ms[2]);
        for (int k = 0; k < 3; k++)
            lm_gather_free(g[k]);
    }
}

static void print_rays(bench_scene *sc, int n)
{
    printf("\nEmbree ray-cast gather, %d rays per texel, ms per texel (paper: 16.7 ms for 1,024 rays, 8,000 "
           "polygons):\n", RAYS_SIDE * RAYS_SIDE);
    printf("%-24s %9s %12s %12s %14s\n", "scene", "triangles", "1 thread", "all threads", "GPU (proxy)");
    for (int s = 0; s < n; s++) {
        double one, all, gpu;
        int tris;
        lm_hemicube_settings def;
        lm_hemicube_settings_default(&def);
        lm_gather *g = gather_for(&sc[s], 32, 1, def.scheme, 0, &tris);
        time_configs(&g, 1, &sc[s], &gpu);
        lm_gather_free(g);
        time_rays(&sc[s], &one, &all);
        printf("%-24s %9u %12.3f %12.3f %14.3f\n", sc[s].label, sc[s].sc->scene->tri_count, one, all, gpu);
    }
}

/* The whole frame loop on the animated Cornell box at its defaults (512 x 512, 20 texels per frame):
 * median ms per stage over FRAMES frames at 30 fps of animation, overlapped (the default) and in the
 * paper's order. */
#define FRAMES 60
static void print_frame_mode(lmgi_scene *sc, const char *path, int overlap)
{
    lm_frame_loop_settings set;
    lm_frame_loop_settings_default(&set);
    set.overlap = overlap;
    lm_frame_loop *fl = NULL;
    lm_error err;
    double t_setup = 0.0;
    if (lm_frame_loop_create(&sc->world, &set, &fl, NULL, &t_setup, &err) != LM_OK) {
        printf("\nframe loop: %s\n", err.msg);
        return;
    }
    static double t[6][FRAMES];
    int n = 0;
    for (; n < FRAMES; n++) {
        lm_frame_stats o;
        if (lm_frame_loop_step(fl, (float)n / 30.0f, &o, &err) != LM_OK) {
            printf("frame %d: %s\n", n, err.msg);
            break;
        }
        const double v[6] = {o.t_photons, o.t_gather, o.t_blend, o.t_direct, o.t_composite, o.t_total};
        for (int k = 0; k < 6; k++)
            t[k][n] = 1e3 * v[k];
    }
    if (n > 0) {
        double m[6];
        for (int k = 0; k < 6; k++)
            m[k] = lm_median(t[k], n);
        printf("\nframe loop on %s, %u atlas texels, %s, %dx%d, %d texels per frame (median of %d frames; first "
               "full gather %.1f s):\n", path, sc->atlas.texel_count,
               overlap ? "photon stage overlapped (default)" : "in the paper's order", set.width, set.height,
               set.iim.texels_per_frame, n, t_setup);
        printf("  frame %.1f ms = %.1f fps (target 35 fps): photons + AIMs %s %.1f, gather %.1f, blend %.1f, "
               "direct + indirect + read-back %.1f, indirect atlas %.1f\n", m[5], 1e3 / m[5],
               overlap ? "(waited for)" : "", m[0], m[1], m[2], m[3], m[4]);
    }
    lm_frame_loop_free(fl);
}

static void print_frame(void)
{
    const char *path = "scenes/cornell.glb";
    /* lmgi run's atlas (its texel budget regathers it in full every 3 s), then a bake's 64k texels */
    const int targets[2] = {lm_frame_loop_atlas_texels(LM_IIM_DEFAULT_TEXELS_PER_FRAME), 0};
    for (int k = 0; k < 2; k++) {
        lmgi_scene *sc = lm_dev_load(path, targets[k]);
        if (!sc) {
            printf("\nframe loop: skipped (%s not loaded)\n", path);
            return;
        }
        print_frame_mode(sc, path, 1);
        if (k == 0)
            print_frame_mode(sc, path, 0);
        lmgi_free(sc);
    }
}

void lm_dev_bench_gather(const char *big_cornell)
{
    lm_gl_context *gl = NULL;
    lm_error err;
    if (lm_gl_context_create(&gl, &err) != LM_OK) {
        printf("\nfinal gather: skipped (%s)\n", err.msg);
        return;
    }
    printf("\nfinal gather on %s\n", lm_gl_context_description(gl));
    const char *paths[3] = {"../shared/scenes/cornell-box/CornellBox.glb", "scenes/cornell.glb", big_cornell};
    const char *labels[3] = {"CornellBox.glb", "cornell.glb", "cornell (floor 255^2)"};
    bench_scene sc[3];
    int n = 0;
    for (int i = 0; i < 3; i++) {
        if (paths[i] && open_scene(labels[i], i, paths[i], &sc[n]))
            n++;
        else
            printf("%s: skipped (not found: %s)\n", labels[i], paths[i] ? paths[i] : "no path");
    }
    print_schemes(sc, n);
    print_contexts(sc, n);
    print_table2(sc, n);
    print_rays(sc, n);
    for (int i = 0; i < n; i++)
        close_scene(&sc[i]);
    lm_gl_context_destroy(gl);
    print_frame();
}

void lm_dev_bench_levels(const char *const *paths, int count)
{
    lm_gl_context *gl = NULL;
    lm_error err;
    if (lm_gl_context_create(&gl, &err) != LM_OK) {
        printf("\ngather on levels: skipped (%s)\n", err.msg);
        return;
    }
    printf("\ngather on levels, the frame loop's defaults (R = 32 with the proxy and the rim traced; rays: %d strata, "
           "the sun at their hits; sun texels: the rays reading the sun from the AIM's texels instead), ms per texel "
           "of wall time (median of %d passes of up to %d texels spread over the atlas; x first: against the first "
           "scene's hemicube) on %s:\n", LM_DEV_RAY_STRATA, REPEATS, PASS, lm_gl_context_description(gl));
    printf("%-24s %10s %11s %10s %8s %10s %8s %11s\n", "scene", "triangles", "proxy tris", "hemicube", "x first", "rays",
           "x first", "sun texels");
    double first = NAN;
    for (int i = 0; i < count; i++) {
        const char *label = strrchr(paths[i], '/') ? strrchr(paths[i], '/') + 1 : paths[i];
        bench_scene b;
        if (!open_scene(label, 0, paths[i], &b)) {
            printf("%-24s skipped (cannot load %s)\n", label, paths[i]);
            continue;
        }
        int tris = 0, ray_tris = 0;
        lm_gather *g[3] = {gather_traced(&b, 32, 1, LM_GATHER_VIEWPORTS, 0, 1, &tris),
                           sun_at_hits(gather_traced(&b, 32, 1, LM_GATHER_RAYS, 0, 1, &ray_tris), &b),
                           gather_traced(&b, 32, 1, LM_GATHER_RAYS, 0, 1, &ray_tris)};
        double ms[3] = {NAN, NAN, NAN};
        time_configs(g, 3, &b, ms);
        if (isnan(first))
            first = ms[0];
        printf("%-24s %10u %11d %10.3f %8.2f %10.3f %8.2f %11.3f\n", label, b.sc->scene->tri_count, tris, ms[0],
               ms[0] / first, ms[1], ms[1] / first, ms[2]);
        fflush(stdout);
        for (int k = 0; k < 3; k++)
            lm_gather_free(g[k]);
        close_scene(&b);
    }
    lm_gl_context_destroy(gl);
}
