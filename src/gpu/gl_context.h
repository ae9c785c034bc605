/* The OpenGL context lmgi renders with: headless OSMesa (Mesa llvmpipe) with a 4.5 core profile.
 * Rendering goes to framebuffer objects the caller makes; the context's own buffer is a 1x1 dummy.
 * The backend is chosen at run time: the interface leaves room for EGL on machines with a GPU. */
#ifndef LM_GL_CONTEXT_H
#define LM_GL_CONTEXT_H

#include "../core/error.h"

typedef enum { LM_GL_BACKEND_OSMESA = 0 } lm_gl_backend;

typedef struct lm_gl_context lm_gl_context;

/* Creates a GL >= 4.5 core context and makes it current on the calling thread. */
lm_status lm_gl_context_create(lm_gl_context **out, lm_error *err);
void lm_gl_context_destroy(lm_gl_context *ctx);
lm_status lm_gl_make_current(lm_gl_context *ctx, lm_error *err);
lm_gl_backend lm_gl_context_backend(const lm_gl_context *ctx);
/* "4.5 (Core Profile) Mesa 22.3.6 / llvmpipe ..." */
const char *lm_gl_context_description(const lm_gl_context *ctx);
/* Entry point of a GL function the library does not export directly (e.g. glClipControl); NULL if none. */
typedef void (*lm_gl_proc)(void);
lm_gl_proc lm_gl_get_proc(const char *name);

#endif
