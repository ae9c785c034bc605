/* The atlas as a picture: each chart's covered texels in its own colour, everything else black. */
#ifndef LM_ATLAS_IMAGE_H
#define LM_ATLAS_IMAGE_H

#include <stdint.h>

#include "charts.h"

/* Returns a width*height*4 RGBA8 buffer (row 0 = atlas row 0) the caller frees, or NULL. */
uint8_t *lm_atlas_chart_image(const lm_atlas *a);

#endif
