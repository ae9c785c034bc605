#include "gl_mesh.h"

#include "gl_api.h"

void lm_gl_mesh_create(lm_gl_mesh *m, const float *data, int vertices, const int *sizes, int attributes)
{
    int stride = 0;
    for (int i = 0; i < attributes; i++)
        stride += sizes[i];
    m->vertices = vertices;
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

void lm_gl_mesh_draw(const lm_gl_mesh *m)
{
    glBindVertexArray(m->vao);
    glDrawArrays(GL_TRIANGLES, 0, m->vertices);
}

void lm_gl_mesh_destroy(lm_gl_mesh *m)
{
    glDeleteBuffers(1, &m->vbo);
    glDeleteVertexArrays(1, &m->vao);
    m->vao = m->vbo = 0;
}
