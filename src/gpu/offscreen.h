/* An offscreen render target (colour + depth) and reading it back as a top-down RGBA8 image. */
#ifndef LM_OFFSCREEN_H
#define LM_OFFSCREEN_H

#include <stdint.h>

#include "../core/error.h"

typedef struct {
    unsigned fbo, color, depth;
    int width, height;
} lm_offscreen;

/* Creates, binds and clears (black, depth 1) the target. Needs a current GL context. */
lm_status lm_offscreen_begin(lm_offscreen *o, int width, int height, lm_error *err);
/* Reads the picture back into rgba8 (row 0 at the top), unbinds and deletes the target. */
lm_status lm_offscreen_end(lm_offscreen *o, uint8_t *rgba8, lm_error *err);

#endif
