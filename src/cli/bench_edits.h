#ifndef LM_CLI_BENCH_EDITS_H
#define LM_CLI_BENCH_EDITS_H
#include "args.h"
/* `lmgi bench --edits SCRIPT.json SCENE`: plays a scripted edit sequence (docs/bench.md, "Edit scripts")
 * through an updater at the script's budget and reports per-update times and work, budget overruns, and
 * after each edit the update lag: updates and milliseconds until the lightmap is within 5% and 2% of
 * the converged lightmap of the edited scene. --json FILE also writes every number. */
int lm_cli_bench_edits(const lm_cli_args *a);
#endif
