/* Linear HDR to 8-bit sRGB for pictures people look at (EXR files keep the linear numbers).
 *
 * The tone map is exposure then clamp then the sRGB transfer: c' = srgb(min(1, k c)). With automatic
 * exposure, k puts the 99th percentile of the non-zero luminances at 0.9, so a few hot pixels (a
 * light, a caustic) may clip while everything else keeps its contrast. */
#ifndef LM_TONEMAP_H
#define LM_TONEMAP_H

#include <stddef.h>
#include <stdint.h>

/* k such that the 99th percentile of the luminances of the n RGB values (stride floats apart) that are
 * > 0 maps to 0.9; 1 if there are none. */
float lm_auto_exposure(const float *rgb, size_t n, int stride);
/* rgba8[4i..] = srgb(min(1, k * rgb[stride i..])), alpha 255. */
void lm_tonemap_srgb8(const float *rgb, size_t n, int stride, float k, uint8_t *rgba8);

#endif
