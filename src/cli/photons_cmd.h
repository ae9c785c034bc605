#ifndef LM_CLI_PHOTONS_CMD_H
#define LM_CLI_PHOTONS_CMD_H
#include "../update/photon_stage.h"
#include "args.h"
/* `lmgi photons SCENE --frames N --out DIR`: the photon stage alone over the scene's animations. */
int lm_cli_photons(const lm_cli_args *a);
/* Photon stage settings: defaults overridden by --photons, --groups, ... (shared with `lmgi run`). */
void lm_cli_photon_settings(const lm_cli_args *a, lm_photon_stage_settings *s);
#endif
