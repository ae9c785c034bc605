/* The scene as direct.c draws it: one indexed vertex buffer whose triangles are grouped by base colour
 * texture, those textures uploaded, and an indexed positions-only buffer of the shadow casters. Corners
 * that share a scene vertex, a material and a lightmap uv share one GPU vertex, so llvmpipe shades each
 * vertex once instead of once per triangle corner (a sixth of the vertex work on the Cornell box). Each
 * node's vertices are contiguous, so a moved node re-uploads one range. Within a group the triangles run
 * node by node, the smallest node first (its world bounds at the build): enclosing walls and floors are
 * drawn last, so their pixels hidden behind props fail the early depth test instead of being shaded and
 * covered. Internal to gpu/frame/direct. */
#ifndef LM_DIRECT_MESH_H
#define LM_DIRECT_MESH_H

#include "../../charts/charts.h"
#include "../../core/error.h"
#include "../../scene/scene.h"
#include "../gl/gl_mesh.h"

typedef struct {
    lm_gl_mesh mesh;      /* attributes: see glsl/direct_vs.glsl; 7 = lightmap uv when built with an atlas */
    lm_gl_mesh casters;   /* attribute 0 = world position; indices of nodes with shadows on, those of
                           * static nodes (lm_node.dynamic 0) first */
    int static_caster_indices; /* indices of the static casters at the start of `casters` */
    int groups;           /* texture_count + 1: group 0 untextured, group g + 1 texture g */
    int *first, *count;   /* index range of each group */
    int *paired;          /* of which the last `paired` are sides of split double-sided surfaces, drawn
                           * with back faces culled (the twin on the same plane shows the other side) */
    int *lod_first, *lod_count, *lod_paired; /* the same per group for the simplified triangles, after the full
                           * ones in the index buffer (lm_direct_mesh_draw_lod) */
    uint32_t lod_tris;    /* triangles of the simplified mesh (the scene's own without lod_error) */
    unsigned *tex;        /* GL texture of group g + 1 (0 when the group is empty) */
    int node_count;
    int *node_first, *node_verts;     /* per node: its vertex range in `mesh` */
    int *caster_first, *caster_verts; /* per node: its vertex range in `casters` (0 vertices: no shadows) */
    uint32_t *vert_src;   /* per mesh vertex: scene vertex */
    int *vert_mat;        /* per mesh vertex: material */
    uint32_t *caster_src; /* per caster vertex: scene vertex */
    float *node_world;    /* per node: the world matrix its vertices were last uploaded with */
    float *scratch;       /* vertices of the largest node (update) */
    unsigned uv_vbo;      /* lightmap uv per vertex (attribute 7), 0 without an atlas */
    float dynamic_lo[3], dynamic_hi[3]; /* world bounds of the dynamic nodes' casters (after an update) */
    uint32_t material_version; /* the scene's when the vertices (which carry their material) were uploaded */
    uint32_t pass_version;     /* the scene's when the casters were chosen and split into static and dynamic */
} lm_direct_mesh;

/* Builds the meshes; with an atlas (may be NULL) also attribute 7: each vertex's lightmap uv, (-1, -1) on
 * triangles without a chart (uvs are fixed: they do not move with their node). shadows 0: no casters at
 * all (the run's switch), else the nodes whose own switch is on. lod_error > 0 (world units): also a
 * simplified set of triangles over the same vertices, each node's triangles of one texture and side rule
 * simplified on their own by meshoptimizer's edge collapse (quadric error about lod_error, under the world
 * matrices at the build); vertices are only removed, and corners that differ in any attribute (a chart's
 * border, a hard edge's normals) stay apart, so the simplified triangles keep their lightmap charts. */
lm_status lm_direct_mesh_build(lm_direct_mesh *d, const lm_scene *s, const lm_atlas *a, int shadows, float lod_error,
                               lm_error *err);
/* Re-uploads the vertices of every node whose world matrix changed since they were uploaded, and of
 * every node after a material edit (lm_scene.material_version). Returns
 * LM_MESH_MOVED when some node moved, | LM_MESH_DYNAMIC_CASTERS_MOVED or LM_MESH_STATIC_CASTERS_MOVED
 * when one of them casts shadows (a static node only moves when the caller edits it). */
enum { LM_MESH_MOVED = 1, LM_MESH_DYNAMIC_CASTERS_MOVED = 2, LM_MESH_STATIC_CASTERS_MOVED = 4 };
int lm_direct_mesh_update(lm_direct_mesh *d, const lm_scene *s);
/* Draws every group, binding its texture to unit 2 and setting uniform `has_tex` of prog (prog 0: the
 * current program, no uniform set). */
void lm_direct_mesh_draw(const lm_direct_mesh *d, unsigned prog);
/* The same with the simplified triangles (lm_direct_mesh_build's lod_error). */
void lm_direct_mesh_draw_lod(const lm_direct_mesh *d, unsigned prog);
void lm_direct_mesh_free(lm_direct_mesh *d);

#endif
