#include "gl_shader.h"

#include "gl_api.h"

static lm_status compile(const char *name, const char *stage, GLenum type, const char *src, GLuint *out,
                         lm_error *err)
{
    GLuint sh = glCreateShader(type);
    glShaderSource(sh, 1, &src, NULL);
    glCompileShader(sh);
    GLint ok = 0;
    glGetShaderiv(sh, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[700];
        glGetShaderInfoLog(sh, sizeof log, NULL, log);
        glDeleteShader(sh);
        return lm_fail(err, LM_ERR_BACKEND, "shader '%s' (%s) failed to compile:\n%s", name, stage, log);
    }
    *out = sh;
    return LM_OK;
}

static lm_status link(const char *name, GLuint prog, lm_error *err)
{
    glLinkProgram(prog);
    GLint ok = 0;
    glGetProgramiv(prog, GL_LINK_STATUS, &ok);
    if (!ok) {
        char log[700];
        glGetProgramInfoLog(prog, sizeof log, NULL, log);
        glDeleteProgram(prog);
        return lm_fail(err, LM_ERR_BACKEND, "program '%s' failed to link:\n%s", name, log);
    }
    return LM_OK;
}

lm_status lm_gl_program(const char *name, const char *vs, const char *fs, unsigned *program, lm_error *err)
{
    GLuint v = 0, f = 0;
    lm_status st = compile(name, "vertex", GL_VERTEX_SHADER, vs, &v, err);
    if (st != LM_OK)
        return st;
    st = compile(name, "fragment", GL_FRAGMENT_SHADER, fs, &f, err);
    if (st != LM_OK) {
        glDeleteShader(v);
        return st;
    }
    GLuint prog = glCreateProgram();
    glAttachShader(prog, v);
    glAttachShader(prog, f);
    st = link(name, prog, err);
    glDeleteShader(v);
    glDeleteShader(f);
    if (st == LM_OK)
        *program = prog;
    return st;
}

lm_status lm_gl_compute_program(const char *name, const char *cs, unsigned *program, lm_error *err)
{
    GLuint c = 0;
    lm_status st = compile(name, "compute", GL_COMPUTE_SHADER, cs, &c, err);
    if (st != LM_OK)
        return st;
    GLuint prog = glCreateProgram();
    glAttachShader(prog, c);
    st = link(name, prog, err);
    glDeleteShader(c);
    if (st == LM_OK)
        *program = prog;
    return st;
}

lm_status lm_gl_check(const char *what, lm_error *err)
{
    GLenum e = glGetError();
    if (e != GL_NO_ERROR)
        return lm_fail(err, LM_ERR_BACKEND, "%s: OpenGL error 0x%04x", what, (unsigned)e);
    return LM_OK;
}
