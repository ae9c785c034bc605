#ifndef LM_CLI_BENCH_BUDGET_H
#define LM_CLI_BENCH_BUDGET_H
/* Part of `lmgi bench`: how well lmgi_update keeps a time budget. On scenes/cornell.glb, an updater that
 * draws no frame (a game's), the cube moved by an edit every update, updates paced at 60 per second
 * (the rest of each 1/60 s stands for the game's own frame): per budget, the median, 95th percentile and
 * worst update time and the texels gathered, over 150 updates after 10 to settle. Uses the public
 * headers only. */
void lm_cli_bench_budget(void);
#endif
