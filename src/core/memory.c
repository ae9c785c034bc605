#include "memory.h"

#include <stdio.h>
#include <sys/resource.h>
#include <unistd.h>

#include "log.h"

/* The address space this process already holds (/proc/self/statm's first field), 0 if unknown. */
static uint64_t address_space_used(void)
{
    FILE *f = fopen("/proc/self/statm", "r");
    unsigned long long pages = 0;
    if (f) {
        if (fscanf(f, "%llu", &pages) != 1)
            pages = 0;
        fclose(f);
    }
    long page = sysconf(_SC_PAGE_SIZE);
    return page > 0 ? pages * (uint64_t)page : 0;
}

uint64_t lm_memory_physical(void)
{
    long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
    uint64_t have = pages > 0 && page > 0 ? (uint64_t)pages * (uint64_t)page : 0;
    struct rlimit r; /* ulimit -v: what is left of it is all this process can still take */
    if (getrlimit(RLIMIT_AS, &r) == 0 && r.rlim_cur != RLIM_INFINITY) {
        uint64_t used = address_space_used(), left = (uint64_t)r.rlim_cur > used ? (uint64_t)r.rlim_cur - used : 0;
        have = have && have < left ? have : left;
    }
    return have;
}

lm_status lm_memory_plan(const char *what, double bytes, const char *advice, lm_error *err)
{
    const double gb = 1024.0 * 1024.0 * 1024.0;
    double have = (double)lm_memory_physical();
    if (have > 0.0 && bytes > have)
        return lm_fail(err, LM_ERR_NOMEM, "%s would need about %.2f GB, more than the %.2f GB this process can "
                       "take (the machine's memory, or what is left under its limit: ulimit -v); %s", what,
                       bytes / gb, have / gb, advice);
    if (bytes > LM_MEMORY_WARN_BYTES)
        lm_warn("%s will need about %.1f GB (of %.1f GB) and a long setup; %s", what, bytes / gb, have / gb, advice);
    return LM_OK;
}
