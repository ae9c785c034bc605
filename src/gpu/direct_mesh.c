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

/* Fills the shading vertices (grouped) and the casters, those of static nodes first; returns the caster
 * triangle count. */
static int fill(lm_direct_mesh *d, const lm_scene *s, float *v, float *c)
{
    int *next = calloc((size_t)d->groups, sizeof(int)), casters = 0, next_static = 0, next_dynamic = 0;
    if (!next)
        return -1;
    for (uint32_t t = 0; t < s->tri_count; t++) {
        const lm_node *nd = &s->nodes[s->tri_node[t]];
        casters += nd->settings.shadows != 0;
        next_dynamic += nd->settings.shadows && !nd->dynamic;
    }
    d->static_caster_vertices = 3 * next_dynamic;
    memcpy(next, d->first, sizeof(int) * (size_t)d->groups);
    for (uint32_t t = 0; t < s->tri_count; t++) {
        int g = group_of(s, t);
        float *o = v + (size_t)FLOATS * (size_t)next[g];
        d->slot[t] = next[g];
        next[g] += 3;
        triangle_vertices(s, t, o);
        d->caster_slot[t] = -1;
        const lm_node *nd = &s->nodes[s->tri_node[t]];
        if (!nd->settings.shadows)
            continue;
        int *at = nd->dynamic ? &next_dynamic : &next_static;
        d->caster_slot[t] = 3 * *at;
        for (int k = 0; k < 3; k++)
            memcpy(c + 9 * (size_t)*at + 3 * k, o + FLOATS * k, 3 * sizeof(float));
        ++*at;
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
    d->slot = malloc(sizeof(int) * n);
    d->caster_slot = malloc(sizeof(int) * n);
    d->node_count = s->node_count;
    d->node_world = malloc(sizeof(float) * 16 * (size_t)(s->node_count ? s->node_count : 1));
    uint32_t most = 1;
    for (int i = 0; i < s->node_count; i++)
        most = s->nodes[i].tri_count > most ? s->nodes[i].tri_count : most;
    d->scratch = malloc(sizeof(float) * (FLOATS * 3 + 9) * most);
    float *v = malloc(sizeof(float) * FLOATS * 3 * n), *c = malloc(sizeof(float) * 9 * n);
    int casters = -1;
    if (d->first && d->count && d->tex && d->slot && d->caster_slot && d->node_world && d->scratch && v && c) {
        for (int i = 0; i < s->node_count; i++)
            memcpy(d->node_world + 16 * (size_t)i, s->nodes[i].world, sizeof s->nodes[i].world);
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

/* Uploads `count` vertices of node-ordered data to buffer `vbo` at the slots given per triangle, one
 * glBufferSubData per run of consecutive slots. stride: floats per vertex. data has room for the
 * casters' packed positions after its n triangles. */
static void upload_runs(unsigned vbo, const int *slot, uint32_t first, uint32_t n, float *data, int stride,
                        int only_positions)
{
    glBindBuffer(GL_ARRAY_BUFFER, vbo);
    size_t vbytes = sizeof(float) * (size_t)stride;
    uint32_t i = 0;
    while (i < n) {
        if (slot[first + i] < 0) {
            i++;
            continue;
        }
        uint32_t j = i + 1;
        while (j < n && slot[first + j] == slot[first + j - 1] + 3)
            j++;
        if (!only_positions)
            glBufferSubData(GL_ARRAY_BUFFER, (GLintptr)(vbytes * (size_t)slot[first + i]),
                            (GLsizeiptr)(vbytes * 3 * (j - i)), data + (size_t)stride * 3 * i);
        else { /* casters: 3 floats per vertex, the shading vertices' positions, packed after data */
            float *p = data + (size_t)FLOATS * 3 * n;
            for (uint32_t t = i; t < j; t++)
                for (int k = 0; k < 3; k++)
                    memcpy(p + 9 * (t - i) + 3 * k, data + (size_t)FLOATS * (3 * t + (uint32_t)k), 3 * sizeof(float));
            glBufferSubData(GL_ARRAY_BUFFER, (GLintptr)(sizeof(float) * 3 * (size_t)slot[first + i]),
                            (GLsizeiptr)(sizeof(float) * 9 * (j - i)), p);
        }
        i = j;
    }
}

int lm_direct_mesh_update(lm_direct_mesh *d, const lm_scene *s)
{
    int moved = 0;
    for (int i = 0; i < s->node_count && i < d->node_count; i++) {
        const lm_node *nd = &s->nodes[i];
        float *w = d->node_world + 16 * (size_t)i;
        if (!memcmp(w, nd->world, sizeof nd->world))
            continue;
        memcpy(w, nd->world, sizeof nd->world);
        if (!nd->tri_count)
            continue;
        for (uint32_t t = 0; t < nd->tri_count; t++)
            triangle_vertices(s, nd->first_tri + t, d->scratch + (size_t)FLOATS * 3 * t);
        upload_runs(d->mesh.vbo, d->slot, nd->first_tri, nd->tri_count, d->scratch, FLOATS, 0);
        moved |= LM_MESH_MOVED;
        if (nd->settings.shadows) {
            upload_runs(d->casters.vbo, d->caster_slot, nd->first_tri, nd->tri_count, d->scratch, FLOATS, 1);
            moved |= nd->dynamic ? LM_MESH_DYNAMIC_CASTERS_MOVED : LM_MESH_STATIC_CASTERS_MOVED;
        }
    }
    return moved;
}

lm_status lm_direct_mesh_add_lightmap_uv(lm_direct_mesh *d, const lm_scene *s, const lm_atlas *a, lm_error *err)
{
    float *uv = malloc(sizeof(float) * 6 * (s->tri_count ? s->tri_count : 1));
    if (!uv)
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for the lightmap uvs", s->path);
    for (uint32_t t = 0; t < s->tri_count; t++)
        for (int k = 0; k < 3; k++) { /* as lm_lightmapped_vertices */
            const float *c = a->corner_uv + 6 * (size_t)t + 2 * k;
            int none = a->tri_chart[t] < 0 || !isfinite(c[0]);
            float *o = uv + 2 * ((size_t)d->slot[t] + (size_t)k);
            o[0] = none ? -1.0f : c[0];
            o[1] = none ? -1.0f : c[1];
        }
    if (!d->uv_vbo)
        glGenBuffers(1, &d->uv_vbo);
    glBindVertexArray(d->mesh.vao);
    glBindBuffer(GL_ARRAY_BUFFER, d->uv_vbo);
    glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(sizeof(float) * 6 * s->tri_count), uv, GL_STATIC_DRAW);
    glVertexAttribPointer(7, 2, GL_FLOAT, GL_FALSE, 2 * sizeof(float), (void *)0);
    glEnableVertexAttribArray(7);
    free(uv);
    return LM_OK;
}

void lm_direct_mesh_draw(const lm_direct_mesh *d, unsigned prog)
{
    GLint has_tex = prog ? glGetUniformLocation(prog, "has_tex") : -1;
    glBindVertexArray(d->mesh.vao);
    for (int g = 0; g < d->groups; g++) {
        if (!d->count[g])
            continue;
        if (has_tex >= 0)
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
    if (d->uv_vbo)
        glDeleteBuffers(1, &d->uv_vbo);
    for (int g = 0; d->tex && g + 1 < d->groups; g++)
        if (d->tex[g])
            glDeleteTextures(1, &d->tex[g]);
    free(d->first);
    free(d->count);
    free(d->tex);
    free(d->slot);
    free(d->caster_slot);
    free(d->node_world);
    free(d->scratch);
    memset(d, 0, sizeof *d);
}
