#include "tonemap.h"

#include <math.h>
#include <stdlib.h>

#include "image.h"
#include "vecmath.h"

static int cmp_float(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}


/* The q-quantile of the finite luminances > 0; 0 if there are none. */
static float lit_quantile(const float *rgb, size_t n, int stride, double q)
{
    float *lum = malloc(sizeof *lum * (n ? n : 1));
    if (!lum)
        return 0.0f;
    size_t m = 0;
    for (size_t i = 0; i < n; i++) {
        float l = lm_luminance(rgb + i * (size_t)stride);
        if (l > 0.0f && isfinite(l))
            lum[m++] = l;
    }
    float v = 0.0f;
    if (m > 0) {
        qsort(lum, m, sizeof *lum, cmp_float);
        v = lum[(size_t)(q * (double)(m - 1))];
    }
    free(lum);
    return v;
}

float lm_auto_exposure(const float *rgb, size_t n, int stride)
{
    float p99 = lit_quantile(rgb, n, stride, 0.99);
    return p99 > 0.0f ? 0.9f / p99 : 1.0f;
}

float lm_tonemap_exposure(lm_tonemap_op op, const float *rgb, size_t n, int stride)
{
    if (op == LM_TONEMAP_CLAMP)
        return lm_auto_exposure(rgb, n, stride);
    float median = lit_quantile(rgb, n, stride, 0.5);
    return median > 0.0f ? 0.18f / median : 1.0f;
}

/* Khronos PBR Neutral on one linear colour (in place). The constants are the operator's: compression
 * starts at 0.8 - 0.04 (the 0.04 taken off dark colours' offset below), desaturation 0.15. */
static void neutral(float c[3])
{
    const float start = 0.8f - 0.04f, desaturation = 0.15f;
    float x = fminf(c[0], fminf(c[1], c[2]));
    float offset = x < 0.08f ? x - 6.25f * x * x : 0.04f; /* a toe that lifts nothing below 0.08 twice */
    for (int k = 0; k < 3; k++)
        c[k] -= offset;
    float peak = fmaxf(c[0], fmaxf(c[1], c[2]));
    if (peak < start)
        return;
    float d = 1.0f - start;
    float new_peak = 1.0f - d * d / (peak + d - start);
    float g = 1.0f - 1.0f / (desaturation * (peak - new_peak) + 1.0f);
    for (int k = 0; k < 3; k++)
        c[k] = c[k] * (new_peak / peak) * (1.0f - g) + new_peak * g;
}

void lm_tonemap(lm_tonemap_op op, const float *rgb, size_t n, int stride, float k, uint8_t *rgba8)
{
    for (size_t i = 0; i < n; i++) {
        const float *src = rgb + i * (size_t)stride;
        float c[3];
        for (int ch = 0; ch < 3; ch++)
            c[ch] = isfinite(src[ch]) && src[ch] > 0.0f ? k * src[ch] : 0.0f;
        if (op == LM_TONEMAP_NEUTRAL)
            neutral(c);
        for (int ch = 0; ch < 3; ch++)
            rgba8[4 * i + ch] = (uint8_t)(255.0f * lm_linear_to_srgb(fminf(1.0f, fmaxf(0.0f, c[ch]))) + 0.5f);
        rgba8[4 * i + 3] = 255;
    }
}

void lm_tonemap_srgb8(const float *rgb, size_t n, int stride, float k, uint8_t *rgba8)
{
    lm_tonemap(LM_TONEMAP_CLAMP, rgb, n, stride, k, rgba8);
}
