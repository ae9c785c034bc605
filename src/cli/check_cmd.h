#ifndef LM_CLI_CHECK_CMD_H
#define LM_CLI_CHECK_CMD_H
#include "args.h"
/* `lmgi check SCENE [run options] [reference options] [--out DIR]`: one frame of `lmgi run` at the same
 * settings against the reference's pixels (api/frame_check.h), per visible surface and over the frame. */
int lm_cli_check(const lm_cli_args *a);
#endif
