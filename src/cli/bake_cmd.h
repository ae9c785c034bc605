#ifndef LM_CLI_BAKE_CMD_H
#define LM_CLI_BAKE_CMD_H
#include "args.h"
/* `lmgi bake SCENE --out DIR [--half]`: the full solution (lmgi_updater_create is the first bake) with a
 * progress bar and the time left; Ctrl-C cancels within about 100 ms and writes nothing. Writes
 * DIR/lightmap.exr (the IIM: irradiance, alpha = validity; --half: 16-bit floats), DIR/lightmap.png (a
 * tone-mapped preview) and DIR/aim.exr. */
int lm_cli_bake(const lm_cli_args *a);
/* What a bake's stages took (lm_cli_bake_timed): the whole call in seconds, the first full solution's
 * photon tracing, AIMs and gather in milliseconds (lmgi_updater_info). */
typedef struct {
    double seconds, ms_trace, ms_aim, ms_gather;
} lm_cli_bake_times;
/* lm_cli_bake, and its stages' times into *t (zeroed when it fails before the solution). */
int lm_cli_bake_timed(const lm_cli_args *a, lm_cli_bake_times *t);
/* lmgi merge SCENE PART... --out DIR: the parts of a bake in shards put together (a bake from them). */
int lm_cli_merge(const lm_cli_args *a);
#endif
