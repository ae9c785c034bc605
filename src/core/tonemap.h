/* Linear HDR to 8-bit sRGB for pictures people look at (EXR files keep the linear numbers).
 *
 * Two operators, each exposure k first:
 *   neutral (the default): Khronos' PBR Neutral tone mapper (Khronos 3D Commerce, 2024): colours pass
 *     unchanged below 0.76, above it the brightest channel is compressed smoothly towards 1 and the
 *     colour desaturated towards white in proportion to the compression, so bright lit surfaces keep
 *     their hue and shading instead of clipping to flat white. Automatic exposure meters like a camera:
 *     the median of the lit (non-zero) luminances goes to 0.18, mid grey, whatever the few hot pixels do.
 *   clamp: c' = min(1, k c), the linear look the numbers have; automatic exposure puts the 99th
 *     percentile of the lit luminances at 0.9 (a few hot pixels may clip, large bright areas go white).
 * Then the sRGB transfer. */
#ifndef LM_TONEMAP_H
#define LM_TONEMAP_H

#include <stddef.h>
#include <stdint.h>

typedef enum { LM_TONEMAP_NEUTRAL = 0, LM_TONEMAP_CLAMP = 1 } lm_tonemap_op;

/* The automatic exposure of `op` for n RGB values (stride floats apart); 1 if none is > 0. */
float lm_tonemap_exposure(lm_tonemap_op op, const float *rgb, size_t n, int stride);
/* rgba8[4i..] = srgb(op(k * rgb[stride i..])), alpha 255. */
void lm_tonemap(lm_tonemap_op op, const float *rgb, size_t n, int stride, float k, uint8_t *rgba8);

/* The clamp operator's (kept for the lightmap views and the reference's pictures). */
float lm_auto_exposure(const float *rgb, size_t n, int stride);
void lm_tonemap_srgb8(const float *rgb, size_t n, int stride, float k, uint8_t *rgba8);

#endif
