/* Filling gutter texels from their covered neighbours, so bilinear lookups at chart edges never blend
 * in the black of the gutter (which shows as dark seams). */
#ifndef LM_ATLAS_DILATE_H
#define LM_ATLAS_DILATE_H

#include "charts.h"

/* data: width*height*channels floats over the atlas. Each of `passes` rounds gives every uncovered texel
 * that touches (8-neighbourhood) a texel filled so far the mean of those neighbours. Covered texels are
 * never changed. With passes >= gutter, every texel a bilinear lookup inside a chart can reach is set. */
void lm_atlas_dilate(const lm_atlas *a, float *data, int channels, int passes);
/* As many passes as the atlas's gutter (at least one): what bilinear sampling of a chart needs. */
void lm_atlas_dilate_gutters(const lm_atlas *a, float *data, int channels);
/* rgba = rgb (width * height * 3 floats) with alpha 0, gutters dilated: an RGB map as a bilinearly sampled
 * RGBA texture wants it (four floats a texel sample faster than three, and need no conversion on upload). */
void lm_atlas_dilated_rgba(const lm_atlas *a, const float *rgb, float *rgba);

#endif
