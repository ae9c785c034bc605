/* The sky (issue 30, item 3): a uniform environment of radiance L. Under it an open plane receives
 * E = pi L (every direction of its hemisphere sees the sky) and leaves rho L; the reference, the gather
 * and the photons must each give that, a box open to the sky must match the reference, an edit of the
 * sky (darker, or given after the updater was made) must reach the lightmaps, and a file's or the API's
 * bad sky must be refused. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>
#include <lmgi_tools.h>
#include <stb/stb_image_write.h>

#include "edit_room.h"
#include "support.h"

#define PI 3.14159265358979323846
#define RHO 0.8 /* lmt_write_gltf's scenes use the default material: 0.8 grey */

static const float k_sky[3] = {1.0f, 0.5f, 0.25f};

/* A 20 x 20 plane facing up; `sky`: the file's extras.lmgi.sky JSON (NULL: none); `light`: one point light
 * 2 above it (KHR_lights_punctual JSON, NULL: none). */
static const char *plane_scene(const char *name, const char *sky, const char *light)
{
    static char path[512];
    lmt_mesh m;
    memset(&m, 0, sizeof m);
    lmt_mesh_quad(&m, (float[3]){-10, 0, 10}, (float[3]){20, 0, 0}, (float[3]){0, 0, -20});
    char extra[1024] = "", nodes[512];
    size_t at = 0;
    if (sky)
        at += (size_t)snprintf(extra + at, sizeof extra - at, "\"extras\": {\"lmgi\": {\"sky\": %s}}, ", sky);
    if (light)
        snprintf(extra + at, sizeof extra - at,
                 "\"extensionsUsed\": [\"KHR_lights_punctual\"], \"extensions\": {\"KHR_lights_punctual\": {\"lights\": [%s]}},",
                 light);
    snprintf(nodes, sizeof nodes, "[{\"mesh\": 0}%s]",
             light ? ", {\"translation\": [0, 2, 0], \"extensions\": {\"KHR_lights_punctual\": {\"light\": 0}}}" : "");
    snprintf(path, sizeof path, "%s/%s.gltf", lmt_tmpdir(), name);
    assert_int_equal(lmt_write_gltf(path, &m, 1, nodes, NULL, 0, extra), 0);
    return path;
}

/* Mean of channel c of the valid texels of a lightmap whose texel centres lie within `inner` of the plane's
 * middle (x and z), from the atlas's texel positions. */
typedef struct {
    double mean[3];
    int n;
} texel_mean;

/* The updater's lightmap of that kind, malloc'd, *n floats (RGBA over the atlas). */
static float *read_lightmap(lmgi_updater *u, lmgi_scene *sc, lmgi_lightmap kind, size_t *n)
{
    lmgi_info in;
    lmgi_get_info(sc, &in);
    *n = 4 * (size_t)in.atlas_width * in.atlas_height;
    float *rgba = malloc(*n * sizeof *rgba);
    assert_non_null(rgba);
    lmgi_error e;
    assert_int_equal(lmgi_get_lightmap(u, kind, rgba, *n, &e), LMGI_OK);
    return rgba;
}

static texel_mean lightmap_mean(lmgi_updater *u, lmgi_scene *sc, lmgi_lightmap kind)
{
    size_t n;
    float *rgba = read_lightmap(u, sc, kind, &n);
    texel_mean m;
    m.n = lmt_texel_mean(rgba, n, m.mean);
    free(rgba);
    return m;
}

/* The plane under the sky alone: the reference's texels E = pi L to its noise (every path escapes at
 * once), the gather's IIM pi L (the hemicube sees nothing but sky: exact), and the photon estimate
 * (AIM) rho L within 3% on average. */
static void test_open_plane(void **state)
{
    (void)state;
    lmgi_scene *sc = lmt_load(plane_scene("open", "[1, 0.5, 0.25]", NULL), 4000);
    float sky[3];
    assert_int_equal(lmgi_get_environment(sc, sky), 1);
    assert_float_equal(sky[1], 0.5f, 0.0f);

    lmgi_error e;
    lmgi_context *ctx = NULL;
    assert_int_equal(lmgi_context_create(NULL, &ctx, &e), LMGI_OK);
    lmgi_updater *u = lmt_updater(ctx, sc);
    texel_mean iim = lightmap_mean(u, sc, LMGI_LIGHTMAP_IIM), aim = lightmap_mean(u, sc, LMGI_LIGHTMAP_AIM);
    double ref[3];
    assert_int_equal(lmt_reference_mean(sc, 0.02f, ref), iim.n);

    for (int c = 0; c < 3; c++) {
        double want = PI * k_sky[c];
        print_message("channel %d: pi L %.4f, reference %.4f, IIM %.4f; rho L %.4f, AIM %.4f\n", c, want, ref[c],
                      iim.mean[c], RHO * k_sky[c], aim.mean[c]);
        assert_float_equal(ref[c] / want, 1.0, 0.005);
        assert_float_equal(iim.mean[c] / want, 1.0, 0.01);
        assert_float_equal(aim.mean[c] / (RHO * k_sky[c]), 1.0, 0.03);
    }
    /* the export carries the sky, and loads back with it */
    lmgi_scene *back = lmt_export_reload(u, "open", 1000);
    float sky_back[3];
    assert_int_equal(lmgi_get_environment(back, sky_back), 1);
    for (int c = 0; c < 3; c++)
        assert_float_equal(sky_back[c], k_sky[c], 0.0f);
    lmgi_free(back);
    lmgi_updater_free(u);
    lmgi_free(sc);
    lmgi_context_free(ctx);
}

/* An edit of the sky is taken up like a light's: twice the sky, twice the lightmap after a bake; a sky
 * given to a scene lit by a lamp after its updater was made adds pi L to every texel's IIM. */
static void test_sky_edits(void **state)
{
    (void)state;
    lmgi_error e;
    lmgi_context *ctx = NULL;
    assert_int_equal(lmgi_context_create(NULL, &ctx, &e), LMGI_OK);
    lmgi_scene *sc = lmt_load(plane_scene("edit", "[1, 0.5, 0.25]", NULL), 4000);
    lmgi_updater *u = lmt_updater(ctx, sc);
    texel_mean before = lightmap_mean(u, sc, LMGI_LIGHTMAP_IIM);
    const float twice[3] = {2.0f, 1.0f, 0.5f};
    assert_int_equal(lmgi_set_environment(sc, twice, &e), LMGI_OK);
    assert_int_equal(lmgi_bake(u, NULL, NULL, &e), LMGI_OK);
    texel_mean after = lightmap_mean(u, sc, LMGI_LIGHTMAP_IIM);
    for (int c = 0; c < 3; c++)
        assert_float_equal(after.mean[c] / before.mean[c], 2.0, 0.02);
    lmgi_updater_free(u);
    lmgi_free(sc);

    /* the lamp's plane sees nothing of it (no other surface): its IIM is 0 until the sky comes */
    sc = lmt_load(plane_scene("lamp", NULL, "{\"type\": \"point\", \"intensity\": 10}"), 4000);
    assert_int_equal(lmgi_get_environment(sc, NULL), 0);
    u = lmt_updater(ctx, sc);
    before = lightmap_mean(u, sc, LMGI_LIGHTMAP_IIM);
    assert_int_equal(lmgi_set_environment(sc, k_sky, &e), LMGI_OK);
    assert_int_equal(lmgi_bake(u, NULL, NULL, &e), LMGI_OK);
    after = lightmap_mean(u, sc, LMGI_LIGHTMAP_IIM);
    for (int c = 0; c < 3; c++) {
        print_message("channel %d: IIM %.4f before the sky, %.4f after (pi L = %.4f)\n", c, before.mean[c],
                      after.mean[c], PI * k_sky[c]);
        assert_true(before.mean[c] == 0.0);
        assert_float_equal(after.mean[c] / (PI * k_sky[c]), 1.0, 0.01);
    }
    lmgi_updater_free(u);
    lmgi_free(sc);
    lmgi_context_free(ctx);
}

/* A box open at the top (floor and four walls of 2 m, the camera above looking in) under the sky alone:
 * the frame against the reference, over the frame within 5%: the sky through the opening, bounced. */
static void test_open_box_against_reference(void **state)
{
    (void)state;
    lmt_mesh m[5];
    memset(m, 0, sizeof m);
    lmt_mesh_quad(&m[0], (float[3]){-1, 0, 1}, (float[3]){2, 0, 0}, (float[3]){0, 0, -2});   /* floor, up */
    lmt_mesh_quad(&m[1], (float[3]){-1, 0, -1}, (float[3]){2, 0, 0}, (float[3]){0, 2, 0});   /* back, +z */
    lmt_mesh_quad(&m[2], (float[3]){1, 0, 1}, (float[3]){-2, 0, 0}, (float[3]){0, 2, 0});    /* front, -z */
    lmt_mesh_quad(&m[3], (float[3]){-1, 0, 1}, (float[3]){0, 0, -2}, (float[3]){0, 2, 0});   /* left, +x */
    lmt_mesh_quad(&m[4], (float[3]){1, 0, -1}, (float[3]){0, 0, 2}, (float[3]){0, 2, 0});    /* right, -x */
    char path[512];
    snprintf(path, sizeof path, "%s/box.gltf", lmt_tmpdir());
    const char *nodes = "[{\"mesh\": 0}, {\"mesh\": 1}, {\"mesh\": 2}, {\"mesh\": 3}, {\"mesh\": 4}, "
                        "{\"camera\": 0, \"translation\": [0, 3.2, 0.9], \"rotation\": [-0.6427876, 0, 0, 0.7660444]}]";
    assert_int_equal(lmt_write_gltf(path, m, 5, nodes, NULL, 0,
                                    "\"extras\": {\"lmgi\": {\"sky\": [1, 0.5, 0.25]}}, \"cameras\": [{\"type\": "
                                    "\"perspective\", \"perspective\": {\"yfov\": 1.0, \"znear\": 0.05}}],"),
                     0);
    lmgi_scene *sc = lmt_load(path, 6000);
    lmgi_error e;
    lmgi_context *ctx = NULL;
    assert_int_equal(lmgi_context_create(NULL, &ctx, &e), LMGI_OK);
    lmgi_updater_desc ud;
    memset(&ud, 0, sizeof ud);
    ud.frame.width = ud.frame.height = 64;
    lmgi_reference_desc rd;
    memset(&rd, 0, sizeof rd);
    rd.target_error = 0.03f;
    rd.no_cache = 1;
    lmgi_check_result c;
    assert_int_equal(lmgi_check(ctx, sc, &ud, &rd, 1, &c, &e), LMGI_OK);
    print_message("open box under the sky: frame / reference %.4f %.4f %.4f over %u pixels, relative RMSE %.4f\n",
                  c.ratio[0], c.ratio[1], c.ratio[2], c.pixels, c.rel_rmse);
    assert_true(c.pixels > 64 * 64 / 2);
    for (int k = 0; k < 3; k++)
        assert_float_equal(c.ratio[k], 1.0, 0.05);
    lmgi_check_free(&c);
    lmgi_free(sc);
    lmgi_context_free(ctx);
}

/* The gradient sky L(d) = H + (Z - H) max(d.y, 0) over an open plane: E = pi H + 2 pi (Z - H) / 3. */
static const float k_zenith[3] = {1.0f, 0.5f, 0.25f}, k_horizon[3] = {0.2f, 0.3f, 0.4f};

static double gradient_e(int c) { return PI * k_horizon[c] + 2.0 * PI * (k_zenith[c] - k_horizon[c]) / 3.0; }

/* An open plane under `sc`'s sky: the reference's texels, the IIM and the AIM (rho / pi E) against
 * scale x gradient_e within the given tolerances; the updater's gather is the rays scheme. */
static void plane_against(lmgi_scene *sc, double scale, double ref_tol, double iim_tol, double aim_tol)
{
    lmgi_error e;
    lmgi_context *ctx = NULL;
    assert_int_equal(lmgi_context_create(NULL, &ctx, &e), LMGI_OK);
    lmgi_updater *u = lmt_updater(ctx, sc);
    lmgi_updater_info ui;
    lmgi_get_updater_info(u, &ui);
    assert_string_equal(ui.gather_scheme, "rays");
    texel_mean iim = lightmap_mean(u, sc, LMGI_LIGHTMAP_IIM), aim = lightmap_mean(u, sc, LMGI_LIGHTMAP_AIM);
    double ref[3];
    lmt_reference_mean(sc, 0.02f, ref);
    for (int c = 0; c < 3; c++) {
        double want = scale * gradient_e(c);
        print_message("channel %d: E %.4f, reference %.4f, IIM %.4f; rho / pi E %.4f, AIM %.4f\n", c, want, ref[c],
                      iim.mean[c], RHO / PI * want, aim.mean[c]);
        assert_float_equal(ref[c] / want, 1.0, ref_tol);
        assert_float_equal(iim.mean[c] / want, 1.0, iim_tol);
        assert_float_equal(aim.mean[c] / (RHO / PI * want), 1.0, aim_tol);
    }
    lmgi_updater_free(u);
    lmgi_context_free(ctx);
}

/* A gradient sky from the file; its export loads back with it. An updater told to draw hemicubes refuses
 * it, and so does such an updater when the sky turns into one afterwards. */
static void test_gradient_sky(void **state)
{
    (void)state;
    lmgi_scene *sc = lmt_load(plane_scene("gradient", "{\"zenith\": [1, 0.5, 0.25], \"horizon\": [0.2, 0.3, 0.4]}",
                                          NULL), 4000);
    plane_against(sc, 1.0, 0.01, 0.01, 0.04);
    lmgi_error e;
    lmgi_context *ctx = NULL;
    assert_int_equal(lmgi_context_create(NULL, &ctx, &e), LMGI_OK);
    lmgi_updater *u = lmt_updater(ctx, sc); /* its export carries the gradient: reloaded, the same E */
    lmgi_scene *back = lmt_export_reload(u, "gradient", 4000);
    lmgi_updater_free(u);
    plane_against(back, 1.0, 0.01, 0.01, 0.04);
    lmgi_free(back);
    lmgi_updater_desc d;
    memset(&d, 0, sizeof d);
    d.gather.scheme = LMGI_GATHER_VIEWPORTS;
    u = NULL;
    assert_int_equal(lmgi_updater_create(ctx, sc, &d, &u, &e), LMGI_ERR_INVALID);
    assert_non_null(strstr(e.message, "rays gather"));
    assert_int_equal(lmgi_set_environment(sc, k_sky, &e), LMGI_OK); /* uniform again: hemicubes may show it */
    assert_int_equal(lmgi_updater_create(ctx, sc, &d, &u, &e), LMGI_OK);
    assert_int_equal(lmgi_set_environment_gradient(sc, k_zenith, k_horizon, &e), LMGI_ERR_INVALID);
    assert_non_null(strstr(e.message, "rays gather"));
    float now[3];
    assert_int_equal(lmgi_get_environment(sc, now), 1);
    assert_float_equal(now[1], k_sky[1], 0.0f); /* nothing changed */
    lmgi_updater_free(u);
    lmgi_free(sc);
    lmgi_context_free(ctx);
}

/* An equirectangular HDR image of the same gradient (64 x 32 pixels: each row's mean direction's height),
 * as Radiance .hdr from the file's extras (its URI percent-encoded) with a scale of 2, and as OpenEXR through the API: the plane gets
 * twice, then once, the gradient's E (within the image's rows' resolution). A PNG named .hdr, a negative
 * pixel, a missing file: refused, naming the file. */
static void test_image_sky(void **state)
{
    (void)state;
    enum { W = 64, H = 32 };
    float *px = malloc(sizeof(float) * 3 * W * H);
    assert_non_null(px);
    for (int y = 0; y < H; y++) {
        /* the row's mean of max(cos theta, 0) over its band of theta, weighted by sin theta: exact for the
         * bilinear lookup's piecewise linearity to first order */
        double t0 = PI * y / H, t1 = PI * (y + 1) / H, c0 = cos(t0), c1 = cos(t1);
        double up = c0 > 0.0 ? (c0 * c0 - fmax(c1, 0.0) * fmax(c1, 0.0)) / 2.0 : 0.0, band = c0 - c1;
        for (int x = 0; x < W; x++)
            for (int c = 0; c < 3; c++)
                px[3 * (y * W + x) + c] = (float)(k_horizon[c] + (k_zenith[c] - k_horizon[c]) * up / band);
    }
    /* percent-encoded, as exporters write URIs: "my sky.hdr" */
    const char *scene = plane_scene("image", "{\"image\": \"my%20sky.hdr\", \"scale\": 2}", NULL);
    char dir[512], path[600];
    snprintf(dir, sizeof dir, "%s", scene);
    *strrchr(dir, '/') = '\0';
    snprintf(path, sizeof path, "%s/my sky.hdr", dir);
    assert_true(stbi_write_hdr(path, W, H, 3, px) != 0);
    lmgi_scene *sc = lmt_load(scene, 4000);
    plane_against(sc, 2.0, 0.02, 0.02, 0.05);
    lmgi_error e;
    snprintf(path, sizeof path, "%s/sky.exr", dir);
    assert_int_equal(lmgi_write_image(path, W, H, 3, px, NULL, &e), LMGI_OK);
    assert_int_equal(lmgi_set_environment_image(sc, path, 1.0f, &e), LMGI_OK);
    plane_against(sc, 1.0, 0.02, 0.02, 0.05);

    /* not an HDR image, a negative pixel, no file: refused, named, the sky as it was */
    snprintf(path, sizeof path, "%s/fake.hdr", dir);
    const unsigned char png[] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n', 0, 0, 0, 0};
    lmt_write_file(path, png, sizeof png);
    assert_int_equal(lmgi_set_environment_image(sc, path, 1.0f, &e), LMGI_ERR_FORMAT);
    assert_non_null(strstr(e.message, "fake.hdr"));
    px[7] = -1.0f;
    snprintf(path, sizeof path, "%s/negative.exr", dir);
    assert_int_equal(lmgi_write_image(path, W, H, 3, px, NULL, &e), LMGI_OK);
    assert_int_equal(lmgi_set_environment_image(sc, path, 1.0f, &e), LMGI_ERR_INVALID);
    assert_non_null(strstr(e.message, "negative"));
    assert_int_equal(lmgi_set_environment_image(sc, "/nonexistent/sky.hdr", 1.0f, &e), LMGI_ERR_IO);
    assert_int_equal(lmgi_set_environment_image(sc, path, NAN, &e), LMGI_ERR_INVALID);
    float now[3];
    assert_int_equal(lmgi_get_environment(sc, now), 1);
    assert_float_equal(now[0], 1.0f, 0.0f); /* the EXR sky's scale */
    free(px);
    lmgi_free(sc);
}

/* The bilinear lookup of sky.h's equirectangular image (u wrapping, v clamped), the test's own. */
static double image_lookup(const float *px, int w, int h, double u, double v, int c)
{
    double x = u * w - 0.5, y = fmin(fmax(v * h - 0.5, 0.0), h - 1);
    x -= floor(x / w) * w;
    int x0 = (int)x % w, x1 = (x0 + 1) % w, y0 = (int)y, y1 = y0 + 1 < h ? y0 + 1 : y0;
    double fx = x - floor(x), fy = y - y0;
    return (1 - fy) * ((1 - fx) * px[3 * (y0 * w + x0) + c] + fx * px[3 * (y0 * w + x1) + c]) +
           fy * ((1 - fx) * px[3 * (y1 * w + x0) + c] + fx * px[3 * (y1 * w + x1) + c]);
}

/* A lightmap of the scene's updater (u, or one made here): its mean and its texels' relative standard
 * deviation (channel sums), over the valid texels. */
static double map_spread(lmgi_context *ctx, lmgi_updater *u, lmgi_scene *sc, lmgi_lightmap kind, double mean[3])
{
    lmgi_updater *own = u ? NULL : lmt_updater(ctx, sc);
    size_t n;
    float *aim = read_lightmap(u ? u : own, sc, kind, &n);
    double y_mean = 0.0, y_sq = 0.0;
    int texels = lmt_texel_mean(aim, n, mean);
    for (size_t i = 0; i < n / 4; i++)
        if (aim[4 * i + 3] > 0.0f) {
            double y = aim[4 * i] + aim[4 * i + 1] + aim[4 * i + 2];
            y_mean += y / texels, y_sq += y * y / texels;
        }
    free(aim);
    lmgi_updater_free(own);
    return sqrt(fmax(y_sq - y_mean * y_mean, 0.0)) / y_mean;
}

/* An HDR sky with a sun in it: a dim blue sky and a 2 x 2 pixel sun 10,000 times as bright, 40 degrees
 * up, giving about 97% of what an open floor receives. Drawn uniformly, the sky's photons would leave the
 * sun to about 1 in 400 of them, each carrying hundreds of times the mean flux: the floor's AIM a field of
 * spots; and the rays gather's one ray a stratum would find the sun or miss it, texel by texel. Drawn by
 * brightness (sky.h), and met by the gather's and the reference's own drawn directions too
 * (hemicube_rim.c, ref_paths.c): the AIM's mean within 3% of rho / pi E, the IIM's and the reference's
 * within 1% of E (E integrated from the image here; the reference without its light samples stopped
 * 19% dark after 28 s, a pixel that had not met the sun yet looking converged), the AIM's
 * texels as even as under a uniform sky of that E with the same photons (relative standard deviation
 * within 1.25 times: the photon estimate's own noise; measured 0.73 times, the sun's photons being
 * parallel), the IIM's under 0.12 (measured 0.083; 0.57 with one ray a stratum alone). */
static void test_image_sky_with_a_sun(void **state)
{
    (void)state;
    enum { W = 64, H = 32 };
    float *px = malloc(sizeof(float) * 3 * W * H);
    assert_non_null(px);
    for (int i = 0; i < W * H; i++) {
        int x = i % W, y = i / W, sun = (x == 40 || x == 41) && (y == 8 || y == 9);
        px[3 * i] = sun ? 400.0f : 0.02f, px[3 * i + 1] = sun ? 380.0f : 0.03f, px[3 * i + 2] = sun ? 350.0f : 0.06f;
    }
    double e_sky[3] = {0, 0, 0}; /* E = integral of L cos(theta) over the upper half, theta = pi v, phi = 2 pi u */
    const int NU = 1024, NV = 512;
    for (int j = 0; j < NV; j++) {
        double v = 0.5 * (j + 0.5) / NV, t = PI * v, dw = (2.0 * PI / NU) * (PI * 0.5 / NV) * sin(t) * cos(t);
        for (int i = 0; i < NU; i++)
            for (int c = 0; c < 3; c++)
                e_sky[c] += dw * image_lookup(px, W, H, (i + 0.5) / NU, v, c);
    }
    const char *scene = plane_scene("sun_image", NULL, NULL);
    char path[600];
    snprintf(path, sizeof path, "%s", scene);
    snprintf(strrchr(path, '/'), 32, "/sun.exr");
    lmgi_error e;
    assert_int_equal(lmgi_write_image(path, W, H, 3, px, NULL, &e), LMGI_OK);
    lmgi_scene *sc = lmt_load(scene, 4000);
    lmgi_context *ctx = NULL;
    assert_int_equal(lmgi_context_create(NULL, &ctx, &e), LMGI_OK);
    float even[3]; /* a uniform sky of the same E: pi L = E */
    for (int c = 0; c < 3; c++)
        even[c] = (float)(e_sky[c] / PI);
    assert_int_equal(lmgi_set_environment(sc, even, &e), LMGI_OK);
    double mean[3], iim[3], spread_even = map_spread(ctx, NULL, sc, LMGI_LIGHTMAP_AIM, mean);
    assert_int_equal(lmgi_set_environment_image(sc, path, 1.0f, &e), LMGI_OK);
    lmgi_updater *u = lmt_updater(ctx, sc);
    double spread = map_spread(ctx, u, sc, LMGI_LIGHTMAP_AIM, mean);
    double spread_iim = map_spread(ctx, u, sc, LMGI_LIGHTMAP_IIM, iim), ref[3];
    lmt_reference_mean(sc, 0.02f, ref);
    print_message("relative standard deviation of the texels: AIM %.3f (under a uniform sky of the same E %.3f), "
                  "IIM %.4f\n", spread, spread_even, spread_iim);
    for (int c = 0; c < 3; c++) {
        print_message("channel %d: E %.4f, reference %.4f (%+.2f%%), IIM %.4f (%+.2f%%); rho / pi E %.4f, AIM %.4f "
                      "(%+.2f%%)\n", c, e_sky[c], ref[c], 100.0 * (ref[c] / e_sky[c] - 1.0), iim[c],
                      100.0 * (iim[c] / e_sky[c] - 1.0), RHO / PI * e_sky[c], mean[c],
                      100.0 * (mean[c] / (RHO / PI * e_sky[c]) - 1.0));
        assert_float_equal(ref[c] / e_sky[c], 1.0, 0.01);
        assert_float_equal(mean[c] / (RHO / PI * e_sky[c]), 1.0, 0.03);
        assert_float_equal(iim[c] / e_sky[c], 1.0, 0.01);
    }
    assert_true(spread < 1.25 * spread_even);
    assert_true(spread_iim < 0.12);
    lmgi_updater_free(u);
    free(px);
    lmgi_free(sc);
    lmgi_context_free(ctx);
}

/* The frame's background is the sky as it is by direction: the middle pixel of a frame looking at the
 * horizon shows the horizon's radiance, one looking 45 degrees up H + (Z - H) sin 45 (the sky pass, to
 * float precision); a uniform sky is its one colour. */
static void test_sky_behind_everything(void **state)
{
    (void)state;
    lmgi_scene *sc = lmt_load(plane_scene("behind", "{\"zenith\": [1, 0.5, 0.25], \"horizon\": [0.2, 0.3, 0.4]}",
                                          NULL), 2000);
    lmgi_error e;
    lmgi_context *ctx = NULL;
    assert_int_equal(lmgi_context_create(NULL, &ctx, &e), LMGI_OK);
    lmgi_updater *u = lmt_updater(ctx, sc);
    enum { SIDE = 33 };
    float rgb[3 * SIDE * SIDE];
    const float eye[3] = {0, 1, 0}, level[3] = {1, 1, 0}, up[3] = {1, 2, 0};
    const double rise[2] = {0.0, sqrt(0.5)};
    for (int k = 0; k < 2; k++) {
        lmgi_camera cam;
        lmt_look_at(eye, k ? up : level, 1.0f, &cam);
        assert_int_equal(lmgi_render(u, &cam, SIDE, SIDE, rgb, &e), LMGI_OK);
        const float *mid = rgb + 3 * (SIDE / 2 * SIDE + SIDE / 2);
        for (int c = 0; c < 3; c++)
            assert_float_equal(mid[c], k_horizon[c] + (k_zenith[c] - k_horizon[c]) * rise[k], 1e-4);
    }
    lmgi_updater_free(u);
    lmgi_free(sc);
    lmgi_context_free(ctx);
}

/* A sky of NaN, a negative one, or a malformed one in the file: refused, naming it, nothing changed. */
static void test_bad_sky(void **state)
{
    (void)state;
    lmgi_error e;
    lmgi_scene *sc = NULL;
    const char *bad[] = {"[1, 2]", "[1, -1, 0]", "[1, \"a\", 0]", "[1e30, 0, 0]"};
    for (int k = 0; k < 4; k++) {
        assert_int_equal(lmgi_load(plane_scene("bad", bad[k], NULL), NULL, &sc, &e), LMGI_ERR_INVALID);
        assert_non_null(strstr(e.message, "extras.lmgi.sky"));
        assert_null(sc);
    }
    sc = lmt_load(plane_scene("good", NULL, NULL), 1000);
    const float nan_sky[3] = {NAN, 0, 0}, negative[3] = {0, -1, 0};
    assert_int_equal(lmgi_set_environment(sc, nan_sky, &e), LMGI_ERR_INVALID);
    assert_non_null(strstr(e.message, "sky radiance"));
    assert_int_equal(lmgi_set_environment(sc, negative, &e), LMGI_ERR_INVALID);
    assert_int_equal(lmgi_set_environment(sc, NULL, &e), LMGI_ERR_INVALID);
    assert_int_equal(lmgi_get_environment(sc, NULL), 0); /* nothing changed */
    lmgi_free(sc);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_open_plane),
        cmocka_unit_test(test_sky_edits),
        cmocka_unit_test(test_open_box_against_reference),
        cmocka_unit_test(test_gradient_sky),
        cmocka_unit_test(test_image_sky),
        cmocka_unit_test(test_image_sky_with_a_sun),
        cmocka_unit_test(test_sky_behind_everything),
        cmocka_unit_test(test_bad_sky),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
