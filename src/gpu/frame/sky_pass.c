/* The sky drawn behind everything (sky_pass.h; glsl/sky_*.glsl). */
#include "sky_pass.h"

#include "../gl/gl_api.h"

#include "../../core/vecmath.h"
#include "../../scene/sky.h"
#include "../gl/gl_shader.h"
#include "glsl.h"

lm_status lm_sky_pass_init(lm_sky_pass *p, lm_error *err)
{
    *p = (lm_sky_pass){0};
    lm_status st = lm_gl_program("sky", lm_glsl_sky_vs, lm_glsl_sky_fs, &p->prog, err);
    if (st == LM_OK)
        glGenVertexArrays(1, &p->vao);
    return st;
}

void lm_sky_pass_free(lm_sky_pass *p)
{
    if (p->prog)
        glDeleteProgram(p->prog);
    if (p->vao)
        glDeleteVertexArrays(1, &p->vao);
    if (p->image_tex)
        glDeleteTextures(1, &p->image_tex);
    *p = (lm_sky_pass){0};
}

static void upload(lm_sky_pass *p, const lm_scene *s)
{
    if (p->uploaded == s->sky_image && p->width == s->sky_width && p->height == s->sky_height)
        return;
    if (!p->image_tex)
        glGenTextures(1, &p->image_tex);
    glBindTexture(GL_TEXTURE_2D, p->image_tex);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB32F, s->sky_width, s->sky_height, 0, GL_RGB, GL_FLOAT, s->sky_image);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    p->uploaded = s->sky_image, p->width = s->sky_width, p->height = s->sky_height;
}

void lm_sky_pass_draw(lm_sky_pass *p, const lm_scene *s, const float view[16], const float proj[16])
{
    if (!p->prog || lm_sky_is_uniform(s) || (s->sky_kind == LM_SKY_IMAGE && !s->sky_image))
        return;
    float inv[16]; /* a view ray: through the pixel in view space (z = -1 at distance 1), turned to the world */
    if (!lm_mat4_invert_affine(inv, view))
        return;
    int ortho = proj[11] == 0.0f;
    glUseProgram(p->prog);
    glUniformMatrix4fv(glGetUniformLocation(p->prog, "inv_view"), 1, GL_FALSE, inv);
    glUniform4f(glGetUniformLocation(p->prog, "lens"), ortho ? 0.0f : proj[0], proj[5], proj[8], proj[9]);
    glUniform1i(glGetUniformLocation(p->prog, "kind"), s->sky_kind == LM_SKY_GRADIENT ? 1 : 2);
    glUniform3fv(glGetUniformLocation(p->prog, "zenith"), 1, s->sky);
    glUniform3fv(glGetUniformLocation(p->prog, "horizon"), 1, s->sky_horizon);
    if (s->sky_kind == LM_SKY_IMAGE) {
        upload(p, s);
        glActiveTexture(GL_TEXTURE0);
        glBindTexture(GL_TEXTURE_2D, p->image_tex);
        glUniform1i(glGetUniformLocation(p->prog, "image"), 0);
    }
    glDisable(GL_DEPTH_TEST);
    glDepthMask(GL_FALSE);
    glColorMaski(1, GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    glColorMaski(2, GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    glBindVertexArray(p->vao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindVertexArray(0);
    glColorMaski(1, GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glColorMaski(2, GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glDepthMask(GL_TRUE);
    glEnable(GL_DEPTH_TEST);
}
