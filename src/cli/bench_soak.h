#ifndef LM_CLI_BENCH_SOAK_H
#define LM_CLI_BENCH_SOAK_H
#include "args.h"
/* `lmgi bench --soak N [SCENE] [--size WxH] [run options]`: N updates of the scene's animations, looped
 * (30 updates a second of animation; scenes/cornell.glb without SCENE), each compositing a frame (default
 * 32 x 32). Every N/100 updates (at least 1,000, at most N) it prints the process's resident memory,
 * the median and 95th-percentile update time of the block, and the frames' non-finite pixels. At the
 * end: the memory's growth and the time's drift from the second block (the first is warm-up) to the
 * last (docs/bench.md, "Soak"). Exit 1 when a frame held NaN or Inf or an update failed.
 * With --random-edits L each update follows one random edit through the API instead (random_edits.h: up
 * to L lights, added and removed), in blocks of N/10, timed by the wall clock, edit included, at --budget
 * MS; it ends with the slowest update after the first, its stages and work, and how many updates took
 * over 10x the budget. Resident memory is read after malloc_trim. */
int lm_cli_bench_soak(const lm_cli_args *a);
#endif
