/* The lmgi command: exit codes and messages for bad input, and the pictures `lmgi charts` writes. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "../src/core/image.h"
#include "../src/core/memory.h"
#include "../src/core/palette.h"
#include "support.h"

static char output[65536];

/* Runs `lmgi ARGS` (stdout and stderr together into `output`) and returns its exit status. */
static int run(const char *args) { return lmt_lmgi("", args, output, sizeof output); }

/* `lmgi info scenes/cornell.glb OPTION VALUE` refused (exit 2) for each of the n values, saying `says`. */
static void refused(const char *option, const char *const *values, int n, const char *says)
{
    for (int k = 0; k < n; k++) {
        char args[256];
        snprintf(args, sizeof args, "info scenes/cornell.glb %s %s", option, values[k]);
        assert_int_equal(run(args), 2);
        assert_non_null(strstr(output, says));
    }
}

/* A run that must succeed: its output is shown when it does not. */
static int run_ok(const char *args)
{
    int rc = run(args);
    if (rc != 0)
        print_message("lmgi %s: exit %d\n%s\n", args, rc, output);
    return rc;
}

/* The option names of a help text: every line that starts with "  -" names one ("  -o, --out DIR": --out);
 * with `commands`, the bracketed list under it (none: every command) as a string. */
static int help_options(const char *text, char names[][48], char commands[][160], int max)
{
    int n = 0;
    for (const char *p = text; p && *p && n < max; p = strchr(p, '\n'), p = p ? p + 1 : NULL) {
        if (strncmp(p, "  -", 3))
            continue;
        const char *name = strstr(p, "--");
        const char *eol = strchr(p, '\n');
        if (!name || (eol && name > eol))
            continue;
        size_t len = strcspn(name, " \n");
        snprintf(names[n], 48, "%.*s", (int)len, name);
        commands[n][0] = '\0';
        /* the continuation lines up to the next option: the last one in brackets lists the commands */
        for (const char *q = eol ? eol + 1 : NULL; q && *q && !strncmp(q, "    ", 4); q = strchr(q, '\n'), q = q ? q + 1 : NULL) {
            const char *open = strchr(q, '['), *end = strchr(q, '\n');
            if (open && (!end || open < end) && open - q == 20)
                snprintf(commands[n], 160, "%.*s", (int)strcspn(open + 1, "]"), open + 1);
        }
        n++;
    }
    return n;
}

/* `lmgi help COMMAND` and `lmgi COMMAND --help` print the same text, made from the parser's own table:
 * every option the general help gives a command is in that command's help and is accepted by it, and
 * every other is refused by it naming the commands that take it; a misspelt option gets the nearest. */
static void test_command_help(void **state)
{
    (void)state;
    static const char *const cmds[] = {"info",  "charts", "run",   "bake",    "merge",
                                       "check", "reference", "bench", "tradeoff", "view"};
    const int ncmds = (int)(sizeof cmds / sizeof *cmds);
    static char all[1 << 16], mine[1 << 16], names[128][48], lists[128][160], my_names[128][48], unused[128][160];
    assert_int_equal(run("help"), 0);
    snprintf(all, sizeof all, "%s", output);
    int n = help_options(all, names, lists, 128);
    assert_true(n > 60);
    int taken_total = 0;
    for (int c = 0; c < ncmds; c++) {
        char args[256];
        snprintf(args, sizeof args, "%s --help", cmds[c]);
        assert_int_equal(run(args), 0);
        snprintf(mine, sizeof mine, "%s", output);
        assert_non_null(strstr(mine, "usage: lmgi "));
        snprintf(args, sizeof args, "help %s", cmds[c]);
        assert_int_equal(run(args), 0);
        assert_string_equal(output, mine);
        int m = help_options(mine, my_names, unused, 128);
        for (int k = 0; k < n; k++) {
            /* the command's word in the list, whole ("check" is not in "checkpoint") */
            int takes = !lists[k][0];
            for (const char *q = lists[k]; !takes && (q = strstr(q, cmds[c])) != NULL; q++)
                takes = (q == lists[k] || q[-1] == ' ') && (q[strlen(cmds[c])] == ',' || q[strlen(cmds[c])] == ' ' ||
                                                            q[strlen(cmds[c])] == '\0');
            int listed = 0;
            for (int j = 0; j < m; j++)
                listed |= !strcmp(my_names[j], names[k]);
            if (listed != takes)
                fail_msg("%s: %s is %s its help, and the general help says it %s it", cmds[c], names[k],
                         listed ? "in" : "not in", takes ? "takes" : "does not take");
            /* a scene that is not there: an option taken ends at its load, not in a whole default bench
             * (bench --quiet alone times every scene: 150 s of this test before) */
            snprintf(args, sizeof args, "%s no-such-scene.glb %.47s", cmds[c], names[k]);
            run(args);
            int refused = strstr(output, "is not an option of") != NULL || strstr(output, "unknown option") != NULL;
            if (refused == takes)
                fail_msg("lmgi %s: %s (help says it %s it)", args, output, takes ? "takes" : "does not take");
            taken_total += takes;
        }
    }
    print_message("%d options, %d of them taken by each command on average\n", n, taken_total / ncmds);
    assert_int_equal(run("info scenes/cornell.glb --hemicube 8"), 2);
    assert_non_null(
        strstr(output, "'--hemicube' is not an option of 'info' (it is one of run, bake, merge, check, bench and view"));
    assert_int_equal(run("run scenes/cornell.glb --texel-sise 0.1 --out x"), 2);
    assert_non_null(strstr(output, "did you mean '--texel-size'?"));
    assert_int_equal(run("bake scenes/cornell.glb --hemicube-sample 4 --out x"), 2);
    assert_non_null(strstr(output, "did you mean '--hemicube-samples'?"));
    assert_int_equal(run("info scenes/cornell.glb --zzzzzzzz"), 2);
    assert_null(strstr(output, "did you mean"));
    assert_int_equal(run("help frobnicate"), 2);
    assert_non_null(strstr(output, "no command 'frobnicate'"));
}

static void test_usage_errors(void **state)
{
    (void)state;
    assert_int_equal(run(""), 2);
    assert_int_equal(run("frobnicate scene.glb"), 2);
    assert_non_null(strstr(output, "unknown command 'frobnicate'"));
    assert_int_equal(run("info"), 2);
    assert_int_equal(run("info a.glb --texel-size abc"), 2);
    assert_non_null(strstr(output, "--texel-size abc"));
    assert_int_equal(run("info a.glb --gutter -1"), 2);
    assert_int_equal(run("info a.glb --wat"), 2);
    assert_non_null(strstr(output, "'--wat'"));
    assert_int_equal(run("charts scenes/cornell.glb"), 2);
    assert_non_null(strstr(output, "--out"));
    assert_int_equal(run("help"), 0);
    assert_non_null(strstr(output, "charts SCENE --out DIR"));
    /* a value is never taken from the next option, and is checked in full */
    assert_int_equal(run("run scenes/cornell.glb --out -q"), 2);
    assert_non_null(strstr(output, "--out (missing)"));
    assert_int_equal(run("run scenes/cornell.glb --size 64x64abc --out x"), 2);
    assert_non_null(strstr(output, "--size 64x64abc"));
    assert_int_equal(run("run scenes/cornell.glb --groups 7 --out x"), 2);
    assert_non_null(strstr(output, "--groups 7"));
    assert_int_equal(run("run scenes/cornell.glb --groups 12 --out"), 2); /* 2^2 3 taken; then --out's value missing */
    assert_non_null(strstr(output, "--out (missing)"));
    assert_null(strstr(output, "--groups"));
    /* --sky: one radiance or three, finite and >= 0; info says what it got */
    static const char *const bad_sky[] = {"nan", "-1", "1,2", "1,2,3,4", "1,,2", "1e30", "inf", "0.5,x,1"};
    refused("--sky", bad_sky, 8, "--sky");
    assert_int_equal(run("info scenes/cornell.glb --sky 0.5,0.25,1"), 0);
    assert_non_null(strstr(output, "sky         uniform radiance (0.5 0.25 1)"));
    assert_int_equal(run("info scenes/cornell.glb --sky 2"), 0);
    assert_non_null(strstr(output, "sky         uniform radiance (2 2 2)"));
    assert_int_equal(run("run scenes/cornell.glb --aim-direct exact --out x"), 2);
    assert_non_null(strstr(output, "--aim-direct exact"));
    assert_non_null(strstr(output, "emitters, photons or all"));
    static const char *const bad_bend[] = {"0", "-5", "181", "15x", "on"};
    refused("--bend", bad_bend, 5, "expected degrees in (0, 180], or off");
    assert_int_equal(run("info scenes/cornell.glb --bend off"), 0);
    assert_int_equal(run("info scenes/cornell.glb --bend 30"), 0);
    /* a negative number is a number: the message says which it must be, not "a finite number" */
    assert_int_equal(run("run scenes/cornell.glb --reflection-lod -1 --out x"), 2);
    assert_non_null(strstr(output, "--reflection-lod -1: expected a number of at least 0"));
    assert_int_equal(run("run scenes/cornell.glb --caustic-thin -0.5 --out x"), 2);
    assert_non_null(strstr(output, "--caustic-thin -0.5: expected a number of at least 0"));
    assert_int_equal(run("run scenes/cornell.glb --reflection-lod 0.5 --out x"), 2);
    assert_non_null(strstr(output, "--reflection-lod 0.5: expected a number in [1e-06, 0.1]"));
    assert_int_equal(run("run scenes/cornell.glb --aim-occluders maybe --out x"), 2);
    assert_non_null(strstr(output, "--aim-occluders maybe: expected on or off"));
    /* the indirect paths and their knobs (docs/tiled.md) */
    assert_int_equal(run("run scenes/cornell.glb --indirect photons --out x"), 2);
    assert_non_null(strstr(output, "--indirect photons"));
    assert_non_null(strstr(output, "tiled"));
    assert_int_equal(run("run scenes/cornell.glb --photon-tile 12 --out x"), 2);
    assert_non_null(strstr(output, "--photon-tile 12"));
    assert_int_equal(run("run scenes/cornell.glb --photon-stochastic 5 --out x"), 2);
    assert_non_null(strstr(output, "--photon-stochastic 5"));
    assert_int_equal(run("run scenes/cornell.glb --photon-chunk 32 --out x"), 2);
    assert_non_null(strstr(output, "--photon-chunk 32"));
    assert_int_equal(run("run scenes/cornell.glb --photon-radius 0 --out x"), 2);
    assert_non_null(strstr(output, "--photon-radius 0"));
    assert_int_equal(run("run scenes/cornell.glb --photon-radius nan --out x"), 2);
    /* a scene named to bench that is not there is an error before anything is timed (only the default
     * list's absent shared scenes are skipped) */
    assert_int_equal(run("bench scenes/cornell.glb no-such-scene.glb"), 1);
    assert_non_null(strstr(output, "no-such-scene.glb: cannot open file"));
    assert_null(strstr(output, "medians of"));
}

/* `lmgi bench --soak N`: N updates of the looped animation, memory and time per block, no non-finite
 * value; a bad count is a usage error. `lmgi info` says how long the animation is. */
static void test_soak(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(scene, lmt_project_scene("cornell.glb"));
    char args[2048];
    snprintf(args, sizeof args, "info %s", scene);
    assert_int_equal(run(args), 0);
    assert_non_null(strstr(output, "animations 3 (8 s)"));
    snprintf(args, sizeof args, "bench --soak 40 %s --size 16x16 --texels 800 --photons 4000 --caustic-photons 1024",
             scene);
    assert_int_equal(run(args), 0);
    assert_non_null(strstr(output, "40 updates at 16 x 16, the animation (8 s) looped"));
    assert_non_null(strstr(output, "non-finite frame values: 0"));
    assert_non_null(strstr(output, "resident MB"));
    assert_int_equal(run("bench --soak 0"), 2);
    assert_non_null(strstr(output, "--soak 0"));
    LMT_REQUIRE_SCENE(rooms, lmt_project_scene("two_rooms.glb"));
    snprintf(args, sizeof args, "bench --soak 30 %s --random-edits 6 --budget 50 --size 16x16 --texels 800 "
             "--shadow-maps-per-frame 2", rooms);
    assert_int_equal(run(args), 0);
    assert_non_null(strstr(output, "30 updates at 16 x 16, each after a random edit (seed 0; up to 6 lights), "
                                   "budget 50 ms"));
    assert_non_null(strstr(output, "slowest update after the first:"));
    assert_non_null(strstr(output, "x the budget;"));
    assert_non_null(strstr(output, "edits: "));
    assert_non_null(strstr(output, "non-finite frame values: 0"));
    assert_int_equal(run("bench --soak 10 --random-edits 0"), 2);
    assert_non_null(strstr(output, "--random-edits"));
}

/* `lmgi run --indirect tiled` writes its frames, and frames.csv counts the gathers: one at the first frame,
 * then one a frame while the animated cube moves. */
static void test_tiled_run(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(scene, lmt_project_scene("cornell.glb"));
    char args[2048], path[2048];
    const char *dir = lmt_tmpdir();
    snprintf(args, sizeof args, "run %s --indirect tiled --photon-stochastic 2 --frames 3 --size 48x48 "
             "--texels 800 --photons 6000 --out %s/tiled", scene, dir);
    assert_int_equal(run(args), 0);
    assert_non_null(strstr(output, "tiled photon gather per pixel: radius"));
    snprintf(path, sizeof path, "%s/tiled/frames.csv", dir);
    FILE *f = fopen(path, "r");
    assert_non_null(f);
    char line[8192];
    assert_non_null(fgets(line, sizeof line, f));
    int col = 0, at = -1;
    for (char *tok = strtok(line, ",\n"); tok; tok = strtok(NULL, ",\n"), col++)
        if (!strcmp(tok, "photon_gathers"))
            at = col;
    assert_true(at >= 0);
    int rows = 0, gathers = 0;
    while (fgets(line, sizeof line, f)) {
        col = 0;
        for (char *tok = strtok(line, ",\n"); tok; tok = strtok(NULL, ",\n"), col++)
            if (col == at)
                gathers += atoi(tok);
        rows++;
    }
    fclose(f);
    assert_int_equal(rows, 3);
    assert_int_equal(gathers, 3);
}

static void test_bad_scene_files(void **state)
{
    (void)state;
    assert_int_equal(run("info /nonexistent/scene.glb"), 1);
    assert_non_null(strstr(output, "/nonexistent/scene.glb"));
    char path[512];
    snprintf(path, sizeof path, "%s/bad.gltf", lmt_tmpdir());
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs("{\"asset\": {\"version\": \"2.0\"}, \"nodes\": [", f);
    fclose(f);
    char args[1024];
    snprintf(args, sizeof args, "info %s", path);
    assert_int_equal(run(args), 1);
    assert_non_null(strstr(output, "bad.gltf"));

    /* A file that is not glTF says what it is and what lmgi reads (a JSON parser's complaint about its
     * first byte before) */
    static const struct { const char *name, *bytes, *said; } other[] = {
        {"picture.gltf", "\x89PNG\r\n\x1a\n\0\0\0\rIHDR", "this is a PNG image, not a glTF scene"},
        {"model.obj", "# exported\nv 0 0 0\nv 1 0 0\n", "this is a text file, not a glTF scene"},
        {"mesh.obj", "v 0 0 0\nv 1 0 0\nf 1 2 1\n", "perhaps a Wavefront OBJ"},
        {"scene.blend", "BLENDER-v300", "this is a Blender file"}};
    for (int i = 0; i < 4; i++) {
        snprintf(path, sizeof path, "%s/%s", lmt_tmpdir(), other[i].name);
        lmt_write_file(path, other[i].bytes, strlen(other[i].bytes) + (i == 0 ? 8 : 0));
        snprintf(args, sizeof args, "info %s", path);
        assert_int_equal(run(args), 1);
        assert_non_null(strstr(output, other[i].said));
        assert_non_null(strstr(output, "lmgi reads glTF 2.0"));
    }

    /* A scene nothing lights: run and bake say so; check refuses, black against black reads 1.000 */
    static lmt_mesh floor_mesh;
    memset(&floor_mesh, 0, sizeof floor_mesh);
    lmt_mesh_quad(&floor_mesh, (float[3]){-1, 0, 1}, (float[3]){2, 0, 0}, (float[3]){0, 0, -2});
    const char *unlit = lmt_write_scene("unlit.gltf", &floor_mesh, 1, "[{\"mesh\": 0}]", "[" LMT_DIFFUSE(0.5) "]");
    snprintf(args, sizeof args, "bake %s --texels 500 --out %s/unlit -q", unlit, lmt_tmpdir());
    assert_int_equal(run(args), 0);
    snprintf(args, sizeof args, "bake %s --texels 500 --out %s/unlit", unlit, lmt_tmpdir());
    assert_int_equal(run(args), 0);
    assert_non_null(strstr(output, "the scene has no light"));
    assert_non_null(strstr(output, "nothing is gathered"));
    snprintf(args, sizeof args, "check %s --texels 500 --size 16x16", unlit);
    assert_int_equal(run(args), 1);
    assert_non_null(strstr(output, "nothing to check: the scene has no light"));

    /* An empty scene: info says so (its bounds printed as +-3.4e38 before); run has nothing to light. */
    snprintf(path, sizeof path, "%s/empty.gltf", lmt_tmpdir());
    f = fopen(path, "w");
    assert_non_null(f);
    fputs("{\"asset\": {\"version\": \"2.0\"}}", f);
    fclose(f);
    snprintf(args, sizeof args, "info %s", path);
    assert_int_equal(run(args), 0);
    assert_non_null(strstr(output, "the scene is empty"));
    snprintf(args, sizeof args, "run %s --out %s/out", path, lmt_tmpdir());
    assert_int_equal(run(args), 1);
    assert_non_null(strstr(output, "nothing to light"));

    /* A material whose texture is missing: info says it uses its factor alone. */
    static lmt_mesh m;
    memset(&m, 0, sizeof m);
    lmt_mesh_quad(&m, (float[3]){0, 0, 0}, (float[3]){1, 0, 0}, (float[3]){0, 0, -1});
    const char *textured = lmt_write_scene("textured.gltf", &m, 1, "[{\"mesh\": 0}]",
                                           "[{\"name\": \"poster\", \"pbrMetallicRoughness\": "
                                           "{\"baseColorTexture\": {\"index\": 0}}}], \"textures\": [{\"source\": 0}], "
                                           "\"images\": [{\"uri\": \"gone.png\"}]");
    snprintf(args, sizeof args, "info %s", textured);
    assert_int_equal(run(args), 0);
    assert_non_null(strstr(output, "gone.png"));
    assert_non_null(strstr(output, "texture is missing or undecodable"));

    /* A texel size that asks for more memory than the machine has is refused at once (--texel-size 1e-9
     * built an 8040 x 5604 atlas in a minute and 4.9 GB): 32136 x 22400 texels, about 74 GB. */
    if (lm_memory_physical() < 60e9) {
        assert_int_equal(run("info scenes/cornell.glb --texel-size 1e-9 --max-atlas 32768"), 1);
        assert_non_null(strstr(output, "would need about"));
        assert_non_null(strstr(output, "--texel-size"));
    }
}

/* Degenerate triangles are a warning by default (the scene still loads) and an error with --strict. */
static void test_strict_refuses_degenerate_triangles(void **state)
{
    (void)state;
    static lmt_mesh m;
    memset(&m, 0, sizeof m);
    float c[3] = {0, 0, 0}, u[3] = {1, 0, 0}, v[3] = {0, 0, -1};
    lmt_mesh_quad(&m, c, u, v);
    /* A zero-area triangle: its third corner lies on the edge between the first two. */
    float line[3][3] = {{0, 0, 0}, {1, 0, 0}, {0.5f, 0, 0}};
    for (int k = 0; k < 3; k++) {
        memcpy(m.pos + 3 * m.vertex_count, line[k], sizeof line[k]);
        m.idx[m.index_count++] = (uint16_t)m.vertex_count++;
    }
    char path[512], args[1024];
    snprintf(path, sizeof path, "%s/degenerate.gltf", lmt_tmpdir());
    assert_int_equal(lmt_write_gltf(path, &m, 1, "[{\"name\": \"plate\", \"mesh\": 0}]", NULL, 0, NULL), 0);
    snprintf(args, sizeof args, "info %s", path);
    assert_int_equal(run(args), 0);
    assert_non_null(strstr(output, "warning"));
    assert_non_null(strstr(output, "1 degenerate triangles dropped"));
    snprintf(args, sizeof args, "info --strict %s", path);
    assert_int_equal(run(args), 1);
    assert_non_null(strstr(output, "degenerate.gltf"));
    assert_non_null(strstr(output, "degenerate"));
}

static void test_info_on_generated_cornell(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(path, lmt_project_scene("cornell.glb"));
    char args[1024];
    snprintf(args, sizeof args, "info %s", path);
    assert_int_equal(run(args), 0);
    assert_non_null(strstr(output, "surfaces    16 "));
    assert_non_null(strstr(output, "caustics: on — 1 mirror and 1 glass materials (the first on node 'mirror_sphere')"));
    assert_non_null(strstr(output, "1 point, 0 spot, 0 directional"));
}

/* Every pixel is black (background), grey (specular) or the colour of one surface id < count. */
static int surface_of_pixel(const uint8_t *px, int count)
{
    for (int id = -1; id < count; id++) {
        uint8_t rgb[3];
        lm_id_color(id, rgb);
        if (!memcmp(rgb, px, 3))
            return id;
    }
    return px[0] == 0 && px[1] == 0 && px[2] == 0 ? -2 : -3;
}

static void test_charts_pictures(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(path, lmt_project_scene("cornell.glb"));
    const char *dir = lmt_tmpdir();
    char args[1024], file[1024];
    snprintf(args, sizeof args, "charts %s --out %s/out --size 320x240", path, dir);
    assert_int_equal(run(args), 0);

    snprintf(file, sizeof file, "%s/out/surfaces.png", dir);
    int w, h;
    uint8_t *img = NULL;
    lm_error err;
    assert_int_equal(lm_read_image8(file, &w, &h, &img, &err), LM_OK);
    assert_int_equal(w, 320);
    assert_int_equal(h, 240);
    int seen[16] = {0}, grey = 0, distinct = 0;
    for (int i = 0; i < w * h; i++) {
        int id = surface_of_pixel(img + 4 * i, 16);
        assert_true(id >= -2); /* flat colours only: no blending, no stray values */
        if (id >= 0 && !seen[id]++)
            distinct++;
        grey += id == -1;
    }
    free(img);
    /* From the file's camera: the five walls, faces of the block and cube, and the grey mirror sphere. */
    assert_true(distinct >= 9);
    assert_true(grey > 100);

    snprintf(file, sizeof file, "%s/out/atlas.png", dir);
    assert_int_equal(lm_read_image8(file, &w, &h, &img, &err), LM_OK);
    assert_true(w >= 64 && h >= 64);
    int black = 0;
    for (int i = 0; i < w * h; i++)
        black += img[4 * i] == 0 && img[4 * i + 1] == 0 && img[4 * i + 2] == 0;
    free(img);
    assert_true(black > 0 && black < w * h / 2); /* gutters and free space, but mostly charts */

    snprintf(args, sizeof args, "charts %s --out /proc/lmgi-not-writable", path);
    assert_int_equal(run(args), 1);
    assert_non_null(strstr(output, "/proc/lmgi-not-writable"));
}

/* lmgi bake writes the lightmap, its preview and the AIM; Ctrl-C stops it soon, writing nothing. */
/* LMGI_PROGRESS_SECONDS=0: a line for every step of the gather, each with its stage, share and time
 * left; -q: none. */
static void test_progress_lines(void **state)
{
    (void)state;
    char args[2048];
    snprintf(args, sizeof args, "bake scenes/cornell.glb --texels 2000 --photons 4000 --out %s/bake", lmt_tmpdir());
    setenv("LMGI_PROGRESS_SECONDS", "0", 1);
    assert_int_equal(run(args), 0);
    int lines = 0;
    for (const char *p = output; (p = strstr(p, "bake: gather ")); p++)
        lines += strstr(p, "s left)\n") != NULL;
    print_message("%d gather progress lines\n", lines);
    assert_true(lines >= 3);
    snprintf(args, sizeof args, "bake scenes/cornell.glb --texels 2000 --photons 4000 -q --out %s/quiet", lmt_tmpdir());
    assert_int_equal(run(args), 0);
    assert_null(strstr(output, "bake: "));
    unsetenv("LMGI_PROGRESS_SECONDS");
}

/* 1 if the two files hold the same bytes. */
static int same_bytes(const char *a, const char *b)
{
    size_t na = 0, nb = 0;
    unsigned char *x = lmt_read_file(a, &na, 0), *y = lmt_read_file(b, &nb, 0);
    int same = na == nb && memcmp(x, y, na) == 0;
    free(x);
    free(y);
    return same;
}

/* A bake killed (SIGKILL: nothing of its own runs) keeps what its gather finished in DIR/bake.checkpoint;
 * --resume gathers only the rest and writes the same bytes as a bake that never stopped. A resume of
 * another scene's checkpoint is refused, naming it, with nothing overwritten, and a bake that fails
 * leaves the last good lightmaps in place. */
static void test_bake_killed_and_resumed(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(scene, lmt_project_scene("two_rooms.glb"));
    char dir[256], args[2048], a_path[600], b_path[600], ck[800];
    snprintf(dir, sizeof dir, "%s", lmt_tmpdir());
    snprintf(args, sizeof args, "bake %s --texels 20000 --out %s/whole -q", scene, dir);
    assert_int_equal(run(args), 0);
    snprintf(ck, sizeof ck, "%s/part/bake.checkpoint", dir);
    const char *build = getenv("LMGI_BUILD");
    char exe[512];
    snprintf(exe, sizeof exe, "%s/lmgi", build ? build : "build");
    char out_dir[600];
    snprintf(out_dir, sizeof out_dir, "%s/part", dir);
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        freopen("/dev/null", "w", stderr);
        execl(exe, exe, "bake", scene, "--texels", "20000", "--checkpoint-seconds", "0.05", "--out", out_dir,
              (char *)NULL);
        _exit(127);
    }
    int waited = 0;
    while (access(ck, R_OK) != 0 && waited < 60000) { /* the first checkpoint, then a little more */
        usleep(10000);
        waited += 10;
    }
    usleep(300000);
    kill(pid, SIGKILL);
    int status = 0;
    waitpid(pid, &status, 0);
    assert_true(WIFSIGNALED(status)); /* killed before it finished */
    assert_int_equal(access(ck, R_OK), 0);
    char saved[700];
    snprintf(saved, sizeof saved, "%s/saved.checkpoint", dir);
    assert_int_equal(link(ck, saved), 0);

    /* another scene's resume: refused, naming the checkpoint, which stays for the right one */
    snprintf(args, sizeof args, "bake scenes/cornell.glb --texels 2000 --out %s/part --resume", dir);
    assert_int_equal(run(args), 1);
    assert_non_null(strstr(output, "a checkpoint of another scene or other settings"));
    assert_non_null(strstr(output, "part/bake.checkpoint"));
    assert_true(same_bytes(saved, ck));

    snprintf(args, sizeof args, "bake %s --texels 20000 --out %s/part --resume -v", scene, dir);
    assert_int_equal(run(args), 0);
    const char *at = strstr(output, "resuming the gather at texel ");
    assert_non_null(at);
    unsigned from = 0, of = 0;
    assert_int_equal(sscanf(at, "resuming the gather at texel %u of %u", &from, &of), 2);
    print_message("killed and resumed at texel %u of %u\n", from, of);
    assert_true(from > 0 && from < of);
    snprintf(a_path, sizeof a_path, "%s/whole/lightmap.exr", dir);
    snprintf(b_path, sizeof b_path, "%s/part/lightmap.exr", dir);
    assert_true(same_bytes(a_path, b_path));
    assert_int_equal(access(ck, F_OK), -1); /* done with */

    /* a checkpoint lmgi did not put there is not lmgi's to read, rewrite or remove */
    char other[400];
    snprintf(other, sizeof other, "%s/other", dir);
    assert_int_equal(mkdir(other, 0755), 0);
    snprintf(ck, sizeof ck, "%s/bake.checkpoint", other);
    assert_int_equal(link(saved, ck), 0);
    snprintf(args, sizeof args, "bake %s --texels 20000 --out %s --resume --force", scene, other);
    assert_int_equal(run(args), 1);
    assert_non_null(strstr(output, "other/bake.checkpoint: lmgi did not write this file"));
    assert_true(same_bytes(saved, ck));

    /* a bake that fails keeps the last good lightmaps */
    snprintf(args, sizeof args, "bake %s/missing.glb --out %s/whole", dir, dir);
    assert_int_equal(run(args), 1);
    snprintf(b_path, sizeof b_path, "%s/part/lightmap.exr", dir);
    assert_true(same_bytes(a_path, b_path));
}

/* lmgi bake makes one bounce pass unless told otherwise (docs/gather.md, "Bounce passes"): the sunlit room
 * (its sky makes the gather rays) baked at the defaults is the same bytes as with --bounce-passes 1, not as
 * with 0; baked in two shards (which make none) and merged, the same bytes as one bake. The Cornell box's
 * hemicube gather makes none, and says so without a warning; a level of more than 8 lamps makes none. */
static void test_bake_makes_a_bounce_pass(void **state)
{
    (void)state;
    char dir[256], args[4096], a_path[600], b_path[600];
    snprintf(dir, sizeof dir, "%s", lmt_tmpdir());
    static const char *const runs[3][2] = {{"whole", ""}, {"one", " --bounce-passes 1"}, {"none", " --bounce-passes 0"}};
    for (int r = 0; r < 3; r++) {
        snprintf(args, sizeof args, "bake scenes/sunlit_room.glb --texels 2000%s --out %s/%s -q", runs[r][1], dir,
                 runs[r][0]);
        if (run(args) != 0)
            fail_msg("%s: %s", args, output);
    }
    for (int k = 1; k <= 2; k++) {
        snprintf(args, sizeof args, "bake scenes/sunlit_room.glb --texels 2000 --shard %d/2 --out %s/s%d", k, dir, k);
        if (run(args) != 0)
            fail_msg("%s: %s", args, output);
    }
    snprintf(args, sizeof args, "merge scenes/sunlit_room.glb %s/s1 %s/s2 --texels 2000 --out %s/merged -q", dir, dir,
             dir);
    if (run(args) != 0)
        fail_msg("%s: %s", args, output);
    static const char *const same_as[3] = {"one", "merged", "none"};
    for (int k = 0; k < 3; k++) {
        snprintf(a_path, sizeof a_path, "%s/whole/lightmap.exr", dir);
        snprintf(b_path, sizeof b_path, "%s/%s/lightmap.exr", dir, same_as[k]);
        assert_int_equal(same_bytes(a_path, b_path), k < 2);
    }
    snprintf(args, sizeof args, "bake scenes/cornell.glb --texels 2000 --photons 4000 --out %s/box", dir);
    assert_int_equal(run(args), 0);
    assert_null(strstr(output, "bounce pass"));
    assert_null(strstr(output, "warning"));
    snprintf(args, sizeof args, "bake scenes/cornell.glb --texels 2000 --photons 4000 --out %s/box_v -v", dir);
    assert_int_equal(run(args), 0);
    assert_non_null(strstr(output, "info: scenes/cornell.glb: no bounce pass: they need the rays gather"));
    /* a floor under 8 lamps gets its pass, under 9 none (each lamp costs a shadow ray at each of its hits) */
    static lmt_mesh floor_mesh;
    memset(&floor_mesh, 0, sizeof floor_mesh);
    lmt_mesh_quad(&floor_mesh, (float[3]){-5, 0, 5}, (float[3]){10, 0, 0}, (float[3]){0, 0, -10});
    for (int lamps = 8; lamps <= 9; lamps++) {
        char nodes[2048] = "[{\"mesh\": 0}", lights[2048] = "";
        for (int k = 0; k < lamps; k++) {
            size_t n = strlen(nodes), l = strlen(lights);
            snprintf(nodes + n, sizeof nodes - n, ", {\"translation\": [%d, 1, 0], \"extensions\": "
                     "{\"KHR_lights_punctual\": {\"light\": %d}}}", k - 4, k);
            snprintf(lights + l, sizeof lights - l, "%s{\"type\": \"point\", \"intensity\": 5}", k ? ", " : "");
        }
        strcat(nodes, "]");
        char materials[4096], name[64];
        snprintf(materials, sizeof materials, "[" LMT_DIFFUSE(0.5) "], \"extensionsUsed\": [\"KHR_lights_punctual\"], "
                 "\"extensions\": {\"KHR_lights_punctual\": {\"lights\": [%s]}}", lights);
        snprintf(name, sizeof name, "lamps%d.gltf", lamps);
        const char *path = lmt_write_scene(name, &floor_mesh, 1, nodes, materials);
        snprintf(args, sizeof args, "bake %s --texels 500 --gather-scheme rays --out %s/lamps%d -v", path, dir, lamps);
        if (run(args) != 0)
            fail_msg("%s: %s", args, output);
        assert_int_equal(strstr(output, "bounce pass 1 of 1") != NULL, lamps <= 8);
    }
}

/* A bake in shards (docs/levels.md, "A bake in shards"): the Cornell box at 8,000 texels (four gather
 * passes) baked as 3 shards and as 5 (one share empty), each put together by merge: the same bytes as
 * one bake, lightmap and AIM. A missing shard, the same shard twice, a part of other settings or of a
 * bake in another number of shards are refused, naming it, and nothing is written. */
static void test_bake_in_shards(void **state)
{
    (void)state;
    char dir[256], args[4096], a_path[600], b_path[600];
    snprintf(dir, sizeof dir, "%s", lmt_tmpdir());
    snprintf(args, sizeof args, "bake scenes/cornell.glb --texels 8000 --out %s/whole -q", dir);
    assert_int_equal(run(args), 0);
    static const int counts[2] = {3, 5};
    for (int c = 0; c < 2; c++) {
        int n = counts[c];
        char parts[2048] = "";
        for (int k = 1; k <= n; k++) {
            snprintf(args, sizeof args, "bake scenes/cornell.glb --texels 8000 --shard %d/%d --out %s/s%d_%d", k, n,
                     dir, n, k);
            assert_int_equal(run(args), 0);
            assert_non_null(strstr(output, "part.checkpoint"));
            size_t used = strlen(parts);
            snprintf(parts + used, sizeof parts - used, " %s/s%d_%d", dir, n, k);
        }
        snprintf(args, sizeof args, "merge scenes/cornell.glb%s --texels 8000 --out %s/merged%d", parts, dir, n);
        if (run(args) != 0)
            fail_msg("%s: %s", args, output);
        static const char *const files[2] = {"lightmap.exr", "aim.exr"};
        for (int f = 0; f < 2; f++) {
            snprintf(a_path, sizeof a_path, "%s/whole/%s", dir, files[f]);
            snprintf(b_path, sizeof b_path, "%s/merged%d/%s", dir, n, files[f]);
            assert_true(same_bytes(a_path, b_path));
        }
        print_message("%d shards merged: lightmap.exr and aim.exr the same bytes as one bake\n", n);
    }
    static const struct {
        const char *parts, *options, *says;
    } bad[] = {
        {"s3_1 s3_3", "", "shard 2 of 3 is missing"},
        {"s3_1 s3_2 s3_2 s3_3", "", "are both shard 2 of 3"},
        {"s3_1 s3_2 s3_3", " --photons 5000", "give merge the scene and the options its shards were baked with"},
        {"s3_1 s5_2", "", "a part of a bake in 5 shards"},
        {"whole", "", "part.checkpoint: no checkpoint"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        char list[512] = "", *w, copy[256];
        snprintf(copy, sizeof copy, "%s", bad[i].parts);
        char *save = NULL;
        for (w = strtok_r(copy, " ", &save); w; w = strtok_r(NULL, " ", &save)) {
            size_t used = strlen(list);
            snprintf(list + used, sizeof list - used, " %s/%s", dir, w);
        }
        snprintf(args, sizeof args, "merge scenes/cornell.glb%s --texels 8000%s --out %s/refused", list,
                 bad[i].options, dir);
        assert_int_equal(run(args), 1);
        if (!strstr(output, bad[i].says))
            fail_msg("merge of%s: expected \"%s\" in: %s", list, bad[i].says, output);
        snprintf(a_path, sizeof a_path, "%s/refused/lightmap.exr", dir);
        assert_int_equal(access(a_path, F_OK), -1);
    }
    snprintf(args, sizeof args, "bake scenes/cornell.glb --shard 4/3 --out %s/x", dir);
    assert_int_equal(run(args), 2);
    assert_non_null(strstr(output, "1 <= K <= N"));
    snprintf(args, sizeof args, "bake scenes/cornell.glb --shard 1/3 --gltf --out %s/x", dir);
    assert_int_equal(run(args), 2);
    assert_non_null(strstr(output, "give --gltf, --accuracy and --half to lmgi merge"));
}

/* `lmgi merge PARTS --out DIR/refused`, which must say `says` and write nothing: its exit status. */
static int merge_refused(const char *dir, const char *parts, const char *says)
{
    char args[2048], path[600];
    snprintf(args, sizeof args, "merge %s --out %s/refused", parts, dir);
    int rc = run(args);
    if (!strstr(output, says))
        fail_msg("lmgi %s: expected \"%s\" in: %s", args, says, output);
    snprintf(path, sizeof path, "%s/refused/lightmap.exr", dir);
    assert_int_equal(access(path, F_OK), -1);
    return rc;
}

/* lmgi merge PART... --out DIR: the scene and the bake's options come from the parts' part.json (each
 * shard writes its own), to the same bytes as one bake with those options. Refused, naming the part,
 * with nothing written: a part of other options or another scene, a bake option given to the merge, a
 * part without part.json (an older lmgi's: the form with the scene still merges it), a scene that is no
 * longer where the parts say. */
static void test_merge_parts_alone(void **state)
{
    (void)state;
    char dir[256], args[4096], a_path[600], b_path[600], parts[2048];
    snprintf(dir, sizeof dir, "%s", lmt_tmpdir());
    static const char options[] = "--texels 8000 --photons 20000";
    snprintf(args, sizeof args, "bake scenes/cornell.glb %s --out %s/whole -q", options, dir);
    assert_int_equal(run_ok(args), 0);
    for (int k = 1; k <= 3; k++) { /* run-only options among the bake's: part.json leaves them out */
        snprintf(args, sizeof args, "bake -q --texels 8000 --shard %d/3 scenes/cornell.glb --checkpoint-seconds 5 "
                 "--out %s/p%d --photons 20000", k, dir, k);
        assert_int_equal(run_ok(args), 0);
    }
    char scene[4096], json_path[600];
    assert_non_null(realpath("scenes/cornell.glb", scene));
    snprintf(json_path, sizeof json_path, "%s/p2/part.json", dir);
    size_t size = 0;
    char *json = (char *)lmt_read_file(json_path, &size, 1);
    json[size] = '\0';
    print_message("p2/part.json: %s", json);
    assert_non_null(strstr(json, scene));
    assert_non_null(strstr(json, "[\"--texels\", \"8000\", \"--photons\", \"20000\"]"));
    free(json);

    snprintf(parts, sizeof parts, "%s/p1 %s/p2 %s/p3", dir, dir, dir);
    snprintf(args, sizeof args, "merge %s --out %s/merged", parts, dir);
    if (run(args) != 0)
        fail_msg("%s: %s", args, output);
    static const char *const files[2] = {"lightmap.exr", "aim.exr"};
    for (int f = 0; f < 2; f++) {
        snprintf(a_path, sizeof a_path, "%s/whole/%s", dir, files[f]);
        snprintf(b_path, sizeof b_path, "%s/merged/%s", dir, files[f]);
        assert_true(same_bytes(a_path, b_path));
    }
    print_message("merge PART... of 3 shards (%s): the same bytes as one bake\n", options);

    /* a part of other options, and a bake option given to the merge */
    snprintf(args, sizeof args, "bake scenes/cornell.glb --texels 8000 --photons 5000 --shard 2/3 --out %s/other2 -q",
             dir);
    assert_int_equal(run_ok(args), 0);
    snprintf(parts, sizeof parts, "%s/p1 %s/other2 %s/p3", dir, dir, dir);
    snprintf(a_path, sizeof a_path, "%s/other2 was baked with the options '--texels 8000 --photons 5000'", dir);
    assert_int_equal(merge_refused(dir, parts, a_path), 1);
    snprintf(parts, sizeof parts, "%s/p1 %s/p2 %s/p3 --photons 5000", dir, dir, dir);
    assert_int_equal(merge_refused(dir, parts, "'--photons' would change the bake"), 2);

    /* an older lmgi's part: no part.json; given the scene and the options it merges as before */
    snprintf(args, sizeof args, "cp -r %s/p2 %s/old2 && rm %s/old2/part.json", dir, dir, dir);
    assert_int_equal(lmt_run(args, output, sizeof output), 0);
    snprintf(parts, sizeof parts, "%s/p1 %s/old2 %s/p3", dir, dir, dir);
    assert_int_equal(merge_refused(dir, parts, "the part was written by an older lmgi"), 1);
    assert_non_null(strstr(output, "old2: no "));
    snprintf(args, sizeof args, "merge scenes/cornell.glb %s %s --out %s/old -q", parts, options, dir);
    assert_int_equal(run_ok(args), 0);
    snprintf(a_path, sizeof a_path, "%s/whole/lightmap.exr", dir);
    snprintf(b_path, sizeof b_path, "%s/old/lightmap.exr", dir);
    assert_true(same_bytes(a_path, b_path));

    /* a shard of a copy of the scene: another scene for the merge, and refused once the copy is gone */
    snprintf(args, sizeof args, "mkdir %s/moved && cp scenes/cornell.glb %s/moved/", dir, dir);
    assert_int_equal(lmt_run(args, output, sizeof output), 0);
    snprintf(args, sizeof args, "bake %s/moved/cornell.glb %s --shard 1/3 --out %s/g1 -q", dir, options, dir);
    assert_int_equal(run_ok(args), 0);
    snprintf(parts, sizeof parts, "%s/p2 %s/g1", dir, dir);
    snprintf(a_path, sizeof a_path, "%s/g1 was baked from ", dir);
    assert_int_equal(merge_refused(dir, parts, a_path), 1);
    assert_non_null(strstr(output, "moved/cornell.glb"));
    snprintf(a_path, sizeof a_path, "%s/moved/cornell.glb", dir);
    assert_int_equal(unlink(a_path), 0);
    snprintf(parts, sizeof parts, "%s/g1", dir);
    assert_int_equal(merge_refused(dir, parts, "moved/cornell.glb ("), 1);
    assert_non_null(strstr(output, "which is not there"));
    assert_non_null(strstr(output, "lmgi merge SCENE PART... --out DIR --texels 8000 --photons 20000"));
}

/* mpirun's command line for n ranks of build/lmgi-mpi, or NULL (printed why) where there is none. */
static const char *mpi_command(int n)
{
    static char cmd[1024];
    const char *build = getenv("LMGI_BUILD");
    char exe[512];
    snprintf(exe, sizeof exe, "%s/lmgi-mpi", build ? build : "build");
    if (access(exe, X_OK) != 0 || system("command -v mpirun > /dev/null 2>&1") != 0) {
        print_message("skipped: no %s or no mpirun (make test builds it where mpicc is found; Debian: apt-get "
                      "install libopenmpi-dev openmpi-bin)\n", exe);
        return NULL;
    }
    /* Under the sanitizers: OpenMPI never frees what MPI_Init allocates (LeakSanitizer reports it from
     * libmpi and from components it has unloaded, which no suppression can name), so leak detection is
     * off for the ranks; lmgi's side of the MPI bake, the shards and the merge, is leak-checked in
     * test_bake_in_shards. */
    const char *asan = getenv("ASAN_OPTIONS");
    snprintf(cmd, sizeof cmd, "ASAN_OPTIONS=%s%sdetect_leaks=0 mpirun %s--oversubscribe -n %d %s", asan ? asan : "",
             asan && *asan ? ":" : "", geteuid() == 0 ? "--allow-run-as-root " : "", n, exe);
    return cmd;
}

/* mpirun -n 2 lmgi-mpi bake: the same bytes as one process's bake (docs/farm.md). A killed rank ends the
 * job with a non-zero status and nothing in --out. */
static void test_mpi_bake(void **state)
{
    (void)state;
    const char *mpi = mpi_command(2);
    if (!mpi)
        skip();
    char dir[256], cmd[4096], a_path[600], b_path[600];
    snprintf(dir, sizeof dir, "%s", lmt_tmpdir());
    snprintf(cmd, sizeof cmd, "bake scenes/cornell.glb --texels 8000 --out %s/one -q", dir);
    assert_int_equal(run(cmd), 0);
    snprintf(cmd, sizeof cmd, "TMPDIR=%s %s bake scenes/cornell.glb --texels 8000 --out %s/ranks 2>&1", dir, mpi, dir);
    if (lmt_run(cmd, output, sizeof output) != 0)
        fail_msg("%s: %s", cmd, output);
    assert_non_null(strstr(output, "part 2 of 2 in"));
    static const char *const files[2] = {"lightmap.exr", "aim.exr"};
    for (int f = 0; f < 2; f++) {
        snprintf(a_path, sizeof a_path, "%s/one/%s", dir, files[f]);
        snprintf(b_path, sizeof b_path, "%s/ranks/%s", dir, files[f]);
        assert_true(same_bytes(a_path, b_path));
    }
    print_message("2 MPI ranks: lightmap.exr and aim.exr the same bytes as one process's bake\n");

    /* a rank that fails (rank 1 is given a scene that is not there: MPMD) ends the job, naming itself */
    const char *exe = strstr(mpi, " -n 2 ") + 6;
    snprintf(cmd, sizeof cmd, "TMPDIR=%s %.*s -n 1 %s bake scenes/cornell.glb --texels 8000 --out %s/failed : -n 1 %s "
             "bake scenes/no_such.glb --texels 8000 --out %s/failed 2>&1", dir, (int)(exe - 6 - mpi), mpi, exe, dir,
             exe, dir);
    assert_int_not_equal(lmt_run(cmd, output, sizeof output), 0);
    if (!strstr(output, "rank 1 of 2 failed"))
        fail_msg("%s: %s", cmd, output);
    snprintf(a_path, sizeof a_path, "%s/failed", dir);
    assert_int_equal(access(a_path, F_OK), -1);

    /* a rank killed while the ranks gather (rank 0's progress shows the gather under way) */
    snprintf(cmd, sizeof cmd, "TMPDIR=%s %s bake scenes/two_rooms.glb --texels 20000 "
             "--out %s/killed > %s/killed.log 2>&1 & echo $!", dir, mpi, dir, dir);
    assert_int_equal(lmt_run(cmd, output, sizeof output), 0);
    int job = atoi(output); /* mpirun */
    assert_true(job > 0);
    int waited = 0, found = 0;
    while (!found && waited < 60000) {
        snprintf(cmd, sizeof cmd, "grep -q 'bake: gather' %s/killed.log", dir);
        found = system(cmd) == 0;
        usleep(20000);
        waited += 20;
    }
    assert_true(found);
    snprintf(cmd, sizeof cmd, "pkill -9 -n -P %d", job); /* the newest of mpirun's ranks */
    assert_int_equal(system(cmd), 0);
    snprintf(cmd, sizeof cmd, "while kill -0 %d 2> /dev/null; do sleep 0.1; done; cat %s/killed.log", job, dir);
    lmt_run(cmd, output, sizeof output);
    print_message("killed rank: %s\n", output);
    assert_non_null(strstr(output, "exited on signal 9"));
    snprintf(a_path, sizeof a_path, "%s/killed/lightmap.exr", dir);
    assert_int_equal(access(a_path, F_OK), -1);
}

static void test_bake_command(void **state)
{
    (void)state;
    char args[2048], path[1200], dir[256];
    snprintf(dir, sizeof dir, "%s", lmt_tmpdir()); /* a fresh directory at each call */
    snprintf(args, sizeof args, "bake scenes/cornell.glb --texels 2000 --photons 4000 --out %s/bake", dir);
    if (run(args) != 0)
        fail_msg("%s: %s", args, output);
    assert_non_null(strstr(output, "baked"));
    /* stderr is a pipe here, not a terminal: progress comes as whole lines, the first and the last at least */
    assert_non_null(strstr(output, "bake: gather"));
    assert_non_null(strstr(output, "bake: done in"));
    assert_null(strstr(output, "\r"));
    static const char *const files[] = {"lightmap.exr", "lightmap.png", "aim.exr"};
    for (int k = 0; k < 3; k++) {
        snprintf(path, sizeof path, "%s/bake/%s", dir, files[k]);
        assert_int_equal(access(path, R_OK), 0);
    }
    /* --half: the same lightmap in 16-bit floats, under half the size; --gltf: the copy for engines, whose
     * lightmap is the bake's */
    snprintf(args, sizeof args, "bake scenes/cornell.glb --texels 2000 --photons 4000 --half --gltf --out %s/half", dir);
    if (run(args) != 0)
        fail_msg("%s: %s", args, output);
    char full_path[1200];
    snprintf(full_path, sizeof full_path, "%s/bake/lightmap.exr", dir);
    snprintf(path, sizeof path, "%s/half/lightmap.exr", dir);
    int w = 0, h = 0, w2 = 0, h2 = 0;
    float *full = NULL, *half = NULL;
    lm_error err;
    assert_int_equal(lm_read_exr(full_path, &w, &h, &full, &err), LM_OK);
    assert_int_equal(lm_read_exr(path, &w2, &h2, &half, &err), LM_OK);
    assert_true(w == w2 && h == h2);
    double worst = 0.0;
    for (size_t i = 0; i < 4 * (size_t)w * h; i++)
        worst = fmax(worst, fabs((double)half[i] - full[i]) / (fabs((double)full[i]) + 1e-6));
    print_message("lightmap.exr in half floats: largest relative difference %.1e\n", worst);
    assert_true(worst < 1e-3); /* 11 bits */
    snprintf(path, sizeof path, "%s/half/cornell_lightmap.exr", dir);
    float *exported = NULL;
    assert_int_equal(lm_read_exr(path, &w2, &h2, &exported, &err), LM_OK);
    assert_memory_equal(exported, half, 4 * sizeof(float) * (size_t)w * h);
    free(exported);
    static const char *const gltf_files[] = {"cornell.gltf", "cornell.bin", "cornell_lightmap.png"};
    for (int k = 0; k < 3; k++) {
        snprintf(path, sizeof path, "%s/half/%s", dir, gltf_files[k]);
        assert_int_equal(access(path, R_OK), 0);
    }
    snprintf(path, sizeof path, "%s/half/lightmap.exr", dir);
    free(full);
    free(half);
    FILE *fa = fopen(full_path, "rb"), *fb = fopen(path, "rb");
    assert_true(fa && fb);
    fseek(fa, 0, SEEK_END), fseek(fb, 0, SEEK_END);
    assert_true(ftell(fb) < ftell(fa) / 2 + 1024);
    fclose(fa), fclose(fb);

    /* the default density of the two rooms takes seconds to gather: interrupted after 1 s */
    snprintf(args, sizeof args, "bake scenes/two_rooms.glb --out %s/interrupted", dir);
    int status = lmt_lmgi("timeout --preserve-status -s INT 1 ", args, output, sizeof output);
    if (status != 130 || !strstr(output, "bake cancelled"))
        fail_msg("interrupted bake: exit %d, %s", status, output);
    snprintf(path, sizeof path, "%s/interrupted/lightmap.exr", dir);
    assert_int_not_equal(access(path, F_OK), 0);

    /* interrupted while it loads: the scene is a FIFO, so the shell's open for writing returns only once
     * the bake has opened it, inside its loading, whatever the machine's load (under ASan on a busy machine
     * the two rooms' loading alone once passed the 1 s above, and the command died without a word). The
     * signal is pending before the FIFO is closed, so the bake meets it before it reads the end of file. */
    char fifo[300];
    snprintf(fifo, sizeof fifo, "%s/loading.glb", dir);
    assert_int_equal(mkfifo(fifo, 0600), 0);
    const char *build = getenv("LMGI_BUILD");
    snprintf(args, sizeof args,
             "timeout 60 sh -c '%s/lmgi bake %s --out %s/loading 2>&1 & pid=$!; exec 3>%s; kill -INT $pid; exec 3>&-; wait $pid'",
             build ? build : "build", fifo, dir, fifo);
    status = lmt_run(args, output, sizeof output);
    if (status != 130 || !strstr(output, "bake cancelled while loading the scene"))
        fail_msg("interrupted while loading: exit %d, %s", status, output);
    snprintf(path, sizeof path, "%s/loading", dir);
    assert_int_not_equal(access(path, F_OK), 0); /* the output folder is made only after loading */
}

/* Whether DIR/NAME exists. */
static int exists(const char *dir, const char *name)
{
    char path[1400];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    return access(path, F_OK) == 0;
}

/* A level on several pages (the Cornell box at 6,000 texels, --max-atlas 64): info prints the pages; bake
 * writes lightmap_pageP.exr and .png and aim_pageP.exr for each page, each a page's size, and the glTF's
 * images a page, no lightmap.exr, and its wrote line names them; run writes iim_pageP and aim_pageP. The
 * same folder baked again on one page has lightmap.exr again and no page's file (lmgi replaces its own
 * files). A page side outside 64..32768 is refused naming --max-atlas. */
static void test_bake_pages(void **state)
{
    (void)state;
    char args[2048], dir[256], paged[600], name[64];
    snprintf(dir, sizeof dir, "%s", lmt_tmpdir());
    snprintf(paged, sizeof paged, "%s/paged", dir);
    assert_int_equal(run_ok("info scenes/cornell.glb --texels 6000 --max-atlas 64"), 0);
    int pages = 0, pw = 0, ph = 0;
    const char *atlas = strstr(output, "atlas       ");
    assert_non_null(atlas);
    assert_int_equal(sscanf(atlas, "atlas       %d pages of %d x %d", &pages, &pw, &ph), 3);
    assert_true(pages > 1 && pw <= 64 && ph <= 64);
    snprintf(args, sizeof args, "bake scenes/cornell.glb --texels 6000 --max-atlas 64 --photons 4000 --gltf --out %s",
             paged);
    assert_int_equal(run_ok(args), 0);
    snprintf(name, sizeof name, "lightmap_page0..%d.exr", pages - 1);
    assert_non_null(strstr(output, name));
    for (int p = 0; p < pages; p++) {
        static const char *const kinds[] = {"lightmap_page%d.exr", "lightmap_page%d.png", "aim_page%d.exr",
                                            "cornell_lightmap_page%d.exr", "cornell_lightmap_page%d_rgbd.png"};
        for (int k = 0; k < 5; k++) {
            snprintf(name, sizeof name, kinds[k], p);
            if (!exists(paged, name))
                fail_msg("%s/%s is missing", paged, name);
        }
        char path[1400];
        snprintf(path, sizeof path, "%s/lightmap_page%d.exr", paged, p);
        float *px = NULL;
        int w = 0, h = 0;
        lm_error err;
        assert_int_equal(lm_read_exr(path, &w, &h, &px, &err), LM_OK);
        assert_true(w == pw && h == ph);
        free(px);
    }
    snprintf(name, sizeof name, "lightmap_page%d.exr", pages);
    assert_false(exists(paged, name));
    assert_false(exists(paged, "lightmap.exr") || exists(paged, "cornell_lightmap.exr"));
    char ran[600];
    snprintf(ran, sizeof ran, "%s/run", dir);
    snprintf(args, sizeof args, "run scenes/cornell.glb --texels 6000 --max-atlas 64 --frames 2 --size 32x32 --out %s",
             ran);
    assert_int_equal(run_ok(args), 0);
    assert_non_null(strstr(output, "iim_page0.."));
    assert_true(exists(ran, "iim_page0.exr") && exists(ran, "aim_page0.png") && !exists(ran, "iim.exr"));
    snprintf(args, sizeof args, "bake scenes/cornell.glb --texels 2000 --photons 4000 --out %s", paged);
    assert_int_equal(run_ok(args), 0);
    assert_true(exists(paged, "lightmap.exr") && exists(paged, "aim.exr"));
    assert_false(exists(paged, "lightmap_page0.exr") || exists(paged, "aim_page0.exr"));
    static const char *const bad[] = {"63", "32769", "65537"};
    for (int k = 0; k < 3; k++) {
        snprintf(args, sizeof args, "info scenes/cornell.glb --max-atlas %s", bad[k]);
        assert_int_equal(run(args), 2);
        assert_non_null(strstr(output, "--max-atlas"));
    }
}

/* lmgi bench --edits: the lag table and the JSON from a small script; bad scripts named where they fail. */
static void test_bench_edits(void **state)
{
    (void)state;
    char dir[256], path[512], args[2048];
    snprintf(dir, sizeof dir, "%s", lmt_tmpdir());
    snprintf(path, sizeof path, "%s/edits.json", dir);
    const char *script = "{\"frames\": 12, \"budget_ms\": 0, \"fps\": 0, \"texels\": 600,\n"
                         " \"edits\": [{\"frame\": 2, \"light\": \"light_a1\", \"intensity\": 2},\n"
                         "  {\"frame\": 5, \"add_light\": \"point\", \"position\": [2, 2.2, 0], \"intensity\": 15},\n"
                         "  {\"frame\": 8, \"remove_light\": \"light_b2\"}]}\n";
    lmt_write_file(path, script, strlen(script));
    snprintf(args, sizeof args, "bench --edits %s scenes/two_rooms.glb --json %s/out.json", path, dir);
    if (run(args) != 0)
        fail_msg("%s: %s", args, output);
    const char *row = strstr(output, "light light_a1");
    assert_non_null(row);
    int frame = -1;
    double error = -1.0;
    assert_int_equal(sscanf(row, "light light_a1 %d %lf%%", &frame, &error), 2);
    assert_int_equal(frame, 2);
    assert_true(error < 2.0); /* one of room A's lights changed in power alone: shown at the next update
                               * (test_light_edits; 30% off there before) */
    assert_non_null(strstr(output, "updates: median"));
    double added = -1.0, removed = -1.0; /* a lamp added in room B, then one of its lights removed */
    assert_non_null(row = strstr(output, "add_light point"));
    assert_int_equal(sscanf(row, "add_light point %d %lf%%", &frame, &added), 2);
    assert_int_equal(frame, 5);
    assert_non_null(row = strstr(output, "remove_light light_b2"));
    assert_int_equal(sscanf(row, "remove_light light_b2 %d %lf%%", &frame, &removed), 2);
    assert_int_equal(frame, 8);
    /* both shown at the next update: the lamp's photons traced at once (docs/tradeoff.md, "Lights added or
     * switched on"; 19% and 18% off when its groups waited in the re-trace queue), the light removed in
     * power alone */
    assert_true(added < 5.0 && removed < 5.0);
    snprintf(path, sizeof path, "%s/out.json", dir);
    size_t n = 0;
    char *json = (char *)lmt_read_file(path, &n, 1);
    json[n] = '\0';
    assert_non_null(strstr(json, "\"frames_to_5\""));
    assert_non_null(strstr(json, "\"edit_ms\""));
    free(json);
    assert_non_null(strstr(output, "edit calls before 3 updates: median")); /* the edits' own calls, timed */

    /* the work outside an edit's reach, the door closed: a light in room A, then one in room B, each caught
     * up on before the next (200 texels an update; 16 photon groups an update, the first within 2% after
     * 22 updates); the other room's surfaces are never rewritten */
    snprintf(path, sizeof path, "%s/reach.json", dir);
    const char *reach = "{\"frames\": 80, \"budget_ms\": 0, \"fps\": 0, \"texels\": 600,\n"
                        " \"edits\": [{\"frame\": 2, \"light\": \"light_a1\", \"intensity\": 2},\n"
                        "  {\"frame\": 40, \"light\": \"light_b2\", \"enabled\": false}]}\n";
    lmt_write_file(path, reach, strlen(reach));
    snprintf(args, sizeof args, "bench --edits %s scenes/two_rooms.glb --texels-per-frame 200 --json %s/reach_out.json",
             path, dir);
    if (run(args) != 0)
        fail_msg("%s: %s", args, output);
    snprintf(path, sizeof path, "%s/reach_out.json", dir);
    json = (char *)lmt_read_file(path, &n, 1);
    json[n] = '\0';
    static const char *const lights[2] = {"\"light light_a1\"", "\"light light_b2\""};
    int reaches[2];
    for (int k = 0; k < 2; k++) {
        int reach = -1, rewrites = -1, outside = -1;
        unsigned outside_texels = 1;
        assert_non_null(row = strstr(json, lights[k]));
        assert_non_null(row = strstr(row, "\"reach_surfaces\""));
        assert_int_equal(sscanf(row, "\"reach_surfaces\": %d, \"rewritten_in_reach\": %d, \"outside_surfaces\": %d, "
                                "\"outside_texels\": %u", &reach, &rewrites, &outside, &outside_texels), 4);
        print_message("%s: %d surfaces in its reach, %d surface rewrites there, %d outside (%u texels)\n", lights[k],
                      reach, rewrites, outside, outside_texels);
        reaches[k] = reach;
        assert_true(rewrites > 10);
        assert_int_equal(outside, 0);
        assert_int_equal(outside_texels, 0);
    }
    /* each light reaches its own room (and the door's two sides), not the other: together fewer surfaces
     * than the scene's, each some */
    free(json);
    int surfaces = 0;
    assert_int_equal(run("info scenes/two_rooms.glb --texels 600"), 0);
    assert_non_null(row = strstr(output, "surfaces "));
    assert_int_equal(sscanf(row, "surfaces %d", &surfaces), 1);
    print_message("%d surfaces in all\n", surfaces);
    assert_true(reaches[0] > 10 && reaches[1] > 10 && reaches[0] + reaches[1] < surfaces + 10);

    snprintf(path, sizeof path, "%s/broken.json", dir);
    const char *broken = "{\"edits\": [\n  {\"frame\": 1,, }]}";
    lmt_write_file(path, broken, strlen(broken));
    snprintf(args, sizeof args, "bench --edits %s scenes/two_rooms.glb", path);
    assert_int_equal(run(args), 1);
    assert_non_null(strstr(output, "line 2, column"));
    snprintf(path, sizeof path, "%s/unknown.json", dir);
    const char *unknown = "{\"frames\": 5, \"texels\": 300, \"edits\": [{\"frame\": 1, \"light\": \"nope\"}]}";
    lmt_write_file(path, unknown, strlen(unknown));
    snprintf(args, sizeof args, "bench --edits %s scenes/two_rooms.glb", path);
    assert_int_equal(run(args), 1);
    assert_non_null(strstr(output, "edit 0: no light on that node"));
}

/* `lmgi check`'s row over the frame in the last command's output: frame / reference per channel into c, and
 * its compared pixels (returned). */
static unsigned check_frame_row(double c[3])
{
    const char *row = strstr(output, "frame (not emitters)");
    assert_non_null(row);
    unsigned pixels;
    assert_int_equal(sscanf(row + strlen("frame (not emitters)"), "%u %lf %lf %lf", &pixels, &c[0], &c[1], &c[2]), 4);
    return pixels;
}

/* `lmgi reference` writes the atlas-sized texel images and the picture, and `lmgi check` compares a frame
 * with the reference: the frame within 10% of it over the lit pixels at these small settings. */
static void test_reference_and_check_commands(void **state)
{
    (void)state;
    const char *dir = lmt_tmpdir();
    char args[2048], path[1100];
    snprintf(args, sizeof args, "info scenes/cornell.glb --texels 800");
    assert_int_equal(run(args), 0);
    int aw = 0, ah = 0;
    const char *atlas = strstr(output, "\natlas ");
    assert_non_null(atlas);
    assert_int_equal(sscanf(strpbrk(atlas, "0123456789"), "%d x %d", &aw, &ah), 2);
    snprintf(args, sizeof args, "reference scenes/cornell.glb --texels 800 --size 24x20 --target-error 0.1 "
             "--no-cache --out %s/ref", dir);
    assert_int_equal(run(args), 0);
    static const char *const atlas_images[] = {"reference_full.exr", "reference_iim.exr", "reference_radiance.exr"};
    for (int k = 0; k < 3; k++) {
        snprintf(path, sizeof path, "%s/ref/%s", dir, atlas_images[k]);
        int w, h;
        float *img = NULL;
        lm_error err;
        assert_int_equal(lm_read_exr(path, &w, &h, &img, &err), LM_OK);
        assert_int_equal(w, aw);
        assert_int_equal(h, ah);
        double sum = 0.0;
        for (size_t i = 0; i < (size_t)w * h * 4; i++)
            sum += img[i];
        assert_true(sum > 0.0); /* lit */
        free(img);
    }
    snprintf(path, sizeof path, "%s/ref/reference_pixels.png", dir);
    assert_int_equal(access(path, R_OK), 0);
    snprintf(args, sizeof args, "check scenes/cornell.glb --texels 800 --size 32x32 --photons 6000 --hemicube 16 "
             "--target-error 0.1 --no-cache --out %s/check -q", dir);
    assert_int_equal(run(args), 0);
    double c[3];
    unsigned pixels = check_frame_row(c);
    print_message("lmgi check at 32 x 32: %u pixels, frame / reference %.3f %.3f %.3f\n", pixels, c[0], c[1], c[2]);
    assert_true(pixels > 100);
    assert_true(fabs(c[0] - 1.0) < 0.1 && fabs(c[1] - 1.0) < 0.1 && fabs(c[2] - 1.0) < 0.1);
    const char *per_channel = strstr(output, "per channel: "); /* the summary of issue 33's criterion */
    int within, judged;
    assert_non_null(per_channel);
    assert_int_equal(sscanf(per_channel, "per channel: %d of %d surfaces of 100+ pixels within 5%%", &within, &judged), 2);
    assert_true(judged >= 1 && within >= 0 && within <= judged);
    static const char *const check_files[] = {"check_frame.exr", "check_reference.exr", "check_ratio.png"};
    for (int k = 0; k < 3; k++) {
        snprintf(path, sizeof path, "%s/check/%s", dir, check_files[k]);
        assert_int_equal(access(path, R_OK), 0);
    }
}

/* `lmgi check PATH` at 96 x 96 (the reference at 0.03, solved again): issue 33's criterion per channel
 * (lm_cli_surface_channels) as it prints it, at least `within` of the surfaces of 100+ pixels within 5% and
 * the one furthest off within `worst`. */
static void check_level_channels(const char *path, int within, double worst)
{
    char args[1200];
    snprintf(args, sizeof args, "check %s --size 96x96 --target-error 0.03 --no-cache -q", path);
    assert_int_equal(run(args), 0);
    const char *line = strstr(output, "per channel: ");
    assert_non_null(line);
    int n, judged;
    assert_int_equal(sscanf(line, "per channel: %d of %d surfaces", &n, &judged), 2);
    const char *far = strstr(line, "furthest off: ");
    assert_non_null(far);
    far = strstr(far, ") ");
    assert_non_null(far);
    char channel;
    double off;
    assert_int_equal(sscanf(far, ") %c %lf%%", &channel, &off), 2);
    print_message("%s: %d of %d surfaces within 5%% per channel, furthest off %c %+.1f%%\n", path, n, judged, channel, off);
    assert_true(n >= within);
    assert_true(fabs(off) < 100.0 * worst);
}

/* The shared levels at `lmgi run`'s density (issue 33, item 4). room_lit's blue sphere facets read 7-14%
 * bright in red, and truck-town's retaining wall 12% dark, while each texel faced the shading normal at
 * its centre alone; facing the mean over what it covers (docs/levels.md, "Faceted spheres"), measured 8
 * of 9 (worst R +8.1%, before 6 of 9 and +13.1%) and 7 of 8 (worst G -8.6%, before -11.7%). The town with
 * its texels and photons where it needs them (docs/levels.md, "Built: open surfaces, a guided sun"),
 * its gather's eyes and proxy within a texel (docs/gather.md): every surface within 5% (measured 8 of 8,
 * worst G +3.6%; room_lit 8 of 9, R +7.1%). room_lit's facets gathered over their footprints (docs/charts.md,
 * "Footprints"): every surface within 5% (measured 9 of 9, worst B -3.7%; later -4.5%). Their one texel
 * turned with each pixel's normal ("Turning with the normal"): within 4% (measured 9 of 9, worst B -3.4%). */
static void test_check_levels_per_channel(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(room, lmt_shared_scene("occlusion-room/room_lit.glb"));
    check_level_channels(room, 9, 0.04);
    LMT_REQUIRE_SCENE(town, lmt_shared_scene("truck-town/town_lit.gltf"));
    check_level_channels(town, 8, 0.05);
}

/* `lmgi check --as-bake` checks the lightmap `lmgi bake` makes (src/cli/bake_options.h): 16 photons a texel
 * (at least 46,080), a bounce pass and the AIMs' direct light over 4 x 4 parts a texel, which it says; plain
 * `check` solves as `run` does, with none of them. The frame is right either way (measured at 32 x 32:
 * 0.99-1.01 per channel). */
static void test_check_as_bake(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(box, lmt_shared_scene("cornell-box/CornellBox.glb"));
    char args[1200];
    const char *as_bake[2] = {"", " --as-bake"};
    for (int k = 0; k < 2; k++) {
        snprintf(args, sizeof args, "check %s --texels 12000 --size 32x32 --target-error 0.1 --no-cache -q%s", box,
                 as_bake[k]);
        assert_int_equal(run(args), 0);
        const char *line = strstr(output, "the lightmap as lmgi bake makes it: ");
        if (!k) {
            assert_null(line);
        } else {
            unsigned texels, photons;
            int passes, parts[2];
            assert_non_null(line);
            assert_int_equal(sscanf(line, "the lightmap as lmgi bake makes it: %u texels, %u photons, %d bounce pass, "
                                          "direct light over %d x %d parts a texel",
                                    &texels, &photons, &passes, &parts[0], &parts[1]), 5);
            print_message("check --as-bake: %u texels, %u photons, %d bounce pass, %d x %d direct parts\n", texels,
                          photons, passes, parts[0], parts[1]);
            assert_true(texels > 9000 && texels < 15000);
            assert_int_equal(photons, 16 * texels);
            assert_int_equal(passes, 1);
            assert_int_equal(parts[0], 4);
        }
        double c[3];
        check_frame_row(c);
        for (int i = 0; i < 3; i++)
            assert_true(fabs(c[i] - 1.0) < 0.05);
    }
}

/* Issue 37's measure of the caustic filter: `lmgi check` of the generated Cornell box at 256 x 256 and the
 * defaults, its caustic part (the mirror and glass spheres' light) against the reference's light-traced
 * one: relative RMSE per pixel under 0.10 and its sum within 3%. The reference's caustic part does not
 * depend on the path tracer's target error, so a coarse one keeps this quick. Measured 0.0805 and 1.010;
 * 0.119 before the filter narrowed only where the light has structure (docs/caustics.md). */
static void test_check_caustic_part(void **state)
{
    (void)state;
    char args[1200];
    snprintf(args, sizeof args, "check scenes/cornell.glb --size 256x256 --target-error 0.3 --no-cache --out %s/caustic -q",
             lmt_tmpdir());
    assert_int_equal(run(args), 0);
    const char *row = strstr(output, "caustic part");
    assert_non_null(row);
    row = strstr(row, "frame / reference ");
    assert_non_null(row);
    double c[3], rmse;
    assert_int_equal(sscanf(row, "frame / reference %lf %lf %lf, relative RMSE %lf", &c[0], &c[1], &c[2], &rmse), 4);
    print_message("lmgi check of the Cornell box at 256 x 256: caustic part %.3f %.3f %.3f of the reference's, relative "
                  "RMSE %.4f\n", c[0], c[1], c[2], rmse);
    for (int k = 0; k < 3; k++)
        assert_true(fabs(c[k] - 1.0) < 0.03);
    assert_true(rmse > 0.0 && rmse < 0.10);
}

/* Column `name` of a CSV header line, -1 if absent. */
static int csv_column(const char *header, const char *name)
{
    int col = 0;
    for (const char *p = header; *p; col++) {
        size_t len = strcspn(p, ",\n");
        if (len == strlen(name) && !strncmp(p, name, len))
            return col;
        p += len + (p[len] == ',');
        if (p[-1] != ',')
            break;
    }
    return -1;
}

/* Field `col` of a CSV line (no commas inside fields; quotes stripped) into out. */
static void csv_field(const char *line, int col, char *out, size_t size)
{
    const char *p = line;
    for (int c = 0; c < col && p; c++)
        p = strchr(p, ',') ? strchr(p, ',') + 1 : NULL;
    assert_non_null(p);
    size_t len = strcspn(p, ",\n");
    if (len >= 2 && p[0] == '"')
        p++, len -= 2;
    snprintf(out, size, "%.*s", (int)len, p);
}

/* The last row's value of column `name` of DIR/frames.csv. */
static double frames_csv_last(const char *dir, const char *name)
{
    char path[2048], header[8192], line[8192], last[8192] = "", field[64];
    snprintf(path, sizeof path, "%s/frames.csv", dir);
    FILE *f = fopen(path, "r");
    assert_non_null(f);
    assert_non_null(fgets(header, sizeof header, f));
    while (fgets(line, sizeof line, f))
        memcpy(last, line, sizeof last);
    fclose(f);
    int col = csv_column(header, name);
    assert_true(col >= 0);
    csv_field(last, col, field, sizeof field);
    return atof(field);
}

/* The showcase's caustics (issue 37): by default (--caustic-thin 0.25) the thin light its convex mirror and
 * glass spread over the box is the lightmaps' (docs/caustics.md, "Thin light in the lightmaps"), so the
 * screen pass's occlusion queries find few lit tiles; with --caustic-thin 0 every photon is the screen's
 * and nearly every tile is lit. */
static void test_run_caustic_tiles(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(scene, lmt_project_scene("cornell.glb"));
    const char *dir = lmt_tmpdir();
    char args[2048], out[2][1024];
    double lit[2], tiles[2], thin[2], landed[2];
    for (int k = 0; k < 2; k++) {
        snprintf(out[k], sizeof out[k], "%s/caustic_tiles_%d", dir, k);
        snprintf(args, sizeof args, "run %s --frames 3 --size 256x256 %s --out %s", scene,
                 k ? "--caustic-thin 0" : "", out[k]);
        assert_int_equal(run(args), 0);
        lit[k] = frames_csv_last(out[k], "caustic_tiles_lit");
        tiles[k] = frames_csv_last(out[k], "caustic_tiles");
        thin[k] = frames_csv_last(out[k], "caustic_photons_thin");
        landed[k] = frames_csv_last(out[k], "caustic_photons_landed");
    }
    print_message("cornell.glb at 256 x 256, thin light in the lightmaps / all on screen: tiles lit %.0f of %.0f / "
                  "%.0f of %.0f; photons thin %.0f of %.0f / %.0f of %.0f\n", lit[0], tiles[0], lit[1], tiles[1],
                  thin[0], landed[0], thin[1], landed[1]);
    assert_true(tiles[0] > 0 && tiles[1] > 0);
    assert_true(lit[0] < 0.15 * tiles[0]);
    assert_true(lit[1] > 0.75 * tiles[1]);
    assert_true(thin[0] > 0.25 * landed[0] && thin[1] == 0.0);
}

/* `lmgi tradeoff` on one knob: a row per value with the photons it asked for (exactly: a given number per
 * group is not raised to the scene's floor), its stage times and its errors against the reference; 16
 * times the photons leave the AIM closer to the reference; the error maps and the report beside them.
 * Bad knobs and a missing --out are refused. */
static void test_tradeoff(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(scene, lmt_project_scene("cornell.glb"));
    const char *dir = lmt_tmpdir();
    char args[2048], path[2048];
    snprintf(args, sizeof args, "tradeoff %s --knobs photons_per_group,bogus --out %s/bad", scene, dir);
    assert_int_equal(run(args), 2);
    assert_non_null(strstr(output, "unknown knob 'bogus'"));
    snprintf(args, sizeof args, "tradeoff %s --quick", scene);
    assert_int_equal(run(args), 2);
    snprintf(args, sizeof args, "tradeoff %s --quick --knobs photons_per_group,aim_direct --repeats 1 --size 32x32 "
             "--texels 800 "
             "--target-error 0.05 --cache %s/cache --out %s/tradeoff -q", scene, dir, dir);
    assert_int_equal(run_ok(args), 0);
    snprintf(path, sizeof path, "%s/tradeoff/tradeoff.csv", dir);
    FILE *f = fopen(path, "r");
    assert_non_null(f);
    char header[4096], line[4096], v[64];
    assert_non_null(fgets(header, sizeof header, f));
    static const char *const names[] = {"knob", "value", "default", "photons", "solution_ms", "update_ms",
                                        "aim_rmse", "iim_rmse", "frame_rmse", "frame_r", "caustic_rmse", "caustic_g"};
    int col[12];
    for (int k = 0; k < 12; k++)
        assert_true((col[k] = csv_column(header, names[k])) >= 0);
    double aim[3] = {0.0, 0.0, 0.0};
    int rows = 0, defaults = 0;
    while (fgets(line, sizeof line, f)) {
        csv_field(line, col[0], v, sizeof v);
        if (!strcmp(v, "aim_direct")) { /* its suns row (value 0) is the default desc */
            csv_field(line, col[2], v, sizeof v);
            defaults += atoi(v);
            continue;
        }
        assert_true(rows < 3);
        static const int per_group[3] = {40, 160, 640};
        assert_string_equal(v, "photons_per_group");
        csv_field(line, col[1], v, sizeof v);
        assert_int_equal(atoi(v), per_group[rows]);
        csv_field(line, col[2], v, sizeof v);
        assert_int_equal(atoi(v), 0); /* photons per group given: none is the default, which is the scene's floor */
        csv_field(line, col[3], v, sizeof v);
        assert_int_equal(atoi(v), 72 * per_group[rows]); /* one light, 72 groups */
        double x[6];
        for (int k = 0; k < 6; k++) {
            csv_field(line, col[4 + k], v, sizeof v);
            x[k] = atof(v);
            assert_true(isfinite(x[k]) && x[k] > 0.0);
        }
        aim[rows] = x[2];
        print_message("tradeoff: %d photons per group: solution %.1f ms, update %.1f ms, relative RMSE AIM %.4f "
                      "IIM %.4f frame %.4f (frame / reference R %.3f)\n", per_group[rows], x[0], x[1], x[2], x[3],
                      x[4], x[5]);
        assert_true(x[3] < 0.2);
        assert_true(fabs(x[5] - 1.0) < 0.1);
        double caustic[2]; /* the box's mirror and glass spheres: a caustic part against the reference's */
        for (int k = 0; k < 2; k++) {
            csv_field(line, col[10 + k], v, sizeof v);
            caustic[k] = v[0] ? atof(v) : NAN;
        }
        print_message("tradeoff: caustic part relative RMSE %.3f, its sum %.3f of the reference's\n", caustic[0],
                      caustic[1]);
        assert_true(isfinite(caustic[0]) && caustic[0] > 0.0 && caustic[0] < 1.0);
        assert_true(fabs(caustic[1] - 1.0) < 0.25);
        rows++;
    }
    fclose(f);
    assert_int_equal(rows, 3);
    assert_int_equal(defaults, 1);
    assert_true(aim[2] < aim[0]);
    static const char *const files[] = {"tradeoff.json", "map_cornell_default_iim.npy", "map_cornell_default_frame.npy",
                                        "plot_cornell_front.png", "plot_cornell_knobs.png", "plot_cornell_maps.png",
                                        "report.html"};
    for (int k = 0; k < 7; k++) {
        snprintf(path, sizeof path, "%s/tradeoff/%s", dir, files[k]);
        assert_int_equal(access(path, R_OK), 0);
    }
}

/* The update-lag part of `lmgi tradeoff`: an edit script played once per update budget.
 * - The cube moved right after a nudge (a drag's last step) is caught up at the first update without edits
 *   after it (update/photon_stage.c catch_up, update/lightmap_path.c), whatever the texel budget: its worst
 *   surface within 5% after at most 2 updates in every play.
 * - The red wall recoloured is shown at once from its first guess (update/light_scale.h), then regathered
 *   texel by texel, those it moved most first, the waiting texels showing what their rays see: within 5%
 *   at once, within 2% in a few updates at 20 or 80 texels an update, more at 5, and far longer with whole
 *   surfaces only.
 * - The report's lag plot draws the nudge and the move, one update apart, as one gesture's panel.
 * A script for a scene not on the command line is refused. */
static void test_tradeoff_update_lag(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(scene, lmt_project_scene("cornell.glb"));
    const char *dir = lmt_tmpdir();
    char args[4096], path[2048];
    snprintf(path, sizeof path, "%s/lag_script.json", dir);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    enum { MOVE = 2, RECOLOUR = 20 };
    fprintf(f, "{\"scene\": \"cornell.glb\", \"frames\": 80, \"fps\": 0, \"budget_ms\": 0, \"texels\": 800,\n"
               " \"edits\": [{\"frame\": 1, \"node\": \"dynamic_cube\", \"translate\": [-0.001, 0, 0]},\n"
               "  {\"frame\": %d, \"node\": \"dynamic_cube\", \"translate\": [-1.099, 0, 0]},\n"
               "  {\"frame\": %d, \"material\": \"red\", \"base_color\": [0.1, 0.2, 0.63]}]}\n", MOVE, RECOLOUR);
    fclose(f);
    snprintf(args, sizeof args, "tradeoff two_rooms.glb --edits %s --out %s/lagbad", path, dir);
    assert_int_equal(run(args), 2);
    assert_non_null(strstr(output, "its \"scene\" is not on the command line"));
    snprintf(args, sizeof args, "tradeoff %s --quick --knobs hemicube_samples --repeats 1 --size 32x32 --texels 800 "
             "--target-error 0.05 --cache %s/cache --edits %s --out %s/lag --frame-lag -q", scene, dir, path, dir);
    assert_int_equal(run_ok(args), 0);
    snprintf(path, sizeof path, "%s/lag/lag.csv", dir);
    f = fopen(path, "r");
    assert_non_null(f);
    char header[1024], line[1024], v[64];
    assert_non_null(fgets(header, sizeof header, f));
    int knob = csv_column(header, "knob"), value = csv_column(header, "value"), error = csv_column(header, "error");
    int to5 = csv_column(header, "frames_to_5"), to2 = csv_column(header, "frames_to_2");
    int def = csv_column(header, "default");
    int frame_error = csv_column(header, "frame_error"), frame_end = csv_column(header, "frame_end");
    int frame = csv_column(header, "frame");
    assert_true(knob >= 0 && value >= 0 && error >= 0 && to5 >= 0 && to2 >= 0 && def >= 0 && frame_error >= 0 &&
                frame_end >= 0 && frame >= 0);
    int plays = 0, lag5 = -2, lag80 = -2, lag_default = -2, lag2_5 = -2, lag2_80 = -2, lag2_default = -2,
        lag_surfaces = -2, lag2_surfaces = -2;
    while (fgets(line, sizeof line, f)) {
        csv_field(line, frame, v, sizeof v);
        int at = atoi(v);
        if (at != MOVE && at != RECOLOUR) /* the nudge */
            continue;
        plays += at == MOVE;
        csv_field(line, error, v, sizeof v);
        double e = atof(v);
        /* --frame-lag: the default play's frame against the reference of the edited scene, per surface,
         * at the edit and at the end (2-4% when written: the direct light is the frame's own) */
        char fe[64], fend[64];
        csv_field(line, def, v, sizeof v);
        csv_field(line, frame_error, fe, sizeof fe);
        csv_field(line, frame_end, fend, sizeof fend);
        if (atoi(v)) {
            print_message("frame against the reference: %s at the edit, %s at the end\n", fe, fend);
            assert_true(atof(fe) > 0.0 && atof(fe) < 0.1 && atof(fend) > 0.0 && atof(fend) < 0.1);
        } else {
            assert_string_equal(fe, ""); /* only the default play is checked */
        }
        char name[64];
        csv_field(line, knob, name, sizeof name);
        int is_texels = !strcmp(name, "texels_per_frame");
        csv_field(line, value, v, sizeof v);
        int n = atoi(v);
        csv_field(line, to5, v, sizeof v);
        int lag = atoi(v);
        csv_field(line, to2, v, sizeof v);
        int lag2 = atoi(v);
        print_message("lag, %s: %s %d: distance at the edit %.3f, within 5%% after %d updates, 2%% after %d\n",
                      at == MOVE ? "the move" : "the recolour", name, n, e, lag, lag2);
        /* the edit moved some surface's light: the play that gathers least shows over 2% at the edit's own
         * update (the move 2.8%, the recolour 4.7%); the others at least 1% (the move 1.9-2.2% since the near
         * rays, ray_estimate.h, 2.6-2.8% before) */
        assert_true(e > (is_texels && n == 5 ? 0.02 : 0.01));
        if (at == MOVE) {
            assert_true(lag >= 0 && lag <= 2);
            continue;
        }
        if (is_texels && n == 5)
            lag5 = lag, lag2_5 = lag2;
        if (is_texels && n == 80)
            lag80 = lag, lag2_80 = lag2;
        if (is_texels && n == 20)
            lag_default = lag, lag2_default = lag2;
        if (!strcmp(name, "texel_change") && n == 0)
            lag_surfaces = lag, lag2_surfaces = lag2;
    }
    fclose(f);
    assert_int_equal(plays, 8); /* the defaults, two values of each of three budgets, the texel change off */
    assert_true(lag80 > 0 && lag5 > 0 && lag_default > 0);
    assert_true(lag5 >= lag80);
    /* to 2%: 8 updates at 5 texels, 3 at the default 20, 5 at 80 (13, 15 and 5 before the near rays and
     * their estimates shown alone, ray_estimate.h and iim.h: the recolour's waiting texels beside the moved
     * cube now read it right); whole surfaces only are slower at both bounds, by how much the gather's noise
     * on the walls decides (to 5% / 2%: 34 against 3 and not in 60 before the upright strata,
     * docs/gather.md; 2 against 1 and not in 60 with them; 33 against 1 and 40 against 21 with each upright
     * row's rays at their own alpha) */
    assert_true(lag2_default > 0 && lag2_80 > 0 && lag2_5 > lag2_default && lag2_5 > lag2_80);
    assert_true(lag2_default <= 6);
    assert_true(lag_surfaces == -1 || lag_surfaces > lag_default);
    assert_true(lag2_surfaces == -1 || lag2_surfaces > lag2_default);
    assert_true(lag_surfaces == -1 || lag2_surfaces == -1 || lag_surfaces > 2 * lag_default ||
                lag2_surfaces > 2 * lag2_default);
    snprintf(path, sizeof path, "%s/lag/plot_cornell_lag.png", dir);
    assert_int_equal(access(path, R_OK), 0);
    /* the nudge and the move, one update apart, are one gesture: one panel of the plot, not one each */
    snprintf(path, sizeof path, "%s/lag/report.html", dir);
    size_t size = 0;
    char *html = (char *)lmt_read_file(path, &size, 1);
    html[size] = '\0';
    const char *panels = strstr(html, "<p>Panels");
    print_message("%.*s\n", panels ? (int)strcspn(panels, "\n") : 4, panels ? panels : "none");
    assert_non_null(panels);
    assert_non_null(strstr(panels, ": node dynamic_cube x2 (updates 1-2); material red (update 20)."));
    free(html);
}

/* The lmgi command is the public API's first user: no file of src/cli/ includes anything of the library
 * but include/lmgi.h and include/lmgi_tools.h (src/cli's own headers, by plain name). */
static void test_cli_sees_only_the_public_header(void **state)
{
    (void)state;
    DIR *d = opendir("src/cli");
    assert_non_null(d);
    int files = 0;
    for (struct dirent *e; (e = readdir(d));) {
        size_t n = strlen(e->d_name);
        if (n < 3 || (strcmp(e->d_name + n - 2, ".c") && strcmp(e->d_name + n - 2, ".h")))
            continue;
        char path[600], line[1024];
        snprintf(path, sizeof path, "src/cli/%s", e->d_name);
        FILE *f = fopen(path, "r");
        assert_non_null(f);
        while (fgets(line, sizeof line, f)) {
            char name[512];
            if (sscanf(line, " # include \"%511[^\"]\"", name) != 1)
                continue;
            snprintf(path, sizeof path, "src/cli/%s", name);
            if (strchr(name, '/') || access(path, R_OK) != 0)
                fail_msg("src/cli/%s includes \"%s\": the command may use include/lmgi.h, lmgi_tools.h and its own "
                         "files only",
                         e->d_name, name);
        }
        fclose(f);
        files++;
    }
    closedir(d);
    assert_true(files > 20);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_usage_errors),
        cmocka_unit_test(test_command_help),
        cmocka_unit_test(test_tiled_run),
        cmocka_unit_test(test_soak),
        cmocka_unit_test(test_bad_scene_files),
        cmocka_unit_test(test_strict_refuses_degenerate_triangles),
        cmocka_unit_test(test_info_on_generated_cornell),
        cmocka_unit_test(test_charts_pictures),
        cmocka_unit_test(test_bake_command),
        cmocka_unit_test(test_bake_pages),
        cmocka_unit_test(test_progress_lines),
        cmocka_unit_test(test_bake_killed_and_resumed),
        cmocka_unit_test(test_bake_makes_a_bounce_pass),
        cmocka_unit_test(test_bake_in_shards),
        cmocka_unit_test(test_merge_parts_alone),
        cmocka_unit_test(test_mpi_bake),
        cmocka_unit_test(test_bench_edits),
        cmocka_unit_test(test_reference_and_check_commands),
        cmocka_unit_test(test_check_caustic_part),
        cmocka_unit_test(test_check_levels_per_channel),
        cmocka_unit_test(test_check_as_bake),
        cmocka_unit_test(test_run_caustic_tiles),
        cmocka_unit_test(test_tradeoff),
        cmocka_unit_test(test_tradeoff_update_lag),
        cmocka_unit_test(test_cli_sees_only_the_public_header),
    };
    lmt_filter_from_env();
    return cmocka_run_group_tests(tests, NULL, NULL);
}
