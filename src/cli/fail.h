/* The command's errors: the public lmgi_error, filled by the CLI's own checks as by the library. */
#ifndef LM_CLI_FAIL_H
#define LM_CLI_FAIL_H

#include <lmgi.h>

/* Fills err with st and the formatted message, and returns st. */
lmgi_status lm_cli_fail(lmgi_error *err, lmgi_status st, const char *fmt, ...) __attribute__((format(printf, 3, 4)));

#endif
