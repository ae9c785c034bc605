/* The gather proxy (issue 4, item 2): a simplified copy of the scene used only for final gathering.
 *
 * A hemicube gather averages radiance over the hemisphere, so a coarse mesh will do (Larsen &
 * Christensen: "the lowest level of detail"). Each node's triangles are simplified with meshoptimizer
 * (edge collapse, quadric error) in the node's local space, so the proxy follows moving nodes.
 * Corners are welded only where position, lightmap UV, chart and material all agree: chart borders are
 * attribute seams, which meshopt_simplify keeps (a seam vertex only slides along its seam), so every
 * proxy triangle keeps corners of a single chart and its UVs stay inside that chart's rectangle.
 * Vertices are never moved, only removed. */
#ifndef LM_PROXY_H
#define LM_PROXY_H

#include <stdint.h>

#include "../core/error.h"
#include "../scene/scene.h"
#include "charts.h"

#define LM_PROXY_DEFAULT_ERROR 0.005f
/* The proxy's error is at most this share of the atlas's texel size, whatever the scene's size. */
#define LM_PROXY_TEXEL_ERROR 0.25f

typedef struct {
    float pos[3];          /* node local space */
    float uv[2];           /* lightmap UV; -1 where the triangle has no chart */
    int32_t chart;         /* -1: no AIM (mirror, glass) */
    int32_t material;
} lm_proxy_vertex;

typedef struct {
    float error;           /* target error, x scene size, at most LM_PROXY_TEXEL_ERROR texels (0: no
                            * simplification) */
    float max_error;       /* largest error meshopt reports over the nodes, world units */
    uint32_t source_tris;  /* scene triangles it stands for */
    uint32_t vertex_count, tri_count;
    lm_proxy_vertex *vertices;
    uint32_t *tris;        /* 3 vertex indices per triangle */
    uint32_t *tri_node;    /* node per triangle */
} lm_proxy;

/* Builds the proxy of every node's triangles under the current node matrices (they set the error's
 * scale): target error `error` x scene size, at most LM_PROXY_TEXEL_ERROR x a's texel size. error <= 0
 * keeps every triangle. */
lm_status lm_proxy_build(const lm_scene *s, const lm_atlas *a, float error, lm_proxy *out, lm_error *err);
void lm_proxy_free(lm_proxy *p);
/* World position of a proxy vertex under the current matrix of `node`. */
void lm_proxy_vertex_world(const lm_scene *s, const lm_proxy *p, uint32_t node, uint32_t v, float out[3]);

#endif
