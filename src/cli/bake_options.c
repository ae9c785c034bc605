#include "bake_options.h"

uint32_t lm_cli_photons_for(uint32_t texels, uint32_t per_texel)
{
    uint64_t n = (uint64_t)per_texel * texels;
    return n < LM_CLI_BAKE_PHOTONS_MIN ? LM_CLI_BAKE_PHOTONS_MIN : n > LM_CLI_BAKE_PHOTONS_MAX ? LM_CLI_BAKE_PHOTONS_MAX : (uint32_t)n;
}

uint32_t lm_cli_bake_photons(uint32_t texels)
{
    return lm_cli_photons_for(texels, LM_CLI_BAKE_PHOTONS_PER_TEXEL);
}

void lm_cli_bake_solution(const lmgi_info *in, int whole, lmgi_updater_desc *d)
{
    if (!d->photons.count && !d->photons.per_group)
        d->photons.count = lm_cli_bake_photons(in->texels);
    if (!d->aim.direct_parts)
        d->aim.direct_parts = LM_CLI_BAKE_DIRECT_PARTS;
    if (!d->gather.estimate_rays) /* a bake shows every texel it gathers: none waits for an estimate */
        d->gather.estimate_rays = LMGI_OFF;
    int local_lights = in->lights_by_type[LMGI_LIGHT_POINT] + in->lights_by_type[LMGI_LIGHT_SPOT];
    if (!d->gather.bounce_passes && whole && local_lights <= LM_CLI_BAKE_PASS_MAX_LIGHTS)
        d->gather.bounce_passes = LM_CLI_BAKE_BOUNCE_PASSES;
}
