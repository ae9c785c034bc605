/* Material classes for light transport and albedo lookup. The class rule is documented in
 * docs/materials.md; keep the two in step. */
#include "scene.h"

#include <math.h>

#include "../core/vecmath.h"

/* Class thresholds (docs/materials.md). */
#define LM_EMITTER_MIN_LUMINANCE 0.0f  /* emissive luminance above this makes an emitter */
#define LM_GLASS_MIN_TRANSMISSION 0.5f /* transmission at or above this is glass */
#define LM_METAL_MIN_METALLIC 0.5f     /* metallic at or above this is a metal */
#define LM_MIRROR_MAX_ROUGHNESS 0.1f   /* metals smoother than this are mirrors */
#define LM_GLOSSY_MAX_ROUGHNESS 0.2f   /* dielectrics smoother than this are glossy */


lm_material_class lm_material_classify(lm_material *m)
{
    lm_material_class c;
    if (lm_luminance(m->emissive) > LM_EMITTER_MIN_LUMINANCE)
        c = LM_MAT_EMITTER;
    else if (m->transmission >= LM_GLASS_MIN_TRANSMISSION)
        c = LM_MAT_GLASS;
    else if (m->metallic >= LM_METAL_MIN_METALLIC)
        c = m->roughness < LM_MIRROR_MAX_ROUGHNESS ? LM_MAT_MIRROR : LM_MAT_GLOSSY;
    else if (m->roughness < LM_GLOSSY_MAX_ROUGHNESS)
        c = LM_MAT_GLOSSY;
    else
        c = LM_MAT_DIFFUSE;
    m->cls = c;
    return c;
}

const char *lm_material_class_name(lm_material_class c)
{
    switch (c) {
    case LM_MAT_DIFFUSE: return "diffuse";
    case LM_MAT_GLOSSY: return "glossy";
    case LM_MAT_MIRROR: return "mirror";
    case LM_MAT_GLASS: return "glass";
    case LM_MAT_EMITTER: return "emitter";
    case LM_MAT_CLASS_COUNT: break;
    }
    return "unknown";
}

/* KHR_texture_transform: uv' = offset + R(rotation) (scale * uv), with R turning the UVs
 * counter-clockwise in the image (v down): u' = cos u + sin v, v' = -sin u + cos v. */
static void transform_uv(const lm_material *m, float *u, float *v)
{
    float su = *u * m->uv_scale[0], sv = *v * m->uv_scale[1];
    float c = cosf(m->uv_rotation), s = sinf(m->uv_rotation);
    *u = c * su + s * sv + m->uv_offset[0];
    *v = -s * su + c * sv + m->uv_offset[1];
}

static int wrap(int i, int n)
{
    int r = i % n;
    return r < 0 ? r + n : r;
}

/* Bilinear lookup with repeat wrapping; texel centres at (i + 0.5) / size. */
static void sample_bilinear(const lm_texture *t, float u, float v, float out[3])
{
    float x = u * (float)t->width - 0.5f, y = v * (float)t->height - 0.5f;
    if (!isfinite(x) || !isfinite(y)) /* uvs beyond float (the loader bounds transforms; this bounds the rest) */
        x = y = 0.0f;
    float fx = floorf(x), fy = floorf(y), ax = x - fx, ay = y - fy;
    /* keep the integer part small so the int conversion is defined for any finite uv */
    int x0 = wrap((int)fmodf(fx, (float)t->width), t->width), y0 = wrap((int)fmodf(fy, (float)t->height), t->height);
    int x1 = wrap(x0 + 1, t->width), y1 = wrap(y0 + 1, t->height);
    const float *p00 = t->rgba + 4 * ((size_t)y0 * (size_t)t->width + (size_t)x0);
    const float *p10 = t->rgba + 4 * ((size_t)y0 * (size_t)t->width + (size_t)x1);
    const float *p01 = t->rgba + 4 * ((size_t)y1 * (size_t)t->width + (size_t)x0);
    const float *p11 = t->rgba + 4 * ((size_t)y1 * (size_t)t->width + (size_t)x1);
    for (int c = 0; c < 3; c++) {
        float top = p00[c] + (p10[c] - p00[c]) * ax, bottom = p01[c] + (p11[c] - p01[c]) * ax;
        out[c] = top + (bottom - top) * ay;
    }
}

#define LM_DIELECTRIC_F0 0.04f /* reflectance of a dielectric at normal incidence (index 1.5) */

void lm_material_lobes(const lm_material *m, const float albedo[3], float kd[3], float ks[3])
{
    for (int c = 0; c < 3; c++)
        kd[c] = ks[c] = 0.0f;
    if (m->cls == LM_MAT_DIFFUSE || m->cls == LM_MAT_EMITTER) {
        for (int c = 0; c < 3; c++)
            kd[c] = albedo[c];
        return;
    }
    if (m->cls != LM_MAT_GLOSSY)
        return;
    float metal = m->metallic < 0.0f ? 0.0f : m->metallic > 1.0f ? 1.0f : m->metallic, ksmax = 0.0f;
    for (int c = 0; c < 3; c++) {
        ks[c] = LM_DIELECTRIC_F0 * (1.0f - metal) + albedo[c] * metal;
        ksmax = fmaxf(ksmax, ks[c]);
    }
    for (int c = 0; c < 3; c++)
        kd[c] = albedo[c] * (1.0f - metal) * (1.0f - ksmax);
}

void lm_material_albedo(const lm_scene *s, const lm_material *m, float u, float v, float out[3])
{
    for (int c = 0; c < 3; c++)
        out[c] = m->base_color[c];
    if (!s || m->base_color_tex < 0 || m->base_color_tex >= s->texture_count)
        return;
    const lm_texture *t = &s->textures[m->base_color_tex];
    if (!t->rgba || t->width <= 0 || t->height <= 0 || !isfinite(u) || !isfinite(v))
        return;
    float tex[3];
    transform_uv(m, &u, &v);
    if (!isfinite(u) || !isfinite(v))
        return;
    sample_bilinear(t, u, v, tex);
    for (int c = 0; c < 3; c++)
        out[c] *= tex[c];
}
