/* The frame's render targets (frame_targets.h). */
#include "frame_targets.h"

#include "../gl/gl_api.h"
#include <stdlib.h>

#include "../gl/gl_shader.h"

void lm_frame_targets_free(lm_frame_targets *f)
{
    for (int k = 0; k < LM_FRAME_PICTURES; k++)
        lm_float_target_free(&f->t[k]);
    free(f->scratch);
    f->scratch = NULL;
    f->scratch_px = 0;
}

lm_status lm_frame_targets_ensure(lm_frame_targets *f, int which, int width, int height, lm_error *err)
{
    /* radiance, kd and the view's G-buffer (only the view's is read: a 1080p mirror picture would hold
     * 33 MB of it for nothing) */
    return lm_float_target_ensure(&f->t[which], width, height, which == LM_FRAME_VIEW ? 3 : 2, err);
}

unsigned lm_frame_targets_fbo(const lm_frame_targets *f, int which) { return f->t[which].fbo; }

void lm_frame_targets_bind_radiance(const lm_frame_targets *f, int which)
{
    static const GLenum radiance = GL_COLOR_ATTACHMENT0;
    const lm_float_target *t = &f->t[which];
    glBindFramebuffer(GL_FRAMEBUFFER, t->fbo);
    glDrawBuffers(1, &radiance);
    glViewport(0, 0, t->width, t->height);
}

unsigned lm_frame_targets_radiance(const lm_frame_targets *f, int which) { return f->t[which].color[0]; }
unsigned lm_frame_targets_kd(const lm_frame_targets *f, int which) { return f->t[which].color[1]; }
unsigned lm_frame_targets_depth(const lm_frame_targets *f, int which) { return f->t[which].depth; }
unsigned lm_frame_targets_gbuffer(const lm_frame_targets *f) { return f->t[LM_FRAME_VIEW].color[2]; }

lm_status lm_frame_targets_read_kd(const lm_frame_targets *f, float *rgb, lm_error *err)
{
    const lm_float_target *t = &f->t[LM_FRAME_VIEW];
    float *rgba = malloc(((size_t)t->width * (size_t)t->height + 1) * 4 * sizeof *rgba);
    if (!rgba)
        return lm_fail(err, LM_ERR_NOMEM, "direct_light: no memory to read back kd of %dx%d", t->width, t->height);
    lm_float_target_read_rgb(t, 1, rgb, rgba);
    free(rgba);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    return lm_gl_check("direct_light: reading back kd", err);
}

lm_status lm_frame_targets_read(lm_frame_targets *f, float *rgb, lm_error *err)
{
    const lm_float_target *t = &f->t[LM_FRAME_VIEW];
    size_t px = (size_t)t->width * (size_t)t->height;
    if (px > f->scratch_px) {
        free(f->scratch);
        f->scratch = malloc(4 * px * sizeof(float));
        f->scratch_px = f->scratch ? px : 0;
        if (!f->scratch)
            return lm_fail(err, LM_ERR_NOMEM, "direct_light: no memory to read back %dx%d", t->width, t->height);
    }
    lm_float_target_read_rgb(t, 0, rgb, f->scratch);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    return lm_gl_check("direct_light: reading back", err);
}
