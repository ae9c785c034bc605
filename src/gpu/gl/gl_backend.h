/* The two ways gl_context.c gets an OpenGL 4.5 core context, behind one small interface each. Neither
 * includes a GL header here: OSMesa brings <GL/gl.h>, which must not meet gl_api.h's <GL/glcorearb.h>. */
#ifndef LM_GL_BACKEND_H
#define LM_GL_BACKEND_H

#include "../../core/error.h"
#include "gl_context.h"

/* OSMesa (gl_context_osmesa.c): Mesa llvmpipe, drawing into a 1x1 dummy buffer. */
typedef struct lm_gl_osmesa lm_gl_osmesa;
/* Creates the context (in share's share group unless it is NULL) and makes it current on the calling
 * thread. */
lm_status lm_gl_osmesa_create(void *share, lm_gl_osmesa **out, lm_error *err);
lm_status lm_gl_osmesa_make_current(lm_gl_osmesa *o, lm_error *err);
/* Leaves the calling thread with no OSMesa context current. */
void lm_gl_osmesa_release_current(void);
void lm_gl_osmesa_destroy(lm_gl_osmesa *o);
lm_gl_proc lm_gl_osmesa_get_proc(const char *name);

/* EGL (gl_context_egl.c): a device display (EGL_EXT_platform_device, hardware devices first), else
 * Mesa's surfaceless platform, else the default display; current without a surface or on a 1x1 pbuffer. */
typedef struct lm_gl_egl lm_gl_egl;
/* Creates the context and makes it current on the calling thread; every failure names its step. With a
 * share, only the share's display is tried, and the context joins the share context's group. */
lm_status lm_gl_egl_create(const lm_gl_share *share, lm_gl_egl **out, lm_error *err);
lm_status lm_gl_egl_make_current(lm_gl_egl *e, lm_error *err);
/* Leaves the calling thread with no EGL context current. */
void lm_gl_egl_release_current(void);
void lm_gl_egl_destroy(lm_gl_egl *e);
lm_gl_proc lm_gl_egl_get_proc(const char *name);
/* Where the context lives: "device /dev/dri/renderD128", "surfaceless platform", "default display". */
const char *lm_gl_egl_where(const lm_gl_egl *e);

/* --- the host's context: what a good guest saves and gives back (gl_context.c's guest scope) ----------
 * Each *_take saves the calling thread's current context of its kind, if any, and releases it (returns
 * 1 if one was current); each *_give_back makes the saved one current again, as it was. No GL header
 * here: the handles are kept as the kinds' own opaque pointers and XIDs. */

/* EGL: the bound client API (OpenGL ES is a host's usual) and the context with its surfaces. */
typedef struct {
    void *dpy, *ctx, *draw, *read;
    unsigned api;
} lm_gl_egl_host;
int lm_gl_egl_host_take(lm_gl_egl_host *h);
void lm_gl_egl_host_give_back(const lm_gl_egl_host *h);

/* OSMesa: the context with its colour buffer, data type, size, row length and orientation. */
typedef struct {
    void *ctx, *buffer;
    int type, width, height, row_length, y_up;
} lm_gl_osmesa_host;
int lm_gl_osmesa_host_take(lm_gl_osmesa_host *h);
void lm_gl_osmesa_host_give_back(const lm_gl_osmesa_host *h);

/* GLX (gl_host_glx.c), looked up in the host's libGLX or libGL if the process has loaded one: a host
 * without it has no GLX context, and lmgi links no X library. */
typedef struct {
    void *dpy, *ctx;
    unsigned long draw, read;
} lm_gl_glx_host;
int lm_gl_glx_host_take(lm_gl_glx_host *h);
void lm_gl_glx_host_give_back(const lm_gl_glx_host *h);

#endif
