/* The indirect term of a frame's composite (composite.h): a premultiplied IIM / pi atlas, rendered by one
 * atlas-sized pass (glsl/premultiply_*.glsl), and its holes filled by a second pass that the depth test
 * confines to them (glsl/fill_holes_fs.glsl); the direct light's first pass samples it and multiplies by
 * kd. Target and programs persist. */
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
    GLint p_limit, p_covered, p_iim, p_thin, p_use_thin, f_limit, f_covered, f_iim, f_reach;
    GLuint thin_tex;     /* atlas-sized RGBA32F: the caustics' thin light (lm_composite_set_caustics), 0: none */
    lm_float_target lit; /* atlas-sized, linear filter: (E / pi * w, w), w = 1 covered and valid, 1/1024
                          * filled (glsl/fill_holes_fs.glsl), else 0; its depth marks the holes */
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
    c->p_thin = glGetUniformLocation(c->premult_prog, "thin");
    c->p_use_thin = glGetUniformLocation(c->premult_prog, "use_thin");
    c->f_limit = glGetUniformLocation(c->fill_prog, "limit");
    c->f_covered = glGetUniformLocation(c->fill_prog, "covered");
    c->f_iim = glGetUniformLocation(c->fill_prog, "iim");
    c->f_reach = glGetUniformLocation(c->fill_prog, "reach");
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
    if (c->thin_tex)
        glDeleteTextures(1, &c->thin_tex);
    lm_float_target_free(&c->lit);
    free(c);
}

/* Draws the full-screen triangle with program prog, the coverage on unit 0 and the IIM on unit 1. */
static void atlas_pass(const lm_composite *c, GLuint prog, GLint limit, GLint covered, GLint iim, unsigned iim_tex)
{
    glUseProgram(prog);
    glUniform1f(limit, c->limit);
    glUniform1i(covered, 0);
    glUniform1i(iim, 1);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, c->covered_tex);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, iim_tex);
    glBindVertexArray(c->empty_vao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
}

/* The premultiplied atlas (c->lit, bound) from the display IIM, its holes at depth 0 and every other
 * texel at 1; then the fill over the holes alone: its triangle lies at depth 0.5 and passes GL_GREATER
 * only there, so a frame pays for the search where there are holes, not over the atlas (on a software
 * rasteriser a shader's untaken branch is not free). */
static void premultiply_and_fill(const lm_composite *c, unsigned iim_tex)
{
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    glEnable(GL_DEPTH_TEST);
    glDepthMask(GL_TRUE);
    glDepthFunc(GL_ALWAYS);
    glUseProgram(c->premult_prog);
    glUniform1i(c->p_use_thin, c->thin_tex != 0);
    glUniform1i(c->p_thin, 2);
    glActiveTexture(GL_TEXTURE2);
    glBindTexture(GL_TEXTURE_2D, c->thin_tex);
    atlas_pass(c, c->premult_prog, c->p_limit, c->p_covered, c->p_iim, iim_tex);
    glDepthMask(GL_FALSE);
    glDepthFunc(GL_GREATER);
    glUseProgram(c->fill_prog);
    glUniform1i(c->f_reach, LM_COMPOSITE_FILL_REACH);
    atlas_pass(c, c->fill_prog, c->f_limit, c->f_covered, c->f_iim, iim_tex);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glDisable(GL_DEPTH_TEST);
}

lm_status lm_composite_indirect(lm_composite *c, unsigned iim_tex, unsigned *lit_tex, lm_error *err)
{
    lm_status st = lm_float_target_ensure(&c->lit, c->width, c->height, 1, err);
    if (st != LM_OK)
        return st;
    premultiply_and_fill(c, iim_tex);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, c->lit.color[0]);
    lm_texture_linear_clamped(); /* sampled with the bilinear filter */
    glActiveTexture(GL_TEXTURE0);
    *lit_tex = c->lit.color[0];
    return lm_gl_check("composite: indirect", err);
}

lm_status lm_composite_set_caustics(lm_composite *c, const float *thin, lm_error *err)
{
    if (!thin) {
        if (c->thin_tex)
            glDeleteTextures(1, &c->thin_tex);
        c->thin_tex = 0;
        return LM_OK;
    }
    if (!c->thin_tex) { /* the premultiply pass reads it texel by texel, a view of it bilinearly */
        c->thin_tex = lm_float_texture(c->width, c->height, thin);
        lm_texture_linear_clamped();
    } else {
        glBindTexture(GL_TEXTURE_2D, c->thin_tex);
        glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
        glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, c->width, c->height, GL_RGBA, GL_FLOAT, thin);
    }
    return lm_gl_check("composite: the caustics' thin light", err);
}

unsigned lm_composite_caustics_texture(const lm_composite *c) { return c->thin_tex; }
