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

/* rgb (w x h, malloc'd; taken whatever happens) as s's sky image, times scale, once every pixel and the
 * scale are finite and >= 0; `what` names it in the errors. */
static lm_status set_image(lm_scene *s, float *rgb, int w, int h, const float scale[3], const char *what,
                           lm_error *err)
{
    if (w < 1 || h < 1 || (long long)w * h > LM_SKY_MAX_PIXELS) {
        free(rgb);
        return lm_fail(err, LM_ERR_INVALID, "%s: a sky image of %d x %d pixels (1 to %d)", what, w, h,
                       LM_SKY_MAX_PIXELS);
    }
    for (size_t i = 0; i < 3 * (size_t)w * (size_t)h; i++)
        if (!(rgb[i] >= 0.0f && rgb[i] <= (float)LM_MAX_EMISSION)) {
            size_t p = i / 3;
            free(rgb);
            return lm_fail(err, LM_ERR_INVALID, "%s: pixel (%zu, %zu) of the sky image is negative or not finite",
                           what, p % (size_t)w, p / (size_t)w);
        }
    free(s->sky_image);
    s->sky_image = rgb, s->sky_width = w, s->sky_height = h;
    image_mean(rgb, w, h, s->sky_image_mean);
    s->sky_kind = LM_SKY_IMAGE;
    memcpy(s->sky, scale, sizeof s->sky);
    s->has_sky = 1;
    return LM_OK;
}

static lm_status check_scale(const float scale[3], const char *what, lm_error *err)
{
    for (int c = 0; c < 3; c++)
        if (!(scale[c] >= 0.0f && scale[c] <= (float)LM_MAX_EMISSION))
            return lm_fail(err, LM_ERR_INVALID, "%s: the sky image's scale %g must be a finite number >= 0", what,
                           (double)scale[c]);
    return LM_OK;
}

lm_status lm_sky_load_image(lm_scene *s, const char *path, const float scale[3], lm_error *err)
{
    lm_status st = check_scale(scale, path, err);
    if (st != LM_OK)
        return st;
    int w = 0, h = 0;
    float *rgb = NULL;
    if ((st = read_hdr(path, &w, &h, &rgb, err)) != LM_OK)
        return st;
    return set_image(s, rgb, w, h, scale, path, err);
}

/* The cube's radiance towards cube-space direction c (not zero): the face of its largest coordinate, at
 * the face's (s, t) as OpenGL's cube maps define them, that face's image upside down (the extension's
 * flip: row 0 at t = 1), bilinear between texel centres and clamped at the face's edges. */
static void cube_at(const float *const face[6], int n, const double c[3], float out[3])
{
    double ax = fabs(c[0]), ay = fabs(c[1]), az = fabs(c[2]), sc, tc, ma;
    int f;
    if (ax >= ay && ax >= az)
        f = c[0] > 0.0 ? 0 : 1, ma = ax, sc = c[0] > 0.0 ? -c[2] : c[2], tc = -c[1];
    else if (ay >= az)
        f = c[1] > 0.0 ? 2 : 3, ma = ay, sc = c[0], tc = c[1] > 0.0 ? c[2] : -c[2];
    else
        f = c[2] > 0.0 ? 4 : 5, ma = az, sc = c[2] > 0.0 ? c[0] : -c[0], tc = -c[1];
    double x = 0.5 * (sc / ma + 1.0) * n - 0.5, y = 0.5 * (1.0 - tc / ma) * n - 0.5;
    x = fmin(fmax(x, 0.0), n - 1), y = fmin(fmax(y, 0.0), n - 1);
    int x0 = (int)x, y0 = (int)y, x1 = x0 + 1 < n ? x0 + 1 : x0, y1 = y0 + 1 < n ? y0 + 1 : y0;
    float fx = (float)(x - x0), fy = (float)(y - y0);
    const float *p00 = face[f] + 3 * ((size_t)y0 * n + x0), *p10 = face[f] + 3 * ((size_t)y0 * n + x1);
    const float *p01 = face[f] + 3 * ((size_t)y1 * n + x0), *p11 = face[f] + 3 * ((size_t)y1 * n + x1);
    for (int k = 0; k < 3; k++)
        out[k] = (1.0f - fy) * ((1.0f - fx) * p00[k] + fx * p10[k]) + fy * ((1.0f - fx) * p01[k] + fx * p11[k]);
}

/* The equirectangular image of the cube: each pixel the mean of k x k lookups across it (k > 1 where the
 * image is coarser than the faces), a scene direction d turned into the cube's space as
 * c = R(rotation)^T (-d.x, d.y, d.z) (the mirror: cube maps are left-handed, glTF is not). */
static void cube_to_equirect(const float *const face[6], int n, const float rotation[4], int w, int h, int k,
                             float *rgb)
{
    static const float zero[3] = {0, 0, 0}, one[3] = {1, 1, 1};
    float r[16];
    lm_mat4_from_trs(r, zero, rotation, one);
#pragma omp parallel for schedule(dynamic)
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            double sum[3] = {0, 0, 0};
            for (int j = 0; j < k; j++)
                for (int i = 0; i < k; i++) {
                    /* the inverse of lm_sky_radiance's (u, v), mirrored in x */
                    double phi = 2.0 * LM_PI * ((x + (i + 0.5) / k) / w - 0.5);
                    double theta = LM_PI * (y + (j + 0.5) / k) / h;
                    double p[3] = {-sin(theta) * sin(phi), cos(theta), -sin(theta) * cos(phi)}, c[3];
                    for (int a = 0; a < 3; a++)
                        c[a] = r[4 * a] * p[0] + r[4 * a + 1] * p[1] + r[4 * a + 2] * p[2];
                    float v[3];
                    cube_at(face, n, c, v);
                    for (int a = 0; a < 3; a++)
                        sum[a] += v[a];
                }
            for (int a = 0; a < 3; a++)
                rgb[3 * ((size_t)y * w + x) + a] = (float)(sum[a] / (k * k));
        }
}

lm_status lm_sky_set_cube(lm_scene *s, const uint8_t *const rgbd[6], int n, const float rotation[4], float intensity,
                          const char *what, lm_error *err)
{
    const float scale[3] = {intensity, intensity, intensity};
    lm_status st = check_scale(scale, what, err);
    if (st != LM_OK)
        return st;
    if (n < 1 || (long long)n * n > LM_SKY_MAX_PIXELS)
        return lm_fail(err, LM_ERR_INVALID, "%s: cube faces of %d x %d pixels, more than the %d a sky image may "
                       "have", what, n, n, LM_SKY_MAX_PIXELS);
    int w = 4 * n < LM_SKY_CUBE_MIN_WIDTH ? LM_SKY_CUBE_MIN_WIDTH : 4 * n;
    w = w > LM_SKY_CUBE_MAX_WIDTH ? LM_SKY_CUBE_MAX_WIDTH : w;
    int h = w / 2, k = (4 * n + w - 1) / w; /* 4n across keeps the faces' detail at the horizon */
    size_t texels = (size_t)n * (size_t)n;
    float *linear = malloc(6 * 3 * sizeof(float) * texels), *rgb = malloc(3 * sizeof(float) * (size_t)w * h);
    if (!linear || !rgb) {
        free(linear);
        free(rgb);
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for a sky of six %d x %d faces", what, n, n);
    }
    const float *face[6];
    for (int f = 0; f < 6; f++) { /* RGBD: an LDR face (alpha 255) reads as its colour to the power 2.2 */
        float *out = linear + 3 * texels * (size_t)f;
        for (size_t i = 0; i < texels; i++)
            lm_decode_rgbd(rgbd[f] + 4 * i, 1.0f, out + 3 * i);
        face[f] = out;
    }
    cube_to_equirect(face, n, rotation, w, h, k, rgb);
    free(linear);
    return set_image(s, rgb, w, h, scale, what, err);
}
