#include "log.h"

#include <stdarg.h>
#include <stdatomic.h>
#include <stdio.h>

static lm_log_level g_level = LM_LOG_WARN;
static atomic_int g_warnings;
static _Thread_local lm_log_target t_target; /* fn NULL: stderr */

void lm_log_set_level(lm_log_level level) { g_level = level; }
lm_log_level lm_log_get_level(void) { return t_target.fn ? t_target.level : g_level; }
int lm_log_warning_count(void) { return atomic_load(&g_warnings); }
void lm_log_reset_warning_count(void) { atomic_store(&g_warnings, 0); }

lm_log_target lm_log_swap_target(lm_log_target t)
{
    lm_log_target old = t_target;
    t_target = t;
    return old;
}

lm_log_target lm_log_get_target(void) { return t_target; }

void lm_log(lm_log_level level, const char *fmt, ...)
{
    static const char *names[] = {"error", "warning", "info", "debug"};
    if (level == LM_LOG_WARN)
        atomic_fetch_add(&g_warnings, 1);
    if (level > lm_log_get_level())
        return;
    va_list ap;
    va_start(ap, fmt);
    if (t_target.fn) {
        char msg[2048];
        vsnprintf(msg, sizeof msg, fmt, ap);
        t_target.fn(t_target.user, level, msg);
    } else {
        fprintf(stderr, "lmgi: %s: ", names[level]);
        vfprintf(stderr, fmt, ap);
        fputc('\n', stderr);
    }
    va_end(ap);
}
