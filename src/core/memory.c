#include "memory.h"

#include <unistd.h>

#include "log.h"

uint64_t lm_memory_physical(void)
{
    long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
    return pages > 0 && page > 0 ? (uint64_t)pages * (uint64_t)page : 0;
}

lm_status lm_memory_plan(const char *what, double bytes, const char *advice, lm_error *err)
{
    const double gb = 1024.0 * 1024.0 * 1024.0;
    double have = (double)lm_memory_physical();
    if (have > 0.0 && bytes > have)
        return lm_fail(err, LM_ERR_NOMEM, "%s would need about %.1f GB, more than this machine's %.1f GB; %s", what,
                       bytes / gb, have / gb, advice);
    if (bytes > LM_MEMORY_WARN_BYTES)
        lm_warn("%s will need about %.1f GB (of %.1f GB) and a long setup; %s", what, bytes / gb, have / gb, advice);
    return LM_OK;
}
