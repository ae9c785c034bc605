/* Unwrapping surfaces into charts: planar projection, greedy chart growth that rejects folding or
 * overlapping triangles, and orientation to the minimum-area bounding rectangle. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "charts_internal.h"

/* A triangle joins a chart only if its normal is within 60 degrees of the projection direction:
 * beyond that the projection stretches texels too much (and at 90 degrees it folds). */
#define FOLD_COS 0.5
/* Overlaps thinner than this fraction of the grid cell (about a triangle's size) are touching edges. */
#define OVERLAP_EPS 1e-4

typedef struct {
    double x, y;
} p2;

/* ---- hash grid of placed triangles (cells about one triangle wide) ---- */

typedef struct {
    int64_t x, y;
    int head;
} cell_slot;

typedef struct {
    cell_slot *slot;
    size_t mask, used;
    size_t *used_idx;
    int *node_tri, *node_next;
    size_t nodes, node_cap;
    double inv_h;
} hgrid;

static size_t cell_hash(int64_t x, int64_t y)
{
    uint64_t h = (uint64_t)x * 0x9E3779B97F4A7C15ull ^ (uint64_t)y * 0xC2B2AE3D27D4EB4Full;
    return (size_t)(h ^ (h >> 31));
}

static cell_slot *cell_find(const hgrid *g, int64_t x, int64_t y)
{
    size_t i = cell_hash(x, y) & g->mask;
    while (g->slot[i].head >= -1 && !(g->slot[i].x == x && g->slot[i].y == y))
        i = (i + 1) & g->mask;
    return &g->slot[i];
}

/* Empty slots hold head -2; a slot in use holds -1 (no triangle yet) or a node index. */
static int grid_init(hgrid *g, size_t cap, double h)
{
    memset(g, 0, sizeof *g);
    g->slot = malloc(cap * sizeof *g->slot);
    g->used_idx = malloc(cap * sizeof *g->used_idx);
    if (!g->slot || !g->used_idx)
        return -1;
    for (size_t i = 0; i < cap; i++)
        g->slot[i].head = -2;
    g->mask = cap - 1;
    g->inv_h = 1.0 / h;
    return 0;
}

static void grid_free(hgrid *g)
{
    free(g->slot);
    free(g->used_idx);
    free(g->node_tri);
    free(g->node_next);
}

static void grid_clear(hgrid *g)
{
    for (size_t i = 0; i < g->used; i++)
        g->slot[g->used_idx[i]].head = -2;
    g->used = 0;
    g->nodes = 0;
}

static int grid_grow(hgrid *g)
{
    hgrid n;
    if (grid_init(&n, 2 * (g->mask + 1), 1.0) != 0) {
        grid_free(&n);
        return -1;
    }
    for (size_t i = 0; i < g->used; i++) {
        cell_slot *o = &g->slot[g->used_idx[i]], *d = cell_find(&n, o->x, o->y);
        *d = *o;
        n.used_idx[n.used++] = (size_t)(d - n.slot);
    }
    free(g->slot);
    free(g->used_idx);
    g->slot = n.slot;
    g->used_idx = n.used_idx;
    g->mask = n.mask;
    return 0;
}

static int grid_add(hgrid *g, int64_t x, int64_t y, int tri)
{
    if (2 * (g->used + 1) > g->mask + 1 && grid_grow(g) != 0)
        return -1;
    if (g->nodes == g->node_cap) {
        size_t cap = g->node_cap ? 2 * g->node_cap : 256;
        int *a = realloc(g->node_tri, cap * sizeof *a);
        if (a)
            g->node_tri = a;
        int *b = realloc(g->node_next, cap * sizeof *b);
        if (b)
            g->node_next = b;
        if (!a || !b)
            return -1;
        g->node_cap = cap;
    }
    cell_slot *c = cell_find(g, x, y);
    if (c->head == -2) {
        c->x = x;
        c->y = y;
        c->head = -1;
        g->used_idx[g->used++] = (size_t)(c - g->slot);
    }
    g->node_tri[g->nodes] = tri;
    g->node_next[g->nodes] = c->head;
    c->head = (int)g->nodes++;
    return 0;
}

static void cell_range(const hgrid *g, const double *t, int64_t lo[2], int64_t hi[2])
{
    for (int a = 0; a < 2; a++) {
        double mn = fmin(t[a], fmin(t[2 + a], t[4 + a])), mx = fmax(t[a], fmax(t[2 + a], t[4 + a]));
        lo[a] = (int64_t)floor(mn * g->inv_h);
        hi[a] = (int64_t)floor(mx * g->inv_h);
    }
}

/* ---- 2D triangle overlap (separating axis; touching is not overlapping) ---- */

static int separated_by_edges(const double *a, const double *b, double eps)
{
    for (int k = 0; k < 3; k++) {
        double ex = a[2 * ((k + 1) % 3)] - a[2 * k], ey = a[2 * ((k + 1) % 3) + 1] - a[2 * k + 1];
        double nx = -ey, ny = ex, len = sqrt(nx * nx + ny * ny);
        double amin = DBL_MAX, amax = -DBL_MAX, bmin = DBL_MAX, bmax = -DBL_MAX;
        for (int i = 0; i < 3; i++) {
            double pa = a[2 * i] * nx + a[2 * i + 1] * ny, pb = b[2 * i] * nx + b[2 * i + 1] * ny;
            amin = fmin(amin, pa);
            amax = fmax(amax, pa);
            bmin = fmin(bmin, pb);
            bmax = fmax(bmax, pb);
        }
        if (amax - bmin <= eps * len || bmax - amin <= eps * len)
            return 1;
    }
    return 0;
}

static int tris_overlap(const double *a, const double *b, double eps)
{
    return !separated_by_edges(a, b, eps) && !separated_by_edges(b, a, eps);
}

/* ---- per-surface chart growth ---- */

typedef struct {
    const lm_scene *s;
    const lm_surfaces *su;
    const float *pos;
    double *tri_uv;     /* 6 per scene triangle */
    int *local;         /* per scene triangle: index in its surface */
    const lm_surface *f;
    int sid;
    unsigned char *done; /* per local triangle: in a chart */
    int *reject;        /* per local triangle: chart number that rejected it */
    int *seen;          /* per local triangle: query stamp */
    int stamp;
    uint32_t *queue;    /* local ids */
    hgrid grid;
    double eps;
    int chart_count, chart_cap;
    lmc_chart *charts;
} surf_ctx;

static void basis(const double n[3], double e1[3], double e2[3])
{
    double a[3] = {0.0, 0.0, 0.0};
    a[fabs(n[0]) < 0.6 ? 0 : fabs(n[1]) < 0.6 ? 1 : 2] = 1.0;
    double d = a[0] * n[0] + a[1] * n[1] + a[2] * n[2];
    for (int k = 0; k < 3; k++)
        e1[k] = a[k] - d * n[k];
    double l = sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
    for (int k = 0; k < 3; k++)
        e1[k] /= l;
    e2[0] = n[1] * e1[2] - n[2] * e1[1];
    e2[1] = n[2] * e1[0] - n[0] * e1[2];
    e2[2] = n[0] * e1[1] - n[1] * e1[0];
}

typedef struct {
    double n[3], e1[3], e2[3], o[3];
} frame;

static const float *welded(const surf_ctx *c, uint32_t t, int k)
{
    return c->pos + 3 * (size_t)c->su->vertex_weld[c->s->tris[3 * (size_t)t + k]];
}

/* Projects triangle t into fr (writing its tri_uv) and says whether it faces the frame enough. */
static int project(surf_ctx *c, const frame *fr, uint32_t t)
{
    double p[3][3];
    for (int k = 0; k < 3; k++) {
        const float *w = welded(c, t, k);
        for (int a = 0; a < 3; a++)
            p[k][a] = (double)w[a] - fr->o[a];
        c->tri_uv[6 * (size_t)t + 2 * k] = p[k][0] * fr->e1[0] + p[k][1] * fr->e1[1] + p[k][2] * fr->e1[2];
        c->tri_uv[6 * (size_t)t + 2 * k + 1] = p[k][0] * fr->e2[0] + p[k][1] * fr->e2[1] + p[k][2] * fr->e2[2];
    }
    double u[3], v[3], x[3];
    for (int a = 0; a < 3; a++) {
        u[a] = p[1][a] - p[0][a];
        v[a] = p[2][a] - p[0][a];
    }
    x[0] = u[1] * v[2] - u[2] * v[1];
    x[1] = u[2] * v[0] - u[0] * v[2];
    x[2] = u[0] * v[1] - u[1] * v[0];
    double l = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
    double d = x[0] * fr->n[0] + x[1] * fr->n[1] + x[2] * fr->n[2];
    return l > 0.0 && d >= FOLD_COS * l;
}

static int overlaps_placed(surf_ctx *c, uint32_t t)
{
    const double *a = c->tri_uv + 6 * (size_t)t;
    int64_t lo[2], hi[2];
    cell_range(&c->grid, a, lo, hi);
    c->stamp++;
    for (int64_t y = lo[1]; y <= hi[1]; y++)
        for (int64_t x = lo[0]; x <= hi[0]; x++) {
            const cell_slot *cs = cell_find(&c->grid, x, y);
            for (int n = cs->head; n >= 0; n = c->grid.node_next[n]) {
                int u = c->grid.node_tri[n];
                if (c->seen[u] == c->stamp)
                    continue;
                c->seen[u] = c->stamp;
                if (tris_overlap(a, c->tri_uv + 6 * (size_t)c->f->tris[u], c->eps))
                    return 1;
            }
        }
    return 0;
}

static int place(surf_ctx *c, uint32_t t, int li)
{
    int64_t lo[2], hi[2];
    cell_range(&c->grid, c->tri_uv + 6 * (size_t)t, lo, hi);
    for (int64_t y = lo[1]; y <= hi[1]; y++)
        for (int64_t x = lo[0]; x <= hi[0]; x++)
            if (grid_add(&c->grid, x, y, li) != 0)
                return -1;
    c->done[li] = 1;
    return 0;
}

static void tri_normal(const surf_ctx *c, uint32_t t, double n[3])
{
    double a = lmc_tri_area(c->s, c->pos, t, n);
    for (int k = 0; k < 3; k++)
        n[k] = a > 0.0 ? n[k] / (2.0 * a) : 0.0;
}

/* The surface's mean normal when the seed faces it, else the seed's own normal. */
static void chart_frame(surf_ctx *c, uint32_t seed, frame *fr)
{
    for (int k = 0; k < 3; k++) {
        fr->n[k] = c->f->normal[k];
        fr->o[k] = welded(c, seed, 0)[k];
    }
    basis(fr->n, fr->e1, fr->e2);
    if (!project(c, fr, seed)) {
        tri_normal(c, seed, fr->n);
        basis(fr->n, fr->e1, fr->e2);
        project(c, fr, seed);
    }
}

/* Grows one chart from seed (local id) breadth-first; returns the number of triangles or -1. */
static int grow_chart(surf_ctx *c, int seed, int chart_no, size_t *tail_out)
{
    frame fr;
    chart_frame(c, c->f->tris[seed], &fr);
    grid_clear(&c->grid);
    size_t head = 0, tail = 0;
    if (place(c, c->f->tris[seed], seed) != 0)
        return -1;
    c->queue[tail++] = (uint32_t)seed;
    while (head < tail) {
        uint32_t t = c->f->tris[c->queue[head++]];
        for (int k = 0; k < 3; k++) {
            int32_t nb = c->su->tri_adj[3 * (size_t)t + k];
            if (nb < 0 || c->su->tri_surface[nb] != c->sid)
                continue;
            int li = c->local[nb];
            if (c->done[li] || c->reject[li] == chart_no)
                continue;
            if (!project(c, &fr, (uint32_t)nb) || overlaps_placed(c, (uint32_t)nb)) {
                c->reject[li] = chart_no; /* placing more triangles never makes it fit later */
                continue;
            }
            if (place(c, (uint32_t)nb, li) != 0)
                return -1;
            c->queue[tail++] = (uint32_t)li;
        }
    }
    *tail_out = tail;
    return (int)tail;
}

/* ---- minimum-area bounding rectangle (convex hull + rotating calipers) ---- */

static int cmp_p2(const void *a, const void *b)
{
    const p2 *p = a, *q = b;
    if (p->x != q->x)
        return p->x < q->x ? -1 : 1;
    return (p->y > q->y) - (p->y < q->y);
}

static double cross3(p2 o, p2 a, p2 b) { return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x); }

/* Andrew's monotone chain; pts is sorted in place, hull (counter-clockwise) written to h. */
static int convex_hull(p2 *pts, int n, p2 *h)
{
    qsort(pts, (size_t)n, sizeof *pts, cmp_p2);
    int m = 0;
    for (int i = 0; i < n; i++) {
        while (m >= 2 && cross3(h[m - 2], h[m - 1], pts[i]) <= 0.0)
            m--;
        h[m++] = pts[i];
    }
    for (int i = n - 2, lower = m + 1; i >= 0; i--) {
        while (m >= lower && cross3(h[m - 2], h[m - 1], pts[i]) <= 0.0)
            m--;
        h[m++] = pts[i];
    }
    return m > 1 ? m - 1 : m;
}

static double dot2(p2 a, double ux, double uy) { return a.x * ux + a.y * uy; }

/* Direction (ux, uy) of the rectangle's first axis. */
static void min_area_rect(const p2 *h, int m, double *ux_out, double *uy_out)
{
    *ux_out = 1.0;
    *uy_out = 0.0;
    if (m < 3)
        return;
    double best = DBL_MAX;
    int a = 0, b = 0, d = 0;
    for (int i = 0; i < m; i++) {
        p2 e = {h[(i + 1) % m].x - h[i].x, h[(i + 1) % m].y - h[i].y};
        double l = sqrt(e.x * e.x + e.y * e.y);
        if (l <= 0.0)
            continue;
        double ux = e.x / l, uy = e.y / l, vx = -uy, vy = ux;
        if (i == 0)
            for (int j = 1; j < m; j++) {
                if (dot2(h[j], ux, uy) > dot2(h[a], ux, uy))
                    a = j;
                if (dot2(h[j], vx, vy) > dot2(h[b], vx, vy))
                    b = j;
                if (dot2(h[j], ux, uy) < dot2(h[d], ux, uy))
                    d = j;
            }
        for (int s = 0; s < m && dot2(h[(a + 1) % m], ux, uy) > dot2(h[a], ux, uy); s++)
            a = (a + 1) % m;
        for (int s = 0; s < m && dot2(h[(b + 1) % m], vx, vy) > dot2(h[b], vx, vy); s++)
            b = (b + 1) % m;
        for (int s = 0; s < m && dot2(h[(d + 1) % m], ux, uy) < dot2(h[d], ux, uy); s++)
            d = (d + 1) % m;
        double w = dot2(h[a], ux, uy) - dot2(h[d], ux, uy), ht = dot2(h[b], vx, vy) - dot2(h[i], vx, vy);
        if (w * ht < best) {
            best = w * ht;
            *ux_out = ux;
            *uy_out = uy;
        }
    }
}

static int cmp_u32(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return (x > y) - (x < y);
}

/* Rotates the chart's corners to its minimum-area rectangle (wider than tall), moves its minimum
 * corner to the origin and records the extent. */
static int orient_chart(surf_ctx *c, lmc_chart *ch)
{
    int n = 3 * (int)ch->tri_count;
    p2 *pts = malloc((size_t)n * sizeof *pts), *hull = malloc((2 * (size_t)n + 1) * sizeof *hull);
    if (!pts || !hull) {
        free(pts);
        free(hull);
        return -1;
    }
    for (uint32_t i = 0; i < ch->tri_count; i++)
        for (int k = 0; k < 3; k++)
            pts[3 * i + k] = (p2){c->tri_uv[6 * (size_t)ch->tris[i] + 2 * k], c->tri_uv[6 * (size_t)ch->tris[i] + 2 * k + 1]};
    double ux, uy;
    min_area_rect(hull, convex_hull(pts, n, hull), &ux, &uy);
    free(pts);
    free(hull);
    double lo[2] = {DBL_MAX, DBL_MAX}, hi[2] = {-DBL_MAX, -DBL_MAX};
    for (uint32_t i = 0; i < ch->tri_count; i++)
        for (int k = 0; k < 3; k++) {
            double *q = c->tri_uv + 6 * (size_t)ch->tris[i] + 2 * k, x = q[0] * ux + q[1] * uy, y = -q[0] * uy + q[1] * ux;
            q[0] = x;
            q[1] = y;
            for (int a = 0; a < 2; a++) {
                lo[a] = fmin(lo[a], q[a]);
                hi[a] = fmax(hi[a], q[a]);
            }
        }
    int turn = hi[1] - lo[1] > hi[0] - lo[0]; /* (x, y) -> (y, -x) keeps the winding */
    for (uint32_t i = 0; i < ch->tri_count; i++)
        for (int k = 0; k < 3; k++) {
            double *q = c->tri_uv + 6 * (size_t)ch->tris[i] + 2 * k, x = q[0] - lo[0], y = q[1] - lo[1];
            q[0] = turn ? y : x;
            q[1] = turn ? hi[0] - lo[0] - x : y;
        }
    ch->ext[0] = turn ? hi[1] - lo[1] : hi[0] - lo[0];
    ch->ext[1] = turn ? hi[0] - lo[0] : hi[1] - lo[1];
    return 0;
}

static int add_chart(surf_ctx *c, size_t n)
{
    if (c->chart_count == c->chart_cap) {
        int cap = c->chart_cap ? 2 * c->chart_cap : 4;
        lmc_chart *a = realloc(c->charts, (size_t)cap * sizeof *a);
        if (!a)
            return -1;
        c->charts = a;
        c->chart_cap = cap;
    }
    lmc_chart *ch = &c->charts[c->chart_count];
    ch->surface = c->sid;
    ch->tri_count = (uint32_t)n;
    ch->tris = malloc(n * sizeof *ch->tris);
    if (!ch->tris)
        return -1;
    for (size_t i = 0; i < n; i++)
        ch->tris[i] = c->f->tris[c->queue[i]];
    qsort(ch->tris, n, sizeof *ch->tris, cmp_u32);
    c->chart_count++;
    return orient_chart(c, ch);
}

static int unwrap_surface(surf_ctx *c)
{
    uint32_t n = c->f->tri_count;
    c->done = calloc((size_t)n + 1, 1);
    c->reject = malloc(((size_t)n + 1) * sizeof *c->reject);
    c->seen = calloc((size_t)n + 1, sizeof *c->seen);
    c->queue = malloc(((size_t)n + 1) * sizeof *c->queue);
    size_t cap = 64;
    while (cap < 4 * (size_t)n)
        cap <<= 1;
    double h = 2.0 * sqrt(fmax((double)c->f->area, 0.0) / (n ? n : 1));
    if (!(h > 0.0))
        h = 1.0;
    c->eps = OVERLAP_EPS * h;
    int rc = (!c->done || !c->reject || !c->seen || !c->queue || grid_init(&c->grid, cap, h) != 0) ? -1 : 0;
    for (uint32_t i = 0; i < n && rc == 0; i++) {
        c->local[c->f->tris[i]] = (int)i;
        c->reject[i] = -1;
    }
    for (uint32_t seed = 0; seed < n && rc == 0; seed++) {
        if (c->done[seed])
            continue;
        size_t len = 0;
        rc = grow_chart(c, (int)seed, c->chart_count, &len) < 0 ? -1 : add_chart(c, len);
    }
    free(c->done);
    free(c->reject);
    free(c->seen);
    free(c->queue);
    grid_free(&c->grid);
    return rc;
}

void lmc_charts_free(lmc_charts *c)
{
    for (int i = 0; i < c->count; i++)
        free(c->charts[i].tris);
    free(c->charts);
    free(c->tri_uv);
    memset(c, 0, sizeof *c);
}

/* Concatenates the per-surface chart lists in surface order. */
static int gather(lmc_charts *out, surf_ctx *sc, int n)
{
    int total = 0;
    for (int i = 0; i < n; i++)
        total += sc[i].chart_count;
    out->charts = malloc(((size_t)total + 1) * sizeof *out->charts);
    if (!out->charts)
        return -1;
    for (int i = 0; i < n; i++) {
        memcpy(out->charts + out->count, sc[i].charts, (size_t)sc[i].chart_count * sizeof *sc[i].charts);
        out->count += sc[i].chart_count;
        sc[i].chart_count = 0;
    }
    return 0;
}

lm_status lmc_unwrap(const lm_scene *s, const lm_surfaces *su, const float *pos, lmc_charts *out, lm_error *err)
{
    memset(out, 0, sizeof *out);
    int n = su->surface_count, failed = 0;
    out->tri_uv = malloc(6 * (size_t)s->tri_count * sizeof *out->tri_uv + 1);
    int *local = malloc((size_t)s->tri_count * sizeof *local + 1);
    surf_ctx *sc = calloc((size_t)n + 1, sizeof *sc);
    if (!out->tri_uv || !local || !sc) {
        failed = 1;
        n = 0;
    }
#pragma omp parallel for schedule(dynamic, 1) reduction(| : failed)
    for (int i = 0; i < n; i++) {
        sc[i] = (surf_ctx){.s = s, .su = su, .pos = pos, .tri_uv = out->tri_uv, .local = local,
                           .f = &su->surfaces[i], .sid = i};
        failed |= unwrap_surface(&sc[i]) != 0;
    }
    if (!failed)
        failed = gather(out, sc, n) != 0;
    for (int i = 0; i < n; i++) {
        for (int k = 0; k < sc[i].chart_count; k++)
            free(sc[i].charts[k].tris);
        free(sc[i].charts);
    }
    free(sc);
    free(local);
    if (failed) {
        lmc_charts_free(out);
        return lm_fail(err, LM_ERR_NOMEM, "charts: out of memory while unwrapping");
    }
    return LM_OK;
}
