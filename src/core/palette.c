#include "palette.h"

#include <math.h>

void lm_id_color(int id, uint8_t rgb[3])
{
    if (id < 0) {
        rgb[0] = rgb[1] = rgb[2] = 96;
        return;
    }
    /* Golden-ratio hue steps; saturation and value cycle so that many ids stay distinguishable. */
    float h = fmodf(0.13f + 0.61803398875f * (float)id, 1.0f) * 6.0f;
    float s = 0.55f + 0.45f * (float)((id / 7) % 2);
    float v = 0.75f + 0.25f * (float)((id / 3) % 2);
    int i = (int)h;
    float f = h - (float)i, p = v * (1 - s), q = v * (1 - s * f), t = v * (1 - s * (1 - f));
    float r, g, b;
    switch (i % 6) {
    case 0: r = v; g = t; b = p; break;
    case 1: r = q; g = v; b = p; break;
    case 2: r = p; g = v; b = t; break;
    case 3: r = p; g = q; b = v; break;
    case 4: r = t; g = p; b = v; break;
    default: r = v; g = p; b = q; break;
    }
    rgb[0] = (uint8_t)(r * 255.0f + 0.5f);
    rgb[1] = (uint8_t)(g * 255.0f + 0.5f);
    rgb[2] = (uint8_t)(b * 255.0f + 0.5f);
}
