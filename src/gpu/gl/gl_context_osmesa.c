/* The OSMesa backend: a headless Mesa (llvmpipe) OpenGL 4.5 core context with a 1x1 dummy buffer;
 * rendering goes to framebuffer objects. libOSMesa is opened when first needed, not linked: it brings
 * Mesa's LLVM (over 100 MB), which a program on a machine with a GPU (EGL) does without. */
#include "gl_backend.h"

#include <GL/osmesa.h>
#include <dlfcn.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define OSMESA_LIBRARY "libOSMesa.so.8"

/* The library's functions lmgi calls; all of them or none (g_why says why none). */
static struct {
    OSMesaContext (*create)(const int *attribs, OSMesaContext share);
    GLboolean (*make_current)(OSMesaContext, void *, GLenum, GLsizei, GLsizei);
    OSMesaContext (*get_current)(void);
    void (*destroy)(OSMesaContext);
    OSMESAproc (*get_proc)(const char *);
    GLboolean (*get_color_buffer)(OSMesaContext, GLint *, GLint *, GLint *, void **);
    void (*get_integerv)(GLint, GLint *);
    void (*pixel_store)(GLint, GLint);
} g_os;
static char g_why[300];
static pthread_once_t g_once = PTHREAD_ONCE_INIT;

static void open_library(void)
{
    void *lib = dlopen(OSMESA_LIBRARY, RTLD_NOW | RTLD_LOCAL);
    if (!lib) {
        snprintf(g_why, sizeof g_why, "%s", dlerror());
        return;
    }
    /* POSIX's way of taking a function from dlsym's object pointer */
    const struct { void **fn; const char *name; } syms[] = {
        {(void **)&g_os.create, "OSMesaCreateContextAttribs"}, {(void **)&g_os.make_current, "OSMesaMakeCurrent"},
        {(void **)&g_os.get_current, "OSMesaGetCurrentContext"}, {(void **)&g_os.destroy, "OSMesaDestroyContext"},
        {(void **)&g_os.get_proc, "OSMesaGetProcAddress"}, {(void **)&g_os.get_color_buffer, "OSMesaGetColorBuffer"},
        {(void **)&g_os.get_integerv, "OSMesaGetIntegerv"}, {(void **)&g_os.pixel_store, "OSMesaPixelStore"},
    };
    for (size_t i = 0; i < sizeof syms / sizeof syms[0]; i++)
        if (!(*syms[i].fn = dlsym(lib, syms[i].name))) {
            snprintf(g_why, sizeof g_why, "%s has no %s (Mesa older than 20?)", OSMESA_LIBRARY, syms[i].name);
            memset(&g_os, 0, sizeof g_os);
            return;
        }
}

/* 1 once the library is open; a host's OSMesa context can only be current if it is. */
static int loaded(void)
{
    pthread_once(&g_once, open_library);
    return g_os.create != NULL;
}

struct lm_gl_osmesa {
    OSMesaContext ctx;
    unsigned char dummy[4 * 4];
};

lm_status lm_gl_osmesa_create(void *share, lm_gl_osmesa **out, lm_error *err)
{
    *out = NULL;
    if (!loaded())
        return lm_fail(err, LM_ERR_BACKEND, "OSMesa is not available: %s (Debian: apt-get install libosmesa6)",
                       g_why);
    lm_gl_osmesa *o = calloc(1, sizeof *o);
    if (!o)
        return lm_fail(err, LM_ERR_NOMEM, "no memory for an OSMesa context");
    const int attribs[] = {
        OSMESA_FORMAT, OSMESA_RGBA,
        OSMESA_DEPTH_BITS, 24,
        OSMESA_PROFILE, OSMESA_CORE_PROFILE,
        OSMESA_CONTEXT_MAJOR_VERSION, 4,
        OSMESA_CONTEXT_MINOR_VERSION, 5,
        0,
    };
    o->ctx = g_os.create(attribs, (OSMesaContext)share);
    if (!o->ctx) {
        free(o);
        return lm_fail(err, LM_ERR_BACKEND, "OSMesa could not create an OpenGL 4.5 core context%s "
                       "(is libosmesa6 from Mesa >= 20 installed?)", share ? " sharing with the host's" : "");
    }
    lm_status st = lm_gl_osmesa_make_current(o, err);
    if (st != LM_OK) {
        lm_gl_osmesa_destroy(o);
        return st;
    }
    *out = o;
    return LM_OK;
}

lm_status lm_gl_osmesa_make_current(lm_gl_osmesa *o, lm_error *err)
{
    if (!g_os.make_current(o->ctx, o->dummy, GL_UNSIGNED_BYTE, 1, 1))
        return lm_fail(err, LM_ERR_BACKEND, "OSMesa: OSMesaMakeCurrent failed");
    return LM_OK;
}

void lm_gl_osmesa_release_current(void)
{
    if (g_os.get_current())
        g_os.make_current(NULL, NULL, 0, 0, 0);
}

void lm_gl_osmesa_destroy(lm_gl_osmesa *o)
{
    if (!o)
        return;
    if (o->ctx)
        g_os.destroy(o->ctx);
    free(o);
}

/* Whether the process has libOSMesa, opened by the host or by lmgi (never opened here for the asking). */
static int present(void)
{
    if (g_os.create)
        return 1;
    void *lib = dlopen(OSMESA_LIBRARY, RTLD_NOW | RTLD_NOLOAD);
    if (!lib)
        return 0;
    dlclose(lib);
    return loaded();
}

int lm_gl_osmesa_host_take(lm_gl_osmesa_host *h)
{
    memset(h, 0, sizeof *h);
    if (!present())
        return 0;
    OSMesaContext ctx = g_os.get_current();
    if (!ctx)
        return 0;
    GLint format = 0;
    h->ctx = ctx;
    g_os.get_color_buffer(ctx, &h->width, &h->height, &format, &h->buffer);
    g_os.get_integerv(OSMESA_TYPE, &h->type);
    g_os.get_integerv(OSMESA_ROW_LENGTH, &h->row_length);
    g_os.get_integerv(OSMESA_Y_UP, &h->y_up);
    g_os.make_current(NULL, NULL, 0, 0, 0);
    return 1;
}

void lm_gl_osmesa_host_give_back(const lm_gl_osmesa_host *h)
{
    if (!h->ctx)
        return;
    g_os.make_current(h->ctx, h->buffer, (GLenum)h->type, h->width, h->height);
    g_os.pixel_store(OSMESA_ROW_LENGTH, h->row_length);
    g_os.pixel_store(OSMESA_Y_UP, h->y_up);
}

lm_gl_proc lm_gl_osmesa_get_proc(const char *name) { return (lm_gl_proc)g_os.get_proc(name); }
