/* Surfaces that continue each other across a seam (seams.h). */
#include "seams.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../core/vecmath.h"

typedef struct {
    int64_t cell[3]; /* the world position quantised to cells of twice the tolerance */
    float p[3];
    int surface;
} corner;

typedef struct {
    int a, b;
} pair;

static int cell_cmp(const int64_t *x, const int64_t *y)
{
    for (int k = 0; k < 3; k++)
        if (x[k] != y[k])
            return x[k] < y[k] ? -1 : 1;
    return 0;
}

static int by_cell(const void *x, const void *y)
{
    const corner *a = x, *b = y;
    int c = cell_cmp(a->cell, b->cell);
    return c ? c : (a->surface > b->surface) - (a->surface < b->surface);
}

static int by_pair(const void *x, const void *y)
{
    const pair *a = x, *b = y;
    return a->a != b->a ? (a->a > b->a) - (a->a < b->a) : (a->b > b->b) - (a->b < b->b);
}

/* The first corner at or after cell c in the sorted corners. */
static size_t first_in_cell(const corner *cs, size_t n, const int64_t c[3])
{
    size_t lo = 0, hi = n;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (cell_cmp(cs[mid].cell, c) < 0)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo;
}

/* Both ends of every edge on a surface's boundary (nothing of the same surface across it), in world
 * space. */
static corner *boundary_corners(const lm_scene *s, const lm_surfaces *su, double cell, size_t *count)
{
    size_t n = 0, cap = 64;
    corner *cs = malloc(cap * sizeof *cs);
    for (int i = 0; cs && i < su->surface_count; i++) {
        const lm_surface *sf = &su->surfaces[i];
        for (uint32_t j = 0; cs && j < sf->tri_count; j++)
            for (int k = 0; cs && k < 3; k++) {
                uint32_t t = sf->tris[j];
                int32_t adj = su->tri_adj ? su->tri_adj[3 * (size_t)t + (size_t)k] : -1;
                if (adj >= 0 && su->tri_surface[adj] == i)
                    continue;
                if (n + 2 > cap) {
                    corner *g = realloc(cs, 2 * cap * sizeof *cs);
                    if (!g) {
                        free(cs);
                        return NULL;
                    }
                    cs = g, cap *= 2;
                }
                for (int e = 0; e < 2; e++) {
                    uint32_t v = s->tris[3 * (size_t)t + (size_t)(k + e) % 3];
                    corner *c = &cs[n++];
                    lm_v3_store(c->p, lm_mat4_point(s->nodes[sf->node].world,
                                                    lm_v3_load(s->positions + 3 * (size_t)v)));
                    for (int a = 0; a < 3; a++)
                        c->cell[a] = (int64_t)floor((double)c->p[a] / cell);
                    c->surface = i;
                }
            }
    }
    *count = n;
    return cs;
}

/* Whether surfaces a and b may continue each other: normals within the cone, materials alike sided. */
static int continues(const lm_scene *s, const lm_surfaces *su, int a, int b)
{
    const lm_surface *x = &su->surfaces[a], *y = &su->surfaces[b];
    lm_vec3 nx = lm_v3_load(x->normal), ny = lm_v3_load(y->normal);
    float lx = lm_length(nx), ly = lm_length(ny);
    if (!(lx > 0.0f && ly > 0.0f) || lm_dot(nx, ny) < (float)cos(LM_SEAM_CONE_DEG * LM_PI / 180.0) * lx * ly)
        return 0;
    return s->materials[x->material].double_sided == s->materials[y->material].double_sided;
}

/* Every pair of corners of different surfaces within tol of each other, both ways round. */
static pair *corner_pairs(const lm_scene *s, const lm_surfaces *su, const corner *cs, size_t n, double tol,
                          size_t *count)
{
    size_t m = 0, cap = 64;
    pair *ps = malloc(cap * sizeof *ps);
    for (size_t i = 0; ps && i < n; i++)
        for (int d = 0; ps && d < 27; d++) {
            int64_t c[3] = {cs[i].cell[0] + d % 3 - 1, cs[i].cell[1] + d / 3 % 3 - 1, cs[i].cell[2] + d / 9 - 1};
            for (size_t j = first_in_cell(cs, n, c); ps && j < n && cell_cmp(cs[j].cell, c) == 0; j++) {
                const corner *x = &cs[i], *y = &cs[j];
                if (x->surface == y->surface || lm_length(lm_sub(lm_v3_load(x->p), lm_v3_load(y->p))) > tol ||
                    !continues(s, su, x->surface, y->surface))
                    continue;
                if (m == cap) {
                    pair *g = realloc(ps, 2 * cap * sizeof *ps);
                    if (!g) {
                        free(ps);
                        return NULL;
                    }
                    ps = g, cap *= 2;
                }
                ps[m++] = (pair){x->surface, y->surface};
            }
        }
    *count = m;
    return ps;
}

lm_status lm_seams_find(lm_seams *out, const lm_scene *s, const lm_surfaces *su, lm_error *err)
{
    memset(out, 0, sizeof *out);
    out->surface_count = su->surface_count;
    double tol = 1e-5 * (double)lm_scene_size(s);
    tol = tol > 0.0 ? tol : 1e-9;
    size_t n = 0, m = 0;
    corner *cs = boundary_corners(s, su, 2.0 * tol, &n);
    pair *ps = NULL;
    if (cs) {
        qsort(cs, n, sizeof *cs, by_cell);
        ps = corner_pairs(s, su, cs, n, tol, &m);
    }
    out->first = calloc((size_t)su->surface_count + 1, sizeof *out->first);
    if (ps && out->first) {
        qsort(ps, m, sizeof *ps, by_pair);
        size_t u = 0;
        for (size_t i = 0; i < m; i++)
            if (u == 0 || by_pair(&ps[u - 1], &ps[i]) != 0)
                ps[u++] = ps[i];
        out->list = malloc((u ? u : 1) * sizeof *out->list);
        for (size_t i = 0; out->list && i < u; i++) {
            out->list[i] = ps[i].b;
            out->first[ps[i].a + 1]++;
        }
        for (int i = 0; i < su->surface_count; i++)
            out->first[i + 1] += out->first[i];
    }
    free(cs);
    free(ps);
    if (!out->first || !out->list) {
        lm_seams_free(out);
        return lm_fail(err, LM_ERR_NOMEM, "AIM: no memory for the seams of %d surfaces", su->surface_count);
    }
    return LM_OK;
}

void lm_seams_free(lm_seams *sm)
{
    free(sm->first);
    free(sm->list);
    memset(sm, 0, sizeof *sm);
}
