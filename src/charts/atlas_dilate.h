/* Filling uncovered texels from their covered neighbours, so bilinear lookups at chart edges never blend
 * in black (which shows as dark seams). An uncovered texel inside a chart's rect is filled only from that
 * chart's texels: rects touch, and another chart's light would bleed in. */
#ifndef LM_ATLAS_DILATE_H
#define LM_ATLAS_DILATE_H

#include "charts.h"

/* data: width*height*channels floats over the atlas. Each of `passes` rounds gives every uncovered texel
 * that touches (8-neighbourhood) a texel filled so far the mean of those neighbours (of its own chart
 * inside a rect). Covered texels are never changed. A lookup at corner_uv lies within half a texel of
 * its coverage point, so its four texels are at most two texels from a covered one of its chart: two
 * passes set every texel a bilinear lookup inside a chart can reach. */
void lm_atlas_dilate(const lm_atlas *a, float *data, int channels, int passes);
/* The same over the atlas window win = {x, y, w, h}, data holding the window alone (w * h * channels);
 * texels beyond it count as unfilled. A texel's value after p passes depends only on those within p of
 * it, so the window's texels at least `passes` from its edges (or at the atlas's) come out exactly as
 * the whole atlas's. */
void lm_atlas_dilate_window(const lm_atlas *a, float *data, int channels, int passes, const int win[4]);
/* The passes lm_atlas_dilate_gutters makes: how far a texel's dilated value reaches. */
int lm_atlas_dilate_reach(const lm_atlas *a);
/* As many passes as the atlas's gutter, at least two: what bilinear sampling of a chart needs. */
void lm_atlas_dilate_gutters(const lm_atlas *a, float *data, int channels);
/* rgba = rgb (width * height * 3 floats) with alpha 0, gutters dilated: an RGB map as a bilinearly sampled
 * RGBA texture wants it (four floats a texel sample faster than three, and need no conversion on upload). */
void lm_atlas_dilated_rgba(const lm_atlas *a, const float *rgb, float *rgba);

#endif
