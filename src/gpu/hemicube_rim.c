/* The rim of the hemisphere the plane misses, by rays (hemicube_rim.h). */
#include "hemicube_rim.h"

#include <math.h>
#include <string.h>

#include "../core/qmc.h"
#include "../core/vecmath.h"

#define RIM_PI 3.14159265358979323846

/* Bilinear RGBA lookup at uv in [0, 1]^2 (texel (x, y) spans [x, x + 1] / width), clamped to the edge. */
static void sample_atlas(const lm_atlas *a, const float *rgba, float u, float v, float out[3])
{
    float x = u * (float)a->width - 0.5f, y = v * (float)a->height - 0.5f;
    x = fminf(fmaxf(x, 0.0f), (float)(a->width - 1));
    y = fminf(fmaxf(y, 0.0f), (float)(a->height - 1));
    int x0 = (int)x, y0 = (int)y, x1 = x0 + 1 < a->width ? x0 + 1 : x0, y1 = y0 + 1 < a->height ? y0 + 1 : y0;
    float fx = x - (float)x0, fy = y - (float)y0;
    const float *p00 = rgba + 4 * ((size_t)y0 * a->width + x0), *p10 = rgba + 4 * ((size_t)y0 * a->width + x1);
    const float *p01 = rgba + 4 * ((size_t)y1 * a->width + x0), *p11 = rgba + 4 * ((size_t)y1 * a->width + x1);
    for (int c = 0; c < 3; c++)
        out[c] = (1.0f - fy) * ((1.0f - fx) * p00[c] + fx * p10[c]) + fy * ((1.0f - fx) * p01[c] + fx * p11[c]);
}

/* What the hemicube would show along dir from eye. */
static void radiance(const lm_rim *r, const float eye[3], const float dir[3], float L[3])
{
    lm_rt_hit h;
    if (!lm_rt_intersect(r->rt, eye, dir, 0.0f, INFINITY, &h)) {
        memcpy(L, r->sky, 3 * sizeof(float));
        return;
    }
    memset(L, 0, 3 * sizeof(float));
    const lm_material *m = &r->scene->materials[r->scene->tri_material[h.tri]];
    if (!m->double_sided && lm_dot(lm_v3_load(h.ng), lm_v3_load(dir)) > 0.0f)
        return; /* the back of a single-sided surface: black, as on the plane */
    const float *c = r->atlas->corner_uv + 6 * (size_t)h.tri;
    if (r->atlas->tri_chart[h.tri] >= 0 && isfinite(c[0])) {
        float w0 = 1.0f - h.u - h.v;
        sample_atlas(r->atlas, r->aim, w0 * c[0] + h.u * c[2] + h.v * c[4], w0 * c[1] + h.u * c[3] + h.v * c[5], L);
    }
    if (r->emission)
        for (int k = 0; k < 3; k++)
            L[k] += m->emissive[k];
}

void lm_rim_irradiance(const lm_rim *r, const float eye[3], const float b[3], const float t[3], const float n[3],
                       uint32_t seed, float out[3])
{
    int side = (int)sqrtf((float)r->samples);
    double shift[2], sum[3] = {0.0, 0.0, 0.0};
    lm_seed_shift(seed, shift);
    lm_vec3 B = lm_v3_load(b), T = lm_v3_load(t), N = lm_v3_load(n);
    for (int i = 0; i < side; i++)
        for (int j = 0; j < side; j++) {
            double u0 = fmod((i + shift[0]) / side, 1.0), u1 = fmod((j + shift[1]) / side, 1.0);
            /* cosine-weighted: sin(theta) = sqrt(u0), so the plane hit is (x, y) / z */
            float s = (float)sqrt(u0), z = (float)sqrt(1.0 - u0), sn, cs;
            lm_sincos_turn((float)u1, &sn, &cs);
            float x = s * cs, y = s * sn, lim = r->enlargement * z;
            if (fabsf(x) <= lim && fabsf(y) <= lim)
                continue; /* the plane sees this direction */
            float dir[3], L[3];
            lm_v3_store(dir, lm_normalize(lm_add(lm_add(lm_scale(B, x), lm_scale(T, y)), lm_scale(N, z))));
            radiance(r, eye, dir, L);
            for (int c = 0; c < 3; c++)
                sum[c] += L[c];
        }
    int K = side * side;
    for (int c = 0; c < 3; c++)
        out[c] = K ? (float)(RIM_PI * sum[c] / K) : 0.0f;
}
