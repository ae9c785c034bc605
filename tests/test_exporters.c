/* The files real exporters write (issue 30, item 4): WebP textures behind a required EXT_texture_webp
 * (Godot 4) with percent-encoded URIs, images reduced on decode to the size lmgi needs with their mean
 * albedo kept, metalness and roughness from metallicRoughnessTexture (UnityGLTF leaves the factor at 1),
 * KHR_lights_punctual range, and the shared Godot level that needs all of them. */
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
#include <stb/stb_image_write.h>
#include <webp/encode.h>

#include "../src/core/log.h"
#include "../src/core/timing.h"
#include "../src/scene/image_decode.h"
#include "../src/scene/scene.h"
#include "support.h"

static lm_scene *load(const char *path)
{
    lm_error err = {0};
    lm_scene *s = NULL;
    lm_status st = lm_scene_load_gltf(path, NULL, &s, &err);
    if (st)
        print_message("load failed: %s\n", err.msg);
    assert_int_equal(st, LM_OK);
    return s;
}

static double srgb_to_linear(double c) { return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4); }

/* Mean of channel c over a texture. */
static double texture_mean(const lm_texture *t, int c)
{
    double sum = 0.0;
    for (int i = 0; i < t->width * t->height; i++)
        sum += t->rgba[4 * i + c];
    return sum / (t->width * t->height);
}

/* A quad whose material 0 is `material` and whose top-level JSON ends with `rest` (textures, images, ...). */
static const char *quad_scene(const char *name, const char *materials_and_rest)
{
    lmt_mesh m;
    memset(&m, 0, sizeof m);
    lmt_mesh_quad(&m, (float[3]){-1, 0, 1}, (float[3]){2, 0, 0}, (float[3]){0, 0, -2});
    return lmt_write_scene(name, &m, 1, "[{\"mesh\": 0}]", materials_and_rest);
}

/* The folder of a scene lmt_write_scene wrote (each lmt_tmpdir() call makes a new one). */
static const char *dir_of(const char *scene)
{
    static char dir[512];
    snprintf(dir, sizeof dir, "%s", scene);
    *strrchr(dir, '/') = '\0';
    return dir;
}

/* Godot 4's form: the texture's image only in EXT_texture_webp (required), its URI percent-encoded into a
 * sub-folder whose name has a space. The lossless WebP's colour arrives exactly (sRGB 188 -> 0.50289). */
static void test_webp_percent_encoded(void **state)
{
    (void)state;
    enum { W = 8, H = 4 };
    uint8_t px[W * H * 4];
    for (int i = 0; i < W * H; i++)
        px[4 * i] = 188, px[4 * i + 1] = 100, px[4 * i + 2] = 20, px[4 * i + 3] = 255;
    uint8_t *webp = NULL;
    size_t n = WebPEncodeLosslessRGBA(px, W, H, W * 4, &webp);
    assert_true(n > 0);
    const char *scene = quad_scene("webp.gltf",
                                   "[{\"pbrMetallicRoughness\": {\"baseColorTexture\": {\"index\": 0}, \"metallicFactor\": 0}}], "
                                   "\"extensionsUsed\": [\"EXT_texture_webp\"], \"extensionsRequired\": [\"EXT_texture_webp\"], "
                                   "\"textures\": [{\"extensions\": {\"EXT_texture_webp\": {\"source\": 0}}}], "
                                   "\"images\": [{\"uri\": \"tex%20dir%2Falbedo.webp\"}]");
    char dir[600], path[700];
    snprintf(dir, sizeof dir, "%s/tex dir", dir_of(scene));
    assert_int_equal(mkdir(dir, 0755), 0);
    snprintf(path, sizeof path, "%s/albedo.webp", dir);
    lmt_write_file(path, webp, n);
    WebPFree(webp);
    lm_scene *s = load(scene);
    assert_int_equal(s->texture_count, 1);
    assert_int_equal(s->materials[0].base_color_tex, 0);
    assert_int_equal(s->materials[0].missing_textures, 0);
    const lm_texture *t = &s->textures[0];
    assert_int_equal(t->width, W);
    assert_int_equal(t->height, H);
    assert_float_equal(t->rgba[0], srgb_to_linear(188 / 255.0), 1e-4);
    assert_float_equal(t->rgba[1], srgb_to_linear(100 / 255.0), 1e-4);
    assert_float_equal(t->rgba[2], srgb_to_linear(20 / 255.0), 1e-4);
    lm_scene_free(s);
}

/* A file named .webp that is not one: a warning naming the image, the material keeps its factor. */
static void test_webp_corrupt(void **state)
{
    (void)state;
    const char *scene = quad_scene("badwebp.gltf",
                                   "[{\"pbrMetallicRoughness\": {\"baseColorTexture\": {\"index\": 0}, \"metallicFactor\": 0}}], "
                                   "\"extensionsUsed\": [\"EXT_texture_webp\"], \"extensionsRequired\": [\"EXT_texture_webp\"], "
                                   "\"textures\": [{\"extensions\": {\"EXT_texture_webp\": {\"source\": 0}}}], "
                                   "\"images\": [{\"uri\": \"bad.webp\"}]");
    char path[600];
    snprintf(path, sizeof path, "%s/bad.webp", dir_of(scene));
    lmt_write_file(path, "RIFF\x10\0\0\0WEBPVP8 garbage!", 24);
    lm_log_set_level(LM_LOG_ERROR);
    lm_scene *s = load(scene);
    lm_log_set_level(LM_LOG_WARN);
    assert_int_equal(s->texture_count, 0);
    assert_int_equal(s->materials[0].base_color_tex, -1);
    assert_int_equal(s->materials[0].missing_textures, 1);
    lm_scene_free(s);
}

/* A 2048 x 1024 PNG of one-pixel black and white stripes (sRGB 0 and 255) is reduced to 512 x 256; in
 * linear light its mean stays 0.5 (a reduction in sRGB numbers would read 0.21). The WebP decoder's
 * own scaling keeps its size too. */
static void test_reduced_on_decode(void **state)
{
    (void)state;
    enum { W = 2048, H = 1024 };
    uint8_t *px = malloc((size_t)W * H * 4);
    assert_non_null(px);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            for (int c = 0; c < 4; c++)
                px[((size_t)y * W + (size_t)x) * 4 + (size_t)c] = c == 3 || (x & 1) ? 255 : 0;
    const char *scene = quad_scene("stripes.gltf",
                                   "[{\"pbrMetallicRoughness\": {\"baseColorTexture\": {\"index\": 0}, \"metallicFactor\": 0}}], "
                                   "\"textures\": [{\"source\": 0}], \"images\": [{\"uri\": \"stripes.png\"}]");
    char png[600];
    snprintf(png, sizeof png, "%s/stripes.png", dir_of(scene));
    assert_true(stbi_write_png(png, W, H, 4, px, W * 4) != 0);
    uint8_t *webp = NULL;
    size_t wn = WebPEncodeLosslessRGBA(px, W, H, W * 4, &webp);
    assert_true(wn > 0);
    free(px);
    size_t pn = 0;
    uint8_t *pbytes = lmt_read_file(png, &pn, 0), *out = NULL;
    int w = 0, h = 0;
    const char *why = NULL;
    assert_int_equal(lm_image_decode(webp, wn, LM_TEXTURE_MAX_SIDE, 1, &out, &w, &h, &why), LM_OK);
    assert_int_equal(w, LM_TEXTURE_MAX_SIDE);
    assert_int_equal(h, LM_TEXTURE_MAX_SIDE / 2);
    free(out);
    WebPFree(webp);
    assert_int_equal(lm_image_decode(pbytes, pn, 0, 1, &out, &w, &h, &why), LM_OK); /* 0: full size */
    assert_int_equal(w, W);
    free(out);
    free(pbytes);
    lm_scene *s = load(scene);
    assert_int_equal(s->texture_count, 1);
    assert_int_equal(s->textures[0].width, LM_TEXTURE_MAX_SIDE);
    assert_int_equal(s->textures[0].height, LM_TEXTURE_MAX_SIDE / 2);
    for (int c = 0; c < 3; c++)
        assert_float_equal(texture_mean(&s->textures[0], c), 0.5, 0.01);
    lm_scene_free(s);
}

/* metallicRoughnessTexture: factor x the texture's mean (metal in B, roughness in G, linear). UnityGLTF's
 * form, metallicFactor left at 1 with a texture that is not metal, is a diffuse material; the same texture
 * with B = 255 and G = 0 makes a mirror; half the texels metal make metallic 0.5. */
static void test_metal_rough_texture(void **state)
{
    (void)state;
    enum { W = 4, H = 4 };
    const struct { uint8_t g, b_even, b_odd; const char *name; } tex[] = {
        {200, 0, 0, "plastic.png"}, {0, 255, 255, "chrome.png"}, {128, 255, 0, "half.png"}};
    lmt_mesh m[3];
    memset(m, 0, sizeof m);
    for (int k = 0; k < 3; k++)
        lmt_mesh_quad(&m[k], (float[3]){-1, (float)k, 1}, (float[3]){2, 0, 0}, (float[3]){0, 0, -2});
    const char *scene = lmt_write_scene(
        "metal.gltf", m, 3, "[{\"mesh\": 0}, {\"mesh\": 1}, {\"mesh\": 2}]",
        "[{\"pbrMetallicRoughness\": {\"metallicRoughnessTexture\": {\"index\": 0}}}, "
        "{\"pbrMetallicRoughness\": {\"metallicRoughnessTexture\": {\"index\": 1}}}, "
        "{\"pbrMetallicRoughness\": {\"metallicRoughnessTexture\": {\"index\": 2}, \"roughnessFactor\": 0.5}}], "
        "\"textures\": [{\"source\": 0}, {\"source\": 1}, {\"source\": 2}], "
        "\"images\": [{\"uri\": \"plastic.png\"}, {\"uri\": \"chrome.png\"}, {\"uri\": \"half.png\"}]");
    for (int k = 0; k < 3; k++) {
        uint8_t px[W * H * 4];
        for (int i = 0; i < W * H; i++)
            px[4 * i] = 0, px[4 * i + 1] = tex[k].g, px[4 * i + 2] = i & 1 ? tex[k].b_odd : tex[k].b_even,
                      px[4 * i + 3] = 255;
        char png[600];
        snprintf(png, sizeof png, "%s/%s", dir_of(scene), tex[k].name);
        assert_true(stbi_write_png(png, W, H, 4, px, W * 4) != 0);
    }
    lm_scene *s = load(scene);
    assert_float_equal(s->materials[0].metallic, 0.0f, 1e-6);
    assert_float_equal(s->materials[0].roughness, 200 / 255.0f, 1e-4);
    assert_int_equal(s->materials[0].cls, LM_MAT_DIFFUSE);
    assert_float_equal(s->materials[1].metallic, 1.0f, 1e-6);
    assert_float_equal(s->materials[1].roughness, 0.0f, 1e-6);
    assert_int_equal(s->materials[1].cls, LM_MAT_MIRROR);
    assert_float_equal(s->materials[2].metallic, 0.5f, 1e-4);
    assert_float_equal(s->materials[2].roughness, 0.5f * 128 / 255.0f, 1e-4);
    assert_int_equal(s->texture_count, 0); /* averaged, not kept */
    lm_scene_free(s);
}

/* Appends printf-formatted text to a growing buffer. */
static void put(char **buf, size_t *len, size_t *cap, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    char piece[512];
    int n = vsnprintf(piece, sizeof piece, fmt, ap);
    va_end(ap);
    assert_true(n >= 0 && (size_t)n < sizeof piece);
    if (*len + (size_t)n + 1 > *cap) {
        *cap = 2 * (*cap + (size_t)n + 1);
        *buf = realloc(*buf, *cap);
        assert_non_null(*buf);
    }
    memcpy(*buf + *len, piece, (size_t)n + 1);
    *len += (size_t)n;
}

/* UnityGLTF's apartment block in small: 2,000 materials over 2,000 quads, their base colour from 300
 * textures (each a 1024 x 1024 PNG). Every texture is reduced to 512 on decode, and `lmgi info` fits the
 * scene on a screen: the totals, the first materials and lights, and how many more there are. */
static void test_many_materials_and_textures(void **state)
{
    (void)state;
    enum { MATERIALS = 2000, TEXTURES = 300, SIDE = 1024, PER_ROW = 50 };
    const char *dir = lmt_tmpdir();
    uint8_t *px = malloc((size_t)SIDE * SIDE * 4);
    assert_non_null(px);
    for (int i = 0; i < SIDE * SIDE; i++)
        px[4 * i] = (uint8_t)(i % SIDE / 4), px[4 * i + 1] = (uint8_t)(i / SIDE / 4), px[4 * i + 2] = 128,
                 px[4 * i + 3] = 255;
    char path[700];
    snprintf(path, sizeof path, "%s/wall.png", dir);
    assert_true(stbi_write_png(path, SIDE, SIDE, 4, px, SIDE * 4) != 0);
    free(px);
    const uint16_t idx[6] = {0, 1, 2, 0, 2, 3};
    const float pos[12] = {0, 0, 0, 1, 0, 0, 1, 0, -1, 0, 0, -1};
    uint8_t bin[60];
    memcpy(bin, idx, 12);
    memcpy(bin + 12, pos, 48);
    snprintf(path, sizeof path, "%s/quad.bin", dir);
    lmt_write_file(path, bin, sizeof bin);
    char *j = NULL;
    size_t len = 0, cap = 0;
    put(&j, &len, &cap, "{\"asset\": {\"version\": \"2.0\"}, \"buffers\": [{\"uri\": \"quad.bin\", \"byteLength\": 60}], "
        "\"bufferViews\": [{\"buffer\": 0, \"byteLength\": 12}, {\"buffer\": 0, \"byteOffset\": 12, \"byteLength\": 48}], "
        "\"accessors\": [{\"bufferView\": 0, \"componentType\": 5123, \"count\": 6, \"type\": \"SCALAR\"}, "
        "{\"bufferView\": 1, \"componentType\": 5126, \"count\": 4, \"type\": \"VEC3\", \"min\": [0, 0, -1], \"max\": [1, 0, 0]}], "
        "\"extensionsUsed\": [\"KHR_lights_punctual\"], \"extensions\": {\"KHR_lights_punctual\": {\"lights\": [");
    for (int l = 0; l < 40; l++)
        put(&j, &len, &cap, "%s{\"type\": \"point\", \"intensity\": 5, \"range\": 4}", l ? ", " : "");
    put(&j, &len, &cap, "]}}, \"nodes\": [");
    for (int i = 0; i < MATERIALS + 40; i++) {
        float x = 1.5f * (float)(i % PER_ROW), z = -1.5f * (float)(i / PER_ROW % PER_ROW);
        if (i < MATERIALS)
            put(&j, &len, &cap, "%s{\"mesh\": %d, \"translation\": [%g, 0, %g]}", i ? ", " : "", i, x, z);
        else
            put(&j, &len, &cap, ", {\"translation\": [%g, 2, %g], \"extensions\": {\"KHR_lights_punctual\": {\"light\": %d}}}",
                4.0f * (float)(i - MATERIALS), -20.0f, i - MATERIALS);
    }
    put(&j, &len, &cap, "], \"meshes\": [");
    for (int i = 0; i < MATERIALS; i++)
        put(&j, &len, &cap, "%s{\"primitives\": [{\"attributes\": {\"POSITION\": 1}, \"indices\": 0, \"material\": %d}]}",
            i ? ", " : "", i);
    put(&j, &len, &cap, "], \"materials\": [");
    for (int i = 0; i < MATERIALS; i++)
        put(&j, &len, &cap, "%s{\"name\": \"material_%04d\", \"pbrMetallicRoughness\": {\"baseColorTexture\": "
            "{\"index\": %d}, \"metallicFactor\": 0}}", i ? ", " : "", i, i % TEXTURES);
    put(&j, &len, &cap, "], \"textures\": [");
    for (int i = 0; i < TEXTURES; i++)
        put(&j, &len, &cap, "%s{\"source\": %d}", i ? ", " : "", i);
    put(&j, &len, &cap, "], \"images\": [");
    for (int i = 0; i < TEXTURES; i++) /* one file, named by every image: each image is decoded on its own */
        put(&j, &len, &cap, "%s{\"uri\": \"wall.png\"}", i ? ", " : "");
    put(&j, &len, &cap, "]}");
    snprintf(path, sizeof path, "%s/apartments.gltf", dir);
    lmt_write_file(path, j, len);
    free(j);

    double t0 = lm_now();
    lm_scene *s = load(path);
    double seconds = lm_now() - t0, bytes = 0.0;
    assert_int_equal(s->material_count, MATERIALS);
    assert_int_equal(s->texture_count, TEXTURES);
    for (int i = 0; i < s->texture_count; i++) {
        assert_int_equal(s->textures[i].width, LM_TEXTURE_MAX_SIDE);
        bytes += 16.0 * s->textures[i].width * s->textures[i].height;
    }
    print_message("%d materials, %d textures of %d x %d: loaded in %.2f s; textures %.0f MiB as lmgi keeps them "
                  "(%.0f MiB at full size)\n", MATERIALS, TEXTURES, SIDE, SIDE, seconds, bytes / 1048576.0,
                  16.0 * SIDE * SIDE * TEXTURES / 1048576.0);
    assert_true(bytes <= 16.0 * LM_TEXTURE_MAX_SIDE * LM_TEXTURE_MAX_SIDE * TEXTURES);
    lm_scene_free(s);

    const char *build = getenv("LMGI_BUILD");
    char cmd[1024], line[1024];
    snprintf(cmd, sizeof cmd, "%s/lmgi info %s --texels 20000 2>&1", build ? build : "build", path);
    FILE *p = popen(cmd, "r");
    assert_non_null(p);
    int lines = 0, more_materials = 0, more_lights = 0;
    while (fgets(line, sizeof line, p)) {
        lines++;
        more_materials += strstr(line, "... and 1988 more materials") != NULL;
        more_lights += strstr(line, "... and 28 more lights") != NULL;
    }
    assert_int_equal(pclose(p), 0);
    print_message("lmgi info: %d lines\n", lines);
    assert_true(lines <= 50);
    assert_int_equal(more_materials, 1);
    assert_int_equal(more_lights, 1);
}

/* ../shared/scenes/truck-town: Godot 4's export (required EXT_texture_webp, percent-encoded URIs into
 * textures/, OMI physics extensions) loads with both its WebP textures, reduced to 512 on their longer
 * side, and its sun. */
static void test_truck_town_loads(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(path, lmt_shared_scene("truck-town/town_lit.gltf"));
    lm_log_set_level(LM_LOG_ERROR);
    lm_scene *s = load(path);
    lm_log_set_level(LM_LOG_WARN);
    assert_int_equal(s->texture_count, 2);
    for (int i = 0; i < s->texture_count; i++) {
        int side = s->textures[i].width > s->textures[i].height ? s->textures[i].width : s->textures[i].height;
        assert_true(side <= LM_TEXTURE_MAX_SIDE);
        double mean = texture_mean(&s->textures[i], 1);
        print_message("texture %d: %d x %d, mean green %.3f\n", i, s->textures[i].width, s->textures[i].height, mean);
        assert_true(mean > 0.02 && mean < 0.9);
    }
    int missing = 0;
    for (int i = 0; i < s->material_count; i++)
        missing += s->materials[i].missing_textures;
    assert_int_equal(missing, 0);
    assert_int_equal(s->light_count, 1);
    lm_scene_free(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_webp_percent_encoded), cmocka_unit_test(test_webp_corrupt),
        cmocka_unit_test(test_reduced_on_decode),    cmocka_unit_test(test_metal_rough_texture),
        cmocka_unit_test(test_many_materials_and_textures), cmocka_unit_test(test_truck_town_loads),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
