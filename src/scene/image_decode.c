/* Image decoding at the size lmgi needs (image_decode.h). */
#include "image_decode.h"

#include <stdlib.h>
#include <string.h>

#include <stb/stb_image.h>
#include <stb/stb_image_resize.h>
#include <webp/decode.h>

int lm_image_is_webp(const uint8_t *bytes, size_t size)
{
    return size >= 12 && memcmp(bytes, "RIFF", 4) == 0 && memcmp(bytes + 8, "WEBP", 4) == 0;
}

/* The reduced size: the longer side max_side, the shorter in proportion (at least 1). */
static void fit(int w, int h, int max_side, int *ow, int *oh)
{
    *ow = w, *oh = h;
    if (max_side <= 0 || (w <= max_side && h <= max_side))
        return;
    if (w >= h) {
        *ow = max_side;
        *oh = (int)((long long)h * max_side / w);
    } else {
        *oh = max_side;
        *ow = (int)((long long)w * max_side / h);
    }
    *ow = *ow < 1 ? 1 : *ow;
    *oh = *oh < 1 ? 1 : *oh;
}

static lm_status decode_webp(const uint8_t *bytes, size_t size, int max_side, uint8_t **rgba, int *w, int *h,
                             const char **why)
{
    WebPDecoderConfig cfg;
    if (!WebPInitDecoderConfig(&cfg) || WebPGetFeatures(bytes, size, &cfg.input) != VP8_STATUS_OK) {
        *why = "not a WebP image libwebp can read";
        return LM_ERR_FORMAT;
    }
    int iw = cfg.input.width, ih = cfg.input.height, ow, oh;
    if (iw <= 0 || ih <= 0 || (long long)iw * ih > LM_IMAGE_MAX_PIXELS) {
        *why = "WebP image larger than 2^26 pixels";
        return LM_ERR_FORMAT;
    }
    fit(iw, ih, max_side, &ow, &oh);
    size_t bytes_out = (size_t)ow * (size_t)oh * 4;
    uint8_t *px = malloc(bytes_out);
    if (!px)
        return LM_ERR_NOMEM;
    cfg.options.use_scaling = ow != iw || oh != ih;
    cfg.options.scaled_width = ow, cfg.options.scaled_height = oh;
    cfg.output.colorspace = MODE_RGBA;
    cfg.output.is_external_memory = 1;
    cfg.output.u.RGBA.rgba = px, cfg.output.u.RGBA.stride = ow * 4, cfg.output.u.RGBA.size = bytes_out;
    VP8StatusCode st = WebPDecode(bytes, size, &cfg);
    WebPFreeDecBuffer(&cfg.output);
    if (st != VP8_STATUS_OK) {
        free(px);
        *why = st == VP8_STATUS_OUT_OF_MEMORY ? "out of memory decoding WebP" : "corrupt WebP image";
        return st == VP8_STATUS_OUT_OF_MEMORY ? LM_ERR_NOMEM : LM_ERR_FORMAT;
    }
    *rgba = px, *w = ow, *h = oh;
    return LM_OK;
}

static lm_status decode_stb(const uint8_t *bytes, size_t size, int max_side, int srgb, uint8_t **rgba, int *w,
                            int *h, const char **why)
{
    int iw = 0, ih = 0, comp = 0, ow, oh;
    if (size > INT32_MAX || !stbi_info_from_memory(bytes, (int)size, &iw, &ih, &comp) || iw <= 0 || ih <= 0) {
        *why = "not an image lmgi reads (PNG, JPEG, WebP, BMP, TGA)";
        return LM_ERR_FORMAT;
    }
    if ((long long)iw * ih > LM_IMAGE_MAX_PIXELS) {
        *why = "image larger than 2^26 pixels";
        return LM_ERR_FORMAT;
    }
    uint8_t *full = stbi_load_from_memory(bytes, (int)size, &iw, &ih, &comp, 4);
    if (!full) { /* out of memory is the machine's limit, not the file's fault: never "ignored" */
        int nomem = stbi_failure_reason() && !strcmp(stbi_failure_reason(), "outofmem");
        *why = nomem ? "out of memory decoding it" : "corrupt image";
        return nomem ? LM_ERR_NOMEM : LM_ERR_FORMAT;
    }
    fit(iw, ih, max_side, &ow, &oh);
    if (ow == iw && oh == ih) {
        *rgba = full, *w = iw, *h = ih;
        return LM_OK;
    }
    uint8_t *px = malloc((size_t)ow * (size_t)oh * 4);
    int ok = px && (srgb ? stbir_resize_uint8_srgb(full, iw, ih, 0, px, ow, oh, 0, 4, 3, 0)
                         : stbir_resize_uint8(full, iw, ih, 0, px, ow, oh, 0, 4));
    stbi_image_free(full);
    if (!ok) {
        free(px);
        return LM_ERR_NOMEM;
    }
    *rgba = px, *w = ow, *h = oh;
    return LM_OK;
}

double lm_image_decode_bytes(const uint8_t *bytes, size_t size, int max_side)
{
    int iw = 0, ih = 0, comp = 0, ow, oh;
    if (!bytes || size == 0 || size > INT32_MAX)
        return 0.0;
    if (lm_image_is_webp(bytes, size)) {
        if (!WebPGetInfo(bytes, size, &iw, &ih))
            return 0.0;
        fit(iw, ih, max_side, &ow, &oh);
        return 4.0 * ow * oh; /* libwebp scales as it decodes */
    }
    if (!stbi_info_from_memory(bytes, (int)size, &iw, &ih, &comp) || (long long)iw * ih > LM_IMAGE_MAX_PIXELS)
        return 0.0;
    fit(iw, ih, max_side, &ow, &oh);
    return 4.0 * iw * ih + 4.0 * ow * oh;
}

lm_status lm_image_decode(const uint8_t *bytes, size_t size, int max_side, int srgb, uint8_t **rgba, int *w, int *h,
                          const char **why)
{
    *rgba = NULL, *w = *h = 0, *why = "out of memory";
    if (!bytes || size == 0) {
        *why = "no image data";
        return LM_ERR_FORMAT;
    }
    return lm_image_is_webp(bytes, size) ? decode_webp(bytes, size, max_side, rgba, w, h, why)
                                         : decode_stb(bytes, size, max_side, srgb, rgba, w, h, why);
}
