#include "run_options.h"

void lm_cli_run_options(lmgi_options *o, int texels_per_frame)
{
    if (o->texel_size <= 0.0f && o->target_texels <= 0) { /* a density the texel budget keeps up with */
        o->target_texels = lmgi_atlas_texels_for(texels_per_frame);
        o->wall_texels = LM_CLI_RUN_WALL_TEXELS; /* and that a level's walls show */
    }
    if (o->open_need == 0.0f) /* and where a level's texels are worth something (docs/charts.md) */
        o->open_need = LM_CLI_RUN_OPEN_NEED;
}
