#include "atlas_dilate.h"

#include <stdlib.h>
#include <string.h>

/* Whether two atlas texels lie on the same page (always, on an atlas of one page). */
static int same_page(const lm_atlas *a, int x0, int y0, int x1, int y1)
{
    return a->page_count <= 1 || (x0 / a->page_width == x1 / a->page_width && y0 / a->page_height == y1 / a->page_height);
}

void lm_atlas_dilate_window(const lm_atlas *a, float *data, int channels, int passes, const int win[4])
{
    int wx = win[0], wy = win[1], w = win[2], h = win[3];
    size_t n = (size_t)w * h;
    unsigned char *filled = malloc(n ? n : 1), *next = malloc(n ? n : 1);
    if (!filled || !next) {
        free(filled);
        free(next);
        return;
    }
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            filled[(size_t)y * w + x] = a->texel_index[(size_t)(wy + y) * a->width + (wx + x)] >= 0;
    for (int pass = 0; pass < passes; pass++) {
        memcpy(next, filled, n);
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++) {
                size_t i = (size_t)y * w + x, ai = (size_t)(wy + y) * a->width + (wx + x);
                if (filled[i])
                    continue;
                float sum[4] = {0, 0, 0, 0};
                int count = 0;
                for (int dy = -1; dy <= 1; dy++)
                    for (int dx = -1; dx <= 1; dx++) {
                        int xx = x + dx, yy = y + dy;
                        if (xx < 0 || yy < 0 || xx >= w || yy >= h)
                            continue;
                        size_t j = (size_t)yy * w + xx, aj = (size_t)(wy + yy) * a->width + (wx + xx);
                        if (!filled[j])
                            continue;
                        /* inside a chart's rect only from the same chart: rects touch (no gutter) */
                        if (a->chart_owner && a->chart_owner[ai] >= 0 && a->chart_owner[aj] != a->chart_owner[ai])
                            continue;
                        if (!same_page(a, wx + x, wy + y, wx + xx, wy + yy)) /* a page is an engine's texture */
                            continue;
                        for (int c = 0; c < channels && c < 4; c++)
                            sum[c] += data[j * channels + c];
                        count++;
                    }
                if (!count)
                    continue;
                for (int c = 0; c < channels && c < 4; c++)
                    data[i * channels + c] = sum[c] / (float)count;
                next[i] = 1;
            }
        memcpy(filled, next, n);
    }
    free(filled);
    free(next);
}

void lm_atlas_dilate(const lm_atlas *a, float *data, int channels, int passes)
{
    const int whole[4] = {0, 0, a->width, a->height};
    lm_atlas_dilate_window(a, data, channels, passes, whole);
}

int lm_atlas_dilate_reach(const lm_atlas *a) { return a->gutter > 2 ? a->gutter : 2; }

void lm_atlas_dilate_gutters(const lm_atlas *a, float *data, int channels)
{
    lm_atlas_dilate(a, data, channels, lm_atlas_dilate_reach(a));
}

void lm_atlas_dilated_rgba(const lm_atlas *a, const float *rgb, float *rgba)
{
    size_t n = (size_t)a->width * (size_t)a->height;
    for (size_t i = 0; i < n; i++) {
        rgba[4 * i + 0] = rgb[3 * i + 0];
        rgba[4 * i + 1] = rgb[3 * i + 1];
        rgba[4 * i + 2] = rgb[3 * i + 2];
        rgba[4 * i + 3] = 0.0f;
    }
    lm_atlas_dilate_gutters(a, rgba, 4);
}
