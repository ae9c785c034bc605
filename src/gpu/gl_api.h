/* The OpenGL API as every GL file in lmgi sees it: include this, never <GL/gl.h> directly, so that the
 * entry points can come from whichever backend gl_context.h chose at run time. */
#ifndef LM_GL_API_H
#define LM_GL_API_H

#define GL_GLEXT_PROTOTYPES 1
#include <GL/gl.h>
#include <GL/glext.h>

#endif
