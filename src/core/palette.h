#ifndef LM_PALETTE_H
#define LM_PALETTE_H
#include <stdint.h>
/* A distinct, saturated colour for an id (neighbouring ids get far-apart hues); id < 0 gives grey. */
void lm_id_color(int id, uint8_t rgb[3]);
#endif
