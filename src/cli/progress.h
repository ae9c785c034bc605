#ifndef LM_CLI_PROGRESS_H
#define LM_CLI_PROGRESS_H
/* A one-line progress bar on stderr, drawn only when stderr is a terminal: `what [####....] done/total`. */
void lm_progress(const char *what, int done, int total);
/* The same for work measured as a fraction, with the stage under way and the time left estimated from
 * the time since `started` (lm_cli_now() when the work began): `what [####....] 42% gather, 12 s left`.
 * A fraction of 1 ends the line. */
void lm_progress_fraction(const char *what, float fraction, const char *stage, double started);
/* Seconds on a monotonic clock. */
double lm_cli_now(void);
#endif
