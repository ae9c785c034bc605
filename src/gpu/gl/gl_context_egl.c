/* The EGL backend: an OpenGL 4.5 core context without a window, on a GPU when there is one.
 * Displays are tried in order: each hardware device of EGL_EXT_platform_device (those with a DRM file
 * first), Mesa's surfaceless platform, the default display. The context is made current without a
 * surface (EGL_KHR_surfaceless_context) or on a 1x1 pbuffer; GL functions come from eglGetProcAddress,
 * which returns core functions too (EGL_KHR_get_all_proc_addresses, true of Mesa and NVIDIA). */
#include "gl_backend.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct lm_gl_egl {
    EGLDisplay dpy;
    EGLContext ctx;
    EGLSurface surf; /* EGL_NO_SURFACE when current without one */
    char where[160];
};

/* --- errors ------------------------------------------------------------------------------------- */

static const char *egl_error_name(EGLint code)
{
    static const struct { EGLint code; const char *name; } names[] = {
        {EGL_NOT_INITIALIZED, "EGL_NOT_INITIALIZED"}, {EGL_BAD_ACCESS, "EGL_BAD_ACCESS"},
        {EGL_BAD_ALLOC, "EGL_BAD_ALLOC"}, {EGL_BAD_ATTRIBUTE, "EGL_BAD_ATTRIBUTE"},
        {EGL_BAD_CONFIG, "EGL_BAD_CONFIG"}, {EGL_BAD_CONTEXT, "EGL_BAD_CONTEXT"},
        {EGL_BAD_CURRENT_SURFACE, "EGL_BAD_CURRENT_SURFACE"}, {EGL_BAD_DISPLAY, "EGL_BAD_DISPLAY"},
        {EGL_BAD_MATCH, "EGL_BAD_MATCH"}, {EGL_BAD_NATIVE_PIXMAP, "EGL_BAD_NATIVE_PIXMAP"},
        {EGL_BAD_NATIVE_WINDOW, "EGL_BAD_NATIVE_WINDOW"}, {EGL_BAD_PARAMETER, "EGL_BAD_PARAMETER"},
        {EGL_BAD_SURFACE, "EGL_BAD_SURFACE"}, {EGL_CONTEXT_LOST, "EGL_CONTEXT_LOST"},
    };
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
        if (names[i].code == code)
            return names[i].name;
    return "unknown EGL error";
}

/* "EGL (where): step failed (EGL_BAD_MATCH 0x3009)" with the error eglGetError reports now. */
static lm_status egl_fail(lm_error *err, const char *where, const char *step)
{
    EGLint code = eglGetError();
    return lm_fail(err, LM_ERR_BACKEND, "EGL (%s): %s failed (%s 0x%04x)", where, step, egl_error_name(code),
                   (unsigned)code);
}

/* Whether the space-separated extension list has `name` as a whole word. */
static int has_extension(const char *list, const char *name)
{
    size_t n = strlen(name);
    for (const char *p = list; p && (p = strstr(p, name)) != NULL; p += n)
        if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0'))
            return 1;
    return 0;
}

/* --- one display: config, context, current ---------------------------------------------------------
 * A display stays initialized for the life of the process (eglInitialize again is a no-op): eglTerminate
 * would end every other context on the same display and unload the driver, only for the next context to
 * load it again. */

static lm_status try_display(lm_gl_egl *e, EGLDisplay dpy, EGLContext share, lm_error *err)
{
    if (dpy == EGL_NO_DISPLAY)
        return egl_fail(err, e->where, "getting the display");
    EGLint major = 0, minor = 0;
    if (!eglInitialize(dpy, &major, &minor))
        return egl_fail(err, e->where, "eglInitialize");
    e->dpy = dpy;
    if (!eglBindAPI(EGL_OPENGL_API))
        return egl_fail(err, e->where, "eglBindAPI(EGL_OPENGL_API)");

    /* A pbuffer-capable config if there is one (needed without EGL_KHR_surfaceless_context), else any. */
    EGLint config_attribs[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_SURFACE_TYPE, EGL_PBUFFER_BIT,
                               EGL_NONE};
    EGLConfig config = NULL;
    EGLint configs = 0;
    if (!eglChooseConfig(dpy, config_attribs, &config, 1, &configs))
        return egl_fail(err, e->where, "eglChooseConfig");
    if (configs == 0) {
        config_attribs[3] = 0;
        if (!eglChooseConfig(dpy, config_attribs, &config, 1, &configs))
            return egl_fail(err, e->where, "eglChooseConfig");
    }
    if (configs == 0)
        return lm_fail(err, LM_ERR_BACKEND, "EGL (%s): eglChooseConfig found no config for desktop OpenGL "
                       "(EGL_OPENGL_BIT)", e->where);

    const EGLint context_attribs[] = {
        EGL_CONTEXT_MAJOR_VERSION, 4,
        EGL_CONTEXT_MINOR_VERSION, 5,
        EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
        EGL_NONE,
    };
    e->ctx = eglCreateContext(dpy, config, share, context_attribs);
    if (e->ctx == EGL_NO_CONTEXT) /* sharing: EGL_BAD_MATCH when the host's is OpenGL ES */
        return egl_fail(err, e->where, share != EGL_NO_CONTEXT ? "eglCreateContext (OpenGL 4.5 core, sharing "
                        "with the host's context, which must be desktop OpenGL)" : "eglCreateContext (OpenGL 4.5 core)");

    if (!has_extension(eglQueryString(dpy, EGL_EXTENSIONS), "EGL_KHR_surfaceless_context")) {
        EGLint surface_type = 0;
        eglGetConfigAttrib(dpy, config, EGL_SURFACE_TYPE, &surface_type);
        if (!(surface_type & EGL_PBUFFER_BIT))
            return lm_fail(err, LM_ERR_BACKEND, "EGL (%s): neither EGL_KHR_surfaceless_context nor a pbuffer "
                           "config", e->where);
        const EGLint pbuffer_attribs[] = {EGL_WIDTH, 1, EGL_HEIGHT, 1, EGL_NONE};
        e->surf = eglCreatePbufferSurface(dpy, config, pbuffer_attribs);
        if (e->surf == EGL_NO_SURFACE)
            return egl_fail(err, e->where, "eglCreatePbufferSurface (1x1)");
    }
    return lm_gl_egl_make_current(e, err);
}

/* Undoes a failed try_display so the next display can be tried with the same struct. */
static void untry_display(lm_gl_egl *e)
{
    if (e->dpy == EGL_NO_DISPLAY)
        return;
    if (e->ctx != EGL_NO_CONTEXT && eglGetCurrentContext() == e->ctx)
        lm_gl_egl_release_current();
    if (e->surf != EGL_NO_SURFACE)
        eglDestroySurface(e->dpy, e->surf);
    if (e->ctx != EGL_NO_CONTEXT)
        eglDestroyContext(e->dpy, e->ctx);
    e->dpy = EGL_NO_DISPLAY;
    e->ctx = EGL_NO_CONTEXT;
    e->surf = EGL_NO_SURFACE;
}

/* --- the displays to try, in order ----------------------------------------------------------------- */

#define MAX_CANDIDATES 18
typedef struct {
    EGLDisplay dpy;
    char where[160];
} candidate;

/* Hardware devices of EGL_EXT_platform_device: those naming a DRM file first. Mesa's software device
 * (EGL_MESA_device_software) is left out: the surfaceless platform gives the same llvmpipe. */
static int device_candidates(candidate *out, int max, const char *client_exts,
                             PFNEGLGETPLATFORMDISPLAYEXTPROC get_platform_display)
{
    if (!get_platform_display || !has_extension(client_exts, "EGL_EXT_platform_device"))
        return 0;
    PFNEGLQUERYDEVICESEXTPROC query_devices =
        (PFNEGLQUERYDEVICESEXTPROC)eglGetProcAddress("eglQueryDevicesEXT");
    PFNEGLQUERYDEVICESTRINGEXTPROC query_string =
        (PFNEGLQUERYDEVICESTRINGEXTPROC)eglGetProcAddress("eglQueryDeviceStringEXT");
    if (!query_devices || !query_string)
        return 0;
    EGLDeviceEXT devices[16];
    EGLint count = 0;
    if (!query_devices(16, devices, &count))
        return 0;
    int n = 0;
    for (int with_file = 1; with_file >= 0; with_file--) {
        for (EGLint i = 0; i < count && n < max; i++) {
            const char *exts = query_string(devices[i], EGL_EXTENSIONS);
            if (has_extension(exts, "EGL_MESA_device_software"))
                continue;
            const char *file = NULL;
            if (has_extension(exts, "EGL_EXT_device_drm_render_node"))
                file = query_string(devices[i], EGL_DRM_RENDER_NODE_FILE_EXT);
            if (!file && has_extension(exts, "EGL_EXT_device_drm"))
                file = query_string(devices[i], EGL_DRM_DEVICE_FILE_EXT);
            if ((file != NULL) != with_file)
                continue;
            out[n].dpy = get_platform_display(EGL_PLATFORM_DEVICE_EXT, devices[i], NULL);
            if (file)
                snprintf(out[n].where, sizeof out[n].where, "device %s", file);
            else
                snprintf(out[n].where, sizeof out[n].where, "EGL device %d", (int)i);
            n++;
        }
    }
    eglGetError(); /* a failed string query above leaves an error nobody asked about */
    return n;
}

static int all_candidates(candidate *out)
{
    const char *client_exts = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    if (!client_exts)
        eglGetError(); /* no client extensions: EGL 1.4 without EGL_EXT_client_extensions */
    PFNEGLGETPLATFORMDISPLAYEXTPROC get_platform_display = NULL;
    if (has_extension(client_exts, "EGL_EXT_platform_base"))
        get_platform_display = (PFNEGLGETPLATFORMDISPLAYEXTPROC)eglGetProcAddress("eglGetPlatformDisplayEXT");
    int n = device_candidates(out, MAX_CANDIDATES - 2, client_exts, get_platform_display);
    if (get_platform_display && has_extension(client_exts, "EGL_MESA_platform_surfaceless")) {
        out[n].dpy = get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, NULL);
        snprintf(out[n].where, sizeof out[n].where, "surfaceless platform");
        n++;
    }
    out[n].dpy = eglGetDisplay(EGL_DEFAULT_DISPLAY);
    snprintf(out[n].where, sizeof out[n].where, "default display");
    return n + 1;
}

/* --- the interface --------------------------------------------------------------------------------- */

lm_status lm_gl_egl_create(const lm_gl_share *share, lm_gl_egl **out, lm_error *err)
{
    *out = NULL;
    lm_gl_egl *e = calloc(1, sizeof *e);
    if (!e)
        return lm_fail(err, LM_ERR_NOMEM, "no memory for an EGL context");
    e->dpy = EGL_NO_DISPLAY;
    e->ctx = EGL_NO_CONTEXT;
    e->surf = EGL_NO_SURFACE;

    candidate cands[MAX_CANDIDATES];
    int count = 1;
    if (share) { /* the host's display, which the host initialized */
        cands[0].dpy = (EGLDisplay)share->display;
        snprintf(cands[0].where, sizeof cands[0].where, "the host's display");
    } else {
        count = all_candidates(cands);
    }
    EGLContext share_ctx = share ? (EGLContext)share->context : EGL_NO_CONTEXT;
    char tried[sizeof err->msg] = "";
    size_t used = 0;
    for (int i = 0; i < count; i++) {
        lm_error one;
        memcpy(e->where, cands[i].where, sizeof e->where);
        if (try_display(e, cands[i].dpy, share_ctx, &one) == LM_OK) {
            *out = e;
            return LM_OK;
        }
        untry_display(e);
        if (count == 1) {
            free(e);
            if (err)
                *err = one;
            return one.status;
        }
        int w = snprintf(tried + used, sizeof tried - used, "%s%s", i ? "; " : "", one.msg);
        if (w > 0)
            used = used + (size_t)w < sizeof tried ? used + (size_t)w : sizeof tried - 1;
    }
    free(e);
    return lm_fail(err, LM_ERR_BACKEND, "EGL: no display gave an OpenGL 4.5 core context: %s", tried);
}

lm_status lm_gl_egl_make_current(lm_gl_egl *e, lm_error *err)
{
    eglBindAPI(EGL_OPENGL_API);
    if (!eglMakeCurrent(e->dpy, e->surf, e->surf, e->ctx))
        return egl_fail(err, e->where, "eglMakeCurrent");
    return LM_OK;
}

void lm_gl_egl_release_current(void)
{
    eglBindAPI(EGL_OPENGL_API);
    EGLDisplay dpy = eglGetCurrentDisplay();
    if (dpy != EGL_NO_DISPLAY)
        eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
}

void lm_gl_egl_destroy(lm_gl_egl *e)
{
    if (!e)
        return;
    untry_display(e);
    free(e);
}

/* --- the host's context ---------------------------------------------------------------------------- */

int lm_gl_egl_host_take(lm_gl_egl_host *h)
{
    memset(h, 0, sizeof *h);
    EGLContext ctx = eglGetCurrentContext();
    if (ctx == EGL_NO_CONTEXT)
        return 0;
    h->api = (unsigned)eglQueryAPI();
    h->dpy = eglGetCurrentDisplay();
    h->ctx = ctx;
    h->draw = eglGetCurrentSurface(EGL_DRAW);
    h->read = eglGetCurrentSurface(EGL_READ);
    eglMakeCurrent(h->dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT); /* under the host's own API */
    return 1;
}

void lm_gl_egl_host_give_back(const lm_gl_egl_host *h)
{
    if (!h->ctx)
        return;
    eglBindAPI((EGLenum)h->api);
    eglMakeCurrent(h->dpy, h->draw, h->read, h->ctx);
}

lm_gl_proc lm_gl_egl_get_proc(const char *name) { return (lm_gl_proc)eglGetProcAddress(name); }

const char *lm_gl_egl_where(const lm_gl_egl *e) { return e->where; }
