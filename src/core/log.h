/* Logging with a level filter. Warnings are also counted so tests and strict mode can see them.
 *
 * Where a message goes is decided per thread: a thread with a target set (lm_log_swap_target: what the
 * public API does on entry for a context with a log callback) sends its messages there, filtered by the
 * target's level; any other thread prints to stderr, filtered by the process-wide level. So two contexts
 * used on two threads never see each other's messages. */
#ifndef LM_LOG_H
#define LM_LOG_H

typedef enum { LM_LOG_ERROR = 0, LM_LOG_WARN, LM_LOG_INFO, LM_LOG_DEBUG } lm_log_level;

void lm_log_set_level(lm_log_level level);
lm_log_level lm_log_get_level(void);
void lm_log(lm_log_level level, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
/* Number of warnings logged since start (or the last reset), whether or not they were printed. */
int lm_log_warning_count(void);
void lm_log_reset_warning_count(void);

/* A thread's message target: fn (NULL: stderr at the process-wide level) gets each message at or below
 * `level`, without the "lmgi: warning: " prefix or newline. */
typedef void (*lm_log_fn)(void *user, lm_log_level level, const char *message);
typedef struct {
    lm_log_fn fn;
    void *user;
    lm_log_level level;
} lm_log_target;

/* Sets the calling thread's target and returns the one it replaces (to be put back on the way out). */
lm_log_target lm_log_swap_target(lm_log_target t);
/* The calling thread's target (a worker takes its caller's). */
lm_log_target lm_log_get_target(void);

#define lm_warn(...) lm_log(LM_LOG_WARN, __VA_ARGS__)
#define lm_info(...) lm_log(LM_LOG_INFO, __VA_ARGS__)
#define lm_debug(...) lm_log(LM_LOG_DEBUG, __VA_ARGS__)

#endif
