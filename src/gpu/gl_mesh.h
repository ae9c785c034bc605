/* Triangles for drawing: a vertex array and buffer of interleaved float attributes. */
#ifndef LM_GL_MESH_H
#define LM_GL_MESH_H

#include <stddef.h>

typedef struct {
    unsigned vao, vbo;
    int vertices;
} lm_gl_mesh;

/* Uploads `vertices` vertices of interleaved floats; attribute i (location i) has sizes[i] floats. */
void lm_gl_mesh_create(lm_gl_mesh *m, const float *data, int vertices, const int *sizes, int attributes);
void lm_gl_mesh_draw(const lm_gl_mesh *m);
void lm_gl_mesh_destroy(lm_gl_mesh *m);

#endif
