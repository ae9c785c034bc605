#include "log.h"

#include <stdarg.h>
#include <stdio.h>

static lm_log_level g_level = LM_LOG_WARN;
static int g_warnings;

void lm_log_set_level(lm_log_level level) { g_level = level; }
lm_log_level lm_log_get_level(void) { return g_level; }
int lm_log_warning_count(void) { return g_warnings; }
void lm_log_reset_warning_count(void) { g_warnings = 0; }

void lm_log(lm_log_level level, const char *fmt, ...)
{
    static const char *names[] = {"error", "warning", "info", "debug"};
    if (level == LM_LOG_WARN)
        g_warnings++;
    if (level > g_level)
        return;
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, "lmgi: %s: ", names[level]);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
}
