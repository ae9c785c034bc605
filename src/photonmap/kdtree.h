/* A balanced 3-d kd-tree over points, for the per-surface photon maps of Larsen & Christensen
 * (section 3: "Kd-trees are fast for N-nearest neighbor queries").
 *
 * Layout: arrays in tree order, no pointers. The subtree over the range [lo, hi) is split at
 * mid = (lo + hi) / 2 on the axis of the range's largest extent: [lo, mid) holds keys <= the key of point
 * mid, [mid, hi) keys >= it, so the splitting plane is point mid's coordinate. Ranges of at most
 * LM_KDTREE_LEAF points are leaves ("buckets"); every point lies in one. Queries read the positions as
 * three coordinate arrays (a leaf is a short run of each, scanned by a loop the compiler vectorises).
 * Building selects medians in place (three-way quickselect, linear in the range even when all keys are
 * equal), so it is O(n log n) and allocates only the arrays (reused by later builds).
 *
 * Queries are read-only and may run from several threads at once. Results are deterministic: the same
 * points in the same order give the same tree and the same answers. */
#ifndef LM_KDTREE_H
#define LM_KDTREE_H

#include <stdint.h>
#include <stdio.h>

#include "../core/error.h"

#define LM_KDTREE_LEAF 16u         /* ranges this small are leaves, scanned, not split */
#define LM_KDTREE_MAX_POINTS (1u << 30)

typedef struct {
    float p[3];
    uint32_t index;               /* the caller's index of the point */
} lm_kd_node;

typedef struct {
    lm_kd_node *nodes;            /* the points in tree order (built in place) */
    float *x, *y, *z;             /* their coordinates, LM_KDTREE_LEAF zero slots of padding at the end */
    uint32_t *index;              /* their caller's indices */
    float *split;                 /* at mid of each split range: the splitting coordinate ... */
    uint8_t *axis;                /* ... and its axis */
    uint32_t count, capacity;
} lm_kdtree;

void lm_kdtree_init(lm_kdtree *t);
void lm_kdtree_free(lm_kdtree *t);
/* Builds the tree over count points (xyz, `stride` floats apart, stride >= 3); index i of the answers is
 * the i-th input point. count may be 0. Non-finite coordinates are an error (LM_ERR_INVALID), as is
 * count > LM_KDTREE_MAX_POINTS. */
lm_status lm_kdtree_build(lm_kdtree *t, const float *points, size_t stride, uint32_t count, lm_error *err);

/* The n nearest points to q (Euclidean). Writes min(n, count) indices and their squared distances to
 * out_index / out_d2 (caller's arrays of n entries, not in sorted order: for n <= 256 in the search's
 * leaf order, a function of the tree and q) and returns how many. *r2 (if non-NULL) receives the
 * squared distance of the farthest one returned (0 if none). Among points tied
 * at the n-th distance, the lower caller's indices are returned, so the answer does not depend on the
 * tree's shape. No allocation. */
uint32_t lm_kdtree_nearest(const lm_kdtree *t, const float q[3], uint32_t n, uint32_t *out_index, float *out_d2,
                           float *r2);

/* The same among the points with squared distance <= max_d2 only (fewer than n when fewer lie there,
 * and then all of them): a bound known in advance (from a nearby query) spares the search. When it
 * returns n, the answer is exactly lm_kdtree_nearest's. */
uint32_t lm_kdtree_nearest_within(const lm_kdtree *t, const float q[3], uint32_t n, float max_d2,
                                  uint32_t *out_index, float *out_d2, float *r2);

/* Runs of nearby queries (a row of texels): the last query and its n-th squared distance bound the next
 * query's search (its n-th distance is within the step between them of the last one). */
typedef struct {
    int valid;                    /* 0: no last query (the next one searches unbounded) */
    float q[3], r2;
} lm_kdtree_hint;

/* lm_kdtree_nearest's answer, searched with the hint, which then holds this query. For n <= 256 the
 * answer is listed in the same order whatever the hint (the search's leaf order), so that sums over it
 * are the same for any run of queries. */
uint32_t lm_kdtree_nearest_hinted(const lm_kdtree *t, lm_kdtree_hint *h, const float q[3], uint32_t n,
                                  uint32_t *out_index, float *out_d2, float *r2);

/* Calls visit(ctx, index, d2) for every point with squared distance d2 <= r2 from q, in a deterministic
 * order; returns how many. */
typedef void (*lm_kdtree_visit)(void *ctx, uint32_t index, float d2);
uint32_t lm_kdtree_radius(const lm_kdtree *t, const float q[3], float r2, lm_kdtree_visit visit, void *ctx);

/* Build and 100-nearest query times at 300, 500, 1000 and 2000 uniform random points (fixed seed,
 * medians of several runs), next to Larsen & Christensen's Table 1 (2004). */
typedef struct {
    uint32_t points;
    double build_ms, query_ms;           /* ours: one build, one 100-nearest query */
    double paper_build_ms, paper_query_ms;
} lm_kdtree_bench_row;

#define LM_KDTREE_BENCH_ROWS 4
void lm_kdtree_bench_run(lm_kdtree_bench_row rows[LM_KDTREE_BENCH_ROWS]);
/* Runs the benchmark and prints it as a table with the speed-up over the paper. */
void lm_kdtree_bench(FILE *out);

#endif
