#ifndef LM_CLI_RUN_CMD_H
#define LM_CLI_RUN_CMD_H
#include "args.h"
/* `lmgi run SCENE --frames N --size WxH --out DIR`: the whole frame loop over the scene's animations. */
int lm_cli_run(const lm_cli_args *a);
#endif
