/* lmgi's glTF export in other programs: the Khronos glTF validator finds no error in an export, before and
 * after edits, and Babylon.js (in headless Chromium, with tools/engines/babylon_lmgi_lightmap.js) draws an
 * emitter-lit room from the export's lightmap as lmgi draws it. Both need what make test installs (node
 * packages in build/npm, Debian's chromium) and skip, saying what is missing, without it. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <lmgi.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../src/core/image.h"
#include "edit_room.h"
#include "support.h"

/* An API call that must succeed, or the test fails with its message. */
static void ok(lmgi_status st, const lmgi_error *e)
{
    if (st != LMGI_OK)
        fail_msg("%s", e->message);
}

static lmgi_updater *bake(lmgi_context *ctx, lmgi_scene *sc, int photons)
{
    lmgi_updater_desc d;
    memset(&d, 0, sizeof d);
    d.photons.count = photons;
    d.gather.resolution = 32;
    lmgi_updater *u = NULL;
    lmgi_error e;
    if (lmgi_updater_create(ctx, sc, &d, &u, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    return u;
}

static void export_to(lmgi_updater *u, const char *name, char *gltf, size_t size)
{
    lmgi_export_desc d = {.name = name};
    lmgi_error e;
    const char *dir = lmt_tmpdir(); /* a new folder each call */
    if (lmgi_export_gltf(u, dir, &d, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    snprintf(gltf, size, "%s/%s.gltf", dir, name);
}

/* The node packages' folder holding the Khronos validator; the test skips, saying what is missing, without. */
static const char *validator_modules(void)
{
    const char *why = NULL, *modules = lmt_node_modules("gltf-validator", &why);
    if (!modules) {
        print_message("skipped: %s\n", why);
        skip();
    }
    return modules;
}

/* Exports of the Cornell box as baked, then after every kind of edit (a light added, one switched off,
 * one removed, a node moved, a material's colour changed), and of a shared scene with textures: the
 * Khronos validator finds 0 errors in each. */
static void test_exports_validate(void **state)
{
    (void)state;
    const char *modules = validator_modules();
    lmgi_context *ctx = NULL;
    lmgi_error e;
    assert_int_equal(lmgi_context_create(NULL, &ctx, &e), LMGI_OK);
    lmgi_scene *sc = lmt_load(lmt_project_scene("cornell.glb"), 2000);
    lmgi_updater *u = bake(ctx, sc, 20000);
    char gltf[PATH_MAX];
    export_to(u, "baked", gltf, sizeof gltf);
    lmt_gltf_validate(modules, gltf);

    lmgi_light lamp = {.type = LMGI_LIGHT_SPOT, .color = {1, 0.8f, 0.6f}, .intensity = 4.0f, .enabled = 1,
                       .inner_cone = 0.3f, .outer_cone = 0.5f, .position = {0.2f, 1.5f, 0.1f}, .direction = {0, -1, 0}};
    int lamp_id, second;
    ok(lmgi_add_light(sc, &lamp, &lamp_id, &e), &e);
    ok(lmgi_add_light(sc, &lamp, &second, &e), &e);
    ok(lmgi_remove_light(sc, second, &e), &e);
    lmgi_light first;
    ok(lmgi_get_light(sc, 0, &first, &e), &e);
    first.enabled = 0;
    ok(lmgi_set_light(sc, 0, &first, &e), &e);
    int cube = lmgi_find_node(sc, "dynamic_cube");
    assert_true(cube >= 0);
    float m[16];
    assert_true(lmgi_get_node_transform(sc, cube, m));
    m[12] += 0.1f;
    ok(lmgi_set_node_transform(sc, cube, m, &e), &e);
    lmgi_material mat;
    ok(lmgi_get_material(sc, 0, &mat, &e), &e);
    mat.base_color[1] = 0.2f;
    ok(lmgi_set_material(sc, 0, &mat, &e), &e);
    ok(lmgi_bake(u, NULL, NULL, &e), &e);
    export_to(u, "edited", gltf, sizeof gltf);
    lmt_gltf_validate(modules, gltf);
    lmgi_updater_free(u);
    lmgi_free(sc);

    const char *textured = lmt_shared_scene("cornell-suzanne/cornellBox-2.80-Eevee-gltf.gltf");
    if (access(textured, R_OK) == 0) {
        sc = lmt_load(textured, 2000);
        u = bake(ctx, sc, 20000);
        export_to(u, "suzanne", gltf, sizeof gltf);
        lmt_gltf_validate(modules, gltf);
        lmgi_updater_free(u);
        lmgi_free(sc);
    } else {
        print_message("%s is absent: its export is not validated\n", textured);
    }
    lmgi_context_free(ctx);
}

/* A level of several lightmap pages (the Cornell box at 6,000 texels on pages of 64 texels): its export,
 * with an image, primitives and material copies a page, has no error and no warning. */
static void test_paged_export_validates(void **state)
{
    (void)state;
    const char *modules = validator_modules();
    lmgi_context *ctx = NULL;
    lmgi_error e;
    assert_int_equal(lmgi_context_create(NULL, &ctx, &e), LMGI_OK);
    lmgi_scene *sc = lmt_paged_cornell();
    lmgi_info in;
    lmgi_get_info(sc, &in);
    lmgi_updater *u = bake(ctx, sc, 20000);
    char gltf[PATH_MAX], cmd[2 * PATH_MAX + 64], out[8192];
    export_to(u, "paged", gltf, sizeof gltf);
    snprintf(cmd, sizeof cmd, "node tests/engines/validate.mjs '%s' '%s' 2>&1", modules, gltf);
    int rc = lmt_run(cmd, out, sizeof out);
    print_message("%d pages: %s", in.pages, out);
    assert_int_equal(rc, 0);
    assert_non_null(strstr(out, ": 0 errors, 0 warnings"));
    lmgi_updater_free(u);
    lmgi_free(sc);
    lmgi_context_free(ctx);
}

/* A room lit only by an emissive ceiling panel, a blue box and a red panel in it, and a camera: every
 * light in the picture but the panel's own glow comes from the lightmap. */
static const char *emitter_room(void)
{
    lmt_mesh m[4];
    memset(m, 0, sizeof m);
    lmt_mesh_cube_inward(&m[0], 1.0f);
    lmt_mesh_cube(&m[1], 0.25f);
    lmt_mesh_quad(&m[2], (float[3]){-0.3f, 0.98f, -0.3f}, (float[3]){0.6f, 0, 0}, (float[3]){0, 0, 0.6f});
    lmt_mesh_quad(&m[3], (float[3]){-0.9f, -0.6f, -0.6f}, (float[3]){0, 1.2f, 0}, (float[3]){0, 0, 1.0f});
    return lmt_write_scene(
        "emitter_room.gltf", m, 4,
        "[{\"mesh\": 0}, {\"mesh\": 1, \"translation\": [0.3, -0.75, -0.3]}, {\"mesh\": 2}, {\"mesh\": 3},"
        " {\"camera\": 0, \"translation\": [0, 0, 0.95]}]",
        "[{\"pbrMetallicRoughness\": {\"baseColorFactor\": [0.7, 0.7, 0.7, 1], \"metallicFactor\": 0}},"
        " {\"pbrMetallicRoughness\": {\"baseColorFactor\": [0.25, 0.35, 0.8, 1], \"metallicFactor\": 0}},"
        " {\"pbrMetallicRoughness\": {\"baseColorFactor\": [0, 0, 0, 1], \"metallicFactor\": 0},"
        "  \"emissiveFactor\": [1, 0.9, 0.8], \"extensions\": {\"KHR_materials_emissive_strength\":"
        "  {\"emissiveStrength\": 6}}},"
        " {\"pbrMetallicRoughness\": {\"baseColorFactor\": [0.8, 0.2, 0.15, 1], \"metallicFactor\": 0}}],"
        " \"extensionsUsed\": [\"KHR_materials_emissive_strength\"],"
        " \"cameras\": [{\"type\": \"perspective\", \"perspective\": {\"yfov\": 1.2, \"znear\": 0.05,"
        " \"aspectRatio\": 1.3333333}}]");
}

static size_t base64_decode(const char *in, unsigned char *out)
{
    size_t n = 0;
    unsigned bits = 0;
    int have = 0;
    for (const char *c = in; *c && *c != '='; c++) {
        const char *digits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
        const char *d = strchr(digits, *c);
        if (!d || !*c)
            break;
        bits = bits << 6 | (unsigned)(d - digits);
        if ((have += 6) >= 8) {
            have -= 8;
            out[n++] = (unsigned char)(bits >> have);
        }
    }
    return n;
}

/* Babylon.js's picture of `gltf` from its first camera, w x h RGBA8, or NULL with the reason printed. */
static uint8_t *babylon_picture(const char *modules, const char *gltf, int w, int h)
{
    char page[PATH_MAX], extension[PATH_MAX], cmd[6 * PATH_MAX], dir[64];
    snprintf(dir, sizeof dir, "%s", lmt_tmpdir());
    assert_non_null(realpath("tests/engines/babylon_view.html", page));
    assert_non_null(realpath("tools/engines/babylon_lmgi_lightmap.js", extension));
    snprintf(cmd, sizeof cmd,
             "chromium --headless --no-sandbox --disable-dev-shm-usage --use-angle=swiftshader --enable-unsafe-swiftshader "
             "--allow-file-access-from-files --user-data-dir='%s/chromium' --virtual-time-budget=120000 "
             "--dump-dom 'file://%s?npm=%s&extension=%s&gltf=file://%s&w=%d&h=%d' 2>/dev/null",
             dir, page, modules, extension, gltf, w, h);
    static char dom[1 << 23];
    int rc = lmt_run(cmd, dom, sizeof dom);
    const char *png = strstr(dom, "PNG data:image/png;base64,");
    if (rc != 0 || !png) {
        const char *err = strstr(dom, "ERROR");
        print_message("chromium exited %d without a picture: %.300s\n", rc, err ? err : dom);
        return NULL;
    }
    png += strlen("PNG data:image/png;base64,");
    size_t len = strcspn(png, "<");
    unsigned char *bytes = malloc(len);
    assert_non_null(bytes);
    char *text = strndup(png, len);
    size_t n = base64_decode(text, bytes);
    free(text);
    char path[PATH_MAX];
    snprintf(path, sizeof path, "%s/babylon.png", dir);
    lmt_write_file(path, bytes, n);
    free(bytes);
    int pw, ph;
    uint8_t *rgba = NULL;
    lm_error le;
    assert_int_equal(lm_read_image8(path, &pw, &ph, &rgba, &le), LM_OK);
    assert_int_equal(pw, w);
    assert_int_equal(ph, h);
    return rgba;
}

/* Babylon.js draws the emitter room from the export, its lightmap through LMGI_lightmap, and its picture
 * (Babylon's gamma 2.2 output decoded) matches lmgi's own frame of the same camera once Babylon's diffuse
 * weight is divided out: Babylon's PBR material, as glTF's BRDF, gives diffuse light (1 - F0) of albedo /
 * pi x E, F0 = ((ior - 1) / (ior + 1))^2 = 0.04 for the export's ior 1.5; lmgi's Lambert surfaces give
 * all of it. Then the mean over the unsaturated pixels is within 2% per channel and 95% of the pixels are
 * within 5% + 0.004: what may differ is RGBD's 8-bit steps, bilinear filtering of the encoded values and
 * the rasterisers' edges. */
static void test_babylon_draws_the_lightmap(void **state)
{
    (void)state;
    const char *why = NULL, *modules = lmt_node_modules("babylonjs-loaders", &why);
    if (!modules || system("command -v chromium > /dev/null 2>&1") != 0) {
        print_message("skipped: %s\n", modules ? "chromium is not installed (Debian: apt-get install chromium)" : why);
        skip();
    }
    enum { W = 200, H = 150 };
    lmgi_context *ctx = NULL;
    lmgi_error e;
    assert_int_equal(lmgi_context_create(NULL, &ctx, &e), LMGI_OK);
    lmgi_scene *sc = lmt_load(emitter_room(), 6000);
    lmgi_updater *u = bake(ctx, sc, 100000);
    char gltf[PATH_MAX];
    export_to(u, "room", gltf, sizeof gltf);
    lmt_gltf_validate(modules, gltf);
    lmgi_camera cam;
    assert_int_equal(lmgi_scene_camera(sc, 0, W, H, &cam, &e), LMGI_OK);
    float *mine = malloc(sizeof(float) * 3 * W * H);
    assert_non_null(mine);
    assert_int_equal(lmgi_render(u, &cam, W, H, mine, &e), LMGI_OK);
    uint8_t *theirs = babylon_picture(modules, gltf, W, H);
    assert_non_null(theirs);

    double sum_mine[3] = {0}, sum_theirs[3] = {0};
    int compared = 0, close = 0;
    for (int p = 0; p < W * H; p++) {
        const float *a = mine + 3 * p;
        if (fmaxf(a[0], fmaxf(a[1], a[2])) > 0.9f)
            continue; /* the panel's glow: both clamp it at 1 */
        int near = 1;
        for (int c = 0; c < 3; c++) {
            double b = pow(theirs[4 * p + c] / 255.0, 2.2) / (1.0 - 0.04);
            sum_mine[c] += a[c];
            sum_theirs[c] += b;
            near &= fabs(b - a[c]) <= 0.05 * a[c] + 0.004;
        }
        compared++;
        close += near;
    }
    print_message("Babylon.js / (1 - F0) vs lmgi over %d unsaturated pixels: mean R %.4f / %.4f, G %.4f / %.4f,"
                  " B %.4f / %.4f; %.1f%% of pixels within 5%% + 0.004\n", compared, sum_theirs[0] / compared,
                  sum_mine[0] / compared, sum_theirs[1] / compared, sum_mine[1] / compared, sum_theirs[2] / compared,
                  sum_mine[2] / compared, 100.0 * close / compared);
    assert_true(compared > W * H / 2);
    for (int c = 0; c < 3; c++)
        assert_true(fabs(sum_theirs[c] / sum_mine[c] - 1.0) < 0.02);
    assert_true(close >= 0.95 * compared);
    free(mine);
    free(theirs);
    lmgi_updater_free(u);
    lmgi_free(sc);
    lmgi_context_free(ctx);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_exports_validate),
        cmocka_unit_test(test_paged_export_validates),
        cmocka_unit_test(test_babylon_draws_the_lightmap),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
