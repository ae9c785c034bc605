/* World positions, scene validation and welding of coincident vertices (hash grid, O(n)). */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../core/vecmath.h"
#include "charts_internal.h"

lm_status lmc_check_scene(const lm_scene *s, lm_error *err)
{
    if (!s)
        return lm_fail(err, LM_ERR_INVALID, "charts: no scene");
    if (s->tri_count && (!s->tris || !s->tri_node || !s->tri_material || !s->positions || !s->vertex_node))
        return lm_fail(err, LM_ERR_INVALID, "charts: scene '%s' lacks triangle or vertex arrays", s->path);
    for (uint32_t v = 0; v < s->vertex_count; v++)
        if (s->vertex_node[v] >= (uint32_t)s->node_count)
            return lm_fail(err, LM_ERR_INVALID, "charts: vertex %u has node %u out of range", v, s->vertex_node[v]);
    for (uint32_t t = 0; t < s->tri_count; t++) {
        const uint32_t *c = s->tris + 3 * (size_t)t;
        if (c[0] >= s->vertex_count || c[1] >= s->vertex_count || c[2] >= s->vertex_count)
            return lm_fail(err, LM_ERR_INVALID, "charts: triangle %u has a vertex index out of range", t);
        if (s->tri_node[t] >= (uint32_t)s->node_count)
            return lm_fail(err, LM_ERR_INVALID, "charts: triangle %u has node %u out of range", t, s->tri_node[t]);
        if (s->tri_material[t] < 0 || s->tri_material[t] >= s->material_count)
            return lm_fail(err, LM_ERR_INVALID, "charts: triangle %u has material %d out of range", t,
                           s->tri_material[t]);
    }
    return LM_OK;
}

float *lmc_world_positions(const lm_scene *s, float *size)
{
    float *pos = malloc(3 * (size_t)s->vertex_count * sizeof *pos + 1);
    if (!pos)
        return NULL;
    lm_vec3 lo = lm_v3(FLT_MAX, FLT_MAX, FLT_MAX), hi = lm_scale(lo, -1.0f);
    for (uint32_t v = 0; v < s->vertex_count; v++) {
        lm_vec3 p = lm_mat4_point(s->nodes[s->vertex_node[v]].world, lm_v3_load(s->positions + 3 * (size_t)v));
        lm_v3_store(pos + 3 * (size_t)v, p);
        if (lm_v3_finite(p)) {
            lo = lm_vmin(lo, p);
            hi = lm_vmax(hi, p);
        }
    }
    *size = lo.x <= hi.x ? lm_length(lm_sub(hi, lo)) : 0.0f;
    return pos;
}

float *lmc_world_normals(const lm_scene *s)
{
    float *nrm = malloc(3 * (size_t)s->vertex_count * sizeof *nrm + 1);
    if (!nrm)
        return NULL;
    for (uint32_t v = 0; v < s->vertex_count; v++) {
        lm_vec3 n = s->normals ? lm_v3_load(s->normals + 3 * (size_t)v) : lm_v3(0.0f, 0.0f, 0.0f);
        lm_v3_store(nrm + 3 * (size_t)v, lm_mat4_normal(s->nodes[s->vertex_node[v]].world, n));
    }
    return nrm;
}

/* Open-addressing table from (cell, node and side) to the first representative vertex in that cell; further
 * representatives of the cell are chained through next[]. */
typedef struct {
    int64_t key[4];
    uint32_t head;
} weld_slot;

typedef struct {
    weld_slot *slot;
    size_t mask;
    uint32_t *next;
} weld_grid;

static size_t slot_hash(const int64_t k[4])
{
    uint64_t h = (uint64_t)k[0] * 0x9E3779B97F4A7C15ull ^ (uint64_t)k[1] * 0xC2B2AE3D27D4EB4Full ^
                 (uint64_t)k[2] * 0x165667B19E3779F9ull ^ (uint64_t)k[3] * 0x27D4EB2F165667C5ull;
    return (size_t)(h ^ (h >> 29));
}

/* Returns the slot for key k: the one holding it, or the empty one where it would go. */
static weld_slot *find_slot(const weld_grid *g, const int64_t k[4])
{
    size_t i = slot_hash(k) & g->mask;
    while (g->slot[i].head != UINT32_MAX && memcmp(g->slot[i].key, k, sizeof g->slot[i].key) != 0)
        i = (i + 1) & g->mask;
    return &g->slot[i];
}

static int64_t cell_coord(float x, double inv_cell)
{
    double c = floor((double)x * inv_cell);
    return (int64_t)fmax(fmin(c, 4e15), -4e15);
}

/* Looks for an earlier representative within tol of p among the 2x2x2 cells p may reach: cells are
 * 2 tol wide, so a point within tol lies in p's cell or the neighbour on the side p is nearer to. */
static uint32_t find_rep(const weld_grid *g, const float *pos, const float *p, uint32_t node, double inv_cell,
                         float tol)
{
    int64_t base[3], step[3];
    for (int a = 0; a < 3; a++) {
        double f = (double)p[a] * inv_cell;
        base[a] = cell_coord(p[a], inv_cell);
        step[a] = f - floor(f) < 0.5 ? -1 : 1;
    }
    for (int i = 0; i < 8; i++) {
        int64_t k[4] = {base[0] + (i & 1 ? step[0] : 0), base[1] + (i & 2 ? step[1] : 0),
                        base[2] + (i & 4 ? step[2] : 0), node};
        for (uint32_t r = find_slot(g, k)->head; r != UINT32_MAX; r = g->next[r]) {
            const float *q = pos + 3 * (size_t)r;
            if (fabsf(q[0] - p[0]) <= tol && fabsf(q[1] - p[1]) <= tol && fabsf(q[2] - p[2]) <= tol)
                return r;
        }
    }
    return UINT32_MAX;
}

static void insert_rep(weld_grid *g, const float *p, uint32_t v, uint32_t node, double inv_cell)
{
    int64_t k[4] = {cell_coord(p[0], inv_cell), cell_coord(p[1], inv_cell), cell_coord(p[2], inv_cell), node};
    weld_slot *sl = find_slot(g, k);
    if (sl->head == UINT32_MAX)
        memcpy(sl->key, k, sizeof k);
    g->next[v] = sl->head;
    sl->head = v;
}

uint32_t *lmc_weld(const lm_scene *s, const float *pos, float tol)
{
    uint32_t n = s->vertex_count;
    uint32_t *rep = malloc((size_t)n * sizeof *rep + 1);
    weld_grid g = {0};
    size_t cap = 16;
    while (cap < 2 * (size_t)n)
        cap <<= 1;
    g.slot = malloc(cap * sizeof *g.slot);
    g.next = malloc((size_t)n * sizeof *g.next + 1);
    g.mask = cap - 1;
    if (!rep || !g.slot || !g.next) {
        free(rep);
        rep = NULL;
        goto done;
    }
    uint8_t *back = calloc((size_t)n + 1, 1);
    if (!back) {
        free(rep);
        rep = NULL;
        goto done;
    }
    /* the two sides of a split surface stay apart: each is its own single-sided sheet */
    for (uint32_t t = 0; t < s->tri_count; t++)
        if (lm_tri_is_back(s, t))
            for (int k = 0; k < 3; k++)
                back[s->tris[3 * (size_t)t + k]] = 1;
    for (size_t i = 0; i < cap; i++)
        g.slot[i].head = UINT32_MAX;
    tol = fmaxf(tol, FLT_MIN);
    double inv_cell = 1.0 / (2.0 * (double)tol);
    for (uint32_t v = 0; v < n; v++) {
        const float *p = pos + 3 * (size_t)v;
        uint32_t r = UINT32_MAX;
        if (isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2])) {
            uint32_t key = 2 * s->vertex_node[v] + back[v];
            r = find_rep(&g, pos, p, key, inv_cell, tol);
            if (r == UINT32_MAX)
                insert_rep(&g, p, v, key, inv_cell);
        }
        rep[v] = r == UINT32_MAX ? v : r;
    }
    free(back);
done:
    free(g.slot);
    free(g.next);
    return rep;
}
