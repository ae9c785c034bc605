/* Tiles of a gather pass fixed by the texel (gather_passes.h). */
#include "gather_passes.h"

uint32_t lm_gather_place_pass(uint32_t *rest, uint32_t left, uint32_t *slots, uint32_t slots_count, uint32_t *top)
{
    for (uint32_t s = 0; s < slots_count; s++)
        slots[s] = LM_GATHER_NO_TEXEL;
    uint32_t kept = 0, end = 0;
    for (uint32_t k = 0; k < left; k++) {
        uint32_t t = rest[k], s = t % slots_count;
        if (slots[s] == LM_GATHER_NO_TEXEL) {
            slots[s] = t;
            end = s + 1 > end ? s + 1 : end;
        } else {
            rest[kept++] = t;
        }
    }
    *top = end;
    return kept;
}
