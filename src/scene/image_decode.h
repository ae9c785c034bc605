/* Decoding the images a scene names, at the size lmgi needs them.
 *
 * Formats: WebP (EXT_texture_webp; Godot 4 writes its textures so) through libwebp, recognised by its
 * RIFF....WEBP header; everything else (PNG, JPEG, BMP, TGA, ...) through stb_image.
 *
 * Size: lmgi samples a texture for a texel's or a pixel's albedo, an average over a footprint of
 * centimetres to metres, never for detail finer than the frame's pixels. So an image whose longer side
 * exceeds max_side is reduced on decode (aspect kept) to a longer side of max_side: libwebp scales as it
 * decodes; stb's images are decoded whole and then box-filtered by stb_image_resize, in linear light
 * when srgb is set (colour textures), so that a reduced texture keeps its mean albedo. A 4096 x 4096
 * colour texture costs 256 MiB as lmgi's float RGBA; at the default 512 it costs 4 MiB.
 *
 * Output: 8-bit RGBA, row 0 at the top, malloc'd into *rgba (the caller frees), *w x *h.
 * Returns LM_OK, LM_ERR_FORMAT (not an image lmgi reads, or corrupt: *why says so), LM_ERR_NOMEM.
 * An image of more than LM_IMAGE_MAX_PIXELS before reduction is refused as LM_ERR_FORMAT without being
 * decoded (its header alone is read).
 *
 * Thread-safety: reentrant; no state. */
#ifndef LM_IMAGE_DECODE_H
#define LM_IMAGE_DECODE_H

#include <stddef.h>
#include <stdint.h>

#include "../core/error.h"

#ifdef __cplusplus
extern "C" {
#endif

#define LM_TEXTURE_MAX_SIDE 256
#define LM_IMAGE_MAX_PIXELS (1LL << 26)

/* 1 if the bytes start as a WebP file does. */
int lm_image_is_webp(const uint8_t *bytes, size_t size);

lm_status lm_image_decode(const uint8_t *bytes, size_t size, int max_side, int srgb, uint8_t **rgba, int *w, int *h,
                          const char **why);
/* The bytes decoding the image will hold at once at most (its full-size RGBA and the reduced copy), from
 * its header alone; 0 when the header is not one lmgi reads (the decode then refuses it cheaply). */
double lm_image_decode_bytes(const uint8_t *bytes, size_t size, int max_side);

#ifdef __cplusplus
}
#endif
#endif
