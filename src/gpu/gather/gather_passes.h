/* Which tile of a gather pass each texel is drawn into (hemicube_gather.c).
 *
 * A texel always lands in tile `texel % tiles_per_pass`, whatever else is gathered with it. The
 * rasterizer's numbers depend on where in the target a hemicube is drawn: the viewport transform adds the
 * tile's offset in float, and a software rasterizer evaluates depth and UVs from absolute pixel positions.
 * A texel drawn in another tile reads up to 2.4e-5 differently (two rooms, 172 of 2,048 texels), so an
 * incremental bake, which gathers the same texels in other groups than a fresh one, differed from it in
 * the last bits. With the tile fixed by the texel, the gather of a texel is a function of the scene, the
 * AIM and the texel alone (issue 32, item 5).
 *
 * Layout: a pass is `slots` entries, entry s the texel drawn in tile s or LM_GATHER_NO_TEXEL; `top` is one
 * past the last used tile (the tiles the pass draws, clears and reduces).
 * Cost: O(texels left) per pass. Texels of consecutive indices (a surface's, a full regather) fill whole
 * passes; texels that share a tile wait for the next pass, so a list with many indices equal modulo the
 * pass size takes more passes (the worst, one texel a pass, needs indices that are all multiples of it).
 * Deterministic; no state; thread-safe. */
#ifndef LM_GATHER_PASSES_H
#define LM_GATHER_PASSES_H

#include <stdint.h>

#define LM_GATHER_NO_TEXEL UINT32_MAX

/* Fills slots[0, slots_count) with the next pass of the texels in rest[0, left): each texel whose tile is
 * free is placed, in list order (a texel listed twice goes in a later pass again); those not placed are
 * moved to the front of rest, in their order. Returns how many are left; *top gets one past the last
 * used tile. */
uint32_t lm_gather_place_pass(uint32_t *rest, uint32_t left, uint32_t *slots, uint32_t slots_count, uint32_t *top);

#endif
