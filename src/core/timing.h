#ifndef LM_TIMING_H
#define LM_TIMING_H
/* Monotonic wall-clock time in seconds. */
double lm_now(void);
#endif
