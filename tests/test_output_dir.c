/* Output directories never lose a user's file (lmgi_output_*, lmgi_write_file and the commands on them):
 * lmgi removes or replaces only what its manifest says it placed, a failed, cancelled or killed command
 * leaves the last good result, two commands never write one folder at once, and no output replaces an
 * input. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <lmgi_tools.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "support.h"

static char output[65536];

/* Runs `lmgi ARGS` (stdout and stderr together into `output`) and returns its exit status. */
static int lmgi(const char *args) { return lmt_lmgi("", args, output, sizeof output); }

static const char *in(const char *dir, const char *name)
{
    static char path[8][1400];
    static int next;
    char joined[sizeof path[0]]; /* dir may be one of path[]: joined first */
    if (snprintf(joined, sizeof joined, "%s/%s", dir, name) >= (int)sizeof joined)
        fail_msg("path too long: %s/%s", dir, name);
    char *p = path[next++ % 8];
    memcpy(p, joined, sizeof joined);
    return p;
}

static int exists(const char *dir, const char *name)
{
    struct stat s;
    return lstat(in(dir, name), &s) == 0;
}

static void put_file(const char *dir, const char *name, const char *text)
{
    lmt_write_file(in(dir, name), text, strlen(text));
}

/* Whether DIR/NAME holds exactly `text`. */
static int holds(const char *dir, const char *name, const char *text)
{
    size_t n = 0;
    unsigned char *b = lmt_read_file(in(dir, name), &n, 1);
    int same = b && n == strlen(text) && memcmp(b, text, n) == 0;
    free(b);
    return same;
}

/* One command's result: opens DIR for COMMAND, writes each NAME holding `text`, commits. */
static lmgi_status result(const char *dir, const char *command, int force, const char *const *names, const char *text,
                          lmgi_error *e)
{
    lmgi_output *o = NULL;
    lmgi_status st = lmgi_output_open(dir, command, force, NULL, &o, e);
    for (; st == LMGI_OK && *names; names++) {
        char path[1400];
        st = lmgi_output_file(o, *names, path, sizeof path, e);
        if (st == LMGI_OK)
            st = lmgi_write_file(path, text, strlen(text), e);
    }
    if (st != LMGI_OK) {
        lmgi_output_abort(o);
        return st;
    }
    return lmgi_output_commit(o, e);
}

/* The cases: files named like lmgi's own, and *.partial of other programs, all kept. */
static void test_only_its_own_files(void **state)
{
    (void)state;
    char dir[1200];
    snprintf(dir, sizeof dir, "%s", in(lmt_tmpdir(), "shared/out"));
    lmgi_error e;
    static const char *const three[] = {"frame_0000.png", "frame_0001.png", "frame_0002.png", NULL};
    static const char *const one[] = {"frame_0000.png", NULL};
    assert_int_equal(result(dir, "run", 0, three, "first", &e), LMGI_OK); /* made with its parents */
    assert_true(exists(dir, ".lmgi") && holds(dir, "frame_0002.png", "first"));
    static const char *const users[] = {"download.iso.partial", "thesis.docx.partial", "frame_holiday.png",
                                        "frame_final.exr", "caustics.png", "accuracy.png", "scene_tex0.png",
                                        "frame_0000.png.partial"};
    for (int i = 0; i < 8; i++)
        put_file(dir, users[i], "mine");
    /* the folder is lmgi's now: no force needed; the second run replaces the first's frames and nothing else */
    assert_int_equal(result(dir, "run", 0, one, "second", &e), LMGI_OK);
    assert_true(holds(dir, "frame_0000.png", "second"));
    assert_false(exists(dir, "frame_0001.png") || exists(dir, "frame_0002.png"));
    for (int i = 0; i < 8; i++)
        assert_true(holds(dir, users[i], "mine"));
    /* another command's result stays beside it */
    static const char *const maps[] = {"lightmap.exr", NULL};
    assert_int_equal(result(dir, "bake", 0, maps, "baked", &e), LMGI_OK);
    assert_true(holds(dir, "frame_0000.png", "second") && holds(dir, "lightmap.exr", "baked"));
    /* a user's file put under a name lmgi used is the user's: refused, never replaced, never removed */
    assert_int_equal(unlink(in(dir, "frame_0000.png")), 0);
    put_file(dir, "frame_0000.png", "my frame");
    assert_int_equal(result(dir, "run", 0, one, "third", &e), LMGI_ERR_IO);
    assert_non_null(strstr(e.message, "frame_0000.png: lmgi did not write this file"));
    static const char *const none[] = {NULL};
    assert_int_equal(result(dir, "run", 0, none, "", &e), LMGI_OK); /* a run that writes no frame 0 */
    assert_true(holds(dir, "frame_0000.png", "my frame"));
    /* lmgi's own file written over in place (same inode) is the user's now too */
    put_file(dir, "lightmap.exr", "edited by hand");
    assert_int_equal(result(dir, "bake", 0, maps, "rebaked", &e), LMGI_ERR_IO);
    assert_true(holds(dir, "lightmap.exr", "edited by hand"));
    static const char *const other[] = {"aim.exr", NULL};
    assert_int_equal(result(dir, "bake", 0, other, "rebaked", &e), LMGI_OK); /* nor removed when not rewritten */
    assert_true(holds(dir, "lightmap.exr", "edited by hand") && holds(dir, "aim.exr", "rebaked"));
    for (int i = 0; i < 8; i++)
        assert_true(holds(dir, users[i], "mine"));
}

/* An unmarked folder with files is refused without force and left as it was; with force lmgi writes
 * beside the files; names that are not plain files are refused. */
static void test_force_and_names(void **state)
{
    (void)state;
    char dir[1200];
    snprintf(dir, sizeof dir, "%s", in(lmt_tmpdir(), "home"));
    mkdir(dir, 0755);
    put_file(dir, "thesis.tex", "mine");
    lmgi_error e;
    lmgi_output *o = NULL;
    assert_int_equal(lmgi_output_open(dir, "bake", 0, NULL, &o, &e), LMGI_ERR_IO);
    assert_null(o);
    assert_non_null(strstr(e.message, "thesis.tex"));
    assert_false(exists(dir, ".lmgi") || exists(dir, ".lmgi-new"));
    static const char *const maps[] = {"lightmap.exr", NULL};
    assert_int_equal(result(dir, "bake", 1, maps, "baked", &e), LMGI_OK);
    assert_true(holds(dir, "thesis.tex", "mine") && holds(dir, "lightmap.exr", "baked"));

    assert_int_equal(lmgi_output_open(dir, "bake", 0, NULL, &o, &e), LMGI_OK);
    char path[1400];
    static const char *const bad[] = {"../escape.png", ".lmgi", "", "a/b.png", "tab\there"};
    for (int i = 0; i < 5; i++)
        assert_int_equal(lmgi_output_file(o, bad[i], path, sizeof path, &e), LMGI_ERR_INVALID);
    assert_int_equal(lmgi_output_file(o, "thesis.tex", path, sizeof path, &e), LMGI_ERR_IO);
    assert_int_equal(lmgi_output_file(o, "ok.png", path, 8, &e), LMGI_ERR_INVALID); /* too small */
    lmgi_output_abort(o);
    assert_int_equal(lmgi_output_open(NULL, "bake", 0, NULL, &o, &e), LMGI_ERR_INVALID);
    assert_int_equal(lmgi_output_open(dir, "Bake!", 0, NULL, &o, &e), LMGI_ERR_INVALID);
    assert_int_equal(lmgi_output_open(in(dir, "thesis.tex"), "bake", 1, NULL, &o, &e), LMGI_ERR_IO);
    assert_int_equal(lmgi_output_commit(NULL, &e), LMGI_ERR_INVALID);
    lmgi_output_abort(NULL);
}

/* Abort, and a process killed while writing, leave the previous result; the next open clears what the
 * killed one left; the work file survives both and the next commit removes it. */
static void test_failure_keeps_the_last_result(void **state)
{
    (void)state;
    char dir[1200];
    snprintf(dir, sizeof dir, "%s", in(lmt_tmpdir(), "keep"));
    lmgi_error e;
    static const char *const maps[] = {"lightmap.exr", "aim.exr", NULL};
    assert_int_equal(result(dir, "bake", 0, maps, "good", &e), LMGI_OK);
    lmgi_output *o = NULL;
    char path[1400], work[1400];
    assert_int_equal(lmgi_output_open(dir, "bake", 0, NULL, &o, &e), LMGI_OK);
    assert_int_equal(lmgi_output_work_file(o, "bake.checkpoint", work, sizeof work, &e), LMGI_OK);
    assert_string_equal(work, in(dir, "bake.checkpoint"));
    assert_int_equal(lmgi_write_file(work, "half", 4, &e), LMGI_OK);
    assert_int_equal(lmgi_output_file(o, "lightmap.exr", path, sizeof path, &e), LMGI_OK);
    assert_int_equal(lmgi_write_file(path, "bad", 3, &e), LMGI_OK);
    lmgi_output_abort(o);
    assert_true(holds(dir, "lightmap.exr", "good") && holds(dir, "aim.exr", "good"));
    assert_true(holds(dir, "bake.checkpoint", "half") && !exists(dir, ".lmgi-new"));

    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) { /* writes a new result and dies before its commit */
        lmgi_output *c = NULL;
        char p[1400];
        if (lmgi_output_open(dir, "bake", 0, NULL, &c, NULL) == LMGI_OK &&
            lmgi_output_file(c, "lightmap.exr", p, sizeof p, NULL) == LMGI_OK)
            lmgi_write_file(p, "killed", 6, NULL);
        raise(SIGKILL);
    }
    int status;
    waitpid(pid, &status, 0);
    assert_true(WIFSIGNALED(status));
    assert_true(exists(dir, ".lmgi-new") && holds(dir, "lightmap.exr", "good"));
    static const char *const one[] = {"lightmap.exr", NULL};
    assert_int_equal(result(dir, "bake", 0, one, "new", &e), LMGI_OK); /* the lock died with it */
    assert_true(holds(dir, "lightmap.exr", "new"));
    assert_false(exists(dir, ".lmgi-new") || exists(dir, "aim.exr") || exists(dir, "bake.checkpoint"));
}

/* Two writers of one folder: the second is refused while the first holds it, from another process too. */
static void test_one_writer_at_a_time(void **state)
{
    (void)state;
    char dir[1200];
    snprintf(dir, sizeof dir, "%s", in(lmt_tmpdir(), "locked"));
    lmgi_error e;
    lmgi_output *a = NULL, *b = NULL;
    assert_int_equal(lmgi_output_open(dir, "run", 0, NULL, &a, &e), LMGI_OK);
    assert_int_equal(lmgi_output_open(dir, "bake", 0, NULL, &b, &e), LMGI_ERR_IO);
    assert_non_null(strstr(e.message, "another lmgi command is writing into this directory"));
    char pid[32];
    snprintf(pid, sizeof pid, "process %ld run", (long)getpid());
    assert_non_null(strstr(e.message, pid));
    int ready[2];
    assert_int_equal(pipe(ready), 0);
    pid_t child = fork();
    assert_true(child >= 0);
    if (child == 0) {
        lmgi_output *c = NULL;
        char r = lmgi_output_open(dir, "bake", 0, NULL, &c, NULL) == LMGI_OK ? 'y' : 'n';
        _exit(write(ready[1], &r, 1) == 1 && r == 'n' ? 0 : 1);
    }
    int status;
    waitpid(child, &status, 0);
    assert_true(WIFEXITED(status) && WEXITSTATUS(status) == 0); /* refused in the other process too */
    close(ready[0]), close(ready[1]);
    assert_int_equal(lmgi_output_commit(a, &e), LMGI_OK);
    assert_int_equal(lmgi_output_open(dir, "bake", 0, NULL, &b, &e), LMGI_OK);
    lmgi_output_abort(b);
}

/* An input is never replaced: refused at open when it is the command's earlier output, and by name. */
static void test_inputs_are_never_replaced(void **state)
{
    (void)state;
    char dir[1200];
    snprintf(dir, sizeof dir, "%s", in(lmt_tmpdir(), "inputs"));
    lmgi_error e;
    static const char *const exported[] = {"scene.gltf", NULL};
    assert_int_equal(result(dir, "export", 0, exported, "{}", &e), LMGI_OK);
    const char *const inputs[] = {in(dir, "scene.gltf"), NULL};
    lmgi_output *o = NULL;
    assert_int_equal(lmgi_output_open(dir, "export", 0, inputs, &o, &e), LMGI_ERR_IO);
    assert_non_null(strstr(e.message, "earlier 'export' output"));
    assert_int_equal(lmgi_output_open(dir, "bake", 0, inputs, &o, &e), LMGI_OK); /* another command's */
    char path[1400];
    assert_int_equal(lmgi_output_file(o, "scene.gltf", path, sizeof path, &e), LMGI_ERR_IO);
    assert_non_null(strstr(e.message, "input"));
    lmgi_output_abort(o);
    assert_true(holds(dir, "scene.gltf", "{}"));
}

/* lmgi_write_file creates NAME.partial exclusively: a link planted there is refused, its target untouched. */
static void test_partial_files_are_created(void **state)
{
    (void)state;
    const char *dir = lmt_tmpdir();
    lmgi_error e;
    put_file(dir, "target", "secret");
    assert_int_equal(symlink(in(dir, "target"), in(dir, "frame_0100.png.partial")), 0);
    assert_int_equal(lmgi_write_file(in(dir, "frame_0100.png"), "x", 1, &e), LMGI_ERR_IO);
    assert_non_null(strstr(e.message, "frame_0100.png.partial is in the way"));
    assert_true(holds(dir, "target", "secret"));
    assert_false(exists(dir, "frame_0100.png"));
    float px[12] = {0};
    assert_int_equal(lmgi_write_image(in(dir, "frame_0100.png"), 2, 2, 3, px, NULL, &e), LMGI_ERR_IO);
    assert_true(holds(dir, "target", "secret"));
    assert_int_equal(lmgi_write_file(in(dir, "plain.txt"), "abc", 3, &e), LMGI_OK);
    assert_int_equal(lmgi_write_file(in(dir, "plain.txt"), "de", 2, &e), LMGI_OK); /* replaced whole */
    assert_true(holds(dir, "plain.txt", "de"));
    assert_int_equal(lmgi_write_file(NULL, "x", 1, &e), LMGI_ERR_INVALID);
    assert_int_equal(lmgi_write_file(in(dir, "y"), NULL, 1, &e), LMGI_ERR_INVALID);
}

static int same_bytes(const char *a, const char *b)
{
    size_t na = 0, nb = 0;
    unsigned char *x = lmt_read_file(a, &na, 1), *y = lmt_read_file(b, &nb, 1);
    int same = x && y && na == nb && memcmp(x, y, na) == 0;
    free(x);
    free(y);
    return same;
}

#define QUICK "scenes/cornell.glb --size 32x32 --texel-size 0.1 --photons 5000 -q"

/* The commands: a re-bake stopped by SIGTERM, a mistyped scene and a run killed by SIGINT keep the last
 * result byte for byte; a second run into a busy folder is refused and nothing of it is left. */
static void test_commands_keep_the_last_result(void **state)
{
    (void)state;
    char dir[1200];
    snprintf(dir, sizeof dir, "%s", in(lmt_tmpdir(), "cmd"));
    char args[2048], saved[1200];
    snprintf(args, sizeof args, "bake scenes/two_rooms.glb --texels 2000 --out %s", dir);
    if (lmgi(args) != 0)
        fail_msg("%s: %s", args, output);
    snprintf(saved, sizeof saved, "%s.saved", in(dir, "lightmap.exr"));
    assert_int_equal(link(in(dir, "lightmap.exr"), saved), 0);
    const char *build = getenv("LMGI_BUILD");
    snprintf(args, sizeof args, "timeout -s TERM 1 %s/lmgi bake scenes/two_rooms.glb --out %s >/dev/null 2>&1",
             build ? build : "build", dir);
    assert_int_not_equal(system(args), 0);
    assert_true(same_bytes(in(dir, "lightmap.exr"), saved) && exists(dir, "lightmap.png") && exists(dir, "aim.exr"));
    snprintf(args, sizeof args, "bake scenes/missing.glb --out %s", dir);
    assert_int_equal(lmgi(args), 1);
    assert_true(same_bytes(in(dir, "lightmap.exr"), saved));

    char runs[1200];
    snprintf(runs, sizeof runs, "%s", in(lmt_tmpdir(), "runs"));
    snprintf(args, sizeof args, "run " QUICK " --frames 2 --out %s", runs);
    assert_int_equal(lmgi(args), 0);
    char csv[1200];
    snprintf(csv, sizeof csv, "%s.saved", in(runs, "frames.csv"));
    assert_int_equal(link(in(runs, "frames.csv"), csv), 0);
    char exe[600];
    snprintf(exe, sizeof exe, "%s/lmgi", build ? build : "build");
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        freopen("/dev/null", "w", stdout);
        freopen("/dev/null", "w", stderr);
        signal(SIGINT, SIG_DFL); /* as a terminal's Ctrl-C meets it: a background job inherits SIGINT ignored */
        execl(exe, exe, "run", "scenes/cornell.glb", "--size", "32x32", "--texel-size", "0.1", "--photons", "5000",
              "--frames", "100000", "--out", runs, (char *)NULL);
        _exit(127);
    }
    int waited = 0; /* until the long run holds the folder and has written frames */
    while (!exists(runs, ".lmgi-new/frame_0003.png") && waited++ < 6000)
        usleep(10000);
    assert_true(exists(runs, ".lmgi-new/frame_0003.png"));
    snprintf(args, sizeof args, "run " QUICK " --frames 1 --out %s", runs);
    assert_int_equal(lmgi(args), 1); /* a second writer */
    assert_non_null(strstr(output, "another lmgi command is writing into this directory"));
    kill(pid, SIGINT);
    int status;
    waitpid(pid, &status, 0);
    assert_true(WIFSIGNALED(status));
    assert_true(same_bytes(in(runs, "frames.csv"), csv));
    assert_true(exists(runs, "frame_0001.png") && !exists(runs, "frame_0002.png"));
}

/* --json: never over an input; a path that cannot be written, stdout included, is an error, not exit 0. */
static void test_single_output_files(void **state)
{
    (void)state;
    const char *dir = lmt_tmpdir();
    char scene[1200], args[3000];
    snprintf(scene, sizeof scene, "%s", in(dir, "scene.glb"));
    size_t n = 0;
    unsigned char *bytes = lmt_read_file("scenes/cornell.glb", &n, 1);
    assert_non_null(bytes);
    lmt_write_file(scene, bytes, n);
    free(bytes);
    char copy[1300];
    snprintf(copy, sizeof copy, "%s.copy", scene);
    assert_int_equal(link(scene, copy), 0);
    snprintf(args, sizeof args, "bench %s --repeats 1 --json %s", scene, scene);
    assert_int_equal(lmgi(args), 1);
    assert_non_null(strstr(output, "is the input"));
    snprintf(args, sizeof args, "bench %s --repeats 1 --json %s/no/such/dir/out.json", scene, dir);
    assert_int_equal(lmgi(args), 1);
    assert_non_null(strstr(output, "out.json"));
    snprintf(args, sizeof args, "bench %s --repeats 1 --json %s", scene, in(dir, "bench.json"));
    assert_int_equal(lmgi(args), 0);
    assert_true(exists(dir, "bench.json"));
    struct stat s;
    assert_int_equal(stat(scene, &s), 0);
    assert_true(s.st_nlink == 2); /* the same file as its copy: never rewritten */
    assert_int_equal(lmgi("info scenes/cornell.glb >/dev/full"), 1); /* what it prints is its output too */
    assert_int_equal(lmgi("info scenes/cornell.glb >/dev/null"), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_only_its_own_files),
        cmocka_unit_test(test_force_and_names),
        cmocka_unit_test(test_failure_keeps_the_last_result),
        cmocka_unit_test(test_one_writer_at_a_time),
        cmocka_unit_test(test_inputs_are_never_replaced),
        cmocka_unit_test(test_partial_files_are_created),
        cmocka_unit_test(test_commands_keep_the_last_result),
        cmocka_unit_test(test_single_output_files),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
