#include "prefault.h"

#include <stdint.h>
#include <sys/mman.h>

#define LM_PAGE 4096u

void lm_prefault(void *p, size_t bytes)
{
#ifdef MADV_POPULATE_WRITE
    uintptr_t lo = ((uintptr_t)p + LM_PAGE - 1) & ~(uintptr_t)(LM_PAGE - 1);
    uintptr_t hi = ((uintptr_t)p + bytes) & ~(uintptr_t)(LM_PAGE - 1);
    if (hi > lo) /* partial pages at the ends belong to neighbours too: leave them to fault */
        (void)madvise((void *)lo, hi - lo, MADV_POPULATE_WRITE);
#else
    (void)p;
    (void)bytes;
#endif
}
