#include "gl_context.h"

#include <GL/osmesa.h>
#include "gl_api.h"
#include <stdio.h>
#include <stdlib.h>

struct lm_gl_context {
    lm_gl_backend backend;
    OSMesaContext osmesa;
    unsigned char dummy[4 * 4];
    char description[256];
};

static lm_status create_osmesa(lm_gl_context *ctx, lm_error *err)
{
    const int attribs[] = {
        OSMESA_FORMAT, OSMESA_RGBA,
        OSMESA_DEPTH_BITS, 24,
        OSMESA_PROFILE, OSMESA_CORE_PROFILE,
        OSMESA_CONTEXT_MAJOR_VERSION, 4,
        OSMESA_CONTEXT_MINOR_VERSION, 5,
        0,
    };
    ctx->osmesa = OSMesaCreateContextAttribs(attribs, NULL);
    if (!ctx->osmesa)
        return lm_fail(err, LM_ERR_BACKEND, "OSMesa could not create an OpenGL 4.5 core context "
                       "(is libosmesa6 from Mesa >= 20 installed?)");
    if (!OSMesaMakeCurrent(ctx->osmesa, ctx->dummy, GL_UNSIGNED_BYTE, 1, 1))
        return lm_fail(err, LM_ERR_BACKEND, "OSMesaMakeCurrent failed");
    return LM_OK;
}

lm_status lm_gl_context_create(lm_gl_context **out, lm_error *err)
{
    *out = NULL;
    lm_gl_context *ctx = calloc(1, sizeof *ctx);
    if (!ctx)
        return lm_fail(err, LM_ERR_NOMEM, "no memory for a GL context");
    ctx->backend = LM_GL_BACKEND_OSMESA;
    lm_status st = create_osmesa(ctx, err);
    if (st != LM_OK) {
        lm_gl_context_destroy(ctx);
        return st;
    }
    GLint major = 0, minor = 0;
    glGetIntegerv(GL_MAJOR_VERSION, &major);
    glGetIntegerv(GL_MINOR_VERSION, &minor);
    if (major * 10 + minor < 45) {
        lm_gl_context_destroy(ctx);
        return lm_fail(err, LM_ERR_BACKEND, "OpenGL %d.%d context; lmgi needs 4.5 core", major, minor);
    }
    snprintf(ctx->description, sizeof ctx->description, "%s / %s (OSMesa)",
             (const char *)glGetString(GL_VERSION), (const char *)glGetString(GL_RENDERER));
    *out = ctx;
    return LM_OK;
}

void lm_gl_context_destroy(lm_gl_context *ctx)
{
    if (!ctx)
        return;
    if (ctx->osmesa)
        OSMesaDestroyContext(ctx->osmesa);
    free(ctx);
}

lm_status lm_gl_make_current(lm_gl_context *ctx, lm_error *err)
{
    if (!OSMesaMakeCurrent(ctx->osmesa, ctx->dummy, GL_UNSIGNED_BYTE, 1, 1))
        return lm_fail(err, LM_ERR_BACKEND, "OSMesaMakeCurrent failed");
    return LM_OK;
}

lm_gl_backend lm_gl_context_backend(const lm_gl_context *ctx) { return ctx->backend; }
const char *lm_gl_context_description(const lm_gl_context *ctx) { return ctx->description; }

lm_gl_proc lm_gl_get_proc(const char *name) { return (lm_gl_proc)OSMesaGetProcAddress(name); }
