/* The texel table: each chart's triangles clipped against the texel squares they touch. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "charts_internal.h"
#include "../core/vecmath.h"

typedef struct {
    double best;   /* largest single-triangle overlap (texel units) */
    double cx, cy; /* centroid of that overlap, chart-local texel coordinates */
    double area;   /* world area of all overlaps */
    int tri;       /* triangle with the largest overlap, -1 if none */
    double nsum[3], lsum[3]; /* interpolated shading normals over the overlaps, by world area (world, local) */
} texel_acc;

typedef struct {
    double x, y;
} pt;

/* Keeps the part of polygon in[0..n) left of the directed line a->b; returns the new count. */
static int clip_half(const pt *in, int n, pt a, pt b, pt *out)
{
    int m = 0;
    for (int i = 0; i < n; i++) {
        pt p = in[i], q = in[(i + 1) % n];
        double dp = (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x);
        double dq = (b.x - a.x) * (q.y - a.y) - (b.y - a.y) * (q.x - a.x);
        if (dp >= 0.0)
            out[m++] = p;
        if ((dp >= 0.0) != (dq >= 0.0)) {
            double s = dp / (dp - dq);
            out[m++] = (pt){p.x + s * (q.x - p.x), p.y + s * (q.y - p.y)};
        }
    }
    return m;
}

/* Area and centroid of the square of side `side` at (x0, y0) clipped to the counter-clockwise triangle t. */
static double clip_square(const pt t[3], double x0, double y0, double side, pt *centroid)
{
    pt a[16], b[16];
    a[0] = (pt){x0, y0};
    a[1] = (pt){x0 + side, y0};
    a[2] = (pt){x0 + side, y0 + side};
    a[3] = (pt){x0, y0 + side};
    int n = 4;
    n = clip_half(a, n, t[0], t[1], b);
    n = clip_half(b, n, t[1], t[2], a);
    n = clip_half(a, n, t[2], t[0], b);
    double area2 = 0.0, cx = 0.0, cy = 0.0;
    for (int i = 0; i < n; i++) {
        pt p = b[i], q = b[(i + 1) % n];
        double c = p.x * q.y - q.x * p.y;
        area2 += c;
        cx += (p.x + q.x) * c;
        cy += (p.y + q.y) * c;
    }
    if (!(area2 > 0.0))
        return 0.0;
    centroid->x = cx / (3.0 * area2);
    centroid->y = cy / (3.0 * area2);
    return 0.5 * area2;
}

/* The unit square at (ix, iy): a texel. */
static double clip_texel(const pt t[3], int ix, int iy, pt *centroid)
{
    return clip_square(t, ix, iy, 1.0, centroid);
}

typedef struct {
    const lm_scene *s;
    const lmc_charts *c;
    const float *pos, *nrm;
    lm_atlas *a;
} texel_job;

/* Chart-local texel coordinates of triangle t's corners (counter-clockwise) and its signed uv area. */
static double chart_corners(const texel_job *j, int ci, uint32_t t, pt out[3], int order[3])
{
    double off[2];
    lmc_chart_offset(&j->c->charts[ci], &j->a->charts[ci], j->a->texel_size, off);
    const double *uv = j->c->tri_uv + 6 * (size_t)t;
    double inv = 1.0 / ((double)j->a->texel_size * j->c->charts[ci].texel_scale);
    for (int k = 0; k < 3; k++)
        out[k] = (pt){off[0] + uv[2 * k] * inv, off[1] + uv[2 * k + 1] * inv};
    double sa = 0.5 * ((out[1].x - out[0].x) * (out[2].y - out[0].y) - (out[2].x - out[0].x) * (out[1].y - out[0].y));
    order[0] = 0;
    order[1] = sa < 0.0 ? 2 : 1;
    order[2] = sa < 0.0 ? 1 : 2;
    if (sa < 0.0) {
        pt tmp = out[1];
        out[1] = out[2];
        out[2] = tmp;
    }
    return fabs(sa);
}

/* Adds weight times the shading normals (world and local) at chart-local point m of triangle t (corners c,
 * in the order ord of chart_corners) to e's sums. */
static void add_normal(const texel_job *j, uint32_t t, const pt c[3], const int ord[3], pt m, double weight,
                       texel_acc *e)
{
    double d = (c[1].x - c[0].x) * (c[2].y - c[0].y) - (c[2].x - c[0].x) * (c[1].y - c[0].y);
    double b1 = d != 0.0 ? ((m.x - c[0].x) * (c[2].y - c[0].y) - (c[2].x - c[0].x) * (m.y - c[0].y)) / d : 1.0 / 3.0;
    double b2 = d != 0.0 ? ((c[1].x - c[0].x) * (m.y - c[0].y) - (m.x - c[0].x) * (c[1].y - c[0].y)) / d : 1.0 / 3.0;
    double w[3] = {1.0 - b1 - b2, b1, b2};
    for (int k = 0; k < 3; k++) {
        uint32_t v = j->s->tris[3 * (size_t)t + ord[k]];
        for (int a = 0; a < 3; a++) {
            e->nsum[a] += weight * w[k] * j->nrm[3 * (size_t)v + a];
            e->lsum[a] += weight * w[k] * j->s->normals[3 * (size_t)v + a];
        }
    }
}

/* The cells of side 1 / k texels (k 1: texels; 2: their quarters) of chart rect r that triangle c's bounds
 * touch: x in [xy[0], xy[1]], y in [xy[2], xy[3]]. */
static void cell_range(const pt c[3], int k, const lm_chart *r, int xy[4])
{
    double lo[2] = {fmin(c[0].x, fmin(c[1].x, c[2].x)), fmin(c[0].y, fmin(c[1].y, c[2].y))};
    double hi[2] = {fmax(c[0].x, fmax(c[1].x, c[2].x)), fmax(c[0].y, fmax(c[1].y, c[2].y))};
    xy[0] = (int)fmax(floor(k * lo[0]), 0.0), xy[1] = (int)fmin(floor(k * hi[0]), k * r->w - 1.0);
    xy[2] = (int)fmax(floor(k * lo[1]), 0.0), xy[3] = (int)fmin(floor(k * hi[1]), k * r->h - 1.0);
}

static void accumulate(const texel_job *j, const int ord[3], texel_acc *acc, const lm_chart *r, uint32_t t,
                       const pt c[3], double scale, double world)
{
    int xy[4], covered = 0;
    cell_range(c, 1, r, xy);
    for (int y = xy[2]; y <= xy[3]; y++)
        for (int x = xy[0]; x <= xy[1]; x++) {
            pt m;
            double ov = clip_texel(c, x, y, &m);
            if (ov <= 0.0)
                continue;
            texel_acc *e = &acc[(size_t)y * r->w + x];
            e->area += ov * scale;
            add_normal(j, t, c, ord, m, ov * scale, e);
            covered = 1;
            if (ov > e->best) {
                e->best = ov;
                e->tri = (int)t;
                e->cx = m.x;
                e->cy = m.y;
            }
        }
    if (covered)
        return;
    /* A sliver too thin to clip to a positive area still gets the texel under its centroid. */
    double mx = (c[0].x + c[1].x + c[2].x) / 3.0, my = (c[0].y + c[1].y + c[2].y) / 3.0;
    int x = (int)fmin(fmax(floor(mx), 0.0), r->w - 1.0), y = (int)fmin(fmax(floor(my), 0.0), r->h - 1.0);
    texel_acc *e = &acc[(size_t)y * r->w + x];
    e->area += world;
    add_normal(j, t, c, ord, (pt){mx, my}, world, e);
    if (e->tri < 0) {
        e->tri = (int)t;
        e->cx = mx;
        e->cy = my;
    }
}

/* World position and shading normal at barycentric weights w (summing to 1) on the corners of triangle t. */
static void texel_at(const texel_job *j, uint32_t t, const double w[3], lm_texel *out)
{
    double p[3] = {0, 0, 0}, n[3] = {0, 0, 0}, local[3] = {0, 0, 0}, ln[3] = {0, 0, 0};
    for (int k = 0; k < 3; k++) {
        uint32_t v = j->s->tris[3 * (size_t)t + k];
        out->bary[k] = (float)w[k];
        for (int a = 0; a < 3; a++) {
            p[a] += w[k] * j->pos[3 * (size_t)v + a];
            n[a] += w[k] * j->nrm[3 * (size_t)v + a];
            local[a] += w[k] * j->s->positions[3 * (size_t)v + a];
            ln[a] += w[k] * j->s->normals[3 * (size_t)v + a];
        }
    }
    double l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]), ll = sqrt(ln[0] * ln[0] + ln[1] * ln[1] + ln[2] * ln[2]);
    if (!(l > 1e-12)) {
        l = 2.0 * lmc_tri_area(j->s, j->pos, t, n);
        l = l > 0.0 ? l : 1.0;
    }
    if (!(ll > 1e-12)) {
        ll = 2.0 * lmc_tri_area(j->s, j->s->positions, t, ln);
        ll = ll > 0.0 ? ll : 1.0;
    }
    for (int a = 0; a < 3; a++) {
        out->pos[a] = (float)p[a];
        out->local[a] = (float)local[a];
        out->normal[a] = (float)(n[a] / l);
        out->lnormal[a] = (float)(ln[a] / ll);
    }
}

/* World position and shading normal at chart-local point (px, py) of triangle t. */
static void texel_point(const texel_job *j, int ci, uint32_t t, double px, double py, lm_texel *out)
{
    pt c[3];
    int ord[3];
    chart_corners(j, ci, t, c, ord);
    double d = (c[1].x - c[0].x) * (c[2].y - c[0].y) - (c[2].x - c[0].x) * (c[1].y - c[0].y);
    double b1 = d != 0.0 ? ((px - c[0].x) * (c[2].y - c[0].y) - (c[2].x - c[0].x) * (py - c[0].y)) / d : 1.0 / 3.0;
    double b2 = d != 0.0 ? ((c[1].x - c[0].x) * (py - c[0].y) - (px - c[0].x) * (c[1].y - c[0].y)) / d : 1.0 / 3.0;
    double w[3] = {fmax(1.0 - b1 - b2, 0.0), fmax(b1, 0.0), fmax(b2, 0.0)}, sum = w[0] + w[1] + w[2], wt[3];
    for (int k = 0; k < 3; k++)
        wt[ord[k]] = w[k] / sum;
    texel_at(j, t, wt, out);
}

/* The texel's normals: the area-weighted means of its overlaps' (texel_acc), where they do not cancel;
 * else the point's own (texel_point's). */
static void mean_normal(const texel_acc *e, lm_texel *o)
{
    double ln = sqrt(e->nsum[0] * e->nsum[0] + e->nsum[1] * e->nsum[1] + e->nsum[2] * e->nsum[2]);
    double ll = sqrt(e->lsum[0] * e->lsum[0] + e->lsum[1] * e->lsum[1] + e->lsum[2] * e->lsum[2]);
    if (!(ln > 1e-12) || !(ll > 1e-12))
        return;
    for (int a = 0; a < 3; a++) {
        o->normal[a] = (float)(e->nsum[a] / ln);
        o->lnormal[a] = (float)(e->lsum[a] / ll);
    }
}

/* Chart-local coordinate q as a bilinear lookup takes it: itself (lmc_pack sized the rect so that lookups
 * stay in it and its border), or the centre of a chart of one texel. */
static double lookup_coord(double q, int w)
{
    return w <= 1 ? 0.5 : q;
}

void lm_chart_lookup_rect(const lm_atlas *a, int c, float rect[4])
{
    const lm_chart *ch = &a->charts[c];
    float in = 0.5f - (float)ch->pad;
    rect[0] = (ch->x + in) / (float)a->width, rect[1] = (ch->y + in) / (float)a->height;
    rect[2] = (ch->x + ch->w - in) / (float)a->width, rect[3] = (ch->y + ch->h - in) / (float)a->height;
}

/* Whether a texel's interpolated shading normals spread past LM_FOOTPRINT_SPREAD: their area-weighted
 * mean is shorter than that. */
static int normals_spread(const texel_acc *e)
{
    double len = sqrt(e->nsum[0] * e->nsum[0] + e->nsum[1] * e->nsum[1] + e->nsum[2] * e->nsum[2]);
    return e->area > 0.0 && len < LM_FOOTPRINT_SPREAD * e->area;
}

/* The texel's footprint points (lm_atlas.footprints) when its chart is one texel whose shading normals
 * spread (normals_spread): *foot (NULL, 0 when none). Returns 0 when memory ran out. */
static int footprint(const texel_job *j, const lmc_chart *ch, const texel_acc *e, const lm_texel *tx,
                     lm_texel **foot, uint32_t *foot_count)
{
    *foot = NULL, *foot_count = 0;
    if (!normals_spread(e))
        return 1;
    lmc_point pts[LM_FOOTPRINT_POINTS];
    int n = lmc_footprint(j->s, j->pos, ch->tris, ch->tri_count, pts);
    if (n < 0)
        return 0;
    if (n < 2)
        return 1;
    *foot = malloc((size_t)n * sizeof **foot);
    if (!*foot)
        return 0;
    for (int i = 0; i < n; i++) {
        lm_texel *o = &(*foot)[i];
        double w[3] = {pts[i].w[0], pts[i].w[1], pts[i].w[2]};
        *o = *tx;
        o->tri = pts[i].tri;
        texel_at(j, o->tri, w, o);
        o->area = pts[i].area;
    }
    *foot_count = (uint32_t)n;
    return 1;
}

/* Whether a chart's triangles turn: the area-weighted mean of their unit geometric normals is shorter than
 * LM_FOOTPRINT_TURNING (a terrain's slope, a column; not a wall, whose interpolated normals may still
 * disagree at its corners). */
static int chart_turns(const texel_job *j, const lmc_chart *ch)
{
    double g[3] = {0.0, 0.0, 0.0}, area = 0.0;
    for (uint32_t i = 0; i < ch->tri_count; i++) {
        double n[3], a = lmc_tri_area(j->s, j->pos, ch->tris[i], n), l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        for (int k = 0; l > 0.0 && k < 3; k++)
            g[k] += a * n[k] / l;
        area += a;
    }
    return area > 0.0 && sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]) < LM_FOOTPRINT_TURNING * area;
}

/* Each quarter of a texel square: its largest overlap's triangle and centroid, and the world area of all. */
typedef struct {
    double best, cx, cy, area;
    int tri;
} quarter;

/* Triangle t's (chart-local corners c, world area per uv area `scale`) overlaps with the quarters of chart
 * rect r's cells (4 a cell, row-major cells) added to q. */
static void add_quarters(quarter *q, const lm_chart *r, uint32_t t, const pt c[3], double scale)
{
    int xy[4];
    cell_range(c, 2, r, xy);
    for (int y = xy[2]; y <= xy[3]; y++)
        for (int x = xy[0]; x <= xy[1]; x++) {
            pt m;
            double ov = clip_square(c, 0.5 * x, 0.5 * y, 0.5, &m);
            if (ov <= 0.0)
                continue;
            quarter *e = &q[((size_t)(y / 2) * r->w + (size_t)(x / 2)) * 4 + (size_t)(y % 2 * 2 + x % 2)];
            e->area += ov * scale;
            if (ov > e->best)
                *e = (quarter){ov, m.x, m.y, e->area, (int)t};
        }
}

/* The footprints of a chart of several texels whose triangles turn (chart_turns): each texel whose shading
 * normals spread (normals_spread) is gathered at its quarters' points (their largest overlaps' centroids,
 * q from add_quarters), where two or more quarters are covered; n texels tx, their accumulators acc
 * (row-major cells). *foot gets the points, (*per_texel)[k] how many texel k has. Returns 0 when memory ran
 * out. */
static int quarter_footprints(const texel_job *j, int ci, const texel_acc *acc, const quarter *q, const lm_texel *tx,
                              uint32_t n, lm_texel **foot, uint32_t *foot_count, uint32_t **per_texel)
{
    const lm_chart *r = &j->a->charts[ci];
    *per_texel = calloc((size_t)n + 1, sizeof **per_texel);
    *foot = malloc(((size_t)n * 4 + 1) * sizeof **foot);
    if (!*per_texel || !*foot)
        return 0;
    uint32_t k = 0, f = 0;
    for (size_t cell = 0; cell < (size_t)r->w * r->h; cell++) {
        const texel_acc *e = &acc[cell];
        if (e->tri < 0)
            continue;
        uint32_t got = 0;
        for (int i = 0; normals_spread(e) && i < 4; i++) {
            const quarter *p = &q[cell * 4 + (size_t)i];
            if (p->tri < 0)
                continue;
            lm_texel *o = &(*foot)[f + got++];
            *o = tx[k];
            o->tri = (uint32_t)p->tri;
            texel_point(j, ci, o->tri, p->cx, p->cy, o);
            o->area = (float)p->area;
        }
        (*per_texel)[k++] = got >= 2 ? got : 0;
        f += got >= 2 ? got : 0;
    }
    *foot_count = f;
    return 1;
}

/* Fills this chart's corner UVs and returns its texels (row-major), or NULL when memory ran out; a chart
 * of one texel over a curved piece also its footprint points (footprint), a chart of several whose
 * triangles turn its texels' (quarter_footprints: *per_texel, NULL where no texel has any). */
static lm_texel *chart_texels(const texel_job *j, int ci, uint32_t *count, lm_texel **foot, uint32_t *foot_count,
                              uint32_t **per_texel)
{
    *per_texel = NULL;
    const lmc_chart *ch = &j->c->charts[ci];
    const lm_chart *r = &j->a->charts[ci];
    size_t cells = (size_t)r->w * r->h;
    texel_acc *acc = malloc(cells * sizeof *acc);
    /* a chart of several texels whose triangles turn: its texels' quarters too (quarter_footprints) */
    int quartered = (r->w > 1 || r->h > 1) && chart_turns(j, ch);
    quarter *q = quartered ? malloc(cells * 4 * sizeof *q) : NULL;
    if (!acc || (quartered && !q)) {
        free(acc);
        free(q);
        return NULL;
    }
    for (size_t i = 0; i < cells; i++)
        acc[i] = (texel_acc){0.0, 0.0, 0.0, 0.0, -1, {0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}};
    for (size_t i = 0; q && i < cells * 4; i++)
        q[i] = (quarter){0.0, 0.0, 0.0, 0.0, -1};
    for (uint32_t i = 0; i < ch->tri_count; i++) {
        uint32_t t = ch->tris[i];
        pt c[3];
        int ord[3];
        double uv_area = chart_corners(j, ci, t, c, ord), n[3], world = lmc_tri_area(j->s, j->pos, t, n);
        for (int k = 0; k < 3; k++) {
            float *cov = j->a->coverage_uv + 6 * (size_t)t + 2 * ord[k], *uv = j->a->corner_uv + 6 * (size_t)t + 2 * ord[k];
            cov[0] = (float)((r->x + c[k].x) / j->a->width);
            cov[1] = (float)((r->y + c[k].y) / j->a->height);
            uv[0] = (float)((r->x + lookup_coord(c[k].x, r->w)) / j->a->width);
            uv[1] = (float)((r->y + lookup_coord(c[k].y, r->h)) / j->a->height);
        }
        j->a->tri_chart[t] = ci;
        double scale = uv_area > 0.0 ? world / uv_area : 0.0;
        accumulate(j, ord, acc, r, t, c, scale, world);
        if (q)
            add_quarters(q, r, t, c, scale);
    }
    uint32_t n = 0;
    for (size_t i = 0; i < (size_t)r->w * r->h; i++)
        n += acc[i].tri >= 0;
    lm_texel *tx = malloc(((size_t)n + 1) * sizeof *tx);
    if (tx) {
        n = 0;
        for (int y = 0; y < r->h; y++)
            for (int x = 0; x < r->w; x++) {
                const texel_acc *e = &acc[(size_t)y * r->w + x];
                if (e->tri < 0)
                    continue;
                lm_texel *o = &tx[n++];
                o->tri = (uint32_t)e->tri;
                texel_point(j, ci, o->tri, e->cx, e->cy, o);
                mean_normal(e, o);
                o->x = r->x + x;
                o->y = r->y + y;
                o->surface = ch->surface;
                o->area = (float)e->area;
            }
        *count = n;
        *foot = NULL, *foot_count = 0;
        if (r->w == 1 && r->h == 1 && n == 1 && !footprint(j, ch, &acc[0], &tx[0], foot, foot_count)) {
            free(tx);
            tx = NULL;
        } else if (q && !quarter_footprints(j, ci, acc, q, tx, n, foot, foot_count, per_texel)) {
            free(tx);
            tx = NULL;
        }
    }
    free(acc);
    free(q);
    return tx;
}

static lm_status assemble(lm_atlas *a, lm_texel **per, const uint32_t *count, lm_texel **foot,
                          const uint32_t *foot_count, uint32_t **per_texel, lm_error *err)
{
    size_t total = 0, feet = 0;
    for (int i = 0; i < a->chart_count; i++)
        total += count[i], feet += foot_count[i];
    a->texels = malloc((total + 1) * sizeof *a->texels);
    a->footprint_first = malloc((total + 1) * sizeof *a->footprint_first);
    a->footprints = malloc((feet + 1) * sizeof *a->footprints);
    if (!a->texels || !a->footprint_first || !a->footprints)
        return lm_fail(err, LM_ERR_NOMEM, "charts: out of memory for %zu texels", total);
    for (int i = 0; i < a->chart_count; i++) {
        memcpy(a->texels + a->texel_count, per[i], count[i] * sizeof *per[i]);
        for (uint32_t k = 0, at = a->footprint_count; k < count[i]; k++) { /* a chart's points are its one texel's, or per_texel's */
            a->footprint_first[a->texel_count + k] = at;
            at += per_texel[i] ? per_texel[i][k] : 0;
        }
        if (foot_count[i]) /* memcpy from NULL is undefined even for no bytes */
            memcpy(a->footprints + a->footprint_count, foot[i], foot_count[i] * sizeof *foot[i]);
        a->footprint_count += foot_count[i];
        a->texel_count += count[i];
    }
    a->footprint_first[a->texel_count] = a->footprint_count;
    for (uint32_t i = 0; i < a->texel_count; i++)
        a->texel_index[(size_t)a->texels[i].y * a->width + a->texels[i].x] = (int)i;
    a->utilization = (float)((double)a->texel_count / ((double)a->width * a->height));
    a->page_utilization = (float)((double)a->texel_count / ((double)a->page_count * a->page_width * a->page_height));
    return LM_OK;
}

lm_status lmc_texels(const lm_scene *s, const lmc_charts *c, const float *pos, lm_atlas *a, lm_error *err)
{
    size_t np = (size_t)a->width * a->height;
    a->corner_uv = malloc(6 * (size_t)s->tri_count * sizeof *a->corner_uv + 1);
    a->coverage_uv = malloc(6 * (size_t)s->tri_count * sizeof *a->coverage_uv + 1);
    a->chart_owner = malloc(np * sizeof *a->chart_owner + 1);
    a->tri_chart = malloc((size_t)s->tri_count * sizeof *a->tri_chart + 1);
    a->texel_index = malloc(np * sizeof *a->texel_index + 1);
    lm_texel **per = calloc((size_t)a->chart_count + 1, sizeof *per), **foot = calloc((size_t)a->chart_count + 1, sizeof *foot);
    uint32_t *count = calloc((size_t)a->chart_count + 1, sizeof *count);
    uint32_t *foot_count = calloc((size_t)a->chart_count + 1, sizeof *foot_count);
    uint32_t **per_texel = calloc((size_t)a->chart_count + 1, sizeof *per_texel);
    float *nrm = lmc_world_normals(s);
    lm_status st = LM_OK;
    if (!a->corner_uv || !a->coverage_uv || !a->chart_owner || !a->tri_chart || !a->texel_index || !per || !count ||
        !foot || !foot_count || !nrm) {
        st = lm_fail(err, LM_ERR_NOMEM, "charts: out of memory for the texel table");
        goto done;
    }
    for (size_t i = 0; i < 6 * (size_t)s->tri_count; i++)
        a->corner_uv[i] = a->coverage_uv[i] = NAN;
    for (uint32_t t = 0; t < s->tri_count; t++)
        a->tri_chart[t] = -1;
    for (size_t i = 0; i < np; i++)
        a->texel_index[i] = a->chart_owner[i] = -1;
    for (int i = 0; i < a->chart_count; i++) {
        const lm_chart *r = &a->charts[i];
        for (int y = r->y - r->pad; y < r->y + r->h + r->pad; y++)
            for (int x = r->x - r->pad; x < r->x + r->w + r->pad; x++)
                a->chart_owner[(size_t)y * a->width + x] = i;
    }
    texel_job j = {s, c, pos, nrm, a};
    int failed = 0;
#pragma omp parallel for schedule(dynamic, 1) reduction(| : failed)
    for (int i = 0; i < a->chart_count; i++) {
        per[i] = chart_texels(&j, i, &count[i], &foot[i], &foot_count[i], &per_texel[i]);
        failed |= per[i] == NULL;
    }
    st = failed ? lm_fail(err, LM_ERR_NOMEM, "charts: out of memory for the texel table")
                : assemble(a, per, count, foot, foot_count, per_texel, err);
done:
    for (int i = 0; per && foot && i < a->chart_count; i++)
        free(per[i]), free(foot[i]), free(per_texel[i]);
    free(per_texel);
    free(per);
    free(foot);
    free(count);
    free(foot_count);
    free(nrm);
    return st;
}

int lm_texel_parts(const lm_scene *s, const lm_atlas *a, const lm_texel *t, int k, float local[][3], float share[])
{
    pt c[3];
    const float *uv = a->coverage_uv + 6 * (size_t)t->tri;
    for (int i = 0; i < 3; i++)
        c[i] = (pt){(double)uv[2 * i] * a->width, (double)uv[2 * i + 1] * a->height};
    int order[3] = {0, 1, 2};
    double d = (c[1].x - c[0].x) * (c[2].y - c[0].y) - (c[2].x - c[0].x) * (c[1].y - c[0].y);
    if (!(fabs(d) > 0.0) || k < 1)
        return 0;
    if (d < 0.0) { /* clip_square wants the corners counter-clockwise */
        pt tmp = c[1];
        c[1] = c[2], c[2] = tmp;
        order[1] = 2, order[2] = 1;
        d = -d;
    }
    int n = 0;
    double total = 0.0;
    for (int j = 0; j < k; j++)
        for (int i = 0; i < k; i++) {
            pt m;
            double ov = clip_square(c, t->x + (double)i / k, t->y + (double)j / k, 1.0 / k, &m);
            if (!(ov > 0.0))
                continue;
            double b1 = ((m.x - c[0].x) * (c[2].y - c[0].y) - (c[2].x - c[0].x) * (m.y - c[0].y)) / d;
            double b2 = ((c[1].x - c[0].x) * (m.y - c[0].y) - (m.x - c[0].x) * (c[1].y - c[0].y)) / d;
            double w[3] = {1.0 - b1 - b2, b1, b2};
            for (int axis = 0; axis < 3; axis++) {
                double v = 0.0;
                for (int q = 0; q < 3; q++)
                    v += w[q] * s->positions[3 * (size_t)s->tris[3 * (size_t)t->tri + (size_t)order[q]] + (size_t)axis];
                local[n][axis] = (float)v;
            }
            share[n++] = (float)ov;
            total += ov;
        }
    for (int i = 0; i < n; i++)
        share[i] = (float)(share[i] / total);
    return n;
}

void lm_texel_kd(const lm_scene *s, const lm_texel *t, float kd[3])
{
    const lm_material *m = &s->materials[s->tri_material[t->tri]];
    const float *uvs = m->base_color_uv == 1 && s->uv1 ? s->uv1 : s->uv0;
    float uv[2] = {0.0f, 0.0f}, albedo[3], ks[3];
    for (int k = 0; k < 3; k++) {
        uint32_t v = s->tris[3 * (size_t)t->tri + (size_t)k];
        uv[0] += t->bary[k] * uvs[2 * (size_t)v];
        uv[1] += t->bary[k] * uvs[2 * (size_t)v + 1];
    }
    lm_material_albedo(s, m, uv[0], uv[1], albedo);
    lm_material_lobes(m, albedo, kd, ks);
}

void lm_texel_world(const lm_scene *s, const lm_texel *t, float pos[3], float nrm[3])
{
    lm_vec3 p = lm_v3(0, 0, 0);
    for (int k = 0; k < 3; k++) {
        float v[3];
        lm_scene_vertex_world(s, s->tris[3 * (size_t)t->tri + k], v);
        p = lm_add(p, lm_scale(lm_v3_load(v), t->bary[k]));
    }
    lm_v3_store(pos, p);
    const float *m = s->nodes[s->vertex_node[s->tris[3 * (size_t)t->tri]]].world;
    lm_vec3 n = lm_mat4_normal(m, lm_v3_load(t->lnormal));
    lm_v3_store(nrm, lm_length(n) > 0.5f ? n : lm_normalize(lm_v3_load(t->normal)));
}

void lm_texel_centre_normal(const lm_scene *s, const lm_texel *t, float pos[3], float nrm[3])
{
    lm_vec3 p = lm_v3(0, 0, 0), n = lm_v3(0, 0, 0);
    for (int k = 0; k < 3; k++) {
        float v[3], vn[3];
        lm_scene_vertex_world(s, s->tris[3 * (size_t)t->tri + k], v);
        lm_scene_normal_world(s, s->tris[3 * (size_t)t->tri + k], vn);
        p = lm_add(p, lm_scale(lm_v3_load(v), t->bary[k]));
        n = lm_add(n, lm_scale(lm_v3_load(vn), t->bary[k]));
    }
    lm_v3_store(pos, p);
    lm_v3_store(nrm, lm_length(n) > 0.0f ? lm_normalize(n) : lm_normalize(lm_v3_load(t->normal)));
}
