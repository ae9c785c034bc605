/* lmgi run: the files it writes, one CSV row per frame, deterministic frames, its atlas sized for its texel
 * budget, bad arguments, and the composite in numbers on the furnace box (emission + albedo / pi * E_IIM
 * = Le / (1 - rho)). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "../src/core/image.h"
#include "../src/update/frame_loop.h"
#include "support.h"

static char output[65536];

/* Runs `SHELL_PREFIX lmgi ARGS` and returns its exit status (output kept in `output`). */
static int lmgi_after(const char *shell_prefix, const char *args)
{
    return lmt_lmgi(shell_prefix, args, output, sizeof output);
}

static int lmgi(const char *args) { return lmgi_after("", args); }

/* A small, quick run of the Cornell box into DIR/NAME with extra options; returns the directory (static
 * storage). */
static const char *quick_run_with(const char *name, const char *extra)
{
    static char dir[1024];
    char args[2048];
    snprintf(dir, sizeof dir, "%s/%s", lmt_tmpdir(), name);
    snprintf(args, sizeof args, "run scenes/cornell.glb --frames 3 --size 64x48 --texel-size 0.1 --photons 20000 "
             "--exr-every 2 %s --out %s", extra, dir);
    if (lmgi(args) != 0)
        fail_msg("lmgi run failed: %s", output);
    return dir;
}

static const char *quick_run(const char *name) { return quick_run_with(name, "-q"); }

static int exists(const char *dir, const char *file)
{
    char path[2048];
    snprintf(path, sizeof path, "%s/%s", dir, file);
    return access(path, R_OK) == 0;
}

static int count_lines(const char *path)
{
    FILE *f = fopen(path, "r");
    assert_non_null(f);
    int n = 0, c;
    while ((c = fgetc(f)) != EOF)
        n += c == '\n';
    fclose(f);
    return n;
}

/* `lmgi run --budget MS`: frames.csv gives each update's texels allowed, the stage that took its longest
 * time and why, in words that name the budget (docs/api.md, "The time budget"), and the waiting texels'
 * estimates with their time; without it, the fixed counts (20 texels). */
static void test_run_budget_in_csv(void **state)
{
    (void)state;
    const char *runs[2] = {"-q --budget 4", "-q"};
    for (int k = 0; k < 2; k++) {
        const char *dir = quick_run_with(k ? "fixed" : "budget", runs[k]);
        char path[2048], line[1024];
        snprintf(path, sizeof path, "%s/frames.csv", dir);
        FILE *f = fopen(path, "r");
        assert_non_null(f);
        assert_non_null(fgets(line, sizeof line, f));
        assert_non_null(strstr(line, ",texels_budget,busiest_stage,why"));
        assert_non_null(strstr(line, ",texels_estimated,estimates_ms\n"));
        int rows = 0;
        while (fgets(line, sizeof line, f)) {
            const char *why = strchr(line, '"');
            assert_non_null(why);
            const char *stage = why - 1; /* the field before the quoted why */
            while (stage > line && stage[-1] != ',')
                stage--;
            print_message("%s", line);
            const char *names[] = {"photons,", "AIM,",         "caustic photons,", "reflections,",
                                   "gather,",  "light scale,", "estimates,",       "frame,"};
            int known = 0;
            for (int i = 0; i < 8; i++)
                known |= strncmp(stage, names[i], strlen(names[i])) == 0;
            assert_true(known);
            const char *texels = stage - 1; /* the field before: the texels allowed */
            while (texels > line && texels[-1] != ',')
                texels--;
            if (k == 1)
                assert_int_equal(atoi(texels), 20);
            if (strncmp(stage, "frame,", 6) != 0)
                assert_non_null(strstr(why, k ? "fixed counts" : "budget 4 ms"));
            rows++;
        }
        fclose(f);
        assert_int_equal(rows, 3);
    }
}

static void test_writes_files(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(scene, lmt_project_scene("cornell.glb"));
    (void)scene;
    const char *dir = quick_run("files");
    const char *want[] = {"frame_0000.png", "frame_0001.png", "frame_0002.png", "frame_0000.exr", "frame_0002.exr",
                          "iim.exr", "iim.png", "aim.exr", "aim.png", "frames.csv"};
    for (size_t i = 0; i < sizeof want / sizeof *want; i++)
        if (!exists(dir, want[i]))
            fail_msg("missing %s/%s", dir, want[i]);
    assert_false(exists(dir, "frame_0001.exr")); /* --exr-every 2 */
    char path[2048];
    snprintf(path, sizeof path, "%s/frames.csv", dir);
    assert_int_equal(count_lines(path), 1 + 3); /* header + one row per frame */
    int w, h;
    float *px = NULL;
    lm_error err;
    snprintf(path, sizeof path, "%s/frame_0002.exr", dir);
    assert_int_equal(lm_read_exr(path, &w, &h, &px, &err), LM_OK);
    assert_int_equal(w, 64);
    assert_int_equal(h, 48);
    free(px);
    /* iim.exr's alpha says which texels are valid: 1 or 0, and both occur (the floor under the tall block,
     * which stands on it, is covered) */
    snprintf(path, sizeof path, "%s/iim.exr", dir);
    assert_int_equal(lm_read_exr(path, &w, &h, &px, &err), LM_OK);
    lmt_pipeline p;
    lmt_pipeline_load(&p, scene, 0.1f); /* the quick run's atlas */
    assert_int_equal(w, p.atlas.width);
    assert_int_equal(h, p.atlas.height);
    int ones = 0, invalid = 0;
    for (size_t i = 0; i < (size_t)w * h; i++) {
        assert_true(px[4 * i + 3] == 0.0f || px[4 * i + 3] == 1.0f);
        ones += px[4 * i + 3] == 1.0f;
        invalid += p.atlas.texel_index[i] >= 0 && px[4 * i + 3] == 0.0f;
        if (p.atlas.texel_index[i] < 0)
            assert_true(px[4 * i + 3] == 0.0f); /* gutters */
    }
    print_message("iim.exr: %d valid texels, %d invalid\n", ones, invalid);
    assert_true(ones > 100);
    assert_true(invalid > 0);
    float *aim = NULL;
    snprintf(path, sizeof path, "%s/aim.exr", dir);
    assert_int_equal(lm_read_exr(path, &w, &h, &aim, &err), LM_OK); /* the same validity */
    for (size_t i = 0; i < (size_t)w * h; i++)
        assert_true(aim[4 * i + 3] == px[4 * i + 3]);
    free(aim);
    lmt_pipeline_free(&p);
    free(px);
}

static float *read_exr(const char *dir, const char *file, int *w, int *h)
{
    char path[2048];
    float *px = NULL;
    lm_error err;
    snprintf(path, sizeof path, "%s/%s", dir, file);
    if (lm_read_exr(path, w, h, &px, &err) != LM_OK)
        fail_msg("%s", err.msg);
    return px;
}

/* The sum over its rows of column `name` of DIR/frames.csv. */
static long csv_column_sum(const char *dir, const char *name)
{
    char path[2048], line[8192];
    snprintf(path, sizeof path, "%s/frames.csv", dir);
    FILE *f = fopen(path, "r");
    assert_non_null(f);
    assert_non_null(fgets(line, sizeof line, f));
    int col = 0, at = -1;
    for (char *tok = strtok(line, ",\n"); tok; tok = strtok(NULL, ",\n"), col++)
        at = strcmp(tok, name) ? at : col;
    assert_true(at >= 0);
    long sum = 0;
    while (fgets(line, sizeof line, f)) {
        col = 0;
        for (char *tok = strtok(line, ",\n"); tok; tok = strtok(NULL, ",\n"), col++)
            sum += col == at ? atol(tok) : 0;
    }
    fclose(f);
    return sum;
}

/* `lmgi run SCENE --frames 1 -q OPTS` into a fresh folder lmt_tmpdir()/out (its path in dir, 1,100 bytes):
 * its first frame (RGBA floats, row 0 at the top), w x h. */
static float *run_frame(const char *scene, const char *out, const char *opts, char *dir, int *w, int *h)
{
    char args[4096];
    snprintf(dir, 1100, "%s/%s", lmt_tmpdir(), out);
    snprintf(args, sizeof args, "run %s --frames 1 -q %s --out %s", scene, opts, dir);
    if (lmgi(args) != 0)
        fail_msg("lmgi run failed: %s", output);
    return read_exr(dir, "frame_0000.exr", w, h);
}

static void test_deterministic(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(scene, lmt_project_scene("cornell.glb"));
    (void)scene;
    char a[1024];
    snprintf(a, sizeof a, "%s", quick_run("a"));
    const char *b = quick_run("b");
    const char *frames[] = {"frame_0000.exr", "frame_0002.exr", "iim.exr", "aim.exr"};
    for (int i = 0; i < 4; i++) {
        int w, h, w2, h2;
        float *x = read_exr(a, frames[i], &w, &h), *y = read_exr(b, frames[i], &w2, &h2);
        assert_int_equal(w, w2);
        assert_int_equal(h, h2);
        assert_memory_equal(x, y, sizeof(float) * 4 * (size_t)w * h);
        free(x);
        free(y);
    }
}

/* Mean |a - b| / mean |a| over the colour channels of two same-sized EXRs in dirs a and b. */
static double exr_difference(const char *a, const char *b, const char *file)
{
    int w, h, w2, h2;
    float *x = read_exr(a, file, &w, &h), *y = read_exr(b, file, &w2, &h2);
    assert_int_equal(w, w2);
    assert_int_equal(h, h2);
    double d = 0.0, m = 0.0;
    for (size_t i = 0; i < 4 * (size_t)w * h; i++)
        if (i % 4 != 3)
            d += fabs((double)x[i] - y[i]), m += fabs((double)x[i]);
    free(x);
    free(y);
    return d / (m > 0.0 ? m : 1.0);
}

/* The photon stage on its own thread (the default) against the paper's order on one thread: the photon
 * stage runs the same steps in the same order either way, so the AIMs are identical; the gather sees them
 * one frame later, so the IIM differs a little (1,000 texels a frame, so that whole surfaces are
 * regathered and shown within the run). */
static void test_overlap_against_order(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(scene, lmt_project_scene("cornell.glb"));
    (void)scene;
    char a[1024];
    snprintf(a, sizeof a, "%s", quick_run_with("overlapped", "-q --texels-per-frame 1000"));
    const char *b = quick_run_with("in_order", "-q --texels-per-frame 1000 --in-order");
    int w, h, w2, h2;
    float *x = read_exr(a, "aim.exr", &w, &h), *y = read_exr(b, "aim.exr", &w2, &h2);
    assert_int_equal(w, w2);
    assert_int_equal(h, h2);
    for (size_t i = 0; i < 4 * (size_t)w * h; i++) /* the AIM's colour; its alpha is the IIM's validity */
        if (i % 4 != 3 && memcmp(&x[i], &y[i], sizeof x[i]) != 0)
            fail_msg("aim.exr differs at float %zu: %g against %g", i, (double)x[i], (double)y[i]);
    free(x);
    free(y);
    double iim = exr_difference(a, b, "iim.exr"), frame = exr_difference(a, b, "frame_0002.exr");
    print_message("overlapped vs in order: AIMs identical, IIM %.2e, frame 2 %.2e (mean relative difference)\n",
                  iim, frame);
    assert_true(iim > 0.0 && iim < 0.02); /* the order did change: the gathers saw other AIMs */
    assert_true(frame < 0.02);
}

/* The gather options reach the gather: another scheme gives the same lightmap up to edge pixels, another
 * hemicube resolution a different one. */
static void test_gather_options(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(scene, lmt_project_scene("cornell.glb"));
    (void)scene;
    char a[1024], b[1024];
    snprintf(a, sizeof a, "%s", quick_run("default"));
    snprintf(b, sizeof b, "%s", quick_run_with("instanced", "-q --gather-scheme instanced"));
    double same = exr_difference(a, b, "iim.exr");
    quick_run_with("layered", "-q --gather-scheme layered"); /* runs: coverage 1 is implied */
    char args[2048], dir[1024];
    snprintf(dir, sizeof dir, "%s/refused", lmt_tmpdir());
    snprintf(args, sizeof args, "run scenes/cornell.glb --frames 1 --texel-size 0.1 -q --gather-scheme layered "
             "--hemicube-coverage 4 --out %s", dir);
    assert_int_equal(lmgi(args), 1);
    assert_non_null(strstr(output, "1 with the layered scheme"));
    assert_false(exists(dir, "frames.csv")); /* refused settings write nothing */
    const char *c = quick_run_with("coarse", "--hemicube 8 --enlargement 1 --hemicube-samples 1");
    /* not quiet: the summary names the GL backend it ran on */
    assert_true(strstr(output, "gl          ") && (strstr(output, "(OSMesa") || strstr(output, "(EGL")));
    double other = exr_difference(a, c, "iim.exr");
    print_message("IIM vs default: instanced %.2e, R = 8 and a = 1 %.2e (mean relative difference)\n", same, other);
    assert_true(same < 1e-3);
    assert_true(other > 1e-2);
}

typedef struct {
    int calls;
    uint32_t last_done, total, monotonic;
} progress_log;

static void log_progress(void *user, uint32_t done, uint32_t total)
{
    progress_log *l = user;
    l->monotonic &= done > l->last_done && done <= total;
    l->calls++, l->last_done = done, l->total = total;
}

/* The first full gather reports progress in chunks, ending at the total, and chunking changes nothing. */
static void test_setup_progress(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(path, lmt_project_scene("cornell.glb"));
    lmt_pipeline p;
    lmt_pipeline_load(&p, path, 0.1f);
    float *iim[2];
    progress_log log = {0, 0, 0, 1};
    for (int k = 0; k < 2; k++) {
        lm_frame_loop_settings set;
        lm_frame_loop_settings_default(&set);
        set.width = set.height = 32;
        set.stage.photons.total_photons = 5000;
        set.gather.tiles = 4; /* 16 texels per pass, chunks of 256 */
        if (k) {
            set.progress = log_progress;
            set.progress_user = &log;
        }
        lm_frame_loop *fl = NULL;
        lm_error err;
        if (lm_frame_loop_create(&p.w, &set, &fl, NULL, NULL, &err) != LM_OK)
            fail_msg("%s", err.msg);
        assert_int_equal(lm_frame_loop_read_iim(fl, &iim[k], &err), LM_OK);
        lm_frame_loop_free(fl);
    }
    print_message("%u texels gathered in %d chunks\n", log.total, log.calls);
    assert_true(log.calls > 1);
    assert_true(log.monotonic);
    assert_int_equal(log.last_done, log.total);
    assert_int_equal(log.total, p.atlas.texel_count);
    assert_memory_equal(iim[0], iim[1], sizeof(float) * 4 * (size_t)p.atlas.width * p.atlas.height);
    free(iim[0]);
    free(iim[1]);
    lmt_pipeline_free(&p);
}

/* The texels `lmgi run` reports on its "atlas" line. */
static unsigned atlas_texels(void)
{
    const char *line = strstr(output, "atlas ");
    unsigned w, h, n;
    if (!line || sscanf(line, "atlas %u x %u, %u texels", &w, &h, &n) != 3)
        fail_msg("no atlas line in: %s", output);
    return n;
}

/* Without a texel size, run sizes its atlas for its texel budget: about 90 frames' worth of texels
 * (LM_FRAME_LOOP_REFRESH_FRAMES), so that the IIM is regathered in full every 3 s; --texels and
 * --texel-size override it. */
static void test_atlas_follows_budget(void **state)
{
    (void)state;
    char dir[1024], args[2048];
    snprintf(dir, sizeof dir, "%s/budget", lmt_tmpdir());
    const int budgets[2] = {10, 40};
    for (int k = 0; k < 2; k++) {
        snprintf(args, sizeof args, "run scenes/cornell.glb --frames 1 --size 32x32 --photons 5000 "
                 "--texels-per-frame %d --out %s", budgets[k], dir);
        if (lmgi(args) != 0)
            fail_msg("lmgi run failed: %s", output);
        unsigned n = atlas_texels(), want = (unsigned)lm_frame_loop_atlas_texels(budgets[k]);
        print_message("--texels-per-frame %d: %u atlas texels (aimed at %u)\n", budgets[k], n, want);
        assert_int_equal(want, 90u * (unsigned)budgets[k]);
        assert_true(n > 0.75 * want && n < 1.25 * want);
    }
    snprintf(args, sizeof args, "run scenes/cornell.glb --frames 1 --size 32x32 --photons 5000 --texels 3000 "
             "--out %s", dir);
    assert_int_equal(lmgi(args), 0);
    assert_true(atlas_texels() > 2250 && atlas_texels() < 3750);
    snprintf(args, sizeof args, "run scenes/cornell.glb --frames 1 --size 32x32 --photons 5000 --texel-size 0.1 "
             "--out %s", dir);
    assert_int_equal(lmgi(args), 0);
    unsigned fixed = atlas_texels();
    assert_int_equal(lmgi("info scenes/cornell.glb --texel-size 0.1"), 0);
    char want[64];
    snprintf(want, sizeof want, "%u texels", fixed);
    assert_non_null(strstr(output, want));
}

static void test_bad_args(void **state)
{
    (void)state;
    assert_int_equal(lmgi("run scenes/cornell.glb --frames 2"), 2);
    assert_non_null(strstr(output, "--out"));
    assert_int_equal(lmgi("run --out /tmp/x"), 2);
    assert_int_equal(lmgi("run scenes/cornell.glb --out /tmp/x --texels-per-frame 0"), 2);
    assert_int_equal(lmgi("run scenes/cornell.glb --out /tmp/x --exr-every x"), 2);
    assert_int_equal(lmgi("run scenes/cornell.glb --out /tmp/x --gather-scheme bogus"), 2);
    assert_non_null(strstr(output, "viewports, instanced, layered or rays"));
    assert_int_equal(lmgi("run scenes/cornell.glb --out /tmp/x --hemicube 1"), 2);
    assert_int_equal(lmgi("run scenes/cornell.glb --out /tmp/x --hemicube-samples 2"), 2);
    assert_int_equal(lmgi("run scenes/cornell.glb --out /tmp/x --enlargement 0"), 2);
    assert_int_equal(lmgi("run scenes/cornell.glb --out /tmp/x --emitter-light bogus"), 2);
    assert_non_null(strstr(output, "closed or drawn"));
    assert_int_equal(lmgi("run scenes/cornell.glb --out /tmp/x --emitter-rays 0"), 2);
    assert_int_equal(lmgi("run scenes/cornell.glb --out /tmp/x --reflection-size -1"), 2);
    assert_int_equal(lmgi("run scenes/cornell.glb --out /tmp/x --reflection-faces 0"), 2);
    assert_int_equal(lmgi("run scenes/cornell.glb --out /tmp/x --texels 4"), 2);
    assert_non_null(strstr(output, "--texels"));
}

/* Inside a closed box of albedo 0.5 whose walls all emit Le = 1: every wall pixel of a frame shows
 * Le + rho / pi * E_IIM, which must reach Le / (1 - rho) = 2 within 3%. The camera sits inside. By
 * default the walls' 12 emissive triangles take the closed form (the summary says so); drawn into the
 * hemicubes instead, the result is the same. */
static void test_furnace_composite(void **state)
{
    (void)state;
    static lmt_mesh m;
    memset(&m, 0, sizeof m);
    lmt_mesh_cube_inward(&m, 1.0f);
    const char *extra = "\"materials\": [{\"pbrMetallicRoughness\": {\"baseColorFactor\": [0.5, 0.5, 0.5, 1],"
                        " \"metallicFactor\": 0, \"roughnessFactor\": 1}, \"emissiveFactor\": [1, 1, 1]}],"
                        " \"cameras\": [{\"type\": \"perspective\", \"perspective\": {\"yfov\": 1.2, \"znear\": 0.01,"
                        " \"aspectRatio\": 1}}],";
    const char *nodes = "[{\"mesh\": 0}, {\"camera\": 0, \"translation\": [0.2, 0.1, 0.7]}]";
    char tmp[1024], path[1100], args[4096], dir[1100];
    snprintf(tmp, sizeof tmp, "%s", lmt_tmpdir());
    snprintf(path, sizeof path, "%s/furnace.gltf", tmp);
    assert_int_equal(lmt_write_gltf(path, &m, 1, nodes, NULL, 0, extra), 0);
    lmt_use_material_0(path);
    for (int drawn = 0; drawn < 2; drawn++) {
        snprintf(dir, sizeof dir, "%s/fout%d", tmp, drawn);
        snprintf(args, sizeof args, "run %s --frames 1 --size 64x64 --texel-size 0.2 --photons 100000 %s --out %s",
                 path, drawn ? "-q --emitter-light drawn" : "", dir);
        if (lmgi(args) != 0)
            fail_msg("lmgi run failed: %s", output);
        if (!drawn)
            assert_non_null(strstr(output, "12 emissive triangles in closed form"));
        int w, h;
        float *px = read_exr(dir, "frame_0000.exr", &w, &h);
        double sum = 0.0, worst = 0.0;
        for (int i = 0; i < w * h; i++) {
            double L = px[4 * i + 1];
            sum += L;
            worst = fmax(worst, fabs(L / 2.0 - 1.0));
        }
        double mean = sum / (w * h);
        print_message("furnace composite, emitters %s: %d pixels, mean radiance %.4f (want 2, %+.2f%%), worst pixel "
                      "%.2f%%\n", drawn ? "drawn" : "in closed form", w * h, mean, 100.0 * (mean / 2.0 - 1.0),
                      100.0 * worst);
        assert_true(fabs(mean / 2.0 - 1.0) < 0.03);
        assert_true(worst < 0.03); /* every pixel is a wall: the camera is inside */
        free(px);
    }
}

/* Reflections (gpu/frame/reflections.h): a cube at the centre of a closed room whose walls emit Le = 1 and
 * reflect nothing, seen face on from inside; every pixel is the cube's front face reflecting the wall
 * behind the camera. A mirror of albedo 0.8 shows 0.8 Le; a glossy metal (albedo 0.8, roughness 0.3:
 * Phong n = 245, ks = 0.8, kd = 0) shows ks (n + 2) / (n + 1) (n.v) Le, 0.803 at the centre; a glass cube
 * (ior 1.5, tint 0.5 0.8 1) F Le + (1 - F) 0.8 Le in green, F = 0.04 face on: 0.808, and a clear one Le
 * (what it reflects and what it lets through add up: nothing lost, nothing gained); with
 * --reflection-size 0 the mirror is black. `flat`: the cube's front face alone, a flat reflector, which
 * shows the same through its mirrored picture of the view instead of a cube map. */
static void check_reflection(const char *material, const char *opts, int flat, double want)
{
    static lmt_mesh m[2];
    memset(m, 0, sizeof m);
    lmt_mesh_cube_inward(&m[0], 10.0f);
    if (flat)
        lmt_mesh_quad(&m[1], (float[3]){-1, -1, 1}, (float[3]){2, 0, 0}, (float[3]){0, 2, 0});
    else
        lmt_mesh_cube(&m[1], 1.0f);
    char materials[1024];
    snprintf(materials, sizeof materials,
             "[{\"pbrMetallicRoughness\": {\"baseColorFactor\": [0, 0, 0, 1]}, \"emissiveFactor\": [1, 1, 1]}, %s],"
             " \"cameras\": [{\"type\": \"perspective\", \"perspective\": {\"yfov\": 0.5, \"znear\": 0.01,"
             " \"aspectRatio\": 1}}], \"extensionsUsed\": [\"KHR_materials_transmission\", \"KHR_materials_ior\"]",
             material);
    const char *path = lmt_write_scene("mirror.gltf", m, 2, "[{\"mesh\": 0}, {\"mesh\": 1}, {\"camera\": 0, "
                                       "\"translation\": [0, 0, 4]}]", materials);
    char run_opts[1024];
    snprintf(run_opts, sizeof run_opts, "--size 32x32 --photons 20000 %s", opts);
    int w, h;
    char dir[1100];
    float *px = run_frame(path, "mirror_out", run_opts, dir, &w, &h);
    double centre = px[4 * ((h / 2) * w + w / 2) + 1], worst = 0.0;
    for (int i = 0; i < w * h; i++)
        worst = fmax(worst, px[4 * i + 1]);
    print_message("reflection (%s%s%s): centre %.4f (want %.4f), brightest %.4f\n", flat ? "flat" : "cube",
                  *opts ? ", " : "", opts, centre, want, worst);
    assert_true(fabs(centre - want) <= 0.02 * fmax(want, 0.05));
    assert_true(worst <= fmax(want, 0.0) * 1.02 + 1e-6);
    free(px);
}

/* A flat mirror (gpu/frame/reflections.h, "Flat reflectors"): a 4 x 4 m metal floor (albedo 0.8, roughness
 * 0) under a 0.6 m square emitter (Le = 1, facing down) 1 m above (0.5, 1, -0.5), seen from (0, 2, 3)
 * looking at the origin. Each pixel's expected value is ray-cast here: the eye ray to the floor, reflected,
 * meets the emitter's front (F Le, F the metal's Schlick Fresnel at the eye ray's angle) or the black sky
 * (0); pixels whose eye ray meets the emitter first, or misses the floor, are not compared. A cube map seen
 * from the floor's centre (the way before flat reflectors) puts the emitter's image about 1 m off (the
 * emitter is 1 m from the map's centre), so its lit pixels and the expected ones barely overlap. The
 * frame drew the floor's mirrored picture once and no cube map face (frames.csv). */
static void test_flat_mirror_image(void **state)
{
    (void)state;
    static lmt_mesh m[2];
    memset(m, 0, sizeof m);
    lmt_mesh_quad(&m[0], (float[3]){-2, 0, 2}, (float[3]){4, 0, 0}, (float[3]){0, 0, -4});
    lmt_mesh_quad(&m[1], (float[3]){0.2f, 1, -0.8f}, (float[3]){0.6f, 0, 0}, (float[3]){0, 0, 0.6f}); /* facing down */
    const double pitch = atan2(2.0, 3.0), yfov = 0.7; /* looking down at the origin */
    char nodes[512], materials[1024];
    snprintf(nodes, sizeof nodes, "[{\"mesh\": 0}, {\"mesh\": 1}, {\"camera\": 0, \"translation\": [0, 2, 3], "
             "\"rotation\": [%.9f, 0, 0, %.9f]}]", -sin(0.5 * pitch), cos(0.5 * pitch));
    snprintf(materials, sizeof materials, "[%s, {\"pbrMetallicRoughness\": {\"baseColorFactor\": [0, 0, 0, 1]}, "
             "\"emissiveFactor\": [1, 1, 1]}], \"cameras\": [{\"type\": \"perspective\", \"perspective\": "
             "{\"yfov\": %g, \"znear\": 0.01, \"aspectRatio\": 1}}]", LMT_MIRROR(0.8), yfov);
    const char *path = lmt_write_scene("flat_mirror.gltf", m, 2, nodes, materials);
    int w, h;
    char dir[1100];
    float *px = run_frame(path, "flat_mirror_out", "--size 64x64 --photons 20000", dir, &w, &h);
    assert_int_equal(csv_column_sum(dir, "planar_maps_rendered"), 1);
    assert_int_equal(csv_column_sum(dir, "cube_faces_rendered"), 0);
    int lit_both = 0, lit_want = 0, lit_got = 0, compared = 0;
    double ratio = 0.0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            double t = tan(0.5 * yfov), a = t * (2.0 * (x + 0.5) / w - 1.0), b = t * (1.0 - 2.0 * (y + 0.5) / h);
            /* the view ray (a, b, -1) pitched down about x */
            double d[3] = {a, b * cos(pitch) - sin(pitch), -b * sin(pitch) - cos(pitch)};
            double e[3] = {0.0, 2.0, 3.0};
            double te = (1.0 - e[1]) / d[1], ex = e[0] + te * d[0], ez = e[2] + te * d[2];
            if (te > 0.0 && ex > 0.2 && ex < 0.8 && ez > -0.8 && ez < -0.2)
                continue; /* the emitter's back, in front of the floor */
            double tf = -e[1] / d[1], fx = e[0] + tf * d[0], fz = e[2] + tf * d[2];
            if (!(tf > 0.0) || fabs(fx) > 1.95 || fabs(fz) > 1.95)
                continue;
            /* reflected: (d.x, -d.y, d.z) from the floor point, up to y = 1 */
            double tr = 1.0 / -d[1], rx = fx + tr * d[0], rz = fz + tr * d[2];
            double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            double want = rx > 0.2 && rx < 0.8 && rz > -0.8 && rz < -0.2
                              ? lmt_mirror_fresnel(0.8, 1.0 + d[1] / len) : 0.0;
            double got = px[4 * (y * w + x) + 1];
            compared++;
            lit_want += want > 0.4;
            lit_got += got > 0.4;
            if (want > 0.4 && got > 0.4) {
                lit_both++;
                ratio += got / want;
            }
        }
    free(px);
    int lit_any = lit_want + lit_got - lit_both;
    print_message("flat mirror: %d pixels compared, the emitter's image %d expected, %d drawn, %d both (overlap "
                  "%.3f), drawn / expected where both %.4f\n", compared, lit_want, lit_got, lit_both,
                  lit_any ? (double)lit_both / lit_any : 0.0, lit_both ? ratio / lit_both : 0.0);
    assert_true(compared > w * h / 2 && lit_want > 60);
    assert_true(lit_both >= 0.85 * lit_any); /* only the image's edge pixels may differ */
    assert_true(fabs(ratio / lit_both - 1.0) < 0.02);
}

/* The first hit of the ray o + t d on mesh m's triangles (-1: none), its shading normal into n: the vertex
 * normals vn (3 a vertex) interpolated and made unit, as the frame's pixel has it. */
static int first_triangle(const lmt_mesh *m, const double *vn, const double o[3], const double d[3], double n[3])
{
    int best = -1;
    double best_t = INFINITY;
    for (int t = 0; t < m->index_count / 3; t++) {
        const float *v[3];
        for (int k = 0; k < 3; k++)
            v[k] = m->pos + 3 * m->idx[3 * t + k];
        double e1[3], e2[3], q[3], s0[3], r[3];
        for (int k = 0; k < 3; k++)
            e1[k] = v[1][k] - v[0][k], e2[k] = v[2][k] - v[0][k], s0[k] = o[k] - v[0][k];
        q[0] = d[1] * e2[2] - d[2] * e2[1], q[1] = d[2] * e2[0] - d[0] * e2[2], q[2] = d[0] * e2[1] - d[1] * e2[0];
        double det = e1[0] * q[0] + e1[1] * q[1] + e1[2] * q[2];
        if (fabs(det) < 1e-12)
            continue;
        double u = (s0[0] * q[0] + s0[1] * q[1] + s0[2] * q[2]) / det;
        r[0] = s0[1] * e1[2] - s0[2] * e1[1], r[1] = s0[2] * e1[0] - s0[0] * e1[2], r[2] = s0[0] * e1[1] - s0[1] * e1[0];
        double w = (d[0] * r[0] + d[1] * r[1] + d[2] * r[2]) / det, t_hit = (e2[0] * r[0] + e2[1] * r[1] + e2[2] * r[2]) / det;
        if (u < 0.0 || w < 0.0 || u + w > 1.0 || t_hit <= 0.0 || t_hit >= best_t)
            continue;
        best = t, best_t = t_hit;
        double l = 0.0;
        for (int k = 0; k < 3; k++) {
            const double *n0 = vn + 3 * m->idx[3 * t], *n1 = vn + 3 * m->idx[3 * t + 1], *n2 = vn + 3 * m->idx[3 * t + 2];
            n[k] = (1.0 - u - w) * n0[k] + u * n1[k] + w * n2[k];
            l += n[k] * n[k];
        }
        for (int k = 0; k < 3; k++)
            n[k] /= sqrt(l);
    }
    return best;
}

/* A curved piece's one texel turns with the pixel's normal (docs/charts.md, "Turning with the normal"): a
 * cap of 48 triangles (half-angle 25 degrees, radius 0.5, facing +x) 0.6 m over a black 200 m floor under a
 * uniform sky of 1, at 2 m texels, so its chart is one texel gathered at its four footprint points. A point
 * of shading normal n (the glTF has none: each vertex's is the mean of its triangles', area-weighted, as the
 * loader makes them) gets E = pi (1 + n.y) / 2 (the floor hides the lower half of the directions), so the
 * frame should show 0.8 (1 + n.y) / 2, from 0.23 at the cap's bottom to 0.57 at its top. Compared on the
 * pixels whose neighbours see their triangle: the mean of |frame / that - 1| and the furthest triangle's
 * mean; and what one value for the piece would show (the pixels' mean everywhere). */
typedef struct {
    double mean, worst, flat_mean, flat_worst;
} piece_error;

static piece_error curved_piece_error(const char *opts)
{
    const double alpha = 25.0 * M_PI / 180.0, cy = 0.6;
    static lmt_mesh m[2];
    memset(m, 0, sizeof m);
    lmt_mesh_quad(&m[0], (float[3]){-100, 0, 100}, (float[3]){200, 0, 0}, (float[3]){0, 0, -200});
    lmt_mesh_cap(&m[1], alpha, 0.5, 0.0);
    for (int v = 0; v < m[1].vertex_count; v++) { /* (x, y, z) -> (y, cy - x, z): turned to face +x */
        float *p = m[1].pos + 3 * v, x = p[0];
        p[0] = p[1], p[1] = (float)cy - x;
    }
    const double eye[3] = {3.0, cy, 0.0}, yfov = 0.2, t = tan(0.5 * yfov);
    char nodes[512], materials[512], args[512];
    snprintf(nodes, sizeof nodes, "[{\"mesh\": 0}, {\"mesh\": 1}, {\"camera\": 0, \"translation\": [%g, %g, %g], "
             "\"rotation\": [0, %.9f, 0, %.9f]}]", eye[0], eye[1], eye[2], sqrt(0.5), sqrt(0.5)); /* looking along -x */
    snprintf(materials, sizeof materials, "[{\"pbrMetallicRoughness\": {\"baseColorFactor\": [0, 0, 0, 1], "
             "\"metallicFactor\": 0}}, {\"pbrMetallicRoughness\": {\"baseColorFactor\": [0.8, 0.8, 0.8, 1], "
             "\"metallicFactor\": 0}}], \"cameras\": [{\"type\": \"perspective\", \"perspective\": {\"yfov\": %g, "
             "\"znear\": 0.01, \"aspectRatio\": 1}}]", yfov);
    const char *path = lmt_write_scene("curved_piece.gltf", m, 2, nodes, materials);
    snprintf(args, sizeof args, "--size 64x64 --sky 1 --texel-size 2 %s", opts);
    int w, h;
    char dir[1100];
    float *px = run_frame(path, "curved_piece_out", args, dir, &w, &h);
    double vn[3 * 64] = {0.0};
    for (int k = 0; k < m[1].index_count; k += 3) { /* the loader's normals: area-weighted face normals */
        const float *v0 = m[1].pos + 3 * m[1].idx[k], *v1 = m[1].pos + 3 * m[1].idx[k + 1], *v2 = m[1].pos + 3 * m[1].idx[k + 2];
        double e1[3] = {v1[0] - v0[0], v1[1] - v0[1], v1[2] - v0[2]}, e2[3] = {v2[0] - v0[0], v2[1] - v0[1], v2[2] - v0[2]};
        double c[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
        for (int j = 0; j < 3; j++)
            for (int a = 0; a < 3; a++)
                vn[3 * m[1].idx[k + j] + a] += c[a];
    }
    for (int v = 0; v < m[1].vertex_count; v++) {
        double *n = vn + 3 * v, l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        for (int a = 0; a < 3; a++)
            n[a] /= l;
    }
    int *tri = malloc(sizeof(int) * (size_t)w * (size_t)h);
    double *want = malloc(sizeof(double) * (size_t)w * (size_t)h);
    assert_non_null(tri);
    assert_non_null(want);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) { /* the view ray: forward -x, right -z, up +y */
            double a = t * (2.0 * (x + 0.5) / w - 1.0), b = t * (1.0 - 2.0 * (y + 0.5) / h), d[3] = {-1.0, b, -a},
                   n[3] = {0.0, 0.0, 0.0};
            tri[y * w + x] = first_triangle(&m[1], vn, eye, d, n);
            want[y * w + x] = 0.8 * (1.0 + n[1]) / 2.0;
        }
    enum { TRIS = 48 };
    double got_sum = 0.0, err_sum = 0.0, tri_got[TRIS] = {0}, tri_want[TRIS] = {0};
    int compared = 0, tri_px[TRIS] = {0};
    for (int y = 1; y + 1 < h; y++)
        for (int x = 1; x + 1 < w; x++) {
            int i = y * w + x, f = tri[i];
            if (f < 0 || tri[i - 1] != f || tri[i + 1] != f || tri[i - w] != f || tri[i + w] != f)
                continue;
            err_sum += fabs(px[4 * i] / want[i] - 1.0);
            got_sum += px[4 * i];
            tri_got[f] += px[4 * i], tri_want[f] += want[i], tri_px[f]++;
            compared++;
        }
    assert_true(compared > 300);
    piece_error e = {err_sum / compared, 0.0, 0.0, 0.0};
    double flat = got_sum / compared; /* about the one value the piece would show */
    for (int f = 0; f < TRIS; f++)
        if (tri_px[f] >= 3) {
            e.worst = fmax(e.worst, fabs(tri_got[f] / tri_want[f] - 1.0));
            e.flat_worst = fmax(e.flat_worst, fabs(flat * tri_px[f] / tri_want[f] - 1.0));
            e.flat_mean += fabs(flat * tri_px[f] / tri_want[f] - 1.0) * tri_px[f] / compared;
        }
    print_message("curved piece (%s): %d pixels; mean |frame / analytic - 1| %.4f, furthest triangle %.4f; one value "
                  "for the piece: %.4f and %.4f\n", opts, compared, e.mean, e.worst, e.flat_mean, e.flat_worst);
    free(tri);
    free(want);
    free(px);
    return e;
}

/* The cap at the defaults (on this machine the hemicube, whose plane meets the horizon differently at each
 * point: the turn leans 0.1 sideways) within 4% on the mean and 8% on its furthest triangle; with the rays
 * gather's 1,600 strata (400 a point) within 1% and 2%. One value for the piece is 18% off on the mean and
 * 43% on its furthest triangle. Measured: 2.2% and 4.6%; 0.2% and 0.5%. */
static void test_curved_piece_turns(void **state)
{
    (void)state;
    piece_error e = curved_piece_error("");
    assert_true(e.mean < 0.04 && e.worst < 0.08);
    assert_true(e.flat_mean > 0.10 && e.flat_worst > 0.3); /* what the turn is for */
    e = curved_piece_error("--gather-scheme rays --gather-rays 1600");
    assert_true(e.mean < 0.01 && e.worst < 0.02);
}

/* A flat mirror shows the caustic it throws (the caustic pass runs over its mirrored picture too): the
 * caustic tests' scene (support.h, lmt_mirror_scene: a point light at (0, 2, 0), a 0.5 m vertical mirror
 * of albedo 0.9 at x = 1 facing -x, a diffuse floor of albedo 0.8) seen from (-0.5, 3, 0) looking at
 * (0.5, 0.5, 0), where both the floor's focal spot and its image in the mirror are in view. Per pixel the
 * caustic is the frame with caustics less the frame without (--effects -caustics). Where the eye ray meets
 * the floor, the expected caustic is 0.8 / pi x E(q), E the virtual light's irradiance
 * (lmt_mirror_image); where it meets the mirror, F x 0.8 / pi x E(q) at the floor point q the reflected ray
 * meets. Each sum within 15% of what is expected, so the mirror's image of the spot as bright as the spot
 * (measured: floor 1.012, mirror 0.963; the mirror 0.000 without the caustic pass over its picture). */
static void test_flat_mirror_shows_caustic(void **state)
{
    (void)state;
    static lmt_mesh m[2];
    memset(m, 0, sizeof m);
    lmt_mesh_quad(&m[0], (float[3]){-4, 0, 4}, (float[3]){8, 0, 0}, (float[3]){0, 0, -8});
    lmt_mesh_quad(&m[1], (float[3]){1, 0.75f, -0.25f}, (float[3]){0, 0, 0.5f}, (float[3]){0, 0.5f, 0});
    const double eye[3] = {-0.5, 3.0, 0.0}, pitch = atan2(2.5, 1.0), yfov = 0.9, s45 = sqrt(0.5);
    /* turned to look along +x, then pitched down: forward (cos, -sin, 0), up (sin, cos, 0), right +z */
    const double sp = sin(0.5 * pitch), cp = cos(0.5 * pitch);
    char nodes[512], materials[1024];
    snprintf(nodes, sizeof nodes, "[{\"mesh\": 0}, {\"mesh\": 1}, {\"translation\": [0, 2, 0], \"extensions\": "
             "{\"KHR_lights_punctual\": {\"light\": 0}}}, {\"camera\": 0, \"translation\": [%g, %g, %g], "
             "\"rotation\": [%.9f, %.9f, %.9f, %.9f]}]", eye[0], eye[1], eye[2], -s45 * sp, -s45 * cp, -s45 * sp,
             s45 * cp);
    snprintf(materials, sizeof materials, "[" LMT_DIFFUSE(0.8) ", " LMT_MIRROR(0.9) "], \"cameras\": [{\"type\": "
             "\"perspective\", \"perspective\": {\"yfov\": %g, \"znear\": 0.01, \"aspectRatio\": 1}}], "
             LMT_LIGHTS("{\"type\": \"point\", \"intensity\": 10}"), yfov);
    const char *path = lmt_write_scene("mirror_caustic.gltf", m, 2, nodes, materials);
    float *px[2];
    int w = 0, h = 0;
    char dir[1100];
    for (int on = 0; on < 2; on++)
        px[on] = run_frame(path, on ? "mirror_caustic_on" : "mirror_caustic_off",
                           on ? "--size 96x96 --photons 40000 --caustic-photons 65536"
                              : "--size 96x96 --photons 40000 --caustic-photons 65536 --effects -caustics",
                           dir, &w, &h);
    double got[2] = {0.0, 0.0}, want[2] = {0.0, 0.0}; /* the floor's, the mirror's */
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            double t = tan(0.5 * yfov), a = t * (2.0 * (x + 0.5) / w - 1.0), b = t * (1.0 - 2.0 * (y + 0.5) / h);
            double d[3] = {cos(pitch) + b * sin(pitch), -sin(pitch) + b * cos(pitch), a};
            double tm = (1.0 - eye[0]) / d[0], my = eye[1] + tm * d[1], mz = eye[2] + tm * d[2];
            int mirror = my > 0.75 && my < 1.25 && fabs(mz) < 0.25, inside;
            if (mirror && (my < 0.78 || my > 1.22 || fabs(mz) > 0.22))
                continue; /* the mirror's rim pixels: partly floor */
            /* the floor point the pixel shows, seen directly or in the mirror (reflected about x = 1) */
            double o[3] = {eye[0], eye[1], eye[2]}, r[3] = {d[0], d[1], d[2]};
            if (mirror)
                o[0] = 1.0, o[1] = my, o[2] = mz, r[0] = -d[0];
            double tf = -o[1] / r[1], e = lmt_mirror_image(o[0] + tf * r[0], o[2] + tf * r[2], &inside);
            double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            double f = mirror ? lmt_mirror_fresnel(0.9, 1.0 - d[0] / len) : 1.0;
            want[mirror] += inside ? f * 0.8 / M_PI * e : 0.0;
            const float *p1 = px[1] + 4 * (y * w + x), *p0 = px[0] + 4 * (y * w + x);
            got[mirror] += (p1[0] + p1[1] + p1[2] - p0[0] - p0[1] - p0[2]) / 3.0;
        }
    free(px[0]);
    free(px[1]);
    print_message("caustic seen directly: %.4f of the expected (%.2f); in the flat mirror: %.4f (%.2f)\n",
                  got[0] / want[0], want[0], got[1] / want[1], want[1]);
    assert_true(want[0] > 1.0 && want[1] > 1.0);
    assert_true(fabs(got[0] / want[0] - 1.0) < 0.15 && fabs(got[1] / want[1] - 1.0) < 0.15);
}

/* A node flattened by a zero scale (glTF allows it; animations hide nodes so): a static one makes zero-area
 * triangles with NaN normals, whose photons must not hand Embree a NaN ray; a dynamic one an instance
 * without an inverse, which Embree cannot take a ray into (it aborted the process): left out of the rays.
 * The frame is finite either way. */
static void test_flattened_node(void **state)
{
    (void)state;
    static lmt_mesh m[2];
    memset(m, 0, sizeof m);
    lmt_mesh_quad(&m[0], (float[3]){-2, 0, 2}, (float[3]){4, 0, 0}, (float[3]){0, 0, -4});
    lmt_mesh_cube(&m[1], 0.5f);
    const char *materials = "[{}, {}], \"extensionsUsed\": [\"KHR_lights_punctual\"], \"extensions\": "
                            "{\"KHR_lights_punctual\": {\"lights\": [{\"type\": \"point\", \"intensity\": 10}]}}";
    for (int dynamic = 0; dynamic < 2; dynamic++) {
    char nodes[512];
    snprintf(nodes, sizeof nodes, "[{\"mesh\": 0}, {\"mesh\": 1, \"scale\": [1, 1, 0], \"translation\": [0, 0.5, 0]%s}, "
             "{\"translation\": [0, 2, 0], \"extensions\": {\"KHR_lights_punctual\": {\"light\": 0}}}]",
             dynamic ? ", \"extras\": {\"lmgi\": {\"dynamic\": true}}" : "");
    const char *path = lmt_write_scene("flat.gltf", m, 2, nodes, materials);
    char args[4096], dir[1100];
    snprintf(dir, sizeof dir, "%s/flat_out", lmt_tmpdir());
    snprintf(args, sizeof args, "run %s --frames 2 --size 32x32 --photons 20000 -q --out %s", path, dir);
    if (lmgi(args) != 0)
        fail_msg("lmgi run failed: %s", output);
    int w, h;
    float *px = read_exr(dir, "frame_0000.exr", &w, &h);
    double sum = 0.0;
    for (int i = 0; i < 4 * w * h; i++) {
        assert_true(isfinite(px[i]));
        sum += px[i];
    }
    assert_true(sum > 0.0);
    free(px);
    }
}

/* Mean of an EXR's colour channels. */
static double frame_mean(const char *dir, const char *file)
{
    int w, h;
    float *px = read_exr(dir, file, &w, &h);
    double sum = 0.0;
    for (int i = 0; i < 4 * w * h; i++)
        if (i % 4 != 3)
            sum += px[i];
    free(px);
    return sum / (3.0 * w * h);
}

/* The mean of a lightmap's valid texels (alpha 1): not of its free space, which depends on the layout. */
static double lightmap_mean(const char *dir, const char *file)
{
    int w, h;
    float *px = read_exr(dir, file, &w, &h);
    double sum = 0.0, n = 0.0;
    for (int i = 0; i < w * h; i++)
        if (px[4 * i + 3] > 0.0f) {
            sum += px[4 * i] + px[4 * i + 1] + px[4 * i + 2];
            n += 3.0;
        }
    free(px);
    return n > 0.0 ? sum / n : 0.0;
}

/* A floor (mesh 0) and a box (mesh 1), both diffuse, one point light (light 0) and a camera (camera 0),
 * placed by `nodes`, written as NAME.gltf and run for 2 frames at 48 x 48: the second frame's mean and
 * the IIM's. */
static void run_floor_and_box(const char *name, const char *nodes, double *frame, double *iim)
{
    static lmt_mesh m[2];
    memset(m, 0, sizeof m);
    lmt_mesh_quad(&m[0], (float[3]){-2, 0, 2}, (float[3]){4, 0, 0}, (float[3]){0, 0, -4});
    lmt_mesh_cube(&m[1], 0.5f);
    const char *materials = "[{\"pbrMetallicRoughness\": {\"metallicFactor\": 0}}, "
                            "{\"pbrMetallicRoughness\": {\"metallicFactor\": 0}}], \"extensionsUsed\": "
                            "[\"KHR_lights_punctual\"], \"extensions\": {\"KHR_lights_punctual\": {\"lights\": "
                            "[{\"type\": \"point\", \"intensity\": 10}]}}, \"cameras\": [{\"type\": \"perspective\", "
                            "\"perspective\": {\"yfov\": 1.0, \"znear\": 0.01}}]";
    char file[64], dir[1100], args[4096];
    snprintf(file, sizeof file, "%s.gltf", name);
    const char *path = lmt_write_scene(file, m, 2, nodes, materials);
    snprintf(dir, sizeof dir, "%s/%s_out", lmt_tmpdir(), name);
    snprintf(args, sizeof args, "run %s --frames 2 --size 48x48 --photons 20000 --exr-every 1 -q --out %s", path, dir);
    if (lmgi(args) != 0)
        fail_msg("lmgi run failed: %s", output);
    *frame = frame_mean(dir, "frame_0001.exr");
    *iim = lightmap_mean(dir, "iim.exr");
}

/* glTF: a negative determinant turns a node's triangles over. A floor and a dynamic box, symmetric about
 * x = 0, mirrored in x (static floor and the box's Embree instance alike), must light as they do unmirrored
 * (before, the mirrored walls of the generated Cornell box rendered black). */
static void test_mirrored_nodes(void **state)
{
    (void)state;
    double mean[2], iim[2];
    for (int mirrored = 0; mirrored < 2; mirrored++) {
        const char *s = mirrored ? "-1" : "1";
        char nodes[512], name[32];
        snprintf(nodes, sizeof nodes, "[{\"mesh\": 0, \"scale\": [%s, 1, 1]}, {\"mesh\": 1, \"scale\": [%s, 1, 1], "
                 "\"translation\": [0, 0.5, 0], \"extras\": {\"lmgi\": {\"dynamic\": true}}}, "
                 "{\"translation\": [0.3, 2, 0.2], \"extensions\": {\"KHR_lights_punctual\": {\"light\": 0}}}, "
                 "{\"translation\": [0, 1.5, 3], \"rotation\": [-0.2588, 0, 0, 0.9659], \"camera\": 0}]", s, s);
        snprintf(name, sizeof name, "mirror%d", mirrored);
        run_floor_and_box(name, nodes, &mean[mirrored], &iim[mirrored]);
    }
    print_message("mirrored nodes: frame mean %.4f unmirrored, %.4f mirrored; IIM %.4f, %.4f\n", mean[0],
                  mean[1], iim[0], iim[1]);
    assert_true(mean[0] > 0.05 && iim[0] > 0.01);
    assert_float_equal(mean[1] / mean[0], 1.0, 0.03);
    assert_float_equal(iim[1] / iim[0], 1.0, 0.03);
}

/* --out: a directory holding someone else's files is refused (--force writes there), a second run
 * replaces the first's frames without leaving the extra ones, and a run that cannot write (here past a
 * file-size limit, as on a full disk) stops at the first file, names it and leaves nothing truncated. */
static void test_output_dir(void **state)
{
    (void)state;
    char dir[1024], args[2048], keep[1200];
    snprintf(dir, sizeof dir, "%s/theirs", lmt_tmpdir());
    snprintf(keep, sizeof keep, "%s/notes.txt", dir);
    assert_int_equal(lm_mkdir_p(dir, &(lm_error){0}), LM_OK);
    FILE *f = fopen(keep, "w");
    assert_non_null(f);
    fputs("mine", f);
    fclose(f);
    const char *quick = "run scenes/cornell.glb --size 32x32 --texel-size 0.1 --photons 5000 -q";
    snprintf(args, sizeof args, "%s --frames 3 --out %s", quick, dir);
    assert_int_equal(lmgi(args), 1);
    assert_non_null(strstr(output, "notes.txt"));
    assert_non_null(strstr(output, "--force"));
    assert_false(exists(dir, "frame_0000.png"));
    snprintf(args, sizeof args, "%s --frames 3 --out %s --force", quick, dir);
    assert_int_equal(lmgi(args), 0);
    assert_true(exists(dir, "frame_0002.png"));
    snprintf(args, sizeof args, "%s --frames 1 --out %s", quick, dir); /* marked now: no --force needed */
    assert_int_equal(lmgi(args), 0);
    assert_true(exists(dir, "frame_0000.png") && exists(dir, "notes.txt"));
    assert_false(exists(dir, "frame_0001.png") || exists(dir, "frame_0002.png"));

    snprintf(dir, sizeof dir, "%s/full", lmt_tmpdir());
    snprintf(args, sizeof args, "run scenes/cornell.glb --size 128x128 --texel-size 0.1 --photons 5000 -q "
             "--frames 3 --out %s", dir);
    assert_int_equal(lmgi_after("ulimit -f 100; ", args), 1); /* 50 or 100 KB: a frame's EXR does not fit */
    print_message("past the file-size limit: %s", output);
    assert_non_null(strstr(output, "frame_0000.exr"));
    assert_non_null(strstr(output, "write failed"));
    assert_false(exists(dir, "frame_0000.exr") || exists(dir, "frame_0000.exr.partial"));
    assert_false(exists(dir, "frame_0001.png"));
}

/* 1,000 point lights took 13.5 GB of shadow maps: all maps together now stay within a budget, each made
 * smaller (and the run says so) when many lights share it. 30 point lights at 512 a face would take
 * 360 MB: they get 256. */
static void test_many_lights_share_shadow_maps(void **state)
{
    (void)state;
    static lmt_mesh m;
    memset(&m, 0, sizeof m);
    lmt_mesh_quad(&m, (float[3]){-2, 0, 2}, (float[3]){4, 0, 0}, (float[3]){0, 0, -4});
    const char *materials = "[{\"pbrMetallicRoughness\": {\"metallicFactor\": 0}}], \"extensionsUsed\": "
                            "[\"KHR_lights_punctual\"], \"extensions\": {\"KHR_lights_punctual\": {\"lights\": "
                            "[{\"type\": \"point\", \"intensity\": 0.5}]}}";
    char nodes[8192];
    int at = snprintf(nodes, sizeof nodes, "[{\"mesh\": 0}");
    for (int i = 0; i < 30; i++)
        at += snprintf(nodes + at, sizeof nodes - (size_t)at, ", {\"translation\": [%g, 1.5, %g], \"extensions\": "
                       "{\"KHR_lights_punctual\": {\"light\": 0}}}", -1.5 + 0.5 * (i % 6), -1.0 + 0.5 * (i / 6));
    snprintf(nodes + at, sizeof nodes - (size_t)at, "]");
    const char *path = lmt_write_scene("lights30.gltf", &m, 1, nodes, materials);
    char dir[1100], args[4096];
    snprintf(dir, sizeof dir, "%s/lights30", lmt_tmpdir());
    snprintf(args, sizeof args, "run %s --frames 1 --size 32x32 --photons 20000 --exr-every 1 --out %s", path, dir);
    assert_int_equal(lmgi(args), 0);
    assert_non_null(strstr(output, "30 lights: shadow maps of 256 (cube faces)"));
    assert_true(frame_mean(dir, "frame_0000.exr") > 0.0);
}

/* The same room 1e7 units from the origin renders as it does at the origin (it rendered black: float keeps
 * 24 bits, so rays' offsets and depths there lost every digit; lmgi now works relative to the scene). */
static void test_far_from_origin(void **state)
{
    (void)state;
    double mean[2], iim[2];
    for (int far = 0; far < 2; far++) {
        char nodes[1024], name[32];
        snprintf(nodes, sizeof nodes, "[{\"children\": [1, 2, 3, 4], \"translation\": [%s]}, {\"mesh\": 0}, "
                 "{\"mesh\": 1, \"translation\": [0, 0.5, 0]}, {\"translation\": [0.3, 2, 0.2], \"extensions\": "
                 "{\"KHR_lights_punctual\": {\"light\": 0}}}, {\"translation\": [0, 1.5, 3], "
                 "\"rotation\": [-0.2588, 0, 0, 0.9659], \"camera\": 0}]", far ? "1e7, 1e7, -1e7" : "0, 0, 0");
        snprintf(name, sizeof name, "far%d", far);
        run_floor_and_box(name, nodes, &mean[far], &iim[far]);
    }
    print_message("far from the origin: frame mean %.4f at the origin, %.4f at 1e7; IIM %.4f, %.4f\n", mean[0],
                  mean[1], iim[0], iim[1]);
    assert_true(mean[0] > 0.05);
    assert_float_equal(mean[1] / mean[0], 1.0, 0.01);
    assert_float_equal(iim[1] / iim[0], 1.0, 0.01);
}

static void test_reflections(void **state)
{
    (void)state;
    const char *mirror = "{\"pbrMetallicRoughness\": {\"baseColorFactor\": [0.8, 0.8, 0.8, 1], \"metallicFactor\": 1,"
                         " \"roughnessFactor\": 0}}";
    const char *glossy = "{\"pbrMetallicRoughness\": {\"baseColorFactor\": [0.8, 0.8, 0.8, 1], \"metallicFactor\": 1,"
                         " \"roughnessFactor\": 0.3}}";
    double n = 2.0 / (0.3 * 0.3 * 0.3 * 0.3) - 2.0;
    for (int flat = 0; flat < 2; flat++) {
        check_reflection(mirror, "", flat, 0.8);
        check_reflection(glossy, "", flat, 0.8 * (n + 2.0) / (n + 1.0));
        check_reflection(mirror, "--reflection-size 0", flat, 0.0);
    }
    const char *glass = "{\"pbrMetallicRoughness\": {\"baseColorFactor\": [0.5, 0.8, 1, 1], \"metallicFactor\": 0},"
                        " \"extensions\": {\"KHR_materials_transmission\": {\"transmissionFactor\": 1},"
                        " \"KHR_materials_ior\": {\"ior\": 1.5}}}";
    const char *clear = "{\"pbrMetallicRoughness\": {\"metallicFactor\": 0},"
                        " \"extensions\": {\"KHR_materials_transmission\": {\"transmissionFactor\": 1}}}";
    check_reflection(glass, "", 0, 0.04 + 0.96 * 0.8);
    check_reflection(clear, "", 0, 1.0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_writes_files),
        cmocka_unit_test(test_deterministic),
        cmocka_unit_test(test_gather_options),
        cmocka_unit_test(test_overlap_against_order),
        cmocka_unit_test(test_setup_progress),
        cmocka_unit_test(test_atlas_follows_budget),
        cmocka_unit_test(test_run_budget_in_csv),
        cmocka_unit_test(test_bad_args),
        cmocka_unit_test(test_furnace_composite),
        cmocka_unit_test(test_reflections),
        cmocka_unit_test(test_flat_mirror_image),
        cmocka_unit_test(test_curved_piece_turns),
        cmocka_unit_test(test_flat_mirror_shows_caustic),
        cmocka_unit_test(test_flattened_node),
        cmocka_unit_test(test_mirrored_nodes),
        cmocka_unit_test(test_output_dir),
        cmocka_unit_test(test_far_from_origin),
        cmocka_unit_test(test_many_lights_share_shadow_maps),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
