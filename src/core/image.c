#include "image.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <stb/stb_image.h>
#include <stb/stb_image_write.h>
#include <tinyexr.h>

lm_status lm_write_png(const char *path, int width, int height, const uint8_t *rgba8, lm_error *err)
{
    if (width <= 0 || height <= 0 || !rgba8)
        return lm_fail(err, LM_ERR_INVALID, "%s: cannot write an empty %dx%d image", path, width, height);
    if (!stbi_write_png(path, width, height, 4, rgba8, width * 4))
        return lm_fail(err, LM_ERR_IO, "%s: cannot write PNG (%s)", path, strerror(errno));
    return LM_OK;
}

lm_status lm_write_exr(const char *path, int width, int height, int channels, const float *data, lm_error *err)
{
    if (width <= 0 || height <= 0 || !data || (channels != 1 && channels != 3 && channels != 4))
        return lm_fail(err, LM_ERR_INVALID, "%s: cannot write a %dx%d EXR with %d channels", path, width,
                       height, channels);
    /* tinyexr leaks when it cannot open the file, so find that out first. */
    FILE *probe = fopen(path, "wb");
    if (!probe)
        return lm_fail(err, LM_ERR_IO, "%s: cannot write EXR (%s)", path, strerror(errno));
    fclose(probe);
    const char *msg = NULL;
    if (SaveEXR(data, width, height, channels, 0, path, &msg) < 0) {
        lm_status st = lm_fail(err, LM_ERR_IO, "%s: cannot write EXR (%s)", path, msg ? msg : "unknown");
        if (msg)
            FreeEXRErrorMessage(msg);
        return st;
    }
    return LM_OK;
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
