/* Triangle adjacency through OpenMesh's half-edge structure (mesh_topology.cpp is the only C++ file of
 * src/charts). Vertex indices must already be welded (one index per distinct position). */
#ifndef LM_MESH_TOPOLOGY_H
#define LM_MESH_TOPOLOGY_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
    uint32_t nonmanifold_edges; /* distinct edges with more than two triangles */
    uint32_t refused_faces;     /* triangles OpenMesh could not add (complex edge or vertex) */
} lm_topology_stats;

/* tri_vertex: 3 welded vertex ids per triangle (< vertex_count); use[t] == 0 leaves triangle t out.
 * Writes adj[3 t + k]: the triangle across edge (corner k, corner k+1), or -1 on a boundary, a
 * non-manifold edge, a refused triangle or a triangle left out. nm_tri (may be NULL) receives, for each
 * non-manifold edge, one triangle that holds it (stats->nonmanifold_edges entries; caller sizes it
 * tri_count). Returns 0 on success, -1 if memory ran out. */
int lm_mesh_topology(uint32_t vertex_count, uint32_t tri_count, const uint32_t *tri_vertex,
                     const unsigned char *use, int32_t *adj, uint32_t *nm_tri, lm_topology_stats *stats);

#ifdef __cplusplus
}
#endif

#endif
