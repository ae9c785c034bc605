/* The layer rule, checked: every `#include "..."` in src/<module>/ (subfolders included: src/gpu/gl/ is
 * gpu) points to its own module or one to its left in LAYERS, the order docs/architecture.md draws, and
 * only api and cli include the public headers (<lmgi.h>, <lmgi_tools.h>, which api implements). A file
 * that breaks it is named with the include. Reads the tree from the worktree root; needs no GPU. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include <dirent.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

/* The layers, lowest first: the one list the check and docs/architecture.md's picture follow. */
static const char *const LAYERS[] = {"core", "scene", "charts", "trace", "photonmap",
                                     "gpu", "update", "reference", "api", "cli"};
enum { LAYER_COUNT = sizeof LAYERS / sizeof LAYERS[0] };

typedef struct {
    int files, includes, broken;
} tally;

/* The rank of module `name` (its first len characters), -1 when it is none of LAYERS. */
static int rank_of(const char *name, size_t len)
{
    for (int i = 0; i < LAYER_COUNT; i++)
        if (strlen(LAYERS[i]) == len && !strncmp(LAYERS[i], name, len))
            return i;
    return -1;
}

/* path ("src/a/b/../c.h") with "." and ".." folded away, into out. */
static void normalize(const char *path, char *out, size_t size)
{
    const char *part[64];
    size_t len[64];
    int n = 0;
    for (const char *p = path; *p;) {
        const char *slash = strchr(p, '/');
        size_t l = slash ? (size_t)(slash - p) : strlen(p);
        if (l == 2 && !strncmp(p, "..", 2) && n > 0)
            n--;
        else if (!(l == 1 && *p == '.') && l > 0 && n < 64) {
            part[n] = p;
            len[n++] = l;
        }
        p += l + (slash != NULL);
    }
    size_t at = 0;
    out[0] = '\0';
    for (int i = 0; i < n && at + len[i] + 2 < size; i++) {
        if (i)
            out[at++] = '/';
        memcpy(out + at, part[i], len[i]);
        at += len[i];
        out[at] = '\0';
    }
}

/* The rank of the module a path under src/ lies in, -1 when it lies outside src/ or in no known module. */
static int module_of(const char *path)
{
    if (strncmp(path, "src/", 4))
        return -1;
    const char *slash = strchr(path + 4, '/');
    return slash ? rank_of(path + 4, (size_t)(slash - path - 4)) : -1;
}

static void check_file(const char *path, int rank, tally *t)
{
    FILE *f = fopen(path, "r");
    assert_non_null(f);
    char line[1024], name[512], target[1200], folded[1200];
    const int api = rank_of("api", 3);
    for (int number = 1; fgets(line, sizeof line, f); number++) {
        int to;
        if (sscanf(line, " # include \"%511[^\"]\"", name) == 1) {
            const char *dir_end = strrchr(path, '/');
            snprintf(target, sizeof target, "%.*s/%s", (int)(dir_end - path), path, name);
            normalize(target, folded, sizeof folded);
            to = module_of(folded);
            if (to < 0) {
                print_error("%s:%d includes \"%s\" (%s), which is in no module of the layer list\n", path, number,
                            name, folded);
                t->broken++;
                continue;
            }
        } else if (sscanf(line, " # include <%511[^>]>", name) == 1 &&
                   (!strcmp(name, "lmgi.h") || !strcmp(name, "lmgi_tools.h")))
            to = api;
        else
            continue;
        t->includes++;
        if (to > rank) {
            print_error("%s:%d includes \"%s\": %s is above %s in the layers (%s)\n", path, number, name,
                        LAYERS[to], LAYERS[rank], "docs/architecture.md");
            t->broken++;
        }
    }
    fclose(f);
    t->files++;
}

/* Every .c, .cpp and .h under dir (recursively), each checked as a file of module `rank`. */
static void check_tree(const char *dir, int rank, tally *t)
{
    DIR *d = opendir(dir);
    assert_non_null(d);
    for (struct dirent *e; (e = readdir(d));) {
        if (e->d_name[0] == '.')
            continue;
        char path[1024];
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        struct stat st;
        assert_int_equal(stat(path, &st), 0);
        const char *dot = strrchr(e->d_name, '.');
        if (S_ISDIR(st.st_mode))
            check_tree(path, rank, t);
        else if (dot && (!strcmp(dot, ".c") || !strcmp(dot, ".h") || !strcmp(dot, ".cpp")))
            check_file(path, rank, t);
    }
    closedir(d);
}

static void test_includes_point_down_the_layers(void **state)
{
    (void)state;
    tally t = {0};
    for (int i = 0; i < LAYER_COUNT; i++) {
        char dir[64];
        snprintf(dir, sizeof dir, "src/%s", LAYERS[i]);
        check_tree(dir, i, &t);
    }
    /* and no folder of src/ is left out of the list */
    DIR *d = opendir("src");
    assert_non_null(d);
    for (struct dirent *e; (e = readdir(d));) {
        struct stat st;
        char path[600];
        snprintf(path, sizeof path, "src/%s", e->d_name);
        if (e->d_name[0] != '.' && stat(path, &st) == 0 && S_ISDIR(st.st_mode) &&
            rank_of(e->d_name, strlen(e->d_name)) < 0) {
            print_error("src/%s is a module the layer list (tests/test_layers.c) does not name\n", e->d_name);
            t.broken++;
        }
    }
    closedir(d);
    print_message("layers:");
    for (int i = 0; i < LAYER_COUNT; i++)
        print_message(" %s%s", i ? "< " : "", LAYERS[i]);
    print_message("\n%d files, %d includes of the library's own headers, %d pointing up or out\n", t.files,
                  t.includes, t.broken);
    assert_true(t.files > 100);
    assert_int_equal(t.broken, 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_includes_point_down_the_layers),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
