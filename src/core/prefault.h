/* Mapping in fresh memory ahead of use. */
#ifndef LM_PREFAULT_H
#define LM_PREFAULT_H

#include <stddef.h>

/* Asks the kernel to map the whole pages of [p, p + bytes) writable now, in one call, instead of one
 * page fault per 4 KiB page as they are first written. Worth it for large buffers about to be filled
 * (a fresh photon store and its paths: faults were a sizeable share of a full trace). Only a hint:
 * where the kernel lacks it (before Linux 5.14, other systems) nothing happens. */
void lm_prefault(void *p, size_t bytes);

#endif
