#include "caustic_split.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../core/vecmath.h"

void lm_caustic_split_free(lm_caustic_split *sp)
{
    free(sp->thin);
    free(sp->screen);
    memset(sp, 0, sizeof *sp);
}

/* The covered atlas cell a photon landed on (triangle t, barycentrics b as lm_caustic_hit's), or -1:
 * none of its chart within one texel, or a node that takes no indirect light (its lightmap shows none).
 * The barycentrics are where it landed as it was traced: a receiver that moved since keeps its photons
 * where they fell on it. */
static long texel_under(const lm_scene *s, const lm_atlas *a, uint32_t t, const float b[2])
{
    int chart = t < s->tri_count ? a->tri_chart[t] : -1;
    if (chart < 0 || !s->nodes[s->tri_node[t]].settings.indirect)
        return -1;
    const float w[3] = {1.0f - b[0] - b[1], b[0], b[1]}, *c = a->coverage_uv + 6 * (size_t)t;
    float uv[2] = {w[0] * c[0] + w[1] * c[2] + w[2] * c[4], w[0] * c[1] + w[1] * c[3] + w[2] * c[5]};
    if (!isfinite(uv[0]) || !isfinite(uv[1]))
        return -1;
    int x = (int)floorf(uv[0] * (float)a->width), y = (int)floorf(uv[1] * (float)a->height);
    long best = -1;
    for (int r = 0; r <= 1 && best < 0; r++) /* the cell itself, else the first of its ring, in a fixed order */
        for (int dy = -r; dy <= r && best < 0; dy++)
            for (int dx = -r; dx <= r && best < 0; dx++) {
                int cx = x + dx, cy = y + dy;
                if (cx < 0 || cy < 0 || cx >= a->width || cy >= a->height)
                    continue;
                long cell = (long)cy * a->width + cx;
                if (a->texel_index[cell] >= 0 && a->chart_owner[cell] == chart)
                    best = cell;
            }
    return best;
}

/* Per atlas cell: the photons on it and their flux; wanted: which photons count (NULL: all). */
static void bin_photons(const lm_caustic_hit *hits, const long *cell_of, uint32_t count, const uint8_t *wanted,
                        uint32_t *n, float *flux, size_t cells)
{
    memset(n, 0, cells * sizeof *n);
    memset(flux, 0, 3 * cells * sizeof *flux);
    for (uint32_t i = 0; i < count; i++) {
        if (cell_of[i] < 0 || (wanted && !wanted[i]))
            continue;
        n[cell_of[i]]++;
        for (int c = 0; c < 3; c++)
            flux[3 * cell_of[i] + c] += hits[i].flux[c];
    }
}

/* Per surface: the mean irradiance of its light other than the caustic photons', luminance: the AIM's
 * (pi Y(L) / Y(kd) over its texels, by area) less the caustic photons' flux over its area; and per covered
 * atlas cell in local, the texel's own pi Y(L) / Y(kd). Out of memory for the sums, every surface's is 0:
 * no texel is thin, and every photon stays on screen. */
static void other_light(const lm_scene *s, const lm_atlas *a, const float *aim_rgb, const float *flux, double *other,
                        float *local)
{
    int ns = a->surface_count;
    double *area = calloc((size_t)ns + 1, sizeof *area), *caustic = calloc((size_t)ns + 1, sizeof *caustic);
    memset(other, 0, (size_t)ns * sizeof *other);
    for (uint32_t i = 0; area && caustic && i < a->texel_count; i++) {
        const lm_texel *t = &a->texels[i];
        size_t cell = (size_t)t->y * a->width + t->x;
        float kd[3];
        lm_texel_kd(s, t, kd);
        float y_kd = lm_luminance(kd);
        area[t->surface] += t->area;
        caustic[t->surface] += lm_luminance(flux + 3 * cell);
        local[cell] = y_kd > 0.0f ? (float)M_PI * lm_luminance(aim_rgb + 3 * cell) / y_kd : 0.0f;
        other[t->surface] += t->area * local[cell];
    }
    for (int k = 0; area && caustic && k < ns; k++)
        other[k] = area[k] > 0.0 ? fmax((other[k] - caustic[k]) / area[k], 0.0) : 0.0;
    free(area);
    free(caustic);
}

/* One chart's rectangle, its border included, with summed-area tables of its texels' photons, flux and
 * area (other charts' and uncovered cells count 0): any window's sums in four reads. */
enum { S_PHOTONS, S_FLUX, S_AREA = 4, S_COUNT };
typedef struct {
    int x0, y0, w, h, chart;
    double *sum;             /* (w + 1) x (h + 1) x S_COUNT, row and column 0 zero */
} chart_sums;

static int in_chart(const lm_atlas *a, int chart, size_t cell)
{
    return a->texel_index[cell] >= 0 && a->chart_owner[cell] == chart;
}

static int chart_sums_make(const lm_atlas *a, int c, const uint32_t *n, const float *flux, chart_sums *cs)
{
    const lm_chart *ch = &a->charts[c];
    cs->chart = c;
    cs->x0 = ch->x - ch->pad > 0 ? ch->x - ch->pad : 0;
    cs->y0 = ch->y - ch->pad > 0 ? ch->y - ch->pad : 0;
    int x1 = ch->x + ch->w + ch->pad < a->width ? ch->x + ch->w + ch->pad : a->width;
    int y1 = ch->y + ch->h + ch->pad < a->height ? ch->y + ch->h + ch->pad : a->height;
    cs->w = x1 - cs->x0, cs->h = y1 - cs->y0;
    size_t row = (size_t)(cs->w + 1) * S_COUNT;
    cs->sum = calloc(row * (size_t)(cs->h + 1), sizeof *cs->sum);
    if (!cs->sum)
        return 0;
    for (int y = 0; y < cs->h; y++)
        for (int x = 0; x < cs->w; x++) {
            size_t cell = (size_t)(cs->y0 + y) * a->width + cs->x0 + x;
            int on = in_chart(a, c, cell);
            const double v[S_COUNT] = {on ? n[cell] : 0.0, on ? flux[3 * cell] : 0.0, on ? flux[3 * cell + 1] : 0.0,
                                       on ? flux[3 * cell + 2] : 0.0, on ? a->texels[a->texel_index[cell]].area : 0.0};
            double *o = cs->sum + (size_t)(y + 1) * row + (size_t)(x + 1) * S_COUNT;
            for (int k = 0; k < S_COUNT; k++)
                o[k] = v[k] + o[k - (long)row] + o[k - S_COUNT] - o[k - (long)row - S_COUNT];
        }
    return 1;
}

/* The sums over atlas cells [xa, xb] x [ya, yb] (inclusive) within the chart's rectangle. */
static void box(const chart_sums *cs, int xa, int ya, int xb, int yb, double out[S_COUNT])
{
    xa = xa - cs->x0 > 0 ? xa - cs->x0 : 0, xb = xb - cs->x0 < cs->w - 1 ? xb - cs->x0 : cs->w - 1;
    ya = ya - cs->y0 > 0 ? ya - cs->y0 : 0, yb = yb - cs->y0 < cs->h - 1 ? yb - cs->y0 : cs->h - 1;
    size_t row = (size_t)(cs->w + 1) * S_COUNT;
    for (int k = 0; k < S_COUNT; k++)
        out[k] = xa > xb || ya > yb ? 0.0
                                    : cs->sum[(size_t)(yb + 1) * row + (size_t)(xb + 1) * S_COUNT + k] -
                                          cs->sum[(size_t)ya * row + (size_t)(xb + 1) * S_COUNT + k] -
                                          cs->sum[(size_t)(yb + 1) * row + (size_t)xa * S_COUNT + k] +
                                          cs->sum[(size_t)ya * row + (size_t)xa * S_COUNT + k];
}

/* Whether the photons of the window of half side r around (x, y) change across it by more than their
 * noise allows: for either axis, the photon densities (photons / area) of the window's two halves either
 * side of the texel differ by over LM_CAUSTIC_SPLIT_SIGMA standard deviations of Poisson counts. The rim
 * of a focal spot, which the lightmap's texels would blur. */
static int has_structure(const chart_sums *cs, int x, int y, int r)
{
    double lo[2][S_COUNT], hi[2][S_COUNT]; /* [axis] */
    box(cs, x - r, y - r, x - 1, y + r, lo[0]);
    box(cs, x + 1, y - r, x + r, y + r, hi[0]);
    box(cs, x - r, y - r, x + r, y - 1, lo[1]);
    box(cs, x - r, y + 1, x + r, y + r, hi[1]);
    for (int k = 0; k < 2; k++) {
        double n0 = lo[k][S_PHOTONS], n1 = hi[k][S_PHOTONS], a0 = lo[k][S_AREA], a1 = hi[k][S_AREA];
        if (!(a0 > 0.0) || !(a1 > 0.0) || n0 + n1 < LM_CAUSTIC_SPLIT_PHOTONS)
            continue;
        double d0 = n0 / a0, d1 = n1 / a1;
        if (fabs(d0 - d1) > LM_CAUSTIC_SPLIT_SIGMA * sqrt(n0 / (a0 * a0) + n1 / (a1 * a1)))
            return 1;
    }
    return 0;
}

/* Whether the light in the window of half side r around (x, y), whose sums are v, is gathered into its middle: the photon
 * density of the middle (half side r / 2) is over 1 + LM_CAUSTIC_SPLIT_GATHERED times the whole window's,
 * by more than LM_CAUSTIC_SPLIT_GATHERED_SIGMA standard deviations of the middle's binomial count under an
 * even density. The window is then wider than the light: spread evenly over it, a fan or a spot a few
 * texels across would be carried out of itself (a lamp's reflection at grazing incidence, falling as
 * 1 / d^3). Light that changes linearly across the window is spread without error, and a dark middle (a
 * shadow in thin light) is only blurred, so neither keeps the light on screen. */
static int gathered_in_middle(const chart_sums *cs, int x, int y, int r, const double v[S_COUNT])
{
    if (r < 1)
        return 0;
    double mid[S_COUNT];
    box(cs, x - r / 2, y - r / 2, x + r / 2, y + r / 2, mid);
    double p = v[S_AREA] > 0.0 ? mid[S_AREA] / v[S_AREA] : 0.0, want = v[S_PHOTONS] * p, got = mid[S_PHOTONS];
    return p > 0.0 && p < 1.0 && got > (1.0 + LM_CAUSTIC_SPLIT_GATHERED) * want &&
           got - want > LM_CAUSTIC_SPLIT_GATHERED_SIGMA * sqrt(want * (1.0 - p));
}

/* The chart's texels: each one's window half side + 1 (0: no photon within the widest) and whether it is
 * thin next to its surface's other light. */
static void classify(const lm_atlas *a, const chart_sums *cs, const double *other, const float *local, float fraction,
                     uint8_t *radius, uint8_t *thin)
{
    for (int y = cs->y0; y < cs->y0 + cs->h; y++)
        for (int x = cs->x0; x < cs->x0 + cs->w; x++) {
            size_t cell = (size_t)y * a->width + x;
            if (!in_chart(a, cs->chart, cell))
                continue;
            double v[S_COUNT];
            int r = 0;
            box(cs, x, y, x, y, v);
            while (r < LM_CAUSTIC_SPLIT_REACH && v[S_PHOTONS] < LM_CAUSTIC_SPLIT_PHOTONS) {
                r++;
                box(cs, x - r, y - r, x + r, y + r, v);
            }
            radius[cell] = v[S_PHOTONS] > 0.0 ? (uint8_t)(r + 1) : 0; /* + 1: 0 is "no photon near" */
            float ec[3] = {(float)(v[S_FLUX] / v[S_AREA]), (float)(v[S_FLUX + 1] / v[S_AREA]),
                           (float)(v[S_FLUX + 2] / v[S_AREA])};
            int surface = a->texels[a->texel_index[cell]].surface;
            float y_c = lm_luminance(ec);
            thin[cell] = radius[cell] && v[S_AREA] > 0.0 && y_c < fraction * other[surface] &&
                         y_c < fraction * fmaxf(local[cell] - y_c, 0.0f) && !has_structure(cs, x, y, r > 1 ? r : 1) &&
                         !gathered_in_middle(cs, x, y, r, v);
        }
}

/* E_thin on the chart: each texel's thin photons (cs's bins) spread over its own window, flux / the
 * window's area on every texel of it, so each photon's power is kept whatever the windows around it
 * (a texel's gather over its own window would count a dense neighbour's photons both there and in every
 * wide window reaching it). The windows are added as corners of a difference table, summed once. */
static int thin_layer(const lm_scene *s, const lm_atlas *a, const chart_sums *cs, const uint32_t *n,
                      const float *flux, const uint8_t *radius, float *out)
{
    size_t row = (size_t)(cs->w + 1) * 3;
    double *d = calloc(row * (size_t)(cs->h + 1), sizeof *d);
    if (!d)
        return 0;
    for (int y = 0; y < cs->h; y++)
        for (int x = 0; x < cs->w; x++) {
            size_t cell = (size_t)(cs->y0 + y) * a->width + cs->x0 + x;
            if (!in_chart(a, cs->chart, cell) || !n[cell] || !radius[cell])
                continue;
            int r = radius[cell] - 1;
            int xa = x - r > 0 ? x - r : 0, xb = x + r < cs->w - 1 ? x + r : cs->w - 1;
            int ya = y - r > 0 ? y - r : 0, yb = y + r < cs->h - 1 ? y + r : cs->h - 1;
            double v[S_COUNT];
            box(cs, cs->x0 + xa, cs->y0 + ya, cs->x0 + xb, cs->y0 + yb, v);
            for (int c = 0; c < 3 && v[S_AREA] > 0.0; c++) {
                double e = flux[3 * cell + c] / v[S_AREA];
                d[(size_t)ya * row + 3 * (size_t)xa + c] += e;
                d[(size_t)ya * row + 3 * (size_t)(xb + 1) + c] -= e;
                d[(size_t)(yb + 1) * row + 3 * (size_t)xa + c] -= e;
                d[(size_t)(yb + 1) * row + 3 * (size_t)(xb + 1) + c] += e;
            }
        }
    for (int y = 0; y < cs->h; y++) /* the table's running sums are each cell's E */
        for (int x = 0; x < cs->w; x++)
            for (int c = 0; c < 3; c++) {
                double *o = d + (size_t)y * row + 3 * (size_t)x + c;
                *o += (x ? o[-3] : 0.0) + (y ? o[-(long)row] : 0.0) - (x && y ? o[-(long)row - 3] : 0.0);
            }
    for (int y = 0; y < cs->h; y++)
        for (int x = 0; x < cs->w; x++) {
            size_t cell = (size_t)(cs->y0 + y) * a->width + cs->x0 + x;
            if (!in_chart(a, cs->chart, cell))
                continue;
            float *o = out + 4 * cell;
            for (int c = 0; c < 3; c++)
                o[c] = (float)fmax(d[(size_t)y * row + 3 * (size_t)x + c], 0.0); /* rounding below 0 */
            o[3] = s->nodes[s->tri_node[a->texels[a->texel_index[cell]].tri]].settings.indirect ? 1.0f : 0.0f;
        }
    free(d);
    return 1;
}

/* Per chart (in parallel; charts own disjoint cells): the sums of the bins, then `pass` 0 classifies
 * its texels, pass 1 spreads the thin photons. Returns 0 when memory ran out. */
static int over_charts(const lm_scene *s, const lm_atlas *a, int pass, const uint32_t *n, const float *flux,
                       const double *other, const float *local, float fraction, uint8_t *radius, uint8_t *thin,
                       float *out)
{
    int ok = 1;
#pragma omp parallel for schedule(dynamic, 1) reduction(&& : ok)
    for (int c = 0; c < a->chart_count; c++) {
        chart_sums cs;
        if (!chart_sums_make(a, c, n, flux, &cs)) {
            ok = 0;
            continue;
        }
        if (pass == 0)
            classify(a, &cs, other, local, fraction, radius, thin);
        else
            ok = thin_layer(s, a, &cs, n, flux, radius, out) && ok;
        free(cs.sum);
    }
    return ok;
}

lm_status lm_caustic_split_make(const lm_scene *s, const lm_atlas *a, const float *aim_rgb, const lm_caustic_hit *hits,
                                uint32_t count, float fraction, lm_caustic_split *out, lm_error *err)
{
    lm_caustic_split_free(out);
    size_t cells = (size_t)a->width * a->height;
    long *cell_of = calloc(count ? count : 1, sizeof *cell_of);
    uint8_t *thin_photon = calloc(count ? count : 1, 1), *radius = malloc(cells ? cells : 1);
    uint8_t *thin = malloc(cells ? cells : 1);
    uint32_t *n = malloc((cells ? cells : 1) * sizeof *n);
    float *flux = malloc((cells ? cells : 1) * 3 * sizeof *flux);
    double *other = malloc(((size_t)a->surface_count + 1) * sizeof *other);
    float *local = calloc(cells ? cells : 1, sizeof *local);
    out->thin = malloc((cells ? cells : 1) * 4 * sizeof *out->thin);
    out->screen = malloc((count ? count : 1) * sizeof *out->screen);
    lm_status st = LM_OK;
    if (!cell_of || !thin_photon || !radius || !thin || !n || !flux || !other || !local || !out->thin || !out->screen)
        goto nomem;
    uint32_t landed = 0;
#pragma omp parallel for schedule(static) reduction(+ : landed)
    for (long i = 0; i < (long)count; i++) {
        int on = hits[i].flux[0] > 0.0f || hits[i].flux[1] > 0.0f || hits[i].flux[2] > 0.0f;
        landed += (uint32_t)on;
        cell_of[i] = on ? texel_under(s, a, hits[i].tri, hits[i].bary) : -1;
    }
    out->landed = landed;
    bin_photons(hits, cell_of, count, NULL, n, flux, cells);
    other_light(s, a, aim_rgb, flux, other, local);
    memset(radius, 0, cells);
    memset(thin, 0, cells);
    memset(out->thin, 0, 4 * cells * sizeof *out->thin);
    if (!over_charts(s, a, 0, n, flux, other, local, fraction, radius, thin, NULL))
        goto nomem;
    memcpy(out->screen, hits, count * sizeof *hits);
    out->count = count;
    for (uint32_t i = 0; i < count; i++)
        if (cell_of[i] >= 0 && thin[cell_of[i]]) {
            thin_photon[i] = 1;
            out->thin_photons++;
            memset(out->screen[i].flux, 0, sizeof out->screen[i].flux);
        }
    for (uint32_t i = 0; i < a->texel_count; i++) {
        size_t cell = (size_t)a->texels[i].y * a->width + a->texels[i].x;
        out->texels_lit += radius[cell] > 0;
        out->texels_concentrated += radius[cell] > 0 && !thin[cell];
    }
    bin_photons(hits, cell_of, count, thin_photon, n, flux, cells);
    if (over_charts(s, a, 1, n, flux, other, local, fraction, radius, thin, out->thin))
        goto done;
nomem:
    st = lm_fail(err, LM_ERR_NOMEM, "%s: no memory to split the caustic photons", s->path);
    lm_caustic_split_free(out);
done:
    free(cell_of);
    free(thin_photon);
    free(radius);
    free(thin);
    free(n);
    free(flux);
    free(other);
    free(local);
    return st;
}
