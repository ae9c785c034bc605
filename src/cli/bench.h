#ifndef LM_CLI_BENCH_H
#define LM_CLI_BENCH_H
#include "args.h"
/* `lmgi bench`: per-stage times of turning scene files into atlas and BVH (medians of a->repeats runs). */
int lm_cli_bench(const lm_cli_args *a);
/* The file name of a path (after its last '/'), for the tables. */
const char *lm_cli_base_name(const char *path);
#endif
