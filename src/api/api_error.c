#include "api_error.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

lmgi_status lm_export_error(lmgi_error *out, const lm_error *in)
{
    if (out) {
        out->status = (lmgi_status)in->status;
        memcpy(out->message, in->msg, sizeof out->message);
    }
    return (lmgi_status)in->status;
}

lmgi_status lm_api_refuse(lmgi_error *err, const char *fmt, ...)
{
    lm_error e;
    e.status = LM_ERR_INVALID;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(e.msg, sizeof e.msg, fmt, ap);
    va_end(ap);
    return lm_export_error(err, &e);
}
