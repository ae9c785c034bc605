/* The command's --out directory, claimed through lmgi_claim_output_dir (README, "Output directories"). */
#ifndef LM_CLI_OUT_DIR_H
#define LM_CLI_OUT_DIR_H

#include "args.h"

/* Claims a->out_dir (a->force as given) for output named like `own`; prints "lmgi: error: ..." and
 * returns 0 when refused. */
int lm_cli_claim_out_dir(const lm_cli_args *a, const char *const *own);

#endif
