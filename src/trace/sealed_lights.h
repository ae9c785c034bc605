/* Point and spot lights sealed inside a closed opaque object (a lamp modelled inside its shade, a light
 * left inside a crate): everything they emit ends on the back of a single-sided surface, which absorbs
 * it, so they light nothing anyone sees. Photons would say otherwise where the object stands on a floor:
 * its bottom lies in the floor's plane, a photon from inside may hit the floor there instead of the
 * bottom's back, and the hit, stored under the object, spreads into the visible floor around it through
 * the N-nearest estimate (docs/hard-cases.md: the room around a sealed lamp of 1,000 cd read 17 W/m^2).
 *
 * A light is sealed when rays from it in 14 directions (the 6 axes and the 8 diagonals) all hit the back
 * of a single-sided surface that is not glass. Cost: 14 closest-hit rays a point or spot light. A light
 * inside a closed room (whose walls face in) or in the open is not sealed; one inside a box with an
 * opening is not sealed either unless every one of the 14 rays misses the opening. Thread-safe (Embree
 * queries). */
#ifndef LM_SEALED_LIGHTS_H
#define LM_SEALED_LIGHTS_H

#include "../scene/scene.h"
#include "lights.h"
#include "rt_scene.h"

/* 1 when world point p is sealed (above). */
int lm_point_sealed(const lm_scene *s, const lm_rt *rt, const float p[3]);
/* Sets the power and radiant of every sealed point or spot light in em to 0 (call after
 * lm_emitters_update, which sets them from the lights again). Returns how many. */
int lm_emitters_seal(lm_emitters *em, const lm_scene *s, const lm_rt *rt);

#endif
