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

int lm_cli_opt_sky(const char *o, const char *v, lm_cli_args *a);
int lm_cli_opt_size(const char *o, const char *v, lm_cli_args *a);
int lm_cli_opt_groups(const char *o, const char *v, lm_cli_args *a);
int lm_cli_opt_emitter_light(const char *o, const char *v, lm_cli_args *a);
int lm_cli_opt_tonemap(const char *o, const char *v, lm_cli_args *a);
int lm_cli_opt_effects(const char *o, const char *v, lm_cli_args *a);
int lm_cli_opt_caustic_space(const char *o, const char *v, lm_cli_args *a);
int lm_cli_opt_indirect(const char *o, const char *v, lm_cli_args *a);
int lm_cli_opt_aim_direct(const char *o, const char *v, lm_cli_args *a);
int lm_cli_opt_find_portals(const char *o, const char *v, lm_cli_args *a);
int lm_cli_opt_scheme(const char *o, const char *v, lm_cli_args *a);
int lm_cli_opt_scaling(const char *o, const char *v, lm_cli_args *a);
int lm_cli_opt_seed(const char *o, const char *v, lm_cli_args *a);
/* --shard K/N: share K of N, 1 <= K <= N <= 4096. */
int lm_cli_opt_shard(const char *o, const char *v, lm_cli_args *a);
int lm_cli_opt_caustic_retrace(const char *o, const char *v, lm_cli_args *a);
int lm_cli_opt_photon_tile(const char *o, const char *v, lm_cli_args *a);
int lm_cli_opt_hemicube_samples(const char *o, const char *v, lm_cli_args *a);
int lm_cli_opt_photon_radius(const char *o, const char *v, lm_cli_args *a);

#endif
