/* The command's --out directory, claimed through lmgi_claim_output_dir (README, "Output directories"). */
#ifndef LM_CLI_OUT_DIR_H
#define LM_CLI_OUT_DIR_H

#include "args.h"

/* Claims a->out_dir (a->force as given) for output named like `own`; prints "lmgi: error: ..." and
 * returns 0 when refused. */
int lm_cli_claim_out_dir(const lm_cli_args *a, const char *const *own);

/* lmgi_write_image of DIR/NAME (the format from NAME's extension). */
lmgi_status lm_cli_write_image(const char *dir, const char *name, int width, int height, int channels,
                               const float *pixels, const lmgi_image_desc *desc, lmgi_error *err);

#endif
