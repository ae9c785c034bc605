/* The sky's radiance by direction (sky.h). */
#include "sky.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <stb/stb_image.h>

#include "../core/hash.h"
#include "../core/image.h"

#include "../core/vecmath.h"

int lm_sky_is_uniform(const lm_scene *s) { return !s->has_sky || s->sky_kind == LM_SKY_UNIFORM; }

/* Bilinear lookup of the equirectangular image at (u, v) in [0, 1)^2, u wrapping round, v clamped. */
static void image_at(const lm_scene *s, double u, double v, float out[3])
{
    int w = s->sky_width, h = s->sky_height;
    double x = u * w - 0.5, y = v * h - 0.5;
    x -= floor(x / w) * w;
    y = y < 0.0 ? 0.0 : y > h - 1 ? h - 1 : y;
    int x0 = (int)x % w, x1 = (x0 + 1) % w, y0 = (int)y, y1 = y0 + 1 < h ? y0 + 1 : y0;
    float fx = (float)(x - floor(x)), fy = (float)(y - y0);
    const float *p00 = s->sky_image + 3 * ((size_t)y0 * w + x0), *p10 = s->sky_image + 3 * ((size_t)y0 * w + x1);
    const float *p01 = s->sky_image + 3 * ((size_t)y1 * w + x0), *p11 = s->sky_image + 3 * ((size_t)y1 * w + x1);
    for (int c = 0; c < 3; c++)
        out[c] = (1.0f - fy) * ((1.0f - fx) * p00[c] + fx * p10[c]) + fy * ((1.0f - fx) * p01[c] + fx * p11[c]);
}

void lm_sky_radiance(const lm_scene *s, const float d[3], float out[3])
{
    if (!s->has_sky) {
        out[0] = out[1] = out[2] = 0.0f;
        return;
    }
    if (s->sky_kind == LM_SKY_GRADIENT) {
        float t = d[1] > 0.0f ? (d[1] < 1.0f ? d[1] : 1.0f) : 0.0f;
        for (int c = 0; c < 3; c++)
            out[c] = s->sky_horizon[c] + (s->sky[c] - s->sky_horizon[c]) * t;
        return;
    }
    if (s->sky_kind == LM_SKY_IMAGE && s->sky_image) {
        double u = atan2((double)d[0], -(double)d[2]) / (2.0 * LM_PI) + 0.5;
        double v = acos(fmin(1.0, fmax(-1.0, (double)d[1]))) / LM_PI;
        image_at(s, u, v, out);
        for (int c = 0; c < 3; c++)
            out[c] *= s->sky[c];
        return;
    }
    for (int c = 0; c < 3; c++)
        out[c] = s->sky[c];
}

void lm_sky_mean(const lm_scene *s, float out[3])
{
    if (!s->has_sky || s->sky_kind == LM_SKY_UNIFORM) {
        for (int c = 0; c < 3; c++)
            out[c] = s->has_sky ? s->sky[c] : 0.0f;
        return;
    }
    if (s->sky_kind == LM_SKY_GRADIENT) { /* the upper half: h + (z - h) / 2 on average; the lower: h */
        for (int c = 0; c < 3; c++)
            out[c] = s->sky_horizon[c] + 0.25f * (s->sky[c] - s->sky_horizon[c]);
        return;
    }
    for (int c = 0; c < 3; c++)
        out[c] = s->sky_image_mean[c] * s->sky[c];
}

uint64_t lm_sky_hash(uint64_t h, const lm_scene *s)
{
    uint32_t has = (uint32_t)s->has_sky, kind = (uint32_t)s->sky_kind;
    h = lm_hash_bytes(h, s->sky, sizeof s->sky);
    h = lm_hash_bytes(h, &has, sizeof has);
    h = lm_hash_bytes(h, &kind, sizeof kind);
    h = lm_hash_bytes(h, s->sky_horizon, sizeof s->sky_horizon);
    if (s->sky_image)
        h = lm_hash_bytes(h, s->sky_image, 3 * sizeof(float) * (size_t)s->sky_width * (size_t)s->sky_height);
    return h;
}

/* The image's mean over the sphere: a row's solid angle goes as sin(theta). */
static void image_mean(const float *rgb, int w, int h, float out[3])
{
    double sum[3] = {0, 0, 0}, weight = 0.0;
    for (int y = 0; y < h; y++) {
        double wt = sin(LM_PI * (y + 0.5) / h);
        for (int x = 0; x < w; x++)
            for (int c = 0; c < 3; c++)
                sum[c] += wt * rgb[3 * ((size_t)y * w + x) + c];
        weight += wt * w;
    }
    for (int c = 0; c < 3; c++)
        out[c] = weight > 0.0 ? (float)(sum[c] / weight) : 0.0f;
}

/* RGB floats of the file, from .hdr (stb_image) or .exr (tinyexr), by its content. */
static lm_status read_hdr(const char *path, int *w, int *h, float **rgb, lm_error *err)
{
    lm_status regular = lm_check_regular_file(path, "the sky image", err);
    if (regular != LM_OK)
        return regular;
    FILE *f = fopen(path, "rb");
    if (!f)
        return lm_fail(err, LM_ERR_IO, "%s: cannot open the sky image: %s", path, strerror(errno));
    unsigned char magic[4] = {0};
    size_t got = fread(magic, 1, 4, f);
    fclose(f);
    if (got == 4 && magic[0] == 0x76 && magic[1] == 0x2f && magic[2] == 0x31 && magic[3] == 0x01) { /* OpenEXR */
        float *rgba = NULL;
        lm_status st = lm_read_exr(path, w, h, &rgba, err);
        if (st != LM_OK)
            return st;
        size_t n = (size_t)*w * (size_t)*h;
        *rgb = malloc(3 * sizeof(float) * (n ? n : 1));
        for (size_t i = 0; *rgb && i < n; i++)
            memcpy(*rgb + 3 * i, rgba + 4 * i, 3 * sizeof(float));
        free(rgba);
        return *rgb ? LM_OK : lm_fail(err, LM_ERR_NOMEM, "%s: no memory for the sky image", path);
    }
    int comp = 0;
    if (!stbi_is_hdr(path))
        return lm_fail(err, LM_ERR_FORMAT, "%s: not an HDR image lmgi reads as a sky (Radiance .hdr, OpenEXR .exr)",
                       path);
    if (!stbi_info(path, w, h, &comp) || (long long)*w * *h > LM_SKY_MAX_PIXELS)
        return lm_fail(err, LM_ERR_INVALID, "%s: the sky image is unreadable or larger than %d pixels", path,
                       LM_SKY_MAX_PIXELS);
    *rgb = stbi_loadf(path, w, h, &comp, 3);
    return *rgb ? LM_OK : lm_fail(err, LM_ERR_FORMAT, "%s: corrupt HDR image: %s", path, stbi_failure_reason());
}

lm_status lm_sky_load_image(lm_scene *s, const char *path, const float scale[3], lm_error *err)
{
    for (int c = 0; c < 3; c++)
        if (!(scale[c] >= 0.0f && scale[c] <= (float)LM_MAX_EMISSION))
            return lm_fail(err, LM_ERR_INVALID, "%s: the sky image's scale %g must be a finite number >= 0", path,
                           (double)scale[c]);
    int w = 0, h = 0;
    float *rgb = NULL;
    lm_status st = read_hdr(path, &w, &h, &rgb, err);
    if (st != LM_OK)
        return st;
    if (w < 1 || h < 1 || (long long)w * h > LM_SKY_MAX_PIXELS) {
        free(rgb);
        return lm_fail(err, LM_ERR_INVALID, "%s: a sky image of %d x %d pixels (1 to %d)", path, w, h,
                       LM_SKY_MAX_PIXELS);
    }
    for (size_t i = 0; i < 3 * (size_t)w * (size_t)h; i++)
        if (!(rgb[i] >= 0.0f && rgb[i] <= (float)LM_MAX_EMISSION)) {
            size_t p = i / 3;
            free(rgb);
            return lm_fail(err, LM_ERR_INVALID, "%s: pixel (%zu, %zu) of the sky image is negative or not finite",
                           path, p % (size_t)w, p / (size_t)w);
        }
    free(s->sky_image);
    s->sky_image = rgb, s->sky_width = w, s->sky_height = h;
    image_mean(rgb, w, h, s->sky_image_mean);
    s->sky_kind = LM_SKY_IMAGE;
    memcpy(s->sky, scale, sizeof s->sky);
    s->has_sky = 1;
    return LM_OK;
}
