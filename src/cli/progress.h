#ifndef LM_CLI_PROGRESS_H
#define LM_CLI_PROGRESS_H
/* A one-line progress bar on stderr, drawn only when stderr is a terminal. */
void lm_progress(const char *what, int done, int total);
#endif
