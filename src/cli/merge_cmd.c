/* lmgi merge: the parts of a bake in shards put together, in two forms. `merge PART... --out DIR` takes
 * the scene and the bake's options from the parts' part.json, which each shard writes beside its
 * part.checkpoint; `merge SCENE PART... --out DIR [the bake's options]` is given them (the parts of an
 * older lmgi, lmgi-mpi's merge). Either way the library checks that the parts are of this scene and these
 * options. */
#include "merge_cmd.h"

#include <lmgi_tools.h>
#include <cjson/cJSON.h>
#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "bake_cmd.h"
#include "options.h"
#include "out_dir.h"
#include "read_file.h"

#define PATH_SIZE 4200

/* The options that concern one shard's run, not what it bakes: part.json leaves them out. */
static const char *const k_run_only[] = {"--out",   "--shard", "--resume",           "--quiet",
                                         "--verbose", "--force", "--checkpoint-seconds", NULL};
/* The options of `merge PART...`: where and how the lightmaps are written, never what is baked. */
static const char *const k_output_only[] = {"--out",   "--gltf",    "--accuracy", "--half",
                                            "--quiet", "--verbose", "--force",    NULL};

static int named(const char *const *names, const lm_cli_option *o)
{
    for (; *names; names++)
        if (!strcmp(*names, o->name))
            return 1;
    return 0;
}

/* A word of the command line that is a file (the parser's own test), not an option. */
static int is_file_word(const char *w) { return w[0] != '-' || !w[1]; }

/* The option `w` and whether the word after it is its value (as the parser takes it). */
static const lm_cli_option *option_at(const lm_cli_args *a, int i, int *with_value)
{
    const lm_cli_option *o = lm_cli_find_option(a->words[i]);
    *with_value = o && o->arg && i + 1 < a->word_count;
    return o;
}

/* ---- part.json, written by a shard ---- */

static int add_word(cJSON *list, const char *w)
{
    cJSON *s = cJSON_CreateString(w);
    return s && cJSON_AddItemToArray(list, s);
}

/* The bake's option words: a's words as given, without the scene and the run-only options (with their
 * values). NULL when out of memory. */
static cJSON *option_words(const lm_cli_args *a)
{
    cJSON *list = cJSON_CreateArray();
    int ok = list != NULL;
    for (int i = 0; ok && i < a->word_count; i++) {
        if (is_file_word(a->words[i])) /* the scene: part.json names it by its absolute path */
            continue;
        int with_value;
        const lm_cli_option *o = option_at(a, i, &with_value);
        if (o && named(k_run_only, o)) {
            i += with_value;
            continue;
        }
        ok = add_word(list, a->words[i]) && (!with_value || add_word(list, a->words[++i]));
    }
    if (!ok)
        cJSON_Delete(list);
    return ok ? list : NULL;
}

/* {"scene": ABSOLUTE PATH, "options": [WORDS]} and a newline (free it), or NULL when out of memory. */
static char *part_json_text(const char *scene, const lm_cli_args *a)
{
    cJSON *root = cJSON_CreateObject(), *words = option_words(a);
    char *printed = NULL, *text = NULL;
    if (root && words && cJSON_AddStringToObject(root, "scene", scene) &&
        cJSON_AddItemToObject(root, "options", words)) {
        words = NULL; /* root's now */
        printed = cJSON_Print(root);
    }
    size_t n = printed ? strlen(printed) : 0;
    if (printed && (text = malloc(n + 2)))
        memcpy(text, printed, n), memcpy(text + n, "\n", 2);
    cJSON_free(printed);
    cJSON_Delete(words);
    cJSON_Delete(root);
    return text;
}

int lm_cli_write_part_json(lmgi_output *out, const lm_cli_args *a)
{
    char path[PATH_SIZE];
    char *scene = realpath(a->files[0], NULL);
    if (!scene) {
        fprintf(stderr, "lmgi: error: %s: no absolute path for part.json (%s)\n", a->files[0], strerror(errno));
        return 1;
    }
    int rc = lm_cli_out_path(out, "part.json", path, sizeof path) ? 0 : 1;
    char *text = rc == 0 ? part_json_text(scene, a) : NULL;
    lmgi_error e;
    if (rc == 0 && !text)
        rc = 1, fprintf(stderr, "lmgi: error: no memory for %s\n", path);
    else if (rc == 0 && lmgi_write_file(path, text, strlen(text), &e) != LMGI_OK)
        rc = 1, fprintf(stderr, "lmgi: error: %s\n", e.message);
    free(text);
    free(scene);
    return rc;
}

/* ---- part.json, read by the merge ---- */

typedef struct {
    char where[PATH_SIZE]; /* the part.json read */
    cJSON *root;           /* owns scene and words */
    const char *scene;
    int count;
    char **words; /* count option words */
} part_info;

static void free_part(part_info *p)
{
    cJSON_Delete(p->root);
    free(p->words);
    p->root = NULL, p->words = NULL;
}

/* The checkpoint file of a part given as a folder a shard wrote, or as the file itself. */
static void checkpoint_of(const char *part, char *path, size_t size)
{
    struct stat st;
    if (stat(part, &st) == 0 && S_ISDIR(st.st_mode))
        snprintf(path, size, "%s/part.checkpoint", part);
    else
        snprintf(path, size, "%s", part);
}

/* The part.json of a part: in its folder, or beside its checkpoint file. */
static void json_of(const char *part, char *path, size_t size)
{
    struct stat st;
    const char *slash = strrchr(part, '/');
    if (stat(part, &st) == 0 && S_ISDIR(st.st_mode))
        snprintf(path, size, "%s/part.json", part);
    else if (slash)
        snprintf(path, size, "%.*s/part.json", (int)(slash - part), part);
    else
        snprintf(path, size, "part.json");
}

/* Why a part has no part.json: it is no part at all, or an older lmgi's (which wrote none). */
static int no_part_json(const char *part, const char *json)
{
    char checkpoint[PATH_SIZE];
    checkpoint_of(part, checkpoint, sizeof checkpoint);
    if (access(checkpoint, F_OK) != 0)
        fprintf(stderr, "lmgi: error: %s: not a part: no %s (lmgi bake SCENE --shard K/N --out PART writes one)\n",
                part, checkpoint);
    else
        fprintf(stderr, "lmgi: error: %s: no %s: the part was written by an older lmgi, which did not record the "
                "scene and the options of its bake; give them: lmgi merge SCENE PART... --out DIR [the bake's "
                "options]\n", part, json);
    return 0;
}

/* Its words, pointing into p->root; 0 when one is not a string or out of memory. */
static int take_words(part_info *p, const cJSON *options)
{
    p->count = cJSON_GetArraySize(options);
    p->words = calloc((size_t)p->count + 1, sizeof *p->words);
    int i = 0;
    const cJSON *w;
    cJSON_ArrayForEach(w, options)
    {
        if (!p->words || !cJSON_IsString(w))
            return 0;
        p->words[i++] = w->valuestring;
    }
    return p->words != NULL;
}

/* Reads the part.json of `part` into *p: 1, or 0 having printed why, naming the part or the file. */
static int read_part(const char *part, part_info *p)
{
    struct stat st;
    if (stat(part, &st) != 0) {
        fprintf(stderr, "lmgi: error: %s: no such part (%s)\n", part, strerror(errno));
        return 0;
    }
    json_of(part, p->where, sizeof p->where);
    size_t size;
    char *text = lm_cli_read_file(p->where, SIZE_MAX, &size);
    if (!text && errno == ENOENT)
        return no_part_json(part, p->where);
    if (!text) {
        fprintf(stderr, "lmgi: error: %s: %s\n", p->where, strerror(errno));
        return 0;
    }
    p->root = cJSON_Parse(text);
    free(text);
    const cJSON *scene = cJSON_GetObjectItemCaseSensitive(p->root, "scene");
    const cJSON *options = cJSON_GetObjectItemCaseSensitive(p->root, "options");
    if (!cJSON_IsString(scene) || !cJSON_IsArray(options) || !take_words(p, options)) {
        fprintf(stderr, "lmgi: error: %s: not a part.json of lmgi bake --shard (expected {\"scene\": PATH, "
                "\"options\": [WORDS]})\n", p->where);
        free_part(p);
        return 0;
    }
    p->scene = scene->valuestring;
    return 1;
}

/* "the options '--texels 8000 --photons 5000'" or "no options", cut short to fit. */
static void describe(const part_info *p, char *buf, size_t size)
{
    size_t used = (size_t)snprintf(buf, size, "%s", p->count ? "the options '" : "no options");
    for (int i = 0; i < p->count && used < size; i++)
        used += (size_t)snprintf(buf + used, size - used, "%s%s", i ? " " : "", p->words[i]);
    if (p->count && used < size)
        snprintf(buf + used, size - used, "'");
}

/* Part p was baked as the first one (the same scene, the same option words): 1, or 0 having said what
 * differs, naming both. */
static int same_bake(const part_info *first, const char *first_name, const part_info *p, const char *name)
{
    if (strcmp(first->scene, p->scene)) {
        fprintf(stderr, "lmgi: error: %s was baked from %s, %s from %s: merge the parts of one bake\n", name,
                p->scene, first_name, first->scene);
        return 0;
    }
    int same = first->count == p->count;
    for (int i = 0; same && i < p->count; i++)
        same = !strcmp(first->words[i], p->words[i]);
    if (!same) {
        char mine[1024], theirs[1024];
        describe(p, mine, sizeof mine);
        describe(first, theirs, sizeof theirs);
        fprintf(stderr, "lmgi: error: %s was baked with %s, %s with %s: merge the parts of one bake\n", name, mine,
                first_name, theirs);
    }
    return same;
}

static int scene_exists(const part_info *p, const char *part)
{
    struct stat st;
    if (stat(p->scene, &st) == 0)
        return 1;
    char options[1024] = "";
    for (int i = 0; i < p->count; i++) {
        size_t used = strlen(options);
        snprintf(options + used, sizeof options - used, " %s", p->words[i]);
    }
    fprintf(stderr, "lmgi: error: %s was baked from %s (%s), which is not there (%s); if the scene is elsewhere "
            "now: lmgi merge SCENE PART... --out DIR%s\n", part, p->scene, p->where, strerror(errno), options);
    return 0;
}

/* `merge PART...` takes the output options alone: the parts fix the scene and what is baked. */
static int only_output_options(const lm_cli_args *a)
{
    for (int i = 0; i < a->word_count; i++) {
        if (is_file_word(a->words[i]))
            continue;
        int with_value;
        const lm_cli_option *o = option_at(a, i, &with_value);
        if (o && !named(k_output_only, o)) {
            fprintf(stderr, "lmgi: merge PART... takes the scene and the bake's options from the parts, which fix "
                    "them: '%s' would change the bake (to give them: lmgi merge SCENE PART... --out DIR "
                    "[options])\n", a->words[i]);
            return 0;
        }
        i += with_value;
    }
    return 1;
}

/* *m: the bake's arguments as its shards had them (their words through the same parser), with the
 * recorded scene, the parts, and the merge's output and output options. */
static int bake_args(const part_info *p, const lm_cli_args *a, lm_cli_args *m)
{
    if (lm_cli_parse(p->count, p->words, 0, "bake", LM_CMD_BAKE, m) != 0 || m->file_count || m->out_dir ||
        m->shards || m->resume) {
        fprintf(stderr, "lmgi: error: %s: its options are not those of a shard's bake\n", p->where);
        return 0;
    }
    m->files[0] = p->scene;
    for (int i = 0; i < a->file_count; i++)
        m->files[1 + i] = a->files[i];
    m->file_count = 1 + a->file_count;
    m->out_dir = a->out_dir;
    m->force = a->force;
    m->quiet = a->quiet;
    m->verbose = a->verbose;
    m->gltf = a->gltf;
    m->accuracy = a->accuracy;
    m->half = a->half;
    return 1;
}

/* The bake of m (scene and options) from the parts' checkpoint files. */
static int merge_parts(const lm_cli_args *m, const char *const *files, int n)
{
    char (*paths)[PATH_SIZE] = malloc(sizeof *paths * (size_t)n);
    const char **parts = malloc(sizeof *parts * (size_t)n);
    int rc = 1;
    if (!paths || !parts)
        fprintf(stderr, "lmgi: error: no memory for %d parts\n", n);
    else {
        for (int p = 0; p < n; p++)
            checkpoint_of(files[p], paths[p], sizeof paths[p]), parts[p] = paths[p];
        rc = lm_cli_bake_merge(m, parts, n);
    }
    free(paths);
    free(parts);
    return rc;
}

/* `merge PART... --out DIR`: every part's part.json names the same scene and options, which are the
 * merge's. */
static int merge_recorded(const lm_cli_args *a)
{
    if (!only_output_options(a))
        return 2;
    if (a->file_count >= LM_CLI_MAX_FILES) {
        fprintf(stderr, "lmgi: merge takes at most %d parts\n", LM_CLI_MAX_FILES - 1);
        return 2;
    }
    int n = a->file_count, ok = 1, rc = 1;
    part_info *info = calloc((size_t)n, sizeof *info);
    lm_cli_args *m = malloc(sizeof *m);
    if (!info || !m)
        ok = 0, fprintf(stderr, "lmgi: error: no memory for %d parts\n", n);
    for (int p = 0; ok && p < n; p++)
        ok = read_part(a->files[p], &info[p]) && (p == 0 || same_bake(&info[0], a->files[0], &info[p], a->files[p]));
    if (ok && scene_exists(&info[0], a->files[0]) && bake_args(&info[0], a, m))
        rc = merge_parts(m, m->files + 1, n);
    for (int p = 0; info && p < n; p++)
        free_part(&info[p]);
    free(info);
    free(m);
    return rc;
}

/* Whether the merge's first file is a part (`merge PART...`) rather than a scene: a folder (a shard's),
 * a file named *.checkpoint, or one that starts as lmgi's checkpoints do ("LMGICKP" and the format's
 * version: an older format's part is still a part, for the library to refuse by name). */
static int is_part(const char *f)
{
    struct stat st;
    if (stat(f, &st) == 0 && S_ISDIR(st.st_mode))
        return 1;
    size_t n = strlen(f);
    if (n >= 11 && !strcmp(f + n - 11, ".checkpoint"))
        return 1;
    char head[7];
    FILE *in = fopen(f, "rb");
    int magic = in && fread(head, 1, sizeof head, in) == sizeof head && !memcmp(head, "LMGICKP", sizeof head);
    if (in)
        fclose(in);
    return magic;
}

int lm_cli_merge(const lm_cli_args *a)
{
    int recorded = a->file_count >= 1 && is_part(a->files[0]);
    if (!a->out_dir || (!recorded && a->file_count < 2)) {
        fprintf(stderr, "lmgi: merge needs the parts (each the folder lmgi bake SCENE --shard K/N --out PART "
                "wrote, or its part.checkpoint) and --out DIR; or the scene file, then the parts\n");
        return 2;
    }
    return recorded ? merge_recorded(a) : merge_parts(a, a->files + 1, a->file_count - 1);
}
