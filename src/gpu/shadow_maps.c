#include "shadow_maps.h"

#include "gl_api.h"
#include <math.h>
#include <string.h>

#include "../core/vecmath.h"
#include "gl_shader.h"

#define NO_CASTER 1e30f /* metric where nothing occludes */

static const char *VS =
    "#version 450 core\n"
    "layout(location = 0) in vec3 pos;\n"
    "uniform mat4 vp;\n"
    "out vec3 v_pos;\n"
    "void main() { v_pos = pos; gl_Position = vp * vec4(pos, 1.0); }\n";
/* ortho: depth along dir from origin; else distance to origin. The depth test keeps the smallest
 * metric exactly (it is the depth), whatever the projection's depth precision. */
static const char *FS =
    "#version 450 core\n"
    "in vec3 v_pos;\n"
    "uniform vec3 origin, dir;\n"
    "uniform int ortho;\n"
    "uniform float range;\n"
    "out vec4 frag;\n"
    "void main() {\n"
    "    vec3 d = v_pos - origin;\n"
    "    float m = ortho != 0 ? dot(d, dir) : length(d);\n"
    "    gl_FragDepth = clamp(m / range, 0.0, 1.0);\n"
    "    frag = vec4(m, 0.0, 0.0, 1.0);\n"
    "}\n";

static void ortho_proj(float m[16], float half, float zfar)
{
    lm_mat4_identity(m);
    m[0] = m[5] = 1.0f / half;
    m[10] = -2.0f / zfar; /* znear = 0 */
    m[14] = -1.0f;
}

/* Any unit vector not parallel to d, for look_at. */
static lm_vec3 up_for(lm_vec3 d) { return fabsf(d.y) < 0.9f ? lm_v3(0, 1, 0) : lm_v3(1, 0, 0); }

/* Distance from p to the farthest corner of the scene bounds (at least `floor_`). */
static float far_corner(const lm_scene *s, lm_vec3 p, float floor_)
{
    float best = floor_;
    for (int k = 0; k < 8; k++) {
        lm_vec3 c = lm_v3(k & 1 ? s->bounds_max[0] : s->bounds_min[0], k & 2 ? s->bounds_max[1] : s->bounds_min[1],
                          k & 4 ? s->bounds_max[2] : s->bounds_min[2]);
        best = fmaxf(best, lm_length(lm_sub(c, p)));
    }
    return best;
}

static GLuint make_texture(GLenum target, int size)
{
    GLuint tex;
    glGenTextures(1, &tex);
    glBindTexture(target, tex);
    if (target == GL_TEXTURE_CUBE_MAP)
        for (int f = 0; f < 6; f++)
            glTexImage2D(GL_TEXTURE_CUBE_MAP_POSITIVE_X + f, 0, GL_R32F, size, size, 0, GL_RED, GL_FLOAT, NULL);
    else
        glTexImage2D(target, 0, GL_R32F, size, size, 0, GL_RED, GL_FLOAT, NULL);
    glTexParameteri(target, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(target, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTexParameteri(target, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(target, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glTexParameteri(target, GL_TEXTURE_WRAP_R, GL_CLAMP_TO_EDGE);
    return tex;
}

/* Draws the casters into one face (GL target `face` of m->tex) with view-projection vp. */
static void draw_face(const lm_shadow_map *m, GLuint prog, GLenum face, const float vp[16],
                      const lm_gl_mesh *casters)
{
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, face, m->tex, 0);
    const float clear[4] = {NO_CASTER, 0, 0, 1};
    glClearBufferfv(GL_COLOR, 0, clear);
    glClear(GL_DEPTH_BUFFER_BIT);
    glUniformMatrix4fv(glGetUniformLocation(prog, "vp"), 1, GL_FALSE, vp);
    lm_gl_mesh_draw(casters);
}

static void cube_faces(lm_shadow_map *m, GLuint prog, lm_vec3 p, float znear, float zfar,
                       const lm_gl_mesh *casters)
{
    /* GL's cube map face order and orientation (+X, -X, +Y, -Y, +Z, -Z). */
    static const float dirs[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    static const float ups[6][3] = {{0, -1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}, {0, -1, 0}, {0, -1, 0}};
    float proj[16], view[16], vp[16];
    lm_mat4_perspective(proj, (float)(M_PI / 2), 1.0f, znear, zfar);
    for (int f = 0; f < 6; f++) {
        lm_mat4_look_at(view, p, lm_add(p, lm_v3_load(dirs[f])), lm_v3_load(ups[f]));
        lm_mat4_mul(vp, proj, view);
        draw_face(m, prog, GL_TEXTURE_CUBE_MAP_POSITIVE_X + (GLenum)f, vp, casters);
    }
    m->texel = 2.0f / (float)m->size;
}

static void spot_map(lm_shadow_map *m, const lm_light *l, lm_vec3 p, lm_vec3 d, float znear, float zfar)
{
    float half = fminf(l->outer_cone, 1.48f) * 1.02f, view[16], proj[16];
    lm_mat4_look_at(view, p, lm_add(p, d), up_for(d));
    lm_mat4_perspective(proj, 2.0f * half, 1.0f, znear, zfar);
    lm_mat4_mul(m->light_vp, proj, view);
    m->texel = 2.0f * tanf(half) / (float)m->size;
}

static void directional_map(lm_shadow_map *m, const lm_scene *s, lm_vec3 d)
{
    lm_vec3 lo = lm_v3_load(s->bounds_min), hi = lm_v3_load(s->bounds_max);
    lm_vec3 c = lm_scale(lm_add(lo, hi), 0.5f);
    float r = fmaxf(0.5f * lm_length(lm_sub(hi, lo)), 1e-4f), view[16], proj[16];
    lm_vec3 eye = lm_sub(c, lm_scale(d, 1.01f * r));
    lm_mat4_look_at(view, eye, c, up_for(d));
    ortho_proj(proj, r, 2.02f * r);
    lm_mat4_mul(m->light_vp, proj, view);
    lm_v3_store(m->origin, eye);
    m->texel = 2.0f * r / (float)m->size;
}

lm_status lm_shadow_map_render(lm_shadow_map *m, const lm_scene *s, const lm_emitter *e,
                               const lm_gl_mesh *casters, int size, lm_error *err)
{
    memset(m, 0, sizeof *m);
    m->size = size;
    m->cube = e->kind == LM_EMIT_POINT;
    m->ortho = e->kind == LM_EMIT_DIRECTIONAL;
    lm_vec3 p = lm_v3_load(e->pos), d = lm_normalize(lm_v3_load(e->dir));
    lm_v3_store(m->origin, p);
    lm_v3_store(m->dir, d);
    GLuint prog = 0;
    lm_status st = lm_gl_program("shadow_map", VS, FS, &prog, err);
    if (st != LM_OK)
        return st;
    m->tex = make_texture(m->cube ? GL_TEXTURE_CUBE_MAP : GL_TEXTURE_2D, size);
    GLuint fbo, depth;
    glGenFramebuffers(1, &fbo);
    glGenRenderbuffers(1, &depth);
    glBindRenderbuffer(GL_RENDERBUFFER, depth);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT32F, size, size);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth);
    glViewport(0, 0, size, size);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE); /* both sides cast: open meshes too */
    glUseProgram(prog);
    glUniform3fv(glGetUniformLocation(prog, "dir"), 1, m->dir);
    glUniform1i(glGetUniformLocation(prog, "ortho"), m->ortho);
    float size_s = lm_scene_size(s) > 0.0f ? lm_scene_size(s) : 1.0f;
    float znear = 1e-4f * size_s, zfar = 1.01f * far_corner(s, p, size_s) + znear;
    glUniform1f(glGetUniformLocation(prog, "range"), m->ortho ? 2.02f * size_s : zfar);
    if (m->cube) {
        glUniform3fv(glGetUniformLocation(prog, "origin"), 1, m->origin);
        cube_faces(m, prog, p, znear, zfar, casters);
    } else {
        if (m->ortho)
            directional_map(m, s, d);
        else
            spot_map(m, &s->lights[e->light], p, d, znear, zfar);
        glUniform3fv(glGetUniformLocation(prog, "origin"), 1, m->origin);
        draw_face(m, prog, GL_TEXTURE_2D, m->light_vp, casters);
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glDeleteRenderbuffers(1, &depth);
    glDeleteFramebuffers(1, &fbo);
    glDeleteProgram(prog);
    st = lm_gl_check("shadow_map: rendering", err);
    if (st != LM_OK)
        lm_shadow_map_free(m);
    return st;
}

void lm_shadow_map_free(lm_shadow_map *m)
{
    glDeleteTextures(1, &m->tex);
    m->tex = 0;
}
