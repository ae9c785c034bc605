/* Scattering for the material classes (scene.h): diffuse (Lambert), glossy (Lambert + a normalized
 * Phong lobe whose exponent follows roughness), mirror (perfect reflection, tinted by base colour) and
 * glass (Fresnel-weighted reflection or refraction with the material's IOR). Emitters scatter as
 * diffuse. Directions are unit vectors; `wi` points along the incoming travel direction (towards the
 * surface), `wo` away from it. */
#ifndef LM_BSDF_H
#define LM_BSDF_H

#include "../core/vecmath.h"
#include "shading.h"

typedef struct {
    float wo[3];         /* sampled outgoing direction */
    float weight[3];     /* f * cos / pdf: what carried power or throughput is multiplied by */
    int specular;        /* 1 for mirror reflection and glass (a delta lobe: no stored hit, no NEE) */
    int transmitted;     /* 1 if it went through the surface */
} lm_bsdf_sample_t;

/* Samples an outgoing direction from three uniform numbers in [0,1). Returns 0 if the sample is
 * absorbed or invalid (below the surface for a reflective lobe). */
int lm_bsdf_sample(const lm_shading *sh, const float wi[3], const float u[3], lm_bsdf_sample_t *out);
/* f(wi -> wo) * |cos(ns, wo)| for the non-specular part (0 for mirror and glass). */
void lm_bsdf_eval(const lm_shading *sh, const float wi[3], const float wo[3], float out[3]);

/* Inline, as every photon hit asks them (a call each cost more than the answer). */
/* How many of lm_bsdf_sample's numbers the material reads, u[0 .. n): 0 mirror, 1 glass, 2 diffuse
 * and emitter, 3 glossy. The others may be left unset (a photon then skips computing them). */
static inline int lm_bsdf_sample_dims(const lm_shading *sh)
{
    lm_material_class c = sh->material->cls;
    return c == LM_MAT_MIRROR ? 0 : c == LM_MAT_GLASS ? 1 : c == LM_MAT_GLOSSY ? 3 : 2;
}
/* A Russian-roulette survival probability p for a bounce off sh: 1 for mirror and glass, else p clamped
 * to [0.05, 0.999], so that no path is certain to end nor to go on. The top is the albedo itself up to
 * 0.999: at 0.95, an albedo of 0.99 multiplied a photon's flux by 1.04 a bounce, and the few photons
 * that lived long carried most of the light (a white furnace's AIM read 87 to 105 for 99 between photon
 * counts, docs/hard-cases.md). */
static inline float lm_bsdf_roulette(const lm_shading *sh, float p)
{
    if (lm_material_is_specular(sh->material->cls))
        return 1.0f;
    return p < 0.05f ? 0.05f : p > 0.999f ? 0.999f : p;
}
/* The reference's survival before a bounce: the albedo's luminance (lm_bsdf_roulette). */
static inline float lm_bsdf_survival(const lm_shading *sh) { return lm_bsdf_roulette(sh, lm_luminance(sh->albedo)); }
/* A photon's survival before a bounce: the albedo's largest channel (lm_bsdf_roulette). Not the
 * luminance: a photon's flux is multiplied by albedo / p per channel, which the largest channel keeps at
 * most 1 (but for the clamp); with the luminance a saturated red (0.8 0.2 0.1, luminance 0.32) gave the
 * red channel 2.5x a bounce, and the few photons that survived many bounces carried thousands of times a
 * photon's power into the AIMs, in a closed red box 2e12 times (docs/photons.md, "Russian roulette"). */
static inline float lm_bsdf_photon_survival(const lm_shading *sh)
{
    const float *a = sh->albedo; /* by comparisons: fmaxf may be a call, and this is asked every bounce */
    float m = a[0] > a[1] ? a[0] : a[1];
    return lm_bsdf_roulette(sh, m > a[2] ? m : a[2]);
}
/* True for classes that store photon hits (diffuse, glossy, emitter). */
static inline int lm_material_stores_hits(lm_material_class c)
{
    return c == LM_MAT_DIFFUSE || c == LM_MAT_GLOSSY || c == LM_MAT_EMITTER;
}

/* Additions used by the reference solver and the tests (bsdf.c documents the lobes):
 * lm_bsdf_pdf: solid-angle density with which lm_bsdf_sample picks wo for the non-specular part
 * (0 for mirror, glass, or wo on the wrong side), for multiple importance sampling.
 * lm_fresnel_dielectric: unpolarized Fresnel reflectance for light arriving at cos_i (> 0) from a
 * medium of index eta_i onto one of index eta_t; 1 under total internal reflection.
 * lm_phong_exponent: the glossy lobe's exponent for a roughness, n = 2 / r^4 - 2 clamped to [1, 1e4]. */
float lm_bsdf_pdf(const lm_shading *sh, const float wi[3], const float wo[3]);
/* Both at once: f cos as lm_bsdf_eval, the density as lm_bsdf_pdf. */
void lm_bsdf_eval_pdf(const lm_shading *sh, const float wi[3], const float wo[3], float f[3], float *pdf);
float lm_fresnel_dielectric(float cos_i, float eta_i, float eta_t);
/* A mirror's reflectance at cos_i (the cosine between the incoming direction and the normal, either sign):
 * Schlick's F0 + (1 - F0)(1 - cos)^5 per channel, F0 the albedo. The reflection pass's shader computes
 * the same. */
void lm_mirror_fresnel(const float albedo[3], float cos_i, float out[3]);
float lm_phong_exponent(float roughness);

#endif
