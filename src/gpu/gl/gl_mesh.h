/* Triangles for drawing: a vertex array and buffer of interleaved float attributes, optionally indexed. */
#ifndef LM_GL_MESH_H
#define LM_GL_MESH_H

#include <stddef.h>
#include <stdint.h>

#include "../../scene/scene.h"

typedef struct {
    unsigned vao, vbo, ibo;
    int vertices;         /* vertices drawn: index count when indexed */
} lm_gl_mesh;

/* Uploads `vertices` vertices of interleaved floats; attribute i (location i) has sizes[i] floats. */
void lm_gl_mesh_create(lm_gl_mesh *m, const float *data, int vertices, const int *sizes, int attributes);
/* Uploads `vertices` vertices as above and `indices` indices (3 per triangle) into them. */
void lm_gl_mesh_create_elements(lm_gl_mesh *m, const float *data, int vertices, const int *sizes, int attributes,
                                const uint32_t *index, int indices);
/* The same triangles with identical vertices shared through an index buffer (fewer vertex shader runs).
 * Returns 0 when out of memory (nothing created). */
int lm_gl_mesh_create_indexed(lm_gl_mesh *m, const float *data, int vertices, const int *sizes, int attributes);
void lm_gl_mesh_draw(const lm_gl_mesh *m);
/* Draws `count` vertices (indices when indexed) from the `first`-th. */
void lm_gl_mesh_draw_range(const lm_gl_mesh *m, int first, int count);
/* The same with back faces culled (counter-clockwise fronts), for the sides of split double-sided
 * surfaces: the twin in the same plane shows the other side. */
void lm_gl_mesh_draw_front_range(const lm_gl_mesh *m, int first, int count);
/* Draws a mesh of unindexed triangles, one per scene triangle in the scene's order, with the back faces
 * of split double-sided sides culled (lm_scene.tri_twin: the twin in the same plane shows that side),
 * the others from both sides. */
void lm_gl_mesh_draw_scene_sides(const lm_gl_mesh *m, const lm_scene *s);
void lm_gl_mesh_draw_instanced(const lm_gl_mesh *m, int instances);
void lm_gl_mesh_destroy(lm_gl_mesh *m);

#endif
