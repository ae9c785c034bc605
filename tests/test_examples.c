/* The examples, built as a user builds them: this build's library installed into a temporary prefix
 * (make install-files), each example compiled against it through pkg-config alone, then run. The runtime
 * loop at a fixed texel count gives lmgi run's lightmap byte for byte; with a time budget and a node moved
 * every frame it runs, uploads changed surfaces and writes its frame. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "support.h"

static char output[16384];

static int sh(const char *cmd)
{
    char full[8192];
    snprintf(full, sizeof full, "%s 2>&1", cmd);
    FILE *p = popen(full, "r");
    assert_non_null(p);
    size_t n = fread(output, 1, sizeof output - 1, p);
    output[n] = '\0';
    int status = pclose(p);
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128;
}

static const char *build_dir(void)
{
    const char *b = getenv("LMGI_BUILD");
    return b ? b : "build";
}

/* Installs into DIR/prefix and compiles examples/NAME.c to DIR/prefix/NAME; returns the program's path. */
static const char *install_and_compile(const char *name)
{
    static char prefix[1024], program[1200];
    snprintf(prefix, sizeof prefix, "%s/prefix", lmt_tmpdir());
    char cmd[4096];
    snprintf(cmd, sizeof cmd, "make -s --no-print-directory install-files PREFIX=%s BUILD=%s", prefix, build_dir());
    if (sh(cmd) != 0)
        fail_msg("%s: %s", cmd, output);
#if defined(__SANITIZE_ADDRESS__)
    const char *san = "-fsanitize=address,undefined"; /* a library built with the sanitizers needs them */
#else
    const char *san = "";
#endif
    snprintf(program, sizeof program, "%s/%s", prefix, name);
    snprintf(cmd, sizeof cmd,
             "PKG_CONFIG_PATH=%s/lib/pkgconfig; export PKG_CONFIG_PATH; cc -std=c11 -Wall -Wextra -Werror "
             "%s examples/%s.c $(pkg-config --cflags --libs lmgi) " /* the README's one-liner, and warnings */
             "-Wl,-rpath,%s/lib -o %s",
             prefix, san, name, prefix, program);
    if (sh(cmd) != 0)
        fail_msg("%s: %s", cmd, output);
    return program;
}

static long file_size(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return -1;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fclose(f);
    return n;
}

static void test_runtime_loop(void **state)
{
    (void)state;
    const char *prog = install_and_compile("runtime_loop");
    char cmd[4096], a[1024], b[1024];
    snprintf(a, sizeof a, "%s/example", lmt_tmpdir());
    snprintf(b, sizeof b, "%s/run", lmt_tmpdir());
    snprintf(cmd, sizeof cmd, "%s scenes/cornell.glb %s --frames 6 --texels 20 --fps 0", prog, a); /* it makes a */
    if (sh(cmd) != 0)
        fail_msg("%s: %s", cmd, output);
    assert_non_null(strstr(output, "6 frames, fixed texels"));
    snprintf(cmd, sizeof cmd, "%s/lmgi run scenes/cornell.glb --frames 6 --size 32x32 --texels-per-frame 20 -q --out %s",
             build_dir(), b);
    if (sh(cmd) != 0)
        fail_msg("%s: %s", cmd, output);
    snprintf(cmd, sizeof cmd, "cmp %s/iim.exr %s/iim.exr", a, b);
    if (sh(cmd) != 0)
        fail_msg("the example's lightmap differs from lmgi run's: %s", output);

    snprintf(cmd, sizeof cmd, "%s scenes/cornell.glb %s --frames 20 --budget 4 --move dynamic_cube --fps 0", prog, a);
    if (sh(cmd) != 0)
        fail_msg("%s: %s", cmd, output);
    assert_non_null(strstr(output, "20 frames, time budget"));
    snprintf(cmd, sizeof cmd, "%s/frame.png", a);
    assert_true(file_size(cmd) > 1000);
    snprintf(cmd, sizeof cmd, "%s scenes/cornell.glb %s --move no_such_node --fps 0", prog, a);
    assert_int_equal(sh(cmd), 1);
    assert_non_null(strstr(output, "no node 'no_such_node'"));
}

/* The editor's session on the two rooms: a first bake, the blue cube in room A recoloured and a light
 * of room B moved, each re-bake touching part of the scene and saying so, every lightmap written and the
 * level exported. */
static void test_editor_session(void **state)
{
    (void)state;
    const char *prog = install_and_compile("editor_session");
    char cmd[4096], dir[1024];
    snprintf(dir, sizeof dir, "%s", lmt_tmpdir());
    snprintf(cmd, sizeof cmd, "(%s scenes/two_rooms.glb %s --material blue --light light_b2 --texels 3000 2>/dev/null)",
             prog, dir); /* stdout only: the report, not the progress bars */
    if (sh(cmd) != 0)
        fail_msg("%s: %s", cmd, output);
    print_message("%s", output);
    unsigned changed = 0, traced = 0, texels = 0;
    const char *line = strstr(output, "recolour ");
    assert_non_null(line);
    assert_int_equal(sscanf(line, "recolour %u of %u photon paths changed, %*d AIM surfaces refreshed, %u texels",
                            &changed, &traced, &texels), 3);
    assert_true(changed > 0 && changed < traced / 10); /* the cube's photons, not the rooms' */
    assert_true(texels > 0 && texels < 3300);
    line = strstr(output, "move ");
    assert_non_null(line);
    assert_int_equal(sscanf(line, "move %u of %u photon paths changed", &changed, &traced), 2);
    assert_int_equal(changed, traced / 4); /* light_b2's own photons: one light of four */
    line = strstr(output, "lamp ");
    assert_non_null(line);
    assert_int_equal(sscanf(line, "lamp %u of %u photon paths changed", &changed, &traced), 2);
    assert_int_equal(changed, traced / 5); /* the added lamp's, as many as its twin light_b2 has */
    static const char *const files[] = {"lightmap.exr", "lightmap_recoloured.exr", "lightmap_moved.exr",
                                        "lightmap_lamp.exr", "view.png", "level.gltf", "level.bin",
                                        "level_lightmap.exr"};
    for (int k = 0; k < 8; k++) {
        snprintf(cmd, sizeof cmd, "%s/%s", dir, files[k]);
        assert_true(file_size(cmd) > 1000);
    }
    const char *why = NULL, *modules = lmt_node_modules("gltf-validator", &why);
    snprintf(cmd, sizeof cmd, "%s/level.gltf", dir); /* exported after a recolour, a move and an added lamp */
    if (modules)
        lmt_gltf_validate(modules, cmd);
    else
        print_message("the export is not validated: %s\n", why);
    snprintf(cmd, sizeof cmd, "%s scenes/two_rooms.glb %s --material nothing --texels 500", prog, dir);
    assert_int_equal(sh(cmd), 1);
    assert_non_null(strstr(output, "no material 'nothing'"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_runtime_loop), cmocka_unit_test(test_editor_session)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
