/* Atlas packing: charts sorted by height go onto shelves (next-fit decreasing height), O(n log n); onto
 * pages (pages.c) where they do not fit one atlas of max_size a side. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../core/log.h"
#include "charts_internal.h"

/* Atlas width relative to the square root of the padded chart area: room for shelf waste. */
#define WIDTH_SLACK 1.1
#define MAX_RETRIES 64

static int cmp_rect(const void *a, const void *b)
{
    const lmc_rect *p = a, *q = b;
    if (p->h != q->h)
        return p->h > q->h ? -1 : 1;
    if (p->w != q->w)
        return p->w > q->w ? -1 : 1;
    return (p->id > q->id) - (p->id < q->id);
}

static int round4(double v) { return 4 * (int)ceil(v / 4.0); }

/* Texels a chart extent of t texels needs, and the border of its own (*pad) it keeps around them. One
 * texel below a texel (all of it shown as that texel). Below LMC_PAD_MIN, enough that the extent, centred
 * (lmc_chart_offset), lies between the first and last texel centres, where a bilinear lookup reads
 * nothing outside the rect: no border. A wider chart keeps the texels its extent covers and a border of
 * one texel, which its lookups reach and its own light fills (lm_atlas_dilate): the texel more would
 * place its texels half a texel apart from where they sit at every other size. */
static int texels_for(double t, int *pad)
{
    int covered = (int)floor(t + 0.01) + 1;
    *pad = covered >= LMC_PAD_MIN;
    return t + 0.01 < 1.0 ? 1 : *pad ? covered : (int)ceil(t - 1e-6) + 1;
}

void lmc_chart_offset(const lmc_chart *c, const lm_chart *r, float texel_size, double off[2])
{
    off[0] = 0.5 * ((double)r->w - lmc_chart_texels(c, 0, texel_size));
    off[1] = 0.5 * ((double)r->h - lmc_chart_texels(c, 1, texel_size));
}

/* Shelf-packs the sorted rects into width W (gutter g around every rect and the border); returns the
 * height used. W is at least the widest rect plus two gutters. */
static long shelf_pack(const lmc_rect *k, int n, int W, int g, lm_chart *ch)
{
    long x = g, y = g, shelf = 0;
    for (int i = 0; i < n; i++) {
        if (x + k[i].w + g > W) {
            y += shelf + g;
            x = g;
            shelf = 0;
        }
        ch[k[i].id].x = (int)x + ch[k[i].id].pad; /* the rect inside its border */
        ch[k[i].id].y = (int)y + ch[k[i].id].pad;
        x += k[i].w + g;
        if (k[i].h > shelf)
            shelf = k[i].h;
    }
    return y + shelf + g;
}

/* The charts' rects at texel size ts into out->charts and k, sorted tallest first, with their area
 * (gutters included) and the widest; 0, or the side a chart too large for max_size would need. */
static double size_rects(const lmc_charts *c, lmc_rect *k, float ts, int g, int max_size, lm_atlas *out,
                         double *area, double *widest)
{
    *area = *widest = 0.0;
    for (int i = 0; i < c->count; i++) {
        lm_chart *r = &out->charts[i];
        double ew = lmc_chart_texels(&c->charts[i], 0, ts), eh = lmc_chart_texels(&c->charts[i], 1, ts);
        if (!(ew < max_size && eh < max_size))
            return fmax(ew, eh) + 2.0 * g + 1.0;
        int px, py;
        r->w = texels_for(ew, &px);
        r->h = texels_for(eh, &py);
        r->pad = px | py;
        r->page = 0;
        k[i] = (lmc_rect){r->w + 2 * r->pad, r->h + 2 * r->pad, i};
        *area += (double)(k[i].w + g) * (double)(k[i].h + g);
        *widest = fmax(*widest, k[i].w);
    }
    qsort(k, (size_t)c->count, sizeof *k, cmp_rect);
    return 0.0;
}

/* The sorted rects in one atlas of at most max_size a side: 0 if they fit, else the side it would need. */
static double one_page(const lmc_charts *c, const lmc_rect *k, double area, double widest, int g, int max_size,
                       lm_atlas *out)
{
    /* A few widths around the square root of the area; the smallest atlas that fits wins. */
    static const double slack[] = {1.0, 1.05, WIDTH_SLACK, 1.2, 1.35, 1.5};
    int best_w = 0, best_h = 0;
    double need = DBL_MAX;
    for (size_t i = 0; i < sizeof slack / sizeof *slack; i++) {
        int W = round4(fmax(fmax(sqrt(area) * slack[i] + g, widest + 2.0 * g), 4.0)); /* 4: no charts at all */
        int H = round4((double)shelf_pack(k, c->count, W, g, out->charts));
        if (W <= max_size && H <= max_size) {
            if (!best_w || (double)W * H < (double)best_w * best_h) {
                best_w = W;
                best_h = H;
            }
        } else {
            need = fmin(need, fmax(W, H));
        }
    }
    if (!best_w)
        return need;
    shelf_pack(k, c->count, best_w, g, out->charts);
    out->width = out->page_width = best_w;
    out->height = out->page_height = best_h;
    out->page_count = out->page_columns = 1;
    return 0.0;
}

/* The largest side of the rects. */
static int largest_side(const lmc_rect *k, int n)
{
    int m = 0;
    for (int i = 0; i < n; i++) {
        int side = k[i].w > k[i].h ? k[i].w : k[i].h;
        m = side > m ? side : m;
    }
    return m;
}

/* One packing attempt at texel size ts: one atlas where the charts fit one, else pages. 0 if it fits,
 * else the page side it would need (the texel size grows by that over max_size). */
static double try_pack(const lmc_charts *c, const lm_surfaces *su, lmc_rect *k, float ts, int g, int max_size,
                       lm_atlas *out, lm_status *st, lm_error *err)
{
    double area, widest, need = size_rects(c, k, ts, g, max_size, out, &area, &widest);
    if (need > 0.0) /* a chart larger than max_size */
        return need;
    need = one_page(c, k, area, widest, g, max_size, out);
    if (need == 0.0) {
        out->texel_size = ts;
        return 0.0;
    }
    if (2 * max_size > LM_ATLAS_MAX_SIDE) /* no room for two pages: one atlas, as large as it must be */
        return need;
    int largest = largest_side(k, c->count), side = max_size / 4 * 4; /* pages a multiple of 4, as one atlas */
    if (largest + 2 * g > side) /* a chart larger than a page: it must shrink, whatever the pages */
        return (largest + 2.0 * g + 1.0) * max_size / side;
    double grow;
    *st = lmc_pack_pages(c, su, k, side, g, out, &grow, err);
    if (*st != LM_OK || grow == 0.0) {
        out->texel_size = ts;
        return 0.0;
    }
    return grow * max_size;
}

lm_status lmc_pack(const lmc_charts *c, const lm_surfaces *su, float texel_size, int gutter, int max_size,
                   lm_atlas *out, lm_error *err)
{
    if (!(texel_size > 0.0f) || !isfinite(texel_size))
        return lm_fail(err, LM_ERR_INVALID, "charts: texel size %g to pack at (a positive, finite size)",
                       (double)texel_size);
    out->charts = calloc((size_t)c->count + 1, sizeof *out->charts);
    lmc_rect *k = malloc(((size_t)c->count + 1) * sizeof *k);
    if (!out->charts || !k) {
        free(k);
        return lm_fail(err, LM_ERR_NOMEM, "charts: out of memory while packing");
    }
    out->chart_count = c->count;
    out->gutter = gutter;
    float ts = texel_size;
    int ok = 0;
    lm_status st = LM_OK;
    for (int i = 0; i < MAX_RETRIES && !ok && st == LM_OK; i++) {
        double need = try_pack(c, su, k, ts, gutter, max_size, out, &st, err);
        ok = need == 0.0;
        if (!ok) /* sides shrink in proportion to the texel size */
            ts *= (float)fmax(1.02, need / max_size);
    }
    free(k);
    if (st != LM_OK)
        return st;
    if (!ok)
        return lm_fail(err, LM_ERR_INVALID, "charts: %d charts do not fit a %dx%d atlas even at texel size %g",
                       c->count, max_size, max_size, (double)ts);
    if (ts != texel_size && out->page_count == 1)
        lm_warn("charts: atlas would exceed %d texels a side at texel size %g; texel size raised to %g (%dx%d)",
                max_size, (double)texel_size, (double)ts, out->width, out->height);
    else if (ts != texel_size)
        lm_warn("charts: a chart larger than a page of %d texels a side, or pages past a %d x %d atlas, at texel "
                "size %g; texel size raised to %g (%d pages of %dx%d)", max_size, LM_ATLAS_MAX_SIDE,
                LM_ATLAS_MAX_SIDE, (double)texel_size, (double)ts, out->page_count, out->page_width,
                out->page_height);
    for (int i = 0; i < c->count; i++) {
        out->charts[i].surface = c->charts[i].surface;
        out->charts[i].texel_size = (float)(out->texel_size * c->charts[i].texel_scale);
    }
    return LM_OK;
}
