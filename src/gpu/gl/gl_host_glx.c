/* The host's GLX context (gl_backend.h): found through the GLX library the process has already loaded,
 * never by loading one. A host with a GLX context current has libGLX (glvnd) or libGL loaded; one
 * without either has none, and lmgi needs no X library to build or run. */
#include "gl_backend.h"

#include <dlfcn.h>
#include <pthread.h>
#include <string.h>

typedef void *(*get_pointer_fn)(void);
typedef unsigned long (*get_drawable_fn)(void);
typedef int (*make_current_fn)(void *dpy, unsigned long draw, unsigned long read, void *ctx);

static struct {
    get_pointer_fn context, display;
    get_drawable_fn drawable, read_drawable;
    make_current_fn make_current;
} g_glx;
static _Thread_local int t_looked;

/* Looks for GLX in the libraries loaded now; a host that loads GLX later than its first call into lmgi
 * is looked for again on each call until found (RTLD_NOLOAD costs a lookup in the loaded list). */
static int find_glx(void)
{
    static pthread_mutex_t lock = PTHREAD_MUTEX_INITIALIZER;
    if (t_looked) /* found before: the table stays */
        return 1;
    pthread_mutex_lock(&lock);
    if (!g_glx.make_current) {
        const char *const names[] = {"libGLX.so.0", "libGL.so.1"};
        for (size_t i = 0; i < sizeof names / sizeof names[0] && !g_glx.make_current; i++) {
            void *lib = dlopen(names[i], RTLD_LAZY | RTLD_NOLOAD);
            if (!lib)
                continue;
            /* POSIX's way of taking a function from dlsym's object pointer */
            *(void **)&g_glx.context = dlsym(lib, "glXGetCurrentContext");
            *(void **)&g_glx.display = dlsym(lib, "glXGetCurrentDisplay");
            *(void **)&g_glx.drawable = dlsym(lib, "glXGetCurrentDrawable");
            *(void **)&g_glx.read_drawable = dlsym(lib, "glXGetCurrentReadDrawable");
            void *mc = dlsym(lib, "glXMakeContextCurrent");
            if (g_glx.context && g_glx.display && g_glx.drawable && g_glx.read_drawable && mc)
                *(void **)&g_glx.make_current = mc; /* set last: the others are ready once it is */
        }
    }
    int found = g_glx.make_current != NULL;
    pthread_mutex_unlock(&lock);
    t_looked = found;
    return found;
}

int lm_gl_glx_host_take(lm_gl_glx_host *h)
{
    memset(h, 0, sizeof *h);
    if (!find_glx())
        return 0;
    void *ctx = g_glx.context();
    if (!ctx)
        return 0;
    h->ctx = ctx;
    h->dpy = g_glx.display();
    h->draw = g_glx.drawable();
    h->read = g_glx.read_drawable();
    g_glx.make_current(h->dpy, 0, 0, NULL); /* glvnd lets no EGL context be made current over it */
    return 1;
}

void lm_gl_glx_host_give_back(const lm_gl_glx_host *h)
{
    if (h->ctx)
        g_glx.make_current(h->dpy, h->draw, h->read, h->ctx);
}
