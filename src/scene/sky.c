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

/* Bilinear lookup of the equirectangular image at (u, v) in [0, 1)^2, u wrapping round, v clamped; with
 * b (may be NULL) the same lookup of the pixels' brightest channel, and k the row of cells between pixel
 * centres it lies in (lm_sky_sample's: 0 and h the clamped half rows at the top and the bottom). */
static void image_at(const lm_scene *s, double u, double v, float out[3], double *b, int *k)
{
    int w = s->sky_width, h = s->sky_height;
    double x = u * w - 0.5, y = v * h - 0.5;
    x -= floor(x / w) * w;
    if (k)
        *k = y < 0.0 ? 0 : y >= h - 1 ? h : (int)y + 1;
    y = y < 0.0 ? 0.0 : y > h - 1 ? h - 1 : y;
    int x0 = (int)x % w, x1 = (x0 + 1) % w, y0 = (int)y, y1 = y0 + 1 < h ? y0 + 1 : y0;
    float fx = (float)(x - floor(x)), fy = (float)(y - y0);
    const float *p00 = s->sky_image + 3 * ((size_t)y0 * w + x0), *p10 = s->sky_image + 3 * ((size_t)y0 * w + x1);
    const float *p01 = s->sky_image + 3 * ((size_t)y1 * w + x0), *p11 = s->sky_image + 3 * ((size_t)y1 * w + x1);
    for (int c = 0; c < 3; c++)
        out[c] = (1.0f - fy) * ((1.0f - fx) * p00[c] + fx * p10[c]) + fy * ((1.0f - fx) * p01[c] + fx * p11[c]);
    if (b) {
#define BRIGHT(p) fmaxf((p)[0], fmaxf((p)[1], (p)[2]))
        *b = (1.0 - fy) * ((1.0 - fx) * BRIGHT(p00) + fx * BRIGHT(p10)) +
             fy * ((1.0 - fx) * BRIGHT(p01) + fx * BRIGHT(p11));
#undef BRIGHT
    }
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
        image_at(s, u, v, out, NULL, NULL);
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

/* ---- directions drawn by brightness (lm_sky_sample) ----
 *
 * The lookup is bilinear between pixel centres, so the brightness b (the brightest channel, bilinear like
 * the lookup and never below any channel) is drawn exactly as it lies: in cells between four pixel
 * centres (x wrapping round; a half-pixel band at the top and the bottom, where the lookup clamps), a row
 * of cells by its area times its solid angle (sin theta at its middle) times its mean b, a cell of it by
 * its mean b, and a point in it by b there (a linear marginal, then a linear conditional). So each
 * direction's L / p stays near the same however sharp a sun; drawn pixel by pixel, uniformly inside,
 * L / p ran over the bilinear ramp around the sun, and the rays gather's texels under it scattered twice
 * as much. Each row's b and the rows' weights get 1/100 of their mean added, so that every direction
 * keeps a density and float sums keep every cell however bright a sun beside it.
 * The block after the pixels (cdf_floats): h + 1 rows of cells of w + 1 running sums (of the cells' mean
 * b plus the row's floor), the h + 2 running sums of the rows, and the h + 1 rows' floors. */

#define SKY_FLOOR 0.01 /* of the mean, added to every row's brightness and to every row's weight */

static size_t cdf_floats(int w, int h) { return (size_t)(h + 1) * ((size_t)w + 1) + (size_t)(h + 2) + (size_t)(h + 1); }

typedef struct {
    const float *rgb, *cells, *rows, *floors;
    int w, h;
} sky_cdf;

static sky_cdf cdf_of(const float *rgb, int w, int h)
{
    const float *cells = rgb + 3 * (size_t)w * h, *rows = cells + (size_t)(h + 1) * ((size_t)w + 1);
    return (sky_cdf){rgb, cells, rows, rows + h + 2, w, h};
}

/* The brightest channel of pixel (x, y), x wrapping round, y clamped. */
static float bright(const float *rgb, int w, int h, int x, int y)
{
    y = y < 0 ? 0 : y >= h ? h - 1 : y;
    const float *p = rgb + 3 * ((size_t)y * w + (size_t)((x % w + w) % w));
    return fmaxf(p[0], fmaxf(p[1], p[2]));
}

/* Cell row k: its top pixel row (the band at the top: row 0 twice; at the bottom: row h - 1 twice), its
 * height in pixels and the y of its middle (pixel-centre coordinates, y = v h - 0.5). */
static double row_height(int k, int h) { return k == 0 || k == h ? 0.5 : 1.0; }

static void cell_row(int k, int h, int *top, int *bottom, double *height, double *mid)
{
    *top = k == 0 ? 0 : k - 1;
    *bottom = k == 0 ? 0 : k == h ? h - 1 : k;
    *height = row_height(k, h);
    *mid = k == 0 ? -0.25 : k == h ? h - 0.75 : k - 0.5;
}

/* The corners' b of cell (i, k), floor added: a top left, b top right, c bottom left, d bottom right. */
static void cell_corners(const float *rgb, int w, int h, int i, int k, float f, double q[4])
{
    int top, bottom;
    double height, mid;
    cell_row(k, h, &top, &bottom, &height, &mid);
    q[0] = bright(rgb, w, h, i, top) + f, q[1] = bright(rgb, w, h, i + 1, top) + f;
    q[2] = bright(rgb, w, h, i, bottom) + f, q[3] = bright(rgb, w, h, i + 1, bottom) + f;
}

/* Fills the block after the pixels (cdf_floats(w, h)). */
static void build_cdf(float *rgb, int w, int h)
{
    float *cells = rgb + 3 * (size_t)w * h, *rows = cells + (size_t)(h + 1) * ((size_t)w + 1), *floors = rows + h + 2;
    double *weight = malloc(sizeof *weight * (size_t)(h + 1)), total = 0.0;
    for (int k = 0; k <= h; k++) {
        double q[4], sum = 0.0, run = 0.0, height, mid;
        int top, bottom;
        for (int i = 0; i < w; i++) {
            cell_corners(rgb, w, h, i, k, 0.0f, q);
            sum += 0.25 * (q[0] + q[1] + q[2] + q[3]);
        }
        float f = (float)(SKY_FLOOR * sum / w);
        floors[k] = f > 0.0f ? f : 1.0f; /* a black row (or one too dim for a float's floor): even */
        float *row = cells + (size_t)k * ((size_t)w + 1);
        row[0] = 0.0f;
        for (int i = 0; i < w; i++) {
            cell_corners(rgb, w, h, i, k, floors[k], q);
            run += 0.25 * (q[0] + q[1] + q[2] + q[3]);
            row[i + 1] = (float)run;
        }
        cell_row(k, h, &top, &bottom, &height, &mid);
        double wk = height * sin(LM_PI * (mid + 0.5) / h) * sum; /* area x solid angle x brightness */
        if (weight)
            weight[k] = wk;
        total += wk;
    }
    double floor_r = SKY_FLOOR * total / (h + 1), run = 0.0;
    rows[0] = 0.0f;
    for (int k = 0; k <= h; k++) {
        run += (weight ? weight[k] : 1.0) + floor_r;
        rows[k + 1] = (float)run;
    }
    free(weight);
}

/* The index i of [c[i], c[i + 1]) holding t (c: n + 1 rising sums from 0; t in [0, c[n])). */
static int find_interval(const float *c, int n, float t)
{
    int lo = 0, hi = n - 1;
    while (lo < hi) {
        int mid = (lo + hi + 1) / 2;
        if (c[mid] <= t)
            lo = mid;
        else
            hi = mid - 1;
    }
    return lo;
}

/* t in [0, 1] where a density rising linearly from p0 to p1 over [0, 1] has its share r below. */
static double linear_inverse(double p0, double p1, double r)
{
    double den = p0 + sqrt(fmax(p0 * p0 + (p1 * p1 - p0 * p0) * r, 0.0));
    return den > 0.0 ? fmin(fmax(r * (p0 + p1) / den, 0.0), 1.0) : r;
}

/* The density per steradian of lm_sky_sample's directions where the lookup's brightness is b, in cell row
 * k, at polar angle theta: the row's share, times the cell's share times b over the cell's mean (which is
 * (b + floor) over the row's sum, whatever the cell), over the row's height; then per steradian, with
 * x = u w, y = v h, u = phi / 2 pi, v = theta / pi. */
static double density(const lm_scene *s, double b, int k, double sin_theta)
{
    sky_cdf c = cdf_of(s->sky_image, s->sky_width, s->sky_height);
    double height = row_height(k, c.h), row = c.cells[(size_t)k * ((size_t)c.w + 1) + (size_t)c.w];
    double xy = ((double)c.rows[k + 1] - c.rows[k]) / c.rows[c.h + 1] * (b + c.floors[k]) / row / height;
    return xy * c.w * c.h / (2.0 * LM_PI * LM_PI * fmax(sin_theta, 1e-9));
}

void lm_sky_radiance_pdf(const lm_scene *s, const float d[3], float out[3], double *pdf)
{
    if (!lm_sky_by_brightness(s)) {
        lm_sky_radiance(s, d, out);
        *pdf = 1.0 / (4.0 * LM_PI);
        return;
    }
    double u = atan2((double)d[0], -(double)d[2]) / (2.0 * LM_PI) + 0.5;
    double v = acos(fmin(1.0, fmax(-1.0, (double)d[1]))) / LM_PI, b;
    int k;
    image_at(s, u, v, out, &b, &k);
    for (int c = 0; c < 3; c++)
        out[c] *= s->sky[c];
    *pdf = density(s, b, k, sqrt(fmax(0.0, 1.0 - (double)d[1] * d[1])));
}

int lm_sky_by_brightness(const lm_scene *s)
{
    return s->has_sky && s->sky_kind == LM_SKY_IMAGE && s->sky_image &&
           cdf_of(s->sky_image, s->sky_width, s->sky_height).rows[s->sky_height + 1] > 0.0f;
}

/* The share r of [c[i], c[i + 1]) below t. */
static double within(const float *c, int i, float t)
{
    return c[i + 1] > c[i] ? fmin(fmax(((double)t - c[i]) / ((double)c[i + 1] - c[i]), 0.0), 1.0) : 0.5;
}

void lm_sky_sample(const lm_scene *s, float u0, float u1, float d[3])
{ /* lm_sky_by_brightness(s) */
    sky_cdf c = cdf_of(s->sky_image, s->sky_width, s->sky_height);
    float t = fminf(fmaxf(u0, 0.0f), 1.0f) * c.rows[c.h + 1];
    int k = find_interval(c.rows, c.h + 1, fminf(t, nextafterf(c.rows[c.h + 1], 0.0f)));
    double r0 = within(c.rows, k, t);
    const float *row = c.cells + (size_t)k * ((size_t)c.w + 1);
    float tx = fminf(fmaxf(u1, 0.0f), 1.0f) * row[c.w];
    int i = find_interval(row, c.w, fminf(tx, nextafterf(row[c.w], 0.0f)));
    double r1 = within(row, i, tx), q[4];
    cell_corners(c.rgb, c.w, c.h, i, k, c.floors[k], q);
    /* the same stratum of (u0, u1) lands in the same part of the cell */
    double fy = linear_inverse(0.5 * (q[0] + q[1]), 0.5 * (q[2] + q[3]), r0);
    double fx = linear_inverse((1 - fy) * q[0] + fy * q[2], (1 - fy) * q[1] + fy * q[3], r1);
    double y = k == 0 ? -0.5 + 0.5 * fy : k == c.h ? c.h - 1 + 0.5 * fy : (k - 1) + fy;
    double theta = LM_PI * (y + 0.5) / c.h, phi = 2.0 * LM_PI * ((i + fx + 0.5) / c.w - 0.5);
    d[0] = (float)(sin(theta) * sin(phi));
    d[1] = (float)cos(theta);
    d[2] = (float)(-sin(theta) * cos(phi));
}

/* rgb (w x h, malloc'd; taken whatever happens) as s's sky image, times scale, once every pixel and the
 * scale are finite and >= 0; `what` names it in the errors. The running sums of lm_sky_sample go after its
 * pixels, in the same block, so that whoever hands the image on hands them on too. */
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
    float *whole = realloc(rgb, (3 * (size_t)w * (size_t)h + cdf_floats(w, h)) * sizeof *whole);
    if (!whole) {
        free(rgb);
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for a sky image of %d x %d pixels", what, w, h);
    }
    rgb = whole;
    build_cdf(rgb, w, h);
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
