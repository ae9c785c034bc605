/* Errors as the public API hands them out: an internal lm_error copied into the caller's lmgi_error
 * (which may be NULL), and a refusal of bad arguments (LMGI_ERR_INVALID with a message naming what was
 * wrong). Used by every file of api/; depends on nothing else of it. */
#ifndef LM_API_ERROR_H
#define LM_API_ERROR_H

#include <lmgi.h>

#include "../core/error.h"

/* Copies an internal error into the public one and returns its status. */
lmgi_status lm_export_error(lmgi_error *out, const lm_error *in);
/* Fills err with LMGI_ERR_INVALID and the formatted message, and returns LMGI_ERR_INVALID. */
lmgi_status lm_api_refuse(lmgi_error *err, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

#endif
