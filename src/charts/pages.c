/* Pages: charts that do not fit one atlas of max_size a side are shelf-packed onto pages of that side,
 * which then lie side by side in a grid in the one atlas every pass samples (charts.h, "Pages").
 *
 * Engines give an object one lightmap, so charts go onto pages in units: a node's charts together where
 * they fit one page, a larger node's surface by surface, a surface larger than a page chart by chart.
 * Pages are filled one after the other: the units, largest first, each taken where it still fits, the
 * page's charts shelf-packed tallest first as lmc_pack packs one atlas (a unit's charts spread over the
 * page's shelves among the others': units packed whole, each in its own block or on shelves of their
 * own, left a third to two thirds of many_rooms' pages empty under the small charts of one unit beside
 * the tall ones of the next). A page stops after MAX_MISSES units that pass the area test but not the
 * packing. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "charts_internal.h"

#define MAX_MISSES 32

/* Charts placed together: order[first .. first + count), tallest first (ascending rank). */
typedef struct {
    int first, count;
    double area;  /* with their gutters */
} unit;

typedef struct {
    int node, surface, rank; /* rank: the chart's place in k (tallest first) */
} chart_key;

typedef struct {
    const lmc_rect *k;
    int n, side, gutter;
    int *order;       /* ranks into k, unit by unit */
    unit *units;
    int unit_count;
    int *page, *x, *y; /* per rank: its page and the corner of its rect (border included) there */
    int *on, *merged;  /* the open page's ranks, ascending, and a scratch list as long */
    int on_count;
    int pages, used_w, used_h; /* pages filled, the widest and tallest of them */
} packer;

/* Shelf-packs ranks[0..count) (ascending: tallest first) into a page as pack.c's shelf_pack does:
 * whether they fit its height, their corners into x, y (by rank) when `place`, the size used in *w, *h. */
static int shelves(packer *p, const int *ranks, int count, int place, int *w, int *h)
{
    int g = p->gutter, x = g, y = g, shelf = 0, width = 0;
    for (int i = 0; i < count; i++) {
        const lmc_rect *r = &p->k[ranks[i]];
        if (x + r->w + g > p->side) {
            y += shelf + g;
            x = g;
            shelf = 0;
        }
        if (y + (r->h > shelf ? r->h : shelf) + g > p->side)
            return 0;
        if (place)
            p->x[ranks[i]] = x, p->y[ranks[i]] = y;
        x += r->w + g;
        shelf = r->h > shelf ? r->h : shelf;
        width = x > width ? x : width;
    }
    *w = width, *h = y + shelf + g;
    return 1;
}

/* Whether the charts order[first .. first + n) fit one empty page. */
static int fits_alone(packer *p, int first, int n)
{
    int w, h;
    memcpy(p->merged, p->order + first, (size_t)n * sizeof(int));
    return shelves(p, p->merged, n, 0, &w, &h);
}

static void add_unit(packer *p, int first, int n)
{
    unit *u = &p->units[p->unit_count++];
    *u = (unit){first, n, 0.0};
    for (int i = first; i < first + n; i++) {
        const lmc_rect *r = &p->k[p->order[i]];
        u->area += (double)(r->w + p->gutter) * (r->h + p->gutter);
    }
}

static int by_node(const void *a, const void *b)
{
    const chart_key *x = a, *y = b;
    return x->node != y->node ? (x->node > y->node) - (x->node < y->node) : (x->rank > y->rank) - (x->rank < y->rank);
}

static int by_surface(const void *a, const void *b)
{
    const chart_key *x = a, *y = b;
    return x->surface != y->surface ? (x->surface > y->surface) - (x->surface < y->surface)
                                    : (x->rank > y->rank) - (x->rank < y->rank);
}

static int by_area(const void *a, const void *b)
{
    const unit *x = a, *y = b;
    if (x->area != y->area)
        return x->area > y->area ? -1 : 1;
    return (x->first > y->first) - (x->first < y->first);
}

/* The units: each node's charts, or where they do not fit one page each surface's, or each chart;
 * largest first. */
static void make_units(packer *p, chart_key *keys)
{
    int n = p->n;
    qsort(keys, (size_t)n, sizeof *keys, by_node);
    for (int i = 0; i < n; i++)
        p->order[i] = keys[i].rank;
    for (int i = 0, end; i < n; i = end) {
        for (end = i; end < n && keys[end].node == keys[i].node; end++)
            ;
        if (fits_alone(p, i, end - i)) {
            add_unit(p, i, end - i);
            continue;
        }
        qsort(keys + i, (size_t)(end - i), sizeof *keys, by_surface);
        for (int j = i; j < end; j++)
            p->order[j] = keys[j].rank;
        for (int j = i, stop; j < end; j = stop) {
            for (stop = j; stop < end && keys[stop].surface == keys[j].surface; stop++)
                ;
            if (fits_alone(p, j, stop - j))
                add_unit(p, j, stop - j);
            else
                for (int m = j; m < stop; m++)
                    add_unit(p, m, 1);
        }
    }
    qsort(p->units, (size_t)p->unit_count, sizeof *p->units, by_area);
}

/* The open page's charts with unit u's merged in, ascending, into p->merged; returns their count. */
static int merge_unit(packer *p, const unit *u)
{
    int a = 0, b = 0, m = 0;
    const int *add = p->order + u->first;
    while (a < p->on_count || b < u->count)
        p->merged[m++] = b == u->count || (a < p->on_count && p->on[a] < add[b]) ? p->on[a++] : add[b++];
    return m;
}

/* Fills one page from the units not yet placed (placed[u] 0), largest first; returns how many it took. */
static int fill_page(packer *p, char *placed)
{
    double area = 0.0, room = (double)p->side * p->side;
    int taken = 0, misses = 0, w, h;
    p->on_count = 0;
    for (int u = 0; u < p->unit_count && misses < MAX_MISSES; u++) {
        if (placed[u] || area + p->units[u].area > room)
            continue;
        int m = merge_unit(p, &p->units[u]);
        if (!shelves(p, p->merged, m, 0, &w, &h)) {
            misses++;
            continue;
        }
        int *t = p->on;
        p->on = p->merged, p->merged = t, p->on_count = m;
        placed[u] = 1;
        area += p->units[u].area;
        taken++;
    }
    shelves(p, p->on, p->on_count, 1, &w, &h);
    for (int i = 0; i < p->on_count; i++)
        p->page[p->on[i]] = p->pages;
    p->pages++;
    p->used_w = w > p->used_w ? w : p->used_w;
    p->used_h = h > p->used_h ? h : p->used_h;
    return taken;
}

static int round4(int v) { return (v + 3) / 4 * 4; }

/* The pages into a near-square grid of at most LM_ATLAS_MAX_SIDE a side: the charts' places in the
 * atlas and its page geometry. *grow as lmc_pack_pages gives it. */
static void lay_grid(const packer *p, lm_atlas *out, double *grow)
{
    int pw = round4(p->used_w) < p->side ? round4(p->used_w) : p->side;
    int ph = round4(p->used_h) < p->side ? round4(p->used_h) : p->side;
    int across = LM_ATLAS_MAX_SIDE / pw, down = LM_ATLAS_MAX_SIDE / ph;
    if ((double)p->pages > (double)across * down) {
        *grow = sqrt(p->pages / ((double)across * down));
        return;
    }
    int cols = (int)ceil(sqrt((double)p->pages));
    cols = cols < across ? cols : across;
    if ((p->pages + cols - 1) / cols > down)
        cols = across;
    *grow = 0.0;
    out->page_width = pw, out->page_height = ph;
    out->page_count = p->pages, out->page_columns = cols;
    out->width = cols * pw;
    out->height = (p->pages + cols - 1) / cols * ph;
    for (int r = 0; r < p->n; r++) {
        lm_chart *c = &out->charts[p->k[r].id];
        c->page = p->page[r];
        c->x = c->page % cols * pw + p->x[r] + c->pad; /* the rect inside its border */
        c->y = c->page / cols * ph + p->y[r] + c->pad;
    }
}

lm_status lmc_pack_pages(const lmc_charts *c, const lm_surfaces *su, const lmc_rect *k, int side, int gutter,
                         lm_atlas *out, double *grow, lm_error *err)
{
    size_t n = (size_t)c->count + 1;
    packer p = {.k = k, .n = c->count, .side = side, .gutter = gutter};
    p.order = malloc(n * sizeof(int)), p.units = malloc(n * sizeof(unit));
    p.page = malloc(n * sizeof(int)), p.x = malloc(n * sizeof(int)), p.y = malloc(n * sizeof(int));
    p.on = malloc(n * sizeof(int)), p.merged = malloc(n * sizeof(int));
    chart_key *keys = malloc(n * sizeof *keys);
    char *placed = calloc(n, 1);
    int ok = p.order && p.units && p.page && p.x && p.y && p.on && p.merged && keys && placed;
    for (int r = 0; ok && r < c->count; r++) {
        int surface = c->charts[k[r].id].surface;
        keys[r] = (chart_key){su->surfaces[surface].node, surface, r};
    }
    int left = 0;
    if (ok) {
        make_units(&p, keys);
        left = p.unit_count;
        for (int took = 1; left > 0 && took > 0; left -= took) /* a unit fits an empty page: a page takes one */
            took = fill_page(&p, placed);
        if (!left)
            lay_grid(&p, out, grow);
    }
    free(p.order), free(p.units), free(p.page), free(p.x), free(p.y), free(p.on), free(p.merged);
    free(keys), free(placed);
    if (!ok)
        return lm_fail(err, LM_ERR_NOMEM, "charts: out of memory while packing %d charts onto pages", c->count);
    return left ? lm_fail(err, LM_ERR_INVALID, "charts: %d units of charts fit no page of %d texels", left, side) : LM_OK;
}
