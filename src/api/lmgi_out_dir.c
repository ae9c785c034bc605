/* The public API's output directories and whole-file writes: src/core/output_dir.h under lmgi_ names. */
#include <lmgi_tools.h>

#include <stdlib.h>

#include "../core/image.h"
#include "../core/output_dir.h"
#include "lmgi_scene.h"

struct lmgi_output {
    lm_output *o;
};

lmgi_status lmgi_write_file(const char *path, const void *data, size_t size, lmgi_error *err)
{
    if (!path || (!data && size))
        return lm_api_refuse(err, "lmgi_write_file: %s is NULL", path ? "data" : "path");
    lm_error e;
    return lm_write_file(path, data ? data : "", size, &e) == LM_OK ? LMGI_OK : lm_export_error(err, &e);
}

lmgi_status lmgi_output_open(const char *dir, const char *command, int force, const char *const *inputs,
                             lmgi_output **out, lmgi_error *err)
{
    if (!out)
        return lm_api_refuse(err, "lmgi_output_open: out is NULL");
    *out = NULL;
    if (!dir || !command)
        return lm_api_refuse(err, "lmgi_output_open: %s is NULL", dir ? "command" : "dir");
    lmgi_output *h = malloc(sizeof *h);
    if (!h)
        return lm_api_refuse(err, "lmgi_output_open: no memory");
    lm_error e;
    if (lm_output_open(dir, command, force, inputs, &h->o, &e) != LM_OK) {
        free(h);
        return lm_export_error(err, &e);
    }
    *out = h;
    return LMGI_OK;
}

static lmgi_status path_of(lmgi_output *o, const char *name, char *path, size_t size, int work, lmgi_error *err)
{
    static const char *const fn[2] = {"lmgi_output_file", "lmgi_output_work_file"};
    if (!o || !name || !path || !size)
        return lm_api_refuse(err, "%s: %s is NULL or empty", fn[work], !o ? "output" : !name ? "name" : "path");
    lm_error e;
    lm_status st = work ? lm_output_work_file(o->o, name, path, size, &e) : lm_output_file(o->o, name, path, size, &e);
    return st == LM_OK ? LMGI_OK : lm_export_error(err, &e);
}

lmgi_status lmgi_output_file(lmgi_output *o, const char *name, char *path, size_t size, lmgi_error *err)
{
    return path_of(o, name, path, size, 0, err);
}

lmgi_status lmgi_output_work_file(lmgi_output *o, const char *name, char *path, size_t size, lmgi_error *err)
{
    return path_of(o, name, path, size, 1, err);
}

lmgi_status lmgi_output_commit(lmgi_output *o, lmgi_error *err)
{
    if (!o)
        return lm_api_refuse(err, "lmgi_output_commit: output is NULL");
    lm_error e;
    lm_status st = lm_output_commit(o->o, &e);
    free(o);
    return st == LM_OK ? LMGI_OK : lm_export_error(err, &e);
}

void lmgi_output_abort(lmgi_output *o)
{
    if (!o)
        return;
    lm_output_abort(o->o);
    free(o);
}

const char *lmgi_output_folder(const lmgi_output *o)
{
    return o ? lm_output_stage(o->o) : NULL;
}
