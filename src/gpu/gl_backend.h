/* The two ways gl_context.c gets an OpenGL 4.5 core context, behind one small interface each. Neither
 * includes a GL header here: OSMesa brings <GL/gl.h>, which must not meet gl_api.h's <GL/glcorearb.h>. */
#ifndef LM_GL_BACKEND_H
#define LM_GL_BACKEND_H

#include "../core/error.h"
#include "gl_context.h"

/* OSMesa (gl_context_osmesa.c): Mesa llvmpipe, drawing into a 1x1 dummy buffer. */
typedef struct lm_gl_osmesa lm_gl_osmesa;
/* Creates the context and makes it current on the calling thread. */
lm_status lm_gl_osmesa_create(lm_gl_osmesa **out, lm_error *err);
lm_status lm_gl_osmesa_make_current(lm_gl_osmesa *o, lm_error *err);
/* Leaves the calling thread with no OSMesa context current. */
void lm_gl_osmesa_release_current(void);
void lm_gl_osmesa_destroy(lm_gl_osmesa *o);
lm_gl_proc lm_gl_osmesa_get_proc(const char *name);

/* EGL (gl_context_egl.c): a device display (EGL_EXT_platform_device, hardware devices first), else
 * Mesa's surfaceless platform, else the default display; current without a surface or on a 1x1 pbuffer. */
typedef struct lm_gl_egl lm_gl_egl;
/* Creates the context and makes it current on the calling thread; every failure names its step. */
lm_status lm_gl_egl_create(lm_gl_egl **out, lm_error *err);
lm_status lm_gl_egl_make_current(lm_gl_egl *e, lm_error *err);
/* Leaves the calling thread with no EGL context current. */
void lm_gl_egl_release_current(void);
void lm_gl_egl_destroy(lm_gl_egl *e);
lm_gl_proc lm_gl_egl_get_proc(const char *name);
/* Where the context lives: "device /dev/dri/renderD128", "surfaceless platform", "default display". */
const char *lm_gl_egl_where(const lm_gl_egl *e);

#endif
