/* Which passes a scene calls for, and why (DESIGN.md, "Only what the scene calls for"). */
#ifndef LM_EFFECTS_H
#define LM_EFFECTS_H

#include "../scene/scene.h"

typedef enum {
    LM_EFFECT_DIRECT = 0,   /* per-pixel direct light of point/spot/directional lights */
    LM_EFFECT_SHADOWS,      /* shadow maps for them */
    LM_EFFECT_INDIRECT,     /* photons, AIMs and final gathering into IIMs */
    LM_EFFECT_CAUSTICS,     /* caustic photons and the screen-space caustic filter */
    LM_EFFECT_REFLECTIONS,  /* dynamic environment map for mirror and glass */
    LM_EFFECT_PHOTON_UPDATES, /* per-frame re-tracing (off: photons traced once) */
    LM_EFFECT_COUNT
} lm_effect_id;

typedef struct {
    int on[LM_EFFECT_COUNT];
    char reason[LM_EFFECT_COUNT][256];
} lm_effects;

void lm_effects_decide(const lm_scene *s, lm_effects *out);
const char *lm_effect_name(lm_effect_id e);

#endif
