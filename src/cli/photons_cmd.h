#ifndef LM_CLI_PHOTONS_CMD_H
#define LM_CLI_PHOTONS_CMD_H
#include "args.h"
/* `lmgi photons SCENE --frames N --out DIR`: the photon stage alone over the scene's animations. */
int lm_cli_photons(const lm_cli_args *a);
#endif
