/* EXT_lights_image_based as the scene's sky (issue 30, "real levels"; docs/levels.md, "Sky"). Each test
 * writes a 20 x 20 plane (y = 0, facing up) whose scene names an image-based light, the six faces of its
 * mip 0 made here so that they encode a known function of direction, and checks what lmgi makes of it
 * against that function: the radiance by direction (every face's colour and orientation, Babylon.js's
 * layout), its mean, the irradiance of the plane (E = integral of L cos), a rotation, the intensity, an
 * LDR JPEG set, the export's round trip, lmgi's own extras winning, and bad lights refused by name. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <cmocka.h>
#include <lmgi.h>
#include <stb/stb_image_write.h>

#include "../src/api/lmgi_scene.h"
#include "../src/core/image.h"
#include "../src/core/log.h"
#include "../src/scene/sky.h"
#include "edit_room.h"
#include "support.h"

#define PI 3.14159265358979323846
enum { N = 32 };

/* An encoded image file in memory. */
typedef struct {
    unsigned char *data;
    size_t size;
    const char *mime, *ext;
} blob;

static void blob_put(void *user, void *data, int n)
{
    blob *b = user;
    b->data = realloc(b->data, b->size + (size_t)n);
    assert_non_null(b->data);
    memcpy(b->data + b->size, data, (size_t)n);
    b->size += (size_t)n;
}

/* Face k of the test cube, w x h pixels, as RGBD in a 4-channel PNG: red 2 + k (above 1, so RGBD's alpha
 * is below 1), green 2u and blue 2v at the texel centre (u, v) of the image (u from the left, v from the
 * top): the colour says the face, green and blue where on it. */
static blob rgbd_face(int k, int w, int h)
{
    float *rgba = malloc(4 * sizeof(float) * (size_t)w * h);
    uint8_t *px = malloc(4 * (size_t)w * h);
    assert_true(rgba && px);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            float *p = rgba + 4 * ((size_t)y * w + x);
            p[0] = 2.0f + k, p[1] = 2.0f * (x + 0.5f) / w, p[2] = 2.0f * (y + 0.5f) / h, p[3] = 1.0f;
        }
    lm_encode_rgbd(rgba, (size_t)w * h, 1.0f, px);
    blob b = {NULL, 0, "image/png", "png"};
    assert_true(stbi_write_png_to_func(blob_put, &b, w, h, 4, px, 4 * w) != 0);
    free(rgba);
    free(px);
    return b;
}

/* An LDR face of one 8-bit colour, a JPEG (no alpha: LDR, the spec says). */
static blob jpeg_face(const uint8_t rgb[3])
{
    uint8_t px[3 * N * N];
    for (int i = 0; i < N * N; i++)
        memcpy(px + 3 * i, rgb, 3);
    blob b = {NULL, 0, "image/jpeg", "jpg"};
    assert_true(stbi_write_jpg_to_func(blob_put, &b, N, N, 3, px, 100) != 0);
    return b;
}

/* The six faces of the test cube, n x n. */
static void rgbd_cube(blob faces[6], int n)
{
    for (int k = 0; k < 6; k++)
        faces[k] = rgbd_face(k, n, n);
}

static void faces_free(blob *f, int n)
{
    for (int i = 0; i < n; i++)
        free(f[i].data);
}

enum { DATA_URIS, BUFFER_VIEWS, FILES };

typedef struct {
    const char *name;      /* the scene's file name, in dir */
    const char *dir;       /* NULL: a fresh temporary folder */
    const blob *images;    /* the glTF images */
    int image_count;       /* 0: 6 */
    int where;             /* how the images are stored: DATA_URIS, BUFFER_VIEWS, FILES (named uri_prefix +
                            * "face<i>.<ext>", written into dir unless uri_prefix is set) */
    const char *uri_prefix;
    const char *light;     /* more of the light's properties, each followed by ", " (NULL: none) */
    const char *specular;  /* its specularImages (NULL: [[0, 1, 2, 3, 4, 5]]) */
    int scene_light;       /* the light the scene names */
    const char *extras;    /* the root's extras (NULL: none) */
} ibl_desc;

/* Writes the plane and its image-based light as d says; returns the file's path (static storage). */
static const char *ibl_scene(const ibl_desc *d)
{
    static char path[600];
    const char *dir = d->dir ? d->dir : lmt_tmpdir();
    int count = d->image_count ? d->image_count : 6;
    const float pos[12] = {-10, 0, 10, 10, 0, 10, 10, 0, -10, -10, 0, -10};
    const uint16_t idx[6] = {0, 1, 2, 0, 2, 3};
    size_t size = 60, at[16];
    for (int i = 0; i < count && d->where == BUFFER_VIEWS; i++) {
        at[i] = size;
        size += (d->images[i].size + 3) & ~(size_t)3;
    }
    unsigned char *buf = calloc(size, 1);
    char *b64 = malloc(4 * (size / 3 + 1) + 1);
    assert_true(buf && b64);
    memcpy(buf, pos, sizeof pos);
    memcpy(buf + 48, idx, sizeof idx);
    for (int i = 0; i < count && d->where == BUFFER_VIEWS; i++)
        memcpy(buf + at[i], d->images[i].data, d->images[i].size);
    lmt_base64(buf, size, b64);

    snprintf(path, sizeof path, "%s/%s", dir, d->name);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fprintf(f, "{\"asset\": {\"version\": \"2.0\"}, \"extensionsUsed\": [\"EXT_lights_image_based\"], "
               "\"extensionsRequired\": [\"EXT_lights_image_based\"],\n\"extensions\": {\"EXT_lights_image_based\": "
               "{\"lights\": [{%s\"irradianceCoefficients\": [[0, 0, 0], [0, 0, 0], [0, 0, 0], [0, 0, 0], [0, 0, 0], "
               "[0, 0, 0], [0, 0, 0], [0, 0, 0], [0, 0, 0]], \"specularImageSize\": %d, \"specularImages\": %s}]}},\n",
            d->light ? d->light : "", N, d->specular ? d->specular : "[[0, 1, 2, 3, 4, 5]]");
    fprintf(f, "\"scene\": 0, \"scenes\": [{\"nodes\": [0], \"extensions\": {\"EXT_lights_image_based\": "
               "{\"light\": %d}}}],\n\"nodes\": [{\"mesh\": 0}], \"meshes\": [{\"primitives\": [{\"attributes\": "
               "{\"POSITION\": 0}, \"indices\": 1}]}],\n\"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, "
               "\"count\": 4, \"type\": \"VEC3\", \"min\": [-10, 0, -10], \"max\": [10, 0, 10]}, {\"bufferView\": 1, "
               "\"componentType\": 5123, \"count\": 6, \"type\": \"SCALAR\"}],\n",
            d->scene_light);
    fprintf(f, "\"bufferViews\": [{\"buffer\": 0, \"byteLength\": 48}, {\"buffer\": 0, \"byteOffset\": 48, "
               "\"byteLength\": 12}");
    for (int i = 0; i < count && d->where == BUFFER_VIEWS; i++)
        fprintf(f, ", {\"buffer\": 0, \"byteOffset\": %zu, \"byteLength\": %zu}", at[i], d->images[i].size);
    fprintf(f, "],\n\"buffers\": [{\"byteLength\": %zu, \"uri\": \"data:application/octet-stream;base64,%s\"}],\n"
               "\"images\": [", size, b64);
    for (int i = 0; i < count; i++) {
        const blob *im = &d->images[i];
        if (d->where == BUFFER_VIEWS) {
            fprintf(f, "%s{\"bufferView\": %d, \"mimeType\": \"%s\"}", i ? ", " : "", 2 + i, im->mime);
        } else if (d->where == FILES) {
            char file[700];
            snprintf(file, sizeof file, "%s/face%d.%s", dir, i, im->ext);
            if (!d->uri_prefix)
                lmt_write_file(file, im->data, im->size);
            fprintf(f, "%s{\"uri\": \"%sface%d.%s\"}", i ? ", " : "", d->uri_prefix ? d->uri_prefix : "", i, im->ext);
        } else {
            char *text = malloc(4 * (im->size / 3 + 1) + 1);
            assert_non_null(text);
            lmt_base64(im->data, im->size, text);
            fprintf(f, "%s{\"uri\": \"data:%s;base64,%s\"}", i ? ", " : "", im->mime, text);
            free(text);
        }
    }
    fprintf(f, "]%s%s}\n", d->extras ? ",\n\"extras\": " : "", d->extras ? d->extras : "");
    fclose(f);
    free(buf);
    free(b64);
    return path;
}

/* A unit direction in the scene. */
static void unit(float x, float y, float z, float d[3])
{
    float n = sqrtf(x * x + y * y + z * z);
    d[0] = x / n, d[1] = y / n, d[2] = z / n;
}

/* The scene's sky towards (x, y, z) against want[] (each channel within tol of its value, relatively). */
static void sky_is(const lmgi_scene *sc, float x, float y, float z, const double want[3], double tol)
{
    float d[3], got[3];
    unit(x, y, z, d);
    lm_sky_radiance(sc->scene, d, got);
    print_message("towards (%g, %g, %g): %.4f %.4f %.4f, want %.4f %.4f %.4f\n", (double)x, (double)y, (double)z,
                  (double)got[0], (double)got[1], (double)got[2], want[0], want[1], want[2]);
    for (int c = 0; c < 3; c++)
        assert_float_equal(got[c] / want[c], 1.0, tol);
}

/* Where the test cube's faces show, as Babylon.js lays them out: the scene's -x sees face +X and +x face -X
 * (cube maps are left-handed), each face's image upside down against OpenGL's layout (the extension's
 * flip). So towards (-1, 0.5, 0.25) lies face +X (red 2) at (u, v) = (0.375, 0.75): its left half looks
 * to +z, its bottom half up. Each row: a direction and the face colour (2 + k, 2u, 2v) there. */
static const struct {
    float d[3];
    double want[3];
} k_seen[] = {
    {{-1, 0.5f, 0.25f}, {2, 0.75, 1.5}},  /* +X at (0.375, 0.75) */
    {{1, 0.5f, 0.25f}, {3, 1.25, 1.5}},   /* -X at (0.625, 0.75) */
    {{0.25f, 1, -0.5f}, {4, 0.75, 1.5}},  /* +Y at (0.375, 0.75) */
    {{0.25f, -1, -0.5f}, {5, 0.75, 0.5}}, /* -Y at (0.375, 0.25) */
    {{0.25f, 0.5f, 1}, {6, 0.75, 1.5}},   /* +Z at (0.375, 0.75) */
    {{0.25f, 0.5f, -1}, {7, 1.25, 1.5}},  /* -Z at (0.625, 0.75) */
};

/* Six RGBD faces as data: URIs: every face's colour and orientation where Babylon.js shows them (within
 * 2%: RGBD's 8 bits and two bilinear lookups); an equirectangular image of 4n x 2n for faces of n; its mean
 * the faces' mean (each face covers a sixth of the sphere: red 4.5, green and blue 1). Faces of 600 (not a
 * power of two: read all the same) make an image of the most, 2048 x 1024, each pixel the mean of 2 x 2
 * lookups, and the same sky. */
static void test_rgbd_faces(void **state)
{
    (void)state;
    static const int side[2] = {N, 600}, width[2] = {4 * N, 2048};
    for (int t = 0; t < 2; t++) {
        blob faces[6];
        rgbd_cube(faces, side[t]);
        ibl_desc d = {.name = "rgbd.gltf", .images = faces, .where = DATA_URIS};
        lmgi_scene *sc = lmt_load(ibl_scene(&d), 1000);
        const lm_scene *s = sc->scene;
        assert_int_equal(s->has_sky, 1);
        assert_int_equal(s->sky_kind, LM_SKY_IMAGE);
        assert_int_equal(s->sky_width, width[t]);
        assert_int_equal(s->sky_height, width[t] / 2);
        for (size_t i = 0; i < sizeof k_seen / sizeof k_seen[0]; i++)
            sky_is(sc, k_seen[i].d[0], k_seen[i].d[1], k_seen[i].d[2], k_seen[i].want, 0.02);
        float mean[3], scale[3];
        lm_sky_mean(s, mean);
        print_message("faces of %d: mean %.4f %.4f %.4f\n", side[t], (double)mean[0], (double)mean[1],
                      (double)mean[2]);
        assert_float_equal(mean[0], 4.5, 4.5 * 0.01);
        assert_float_equal(mean[1], 1.0, 0.01);
        assert_float_equal(mean[2], 1.0, 0.01);
        assert_int_equal(lmgi_get_environment(sc, scale), 1);
        assert_float_equal(scale[0], 1.0f, 0.0f);
        lmgi_free(sc);
        faces_free(faces, 6);
    }
}

/* The same faces from a bufferView, turned by 90 degrees about y and 3 times as intense. Babylon.js rotates
 * the direction it looks up (in its left-handed space: R(q)^T after the mirror), so face +X, seen towards -x
 * unturned, is seen towards -z, and -Z towards +x; up stays face +Y, turned: towards (0.25, 1, -0.5) it
 * shows at (0.75, 0.625). The scale is 3, the mean 3 times the faces'. */
static void test_rotation_intensity(void **state)
{
    (void)state;
    blob faces[6];
    rgbd_cube(faces, N);
    ibl_desc d = {.name = "turned.gltf", .images = faces, .where = BUFFER_VIEWS,
                  .light = "\"intensity\": 3, \"rotation\": [0, 0.70710678, 0, 0.70710678], "};
    lmgi_scene *sc = lmt_load(ibl_scene(&d), 1000);
    const double plus_x[3] = {6, 3, 3}, minus_z[3] = {21, 3, 3}, minus_x[3] = {9, 3, 3}, plus_z[3] = {18, 3, 3};
    const double top[3] = {12, 4.5, 3.75};
    sky_is(sc, 0, 0, -1, plus_x, 0.02);
    sky_is(sc, 1, 0, 0, minus_z, 0.02);
    sky_is(sc, 0, 0, 1, minus_x, 0.02);
    sky_is(sc, -1, 0, 0, plus_z, 0.02);
    sky_is(sc, 0.25f, 1, -0.5f, top, 0.02);
    float scale[3], mean[3];
    assert_int_equal(lmgi_get_environment(sc, scale), 1);
    assert_float_equal(scale[0], 3.0f, 0.0f);
    lm_sky_mean(sc->scene, mean);
    assert_float_equal(mean[0], 13.5, 13.5 * 0.01);
    lmgi_free(sc);
    faces_free(faces, 6);
}

/* LDR JPEG faces (one colour each) in files beside the scene: 8-bit c reads as (c / 255)^2.2, Babylon.js's
 * RGBD decoding with alpha 1, at each face's middle (within 3%: JPEG's rounding of a flat colour). A scene in
 * a folder below that names them as ../face<i>.jpg loads with a warning, and is refused when untrusted. */
static void test_ldr_jpeg_files(void **state)
{
    (void)state;
    static const uint8_t colour[6][3] = {{100, 180, 140}, {130, 180, 140}, {160, 180, 140},
                                         {190, 180, 140}, {220, 180, 140}, {250, 180, 140}};
    static const float middle[6][3] = {{-1, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    blob faces[6];
    for (int k = 0; k < 6; k++)
        faces[k] = jpeg_face(colour[k]);
    ibl_desc d = {.name = "ldr.gltf", .images = faces, .where = FILES};
    const char *path = ibl_scene(&d);
    lmgi_scene *sc = lmt_load(path, 1000);
    for (int k = 0; k < 6; k++) {
        double want[3];
        for (int c = 0; c < 3; c++)
            want[c] = pow(colour[k][c] / 255.0, 2.2);
        sky_is(sc, middle[k][0], middle[k][1], middle[k][2], want, 0.03);
    }
    lmgi_free(sc);

    char dir[600];
    snprintf(dir, sizeof dir, "%s", path);
    *strrchr(dir, '/') = '\0';
    strcat(dir, "/inner");
    assert_int_equal(mkdir(dir, 0755), 0);
    ibl_desc below = {.name = "below.gltf", .dir = dir, .images = faces, .where = FILES, .uri_prefix = "../"};
    const char *inner = ibl_scene(&below);
    lmgi_free(lmt_load(inner, 1000));
    lmgi_options o;
    lmgi_options_init(&o);
    o.untrusted = 1;
    lmgi_error e;
    sc = NULL;
    assert_int_equal(lmgi_load(inner, &o, &sc, &e), LMGI_ERR_IO);
    print_message("%s\n", e.message);
    assert_non_null(strstr(e.message, "outside the scene's folder"));
    assert_null(sc);
    faces_free(faces, 6);
}

/* The plane under the RGBD cube: every direction of its hemisphere sees the sky, so its irradiance is
 * E = integral of L cos over the upper hemisphere. In red, face +Y's 4 covers the square straight up (cos
 * integrates to pi F(1) over it, F(a) = 4/pi a/sqrt(1 + a^2) atan(a/sqrt(1 + a^2)), DESIGN.md) and the four
 * side faces' 2 + 3 + 6 + 7 their upper halves (a quarter each of the rest, pi - pi F(1)); in green, 2u
 * averages 1 over each face and its halves, so E = pi. The gather's IIM (rays) and the reference give it
 * within 2%. Exported, the scene loads back with the same sky (the image, its scale, to float precision). */
static void test_open_plane(void **state)
{
    (void)state;
    blob faces[6];
    rgbd_cube(faces, N);
    ibl_desc d = {.name = "plane.gltf", .images = faces, .where = DATA_URIS, .light = "\"intensity\": 0.5, "};
    lmgi_scene *sc = lmt_load(ibl_scene(&d), 2000);
    double a = 1.0 / sqrt(2.0), f = 4.0 / PI * a * atan(a);
    const double want[2] = {0.5 * (PI * f * 4 + (PI - PI * f) / 4 * 18), 0.5 * PI};

    lmgi_context *ctx = lmt_context();
    lmgi_updater *u = lmt_updater(ctx, sc);
    size_t n;
    float *rgba = lmt_iim(u, sc, &n);
    double iim[3], ref[3];
    assert_int_equal(lmt_texel_mean(rgba, n, iim), lmt_reference_mean(sc, 0.02f, ref));
    free(rgba);
    for (int c = 0; c < 2; c++) {
        print_message("channel %d: E %.4f, reference %.4f, IIM %.4f\n", c, want[c], ref[c], iim[c]);
        assert_float_equal(ref[c] / want[c], 1.0, 0.02);
        assert_float_equal(iim[c] / want[c], 1.0, 0.02);
    }

    lmgi_scene *back = lmt_export_reload(u, "plane", 2000);
    const lm_scene *s0 = sc->scene, *s1 = back->scene;
    assert_int_equal(s1->sky_kind, LM_SKY_IMAGE);
    assert_int_equal(s1->sky_width, s0->sky_width);
    assert_int_equal(s1->sky_height, s0->sky_height);
    assert_float_equal(s1->sky[0], 0.5f, 0.0f);
    for (int i = 0; i < 3 * s0->sky_width * s0->sky_height; i++)
        assert_float_equal(s1->sky_image[i], s0->sky_image[i], 1e-6 * s0->sky_image[i]);
    lmgi_free(back);
    lmgi_updater_free(u);
    lmgi_context_free(ctx);
    lmgi_free(sc);
    faces_free(faces, 6);
}

/* What the loader's warnings said, last first. */
static char g_warning[1024];
static void record(void *user, lm_log_level level, const char *message)
{
    (void)user;
    if (level == LM_LOG_WARN)
        snprintf(g_warning, sizeof g_warning, "%s", message);
}

/* extras.lmgi.sky and the extension both: lmgi's own word wins (the uniform sky), a warning says the
 * extension was ignored, and an ignored light is not read at all (one out of range loads). */
static void test_extras_win(void **state)
{
    (void)state;
    blob faces[6];
    rgbd_cube(faces, N);
    ibl_desc d = {.name = "both.gltf", .images = faces, .where = DATA_URIS, .scene_light = 5,
                  .extras = "{\"lmgi\": {\"sky\": [1, 0.5, 0.25]}}"};
    lm_log_target was = lm_log_swap_target((lm_log_target){record, NULL, LM_LOG_WARN});
    g_warning[0] = '\0';
    lmgi_scene *sc = lmt_load(ibl_scene(&d), 1000);
    lm_log_swap_target(was);
    print_message("warning: %s\n", g_warning);
    assert_non_null(strstr(g_warning, "EXT_lights_image_based light ignored: extras.lmgi.sky gives the sky"));
    assert_int_equal(sc->scene->sky_kind, LM_SKY_UNIFORM);
    const double sky[3] = {1, 0.5, 0.25};
    sky_is(sc, 0.3f, 0.2f, -1, sky, 0.0);
    lmgi_free(sc);
    faces_free(faces, 6);
}

/* A bad light is refused with an error naming what is wrong; the scene is not loaded. */
static void test_bad_lights(void **state)
{
    (void)state;
    blob faces[8];
    rgbd_cube(faces, N);
    faces[6] = rgbd_face(0, N / 2, N / 2);
    faces[7] = rgbd_face(0, N, N / 2);
    const char garbage[] = "not an image at all";
    blob junk = {(unsigned char *)garbage, sizeof garbage, "image/png", "png"};
    static const struct {
        const char *light, *specular;
        int scene_light, status;
        const char *says;
    } bad[] = {
        {NULL, NULL, 1, LMGI_ERR_FORMAT, "scene 0: EXT_lights_image_based light 1 out of range (1 lights)"},
        {NULL, NULL, -1, LMGI_ERR_FORMAT, "light -1 out of range"},
        {NULL, "[[0, 1, 2, 3, 4]]", 0, LMGI_ERR_FORMAT, "specularImages[0] has 5 faces; a cube has 6"},
        {NULL, "[]", 0, LMGI_ERR_FORMAT, "specularImages must be an array of mips"},
        {NULL, "[[0, 1, 2, 3, 4, 9]]", 0, LMGI_ERR_FORMAT, "face -Z (specularImages[0][5]): image 9 out of range"},
        {NULL, "[[0, 1, 2, 6, 4, 5]]", 0, LMGI_ERR_FORMAT, "face -Y (image 6) is 16 x 16 pixels, face +X 32 x 32"},
        {NULL, "[[7, 1, 2, 3, 4, 5]]", 0, LMGI_ERR_FORMAT, "face +X (image 7) is 32 x 16 pixels; cube faces are"},
        {NULL, "[[0, 1, 8, 3, 4, 5]]", 0, LMGI_ERR_FORMAT, "face +Y (image 8): not an image lmgi reads"},
        {"\"intensity\": -1, ", NULL, 0, LMGI_ERR_INVALID, "light 0: intensity -1 must be a number from 0 to 1e+20"},
        {"\"intensity\": 1e30, ", NULL, 0, LMGI_ERR_INVALID, "intensity 1e+30 must be a number from 0"},
        {"\"intensity\": \"bright\", ", NULL, 0, LMGI_ERR_INVALID, "intensity must be a number"},
        {"\"rotation\": [0, 0, 0, 2], ", NULL, 0, LMGI_ERR_INVALID, "rotation [0, 0, 0, 2] is not a unit quaternion"},
        {"\"rotation\": [0, 1], ", NULL, 0, LMGI_ERR_INVALID, "rotation must be a quaternion [x, y, z, w]"},
        {"\"rotation\": [0, \"y\", 0, 1], ", NULL, 0, LMGI_ERR_INVALID, "rotation must be a quaternion"},
    };
    blob images[9];
    memcpy(images, faces, sizeof faces);
    images[8] = junk;
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        ibl_desc d = {.name = "bad.gltf", .images = images, .image_count = 9, .where = DATA_URIS,
                      .light = bad[i].light, .specular = bad[i].specular, .scene_light = bad[i].scene_light};
        lmgi_scene *sc = NULL;
        lmgi_error e;
        int st = lmgi_load(ibl_scene(&d), NULL, &sc, &e);
        print_message("%s\n", e.message);
        assert_int_equal(st, bad[i].status);
        assert_non_null(strstr(e.message, bad[i].says));
        assert_null(sc);
    }
    /* a face whose file is missing */
    ibl_desc d = {.name = "missing.gltf", .images = faces, .where = FILES, .uri_prefix = "gone/"};
    lmgi_scene *sc = NULL;
    lmgi_error e;
    assert_int_equal(lmgi_load(ibl_scene(&d), NULL, &sc, &e), LMGI_ERR_FORMAT);
    print_message("%s\n", e.message);
    assert_non_null(strstr(e.message, "face +X (image 0 \"gone/face0.png\") has no bytes"));
    faces_free(faces, 8);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_rgbd_faces),     cmocka_unit_test(test_rotation_intensity),
        cmocka_unit_test(test_ldr_jpeg_files), cmocka_unit_test(test_open_plane),
        cmocka_unit_test(test_extras_win),     cmocka_unit_test(test_bad_lights),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
