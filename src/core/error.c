#include "error.h"

#include <stdarg.h>
#include <stdio.h>

lm_status lm_fail(lm_error *err, lm_status status, const char *fmt, ...)
{
    if (err) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err->msg, sizeof err->msg, fmt, ap);
        va_end(ap);
        err->status = status;
    }
    return status;
}

void lm_error_clear(lm_error *err)
{
    if (err) {
        err->status = LM_OK;
        err->msg[0] = '\0';
    }
}

const char *lm_status_name(lm_status s)
{
    switch (s) {
    case LM_OK: return "ok";
    case LM_ERR_IO: return "I/O error";
    case LM_ERR_FORMAT: return "format error";
    case LM_ERR_INVALID: return "invalid input";
    case LM_ERR_UNSUPPORTED: return "unsupported";
    case LM_ERR_NOMEM: return "out of memory";
    case LM_ERR_BACKEND: return "backend error";
    case LM_ERR_CANCELLED: return "cancelled";
    }
    return "unknown error";
}
