/* Writing and reading images: PNG (8-bit sRGB, for people) and EXR (32-bit float, for numbers). */
#ifndef LM_IMAGE_H
#define LM_IMAGE_H

#include <stddef.h>
#include <stdint.h>

#include "error.h"

/* Writes size bytes to path through path.partial and a rename: the file is whole or absent, every write
 * and the close checked; on failure the message names path and the reason, and path is as it was.
 * path.partial is created exclusively: one already there (a file or a link) is refused, never followed. */
lm_status lm_write_file(const char *path, const void *data, size_t size, lm_error *err);
/* rgba8: width*height*4 bytes, row 0 at the top. Both writers go through lm_write_file. */
lm_status lm_write_png(const char *path, int width, int height, const uint8_t *rgba8, lm_error *err);
/* rgb: width*height*channels floats (channels 1, 3 or 4), row 0 at the top. */
lm_status lm_write_exr(const char *path, int width, int height, int channels, const float *data, lm_error *err);
/* The same stored as 16-bit half floats when `half` (half the size; 11 bits of precision, values up to
 * 65504: larger ones are written as 65504, with a warning that counts them). A non-finite value in data:
 * LM_ERR_INVALID naming the file and how many, nothing written. */
#define LM_HALF_MAX 65504.0f
lm_status lm_write_exr_as(const char *path, int width, int height, int channels, const float *data, int half,
                          lm_error *err);
/* Reads an EXR as RGBA floats (caller frees *out with free()). */
lm_status lm_read_exr(const char *path, int *width, int *height, float **out, lm_error *err);
/* Reads a PNG/JPEG as RGBA8 (caller frees *out with free()). */
lm_status lm_read_image8(const char *path, int *width, int *height, uint8_t **out, lm_error *err);

/* Linear <-> sRGB transfer (IEC 61966-2-1). */
float lm_srgb_to_linear(float c);
float lm_linear_to_srgb(float c);
/* RGBD, an HDR colour in 8-bit RGBA (the encoding Babylon.js decodes for lightmaps, `isRGBD`): a value x
 * (linear, >= 0) is stored as rgb = (x * d)^(1/2.2) and a = d, with d = min(255, floor(255 / max(x))) / 255,
 * so x = rgb^2.2 / a for x up to 255 (above: clamped to 255). Below 1, d = 1 and the 8-bit gamma-2.2 steps
 * set the precision (x = 0.5: 1.2%, 0.1: 2.5%, 0.01: 7%); above, about 0.5%, unless the reader premultiplies
 * the colour by alpha on loading (browsers' image decoders do), which costs log2(1/d) bits. Encodes n pixels of
 * rgba (4 floats each, alpha ignored) divided by `scale` into rgbd8 (4 bytes each). */
#define LM_RGBD_GAMMA 2.2f
#define LM_RGBD_RANGE 255.0f
void lm_encode_rgbd(const float *rgba, size_t n, float scale, uint8_t *rgbd8);
/* The value an RGBD pixel holds, times scale (the inverse of lm_encode_rgbd up to its rounding). */
void lm_decode_rgbd(const uint8_t rgbd8[4], float scale, float rgb[3]);
/* A file a scene names (an image, a buffer, a sky) is read only when it is a regular file: a FIFO blocks
 * its reader until some writer comes (lmgi info hung on one until killed), a device never ends. Opened
 * without blocking and checked by fstat; LM_ERR_IO naming `what`, the path and its kind otherwise. */
lm_status lm_check_regular_file(const char *path, const char *what, lm_error *err);
/* Creates a directory and its parents if missing. */
lm_status lm_mkdir_p(const char *path, lm_error *err);

#endif
