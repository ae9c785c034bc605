#include "sun_guide.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../core/qmc.h"
#include "../core/vecmath.h"

#define N LM_GUIDE_CELLS

/* The texel density on surface f (-1: a mirror or glass, where the light goes on) over the atlas's, at most 1. */
static double texel_weight(const lm_atlas *a, int f)
{
    if (f < 0 || !a->surface_texel_size)
        return 1.0;
    double r = (double)a->texel_size / a->surface_texel_size[f];
    return fmin(r * r, 1.0);
}

/* What a line from o along dir is worth (sun_guide.h): the texel weight where it first lands into *land, and
 * where that is an open surface's (*coarse set), the share of LM_GUIDE_BOUNCES cosine bounces from there that
 * land on texels at the atlas's density into *bounce (else 0). index: the line's number, for the bounces. */
static void line_weight(const lm_rt *rt, const lm_scene *s, const lm_atlas *a, const float o[3], const float dir[3],
                        uint32_t index, double *land, double *bounce, int *coarse)
{
    lm_rt_hit h;
    *land = *bounce = 0.0;
    if (!lm_rt_intersect(rt, o, dir, 0.0f, INFINITY, &h))
        return;
    if ((*land = texel_weight(a, h.surface)) >= 1.0)
        return;
    *coarse = 1;
    lm_vec3 n = lm_v3_load(h.ng), d = lm_v3_load(dir);
    if (lm_dot(n, d) > 0.0f)
        n = lm_scale(n, -1.0f);
    float p[3];
    lm_v3_store(p, lm_add(lm_add(lm_v3_load(o), lm_scale(d, h.t)), lm_scale(n, lm_scene_ray_lift(s))));
    int fine = 0;
    for (int k = 0; k < LM_GUIDE_BOUNCES; k++) {
        double u[2];
        lm_halton_dims(0, 2, (uint64_t)index * LM_GUIDE_BOUNCES + (uint64_t)k, u);
        float b[3];
        lm_v3_store(b, lm_cosine_dir(n, (float)u[0], (float)u[1]));
        lm_rt_hit bh;
        fine += lm_rt_intersect(rt, p, b, 0.0f, INFINITY, &bh) && texel_weight(a, bh.surface) >= 1.0;
    }
    *bounce = (double)fine / LM_GUIDE_BOUNCES;
}

/* The cell weights w (N x N, row-major, rows along the rectangle's 2nd edge): the largest of the landing
 * weights of the cell and its eight neighbours (a cell whose lines all missed the edge of a house still holds
 * some of it), or the cell's own bounces' where more; 1 if a line landed on an open surface. land: N x N
 * scratch. */
static int cell_weights(const lm_rt *rt, const lm_scene *s, const lm_atlas *a, const float rect[3][3],
                        const float dir[3], double *land, double *w)
{
    lm_vec3 r0 = lm_v3_load(rect[0]), eu = lm_v3_load(rect[1]), ev = lm_v3_load(rect[2]);
    int coarse = 0;
#pragma omp parallel for schedule(dynamic, 1) reduction(| : coarse)
    for (int j = 0; j < N; j++) {
        lm_rt_thread_init();
        for (int i = 0; i < N; i++) {
            double lands = 0.0, bounces = 0.0;
            for (int k = 0; k < LM_GUIDE_LINES; k++) {
                float x = (i + (k % 2 + 0.5f) / 2.0f) / N, y = (j + (k / 2 + 0.5f) / 2.0f) / N, o[3];
                lm_v3_store(o, lm_add(r0, lm_add(lm_scale(eu, x), lm_scale(ev, y))));
                double l, b;
                line_weight(rt, s, a, o, dir, (uint32_t)((j * N + i) * LM_GUIDE_LINES + k), &l, &b, &coarse);
                lands += l, bounces += b;
            }
            land[(size_t)j * N + i] = lands / LM_GUIDE_LINES;
            w[(size_t)j * N + i] = bounces / LM_GUIDE_LINES;
        }
    }
    for (int j = 0; j < N; j++)
        for (int i = 0; i < N; i++) {
            double most = w[(size_t)j * N + i];
            for (int y = j - 1; y <= j + 1; y++)
                for (int x = i - 1; x <= i + 1; x++)
                    if (x >= 0 && x < N && y >= 0 && y < N)
                        most = fmax(most, land[(size_t)y * N + x]);
            w[(size_t)j * N + i] = most;
        }
    return coarse;
}

lm_status lm_sun_guide_make(const lm_rt *rt, const lm_scene *s, const lm_atlas *a, const float rect[3][3],
                            const float dir[3], lm_sun_guide **out, lm_error *err)
{
    *out = NULL;
    lm_sun_guide *g = calloc(1, sizeof *g);
    double *w = malloc(sizeof *w * N * N * 2);
    if (g) {
        g->row_cdf = malloc(sizeof *g->row_cdf * (N + 1));
        g->col_cdf = malloc(sizeof *g->col_cdf * N * (N + 1));
        g->density = malloc(sizeof *g->density * N * N);
    }
    if (!g || !w || !g->row_cdf || !g->col_cdf || !g->density) {
        free(w);
        lm_sun_guide_free(g);
        return lm_fail(err, LM_ERR_NOMEM, "sun guide: out of memory");
    }
    double sum = 0.0;
    if (cell_weights(rt, s, a, rect, dir, w + N * N, w))
        for (int c = 0; c < N * N; c++)
            sum += w[c];
    if (!(sum > 0.0)) { /* no open surface in the sun's way: uniform */
        free(w);
        lm_sun_guide_free(g);
        return LM_OK;
    }
    memcpy(g->rect, rect, sizeof g->rect);
    g->row_cdf[0] = 0.0;
    for (int j = 0; j < N; j++) {
        double *col = g->col_cdf + (size_t)j * (N + 1), row = 0.0;
        col[0] = 0.0;
        for (int i = 0; i < N; i++) {
            double p = (1.0 - LM_GUIDE_UNIFORM) * w[(size_t)j * N + i] / sum + LM_GUIDE_UNIFORM / (N * N);
            g->density[(size_t)j * N + i] = p * (N * N);
            col[i + 1] = row += p;
        }
        for (int i = 1; i <= N; i++)
            col[i] /= row;
        col[N] = 1.0;
        g->row_cdf[j + 1] = g->row_cdf[j] + row;
    }
    for (int j = 1; j <= N; j++)
        g->row_cdf[j] /= g->row_cdf[N];
    g->row_cdf[N] = 1.0;
    free(w);
    *out = g;
    return LM_OK;
}

void lm_sun_guide_free(lm_sun_guide *g)
{
    if (!g)
        return;
    free(g->row_cdf);
    free(g->col_cdf);
    free(g->density);
    free(g);
}

int lm_sun_guide_same(const lm_sun_guide *a, const lm_sun_guide *b)
{
    if (!a || !b)
        return a == b;
    return !memcmp(a->rect, b->rect, sizeof a->rect) && !memcmp(a->density, b->density, sizeof *a->density * N * N);
}

/* The cell k of cdf (n + 1 entries, cdf[0] 0, cdf[n] 1) that holds u, and u's place inside it in *t. */
static int find_cell(const double *cdf, double u, double *t)
{
    int lo = 0, hi = N - 1;
    while (lo < hi) { /* the last k with cdf[k] <= u */
        int mid = (lo + hi + 1) / 2;
        if (cdf[mid] <= u)
            lo = mid;
        else
            hi = mid - 1;
    }
    double width = cdf[lo + 1] - cdf[lo];
    *t = width > 0.0 ? fmin(fmax((u - cdf[lo]) / width, 0.0), 1.0) : 0.5;
    return lo;
}

double lm_sun_guide_draw(const lm_sun_guide *g, float u[2])
{
    double tu, tv;
    int j = find_cell(g->row_cdf, u[1], &tv);
    int i = find_cell(g->col_cdf + (size_t)j * (N + 1), u[0], &tu);
    /* inside the cell drawn, whose density this is, to the float: its far edge rounded would be the next's */
    u[0] = fminf((float)((i + tu) / N), nextafterf((float)(i + 1) / N, 0.0f));
    u[1] = fminf((float)((j + tv) / N), nextafterf((float)(j + 1) / N, 0.0f));
    return g->density[(size_t)j * N + i];
}
