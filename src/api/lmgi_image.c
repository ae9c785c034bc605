/* The public API's pictures: EXR as the numbers, PNG tone-mapped (core/tonemap.h). */
#include <lmgi_tools.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../core/image.h"
#include "../core/tonemap.h"
#include "lmgi_scene.h"

float lmgi_auto_exposure(lmgi_tonemap op, const float *rgb, size_t pixels)
{
    return rgb ? lm_tonemap_exposure((lm_tonemap_op)op, rgb, pixels, 3) : 1.0f;
}

float lmgi_tonemap_rgba8(lmgi_tonemap op, float exposure, const float *rgb, size_t pixels, unsigned char *rgba8)
{
    if (!rgb || !rgba8 || (op != LMGI_TONEMAP_NEUTRAL && op != LMGI_TONEMAP_CLAMP))
        return 0.0f;
    float k = exposure > 0.0f && isfinite(exposure) ? exposure : lm_tonemap_exposure((lm_tonemap_op)op, rgb, pixels, 3);
    lm_tonemap((lm_tonemap_op)op, rgb, pixels, 3, k, rgba8);
    return k;
}

static int ends_with(const char *s, const char *tail)
{
    size_t n = strlen(s), m = strlen(tail);
    return n > m && strcmp(s + n - m, tail) == 0;
}

lmgi_status lmgi_write_image(const char *path, int width, int height, int channels, const float *pixels,
                             const lmgi_image_desc *desc, lmgi_error *err)
{
    lmgi_image_desc d;
    memset(&d, 0, sizeof d);
    if (desc)
        d = *desc;
    lmgi_tonemap op = d.tonemap;
    float exposure = d.exposure;
    lm_error e;
    lm_status st = LM_OK;
    if (!path || !pixels)
        st = lm_fail(&e, LM_ERR_INVALID, "lmgi_write_image: %s is NULL", path ? "pixels" : "path");
    else if (width < 1 || height < 1 || width > 65536 || height > 65536)
        st = lm_fail(&e, LM_ERR_INVALID, "%s: picture %d x %d must have sides in 1..65536", path, width, height);
    else if (channels != 1 && channels != 3 && channels != 4)
        st = lm_fail(&e, LM_ERR_INVALID, "%s: %d channels; pictures have 1, 3 or 4", path, channels);
    else if (op != LMGI_TONEMAP_NEUTRAL && op != LMGI_TONEMAP_CLAMP)
        st = lm_fail(&e, LM_ERR_INVALID, "%s: %d is not a tone map", path, (int)op);
    else if (!(exposure >= 0.0f) || exposure > 1e30f)
        st = lm_fail(&e, LM_ERR_INVALID, "%s: exposure %g must be a finite number >= 0 (0: automatic)", path,
                     (double)exposure);
    size_t values = st == LM_OK ? (size_t)width * (size_t)height * (size_t)channels : 0, bad = 0;
    for (size_t i = 0; i < values; i++) /* a NaN tone-maps to some colour: a picture of one is never "ok" */
        bad += !isfinite(pixels[i]);
    if (bad)
        st = lm_fail(&e, LM_ERR_INVALID, "%s: %zu values are not finite numbers (NaN or infinity): not written",
                     path, bad);
    if (st != LM_OK)
        return lm_export_error(err, &e);
    if (ends_with(path, ".exr"))
        st = lm_write_exr_as(path, width, height, channels, pixels, d.half != 0, &e);
    else if (!ends_with(path, ".png"))
        st = lm_fail(&e, LM_ERR_INVALID, "%s: the name must end in .exr or .png", path);
    else {
        size_t n = (size_t)width * height;
        float *rgb = malloc(n * 3 * sizeof *rgb);
        uint8_t *png = malloc(n * 4);
        if (!rgb || !png)
            st = lm_fail(&e, LM_ERR_NOMEM, "%s: no memory for a %d x %d picture", path, width, height);
        for (size_t i = 0; st == LM_OK && i < n; i++)
            for (int c = 0; c < 3; c++) /* grey from one channel; RGB from the first three */
                rgb[3 * i + c] = pixels[(size_t)channels * i + (channels == 1 ? 0 : c)];
        if (st == LM_OK) {
            float k = exposure > 0.0f ? exposure : lm_tonemap_exposure((lm_tonemap_op)op, rgb, n, 3);
            lm_tonemap((lm_tonemap_op)op, rgb, n, 3, k, png);
            st = lm_write_png(path, width, height, png, &e);
        }
        free(rgb);
        free(png);
    }
    return st == LM_OK ? LMGI_OK : lm_export_error(err, &e);
}
