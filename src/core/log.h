/* Logging to stderr with a level filter. Warnings are also counted so tests and strict mode can see them. */
#ifndef LM_LOG_H
#define LM_LOG_H

typedef enum { LM_LOG_ERROR = 0, LM_LOG_WARN, LM_LOG_INFO, LM_LOG_DEBUG } lm_log_level;

void lm_log_set_level(lm_log_level level);
lm_log_level lm_log_get_level(void);
void lm_log(lm_log_level level, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
/* Number of warnings logged since start (or the last reset), whether or not they were printed. */
int lm_log_warning_count(void);
void lm_log_reset_warning_count(void);

#define lm_warn(...) lm_log(LM_LOG_WARN, __VA_ARGS__)
#define lm_info(...) lm_log(LM_LOG_INFO, __VA_ARGS__)
#define lm_debug(...) lm_log(LM_LOG_DEBUG, __VA_ARGS__)

#endif
