#ifndef LM_DEV_PHOTONS_CMD_H
#define LM_DEV_PHOTONS_CMD_H
#include "../../src/update/photon_stage.h"
#include "../../src/cli/args.h"
/* `lmgi-dev photons SCENE --frames N --out DIR`: the photon stage alone over the scene's animations. */
int lm_dev_photons(const lm_cli_args *a);
/* Photon stage settings: defaults overridden by --photons, --groups, ... . */
void lm_dev_photon_settings(const lm_cli_args *a, lm_photon_stage_settings *s);
#endif
