/* lmgi view as a person uses it (issue 35): in a window on an X server (Xvfb, by xvfb-run), with keys
 * pressed by xdotool. Its picture from the scene's camera is lmgi run's frame; a light switched off from
 * the keyboard darkens the next frame; an edit script plays at its frames; P writes the window as shown;
 * and where there is no display it fails with a message, not a crash. Skipped with a message where xvfb-run
 * or xdotool is absent (make deps installs both). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <lmgi.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../src/core/image.h"
#include "support.h"

#define SIZE "96x72"

static char output[65536];

static int have_x_tools(void)
{
    if (access("/usr/bin/xvfb-run", X_OK) == 0 && access("/usr/bin/xdotool", X_OK) == 0)
        return 1;
    print_message("skipped: xvfb-run or xdotool is absent (make deps installs xvfb and xdotool)\n");
    return 0;
}

static const char *lmgi_bin(void)
{
    static char path[512];
    const char *build = getenv("LMGI_BUILD");
    snprintf(path, sizeof path, "%s/lmgi", build ? build : "build");
    return path;
}

/* How much longer the scripts wait for the window's work: 4 under the sanitizers (make test-asan builds
 * this test and lmgi alike), whose updates are several times slower, else 1. */
static int slow(void) { return LMT_UNDER_ASAN ? 4 : 1; }

/* Shell functions for the scripts: `C=$(caught)` counts the viewer's "lighting: caught up" lines in its log
 * (log.txt; view prints "catching up" when an update starts work on an edit and "caught up" when the work
 * is done), and `settled $C`, after an edit, waits until a new one has come and is the log's last word on
 * the lighting. The viewer says "caught up" only once a whole round of the round robin has passed since the
 * last change (every stored photon re-checked: photons per group / --retrace updates, 640 at the defaults on
 * these scenes): the scripts re-trace 16 a group an update, a round of 40 updates. */
#define IDLE_FN                                                                                               \
    "caught() { grep -c 'caught up' log.txt || true; }\n"                                                    \
    "settled() { n=0; while :; do k=$(caught); last=$(grep '^lighting' log.txt | tail -1);\n"                \
    "  case \"$last\" in *'caught up'*) if [ \"$k\" -gt \"$1\" ]; then return 0; fi;; esac\n"                 \
    "  sleep 0.1; n=$((n + 1)); if [ $n -gt $((1200 * F)) ]; then echo 'never caught up'; exit 1; fi; done; }\n"

/* The scripts end the viewer with Esc and then take its exit status (wait): xdotool itself may report a
 * BadWindow when the viewer has already closed the window it sent Esc to (Xlib reports errors late), so its
 * own status on that last key is not the test's. */

/* Runs `sh -c SCRIPT` under a fresh Xvfb; its exit status. */
static int under_x(const char *script)
{
    char path[512], cmd[1024];
    snprintf(path, sizeof path, "%s/view_test.sh", lmt_tmpdir());
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fprintf(f, "%s\n", script);
    fclose(f);
    /* -a tries the next display number while one is taken; starting from one of this process's own keeps
     * two runs side by side (make test and make test-asan) from picking the same free one at once */
    snprintf(cmd, sizeof cmd, "xvfb-run -a -n %d -s '-screen 0 320x240x24 -nolisten tcp' sh %s 2>&1",
             100 + (int)(getpid() % 800), path);
    return lmt_run(cmd, output, sizeof output);
}

/* Mean luminance (sum of the channels) of an EXR's pixels, and the picture itself into *img (NULL: not
 * kept). */
/* What the window printed (log.txt in dir), as one string to free. */
static char *window_log(const char *dir)
{
    char path[512];
    snprintf(path, sizeof path, "%s/log.txt", dir);
    size_t size = 0;
    char *text = (char *)lmt_read_file(path, &size, 1);
    text[size] = '\0';
    return text;
}

static double mean_of(const char *path, float **img, int *w, int *h)
{
    float *p = NULL;
    lm_error err;
    if (lm_read_exr(path, w, h, &p, &err) != LM_OK)
        fail_msg("%s: %s", path, err.msg);
    double sum = 0.0;
    for (size_t i = 0; i < (size_t)*w * (size_t)*h; i++)
        sum += (double)p[4 * i] + p[4 * i + 1] + p[4 * i + 2];
    if (img)
        *img = p;
    else
        free(p);
    return sum / ((double)*w * *h);
}

/* scenes/cornell.glb loaded with the defaults (the test holds it; lmgi_free). */
static lmgi_scene *generated_cornell(void)
{
    lmgi_options o;
    lmgi_options_init(&o);
    lmgi_scene *sc = NULL;
    lmgi_error e;
    if (lmgi_load("scenes/cornell.glb", &o, &sc, &e) != LMGI_OK)
        fail_msg("%s", e.message);
    return sc;
}

static void test_no_display(void **state)
{
    (void)state;
    int rc = lmt_lmgi("env -u DISPLAY -u WAYLAND_DISPLAY ", "view scenes/cornell.glb", output, sizeof output);
    print_message("without a display: exit %d, \"%.120s\"\n", rc, output);
    assert_int_equal(rc, 1);
    assert_non_null(strstr(output, "needs a display"));
}

/* The shared Cornell box is still, so its lighting is whole from the first frame on: the window's picture
 * from the scene's camera (--screenshot, the linear numbers) is lmgi run's frame 0, within 1% on average
 * and 5% on 99% of the pixels (the camera made again from the scene's and the picture drawn by lmgi_render
 * rather than the update's composite). A second --screenshot to the same file is refused, the file kept;
 * with --force it is written. */
static void test_picture_is_run_frame(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(scene, lmt_shared_scene("cornell-box/CornellBox.glb"));
    if (!have_x_tools())
        return;
    char dir[64]; /* lmt_tmpdir's buffer is its next call's */
    snprintf(dir, sizeof dir, "%s", lmt_tmpdir());
    char script[4096];
    snprintf(script, sizeof script,
             "rm -rf %s/vrun %s/view.exr && %s run %s --frames 1 --size " SIZE " --out %s/vrun -q && "
             "%s view %s --frames 3 --size " SIZE " --screenshot %s/view.exr -q && D=%s && cp $D/view.exr $D/kept.exr && "
             "! %s view %s --frames 1 --size " SIZE " --screenshot $D/view.exr -q 2> $D/refused.txt && "
             "cmp $D/view.exr $D/kept.exr && %s view %s --frames 1 --size " SIZE " --screenshot $D/view.exr --force -q",
             dir, dir, lmgi_bin(), scene, dir, lmgi_bin(), scene, dir, dir, lmgi_bin(), scene, lmgi_bin(), scene);
    int rc = under_x(script);
    if (rc != 0)
        fail_msg("exit %d: %s", rc, output);
    /* the second screenshot over the first was refused (the file kept), the third forced */
    char refused[512];
    snprintf(refused, sizeof refused, "%s/refused.txt", dir);
    FILE *rf = fopen(refused, "r");
    assert_non_null(rf);
    char said[512] = "";
    assert_non_null(fgets(said, sizeof said, rf));
    fclose(rf);
    assert_non_null(strstr(said, "exists"));
    assert_non_null(strstr(said, "--force"));
    char a[512], b[512];
    snprintf(a, sizeof a, "%s/view.exr", dir);
    snprintf(b, sizeof b, "%s/vrun/frame_0000.exr", dir);
    float *pa, *pb;
    int w, h, w2, h2;
    double ma = mean_of(a, &pa, &w, &h), mb = mean_of(b, &pb, &w2, &h2);
    assert_int_equal(w, w2);
    assert_int_equal(h, h2);
    int n = 0, off = 0;
    for (size_t i = 0; i < (size_t)w * h; i++) {
        double x = (double)pa[4 * i] + pa[4 * i + 1] + pa[4 * i + 2], y = (double)pb[4 * i] + pb[4 * i + 1] + pb[4 * i + 2];
        if (y <= 0.0)
            continue;
        n++;
        off += fabs(x / y - 1.0) > 0.05;
    }
    print_message("view against run, the shared Cornell box at " SIZE ": mean %.5g / %.5g (%+.3f%%), %d of %d "
                  "pixels more than 5%% apart\n", ma, mb, 100.0 * (ma / mb - 1.0), off, n);
    assert_true(fabs(ma / mb - 1.0) < 0.01);
    assert_true(off <= n / 100);
    free(pa);
    free(pb);
}

/* The generated Cornell box's one light switched off from the keyboard (O), then Esc: the frame drawn after
 * them (the screenshot) has no direct light, and whatever indirect light has not caught up yet: well under
 * half of what the same frames show with the light on. P writes the window as it is, panel and all, to
 * lmgi-view-001.png in the working folder. */
static void test_keys_switch_light_off(void **state)
{
    (void)state;
    if (!have_x_tools())
        return;
    char dir[64]; /* lmt_tmpdir's buffer is its next call's */
    snprintf(dir, sizeof dir, "%s", lmt_tmpdir());
    char script[2048], cwd[1024];
    assert_non_null(getcwd(cwd, sizeof cwd));
    /* the binary and the scene by absolute paths: the screenshots land in the test's folder */
    snprintf(script, sizeof script,
             "set -e; B=$(cd %s && pwd)/lmgi; S=%s/scenes/cornell.glb; cd %s; rm -f on.exr off.exr lmgi-view-*.png\n"
             "$B view $S --size " SIZE " --frames 2 --screenshot on.exr -q\n"
             "$B view $S --size " SIZE " --screenshot off.exr -q &\n"
             "P=$!; W=$(xdotool search --sync --name 'lmgi view')\n"
             "sleep 1; xdotool key --window $W p; sleep 1; xdotool key --window $W o Escape || true\n"
             "wait $P",
             getenv("LMGI_BUILD") ? getenv("LMGI_BUILD") : "build", cwd, dir);
    int rc = under_x(script);
    if (rc != 0)
        fail_msg("exit %d: %s", rc, output);
    char on[512], off[512], shot[512];
    snprintf(on, sizeof on, "%s/on.exr", dir);
    snprintf(off, sizeof off, "%s/off.exr", dir);
    snprintf(shot, sizeof shot, "%s/lmgi-view-001.png", dir);
    int w, h;
    double m_on = mean_of(on, NULL, &w, &h), m_off = mean_of(off, NULL, &w, &h);
    print_message("light on %.5g, switched off by its key %.5g (%.1f%%)\n", m_on, m_off, 100.0 * m_off / m_on);
    assert_true(m_on > 0.0);
    assert_true(m_off < 0.5 * m_on);
    assert_int_equal(access(shot, R_OK), 0);
}

/* An edit script (the format of lmgi bench --edits) halves the light at frame 2 of 4: the last frame's direct
 * light is half, its indirect light on its way down: between 45% and 85% of the unedited frame's. */
static void test_script(void **state)
{
    (void)state;
    if (!have_x_tools())
        return;
    lmgi_scene *sc = generated_cornell();
    lmgi_error e;
    lmgi_light l;
    assert_int_equal(lmgi_get_light(sc, 0, &l, &e), LMGI_OK);
    lmgi_free(sc);
    char dir[64]; /* lmt_tmpdir's buffer is its next call's */
    snprintf(dir, sizeof dir, "%s", lmt_tmpdir());
    char path[512], script[2048];
    snprintf(path, sizeof path, "%s/halve.json", dir);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fprintf(f, "{\"frames\": 4, \"edits\": [{\"frame\": 2, \"light\": \"ceiling_light\", \"intensity\": %.9g}]}\n",
            0.5 * (double)l.intensity);
    fclose(f);
    snprintf(script, sizeof script,
             "set -e; rm -f %s/plain.exr %s/halved.exr\n"
             "%s view scenes/cornell.glb --size " SIZE " --frames 4 --screenshot %s/plain.exr -q\n"
             "%s view scenes/cornell.glb --size " SIZE " --frames 4 --script %s --screenshot %s/halved.exr -q",
             dir, dir, lmgi_bin(), dir, lmgi_bin(), path, dir);
    int rc = under_x(script);
    if (rc != 0)
        fail_msg("exit %d: %s", rc, output);
    char a[512], b[512];
    snprintf(a, sizeof a, "%s/plain.exr", dir);
    snprintf(b, sizeof b, "%s/halved.exr", dir);
    int w, h;
    double plain = mean_of(a, NULL, &w, &h), halved = mean_of(b, NULL, &w, &h);
    print_message("the light halved by a script at frame 2 of 4: %.1f%% of the unedited frame\n", 100.0 * halved / plain);
    assert_true(halved > 0.45 * plain && halved < 0.85 * plain);
}

/* Pixels of a and b (EXR paths) more than `rel` apart in luminance, of those b lights, and a's mean over b's. */
static int apart(const char *a, const char *b, double rel, int *lit, double *ratio)
{
    float *pa, *pb;
    int w, h, w2, h2;
    double ma = mean_of(a, &pa, &w, &h), mb = mean_of(b, &pb, &w2, &h2);
    assert_int_equal(w, w2);
    assert_int_equal(h, h2);
    int off = 0;
    *lit = 0;
    for (size_t i = 0; i < (size_t)w * h; i++) {
        double x = (double)pa[4 * i] + pa[4 * i + 1] + pa[4 * i + 2], y = (double)pb[4 * i] + pb[4 * i + 1] + pb[4 * i + 2];
        if (y > 0.0)
            ++*lit, off += fabs(x / y - 1.0) > rel;
    }
    *ratio = ma / mb;
    free(pa);
    free(pb);
    return off;
}

/* The generated Cornell box's cube: its world matrix, and the pixel its origin falls on in a 320 x 240
 * picture from the scene's camera (where the viewer's window starts). */
static void cube_pixel(float m0[16], int *x, int *y)
{
    lmgi_scene *sc = generated_cornell();
    lmgi_error e;
    int cube = lmgi_find_node(sc, "dynamic_cube");
    float p[4], v[4] = {0}, c[4] = {0};
    assert_true(cube >= 0 && lmgi_get_node_transform(sc, cube, m0));
    lmgi_camera cam;
    assert_int_equal(lmgi_scene_camera(sc, -1, 320, 240, &cam, &e), LMGI_OK);
    memcpy(p, m0 + 12, 3 * sizeof(float));
    p[3] = 1.0f;
    for (int r = 0; r < 4; r++)
        for (int k = 0; k < 4; k++)
            v[r] += cam.view[4 * k + r] * p[k];
    for (int r = 0; r < 4; r++)
        for (int k = 0; k < 4; k++)
            c[r] += cam.proj[4 * k + r] * v[k];
    *x = (int)lround((c[0] / c[3] * 0.5 + 0.5) * 320), *y = (int)lround((0.5 - c[1] / c[3] * 0.5) * 240);
    lmgi_free(sc);
}

/* The generated Cornell box standing still (--still: the file's pose), its cube dragged with the mouse
 * (ctrl + drag, 60 pixels left), its lighting captured (shift+P, the linear numbers), the scene saved
 * (ctrl+S), then the move undone (ctrl+Z). The saved file has the cube where the drag put it; lmgi run's
 * frame of that file is the window after the drag (the same mean within 0.5%, under 0.5% of the pixels
 * more than 25% apart; measured: none), which the unmoved scene is not (4% or more of the pixels 25% apart:
 * the cube is elsewhere); after the undo the picture is the unmoved scene's again (the same bounds). Each
 * picture is taken when the window says its lighting caught up with the edit. The drag's moves, made under
 * the window's budget, are caught up at the release by one update without it, which the window reports;
 * so is the undo. */
static void test_drag_save_undo(void **state)
{
    (void)state;
    if (!have_x_tools())
        return;
    float m0[16];
    int x, y;
    cube_pixel(m0, &x, &y);
    char dir[64], cwd[1024], script[3072];
    snprintf(dir, sizeof dir, "%s", lmt_tmpdir());
    assert_non_null(getcwd(cwd, sizeof cwd));
    snprintf(script, sizeof script,
             "set -e; B=$(cd %s && pwd)/lmgi; S=%s/scenes/cornell.glb; cd %s; F=%d\n" IDLE_FN
             "$B view $S --still --size 320x240 --budget 500 --retrace 16 --screenshot undone.exr > log.txt &\n"
             "P=$!; W=$(xdotool search --sync --name 'lmgi view')\n"
             "sleep $((2 * F)); C=$(caught); xdotool mousemove --window $W %d %d; sleep 0.3\n"
             "xdotool keydown ctrl mousedown 1; sleep 0.3; xdotool mousemove --window $W %d %d; sleep 0.3\n"
             "xdotool mousemove --window $W %d %d; sleep 0.3; xdotool mouseup 1 keyup ctrl; settled $C\n"
             "xdotool key --window $W shift+p; sleep $F; xdotool key --window $W ctrl+s; sleep $F\n"
             "C=$(caught); xdotool key --window $W ctrl+z; settled $C\n"
             "xdotool key --window $W Escape || true; wait $P\n"
             "$B run lmgi-view-scene-001/scene.gltf --frames 1 --size 320x240 --out edited -q\n"
             "$B run $S --frames 1 --size 320x240 --out original -q",
             getenv("LMGI_BUILD") ? getenv("LMGI_BUILD") : "build", cwd, dir, slow(), x, y, x - 30, y, x - 60, y);
    int rc = under_x(script);
    if (rc != 0)
        fail_msg("exit %d: %s", rc, output);
    /* the saved scene: the cube moved left, not up */
    char saved[512];
    snprintf(saved, sizeof saved, "%s/lmgi-view-scene-001/scene.gltf", dir);
    lmgi_options o;
    lmgi_options_init(&o);
    lmgi_scene *sc;
    lmgi_error e;
    assert_int_equal(lmgi_load(saved, &o, &sc, &e), LMGI_OK);
    float m1[16];
    assert_true(lmgi_get_node_transform(sc, lmgi_find_node(sc, "dynamic_cube"), m1));
    lmgi_free(sc);
    print_message("cube at pixel (%d, %d) dragged 60 pixels left: from (%.3f, %.3f, %.3f) to (%.3f, %.3f, %.3f)\n", x, y,
                  (double)m0[12], (double)m0[13], (double)m0[14], (double)m1[12], (double)m1[13], (double)m1[14]);
    assert_true(m0[12] - m1[12] > 0.1f && fabsf(m1[13] - m0[13]) < 1e-4f);
    /* the drag, committed under the window's budget, caught up at its release by an update without it */
    char *log = window_log(dir);
    const char *release = strstr(log, "drag released: its light followed at once");
    print_message("%.*s\n", release ? (int)strcspn(release, "\n") : 4, release ? release : "none");
    assert_non_null(release);
    /* so is the undo, a move made in one go */
    const char *undo = strstr(log, "undo: its light followed at once");
    print_message("%.*s\n", undo ? (int)strcspn(undo, "\n") : 4, undo ? undo : "none");
    assert_non_null(undo);
    free(log);
    char edited[512], original[512], undone[512], window[512];
    snprintf(edited, sizeof edited, "%s/edited/frame_0000.exr", dir);
    snprintf(original, sizeof original, "%s/original/frame_0000.exr", dir);
    snprintf(undone, sizeof undone, "%s/undone.exr", dir);
    snprintf(window, sizeof window, "%s/lmgi-view-001.exr", dir);
    int lit;
    double ratio;
    int same = apart(window, edited, 0.25, &lit, &ratio);
    print_message("the window's lighting after the drag (shift+P) against lmgi run's frame of the saved scene: mean "
                  "%.4f, %d of %d pixels 25%% apart\n", ratio, same, lit);
    assert_true(fabs(ratio - 1.0) < 0.005 && same < lit / 200);
    int moved = apart(edited, original, 0.25, &lit, &ratio);
    print_message("the moved scene against the unmoved: %d of %d pixels 25%% apart\n", moved, lit);
    assert_true(moved > lit / 25);
    int back = apart(undone, original, 0.25, &lit, &ratio);
    print_message("after the undo against the unmoved scene: mean %.4f, %d of %d pixels 25%% apart\n", ratio, back, lit);
    assert_true(fabs(ratio - 1.0) < 0.005 && back < lit / 200);
}

/* Every other edit the window makes, as a person makes it, on the generated Cornell box standing still:
 * the cube dragged 60 pixels up with Y held (along the world's y axis: it rises, x and z stay), its
 * material recoloured (B: the first of the viewer's colours, 0.8 grey), its shadows switched off (1); the
 * light dimmed from the keyboard (-: x 0.8) and lowered (Page Down: a twentieth of the scene); then the
 * lighting captured once caught up (shift+P), the scene saved (ctrl+S) and the view switched to the IIM
 * (V: the terminal says so). The saved file holds every edit, and lmgi run's frame of it is the window's
 * lighting: the same mean within 0.5%, under 0.5% of the pixels more than 25% apart. */
static void test_axis_material_effects_light(void **state)
{
    (void)state;
    if (!have_x_tools())
        return;
    float m0[16];
    int x, y;
    cube_pixel(m0, &x, &y);
    lmgi_scene *sc = generated_cornell();
    lmgi_error e;
    lmgi_light l0;
    assert_int_equal(lmgi_get_light(sc, 0, &l0, &e), LMGI_OK);
    lmgi_info in;
    lmgi_get_info(sc, &in);
    float size = 0.0f;
    for (int k = 0; k < 3; k++)
        size += (in.bounds_max[k] - in.bounds_min[k]) * (in.bounds_max[k] - in.bounds_min[k]);
    size = sqrtf(size);
    lmgi_free(sc);
    char dir[64], cwd[1024], script[3072];
    snprintf(dir, sizeof dir, "%s", lmt_tmpdir());
    assert_non_null(getcwd(cwd, sizeof cwd));
    snprintf(script, sizeof script,
             "set -e; B=$(cd %s && pwd)/lmgi; S=%s/scenes/cornell.glb; cd %s; F=%d\n" IDLE_FN
             "$B view $S --still --size 320x240 --budget 500 --retrace 16 > log.txt &\n"
             "P=$!; W=$(xdotool search --sync --name 'lmgi view')\n"
             "sleep $((2 * F)); C=$(caught); xdotool mousemove --window $W %d %d; sleep 0.3\n"
             "xdotool keydown ctrl mousedown 1; sleep 0.3; xdotool key --window $W y; sleep 0.3\n"
             "xdotool mousemove --window $W %d %d; sleep 0.3; xdotool mousemove --window $W %d %d; sleep 0.3\n"
             "xdotool mouseup 1 keyup ctrl; settled $C\n"
             "C=$(caught); xdotool key --window $W b; settled $C\n"
             "C=$(caught); xdotool key --window $W 1; settled $C\n"
             "C=$(caught); xdotool key --window $W minus; settled $C\n"
             "C=$(caught); xdotool key --window $W Next; settled $C\n"
             "xdotool key --window $W shift+p; sleep $F; xdotool key --window $W ctrl+s; sleep $F\n"
             "xdotool key --window $W v; sleep $F; xdotool key --window $W Escape || true; wait $P\n"
             "$B run lmgi-view-scene-001/scene.gltf --frames 1 --size 320x240 --out edited -q",
             getenv("LMGI_BUILD") ? getenv("LMGI_BUILD") : "build", cwd, dir, slow(), x, y, x, y - 30, x, y - 60);
    int rc = under_x(script);
    if (rc != 0)
        fail_msg("exit %d: %s", rc, output);
    char saved[512];
    snprintf(saved, sizeof saved, "%s/lmgi-view-scene-001/scene.gltf", dir);
    lmgi_options o;
    lmgi_options_init(&o);
    assert_int_equal(lmgi_load(saved, &o, &sc, &e), LMGI_OK);
    int cube = lmgi_find_node(sc, "dynamic_cube");
    float m1[16];
    assert_true(lmgi_get_node_transform(sc, cube, m1));
    lmgi_node_effects fx;
    assert_int_equal(lmgi_get_node_effects(sc, cube, &fx, &e), LMGI_OK);
    lmgi_hit hit;
    const float above[3] = {m1[12], in.bounds_max[1] - 1e-3f, m1[14]}, down[3] = {0.0f, -1.0f, 0.0f};
    lmgi_intersect(sc, above, down, INFINITY, &hit);
    assert_true(hit.hit && hit.node == cube);
    lmgi_material mat;
    assert_int_equal(lmgi_get_material(sc, hit.material, &mat, &e), LMGI_OK);
    lmgi_light l1;
    assert_int_equal(lmgi_get_light(sc, 0, &l1, &e), LMGI_OK);
    lmgi_free(sc);
    print_message("cube moved along y: (%.3f, %.3f, %.3f) -> (%.3f, %.3f, %.3f); its material %.2f %.2f %.2f, shadows "
                  "%d; light %.4g -> %.4g at height %.3f -> %.3f\n", (double)m0[12], (double)m0[13], (double)m0[14],
                  (double)m1[12], (double)m1[13], (double)m1[14], (double)mat.base_color[0], (double)mat.base_color[1],
                  (double)mat.base_color[2], fx.shadows, (double)l0.intensity, (double)l1.intensity,
                  (double)l0.position[1], (double)l1.position[1]);
    assert_true(m1[13] - m0[13] > 0.05f && fabsf(m1[12] - m0[12]) < 1e-4f && fabsf(m1[14] - m0[14]) < 1e-4f);
    for (int k = 0; k < 3; k++)
        assert_float_equal(mat.base_color[k], 0.8f, 1e-6);
    assert_int_equal(fx.shadows, 0);
    assert_float_equal(l1.intensity, l0.intensity / 1.25f, 1e-4 * l0.intensity);
    assert_float_equal(l1.position[1], l0.position[1] - 0.05f * size, 1e-4 * size);
    char *said = window_log(dir);
    assert_non_null(strstr(said, "view: IIM"));
    /* the drag and Page Down each caught up by an update without the budget */
    assert_non_null(strstr(said, "drag released: its light followed at once"));
    assert_non_null(strstr(said, "light lowered: its light followed at once"));
    free(said);
    char edited[512], window[512];
    snprintf(edited, sizeof edited, "%s/edited/frame_0000.exr", dir);
    snprintf(window, sizeof window, "%s/lmgi-view-001.exr", dir);
    int lit;
    double ratio;
    int same = apart(window, edited, 0.25, &lit, &ratio);
    print_message("the window's lighting against lmgi run's frame of the saved scene: mean %.4f, %d of %d pixels 25%% "
                  "apart\n", ratio, same, lit);
    assert_true(fabs(ratio - 1.0) < 0.005 && same < lit / 200);
}

/* A room (an inward cube of side 4), a box on its floor, a lamp and a camera inside: the box at
 * (bx, -1.5, bz); with `second`, a second box (another node with triangles: new geometry to the watch);
 * with `lamp2`, a second lamp (a node without triangles: a light added, to the watch). */
static void write_room(const char *path, float bx, float bz, int second, int lamp2)
{
    lmt_mesh m[2];
    memset(m, 0, sizeof m);
    lmt_mesh_cube_inward(&m[0], 2.0f);
    lmt_mesh_cube(&m[1], 0.5f);
    char nodes[1024], extra[512];
    snprintf(nodes, sizeof nodes,
             "[{\"name\": \"room\", \"mesh\": 0}, {\"name\": \"box\", \"mesh\": 1, \"translation\": [%g, -1.5, %g]},"
             " {\"name\": \"lamp\", \"translation\": [0, 1.5, 0], \"extensions\": {\"KHR_lights_punctual\": "
             "{\"light\": 0}}}, {\"name\": \"eye\", \"camera\": 0, \"translation\": [0, 0, 1.9]}%s%s]",
             (double)bx, (double)bz, second ? ", {\"name\": \"box2\", \"mesh\": 1, \"translation\": [1, -1.5, 1]}" : "",
             lamp2 ? ", {\"name\": \"lamp2\", \"translation\": [1, 1.5, -1], \"extensions\": {\"KHR_lights_punctual\": "
                     "{\"light\": 1}}}" : "");
    snprintf(extra, sizeof extra,
             "\"extensionsUsed\": [\"KHR_lights_punctual\"], \"extensions\": {\"KHR_lights_punctual\": {\"lights\": "
             "[{\"type\": \"point\", \"intensity\": 20}, {\"type\": \"point\", \"intensity\": 10, \"color\": [1, 0.5, 0.3]}]}},"
             " \"cameras\": [{\"type\": \"perspective\", \"perspective\": {\"yfov\": 1.2, \"znear\": 0.01}}],");
    assert_int_equal(lmt_write_gltf(path, m, 2, nodes, NULL, 0, extra), 0);
}

/* Pixels of a window's lighting (EXR in dir) against a fresh window's, within the test's bounds: the same
 * mean within 0.5%, under 0.5% of the pixels 25% apart. */
static void same_as_fresh(const char *dir, const char *shot, const char *fresh, const char *what)
{
    char a[512], b[512];
    snprintf(a, sizeof a, "%s/%s", dir, shot);
    snprintf(b, sizeof b, "%s/%s", dir, fresh);
    int lit;
    double ratio;
    int off = apart(a, b, 0.25, &lit, &ratio);
    print_message("the watched window %s against a fresh window on the saved file: mean %.4f, %d of %d pixels 25%% "
                  "apart\n", what, ratio, off, lit);
    assert_true(fabs(ratio - 1.0) < 0.005 && off < lit / 200);
}

/* --watch: the window follows the file as an artist saves it. The box moved in the file becomes one node
 * edit ("1 node moved"), a lamp added in the file a light added ("1 added") and the lamp taken out again
 * a light removed ("1 removed"); after the first two the window's lighting once caught up (shift+P) is
 * what a fresh window on the saved file shows (the same mean within 0.5%, under 0.5% of the pixels 25%
 * apart; measured: none). A box added to the file is new geometry: the scene is loaded again, and says
 * so. */
static void test_watch(void **state)
{
    (void)state;
    if (!have_x_tools())
        return;
    char dir[64], path[512], script[3072];
    snprintf(dir, sizeof dir, "%s", lmt_tmpdir());
    const char *names[4] = {"a.gltf", "b.gltf", "c.gltf", "d.gltf"};
    const float x[4] = {0.8f, -0.9f, -0.9f, -0.9f}, z[4] = {0.3f, -0.4f, -0.4f, -0.4f};
    for (int k = 0; k < 4; k++) {
        snprintf(path, sizeof path, "%s/%s", dir, names[k]);
        write_room(path, x[k], z[k], k == 2, k == 3);
    }
    snprintf(script, sizeof script,
             "set -e; B=$(cd %s && pwd)/lmgi; cd %s; F=%d; cp a.gltf watched.gltf\n" IDLE_FN
             "save() { C=$(caught); cp $1 next.gltf; mv next.gltf watched.gltf; settled $C; }\n"
             "$B view watched.gltf --watch --still --size 160x120 --budget 500 --retrace 16 > log.txt 2>&1 &\n"
             "P=$!; W=$(xdotool search --sync --name 'lmgi view')\n"
             "sleep $((2 * F)); save b.gltf; xdotool key --window $W shift+p; sleep $F\n"
             "save d.gltf; xdotool key --window $W shift+p; sleep $F; save b.gltf\n"
             "cp c.gltf next.gltf; mv next.gltf watched.gltf; sleep $((3 * F))\n"
             "xdotool key --window $W Escape || true; wait $P\n"
             "$B view b.gltf --still --size 160x120 --budget 500 --frames 3 --screenshot fresh_b.exr -q\n"
             "$B view d.gltf --still --size 160x120 --budget 500 --frames 3 --screenshot fresh_d.exr -q",
             getenv("LMGI_BUILD") ? getenv("LMGI_BUILD") : "build", dir, slow());
    int rc = under_x(script);
    char *text = window_log(dir);
    print_message("%s", text);
    if (rc != 0)
        fail_msg("exit %d: %s", rc, output);
    assert_non_null(strstr(text, "file saved: 1 node moved, 0 materials, 0 lights changed, 0 added, 0 removed"));
    assert_non_null(strstr(text, "file saved: 0 nodes moved, 0 materials, 0 lights changed, 1 added, 0 removed"));
    assert_non_null(strstr(text, "file saved: 0 nodes moved, 0 materials, 0 lights changed, 0 added, 1 removed"));
    assert_non_null(strstr(text, "the file's geometry changed: the scene was loaded again"));
    assert_non_null(strstr(text, "file saved: its light followed at once")); /* the move, outside the budget */
    free(text);
    same_as_fresh(dir, "lmgi-view-001.exr", "fresh_b.exr", "after the box moved");
    same_as_fresh(dir, "lmgi-view-002.exr", "fresh_d.exr", "after a lamp was added");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_no_display),
        cmocka_unit_test(test_picture_is_run_frame),
        cmocka_unit_test(test_keys_switch_light_off),
        cmocka_unit_test(test_script),
        cmocka_unit_test(test_drag_save_undo),
        cmocka_unit_test(test_axis_material_effects_light),
        cmocka_unit_test(test_watch),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
