#include "atlas_image.h"

#include <stdlib.h>

#include "../core/palette.h"

uint8_t *lm_atlas_chart_image(const lm_atlas *a)
{
    size_t n = (size_t)a->width * (size_t)a->height;
    uint8_t *img = calloc(n ? n * 4 : 4, 1);
    if (!img)
        return NULL;
    for (size_t i = 0; i < n; i++) {
        img[4 * i + 3] = 255;
        int ti = a->texel_index[i];
        if (ti < 0)
            continue;
        int tri = (int)a->texels[ti].tri;
        lm_id_color(a->tri_chart[tri], img + 4 * i);
    }
    return img;
}
