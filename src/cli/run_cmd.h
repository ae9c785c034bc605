#ifndef LM_CLI_RUN_CMD_H
#define LM_CLI_RUN_CMD_H
#include "args.h"
/* `lmgi run SCENE --frames N --size WxH --out DIR`: the whole frame loop over the scene's animations. */
int lm_cli_run(const lm_cli_args *a);

#include <lmgi.h>
#include "run_options.h"
#define LM_CLI_FRAME_SIZE 512 /* lmgi run's frame side when not given --size */
/* The updater's desc from the command line (0, the defaults, where not given). */
void lm_cli_updater_desc(const lm_cli_args *a, lmgi_updater_desc *d);
/* lm_cli_updater_desc for a scene as run and check load it (lm_cli_run_load), its photons 4 a texel of its
 * atlas where --photons and --per-group are not given and that is more than the updater's 46,080
 * (LM_CLI_RUN_PHOTONS_PER_TEXEL, as a bake took them until it took 16): at run's density only the levels,
 * whose walls' own texels come on top; truck-town's 27,801 texels of 4 m held 1.7 of the default photons
 * each, and its grass slope read 6% dark from them (docs/photons.md, "A bake's photons"). */
void lm_cli_run_desc(const lm_cli_args *a, lmgi_scene *sc, lmgi_updater_desc *d);
/* The photons lm_cli_run_desc gives sc when not told: 4 a texel of its atlas where more than the updater's
 * 46,080, else 0 (the updater's default). */
uint32_t lm_cli_run_photons(const lmgi_scene *sc);
/* Loads a->files[0] as 'run' does (lm_cli_run_options). 0 (after printing the error) on failure. */
int lm_cli_run_load(const lm_cli_args *a, lmgi_scene **sc);
#endif
