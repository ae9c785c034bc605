/* Compressed glTF (docs/loading.md, "Compressed glTF"): EXT_meshopt_compression and
 * KHR_draco_mesh_compression decoded into the scene the uncompressed file gives.
 *
 * The lossless check writes its own EXT_meshopt_compression copy of a scene (meshoptimizer's encoders,
 * every vertex stream as ATTRIBUTES and every index stream as INDICES, which keep every byte and every
 * triangle's vertex order) and bakes both: the same surfaces and the same lightmap, bit for bit. gltfpack's
 * and draco_transcoder's output (Debian's tools) are checked against the file they were made from as far
 * as their codecs allow: gltfpack's TRIANGLES codec rotates each triangle's vertices, Draco reorders and
 * quantizes, so the atlas differs and the lightmaps are compared by their mean. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <cjson/cJSON.h>
#include <lmgi.h>
#include <math.h>
#include <meshoptimizer.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "edit_room.h"
#include "support.h"

static uint32_t le32(const unsigned char *p) { return p[0] | p[1] << 8 | p[2] << 16 | (uint32_t)p[3] << 24; }

static void put32(unsigned char *p, uint32_t v)
{
    for (int i = 0; i < 4; i++)
        p[i] = (unsigned char)(v >> (8 * i));
}

static int number(const cJSON *o, const char *key, int otherwise)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
    return cJSON_IsNumber(v) ? v->valueint : otherwise;
}

/* How view v is read: its accessor's element size and whether it holds a primitive's indices; 0: no
 * accessor reads it (an image). */
static size_t view_element(const cJSON *j, int v, int *indices)
{
    const cJSON *acc;
    int i = 0;
    *indices = 0;
    cJSON_ArrayForEach(acc, cJSON_GetObjectItemCaseSensitive(j, "accessors")) {
        if (number(acc, "bufferView", -1) == v) {
            static const char *const types[] = {"SCALAR", "VEC2", "VEC3", "VEC4", "MAT4"};
            static const int comps[] = {1, 2, 3, 4, 16};
            const char *type = cJSON_GetObjectItemCaseSensitive(acc, "type")->valuestring;
            int n = 0, ct = number(acc, "componentType", 0);
            for (int t = 0; t < 5; t++)
                n = strcmp(type, types[t]) ? n : comps[t];
            const cJSON *mesh, *prim;
            cJSON_ArrayForEach(mesh, cJSON_GetObjectItemCaseSensitive(j, "meshes"))
                cJSON_ArrayForEach(prim, cJSON_GetObjectItemCaseSensitive(mesh, "primitives"))
                    *indices |= number(prim, "indices", -1) == i;
            return (size_t)n * (ct == 5126 || ct == 5125 ? 4 : ct == 5122 || ct == 5123 ? 2 : 1);
        }
        i++;
    }
    return 0;
}

/* Writes `out`, the GLB `in` with every bufferView an accessor reads stored EXT_meshopt_compression-
 * compressed (vertex streams of a whole number of 4-byte words as ATTRIBUTES, index streams as INDICES),
 * the others copied; the compressed views' bytes in a fallback buffer, as gltfpack writes. */
static void meshopt_pack(const char *in, const char *out)
{
    size_t size;
    unsigned char *glb = lmt_read_file(in, &size, 0);
    size_t json_len = le32(glb + 12), bin_at = 20 + ((json_len + 3) & ~(size_t)3);
    const unsigned char *bin = glb + bin_at + 8;
    size_t bin_len = le32(glb + bin_at);
    cJSON *j = cJSON_ParseWithLength((const char *)glb + 20, json_len);
    assert_non_null(j);
    unsigned char *packed = malloc(2 * bin_len + 1024);
    size_t at = 0;
    cJSON *view;
    int v = 0, compressed = 0;
    cJSON_ArrayForEach(view, cJSON_GetObjectItemCaseSensitive(j, "bufferViews")) {
        size_t offset = (size_t)number(view, "byteOffset", 0), length = (size_t)number(view, "byteLength", 0);
        int indices;
        size_t stride = (size_t)number(view, "byteStride", 0), elem = view_element(j, v++, &indices);
        stride = stride ? stride : elem;
        size_t bytes = 0;
        if (elem && indices && (stride == 2 || stride == 4)) {
            size_t count = length / stride, vertices = 0;
            unsigned *idx = malloc(sizeof *idx * (count + 1)); /* the encoder takes 32-bit indices */
            for (size_t k = 0; k < count; k++) {
                idx[k] = stride == 2 ? (unsigned)(bin[offset + 2 * k] | bin[offset + 2 * k + 1] << 8) : le32(bin + offset + 4 * k);
                vertices = idx[k] + 1 > vertices ? idx[k] + 1 : vertices;
            }
            bytes = meshopt_encodeIndexSequence(packed + at, meshopt_encodeIndexSequenceBound(count, vertices), idx, count);
            free(idx);
        } else if (elem && !indices && stride % 4 == 0 && length % stride == 0) {
            bytes = meshopt_encodeVertexBuffer(packed + at, meshopt_encodeVertexBufferBound(length / stride, stride),
                                               bin + offset, length / stride, stride);
        }
        if (bytes) { /* the view's bytes now come from decoding into the fallback buffer 1 */
            cJSON *ext = cJSON_CreateObject(), *exts = cJSON_CreateObject();
            cJSON_AddNumberToObject(ext, "buffer", 0);
            cJSON_AddNumberToObject(ext, "byteOffset", (double)at);
            cJSON_AddNumberToObject(ext, "byteLength", (double)bytes);
            cJSON_AddNumberToObject(ext, "byteStride", (double)stride);
            cJSON_AddNumberToObject(ext, "count", (double)(length / stride));
            cJSON_AddStringToObject(ext, "mode", indices ? "INDICES" : "ATTRIBUTES");
            cJSON_AddItemToObject(exts, "EXT_meshopt_compression", ext);
            cJSON_AddItemToObject(view, "extensions", exts);
            cJSON_ReplaceItemInObject(view, "buffer", cJSON_CreateNumber(1));
            compressed++;
        } else { /* kept as it was, in buffer 0 */
            memcpy(packed + at, bin + offset, length);
            bytes = length;
            cJSON_ReplaceItemInObject(view, "byteOffset", cJSON_CreateNumber((double)at));
        }
        at = (at + bytes + 3) & ~(size_t)3;
    }
    assert_true(compressed > 0);
    cJSON *buffers = cJSON_GetObjectItemCaseSensitive(j, "buffers");
    cJSON_ReplaceItemInObject(cJSON_GetArrayItem(buffers, 0), "byteLength", cJSON_CreateNumber((double)at));
    cJSON *fallback = cJSON_CreateObject(), *fexts = cJSON_CreateObject(), *fext = cJSON_CreateObject();
    cJSON_AddNumberToObject(fallback, "byteLength", (double)bin_len);
    cJSON_AddTrueToObject(fext, "fallback");
    cJSON_AddItemToObject(fexts, "EXT_meshopt_compression", fext);
    cJSON_AddItemToObject(fallback, "extensions", fexts);
    cJSON_AddItemToArray(buffers, fallback);
    static const char *const lists[] = {"extensionsUsed", "extensionsRequired"};
    for (int l = 0; l < 2; l++) {
        if (!cJSON_GetObjectItemCaseSensitive(j, lists[l]))
            cJSON_AddItemToObject(j, lists[l], cJSON_CreateArray());
        cJSON_AddItemToArray(cJSON_GetObjectItemCaseSensitive(j, lists[l]), cJSON_CreateString("EXT_meshopt_compression"));
    }
    char *text = cJSON_PrintUnformatted(j);
    size_t tlen = strlen(text), tpad = (tlen + 3) & ~(size_t)3, total = 20 + tpad + 8 + at;
    unsigned char *outb = calloc(1, total);
    memcpy(outb, glb, 8);
    put32(outb + 8, (uint32_t)total);
    put32(outb + 12, (uint32_t)tpad);
    put32(outb + 16, 0x4E4F534Au);
    memset(outb + 20, ' ', tpad);
    memcpy(outb + 20, text, tlen);
    put32(outb + 20 + tpad, (uint32_t)at);
    put32(outb + 24 + tpad, 0x004E4942u);
    memcpy(outb + 28 + tpad, packed, at);
    lmt_write_file(out, outb, total);
    print_message("%s: %d bufferViews compressed, %zu bytes of BIN -> %zu\n", in, compressed, bin_len, at);
    free(outb);
    cJSON_free(text);
    cJSON_Delete(j);
    free(packed);
    free(glb);
}

typedef struct {
    int triangles, surfaces;
    size_t n;
    float *iim;
    double mean; /* of the valid texels' RGB */
} bake_result;

static bake_result bake(lmgi_context *ctx, const char *path, int texels)
{
    bake_result r = {0};
    lmgi_scene *sc = lmt_load(path, texels);
    lmgi_updater_desc d;
    memset(&d, 0, sizeof d);
    d.photons.count = 20000;
    lmgi_updater *u = NULL;
    lmgi_error e;
    if (lmgi_updater_create(ctx, sc, &d, &u, &e) != LMGI_OK)
        fail_msg("%s: %s", path, e.message);
    lmgi_info in;
    lmgi_get_info(sc, &in);
    r.triangles = (int)in.triangles, r.surfaces = in.surfaces;
    r.n = 4 * (size_t)in.atlas_width * in.atlas_height;
    r.iim = malloc(r.n * sizeof *r.iim);
    assert_int_equal(lmgi_get_lightmap(u, LMGI_LIGHTMAP_IIM, r.iim, r.n, &e), LMGI_OK);
    size_t valid = 0;
    for (size_t i = 0; i < r.n; i += 4)
        if (r.iim[i + 3] > 0.0f)
            r.mean += (double)r.iim[i] + r.iim[i + 1] + r.iim[i + 2], valid++;
    r.mean /= 3.0 * (double)(valid ? valid : 1);
    lmgi_updater_free(u);
    lmgi_free(sc);
    return r;
}

static void same_bake(lmgi_context *ctx, const char *a, const char *b, int texels)
{
    bake_result x = bake(ctx, a, texels), y = bake(ctx, b, texels);
    assert_int_equal(x.triangles, y.triangles);
    assert_int_equal(x.surfaces, y.surfaces);
    assert_int_equal(x.n, y.n);
    assert_memory_equal(x.iim, y.iim, x.n * sizeof *x.iim);
    print_message("%s: %d triangles, %d surfaces, the same lightmap bit for bit (mean %.4f)\n", b, y.triangles,
                  y.surfaces, y.mean);
    free(x.iim);
    free(y.iim);
}

/* Our own lossless EXT_meshopt_compression copy of the generated Cornell box (animated nodes: their
 * animation streams compressed too) and of the shared living room: the same bake, bit for bit. */
static void test_meshopt_lossless(void **state)
{
    (void)state;
    lmgi_context *ctx = NULL;
    lmgi_error e;
    assert_int_equal(lmgi_context_create(NULL, &ctx, &e), LMGI_OK);
    char packed[600];
    LMT_REQUIRE_SCENE(cornell, lmt_project_scene("cornell.glb"));
    char plain[600];
    snprintf(plain, sizeof plain, "%s", cornell);
    snprintf(packed, sizeof packed, "%s/cornell_meshopt.glb", lmt_tmpdir());
    meshopt_pack(plain, packed);
    same_bake(ctx, plain, packed, 4000);
    const char *room = lmt_shared_scene("occlusion-room/room_lit.glb");
    if (room) {
        snprintf(plain, sizeof plain, "%s", room);
        snprintf(packed, sizeof packed, "%s/room_lit_meshopt.glb", lmt_tmpdir());
        meshopt_pack(plain, packed);
        same_bake(ctx, plain, packed, 4000);
    } else {
        print_message("skipped the shared room: ../shared/scenes/occlusion-room/room_lit.glb not found\n");
    }
    /* a stream cut short: refused naming the bufferView */
    size_t size;
    unsigned char *b = lmt_read_file(packed, &size, 0);
    size_t bin_at = 20 + ((le32(b + 12) + 3) & ~(size_t)3);
    memset(b + bin_at + 8, 0xff, 64); /* the first stream's header and first bytes */
    lmt_write_file(packed, b, size);
    free(b);
    lmgi_scene *sc = NULL;
    assert_int_not_equal(lmgi_load(packed, NULL, &sc, &e), LMGI_OK);
    print_message("damaged: %s\n", e.message);
    assert_non_null(strstr(e.message, "(EXT_meshopt_compression)"));
    assert_non_null(strstr(e.message, "does not decode"));
    lmgi_context_free(ctx);
}

/* Runs a Debian tool; 0 when it is not installed (the test then skips that part, saying so). */
static int tool(const char *name, const char *args)
{
    char cmd[2048], out[4096];
    snprintf(cmd, sizeof cmd, "command -v %s > /dev/null 2>&1", name);
    if (system(cmd) != 0) {
        print_message("skipped: %s is not installed (Debian: apt-get install %s; make test installs it)\n", name,
                      strcmp(name, "gltfpack") ? "draco" : "gltfpack");
        return 0;
    }
    snprintf(cmd, sizeof cmd, "%s %s 2>&1", name, args);
    if (lmt_run(cmd, out, sizeof out) != 0)
        fail_msg("%s: %s", cmd, out);
    return 1;
}

/* Two bakes of one geometry whose triangles a codec reordered: the same triangles, the surfaces within
 * `split` of them (a rotated triangle's normal rounds differently, Draco welds vertices, and surfaces are
 * split where normals bend and edges part), the mean irradiance within `tolerance`. */
static void close_bake(lmgi_context *ctx, const char *a, const char *b, double split, double tolerance)
{
    bake_result x = bake(ctx, a, 4000), y = bake(ctx, b, 4000);
    print_message("%s: %d triangles, %d surfaces, mean %.4f; %s: %d, %d, %.4f\n", a, x.triangles, x.surfaces, x.mean, b,
                  y.triangles, y.surfaces, y.mean);
    assert_int_equal(x.triangles, y.triangles);
    assert_true(abs(x.surfaces - y.surfaces) <= split * x.surfaces);
    assert_true(x.mean > 0.0 && fabs(y.mean / x.mean - 1.0) < tolerance);
    free(x.iim);
    free(y.iim);
}

/* gltfpack's own compression (-c) of the shared living room against the same file uncompressed (-noq
 * both: no quantization) and with its defaults (quantized), and draco_transcoder's of the two-rooms scene and of the living room against
 * the files it read. */
static void test_tools_output(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(room, lmt_shared_scene("occlusion-room/room_lit.glb"));
    lmgi_context *ctx = NULL;
    lmgi_error e;
    assert_int_equal(lmgi_context_create(NULL, &ctx, &e), LMGI_OK);
    const char *dir = lmt_tmpdir();
    char args[2048], a[600], b[600];
    snprintf(a, sizeof a, "%s/plain.glb", dir);
    snprintf(b, sizeof b, "%s/packed.glb", dir);
    snprintf(args, sizeof args, "-i %s -o %s -noq -kn -km", room, a);
    int have = tool("gltfpack", args);
    if (have) {
        snprintf(args, sizeof args, "-i %s -o %s -noq -kn -km -c", room, b);
        tool("gltfpack", args);
        close_bake(ctx, a, b, 0.05, 0.01);
        /* gltfpack's defaults: quantized (KHR_mesh_quantization: 14-bit positions, 8-bit normals, the
         * meshes merged into one) and compressed */
        snprintf(b, sizeof b, "%s/quantized.glb", dir);
        snprintf(args, sizeof args, "-i %s -o %s -cc", room, b);
        tool("gltfpack", args);
        close_bake(ctx, room, b, 1.0, 0.03); /* surfaces: 821 for 476, the quantized walls bend */
    }
    static const char *const sources[] = {"two_rooms", "room_lit"};
    for (int s = 0; s < 2; s++) {
        const char *src = s ? room : lmt_project_scene("two_rooms.glb");
        char source[600];
        snprintf(source, sizeof source, "%s", src);
        snprintf(b, sizeof b, "%s/%s_draco.glb", dir, sources[s]);
        snprintf(args, sizeof args, "-i %s -o %s -qp 16 -qn 12 -qt 14", source, b);
        if (tool("draco_transcoder", args))
            close_bake(ctx, source, b, 0.12, 0.04); /* room_lit: 524 surfaces for 476 */
    }
    /* a Draco stream cut short: refused naming the primitive */
    size_t size;
    unsigned char *bytes = lmt_read_file(b, &size, 0);
    if (size > 200) {
        size_t bin_at = 20 + ((le32(bytes + 12) + 3) & ~(size_t)3);
        memset(bytes + bin_at + 8, 0, size - bin_at - 8);
        lmt_write_file(b, bytes, size);
        lmgi_scene *sc = NULL;
        assert_int_not_equal(lmgi_load(b, NULL, &sc, &e), LMGI_OK);
        print_message("damaged: %s\n", e.message);
        assert_non_null(strstr(e.message, "(KHR_draco_mesh_compression): the Draco stream does not decode"));
    }
    free(bytes);
    lmgi_context_free(ctx);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_meshopt_lossless),
        cmocka_unit_test(test_tools_output),
    };
    lmgi_set_verbosity(0);
    return cmocka_run_group_tests(tests, NULL, NULL);
}
