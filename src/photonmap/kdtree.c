/* Balanced kd-tree: in-place median build and N-nearest / radius queries (see kdtree.h). */
#include "kdtree.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../core/timing.h"

#define LEAF_AXIS 3u
#define STACK_MAX 64

void lm_kdtree_init(lm_kdtree *t) { memset(t, 0, sizeof *t); }

void lm_kdtree_free(lm_kdtree *t)
{
    free(t->nodes);
    memset(t, 0, sizeof *t);
}

/* ---------- build ---------- */

static inline void swap_nodes(lm_kd_node *a, lm_kd_node *b)
{
    lm_kd_node t = *a;
    *a = *b;
    *b = t;
}

static inline float median3(float a, float b, float c)
{
    if (a > b) {
        float t = a;
        a = b;
        b = t;
    }
    return c <= a ? a : c >= b ? b : c;
}

/* Puts the k-th smallest key (on axis) at k, smaller-or-equal keys before it, greater-or-equal after.
 * Hoare partitioning stops on keys equal to the pivot, so runs of duplicates split evenly (coincident
 * points cost O(n) per level, not O(n^2)). */
static void select_kth(lm_kd_node *nd, uint32_t lo, uint32_t hi, uint32_t k, int axis)
{
    while (hi - lo > 1) {
        float pivot = median3(nd[lo].p[axis], nd[lo + (hi - lo) / 2].p[axis], nd[hi - 1].p[axis]);
        int64_t i = lo, j = (int64_t)hi - 1;
        while (i <= j) {
            while (nd[i].p[axis] < pivot)
                i++;
            while (nd[j].p[axis] > pivot)
                j--;
            if (i <= j)
                swap_nodes(&nd[i++], &nd[j--]);
        }
        /* Now [lo, j] <= pivot, [i, hi) >= pivot, and anything between equals the pivot. */
        if ((int64_t)k <= j)
            hi = (uint32_t)(j + 1);
        else if ((int64_t)k >= i)
            lo = (uint32_t)i;
        else
            return;
    }
}

/* Axis of the largest extent of a box (min xyz, max xyz). */
static int widest_axis(const float box[6])
{
    float e0 = box[3] - box[0], e1 = box[4] - box[1], e2 = box[5] - box[2];
    return e1 > e0 ? (e2 > e1 ? 2 : 1) : (e2 > e0 ? 2 : 0);
}

/* Builds [lo, hi) inside box; children get the box cut at the median (a conservative bound, O(1) per
 * node instead of a pass over the range). */
static void build_range(lm_kd_node *nd, uint32_t lo, uint32_t hi, const float box[6])
{
    float b[6];
    memcpy(b, box, sizeof b);
    while (hi - lo > LM_KDTREE_LEAF) {
        int axis = widest_axis(b);
        uint32_t mid = lo + (hi - lo) / 2;
        select_kth(nd, lo, hi, mid, axis);
        nd[mid].meta = (nd[mid].meta & ~3u) | (uint32_t)axis;
        float left[6];
        memcpy(left, b, sizeof left);
        left[3 + axis] = nd[mid].p[axis];
        build_range(nd, lo, mid, left);
        b[axis] = nd[mid].p[axis];
        lo = mid + 1;
    }
}

lm_status lm_kdtree_build(lm_kdtree *t, const float *points, size_t stride, uint32_t count, lm_error *err)
{
    if (count > LM_KDTREE_MAX_POINTS || stride < 3)
        return lm_fail(err, LM_ERR_INVALID, "kd-tree: %u points (max %u), stride %zu", count,
                       LM_KDTREE_MAX_POINTS, stride);
    if (count > t->capacity) {
        lm_kd_node *grown = realloc(t->nodes, sizeof *grown * count);
        if (!grown)
            return lm_fail(err, LM_ERR_NOMEM, "kd-tree: no memory for %u points", count);
        t->nodes = grown;
        t->capacity = count;
    }
    t->count = 0;
    float box[6] = {INFINITY, INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY};
    for (uint32_t i = 0; i < count; i++) {
        const float *p = points + stride * i;
        if (!isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2]))
            return lm_fail(err, LM_ERR_INVALID, "kd-tree: point %u is not finite", i);
        lm_kd_node *n = &t->nodes[i];
        for (int a = 0; a < 3; a++) {
            n->p[a] = p[a];
            box[a] = p[a] < box[a] ? p[a] : box[a];
            box[3 + a] = p[a] > box[3 + a] ? p[a] : box[3 + a];
        }
        n->meta = i << 2 | LEAF_AXIS;
    }
    t->count = count;
    if (count)
        build_range(t->nodes, 0, count, box);
    return LM_OK;
}

/* ---------- queries ---------- */

/* The N-nearest collector. Small N (the common case, N <= KNN_BUFFER / 2) keeps candidates in an
 * unsorted buffer of 2N: once full, a selection keeps the N closest and their farthest becomes the
 * bound (amortised O(1) per candidate, few unpredictable branches). Larger N use a max-heap of N in the
 * caller's arrays (O(log N) per candidate, no allocation). */
#define KNN_BUFFER 512

typedef struct {
    float d2;
    uint32_t idx;
} cand;

typedef struct {
    uint32_t *idx;
    float *d2;
    cand *buf;     /* buffered mode when non-NULL */
    uint32_t count, n, cap;
    float top;       /* candidates farther than this cannot be among the n nearest (+inf at first) */
    uint32_t seen;   /* leaf points scanned while top was +inf ... */
    float seen_max;  /* ... and the farthest of them: n of them bound the n-th distance */
} knn;

/* Moves (idx, d2) down from slot i of the heap to where the max-heap order holds. */
static void sift_down(knn *h, uint32_t i, uint32_t idx, float d2)
{
    uint32_t n = h->count;
    for (;;) {
        uint32_t c = 2 * i + 1;
        if (c >= n)
            break;
        if (c + 1 < n && h->d2[c + 1] > h->d2[c])
            c++;
        if (h->d2[c] <= d2)
            break;
        h->d2[i] = h->d2[c];
        h->idx[i] = h->idx[c];
        i = c;
    }
    h->d2[i] = d2;
    h->idx[i] = idx;
}

/* Heap mode: the first n candidates are appended and heapified once; later ones replace the root. */
static void heap_insert(knn *h, uint32_t idx, float d2)
{
    if (h->count < h->n) {
        h->idx[h->count] = idx;
        h->d2[h->count++] = d2;
        if (h->count < h->n)
            return;
        for (uint32_t i = h->n / 2; i-- > 0;)
            sift_down(h, i, h->idx[i], h->d2[i]);
    } else if (d2 < h->d2[0]) {
        sift_down(h, 0, idx, d2);
    } else {
        return;
    }
    if (h->d2[0] < h->top)
        h->top = h->d2[0];
}

/* Puts the k-th smallest candidate at k, smaller-or-equal before it (Hoare partitioning, as select_kth). */
static void select_cand(cand *c, uint32_t count, uint32_t k)
{
    uint32_t lo = 0, hi = count;
    while (hi - lo > 1) {
        float pivot = median3(c[lo].d2, c[lo + (hi - lo) / 2].d2, c[hi - 1].d2);
        int64_t i = lo, j = (int64_t)hi - 1;
        while (i <= j) {
            while (c[i].d2 < pivot)
                i++;
            while (c[j].d2 > pivot)
                j--;
            if (i <= j) {
                cand t = c[i];
                c[i++] = c[j];
                c[j--] = t;
            }
        }
        if ((int64_t)k <= j)
            hi = (uint32_t)(j + 1);
        else if ((int64_t)k >= i)
            lo = (uint32_t)i;
        else
            return;
    }
}

/* Buffered mode: keeps the n closest candidates; the n-th becomes the bound. */
static void buffer_shrink(knn *k)
{
    select_cand(k->buf, k->count, k->n - 1);
    k->count = k->n;
    k->top = k->buf[k->n - 1].d2;
}

static inline float dist2(const float a[3], const float b[3])
{
    float dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
    return dx * dx + dy * dy + dz * dz;
}

static inline void add(knn *k, uint32_t idx, float d2)
{
    if (!k->buf) {
        heap_insert(k, idx, d2);
        return;
    }
    k->buf[k->count++] = (cand){d2, idx};
    if (k->count == k->cap)
        buffer_shrink(k);
}

static inline void consider(knn *k, const lm_kd_node *nd, const float q[3])
{
    float d2 = dist2(nd->p, q);
    if (d2 <= k->top)
        add(k, nd->meta >> 2, d2);
}

/* A leaf range. Before any bound exists, the first n leaf points seen (the ones nearest q in the
 * near-first order, unlike the medians met on the way down) give one: their farthest distance. */
static void scan_leaf(knn *k, const lm_kd_node *nd, uint32_t lo, uint32_t hi, const float q[3])
{
    if (k->top < INFINITY) {
        for (uint32_t i = lo; i < hi; i++)
            consider(k, &nd[i], q);
        return;
    }
    for (uint32_t i = lo; i < hi; i++) {
        float d2 = dist2(nd[i].p, q);
        k->seen_max = d2 > k->seen_max ? d2 : k->seen_max;
        add(k, nd[i].meta >> 2, d2);
    }
    k->seen += hi - lo;
    if (k->seen >= k->n && k->seen_max < k->top)
        k->top = k->seen_max;
}

typedef struct {
    uint32_t lo, hi;
    float d2; /* squared distance from q to the splitting plane that bounds this range */
} frame;

/* Depth-first, nearer side first; a range is skipped once its plane is no closer than the bound. */
static void knn_search(const lm_kdtree *t, const float q[3], knn *k)
{
    frame stack[STACK_MAX];
    int sp = 0;
    stack[sp++] = (frame){0, t->count, 0.0f};
    const lm_kd_node *nd = t->nodes;
    while (sp > 0) {
        frame f = stack[--sp];
        if (f.d2 > k->top) /* every point beyond that plane is farther than the bound */
            continue;
        uint32_t lo = f.lo, hi = f.hi;
        while (hi - lo > LM_KDTREE_LEAF) {
            uint32_t mid = lo + (hi - lo) / 2;
            const lm_kd_node *m = &nd[mid];
            float diff = q[m->meta & 3u] - m->p[m->meta & 3u];
            consider(k, m, q);
            if (diff < 0.0f) {
                stack[sp++] = (frame){mid + 1, hi, diff * diff};
                hi = mid;
            } else {
                stack[sp++] = (frame){lo, mid, diff * diff};
                lo = mid + 1;
            }
        }
        scan_leaf(k, nd, lo, hi, q);
    }
}

/* Index of the largest of d2[0..count). */
static uint32_t argmax(const float *d2, uint32_t count)
{
    uint32_t best = 0;
    for (uint32_t i = 1; i < count; i++)
        if (d2[i] > d2[best])
            best = i;
    return best;
}

uint32_t lm_kdtree_nearest(const lm_kdtree *t, const float q[3], uint32_t n, uint32_t *out_index, float *out_d2,
                           float *r2)
{
    cand buf[KNN_BUFFER];
    knn k = {out_index, out_d2, n <= KNN_BUFFER / 2 ? buf : NULL, 0, n, 2 * n, INFINITY, 0, 0.0f};
    if (n > 0 && t->count > 0)
        knn_search(t, q, &k);
    if (k.buf) {
        if (k.count > n)
            buffer_shrink(&k);
        for (uint32_t i = 0; i < k.count; i++) {
            out_index[i] = k.buf[i].idx;
            out_d2[i] = k.buf[i].d2;
        }
    }
    if (r2)
        *r2 = k.count ? out_d2[argmax(out_d2, k.count)] : 0.0f;
    return k.count;
}

uint32_t lm_kdtree_radius(const lm_kdtree *t, const float q[3], float r2, lm_kdtree_visit visit, void *ctx)
{
    frame stack[STACK_MAX];
    int sp = 0;
    uint32_t found = 0;
    if (t->count > 0 && r2 >= 0.0f)
        stack[sp++] = (frame){0, t->count, 0.0f};
    const lm_kd_node *nd = t->nodes;
    while (sp > 0) {
        frame f = stack[--sp];
        if (f.d2 > r2)
            continue;
        uint32_t lo = f.lo, hi = f.hi;
        while (hi - lo > LM_KDTREE_LEAF) {
            uint32_t mid = lo + (hi - lo) / 2;
            const lm_kd_node *m = &nd[mid];
            float diff = q[m->meta & 3u] - m->p[m->meta & 3u], d2 = dist2(m->p, q);
            if (d2 <= r2) {
                visit(ctx, m->meta >> 2, d2);
                found++;
            }
            if (diff < 0.0f) {
                stack[sp++] = (frame){mid + 1, hi, diff * diff};
                hi = mid;
            } else {
                stack[sp++] = (frame){lo, mid, diff * diff};
                lo = mid + 1;
            }
        }
        for (uint32_t i = lo; i < hi; i++) {
            float d2 = dist2(nd[i].p, q);
            if (d2 <= r2) {
                visit(ctx, nd[i].meta >> 2, d2);
                found++;
            }
        }
    }
    return found;
}

/* ---------- benchmark ---------- */

#define BENCH_RUNS 9
#define BENCH_QUERIES 2000
#define BENCH_K 100

static uint64_t bench_rng(uint64_t *s)
{
    *s ^= *s << 13;
    *s ^= *s >> 7;
    *s ^= *s << 17;
    return *s;
}

static float bench_uniform(uint64_t *s) { return (float)(bench_rng(s) >> 40) / 16777216.0f; }

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, cmp_double);
    return v[n / 2];
}

/* Milliseconds per build and per 100-nearest query over n photons on a unit square (a surface's map). */
static void bench_size(uint32_t n, double *build_ms, double *query_ms)
{
    uint64_t seed = 0x9E3779B97F4A7C15ull ^ n;
    float *pts = malloc(sizeof *pts * 3 * n), *qs = malloc(sizeof *qs * 3 * BENCH_QUERIES);
    uint32_t idx[BENCH_K];
    float d2[BENCH_K], r2, sink = 0.0f;
    double tb[BENCH_RUNS], tq[BENCH_RUNS];
    lm_kdtree t;
    lm_kdtree_init(&t);
    if (!pts || !qs) {
        *build_ms = *query_ms = NAN;
        free(pts);
        free(qs);
        return;
    }
    for (uint32_t i = 0; i < 3 * n; i++)
        pts[i] = i % 3 == 2 ? 0.0f : bench_uniform(&seed);
    for (uint32_t i = 0; i < 3 * BENCH_QUERIES; i++)
        qs[i] = i % 3 == 2 ? 0.0f : bench_uniform(&seed);
    int builds = (int)(200000 / n) + 1;
    for (int run = 0; run < BENCH_RUNS; run++) {
        double t0 = lm_now();
        for (int b = 0; b < builds; b++)
            lm_kdtree_build(&t, pts, 3, n, NULL);
        double t1 = lm_now();
        for (int i = 0; i < BENCH_QUERIES; i++) {
            lm_kdtree_nearest(&t, qs + 3 * i, BENCH_K, idx, d2, &r2);
            sink += r2;
        }
        double t2 = lm_now();
        tb[run] = (t1 - t0) * 1e3 / builds;
        tq[run] = (t2 - t1) * 1e3 / BENCH_QUERIES;
    }
    *build_ms = median(tb, BENCH_RUNS);
    *query_ms = sink >= 0.0f ? median(tq, BENCH_RUNS) : NAN;
    lm_kdtree_free(&t);
    free(pts);
    free(qs);
}

void lm_kdtree_bench_run(lm_kdtree_bench_row rows[LM_KDTREE_BENCH_ROWS])
{
    /* Larsen & Christensen 2004, Table 1: photons, irradiance lookup (100 photons), balancing time. */
    static const uint32_t sizes[LM_KDTREE_BENCH_ROWS] = {300, 500, 1000, 2000};
    static const double paper_query[LM_KDTREE_BENCH_ROWS] = {0.023, 0.027, 0.029, 0.034};
    static const double paper_build[LM_KDTREE_BENCH_ROWS] = {0.10, 0.18, 0.39, 0.84};
    for (int i = 0; i < LM_KDTREE_BENCH_ROWS; i++) {
        rows[i].points = sizes[i];
        rows[i].paper_build_ms = paper_build[i];
        rows[i].paper_query_ms = paper_query[i];
        bench_size(sizes[i], &rows[i].build_ms, &rows[i].query_ms);
    }
}

void lm_kdtree_bench(FILE *out)
{
    lm_kdtree_bench_row rows[LM_KDTREE_BENCH_ROWS];
    lm_kdtree_bench_run(rows);
    fprintf(out, "kd-tree (median of %d runs; paper = Larsen & Christensen 2004, Table 1)\n", BENCH_RUNS);
    fprintf(out, "%8s %12s %12s %8s %14s %14s %8s\n", "photons", "build ms", "paper ms", "speedup", "100-NN ms",
            "paper ms", "speedup");
    for (int i = 0; i < LM_KDTREE_BENCH_ROWS; i++) {
        const lm_kdtree_bench_row *r = &rows[i];
        fprintf(out, "%8u %12.4f %12.2f %7.1fx %14.5f %14.3f %7.1fx\n", r->points, r->build_ms, r->paper_build_ms,
                r->paper_build_ms / r->build_ms, r->query_ms, r->paper_query_ms, r->paper_query_ms / r->query_ms);
    }
}
