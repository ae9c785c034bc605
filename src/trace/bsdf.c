/* Scattering for the material classes (bsdf.h).
 *
 * Sides: the normals are turned to the side the light arrives from (the side of -wi). Glass and
 * double-sided materials scatter on both sides; a single-sided opaque surface hit from behind
 * absorbs (it is opaque, and glTF gives it no back face to shade). Reflected directions below the
 * geometric surface are absorbed, so light never leaks through a surface.
 *
 * Lobes:
 *   diffuse, emitter   f = albedo / pi, cosine-weighted sampling (weight = albedo).
 *   glossy             f = kd / pi + ks (n + 2) / (2 pi) cos^n(alpha), alpha the angle between wo and
 *                      the mirror direction of wi about ns (normalized Phong, Lafortune & Willems 1994);
 *                      ks = lerp(0.04, albedo, metallic), kd = albedo (1 - metallic)(1 - max(ks)) so that
 *                      kd + ks <= 1; n = lm_phong_exponent(roughness). Sampled as a mixture of the
 *                      cosine lobe and the Phong lobe (pdf (n + 1) / (2 pi) cos^n alpha), picked by
 *                      the luminances of kd and ks; the weight uses the mixture's pdf.
 *   mirror             wo = reflect(wi, ns), weight = the metal's Fresnel reflectance, Schlick's
 *                      approximation with the albedo as F0 (glTF's metallic model): albedo face on,
 *                      rising to 1 at grazing angles (lm_mirror_fresnel).
 *   glass              exact dielectric Fresnel F; reflect with probability F (weight 1), else refract
 *                      by Snell's law (weight = albedo, the glass tint); total internal reflection
 *                      reflects always. Inside/outside from the sign of dot(wi, ng). */
#include "bsdf.h"

#include <math.h>

#include "../core/vecmath.h"


static float clampf(float x, float lo, float hi) { return x < lo ? lo : x > hi ? hi : x; }

/* Direction around n with density cos^e(angle), e > 1 (the Phong lobe). */
static lm_vec3 sample_power_cos(lm_vec3 n, float e, float u0, float u1)
{
    float c = powf(1.0f - u0, 1.0f / (e + 1.0f)), s = sqrtf(1.0f - c * c), sn, cs; /* c <= 1 */
    lm_sincos_turn(u1, &sn, &cs);
    return lm_onb_dir(n, s * cs, s * sn, c);
}

static lm_vec3 reflect(lm_vec3 d, lm_vec3 n) { return lm_sub(d, lm_scale(n, 2.0f * lm_dot(d, n))); }

/* Turns ng, ns towards the side wi comes from. Returns 0 for the back of a single-sided opaque surface. */
static int orient(const lm_shading *sh, lm_vec3 wi, lm_vec3 *ng, lm_vec3 *ns)
{
    *ng = lm_v3_load(sh->ng);
    *ns = lm_v3_load(sh->ns);
    if (lm_dot(wi, *ng) <= 0.0f)
        return 1;
    if (!sh->material->double_sided && sh->material->cls != LM_MAT_GLASS)
        return 0;
    *ng = lm_scale(*ng, -1.0f);
    *ns = lm_scale(*ns, -1.0f);
    return 1;
}

float lm_phong_exponent(float roughness)
{
    float r = clampf(roughness, 0.0f, 1.0f), r4 = r * r * r * r;
    if (r4 < 2e-4f) /* 2 / r^4 beyond the clamp */
        return 1e4f;
    return clampf(2.0f / r4 - 2.0f, 1.0f, 1e4f);
}

float lm_fresnel_dielectric(float cos_i, float eta_i, float eta_t)
{
    cos_i = clampf(cos_i, 0.0f, 1.0f);
    float sin_t = eta_i / eta_t * sqrtf(fmaxf(0.0f, 1.0f - cos_i * cos_i));
    if (sin_t >= 1.0f)
        return 1.0f; /* total internal reflection */
    float cos_t = sqrtf(fmaxf(0.0f, 1.0f - sin_t * sin_t));
    float rs = (eta_i * cos_i - eta_t * cos_t) / (eta_i * cos_i + eta_t * cos_t);
    float rp = (eta_t * cos_i - eta_i * cos_t) / (eta_t * cos_i + eta_i * cos_t);
    return 0.5f * (rs * rs + rp * rp);
}

typedef struct {
    float kd[3], ks[3];
    float n;       /* Phong exponent */
    float p_spec;  /* probability of sampling the Phong lobe */
} glossy_params;

static void glossy(const lm_shading *sh, glossy_params *g)
{
    lm_material_lobes(sh->material, sh->albedo, g->kd, g->ks);
    g->n = lm_phong_exponent(sh->material->roughness);
    float ls = lm_luminance(g->ks), ld = lm_luminance(g->kd);
    g->p_spec = ls + ld > 0.0f ? ls / (ls + ld) : 0.5f;
}

/* Phong lobe value cos^n(alpha), alpha between wo and the mirror direction r. */
static float phong(lm_vec3 r, lm_vec3 wo, float n)
{
    float c = lm_dot(r, wo);
    return c > 0.0f ? powf(c, n) : 0.0f;
}

/* f cos and pdf of the non-specular lobes, with normals already oriented; 0 below the surface. */
static void eval_oriented(const lm_shading *sh, lm_vec3 wi, lm_vec3 wo, lm_vec3 ng, lm_vec3 ns, float f[3],
                          float *pdf)
{
    float cos_o = lm_dot(ns, wo);
    f[0] = f[1] = f[2] = 0.0f;
    *pdf = 0.0f;
    if (cos_o <= 0.0f || lm_dot(ng, wo) <= 0.0f)
        return;
    if (sh->material->cls != LM_MAT_GLOSSY) {
        for (int c = 0; c < 3; c++)
            f[c] = sh->albedo[c] / LM_PI_F * cos_o;
        *pdf = cos_o / LM_PI_F;
        return;
    }
    glossy_params g;
    glossy(sh, &g);
    float lobe = phong(reflect(wi, ns), wo, g.n);
    for (int c = 0; c < 3; c++)
        f[c] = (g.kd[c] / LM_PI_F + g.ks[c] * (g.n + 2.0f) / (2.0f * LM_PI_F) * lobe) * cos_o;
    *pdf = (1.0f - g.p_spec) * cos_o / LM_PI_F + g.p_spec * (g.n + 1.0f) / (2.0f * LM_PI_F) * lobe;
}

static int sample_glass(const lm_shading *sh, lm_vec3 wi, const float u[3], lm_bsdf_sample_t *out)
{
    lm_vec3 ng = lm_v3_load(sh->ng), ns = lm_v3_load(sh->ns);
    int entering = lm_dot(wi, ng) < 0.0f;
    float ior = sh->material->ior == 0.0f ? 1.0f : sh->material->ior; /* 0: reflects all, below */
    float eta_i = entering ? 1.0f : ior, eta_t = entering ? ior : 1.0f;
    if (!(eta_i > 0.0f) || !(eta_t > 0.0f))
        return 0;
    if (lm_dot(wi, ns) > 0.0f) /* normals against wi */
        ns = lm_scale(ns, -1.0f);
    if (!entering)
        ng = lm_scale(ng, -1.0f);
    float cos_i = -lm_dot(wi, ns), F = lm_fresnel_dielectric(cos_i, eta_i, eta_t);
    if (sh->material->ior == 0.0f) /* KHR_materials_ior's 0: the Fresnel term is 1, everything reflected */
        F = 1.0f;
    out->specular = 1;
    if (u[0] < F) { /* Fresnel-weighted reflection (also total internal reflection) */
        lm_vec3 r = reflect(wi, ns);
        if (lm_dot(r, ng) <= 0.0f)
            return 0;
        lm_v3_store(out->wo, r);
        out->weight[0] = out->weight[1] = out->weight[2] = 1.0f;
        out->transmitted = 0;
        return 1;
    }
    /* Snell: wt = eta wi + (eta cos_i - cos_t) n, eta = eta_i / eta_t */
    float eta = eta_i / eta_t, cos_t = sqrtf(fmaxf(0.0f, 1.0f - eta * eta * (1.0f - cos_i * cos_i)));
    lm_vec3 t = lm_normalize(lm_add(lm_scale(wi, eta), lm_scale(ns, eta * cos_i - cos_t)));
    if (lm_dot(t, ng) >= 0.0f)
        return 0;
    lm_v3_store(out->wo, t);
    for (int c = 0; c < 3; c++)
        out->weight[c] = sh->albedo[c];
    out->transmitted = 1;
    return 1;
}

static int sample_mirror(const lm_shading *sh, lm_vec3 ng, lm_vec3 ns, lm_vec3 wi, lm_bsdf_sample_t *out)
{
    lm_vec3 r = reflect(wi, ns);
    if (lm_dot(r, ng) <= 0.0f)
        return 0;
    lm_v3_store(out->wo, r);
    lm_mirror_fresnel(sh->albedo, -lm_dot(wi, ns), out->weight);
    out->specular = 1;
    return 1;
}

void lm_mirror_fresnel(const float albedo[3], float cos_i, float out[3])
{
    float c = cos_i < 0.0f ? -cos_i : cos_i, m = 1.0f - (c > 1.0f ? 1.0f : c), m5 = m * m * m * m * m;
    for (int k = 0; k < 3; k++)
        out[k] = albedo[k] + (1.0f - albedo[k]) * m5;
}

int lm_bsdf_sample(const lm_shading *sh, const float wi_[3], const float u[3], lm_bsdf_sample_t *out)
{
    lm_vec3 wi = lm_v3_load(wi_), ng, ns;
    out->specular = out->transmitted = 0;
    if (sh->material->cls == LM_MAT_GLASS)
        return sample_glass(sh, wi, u, out);
    if (!orient(sh, wi, &ng, &ns))
        return 0;
    if (sh->material->cls == LM_MAT_MIRROR)
        return sample_mirror(sh, ng, ns, wi, out);
    lm_vec3 wo;
    if (sh->material->cls != LM_MAT_GLOSSY) {
        /* Cosine-weighted: f cos / pdf = (albedo / pi) cos / (cos / pi) = albedo, so no evaluation,
         * only eval_oriented's test that wo leaves above both normals. */
        wo = lm_cosine_dir(ns, u[0], u[1]);
        if (lm_dot(ns, wo) <= 0.0f || lm_dot(ng, wo) <= 0.0f)
            return 0;
        lm_v3_store(out->wo, wo);
        for (int c = 0; c < 3; c++)
            out->weight[c] = sh->albedo[c];
        return out->weight[0] > 0.0f || out->weight[1] > 0.0f || out->weight[2] > 0.0f;
    }
    glossy_params g;
    glossy(sh, &g);
    wo = u[2] < g.p_spec ? sample_power_cos(reflect(wi, ns), g.n, u[0], u[1]) : lm_cosine_dir(ns, u[0], u[1]);
    float f[3], pdf;
    eval_oriented(sh, wi, wo, ng, ns, f, &pdf);
    if (!(pdf > 0.0f))
        return 0;
    lm_v3_store(out->wo, wo);
    for (int c = 0; c < 3; c++)
        out->weight[c] = f[c] / pdf;
    return out->weight[0] > 0.0f || out->weight[1] > 0.0f || out->weight[2] > 0.0f;
}

void lm_bsdf_eval_pdf(const lm_shading *sh, const float wi_[3], const float wo_[3], float f[3], float *pdf)
{
    lm_vec3 wi = lm_v3_load(wi_), ng, ns;
    f[0] = f[1] = f[2] = 0.0f;
    *pdf = 0.0f;
    if (!lm_material_is_specular(sh->material->cls) && orient(sh, wi, &ng, &ns))
        eval_oriented(sh, wi, lm_v3_load(wo_), ng, ns, f, pdf);
}

void lm_bsdf_eval(const lm_shading *sh, const float wi[3], const float wo[3], float out[3])
{
    float pdf;
    lm_bsdf_eval_pdf(sh, wi, wo, out, &pdf);
}

float lm_bsdf_pdf(const lm_shading *sh, const float wi[3], const float wo[3])
{
    float f[3], pdf;
    lm_bsdf_eval_pdf(sh, wi, wo, f, &pdf);
    return pdf;
}
