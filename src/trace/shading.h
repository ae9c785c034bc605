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

/* Shading normals for light tracing (Veach 1997, section 5.3). A photon's density on a surface follows the
 * geometric cosine and its bounce should leave with the geometric cosine too (Lambertian exitance), while
 * the reference, the frame's direct pass and the AIMs' exact direct light take the incident cosine on the
 * shading normal. Where the two normals agree within LM_NORMALS_AGREE (a flat triangle's, to a float
 * normal's rounding) nothing changes, to the bit. */
#define LM_NORMALS_AGREE 0.99996f /* cos 0.5 degrees */
int lm_shading_normals_lean(const lm_shading *sh);
/* The weight a photon arriving along dir at a non-specular hit carries: |dir . ns| / |dir . ng|, 0 where
 * dir comes from behind ns while in front of ng; exactly 1 where the normals agree, at mirrors and glass
 * (whose scattering takes the shading normal itself). Weighted, a photon map's irradiance is the one the
 * reference computes. */
float lm_shading_arrival_weight(const lm_shading *sh, const float dir[3]);
/* The shading a photon's bounce off a diffuse surface (or an emitter) is drawn with: sh itself, or where its
 * normals lean, a copy in *flat whose shading normal is the geometric one, so that the bounce leaves with
 * the geometric cosine and the albedo as its weight (drawn about the shading normal it left along cos ns,
 * and the directions below the face were lost). */
const lm_shading *lm_shading_for_bounce(const lm_shading *sh, lm_shading *flat);

#endif
