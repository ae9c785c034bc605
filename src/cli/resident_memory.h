/* The process's resident memory, as a soak reads it (lmgi bench --soak, tests/test_soak.c). */
#ifndef LM_CLI_RESIDENT_MEMORY_H
#define LM_CLI_RESIDENT_MEMORY_H

/* Resident memory of this process in MB (Linux /proc/self/statm; -1 where it cannot be read), after
 * handing the C library's free memory back (malloc_trim): without it the figure stays at the peak of any
 * earlier moment, and memory given back by a removed light would not show. */
double lm_cli_resident_mb(void);

#endif
