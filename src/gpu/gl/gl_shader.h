/* Compiling and linking GLSL programs, with errors that name the shader and carry its log. */
#ifndef LM_GL_SHADER_H
#define LM_GL_SHADER_H

#include "../../core/error.h"

/* Builds a program from vertex + fragment source; the GL program name goes to *program. */
lm_status lm_gl_program(const char *name, const char *vs, const char *fs, unsigned *program, lm_error *err);
lm_status lm_gl_compute_program(const char *name, const char *cs, unsigned *program, lm_error *err);
/* Checks glGetError, naming `what` in the message. */
lm_status lm_gl_check(const char *what, lm_error *err);

#endif
