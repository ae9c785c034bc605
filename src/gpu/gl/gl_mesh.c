#include "gl_mesh.h"

#include <stdlib.h>
#include <string.h>

#include "gl_api.h"

static int stride_of(const int *sizes, int attributes)
{
    int stride = 0;
    for (int i = 0; i < attributes; i++)
        stride += sizes[i];
    return stride;
}

static void upload(lm_gl_mesh *m, const float *data, int vertices, const int *sizes, int attributes)
{
    int stride = stride_of(sizes, attributes);
    glGenVertexArrays(1, &m->vao);
    glBindVertexArray(m->vao);
    glGenBuffers(1, &m->vbo);
    glBindBuffer(GL_ARRAY_BUFFER, m->vbo);
    glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(sizeof(float) * (size_t)stride * (size_t)vertices), data,
                 GL_STATIC_DRAW);
    size_t offset = 0;
    for (int i = 0; i < attributes; i++) {
        glVertexAttribPointer((GLuint)i, sizes[i], GL_FLOAT, GL_FALSE, (GLsizei)(stride * sizeof(float)),
                              (void *)offset);
        glEnableVertexAttribArray((GLuint)i);
        offset += (size_t)sizes[i] * sizeof(float);
    }
}

void lm_gl_mesh_create(lm_gl_mesh *m, const float *data, int vertices, const int *sizes, int attributes)
{
    memset(m, 0, sizeof *m);
    m->vertices = vertices;
    upload(m, data, vertices, sizes, attributes);
}

static uint32_t hash_bytes(const float *v, int n)
{
    uint32_t h = 2166136261u;
    const unsigned char *b = (const unsigned char *)v;
    for (size_t i = 0; i < sizeof(float) * (size_t)n; i++)
        h = (h ^ b[i]) * 16777619u;
    return h;
}

/* Bit-identical vertices become one (open addressing over the first occurrence of each). */
static int dedupe(const float *data, int vertices, int stride, float *unique, uint32_t *index)
{
    size_t cap = 16;
    while (cap < 2 * (size_t)vertices)
        cap *= 2;
    int32_t *slot = malloc(sizeof(int32_t) * cap);
    if (!slot)
        return -1;
    memset(slot, 0xff, sizeof(int32_t) * cap);
    int count = 0;
    for (int v = 0; v < vertices; v++) {
        const float *src = data + (size_t)stride * v;
        size_t h = hash_bytes(src, stride) & (cap - 1);
        while (slot[h] >= 0 && memcmp(unique + (size_t)stride * slot[h], src, sizeof(float) * stride) != 0)
            h = (h + 1) & (cap - 1);
        if (slot[h] < 0) {
            memcpy(unique + (size_t)stride * count, src, sizeof(float) * stride);
            slot[h] = count++;
        }
        index[v] = (uint32_t)slot[h];
    }
    free(slot);
    return count;
}

void lm_gl_mesh_create_elements(lm_gl_mesh *m, const float *data, int vertices, const int *sizes, int attributes,
                                const uint32_t *index, int indices)
{
    memset(m, 0, sizeof *m);
    upload(m, data, vertices, sizes, attributes);
    glGenBuffers(1, &m->ibo);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, m->ibo); /* recorded in the VAO bound by upload */
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, (GLsizeiptr)(sizeof(uint32_t) * (size_t)indices), index, GL_STATIC_DRAW);
    m->vertices = indices;
}

int lm_gl_mesh_create_indexed(lm_gl_mesh *m, const float *data, int vertices, const int *sizes, int attributes)
{
    memset(m, 0, sizeof *m);
    int stride = stride_of(sizes, attributes);
    float *unique = malloc(sizeof(float) * (size_t)stride * (size_t)(vertices ? vertices : 1));
    uint32_t *index = malloc(sizeof(uint32_t) * (size_t)(vertices ? vertices : 1));
    int count = unique && index ? dedupe(data, vertices, stride, unique, index) : -1;
    if (count >= 0)
        lm_gl_mesh_create_elements(m, unique, count, sizes, attributes, index, vertices);
    free(unique);
    free(index);
    return count >= 0;
}

void lm_gl_mesh_draw(const lm_gl_mesh *m)
{
    glBindVertexArray(m->vao);
    if (m->ibo)
        glDrawElements(GL_TRIANGLES, m->vertices, GL_UNSIGNED_INT, NULL);
    else
        glDrawArrays(GL_TRIANGLES, 0, m->vertices);
}

void lm_gl_mesh_draw_range(const lm_gl_mesh *m, int first, int count)
{
    glBindVertexArray(m->vao);
    if (m->ibo)
        glDrawElements(GL_TRIANGLES, count, GL_UNSIGNED_INT, (const void *)(sizeof(uint32_t) * (size_t)first));
    else
        glDrawArrays(GL_TRIANGLES, first, count);
}

void lm_gl_mesh_draw_instanced(const lm_gl_mesh *m, int instances)
{
    glBindVertexArray(m->vao);
    if (m->ibo)
        glDrawElementsInstanced(GL_TRIANGLES, m->vertices, GL_UNSIGNED_INT, NULL, instances);
    else
        glDrawArraysInstanced(GL_TRIANGLES, 0, m->vertices, instances);
}

void lm_gl_mesh_destroy(lm_gl_mesh *m)
{
    glDeleteBuffers(1, &m->vbo);
    if (m->ibo)
        glDeleteBuffers(1, &m->ibo);
    glDeleteVertexArrays(1, &m->vao);
    m->vao = m->vbo = m->ibo = 0;
}

void lm_gl_mesh_draw_front_range(const lm_gl_mesh *m, int first, int count)
{
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    lm_gl_mesh_draw_range(m, first, count);
    glDisable(GL_CULL_FACE);
}

void lm_gl_mesh_draw_scene_sides(const lm_gl_mesh *m, const lm_scene *s)
{
    for (uint32_t t = 0; t < s->tri_count;) {
        int split = s->materials[s->tri_material[t]].split_sides;
        uint32_t end = t + 1;
        while (end < s->tri_count && s->materials[s->tri_material[end]].split_sides == split)
            end++;
        (split ? lm_gl_mesh_draw_front_range : lm_gl_mesh_draw_range)(m, (int)(3 * t), (int)(3 * (end - t)));
        t = end;
    }
}
