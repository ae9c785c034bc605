/* Choosing the GL backend at run time (LMGI_GL), loading its function table, and which context is
 * current on each thread. The backends themselves are gl_context_osmesa.c and gl_context_egl.c. */
#include "gl_context.h"

#include "gl_api.h"
#include "gl_backend.h"

#include <ctype.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct lm_gl_context {
    lm_gl_backend backend;
    lm_gl_osmesa *osmesa;
    lm_gl_egl *egl;
    lm_gl_fns fns;
    char description[512];
};

/* The lmgi context current on this thread (lm_gl_cur is its function table). */
static _Thread_local lm_gl_context *t_current;

/* The guest scope (lm_gl_guest_enter): its depth, and the host's context taken from this thread. */
static _Thread_local int t_guest_depth, t_host_taken;
static _Thread_local struct {
    lm_gl_egl_host egl;
    lm_gl_glx_host glx;
    lm_gl_osmesa_host osmesa;
} t_host;

/* auto: once EGL has failed or given a software renderer, later contexts of this process skip it. */
static pthread_mutex_t g_auto_lock = PTHREAD_MUTEX_INITIALIZER;
static int g_auto_skip_egl;
static char g_auto_reason[300];

/* dst = a + b, cut to fit (a message quoted inside another may be cut). */
static void join_cut(char *dst, size_t size, const char *a, const char *b)
{
    size_t na = strnlen(a, size - 1), nb = strnlen(b, size - 1 - na);
    memmove(dst, a, na);
    memmove(dst + na, b, nb);
    dst[na + nb] = '\0';
}

const char *lm_gl_backend_name(lm_gl_backend backend)
{
    return backend == LM_GL_BACKEND_EGL ? "EGL" : "OSMesa";
}

static void set_current(lm_gl_context *ctx)
{
    t_current = ctx;
    lm_gl_cur = ctx ? &ctx->fns : NULL;
}

/* Releases this thread's current context if it belongs to another backend than `next` (both backends can
 * share Mesa's dispatch, so one must let go before the other takes the thread). */
static void release_other_backend(const lm_gl_context *next)
{
    if (!t_current || (next && t_current->backend == next->backend))
        return;
    if (t_current->backend == LM_GL_BACKEND_EGL)
        lm_gl_egl_release_current();
    else
        lm_gl_osmesa_release_current();
    set_current(NULL);
}

static void close_backend(lm_gl_context *ctx)
{
    if (t_current == ctx) {
        release_other_backend(NULL);
        set_current(NULL);
    }
    lm_gl_egl_destroy(ctx->egl);
    lm_gl_osmesa_destroy(ctx->osmesa);
    ctx->egl = NULL;
    ctx->osmesa = NULL;
}

/* Before lmgi makes a context current inside a guest scope: the host's, if any, is saved and let go
 * (a GLX context current would make glvnd refuse an EGL one; OSMesa and Mesa's EGL share one slot). */
static void take_thread_from_host(void)
{
    if (t_guest_depth == 0 || t_host_taken)
        return;
    lm_gl_glx_host_take(&t_host.glx);
    lm_gl_egl_host_take(&t_host.egl);
    lm_gl_osmesa_host_take(&t_host.osmesa);
    t_host_taken = 1;
}

void lm_gl_guest_enter(void) { t_guest_depth++; }

void lm_gl_guest_leave(void)
{
    if (t_guest_depth == 0 || --t_guest_depth > 0 || !t_host_taken)
        return;
    release_other_backend(NULL);
    lm_gl_osmesa_host_give_back(&t_host.osmesa);
    lm_gl_egl_host_give_back(&t_host.egl);
    lm_gl_glx_host_give_back(&t_host.glx);
    memset(&t_host, 0, sizeof t_host);
    t_host_taken = 0;
}

/* Creates the backend's context, makes it current, loads the function table and checks for GL 4.5. */
static lm_status open_backend(lm_gl_context *ctx, lm_gl_backend backend, const lm_gl_share *share, lm_error *err)
{
    ctx->backend = backend;
    take_thread_from_host();
    release_other_backend(ctx);
    lm_status st;
    if (backend == LM_GL_BACKEND_EGL)
        st = lm_gl_egl_create(share, &ctx->egl, err);
    else
        st = lm_gl_osmesa_create(share ? share->context : NULL, &ctx->osmesa, err);
    if (st != LM_OK)
        return st;
    set_current(ctx);
    st = lm_gl_fns_load(&ctx->fns, backend == LM_GL_BACKEND_EGL ? lm_gl_egl_get_proc : lm_gl_osmesa_get_proc,
                        lm_gl_backend_name(backend), err);
    if (st != LM_OK) {
        close_backend(ctx);
        return st;
    }
    GLint major = 0, minor = 0;
    glGetIntegerv(GL_MAJOR_VERSION, &major);
    glGetIntegerv(GL_MINOR_VERSION, &minor);
    if (major * 10 + minor < 45) {
        close_backend(ctx);
        return lm_fail(err, LM_ERR_BACKEND, "%s: OpenGL %d.%d context; lmgi needs 4.5 core",
                       lm_gl_backend_name(backend), major, minor);
    }
    return LM_OK;
}

static const char *gl_string(GLenum name)
{
    const GLubyte *s = glGetString(name);
    return s ? (const char *)s : "?";
}

/* Mesa's and others' CPU rasterizers: EGL on one of these gives nothing OSMesa does not. */
static int is_software_renderer(const char *renderer)
{
    static const char *const software[] = {"llvmpipe", "softpipe", "swrast", "lavapipe",
                                           "software rasterizer"};
    char lower[256];
    size_t n = 0;
    for (; renderer[n] && n + 1 < sizeof lower; n++)
        lower[n] = (char)tolower((unsigned char)renderer[n]);
    lower[n] = '\0';
    for (size_t i = 0; i < sizeof software / sizeof software[0]; i++)
        if (strstr(lower, software[i]))
            return 1;
    return 0;
}

/* LMGI_GL=auto: EGL if it gives a hardware renderer, else OSMesa; `why` says why OSMesa was taken. */
static lm_status open_auto(lm_gl_context *ctx, char *why, size_t why_size, lm_error *err)
{
    pthread_mutex_lock(&g_auto_lock);
    int skip = g_auto_skip_egl;
    if (!skip) {
        lm_error egl_err;
        if (open_backend(ctx, LM_GL_BACKEND_EGL, NULL, &egl_err) != LM_OK) {
            join_cut(g_auto_reason, sizeof g_auto_reason, "EGL failed: ", egl_err.msg);
            g_auto_skip_egl = skip = 1;
        } else if (is_software_renderer(gl_string(GL_RENDERER))) {
            join_cut(g_auto_reason, sizeof g_auto_reason, "EGL gave ", gl_string(GL_RENDERER));
            close_backend(ctx);
            g_auto_skip_egl = skip = 1;
        }
    }
    join_cut(why, why_size, "", g_auto_reason);
    pthread_mutex_unlock(&g_auto_lock);
    if (!skip)
        return LM_OK;
    return open_backend(ctx, LM_GL_BACKEND_OSMESA, NULL, err);
}

lm_status lm_gl_context_create_backend(const char *backend, const lm_gl_share *share, lm_gl_context **out,
                                       lm_error *err)
{
    *out = NULL;
    const char *choice = backend && *backend ? backend : share ? NULL : getenv("LMGI_GL");
    if (!choice || !*choice)
        choice = "auto";
    if (strcmp(choice, "auto") && strcmp(choice, "egl") && strcmp(choice, "osmesa"))
        return lm_fail(err, LM_ERR_INVALID, "%s%s is not a GL backend; use auto (the default), egl or osmesa",
                       backend && *backend ? "" : "LMGI_GL=", choice);
    if (share) { /* the host's kind decides */
        const char *kind = share->display ? "egl" : "osmesa";
        if (strcmp(choice, "auto") && strcmp(choice, kind))
            return lm_fail(err, LM_ERR_INVALID, "the GL backend %s cannot share the host's %s context (%s)", choice,
                           share->display ? "EGL" : "OSMesa", share->display ? "a display was given" : "no display");
        choice = kind;
    }
    lm_gl_context *ctx = calloc(1, sizeof *ctx);
    if (!ctx)
        return lm_fail(err, LM_ERR_NOMEM, "no memory for a GL context");
    char why[320];
    lm_status st;
    if (!strcmp(choice, "auto")) {
        st = open_auto(ctx, why, sizeof why, err);
    } else {
        snprintf(why, sizeof why, "%s%s", share ? "sharing the host's " : backend && *backend ? "asked for " : "LMGI_GL=",
                 choice);
        st = open_backend(ctx, strcmp(choice, "egl") ? LM_GL_BACKEND_OSMESA : LM_GL_BACKEND_EGL, share, err);
    }
    if (st != LM_OK) {
        free(ctx);
        return st;
    }
    const char *version = gl_string(GL_VERSION), *renderer = gl_string(GL_RENDERER);
    int forced = strcmp(choice, "auto") != 0;
    if (ctx->backend == LM_GL_BACKEND_EGL)
        snprintf(ctx->description, sizeof ctx->description, "%s / %s (EGL, %s%s%s)", version, renderer,
                 lm_gl_egl_where(ctx->egl), forced ? "; " : "", forced ? why : "");
    else
        snprintf(ctx->description, sizeof ctx->description, "%s / %s (OSMesa; %s)", version, renderer, why);
    *out = ctx;
    return LM_OK;
}

lm_status lm_gl_context_create(lm_gl_context **out, lm_error *err)
{
    return lm_gl_context_create_backend(NULL, NULL, out, err);
}

void lm_gl_context_destroy(lm_gl_context *ctx)
{
    if (!ctx)
        return;
    close_backend(ctx);
    free(ctx);
}

lm_status lm_gl_make_current(lm_gl_context *ctx, lm_error *err)
{
    if (!ctx) {
        release_other_backend(NULL);
        return LM_OK;
    }
    take_thread_from_host();
    release_other_backend(ctx);
    lm_status st = ctx->backend == LM_GL_BACKEND_EGL ? lm_gl_egl_make_current(ctx->egl, err)
                                                     : lm_gl_osmesa_make_current(ctx->osmesa, err);
    if (st == LM_OK)
        set_current(ctx);
    return st;
}

lm_gl_backend lm_gl_context_backend(const lm_gl_context *ctx) { return ctx->backend; }
const char *lm_gl_context_description(const lm_gl_context *ctx) { return ctx->description; }

lm_gl_proc lm_gl_get_proc(const char *name)
{
    if (!t_current)
        return NULL;
    return t_current->backend == LM_GL_BACKEND_EGL ? lm_gl_egl_get_proc(name) : lm_gl_osmesa_get_proc(name);
}

int lm_gl_context_is_software(const lm_gl_context *ctx)
{
    return ctx && is_software_renderer(lm_gl_context_description(ctx));
}

int lm_gl_current_is_software(void) { return lm_gl_context_is_software(t_current); }

void lm_gl_finish(void)
{
    if (lm_gl_cur)
        glFinish();
}
