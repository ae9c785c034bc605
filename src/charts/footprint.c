/* Footprint points: where a texel that stands for a whole curved piece is gathered (charts_internal.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "charts_internal.h"

typedef struct {
    double c[3]; /* world centroid */
    double area;
    double key;  /* c along the axis being split */
    uint32_t tri;
} piece;

static int by_key(const void *pa, const void *pb)
{
    const piece *a = pa, *b = pb;
    if (a->key != b->key)
        return a->key < b->key ? -1 : 1;
    return (a->tri > b->tri) - (a->tri < b->tri); /* ties by triangle: the same order on every platform */
}

/* The weight (0..1) of b at the point of segment ab nearest q. */
static double segment_weight(const double a[3], const double b[3], const double q[3])
{
    double ab2 = 0.0, t = 0.0;
    for (int k = 0; k < 3; k++)
        ab2 += (b[k] - a[k]) * (b[k] - a[k]), t += (q[k] - a[k]) * (b[k] - a[k]);
    return ab2 > 0.0 ? fmin(fmax(t / ab2, 0.0), 1.0) : 0.0;
}

/* Squared distance from q to the point of triangle c nearest it, whose barycentric weights go to w: q's
 * projection onto the plane where it falls inside, else the nearest point of the nearest edge. */
static double nearest_on_triangle(const double c[3][3], const double q[3], double w[3])
{
    double e1[3], e2[3], d[3], d11 = 0.0, d22 = 0.0, d12 = 0.0, q1 = 0.0, q2 = 0.0;
    for (int k = 0; k < 3; k++) {
        e1[k] = c[1][k] - c[0][k], e2[k] = c[2][k] - c[0][k], d[k] = q[k] - c[0][k];
        d11 += e1[k] * e1[k], d22 += e2[k] * e2[k], d12 += e1[k] * e2[k], q1 += d[k] * e1[k], q2 += d[k] * e2[k];
    }
    double det = d11 * d22 - d12 * d12;
    double u = det > 0.0 ? (q1 * d22 - q2 * d12) / det : -1.0, v = det > 0.0 ? (q2 * d11 - q1 * d12) / det : -1.0;
    double best = INFINITY;
    if (u >= 0.0 && v >= 0.0 && u + v <= 1.0) {
        w[0] = 1.0 - u - v, w[1] = u, w[2] = v;
    } else {
        for (int k = 0; k < 3; k++) {
            int b = (k + 1) % 3;
            double s = segment_weight(c[k], c[b], q), dist = 0.0;
            for (int a = 0; a < 3; a++) {
                double x = (1.0 - s) * c[k][a] + s * c[b][a] - q[a];
                dist += x * x;
            }
            if (dist < best) {
                best = dist;
                w[0] = w[1] = w[2] = 0.0;
                w[k] = 1.0 - s, w[b] = s;
            }
        }
    }
    double dist = 0.0;
    for (int a = 0; a < 3; a++) {
        double x = w[0] * c[0][a] + w[1] * c[1][a] + w[2] * c[2][a] - q[a];
        dist += x * x;
    }
    return dist;
}

static void corners(const lm_scene *s, const float *pos, uint32_t t, double c[3][3])
{
    for (int k = 0; k < 3; k++)
        for (int a = 0; a < 3; a++)
            c[k][a] = pos[3 * (size_t)s->tris[3 * (size_t)t + k] + a];
}

/* The group's point: the one of its triangles nearest its area-weighted centroid. */
static lmc_point group_point(const lm_scene *s, const float *pos, const piece *p, uint32_t n)
{
    double q[3] = {0.0, 0.0, 0.0}, area = 0.0;
    for (uint32_t i = 0; i < n; i++) {
        for (int a = 0; a < 3; a++)
            q[a] += p[i].area * p[i].c[a];
        area += p[i].area;
    }
    for (int a = 0; a < 3; a++)
        q[a] /= area;
    lmc_point out = {p[0].tri, {1.0f / 3.0f, 1.0f / 3.0f, 1.0f / 3.0f}, (float)area};
    double best = INFINITY;
    for (uint32_t i = 0; i < n; i++) {
        double c[3][3], w[3];
        corners(s, pos, p[i].tri, c);
        double d = nearest_on_triangle(c, q, w);
        if (d < best) {
            best = d;
            out.tri = p[i].tri;
            for (int k = 0; k < 3; k++)
                out.w[k] = (float)w[k];
        }
    }
    return out;
}

/* Cuts p[0..n) in two at the area median along the widest axis of their centroids, depth times over,
 * and appends each part's point to out. */
static void split(const lm_scene *s, const float *pos, piece *p, uint32_t n, int depth, lmc_point *out, int *count)
{
    if (depth == 0 || n < 2) {
        out[(*count)++] = group_point(s, pos, p, n);
        return;
    }
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY}, total = 0.0;
    for (uint32_t i = 0; i < n; i++) {
        for (int a = 0; a < 3; a++)
            lo[a] = fmin(lo[a], p[i].c[a]), hi[a] = fmax(hi[a], p[i].c[a]);
        total += p[i].area;
    }
    int axis = 0;
    for (int a = 1; a < 3; a++)
        if (hi[a] - lo[a] > hi[axis] - lo[axis])
            axis = a;
    for (uint32_t i = 0; i < n; i++)
        p[i].key = p[i].c[axis];
    qsort(p, n, sizeof *p, by_key);
    uint32_t k = 1;
    for (double sum = p[0].area; k < n - 1 && sum < 0.5 * total; k++)
        sum += p[k].area;
    split(s, pos, p, k, depth - 1, out, count);
    split(s, pos, p + k, n - k, depth - 1, out, count);
}

int lmc_footprint(const lm_scene *s, const float *pos, const uint32_t *tris, uint32_t n, lmc_point out[LM_FOOTPRINT_POINTS])
{
    piece *p = malloc(((size_t)n + 1) * sizeof *p);
    if (!p)
        return -1;
    uint32_t m = 0;
    for (uint32_t i = 0; i < n; i++) {
        double nrm[3], a = lmc_tri_area(s, pos, tris[i], nrm), c[3][3];
        if (!(a > 0.0))
            continue;
        corners(s, pos, tris[i], c);
        for (int k = 0; k < 3; k++)
            p[m].c[k] = (c[0][k] + c[1][k] + c[2][k]) / 3.0;
        p[m].area = a, p[m].tri = tris[i];
        m++;
    }
    int count = 0;
    if (m > 1)
        split(s, pos, p, m, 2, out, &count); /* 2 x 2 parts: LM_FOOTPRINT_POINTS */
    free(p);
    return count;
}

/* x = (A + ridge I)^-1 b for symmetric 3 x 3 A, by Cramer's rule (A + ridge I is positive definite). */
static void solve3(const double A[3][3], double ridge, const double b[3], double x[3])
{
    double m[3][3];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            m[i][j] = A[i][j] + (i == j ? ridge : 0.0);
    double c0 = m[1][1] * m[2][2] - m[1][2] * m[2][1], c1 = m[1][2] * m[2][0] - m[1][0] * m[2][2],
           c2 = m[1][0] * m[2][1] - m[1][1] * m[2][0], det = m[0][0] * c0 + m[0][1] * c1 + m[0][2] * c2;
    double inv[3][3] = {{c0, m[0][2] * m[2][1] - m[0][1] * m[2][2], m[0][1] * m[1][2] - m[0][2] * m[1][1]},
                        {c1, m[0][0] * m[2][2] - m[0][2] * m[2][0], m[0][2] * m[1][0] - m[0][0] * m[1][2]},
                        {c2, m[0][1] * m[2][0] - m[0][0] * m[2][1], m[0][0] * m[1][1] - m[0][1] * m[1][0]}};
    for (int i = 0; i < 3; i++)
        x[i] = (inv[i][0] * b[0] + inv[i][1] * b[1] + inv[i][2] * b[2]) / det;
}

void lm_footprint_turn(int m, const float n[][3], const float e[][3], float out[LM_TURN_FLOATS])
{
    memset(out, 0, LM_TURN_FLOATS * sizeof *out);
    if (m < 2)
        return;
    double nbar[3] = {0.0, 0.0, 0.0}, spread[3][3] = {{0.0}};
    for (int k = 0; k < m; k++)
        for (int i = 0; i < 3; i++)
            nbar[i] += n[k][i] / m;
    for (int k = 0; k < m; k++)
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
                spread[i][j] += (n[k][i] - nbar[i]) * (n[k][j] - nbar[j]);
    double trace = spread[0][0] + spread[1][1] + spread[2][2];
    if (!(trace > 1e-6))
        return;
    for (int c = 0; c < 3; c++) {
        double mean = 0.0, b[3] = {0.0, 0.0, 0.0}, g[3];
        for (int k = 0; k < m; k++)
            mean += e[k][c] / m;
        if (!(mean > 0.0))
            continue;
        for (int k = 0; k < m; k++)
            for (int i = 0; i < 3; i++)
                b[i] += (n[k][i] - nbar[i]) * (e[k][c] - mean);
        solve3(spread, 0.01 * trace, b, g);
        for (int i = 0; i < 3; i++)
            out[4 * c + i] = (float)(g[i] / mean);
        out[4 * c + 3] = (float)((g[0] * nbar[0] + g[1] * nbar[1] + g[2] * nbar[2]) / mean);
    }
}
