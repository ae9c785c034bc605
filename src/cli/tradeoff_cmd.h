/* `lmgi tradeoff SCENE... --out DIR [--quick] [--knobs LIST]`: what accuracy costs in time
 * (docs/tradeoff.md). For every knob setting (tradeoff_knobs.h), on each scene: the time of each stage
 * (medians of --repeats runs) and the error of the AIM, the IIM and the frame against the path-traced
 * reference. Writes DIR/tradeoff.csv and DIR/tradeoff.json, the error maps of the default, fastest and
 * most accurate settings (DIR/map_SCENE_WHICH_KIND.npy), then runs tools/tradeoff_report.py (matplotlib) for
 * DIR/report.html and its plots when it finds it. */
#ifndef LM_CLI_TRADEOFF_CMD_H
#define LM_CLI_TRADEOFF_CMD_H
#include "args.h"
int lm_cli_tradeoff(const lm_cli_args *a);
#endif
