/* The indirect term of a frame's composite (composite.h): a premultiplied IIM / pi atlas, rendered by one
 * atlas-sized pass (glsl/premultiply_*.glsl); the direct light's first pass samples it and multiplies by
 * kd. Target and program persist. */
#include "composite.h"

#include "../../core/vecmath.h"
#include "../gl/gl_api.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../gl/gl_shader.h"
#include "glsl.h"
#include "../gl/offscreen.h"

struct lm_composite {
    int width, height;   /* atlas */
    GLuint covered_tex, premult_prog, empty_vao;
    float limit;
    GLuint fill_prog;
    GLint p_limit, p_covered, p_iim, f_src, f_covered;
    lm_float_target lit[2]; /* atlas-sized, linear filter: (E / pi * w, w), w = covered and valid; the
                             * premultiply draws into 0, the hole fill's steps go 0 -> 1 -> 0 */
};

/* Red: 1 at every texel of the texel table (covered by some triangle) whose node takes indirect light, 0
 * in gutters, unused corners and on nodes with indirect light switched off. Green: the texel's surface
 * + 1 (exact in a float up to 2^24 surfaces), which the hole fill stays within. */
static void fill_covered(const lm_scene *s, const lm_atlas *a, float *out)
{
    for (uint32_t i = 0; i < a->texel_count; i++) {
        float *o = out + 4 * ((size_t)a->texels[i].y * a->width + a->texels[i].x);
        o[0] = s->nodes[s->tri_node[a->texels[i].tri]].settings.indirect ? 1.0f : 0.0f;
        o[1] = (float)a->texels[i].surface + 1.0f;
    }
}

lm_status lm_composite_update_coverage(lm_composite *c, const lm_scene *s, const lm_atlas *a, lm_error *err)
{
    float *covered = calloc(4 * (size_t)a->width * a->height, sizeof(float));
    if (!covered)
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for the lightmap coverage", s->path);
    fill_covered(s, a, covered);
    glBindTexture(GL_TEXTURE_2D, c->covered_tex);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, a->width, a->height, GL_RGBA, GL_FLOAT, covered);
    free(covered);
    return LM_OK;
}

lm_status lm_composite_create(const lm_scene *s, const lm_atlas *a, float backface_limit, lm_composite **out,
                              lm_error *err)
{
    *out = NULL;
    lm_composite *c = calloc(1, sizeof *c);
    if (!c)
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for the composite", s->path);
    c->width = a->width;
    c->height = a->height;
    c->limit = backface_limit;
    c->covered_tex = lm_float_texture(a->width, a->height, NULL); /* texels: lm_composite_update_coverage */
    lm_status st = lm_composite_update_coverage(c, s, a, err);
    if (st == LM_OK)
        st = lm_gl_program("composite_premultiply", lm_glsl_premultiply_vs, lm_glsl_premultiply_fs, &c->premult_prog, err);
    if (st == LM_OK) /* the same full-screen triangle */
        st = lm_gl_program("composite_fill_holes", lm_glsl_premultiply_vs, lm_glsl_fill_holes_fs, &c->fill_prog, err);
    if (st != LM_OK) {
        lm_composite_free(c);
        return st;
    }
    glGenVertexArrays(1, &c->empty_vao);
    c->p_limit = glGetUniformLocation(c->premult_prog, "limit");
    c->p_covered = glGetUniformLocation(c->premult_prog, "covered");
    c->p_iim = glGetUniformLocation(c->premult_prog, "iim");
    c->f_src = glGetUniformLocation(c->fill_prog, "src");
    c->f_covered = glGetUniformLocation(c->fill_prog, "covered");
    *out = c;
    return LM_OK;
}


void lm_composite_free(lm_composite *c)
{
    if (!c)
        return;
    if (c->covered_tex)
        glDeleteTextures(1, &c->covered_tex);
    if (c->premult_prog)
        glDeleteProgram(c->premult_prog);
    if (c->fill_prog)
        glDeleteProgram(c->fill_prog);
    if (c->empty_vao)
        glDeleteVertexArrays(1, &c->empty_vao);
    lm_float_target_free(&c->lit[0]);
    lm_float_target_free(&c->lit[1]);
    free(c);
}

/* The premultiplied atlas (c->lit[0], bound) from the display IIM. */
static void premultiply(const lm_composite *c, unsigned iim_tex)
{
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    glUseProgram(c->premult_prog);
    glUniform1f(c->p_limit, c->limit);
    glUniform1i(c->p_covered, 0);
    glUniform1i(c->p_iim, 1);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, c->covered_tex);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, iim_tex);
    glBindVertexArray(c->empty_vao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
}

/* One step of the hole fill (glsl/fill_holes_fs.glsl) from lit[from] into lit[1 - from]. */
static lm_status fill_step(lm_composite *c, int from, lm_error *err)
{
    lm_status st = lm_float_target_ensure(&c->lit[1 - from], c->width, c->height, 1, err);
    if (st != LM_OK)
        return st;
    glUseProgram(c->fill_prog);
    glUniform1i(c->f_src, 1);
    glUniform1i(c->f_covered, 0);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, c->covered_tex);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, c->lit[from].color[0]); /* read by texelFetch: no filter */
    glBindVertexArray(c->empty_vao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    return LM_OK;
}

lm_status lm_composite_indirect(lm_composite *c, unsigned iim_tex, unsigned *lit_tex, lm_error *err)
{
    lm_status st = lm_float_target_ensure(&c->lit[0], c->width, c->height, 1, err);
    if (st != LM_OK)
        return st;
    premultiply(c, iim_tex);
    for (int k = 0; k < LM_COMPOSITE_FILL_STEPS && st == LM_OK; k++)
        st = fill_step(c, k & 1, err);
    if (st != LM_OK)
        return st;
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, c->lit[0].color[0]); /* an even count of steps ends in 0 */
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR); /* sampled with the bilinear filter */
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glActiveTexture(GL_TEXTURE0);
    *lit_tex = c->lit[0].color[0];
    return lm_gl_check("composite: indirect", err);
}
