/* Which surfaces continue each other across a seam (issue 33, item 2), so that an AIM estimate near a
 * surface's boundary can also use the photons that landed just across it.
 *
 * Each surface keeps its own kd-tree ("a structure belonging to the surface that was hit"), so near its
 * boundary an estimate sees only half a disc of photons. The boundary correction (aim.h) divides by the
 * half disc's area, which is right where the light is even across the disc; where it is not (a spot on
 * the vertex where four floor tiles meet) the surface reads what its own side of the disc averages, and
 * the tiles lost 43% of their light. A floor in a real level is many surfaces (materials, the normal
 * cone, modular pieces as separate nodes), so the seams are everywhere.
 *
 * Surfaces S and T continue each other when both have a boundary vertex at the same world position
 * (within 1e-5 of the scene's size, at load: triangles of different nodes are never welded, so this is
 * found geometrically), their mean normals lie within the cone of each other, and their materials are
 * alike sided. Whether their photons may be mixed is decided again at each refresh: only within one
 * node, or between two nodes that do not move (lm_node_moves), so that T's hits map into S's local space
 * by the current world matrices.
 *
 * Layout: compressed rows, first[S] .. first[S + 1] index list[] with S's continuing surfaces in
 * ascending order. Memory: 4 bytes per surface and per pair. Cost at load: O(B log B) for B boundary
 * vertices. Deterministic; read-only afterwards (safe from several threads). Errors: out of memory. */
#ifndef LM_SEAMS_H
#define LM_SEAMS_H

#include <stdint.h>

#include "../charts/charts.h"
#include "../core/error.h"
#include "../scene/scene.h"

#define LM_SEAM_CONE_DEG 30.0 /* the largest angle between continuing surfaces' normals (the charts' cone) */

typedef struct {
    int surface_count;
    uint32_t *first; /* surface_count + 1 */
    int *list;
} lm_seams;

lm_status lm_seams_find(lm_seams *out, const lm_scene *s, const lm_surfaces *su, lm_error *err);
void lm_seams_free(lm_seams *sm);

#endif
