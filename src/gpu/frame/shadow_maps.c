#include "shadow_maps.h"

#include "../gl/gl_api.h"
#include <math.h>
#include <string.h>

#include "../../core/camera.h"
#include "../../core/vecmath.h"
#include "../gl/gl_shader.h"
#include "glsl.h"

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

/* A depth texture (cube or 2D). compare: sampled with hardware comparison and a linear filter (the map
 * itself); else a plain copy source (the static layer). */
static GLuint make_depth_texture(GLenum target, int size, int compare)
{
    GLuint tex;
    glGenTextures(1, &tex);
    glBindTexture(target, tex);
    if (target == GL_TEXTURE_CUBE_MAP)
        for (int f = 0; f < 6; f++)
            glTexImage2D(GL_TEXTURE_CUBE_MAP_POSITIVE_X + f, 0, GL_DEPTH_COMPONENT32F, size, size, 0,
                         GL_DEPTH_COMPONENT, GL_FLOAT, NULL);
    else
        glTexImage2D(target, 0, GL_DEPTH_COMPONENT32F, size, size, 0, GL_DEPTH_COMPONENT, GL_FLOAT, NULL);
    GLint filter = compare ? GL_LINEAR : GL_NEAREST;
    glTexParameteri(target, GL_TEXTURE_MIN_FILTER, filter);
    glTexParameteri(target, GL_TEXTURE_MAG_FILTER, filter);
    glTexParameteri(target, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(target, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glTexParameteri(target, GL_TEXTURE_WRAP_R, GL_CLAMP_TO_EDGE);
    if (compare) { /* lit where reference <= stored */
        glTexParameteri(target, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
        glTexParameteri(target, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
    }
    return tex;
}

/* Which casters a face draws, and how it starts. */
typedef struct {
    int first, count;     /* vertex (index) range of `casters` */
    int from_layer;       /* 1: copy the static layer's face first (else clear) */
    int into_layer;       /* 1: draw into the static layer instead of the map */
    const float *lo, *hi; /* with from_layer: the casters' world bounds (NULL: unknown, every face drawn) */
} face_job;

/* Draws one face (GL target `face`) with view-projection vp. */
static void draw_face(const lm_shadow_map *m, const lm_shadow_renderer *r, GLenum face, const float vp[16],
                      const lm_gl_mesh *casters, const face_job *job)
{
    glBindFramebuffer(GL_FRAMEBUFFER, job->into_layer ? m->layer_fbo : m->fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, face, job->into_layer ? m->layer_tex : m->tex, 0);
    if (job->from_layer) {
        glBindFramebuffer(GL_READ_FRAMEBUFFER, m->layer_fbo);
        glFramebufferTexture2D(GL_READ_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, face, m->layer_tex, 0);
        int n = m->p.size;
        glBlitFramebuffer(0, 0, n, n, 0, 0, n, n, GL_DEPTH_BUFFER_BIT, GL_NEAREST);
        glBindFramebuffer(GL_READ_FRAMEBUFFER, m->fbo);
    } else {
        glClear(GL_DEPTH_BUFFER_BIT); /* depth 1: the range, where nothing occludes */
    }
    if (job->count > 0) {
        glUniformMatrix4fv(r->u_vp, 1, GL_FALSE, vp);
        lm_gl_mesh_draw_range(casters, job->first, job->count);
    }
}

/* Whether box [lo, hi] may reach cube face f (axis f / 2, sign + for even f) of a light at p: it is
 * outside when all its corners lie behind one of the face frustum's four planes through p
 * (|other coordinate| <= the axis coordinate). Conservative. */
static int box_in_face(const float p[3], const float *lo, const float *hi, int f)
{
    int axis = f / 2;
    float sign = f % 2 ? -1.0f : 1.0f;
    for (int k = 1; k < 3; k++) {
        int o = (axis + k) % 3;
        for (int side = -1; side <= 1; side += 2) { /* plane: sign * a - side * b >= 0 */
            int inside = 0;
            for (int c = 0; c < 8 && !inside; c++) {
                float a = ((c >> axis) & 1 ? hi : lo)[axis] - p[axis], b = ((c >> o) & 1 ? hi : lo)[o] - p[o];
                inside = sign * a - (float)side * b >= 0.0f;
            }
            if (!inside)
                return 0;
        }
    }
    return 1;
}

static void cube_faces(lm_shadow_map *m, const lm_shadow_renderer *r, const lm_gl_mesh *casters, const face_job *job)
{
    /* GL's cube map face order and orientation (+X, -X, +Y, -Y, +Z, -Z). */
    static const float dirs[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    static const float ups[6][3] = {{0, -1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}, {0, -1, 0}, {0, -1, 0}};
    float proj[16], view[16], vp[16];
    lm_vec3 p = lm_v3_load(m->p.pos);
    lm_mat4_perspective(proj, (float)(LM_PI / 2), 1.0f, m->p.znear, m->p.zfar);
    for (int f = 0; f < 6; f++) {
        if (job->from_layer && job->lo) { /* skip a face that shows its layer and will again */
            int now = box_in_face(m->p.pos, job->lo, job->hi, f);
            if (!now && !m->face_dynamic[f])
                continue;
            m->face_dynamic[f] = (unsigned char)now;
        } else if (job->from_layer) {
            m->face_dynamic[f] = 1;
        }
        lm_mat4_look_at(view, p, lm_add(p, lm_v3_load(dirs[f])), lm_v3_load(ups[f]));
        lm_mat4_mul(vp, proj, view);
        draw_face(m, r, GL_TEXTURE_CUBE_MAP_POSITIVE_X + (GLenum)f, vp, casters, job);
    }
}

static void spot_map(lm_shadow_params *m, const lm_light *l, lm_vec3 p, lm_vec3 d)
{
    float half = fminf(l->outer_cone, 1.48f) * 1.02f, view[16], proj[16];
    lm_mat4_look_at(view, p, lm_add(p, d), up_for(d));
    lm_mat4_perspective(proj, 2.0f * half, 1.0f, m->znear, m->zfar);
    lm_mat4_mul(m->light_vp, proj, view);
    m->texel = 2.0f * tanf(half) / (float)m->size;
}

/* A directional light's view: along d towards the scene's centre from 1.01 r upstream, r the scene's
 * bounding radius, so that the depth range 0..2.02 r holds every caster. */
static void directional_view(const lm_scene *s, lm_vec3 d, float view[16], lm_vec3 *eye, float *r)
{
    lm_vec3 lo = lm_v3_load(s->bounds_min), hi = lm_v3_load(s->bounds_max);
    lm_vec3 c = lm_scale(lm_add(lo, hi), 0.5f);
    *r = fmaxf(0.5f * lm_length(lm_sub(hi, lo)), 1e-4f);
    *eye = lm_sub(c, lm_scale(d, 1.01f * *r));
    lm_mat4_look_at(view, *eye, c, up_for(d));
}

static void directional_map(lm_shadow_params *m, const lm_scene *s, lm_vec3 d)
{
    float r, view[16], proj[16];
    lm_vec3 eye;
    directional_view(s, d, view, &eye, &r);
    ortho_proj(proj, r, 2.02f * r);
    lm_mat4_mul(m->light_vp, proj, view);
    lm_v3_store(m->origin, eye);
    m->texel = 2.0f * r / (float)m->size;
}

int lm_shadow_params_fit_view(lm_shadow_params *near, const lm_shadow_params *whole, const lm_scene *s,
                              const lm_view *v, float max_depth)
{
    if (!whole->ortho)
        return 0;
    float pts[LM_VIEW_BOX_POINTS][3], view[16], r;
    lm_vec3 eye;
    int n = lm_view_box_part(v, s->bounds_min, s->bounds_max, max_depth, pts);
    if (n == 0)
        return 0;
    directional_view(s, lm_v3_load(whole->dir), view, &eye, &r);
    float x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
    for (int i = 0; i < n; i++) {
        lm_vec3 q = lm_mat4_point(view, lm_v3_load(pts[i]));
        x0 = fminf(x0, q.x), x1 = fmaxf(x1, q.x), y0 = fminf(y0, q.y), y1 = fmaxf(y1, q.y);
    }
    /* Side: the whole map's over a power of two, with room for the corner's snap (a sixteenth), so that a
     * camera moving inside one cell keeps the same map and a moving one's shadows do not crawl. */
    float side = 2.0f * r, need = fmaxf(fmaxf(x1 - x0, y1 - y0), 2.0f * r / 65536.0f) * 16.0f / 15.0f;
    int k = 0;
    while (k < 16 && side * 0.5f >= need)
        side *= 0.5f, k++;
    if (k == 0 || !isfinite(x0 + x1 + y0 + y1))
        return 0; /* the view sees about half the scene or more: the whole map is as fine */
    float cell = side / 16.0f, left = floorf(x0 / cell) * cell, bottom = floorf(y0 / cell) * cell, proj[16];
    ortho_proj(proj, 0.5f * side, 2.02f * r);
    proj[12] = -(2.0f * left + side) / side;
    proj[13] = -(2.0f * bottom + side) / side;
    *near = *whole;
    lm_mat4_mul(near->light_vp, proj, view);
    near->texel = side / (float)whole->size;
    return 1;
}

void lm_shadow_params_compute(lm_shadow_params *m, const lm_scene *s, const lm_emitter *e, int size)
{
    memset(m, 0, sizeof *m);
    m->size = size;
    m->cube = e->kind == LM_EMIT_POINT;
    m->ortho = e->kind == LM_EMIT_DIRECTIONAL;
    lm_vec3 p = lm_v3_load(e->pos), d = lm_normalize(lm_v3_load(e->dir));
    lm_v3_store(m->pos, p);
    lm_v3_store(m->origin, p);
    if (!m->cube) /* a cube map does not depend on where the point light faces: turning it redoes nothing */
        lm_v3_store(m->dir, d);
    float size_s = lm_scene_size(s) > 0.0f ? lm_scene_size(s) : 1.0f;
    m->znear = 1e-4f * size_s;
    m->zfar = 1.01f * far_corner(s, p, size_s) + m->znear;
    m->range = m->ortho ? 2.02f * size_s : m->zfar;
    if (m->cube)
        m->texel = 2.0f / (float)size;
    else if (m->ortho)
        directional_map(m, s, d);
    else
        spot_map(m, &s->lights[e->light], p, d);
}

lm_status lm_shadow_renderer_create(lm_shadow_renderer *r, lm_error *err)
{
    memset(r, 0, sizeof *r);
    lm_status st = lm_gl_program("shadow_map", lm_glsl_shadow_map_vs, lm_glsl_shadow_map_fs, &r->prog, err);
    if (st != LM_OK)
        return st;
    r->u_vp = glGetUniformLocation(r->prog, "vp");
    r->u_origin = glGetUniformLocation(r->prog, "origin");
    r->u_dir = glGetUniformLocation(r->prog, "dir");
    r->u_ortho = glGetUniformLocation(r->prog, "ortho");
    r->u_range = glGetUniformLocation(r->prog, "range");
    return LM_OK;
}

void lm_shadow_renderer_free(lm_shadow_renderer *r)
{
    if (r->prog)
        glDeleteProgram(r->prog);
    memset(r, 0, sizeof *r);
}

/* A depth-only framebuffer (no colour buffer is drawn or read). */
static GLuint depth_only_fbo(void)
{
    GLuint fbo;
    glGenFramebuffers(1, &fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glDrawBuffer(GL_NONE);
    glReadBuffer(GL_NONE);
    return fbo;
}

/* The texture and framebuffer for parameters p, kept when kind and size are unchanged; with `layer`, the
 * static layer's too. */
static void ensure_objects(lm_shadow_map *m, const lm_shadow_params *p, int layer)
{
    GLenum target = p->cube ? GL_TEXTURE_CUBE_MAP : GL_TEXTURE_2D;
    if (m->tex && (m->p.cube != p->cube || m->p.size != p->size))
        lm_shadow_map_free(m);
    if (!m->tex) {
        m->tex = make_depth_texture(target, p->size, 1);
        m->fbo = depth_only_fbo();
    }
    if (layer && !m->layer_tex) {
        m->layer_tex = make_depth_texture(target, p->size, 0);
        m->layer_fbo = depth_only_fbo();
        m->layer_valid = 0;
    }
}

/* Draws every face of the map (or of its layer) as `job` says. */
static void draw_faces(lm_shadow_map *m, const lm_shadow_renderer *r, const lm_gl_mesh *casters,
                       const face_job *job)
{
    if (m->p.cube)
        cube_faces(m, r, casters, job);
    else
        draw_face(m, r, GL_TEXTURE_2D, m->p.light_vp, casters, job);
}

lm_status lm_shadow_map_draw(lm_shadow_map *m, const lm_shadow_params *p, const lm_shadow_renderer *r,
                             const lm_gl_mesh *casters, int static_count, int redo_static, const float dynamic_lo[3],
                             const float dynamic_hi[3], lm_error *err)
{
    int n = casters->vertices, split = static_count > 0 && static_count < n;
    ensure_objects(m, p, split);
    if (memcmp(&m->p, p, sizeof *p))
        m->layer_valid = 0;
    m->p = *p;
    glViewport(0, 0, p->size, p->size);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE); /* both sides cast: open meshes too */
    glUseProgram(r->prog);
    glUniform3fv(r->u_dir, 1, p->dir);
    glUniform1i(r->u_ortho, p->ortho);
    glUniform1f(r->u_range, p->range);
    glUniform3fv(r->u_origin, 1, p->origin);
    if (!split) {
        const face_job all = {0, n, 0, 0, NULL, NULL};
        draw_faces(m, r, casters, &all);
    } else {
        int every_face = !m->layer_valid || redo_static; /* a new layer: every face copies it again */
        if (every_face) {
            const face_job statics = {0, static_count, 0, 1, NULL, NULL};
            draw_faces(m, r, casters, &statics);
            m->layer_valid = 1;
        }
        const face_job dynamics = {static_count, n - static_count, 1, 0, every_face ? NULL : dynamic_lo,
                                   every_face ? NULL : dynamic_hi};
        draw_faces(m, r, casters, &dynamics);
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    lm_status st = lm_gl_check("shadow_map: rendering", err);
    if (st != LM_OK)
        lm_shadow_map_free(m);
    return st;
}

void lm_shadow_map_free(lm_shadow_map *m)
{
    if (m->tex)
        glDeleteTextures(1, &m->tex);
    if (m->fbo)
        glDeleteFramebuffers(1, &m->fbo);
    if (m->layer_tex)
        glDeleteTextures(1, &m->layer_tex);
    if (m->layer_fbo)
        glDeleteFramebuffers(1, &m->layer_fbo);
    memset(m, 0, sizeof *m);
}
