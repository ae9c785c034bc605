/* Never "ok" over NaN, infinity or black: values from a file or the API that would make one are refused
 * by the glTF specification and the limits of float, a frame that has one anyway fails naming the stage,
 * half floats clamp and say so, and a light that loads can always be set again with its own values. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <lmgi_tools.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include "../src/api/lmgi_context.h"
#include "../src/api/lmgi_scene.h"
#include "../src/api/lmgi_updater.h"
#include "../src/core/image.h"
#include "../src/core/log.h"
#include "../src/core/timing.h"
#include "../src/gpu/gl/gl_context.h"
#include "../src/gpu/gather/hemicube.h"
#include "support.h"

/* A 1 x 1 PNG (200, 100, 50). */
#define ONE_TEXEL_PNG "iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAIAAACQd1PeAAAADElEQVR4nGM4kWIEAANWAV/oF4RSAAAAAElFTkSuQmCC"
#define GREY "{\"pbrMetallicRoughness\": {\"baseColorFactor\": [0.5, 0.5, 0.5, 1], \"metallicFactor\": 0}}"

/* A 4 x 4 m floor (y = 0) of `material` (NULL: grey) with a point light 2 m above it (`light`: NULL, 10 cd);
 * `nodes_extra` is appended to the nodes, `top` goes after the materials array (cameras, textures...). */
static const char *floor_scene(const char *name, const char *material, const char *light, const char *nodes_extra,
                               const char *top)
{
    static lmt_mesh m;
    memset(&m, 0, sizeof m);
    lmt_mesh_quad(&m, (float[3]){-2, 0, 2}, (float[3]){4, 0, 0}, (float[3]){0, 0, -4});
    char nodes[2048], materials[4096];
    snprintf(nodes, sizeof nodes, "[{\"mesh\": 0}, {\"translation\": [0, 2, 0], \"extensions\": {\"KHR_lights_punctual\": "
             "{\"light\": 0}}}%s]", nodes_extra ? nodes_extra : "");
    snprintf(materials, sizeof materials, "[%s], %s" LMT_LIGHTS("%s"), material ? material : GREY, top ? top : "",
             light ? light : "{\"type\": \"point\", \"intensity\": 10}");
    return lmt_write_scene(name, &m, 1, nodes, materials);
}

static lmgi_status load(const char *path, lmgi_scene **sc, lmgi_error *e)
{
    lmgi_options o;
    lmgi_options_init(&o);
    o.texel_size = 0.25f;
    *sc = NULL;
    return lmgi_load(path, &o, sc, e);
}

static void expect_refused(const char *path, const char *words)
{
    lmgi_scene *sc = NULL;
    lmgi_error e;
    lmgi_status st = load(path, &sc, &e);
    if (st == LMGI_OK)
        fail_msg("%s loaded; expected a refusal naming \"%s\"", path, words);
    if (!strstr(e.message, words))
        fail_msg("%s: \"%s\" does not say \"%s\"", path, e.message, words);
    assert_null(sc);
}

static void test_file_values(void **state)
{
    (void)state;
    /* KHR_texture_transform of 3e38: every lookup infinite, an 81% NaN frame */
    static const char *const transforms[] = {"\"offset\": [3e38, 0]", "\"scale\": [1, -2e6]", "\"rotation\": 1e7"};
    for (int i = 0; i < 3; i++) {
        char material[512];
        snprintf(material, sizeof material, "{\"pbrMetallicRoughness\": {\"metallicFactor\": 0, \"baseColorTexture\": "
                 "{\"index\": 0, \"extensions\": {\"KHR_texture_transform\": {%s}}}}}", transforms[i]);
        expect_refused(floor_scene("tt.gltf", material, NULL, NULL, "\"textures\": [{\"source\": 0}], \"images\": [{\"uri\": "
                                   "\"data:image/png;base64," ONE_TEXEL_PNG "\"}], "), "KHR_texture_transform");
    }
    static const char *const bad_lights[] = {
        "{\"type\": \"point\", \"intensity\": 10, \"color\": [1, -0.5, 1]}",
        "{\"type\": \"spot\", \"intensity\": 10, \"spot\": {\"innerConeAngle\": -0.2, \"outerConeAngle\": 0.5}}",
        "{\"type\": \"spot\", \"intensity\": 10, \"spot\": {\"innerConeAngle\": 0.6, \"outerConeAngle\": 0.5}}",
        "{\"type\": \"spot\", \"intensity\": 10, \"spot\": {\"innerConeAngle\": 0, \"outerConeAngle\": 2}}"};
    static const char *const said[] = {"colour -0.5", "spot cones -0.2", "spot cones 0.6", "spot cones 0"};
    for (int i = 0; i < 4; i++)
        expect_refused(floor_scene("light.gltf", NULL, bad_lights[i], NULL, NULL), said[i]);
    static const char *const bad_cameras[] = {"{\"type\": \"perspective\", \"perspective\": {\"yfov\": 3.2, \"znear\": 0.1}}",
                                              "{\"type\": \"perspective\", \"perspective\": {\"yfov\": 0.8, \"znear\": 1, "
                                              "\"zfar\": 0.5}}",
                                              "{\"type\": \"orthographic\", \"orthographic\": {\"xmag\": 0, \"ymag\": 1, "
                                              "\"znear\": 0, \"zfar\": 10}}"};
    static const char *const cam_said[] = {"yfov must be in (0, pi)", "zfar must be greater than znear", "xmag"};
    for (int i = 0; i < 3; i++) {
        char top[512];
        snprintf(top, sizeof top, "\"cameras\": [%s], ", bad_cameras[i]);
        expect_refused(floor_scene("cam.gltf", NULL, NULL, ", {\"camera\": 0, \"translation\": [0, 1, 3]}", top),
                       cam_said[i]);
    }
}

/* What is within the rules loads, and a light loads only as it can be set again: Blender's hard-edged spot
 * (inner = outer) is taken back by lmgi_set_light with its own values; a texture transform inside the
 * bounds loads. */
static void test_valid_values_load(void **state)
{
    (void)state;
    lmgi_scene *sc = NULL;
    lmgi_error e;
    const char *spot = "{\"type\": \"spot\", \"intensity\": 10, \"spot\": {\"innerConeAngle\": 0.5, \"outerConeAngle\": 0.5}}";
    if (load(floor_scene("spot.gltf", NULL, spot, NULL, NULL), &sc, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    lmgi_light l;
    assert_int_equal(lmgi_get_light(sc, 0, &l, &e), LMGI_OK);
    assert_float_equal(l.inner_cone, l.outer_cone, 0.0);
    if (lmgi_set_light(sc, 0, &l, &e) != LMGI_OK)
        fail_msg("a light that loads is refused its own values: %s", e.message);
    lmgi_free(sc);
    char material[512];
    snprintf(material, sizeof material, "{\"pbrMetallicRoughness\": {\"metallicFactor\": 0, \"baseColorTexture\": "
             "{\"index\": 0, \"extensions\": {\"KHR_texture_transform\": {\"offset\": [0.5, -3], \"scale\": [1e5, 2], "
             "\"rotation\": 0.3}}}}}");
    if (load(floor_scene("tt.gltf", material, NULL, NULL, "\"textures\": [{\"source\": 0}], \"images\": [{\"uri\": "
                         "\"data:image/png;base64," ONE_TEXEL_PNG "\"}], "), &sc, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    lmgi_free(sc);
}

/* Transforms from animations and edits keep to the limit a file's own coordinates keep to (1e15): a key or
 * an edit that moves a node to 1e30 made the whole frame black. */
static void test_transforms_bounded(void **state)
{
    (void)state;
    static lmt_mesh m[2];
    memset(m, 0, sizeof m);
    lmt_mesh_quad(&m[0], (float[3]){-2, 0, 2}, (float[3]){4, 0, 0}, (float[3]){0, 0, -4});
    lmt_mesh_cube(&m[1], 0.25f);
    const char *nodes = "[{\"mesh\": 0}, {\"name\": \"crate\", \"mesh\": 1, \"translation\": [0, 0.5, 0], \"extras\": "
                        "{\"lmgi\": {\"dynamic\": true}}}, {\"name\": \"lamp\", \"translation\": [0, 2, 0], "
                        "\"extras\": {\"lmgi\": {\"dynamic\": true}}}]";
    static const float times[2] = {0, 1}, far[6] = {0, 0.5f, 0, 1e30f, 0.5f, 0};
    lmt_accessor acc[2] = {{times, 2, "SCALAR"}, {far, 2, "VEC3"}};
    const char *anim = "\"animations\": [{\"samplers\": [{\"input\": 4, \"output\": 5}], \"channels\": [{\"sampler\": 0, "
                       "\"target\": {\"node\": 1, \"path\": \"translation\"}}]}],";
    char path[1200];
    snprintf(path, sizeof path, "%s/anim.gltf", lmt_tmpdir());
    assert_int_equal(lmt_write_gltf(path, m, 2, nodes, acc, 2, anim), 0);
    expect_refused(path, "beyond the 5e+14 a translation key may reach");

    snprintf(path, sizeof path, "%s/still.gltf", lmt_tmpdir());
    assert_int_equal(lmt_write_gltf(path, m, 2, nodes, NULL, 0, ""), 0);
    lmgi_scene *sc = NULL;
    lmgi_error e;
    if (load(path, &sc, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    float before[16], world[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 1e30f, 0.5f, 0, 1};
    assert_true(lmgi_get_node_transform(sc, 1, before));
    assert_int_equal(lmgi_set_node_transform(sc, 1, world, &e), LMGI_ERR_INVALID);
    assert_non_null(strstr(e.message, "beyond the 1e+15 a coordinate may reach"));
    float after[16];
    assert_true(lmgi_get_node_transform(sc, 1, after));
    assert_memory_equal(before, after, sizeof before); /* left where it was */
    int lamp = lmgi_find_node(sc, "lamp"); /* a node with nothing but a light: its place is the light's */
    assert_true(lamp >= 0);
    assert_int_equal(lmgi_set_node_transform(sc, lamp, world, &e), LMGI_ERR_INVALID);
    assert_non_null(strstr(e.message, "node \"lamp\" lies at 1e+30"));
    world[12] = 1e6f; /* scale 1e12 on a 0.25 m crate: its corners at 2.5e11 */
    world[0] = world[5] = world[10] = 1e12f;
    assert_int_equal(lmgi_set_node_transform(sc, 1, world, &e), LMGI_OK);
    lmgi_free(sc);
}

/* The updater: a photon radius of 1e-30 (every pixel NaN), a camera that sees none of the scene (black
 * frames) are refused; a NaN in a lightmap makes lmgi_update fail naming the stage. */
static void test_updater_values(void **state)
{
    (void)state;
    lmgi_context *ctx = NULL;
    lmgi_error e;
    assert_int_equal(lmgi_context_create(NULL, &ctx, &e), LMGI_OK);
    lmgi_scene *sc = NULL;
    if (load(floor_scene("upd.gltf", NULL, NULL, ", {\"camera\": 0, \"translation\": [0, 1, 3e7]}",
                         "\"cameras\": [{\"type\": \"perspective\", \"perspective\": {\"yfov\": 0.8, \"znear\": 0.1, "
                         "\"zfar\": 20}}], "), &sc, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    lmgi_updater_desc d;
    memset(&d, 0, sizeof d);
    d.photons.count = 4000;
    d.frame.width = d.frame.height = 32;
    lmgi_updater *u = NULL;
    assert_int_equal(lmgi_updater_create(ctx, sc, &d, &u, &e), LMGI_ERR_INVALID); /* 3e7 away, far plane at 20 */
    assert_non_null(strstr(e.message, "sees none of the scene"));
    lmgi_free(sc);
    if (load(floor_scene("upd2.gltf", NULL, NULL, NULL, NULL), &sc, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    d.indirect = LMGI_INDIRECT_TILED;
    d.tiled.radius = 1e-30f;
    assert_int_equal(lmgi_updater_create(ctx, sc, &d, &u, &e), LMGI_ERR_INVALID);
    if (!strstr(e.message, "tiled.radius 1e-30"))
        fail_msg("%s", e.message);
    d.tiled.radius = 0.0f;
    d.indirect = LMGI_INDIRECT_LIGHTMAP;
    if (lmgi_updater_create(ctx, sc, &d, &u, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    lmgi_update_stats st;
    assert_int_equal(lmgi_update(u, 0.0f, 0.0f, &st, &e), LMGI_OK);

    /* a NaN in every IIM texture, as a broken gather would leave: the next update fails and says where */
    lmgi_info in;
    lmgi_get_info(sc, &in);
    size_t n = 4 * (size_t)in.atlas_width * in.atlas_height;
    float *nan = malloc(n * sizeof *nan);
    assert_non_null(nan);
    for (size_t i = 0; i < n; i++) /* colour NaN, alpha (the back-face share) 0: valid, composited as it is */
        nan[i] = i % 4 == 3 ? 0.0f : NAN;
    lm_iim *iim = lm_frame_loop_iim(lm_updater_loop(u));
    assert_int_equal(lm_gl_make_current(ctx->gl, &(lm_error){0}), LM_OK);
    unsigned tex[4] = {iim->fresh_tex, iim->old_tex, iim->new_tex, iim->display_tex};
    for (int k = 0; k < 4; k++)
        assert_int_equal(lm_iim_texture_write(tex[k], in.atlas_width, in.atlas_height, nan, &(lm_error){0}), LM_OK);
    free(nan);
    assert_int_equal(lmgi_update(u, 0.1f, 0.0f, &st, &e), LMGI_ERR_BACKEND);
    print_message("%s\n", e.message);
    assert_non_null(strstr(e.message, "not finite numbers"));
    assert_non_null(strstr(e.message, "the IIM lightmap (the gather)"));
    float *rgba = malloc(n * sizeof *rgba);
    assert_int_equal(lmgi_get_lightmap(u, LMGI_LIGHTMAP_IIM, rgba, n, &e), LMGI_ERR_BACKEND); /* read back: the same */
    assert_non_null(strstr(e.message, "not finite numbers"));
    assert_int_equal(lmgi_get_lightmap(u, LMGI_LIGHTMAP_AIM, rgba, n, &e), LMGI_OK);
    free(rgba);
    lmgi_updater_free(u);
    lmgi_free(sc);
    lmgi_context_free(ctx);
}

/* Pictures: a NaN is never written; half floats clamp to 65504 and count what they clamped. */
static void test_pictures(void **state)
{
    (void)state;
    char path[1200];
    snprintf(path, sizeof path, "%s/x.exr", lmt_tmpdir());
    float px[12] = {1, 2, 3, 1e6f, -1e6f, 70000, 0, 0, 0, 0.5f, 0.5f, 0.5f};
    lmgi_error e;
    lmgi_image_desc half = {.half = 1};
    lm_log_level was = lm_log_get_level();
    lm_log_set_level(LM_LOG_ERROR);
    lm_log_reset_warning_count();
    assert_int_equal(lmgi_write_image(path, 2, 2, 3, px, &half, &e), LMGI_OK);
    lm_log_set_level(was);
    assert_int_equal(lm_log_warning_count(), 1);
    int w, h;
    float *back = NULL;
    assert_int_equal(lm_read_exr(path, &w, &h, &back, &(lm_error){0}), LM_OK);
    assert_float_equal(back[4 * 1 + 0], 65504.0, 0.0);
    assert_float_equal(back[4 * 1 + 1], -65504.0, 0.0);
    assert_float_equal(back[4 * 1 + 2], 65504.0, 0.0);
    assert_float_equal(back[0], 1.0, 0.0);
    free(back);
    px[7] = NAN;
    snprintf(path, sizeof path, "%s/y.png", lmt_tmpdir());
    assert_int_equal(lmgi_write_image(path, 2, 2, 3, px, NULL, &e), LMGI_ERR_INVALID);
    assert_non_null(strstr(e.message, "1 values are not finite"));
    px[7] = INFINITY;
    snprintf(path, sizeof path, "%s/y.exr", lmt_tmpdir());
    assert_int_equal(lmgi_write_image(path, 2, 2, 3, px, NULL, &e), LMGI_ERR_INVALID);
}

/* A Draco-compressed mesh whose stream is not Draco (four zero bytes) and that has no uncompressed
 * fallback: refused naming the primitive and the extension, not drawn as nothing (test_compressed decodes
 * real ones). */
static void test_draco_damaged_without_fallback(void **state)
{
    (void)state;
    char path[1200];
    snprintf(path, sizeof path, "%s/draco.gltf", lmt_tmpdir());
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs("{\"asset\": {\"version\": \"2.0\"}, \"extensionsUsed\": [\"KHR_draco_mesh_compression\"], \"scene\": 0, "
          "\"scenes\": [{\"nodes\": [0]}], \"nodes\": [{\"mesh\": 0}], \"meshes\": [{\"primitives\": [{\"attributes\": "
          "{\"POSITION\": 0}, \"extensions\": {\"KHR_draco_mesh_compression\": {\"bufferView\": 0, \"attributes\": "
          "{\"POSITION\": 0}}}}]}], \"accessors\": [{\"componentType\": 5126, \"count\": 3, \"type\": \"VEC3\", \"min\": "
          "[0, 0, 0], \"max\": [1, 1, 0]}], \"bufferViews\": [{\"buffer\": 0, \"byteLength\": 4}], \"buffers\": "
          "[{\"byteLength\": 4, \"uri\": \"data:application/octet-stream;base64,AAAAAA==\"}]}", f);
    fclose(f);
    expect_refused(path, "mesh 0 primitive 0 (KHR_draco_mesh_compression): the Draco stream does not decode");
}

/* Images: memory planned before decoding. Two images whose headers say 8192 x 8192 need about 0.5 GB to
 * decode; with 256 MB left under an address-space limit the load is refused saying so (it used to drop
 * the textures and go on). Forty images of one file are decoded once and all used. */
#define BIG_PNG_A "iVBORw0KGgoAAAANSUhEUgAAIAAAACAACAIAAAD9yF0OAAAADElEQVR4nGNgoAwAAABAAAG3NHzvAAAAAElFTkSuQmCC"
#define BIG_PNG_B "iVBORw0KGgoAAAANSUhEUgAAH0AAACAACAIAAADY4OV0AAAADElEQVR4nGNgoAwAAABAAAG3NHzvAAAAAElFTkSuQmCC"

static const char *textured_scene(const char *name, int images, const char *const *uris, int distinct)
{
    static lmt_mesh m[40];
    static char materials[65536];
    memset(m, 0, sizeof m);
    int at = snprintf(materials, sizeof materials, "[");
    char nodes[8192];
    int nat = snprintf(nodes, sizeof nodes, "[{\"translation\": [0, 3, 0], \"extensions\": {\"KHR_lights_punctual\": "
                       "{\"light\": 0}}}");
    for (int i = 0; i < images; i++) {
        lmt_mesh_quad(&m[i], (float[3]){(float)i, 0, 1}, (float[3]){1, 0, 0}, (float[3]){0, 0, -1});
        at += snprintf(materials + at, sizeof materials - (size_t)at, "%s{\"pbrMetallicRoughness\": {\"metallicFactor\": "
                       "0, \"baseColorTexture\": {\"index\": %d}}}", i ? ", " : "", i);
        nat += snprintf(nodes + nat, sizeof nodes - (size_t)nat, ", {\"mesh\": %d}", i);
    }
    snprintf(nodes + nat, sizeof nodes - (size_t)nat, "]");
    at += snprintf(materials + at, sizeof materials - (size_t)at, "], \"textures\": [");
    for (int i = 0; i < images; i++)
        at += snprintf(materials + at, sizeof materials - (size_t)at, "%s{\"source\": %d}", i ? ", " : "", i);
    at += snprintf(materials + at, sizeof materials - (size_t)at, "], \"images\": [");
    for (int i = 0; i < images; i++)
        at += snprintf(materials + at, sizeof materials - (size_t)at, "%s{\"uri\": \"data:image/png;base64,%s\"}",
                       i ? ", " : "", uris[distinct ? i : 0]);
    snprintf(materials + at, sizeof materials - (size_t)at, "], " LMT_LIGHTS("{\"type\": \"point\", \"intensity\": 10}"));
    return lmt_write_scene(name, m, images, nodes, materials);
}

static void test_images_planned(void **state)
{
    (void)state;
    static const char *const one[] = {ONE_TEXEL_PNG};
    lmgi_scene *sc = NULL;
    lmgi_error e;
    if (load(textured_scene("forty.gltf", 40, one, 0), &sc, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    lmgi_info in;
    lmgi_get_info(sc, &in);
    assert_int_equal(in.textures, 40);
    lmgi_material mat;
    assert_int_equal(lmgi_get_material(sc, 39, &mat, &e), LMGI_OK);
    lmgi_free(sc);
#if defined(__SANITIZE_ADDRESS__)
    print_message("skipped: the address-space limit part (AddressSanitizer reserves terabytes of it)\n");
#else
    static const char *const big[] = {BIG_PNG_A, BIG_PNG_B};
    const char *path = textured_scene("big.gltf", 2, big, 1);
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        FILE *f = fopen("/proc/self/statm", "r");
        unsigned long long pages = 0;
        if (!f || fscanf(f, "%llu", &pages) != 1)
            _exit(3);
        fclose(f);
        struct rlimit r = {pages * (rlim_t)sysconf(_SC_PAGE_SIZE) + (256u << 20), RLIM_INFINITY};
        if (setrlimit(RLIMIT_AS, &r) != 0)
            _exit(4);
        lmgi_scene *s = NULL;
        lmgi_error err;
        lmgi_status st = load(path, &s, &err);
        fprintf(stderr, "%s\n", err.message);
        _exit(st == LMGI_ERR_NOMEM && strstr(err.message, "decoding 2 images would need about") &&
              strstr(err.message, "ulimit -v") ? 0 : 1);
    }
    int status;
    waitpid(pid, &status, 0);
    assert_true(WIFEXITED(status));
    assert_int_equal(WEXITSTATUS(status), 0);
#endif
}

/* Never hang on a file a scene names: a buffer or image that is a FIFO (its reader waited for a writer
 * forever), a device, a directory or a socket is refused naming its kind, at once. */
static void test_named_files_are_regular(void **state)
{
    (void)state;
    static const char *const kinds[] = {"a FIFO (a pipe)", "a device", "a directory", "a socket"};
    for (int k = 0; k < 4; k++) {
        const char *dir = lmt_tmpdir();
        char scene[1200], buf[1200];
        snprintf(scene, sizeof scene, "%s/named.gltf", dir);
        snprintf(buf, sizeof buf, "%s/buf.bin", dir);
        FILE *f = fopen(scene, "w");
        assert_non_null(f);
        fputs("{\"asset\": {\"version\": \"2.0\"}, \"scene\": 0, \"scenes\": [{\"nodes\": [0]}], \"nodes\": [{\"mesh\": 0}], "
              "\"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0}}]}], \"accessors\": [{\"bufferView\": 0, "
              "\"componentType\": 5126, \"count\": 3, \"type\": \"VEC3\", \"min\": [0, 0, 0], \"max\": [1, 1, 0]}], "
              "\"bufferViews\": [{\"buffer\": 0, \"byteLength\": 36}], \"buffers\": [{\"byteLength\": 36, \"uri\": "
              "\"buf.bin\"}]}", f);
        fclose(f);
        if (k == 0)
            assert_int_equal(mkfifo(buf, 0600), 0);
        else if (k == 1)
            assert_int_equal(symlink("/dev/zero", buf), 0);
        else if (k == 2)
            assert_int_equal(mkdir(buf, 0700), 0);
        else {
            int sock = socket(AF_UNIX, SOCK_STREAM, 0);
            struct sockaddr_un a = {.sun_family = AF_UNIX};
            if (sock < 0 || strlen(buf) >= sizeof a.sun_path) {
                print_message("skipped: a socket at %s (path too long for one)\n", buf);
                continue;
            }
            memcpy(a.sun_path, buf, strlen(buf) + 1); /* fits: checked above */
            assert_int_equal(bind(sock, (struct sockaddr *)&a, sizeof a), 0);
            close(sock);
        }
        double t0 = lm_now();
        expect_refused(scene, kinds[k]);
        assert_true(lm_now() - t0 < 5.0);
    }
}

/* Confined reads: a scene names an image outside its folder four ways (../, an absolute path, "..%2F"
 * percent-encoded, a link inside pointing out). Trusted (the default): read, with a warning that says so;
 * untrusted: the load fails naming the file; a file inside the folder is read either way. An absolute
 * URI is never read (tinygltf looks for it under the scene's folder): the texture is missing. */
static void test_untrusted_scene_stays_in_its_folder(void **state)
{
    (void)state;
    const char *base = lmt_tmpdir();
    char outside[1200], scene_dir[1200], png[1300];
    snprintf(outside, sizeof outside, "%s/outside", base);
    snprintf(scene_dir, sizeof scene_dir, "%s/scene", base);
    assert_int_equal(mkdir(outside, 0700), 0);
    assert_int_equal(mkdir(scene_dir, 0700), 0);
    static const uint8_t texel[4] = {200, 100, 50, 255};
    snprintf(png, sizeof png, "%s/tex.png", outside);
    assert_int_equal(lm_write_png(png, 1, 1, texel, &(lm_error){0}), LM_OK);
    snprintf(png, sizeof png, "%s/inside.png", scene_dir);
    assert_int_equal(lm_write_png(png, 1, 1, texel, &(lm_error){0}), LM_OK);
    char link[1300];
    snprintf(link, sizeof link, "%s/link.png", scene_dir);
    assert_int_equal(symlink("../outside/tex.png", link), 0);
    char absolute[1300];
    snprintf(absolute, sizeof absolute, "%s/tex.png", outside);
    const char *uris[5] = {"../outside/tex.png", absolute, "..%2Foutside%2Ftex.png", "link.png", "inside.png"};
    for (int k = 0; k < 5; k++) {
        char path[1300];
        snprintf(path, sizeof path, "%s/s%d.gltf", scene_dir, k);
        FILE *f = fopen(path, "w");
        assert_non_null(f);
        fprintf(f, "{\"asset\": {\"version\": \"2.0\"}, \"scene\": 0, \"scenes\": [{\"nodes\": [0]}], \"nodes\": "
                "[{\"mesh\": 0}], \"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0}, \"material\": 0}]}], "
                "\"materials\": [{\"pbrMetallicRoughness\": {\"baseColorTexture\": {\"index\": 0}}}], \"textures\": "
                "[{\"source\": 0}], \"images\": [{\"uri\": \"%s\"}], \"accessors\": [{\"bufferView\": 0, "
                "\"componentType\": 5126, \"count\": 3, \"type\": \"VEC3\", \"min\": [0, 0, 0], \"max\": [1, 1, 0]}], "
                "\"bufferViews\": [{\"buffer\": 0, \"byteLength\": 36}], \"buffers\": [{\"byteLength\": 36, \"uri\": "
                "\"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA\"}]}",
                uris[k]);
        fclose(f);
        for (int untrusted = 0; untrusted < 2; untrusted++) {
            lmgi_options o;
            lmgi_options_init(&o);
            o.untrusted = untrusted;
            lmgi_scene *sc = NULL;
            lmgi_error e;
            lm_log_level was = lm_log_get_level();
            lm_log_set_level(LM_LOG_ERROR);
            lm_log_reset_warning_count();
            lmgi_status st = lmgi_load(path, &o, &sc, &e);
            lm_log_set_level(was);
            int warned = lm_log_warning_count();
            if (k == 1) { /* an absolute URI names no file at all: tinygltf looks for it under the folder */
                assert_int_equal(st, LMGI_OK);
                lmgi_info in;
                lmgi_get_info(sc, &in);
                assert_int_equal(in.textures, 0);
                lmgi_free(sc);
            } else if (k == 4 || !untrusted) { /* read: inside, or trusted with a warning */
                if (st != LMGI_OK)
                    fail_msg("%s (untrusted %d): %s", uris[k], untrusted, e.message);
                lmgi_info in;
                lmgi_get_info(sc, &in);
                assert_int_equal(in.textures, 1);
                assert_int_equal(warned, k == 4 ? 0 : 1);
                lmgi_free(sc);
            } else {
                assert_int_equal(st, LMGI_ERR_IO);
                if (!strstr(e.message, "lies outside the scene's folder"))
                    fail_msg("%s: %s", uris[k], e.message);
                assert_null(sc);
            }
        }
    }
}

/* Sparse accessors (Blender writes them): a floor and a raised square whose four corners, and one of its
 * triangles' indices, come as sparse values over a base that has them wrong. The scene loads to the same
 * triangles as its dense twin and bakes to the same lightmap, bit for bit. */
static const char *two_squares(const char *name, int sparse)
{
    static const float pos[24] = {-2, 0, 2, 2, 0, 2, 2, 0, -2, -2, 0, -2,
                                  -0.5f, 0.8f, 0.5f, 0.5f, 0.8f, 0.5f, 0.5f, 0.8f, -0.5f, -0.5f, 0.8f, -0.5f};
    static const uint16_t idx[12] = {0, 1, 2, 0, 2, 3, 4, 6, 5, 4, 7, 6};
    uint8_t buf[256];
    size_t at = 0;
    float base[24];
    memcpy(base, pos, sizeof base);
    uint16_t base_idx[12];
    memcpy(base_idx, idx, sizeof base_idx);
    if (sparse) {
        memset(base + 12, 0, 12 * sizeof(float)); /* the raised square's corners: only in the sparse values */
        base_idx[7] = base_idx[8] = 0;            /* and one triangle's indices */
    }
    memcpy(buf + at, base, sizeof base), at += sizeof base;        /* view 0: positions (96) */
    memcpy(buf + at, base_idx, sizeof base_idx), at += sizeof base_idx; /* view 1: indices (24) */
    static const uint16_t where[4] = {4, 5, 6, 7}, where_idx[2] = {7, 8};
    memcpy(buf + at, where, sizeof where), at += sizeof where;     /* view 2 (8) */
    memcpy(buf + at, pos + 12, 12 * sizeof(float)), at += 48;      /* view 3 (48) */
    memcpy(buf + at, where_idx, sizeof where_idx), at += 4;        /* view 4 (4) */
    memcpy(buf + at, idx + 7, 2 * sizeof(uint16_t)), at += 4;      /* view 5 (4) */
    char data[400], json[4096];
    lmt_base64(buf, at, data);
    snprintf(json, sizeof json,
             "{\"asset\": {\"version\": \"2.0\"}, \"scene\": 0, \"scenes\": [{\"nodes\": [0, 1]}], \"nodes\": [{\"mesh\": 0}, "
             "{\"translation\": [0, 2, 0], \"extensions\": {\"KHR_lights_punctual\": {\"light\": 0}}}], "
             "\"extensionsUsed\": [\"KHR_lights_punctual\"], \"extensions\": {\"KHR_lights_punctual\": {\"lights\": "
             "[{\"type\": \"point\", \"intensity\": 10}]}}, \"materials\": [" GREY "], "
             "\"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0}, \"indices\": 1, \"material\": 0}]}], "
             "\"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, \"count\": 8, \"type\": \"VEC3\", \"min\": "
             "[-2, 0, -2], \"max\": [2, 0.8, 2]%s}, {\"bufferView\": 1, \"componentType\": 5123, \"count\": 12, \"type\": "
             "\"SCALAR\"%s}], \"bufferViews\": [{\"buffer\": 0, \"byteLength\": 96}, {\"buffer\": 0, \"byteOffset\": 96, "
             "\"byteLength\": 24}, {\"buffer\": 0, \"byteOffset\": 120, \"byteLength\": 8}, {\"buffer\": 0, \"byteOffset\": "
             "128, \"byteLength\": 48}, {\"buffer\": 0, \"byteOffset\": 176, \"byteLength\": 4}, {\"buffer\": 0, "
             "\"byteOffset\": 180, \"byteLength\": 4}], \"buffers\": [{\"byteLength\": %zu, \"uri\": "
             "\"data:application/octet-stream;base64,%s\"}]}",
             sparse ? ", \"sparse\": {\"count\": 4, \"indices\": {\"bufferView\": 2, \"componentType\": 5123}, \"values\": "
                      "{\"bufferView\": 3}}" : "",
             sparse ? ", \"sparse\": {\"count\": 2, \"indices\": {\"bufferView\": 4, \"componentType\": 5123}, \"values\": "
                      "{\"bufferView\": 5}}" : "",
             at, data);
    static char path[1200];
    snprintf(path, sizeof path, "%s/%s", lmt_tmpdir(), name);
    lmt_write_file(path, json, strlen(json));
    return path;
}

static float *baked_lightmap(lmgi_context *ctx, const char *path, size_t *n)
{
    lmgi_scene *sc = NULL;
    lmgi_error e;
    if (load(path, &sc, &e) != LMGI_OK)
        fail_msg("%s: %s", path, e.message);
    lmgi_updater_desc d;
    memset(&d, 0, sizeof d);
    d.photons.count = 4000;
    d.gather.resolution = 16;
    lmgi_updater *u = NULL;
    if (lmgi_updater_create(ctx, sc, &d, &u, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    lmgi_info in;
    lmgi_get_info(sc, &in);
    *n = 4 * (size_t)in.atlas_width * in.atlas_height;
    float *rgba = malloc(*n * sizeof *rgba);
    assert_non_null(rgba);
    assert_int_equal(lmgi_get_lightmap(u, LMGI_LIGHTMAP_IIM, rgba, *n, &e), LMGI_OK);
    assert_int_equal(in.triangles, 4);
    lmgi_updater_free(u);
    lmgi_free(sc);
    return rgba;
}

static void test_sparse_accessors(void **state)
{
    (void)state;
    lmgi_context *ctx = NULL;
    lmgi_error e;
    assert_int_equal(lmgi_context_create(NULL, &ctx, &e), LMGI_OK);
    size_t nd, ns;
    float *dense = baked_lightmap(ctx, two_squares("dense.gltf", 0), &nd);
    float *sparse = baked_lightmap(ctx, two_squares("sparse.gltf", 1), &ns);
    assert_int_equal(nd, ns);
    double lit = 0.0;
    for (size_t i = 0; i < nd; i += 4)
        lit += dense[i];
    assert_true(lit > 0.0); /* the raised square lights the floor under it */
    assert_memory_equal(dense, sparse, nd * sizeof *dense);
    free(dense);
    free(sparse);
    /* more sparse values than its views hold: refused naming the accessor */
    const char *path = two_squares("bad.gltf", 1);
    size_t size = 0;
    char *text = (char *)lmt_read_file(path, &size, 1);
    text[size] = '\0';
    char *count = strstr(text, "\"count\": 4, \"indices\"");
    assert_non_null(count);
    count[9] = '5'; /* 5 sparse values: the views hold 4 */
    lmt_write_file(path, text, size);
    free(text);
    expect_refused(path, "accessor 0 (sparse)");
    lmgi_context_free(ctx);
}

/* The knob table (include/lmgi_knobs.h): a zero desc resolves to the defaults the stages have themselves
 * (the table's defaults are theirs), each knob past its range or beside its choices is refused naming it
 * as the desc spells it, and a zeroed lmgi_options loads as lmgi_options_init's. */
#define SAME_DEFAULT(stage, field, kind, ctype, def, ...)                                                            \
    if ((def) != 0 && (double)resolved.stage.field != (double)(def))                                                 \
        fail_msg("lmgi_updater_defaults: " #stage "." #field " %g, the table says %g", (double)resolved.stage.field,  \
                 (double)(def));
#define REFUSED(stage, field, kind, ctype, def, lo, hi, ...)                                                          \
    {                                                                                                                 \
        lmgi_updater_desc bad;                                                                                        \
        memset(&bad, 0, sizeof bad);                                                                                  \
        double v = kind == LMGI_KNOB_SWITCH ? 2 : kind == LMGI_KNOB_CHOICE ? 99 : (double)(hi) + 1;                  \
        if (kind != LMGI_KNOB_REAL && v < 2147483647.0) {                                                             \
            int iv = (int)v; /* every knob but the floats is 4 bytes */                                              \
            memcpy(&bad.stage.field, &iv, sizeof iv);                                                                 \
            assert_int_equal(lm_updater_settings(sc->scene, &bad, NULL, &s, &err), LM_ERR_INVALID);                        \
            if (!strstr(err.msg, #stage "." #field))                                                                  \
                fail_msg("%s", err.msg);                                                                              \
            refused++;                                                                                                \
        }                                                                                                             \
    }

static void test_knob_table(void **state)
{
    (void)state;
    lmgi_scene *sc = NULL;
    lmgi_error e;
    lmgi_options zero, init;
    memset(&zero, 0, sizeof zero);
    lmgi_options_init(&init);
    init.texel_size = zero.texel_size = 0.25f;
    const char *path = floor_scene("knobs.gltf", NULL, NULL, NULL, NULL);
    lmgi_info a, b;
    assert_int_equal(lmgi_load(path, &zero, &sc, &e), LMGI_OK);
    lmgi_get_info(sc, &a);
    lmgi_free(sc);
    assert_int_equal(lmgi_load(path, &init, &sc, &e), LMGI_OK);
    lmgi_get_info(sc, &b);
    assert_int_equal(a.texels, b.texels);
    assert_int_equal(a.surfaces, b.surfaces);

    lmgi_updater_desc d, resolved;
    memset(&d, 0, sizeof d);
    lmgi_updater_defaults(&resolved);
    LMGI_UPDATER_KNOBS(SAME_DEFAULT)
    lm_frame_loop_settings s, def;
    lm_error err;
    assert_int_equal(lm_updater_settings(sc->scene, &d, NULL, &s, &err), LM_OK);
    lm_frame_loop_settings_default(&def);
    assert_int_equal(s.iim.texels_per_frame, def.iim.texels_per_frame);
    assert_int_equal(s.iim.blend_frames, def.iim.blend_frames);
    assert_memory_equal(&s.stage, &def.stage, sizeof s.stage);
    assert_memory_equal(&s.gather, &def.gather, sizeof s.gather);
    assert_memory_equal(&s.direct, &def.direct, sizeof s.direct);
    assert_memory_equal(&s.caustic_pass, &def.caustic_pass, sizeof s.caustic_pass);
    assert_memory_equal(&s.photon_gather, &def.photon_gather, sizeof s.photon_gather);
    assert_int_equal(s.emitter_light, def.emitter_light);
    assert_int_equal(s.emitter_rays, def.emitter_rays);
    assert_int_equal(s.reflection_size, def.reflection_size);
    assert_int_equal(s.reflection_faces, def.reflection_faces);
    assert_int_equal(s.overlap, def.overlap);
    assert_true(s.photon_radius == def.photon_radius);
    /* the environment faces' simplification reaches the direct pass: off is every triangle */
    d.frame.reflection_lod = LMGI_OFF;
    assert_int_equal(lm_updater_settings(sc->scene, &d, NULL, &s, &err), LM_OK);
    assert_true(s.direct.probe_lod == 0.0f);
    d.frame.reflection_lod = 0.01f;
    assert_int_equal(lm_updater_settings(sc->scene, &d, NULL, &s, &err), LM_OK);
    assert_true(s.direct.probe_lod == 0.01f);
    d.frame.reflection_lod = 0.0f;
    /* the rays gather's strata reach its settings */
    d.gather.rays = 1600;
    assert_int_equal(lm_updater_settings(sc->scene, &d, NULL, &s, &err), LM_OK);
    assert_int_equal(s.gather.ray_samples, 1600);
    d.gather.rays = 0;
    int refused = 0;
    LMGI_UPDATER_KNOBS(REFUSED)
    print_message("%d knobs refused past their range or choices\n", refused);
    assert_true(refused >= 25);
    lmgi_free(sc);
}

/* The gather scheme on auto is chosen with the settings, so that lmgi_check runs the gather an updater runs:
 * under a gradient sky, rays (a hemicube clears to one colour); hemicubes asked for there are refused. Before,
 * the choice was lmgi_updater_create's alone, and lmgi_check drew hemicubes under the sky's mean. */
static void test_scheme_chosen_with_the_settings(void **state)
{
    (void)state;
    lmgi_scene *sc = NULL;
    lmgi_error e;
    const char *path = floor_scene("gradient.gltf", NULL, NULL, NULL,
                                   "\"extras\": {\"lmgi\": {\"sky\": {\"zenith\": [1, 1, 2], \"horizon\": [2, 2, 2]}}}, ");
    assert_int_equal(load(path, &sc, &e), LMGI_OK);
    lmgi_updater_desc d;
    memset(&d, 0, sizeof d);
    lm_frame_loop_settings s;
    lm_error err;
    assert_int_equal(lm_updater_settings(sc->scene, &d, NULL, &s, &err), LM_OK);
    assert_int_equal(s.gather.scheme, LM_GATHER_RAYS);
    d.gather.scheme = LMGI_GATHER_VIEWPORTS;
    assert_int_equal(lm_updater_settings(sc->scene, &d, NULL, &s, &err), LM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "rays gather"));
    lmgi_free(sc);
    path = floor_scene("uniform.gltf", NULL, NULL, NULL, NULL); /* 2 triangles, no sky: hemicubes */
    assert_int_equal(load(path, &sc, &e), LMGI_OK);
    d.gather.scheme = LMGI_GATHER_DEFAULT;
    assert_int_equal(lm_updater_settings(sc->scene, &d, NULL, &s, &err), LM_OK);
    assert_int_equal(s.gather.scheme, LM_GATHER_VIEWPORTS);
    assert_int_equal(s.stage.exact_direct, LM_EXACT_SUNS); /* a point light: the AIMs compute the suns' */
    lmgi_free(sc);
}

/* A scene lit by emissive triangles alone (a lamp over a floor, no punctual light, no sky): on auto the rays
 * gather, with the emitters' light computed in the AIMs and taken at the rays' near hits (docs/gather.md,
 * "Scenes lit by emitters alone"). Either given keeps the other's old default: suns give hemicubes,
 * hemicubes the suns. lmgi_get_updater_info tells what was chosen. */
static void test_emitters_alone_chosen(void **state)
{
    (void)state;
    static lmt_mesh m[2];
    memset(m, 0, sizeof m);
    lmt_mesh_quad(&m[0], (float[3]){-0.5f, 2, -0.5f}, (float[3]){1, 0, 0}, (float[3]){0, 0, 1});
    lmt_mesh_quad(&m[1], (float[3]){-2, 0, 2}, (float[3]){4, 0, 0}, (float[3]){0, 0, -4});
    const char *path = lmt_write_scene("lamp_alone.gltf", m, 2, "[{\"mesh\": 0}, {\"mesh\": 1}]",
                                       "[{\"pbrMetallicRoughness\": {\"baseColorFactor\": [0, 0, 0, 1]}, "
                                       "\"emissiveFactor\": [1, 1, 1]}, " GREY "]");
    lmgi_scene *sc = NULL;
    lmgi_error e;
    assert_int_equal(load(path, &sc, &e), LMGI_OK);
    /* {aim.direct, gather.scheme, emitter_light} given -> the scheme and the AIMs' direct light chosen */
    static const struct {
        lmgi_aim_direct direct;
        lmgi_gather_scheme scheme;
        lmgi_emitter_light emitters;
        lm_gather_scheme want_scheme;
        int want_direct;
    } cases[] = {
        {LMGI_AIM_DIRECT_DEFAULT, LMGI_GATHER_DEFAULT, LMGI_EMITTERS_AUTO, LM_GATHER_RAYS, LM_EXACT_EMITTERS},
        {LMGI_AIM_DIRECT_SUNS, LMGI_GATHER_DEFAULT, LMGI_EMITTERS_AUTO, LM_GATHER_VIEWPORTS, LM_EXACT_SUNS},
        {LMGI_AIM_DIRECT_DEFAULT, LMGI_GATHER_VIEWPORTS, LMGI_EMITTERS_AUTO, LM_GATHER_VIEWPORTS, LM_EXACT_SUNS},
        {LMGI_AIM_DIRECT_DEFAULT, LMGI_GATHER_RAYS, LMGI_EMITTERS_AUTO, LM_GATHER_RAYS, LM_EXACT_EMITTERS},
        /* drawn into hemicubes: nothing computes them */
        {LMGI_AIM_DIRECT_DEFAULT, LMGI_GATHER_DEFAULT, LMGI_EMITTERS_DRAWN, LM_GATHER_VIEWPORTS, LM_EXACT_SUNS},
    };
    lmgi_updater_desc d;
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        memset(&d, 0, sizeof d);
        d.aim.direct = cases[k].direct;
        d.gather.scheme = cases[k].scheme;
        d.gather.emitter_light = cases[k].emitters;
        lm_frame_loop_settings s;
        lm_error err;
        assert_int_equal(lm_updater_settings(sc->scene, &d, NULL, &s, &err), LM_OK);
        assert_int_equal(s.gather.scheme, cases[k].want_scheme);
        assert_int_equal(s.stage.exact_direct, cases[k].want_direct);
    }

    lmgi_context *ctx = NULL;
    assert_int_equal(lmgi_context_create(NULL, &ctx, &e), LMGI_OK);
    memset(&d, 0, sizeof d);
    d.frame.width = d.frame.height = 0;
    lmgi_updater *u = NULL;
    if (lmgi_updater_create(ctx, sc, &d, &u, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    lmgi_updater_info info;
    lmgi_get_updater_info(u, &info);
    assert_int_equal(info.aim.direct, LMGI_AIM_DIRECT_EMITTERS);
    assert_int_equal(info.gather.scheme, LMGI_GATHER_RAYS);
    lmgi_updater_free(u);
    lmgi_context_free(ctx);
    lmgi_free(sc);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_file_values),
        cmocka_unit_test(test_valid_values_load),
        cmocka_unit_test(test_transforms_bounded),
        cmocka_unit_test(test_updater_values),
        cmocka_unit_test(test_pictures),
        cmocka_unit_test(test_draco_damaged_without_fallback),
        cmocka_unit_test(test_images_planned),
        cmocka_unit_test(test_named_files_are_regular),
        cmocka_unit_test(test_untrusted_scene_stays_in_its_folder),
        cmocka_unit_test(test_sparse_accessors),
        cmocka_unit_test(test_knob_table),
        cmocka_unit_test(test_scheme_chosen_with_the_settings),
        cmocka_unit_test(test_emitters_alone_chosen),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
