/* Direct light per pixel (direct.h): an emission pass that also lays down depth, then per punctual light
 * its shadow map and an additive pass (depth test LEQUAL, no depth writes) into an RGBA32F target. */
#include "direct.h"

#include "gl_api.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../core/vecmath.h"
#include "direct_shader.h"
#include "direct_mesh.h"
#include "gl_shader.h"
#include "offscreen.h"
#include "shadow_maps.h"

void lm_direct_settings_default(lm_direct_settings *s)
{
    s->map_size = 1024;
    s->cube_size = 512;
    s->pcf_radius = 1;
    s->normal_offset = 1.0f;
    s->slope_bias = 1.0f;
    s->max_slope = 10.0f;
    s->const_bias = 0.5f;
}


static void set_light_uniforms(GLuint prog, const lm_scene *s, const lm_emitter *e, const lm_shadow_map *m)
{
    int kind = e->kind == LM_EMIT_POINT ? 0 : e->kind == LM_EMIT_SPOT ? 1 : 2;
    float cos_outer = -2.0f, width = 1.0f;
    if (kind == 1) { /* the same falloff as lm_spot_attenuation */
        const lm_light *l = &s->lights[e->light];
        cos_outer = cosf(l->outer_cone);
        width = fmaxf(1e-3f, cosf(l->inner_cone) - cos_outer);
    }
    glUniform1i(glGetUniformLocation(prog, "pass_kind"), 1);
    glUniform1i(glGetUniformLocation(prog, "kind"), kind);
    glUniform3fv(glGetUniformLocation(prog, "lpos"), 1, e->pos);
    glUniform3fv(glGetUniformLocation(prog, "ldir"), 1, m->dir);
    glUniform3fv(glGetUniformLocation(prog, "radiant"), 1, e->radiant);
    glUniform3fv(glGetUniformLocation(prog, "origin"), 1, m->origin);
    glUniform1f(glGetUniformLocation(prog, "cos_outer"), cos_outer);
    glUniform1f(glGetUniformLocation(prog, "spot_width"), width);
    glUniform1f(glGetUniformLocation(prog, "texel"), m->texel);
    glUniform1f(glGetUniformLocation(prog, "map_size"), (float)m->size);
    glUniformMatrix4fv(glGetUniformLocation(prog, "light_vp"), 1, GL_FALSE, m->light_vp);
    glActiveTexture(m->cube ? GL_TEXTURE1 : GL_TEXTURE0);
    glBindTexture(m->cube ? GL_TEXTURE_CUBE_MAP : GL_TEXTURE_2D, m->tex);
}

static void set_view_uniforms(GLuint prog, const lm_view *view, const lm_direct_settings *set)
{
    float vp[16];
    lm_mat4_mul(vp, view->proj, view->view);
    glUniformMatrix4fv(glGetUniformLocation(prog, "view_proj"), 1, GL_FALSE, vp);
    /* orthographic views (no perspective divide) look along one direction: towards the eye is the
     * view matrix's third row */
    const float towards_eye[3] = {view->view[2], view->view[6], view->view[10]};
    glUniform3fv(glGetUniformLocation(prog, "eye"), 1, view->eye);
    glUniform3fv(glGetUniformLocation(prog, "view_dir"), 1, towards_eye);
    glUniform1i(glGetUniformLocation(prog, "ortho_view"), view->proj[11] == 0.0f && view->proj[15] != 0.0f);
    glUniform1i(glGetUniformLocation(prog, "pcf"), set->pcf_radius);
    glUniform1f(glGetUniformLocation(prog, "normal_offset"), set->normal_offset);
    glUniform1f(glGetUniformLocation(prog, "slope_bias"), set->slope_bias);
    glUniform1f(glGetUniformLocation(prog, "max_slope"), set->max_slope);
    glUniform1f(glGetUniformLocation(prog, "const_bias"), set->const_bias);
    glUniform1i(glGetUniformLocation(prog, "map2d"), 0);
    glUniform1i(glGetUniformLocation(prog, "mapcube"), 1);
    glUniform1i(glGetUniformLocation(prog, "base_tex"), 2);
}

/* Emission pass: clears, writes depth and the emitted radiance. */
static void emission_pass(GLuint prog, const lm_direct_mesh *mesh, int w, int h)
{
    glViewport(0, 0, w, h);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glDisable(GL_CULL_FACE);
    glDisable(GL_BLEND);
    glClearColor(0.0f, 0.0f, 0.0f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glUseProgram(prog);
    glUniform1i(glGetUniformLocation(prog, "pass_kind"), 0);
    lm_direct_mesh_draw(mesh, prog);
}

/* One light: its shadow map, then an additive pass over the laid-down depth. */
static lm_status light_pass(GLuint prog, const lm_scene *s, const lm_emitter *e, const lm_direct_mesh *mesh,
                            const lm_offscreen *t, int w, int h,
                            const lm_direct_settings *set, lm_error *err)
{
    lm_shadow_map m;
    int size = e->kind == LM_EMIT_POINT ? set->cube_size : set->map_size;
    lm_status st = lm_shadow_map_render(&m, s, e, &mesh->casters, size, err);
    if (st != LM_OK)
        return st;
    glBindFramebuffer(GL_FRAMEBUFFER, t->fbo);
    glViewport(0, 0, w, h);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LEQUAL);
    glDepthMask(GL_FALSE);
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE);
    glUseProgram(prog);
    set_light_uniforms(prog, s, e, &m);
    lm_direct_mesh_draw(mesh, prog);
    glDisable(GL_BLEND);
    glDepthMask(GL_TRUE);
    st = lm_gl_check("direct_light: light pass", err);
    lm_shadow_map_free(&m);
    return st;
}

static lm_status draw_all(GLuint prog, const lm_scene *s, const lm_emitters *em, const lm_view *view,
                          const lm_direct_mesh *mesh, int w, int h,
                          const lm_direct_settings *set, float *rgb, lm_error *err)
{
    lm_offscreen t;
    lm_status st = lm_offscreen_begin_float(&t, w, h, err);
    if (st == LM_OK) {
        glUseProgram(prog);
        set_view_uniforms(prog, view, set);
        emission_pass(prog, mesh, w, h);
    }
    for (int i = 0; st == LM_OK && i < em->count; i++)
        if (em->e[i].kind != LM_EMIT_AREA)
            st = light_pass(prog, s, &em->e[i], mesh, &t, w, h, set, err);
    if (st == LM_OK) {
        lm_offscreen_read_rgb(&t, rgb);
        st = lm_gl_check("direct_light: reading back", err);
    }
    if (t.fbo)
        lm_offscreen_release(&t);
    return st;
}

lm_status lm_render_direct(const lm_scene *s, const lm_emitters *em, const lm_view *view, int width,
                           int height, const lm_direct_settings *settings, float *rgb, lm_error *err)
{
    lm_direct_settings set;
    if (settings)
        set = *settings;
    else
        lm_direct_settings_default(&set);
    if (width <= 0 || height <= 0 || set.map_size <= 0 || set.cube_size <= 0 || set.pcf_radius < 0)
        return lm_fail(err, LM_ERR_INVALID, "direct_light: bad size %dx%d or settings", width, height);
    GLuint prog = 0;
    lm_status st = lm_gl_program("direct_light", lm_direct_vs, lm_direct_fs, &prog, err);
    if (st != LM_OK)
        return st;
    lm_direct_mesh mesh;
    st = lm_direct_mesh_build(&mesh, s, err);
    if (st == LM_OK)
        st = draw_all(prog, s, em, view, &mesh, width, height, &set, rgb, err);
    lm_direct_mesh_free(&mesh);
    glDeleteProgram(prog);
    return st;
}
