/* The GL function table: the thread's current table and filling one from a backend's get-proc. */
#define LM_GL_API_NO_DISPATCH_MACROS /* this file names the table's members, which the macros would hide */
#include "gl_api.h"

_Thread_local const lm_gl_fns *lm_gl_cur;

lm_status lm_gl_fns_load(lm_gl_fns *fns, lm_gl_proc (*get_proc)(const char *name), const char *backend,
                         lm_error *err)
{
#define LM_GL_FNS_LOAD(name, type)                                                                       \
    fns->name = (type)get_proc(#name);                                                                    \
    if (!fns->name)                                                                                       \
        return lm_fail(err, LM_ERR_BACKEND, "%s: the GL entry point %s is missing", backend, #name);
    LM_GL_FUNCTIONS(LM_GL_FNS_LOAD)
#undef LM_GL_FNS_LOAD
    return LM_OK;
}
