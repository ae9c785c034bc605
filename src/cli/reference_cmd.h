#ifndef LM_CLI_REFERENCE_H
#define LM_CLI_REFERENCE_H
#include "args.h"
/* `lmgi reference SCENE --out DIR`: converged path-traced references (docs/reference.md): per-texel
 * E_full, E_iim and radiance as atlas-sized EXRs, and the camera's picture as EXR and tone-mapped PNG. */
int lm_cli_reference(const lm_cli_args *a);

#include "../trace/reference.h"
/* The reference solver's settings from the command line (--target-error, --samples, --seed, --cache,
 * --no-cache, -q). */
void lm_cli_ref_settings(const lm_cli_args *a, lm_ref_settings *set);
#endif
