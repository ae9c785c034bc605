/* The Embree scene used for every ray lmgi traces.
 *
 * Static nodes' triangles go, in world space, into one Embree scene placed in the top level as an
 * instance with the identity. Each dynamic node gets its own Embree scene in node-local space, placed
 * in the top level as an instance; moving the node is one transform update and one top-level commit,
 * which rebuilds only the small tree over the instances: O(1) in the scene's triangle count.
 * Hits report the node, the scene triangle id, its surface and a world-space geometric normal. */
#ifndef LM_RT_SCENE_H
#define LM_RT_SCENE_H

#include <stdint.h>

#include "../charts/charts.h"
#include "../core/error.h"
#include "../scene/scene.h"

typedef struct lm_rt lm_rt;

typedef struct {
    float t;           /* ray parameter of the hit */
    int node;          /* scene node */
    uint32_t tri;      /* scene triangle id */
    int surface;       /* surface id, -1 for specular triangles */
    float u, v;        /* barycentrics of the hit on the triangle (Embree's: p = (1-u-v) v0 + u v1 + v v2) */
    float ng[3];       /* world-space geometric normal, unit length, as wound in the file */
    const float *nmat; /* the hit node's normal matrix (lm_mat4_normal_matrix of its world matrix as
                        * the BVH has it), valid until the node moves */
    const float *ns;   /* a flat static triangle's shading normal (its three vertex normals equal), as
                        * lm_shading_normal_of makes it; NULL for the others */
} lm_rt_hit;

/* Builds the BVHs from the scene's current node transforms. surfaces may be NULL (surface = -1). */
lm_status lm_rt_build(const lm_scene *s, const lm_surfaces *su, lm_rt **out, lm_error *err);
void lm_rt_free(lm_rt *rt);
/* Builds the BVHs again from the scene as it is now, in place (rt's address stays, so whoever holds it
 * keeps it): after nodes switched between static and dynamic. As lm_rt_build's cost; on a failure rt is
 * as it was. Not while another thread traces rays in rt. */
lm_status lm_rt_rebuild(lm_rt *rt, lm_error *err);

/* Moves dynamic node `node` to world matrix `world` and commits the top level. Fails for a static
 * node, an out-of-range id or a non-finite matrix, naming the node. */
lm_status lm_rt_set_node_transform(lm_rt *rt, int node, const float world[16], lm_error *err);
/* Copies every dynamic node's world matrix from the scene, then commits the top level once. */
lm_status lm_rt_sync_transforms(lm_rt *rt, const lm_scene *s, lm_error *err);
/* How many times the top level was committed (built, rebuilt, a node moved or synced): edits staged in
 * a batch commit it once (update/edits.h), which tests hold them to. */
uint64_t lm_rt_top_commits(const lm_rt *rt);
/* How many times lm_rt_rebuild built the BVHs again (nodes switched dynamic or static: one a batch). */
uint64_t lm_rt_rebuilds(const lm_rt *rt);

/* Closest hit along org + t dir, t in (tnear, tfar). Returns 1 on a hit. dir need not be unit length. */
int lm_rt_intersect(const lm_rt *rt, const float org[3], const float dir[3], float tnear, float tfar,
                    lm_rt_hit *hit);
/* Up to 16 closest-hit queries (rays i = (org + 3i, dir + 3i), t in (0, inf)) as one Embree packet, for
 * rays that travel together (a light's photons towards one generator): hit[i] = 1 and hits[i] as
 * lm_rt_intersect gives it where ray i hits, hit[i] = 0 where it misses or is not one Embree takes. n in
 * 1..16. */
void lm_rt_intersect16(const lm_rt *rt, const float *org, const float *dir, int n, lm_rt_hit *hits, int *hit);
/* 1 if anything blocks the segment (tnear, tfar). */
int lm_rt_occluded(const lm_rt *rt, const float org[3], const float dir[3], float tnear, float tfar);
/* 1 if other geometry lies within `cover` straight out from p along unit n (the ray leaving p + lift n):
 * that side of p is hidden under something, a box on the floor or a lamp just under a ceiling, rather than
 * dark (photons' cover distance, computed direct light, the AIM's visibility test). 0 when cover <= 0. */
int lm_rt_covered(const lm_rt *rt, const float p[3], const float n[3], float lift, float cover);
/* Up to 8 segments from one origin as one Embree packet: blocked[i] = 1 if anything lies on
 * org + t dir_i (dir: 3 floats each), t in (0, tfar[i]). n in 1..8. */
void lm_rt_occluded8(const lm_rt *rt, const float org[3], const float *dir, const float *tfar, int n, int *blocked);

/* The benchmark's baseline: n closest-hit queries straight through rtcIntersect1 (no hit decoding),
 * rays i = (org + 3i, dir + 3i), spread over the OpenMP threads. Returns the number of hits. */
uint64_t lm_rt_raw_intersect(const lm_rt *rt, const float *org, const float *dir, uint32_t n);

/* Sets flush-to-zero and denormals-are-zero; Embree wants it in every thread that traces. */
void lm_rt_thread_init(void);

/* Counts, for reports. */
uint32_t lm_rt_static_triangle_count(const lm_rt *rt);

#endif
