#ifndef LM_CLI_BENCH_SCENES_H
#define LM_CLI_BENCH_SCENES_H
/* Prints, for our Cornell box and two rooms and every shared scene that is there, `lmgi run`'s frame at
 * its default settings against the reference (api/frame_check.h; 96 x 96, reference at 0.03, cached):
 * frame / reference per channel, the relative RMSE and the surface (100 or more compared pixels)
 * furthest off. Part of `lmgi bench`; minutes per scene when the reference is not cached. */
void lm_cli_bench_scenes(void);
#endif
