#ifndef LM_CLI_BAKE_CMD_H
#define LM_CLI_BAKE_CMD_H
#include "args.h"
/* `lmgi bake SCENE --out DIR [--half]`: the full solution (lmgi_updater_create is the first bake) with a
 * progress bar and the time left; Ctrl-C cancels within about 100 ms and writes nothing. Writes
 * DIR/lightmap.exr (the IIM: irradiance, alpha = validity; --half: 16-bit floats), DIR/lightmap.png (a
 * tone-mapped preview) and DIR/aim.exr. */
int lm_cli_bake(const lm_cli_args *a);
/* lmgi merge SCENE PART... --out DIR: the parts of a bake in shards put together (a bake from them). */
int lm_cli_merge(const lm_cli_args *a);
#endif
