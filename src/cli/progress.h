#ifndef LM_CLI_PROGRESS_H
#define LM_CLI_PROGRESS_H
/* Progress of long work on stderr. On a terminal: a one-line bar redrawn in place,
 * `what [####....] done/total` or `what [####....] 42% gather, 12 s left`. Anywhere else (a log file, a
 * farm's job output, a pipe): whole lines, the first call's, then at most one every
 * LM_PROGRESS_LINE_SECONDS (the environment's LMGI_PROGRESS_SECONDS overrides it; 0: every call), and
 * the last: `what: gather 42% (12 s left)` or `what: 30/90`. Nothing at all once lm_progress_quiet(1)
 * (the CLI's -q). Not thread-safe: call from one thread. */
#define LM_PROGRESS_LINE_SECONDS 5.0
void lm_progress(const char *what, int done, int total);
/* The same for work measured as a fraction, with the stage under way and the time left estimated from
 * the time since `started` (lm_cli_now() when the work began). A fraction of 1 ends the line. */
void lm_progress_fraction(const char *what, float fraction, const char *stage, double started);
void lm_progress_quiet(int quiet);
/* Seconds on a monotonic clock. */
double lm_cli_now(void);
#endif
