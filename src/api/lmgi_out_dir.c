/* The public API's output directories (lmgi_claim_output_dir): a marker file says which are lmgi's. */
#include <lmgi.h>

#include <dirent.h>
#include <errno.h>
#include <fnmatch.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "../core/image.h"
#include "lmgi_scene.h"

#define MARKER ".lmgi"

/* A command's own kind of output, and the NAME.partial files lm_write_file leaves when a run is killed
 * mid-write (every command's). */
static int matches(const char *name, const char *const *own)
{
    if (fnmatch("*.partial", name, 0) == 0)
        return 1;
    for (; *own; own++)
        if (fnmatch(*own, name, 0) == 0)
            return 1;
    return 0;
}

/* Whether DIR holds the marker, and the first other entry in it. */
static lm_status survey(const char *dir, int *marked, char *other, size_t n, lm_error *err)
{
    DIR *d = opendir(dir);
    if (!d)
        return lm_fail(err, LM_ERR_IO, "%s: cannot list (%s)", dir, strerror(errno));
    *marked = 0, other[0] = '\0';
    for (struct dirent *e; (e = readdir(d));) {
        if (!strcmp(e->d_name, MARKER))
            *marked = 1;
        else if (!other[0] && strcmp(e->d_name, ".") && strcmp(e->d_name, ".."))
            snprintf(other, n, "%s", e->d_name);
    }
    closedir(d);
    return LM_OK;
}

static lm_status remove_own(const char *dir, const char *const *own, lm_error *err)
{
    DIR *d = opendir(dir);
    if (!d)
        return lm_fail(err, LM_ERR_IO, "%s: cannot list (%s)", dir, strerror(errno));
    lm_status st = LM_OK;
    for (struct dirent *e; st == LM_OK && (e = readdir(d));) {
        if (!matches(e->d_name, own))
            continue;
        char path[4200];
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        if (remove(path) != 0 && errno != ENOENT)
            st = lm_fail(err, LM_ERR_IO, "%s: cannot remove the earlier output (%s)", path, strerror(errno));
    }
    closedir(d);
    return st;
}

static lm_status claim(const char *dir, int force, const char *const *own, lm_error *err)
{
    lm_status st = lm_mkdir_p(dir, err);
    if (st == LM_OK && access(dir, W_OK) != 0)
        st = lm_fail(err, LM_ERR_IO, "%s: not writable", dir);
    int marked = 0;
    char foreign[256];
    if (st == LM_OK)
        st = survey(dir, &marked, foreign, sizeof foreign, err);
    if (st == LM_OK && !marked && foreign[0] && !force)
        return lm_fail(err, LM_ERR_IO, "%s: not empty and not written by lmgi (it holds '%s'); give a new or "
                       "empty directory, or force the write (lmgi's --force; lmgi then removes only files named "
                       "like its own output)", dir, foreign);
    if (st == LM_OK)
        st = remove_own(dir, own, err);
    char marker[4200];
    snprintf(marker, sizeof marker, "%s/" MARKER, dir);
    static const char text[] = "lmgi writes into this directory; see the README, \"Output directories\"\n";
    if (st == LM_OK && !marked)
        st = lm_write_file(marker, text, sizeof text - 1, err);
    return st;
}

lmgi_status lmgi_claim_output_dir(const char *dir, int force, const char *const *own, lmgi_error *err)
{
    if (!dir)
        return lm_api_refuse(err, "lmgi_claim_output_dir: dir is NULL");
    static const char *const none[] = {NULL};
    lm_error e;
    return claim(dir, force, own ? own : none, &e) == LM_OK ? LMGI_OK : lm_export_error(err, &e);
}
