/* lmgi-dev bench, caustics and reflections part (bench_caustics.h). Each figure is the median of REPEATS
 * runs; the GL ones end with the GPU's work done (glFinish or a query's result). */
#include "bench_caustics.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../../src/api/lmgi_scene.h"
#include "../../src/core/qmc.h"
#include "../../src/core/stats.h"
#include "../../src/core/timing.h"
#include "../../src/core/vecmath.h"
#include "../../src/gpu/frame/caustic_pass.h"
#include "../../src/photonmap/caustic_split.h"
#include "../../src/gpu/gl/gl_context.h"
#include "../../src/trace/caustics.h"
#include "../../src/update/frame_loop.h"
#include "dev_scene.h"

#define REPEATS 5
#define SIZE 512
#define PHOTONS 40000

/* A 20 x 20 m floor under a point light, as a scene of its own. */
static lmgi_scene *floor_scene(void)
{
    static const float pos[12] = {-10, 0, -10, -10, 0, 10, 10, 0, 10, 10, 0, -10};
    static const uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
    lmgi_mesh_desc m = {.name = "floor", .positions = pos, .vertex_count = 4, .indices = idx, .triangle_count = 2};
    lmgi_material_desc mat = {.name = "white", .base_color = {0.8f, 0.8f, 0.8f, 1}};
    lmgi_light_desc l = {.name = "lamp", .type = LMGI_LIGHT_POINT, .intensity = 10.0f, .position = {0, 4, 0}};
    lmgi_scene_desc d = {.name = "bench floor", .meshes = &m, .mesh_count = 1, .materials = &mat, .material_count = 1,
                         .lights = &l, .light_count = 1};
    lmgi_options o;
    lmgi_options_init(&o);
    o.target_texels = 256;
    lmgi_scene *sc = NULL;
    lmgi_error e;
    return lmgi_load_desc(&d, &o, &sc, &e) == LMGI_OK ? sc : NULL;
}

/* PHOTONS photons spread uniformly (Halton) over the floor's square of side `side` about the centre. */
static void square_photons(float side, lm_caustic_hit *h)
{
    for (uint32_t i = 0; i < PHOTONS; i++) {
        memset(&h[i], 0, sizeof h[i]);
        h[i].pos[0] = side * ((float)lm_halton(0, i) - 0.5f);
        h[i].pos[2] = side * ((float)lm_halton(1, i) - 0.5f);
        h[i].ng[1] = 1.0f;
        h[i].flux[0] = h[i].flux[1] = h[i].flux[2] = 1e-4f;
    }
}

typedef struct {
    double splat, query, filter, composite, total;
    int tiles, lit;
} pass_times;

/* REPEATS runs of the pass over the floor seen from 6 m above (60 degrees), medians. */
static int time_pass(lm_caustic_pass *cp, const lm_view *v, const lm_direct *d, unsigned depth, pass_times *out)
{
    double t[5][REPEATS];
    lm_caustic_pass_stats st;
    lm_error err;
    for (int r = 0; r < REPEATS; r++) {
        if (lm_caustic_pass_run(cp, LM_CAUSTIC_SLOT_FRAME, v, depth, SIZE, SIZE, d, &st, &err) != LM_OK) {
            printf("caustic pass: %s\n", err.msg);
            return 0;
        }
        const double x[5] = {st.t_splat, st.t_query, st.t_filter, st.t_composite,
                             st.t_splat + st.t_query + st.t_filter + st.t_composite};
        for (int k = 0; k < 5; k++)
            t[k][r] = 1e3 * x[k];
    }
    out->splat = lm_median(t[0], REPEATS), out->query = lm_median(t[1], REPEATS);
    out->filter = lm_median(t[2], REPEATS), out->composite = lm_median(t[3], REPEATS);
    out->total = lm_median(t[4], REPEATS);
    out->tiles = st.tiles, out->lit = st.tiles_lit;
    return 1;
}

/* The pass at 1, 5, 25 and 100% of the screen covered, and its queries alone at about 100 tiles. */
static void print_filter(void)
{
    lmgi_scene *sc = floor_scene();
    lm_emitters em;
    lm_direct *d = NULL;
    lm_caustic_pass *cp = NULL;
    lm_error err;
    static lm_caustic_hit hits[PHOTONS];
    if (!sc || lm_emitters_build(sc->scene, &em, &err) != LM_OK) {
        printf("caustic pass: skipped (no scene)\n");
        lmgi_free(sc);
        return;
    }
    lm_view v;
    float view[16], proj[16];
    lm_mat4_look_at(view, lm_v3(0, 6, 0), lm_v3(0, 0, 0), lm_v3(0, 0, -1));
    lm_mat4_perspective(proj, (float)(LM_PI / 3.0), 1.0f, 0.1f, 50.0f);
    lm_view_from_matrices(view, proj, &v);
    if (lm_direct_create(sc->scene, &sc->atlas, NULL, &d, &err) != LM_OK ||
        lm_direct_draw(d, sc->scene, &em, &v, SIZE, SIZE, &err) != LM_OK) {
        printf("caustic pass: skipped (%s)\n", err.msg);
        goto done;
    }
    float screen = 2.0f * 6.0f * tanf((float)(LM_PI / 6.0)); /* the floor's width the picture spans */
    static const double cover[4] = {0.01, 0.05, 0.25, 1.0};
    lm_caustic_pass_settings set;
    lm_caustic_pass_settings_default(&set);
    const int default_k = set.filter_k;
    /* the paper's fixed filter; sized by density (the default); and as a frame loop runs it when the thin
     * light is the lightmaps' (photonmap/caustic_split.h): the concentrated photons alone, as dense as the
     * full screen's (PHOTONS x covered), a filter that widens 2x */
    for (int sized = 0; sized < 3; sized++) {
    set.filter_k = sized ? default_k : 3;
    set.widen_levels = sized == 2 ? LM_CAUSTIC_SPLIT_WIDEN : LM_CAUSTIC_FILTER_LEVELS;
    const char *name[3] = {"the paper's fixed 7 x 7", "sized by density (32 photons)",
                           "sized, widening 2x, photons x covered (thin light in the lightmaps)"};
    printf("\ncaustic pass at %d x %d, %d photons, k = %d, %s, %d-pixel tiles; ms, median of %d:\n", SIZE, SIZE,
           PHOTONS, set.filter_k, name[sized], 32, REPEATS);
    printf("%-9s %11s %8s %8s %8s %10s %8s %9s\n", "covered", "tiles lit", "splat", "queries", "filter", "composite",
           "total", "paper");
    set.filter_photons = sized ? 32 : 0;
    if (lm_caustic_pass_create(&set, &cp, &err) != LM_OK) {
        printf("caustic pass: %s\n", err.msg);
        goto done;
    }
    double full_filter = 0.0, five_filter = 0.0;
    for (int c = 0; c < 4; c++) {
        /* the photons' square; at 100% a little wider, so that the filter's border reaches every pixel */
        square_photons(screen * (float)sqrt(cover[c]) * (c == 3 ? 1.05f : 1.0f), hits);
        pass_times t;
        uint32_t n = sized == 2 ? (uint32_t)(PHOTONS * cover[c]) : PHOTONS;
        if (lm_caustic_pass_set_photons(cp, hits, n, &err) != LM_OK || !time_pass(cp, &v, d,
                                                                                        lm_direct_depth_texture(d, 0), &t))
            goto done;
        const char *paper = c == 0 ? "0.38" : c == 3 ? "37.6" : "";
        printf("%7.0f%% %5d / %-4d %8.2f %8.2f %8.2f %10.2f %8.2f %9s\n", 100.0 * cover[c], t.lit, t.tiles, t.splat,
               t.query, t.filter, t.composite, t.total, paper);
        full_filter = c == 3 ? t.filter : full_filter;
        five_filter = c == 1 ? t.filter : five_filter;
    }
    printf("filter at 5%% / full screen: %.3f (target <= 0.10)\n", five_filter / full_filter);
    lm_caustic_pass_free(cp);
    cp = NULL;
    }
    /* queries alone: 100 tiles of 52 pixels (10 x 10 over 512) */
    set.tile = 52;
    if (lm_caustic_pass_create(&set, &cp, &err) == LM_OK) {
        square_photons(screen * 0.1f, hits);
        pass_times t;
        if (lm_caustic_pass_set_photons(cp, hits, PHOTONS, &err) == LM_OK &&
            time_pass(cp, &v, d, lm_direct_depth_texture(d, 0), &t))
            printf("occlusion queries alone: %d tiles in %.3f ms, %.3f ms per 100 (paper: 0.33 ms per 100)\n", t.tiles,
                   t.query, 100.0 * t.query / t.tiles);
    }
done:
    lm_caustic_pass_free(cp);
    lm_direct_free(d);
    lm_emitters_free(&em);
    lmgi_free(sc);
}

/* The caustic photons of scenes/cornell.glb traced whole against raw Embree casting as many rays, from
 * the same emission rays replayed. */
static void print_tracing(lmgi_scene *sc)
{
    lm_emitters em;
    lm_error err;
    if (lm_emitters_build(sc->scene, &em, &err) != LM_OK)
        return;
    lm_caustics *c = NULL;
    lm_caustic_frame_stats st;
    if (lm_caustics_create(sc->scene, sc->rt, &em, NULL, &c, &st, &err) != LM_OK) {
        printf("caustic photons: %s\n", err.msg);
        lm_emitters_free(&em);
        return;
    }
    double t[REPEATS], raw[REPEATS];
    for (int r = 0; r < REPEATS; r++) {
        double t0 = lm_now();
        lm_caustics_trace_all(c, &st, &err);
        t[r] = 1e3 * (lm_now() - t0);
    }
    /* the baseline: the emission rays towards the generators, repeated to the tracer's ray count */
    uint32_t n = (uint32_t)st.rays, photons = lm_caustics_photon_count(c);
    float *org = malloc(3 * sizeof(float) * (n ? n : 1)), *dir = malloc(3 * sizeof(float) * (n ? n : 1));
    uint32_t per = photons / (uint32_t)lm_caustics_pair_count(c);
    for (uint32_t i = 0; org && dir && i < n; i++) {
        uint32_t k = i % photons, p = k / per;
        const lm_caustic_generator *g = lm_caustics_generator(c, p / em.count);
        float u[4] = {(float)lm_halton(0, k), (float)lm_halton(1, k), (float)lm_halton(2, k), (float)lm_halton(3, k)}, f[3];
        lm_caustic_emit(&em, sc->scene, (int)(p % (uint32_t)em.count), NULL, g, u, per, org + 3 * (size_t)i,
                        dir + 3 * (size_t)i, f);
    }
    for (int r = 0; org && dir && r < REPEATS; r++) {
        double t0 = lm_now();
        lm_rt_raw_intersect(sc->rt, org, dir, n);
        raw[r] = 1e3 * (lm_now() - t0);
    }
    double mt = lm_median(t, REPEATS), mr = org && dir ? lm_median(raw, REPEATS) : 0.0;
    printf("\ncaustic photons on scenes/cornell.glb: %u photons (%d pairs), %u landed, %llu rays: %.2f ms (%.2f Mrays/s); "
           "raw Embree, as many rays: %.2f ms; ratio %.2f\n", photons, lm_caustics_pair_count(c), st.landed,
           (unsigned long long)st.rays, mt, st.rays / mt / 1e3, mr, mr > 0.0 ? mt / mr : 0.0);
    free(org);
    free(dir);
    lm_caustics_free(c);
    lm_emitters_free(&em);
}

#define FRAMES 60
enum { P_PHOTONS, P_GATHER, P_BLEND, P_DIRECT, P_CAUSTICS, P_REFLECT, P_COMPOSITE, P_TOTAL, P_COUNT };

/* The frame loop on scenes/cornell.glb at 512 x 512 with `faces` environment map faces a frame and the
 * caustics on or off, their thin light in the lightmaps or all of it on screen (`thin` 0): median ms per
 * pass over FRAMES frames (30 per second of animation). */
static void print_frames(lmgi_scene *sc, int faces, int caustics, int reflections, int thin)
{
    lm_frame_loop_settings set;
    lm_frame_loop_settings_default(&set);
    set.caustic_thin = thin ? LM_CAUSTIC_THIN_DEFAULT : 0.0f;
    set.reflection_faces = faces;
    set.caustics = caustics;
    set.reflection_size = reflections ? set.reflection_size : 0;
    lm_frame_loop *fl = NULL;
    lm_error err;
    if (lm_frame_loop_create(&sc->world, &set, &fl, NULL, NULL, &err) != LM_OK) {
        printf("frame loop: %s\n", err.msg);
        return;
    }
    static double t[P_COUNT][FRAMES], per_face[FRAMES], parts[5][FRAMES];
    int faced = 0;
    uint64_t traced = 0;
    for (int n = 0; n < FRAMES; n++) {
        lm_frame_stats o;
        if (lm_frame_loop_step(fl, (float)n / 30.0f, &o, &err) != LM_OK) {
            printf("frame %d: %s\n", n, err.msg);
            lm_frame_loop_free(fl);
            return;
        }
        const double v[P_COUNT] = {o.t_photons, o.t_gather, o.t_blend, o.t_direct, o.t_caustics, o.t_reflections,
                                   o.t_composite, o.t_total};
        for (int k = 0; k < P_COUNT; k++)
            t[k][n] = 1e3 * v[k];
        const double cp[5] = {o.caustic.t_splat, o.caustic.t_query, o.caustic.t_filter, o.caustic.t_composite,
                              (double)o.caustic.tiles_lit};
        for (int k = 0; k < 5; k++)
            parts[k][n] = k < 4 ? 1e3 * cp[k] : cp[k];
        if (o.cube_faces > 0 && n > 0)
            per_face[faced++] = 1e3 * o.t_reflections / o.cube_faces;
        traced += o.stage.caustics.traced;
    }
    double m[P_COUNT];
    for (int k = 0; k < P_COUNT; k++)
        m[k] = lm_median(t[k], FRAMES);
    char name[64];
    snprintf(name, sizeof name, "%s%s", caustics ? reflections ? "caustics + reflections" : "caustics"
                                        : reflections ? "reflections" : "neither",
             caustics && thin ? ", thin light in lightmaps" : "");
    printf("%-34s %7.1f %5.1f %8.2f %7.2f %6.2f %7.2f %9.2f %8.2f %7.2f", name, m[P_TOTAL], 1e3 / m[P_TOTAL], m[P_PHOTONS],
           m[P_GATHER], m[P_BLEND], m[P_DIRECT], m[P_CAUSTICS], m[P_REFLECT], m[P_COMPOSITE]);
    if (faced)
        printf("   %d faces a frame: %.2f ms a face", faces, lm_median(per_face, faced));
    printf(caustics ? "   %.0f caustic photons a frame\n" : "\n", (double)traced / FRAMES);
    if (caustics)
        printf("%-34s caustic pass: splat %.2f, queries %.2f, filter %.2f, composite %.2f ms; %.0f tiles lit\n", "",
               lm_median(parts[0], FRAMES), lm_median(parts[1], FRAMES), lm_median(parts[2], FRAMES),
               lm_median(parts[3], FRAMES), lm_median(parts[4], FRAMES));
    lm_frame_loop_free(fl);
}

void lm_dev_bench_caustics(void)
{
    lm_gl_context *gl = NULL;
    lm_error err;
    if (lm_gl_context_create(&gl, &err) != LM_OK) {
        printf("\ncaustics: skipped (%s)\n", err.msg);
        return;
    }
    lm_qmc_init();
    print_filter();
    const char *path = "scenes/cornell.glb";
    lmgi_scene *sc = lm_dev_load(path, lmgi_atlas_texels_for(0));
    if (sc) {
        print_tracing(sc);
        printf("\nframe loop on %s at %d x %d (mirror and glass spheres and the cube moving), ms, median of %d "
               "frames:\n", path, SIZE, SIZE, FRAMES);
        printf("%-34s %7s %5s %8s %7s %6s %7s %9s %8s %7s\n", "", "frame", "fps", "photons", "gather", "blend", "direct",
               "caustics", "reflect", "compos.");
        print_frames(sc, 1, 0, 0, 1);
        print_frames(sc, 1, 1, 0, 0);
        print_frames(sc, 1, 1, 0, 1);
        print_frames(sc, 1, 0, 1, 1);
        print_frames(sc, 1, 1, 1, 0);
        print_frames(sc, 1, 1, 1, 1);
        print_frames(sc, 6, 1, 1, 1);
        lmgi_free(sc);
    } else {
        printf("\ncaustics on %s: skipped (not loaded)\n", path);
    }
    lm_gl_context_destroy(gl);
}
