#include "out_dir.h"

#include <stdio.h>
#include <stdlib.h>
#include <sys/stat.h>

#include "scene_load.h"

/* The command line's input files, NULL-terminated, into `in` (LM_CLI_MAX_FILES + 4 entries). */
static void inputs_of(const lm_cli_args *a, const char **in)
{
    int n = 0;
    for (int i = 0; i < a->file_count; i++)
        in[n++] = a->files[i];
    const char *more[3] = {a->edits_path, a->gather_scene, lm_cli_sky_image()};
    for (int i = 0; i < 3; i++)
        if (more[i])
            in[n++] = more[i];
    in[n] = NULL;
}

lmgi_output *lm_cli_open_out(const lm_cli_args *a, const char *command)
{
    const char *in[LM_CLI_MAX_FILES + 4];
    inputs_of(a, in);
    lmgi_output *o = NULL;
    lmgi_error err;
    if (lmgi_output_open(a->out_dir, command, a->force, in, &o, &err) == LMGI_OK)
        return o;
    fprintf(stderr, "lmgi: error: %s\n", err.message);
    return NULL;
}

int lm_cli_out_path(lmgi_output *o, const char *name, char *path, size_t size)
{
    lmgi_error err;
    if (lmgi_output_file(o, name, path, size, &err) == LMGI_OK)
        return 1;
    fprintf(stderr, "lmgi: error: %s\n", err.message);
    return 0;
}

int lm_cli_close_out(lmgi_output *o, int rc)
{
    if (!o)
        return rc;
    if (rc != 0) {
        lmgi_output_abort(o);
        return rc;
    }
    lmgi_error err;
    if (lmgi_output_commit(o, &err) == LMGI_OK)
        return 0;
    fprintf(stderr, "lmgi: error: %s\n", err.message);
    return 1;
}

lmgi_status lm_cli_write_image(lmgi_output *o, const char *name, int width, int height, int channels,
                               const float *pixels, const lmgi_image_desc *desc, lmgi_error *err)
{
    char path[4200];
    lmgi_status st = lmgi_output_file(o, name, path, sizeof path, err);
    return st == LMGI_OK ? lmgi_write_image(path, width, height, channels, pixels, desc, err) : st;
}

int lm_cli_single_allowed(const lm_cli_args *a, const char *path)
{
    const char *in[LM_CLI_MAX_FILES + 4];
    inputs_of(a, in);
    struct stat out, s;
    if (stat(path, &out) != 0)
        return 1;
    for (int i = 0; in[i]; i++)
        if (stat(in[i], &s) == 0 && s.st_dev == out.st_dev && s.st_ino == out.st_ino) {
            fprintf(stderr, "lmgi: error: %s: is the input %s; lmgi will not overwrite it\n", path, in[i]);
            return 0;
        }
    return 1;
}

int lm_cli_single_open(lm_cli_single *s)
{
    s->data = NULL, s->size = 0;
    s->f = open_memstream(&s->data, &s->size);
    if (!s->f)
        fprintf(stderr, "lmgi: error: no memory for an output file\n");
    return s->f != NULL;
}

int lm_cli_single_close(const lm_cli_args *a, const char *path, lm_cli_single *s)
{
    int ok = fclose(s->f) == 0;
    if (!ok)
        fprintf(stderr, "lmgi: error: %s: no memory for its contents\n", path);
    lmgi_error err;
    if (ok && (ok = lm_cli_single_allowed(a, path)) && lmgi_write_file(path, s->data, s->size, &err) != LMGI_OK)
        ok = 0, fprintf(stderr, "lmgi: error: %s\n", err.message);
    free(s->data);
    s->f = NULL, s->data = NULL;
    return ok;
}
