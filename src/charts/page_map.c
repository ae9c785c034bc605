/* Where the atlas's pages lie in it: page p at column p % page_columns, row p / page_columns of a grid
 * of page_width x page_height places (charts.h, "Pages"). */
#include "charts.h"

void lm_atlas_page_rect(const lm_atlas *a, int p, int rect[4])
{
    rect[0] = p % a->page_columns * a->page_width;
    rect[1] = p / a->page_columns * a->page_height;
    rect[2] = a->page_width;
    rect[3] = a->page_height;
}

int lm_atlas_page_of(const lm_atlas *a, int x, int y, int *px, int *py)
{
    int col = x / a->page_width, row = y / a->page_height;
    if (px)
        *px = x - col * a->page_width;
    if (py)
        *py = y - row * a->page_height;
    return row * a->page_columns + col;
}

void lm_atlas_page_uv(const lm_atlas *a, int p, const float uv[2], float out[2])
{
    int r[4];
    lm_atlas_page_rect(a, p, r);
    out[0] = (float)(((double)uv[0] * a->width - r[0]) / r[2]);
    out[1] = (float)(((double)uv[1] * a->height - r[1]) / r[3]);
}

int lm_atlas_tri_page(const lm_atlas *a, uint32_t t)
{
    int c = a->tri_chart[t];
    return c < 0 ? -1 : a->charts[c].page;
}
