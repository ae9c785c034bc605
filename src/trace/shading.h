/* What a ray hit means for light transport: the hit point's position, normals, albedo and material, all in world space. Shared by the photon tracer and the reference solver. */
#ifndef LM_SHADING_H
#define LM_SHADING_H

#include "../scene/scene.h"
#include "rt_scene.h"

typedef struct {
    float pos[3];        /* world position */
    float local[3];      /* the same point in the hit node's local space */
    float ng[3];         /* geometric normal, unit, as wound */
    float ns[3];         /* shading normal, unit, flipped to the side of ng */
    float albedo[3];     /* base colour factor x texture at uv0, linear */
    const lm_material *material;
    int material_id;
    int node, surface;
    uint32_t tri;
} lm_shading;

/* Fills sh from a hit of a ray with origin org and direction dir (current node transforms). */
void lm_shading_from_hit(const lm_scene *s, const lm_rt_hit *hit, const float org[3], const float dir[3],
                         lm_shading *sh);

/* The weight of light arriving along dir at a non-specular hit that a light-tracing estimate (a photon)
 * must carry for shading normals (Veach 1997, section 5.3): |dir . ns| / |dir . ng|, 0 where dir comes
 * from behind ns while in front of ng. A photon's density on a surface follows the geometric cosine,
 * while the reference, the frame's direct pass and the AIMs' exact direct light take the incident cosine
 * on the shading normal; weighted, a photon map's irradiance is the one they compute. Exactly 1 where the
 * two normals agree to within a float normal's rounding (flat triangles) and at mirrors and glass, whose
 * scattering takes the shading normal itself. */
float lm_shading_arrival_weight(const lm_shading *sh, const float dir[3]);

#endif
