/* The OpenGL context lmgi renders with: an OpenGL 4.5 core profile without a window. Rendering goes to
 * framebuffer objects the caller makes.
 *
 * The backend is chosen at run time by the environment variable LMGI_GL:
 *   auto (or unset)  EGL when it gives a hardware renderer (a GPU), else OSMesa;
 *   egl              EGL only (an error if it fails);
 *   osmesa           OSMesa only (Mesa llvmpipe; the tested path).
 * GL functions are called through the current context's function table (gl_api.h). */
#ifndef LM_GL_CONTEXT_H
#define LM_GL_CONTEXT_H

#include "../../core/error.h"

typedef enum { LM_GL_BACKEND_OSMESA = 0, LM_GL_BACKEND_EGL = 1 } lm_gl_backend;

typedef struct lm_gl_context lm_gl_context;

/* Creates a GL >= 4.5 core context and makes it current on the calling thread. */
lm_status lm_gl_context_create(lm_gl_context **out, lm_error *err);
/* A host's context to share objects (textures) with: an EGLContext of desktop OpenGL with its EGLDisplay,
 * or an OSMesaContext (display NULL). The new context is made on that display, in that context's share
 * group, so a texture lmgi makes is a name the host's context can bind. */
typedef struct {
    void *display, *context;
} lm_gl_share;
/* The same with the backend named ("auto", "egl", "osmesa"; NULL or "": LMGI_GL decides) and, unless
 * share is NULL, sharing with a host's context: then the backend is the share's kind (EGL with a display,
 * OSMesa without), and a backend named otherwise is refused (LM_ERR_INVALID). */
lm_status lm_gl_context_create_backend(const char *backend, const lm_gl_share *share, lm_gl_context **out,
                                       lm_error *err);
void lm_gl_context_destroy(lm_gl_context *ctx);
lm_status lm_gl_make_current(lm_gl_context *ctx, lm_error *err);
lm_gl_backend lm_gl_context_backend(const lm_gl_context *ctx);
/* "OSMesa" or "EGL". */
const char *lm_gl_backend_name(lm_gl_backend backend);
/* Waits until the current context's GPU has done every command given so far (glFinish): before a time
 * is taken that must hold that work (on a GPU, a gather's draws are still queued when its calls return). */
void lm_gl_finish(void);
/* 1 when the context's GL rasterizes on the CPU (llvmpipe and its kind). */
int lm_gl_context_is_software(const lm_gl_context *ctx);
/* The same for the context current on the calling thread (0 if none is). */
int lm_gl_current_is_software(void);
/* Version, renderer, backend and why: "4.5 (Core Profile) Mesa 22.3.6 / llvmpipe (LLVM 15.0.6, 256 bits)
 * (OSMesa; EGL gave llvmpipe ...)" or "... (EGL, device /dev/dri/renderD128)". */
const char *lm_gl_context_description(const lm_gl_context *ctx);
/* Being a good guest in a host's process. A public call runs between lm_gl_guest_enter and
 * lm_gl_guest_leave. The first time lmgi makes one of its contexts current inside the scope, the
 * calling thread's current context (the host's: EGL with its bound API and surfaces, GLX, or OSMesa with
 * its buffer) is saved and released; leaving the outermost scope releases lmgi's and makes the host's
 * current again, as it was (none, if none was). Outside any scope (lmgi's own tests and tools) a context
 * stays current as made. Per thread; nests. Cost: nothing for a call that makes no context current,
 * else a few queries and two more make-currents (each may flush the host's GL commands). */
void lm_gl_guest_enter(void);
void lm_gl_guest_leave(void);

/* Entry point of a GL function from the backend of the context current on the calling thread (e.g.
 * glClipControl); NULL if none is current or the backend has no such function. */
typedef void (*lm_gl_proc)(void);
lm_gl_proc lm_gl_get_proc(const char *name);

#endif
