#include "tonemap.h"

#include <math.h>
#include <stdlib.h>

#include "image.h"

static int cmp_float(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

static float luminance(const float *c) { return 0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2]; }

float lm_auto_exposure(const float *rgb, size_t n, int stride)
{
    float *lum = malloc(sizeof *lum * (n ? n : 1));
    if (!lum)
        return 1.0f;
    size_t m = 0;
    for (size_t i = 0; i < n; i++) {
        float l = luminance(rgb + i * (size_t)stride);
        if (l > 0.0f && isfinite(l))
            lum[m++] = l;
    }
    float k = 1.0f;
    if (m > 0) {
        qsort(lum, m, sizeof *lum, cmp_float);
        float p99 = lum[(size_t)(0.99 * (double)(m - 1))];
        k = p99 > 0.0f ? 0.9f / p99 : 1.0f;
    }
    free(lum);
    return k;
}

void lm_tonemap_srgb8(const float *rgb, size_t n, int stride, float k, uint8_t *rgba8)
{
    for (size_t i = 0; i < n; i++) {
        const float *c = rgb + i * (size_t)stride;
        for (int ch = 0; ch < 3; ch++)
            rgba8[4 * i + ch] = (uint8_t)(255.0f * lm_linear_to_srgb(k * c[ch]) + 0.5f);
        rgba8[4 * i + 3] = 255;
    }
}
