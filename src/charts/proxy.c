/* The gather proxy (proxy.h): per-node meshoptimizer simplification with chart seams kept. */
#include "proxy.h"

#include <math.h>
#include <meshoptimizer.h>
#include <stdlib.h>
#include <string.h>

#include "../core/vecmath.h"

#define VSIZE sizeof(lm_proxy_vertex)

/* Corner k of triangle t as a weldable vertex (all fields bitwise comparable, no padding). */
static void corner_vertex(const lm_scene *s, const lm_atlas *a, uint32_t t, int k, lm_proxy_vertex *v)
{
    const float *uv = a->corner_uv + 6 * (size_t)t + 2 * k;
    int none = a->tri_chart[t] < 0 || !isfinite(uv[0]) || !isfinite(uv[1]);
    memcpy(v->pos, s->positions + 3 * (size_t)s->tris[3 * (size_t)t + k], sizeof v->pos);
    v->uv[0] = none ? -1.0f : uv[0];
    v->uv[1] = none ? -1.0f : uv[1];
    v->chart = none ? -1 : a->tri_chart[t];
    v->material = s->tri_material[t];
}

/* Largest length a unit local vector gets under the node's world matrix. */
static float node_scale(const lm_node *n)
{
    float best = 0.0f;
    for (int c = 0; c < 3; c++)
        best = fmaxf(best, lm_length(lm_v3(n->world[4 * c], n->world[4 * c + 1], n->world[4 * c + 2])));
    return best > 0.0f ? best : 1.0f;
}

/* Appends the welded (and, with abs_error > 0, simplified) triangles of one node to p. */
static int add_node(const lm_scene *s, const lm_atlas *a, int node, float abs_error, lm_proxy *p)
{
    const lm_node *nd = &s->nodes[node];
    size_t n = 3 * (size_t)nd->tri_count;
    lm_proxy_vertex *corners = malloc(VSIZE * n), *verts = malloc(VSIZE * n);
    unsigned *remap = malloc(sizeof(unsigned) * n), *idx = malloc(sizeof(unsigned) * n);
    int ok = corners && verts && remap && idx;
    if (ok) {
        for (size_t i = 0; i < n; i++)
            corner_vertex(s, a, nd->first_tri + (uint32_t)(i / 3), (int)(i % 3), &corners[i]);
        size_t unique = meshopt_generateVertexRemap(remap, NULL, n, corners, n, VSIZE);
        meshopt_remapVertexBuffer(verts, corners, n, VSIZE, remap);
        size_t m = n;
        if (abs_error > 0.0f) {
            float local = abs_error / node_scale(nd), extent = meshopt_simplifyScale(verts[0].pos, unique, VSIZE);
            float rel = 0.0f;
            m = meshopt_simplify(idx, remap, n, verts[0].pos, unique, VSIZE, 0, extent > 0.0f ? local / extent : 0.0f,
                                 0, &rel);
            p->max_error = fmaxf(p->max_error, rel * extent * node_scale(nd));
        } else {
            memcpy(idx, remap, sizeof(unsigned) * n);
        }
        size_t used = meshopt_optimizeVertexFetch(p->vertices + p->vertex_count, idx, m, verts, unique, VSIZE);
        for (size_t i = 0; i < m; i++)
            p->tris[3 * (size_t)p->tri_count + i] = p->vertex_count + idx[i];
        for (size_t t = 0; t < m / 3; t++)
            p->tri_node[p->tri_count + t] = (uint32_t)node;
        p->vertex_count += (uint32_t)used;
        p->tri_count += (uint32_t)(m / 3);
    }
    free(corners), free(verts), free(remap), free(idx);
    return ok;
}

lm_status lm_proxy_build(const lm_scene *s, const lm_atlas *a, float error, lm_proxy *out, lm_error *err)
{
    memset(out, 0, sizeof *out);
    out->error = error > 0.0f ? error : 0.0f;
    out->source_tris = s->tri_count;
    size_t cap = s->tri_count ? s->tri_count : 1;
    out->vertices = malloc(VSIZE * 3 * cap);
    out->tris = malloc(sizeof(uint32_t) * 3 * cap);
    out->tri_node = malloc(sizeof(uint32_t) * cap);
    int ok = out->vertices && out->tris && out->tri_node;
    /* at most a share of a texel: on a level whose size is its open ground (truck-town's 2 km) the share of
     * its size was 10 m, and the hemicube saw a town of blocks (docs/gather.md, "The gather proxy") */
    float abs_error = fminf(out->error * lm_scene_size(s), LM_PROXY_TEXEL_ERROR * a->texel_size);
    for (int i = 0; ok && i < s->node_count; i++)
        if (s->nodes[i].tri_count)
            ok = add_node(s, a, i, abs_error, out);
    if (!ok) {
        lm_proxy_free(out);
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for the gather proxy", s->path);
    }
    return LM_OK;
}

void lm_proxy_free(lm_proxy *p)
{
    free(p->vertices);
    free(p->tris);
    free(p->tri_node);
    memset(p, 0, sizeof *p);
}

void lm_proxy_vertex_world(const lm_scene *s, const lm_proxy *p, uint32_t node, uint32_t v, float out[3])
{
    lm_v3_store(out, lm_mat4_point(s->nodes[node].world, lm_v3_load(p->vertices[v].pos)));
}
