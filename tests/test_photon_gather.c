/* The per-pixel photon gathers on the GPU (gpu/tiled/photon_gather.h) and their records
 * (photonmap/photon_records.h): the packing keeps flux and direction to its stated precision; tiled,
 * hash grid and brute force give the same picture on the generated Cornell box and where photons straddle
 * tile and cell borders, lie on a tile frustum's side, behind the camera, or reach past the screen; that
 * picture matches the CPU's float gather (photonmap/pixel_gather.h) over a ray-traced G-buffer; the
 * stochastic gather's mean over k^2 frames is the full gather; limits are refused with a message; and a
 * run is the same every time. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../src/core/vecmath.h"
#include "../src/gpu/frame/direct.h"
#include "../src/gpu/gl/gl_api.h"
#include "../src/gpu/tiled/photon_gather.h"
#include "../src/photonmap/photon_records.h"
#include "../src/photonmap/pixel_gather.h"
#include "../src/scene/scene_view.h"
#include "../src/update/photon_stage.h"
#include "support.h"

typedef struct {
    lmt_pipeline p;
    lm_photon_stage *stage;
    const lm_photon_store *store;
    lm_direct *d;
    lm_view view;
    lm_photon_records rec;
    float radius;
    int w, h;
} fixture;

/* The scene with its photons traced (the stage's defaults), its direct light drawn from its camera at
 * w x h (the G-buffer), the records packed and the radius of N = 128. */
static void setup(fixture *f, const char *path, float texel, int w, int h)
{
    memset(f, 0, sizeof *f);
    lmt_pipeline_load(&f->p, path, texel);
    lm_photon_stage_settings set;
    lm_photon_stage_settings_default(&set);
    lm_error err;
    if (lm_photon_stage_create(&f->p.w, &set, &f->stage, NULL, &err) != LM_OK ||
        lm_direct_create(f->p.s, &f->p.atlas, NULL, &f->d, &err) != LM_OK)
        fail_msg("%s", err.msg);
    f->store = lm_photon_stage_store(f->stage);
    f->w = w, f->h = h;
    lm_view_for_scene(f->p.s, -1, w, h, &f->view);
    if (lm_direct_draw(f->d, f->p.s, lm_photon_stage_emitters(f->stage), &f->view, w, h, &err) != LM_OK ||
        lm_photon_records_update(&f->rec, f->store, f->p.s, &err) != LM_OK)
        fail_msg("%s", err.msg);
    f->radius = lm_pixel_gather_radius(f->store, &f->p.su, 128);
}

static void teardown(fixture *f)
{
    lm_photon_records_free(&f->rec);
    lm_direct_free(f->d);
    lm_photon_stage_free(f->stage);
    lmt_pipeline_free(&f->p);
}

/* E of one gather over the fixture's records and G-buffer (malloc'd, 3 floats a pixel). */
static float *gather(fixture *f, const lm_photon_gather_settings *s, unsigned frame, lm_photon_gather_stats *st)
{
    lm_photon_gather *g = NULL;
    lm_error err;
    float *E = malloc(3 * (size_t)f->w * (size_t)f->h * sizeof *E);
    if (lm_photon_gather_create(s, &g, &err) != LM_OK || lm_photon_gather_set_records(g, &f->rec, st, &err) != LM_OK ||
        lm_photon_gather_run(g, &f->view, f->w, f->h, lm_direct_kd_texture(f->d, 0), lm_direct_gbuffer_texture(f->d),
                             f->radius, frame, st, &err) != LM_OK ||
        lm_photon_gather_read(g, E, &err) != LM_OK)
        fail_msg("%s", err.msg);
    lm_photon_gather_free(g);
    return E;
}

static lm_photon_gather_settings kind(int k)
{
    lm_photon_gather_settings s;
    lm_photon_gather_settings_default(&s);
    s.kind = k;
    return s;
}

/* Largest |a - b| over the pixels, as a share of b's largest value. */
static double max_diff(const float *a, const float *b, size_t n)
{
    double d = 0.0, peak = 0.0;
    for (size_t i = 0; i < n; i++) {
        d = fmax(d, fabs((double)a[i] - (double)b[i]));
        peak = fmax(peak, fabs((double)b[i]));
    }
    return peak > 0.0 ? d / peak : d;
}

static double mean(const float *a, size_t n)
{
    double s = 0.0;
    for (size_t i = 0; i < n; i++)
        s += a[i];
    return s / (double)n;
}

/* ---------- records ---------- */

/* Flux within 2^-13 of its brightest channel, over exponents from the float's bottom to its top; the
 * direction within a degree; left-out hits empty. */
static void test_records(void **state)
{
    (void)state;
    uint32_t seed = 12345;
    double worst_flux = 0.0, worst_angle = 0.0;
    for (int i = 0; i < 20000; i++) {
        lm_hit h;
        memset(&h, 0, sizeof h);
        h.bounce = 1;
        for (int c = 0; c < 3; c++) {
            h.pos[c] = ((float)lmt_xorshift(&seed) / 4294967296.0f - 0.5f) * 1e5f;
            h.dir[c] = (float)lmt_xorshift(&seed) / 4294967296.0f - 0.5f;
        }
        int e = (int)(lmt_xorshift(&seed) % 240) - 120;
        for (int c = 0; c < 3; c++)
            h.flux[c] = ldexpf((float)lmt_xorshift(&seed) / 4294967296.0f, e);
        lm_vec3 d = lm_normalize(lm_v3_load(h.dir));
        lm_v3_store(h.dir, d);
        float side[3];
        lm_hit_side_normal(NULL, &h, side); /* no scene: the arrival direction */
        lm_photon_record r;
        lm_photon_record_encode(&h, side, &r);
        float pos[3], from[3], flux[3];
        assert_true(lm_photon_record_decode(&r, pos, from, flux));
        assert_memory_equal(pos, h.pos, sizeof pos);
        double m = fmax(h.flux[0], fmax(h.flux[1], h.flux[2]));
        for (int c = 0; c < 3; c++)
            worst_flux = fmax(worst_flux, fabs((double)flux[c] - (double)h.flux[c]) / m);
        double cosang = -(from[0] * d.x + from[1] * d.y + from[2] * d.z);
        worst_angle = fmax(worst_angle, acos(fmin(1.0, cosang)) * 180.0 / M_PI);
    }
    print_message("20,000 random hits: flux within %.3g of the brightest channel, side normal within %.3f degrees\n",
                  worst_flux, worst_angle);
    assert_true(worst_flux <= 1.0 / 8192.0 + 1e-9);
    assert_true(worst_angle < 1.0);

    lm_hit h;
    memset(&h, 0, sizeof h);
    h.flux[0] = h.flux[1] = h.flux[2] = 1.0f;
    h.dir[1] = -1.0f;
    lm_photon_record r;
    float pos[3], from[3], flux[3], up[3] = {0.0f, 1.0f, 0.0f};
    h.source = LM_HIT_FROM_PUNCTUAL; /* a punctual light's first hit: the direct pass's */
    lm_photon_record_encode(&h, up, &r);
    assert_false(lm_photon_record_decode(&r, pos, from, flux));
    h.source = LM_HIT_FROM_SUN; /* a sun's first hit: the direct pass's too */
    lm_photon_record_encode(&h, up, &r);
    assert_false(lm_photon_record_decode(&r, pos, from, flux));
    h.source = LM_HIT_FROM_AREA, h.caustic = 1; /* the caustic pass's */
    lm_photon_record_encode(&h, up, &r);
    assert_false(lm_photon_record_decode(&r, pos, from, flux));
    h.caustic = 0, h.surface = -1; /* a free slot */
    lm_photon_record_encode(&h, up, &r);
    assert_false(lm_photon_record_decode(&r, pos, from, flux));
    h.surface = 0, h.flux[0] = h.flux[1] = h.flux[2] = 0.0f;
    lm_photon_record_encode(&h, up, &r);
    assert_false(lm_photon_record_decode(&r, pos, from, flux));
}

/* One hit changed in a store of 5,000: one page of records dirty; nothing changed: none. */
static void test_records_dirty_pages(void **state)
{
    (void)state;
    lm_photon_store ps;
    lm_error err;
    assert_int_equal(lm_photon_store_init(&ps, 1, &err), LM_OK);
    for (int i = 0; i < 5000; i++) {
        lm_hit h;
        memset(&h, 0, sizeof h);
        h.pos[0] = (float)i;
        h.dir[1] = -1.0f;
        h.flux[0] = h.flux[1] = h.flux[2] = 1.0f;
        h.bounce = 1;
        assert_true(lm_photon_store_add(&ps, &h) != LM_NONE);
    }
    lm_photon_records r;
    memset(&r, 0, sizeof r);
    assert_int_equal(lm_photon_records_update(&r, &ps, NULL, &err), LM_OK);
    assert_int_equal(r.count, 5000);
    assert_int_equal(r.live, 5000);
    assert_int_equal(r.dirty_pages, 5);
    assert_int_equal(lm_photon_records_update(&r, &ps, NULL, &err), LM_OK);
    assert_int_equal(r.dirty_pages, 0);
    lm_photon_store_remove(&ps, 2500);
    assert_int_equal(lm_photon_records_update(&r, &ps, NULL, &err), LM_OK);
    assert_int_equal(r.dirty_pages, 1);
    assert_true(r.dirty[2500 / LM_RECORD_PAGE]);
    assert_int_equal(r.live, 4999);
    lm_photon_records_free(&r);
    lm_photon_store_free(&ps);
}

/* ---------- the gathers agree ---------- */

/* On the generated Cornell box: every tiled configuration, the hash grid and the brute force give the
 * same E; and kd / pi x E matches the CPU's float gather over a ray-traced G-buffer where both see the
 * same point. */
static void test_gathers_agree(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(path, lmt_project_scene("cornell.glb"));
    fixture f;
    setup(&f, path, 0.0f, 96, 96);
    size_t n = 3 * (size_t)f.w * (size_t)f.h;
    lm_photon_gather_stats st;
    lm_photon_gather_settings s = kind(LM_PHOTON_GATHER_BRUTEFORCE);
    float *brute = gather(&f, &s, 0, &st);
    print_message("%u records (%u live), radius %.4f; brute force: %.1f ms, mean E %.4g\n", st.records,
                  st.records_live, (double)f.radius, 1e3 * st.t_gather, mean(brute, n));
    assert_true(mean(brute, n) > 0.0);
    const int tiles[4][2] = {{16, 256}, {8, 64}, {32, 512}, {4, 128}};
    for (int t = 0; t < 4; t++) {
        s = kind(LM_PHOTON_GATHER_TILED);
        s.tile = tiles[t][0], s.chunk = tiles[t][1];
        float *E = gather(&f, &s, 0, &st);
        double d = max_diff(E, brute, n);
        print_message("tiled %2d px, chunk %4d: %d of %d tiles lit, %llu entries, insert %.1f ms, gather %.1f ms; "
                      "largest difference from the brute force %.2g\n",
                      s.tile, s.chunk, st.tiles_lit, st.tiles, (unsigned long long)st.entries, 1e3 * st.t_insert,
                      1e3 * st.t_gather, d);
        assert_true(d <= 1e-4);
        free(E);
    }
    s = kind(LM_PHOTON_GATHER_HASHGRID);
    float *E = gather(&f, &s, 0, &st);
    double d = max_diff(E, brute, n);
    print_message("hash grid: %llu entries, insert %.1f ms, gather %.1f ms; largest difference %.2g\n",
                  (unsigned long long)st.entries, 1e3 * st.t_insert, 1e3 * st.t_gather, d);
    assert_true(d <= 1e-4);
    free(E);

    /* the CPU's gather: float records, a ray-traced G-buffer */
    lm_view cam = f.view;
    lm_gbuffer g;
    memset(&g, 0, sizeof g);
    lm_error err;
    if (lm_view_pinhole(&cam, f.w, f.h, &err) != LM_OK ||
        lm_gbuffer_trace(&g, f.p.s, f.p.rt, &cam, &err) != LM_OK)
        fail_msg("%s", err.msg);
    float *cpu = malloc(n * sizeof *cpu);
    lm_pixel_gather_bruteforce(&g, f.store, f.p.s, f.radius, cpu);
    /* the GPU's radiance kd / pi x E at the pixels where both G-buffers see a diffuse point */
    double sum_gpu = 0.0, sum_cpu = 0.0, worst = 0.0;
    int same = 0;
    for (size_t i = 0; i < n / 3; i++) {
        const float *kd = g.kd + 3 * i;
        if (kd[0] + kd[1] + kd[2] <= 0.0f || brute[3 * i] + brute[3 * i + 1] + brute[3 * i + 2] <= 0.0f)
            continue;
        same++;
        for (int c = 0; c < 3; c++) {
            double want = cpu[3 * i + c], got = kd[c] / M_PI * brute[3 * i + c];
            sum_gpu += got, sum_cpu += want;
            if (want > 1e-3 * mean(cpu, n))
                worst = fmax(worst, fabs(got / want - 1.0));
        }
    }
    print_message("against the CPU's float gather: %d pixels, mean %.5f, the pixel furthest off %.3g\n", same,
                  sum_gpu / sum_cpu, worst);
    assert_true(same > (int)(n / 3) / 2);
    assert_true(fabs(sum_gpu / sum_cpu - 1.0) < 2e-3);
    free(cpu);
    lm_gbuffer_free(&g);
    free(brute);
    teardown(&f);
}

/* ---------- borders, behind the camera, past the screen ---------- */

/* The 20 x 20 plane (support.h) from eye towards target at w x w, 60 degrees; the photons are the caller's
 * (set_hits). */
static void setup_plane(fixture *f, lm_vec3 eye, lm_vec3 target, int w)
{
    memset(f, 0, sizeof *f);
    lmt_pipeline_load(&f->p, lmt_plane_scene(), 0.5f);
    float view[16], proj[16];
    lm_vec3 fwd = lm_normalize(lm_sub(target, eye));
    lm_mat4_look_at(view, eye, target, fabsf(fwd.y) > 0.99f ? lm_v3(0.0f, 0.0f, -1.0f) : lm_v3(0.0f, 1.0f, 0.0f));
    lm_mat4_perspective(proj, (float)(M_PI / 3.0), 1.0f, 0.01f, 100.0f);
    assert_true(lm_view_from_matrices(view, proj, &f->view));
    f->w = f->h = w;
    lm_error err;
    if (lm_direct_create(f->p.s, &f->p.atlas, NULL, &f->d, &err) != LM_OK ||
        lm_direct_draw(f->d, f->p.s, &f->p.em, &f->view, w, w, &err) != LM_OK)
        fail_msg("%s", err.msg);
}

/* Photons of flux 1 arriving straight down at (x[i], 0, z[i]) become the fixture's records. */
static void set_hits(fixture *f, const float *x, const float *z, int n)
{
    lm_photon_store ps;
    lm_error err;
    assert_int_equal(lm_photon_store_init(&ps, 1, &err), LM_OK);
    for (int i = 0; i < n; i++) {
        lm_hit h;
        memset(&h, 0, sizeof h);
        h.pos[0] = x[i], h.pos[2] = z[i];
        h.dir[1] = -1.0f;
        h.flux[0] = 1.0f, h.flux[1] = 0.5f, h.flux[2] = 0.25f;
        h.bounce = 1;
        assert_true(lm_photon_store_add(&ps, &h) != LM_NONE);
    }
    lm_photon_records_free(&f->rec);
    assert_int_equal(lm_photon_records_update(&f->rec, &ps, f->p.s, &err), LM_OK);
    lm_photon_store_free(&ps);
}

/* Tiled (8 and 16 pixels), hash grid and brute force over the fixture: the same E; returns the brute
 * force's (malloc'd). */
static float *all_agree(fixture *f, const char *what)
{
    size_t n = 3 * (size_t)f->w * (size_t)f->h;
    lm_photon_gather_stats st;
    lm_photon_gather_settings s = kind(LM_PHOTON_GATHER_BRUTEFORCE);
    float *brute = gather(f, &s, 0, &st);
    double worst = 0.0;
    for (int t = 8; t <= 16; t *= 2) {
        s = kind(LM_PHOTON_GATHER_TILED);
        s.tile = t;
        float *E = gather(f, &s, 0, &st);
        worst = fmax(worst, max_diff(E, brute, n));
        free(E);
    }
    s = kind(LM_PHOTON_GATHER_HASHGRID);
    float *E = gather(f, &s, 0, &st);
    worst = fmax(worst, max_diff(E, brute, n));
    free(E);
    print_message("%s: mean E %.4g, largest difference of tiled and hash grid from the brute force %.2g\n", what,
                  mean(brute, n), worst);
    assert_true(mean(brute, n) > 0.0);
    assert_true(worst <= 1e-4);
    return brute;
}

/* Photons on every tile edge (8 and 16 pixels: the tiles' frustum sides) and every cell border (multiples
 * of 2r), seen from 2 m straight above at 64 x 64. */
static void test_borders(void **state)
{
    (void)state;
    fixture f;
    setup_plane(&f, lm_v3(0.0f, 2.0f, 0.0f), lm_v3(0.0f, 0.0f, 0.0f), 64);
    f.radius = 0.1f;
    float half = 2.0f * (float)tan(M_PI / 6.0), xs[64], zs[64 * 64], xg[64 * 64];
    int nx = 0;
    for (int px = 0; px <= 64; px += 8) /* tile edges: x = (2 px / W - 1) tan(30) h */
        xs[nx++] = (2.0f * (float)px / 64.0f - 1.0f) * half;
    for (int c = -11; c <= 11; c++) /* cell borders */
        xs[nx++] = 2.0f * f.radius * (float)c;
    int n = 0;
    for (int i = 0; i < nx; i++)
        for (int j = 0; j < nx; j++)
            xg[n] = xs[i], zs[n] = xs[j], n++;
    set_hits(&f, xg, zs, n);
    float *E = all_agree(&f, "photons on tile edges and cell borders");
    free(E);
    teardown(&f);
}

/* The eye 0.3 m over the plane looking ahead and down: photons behind it (their spheres reach behind the
 * eye plane, so the tiles are tested one by one) light the nearest visible floor; and a radius of 10,
 * a sphere far larger than the screen. */
static void test_behind_and_past_the_screen(void **state)
{
    (void)state;
    fixture f;
    setup_plane(&f, lm_v3(0.0f, 0.3f, 0.0f), lm_v3(0.0f, 0.0f, -1.0f), 48);
    f.radius = 0.5f;
    float x[400], z[400];
    int n = 0;
    for (int i = 0; i < 20; i++)
        for (int j = 0; j < 20; j++, n++) {
            x[n] = -1.0f + 0.1f * (float)i;
            z[n] = 0.3f - 0.1f * (float)j; /* z > 0: behind the eye */
        }
    set_hits(&f, x, z, n);
    float *all = all_agree(&f, "photons in front of and behind the eye");
    int front = 0;
    for (int i = 0; i < n; i++)
        if (z[i] < 0.0f)
            x[front] = x[i], z[front] = z[i], front++;
    set_hits(&f, x, z, front);
    float *before = all_agree(&f, "the same without those behind the eye");
    assert_true(max_diff(before, all, 3 * (size_t)f.w * (size_t)f.h) > 0.01); /* they count */
    free(all), free(before);
    f.radius = 10.0f;
    set_hits(&f, x, z, 50);
    free(all_agree(&f, "50 photons of radius 10"));
    teardown(&f);
}

/* ---------- the stochastic gather ---------- */

/* A float texture of zeros to composite into, and its read-back (3 floats a pixel). */
static unsigned zero_texture(int w, int h)
{
    float *z = calloc(4 * (size_t)w * (size_t)h, sizeof *z);
    GLuint t;
    glGenTextures(1, &t);
    glBindTexture(GL_TEXTURE_2D, t);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, w, h, 0, GL_RGBA, GL_FLOAT, z);
    free(z);
    return t;
}

static float *composited(fixture *f, const lm_photon_gather_settings *s, unsigned frame, float *E)
{
    lm_photon_gather *g = NULL;
    lm_error err;
    unsigned kd = lm_direct_kd_texture(f->d, 0), gb = lm_direct_gbuffer_texture(f->d), t = zero_texture(f->w, f->h);
    if (lm_photon_gather_create(s, &g, &err) != LM_OK || lm_photon_gather_set_records(g, &f->rec, NULL, &err) != LM_OK ||
        lm_photon_gather_run(g, &f->view, f->w, f->h, kd, gb, f->radius, frame, NULL, &err) != LM_OK ||
        (E && lm_photon_gather_read(g, E, &err) != LM_OK) || lm_photon_gather_composite(g, t, kd, gb, &err) != LM_OK)
        fail_msg("%s", err.msg);
    lm_photon_gather_free(g);
    float *rgba = malloc(4 * (size_t)f->w * (size_t)f->h * sizeof *rgba), *rgb = malloc(3 * (size_t)f->w * (size_t)f->h * sizeof *rgb);
    glBindTexture(GL_TEXTURE_2D, t);
    glGetTexImage(GL_TEXTURE_2D, 0, GL_RGBA, GL_FLOAT, rgba);
    for (size_t i = 0; i < (size_t)f->w * (size_t)f->h; i++)
        memcpy(rgb + 3 * i, rgba + 4 * i, 3 * sizeof *rgb);
    free(rgba);
    glDeleteTextures(1, &t);
    return rgb;
}

/* Relative RMSE of a against b over the pixels where b > 0. */
static double rel_rmse(const float *a, const float *b, size_t n)
{
    double e = 0.0, w = 0.0;
    for (size_t i = 0; i < n; i++)
        if (b[i] > 0.0f)
            e += ((double)a[i] - b[i]) * ((double)a[i] - b[i]), w += (double)b[i] * b[i];
    return w > 0.0 ? sqrt(e / w) : 0.0;
}

/* k = 2 on the Cornell box: each pixel reads a quarter of its tile's photons; over 4 frames every class
 * once, so the mean of the 4 (before the reconstruction) is the full gather. The reconstructed frame's
 * relative RMSE against the full gather's is bounded, and below the raw stochastic frame's. */
static void test_stochastic(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(path, lmt_project_scene("cornell.glb"));
    fixture f;
    setup(&f, path, 0.0f, 96, 96);
    size_t n = 3 * (size_t)f.w * (size_t)f.h;
    lm_photon_gather_settings s = kind(LM_PHOTON_GATHER_TILED);
    float *E = malloc(n * sizeof *E), *sum = calloc(n, sizeof *sum);
    float *full = composited(&f, &s, 0, E), *fullE = E;
    E = malloc(n * sizeof *E);
    s.stochastic = 2;
    float *rec = NULL, *raw = NULL;
    for (unsigned frame = 0; frame < 4; frame++) {
        float *L = composited(&f, &s, frame, E);
        for (size_t i = 0; i < n; i++)
            sum[i] += 0.25f * E[i];
        if (frame == 0) {
            rec = L;
            raw = malloc(n * sizeof *raw);
            memcpy(raw, E, n * sizeof *raw);
        } else {
            free(L);
        }
    }
    double d = max_diff(sum, fullE, n), mean = 0.0;
    for (size_t i = 0; i < n; i++)
        mean += fullE[i] / (double)n;
    print_message("full tiled gather: mean E %.4g over the picture\n", mean);
    assert_true(mean > 0.0); /* the box is lit: a gather that gives nothing is broken, not exact */
    /* the raw stochastic frame as radiance: kd / pi x E, kd from the full gather's L / E */
    float *raw_L = malloc(n * sizeof *raw_L);
    for (size_t i = 0; i < n; i++)
        raw_L[i] = fullE[i] > 0.0f ? full[i] / fullE[i] * raw[i] : 0.0f;
    double e_rec = rel_rmse(rec, full, n), e_raw = rel_rmse(raw_L, full, n);
    print_message("k = 2: the mean of 4 frames is the full gather within %.2g; one frame's relative RMSE %.3f "
                  "raw, %.3f reconstructed\n", d, e_raw, e_rec);
    assert_true(d < 0.01);
    assert_true(e_rec < 0.15);
    assert_true(e_rec < e_raw);
    free(E), free(fullE), free(sum), free(full), free(rec), free(raw), free(raw_L);
    teardown(&f);
}

/* ---------- limits ---------- */

/* No photon: E 0 everywhere, no error. A 1 x 1 frame. Bad settings and a radius of 0 refused with a
 * message. Lists past the limit refused, naming it, before anything is drawn. */
static void test_limits(void **state)
{
    (void)state;
    fixture f;
    setup_plane(&f, lm_v3(0.0f, 2.0f, 0.0f), lm_v3(0.0f, 0.0f, 0.0f), 32);
    f.radius = 0.1f;
    set_hits(&f, NULL, NULL, 0);
    for (int k = 0; k < 3; k++) {
        lm_photon_gather_settings s = kind(k);
        lm_photon_gather_stats st;
        float *E = gather(&f, &s, 0, &st);
        for (size_t i = 0; i < 3 * (size_t)f.w * (size_t)f.h; i++)
            assert_true(E[i] == 0.0f);
        free(E);
    }
    lm_photon_gather *g = NULL;
    lm_error err;
    lm_photon_gather_settings s = kind(LM_PHOTON_GATHER_TILED);
    const struct {
        int tile, chunk, k;
        const char *says;
    } bad[] = {{12, 256, 1, "tile 12"}, {16, 1000, 1, "chunk 1000"}, {16, 256, 5, "k = 5"}, {16, 32, 1, "chunk 32"}};
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        s.tile = bad[i].tile, s.chunk = bad[i].chunk, s.stochastic = bad[i].k;
        assert_int_equal(lm_photon_gather_create(&s, &g, &err), LM_ERR_INVALID);
        assert_non_null(strstr(err.msg, bad[i].says));
        assert_null(g);
    }
    s = kind(LM_PHOTON_GATHER_TILED);
    assert_int_equal(lm_photon_gather_create(&s, &g, &err), LM_OK);
    assert_int_equal(lm_photon_gather_set_records(g, &f.rec, NULL, &err), LM_OK);
    unsigned kd = lm_direct_kd_texture(f.d, 0), gb = lm_direct_gbuffer_texture(f.d);
    assert_int_equal(lm_photon_gather_run(g, &f.view, f.w, f.h, kd, gb, 0.0f, 0, NULL, &err), LM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "radius"));
    lm_photon_gather_free(g);
    teardown(&f);

    /* 1 x 1 */
    setup_plane(&f, lm_v3(0.0f, 2.0f, 0.0f), lm_v3(0.0f, 0.0f, 0.0f), 1);
    f.radius = 0.3f;
    float x[9] = {0, 0.1f, -0.1f, 0, 0, 0.2f, 5, 0.05f, 0}, z[9] = {0, 0, 0, 0.1f, -0.1f, 0.2f, 5, 0, 0.29f};
    set_hits(&f, x, z, 9);
    free(all_agree(&f, "a 1 x 1 frame"));
    teardown(&f);

    /* 4096 x 4096: 4,000 photons on a ring, tiled against the hash grid (the brute force would take
     * minutes here) */
    setup_plane(&f, lm_v3(0.0f, 2.0f, 0.0f), lm_v3(0.0f, 0.0f, 0.0f), 4096);
    f.radius = 0.05f;
    float rx[4000], rz[4000];
    for (int i = 0; i < 4000; i++)
        rx[i] = cosf(0.0015708f * (float)i) * (0.3f + 0.0002f * (float)i), rz[i] = sinf(0.0015708f * (float)i) * 0.8f;
    set_hits(&f, rx, rz, 4000);
    {
        size_t n4 = 3 * (size_t)f.w * (size_t)f.h;
        lm_photon_gather_stats st;
        lm_photon_gather_settings t = kind(LM_PHOTON_GATHER_TILED);
        float *a = gather(&f, &t, 0, &st);
        print_message("4096 x 4096: %d of %d tiles lit, %llu entries, insert %.0f ms, gather %.0f ms\n", st.tiles_lit,
                      st.tiles, (unsigned long long)st.entries, 1e3 * st.t_insert, 1e3 * st.t_gather);
        t = kind(LM_PHOTON_GATHER_HASHGRID);
        float *b = gather(&f, &t, 0, &st);
        double d = max_diff(a, b, n4);
        print_message("4096 x 4096: mean E %.4g, tiled and hash grid differ by %.2g\n", mean(a, n4), d);
        assert_true(mean(a, n4) > 0.0 && d <= 1e-4);
        free(a), free(b);
    }
    teardown(&f);

    /* 200,000 photons of radius 10 over a 512 x 512 frame in 4-pixel tiles: 16,384 tiles each, 3.3e9
     * entries */
    setup_plane(&f, lm_v3(0.0f, 2.0f, 0.0f), lm_v3(0.0f, 0.0f, 0.0f), 512);
    enum { MANY = 200000 };
    float *mx = malloc(MANY * sizeof *mx), *mz = malloc(MANY * sizeof *mz);
    uint32_t seed = 7;
    for (int i = 0; i < MANY; i++) {
        mx[i] = ((float)lmt_xorshift(&seed) / 4294967296.0f - 0.5f) * 4.0f;
        mz[i] = ((float)lmt_xorshift(&seed) / 4294967296.0f - 0.5f) * 4.0f;
    }
    set_hits(&f, mx, mz, MANY);
    free(mx), free(mz);
    s = kind(LM_PHOTON_GATHER_TILED);
    s.tile = 4;
    assert_int_equal(lm_photon_gather_create(&s, &g, &err), LM_OK);
    assert_int_equal(lm_photon_gather_set_records(g, &f.rec, NULL, &err), LM_OK);
    kd = lm_direct_kd_texture(f.d, 0), gb = lm_direct_gbuffer_texture(f.d);
    assert_int_equal(lm_photon_gather_run(g, &f.view, f.w, f.h, kd, gb, 10.0f, 0, NULL, &err), LM_ERR_UNSUPPORTED);
    print_message("refused: %s\n", err.msg);
    assert_non_null(strstr(err.msg, "more than 134217728 entries"));
    lm_photon_gather_free(g);
    teardown(&f);
}

/* A million photons at one point: every one lands in the tile (and the cell) around it; each pixel's E
 * is the million's kernel sum, as the brute force finds it. */
static void test_million_in_one_tile(void **state)
{
    (void)state;
    fixture f;
    setup_plane(&f, lm_v3(0.0f, 2.0f, 0.0f), lm_v3(0.0f, 0.0f, 0.0f), 16); /* one 16-pixel tile */
    f.radius = 0.3f;
    enum { MANY = 1000000 };
    float *x = calloc(MANY, sizeof *x), *z = calloc(MANY, sizeof *z);
    set_hits(&f, x, z, MANY);
    free(x), free(z);
    size_t n = 3 * (size_t)f.w * (size_t)f.h;
    lm_photon_gather_stats st;
    lm_photon_gather_settings s = kind(LM_PHOTON_GATHER_TILED);
    float *tiled = gather(&f, &s, 0, &st);
    print_message("a million photons at one point: %llu entries, %d of %d tiles lit, gather %.0f ms\n",
                  (unsigned long long)st.entries, st.tiles_lit, st.tiles, 1e3 * st.t_gather);
    s = kind(LM_PHOTON_GATHER_HASHGRID);
    float *hash = gather(&f, &s, 0, &st);
    assert_true(max_diff(tiled, hash, n) <= 1e-4);
    /* the kernel sum at the pixel centres (camera straight down from 2 m): E = 1e6 phi kappa / norm */
    const double c = 0.2, r = f.radius, norm = M_PI * c * (1.0 - c + c * c / 3.0) * r * r;
    double worst = 0.0;
    int lit = 0;
    for (int y = 0; y < f.h; y++)
        for (int xx = 0; xx < f.w; xx++) {
            double t = tan(M_PI / 6.0) * 2.0, wx = (2.0 * (xx + 0.5) / f.w - 1.0) * t, wz = -(1.0 - 2.0 * (y + 0.5) / f.h) * t;
            double s_ = sqrt(wx * wx + wz * wz) / r, kappa = s_ < 1.0 ? fmin(c, 1.0 - s_) : 0.0;
            double want = MANY * kappa / norm, got = tiled[3 * ((size_t)y * f.w + xx)];
            if (want > 0.0) {
                lit++;
                worst = fmax(worst, fabs(got / want - 1.0));
            } else {
                assert_true(got == 0.0f || s_ > 0.99);
            }
        }
    print_message("%d pixels lit, the furthest from the kernel sum %.2g\n", lit, worst);
    assert_true(lit > 4);
    assert_true(worst < 0.01);
    free(tiled), free(hash);
    teardown(&f);
}

/* The same records, view and G-buffer: the same bytes, run after run (the lists are filled by atomics in
 * no fixed order; the fixed-point sums make that order not matter). */
static void test_determinism(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(path, lmt_project_scene("cornell.glb"));
    fixture f;
    setup(&f, path, 0.0f, 64, 64);
    for (int k = LM_PHOTON_GATHER_TILED; k <= LM_PHOTON_GATHER_HASHGRID; k++) {
        lm_photon_gather_settings s = kind(k);
        lm_photon_gather_stats st;
        float *a = gather(&f, &s, 0, &st), *b = gather(&f, &s, 0, &st);
        assert_memory_equal(a, b, 3 * (size_t)f.w * (size_t)f.h * sizeof *a);
        free(a), free(b);
    }
    teardown(&f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_records),
        cmocka_unit_test(test_records_dirty_pages),
        cmocka_unit_test(test_gathers_agree),
        cmocka_unit_test(test_borders),
        cmocka_unit_test(test_behind_and_past_the_screen),
        cmocka_unit_test(test_stochastic),
        cmocka_unit_test(test_limits),
        cmocka_unit_test(test_million_in_one_tile),
        cmocka_unit_test(test_determinism),
    };
    return cmocka_run_group_tests(tests, lmt_gl_setup, lmt_gl_teardown);
}
