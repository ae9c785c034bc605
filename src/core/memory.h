/* Memory a plan of work will take, said before the work starts (DESIGN.md: no surprises).
 *
 * A setting can ask for more than a machine has: --texel-size 1e-9 built an 8040 x 5604 atlas in a
 * minute and 4.9 GB, --photons 1e8 sat in setup for minutes at 7 GB, 1,000 point lights took 13.5 GB of
 * shadow maps. Each stage that allocates in proportion to a user's number estimates its bytes first
 * (from measured bytes per texel, photon or map texel, docs/loading.md) and calls lm_memory_plan. */
#ifndef LM_MEMORY_H
#define LM_MEMORY_H

#include <stdint.h>

#include "error.h"

/* Above this a plan is said as a warning (1 GiB). */
#define LM_MEMORY_WARN_BYTES (1024.0 * 1024.0 * 1024.0)

/* The memory this process can still take, in bytes: the machine's physical memory, or under an address
 * space limit (RLIMIT_AS, ulimit -v) what is left of it if that is less; 0 if unknown. */
uint64_t lm_memory_physical(void);

/* A plan of `bytes` for `what` ("atlas 8040 x 5604 (45 M texels)"): above the physical memory an
 * LM_ERR_NOMEM naming what, the estimate, the machine's memory and `advice` (what to change); above
 * LM_MEMORY_WARN_BYTES a warning with the estimate; else nothing. Thread-safe. */
lm_status lm_memory_plan(const char *what, double bytes, const char *advice, lm_error *err);

#endif
