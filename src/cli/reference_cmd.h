#ifndef LM_CLI_REFERENCE_H
#define LM_CLI_REFERENCE_H
#include "args.h"
/* `lmgi reference SCENE --out DIR`: converged path-traced references (docs/reference.md): per-texel
 * E_full, E_iim and radiance as atlas-sized EXRs, and the camera's picture as EXR and tone-mapped PNG. */
int lm_cli_reference(const lm_cli_args *a);

/* The reference's desc from the command line (--target-error, --samples, --seed, --cache, --no-cache),
 * and, unless -q, its progress lines shown. */
void lm_cli_reference_desc(const lm_cli_args *a, lmgi_reference_desc *d);
#endif
