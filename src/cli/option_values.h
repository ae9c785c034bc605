/* The values the lmgi command's options take: each parser checks a value, stores it, and on a bad or
 * missing one prints "lmgi: OPTION VALUE: expected WHAT" and returns 2 (0 when good). The lm_cli_opt_*
 * ones are the option table's custom parsers (options.h). */
#ifndef LM_CLI_OPTION_VALUES_H
#define LM_CLI_OPTION_VALUES_H

#include "args.h"

int lm_cli_bad(const char *opt, const char *value, const char *want);
int lm_cli_parse_int(const char *opt, const char *v, int lo, int hi, int *out);
int lm_cli_parse_float(const char *opt, const char *v, float lo, float *out);
/* A scene file named on the command line (at most LM_CLI_MAX_FILES). */
int lm_cli_add_file(const char **list, int *count, const char *f);
/* v, one of the n names, as its value into *out; else "expected a, b or c" (the names in their order). */
int lm_cli_choose(const char *o, const char *v, const char *const names[], const int values[], int n, int *out);

int lm_cli_opt_sky(const char *o, const char *v, lm_cli_args *a);
int lm_cli_opt_size(const char *o, const char *v, lm_cli_args *a);
int lm_cli_opt_tonemap(const char *o, const char *v, lm_cli_args *a);
int lm_cli_opt_effects(const char *o, const char *v, lm_cli_args *a);
int lm_cli_opt_indirect(const char *o, const char *v, lm_cli_args *a);
int lm_cli_opt_scaling(const char *o, const char *v, lm_cli_args *a);
int lm_cli_opt_seed(const char *o, const char *v, lm_cli_args *a);
/* --bend DEG in (0, 180], or off (lmgi_options.bend_deg). */
int lm_cli_opt_bend(const char *o, const char *v, lm_cli_args *a);
int lm_cli_opt_open_need(const char *o, const char *v, lm_cli_args *a);
/* --shard K/N: share K of N, 1 <= K <= N <= 4096. */
int lm_cli_opt_shard(const char *o, const char *v, lm_cli_args *a);

#endif
