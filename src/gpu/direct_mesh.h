/* The scene as direct.c draws it: one vertex buffer with the triangles grouped by base colour texture,
 * those textures uploaded, and a positions-only buffer of the shadow casters. Internal to gpu/direct. */
#ifndef LM_DIRECT_MESH_H
#define LM_DIRECT_MESH_H

#include "../charts/charts.h"
#include "../core/error.h"
#include "../scene/scene.h"
#include "gl_mesh.h"

typedef struct {
    lm_gl_mesh mesh;      /* attributes: see direct_shader.c */
    lm_gl_mesh casters;   /* attribute 0 = world position; triangles of nodes with shadows on, those of
                           * static nodes (lm_node.dynamic 0) first */
    int static_caster_vertices; /* vertices of the static casters at the start of `casters` */
    int groups;           /* texture_count + 1: group 0 untextured, group g + 1 texture g */
    int *first, *count;   /* vertex range of each group */
    unsigned *tex;        /* GL texture of group g + 1 (0 when the group is empty) */
    int *slot;            /* per triangle: its first vertex in `mesh` */
    int *caster_slot;     /* per triangle: its first vertex in `casters`, -1 when it casts no shadow */
    int node_count;
    float *node_world;    /* per node: the world matrix its vertices were last uploaded with */
    float *scratch;       /* vertices of the largest node (update) */
    unsigned uv_vbo;      /* lightmap uv per vertex (attribute 7), 0 until lm_direct_mesh_add_lightmap_uv */
} lm_direct_mesh;

lm_status lm_direct_mesh_build(lm_direct_mesh *d, const lm_scene *s, lm_error *err);
/* Re-uploads the vertices of every node whose world matrix changed since they were uploaded. Returns
 * LM_MESH_MOVED when some node moved, | LM_MESH_DYNAMIC_CASTERS_MOVED or LM_MESH_STATIC_CASTERS_MOVED
 * when one of them casts shadows (a static node only moves when the caller edits it). */
enum { LM_MESH_MOVED = 1, LM_MESH_DYNAMIC_CASTERS_MOVED = 2, LM_MESH_STATIC_CASTERS_MOVED = 4 };
int lm_direct_mesh_update(lm_direct_mesh *d, const lm_scene *s);
/* Adds attribute 7: each corner's lightmap uv in atlas a, (-1, -1) on triangles without a chart (they do
 * not move with their node: uvs are fixed). */
lm_status lm_direct_mesh_add_lightmap_uv(lm_direct_mesh *d, const lm_scene *s, const lm_atlas *a, lm_error *err);
/* Draws every group, binding its texture to unit 2 and setting uniform `has_tex` of prog (prog 0: the
 * current program, no uniform set). */
void lm_direct_mesh_draw(const lm_direct_mesh *d, unsigned prog);
void lm_direct_mesh_free(lm_direct_mesh *d);

#endif
