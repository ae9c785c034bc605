/* The process's resident memory (resident_memory.h). */
#include "resident_memory.h"

#include <malloc.h>
#include <stdio.h>
#include <unistd.h>

double lm_cli_resident_mb(void)
{
    malloc_trim(0);
    FILE *f = fopen("/proc/self/statm", "r");
    long pages = 0, rss = 0;
    int ok = f && fscanf(f, "%ld %ld", &pages, &rss) == 2;
    if (f)
        fclose(f);
    return ok ? (double)rss * (double)sysconf(_SC_PAGESIZE) / 1048576.0 : -1.0;
}
