#include "frame_settings.h"

#include <string.h>

#include "../trace/emitter_light.h"

void lm_frame_loop_settings_default(lm_frame_loop_settings *s)
{
    memset(s, 0, sizeof *s); /* a field added later is 0, NULL, off, not stack garbage */
    lm_photon_stage_settings_default(&s->stage);
    lm_hemicube_settings_default(&s->gather);
    s->gather.coverage_samples = 0; /* chosen per scene */
    s->emitter_light = -1;
    s->overlap = 1;
    s->emitter_rays = LM_EMITTER_LIGHT_DEFAULT_RAYS;
    lm_iim_settings_default(&s->iim);
    lm_direct_settings_default(&s->direct);
    s->width = 512;
    s->height = 512;
    s->camera = -1;
    s->reflection_size = 128;
    s->reflection_faces = 1;
    s->caustics = 1;
    lm_caustic_pass_settings_default(&s->caustic_pass);
    s->caustic_thin = LM_CAUSTIC_THIN_DEFAULT;
    s->indirect = 1;
    s->indirect_path = LM_INDIRECT_LIGHTMAP;
    lm_photon_gather_settings_default(&s->photon_gather);
}
