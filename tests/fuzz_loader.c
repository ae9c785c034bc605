/* Deterministic mutation fuzzing of the glTF loader, built and run under ASan + UBSan
 * (make build/asan/tests/fuzz_loader). Mutated copies of three shared scenes (two .glb, one .gltf with
 * its .bin) are written to a temp file and loaded; the test passes if nothing crashes, leaks or trips a
 * sanitizer. Each load must either succeed or fail with a message. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "../src/core/log.h"
#include "../src/scene/scene.h"
#include "support.h"

#define FUZZ_SEED 0x5eed1234u
#define FUZZ_ITERATIONS 10500 /* spread evenly over the three sources */

typedef struct {
    unsigned char *data;
    size_t size;
} blob;

static uint32_t g_rng = FUZZ_SEED;

static uint32_t rnd(void) { return lmt_xorshift(&g_rng); } /* fixed sequence for a fixed seed */

static size_t rnd_below(size_t n) { return n ? rnd() % n : 0; }

static blob read_file(const char *path)
{
    blob b;
    b.data = lmt_read_file(path, &b.size, 64);
    return b;
}

static void write_file(const char *path, const unsigned char *d, size_t n) { lmt_write_file(path, d, n); }

static void copy_file(const char *from, const char *dir, const char *name)
{
    char to[1024];
    blob b = read_file(from);
    snprintf(to, sizeof to, "%s/%s", dir, name);
    write_file(to, b.data, b.size);
    free(b.data);
}

/* Position of a random digit (JSON number) or quote (JSON string) in the text, or a random byte. */
static size_t find_char(const blob *b, size_t limit, int (*want)(unsigned char))
{
    size_t start = rnd_below(limit);
    for (size_t k = 0; k < limit; k++) {
        size_t i = (start + k) % limit;
        if (want(b->data[i]))
            return i;
    }
    return start;
}

static int is_digit(unsigned char c) { return c >= '0' && c <= '9'; }
static int is_quote(unsigned char c) { return c == '"'; }

static void put_le32(unsigned char *p, uint32_t v)
{
    for (int i = 0; i < 4; i++)
        p[i] = (unsigned char)(v >> (8 * i));
}

/* Applies 1-3 mutations to m (which has room for 64 extra bytes). json_limit: how many leading bytes
 * are JSON text (the whole file for .gltf, the JSON chunk for .glb); glb: header fields exist. */
static void mutate(blob *m, size_t json_limit, int glb)
{
    static const char *const numbers[] = {"-1", "4294967295", "1e309", "0", "99999999", "-0.5", "2147483648", "NaN"};
    int n = 1 + (int)rnd_below(3);
    for (int k = 0; k < n && m->size > 24; k++) {
        size_t i;
        switch (rnd_below(glb ? 8 : 7)) {
        case 0: /* bit flip */
            i = rnd_below(m->size);
            m->data[i] ^= (unsigned char)(1u << rnd_below(8));
            break;
        case 1: /* random byte */
            m->data[rnd_below(m->size)] = (unsigned char)rnd();
            break;
        case 2: /* truncation */
            m->size = 1 + rnd_below(m->size);
            break;
        case 3: /* insert a byte */
            i = rnd_below(m->size);
            memmove(m->data + i + 1, m->data + i, m->size - i);
            m->data[i] = (unsigned char)rnd();
            m->size++;
            break;
        case 4: /* delete a run of bytes */
            i = rnd_below(m->size);
            {
                size_t len = 1 + rnd_below(16);
                if (len > m->size - i)
                    len = m->size - i;
                memmove(m->data + i, m->data + i + len, m->size - i - len);
                m->size -= len;
            }
            break;
        case 5: /* JSON number corruption: overwrite at a digit with an extreme number */
            if (json_limit > m->size)
                json_limit = m->size;
            i = find_char(m, json_limit, is_digit);
            {
                const char *s = numbers[rnd_below(sizeof numbers / sizeof numbers[0])];
                size_t len = strlen(s);
                if (i + len <= m->size)
                    memcpy(m->data + i, s, len);
            }
            break;
        case 6: /* JSON string corruption: break a quote or a character inside a string */
            if (json_limit > m->size)
                json_limit = m->size;
            i = find_char(m, json_limit, is_quote);
            if (i + 1 < m->size)
                m->data[i + (rnd() & 1)] = "\"\\{}[]:,x"[rnd_below(9)];
            break;
        case 7: /* GLB length fields: total, JSON chunk, BIN chunk */
            {
                static const size_t fields[] = {8, 12};
                uint32_t v = rnd_below(4) == 0 ? 0xffffffffu : (uint32_t)rnd_below(m->size * 2 + 1);
                i = rnd_below(3) < 2 ? fields[rnd_below(2)] : 20 + json_limit;
                if (i + 4 <= m->size)
                    put_le32(m->data + i, v);
            }
            break;
        }
    }
}

typedef struct {
    const char *name; /* file name in the temp dir */
    blob src;
    size_t json_len;
    int glb;
} source;

static uint32_t le32(const unsigned char *p) { return p[0] | p[1] << 8 | p[2] << 16 | (uint32_t)p[3] << 24; }

static void test_fuzz_loader(void **state)
{
    (void)state;
    static const char *const files[] = {"cornell-box/CornellBox.glb", "room/IrradianceVolumeExample.glb",
                                        "cornell-suzanne/cornellBox-2.80-Eevee-gltf.gltf",
                                        "cornell-suzanne/cornellBox-2.80-Eevee-gltf.bin",
                                        "cornell-suzanne/checker-meter.png", "cornell-suzanne/checkerBJS.png"};
    /* check them all before reading any (lmt_shared_scene's result is overwritten by the next call) */
    for (size_t k = 0; k < sizeof files / sizeof files[0]; k++) {
        LMT_REQUIRE_SCENE(p, lmt_shared_scene(files[k]));
    }
    source srcs[3] = {{"fuzz-cornell.glb", read_file(lmt_shared_scene(files[0])), 0, 1},
                      {"fuzz-room.glb", read_file(lmt_shared_scene(files[1])), 0, 1},
                      {"fuzz-suzanne.gltf", read_file(lmt_shared_scene(files[2])), 0, 0}};
    for (int k = 0; k < 2; k++)
        srcs[k].json_len = le32(srcs[k].src.data + 12);
    srcs[2].json_len = srcs[2].src.size;

    /* the .gltf's buffer and images must sit beside the mutated copy */
    const char *dir = lmt_tmpdir();
    for (size_t k = 3; k < sizeof files / sizeof files[0]; k++)
        copy_file(lmt_shared_scene(files[k]), dir, strchr(files[k], '/') + 1);

    lm_log_set_level(LM_LOG_ERROR); /* warnings from thousands of broken files are noise here */
    int ok = 0, failed = 0;
    size_t cap = 0;
    for (int k = 0; k < 3; k++)
        cap = srcs[k].src.size > cap ? srcs[k].src.size : cap;
    blob m = {malloc(cap + 64 * 4), 0};
    assert_non_null(m.data);
    for (int it = 0; it < FUZZ_ITERATIONS; it++) {
        source *s = &srcs[it % 3];
        memcpy(m.data, s->src.data, s->src.size);
        m.size = s->src.size;
        mutate(&m, s->glb ? 20 + s->json_len : s->json_len, s->glb);
        char path[1024];
        snprintf(path, sizeof path, "%s/%s", dir, s->name);
        write_file(path, m.data, m.size);
        lm_scene *scene = NULL;
        lm_error err;
        lm_load_options opt = {.strict = (int)(rnd() & 1)};
        if (lm_scene_load_gltf(path, &opt, &scene, &err) == LM_OK) {
            assert_non_null(scene);
            ok++;
            lm_scene_free(scene);
        } else {
            assert_null(scene);
            assert_true(err.msg[0] != '\0');
            failed++;
        }
    }
    print_message("fuzz: %d loads, %d succeeded, %d failed cleanly (seed 0x%x)\n", ok + failed, ok, failed,
                  FUZZ_SEED);
    assert_int_equal(ok + failed, FUZZ_ITERATIONS);
    free(m.data);
    for (int k = 0; k < 3; k++)
        free(srcs[k].src.data);
    lm_log_set_level(LM_LOG_WARN);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_fuzz_loader)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
