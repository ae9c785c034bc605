#include "fail.h"

#include <stdarg.h>
#include <stdio.h>

lmgi_status lm_cli_fail(lmgi_error *err, lmgi_status st, const char *fmt, ...)
{
    err->status = st;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err->message, sizeof err->message, fmt, ap);
    va_end(ap);
    return st;
}
