/* The OSMesa backend: a headless Mesa (llvmpipe) OpenGL 4.5 core context with a 1x1 dummy buffer;
 * rendering goes to framebuffer objects. */
#include "gl_backend.h"

#include <GL/osmesa.h>
#include <stdlib.h>

struct lm_gl_osmesa {
    OSMesaContext ctx;
    unsigned char dummy[4 * 4];
};

lm_status lm_gl_osmesa_create(lm_gl_osmesa **out, lm_error *err)
{
    *out = NULL;
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
    o->ctx = OSMesaCreateContextAttribs(attribs, NULL);
    if (!o->ctx) {
        free(o);
        return lm_fail(err, LM_ERR_BACKEND, "OSMesa could not create an OpenGL 4.5 core context "
                       "(is libosmesa6 from Mesa >= 20 installed?)");
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
    if (!OSMesaMakeCurrent(o->ctx, o->dummy, GL_UNSIGNED_BYTE, 1, 1))
        return lm_fail(err, LM_ERR_BACKEND, "OSMesa: OSMesaMakeCurrent failed");
    return LM_OK;
}

void lm_gl_osmesa_release_current(void)
{
    if (OSMesaGetCurrentContext())
        OSMesaMakeCurrent(NULL, NULL, 0, 0, 0);
}

void lm_gl_osmesa_destroy(lm_gl_osmesa *o)
{
    if (!o)
        return;
    if (o->ctx)
        OSMesaDestroyContext(o->ctx);
    free(o);
}

lm_gl_proc lm_gl_osmesa_get_proc(const char *name) { return (lm_gl_proc)OSMesaGetProcAddress(name); }
