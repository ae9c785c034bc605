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

/* Runs `sh -c SCRIPT` under a fresh Xvfb; its exit status. */
static int under_x(const char *script)
{
    char path[512], cmd[1024];
    snprintf(path, sizeof path, "%s/view_test.sh", lmt_tmpdir());
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fprintf(f, "%s\n", script);
    fclose(f);
    snprintf(cmd, sizeof cmd, "xvfb-run -a -s '-screen 0 320x240x24 -nolisten tcp' sh %s 2>&1", path);
    return lmt_run(cmd, output, sizeof output);
}

/* Mean luminance (sum of the channels) of an EXR's pixels, and the picture itself into *img (NULL: not
 * kept). */
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
 * rather than the update's composite). */
static void test_picture_is_run_frame(void **state)
{
    (void)state;
    LMT_REQUIRE_SCENE(scene, lmt_shared_scene("cornell-box/CornellBox.glb"));
    if (!have_x_tools())
        return;
    char dir[64]; /* lmt_tmpdir's buffer is its next call's */
    snprintf(dir, sizeof dir, "%s", lmt_tmpdir());
    char script[2048];
    snprintf(script, sizeof script,
             "rm -rf %s/vrun %s/view.exr && %s run %s --frames 1 --size " SIZE " --out %s/vrun -q && "
             "%s view %s --frames 3 --size " SIZE " --screenshot %s/view.exr -q",
             dir, dir, lmgi_bin(), scene, dir, lmgi_bin(), scene, dir);
    int rc = under_x(script);
    if (rc != 0)
        fail_msg("exit %d: %s", rc, output);
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
             "sleep 1; xdotool key --window $W p; sleep 1; xdotool key --window $W o Escape\n"
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
    lmgi_options o;
    lmgi_options_init(&o);
    lmgi_scene *sc = NULL;
    lmgi_error e;
    assert_int_equal(lmgi_load("scenes/cornell.glb", &o, &sc, &e), LMGI_OK);
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

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_no_display),
        cmocka_unit_test(test_picture_is_run_frame),
        cmocka_unit_test(test_keys_switch_light_off),
        cmocka_unit_test(test_script),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
