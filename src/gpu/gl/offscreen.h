/* An offscreen render target (colour + depth): RGBA8 read back as a top-down picture, or RGBA32F for
 * linear HDR read back as top-down RGB floats. */
#ifndef LM_OFFSCREEN_H
#define LM_OFFSCREEN_H

#include <stdint.h>

#include "../../core/error.h"

typedef struct {
    unsigned fbo, color, depth;
    int width, height;
} lm_offscreen;

/* Creates, binds and clears (black, depth 1) the target. Needs a current GL context. */
lm_status lm_offscreen_begin(lm_offscreen *o, int width, int height, lm_error *err);
/* Reads the picture back into rgba8 (row 0 at the top), unbinds and deletes the target. */
lm_status lm_offscreen_end(lm_offscreen *o, uint8_t *rgba8, lm_error *err);
/* The same with an RGBA32F colour buffer, for linear HDR passes. */
lm_status lm_offscreen_begin_float(lm_offscreen *o, int width, int height, lm_error *err);
/* Reads a float target's RGB into rgb (width*height*3, row 0 at the top); the target stays bound. */
void lm_offscreen_read_rgb(const lm_offscreen *o, float *rgb);
/* Unbinds and deletes a target (after lm_offscreen_read_rgb, or on an error path). */
void lm_offscreen_release(lm_offscreen *o);

/* A new w x h RGBA32F texture, nearest filtered, holding rgba (w*h*4 floats, row 0 first) or, for NULL,
 * undefined texels; left bound to GL_TEXTURE_2D. */
unsigned lm_float_texture(int w, int h, const float *rgba);
/* The bound GL_TEXTURE_2D sampled bilinearly and clamped at its edges (an atlas or a picture read between
 * its texels). */
void lm_texture_linear_clamped(void);

/* A persistent float target for per-frame passes: 1 to 3 RGBA32F colour textures (sampleable, e.g. by
 * a later pass) and a 24-bit depth texture (sampleable: the caustic pass reads it), kept between frames
 * and re-made only when the size or the attachment count changes. Zero-initialise before the first lm_float_target_ensure. */
typedef struct {
    unsigned fbo, color[3], depth;
    int width, height, attachments;
} lm_float_target;

/* (Re)creates t when its size or attachment count differs and binds it (every attachment drawn to, the
 * viewport set); does not clear. */
lm_status lm_float_target_ensure(lm_float_target *t, int width, int height, int attachments, lm_error *err);
/* Reads attachment i's RGB into rgb (width*height*3, row 0 at the top). scratch: width*height*4 floats. */
void lm_float_target_read_rgb(const lm_float_target *t, int i, float *rgb, float *scratch);
/* A w x h RGBA float picture as GL reads it (row 0 at the bottom) into rgb (w*h*3, row 0 at the top). */
void lm_rgba_to_rgb_top_down(const float *rgba, int w, int h, float *rgb);
void lm_float_target_free(lm_float_target *t);

#endif
