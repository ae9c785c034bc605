#include "image.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <stb/stb_image.h>
#include <stb/stb_image_write.h>
#include <tinyexr.h>

#include "log.h"

/* A file appears whole or not at all: the bytes go to PATH.partial (created exclusively), every write
 * and the close are checked (a full disk shows up at fclose, when the buffer is flushed), and only then does a rename put
 * it in place. A failure removes the partial file and leaves whatever PATH held before. */
lm_status lm_write_file(const char *path, const void *data, size_t size, lm_error *err)
{
    char tmp[4200];
    if (snprintf(tmp, sizeof tmp, "%s.partial", path) >= (int)sizeof tmp)
        return lm_fail(err, LM_ERR_INVALID, "%s: path too long", path);
    /* created, never opened: a file or a symbolic link already in the way is refused, not written through */
    int fd = open(tmp, O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
    if (fd < 0 && errno == EEXIST)
        return lm_fail(err, LM_ERR_IO, "%s: %s is in the way (a write that was killed left it, another program "
                       "is writing it, or it is a link); lmgi will not write through it: remove it", path, tmp);
    FILE *f = fd < 0 ? NULL : fdopen(fd, "wb");
    if (!f) {
        if (fd >= 0)
            close(fd);
        return lm_fail(err, LM_ERR_IO, "%s: cannot write (%s)", path, strerror(errno));
    }
    int ok = fwrite(data, 1, size, f) == size;
    int e = errno;
    ok = fflush(f) == 0 && ok;
    e = ok ? 0 : (e ? e : errno);
    if (fclose(f) != 0 && ok)
        ok = 0, e = errno;
    if (ok && rename(tmp, path) != 0)
        ok = 0, e = errno;
    if (!ok) {
        remove(tmp);
        return lm_fail(err, LM_ERR_IO, "%s: write failed (%s)", path, e ? strerror(e) : "short write");
    }
    return LM_OK;
}

typedef struct {
    uint8_t *data;
    size_t size, cap;
    int failed;
} byte_buffer;

static void append_bytes(void *context, void *data, int size)
{
    byte_buffer *b = context;
    if (b->failed || size <= 0)
        return;
    if (b->size + (size_t)size > b->cap) {
        size_t cap = 2 * b->cap + (size_t)size;
        uint8_t *grown = realloc(b->data, cap);
        if (!grown) {
            b->failed = 1;
            return;
        }
        b->data = grown, b->cap = cap;
    }
    memcpy(b->data + b->size, data, (size_t)size);
    b->size += (size_t)size;
}

lm_status lm_write_png(const char *path, int width, int height, const uint8_t *rgba8, lm_error *err)
{
    if (width <= 0 || height <= 0 || !rgba8)
        return lm_fail(err, LM_ERR_INVALID, "%s: cannot write an empty %dx%d image", path, width, height);
    byte_buffer b = {0};
    int ok = stbi_write_png_to_func(append_bytes, &b, width, height, 4, rgba8, width * 4) && !b.failed;
    lm_status st = ok ? lm_write_file(path, b.data, b.size, err)
                      : lm_fail(err, LM_ERR_NOMEM, "%s: no memory to encode a %dx%d PNG", path, width, height);
    free(b.data);
    return st;
}

/* EXR in memory: one float plane per channel, in the (A)BGR order viewers expect, ZIP-compressed except
 * for images under 16 x 16 (as tinyexr's SaveEXR does; written here so the file write can be checked). */
lm_status lm_write_exr(const char *path, int width, int height, int channels, const float *data, lm_error *err)
{
    return lm_write_exr_as(path, width, height, channels, data, 0, err);
}

lm_status lm_write_exr_as(const char *path, int width, int height, int channels, const float *data, int half,
                          lm_error *err)
{
    if (width <= 0 || height <= 0 || !data || (channels != 1 && channels != 3 && channels != 4))
        return lm_fail(err, LM_ERR_INVALID, "%s: cannot write a %dx%d EXR with %d channels", path, width,
                       height, channels);
    size_t n = (size_t)width * height;
    float *planes = malloc(sizeof *planes * n * (size_t)channels);
    if (!planes)
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory to encode a %dx%d EXR", path, width, height);
    static const char *names[4][4] = {{"A"}, {0}, {"B", "G", "R"}, {"A", "B", "G", "R"}};
    static const int source[4][4] = {{0}, {0}, {2, 1, 0}, {3, 2, 1, 0}}; /* data channel of each plane */
    unsigned char *plane_ptr[4];
    EXRChannelInfo info[4];
    int types[4], stored[4];
    memset(info, 0, sizeof info);
    size_t bad = 0, clamped = 0;
    for (int c = 0; c < channels; c++) {
        float *plane = planes + (size_t)c * n;
        for (size_t i = 0; i < n; i++) {
            float v = data[(size_t)channels * i + (size_t)source[channels - 1][c]];
            bad += !isfinite(v);
            if (half && fabsf(v) > LM_HALF_MAX) /* a half above it is infinity */
                v = copysignf(LM_HALF_MAX, v), clamped++;
            plane[i] = v;
        }
        plane_ptr[c] = (unsigned char *)plane;
        snprintf(info[c].name, sizeof info[c].name, "%s", names[channels - 1][c]);
        types[c] = TINYEXR_PIXELTYPE_FLOAT;
        stored[c] = half ? TINYEXR_PIXELTYPE_HALF : TINYEXR_PIXELTYPE_FLOAT;
    }
    if (bad) {
        free(planes);
        return lm_fail(err, LM_ERR_INVALID, "%s: %zu values are not finite numbers (NaN or infinity): not written",
                       path, bad);
    }
    if (clamped)
        lm_warn("%s: %zu values beyond %g, the largest half float, written as %g (32-bit floats keep them)", path,
                clamped, (double)LM_HALF_MAX, (double)LM_HALF_MAX);
    EXRHeader header;
    InitEXRHeader(&header);
    header.compression_type = width < 16 && height < 16 ? TINYEXR_COMPRESSIONTYPE_NONE : TINYEXR_COMPRESSIONTYPE_ZIP;
    header.num_channels = channels;
    header.channels = info;
    header.pixel_types = types;
    header.requested_pixel_types = stored;
    EXRImage image;
    InitEXRImage(&image);
    image.num_channels = channels;
    image.images = plane_ptr;
    image.width = width, image.height = height;
    unsigned char *bytes = NULL;
    const char *msg = NULL;
    size_t size = SaveEXRImageToMemory(&image, &header, &bytes, &msg);
    free(planes);
    lm_status st = size ? lm_write_file(path, bytes, size, err)
                        : lm_fail(err, LM_ERR_IO, "%s: cannot encode EXR (%s)", path, msg ? msg : "unknown");
    if (msg)
        FreeEXRErrorMessage(msg);
    free(bytes);
    return st;
}

lm_status lm_read_exr(const char *path, int *width, int *height, float **out, lm_error *err)
{
    const char *msg = NULL;
    *out = NULL;
    if (LoadEXR(out, width, height, path, &msg) < 0) {
        lm_status st = lm_fail(err, LM_ERR_IO, "%s: cannot read EXR (%s)", path, msg ? msg : "unknown");
        if (msg)
            FreeEXRErrorMessage(msg);
        return st;
    }
    return LM_OK;
}

lm_status lm_read_image8(const char *path, int *width, int *height, uint8_t **out, lm_error *err)
{
    int comp = 0;
    *out = stbi_load(path, width, height, &comp, 4);
    if (!*out)
        return lm_fail(err, LM_ERR_IO, "%s: cannot read image (%s)", path, stbi_failure_reason());
    return LM_OK;
}

float lm_srgb_to_linear(float c)
{
    return c <= 0.04045f ? c / 12.92f : powf((c + 0.055f) / 1.055f, 2.4f);
}

float lm_linear_to_srgb(float c)
{
    if (!(c > 0.0f))
        return 0.0f;
    if (c >= 1.0f)
        return 1.0f;
    return c <= 0.0031308f ? 12.92f * c : 1.055f * powf(c, 1.0f / 2.4f) - 0.055f;
}

void lm_encode_rgbd(const float *rgba, size_t n, float scale, uint8_t *rgbd8)
{
    for (size_t p = 0; p < n; p++) {
        float x[3], m = 0.0f;
        for (int c = 0; c < 3; c++) {
            float v = rgba[4 * p + c] / scale;
            x[c] = v > 0.0f ? fminf(v, LM_RGBD_RANGE) : 0.0f; /* NaN and negatives: 0 */
            m = fmaxf(m, x[c]);
        }
        /* d: the largest step of 1/255 that keeps x * d <= 1, so the stored colour uses the whole range */
        float d8 = m > 1.0f ? floorf(LM_RGBD_RANGE / m) : 255.0f;
        float d = fmaxf(d8, 1.0f) / 255.0f;
        for (int c = 0; c < 3; c++)
            rgbd8[4 * p + c] = (uint8_t)lroundf(255.0f * fminf(1.0f, powf(x[c] * d, 1.0f / LM_RGBD_GAMMA)));
        rgbd8[4 * p + 3] = (uint8_t)fmaxf(d8, 1.0f);
    }
}

void lm_decode_rgbd(const uint8_t rgbd8[4], float scale, float rgb[3])
{
    float d = (float)rgbd8[3] / 255.0f;
    for (int c = 0; c < 3; c++)
        rgb[c] = d > 0.0f ? scale * powf((float)rgbd8[c] / 255.0f, LM_RGBD_GAMMA) / d : 0.0f;
}

lm_status lm_check_regular_file(const char *path, const char *what, lm_error *err)
{
    struct stat s; /* by its name first (a socket cannot be opened at all), then as opened, without blocking */
    int ok = stat(path, &s) == 0, fd = -1;
    if (!ok)
        return lm_fail(err, LM_ERR_IO, "%s %s: cannot open: %s", what, path, strerror(errno));
    if (S_ISREG(s.st_mode) && (fd = open(path, O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC)) < 0)
        return lm_fail(err, LM_ERR_IO, "%s %s: cannot open: %s", what, path, strerror(errno));
    if (fd >= 0) {
        ok = fstat(fd, &s) == 0;
        close(fd);
    }
    if (ok && S_ISREG(s.st_mode))
        return LM_OK;
    const char *kind = !ok ? "unknown" : S_ISFIFO(s.st_mode) ? "a FIFO (a pipe)" : S_ISDIR(s.st_mode) ? "a directory"
                     : S_ISSOCK(s.st_mode) ? "a socket" : S_ISCHR(s.st_mode) || S_ISBLK(s.st_mode) ? "a device"
                     : "not a plain file";
    return lm_fail(err, LM_ERR_IO, "%s %s is %s, not a regular file: lmgi reads only regular files a scene names",
                   what, path, kind);
}

lm_status lm_mkdir_p(const char *path, lm_error *err)
{
    char buf[4096];
    size_t n = strlen(path);
    if (n == 0 || n >= sizeof buf)
        return lm_fail(err, LM_ERR_INVALID, "bad directory name '%s'", path);
    memcpy(buf, path, n + 1);
    for (size_t i = 1; i <= n; i++) {
        if (buf[i] != '/' && buf[i] != '\0')
            continue;
        char c = buf[i];
        buf[i] = '\0';
        if (mkdir(buf, 0777) != 0 && errno != EEXIST)
            return lm_fail(err, LM_ERR_IO, "%s: cannot create directory (%s)", buf, strerror(errno));
        buf[i] = c;
    }
    struct stat st;
    if (stat(path, &st) != 0 || !S_ISDIR(st.st_mode))
        return lm_fail(err, LM_ERR_IO, "%s: exists and is not a directory", path);
    return LM_OK;
}
