/* Structured fuzzing of the whole pipeline: mutated real glTF through load, the photon stage and one
 * frame (most aborts an adversarial user found came after a clean load: issue 16). Built and run under
 * ASan + UBSan. Each input is a copy of a shipped or shared scene with 1 to 3 mutations, chosen from:
 *   - values of glTF keys that steer the loader (accessor count, byteOffset, byteStride, componentType,
 *     buffer byteLength and uri, node matrix, scale, translation, rotation, children, light colour and
 *     intensity, texture and image sources, sampler input/output, material factors) set to edge values
 *     (-1, 0, huge, 1e38, NaN, 1e309, a cycle, a missing file, a directory, /dev/zero);
 *   - floats of the binary buffer (positions, normals, keyframes, indices) set to NaN, Inf, 1e30, 0 or
 *     a denormal;
 *   - byte flips, random bytes, insertions, deletions and truncation.
 * An input passes when it loads and renders a frame whose every pixel is finite, or fails with a message
 * naming the problem; never an abort, a sanitizer report, or more than 10 s.
 *
 * LMGI_FUZZ_INPUTS (default 240: the quick slice in make test, about a minute under ASan) and
 * LMGI_FUZZ_SEED (default 1) pick the inputs; make fuzz runs 100,000 over several seeds in parallel.
 * LMGI_FUZZ_ONLY=N (with the same seed and LMGI_FUZZ_INPUTS > N) runs input N alone, to reproduce it. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <cmocka.h>
#include <lmgi.h>
#include <math.h>

#include "../src/core/log.h"
#include "../src/core/timing.h"
#include "../src/gpu/gl/gl_context.h"
#include "../src/update/frame_loop.h"
#include "../src/api/lmgi_scene.h"
#include "support.h"

#define SLOW_SECONDS 10.0

typedef struct {
    unsigned char *data;
    size_t size, cap;
} blob;

static uint32_t g_rng;
static lm_gl_context *g_gl; /* one GL context for every input's frame loop (a context per input cost most of
                             * an input's time: llvmpipe sets up megabytes for each) */

static uint32_t rnd(void) { return lmt_xorshift(&g_rng); }

static size_t rnd_below(size_t n) { return n ? rnd() % n : 0; }

static blob read_blob(const char *path)
{
    blob b;
    b.data = lmt_read_file(path, &b.size, 4096);
    b.cap = b.size + 4096;
    return b;
}

static void write_blob(const char *path, const unsigned char *d, size_t n) { lmt_write_file(path, d, n); }

static uint32_t le32(const unsigned char *p) { return p[0] | p[1] << 8 | p[2] << 16 | (uint32_t)p[3] << 24; }
static void put_le32(unsigned char *p, uint32_t v)
{
    for (int i = 0; i < 4; i++)
        p[i] = (unsigned char)(v >> (8 * i));
}

/* Replaces m[at, at + len) with text (m has room: cap). */
static void splice(blob *m, size_t at, size_t len, const char *text)
{
    size_t n = strlen(text);
    if (m->size - len + n > m->cap)
        return;
    memmove(m->data + at + n, m->data + at + len, m->size - at - len);
    memcpy(m->data + at, text, n);
    m->size = m->size - len + n;
}

/* The extent of the JSON value starting at m[at] (a number, string, literal or bracketed array/object). */
static size_t value_length(const blob *m, size_t at, size_t end)
{
    size_t i = at;
    if (i < end && (m->data[i] == '[' || m->data[i] == '{')) {
        int depth = 0;
        for (; i < end; i++) {
            depth += m->data[i] == '[' || m->data[i] == '{';
            depth -= m->data[i] == ']' || m->data[i] == '}';
            if (depth == 0)
                return i + 1 - at;
        }
        return 0;
    }
    if (i < end && m->data[i] == '"') {
        for (i++; i < end && m->data[i] != '"'; i++)
            ;
        return i < end ? i + 1 - at : 0;
    }
    while (i < end && !strchr(",}] \n\r\t", m->data[i]))
        i++;
    return i - at;
}

typedef struct {
    const char *key;
    const char *const *values;
} key_edit;

static const char *const k_numbers[] = {"-1", "0", "1", "3", "4294967295", "2147483647", "1e38", "-1e38", "1e309",
                                        "0.5", "65536", NULL};
static const char *const k_vec3[] = {"[0,0,0]", "[-1,1,1]", "[1e38,1,1]", "[1e20,1e20,1e20]", "[1,1,0]",
                                     "[1e-30,1e-30,1e-30]", "[1,2]", "[]", "\"x\"", NULL};
static const char *const k_quat[] = {"[0,0,0,0]", "[0,0,0,1e30]", "[1,1,1,1]", "[0,0,0]", "[0.7071,0,0,0.7071]", NULL};
static const char *const k_matrix[] = {"[0,0,0,0, 0,0,0,0, 0,0,0,0, 0,0,0,1]", "[-1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1]",
                                       "[1,0,0,0, 0,1,0,0, 0,0,1,0, 1e20,0,0,1]", "[1,2,3]",
                                       "[1e38,0,0,0, 0,1e38,0,0, 0,0,1e38,0, 0,0,0,1]", NULL};
static const char *const k_children[] = {"[0]", "[0,0]", "[1,2,3,4,5,6,7,8]", "[99]", "[-1]", "[]", NULL};
static const char *const k_color[] = {"[1e38,1e38,1e38]", "[-1,0,0]", "[0,0,0]", "[1e19,1,1]", "[1,1]", NULL};
static const char *const k_uri[] = {"\"missing.bin\"", "\"/dev/zero\"", "\".\"", "\"\"", "\"data:,\"",
                                    "\"../../../../etc/passwd\"", NULL};
static const char *const k_factor4[] = {"[1e38,1,1,1]", "[-1,-1,-1,1]", "[0,0,0,0]", "[1,1,1]", NULL};
static const char *const k_component[] = {"5120", "5121", "5122", "5123", "5125", "5126", "5124", "0", NULL};
static const char *const k_type[] = {"\"SCALAR\"", "\"VEC2\"", "\"VEC4\"", "\"MAT4\"", "\"X\"", NULL};

static const key_edit k_edits[] = {
    {"\"count\"", k_numbers},        {"\"byteOffset\"", k_numbers},    {"\"byteStride\"", k_numbers},
    {"\"byteLength\"", k_numbers},   {"\"componentType\"", k_component}, {"\"type\"", k_type},
    {"\"bufferView\"", k_numbers},   {"\"buffer\"", k_numbers},        {"\"uri\"", k_uri},
    {"\"matrix\"", k_matrix},        {"\"scale\"", k_vec3},            {"\"translation\"", k_vec3},
    {"\"rotation\"", k_quat},        {"\"children\"", k_children},     {"\"mesh\"", k_numbers},
    {"\"color\"", k_color},          {"\"intensity\"", k_numbers},     {"\"source\"", k_numbers},
    {"\"index\"", k_numbers},        {"\"input\"", k_numbers},         {"\"output\"", k_numbers},
    {"\"node\"", k_numbers},         {"\"baseColorFactor\"", k_factor4}, {"\"emissiveFactor\"", k_color},
    {"\"indices\"", k_numbers},      {"\"POSITION\"", k_numbers},      {"\"material\"", k_numbers},
    {"\"outerConeAngle\"", k_numbers}, {"\"yfov\"", k_numbers},        {"\"emissiveStrength\"", k_numbers},
};

/* Sets the value of a random occurrence of a random steering key in m[from, *end) (the JSON text) to an
 * edge value; *end follows the edit. */
static void edit_key(blob *m, size_t from, size_t *end)
{
    const key_edit *e = &k_edits[rnd_below(sizeof k_edits / sizeof k_edits[0])];
    size_t klen = strlen(e->key), hits = 0;
    for (size_t i = from; i + klen < *end; i++)
        hits += memcmp(m->data + i, e->key, klen) == 0;
    if (!hits)
        return;
    size_t want = rnd_below(hits);
    for (size_t i = from; i + klen < *end; i++) {
        if (memcmp(m->data + i, e->key, klen) != 0 || want--)
            continue;
        size_t v = i + klen;
        while (v < *end && (m->data[v] == ':' || m->data[v] == ' '))
            v++;
        size_t len = value_length(m, v, *end), nv = 0;
        while (e->values[nv])
            nv++;
        size_t before = m->size;
        splice(m, v, len, e->values[rnd_below(nv)]);
        *end = *end + m->size - before; /* unsigned: wraps back for a shorter value, as intended */
        return;
    }
}

/* A float of the binary data (4-byte aligned in [from, to)) set to a value the loader must survive. */
static void poison_float(blob *m, size_t from, size_t to)
{
    static const float values[] = {NAN, INFINITY, -INFINITY, 1e30f, -1e30f, 0.0f, 1e-40f, 3e38f};
    if (to <= from + 4 || to > m->size)
        return;
    size_t i = from + 4 * rnd_below((to - from) / 4);
    memcpy(m->data + i, &values[rnd_below(sizeof values / sizeof values[0])], 4);
}

static void byte_mutation(blob *m)
{
    size_t i = rnd_below(m->size);
    switch (rnd_below(5)) {
    case 0:
        m->data[i] ^= (unsigned char)(1u << rnd_below(8));
        break;
    case 1:
        m->data[i] = (unsigned char)rnd();
        break;
    case 2:
        m->size = 1 + rnd_below(m->size);
        break;
    case 3:
        if (m->size < m->cap) {
            memmove(m->data + i + 1, m->data + i, m->size - i);
            m->data[i] = (unsigned char)rnd();
            m->size++;
        }
        break;
    default: {
        size_t len = 1 + rnd_below(16);
        len = len > m->size - i ? m->size - i : len;
        memmove(m->data + i, m->data + i + len, m->size - i - len);
        m->size -= len;
    }
    }
}

/* 1 to 3 mutations: mostly structured (key values, binary floats), an eighth byte-level. For a .glb the
 * JSON chunk's length fields follow the edits; a .gltf's floats are poisoned in its .bin (bin_out). */
static void mutate(blob *m, int glb, const blob *bin, blob *bin_out)
{
    size_t json_at = glb ? 20 : 0, json_end = glb ? 20 + le32(m->data + 12) : m->size;
    int n = 1 + (int)rnd_below(3);
    for (int k = 0; k < n; k++) {
        unsigned what = (unsigned)rnd_below(8);
        if (what < 5) {
            edit_key(m, json_at, &json_end);
        } else if (what < 7) {
            if (glb)
                poison_float(m, (json_end + 3) / 4 * 4 + 8, m->size);
            else if (bin && bin_out->data)
                poison_float(bin_out, 0, bin_out->size);
        } else {
            byte_mutation(m);
            if (json_end > m->size)
                json_end = m->size;
        }
    }
    if (glb && m->size >= 20) { /* keep the container consistent where the edit was in the JSON */
        size_t pad = (4 - (json_end - 20) % 4) % 4;
        if (m->size + pad <= m->cap && pad) {
            memmove(m->data + json_end + pad, m->data + json_end, m->size - json_end);
            memset(m->data + json_end, ' ', pad);
            m->size += pad, json_end += pad;
        }
        put_le32(m->data + 12, (uint32_t)(json_end - 20));
        put_le32(m->data + 8, (uint32_t)m->size);
    }
}

/* With LMGI_FUZZ_KEEP=DIR, a failing input (and the .bin beside it) is copied to DIR for a look. */
static int keep_input(const char *path)
{
    const char *keep = getenv("LMGI_FUZZ_KEEP");
    if (keep) {
        char cmd[4096];
        const char *slash = strrchr(path, '/');
        snprintf(cmd, sizeof cmd, "cp '%s' '%.*s/fuzz-features.bin' '%s/' 2>/dev/null", path, (int)(slash - path),
                 path, keep);
        if (system(cmd) != 0)
            print_error("could not keep %s\n", path);
    }
    return 1;
}

/* One input through load, the photon stage and one frame. Returns 1 when it rendered, 0 when it was
 * refused with a message; fails the test on a non-finite pixel or a missing message. */
static int run_pipeline(const char *path)
{
    lmgi_options o;
    lmgi_options_init(&o);
    o.target_texels = 64;
    o.strict = (int)(rnd() & 1);
    lmgi_scene *sc = NULL;
    lmgi_error err;
    if (lmgi_load(path, &o, &sc, &err) != LMGI_OK) {
        assert_null(sc);
        assert_true(err.message[0] != '\0');
        if (getenv("LMGI_FUZZ_VERBOSE"))
            print_message("refused: %s\n", err.message);
        return 0;
    }
    lmgi_info in;
    lmgi_get_info(sc, &in);
    int rendered = 0;
    if (in.triangles > 0) {
        lm_frame_loop_settings set;
        lm_frame_loop_settings_default(&set);
        set.width = set.height = 16;
        set.stage.photons.total_photons = 500;
        set.iim.texels_per_frame = 20;
        set.reflection_size = 4;
        set.overlap = 0;
        set.gather.resolution = 4;
        set.gather.rim_samples = 2;
        set.emitter_rays = 2;
        set.direct.cube_size = set.direct.map_size = 16;
        set.gl = g_gl;
        lm_frame_loop *fl = NULL;
        lm_error e;
        lm_status st = lm_frame_loop_create(&sc->world, &set, &fl, NULL, NULL, &e);
        if (st == LM_OK) {
            lm_frame_stats fs;
            st = lm_frame_loop_step(fl, 0.25f, &fs, &e);
        }
        if (st == LM_OK) {
            const float *img = lm_frame_loop_image(fl);
            for (int i = 0; i < 3 * 16 * 16; i++)
                if (!isfinite(img[i]) && keep_input(path))
                    fail_msg("%s: pixel %d of the frame is %g", path, i / 3, (double)img[i]);
            rendered = 1;
        } else {
            assert_true(e.msg[0] != '\0');
            if (getenv("LMGI_FUZZ_VERBOSE"))
                print_message("refused: %s\n", e.msg);
        }
        lm_frame_loop_free(fl);
    }
    lmgi_free(sc);
    return rendered;
}

/* A small .gltf with its .bin beside it, written here so that every feature the pipeline reads is in one
 * cheap scene: a floor and a cube (positions, normals, uvs, u16 indices), a mirror cube, a textured
 * material (the shared checker), point, spot and directional lights, a camera, and an animation moving
 * the cube (times and values in the .bin). */
static void write_feature_scene(const char *dir)
{
    float bin[1024];
    size_t n = 0;
    static const float floor_pos[12] = {-2, 0, 2, 2, 0, 2, 2, 0, -2, -2, 0, -2};
    for (int k = 0; k < 12; k++)
        bin[n++] = floor_pos[k];
    for (int v = 0; v < 4; v++) /* normals */
        bin[n++] = 0, bin[n++] = 1, bin[n++] = 0;
    static const float uv[8] = {0, 0, 1, 0, 1, 1, 0, 1};
    for (int k = 0; k < 8; k++)
        bin[n++] = uv[k];
    uint16_t idx[6] = {0, 1, 2, 0, 2, 3};
    memcpy(&bin[n], idx, sizeof idx);
    n += 4; /* 12 bytes of indices, padded to 16 */
    static const float anim[8] = {0, 1, 0, 0.5f, 0, 0.5f, 0.5f, 0}; /* times 0, 1; translations */
    for (int k = 0; k < 8; k++)
        bin[n++] = anim[k];
    char path[1024];
    snprintf(path, sizeof path, "%s/fuzz-features.bin", dir);
    write_blob(path, (const unsigned char *)bin, n * sizeof(float));
    static const char *json =
        "{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"KHR_lights_punctual\"],"
        "\"extensions\":{\"KHR_lights_punctual\":{\"lights\":[{\"type\":\"point\",\"intensity\":5,\"color\":[1,0.9,0.8]},"
        "{\"type\":\"spot\",\"intensity\":8,\"spot\":{\"innerConeAngle\":0.2,\"outerConeAngle\":0.6}},"
        "{\"type\":\"directional\",\"intensity\":1}]}},"
        "\"scene\":0,\"scenes\":[{\"nodes\":[0,1,2,3,4,5,6,7]}],"
        "\"nodes\":[{\"name\":\"floor\",\"mesh\":0},{\"name\":\"cube\",\"mesh\":1,\"translation\":[0,0.5,0],"
        "\"scale\":[0.3,0.3,0.3]},{\"name\":\"mirror\",\"mesh\":2,\"translation\":[1,0.5,0],\"rotation\":[0,0.38,0,0.92],"
        "\"scale\":[0.3,0.6,0.3]},{\"translation\":[0,2,0],\"extensions\":{\"KHR_lights_punctual\":{\"light\":0}}},"
        "{\"translation\":[1,2,1],\"rotation\":[-0.7071,0,0,0.7071],\"extensions\":{\"KHR_lights_punctual\":{\"light\":1}}},"
        "{\"rotation\":[-0.5,0.3,0,0.8],\"extensions\":{\"KHR_lights_punctual\":{\"light\":2}}},"
        "{\"camera\":0,\"translation\":[0,1.5,4],\"rotation\":[-0.17,0,0,0.98]},"
        "{\"name\":\"parent\",\"children\":[],\"matrix\":[1,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1]}],"
        "\"cameras\":[{\"type\":\"perspective\",\"perspective\":{\"yfov\":0.9,\"znear\":0.05,\"aspectRatio\":1}}],"
        "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1,\"TEXCOORD_0\":2},\"indices\":3,"
        "\"material\":0}]},{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1},\"indices\":3,\"material\":1}]},"
        "{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":3,\"material\":2,\"mode\":4}]}],"
        "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0},\"metallicFactor\":0}},"
        "{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.8,0.3,0.2,1],\"metallicFactor\":0},\"doubleSided\":true},"
        "{\"pbrMetallicRoughness\":{\"metallicFactor\":1,\"roughnessFactor\":0},\"emissiveFactor\":[0.2,0.2,0.2]}],"
        "\"textures\":[{\"source\":0,\"sampler\":0}],\"samplers\":[{}],\"images\":[{\"uri\":\"checker-meter.png\"}],"
        "\"animations\":[{\"samplers\":[{\"input\":4,\"output\":5,\"interpolation\":\"LINEAR\"}],"
        "\"channels\":[{\"sampler\":0,\"target\":{\"node\":1,\"path\":\"translation\"}}]}],"
        "\"buffers\":[{\"uri\":\"fuzz-features.bin\",\"byteLength\":176}],"
        "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":48},{\"buffer\":0,\"byteOffset\":48,\"byteLength\":48},"
        "{\"buffer\":0,\"byteOffset\":96,\"byteLength\":32},{\"buffer\":0,\"byteOffset\":128,\"byteLength\":12},"
        "{\"buffer\":0,\"byteOffset\":144,\"byteLength\":32}],"
        "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\",\"min\":[-2,0,-2],"
        "\"max\":[2,0,2]},{\"bufferView\":1,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"},"
        "{\"bufferView\":2,\"componentType\":5126,\"count\":4,\"type\":\"VEC2\"},"
        "{\"bufferView\":3,\"componentType\":5123,\"count\":6,\"type\":\"SCALAR\"},"
        "{\"bufferView\":4,\"byteOffset\":0,\"componentType\":5126,\"count\":2,\"type\":\"SCALAR\"},"
        "{\"bufferView\":4,\"byteOffset\":8,\"componentType\":5126,\"count\":2,\"type\":\"VEC3\"}]}";
    snprintf(path, sizeof path, "%s/fuzz-features-source.gltf", dir);
    write_blob(path, (const unsigned char *)json, strlen(json));
}

typedef struct {
    const char *shared;   /* under ../shared/scenes, or NULL */
    const char *project;  /* under scenes/, or NULL */
    const char *name;     /* the mutated copy's name in the temp dir */
    int glb;
} source;

static void test_fuzz_pipeline(void **state)
{
    (void)state;
    const char *env = getenv("LMGI_FUZZ_INPUTS"), *seed_env = getenv("LMGI_FUZZ_SEED");
    long inputs = env ? strtol(env, NULL, 10) : 240;
    unsigned long seed = seed_env ? strtoul(seed_env, NULL, 10) : 1;
    const char *only_env = getenv("LMGI_FUZZ_ONLY"); /* run input N alone (the others only drawn) */
    long only = only_env ? strtol(only_env, NULL, 10) : -1;
    g_rng = 0x9e3779b9u ^ (uint32_t)(seed * 2654435761u);
    if (!g_rng)
        g_rng = 1;
    static const source sources[] = {
        {"cornell-box/CornellBox.glb", NULL, "fuzz-cornellbox.glb", 1},
        {"room/IrradianceVolumeExample.glb", NULL, "fuzz-room.glb", 1},
        {NULL, "two_rooms.glb", "fuzz-two-rooms.glb", 1},
        {NULL, NULL, "fuzz-features.gltf", 0},
    };
    enum { SOURCES = sizeof sources / sizeof sources[0] };
    LMT_REQUIRE_SCENE(checker, lmt_shared_scene("cornell-suzanne/checker-meter.png"));
    LMT_REQUIRE_SCENE(cb, lmt_shared_scene(sources[0].shared));
    LMT_REQUIRE_SCENE(room, lmt_shared_scene(sources[1].shared));
    LMT_REQUIRE_SCENE(tr, lmt_project_scene(sources[2].project));
    const char *dir = lmt_tmpdir();
    char path[1024], bin_path[1024];
    blob png = read_blob(lmt_shared_scene("cornell-suzanne/checker-meter.png"));
    snprintf(path, sizeof path, "%s/checker-meter.png", dir);
    write_blob(path, png.data, png.size);
    free(png.data);
    write_feature_scene(dir);
    snprintf(path, sizeof path, "%s/fuzz-features-source.gltf", dir);
    snprintf(bin_path, sizeof bin_path, "%s/fuzz-features.bin", dir);
    blob src[SOURCES], bin = read_blob(bin_path);
    for (int k = 0; k < SOURCES; k++)
        src[k] = read_blob(sources[k].shared    ? lmt_shared_scene(sources[k].shared)
                           : sources[k].project ? lmt_project_scene(sources[k].project)
                                                : path);
    lm_log_set_level(LM_LOG_ERROR); /* warnings from thousands of broken files are noise here */
    lm_error gl_err;
    if (lm_gl_context_create(&g_gl, &gl_err) != LM_OK)
        fail_msg("%s", gl_err.msg);
    for (int k = 0; k < SOURCES; k++) { /* unmutated, every source renders (else the fuzzing proves little) */
        snprintf(path, sizeof path, "%s/%s", dir, sources[k].name);
        write_blob(path, src[k].data, src[k].size);
        write_blob(bin_path, bin.data, bin.size);
        if (!run_pipeline(path))
            fail_msg("%s does not render unmutated", sources[k].name);
    }
    long rendered = 0, refused = 0, slow = 0;
    double worst = 0.0;
    for (long it = 0; it < inputs; it++) {
        int k = (int)(it % SOURCES);
        blob m = {malloc(src[k].cap), src[k].size, src[k].cap};
        blob b = {malloc(bin.cap), bin.size, bin.cap};
        assert_true(m.data && b.data);
        memcpy(m.data, src[k].data, src[k].size);
        memcpy(b.data, bin.data, bin.size);
        mutate(&m, sources[k].glb, sources[k].glb ? NULL : &bin, &b);
        snprintf(path, sizeof path, "%s/%s", dir, sources[k].name);
        write_blob(path, m.data, m.size);
        write_blob(bin_path, b.data, b.size);
        if (getenv("LMGI_FUZZ_KEEP_ALL")) /* each input before it runs: the last one kept is the one that aborted */
            keep_input(path);
        if (only >= 0 && it != only) { /* replaying to input `only`: the same random numbers, no work */
            (void)rnd(); /* run_pipeline's strict flag */
            free(m.data);
            free(b.data);
            continue;
        }
        /* processor time, not wall time: a machine starved by other work (a second fuzzer, a build) made
         * inputs that take under 1.2 s alone look slow */
        double t0 = (double)clock() / CLOCKS_PER_SEC;
        int r = run_pipeline(path);
        double dt = (double)clock() / CLOCKS_PER_SEC - t0;
        rendered += r, refused += !r;
        worst = dt > worst ? dt : worst;
        if (dt > SLOW_SECONDS) {
            slow++;
            char keep[1100];
            snprintf(keep, sizeof keep, "%s.slow-%ld", path, it);
            write_blob(keep, m.data, m.size);
            print_error("input %ld (%s, seed %lu) took %.1f s\n", it, sources[k].name, seed, dt);
        }
        free(m.data);
        free(b.data);
        if ((it + 1) % 5000 == 0) /* progress for long runs (make fuzz logs) */
            print_message("fuzz pipeline (seed %lu): %ld of %ld inputs, %ld rendered, %ld refused, %ld slow\n", seed,
                          it + 1, inputs, rendered, refused, slow);
    }
    print_message("fuzz pipeline (seed %lu): %ld inputs, %ld rendered a finite frame, %ld refused with a message, "
                  "%ld over %.0f s of processor time (slowest %.2f s)\n", seed, inputs, rendered, refused, slow, SLOW_SECONDS, worst);
    assert_int_equal(slow, 0);
    for (int k = 0; k < SOURCES; k++)
        free(src[k].data);
    free(bin.data);
    lm_gl_context_destroy(g_gl);
    lm_log_set_level(LM_LOG_WARN);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_fuzz_pipeline)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
