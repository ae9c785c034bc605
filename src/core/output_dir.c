#include "output_dir.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include "image.h"

#define MANIFEST ".lmgi"
#define LOCK ".lmgi.lock"
#define STAGE ".lmgi-new"
#define HEADER "lmgi output 1\n"
#define LEGACY "lmgi writes into this directory"
#define MAX_INPUTS 16

/* A file as lmgi placed it: its inode (rename keeps it), size and modification time. A user's file put
 * under the name, or lmgi's file written over in place, no longer matches. All 0: a working file, which
 * lmgi itself rewrites under its name. */
typedef struct {
    unsigned long long ino, size, mtime_ns;
} stamp;

typedef struct {
    char command[32];
    char name[256];
    stamp at; /* when lmgi placed it */
} entry;

typedef struct {
    entry *v;
    size_t n, cap;
} entries;

struct lm_output {
    char dir[4096], stage[4200], command[32];
    int lock_fd, marked, legacy; /* a manifest found; an older lmgi's marker */
    entries manifest; /* as on disk */
    struct {
        dev_t dev;
        ino_t ino;
        char path[512];
    } inputs[MAX_INPUTS];
    int input_count;
};

static int plain_name(const char *name)
{
    size_t n = strlen(name);
    if (n == 0 || n > 255 || name[0] == '.')
        return 0;
    for (const char *c = name; *c; c++)
        if (*c == '/' || *c == '\t' || *c == '\n' || *c == '\r')
            return 0;
    return 1;
}

static int plain_command(const char *c)
{
    size_t n = strlen(c);
    if (n == 0 || n >= sizeof ((entry *)0)->command)
        return 0;
    for (; *c; c++)
        if (!((*c >= 'a' && *c <= 'z') || *c == '-'))
            return 0;
    return 1;
}

static ptrdiff_t find(const entries *m, const char *name)
{
    for (size_t i = 0; i < m->n; i++)
        if (!strcmp(m->v[i].name, name))
            return (ptrdiff_t)i;
    return -1;
}

/* Adds NAME under COMMAND, or hands an existing entry of that name to COMMAND. */
static stamp stamp_of(const struct stat *s)
{
    return (stamp){(unsigned long long)s->st_ino, (unsigned long long)s->st_size,
                   (unsigned long long)s->st_mtim.tv_sec * 1000000000ull + (unsigned long long)s->st_mtim.tv_nsec};
}

static const stamp working = {0, 0, 0};

static int is_working(stamp s) { return s.ino == 0 && s.size == 0 && s.mtime_ns == 0; }

static lm_status put(entries *m, const char *command, const char *name, stamp at_, lm_error *err)
{
    ptrdiff_t at = find(m, name);
    if (at < 0) {
        if (m->n == m->cap) {
            size_t cap = m->cap ? 2 * m->cap : 64;
            entry *v = realloc(m->v, cap * sizeof *v);
            if (!v)
                return lm_fail(err, LM_ERR_NOMEM, "output directory: no memory for its manifest");
            m->v = v, m->cap = cap;
        }
        at = (ptrdiff_t)m->n++;
        snprintf(m->v[at].name, sizeof m->v[at].name, "%s", name);
    }
    snprintf(m->v[at].command, sizeof m->v[at].command, "%s", command);
    m->v[at].at = at_;
    return LM_OK;
}

static void path_in(char *path, size_t size, const char *dir, const char *name)
{
    snprintf(path, size, "%s/%s", dir, name);
}

/* The manifest, or an empty one where there is none (or an older lmgi's marker: o->legacy). */
static lm_status read_manifest(lm_output *o, lm_error *err)
{
    char path[4200];
    path_in(path, sizeof path, o->dir, MANIFEST);
    int fd = open(path, O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
    if (fd < 0 && errno == ENOENT)
        return LM_OK;
    FILE *f = fd < 0 ? NULL : fdopen(fd, "r");
    if (!f) {
        if (fd >= 0)
            close(fd);
        return lm_fail(err, LM_ERR_IO, "%s: cannot read lmgi's manifest (%s)", path, strerror(errno));
    }
    char line[400];
    lm_status st = LM_OK;
    o->marked = 1;
    if (!fgets(line, sizeof line, f))
        line[0] = '\0';
    if (!strncmp(line, LEGACY, strlen(LEGACY)))
        o->legacy = 1;
    else if (strcmp(line, HEADER))
        st = lm_fail(err, LM_ERR_IO, "%s: not lmgi's manifest; lmgi leaves this directory alone", path);
    while (st == LM_OK && !o->legacy && fgets(line, sizeof line, f)) {
        char command[40], name[300];
        stamp at;
        if (sscanf(line, "%39[a-z-]\t%llu\t%llu\t%llu\t%299[^\n]", command, &at.ino, &at.size, &at.mtime_ns, name) == 5 &&
            plain_command(command) && plain_name(name))
            st = put(&o->manifest, command, name, at, err);
    }
    fclose(f);
    return st;
}

static lm_status write_manifest(const lm_output *o, const entries *m, lm_error *err)
{
    size_t cap = sizeof HEADER + m->n * (sizeof(entry) + 72);
    char *text = malloc(cap);
    if (!text)
        return lm_fail(err, LM_ERR_NOMEM, "output directory: no memory for its manifest");
    size_t len = (size_t)snprintf(text, cap, HEADER);
    for (size_t i = 0; i < m->n; i++)
        len += (size_t)snprintf(text + len, cap - len, "%s\t%llu\t%llu\t%llu\t%s\n", m->v[i].command, m->v[i].at.ino,
                                m->v[i].at.size, m->v[i].at.mtime_ns, m->v[i].name);
    char path[4200];
    path_in(path, sizeof path, o->dir, MANIFEST);
    lm_status st = lm_write_file(path, text, len, err);
    free(text);
    return st;
}

static lm_status take_lock(lm_output *o, lm_error *err)
{
    char path[4200];
    path_in(path, sizeof path, o->dir, LOCK);
    o->lock_fd = open(path, O_RDWR | O_CREAT | O_NOFOLLOW | O_CLOEXEC, 0644);
    if (o->lock_fd < 0)
        return lm_fail(err, LM_ERR_IO, "%s: cannot open the lock (%s)", path, strerror(errno));
    if (flock(o->lock_fd, LOCK_EX | LOCK_NB) != 0) {
        char holder[64] = "";
        ssize_t n = pread(o->lock_fd, holder, sizeof holder - 1, 0);
        holder[n > 0 ? n : 0] = '\0';
        holder[strcspn(holder, "\n")] = '\0';
        return lm_fail(err, LM_ERR_IO, "%s: another lmgi command is writing into this directory (process %s); "
                       "wait for it to finish or choose another directory", o->dir, holder[0] ? holder : "?");
    }
    char holder[64];
    int n = snprintf(holder, sizeof holder, "%ld %s\n", (long)getpid(), o->command);
    if (ftruncate(o->lock_fd, 0) != 0 || pwrite(o->lock_fd, holder, (size_t)n, 0) != n)
        return lm_fail(err, LM_ERR_IO, "%s: cannot write the lock (%s)", path, strerror(errno));
    return LM_OK;
}

/* Whether DIR/NAME is a file lmgi placed: listed, and the same file (a user's file put in place of
 * lmgi's under its name is not lmgi's). A name with nothing there counts as lmgi's. */
static int ours(const lm_output *o, const char *name)
{
    ptrdiff_t at = find(&o->manifest, name);
    if (at < 0)
        return 0;
    char path[4400];
    path_in(path, sizeof path, o->dir, name);
    struct stat s;
    if (lstat(path, &s) != 0)
        return 1;
    stamp now = stamp_of(&s), then = o->manifest.v[at].at;
    return is_working(then) || (now.ino == then.ino && now.size == then.size && now.mtime_ns == then.mtime_ns);
}

/* lmgi's own bookkeeping, and NAME.partial of its manifest or of a working file (a write a kill
 * interrupted: the new result's own partial files are in the staging folder). A NAME.partial beside one
 * of lmgi's finished files is not lmgi's to remove. */
static int bookkeeping(const lm_output *o, const char *name, int *partial)
{
    *partial = 0;
    if (!strcmp(name, ".") || !strcmp(name, "..") || !strcmp(name, MANIFEST) || !strcmp(name, LOCK) ||
        !strcmp(name, STAGE))
        return 1;
    size_t n = strlen(name);
    if (n > 8 && !strcmp(name + n - 8, ".partial")) {
        char base[256];
        snprintf(base, sizeof base, "%.*s", (int)(n - 8), name);
        ptrdiff_t at = find(&o->manifest, base);
        if (!strcmp(base, MANIFEST) || (at >= 0 && is_working(o->manifest.v[at].at)))
            return *partial = 1;
    }
    return 0;
}

/* Removes what a killed command left (its partial files), and refuses foreign files unless force. */
static lm_status survey(lm_output *o, int force, lm_error *err)
{
    DIR *d = opendir(o->dir);
    if (!d)
        return lm_fail(err, LM_ERR_IO, "%s: cannot list (%s)", o->dir, strerror(errno));
    char foreign[256] = "";
    lm_status st = LM_OK;
    for (struct dirent *e; st == LM_OK && (e = readdir(d));) {
        int partial;
        if (bookkeeping(o, e->d_name, &partial)) {
            char path[4400];
            path_in(path, sizeof path, o->dir, e->d_name);
            if (partial && unlink(path) != 0 && errno != ENOENT)
                st = lm_fail(err, LM_ERR_IO, "%s: cannot remove (%s)", path, strerror(errno));
        } else if (!foreign[0] && !ours(o, e->d_name)) {
            snprintf(foreign, sizeof foreign, "%s", e->d_name);
        }
    }
    closedir(d);
    if (st == LM_OK && foreign[0] && !force && !o->marked)
        st = lm_fail(err, LM_ERR_IO, "%s: holds '%s', which lmgi did not write%s; give a new or empty directory, or "
                     "--force (lmgi then writes beside your files and never removes or replaces one)", o->dir,
                     foreign, o->legacy ? " (or an lmgi before output manifests did; it cannot tell)" : "");
    return st;
}

/* Empties and removes DIR/.lmgi-new (a file level only: lmgi never makes folders there). */
static lm_status clear_stage(const char *stage, lm_error *err)
{
    struct stat s;
    if (lstat(stage, &s) != 0)
        return errno == ENOENT ? LM_OK : lm_fail(err, LM_ERR_IO, "%s: %s", stage, strerror(errno));
    if (!S_ISDIR(s.st_mode))
        return lm_fail(err, LM_ERR_IO, "%s: not lmgi's staging folder; remove it", stage);
    DIR *d = opendir(stage);
    if (!d)
        return lm_fail(err, LM_ERR_IO, "%s: cannot list (%s)", stage, strerror(errno));
    for (struct dirent *e; (e = readdir(d));)
        if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..")) {
            char path[4500];
            path_in(path, sizeof path, stage, e->d_name);
            unlink(path);
        }
    closedir(d);
    if (rmdir(stage) != 0 && errno != ENOENT)
        return lm_fail(err, LM_ERR_IO, "%s: cannot remove (%s)", stage, strerror(errno));
    return LM_OK;
}

static int same_file(const struct stat *s, const lm_output *o, const char **which)
{
    for (int i = 0; i < o->input_count; i++)
        if (o->inputs[i].dev == s->st_dev && o->inputs[i].ino == s->st_ino)
            return *which = o->inputs[i].path, 1;
    return 0;
}

/* Refuses when DIR/NAME is an input, or a file lmgi did not write. */
static lm_status check_place(const lm_output *o, const char *name, lm_error *err)
{
    char path[4400];
    path_in(path, sizeof path, o->dir, name);
    struct stat s;
    const char *input;
    if (lstat(path, &s) != 0)
        return LM_OK;
    if (same_file(&s, o, &input))
        return lm_fail(err, LM_ERR_IO, "%s: is this command's input %s; lmgi will not replace it (choose another "
                       "output directory)", path, input);
    if (!ours(o, name))
        return lm_fail(err, LM_ERR_IO, "%s: lmgi did not write this file and will not replace it; move it or "
                       "choose another output directory", path);
    return LM_OK;
}

static lm_status note_inputs(lm_output *o, const char *const *inputs, lm_error *err)
{
    for (; inputs && *inputs; inputs++) {
        struct stat s;
        if (o->input_count == MAX_INPUTS || stat(*inputs, &s) != 0)
            continue; /* an input that is not there cannot be overwritten */
        o->inputs[o->input_count].dev = s.st_dev, o->inputs[o->input_count].ino = s.st_ino;
        snprintf(o->inputs[o->input_count++].path, sizeof o->inputs[0].path, "%s", *inputs);
    }
    for (size_t i = 0; i < o->manifest.n; i++) { /* what commit could replace or remove */
        if (strcmp(o->manifest.v[i].command, o->command))
            continue;
        char path[4400];
        path_in(path, sizeof path, o->dir, o->manifest.v[i].name);
        struct stat s;
        const char *input;
        if (lstat(path, &s) == 0 && same_file(&s, o, &input))
            return lm_fail(err, LM_ERR_IO, "%s: the input %s is this directory's earlier '%s' output, which this "
                           "command would replace; write into another directory", o->dir, input, o->command);
    }
    return LM_OK;
}

lm_status lm_output_open(const char *dir, const char *command, int force, const char *const *inputs,
                         lm_output **out, lm_error *err)
{
    *out = NULL;
    if (!dir || !dir[0] || strlen(dir) >= sizeof ((lm_output *)0)->dir)
        return lm_fail(err, LM_ERR_INVALID, "output directory: bad name '%s'", dir ? dir : "(null)");
    if (!command || !plain_command(command))
        return lm_fail(err, LM_ERR_INVALID, "output directory: bad command name '%s' (a-z and -, under 32)",
                       command ? command : "(null)");
    lm_output *o = calloc(1, sizeof *o);
    if (!o)
        return lm_fail(err, LM_ERR_NOMEM, "output directory: no memory");
    snprintf(o->dir, sizeof o->dir, "%s", dir);
    snprintf(o->stage, sizeof o->stage, "%s/" STAGE, dir);
    snprintf(o->command, sizeof o->command, "%s", command);
    o->lock_fd = -1;
    lm_status st = lm_mkdir_p(dir, err);
    if (st == LM_OK && access(dir, W_OK) != 0)
        st = lm_fail(err, LM_ERR_IO, "%s: not writable", dir);
    if (st == LM_OK)
        st = take_lock(o, err);
    if (st == LM_OK)
        st = read_manifest(o, err);
    if (st == LM_OK)
        st = survey(o, force, err);
    if (st == LM_OK)
        st = note_inputs(o, inputs, err);
    if (st == LM_OK)
        st = clear_stage(o->stage, err);
    if (st == LM_OK && mkdir(o->stage, 0700) != 0)
        st = lm_fail(err, LM_ERR_IO, "%s: cannot create (%s)", o->stage, strerror(errno));
    if (st != LM_OK) {
        if (o->lock_fd >= 0)
            close(o->lock_fd);
        free(o->manifest.v);
        free(o);
        return st;
    }
    *out = o;
    return LM_OK;
}

const char *lm_output_stage(const lm_output *o)
{
    return o->stage;
}

static lm_status name_ok(const char *name, lm_error *err)
{
    if (!name || !plain_name(name))
        return lm_fail(err, LM_ERR_INVALID, "output file name '%s': a plain file name, not starting with '.'",
                       name ? name : "(null)");
    return LM_OK;
}

/* FOLDER/NAME for a file lmgi may place as NAME: a plain name, not a foreign file or an input in DIR. */
static lm_status path_for(const lm_output *o, const char *folder, const char *name, char *path, size_t size,
                          lm_error *err)
{
    lm_status st = name_ok(name, err);
    if (st == LM_OK)
        st = check_place(o, name, err);
    if (st == LM_OK && snprintf(path, size, "%s/%s", folder, name) >= (int)size)
        st = lm_fail(err, LM_ERR_INVALID, "%s/%s: path too long", folder, name);
    return st;
}

lm_status lm_output_file(lm_output *o, const char *name, char *path, size_t size, lm_error *err)
{
    return path_for(o, o->stage, name, path, size, err);
}

lm_status lm_output_work_file(lm_output *o, const char *name, char *path, size_t size, lm_error *err)
{
    lm_status st = path_for(o, o->dir, name, path, size, err);
    ptrdiff_t at = find(&o->manifest, name);
    if (st == LM_OK &&
        (at < 0 || strcmp(o->manifest.v[at].command, o->command) || !is_working(o->manifest.v[at].at))) {
        st = put(&o->manifest, o->command, name, working, err); /* rewritten by lmgi under its name */
        if (st == LM_OK)
            st = write_manifest(o, &o->manifest, err);
    }
    return st;
}

/* The stage's files: every one must be a plain file lmgi may place in DIR. */
static lm_status list_stage(lm_output *o, entries *fresh, lm_error *err)
{
    DIR *d = opendir(o->stage);
    if (!d)
        return lm_fail(err, LM_ERR_IO, "%s: cannot list (%s)", o->stage, strerror(errno));
    lm_status st = LM_OK;
    for (struct dirent *e; st == LM_OK && (e = readdir(d));) {
        if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, ".."))
            continue;
        char path[4500];
        path_in(path, sizeof path, o->stage, e->d_name);
        struct stat s;
        if (!plain_name(e->d_name) || lstat(path, &s) != 0 || !S_ISREG(s.st_mode))
            st = lm_fail(err, LM_ERR_IO, "%s: not a file lmgi wrote", path);
        else
            st = check_place(o, e->d_name, err);
        if (st == LM_OK)
            st = put(fresh, o->command, e->d_name, working, err);
    }
    closedir(d);
    return st;
}

static void release(lm_output *o)
{
    close(o->lock_fd);
    free(o->manifest.v);
    free(o);
}

/* Moves the fresh files in and removes this command's earlier files the fresh result lacks. */
static lm_status swap_in(lm_output *o, const entries *fresh, lm_error *err)
{
    entries all = {0};
    lm_status st = LM_OK;
    for (size_t i = 0; st == LM_OK && i < o->manifest.n; i++)
        st = put(&all, o->manifest.v[i].command, o->manifest.v[i].name, o->manifest.v[i].at, err);
    for (size_t i = 0; st == LM_OK && i < fresh->n; i++)
        st = put(&all, o->command, fresh->v[i].name, working, err); /* until moved: a kill leaves it lmgi's */
    if (st == LM_OK)
        st = write_manifest(o, &all, err); /* every file lmgi may leave here, before any moves */
    for (size_t i = 0; st == LM_OK && i < fresh->n; i++) {
        char from[4500], to[4400];
        path_in(from, sizeof from, o->stage, fresh->v[i].name);
        path_in(to, sizeof to, o->dir, fresh->v[i].name);
        struct stat placed;
        if (rename(from, to) != 0 || lstat(to, &placed) != 0)
            st = lm_fail(err, LM_ERR_IO, "%s: cannot move into place (%s)", to, strerror(errno));
        else
            all.v[find(&all, fresh->v[i].name)].at = stamp_of(&placed);
    }
    entries kept = {0};
    for (size_t i = 0; st == LM_OK && i < all.n; i++) {
        const entry *e = &all.v[i];
        if (strcmp(e->command, o->command) || find(fresh, e->name) >= 0) {
            st = put(&kept, e->command, e->name, e->at, err);
            continue;
        }
        char path[4400];
        path_in(path, sizeof path, o->dir, e->name);
        if (ours(o, e->name) && unlink(path) != 0 && errno != ENOENT)
            st = lm_fail(err, LM_ERR_IO, "%s: cannot remove the earlier output (%s)", path, strerror(errno));
    }
    if (st == LM_OK)
        st = write_manifest(o, &kept, err);
    free(all.v);
    free(kept.v);
    return st;
}

lm_status lm_output_commit(lm_output *o, lm_error *err)
{
    entries fresh = {0};
    lm_status st = list_stage(o, &fresh, err);
    if (st == LM_OK)
        st = swap_in(o, &fresh, err);
    free(fresh.v);
    lm_error ignored;
    clear_stage(o->stage, &ignored);
    release(o);
    return st;
}

void lm_output_abort(lm_output *o)
{
    if (!o)
        return;
    lm_error ignored;
    clear_stage(o->stage, &ignored);
    release(o);
}
