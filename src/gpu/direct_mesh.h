/* The scene as direct.c draws it: one vertex buffer with the triangles grouped by base colour texture,
 * those textures uploaded, and a positions-only buffer of the shadow casters. Internal to gpu/direct. */
#ifndef LM_DIRECT_MESH_H
#define LM_DIRECT_MESH_H

#include "../core/error.h"
#include "../scene/scene.h"
#include "gl_mesh.h"

typedef struct {
    lm_gl_mesh mesh;      /* attributes: see direct_shader.c */
    lm_gl_mesh casters;   /* attribute 0 = world position; triangles of nodes with shadows on */
    int groups;           /* texture_count + 1: group 0 untextured, group g + 1 texture g */
    int *first, *count;   /* vertex range of each group */
    unsigned *tex;        /* GL texture of group g + 1 (0 when the group is empty) */
} lm_direct_mesh;

lm_status lm_direct_mesh_build(lm_direct_mesh *d, const lm_scene *s, lm_error *err);
/* Draws every group, binding its texture to unit 2 and setting uniform `has_tex` of prog. */
void lm_direct_mesh_draw(const lm_direct_mesh *d, unsigned prog);
void lm_direct_mesh_free(lm_direct_mesh *d);

#endif
