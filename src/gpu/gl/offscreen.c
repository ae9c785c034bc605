#include "offscreen.h"

#include "gl_api.h"
#include <stdlib.h>
#include <string.h>

#include "gl_shader.h"

unsigned lm_float_texture(int w, int h, const float *rgba)
{
    GLuint tex;
    glGenTextures(1, &tex);
    glBindTexture(GL_TEXTURE_2D, tex);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, w, h, 0, GL_RGBA, GL_FLOAT, rgba);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    return tex;
}

void lm_texture_linear_clamped(void)
{
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
}

void lm_offscreen_release(lm_offscreen *o)
{
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glDeleteRenderbuffers(1, &o->color);
    glDeleteRenderbuffers(1, &o->depth);
    glDeleteFramebuffers(1, &o->fbo);
    memset(o, 0, sizeof *o);
}

static lm_status begin(lm_offscreen *o, int width, int height, GLenum color_format, lm_error *err)
{
    memset(o, 0, sizeof *o);
    o->width = width;
    o->height = height;
    glGenFramebuffers(1, &o->fbo);
    glGenRenderbuffers(1, &o->color);
    glGenRenderbuffers(1, &o->depth);
    glBindRenderbuffer(GL_RENDERBUFFER, o->color);
    glRenderbufferStorage(GL_RENDERBUFFER, color_format, width, height);
    glBindRenderbuffer(GL_RENDERBUFFER, o->depth);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, width, height);
    glBindFramebuffer(GL_FRAMEBUFFER, o->fbo);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, o->color);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, o->depth);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
        lm_offscreen_release(o);
        return lm_fail(err, LM_ERR_BACKEND, "offscreen target %dx%d is incomplete", width, height);
    }
    glViewport(0, 0, width, height);
    glEnable(GL_DEPTH_TEST);
    glDisable(GL_CULL_FACE); /* lightmapped geometry is seen from both sides */
    glClearColor(0.0f, 0.0f, 0.0f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    return LM_OK;
}

lm_status lm_offscreen_begin(lm_offscreen *o, int width, int height, lm_error *err)
{
    return begin(o, width, height, GL_RGBA8, err);
}

lm_status lm_offscreen_begin_float(lm_offscreen *o, int width, int height, lm_error *err)
{
    return begin(o, width, height, GL_RGBA32F, err);
}

void lm_offscreen_read_rgb(const lm_offscreen *o, float *rgb)
{
    glBindFramebuffer(GL_FRAMEBUFFER, o->fbo);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    for (int y = 0; y < o->height; y++) /* GL's rows start at the bottom */
        glReadPixels(0, o->height - 1 - y, o->width, 1, GL_RGB, GL_FLOAT, rgb + 3 * (size_t)o->width * y);
}

lm_status lm_offscreen_end(lm_offscreen *o, uint8_t *rgba8, lm_error *err)
{
    int w = o->width, h = o->height;
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, rgba8);
    lm_status st = lm_gl_check("reading back the picture", err);
    lm_offscreen_release(o);
    /* GL's rows start at the bottom; images start at the top. */
    uint8_t *tmp = malloc((size_t)w * 4);
    if (!tmp)
        return lm_fail(err, LM_ERR_NOMEM, "no memory to flip a %dx%d picture", w, h);
    for (int y = 0; y < h / 2; y++) {
        uint8_t *a = rgba8 + (size_t)y * w * 4, *b = rgba8 + (size_t)(h - 1 - y) * w * 4;
        memcpy(tmp, a, (size_t)w * 4);
        memcpy(a, b, (size_t)w * 4);
        memcpy(b, tmp, (size_t)w * 4);
    }
    free(tmp);
    return st;
}

void lm_float_target_free(lm_float_target *t)
{
    if (t->fbo) {
        glDeleteFramebuffers(1, &t->fbo);
        glDeleteTextures(1, &t->depth);
        glDeleteTextures(t->attachments, t->color);
    }
    memset(t, 0, sizeof *t);
}

lm_status lm_float_target_ensure(lm_float_target *t, int width, int height, int attachments, lm_error *err)
{
    static const GLenum bufs[3] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2};
    if (t->fbo && t->width == width && t->height == height && t->attachments == attachments) {
        glBindFramebuffer(GL_FRAMEBUFFER, t->fbo);
        glViewport(0, 0, width, height);
        return LM_OK;
    }
    lm_float_target_free(t);
    t->width = width;
    t->height = height;
    t->attachments = attachments;
    glGenFramebuffers(1, &t->fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, t->fbo);
    for (int i = 0; i < attachments; i++) {
        t->color[i] = lm_float_texture(width, height, NULL);
        glFramebufferTexture2D(GL_FRAMEBUFFER, bufs[i], GL_TEXTURE_2D, t->color[i], 0);
    }
    /* depth as a texture: the caustic pass reads the frame's depth (gpu/frame/caustic_pass.h) */
    glGenTextures(1, &t->depth);
    glBindTexture(GL_TEXTURE_2D, t->depth);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT24, width, height, 0, GL_DEPTH_COMPONENT, GL_UNSIGNED_INT, NULL);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, t->depth, 0);
    glDrawBuffers(attachments, bufs);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        lm_float_target_free(t);
        return lm_fail(err, LM_ERR_BACKEND, "float target %dx%d (%d attachments) is incomplete", width, height,
                       attachments);
    }
    glViewport(0, 0, width, height);
    return LM_OK;
}

void lm_rgba_to_rgb_top_down(const float *rgba, int w, int h, float *rgb)
{
    for (int y = 0; y < h; y++) { /* GL's rows start at the bottom */
        const float *src = rgba + 4 * (size_t)w * (size_t)(h - 1 - y);
        float *dst = rgb + 3 * (size_t)w * (size_t)y;
        for (int x = 0; x < w; x++) {
            dst[3 * x] = src[4 * x];
            dst[3 * x + 1] = src[4 * x + 1];
            dst[3 * x + 2] = src[4 * x + 2];
        }
    }
}

void lm_float_target_read_rgb(const lm_float_target *t, int i, float *rgb, float *scratch)
{
    int w = t->width, h = t->height;
    glBindFramebuffer(GL_READ_FRAMEBUFFER, t->fbo);
    glReadBuffer(GL_COLOR_ATTACHMENT0 + (GLenum)i);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    /* one RGBA read (the target's own layout: a plain copy in the driver), then flip and drop alpha */
    glReadPixels(0, 0, w, h, GL_RGBA, GL_FLOAT, scratch);
    lm_rgba_to_rgb_top_down(scratch, w, h, rgb);
    glReadBuffer(GL_COLOR_ATTACHMENT0);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, t->fbo);
}
