/* Surface segmentation: region growing over welded triangle adjacency within a normal cone, then
 * merging of tiny fragments into their most similar neighbour. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../core/log.h"
#include "charts_internal.h"
#include "mesh_topology.h"

/* Rechecks of cone-rejected boundary triangles against the grown region's mean normal. */
#define MAX_RECHECK_PASSES 8
#define EJECT_ROUNDS 2
#define EJECT_SWEEPS 3
/* Surfaces of at most FEW_TRIS triangles also count as fragments up to FEW_TRIS_AREA_FACTOR times
 * min_fragment_area, but merge only into a neighbour within FEW_TRIS_CONE cones (a narrow strip at a
 * right angle, like the side of a slab, stays a surface of its own). */
#define FEW_TRIS 2
#define FEW_TRIS_AREA_FACTOR 10.0
#define FEW_TRIS_CONE 2.0

typedef struct {
    const lm_scene *s;
    const lm_surface_options *o;
    float *pos;
    float size;
    uint32_t *rep;
    double *area;         /* per triangle, world */
    double *nrm;          /* per triangle, unit normal (3) */
    unsigned char *usable; /* non-degenerate */
    int32_t *adj;
    int *label;
    double *node_area;
    /* regions */
    int region_count, region_cap;
    double *r_area, *r_sum; /* area and area-weighted normal sum (3) per region */
    int *r_first, *r_tris;  /* CSR triangle lists */
} seg_ctx;

void lm_surface_options_default(lm_surface_options *o)
{
    o->cone_deg = 30.0f;
    o->min_fragment_area = 1e-3f;
    o->min_surface_area = 0.0f;
    o->strict = 0;
}

double lmc_tri_area(const lm_scene *s, const float *pos, uint32_t t, double n[3])
{
    const uint32_t *c = s->tris + 3 * (size_t)t;
    const float *a = pos + 3 * (size_t)c[0], *b = pos + 3 * (size_t)c[1], *d = pos + 3 * (size_t)c[2];
    double u[3] = {(double)b[0] - a[0], (double)b[1] - a[1], (double)b[2] - a[2]};
    double v[3] = {(double)d[0] - a[0], (double)d[1] - a[1], (double)d[2] - a[2]};
    n[0] = u[1] * v[2] - u[2] * v[1];
    n[1] = u[2] * v[0] - u[0] * v[2];
    n[2] = u[0] * v[1] - u[1] * v[0];
    return 0.5 * sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
}

static int is_specular(const lm_scene *s, uint32_t t)
{
    lm_material_class c = s->materials[s->tri_material[t]].cls;
    return lm_material_is_specular(c);
}

/* Warns about (or, strict, fails on) per-node counts of a geometry problem. */
static lm_status report_per_node(const seg_ctx *c, const uint32_t *count, const char *what, lm_error *err)
{
    for (int n = 0; n < c->s->node_count; n++) {
        if (!count[n])
            continue;
        if (c->o->strict)
            return lm_fail(err, LM_ERR_INVALID, "charts: node '%s' of '%s' has %u %s (strict mode)",
                           c->s->nodes[n].name, c->s->path, count[n], what);
        lm_warn("charts: node '%s' has %u %s", c->s->nodes[n].name, count[n], what);
    }
    return LM_OK;
}

static lm_status tri_geometry(seg_ctx *c, lm_surfaces *out, lm_error *err)
{
    const lm_scene *s = c->s;
    double min_area = LMC_DEGENERATE_AREA * (double)c->size * (double)c->size;
    uint32_t *bad = calloc((size_t)s->node_count + 1, sizeof *bad);
    if (!bad)
        return lm_fail(err, LM_ERR_NOMEM, "charts: out of memory");
    for (uint32_t t = 0; t < s->tri_count; t++) {
        const uint32_t *v = s->tris + 3 * (size_t)t;
        double *n = c->nrm + 3 * (size_t)t;
        double a = lmc_tri_area(s, c->pos, t, n);
        uint32_t r0 = c->rep[v[0]], r1 = c->rep[v[1]], r2 = c->rep[v[2]];
        int degenerate = !(a > min_area) || !isfinite(a) || r0 == r1 || r1 == r2 || r0 == r2;
        c->usable[t] = !degenerate;
        c->area[t] = degenerate ? 0.0 : a;
        for (int k = 0; k < 3; k++)
            n[k] = degenerate ? 0.0 : n[k] / (2.0 * a);
        if (degenerate) {
            bad[s->tri_node[t]]++;
            out->degenerate_tris++;
        } else {
            c->node_area[s->tri_node[t]] += a;
        }
    }
    lm_status st = report_per_node(c, bad, "degenerate (zero-area) triangles without lightmap texels", err);
    free(bad);
    return st;
}

/* Adjacency through OpenMesh on welded vertex ids, and the non-manifold edge count. */
static lm_status topology(seg_ctx *c, lm_surfaces *out, lm_error *err)
{
    const lm_scene *s = c->s;
    uint32_t *id = malloc((size_t)s->vertex_count * sizeof *id + 1);
    uint32_t *tv = malloc(3 * (size_t)s->tri_count * sizeof *tv + 1);
    uint32_t *nm_tri = malloc((size_t)s->tri_count * sizeof *nm_tri + 1);
    uint32_t *bad = calloc((size_t)s->node_count + 1, sizeof *bad);
    lm_status st = LM_OK;
    if (!id || !tv || !nm_tri || !bad) {
        st = lm_fail(err, LM_ERR_NOMEM, "charts: out of memory");
        goto done;
    }
    uint32_t n = 0;
    for (uint32_t v = 0; v < s->vertex_count; v++)
        id[v] = c->rep[v] == v ? n++ : UINT32_MAX;
    for (size_t i = 0; i < 3 * (size_t)s->tri_count; i++)
        tv[i] = id[c->rep[s->tris[i]]];
    lm_topology_stats ts;
    if (lm_mesh_topology(n, s->tri_count, tv, c->usable, c->adj, nm_tri, &ts) != 0) {
        st = lm_fail(err, LM_ERR_NOMEM, "charts: out of memory in mesh topology");
        goto done;
    }
    out->nonmanifold_edges = ts.nonmanifold_edges;
    for (uint32_t i = 0; i < ts.nonmanifold_edges; i++)
        bad[s->tri_node[nm_tri[i]]]++;
    st = report_per_node(c, bad, "non-manifold edges (shared by more than two triangles)", err);
done:
    free(id);
    free(tv);
    free(nm_tri);
    free(bad);
    return st;
}

static int add_region(seg_ctx *c)
{
    if (c->region_count == c->region_cap) {
        int cap = c->region_cap ? 2 * c->region_cap : 64;
        double *a = realloc(c->r_area, (size_t)cap * sizeof *a);
        if (a)
            c->r_area = a;
        double *m = realloc(c->r_sum, 3 * (size_t)cap * sizeof *m);
        if (m)
            c->r_sum = m;
        if (!a || !m)
            return -1;
        c->region_cap = cap;
    }
    int r = c->region_count++;
    c->r_area[r] = 0.0;
    c->r_sum[3 * r] = c->r_sum[3 * r + 1] = c->r_sum[3 * r + 2] = 0.0;
    return r;
}

static void assign(seg_ctx *c, uint32_t t, int r)
{
    c->label[t] = r;
    c->r_area[r] += c->area[t];
    for (int k = 0; k < 3; k++)
        c->r_sum[3 * r + k] += c->area[t] * c->nrm[3 * (size_t)t + k];
}

static int same_kind(const seg_ctx *c, uint32_t a, uint32_t b)
{
    return c->s->tri_node[a] == c->s->tri_node[b] && c->s->tri_material[a] == c->s->tri_material[b];
}

static int within_cone(const seg_ctx *c, uint32_t t, int r, double cos_cone)
{
    const double *m = c->r_sum + 3 * r, *n = c->nrm + 3 * (size_t)t;
    double l = sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
    return l <= 0.0 || (n[0] * m[0] + n[1] * m[1] + n[2] * m[2]) >= cos_cone * l;
}

typedef struct {
    uint32_t *queue, *rejected;
    int *stamp; /* region that last put a triangle on the rejected list */
} grow_buf;

static void unassign(seg_ctx *c, uint32_t t, int r)
{
    c->label[t] = -1;
    c->r_area[r] -= c->area[t];
    for (int k = 0; k < 3; k++)
        c->r_sum[3 * r + k] -= c->area[t] * c->nrm[3 * (size_t)t + k];
}

/* The mean normal drifts while a region grows, so triangles accepted early (the seed too) can end up
 * outside the cone around the final mean: they leave the region and seed regions of their own later. */
static void eject_outliers(seg_ctx *c, const uint32_t *tris, size_t n, int r, double cos_cone)
{
    size_t left = n;
    for (int round = 0; round < EJECT_ROUNDS; round++)
        for (size_t i = 0; i < n && left > 1; i++)
            if (c->label[tris[i]] == r && !within_cone(c, tris[i], r, cos_cone)) {
                unassign(c, tris[i], r);
                left--;
            }
}

/* Breadth-first growth from seed; triangles rejected by the cone are rechecked against the region's
 * mean once the front stops (the mean settles as the region grows, e.g. on a bumpy floor). */
static void grow(seg_ctx *c, grow_buf *b, uint32_t seed, int r, double cos_cone, int eject)
{
    size_t head = 0, tail = 0, nrej = 0;
    assign(c, seed, r);
    b->queue[tail++] = seed;
    for (int pass = 0;; pass++) {
        while (head < tail) {
            uint32_t t = b->queue[head++];
            for (int k = 0; k < 3; k++) {
                int32_t nb = c->adj[3 * (size_t)t + k];
                if (nb < 0 || c->label[nb] >= 0 || !c->usable[nb] || is_specular(c->s, (uint32_t)nb) ||
                    !same_kind(c, t, (uint32_t)nb))
                    continue;
                if (within_cone(c, (uint32_t)nb, r, cos_cone)) {
                    assign(c, (uint32_t)nb, r);
                    b->queue[tail++] = (uint32_t)nb;
                } else if (b->stamp[nb] != r) {
                    b->stamp[nb] = r;
                    b->rejected[nrej++] = (uint32_t)nb;
                }
            }
        }
        if (pass == MAX_RECHECK_PASSES)
            break;
        size_t keep = 0, before = tail;
        for (size_t i = 0; i < nrej; i++) {
            uint32_t t = b->rejected[i];
            if (c->label[t] >= 0)
                continue;
            if (within_cone(c, t, r, cos_cone)) {
                assign(c, t, r);
                b->queue[tail++] = t;
            } else {
                b->rejected[keep++] = t;
            }
        }
        nrej = keep;
        if (tail == before)
            break;
    }
    if (eject)
        eject_outliers(c, b->queue, tail, r, cos_cone);
}

static lm_status grow_regions(seg_ctx *c, lm_error *err)
{
    const lm_scene *s = c->s;
    grow_buf b;
    b.queue = malloc((size_t)s->tri_count * sizeof *b.queue + 1);
    b.rejected = malloc((size_t)s->tri_count * sizeof *b.rejected + 1);
    b.stamp = malloc((size_t)s->tri_count * sizeof *b.stamp + 1);
    lm_status st = LM_OK;
    if (!b.queue || !b.rejected || !b.stamp) {
        st = lm_fail(err, LM_ERR_NOMEM, "charts: out of memory");
        goto done;
    }
    double cos_cone = cos((double)c->o->cone_deg * M_PI / 180.0);
    for (uint32_t t = 0; t < s->tri_count; t++) {
        c->label[t] = -1;
        b.stamp[t] = -1;
    }
    /* Repeated sweeps pick up ejected triangles; the last sweeps eject nothing, so the loop ends. */
    for (int grown = 1, sweep = 0; grown; sweep++) {
        grown = 0;
        for (uint32_t t = 0; t < s->tri_count; t++) {
            if (c->label[t] >= 0 || !c->usable[t] || is_specular(s, t))
                continue;
            int r = add_region(c);
            if (r < 0) {
                st = lm_fail(err, LM_ERR_NOMEM, "charts: out of memory");
                goto done;
            }
            grow(c, &b, t, r, cos_cone, sweep < EJECT_SWEEPS);
            grown = 1;
        }
    }
done:
    free(b.queue);
    free(b.rejected);
    free(b.stamp);
    return st;
}

/* Triangle lists per region (CSR, ascending triangle ids). */
static lm_status region_lists(seg_ctx *c, lm_error *err)
{
    c->r_first = calloc((size_t)c->region_count + 2, sizeof *c->r_first);
    c->r_tris = malloc((size_t)c->s->tri_count * sizeof *c->r_tris + 1);
    if (!c->r_first || !c->r_tris)
        return lm_fail(err, LM_ERR_NOMEM, "charts: out of memory");
    for (uint32_t t = 0; t < c->s->tri_count; t++)
        if (c->label[t] >= 0)
            c->r_first[c->label[t] + 2]++;
    for (int r = 0; r < c->region_count; r++)
        c->r_first[r + 2] += c->r_first[r + 1];
    for (uint32_t t = 0; t < c->s->tri_count; t++)
        if (c->label[t] >= 0)
            c->r_tris[c->r_first[c->label[t] + 1]++] = (int)t;
    return LM_OK;
}

static int uf_find(int *parent, int r)
{
    while (parent[r] != r) {
        parent[r] = parent[parent[r]];
        r = parent[r];
    }
    return r;
}

/* 0: no fragment; 1: tiny (merges into any neighbour); 2: a few small triangles (merges only into a
 * neighbour of similar normal). */
static int fragment_kind(const seg_ctx *c, int r, int tri_count, uint32_t node)
{
    double limit = (double)c->o->min_fragment_area * c->node_area[node];
    if (c->r_area[r] < limit || c->r_area[r] < (double)c->o->min_surface_area)
        return 1;
    return tri_count <= FEW_TRIS && c->r_area[r] < FEW_TRIS_AREA_FACTOR * limit ? 2 : 0;
}

static double mean_dot(const seg_ctx *c, int a, int b)
{
    const double *p = c->r_sum + 3 * a, *q = c->r_sum + 3 * b;
    double lp = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]), lq = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
    return lp > 0.0 && lq > 0.0 ? (p[0] * q[0] + p[1] * q[1] + p[2] * q[2]) / (lp * lq) : -2.0;
}

/* The neighbouring region (by root) of the same node and material whose mean normal is closest. */
static int best_neighbour(const seg_ctx *c, int *parent, int r, int root)
{
    int best = -1;
    double best_dot = -3.0;
    for (int i = c->r_first[r]; i < c->r_first[r + 1]; i++) {
        uint32_t t = (uint32_t)c->r_tris[i];
        for (int k = 0; k < 3; k++) {
            int32_t nb = c->adj[3 * (size_t)t + k];
            if (nb < 0 || c->label[nb] < 0 || !same_kind(c, t, (uint32_t)nb))
                continue;
            int o = uf_find(parent, c->label[nb]);
            if (o == root)
                continue;
            double d = mean_dot(c, root, o);
            if (d > best_dot || (d == best_dot && o < best)) {
                best_dot = d;
                best = o;
            }
        }
    }
    return best;
}

typedef struct {
    double area;
    int r;
} frag_key;

static int cmp_frag(const void *a, const void *b)
{
    const frag_key *x = a, *y = b;
    if (x->area != y->area)
        return x->area < y->area ? -1 : 1;
    return (x->r > y->r) - (x->r < y->r);
}

typedef struct {
    uint32_t node, material, morton;
    int root;
} scatter_key;

static int cmp_scatter(const void *a, const void *b)
{
    const scatter_key *x = a, *y = b;
    if (x->node != y->node)
        return x->node < y->node ? -1 : 1;
    if (x->material != y->material)
        return x->material < y->material ? -1 : 1;
    if (x->morton != y->morton)
        return x->morton < y->morton ? -1 : 1;
    return (x->root > y->root) - (x->root < y->root);
}

/* Bits of v (10 used) spread to every third bit. */
static uint32_t spread3(uint32_t v)
{
    v &= 0x3ff;
    v = (v | (v << 16)) & 0x030000ff;
    v = (v | (v << 8)) & 0x0300f00f;
    v = (v | (v << 4)) & 0x030c30c3;
    return (v | (v << 2)) & 0x09249249;
}

static void unite(seg_ctx *c, int *parent, int from, int to)
{
    parent[from] = to;
    c->r_area[to] += c->r_area[from];
    for (int k = 0; k < 3; k++)
        c->r_sum[3 * to + k] += c->r_sum[3 * from + k];
}

/* Regions still below min_surface_area after the merge across edges have no neighbour of their node and
 * material (a table's separate legs, a bookshelf's books): they are merged with the nearby ones of the
 * same node and material, walking them in Morton order of their centroids, until each group reaches the
 * area. Such a surface is no longer connected; its charts are still split by connectivity. */
static lm_status merge_scattered(seg_ctx *c, int *parent, lm_error *err)
{
    int n = c->region_count, m = 0;
    double *cen = calloc(3 * (size_t)n + 1, sizeof *cen), lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
    scatter_key *k = malloc((size_t)n * sizeof *k + 1);
    if (!cen || !k) {
        free(cen);
        free(k);
        return lm_fail(err, LM_ERR_NOMEM, "charts: out of memory");
    }
    for (int r = 0; r < n; r++) /* area-weighted centroids, per root */
        for (int i = c->r_first[r], root = uf_find(parent, r); i < c->r_first[r + 1]; i++) {
            const uint32_t *v = c->s->tris + 3 * (size_t)c->r_tris[i];
            for (int a = 0; a < 3; a++)
                cen[3 * root + a] += c->area[c->r_tris[i]] / 3.0 *
                                     ((double)c->pos[3 * v[0] + a] + c->pos[3 * v[1] + a] + c->pos[3 * v[2] + a]);
        }
    for (int r = 0; r < n; r++) {
        if (uf_find(parent, r) != r || !(c->r_area[r] < (double)c->o->min_surface_area) || !(c->r_area[r] > 0.0))
            continue;
        uint32_t t = (uint32_t)c->r_tris[c->r_first[r]];
        k[m++] = (scatter_key){c->s->tri_node[t], c->s->tri_material[t], 0, r};
        for (int a = 0; a < 3; a++) {
            cen[3 * r + a] /= c->r_area[r];
            lo[a] = fmin(lo[a], cen[3 * r + a]);
            hi[a] = fmax(hi[a], cen[3 * r + a]);
        }
    }
    for (int i = 0; i < m; i++) {
        uint32_t code = 0;
        for (int a = 0; a < 3; a++) {
            double f = hi[a] > lo[a] ? (cen[3 * k[i].root + a] - lo[a]) / (hi[a] - lo[a]) : 0.0;
            code |= spread3((uint32_t)fmin(fmax(f * 1023.0, 0.0), 1023.0)) << a;
        }
        k[i].morton = code;
    }
    qsort(k, (size_t)m, sizeof *k, cmp_scatter);
    for (int i = 0, cur = -1, done = -1; i < m; i++) {
        int same = i > 0 && k[i].node == k[i - 1].node && k[i].material == k[i - 1].material;
        if (!same)
            cur = done = -1;
        if (cur >= 0)
            unite(c, parent, k[i].root, cur);
        else
            cur = k[i].root;
        int last = i + 1 == m || k[i + 1].node != k[i].node || k[i + 1].material != k[i].material;
        if (c->r_area[cur] >= (double)c->o->min_surface_area)
            done = cur, cur = -1;
        else if (last && done >= 0) /* the group's remainder joins its last full one */
            unite(c, parent, cur, done);
    }
    free(cen);
    free(k);
    return LM_OK;
}

/* Merges fragments, smallest first, into the adjacent region with the most similar normal. */
static lm_status merge_fragments(seg_ctx *c, lm_error *err)
{
    int n = c->region_count, nf = 0;
    int *parent = malloc((size_t)n * sizeof *parent + 1);
    frag_key *frag = malloc((size_t)n * sizeof *frag + 1);
    if (!parent || !frag) {
        free(parent);
        free(frag);
        return lm_fail(err, LM_ERR_NOMEM, "charts: out of memory");
    }
    double few_cos = cos(fmin(FEW_TRIS_CONE * (double)c->o->cone_deg, 180.0) * M_PI / 180.0);
    for (int r = 0; r < n; r++) {
        parent[r] = r;
        uint32_t node = c->s->tri_node[c->r_tris[c->r_first[r]]];
        if (fragment_kind(c, r, c->r_first[r + 1] - c->r_first[r], node))
            frag[nf++] = (frag_key){c->r_area[r], r};
    }
    qsort(frag, (size_t)nf, sizeof *frag, cmp_frag);
    for (int i = 0; i < nf; i++) {
        int r = frag[i].r, root = uf_find(parent, r);
        uint32_t node = c->s->tri_node[c->r_tris[c->r_first[r]]];
        int kind = fragment_kind(c, root, root == r ? c->r_first[r + 1] - c->r_first[r] : FEW_TRIS + 1, node);
        if (!kind)
            continue;
        int to = best_neighbour(c, parent, r, root);
        if (to < 0 || (kind == 2 && mean_dot(c, root, to) < few_cos))
            continue;
        unite(c, parent, root, to);
    }
    lm_status st = c->o->min_surface_area > 0.0f ? merge_scattered(c, parent, err) : LM_OK;
    for (uint32_t t = 0; t < c->s->tri_count; t++)
        if (c->label[t] >= 0)
            c->label[t] = uf_find(parent, c->label[t]);
    free(parent);
    free(frag);
    return st;
}

/* Numbers the merged regions by their first triangle and fills the surface array. */
static lm_status emit(seg_ctx *c, lm_surfaces *out, lm_error *err)
{
    const lm_scene *s = c->s;
    int *id = malloc((size_t)c->region_count * sizeof *id + 1);
    out->tri_surface = malloc((size_t)s->tri_count * sizeof *out->tri_surface + 1);
    if (!id || !out->tri_surface) {
        free(id);
        return lm_fail(err, LM_ERR_NOMEM, "charts: out of memory");
    }
    for (int r = 0; r < c->region_count; r++)
        id[r] = -1;
    int n = 0;
    for (uint32_t t = 0; t < s->tri_count; t++) {
        int l = c->label[t];
        if (l >= 0 && id[l] < 0)
            id[l] = n++;
        out->tri_surface[t] = l >= 0 ? id[l] : -1;
    }
    free(id);
    out->surfaces = calloc((size_t)n + 1, sizeof *out->surfaces);
    double *sum = calloc(4 * (size_t)n + 1, sizeof *sum);
    if (!out->surfaces || !sum) {
        free(sum);
        return lm_fail(err, LM_ERR_NOMEM, "charts: out of memory");
    }
    out->surface_count = n;
    for (uint32_t t = 0; t < s->tri_count; t++) {
        int i = out->tri_surface[t];
        if (i < 0)
            continue;
        lm_surface *f = &out->surfaces[i];
        if (f->tri_count == 0) {
            f->node = (int)s->tri_node[t];
            f->material = s->tri_material[t];
        }
        f->tri_count++;
        sum[4 * i] += c->area[t];
        for (int k = 0; k < 3; k++)
            sum[4 * i + 1 + k] += c->area[t] * c->nrm[3 * (size_t)t + k];
    }
    lm_status st = LM_OK;
    for (int i = 0; i < n && st == LM_OK; i++) {
        lm_surface *f = &out->surfaces[i];
        double *m = sum + 4 * i, l = sqrt(m[1] * m[1] + m[2] * m[2] + m[3] * m[3]);
        f->area = (float)m[0];
        for (int k = 0; k < 3; k++)
            f->normal[k] = l > 0.0 ? (float)(m[1 + k] / l) : 0.0f;
        f->tris = malloc((size_t)f->tri_count * sizeof *f->tris);
        if (!f->tris)
            st = lm_fail(err, LM_ERR_NOMEM, "charts: out of memory");
        f->tri_count = 0;
    }
    free(sum);
    for (uint32_t t = 0; t < s->tri_count && st == LM_OK; t++)
        if (out->tri_surface[t] >= 0) {
            lm_surface *f = &out->surfaces[out->tri_surface[t]];
            f->tris[f->tri_count++] = t;
        }
    return st;
}

static lm_status alloc_ctx(seg_ctx *c, lm_error *err)
{
    const lm_scene *s = c->s;
    size_t n = s->tri_count;
    c->pos = lmc_world_positions(s, &c->size);
    c->area = malloc(n * sizeof *c->area + 1);
    c->nrm = malloc(3 * n * sizeof *c->nrm + 1);
    c->usable = malloc(n + 1);
    c->adj = malloc(3 * n * sizeof *c->adj + 1);
    c->label = malloc(n * sizeof *c->label + 1);
    c->node_area = calloc((size_t)s->node_count + 1, sizeof *c->node_area);
    if (!c->pos || !c->area || !c->nrm || !c->usable || !c->adj || !c->label || !c->node_area)
        return lm_fail(err, LM_ERR_NOMEM, "charts: out of memory");
    c->rep = lmc_weld(s, c->pos, LMC_WELD_TOL * c->size);
    return c->rep ? LM_OK : lm_fail(err, LM_ERR_NOMEM, "charts: out of memory");
}

static void free_ctx(seg_ctx *c)
{
    free(c->pos);
    free(c->rep);
    free(c->area);
    free(c->nrm);
    free(c->usable);
    free(c->adj);
    free(c->label);
    free(c->node_area);
    free(c->r_area);
    free(c->r_sum);
    free(c->r_first);
    free(c->r_tris);
}

lm_status lm_surfaces_build(const lm_scene *s, const lm_surface_options *o, lm_surfaces *out, lm_error *err)
{
    lm_surface_options def;
    if (!o) {
        lm_surface_options_default(&def);
        o = &def;
    }
    memset(out, 0, sizeof *out);
    lm_status st = lmc_check_scene(s, err);
    if (st != LM_OK)
        return st;
    if (!(o->cone_deg > 0.0f && o->cone_deg <= 180.0f) || !(o->min_fragment_area >= 0.0f) ||
        !(o->min_surface_area >= 0.0f) || !isfinite(o->min_surface_area))
        return lm_fail(err, LM_ERR_INVALID,
                       "charts: cone_deg %g must be in (0, 180], min_fragment_area %g and min_surface_area %g >= 0",
                       (double)o->cone_deg, (double)o->min_fragment_area, (double)o->min_surface_area);
    seg_ctx c = {.s = s, .o = o};
    st = alloc_ctx(&c, err);
    if (st == LM_OK)
        st = tri_geometry(&c, out, err);
    if (st == LM_OK)
        st = topology(&c, out, err);
    if (st == LM_OK)
        st = grow_regions(&c, err);
    if (st == LM_OK)
        st = region_lists(&c, err);
    if (st == LM_OK)
        st = merge_fragments(&c, err);
    if (st == LM_OK)
        st = emit(&c, out, err);
    if (st == LM_OK) {
        out->vertex_weld = c.rep;
        out->tri_adj = c.adj;
        c.rep = NULL;
        c.adj = NULL;
    }
    free_ctx(&c);
    if (st != LM_OK)
        lm_surfaces_free(out);
    return st;
}

void lm_surfaces_free(lm_surfaces *su)
{
    if (!su)
        return;
    for (int i = 0; i < su->surface_count; i++)
        free(su->surfaces[i].tris);
    free(su->surfaces);
    free(su->tri_surface);
    free(su->vertex_weld);
    free(su->tri_adj);
    memset(su, 0, sizeof *su);
}

float lm_surface_area_for_budget(const lm_surfaces *su, int target_texels)
{
    double target = target_texels > 0 ? target_texels : LM_ATLAS_DEFAULT_TEXELS, area = 0.0;
    for (int i = 0; i < su->surface_count; i++)
        area += su->surfaces[i].area;
    /* a surface's charts round up to whole texels: past half the budget in surfaces, their count rules */
    if (su->surface_count <= 0.5 * target || !(area > 0.0) || !isfinite(area))
        return 0.0f;
    return (float)(area / target);
}
