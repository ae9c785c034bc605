#include "direct_mesh.h"

#include "gl_api.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../core/vecmath.h"
#include "../trace/bsdf.h"

#define FLOATS 21 /* pos, ns, ng, base colour, (n, double-sided, metallic, class), emission, uv */

/* Group of triangle t: 0 without a base colour texture, else texture index + 1. */
static int group_of(const lm_scene *s, uint32_t t)
{
    const lm_material *m = &s->materials[s->tri_material[t]];
    int tex = m->base_color_tex;
    if (tex < 0 || tex >= s->texture_count || !s->textures[tex].rgba)
        return 0;
    return tex + 1;
}

/* KHR_texture_transform, as lm_material_albedo applies it (affine, so exact at the corners). */
static void transform_uv(const lm_material *m, const float in[2], float out[2])
{
    float su = in[0] * m->uv_scale[0], sv = in[1] * m->uv_scale[1];
    float c = cosf(m->uv_rotation), s = sinf(m->uv_rotation);
    out[0] = c * su + s * sv + m->uv_offset[0];
    out[1] = -s * su + c * sv + m->uv_offset[1];
}

/* The attributes of triangle t's corners into o (3 x FLOATS). */
static void triangle_vertices(const lm_scene *s, uint32_t t, float *o)
{
    const lm_material *m = &s->materials[s->tri_material[t]];
    float p[3][3];
    for (int k = 0; k < 3; k++)
        lm_scene_vertex_world(s, s->tris[3 * (size_t)t + k], p[k]);
    lm_vec3 a = lm_v3_load(p[0]);
    lm_vec3 ng = lm_normalize(lm_cross(lm_sub(lm_v3_load(p[1]), a), lm_sub(lm_v3_load(p[2]), a)));
    for (int k = 0; k < 3; k++) {
        uint32_t vi = s->tris[3 * (size_t)t + k];
        float *v = o + FLOATS * k;
        memcpy(v, p[k], sizeof p[k]);
        lm_scene_normal_world(s, vi, v + 3);
        lm_v3_store(v + 6, ng);
        memcpy(v + 9, m->base_color, 3 * sizeof(float));
        v[12] = m->cls == LM_MAT_GLOSSY ? lm_phong_exponent(m->roughness) : 1.0f;
        v[13] = (float)m->double_sided;
        v[14] = fminf(fmaxf(m->metallic, 0.0f), 1.0f);
        v[15] = (float)m->cls;
        for (int c = 0; c < 3; c++)
            v[16 + c] = m->cls == LM_MAT_EMITTER ? m->emissive[c] : 0.0f;
        const float *uvs = m->base_color_uv == 1 && s->uv1 ? s->uv1 : s->uv0;
        transform_uv(m, uvs + 2 * (size_t)vi, v + 19);
    }
}

static unsigned upload(const lm_texture *t)
{
    GLuint tex;
    glGenTextures(1, &tex);
    glBindTexture(GL_TEXTURE_2D, tex);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    /* row 0 (v = 0) first: GL's t = 0 is the first row, so uv addresses it as the CPU does */
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, t->width, t->height, 0, GL_RGBA, GL_FLOAT, t->rgba);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_REPEAT);
    return tex;
}

/* Vertex ranges per group (counting sort) and the textures of non-empty groups. */
static void plan_groups(lm_direct_mesh *d, const lm_scene *s)
{
    for (uint32_t t = 0; t < s->tri_count; t++)
        d->count[group_of(s, t)] += 3;
    for (int g = 1; g < d->groups; g++)
        d->first[g] = d->first[g - 1] + d->count[g - 1];
    for (int g = 1; g < d->groups; g++)
        d->tex[g - 1] = d->count[g] ? upload(&s->textures[g - 1]) : 0;
}

/* Fills the shading vertices (grouped) and the casters; returns the caster triangle count. */
static int fill(const lm_direct_mesh *d, const lm_scene *s, float *v, float *c)
{
    int *next = calloc((size_t)d->groups, sizeof(int)), casters = 0;
    if (!next)
        return -1;
    memcpy(next, d->first, sizeof(int) * (size_t)d->groups);
    for (uint32_t t = 0; t < s->tri_count; t++) {
        int g = group_of(s, t);
        float *o = v + (size_t)FLOATS * (size_t)next[g];
        next[g] += 3;
        triangle_vertices(s, t, o);
        if (!s->nodes[s->tri_node[t]].settings.shadows)
            continue;
        for (int k = 0; k < 3; k++)
            memcpy(c + 9 * (size_t)casters + 3 * k, o + FLOATS * k, 3 * sizeof(float));
        casters++;
    }
    free(next);
    return casters;
}

lm_status lm_direct_mesh_build(lm_direct_mesh *d, const lm_scene *s, lm_error *err)
{
    memset(d, 0, sizeof *d);
    d->groups = s->texture_count + 1;
    size_t n = s->tri_count ? s->tri_count : 1;
    d->first = calloc((size_t)d->groups, sizeof(int));
    d->count = calloc((size_t)d->groups, sizeof(int));
    d->tex = calloc((size_t)d->groups, sizeof(unsigned));
    float *v = malloc(sizeof(float) * FLOATS * 3 * n), *c = malloc(sizeof(float) * 9 * n);
    int casters = -1;
    if (d->first && d->count && d->tex && v && c) {
        plan_groups(d, s);
        casters = fill(d, s, v, c);
    }
    if (casters >= 0) {
        const int sizes[7] = {3, 3, 3, 3, 4, 3, 2}, pos_only[1] = {3};
        lm_gl_mesh_create(&d->mesh, v, (int)(3 * s->tri_count), sizes, 7);
        lm_gl_mesh_create(&d->casters, c, 3 * casters, pos_only, 1);
    }
    free(v);
    free(c);
    if (casters < 0) {
        lm_direct_mesh_free(d);
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for the direct-light meshes", s->path);
    }
    return LM_OK;
}

void lm_direct_mesh_draw(const lm_direct_mesh *d, unsigned prog)
{
    GLint has_tex = glGetUniformLocation(prog, "has_tex");
    glBindVertexArray(d->mesh.vao);
    for (int g = 0; g < d->groups; g++) {
        if (!d->count[g])
            continue;
        glUniform1i(has_tex, g > 0);
        glActiveTexture(GL_TEXTURE2);
        glBindTexture(GL_TEXTURE_2D, g > 0 ? d->tex[g - 1] : 0);
        glDrawArrays(GL_TRIANGLES, d->first[g], d->count[g]);
    }
}

void lm_direct_mesh_free(lm_direct_mesh *d)
{
    if (d->mesh.vao)
        lm_gl_mesh_destroy(&d->mesh);
    if (d->casters.vao)
        lm_gl_mesh_destroy(&d->casters);
    for (int g = 0; d->tex && g + 1 < d->groups; g++)
        if (d->tex[g])
            glDeleteTextures(1, &d->tex[g]);
    free(d->first);
    free(d->count);
    free(d->tex);
    memset(d, 0, sizeof *d);
}
