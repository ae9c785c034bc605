/* The rim of the hemisphere the plane misses, by rays (hemicube_rim.h). */
#include "hemicube_rim.h"

#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

#include "../core/qmc.h"
#include "../core/vecmath.h"
#include "../scene/sky.h"
#include "../trace/shading.h"


void lm_atlas_sample_rgb(const lm_atlas *a, const float *rgba, float u, float v, float out[3])
{
    float x = u * (float)a->width - 0.5f, y = v * (float)a->height - 0.5f;
    x = fminf(fmaxf(x, 0.0f), (float)(a->width - 1));
    y = fminf(fmaxf(y, 0.0f), (float)(a->height - 1));
    int x0 = (int)x, y0 = (int)y, x1 = x0 + 1 < a->width ? x0 + 1 : x0, y1 = y0 + 1 < a->height ? y0 + 1 : y0;
    float fx = x - (float)x0, fy = y - (float)y0;
    const float *p00 = rgba + 4 * ((size_t)y0 * a->width + x0), *p10 = rgba + 4 * ((size_t)y0 * a->width + x1);
    const float *p01 = rgba + 4 * ((size_t)y1 * a->width + x0), *p11 = rgba + 4 * ((size_t)y1 * a->width + x1);
    for (int c = 0; c < 3; c++)
        out[c] = (1.0f - fy) * ((1.0f - fx) * p00[c] + fx * p10[c]) + fy * ((1.0f - fx) * p01[c] + fx * p11[c]);
}

int lm_atlas_hit_uv(const lm_atlas *a, const lm_rt_hit *h, float uv[2])
{
    const float *c = a->corner_uv + 6 * (size_t)h->tri;
    if (a->tri_chart[h->tri] < 0 || !isfinite(c[0]))
        return 0;
    float w0 = 1.0f - h->u - h->v;
    uv[0] = w0 * c[0] + h->u * c[2] + h->v * c[4];
    uv[1] = w0 * c[1] + h->u * c[3] + h->v * c[5];
    return 1;
}

/* The lightmap UV's gradient over a triangle's plane: rows gu, gv with uv(p) = uv0 + (gu.(p - p0),
 * gv.(p - p0)) (zero across the plane). */
void lm_uv_gradient(const float p[3][3], const float *uv[3], float gu[3], float gv[3])
{
    lm_vec3 e1 = lm_sub(lm_v3_load(p[1]), lm_v3_load(p[0])), e2 = lm_sub(lm_v3_load(p[2]), lm_v3_load(p[0]));
    double a = lm_dot(e1, e1), b = lm_dot(e1, e2), c = lm_dot(e2, e2), det = a * c - b * b;
    memset(gu, 0, 3 * sizeof(float));
    memset(gv, 0, 3 * sizeof(float));
    if (!uv[0] || !uv[1] || !uv[2] || !(det > 1e-30 * a * c))
        return;
    for (int r = 0; r < 2; r++) {
        double d1 = uv[1][r] - uv[0][r], d2 = uv[2][r] - uv[0][r];
        float al = (float)((c * d1 - b * d2) / det), be = (float)((a * d2 - b * d1) / det);
        lm_v3_store(r ? gv : gu, lm_add(lm_scale(e1, al), lm_scale(e2, be)));
    }
}

/* An azimuth of the rim: phi (turns) and where the plane's edge lies in it, s_edge (sin^2 of its polar
 * angle); 1 - s_edge is the azimuth's share of the rim. */
typedef struct {
    float sn, cs;
    double s_edge;
} rim_azimuth;

static rim_azimuth azimuth(const lm_rim *r, double phi)
{
    rim_azimuth a;
    lm_sincos_turn((float)phi, &a.sn, &a.cs);
    double m = fmax(fabs((double)a.cs), fabs((double)a.sn)), t2 = (double)r->enlargement * r->enlargement / (m * m);
    a.s_edge = t2 / (1.0 + t2);
    return a;
}

/* The direction of the rim in the texel's frame at azimuth a and u in [0, 1) across the rim beyond the
 * plane's edge there; *weight is the azimuth's share of the rim. (A stratum's sub-directions share their
 * azimuths: each is computed once.) */
static lm_vec3 rim_dir(const rim_azimuth *a, lm_vec3 B, lm_vec3 T, lm_vec3 N, double u, double *weight)
{
    double s = a->s_edge + (1.0 - a->s_edge) * u;
    float st = (float)sqrt(s), z = (float)sqrt(fmax(0.0, 1.0 - s));
    *weight = 1.0 - a->s_edge;
    return lm_normalize(lm_add(lm_add(lm_scale(B, st * a->cs), lm_scale(T, st * a->sn)), lm_scale(N, z)));
}

/* The frame the strata are laid in. Upright (the rays gather, at a standing texel: |n.y| under
 * UPRIGHT_LEVEL, +y up, within 3 degrees of vertical): phi in [0, 1) picks alpha, the angle from n across
 * the up direction in the texel's plane A, with sin alpha = 2 phi - 1, and u the elevation beta against
 * the level, with the cdf (beta + sin beta cos beta + pi / 2) / pi; d = cos beta (cos alpha n + sin alpha C)
 * + sin beta A, C = n x A. The density of (alpha, beta) is cos(alpha) cos^2(beta) / pi: the same
 * cosine-weighted measure as the polar strata, each stratum's share 1 / K. But a row of strata is a band
 * of elevations, so a floor seen at grazing angles from a face standing on it (its contact line, lit
 * beyond a shadow) lies across the columns of the few rows it falls in alike, and the columns' own
 * fractions of their rows (below) meet it at evenly spread elevations; in the polar strata it cut each of
 * many strata somewhere else, all or nothing for its one ray (docs/gather.md, "Upright strata"). Only
 * standing: off the vertical the rows hold the normal and are not level, and on a cap whose normals tilt
 * up to 25 degrees upright strata took the error from 0.2% to 1.3% (test_run's test_curved_piece_turns). */
#define UPRIGHT_LEVEL 0.05f
typedef struct {
    double c, s;
} cos_sin;

typedef struct {
    lm_vec3 B, T, N;
    int upright;
    lm_vec3 A, C; /* upright: the up direction in the texel's plane, and N x A */
    int split;    /* upright: each row within CONTACT_BELOW under the level traced as this many (1: as one) */
    int sub;      /* sub-directions per side of a stratum's footprint (lm_rim's footprint, or SUB) */
} strata_frame;

#define ELEVATION_STEPS 4096
static double elevation_table[ELEVATION_STEPS + 1];
static pthread_once_t elevation_once = PTHREAD_ONCE_INIT;

/* beta with (beta + sin beta cos beta + pi / 2) / pi = u, by Newton from a guess that holds at both ends
 * (there the cdf is flat to third order): the double's precision in at most 5 steps over [0, 1] */
static double elevation_solve(double u)
{
    double t = (u - 0.5) * LM_PI, a = fabs(t), b = a > 1.0 ? 0.5 * LM_PI - cbrt(1.5 * (0.5 * LM_PI - a)) : 0.5 * a;
    for (int it = 0; it < 8; it++) {
        double df = 2.0 * cos(b) * cos(b);
        if (!(df > 0.0))
            break;
        double step = (b + sin(b) * cos(b) - a) / df;
        b = fmin(fmax(b - step, 0.0), 0.5 * LM_PI);
        if (fabs(step) < 1e-12)
            break;
    }
    return copysign(b, t);
}

static void elevation_table_fill(void)
{
    for (int k = 0; k <= ELEVATION_STEPS; k++)
        elevation_table[k] = elevation_solve((double)k / ELEVATION_STEPS);
}

/* The same as cos and sin: inside, the table's step and one Newton step kept within it (the cdf then
 * within 1e-11 of u); in the end steps, where the cdf is flat to third order, solved. */
static cos_sin elevation(double u)
{
    u = fmin(fmax(u, 0.0), 1.0);
    double x = u * ELEVATION_STEPS, b;
    int k = (int)x < ELEVATION_STEPS ? (int)x : ELEVATION_STEPS - 1;
    if (k == 0 || k == ELEVATION_STEPS - 1) {
        b = elevation_solve(u);
    } else {
        double lo = elevation_table[k], hi = elevation_table[k + 1], df;
        b = lo + (x - k) * (hi - lo);
        df = 2.0 * cos(b) * cos(b);
        b = fmin(fmax(b - (b + sin(b) * cos(b) - (u - 0.5) * LM_PI) / df, lo), hi);
    }
    return (cos_sin){cos(b), sin(b)};
}

/* alpha at phi (turns, taken mod 1), as cos and sin: no trigonometry */
static cos_sin across(double phi)
{
    double s = 2.0 * (phi - floor(phi)) - 1.0;
    return (cos_sin){sqrt(fmax(0.0, 1.0 - s * s)), s};
}

static lm_vec3 upright_dir(const strata_frame *f, cos_sin a, cos_sin b)
{
    return lm_normalize(lm_add(lm_add(lm_scale(f->N, (float)(b.c * a.c)), lm_scale(f->C, (float)(b.c * a.s))),
                               lm_scale(f->A, (float)b.s)));
}

/* Each azimuth column of strata puts its rays at its own fraction of their elevation strata, the texel's
 * shift plus i times the golden ratio's fraction (a Kronecker sequence): a ring of strata under a source
 * smaller than one ring then reads it at as many elevations as it has azimuths, not all at one. */
#define LM_GOLDEN_FRACTION 0.6180339887498949
#define ACROSS_SEED 0x68e31da4u /* the rows' fractions across their columns: a shift of their own */
#define SUB 4 /* sub-directions per side of a stratum: its footprint on the hit's plane */
#define RIMS_AT_ONCE 2 /* the most rims one pass reads over the same rays (lm_rim_irradiance_pair) */
#define SKY_RAYS 36 /* an image sky's directions drawn by brightness a texel, beside the strata (a square) */

/* With an image sky over the whole hemisphere (the rays gather), its light is met two ways: by the K
 * strata, cosine-weighted (p_a = cos / pi), and by SKY_RAYS directions drawn by brightness (p_b,
 * lm_sky_sample), each weighed by the balance heuristic: a sample from either adds L cos / (K p_a + M p_b)
 * to E. A sun a few pixels wide, which one ray a stratum hits or misses, is then found every time. */
typedef struct {
    int on, K, M;
} sky_mis;

/* The strata's share of a sky direction d (unit normal n) whose p_b is pdf: K p_a / (K p_a + M p_b). */
static double strata_share(const sky_mis *m, lm_vec3 n, const float d[3], double pdf)
{
    double ka = m->K * fmax((double)lm_dot(lm_v3_load(d), n), 0.0) / LM_PI, mb = m->M * pdf;
    return ka + mb > 0.0 ? ka / (ka + mb) : 1.0;
}

/* The width of a texel of the surface hit h met (the atlas's where it met none). */
static float hit_texel_width(const lm_atlas *a, const lm_rt_hit *h)
{
    return a->surface_texel_size && h->surface >= 0 ? a->surface_texel_size[h->surface] : a->texel_size;
}

/* kd / pi E_direct at the ray's hit h (direction dir from eye): the direct light the AIM computes for a
 * texel (r->direct: punctual lights, emissive triangles), computed there (the side the geometric normal's,
 * a punctual light's cosine the shading normal's, both sides of a double-sided material); seed picks the
 * emissive triangles' shadow rays. */
static void direct_at_hit(const lm_rim *r, const float eye[3], const float dir[3], const lm_rt_hit *h, uint32_t seed,
                          float out[3])
{
    lm_shading sh;
    lm_shading_from_hit(r->scene, h, eye, dir, &sh);
    float kd[3], ks[3], E[3];
    lm_material_lobes(sh.material, sh.albedo, kd, ks);
    out[0] = out[1] = out[2] = 0.0f;
    if (!(kd[0] > 0.0f || kd[1] > 0.0f || kd[2] > 0.0f))
        return;
    lm_direct_at_hit(r->direct, sh.pos, sh.ng, sh.ns, sh.material->double_sided, seed, E);
    for (int c = 0; c < 3; c++)
        out[c] = (float)(kd[c] / LM_PI * E[c]);
}

/* The stratum (phi0 + [0, dphi), u0 + [0, du)) of the rim: one ray at the fraction `ax` of its width in phi
 * (the hemicube's rim: its middle azimuth, 0.5) and the fraction `at` of its width in u (with every ray at the
 * middle, the elevation's midpoint rule put the same error into every texel that sees a small source, a
 * horizon or a contact line alike: a bias, not noise; docs/gather.md, "Strata") and, on the plane of the
 * triangle it hits, the AIM averaged over the stratum's footprint (fr->sub x fr->sub sub-directions met with
 * that plane, their uv from the triangle's uv gradient, kept inside its chart; of one, the ray's own hit), as
 * a hemicube pixel averages its footprint: a small bright spot is then shared among the strata it overlaps
 * instead of being all or nothing for one. Adds the weighted radiance sum (times fr->sub^2) of each of the nr
 * rims r[k] into sum[k]:
 * one ray and one footprint for all of them (r[0]'s scene, atlas and tracer), each read in its own AIM,
 * emission and direct light. seed: the stratum's own (the texel's and its index), for the emissive
 * triangles' shadow rays at the hit. fr: the frame; sub: upright strata, the elevations of this row's fr->sub
 * sub-rows (NULL: the polar strata, laid in fr's B, T and N). */
static void stratum(const lm_rim *const *r, int nr, const sky_mis *mis, const float eye[3], const strata_frame *fr,
                    const cos_sin *sub, lm_vec3 G, double phi0, double dphi, double u0, double du, double ax,
                    double at, uint32_t seed, double (*sum)[3], double *back)
{
    const lm_rim *r0 = r[0];
    lm_vec3 N = fr->N;
    double w;
    float dir[3];
    if (sub) {
        w = 1.0;
        lm_v3_store(dir, upright_dir(fr, across(phi0 + ax * dphi), elevation(u0 + at * du)));
    } else {
        rim_azimuth mid = azimuth(r0, phi0 + ax * dphi);
        lm_v3_store(dir, rim_dir(&mid, fr->B, fr->T, N, u0 + at * du, &w));
    }
    if (lm_dot(lm_v3_load(dir), G) <= 0.0f)
        return; /* into the texel's own surface */
    lm_rt_hit h;
    if (!lm_rt_intersect(r0->rt, eye, dir, 0.0f, INFINITY, &h)) {
        float scene_sky[3]; /* the scene's own, which may differ by direction: the same for every rim */
        double share = 1.0, pdf;
        int by_direction = mis->on || r0->scene->has_sky;
        if (mis->on) {
            lm_sky_radiance_pdf(r0->scene, dir, scene_sky, &pdf);
            share = strata_share(mis, N, dir, pdf);
        } else if (by_direction) {
            lm_sky_radiance(r0->scene, dir, scene_sky);
        }
        for (int k = 0; k < nr; k++) {
            const float *sky = by_direction ? scene_sky : r[k]->sky;
            for (int c = 0; c < 3; c++)
                sum[k][c] += fr->sub * fr->sub * w * share * sky[c];
        }
        return;
    }
    const lm_material *m = &r0->scene->materials[r0->scene->tri_material[h.tri]];
    lm_vec3 ng = lm_v3_load(h.ng), d = lm_v3_load(dir);
    if (!m->double_sided && lm_dot(ng, d) > 0.0f) {
        *back += w; /* the back of a single-sided surface: black, as on the plane */
        return;
    }
    const float *c = r0->atlas->corner_uv + 6 * (size_t)h.tri;
    lm_vec3 e = lm_v3_load(eye), P = lm_add(e, lm_scale(d, h.t));
    int far[RIMS_AT_ONCE]; /* the direct light read in the whole AIM, not taken at the hit */
    for (int k = 0; k < nr; k++)
        far[k] = r[k]->direct && r[k]->whole && h.t > r[k]->near * hit_texel_width(r0->atlas, &h);
    float hit[2];
    if (lm_atlas_hit_uv(r0->atlas, &h, hit)) {
        float p[3][3], gu[3], gv[3];
        const float *uv[3] = {c, c + 2, c + 4};
        for (int k = 0; k < 3; k++)
            lm_scene_vertex_world(r0->scene, r0->scene->tris[3 * (size_t)h.tri + k], p[k]);
        lm_uv_gradient(p, uv, gu, gv);
        float lo[4], *hi = lo + 2; /* the chart's footprint stays where its lookups read only it */
        lm_chart_lookup_rect(r0->atlas, r0->atlas->tri_chart[h.tri], lo);
        double num = lm_dot(ng, lm_sub(P, e));
        for (int k = 0; fr->sub == 1 && k < nr; k++) { /* a footprint of one: the ray's own hit */
            float L[3];
            lm_atlas_sample_rgb(r0->atlas, far[k] ? r[k]->whole : r[k]->aim, hit[0], hit[1], L);
            for (int q = 0; q < 3; q++)
                sum[k][q] += w * L[q];
        }
        for (int i = 0; fr->sub > 1 && i < fr->sub; i++) {
            rim_azimuth az = {0.0f, 0.0f, 0.0};
            cos_sin al = {0.0, 0.0};
            if (sub)
                al = across(phi0 + (i + 0.5) / fr->sub * dphi);
            else
                az = azimuth(r0, phi0 + (i + 0.5) / fr->sub * dphi);
            for (int j = 0; j < fr->sub; j++) {
                double ws = 1.0;
                lm_vec3 ds = sub ? upright_dir(fr, al, sub[j])
                                 : rim_dir(&az, fr->B, fr->T, N, u0 + (j + 0.5) / fr->sub * du, &ws);
                if (lm_dot(ds, G) <= 0.0f)
                    continue;
                double den = lm_dot(ng, ds), ts = num / den;
                float su = hit[0], sv = hit[1], L[3];
                /* meets the plane on the same side, not much further or nearer than the ray's own hit (at
                 * grazing angles the stratum's far sub-directions would reach across the whole plane, past
                 * whatever hides it): its point's uv; otherwise the ray's */
                if (ts > 0.5 * h.t && ts < 2.0 * h.t) {
                    lm_vec3 off = lm_sub(lm_add(e, lm_scale(ds, (float)ts)), P);
                    su = fminf(fmaxf(hit[0] + lm_dot(lm_v3_load(gu), off), lo[0]), hi[0]);
                    sv = fminf(fmaxf(hit[1] + lm_dot(lm_v3_load(gv), off), lo[1]), hi[1]);
                }
                for (int k = 0; k < nr; k++) {
                    lm_atlas_sample_rgb(r0->atlas, far[k] ? r[k]->whole : r[k]->aim, su, sv, L);
                    for (int q = 0; q < 3; q++)
                        sum[k][q] += ws * L[q];
                }
            }
        }
        for (int k = 0; k < nr; k++)
            if (r[k]->direct && !far[k]) { /* at the ray's own point, for the whole footprint */
                float L[3];
                direct_at_hit(r[k], eye, dir, &h, seed, L);
                for (int q = 0; q < 3; q++)
                    sum[k][q] += fr->sub * fr->sub * w * L[q];
            }
    }
    for (int k = 0; k < nr; k++)
        if (r[k]->emission) {
            const float *em = r[k]->emissive ? r[k]->emissive + 3 * (size_t)r0->scene->tri_material[h.tri]
                                             : m->emissive;
            for (int q = 0; q < 3; q++)
                sum[k][q] += fr->sub * fr->sub * w * em[q];
        }
}

/* A texel standing within CONTACT_TEXELS texel widths (of what it stands on) above what lies under it (a
 * box's face by the floor it stands on, a wall's foot) sees the lit floor beyond its contact shadow as a
 * band a degree or two high just under the level: a fifth of a row of 20, which each of the row's rays
 * meets or misses (docs/gather.md, "Contact rows"). There the rows within CONTACT_BELOW under the level are
 * traced as CONTACT_SPLIT rows each, a ray and a footprint apiece, each 1 / CONTACT_SPLIT of the stratum:
 * the same measure, finer strata (the shared box's face 12 by the floor, as baked: its spread 4.3-4.8% ->
 * 2.2-3.0% in 4, 2.1-2.5% in 8, gather seeds 0-3, against a reference of a million paths a texel). */
#define CONTACT_TEXELS 4.0f
#define CONTACT_BELOW 0.2618 /* 15 degrees */
#define CONTACT_SPLIT 8

/* The rows of side, upright, within CONTACT_BELOW under the level: *lo and the count that follow it, up to
 * the level's row (u from the elevation's cdf at -CONTACT_BELOW up to the level's 1 / 2); 0 for none. */
static int contact_rows(int side, int *lo)
{
    double b = -CONTACT_BELOW, lowest = (b + sin(b) * cos(b) + 0.5 * LM_PI) / LM_PI;
    *lo = (int)ceil(lowest * side - 1e-9);
    return (int)floor(0.5 * side + 1e-9) - *lo;
}

/* The split of a standing texel: CONTACT_SPLIT where straight down (-A) it meets a surface within
 * CONTACT_TEXELS of that surface's texel widths, else 1. */
static int contact_split(const lm_rim *r, const float eye[3], lm_vec3 A)
{
    float down[3];
    lm_v3_store(down, lm_scale(A, -1.0f));
    lm_rt_hit h;
    if (!lm_rt_intersect(r->rt, eye, down, 0.0f, INFINITY, &h))
        return 1;
    return h.t < CONTACT_TEXELS * hit_texel_width(r->atlas, &h) ? CONTACT_SPLIT : 1;
}

/* stratum() over the stratum's fr->split rows of equal measure (rows: their fr->sub sub-row elevations each),
 * each with its ray at the stratum's fraction `at` of it; their sums weighed 1 / split each. */
static void split_stratum(const lm_rim *const *r, int nr, const sky_mis *mis, const float eye[3],
                          const strata_frame *fr, const cos_sin *rows, lm_vec3 G, double phi0, double dphi,
                          double u0, double du, double ax, double at, uint32_t seed, double (*sum)[3], double *back)
{
    int n = fr->split;
    double part[RIMS_AT_ONCE][3], part_back = 0.0, h = du / n;
    memset(part, 0, sizeof part);
    for (int s = 0; s < n; s++)
        stratum(r, nr, mis, eye, fr, rows + (size_t)s * fr->sub, G, phi0, dphi, u0 + s * h, h,
                fmod(ax + s * LM_GOLDEN_FRACTION, 1.0), at, seed ^ (uint32_t)s << 28, part, &part_back);
    for (int k = 0; k < nr; k++)
        for (int c = 0; c < 3; c++)
            sum[k][c] += part[k][c] / n;
    *back += part_back / n;
}

/* The K = side^2 strata of a grid turned by shift, their weighted sums added to sum and back; returns the
 * relative standard error of their mean in r[0]'s channel where it is largest (a colour's weak channel
 * is what a coloured wall's bounce leaves noisy), estimated from the differences of neighbouring strata
 * in pairs (Var of the mean ~ sum of squared pair differences / K^2: larger than the truth where the light
 * changes between neighbours, never smaller). */
static double strata(const lm_rim *const *r, int nr, const sky_mis *m, const float eye[3], const strata_frame *fr,
                     lm_vec3 G, int side, const double shift[2], uint32_t seed,
                     double (*sum)[3], double *back_w)
{
    double d = 1.0 / side, total[3] = {0, 0, 0}, sq[3] = {0, 0, 0}, first[3] = {0, 0, 0};
    int K = side * side;
    cos_sin *sub = NULL; /* upright: every row's sub-rows, shared by its strata (NULL, out of memory: the polar
                            strata, the same measure) */
    cos_sin *split = NULL; /* with fr->split: the contact rows' (`rows` from row `lo`) split rows' sub-rows,
                              split x fr->sub a row (NULL: every row as one) */
    int n = fr->split, lo = 0, rows = 0, S = fr->sub;
    if (fr->upright && (sub = malloc(sizeof *sub * (size_t)side * S)) != NULL) {
        for (int k = 0; k < side * S; k++)
            sub[k] = elevation((k + 0.5) / (side * S));
        if (n > 1 && (rows = contact_rows(side, &lo)) > 0 &&
            (split = malloc(sizeof *split * (size_t)rows * n * S)) != NULL)
            for (int k = 0; k < rows * n * S; k++)
                split[k] = elevation((lo + k / (n * S) + (k % (n * S) + 0.5) / (n * S)) * d);
    }
    /* the rays gather's rows each put their rays at their own fraction of their columns, a Kronecker sequence
     * down the rows as `at` is across the columns: a column's rays at one azimuth (its middle) read something
     * bright and narrow across the columns (a wall seen at grazing angles, from a face standing on the floor)
     * all or none at once: the shared box's face 12 by the floor spread 11.5% so, 5.8% with the rows' own
     * fractions (docs/gather.md, "Upright strata"). Not the hemicube's rim (enlargement > 0): there the ray
     * off its stratum's middle picks the plane its footprint is read on less well, and a wall seeing the
     * ceiling's bright spot in its rim mottled (test_gather's test_rim_smooth, roughness 0.061 -> 0.134). */
    int spread = r[0]->enlargement == 0.0f;
    double across_shift[2];
    lm_seed_shift(seed ^ ACROSS_SEED, across_shift);
    /* the azimuths turned per texel (a turn is periodic; upright, the column it carries past phi = 1 lies
     * at both ends, alpha near +-90 degrees, the grazing directions along the texel's plane) */
    for (int i = 0; i < side; i++) {
        double phi0 = fmod((i + shift[0]) * d, 1.0), at = fmod(shift[1] + i * LM_GOLDEN_FRACTION, 1.0);
        for (int j = 0; j < side; j++) {
            double before[3] = {sum[0][0], sum[0][1], sum[0][2]};
            double ax = spread ? fmod(across_shift[0] + j * LM_GOLDEN_FRACTION, 1.0) : 0.5;
            uint32_t own = seed * (uint32_t)K + (uint32_t)(i * side + j);
            if (split && j >= lo && j < lo + rows)
                split_stratum(r, nr, m, eye, fr, split + (size_t)(j - lo) * n * S, G, phi0, d, j * d, d, ax, at, own,
                              sum, back_w);
            else
                stratum(r, nr, m, eye, fr, sub ? sub + (size_t)j * S : NULL, G, phi0, d, j * d, d, ax, at, own,
                        sum, back_w);
            for (int c = 0; c < 3; c++) {
                double x = sum[0][c] - before[c];
                total[c] += x;
                if (j % 2 == 0)
                    first[c] = x;
                else
                    sq[c] += (x - first[c]) * (x - first[c]);
            }
        }
    }
    free(sub);
    free(split);
    double rel = 0.0;
    for (int c = 0; c < 3; c++)
        if (total[c] > 0.0)
            rel = fmax(rel, sqrt(sq[c]) / total[c]);
    return rel;
}

/* lm_rim_irradiance over the nr rims r[k] at once (lm_rim_irradiance_pair): the same rays, out[k] each. */
static void rim_irradiance(const lm_rim *const *r, int nr, const float eye[3], const float b[3], const float t[3],
                           const float n[3], const float ng[3], uint32_t seed, float (*out)[3], float *back)
{
    const lm_rim *r0 = r[0];
    int side = (int)sqrtf((float)r0->samples);
    double shift[2], sum[RIMS_AT_ONCE][3], back_w = 0.0;
    memset(sum, 0, sizeof sum);
    lm_seed_shift(seed, shift); /* shift[0]: the azimuths' turn; shift[1]: the rays' elevation in their strata */
    lm_vec3 B = lm_v3_load(b), T = lm_v3_load(t), N = lm_v3_load(n), G = lm_v3_load(ng);
    int K = side * side;
    sky_mis m = {r0->enlargement == 0.0f && K > 0 && lm_sky_by_brightness(r0->scene), K, SKY_RAYS};
    strata_frame fr = {B, T, N, 0, N, N, 1, r0->footprint > 0 ? r0->footprint : SUB};
    lm_vec3 up = lm_v3(0.0f, 1.0f, 0.0f);
    if (r0->enlargement == 0.0f && fabsf(lm_dot(up, N)) < UPRIGHT_LEVEL) {
        pthread_once(&elevation_once, elevation_table_fill);
        fr.upright = 1;
        fr.A = lm_normalize(lm_sub(up, lm_scale(N, lm_dot(up, N))));
        fr.C = lm_cross(N, fr.A);
        fr.split = contact_split(r0, eye, fr.A);
    }
    double rel = strata(r, nr, &m, eye, &fr, G, side, shift, seed, sum, &back_w);
    if (r0->adapt > 0.0f && !m.on && rel > r0->adapt) {
        /* a noisy texel (beside a contact, a penumbra on the floor it sees): a finer grid turned apart,
         * its strata's own seeds, the mean of both */
        double more[2];
        lm_seed_shift(seed ^ 0x5bd1e995u, more);
        strata(r, nr, &m, eye, &fr, G, 2 * side, more, seed ^ 0x5bd1e995u, sum, &back_w);
        K += 4 * side * side;
    }
    int ms = (int)sqrt((double)SKY_RAYS);
    for (int j = 0; m.on && j < m.M; j++) { /* the sky's own directions: a grid of strata, shifted per texel */
        float dir[3], L[3];
        lm_sky_sample(r0->scene, (float)((j / ms + shift[1]) / ms), (float)((j % ms + shift[0]) / ms), dir);
        double cos_n = lm_dot(lm_v3_load(dir), N);
        if (cos_n <= 0.0 || lm_dot(lm_v3_load(dir), G) <= 0.0f || lm_rt_occluded(r0->rt, eye, dir, 0.0f, INFINITY))
            continue;
        double pdf;
        lm_sky_radiance_pdf(r0->scene, dir, L, &pdf);
        double f = cos_n / (K * cos_n / LM_PI + m.M * pdf) * K * fr.sub * fr.sub / LM_PI;
        for (int k = 0; k < nr; k++)
            for (int c = 0; c < 3; c++)
                sum[k][c] += f * L[c];
    }
    for (int k = 0; k < nr; k++)
        for (int c = 0; c < 3; c++)
            out[k][c] = K ? (float)(LM_PI * sum[k][c] / ((double)K * fr.sub * fr.sub)) : 0.0f;
    if (back)
        *back = K ? (float)(back_w / K) : 0.0f;
}

void lm_rim_irradiance(const lm_rim *r, const float eye[3], const float b[3], const float t[3], const float n[3],
                       const float ng[3], uint32_t seed, float out[3], float *back)
{
    float o[1][3];
    rim_irradiance(&r, 1, eye, b, t, n, ng, seed, o, back);
    memcpy(out, o[0], sizeof o[0]);
}

void lm_rim_irradiance_pair(const lm_rim *was, const lm_rim *now, const float eye[3], const float b[3],
                            const float t[3], const float n[3], const float ng[3], uint32_t seed, float out_was[3],
                            float out_now[3])
{
    const lm_rim *r[RIMS_AT_ONCE] = {was, now};
    float o[RIMS_AT_ONCE][3];
    rim_irradiance(r, 2, eye, b, t, n, ng, seed, o, NULL);
    memcpy(out_was, o[0], sizeof o[0]);
    memcpy(out_now, o[1], sizeof o[1]);
}
