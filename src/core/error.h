/* Error reporting shared by every layer: a status code plus a message that names the file or object
 * and the problem. Functions that can fail return lm_status and fill an lm_error the caller owns. */
#ifndef LM_ERROR_H
#define LM_ERROR_H

#include <stddef.h>

typedef enum {
    LM_OK = 0,
    LM_ERR_IO,          /* file missing, unreadable, unwritable */
    LM_ERR_FORMAT,      /* malformed file: bad JSON, truncated binary, out-of-range accessor */
    LM_ERR_INVALID,     /* invalid value: NaN/Inf, degenerate geometry in strict mode, bad argument */
    LM_ERR_UNSUPPORTED, /* a required extension or feature lmgi does not implement */
    LM_ERR_NOMEM,
    LM_ERR_BACKEND,     /* Embree or OpenGL failed */
    LM_ERR_CANCELLED    /* the caller's cancel flag stopped the work */
} lm_status;

typedef struct {
    lm_status status;
    char msg[1024];
} lm_error;

/* Sets err (if non-NULL) and returns status, so callers can write `return lm_fail(err, ...)`. */
lm_status lm_fail(lm_error *err, lm_status status, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
void lm_error_clear(lm_error *err);
const char *lm_status_name(lm_status s);

#endif
