/* Balanced kd-tree with bucket leaves: in-place median build and N-nearest / radius queries (see
 * kdtree.h). */
#include "kdtree.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../core/timing.h"

#define STACK_MAX 64
#define LEAF LM_KDTREE_LEAF

void lm_kdtree_init(lm_kdtree *t) { memset(t, 0, sizeof *t); }

void lm_kdtree_free(lm_kdtree *t)
{
    free(t->nodes);
    free(t->x);
    free(t->index);
    free(t->split);
    free(t->axis);
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

/* Splits [lo, hi) inside box at its median into [lo, mid) and [mid, hi) until the ranges are leaves;
 * children get the box cut at the split (a conservative bound, O(1) per node). */
static void build_range(lm_kdtree *t, uint32_t lo, uint32_t hi, const float box[6])
{
    float b[6];
    memcpy(b, box, sizeof b);
    while (hi - lo > LEAF) {
        int axis = widest_axis(b);
        uint32_t mid = lo + (hi - lo) / 2;
        select_kth(t->nodes, lo, hi, mid, axis);
        float at = t->nodes[mid].p[axis];
        t->split[mid] = at;
        t->axis[mid] = (uint8_t)axis;
        float left[6];
        memcpy(left, b, sizeof left);
        left[3 + axis] = at;
        build_range(t, lo, mid, left);
        b[axis] = at;
        lo = mid;
    }
}

/* Grows the arrays to hold count points (coordinates with LEAF slots of padding). */
static lm_status reserve(lm_kdtree *t, uint32_t count, lm_error *err)
{
    if (count <= t->capacity && t->nodes)
        return LM_OK;
    lm_kdtree_free(t);
    size_t slots = (size_t)count + LEAF;
    t->nodes = malloc(sizeof *t->nodes * (count ? count : 1));
    t->x = calloc(3 * slots, sizeof *t->x);
    t->index = malloc(sizeof *t->index * (count ? count : 1));
    t->split = malloc(sizeof *t->split * (count ? count : 1));
    t->axis = malloc(count ? count : 1);
    if (!t->nodes || !t->x || !t->index || !t->split || !t->axis) {
        lm_kdtree_free(t);
        return lm_fail(err, LM_ERR_NOMEM, "kd-tree: no memory for %u points", count);
    }
    t->y = t->x + slots;
    t->z = t->y + slots;
    t->capacity = count;
    return LM_OK;
}

/* Copies the built order into the coordinate and index arrays the queries scan. */
static void publish(lm_kdtree *t)
{
    for (uint32_t i = 0; i < t->count; i++) {
        const lm_kd_node *n = &t->nodes[i];
        t->x[i] = n->p[0];
        t->y[i] = n->p[1];
        t->z[i] = n->p[2];
        t->index[i] = n->index;
    }
    for (uint32_t i = t->count; i < t->count + LEAF; i++) /* padding read by the fixed-width scans */
        t->x[i] = t->y[i] = t->z[i] = 0.0f;
}

lm_status lm_kdtree_build(lm_kdtree *t, const float *points, size_t stride, uint32_t count, lm_error *err)
{
    if (count > LM_KDTREE_MAX_POINTS || stride < 3)
        return lm_fail(err, LM_ERR_INVALID, "kd-tree: %u points (max %u), stride %zu", count,
                       LM_KDTREE_MAX_POINTS, stride);
    t->count = 0;
    lm_status st = reserve(t, count, err);
    if (st != LM_OK)
        return st;
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
        n->index = i;
    }
    t->count = count;
    if (count)
        build_range(t, 0, count, box);
    publish(t);
    return LM_OK;
}

/* ---------- traversal ---------- */

/* A range still to visit, q's per-axis offsets to its cell (0 where q is inside the cell's slab) and
 * the squared distance they make. */
typedef struct {
    uint32_t lo, hi;
    float off[3], d2;
} frame;

/* Squared distance from q to a cell. The same operations as the point distance, so for any point p of
 * the cell it is <= the computed |p - q|^2 exactly (rounding is monotone). */
static inline float cell_d2(float ox, float oy, float oz) { return ox * ox + oy * oy + oz * oz; }

/* Squared distances from q to the LEAF points from slot lo (the padding makes the fixed width safe). */
static inline void leaf_d2(const lm_kdtree *t, uint32_t lo, const float q[3], float d2[LEAF])
{
    const float *x = t->x + lo, *y = t->y + lo, *z = t->z + lo;
    float qx = q[0], qy = q[1], qz = q[2];
    for (uint32_t i = 0; i < LEAF; i++) {
        float dx = x[i] - qx, dy = y[i] - qy, dz = z[i] - qz;
        d2[i] = dx * dx + dy * dy + dz * dz;
    }
}

/* Steps the range f down to its child on q's side until it is a leaf; each farther child is pushed
 * (without a branch) unless its cell is beyond bound. */
static inline void descend(const lm_kdtree *t, const float q[3], frame *f, frame *stack, int *sp, float bound)
{
    uint32_t lo = f->lo, hi = f->hi;
    float ox = f->off[0], oy = f->off[1], oz = f->off[2];
    int n = *sp;
    while (hi - lo > LEAF) {
        uint32_t mid = lo + (hi - lo) / 2;
        int a = t->axis[mid];
        float diff = q[a] - t->split[mid];
        float fx = a == 0 ? diff : ox, fy = a == 1 ? diff : oy, fz = a == 2 ? diff : oz;
        float fd = cell_d2(fx, fy, fz);
        int left = diff < 0.0f;
        stack[n] = (frame){left ? mid : lo, left ? hi : mid, {fx, fy, fz}, fd};
        n += !(fd > bound);
        lo = left ? lo : mid;
        hi = left ? mid : hi;
    }
    *sp = n;
    f->lo = lo;
    f->hi = hi;
}

/* ---------- N nearest ---------- */

/* Candidates are keys (bits of d2 << 32 | index): d2 >= 0, so the keys order by distance, then index.
 * N <= KNN_FAST (the common case) keeps them in a buffer in the order the search meets them: leaf points
 * within the bound are appended without branches, and when 2N have gathered, the N-th smallest is
 * selected (quickselect with branch-free partitioning, on a copy) and becomes the bound, and the buffer
 * keeps the keys up to it, in order. So the answer lists the N nearest in the search's leaf order (nearer
 * side first), which depends only on the tree and the query, not on the bound the search started with.
 * Larger N use a max-heap of N in the caller's arrays. */
#define KNN_FAST 256u
#define KNN_BUFFER (2 * KNN_FAST + LEAF)

typedef struct {
    uint64_t *buf;       /* buffered mode when non-NULL */
    uint32_t *idx;       /* heap mode */
    float *d2;
    uint32_t count, n, cap;
    uint32_t top_bits;   /* keys with more d2 bits cannot be among the n nearest (all ones at first) */
    float top;           /* the same bound as a float, for cells (+inf at first) */
} knn;

static inline uint32_t float_bits(float f)
{
    uint32_t b;
    memcpy(&b, &f, sizeof b);
    return b;
}

static inline float bits_float(uint32_t b)
{
    float f;
    memcpy(&f, &b, sizeof f);
    return f;
}

static inline uint64_t make_key(float d2, uint32_t idx) { return (uint64_t)float_bits(d2) << 32 | idx; }

static inline float key_d2(uint64_t key) { return bits_float((uint32_t)(key >> 32)); }

static void set_bound(knn *k, uint64_t key)
{
    k->top_bits = (uint32_t)(key >> 32);
    k->top = bits_float(k->top_bits);
}

/* Moves in[lo, hi) but the pivot in[p] apart into out[lo, hi), without branches: smaller keys to the
 * front, larger to the back (keys are distinct), and the pivot into the one slot left between them,
 * whose index is returned. in is only read. */
static uint32_t split_keys(const uint64_t *in, uint64_t *out, uint32_t lo, uint32_t hi, uint32_t p)
{
    uint64_t pivot = in[p];
    uint32_t front = lo, back = hi - 1;
    for (uint32_t pass = 0; pass < 2; pass++) { /* [lo, p), then (p, hi): the pivot skipped without a test */
        uint32_t from = pass ? p + 1 : lo, to = pass ? hi : p;
        for (uint32_t i = from; i < to; i++) {
            uint64_t v = in[i];
            uint32_t less = v < pivot;
            out[front] = v;
            out[back] = v;
            front += less;
            back -= 1u - less;
        }
    }
    out[front] = pivot;
    return front;
}

/* Index (of lo, mid, hi) of the median of the three keys. */
static uint32_t median3_at(const uint64_t *a, uint32_t lo, uint32_t mid, uint32_t hi)
{
    uint64_t x = a[lo], y = a[mid], z = a[hi];
    if (x < y)
        return y < z ? mid : x < z ? hi : lo;
    return x < z ? lo : y < z ? hi : mid;
}

/* The k-th smallest (from 0) of the distinct keys src[0, m), k < m, src left as it is: quickselect whose
 * partitions go back and forth between the scratch arrays x and y (room for m each) instead of being
 * copied back after every step. */
static uint64_t nth_key(const uint64_t *src, uint64_t *x, uint64_t *y, uint32_t m, uint32_t k)
{
    const uint64_t *in = src;
    uint64_t *out = x;
    uint32_t lo = 0, hi = m;
    while (hi - lo > 1) {
        uint32_t j = split_keys(in, out, lo, hi, median3_at(in, lo, lo + (hi - lo) / 2, hi - 1));
        if (k == j)
            return out[j];
        if (k < j)
            hi = j;
        else
            lo = j + 1;
        in = out;
        out = out == x ? y : x;
    }
    return in[lo];
}

/* The n-th smallest of the distinct keys a[0, count) (n <= count), a left as it is. Keys with distances
 * below lo (a guess: 0 when none) are only counted, and the n-th is selected among the others when the
 * count shows it is one of them, else among all. */
static uint64_t nth_smallest(const uint64_t *a, uint32_t count, uint32_t n, float lo)
{
    uint64_t sel[KNN_BUFFER], tmp[KNN_BUFFER], lo_key = make_key(lo, 0);
    if (!(lo > 0.0f)) /* no guess: every key is a candidate */
        return nth_key(a, sel, tmp, count, n - 1);
    uint32_t below = 0, m = 0;
    for (uint32_t i = 0; i < count; i++) { /* written without a branch, kept when not below */
        sel[m] = a[i];
        m += a[i] >= lo_key;
        below += a[i] < lo_key;
    }
    if (below >= n)
        return nth_key(a, sel, tmp, count, n - 1);
    return nth_key(sel, tmp, sel, m, n - 1 - below); /* sel is read once before it is written */
}

/* Keeps the keys of a[0, count) up to max, in order; returns how many. */
static uint32_t keep_up_to(uint64_t *a, uint32_t count, uint64_t max)
{
    uint32_t w = 0;
    for (uint32_t i = 0; i < count; i++) {
        a[w] = a[i];
        w += a[i] <= max;
    }
    return w;
}

/* Largest key of a[0, count). */
static uint64_t max_key(const uint64_t *a, uint32_t count)
{
    uint64_t m = 0;
    for (uint32_t i = 0; i < count; i++)
        m = a[i] > m ? a[i] : m;
    return m;
}

/* Keeps the n nearest candidates (in order); the farthest of them becomes the bound. */
static void buffer_shrink(knn *k)
{
    uint64_t nth = nth_smallest(k->buf, k->count, k->n, 0.0f);
    k->count = keep_up_to(k->buf, k->count, nth);
    set_bound(k, nth);
}

static void buffer_leaf(knn *k, const float d2[LEAF], const uint32_t *idx, uint32_t m)
{
    uint64_t *buf = k->buf;
    uint32_t c = k->count, top = k->top_bits;
    for (uint32_t i = 0; i < m; i++) {
        uint32_t b = float_bits(d2[i]);
        buf[c] = (uint64_t)b << 32 | idx[i];
        c += b <= top;
    }
    k->count = c;
    if (c >= k->cap)
        buffer_shrink(k);
    else if (top == UINT32_MAX && c >= k->n) /* the first n points seen bound the n-th distance */
        set_bound(k, max_key(buf, c));
}

/* Heap mode: a max-heap on keys in the caller's arrays. Moves key down from slot i to its place. */
static void sift_down(knn *h, uint32_t i, uint64_t key)
{
    uint32_t n = h->count;
    for (;;) {
        uint32_t c = 2 * i + 1;
        if (c >= n)
            break;
        uint64_t kc = make_key(h->d2[c], h->idx[c]);
        if (c + 1 < n) {
            uint64_t k1 = make_key(h->d2[c + 1], h->idx[c + 1]);
            if (k1 > kc) {
                c++;
                kc = k1;
            }
        }
        if (kc <= key)
            break;
        h->d2[i] = h->d2[c];
        h->idx[i] = h->idx[c];
        i = c;
    }
    h->d2[i] = key_d2(key);
    h->idx[i] = (uint32_t)key;
}

/* The first n keys are appended and heapified once; later ones replace the root when smaller. */
static void heap_insert(knn *h, uint64_t key)
{
    if (h->count < h->n) {
        h->idx[h->count] = (uint32_t)key;
        h->d2[h->count++] = key_d2(key);
        if (h->count < h->n)
            return;
        for (uint32_t i = h->n / 2; i-- > 0;)
            sift_down(h, i, make_key(h->d2[i], h->idx[i]));
    } else if (key < make_key(h->d2[0], h->idx[0])) {
        sift_down(h, 0, key);
    } else {
        return;
    }
    set_bound(h, make_key(h->d2[0], h->idx[0]));
}

static void heap_leaf(knn *k, const float d2[LEAF], const uint32_t *idx, uint32_t m)
{
    for (uint32_t i = 0; i < m; i++)
        if (float_bits(d2[i]) <= k->top_bits)
            heap_insert(k, make_key(d2[i], idx[i]));
}

/* Depth-first, nearer side first; a cell is skipped once it is farther than the bound. */
static void knn_search(const lm_kdtree *t, const float q[3], knn *k)
{
    frame stack[STACK_MAX];
    int sp = 0;
    stack[sp++] = (frame){0, t->count, {0.0f, 0.0f, 0.0f}, 0.0f};
    float d2[LEAF];
    while (sp > 0) {
        frame f = stack[--sp];
        if (f.d2 > k->top)
            continue;
        descend(t, q, &f, stack, &sp, k->top);
        leaf_d2(t, f.lo, q, d2);
        if (k->buf)
            buffer_leaf(k, d2, t->index + f.lo, f.hi - f.lo);
        else
            heap_leaf(k, d2, t->index + f.lo, f.hi - f.lo);
    }
}

/* Largest of d2[0..count). */
static float largest(const float *d2, uint32_t count)
{
    float m = d2[0];
    for (uint32_t i = 1; i < count; i++)
        m = d2[i] > m ? d2[i] : m;
    return m;
}

uint32_t lm_kdtree_nearest(const lm_kdtree *t, const float q[3], uint32_t n, uint32_t *out_index, float *out_d2,
                           float *r2)
{
    return lm_kdtree_nearest_within(t, q, n, INFINITY, out_index, out_d2, r2);
}

/* The search with the candidates' bound at max_d2; lo_d2 is a guess at a squared distance below the n-th
 * (0: none), which only speeds up the selection. */
static uint32_t nearest_between(const lm_kdtree *t, const float q[3], uint32_t n, float lo_d2, float max_d2,
                                uint32_t *out_index, float *out_d2, float *r2)
{
    uint64_t buf[KNN_BUFFER];
    uint32_t top = max_d2 < INFINITY ? float_bits(max_d2 > 0.0f ? max_d2 : 0.0f) : UINT32_MAX;
    knn k = {n <= KNN_FAST ? buf : NULL, out_index, out_d2, 0, n, 2 * n, top, max_d2};
    if (n > 0 && t->count > 0)
        knn_search(t, q, &k);
    float far = 0.0f;
    if (k.buf) {
        uint64_t last = k.count > n ? nth_smallest(buf, k.count, n, lo_d2) : max_key(buf, k.count);
        uint32_t w = 0;
        for (uint32_t i = 0; i < k.count && w < n; i++) { /* written without a branch, kept up to the n-th */
            out_index[w] = (uint32_t)buf[i];
            out_d2[w] = key_d2(buf[i]);
            w += buf[i] <= last;
        }
        k.count = w;
        far = key_d2(last);
    } else if (k.count) {
        far = largest(out_d2, k.count);
    }
    if (r2)
        *r2 = k.count ? far : 0.0f;
    return k.count;
}

uint32_t lm_kdtree_nearest_within(const lm_kdtree *t, const float q[3], uint32_t n, float max_d2,
                                  uint32_t *out_index, float *out_d2, float *r2)
{
    return nearest_between(t, q, n, 0.0f, max_d2, out_index, out_d2, r2);
}

#define HINT_SLACK 1e-5 /* relative margin over the rounding of computed distances (a few float ulps) */

uint32_t lm_kdtree_nearest_hinted(const lm_kdtree *t, lm_kdtree_hint *h, const float q[3], uint32_t n,
                                  uint32_t *out_index, float *out_d2, float *r2)
{
    uint32_t k = 0, want = n < t->count ? n : t->count;
    float found = 0.0f;
    if (h->valid) { /* q's n-th distance is within the step from the last query of the last n-th distance */
        double dx = (double)q[0] - h->q[0], dy = (double)q[1] - h->q[1], dz = (double)q[2] - h->q[2];
        double step = sqrt(dx * dx + dy * dy + dz * dz), r = sqrt((double)h->r2);
        double lo = (r - step) * (1.0 - HINT_SLACK), hi = (r + step) * (1.0 + HINT_SLACK);
        k = nearest_between(t, q, n, lo > 0.0 ? (float)(lo * lo) : 0.0f, (float)(hi * hi), out_index, out_d2,
                            &found);
    }
    if (k < want) /* no hint, or rounding left the bound short */
        k = lm_kdtree_nearest(t, q, n, out_index, out_d2, &found);
    *h = (lm_kdtree_hint){1, {q[0], q[1], q[2]}, found};
    if (r2)
        *r2 = found;
    return k;
}

/* ---------- radius ---------- */

uint32_t lm_kdtree_radius(const lm_kdtree *t, const float q[3], float r2, lm_kdtree_visit visit, void *ctx)
{
    frame stack[STACK_MAX];
    int sp = 0;
    uint32_t found = 0;
    if (t->count > 0 && r2 >= 0.0f)
        stack[sp++] = (frame){0, t->count, {0.0f, 0.0f, 0.0f}, 0.0f};
    float d2[LEAF];
    while (sp > 0) {
        frame f = stack[--sp];
        descend(t, q, &f, stack, &sp, r2);
        leaf_d2(t, f.lo, q, d2);
        for (uint32_t i = 0; i < f.hi - f.lo; i++)
            if (d2[i] <= r2) {
                visit(ctx, t->index[f.lo + i], d2[i]);
                found++;
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
