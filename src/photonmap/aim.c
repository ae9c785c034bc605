/* Approximated illumination maps: per-surface kd-trees, N-nearest radiance estimates and the
 * delta_f / area refresh schedule (see aim.h; Larsen & Christensen, section 3). */
#include "aim.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "../charts/atlas_dilate.h"
#include "../core/timing.h"
#include "../core/vecmath.h"
#include "../trace/photons.h"
#include "aim_sight.h"

#define MIN_COVERAGE 0.0625 /* the disc's part on the surface is never taken below 1/16 of it */

/* Luminance weights (Rec. 709), as the stored hits' energy counts them (lm_hit_energy). */
static const double LUMINANCE[3] = {0.2126, 0.7152, 0.0722};

void lm_aim_settings_default(lm_aim_settings *o)
{
    o->n_nearest = 32;
    o->min_radius_texels = 1.0f;
    o->delta_threshold = 0.01f;
    o->front_only = 1;
    o->boundary_correction = 1;
    o->kernel = 1;
    o->error_estimate = 0;
    o->dense = 1;
    o->seams = 1;
    o->direct_parts = LM_AIM_DIRECT_PARTS;
    o->max_hits = 0;
}

/* ---------- init: per-surface texel lists and boundary edges ---------- */

static lm_status build_texel_lists(lm_aim *aim, const lm_atlas *a, lm_error *err)
{
    int ns = aim->surface_count;
    aim->texel_first = calloc((size_t)ns + 1, sizeof *aim->texel_first);
    aim->texel_list = malloc(sizeof *aim->texel_list * (a->texel_count ? a->texel_count : 1));
    if (!aim->texel_first || !aim->texel_list)
        return lm_fail(err, LM_ERR_NOMEM, "AIM: no memory for %u texels", a->texel_count);
    for (uint32_t i = 0; i < a->texel_count; i++) {
        const lm_texel *t = &a->texels[i];
        if (t->surface < 0 || t->surface >= ns || t->x < 0 || t->y < 0 || t->x >= a->width || t->y >= a->height)
            return lm_fail(err, LM_ERR_INVALID, "AIM: texel %u (surface %d at %d,%d) is outside the atlas", i,
                           t->surface, t->x, t->y);
        aim->texel_first[t->surface + 1]++;
    }
    for (int s = 0; s < ns; s++)
        aim->texel_first[s + 1] += aim->texel_first[s];
    uint32_t *fill = malloc(sizeof *fill * ((size_t)ns + 1));
    if (!fill)
        return lm_fail(err, LM_ERR_NOMEM, "AIM: no memory for %d surfaces", ns);
    memcpy(fill, aim->texel_first, sizeof *fill * ((size_t)ns + 1));
    for (uint32_t i = 0; i < a->texel_count; i++)
        aim->texel_list[fill[a->texels[i].surface]++] = i;
    free(fill);
    return LM_OK;
}

/* Edge k of triangle t (corners k, k+1) is on its surface's boundary when nothing of the same surface
 * lies across it. */
static int is_boundary(const lm_surfaces *su, uint32_t t, int k, int surface)
{
    int32_t adj = su->tri_adj ? su->tri_adj[3 * (size_t)t + (size_t)k] : -1;
    return adj < 0 || su->tri_surface[adj] != surface;
}

/* ---------- joining collinear boundary edges ---------- */

/* A boundary edge: scene vertex ids, from a to b. */
typedef struct {
    uint32_t a, b;
} edge_ids;

static int by_start(const void *x, const void *y)
{
    const edge_ids *p = x, *q = y;
    if (p->a != q->a)
        return (p->a > q->a) - (p->a < q->a);
    return (p->b > q->b) - (p->b < q->b);
}

/* Whether b -> c continues a -> b in the same direction (within 1e-6 of a radian). */
static int continues(const float *pos, uint32_t a, uint32_t b, uint32_t c)
{
    double d1[3], d2[3];
    for (int k = 0; k < 3; k++) {
        d1[k] = (double)pos[3 * (size_t)b + (size_t)k] - pos[3 * (size_t)a + (size_t)k];
        d2[k] = (double)pos[3 * (size_t)c + (size_t)k] - pos[3 * (size_t)b + (size_t)k];
    }
    double x = d1[1] * d2[2] - d1[2] * d2[1], y = d1[2] * d2[0] - d1[0] * d2[2], z = d1[0] * d2[1] - d1[1] * d2[0];
    double dot = d1[0] * d2[0] + d1[1] * d2[1] + d1[2] * d2[2];
    double l1 = d1[0] * d1[0] + d1[1] * d1[1] + d1[2] * d1[2], l2 = d2[0] * d2[0] + d2[1] * d2[1] + d2[2] * d2[2];
    return dot > 0.0 && x * x + y * y + z * z <= 1e-12 * l1 * l2;
}

/* An unused edge of e[0, m) (sorted by start) leaving b along a -> b, or m. */
static uint32_t next_edge(const float *pos, const edge_ids *e, const uint8_t *used, uint32_t m, uint32_t a,
                          uint32_t b)
{
    uint32_t lo = 0, hi = m;
    while (lo < hi) { /* first edge starting at b */
        uint32_t mid = lo + (hi - lo) / 2;
        if (e[mid].a < b)
            lo = mid + 1;
        else
            hi = mid;
    }
    for (; lo < m && e[lo].a == b; lo++)
        if (!used[lo] && continues(pos, a, b, e[lo].b))
            return lo;
    return m;
}

/* Rewrites one surface's m edges (in place, sorted by start) with chains of collinear ones joined:
 * a -> b, b -> c becomes a -> c. The boundary is the same segments, so the disc's area on the surface
 * is unchanged (up to rounding), with fewer edges to walk per texel. Chains start at edges nothing
 * continues into; returns the new count. */
static uint32_t join_collinear(const float *pos, edge_ids *e, uint32_t m, uint8_t *flags, edge_ids *out)
{
    uint8_t *used = flags, *inner = flags + m;
    qsort(e, m, sizeof *e, by_start);
    memset(flags, 0, 2 * (size_t)m);
    for (uint32_t i = 0; i < m; i++) {
        uint32_t j = next_edge(pos, e, inner, m, e[i].a, e[i].b);
        if (j < m)
            inner[j] = 1; /* continues edge i: not a chain start (unless a loop leaves no start) */
    }
    uint32_t w = 0;
    for (int pass = 0; pass < 2; pass++)
        for (uint32_t i = 0; i < m; i++) {
            if (used[i] || (!pass && inner[i]))
                continue;
            used[i] = 1;
            edge_ids c = e[i];
            for (uint32_t j; (j = next_edge(pos, e, used, m, c.a, c.b)) < m; c.b = e[j].b)
                used[j] = 1;
            out[w++] = c;
        }
    memcpy(e, out, sizeof *e * w);
    return w;
}

/* Joins each surface's collinear boundary edges and packs the edge lists. */
static lm_status merge_edges(lm_aim *aim, const lm_scene *s, lm_error *err)
{
    uint32_t total = aim->edge_first[aim->surface_count], w = 0;
    edge_ids *e = malloc(sizeof *e * (total ? total : 1)), *out = malloc(sizeof *out * (total ? total : 1));
    uint8_t *flags = malloc(2 * (size_t)(total ? total : 1));
    lm_status st = e && out && flags ? LM_OK : lm_fail(err, LM_ERR_NOMEM, "AIM: no memory for %u edges", total);
    for (uint32_t i = 0; st == LM_OK && i < total; i++)
        e[i] = (edge_ids){aim->edges[2 * i], aim->edges[2 * i + 1]};
    for (int sf = 0; st == LM_OK && sf < aim->surface_count; sf++) {
        uint32_t first = aim->edge_first[sf], m = aim->edge_first[sf + 1] - first;
        m = join_collinear(s->positions, e + first, m, flags, out);
        aim->edge_first[sf] = w;
        for (uint32_t i = 0; i < m; i++, w++) {
            aim->edges[2 * w] = e[first + i].a;
            aim->edges[2 * w + 1] = e[first + i].b;
        }
    }
    if (st == LM_OK)
        aim->edge_first[aim->surface_count] = w;
    free(e);
    free(out);
    free(flags);
    return st;
}

static lm_status build_edges(lm_aim *aim, const lm_scene *s, const lm_surfaces *su, lm_error *err)
{
    int ns = aim->surface_count;
    aim->edge_first = calloc((size_t)ns + 1, sizeof *aim->edge_first);
    if (!aim->edge_first)
        return lm_fail(err, LM_ERR_NOMEM, "AIM: no memory for %d surfaces", ns);
    for (int pass = 0; pass < 2; pass++) { /* count, then fill */
        uint32_t e = 0;
        for (int i = 0; i < ns; i++) {
            const lm_surface *sf = &su->surfaces[i];
            aim->edge_first[i] = e;
            for (uint32_t j = 0; j < sf->tri_count; j++)
                for (int k = 0; k < 3; k++) {
                    if (!is_boundary(su, sf->tris[j], k, i))
                        continue;
                    if (pass) {
                        aim->edges[2 * e] = s->tris[3 * (size_t)sf->tris[j] + (size_t)k];
                        aim->edges[2 * e + 1] = s->tris[3 * (size_t)sf->tris[j] + (size_t)(k + 1) % 3];
                    }
                    e++;
                }
        }
        aim->edge_first[ns] = e;
        if (!pass && !(aim->edges = malloc(sizeof *aim->edges * 2 * (e ? e : 1))))
            return lm_fail(err, LM_ERR_NOMEM, "AIM: no memory for %u boundary edges", e);
    }
    return merge_edges(aim, s, err);
}

static lm_status check_settings(const lm_aim_settings *o, lm_error *err)
{
    if (o->n_nearest < 1 || !(o->min_radius_texels > 0.0f) || !isfinite(o->min_radius_texels) ||
        !(o->delta_threshold >= 0.0f) || !isfinite(o->delta_threshold) || o->direct_parts < 1 ||
        o->direct_parts > LM_AIM_DIRECT_PARTS_MAX)
        return lm_fail(err, LM_ERR_INVALID,
                       "AIM settings: n_nearest %d (>= 1), min_radius_texels %g (> 0), delta_threshold %g (>= 0), "
                       "direct_parts %d (1 to %d)",
                       o->n_nearest, (double)o->min_radius_texels, (double)o->delta_threshold, o->direct_parts,
                       LM_AIM_DIRECT_PARTS_MAX);
    return LM_OK;
}

lm_status lm_aim_init(lm_aim *aim, const lm_scene *s, const lm_surfaces *su, const lm_atlas *a,
                      const lm_aim_settings *set, lm_error *err)
{
    memset(aim, 0, sizeof *aim);
    if (set)
        aim->set = *set;
    else
        lm_aim_settings_default(&aim->set);
    lm_status st = check_settings(&aim->set, err);
    if (st != LM_OK)
        return st;
    if (a->width <= 0 || a->height <= 0 || su->surface_count < 0 || a->surface_count != su->surface_count)
        return lm_fail(err, LM_ERR_INVALID, "AIM: atlas %dx%d with %d surfaces, scene has %d surfaces", a->width,
                       a->height, a->surface_count, su->surface_count);
    aim->width = a->width;
    aim->height = a->height;
    aim->surface_count = su->surface_count;
    aim->rgb = calloc((size_t)a->width * (size_t)a->height * 3, sizeof *aim->rgb);
    aim->dilated = calloc((size_t)a->width * (size_t)a->height * 4, sizeof *aim->dilated);
    aim->refresh_count = calloc((size_t)su->surface_count + 1, sizeof *aim->refresh_count);
    aim->edge_d2 = malloc(((size_t)a->texel_count + 1) * sizeof *aim->edge_d2);
    for (uint32_t i = 0; aim->edge_d2 && i < a->texel_count; i++)
        aim->edge_d2[i] = -1.0f; /* unknown until the texel's first estimate walks the edges */
    if (aim->set.error_estimate)
        aim->error = calloc((size_t)a->width * (size_t)a->height * 2, sizeof *aim->error);
    if (!aim->rgb || !aim->dilated || !aim->refresh_count || !aim->edge_d2 ||
        (aim->set.error_estimate && !aim->error))
        st = lm_fail(err, LM_ERR_NOMEM, "AIM: no memory for a %dx%d map", a->width, a->height);
    if (st == LM_OK)
        st = build_texel_lists(aim, a, err);
    if (st == LM_OK)
        st = build_edges(aim, s, su, err);
    if (st == LM_OK && aim->set.seams)
        st = lm_seams_find(&aim->seams, s, su, err);
    if (st == LM_OK && (!(aim->seams_used = calloc((size_t)su->surface_count + 1, sizeof *aim->seams_used)) ||
                        !(aim->owed = calloc((size_t)su->surface_count + 1, sizeof *aim->owed))))
        st = lm_fail(err, LM_ERR_NOMEM, "AIM: no memory for %d surfaces", su->surface_count);
    if (st != LM_OK)
        lm_aim_free(aim);
    return st;
}

void lm_aim_free(lm_aim *aim)
{
    free(aim->rgb);
    free(aim->dilated);
    free(aim->rest);
    free(aim->rest_dilated);
    free(aim->error);
    free(aim->texel_first);
    free(aim->texel_list);
    free(aim->edge_first);
    free(aim->edges);
    free(aim->refresh_count);
    free(aim->edge_d2);
    free(aim->seams_used);
    free(aim->owed);
    lm_seams_free(&aim->seams);
    memset(aim, 0, sizeof *aim);
}

void lm_aim_set_direct(lm_aim *aim, const lm_direct_light *d) { aim->direct = d; }

lm_status lm_aim_keep_rest(lm_aim *aim, lm_error *err)
{
    size_t cells = (size_t)aim->width * (size_t)aim->height;
    if (!aim->rest)
        aim->rest = calloc(cells * 3, sizeof *aim->rest);
    if (!aim->rest_dilated)
        aim->rest_dilated = calloc(cells * 4, sizeof *aim->rest_dilated);
    if (!aim->rest || !aim->rest_dilated)
        return lm_fail(err, LM_ERR_NOMEM, "AIM: no memory for a %dx%d map of the light besides the punctual lights'",
                       aim->width, aim->height);
    return LM_OK;
}

const float *lm_aim_rest_dilated_rgba(const lm_aim *aim) { return aim->rest_dilated; }

void lm_aim_set_occluders(lm_aim *aim, const lm_rt *rt, float lift, float cover, const float *cover_by_surface)
{
    aim->occluders = rt;
    aim->occluder_lift = lift;
    aim->occluder_cover = cover;
    aim->occluder_cover_by_surface = cover_by_surface;
}

const float *lm_aim_rgb(const lm_aim *aim) { return aim->rgb; }
const float *lm_aim_dilated_rgba(const lm_aim *aim) { return aim->dilated; }

/* ---------- the node's transform ---------- */

typedef struct {
    double m[3][3];   /* linear part of the node's world matrix, m[row][col] */
    double inv[3][3]; /* its inverse */
    double det;
} linear_map;

static void linear_map_of(const float w[16], linear_map *L)
{
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            L->m[r][c] = w[c * 4 + r];
    double(*m)[3] = L->m;
    double cof[3][3];
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            cof[r][c] = m[(r + 1) % 3][(c + 1) % 3] * m[(r + 2) % 3][(c + 2) % 3] -
                        m[(r + 1) % 3][(c + 2) % 3] * m[(r + 2) % 3][(c + 1) % 3];
    L->det = m[0][0] * cof[0][0] + m[0][1] * cof[0][1] + m[0][2] * cof[0][2];
    double id = L->det != 0.0 ? 1.0 / L->det : 0.0;
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            L->inv[r][c] = cof[c][r] * id;
}

/* World area per local area for a patch with local unit normal n (Nanson: |det M| |M^-T n|). */
static double area_factor(const linear_map *L, const double n[3])
{
    double s2 = 0.0;
    for (int c = 0; c < 3; c++) {
        double v = L->inv[0][c] * n[0] + L->inv[1][c] * n[1] + L->inv[2][c] * n[2];
        s2 += v * v;
    }
    double f = fabs(L->det) * sqrt(s2);
    return f > 0.0 && isfinite(f) ? f : 1.0;
}

/* Unit face normal of triangle t in its node's local space (winding order: the front side). */
static void local_face_normal(const lm_scene *s, uint32_t t, double n[3])
{
    const float *p[3];
    for (int k = 0; k < 3; k++)
        p[k] = s->positions + 3 * (size_t)s->tris[3 * (size_t)t + (size_t)k];
    double e1[3], e2[3];
    for (int a = 0; a < 3; a++) {
        e1[a] = (double)p[1][a] - p[0][a];
        e2[a] = (double)p[2][a] - p[0][a];
    }
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    double l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (int a = 0; a < 3; a++)
        n[a] = l > 0.0 ? n[a] / l : (a == 2);
}

/* The estimate's smallest radius, world units of the atlas, for a surface of `hits` hits: min_radius_texels
 * texels at N = LM_AIM_FLOOR_N, growing with sqrt(N) (aim.h: where hits are denser than that, N still sets
 * the disc). Above LM_AIM_FLOOR_N, N counts for at most the surface's hits: with fewer the disc reaches the
 * farthest as before, and a floor wider than the surface would meet the boundary correction's clamp
 * (N = 100,000 read a room 25% dark). */
static double smallest_radius(const lm_aim *aim, const lm_atlas *a, uint64_t hits)
{
    double n = aim->set.n_nearest, most = fmax((double)hits, LM_AIM_FLOOR_N);
    return (double)aim->set.min_radius_texels * a->texel_size * sqrt(fmin(n, most) / LM_AIM_FLOOR_N);
}

/* ---------- gathering a surface's hits ---------- */

typedef struct {
    float *pos;  /* local positions, 3 per hit */
    double *flux; /* RGB and a 0, 4 per hit (widened once here rather than per lookup; 4 for paired ops) */
    float *ends;  /* with occluders (lm_aim_set_occluders), 6 per hit: its world position and that of the
                   * vertex its photon left (NaN: not known), for the visibility test (aim_sight.h); else NULL */
    uint32_t count;
} hit_set;

/* A photon travelling along world direction d reaches the front of a triangle whose local normal is n
 * when d . n_world < 0, with n_world = det(M) M^-T n (the cofactor map), i.e. det(M) (M^-1 d) . n < 0. */
static int arrives_front(const linear_map *L, const lm_scene *s, const lm_hit *h)
{
    if (h->tri >= s->tri_count)
        return 1;
    double n[3], d = 0.0;
    local_face_normal(s, h->tri, n);
    for (int r = 0; r < 3; r++)
        d += (L->inv[r][0] * h->dir[0] + L->inv[r][1] * h->dir[1] + L->inv[r][2] * h->dir[2]) * n[r];
    return L->det * d < 0.0;
}

/* The local space of one node in that of another (the node with linear map L_to and world matrix w_to):
 * how a continuing surface's hits and edges are read in the surface's own space. */
typedef struct {
    double m[3][3], t[3];
} affine;

static void node_to_node(const float w_from[16], const float w_to[16], const linear_map *L_to, affine *A)
{
    for (int r = 0; r < 3; r++) {
        A->t[r] = 0.0;
        for (int c = 0; c < 3; c++) {
            A->m[r][c] = 0.0;
            for (int k = 0; k < 3; k++)
                A->m[r][c] += L_to->inv[r][k] * w_from[c * 4 + k];
        }
        for (int k = 0; k < 3; k++)
            A->t[r] += L_to->inv[r][k] * ((double)w_from[12 + k] - w_to[12 + k]);
    }
}

static void affine_point(const affine *A, const float p[3], float out[3])
{
    for (int r = 0; r < 3; r++)
        out[r] = (float)(A->m[r][0] * p[0] + A->m[r][1] * p[1] + A->m[r][2] * p[2] + A->t[r]);
}

/* Appends the hits of `surface` that an estimate sums: from the front only (front_only), without those
 * whose light is computed directly (direct, may be NULL); mapped by A (another node's; NULL: none) and
 * with box (a continuing surface's; NULL: every one) only those inside it (lo, hi). out has room for them
 * all. */
static void append_hits(const lm_photon_store *ps, int surface, const lm_scene *s, const linear_map *L,
                        int front_only, const lm_direct_light *direct, const affine *A, const float box[6],
                        hit_set *out)
{
    const uint32_t *slots = ps->surfaces[surface].slots;
    for (uint32_t k = 0; k < ps->surfaces[surface].count; k++) {
        const lm_hit *hit = &ps->hits[slots[k]];
        if ((front_only && !arrives_front(L, s, hit)) || (direct && lm_direct_covers_hit(direct, hit)))
            continue;
        float *p = out->pos + 3 * out->count;
        if (A)
            affine_point(A, hit->local, p);
        else
            memcpy(p, hit->local, sizeof hit->local);
        if (box && (p[0] < box[0] || p[1] < box[1] || p[2] < box[2] || p[0] > box[3] || p[1] > box[4] || p[2] > box[5]))
            continue;
        for (int c = 0; c < 4; c++)
            out->flux[4 * out->count + (uint32_t)c] = c < 3 ? hit->flux[c] : 0.0;
        for (int c = 0; out->ends && c < 3; c++) {
            out->ends[6 * out->count + (uint32_t)c] = hit->pos[c];
            out->ends[6 * out->count + 3 + (uint32_t)c] =
                hit->travelled > 0.0f ? hit->pos[c] - hit->travelled * hit->dir[c] : NAN;
        }
        out->count++;
    }
}

/* Surface k's boundary edges as local positions of the surface the estimate is for (A maps them; NULL:
 * the same node), 6 floats each, into out. Returns how many. */
static uint32_t append_edges(const lm_aim *aim, const lm_scene *s, int k, const affine *A, float *out)
{
    uint32_t n = 0;
    for (uint32_t e = aim->edge_first[k]; e < aim->edge_first[k + 1]; e++, n++)
        for (int v = 0; v < 2; v++) {
            const float *p = s->positions + 3 * (size_t)aim->edges[2 * e + (uint32_t)v];
            float *o = out + 6 * (size_t)n + 3 * v;
            if (A)
                affine_point(A, p, o);
            else
                memcpy(o, p, 3 * sizeof *o);
        }
    return n;
}

static int front_only_for(const lm_aim *aim, const lm_scene *s, const lm_surface *sf, const linear_map *L)
{
    return aim->set.front_only && !s->materials[sf->material].double_sided && L->det != 0.0;
}

/* Whether surface t's hits may join surface k's estimate now: the same node, or two that do not move. */
static int seam_usable(const lm_scene *s, const lm_surfaces *su, int k, int t)
{
    int a = su->surfaces[k].node, b = su->surfaces[t].node;
    return a == b || (!lm_node_moves(&s->nodes[a]) && !lm_node_moves(&s->nodes[b]));
}

/* How far past a surface's texels a continuing surface's hits are taken: 4 times the radius that holds N
 * hits at the surface's mean density (an estimate whose disc reaches farther, where the light is under
 * 1/16 of the surface's mean, misses the hits beyond, as it did without seams). Local units. */
static double seam_reach(const lm_aim *aim, const lm_surfaces *su, int k, const linear_map *L, const lm_scene *s,
                         uint32_t own_hits)
{
    if (own_hits == 0 || su->surfaces[k].tri_count == 0)
        return INFINITY;
    double n[3];
    local_face_normal(s, su->surfaces[k].tris[0], n);
    double area = (double)su->surfaces[k].area / area_factor(L, n);
    return 4.0 * sqrt((double)aim->set.n_nearest * area / (LM_PI * own_hits));
}

/* The box around the surface's texels (local), widened by reach. */
static void texel_box(const lm_aim *aim, const lm_atlas *a, int k, double reach, float box[6])
{
    for (int c = 0; c < 3; c++)
        box[c] = INFINITY, box[3 + c] = -INFINITY;
    for (uint32_t i = aim->texel_first[k]; i < aim->texel_first[k + 1]; i++)
        for (int c = 0; c < 3; c++) {
            float x = a->texels[aim->texel_list[i]].local[c];
            box[c] = fminf(box[c], x), box[3 + c] = fmaxf(box[3 + c], x);
        }
    for (int c = 0; c < 3; c++)
        box[c] = (float)(box[c] - reach), box[3 + c] = (float)(box[3 + c] + reach);
}

/* The hits the estimates of the job's surface sum, its own and (set.seams) those of the surfaces that
 * continue it near its texels, and the edges around them all (boundary); *seams_used names the set of
 * continuing surfaces used (0: none). */
static lm_status gather_hits(const lm_aim *aim, const lm_photon_store *ps, const lm_scene *s,
                             const lm_surfaces *su, const lm_atlas *a, int k, const linear_map *L,
                             hit_set *out, float **edge_ends, uint32_t *edge_count, uint32_t *seams_used,
                             lm_error *err)
{
    const lm_seams *sm = &aim->seams;
    uint32_t first = sm->first ? sm->first[k] : 0, end = sm->first ? sm->first[k + 1] : 0;
    uint64_t hits = ps->surfaces[k].count, edges = aim->edge_first[k + 1] - aim->edge_first[k];
    *seams_used = 0;
    for (uint32_t i = first; i < end; i++)
        if (seam_usable(s, su, k, sm->list[i])) {
            hits += ps->surfaces[sm->list[i]].count;
            edges += aim->edge_first[sm->list[i] + 1] - aim->edge_first[sm->list[i]];
            *seams_used = *seams_used * 31u + (uint32_t)sm->list[i] + 1u;
        }
    out->count = 0;
    out->pos = malloc(sizeof *out->pos * 3 * (hits ? hits : 1));
    out->flux = malloc(sizeof *out->flux * 4 * (hits ? hits : 1));
    out->ends = aim->occluders ? malloc(sizeof *out->ends * 6 * (hits ? hits : 1)) : NULL;
    *edge_ends = malloc(sizeof **edge_ends * 6 * (edges ? edges : 1));
    if (!out->pos || !out->flux || (aim->occluders && !out->ends) || !*edge_ends || hits > UINT32_MAX)
        return lm_fail(err, LM_ERR_NOMEM, "AIM: no memory for %llu hits of surface %d", (unsigned long long)hits, k);
    const lm_surface *sf = &su->surfaces[k];
    append_hits(ps, k, s, L, front_only_for(aim, s, sf, L), aim->direct, NULL, NULL, out);
    *edge_count = append_edges(aim, s, k, NULL, *edge_ends);
    float box[6];
    if (end > first)
        texel_box(aim, a, k, seam_reach(aim, su, k, L, s, out->count), box);
    for (uint32_t i = first; i < end; i++) {
        int t = sm->list[i];
        if (!seam_usable(s, su, k, t))
            continue;
        const lm_surface *tf = &su->surfaces[t];
        linear_map LT;
        affine A;
        linear_map_of(s->nodes[tf->node].world, &LT);
        node_to_node(s->nodes[tf->node].world, s->nodes[sf->node].world, L, &A);
        const affine *map = tf->node == sf->node ? NULL : &A;
        append_hits(ps, t, s, &LT, front_only_for(aim, s, tf, &LT), aim->direct, map, box, out);
        *edge_count += append_edges(aim, s, t, map, *edge_ends + 6 * (size_t)*edge_count);
    }
    return LM_OK;
}

/* ---------- the area the gathered hits span ---------- */

/* Areas below are weighted by the estimate's kernel w(d) over the disc of radius r: box (w = 1, the
 * paper's sum / (pi r^2)) or Epanechnikov (w = 1 - d^2 / r^2, whose integral over the disc is pi r^2 / 2).
 * In polar form a sector of angle theta weighs theta r^2 / 2 (box) or theta r^2 / 4 (Epanechnikov). */
static double sector(const double a[2], const double b[2], double r2, int kernel)
{
    return (kernel ? 0.25 : 0.5) * r2 * atan2(a[0] * b[1] - a[1] * b[0], a[0] * b[0] + a[1] * b[1]);
}

/* Weighted signed area of triangle (0, a, b) lying inside the disc: A, or with the kernel
 * A - (1 / r^2) * integral |x|^2 dA = A (1 - (|a|^2 + |b|^2 + a.b) / (6 r^2)). */
static double inner_triangle(const double a[2], const double b[2], double r2, int kernel)
{
    double A = 0.5 * (a[0] * b[1] - a[1] * b[0]);
    if (!kernel)
        return A;
    double m = a[0] * a[0] + a[1] * a[1] + b[0] * b[0] + b[1] * b[1] + a[0] * b[0] + a[1] * b[1];
    return A * (1.0 - m / (6.0 * r2));
}

/* weighted area(disc(0, r) & triangle(0, a, b)) - sector(a, b): what edge a->b changes in the disc's
 * weighted area (summed over a closed boundary around 0, the sectors alone give the full disc). 0 when
 * the edge misses the disc. */
static double edge_correction(const double a[2], const double b[2], double r2, int kernel)
{
    double d[2] = {b[0] - a[0], b[1] - a[1]};
    double A = d[0] * d[0] + d[1] * d[1], B = a[0] * d[0] + a[1] * d[1], C = a[0] * a[0] + a[1] * a[1] - r2;
    double disc = B * B - A * C;
    if (!(A > 0.0) || disc <= 0.0)
        return 0.0;
    double sq = sqrt(disc), t1 = (-B - sq) / A, t2 = (-B + sq) / A;
    if (t2 <= 0.0 || t1 >= 1.0)
        return 0.0;
    t1 = t1 > 0.0 ? t1 : 0.0;
    t2 = t2 < 1.0 ? t2 : 1.0;
    double p1[2] = {a[0] + t1 * d[0], a[1] + t1 * d[1]}, p2[2] = {a[0] + t2 * d[0], a[1] + t2 * d[1]};
    double inside = inner_triangle(p1, p2, r2, kernel);
    if (t1 > 0.0)
        inside += sector(a, p1, r2, kernel);
    if (t2 < 1.0)
        inside += sector(p2, b, r2, kernel);
    return inside - sector(a, b, r2, kernel);
}

/* The edges around the region an estimate's disc may cover: the surface's own boundary, and with seams
 * the boundaries of the surfaces that continue it, all in the surface's local space. Edges shared by two
 * of them come once each way round and cancel (each edge's correction changes sign with its direction),
 * so the sum is the boundary of their union. */
typedef struct {
    const float *ends;    /* 6 per edge: a, then b, local positions */
    uint32_t count;
} boundary;

/* Squared distance from the origin to the segment ab (2-d). */
static double segment_dist2(const double a[2], const double b[2])
{
    double d[2] = {b[0] - a[0], b[1] - a[1]}, len2 = d[0] * d[0] + d[1] * d[1];
    double t = len2 > 0.0 ? -(a[0] * d[0] + a[1] * d[1]) / len2 : 0.0;
    t = t < 0.0 ? 0.0 : t > 1.0 ? 1.0 : t;
    double x = a[0] + t * d[0], y = a[1] + t * d[1];
    return x * x + y * y;
}

/* Whether the segment ab lies wholly to one side of the square [-r, r]^2 (so it misses the disc). */
static int beside_square(const double a[2], const double b[2], double r)
{
    return ((a[0] > r) & (b[0] > r)) | ((a[0] < -r) & (b[0] < -r)) | ((a[1] > r) & (b[1] > r)) |
           ((a[1] < -r) & (b[1] < -r));
}

/* A tangent frame (t1, t2) of the unit normal n, with t1 x t2 = n: counter-clockwise seen from the front. */
static void tangent_frame(const double n[3], double t1[3], double t2[3])
{
    double h[3] = {fabs(n[0]) < 0.9 ? 1.0 : 0.0, fabs(n[0]) < 0.9 ? 0.0 : 1.0, 0.0};
    t1[0] = h[1] * n[2] - h[2] * n[1];
    t1[1] = h[2] * n[0] - h[0] * n[2];
    t1[2] = h[0] * n[1] - h[1] * n[0];
    double l = sqrt(t1[0] * t1[0] + t1[1] * t1[1] + t1[2] * t1[2]);
    for (int a = 0; a < 3; a++)
        t1[a] /= l;
    t2[0] = n[1] * t1[2] - n[2] * t1[1];
    t2[1] = n[2] * t1[0] - n[0] * t1[2];
    t2[2] = n[0] * t1[1] - n[1] * t1[0];
}

/* One surface's boundary edges in the tangent frame of one normal: per edge the coordinates (a.t1, a.t2,
 * b.t1, b.t2) of its ends. Each thread keeps one and reprojects only when the surface or the normal
 * changes (texels of a flat surface share it). */
typedef struct {
    const boundary *bd;   /* what uv holds (NULL: nothing yet) */
    double n[3], t1[3], t2[3];
    double *uv;           /* 4 per edge, room for the most edges of a surface in the refresh */
} edge_frame;

static void project_edges(edge_frame *ef, const boundary *bd, const double n[3])
{
    if (ef->bd == bd && memcmp(ef->n, n, sizeof ef->n) == 0)
        return;
    ef->bd = bd;
    memcpy(ef->n, n, sizeof ef->n);
    tangent_frame(n, ef->t1, ef->t2);
    for (uint32_t e = 0; e < bd->count; e++)
        for (int k = 0; k < 2; k++) {
            const float *v = bd->ends + 6 * (size_t)e + 3 * k;
            double *o = ef->uv + 4 * (size_t)e + 2 * k;
            o[0] = v[0] * ef->t1[0] + v[1] * ef->t1[1] + v[2] * ef->t1[2];
            o[1] = v[0] * ef->t2[0] + v[1] * ef->t2[1] + v[2] * ef->t2[2];
        }
}

/* Local-space (kernel-weighted) area of the disc of radius^2 r2 around q, in the tangent plane of normal
 * n, that lies on the surface: the full disc's plus the corrections of the boundary edges crossing it.
 * *edge_d2 gets a lower bound on the squared distance to the nearest boundary edge in that plane: a later
 * disc smaller than that lies wholly on the surface and needs no edge walk. Edges beside the disc's
 * bounding square are skipped. */
static double disc_area_on_surface(edge_frame *ef, const boundary *bd, const float q[3], const double n[3],
                                   double r2, int kernel, double *edge_d2)
{
    project_edges(ef, bd, n);
    double qa = q[0] * ef->t1[0] + q[1] * ef->t1[1] + q[2] * ef->t1[2];
    double qb = q[0] * ef->t2[0] + q[1] * ef->t2[1] + q[2] * ef->t2[2];
    double full = (kernel ? 0.5 : 1.0) * LM_PI * r2, area = full, nearest = r2, r = sqrt(r2);
    for (uint32_t e = 0; e < bd->count; e++) {
        const double *o = ef->uv + 4 * (size_t)e;
        double p[2][2] = {{o[0] - qa, o[1] - qb}, {o[2] - qa, o[3] - qb}};
        if (beside_square(p[0], p[1], r))
            continue; /* misses the disc: no correction, and farther than r */
        area += edge_correction(p[0], p[1], r2, kernel);
        nearest = fmin(nearest, segment_dist2(p[0], p[1]));
    }
    *edge_d2 = nearest; /* the nearest edge's distance, or r2 when every edge is farther (a lower bound) */
    return fmin(fmax(area, MIN_COVERAGE * full), full);
}

/* ---------- per-texel estimate ---------- */

typedef struct {
    const lm_scene *s;
    const lm_atlas *a;
    const lm_kdtree *tree;
    const hit_set *hits;
    const linear_map *L;
    boundary bd;
    uint32_t n;           /* N, clamped to the hit count */
    double rmin2_world;   /* squared smallest radius, world units */
    int boundary_correction, kernel;
    const lm_direct_light *direct; /* NULL: no direct light added */
    int direct_parts;     /* the direct light's parts a side (lm_aim_settings.direct_parts) */
    const float *world;   /* the node's world matrix (texel positions for the direct light and the sight) */
    int two_sided;        /* double-sided material: direct light on both sides */
    lm_aim_sight sight;   /* the visibility test (aim_sight.h; rt NULL: none) */
    const double *binned; /* a dense surface's sums (bin_dense_surface), per texel of its list: w Phi (4) and
                           * sum (w Y)^2; NULL: the kd-tree's estimates */
} estimate_job;

typedef struct {
    const double *flux;
    double inv_r2;  /* 1 / r^2 with the Epanechnikov kernel, 0 for the box */
    double sum[4];  /* RGB and the flux's fourth channel, 0 */
} flux_sum;

/* Adds hit index's w(d) Phi to the partial sum s (the fourth channel is 0). */
static inline void add_hit(double s[4], const flux_sum *f, uint32_t index, float d2)
{
    double w = 1.0 - d2 * f->inv_r2;
    w = w > 0.0 ? w : 0.0;
    const double *phi = f->flux + 4 * (size_t)index;
    for (int c = 0; c < 4; c++)
        s[c] += w * phi[c];
}

/* Adds w(d) Phi_i (the radius search's visitor). */
static void add_flux(void *ctx, uint32_t index, float d2)
{
    flux_sum *f = ctx;
    add_hit(f->sum, f, index, d2);
}

/* add_flux over the k found hits: hit i goes to partial sum i % 4 (in order within each), and the four
 * are added up at the end. A fixed grouping given the list, with four times the throughput of one chain. */
static void add_found(flux_sum *f, const uint32_t *idx, const float *d2, uint32_t k)
{
    double p0[4] = {0.0}, p1[4] = {0.0}, p2[4] = {0.0}, p3[4] = {0.0};
    uint32_t i = 0;
    for (; i + 4 <= k; i += 4) {
        add_hit(p0, f, idx[i], d2[i]);
        add_hit(p1, f, idx[i + 1], d2[i + 1]);
        add_hit(p2, f, idx[i + 2], d2[i + 2]);
        add_hit(p3, f, idx[i + 3], d2[i + 3]);
    }
    if (i < k)
        add_hit(p0, f, idx[i], d2[i]);
    if (i + 1 < k)
        add_hit(p1, f, idx[i + 1], d2[i + 1]);
    if (i + 2 < k)
        add_hit(p2, f, idx[i + 2], d2[i + 2]);
    for (int c = 0; c < 3; c++)
        f->sum[c] += (p0[c] + p1[c]) + (p2[c] + p3[c]);
}

/* One thread's working memory for the estimates. */
typedef struct texel_scratch texel_scratch;

/* The N nearest hits to q, searched within the bound the last query of the run gives. They come listed in
 * the search's leaf order (N <= 256) whatever that bound, so the texel's sums do not depend on the run. */
static uint32_t find_nearest(const estimate_job *j, lm_kdtree_hint *h, const float q[3], uint32_t *idx, float *d2,
                             float *r2)
{
    return lm_kdtree_nearest_hinted(j->tree, h, q, j->n, idx, d2, r2);
}

/* A triangle's unit local normal and world area per local area, kept for the next texels (runs of texels
 * share a triangle). */
typedef struct {
    const estimate_job *job; /* NULL: nothing kept yet */
    uint32_t tri;
    double n[3], factor;
    float n_world[3];        /* unit world normal of the front side */
} tri_frame;

static const tri_frame *triangle_frame(const estimate_job *j, uint32_t tri, tri_frame *tf)
{
    if (tf->job != j || tf->tri != tri) {
        tf->job = j;
        tf->tri = tri;
        local_face_normal(j->s, tri, tf->n);
        tf->factor = area_factor(j->L, tf->n);
        double w[3], len = 0.0; /* det(M) M^-T n, as arrives_front */
        for (int c = 0; c < 3; c++) {
            w[c] = j->L->inv[0][c] * tf->n[0] + j->L->inv[1][c] * tf->n[1] + j->L->inv[2][c] * tf->n[2];
            len += w[c] * w[c];
        }
        len = sqrt(len) * (j->L->det < 0.0 ? -1.0 : 1.0);
        for (int c = 0; c < 3; c++)
            tf->n_world[c] = len != 0.0 ? (float)(w[c] / len) : (float)tf->n[c];
    }
    return tf;
}

/* A texel's hits within a radius with their weights, for the visibility test (grown as needed). */
typedef struct {
    uint32_t *idx;
    float *d2, *weight;
    uint32_t count, cap;
} hit_list;

struct texel_scratch {
    uint32_t *idx;  /* N found hits ... */
    float *d2;      /* ... and their squared distances */
    tri_frame tri;
    edge_frame ef;
    lm_kdtree_hint hint;
    hit_list sighted;
};

static int hit_list_reserve(hit_list *l, uint32_t n)
{
    if (n <= l->cap)
        return 1;
    uint32_t cap = l->cap ? l->cap : 64;
    while (cap < n)
        cap *= 2;
    uint32_t *idx = realloc(l->idx, sizeof *idx * cap);
    if (idx)
        l->idx = idx;
    float *d2 = realloc(l->d2, sizeof *d2 * cap);
    if (d2)
        l->d2 = d2;
    float *w = realloc(l->weight, sizeof *w * cap);
    if (w)
        l->weight = w;
    if (!idx || !d2 || !w)
        return 0;
    l->cap = cap;
    return 1;
}

/* The radius search's visitor for the visibility test: lists the hit (one that finds no memory is left
 * out, as if not found). */
static void list_hit(void *ctx, uint32_t index, float d2)
{
    hit_list *l = ctx;
    if (!hit_list_reserve(l, l->count + 1))
        return;
    l->idx[l->count] = index;
    l->d2[l->count++] = d2;
}

/* For the error estimate (lm_aim.error): sum((w_i Y_i)^2), Y_i = y . Phi_i. */
typedef struct {
    const double *flux;
    double inv_r2, y[3], sum;
} square_sum;

static void add_square(void *ctx, uint32_t index, float d2)
{
    square_sum *q = ctx;
    double w = fmax(1.0 - d2 * q->inv_r2, 0.0);
    const double *phi = q->flux + 4 * (size_t)index;
    double v = w * (q->y[0] * phi[0] + q->y[1] * phi[1] + q->y[2] * phi[2]);
    q->sum += v * v;
}

/* The sums of photon_irradiance and the error estimate's (q: NULL when off) with each of the k hits idx (d2
 * their squared distances) weighed by the visibility test too (aim_sight.h), in list order. */
static void sighted_sums(const estimate_job *j, const lm_texel *t, uint32_t index, const tri_frame *tf,
                         texel_scratch *ts, const uint32_t *idx, const float *d2, uint32_t k, float r2, flux_sum *f,
                         square_sum *q)
{
    if (!hit_list_reserve(&ts->sighted, k))
        return; /* no memory: no light rather than untested light */
    float *weight = ts->sighted.weight;
    lm_aim_sight_texel st = {{0.0f}, {tf->n_world[0], tf->n_world[1], tf->n_world[2]},
                             (float)sqrt((double)r2 * tf->factor), index};
    lm_v3_store(st.x, lm_mat4_point(j->world, lm_v3_load(t->local)));
    lm_aim_sight_weigh(&j->sight, &st, j->hits->ends, idx, k, weight);
    for (uint32_t i = 0; i < k; i++) {
        double w = fmax(1.0 - d2[i] * f->inv_r2, 0.0) * weight[i];
        const double *phi = f->flux + 4 * (size_t)idx[i];
        for (int c = 0; c < 3; c++)
            f->sum[c] += w * phi[c];
        if (q) {
            double v = w * (q->y[0] * phi[0] + q->y[1] * phi[1] + q->y[2] * phi[2]);
            q->sum += v * v;
        }
    }
}

/* What the error estimate keeps of one texel's photon estimate: the variance of y . E, as a sum of
 * independently placed hits, and the radius^2 in world units. */
typedef struct {
    int on;
    double y[3];   /* luminance weights times rho / pi: the variance is the radiance's */
    double var, r2_world;
} estimate_error;

/* E = sum(w_i Phi_i) / A_w over the N nearest hits (or every hit within the smallest radius);
 * A_w = pi r^2 (box) or pi r^2 / 2 (Epanechnikov) away from the surface's boundary. 0 without hits. */
static void photon_irradiance(const estimate_job *j, const lm_texel *t, uint32_t index, uint32_t slot,
                              texel_scratch *ts, float *edge_d2, double out[3], estimate_error *ee)
{
    out[0] = out[1] = out[2] = 0.0;
    if (j->n == 0)
        return;
    const tri_frame *tf = triangle_frame(j, t->tri, &ts->tri);
    const double *n = tf->n;
    double factor = tf->factor, rmin2 = j->rmin2_world / factor;
    float r2 = 0.0f, *d2 = ts->d2;
    uint32_t *idx = ts->idx, k = 0;
    int widened = j->binned != NULL; /* a dense surface's: every texel had N hits within the radius */
    if (!widened) {
        k = find_nearest(j, &ts->hint, t->local, idx, d2, &r2);
        if (k == 0)
            return;
        widened = (double)r2 < rmin2;
    }
    if (widened)
        r2 = (float)rmin2;
    flux_sum f = {j->hits->flux, j->kernel ? 1.0 / r2 : 0.0, {0.0, 0.0, 0.0, 0.0}};
    square_sum q = {j->hits->flux, f.inv_r2, {ee->y[0], ee->y[1], ee->y[2]}, 0.0};
    if (j->sight.rt) { /* binned is off then */
        if (widened) {
            ts->sighted.count = 0;
            lm_kdtree_radius(j->tree, t->local, r2, list_hit, &ts->sighted);
            k = ts->sighted.count;
            idx = ts->sighted.idx;
            d2 = ts->sighted.d2;
        }
        sighted_sums(j, t, index, tf, ts, idx, d2, k, r2, &f, ee->on ? &q : NULL);
    } else if (j->binned)
        memcpy(f.sum, j->binned + 5 * (size_t)slot, sizeof f.sum);
    else if (widened)
        lm_kdtree_radius(j->tree, t->local, r2, add_flux, &f);
    else
        add_found(&f, idx, d2, k);
    double area = (j->kernel ? 0.5 : 1.0) * LM_PI * r2;
    if (j->boundary_correction && !((double)r2 < *edge_d2)) {
        double nearest;
        area = disc_area_on_surface(&ts->ef, &j->bd, t->local, n, r2, j->kernel, &nearest);
        *edge_d2 = (float)nearest;
    }
    for (int c = 0; c < 3; c++)
        out[c] = f.sum[c] / (area * factor);
    if (ee->on) { /* only when asked: a second walk over the same hits (summed above with the weights) */
        if (j->binned)
            q.sum = j->binned[5 * (size_t)slot + 4];
        else if (!j->sight.rt && widened)
            lm_kdtree_radius(j->tree, t->local, r2, add_square, &q);
        else if (!j->sight.rt)
            for (uint32_t i = 0; i < k; i++)
                add_square(&q, idx[i], d2[i]);
        ee->var = q.sum / (area * factor * area * factor);
        ee->r2_world = (double)r2 * factor;
    }
}


/* E_direct averaged over the texel's parts at their current world positions (seeded by the atlas index,
 * so the same every refresh), added to e. Covered parts (under a box standing on the floor) are left out
 * of the average, not counted dark: the texel's value is what its visible part receives, as the photon
 * estimate, which has no hits under the box either, gives it. The punctual lights' cosine takes the shading
 * normal at the texel's centre (lm_direct_irradiance). */
static void add_direct(const estimate_job *j, const lm_texel *t, uint32_t index, texel_scratch *ts, double e[3],
                       double direct[3])
{
    float local[LM_AIM_DIRECT_PARTS_MAX * LM_AIM_DIRECT_PARTS_MAX][3];
    float share[LM_AIM_DIRECT_PARTS_MAX * LM_AIM_DIRECT_PARTS_MAX];
    int n = lm_texel_parts(j->s, j->a, t, j->direct_parts, local, share);
    if (n == 0) { /* a degenerate triangle: its centroid */
        memcpy(local[0], t->local, sizeof local[0]);
        share[0] = 1.0f;
        n = 1;
    }
    const tri_frame *tf = triangle_frame(j, t->tri, &ts->tri);
    float centre[3], ns[3]; /* the shading normal at the texel's centre, for the punctual lights' cosine */
    lm_texel_world(j->s, t, centre, ns);
    double sum[3] = {0.0, 0.0, 0.0}, seen = 0.0;
    for (int i = 0; i < n; i++) {
        float p[3], d[3];
        lm_v3_store(p, lm_mat4_point(j->world, lm_v3_load(local[i])));
        uint32_t seed = index * (uint32_t)(j->direct_parts * j->direct_parts) + (uint32_t)i;
        if (!lm_direct_irradiance(j->direct, t->surface, p, tf->n_world, ns, j->two_sided, seed, d))
            continue;
        seen += share[i];
        for (int c = 0; c < 3; c++)
            sum[c] += (double)share[i] * d[c];
    }
    for (int c = 0; seen > 0.0 && c < 3; c++)
        direct[c] = sum[c] / seen, e[c] += direct[c];
}

/* L = rho / pi (E_photons + E_direct); rest (NULL: not kept) the same without E_direct (lm_aim.rest); with
 * error (NULL: not kept) the texel's relative standard error and radius (lm_aim.error). */
static void estimate_texel(const estimate_job *j, const lm_texel *t, uint32_t index, uint32_t slot, texel_scratch *ts,
                           float *edge_d2, float out[3], float rest[3], float *error)
{
    float rho[3];
    lm_texel_kd(j->s, t, rho);
    estimate_error ee = {error != NULL, {LUMINANCE[0] * rho[0] / LM_PI, LUMINANCE[1] * rho[1] / LM_PI,
                                         LUMINANCE[2] * rho[2] / LM_PI},
                         0.0, 0.0};
    double e[3], direct[3] = {0.0, 0.0, 0.0};
    photon_irradiance(j, t, index, slot, ts, edge_d2, e, &ee);
    if (j->direct)
        add_direct(j, t, index, ts, e, direct);
    for (int c = 0; c < 3; c++)
        out[c] = (float)(rho[c] / LM_PI * e[c]);
    for (int c = 0; rest && c < 3; c++)
        rest[c] = (float)(rho[c] / LM_PI * (e[c] - direct[c]));
    if (error) {
        double y = ee.y[0] * e[0] + ee.y[1] * e[1] + ee.y[2] * e[2];
        error[0] = y > 0.0 ? (float)(sqrt(ee.var) / y) : 0.0f;
        error[1] = y > 0.0 ? (float)sqrt(ee.r2_world) : 0.0f;
    }
}

static void clear_texels(lm_aim *aim, const lm_atlas *a, uint32_t first, uint32_t end)
{
    for (uint32_t i = first; i < end; i++) {
        const lm_texel *t = &a->texels[aim->texel_list[i]];
        size_t at = (size_t)t->y * (size_t)aim->width + (size_t)t->x;
        memset(aim->rgb + 3 * at, 0, 3 * sizeof(float));
        if (aim->rest)
            memset(aim->rest + 3 * at, 0, 3 * sizeof(float));
        if (aim->error)
            memset(aim->error + 2 * at, 0, 2 * sizeof(float));
    }
}

void lm_aim_scale_surfaces(lm_aim *aim, const lm_atlas *a, const int *surfaces, int count, const float *factor,
                           const float *computed)
{
    for (int j = 0; j < count; j++) {
        int sf = surfaces[j];
        const float *f = factor + 3 * (size_t)sf, *g = computed && aim->rest ? computed + 3 * (size_t)sf : f;
        for (uint32_t i = aim->texel_first[sf]; i < aim->texel_first[sf + 1]; i++) {
            const lm_texel *t = &a->texels[aim->texel_list[i]];
            size_t at = (size_t)t->y * (size_t)aim->width + (size_t)t->x;
            for (int c = 0; c < 3; c++) {
                float *v = aim->rgb + 3 * at + c, *r = aim->rest ? aim->rest + 3 * at + c : NULL;
                if (r) /* the part computed (rgb - rest) by g, the rest by f */
                    *v = (*v - *r) * g[c] + *r * f[c], *r *= f[c];
                else
                    *v *= f[c];
            }
        }
    }
    if (count > 0) {
        lm_atlas_dilated_rgba(a, aim->rgb, aim->dilated);
        if (aim->rest)
            lm_atlas_dilated_rgba(a, aim->rest, aim->rest_dilated);
    }
}

/* ---------- the per-pixel gathers' kernel on the surface ---------- */

/* The kernel's weight (as lm_aim_kernel_coverage sums it: sum_g w_g pi x_g^2 over the Gauss radii x_g) on
 * the surfaces other than texel t's own that the per-pixel gathers take hits from: facing within 60
 * degrees of its normal, within r/2 of its tangent plane and x_g of it (pixel_gather.h). Sampled by
 * COVER_RINGS x COVER_SPOKES rays a radius into the tangent disc, straight down from r/2 above it, at the
 * texel's world position and face normal; a tilted surface counts 1 / cos as much (its area, and hits,
 * above the sample). World units. */
#define COVER_RINGS 3
#define COVER_SPOKES 8
static double kernel_on_others(const lm_rt *rt, const lm_scene *s, const lm_texel *t, int own, double radius,
                               const double *xs, const double *ws)
{
    lm_vec3 vn = lm_scene_tri_normal_world(s, t->tri), vt, vb;
    if (!(lm_length(vn) > 0.0f))
        return 0.0;
    float n[3], tu[3], tv[3], dir[3] = {-vn.x, -vn.y, -vn.z};
    lm_v3_store(n, vn);
    lm_onb(vn, &vt, &vb);
    lm_v3_store(tu, vt), lm_v3_store(tv, vb);
    double sum = 0.0;
    for (int g = 0; g < 3; g++) {
        double took = 0.0;
        for (int i = 0; i < COVER_RINGS; i++)
            for (int j = 0; j < COVER_SPOKES; j++) {
                double rho = xs[g] * sqrt((i + 0.5) / COVER_RINGS), phi = 2.0 * LM_PI * (j + 0.5 * (i & 1)) / COVER_SPOKES;
                float o[3];
                for (int c = 0; c < 3; c++)
                    o[c] = t->pos[c] + (float)(rho * cos(phi)) * tu[c] + (float)(rho * sin(phi)) * tv[c] +
                           (float)(0.5 * radius) * n[c];
                lm_rt_hit h;
                float cosine = 0.0f;
                double d2 = 0.0;
                if (lm_rt_intersect(rt, o, dir, 0.0f, (float)radius, &h) && h.surface >= 0 && h.surface != own) {
                    cosine = h.ng[0] * n[0] + h.ng[1] * n[1] + h.ng[2] * n[2]; /* its front towards X's side */
                    for (int c = 0; c < 3; c++) /* the gathers' distance is in 3D */
                        d2 += ((double)o[c] + h.t * dir[c] - t->pos[c]) * ((double)o[c] + h.t * dir[c] - t->pos[c]);
                }
                if (d2 >= xs[g] * xs[g])
                    cosine = 0.0f;
                if (cosine >= 0.5f) /* a tilted surface holds 1 / cos as much area, and hits, above the sample */
                    took += 1.0 / cosine;
            }
        sum += ws[g] * LM_PI * xs[g] * xs[g] * took / (COVER_RINGS * COVER_SPOKES);
    }
    return sum;
}

lm_status lm_aim_kernel_coverage(const lm_aim *aim, const lm_scene *s, const lm_surfaces *su, const lm_atlas *a,
                                 const lm_rt *rt, float radius, float *out, lm_error *err)
{
    static const double GX[3] = {-0.7745966692414834, 0.0, 0.7745966692414834}, GW[3] = {5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0};
    const double c = 0.2; /* the kernel's clamp (pixel_gather.h) */
    uint32_t edges_max = 1;
    for (int k = 0; k < su->surface_count; k++) {
        uint32_t m = aim->edge_first[k + 1] - aim->edge_first[k];
        edges_max = m > edges_max ? m : edges_max;
    }
    edge_frame ef;
    memset(&ef, 0, sizeof ef);
    ef.uv = malloc(sizeof *ef.uv * 4 * edges_max);
    float *ends = malloc(sizeof *ends * 6 * edges_max);
    if (!ef.uv || !ends) {
        free(ef.uv);
        free(ends);
        return lm_fail(err, LM_ERR_NOMEM, "no memory for the boundary edges of %d surfaces", su->surface_count);
    }
    for (uint32_t i = 0; i < a->texel_count; i++)
        out[i] = 1.0f;
    double xs[3], world = 0.0; /* the Gauss radii in world units, and the whole kernel's weight there */
    for (int g = 0; g < 3; g++)
        xs[g] = (double)radius * (1.0 - 0.5 * c + 0.5 * c * GX[g]), world += GW[g] * LM_PI * xs[g] * xs[g];
    for (int k = 0; k < su->surface_count; k++) {
        linear_map L;
        linear_map_of(s->nodes[su->surfaces[k].node].world, &L);
        boundary bd = {ends, append_edges(aim, s, k, NULL, ends)};
        ef.bd = NULL; /* bd's address is the same for every surface: reproject */
        for (uint32_t i = aim->texel_first[k]; i < aim->texel_first[k + 1]; i++) {
            const lm_texel *t = &a->texels[aim->texel_list[i]];
            double n[3];
            local_face_normal(s, t->tri, n);
            double r = (double)radius / sqrt(area_factor(&L, n)), on = 0.0, full = 0.0, nearest;
            for (int g = 0; g < 3; g++) {
                double x = r * (1.0 - 0.5 * c + 0.5 * c * GX[g]);
                on += GW[g] * disc_area_on_surface(&ef, &bd, t->local, n, x * x, 0, &nearest);
                full += GW[g] * LM_PI * x * x;
            }
            /* where the disc leaves the surface, the gathers also take the hits of the surfaces around that
             * face the same way (a sphere's other facets): their part of the disc counts too (world units) */
            if (rt && on < full * (1.0 - 1e-6))
                on += kernel_on_others(rt, s, t, k, radius, xs, GW) / world * full;
            out[aim->texel_list[i]] = full > 0.0 ? (float)fmin(fmax(on / full, MIN_COVERAGE), 1.0) : 1.0f;
        }
    }
    free(ef.uv);
    free(ends);
    return LM_OK;
}

/* ---------- refreshing ---------- */

/* One surface of a refresh: its hits, their kd-tree and the estimate's inputs. */
typedef struct {
    int surface;
    hit_set hits;
    lm_kdtree tree;
    double *binned;       /* bin_dense_surface's sums, or NULL */
    float *edge_ends;     /* the boundary the estimates' discs are clipped to (boundary) */
    uint32_t edge_count, seams_used;
    linear_map L;
    estimate_job job;
    lm_status rc;
    lm_error err;
} surface_job;

/* A surface is dense when it holds at least this many hits per texel and N (the many lights' floor of a
 * soak: 250,000 hits for 144 texels, whose kd-tree took 30-50 ms to build for 144 lookups). */
#define DENSE_HITS_PER_TEXEL_AND_N 4

/* The grid of a dense surface's texels: cells of the largest smallest radius a side. */
typedef struct {
    float lo[3], h;
    int dim[3];
    uint32_t *first, *list; /* per cell (cells + 1 offsets) into list, texel slots */
} texel_grid;

/* The cell coordinates of p, inside the grid or not. */
static void grid_coords(const texel_grid *g, const float p[3], int c[3])
{
    for (int k = 0; k < 3; k++)
        c[k] = (int)floorf((p[k] - g->lo[k]) / g->h);
}

/* The cell (x, y, z) inside the grid: its index, else -1. */
static long grid_index(const texel_grid *g, int x, int y, int z)
{
    if (x < 0 || y < 0 || z < 0 || x >= g->dim[0] || y >= g->dim[1] || z >= g->dim[2])
        return -1;
    return ((long)z * g->dim[1] + y) * g->dim[0] + x;
}

static long grid_cell(const texel_grid *g, const float p[3])
{
    int c[3];
    grid_coords(g, p, c);
    return grid_index(g, c[0], c[1], c[2]);
}

/* The texels' grid (slots 0 .. n of the surface's list at first); 0 when it would be too large. */
static int grid_build(texel_grid *g, const lm_atlas *a, const uint32_t *list, uint32_t n, const float *r2)
{
    float hi[3] = {-INFINITY, -INFINITY, -INFINITY}, h2 = 0.0f;
    for (int k = 0; k < 3; k++)
        g->lo[k] = INFINITY;
    for (uint32_t i = 0; i < n; i++) {
        const float *p = a->texels[list[i]].local;
        for (int k = 0; k < 3; k++)
            g->lo[k] = fminf(g->lo[k], p[k]), hi[k] = fmaxf(hi[k], p[k]);
        h2 = fmaxf(h2, r2[i]);
    }
    g->h = sqrtf(h2);
    size_t cells = 1;
    for (int k = 0; k < 3; k++) {
        g->dim[k] = g->h > 0.0f ? (int)fminf((hi[k] - g->lo[k]) / g->h, 4096.0f) + 1 : 1;
        cells *= (size_t)g->dim[k];
    }
    if (!(g->h > 0.0f) || cells > 4 * (size_t)n + 64)
        return 0;
    g->first = calloc(cells + 1, sizeof *g->first);
    g->list = malloc(sizeof *g->list * (n ? n : 1));
    if (!g->first || !g->list)
        return 0;
    for (uint32_t i = 0; i < n; i++) {
        long cell = grid_cell(g, a->texels[list[i]].local);
        if (cell >= 0)
            g->first[cell + 1]++;
    }
    for (size_t k = 0; k < cells; k++)
        g->first[k + 1] += g->first[k];
    uint32_t *fill = malloc(sizeof *fill * (cells ? cells : 1));
    if (!fill)
        return 0;
    memcpy(fill, g->first, sizeof *fill * cells);
    for (uint32_t i = 0; i < n; i++) {
        long cell = grid_cell(g, a->texels[list[i]].local);
        if (cell >= 0)
            g->list[fill[cell]++] = i;
    }
    free(fill);
    return 1;
}

/* The estimate where every texel of a surface has N hits within its smallest radius: then each is the sum
 * over every hit within that radius (photon_irradiance's widened case) and needs no kd-tree. One pass over
 * the hits adds each to the texels within reach (a grid of the texels); returns the sums (w Phi, 4, and
 * sum (w Y)^2 with the error estimate) per texel of the surface's list, or NULL when the surface is not
 * dense after all (a texel with fewer than N), or the grid would be too large or no memory. Per texel the
 * same hits as the kd-tree's radius search (d^2 <= r^2 in float), summed in another order. */
static double *bin_dense_surface(const lm_aim *aim, const lm_scene *s, const lm_atlas *a, const surface_job *sj)
{
    uint32_t first = aim->texel_first[sj->surface], n = aim->texel_first[sj->surface + 1] - first;
    const uint32_t *list = aim->texel_list + first;
    uint32_t N = (uint32_t)aim->set.n_nearest;
    if (!aim->set.dense || aim->occluders || n == 0 ||
        (uint64_t)sj->hits.count < (uint64_t)DENSE_HITS_PER_TEXEL_AND_N * N * n)
        return NULL; /* with occluders every hit needs its own rays: the kd-tree */
    float *r2 = malloc(sizeof *r2 * n);
    double *y = malloc(sizeof *y * 3 * n), *out = calloc(5 * (size_t)n, sizeof *out);
    uint32_t *count = calloc(n, sizeof *count);
    texel_grid g = {0};
    int ok = r2 && y && out && count;
    double rmin = smallest_radius(aim, a, sj->hits.count);
    for (uint32_t i = 0; ok && i < n; i++) {
        const lm_texel *t = &a->texels[list[i]];
        double nrm[3];
        float rho[3];
        local_face_normal(s, t->tri, nrm);
        r2[i] = (float)(rmin * rmin / area_factor(&sj->L, nrm));
        lm_texel_kd(s, t, rho);
        for (int c = 0; c < 3; c++) /* the error estimate's luminance weights (estimate_texel) */
            y[3 * i + (uint32_t)c] = LUMINANCE[c] * rho[c] / LM_PI;
    }
    ok = ok && grid_build(&g, a, list, n, r2);
    for (uint32_t h = 0; ok && h < sj->hits.count; h++) {
        const float *p = sj->hits.pos + 3 * (size_t)h;
        const double *phi = sj->hits.flux + 4 * (size_t)h;
        int c[3];
        grid_coords(&g, p, c);
        for (int z = c[2] - 1; z <= c[2] + 1; z++)
            for (int yy = c[1] - 1; yy <= c[1] + 1; yy++)
                for (int x = c[0] - 1; x <= c[0] + 1; x++) {
                    long cell = grid_index(&g, x, yy, z);
                    if (cell < 0)
                        continue;
                    for (uint32_t k = g.first[cell]; k < g.first[cell + 1]; k++) {
                        uint32_t i = g.list[k];
                        const float *q = a->texels[list[i]].local;
                        float dx = p[0] - q[0], dy = p[1] - q[1], dz = p[2] - q[2];
                        float d2 = dx * dx + dy * dy + dz * dz;
                        if (!(d2 <= r2[i]))
                            continue;
                        double w = aim->set.kernel ? fmax(1.0 - d2 * (1.0 / r2[i]), 0.0) : 1.0;
                        double *o = out + 5 * (size_t)i;
                        for (int ch = 0; ch < 4; ch++)
                            o[ch] += w * phi[ch];
                        double v = w * (y[3 * i] * phi[0] + y[3 * i + 1] * phi[1] + y[3 * i + 2] * phi[2]);
                        o[4] += v * v;
                        count[i]++;
                    }
                }
    }
    for (uint32_t i = 0; ok && i < n; i++)
        ok = count[i] >= N; /* else some texel's estimate reaches past its smallest radius */
    free(r2);
    free(y);
    free(count);
    free(g.first);
    free(g.list);
    if (!ok) {
        free(out);
        return NULL;
    }
    return out;
}

/* Gathers the surface's hits and builds their kd-tree (independent of the other surfaces). */
static void prepare_surface(const lm_aim *aim, const lm_scene *s, const lm_surfaces *su, const lm_atlas *a,
                            const lm_photon_store *ps, surface_job *sj)
{
    const lm_surface *sf = &su->surfaces[sj->surface];
    const lm_material *m = &s->materials[sf->material];
    linear_map_of(s->nodes[sf->node].world, &sj->L);
    lm_kdtree_init(&sj->tree);
    sj->rc = gather_hits(aim, ps, s, su, a, sj->surface, &sj->L, &sj->hits, &sj->edge_ends, &sj->edge_count,
                         &sj->seams_used, &sj->err);
    sj->binned = sj->rc == LM_OK ? bin_dense_surface(aim, s, a, sj) : NULL;
    if (sj->rc == LM_OK && !sj->binned)
        sj->rc = lm_kdtree_build(&sj->tree, sj->hits.pos, 3, sj->hits.count, &sj->err);
    uint32_t n = (uint32_t)aim->set.n_nearest < sj->hits.count ? (uint32_t)aim->set.n_nearest : sj->hits.count;
    double rmin = smallest_radius(aim, a, sj->hits.count);
    sj->job = (estimate_job){s, a, &sj->tree, &sj->hits, &sj->L, {sj->edge_ends, sj->edge_count}, n, rmin * rmin,
                             aim->set.boundary_correction, aim->set.kernel, aim->direct, aim->set.direct_parts,
                             s->nodes[sf->node].world, m->double_sided,
                             {aim->occluders, aim->occluder_lift,
                              lm_cover_reach(aim->occluder_cover, aim->occluder_cover_by_surface, sj->surface),
                              aim->set.kernel},
                             sj->binned};
}

static void free_surface(surface_job *sj)
{
    lm_kdtree_free(&sj->tree);
    free(sj->binned);
    free(sj->edge_ends);
    free(sj->hits.pos);
    free(sj->hits.flux);
    free(sj->hits.ends);
}

static int scratch_init(texel_scratch *ts, uint32_t n_max, uint32_t edges_max)
{
    memset(ts, 0, sizeof *ts);
    ts->idx = malloc(sizeof *ts->idx * (n_max ? n_max : 1));
    ts->d2 = malloc(sizeof *ts->d2 * (n_max ? n_max : 1));
    ts->ef.uv = malloc(sizeof *ts->ef.uv * 4 * (edges_max ? edges_max : 1));
    return ts->idx && ts->d2 && ts->ef.uv;
}

static void scratch_free(texel_scratch *ts)
{
    free(ts->idx);
    free(ts->d2);
    free(ts->ef.uv);
    free(ts->sighted.idx);
    free(ts->sighted.d2);
    free(ts->sighted.weight);
}

/* Texels per work unit. A unit's texels run in order on one thread, and the search hints never cross
 * units (for N <= 256 the answers do not depend on them at all), so every texel's value is the same for
 * any thread count. */
#define TEXEL_CHUNK 64

/* Estimates the texels of jobs[0, count) in one parallel region: each surface's texels are shared out
 * in units and threads move on to the next surface without waiting. */
static void write_texels(lm_aim *aim, const surface_job *jobs, int count, uint32_t n_max, uint32_t edges_max,
                         int *nomem)
{
#pragma omp parallel
    {
        texel_scratch ts;
        int ok = scratch_init(&ts, n_max, edges_max);
        if (!ok) {
#pragma omp atomic write
            *nomem = 1;
        }
        for (int j = 0; j < count; j++) {
            const estimate_job *e = &jobs[j].job;
            int64_t first = aim->texel_first[jobs[j].surface], end = aim->texel_first[jobs[j].surface + 1];
            if (e->n == 0 && !e->direct)
                continue;
#pragma omp for schedule(dynamic, TEXEL_CHUNK) nowait
            for (int64_t i = first; i < end; i++) {
                const lm_texel *t = &e->a->texels[aim->texel_list[i]];
                size_t at = (size_t)t->y * (size_t)aim->width + (size_t)t->x;
                if ((i - first) % TEXEL_CHUNK == 0)
                    ts.hint.valid = 0;
                if (ok)
                    estimate_texel(e, t, aim->texel_list[i], (uint32_t)(i - first), &ts, &aim->edge_d2[i],
                                   aim->rgb + 3 * at, aim->rest ? aim->rest + 3 * at : NULL,
                                   aim->error ? aim->error + 2 * at : NULL);
            }
        }
        scratch_free(&ts);
    }
}

/* The surfaces refreshed now (jobs[0, count)) owe their change to those that continue them across a seam
 * and read their hits now (seam_usable): those refreshed in this call already read them (their owed is
 * reset after this), the others are due a refresh (a moved box's hits changed on one face of a floor; the
 * next tile's texels along the seam were left as they were, and a bake differed from a fresh one by up
 * to 3% there). */
static void owe_across_seams(lm_aim *aim, const lm_scene *s, const lm_surfaces *su, const lm_photon_store *ps,
                             const surface_job *jobs, int count)
{
    const lm_seams *sm = &aim->seams;
    for (int j = 0; sm->first && j < count; j++) {
        int k = jobs[j].surface;
        for (uint32_t i = sm->first[k]; i < sm->first[k + 1]; i++)
            if (seam_usable(s, su, sm->list[i], k))
                aim->owed[sm->list[i]] += ps->surfaces[k].delta_f;
    }
}

/* Recomputes the texels of the given surfaces from their current hits (trees built in parallel, then all
 * texels in one parallel pass), owes their change across seams, resets their delta_f and owed and counts
 * them in st. On an error, the surfaces before the failing one are still refreshed. */
static lm_status refresh_surfaces(lm_aim *aim, const lm_scene *s, const lm_surfaces *su, const lm_atlas *a,
                                  lm_photon_store *ps, const int *surfaces, int count, lm_aim_stats *st,
                                  lm_error *err)
{
    surface_job *jobs = calloc((size_t)(count ? count : 1), sizeof *jobs);
    if (!jobs)
        return lm_fail(err, LM_ERR_NOMEM, "AIM: no memory to refresh %d surfaces", count);
#pragma omp parallel for schedule(dynamic, 1)
    for (int j = 0; j < count; j++) {
        jobs[j].surface = surfaces[j];
        prepare_surface(aim, s, su, a, ps, &jobs[j]);
    }
    int ok = 0;
    uint32_t n_max = 0, edges_max = 0;
    for (; ok < count && jobs[ok].rc == LM_OK; ok++) {
        n_max = jobs[ok].job.n > n_max ? jobs[ok].job.n : n_max;
        edges_max = jobs[ok].edge_count > edges_max ? jobs[ok].edge_count : edges_max;
    }
    lm_status rc = ok < count ? jobs[ok].rc : LM_OK;
    if (rc != LM_OK && err)
        *err = jobs[ok].err;
    for (int j = 0; j < ok; j++) {
        int sf = jobs[j].surface;
        if (jobs[j].seams_used != aim->seams_used[sf]) /* another boundary: its distances are not known */
            for (uint32_t i = aim->texel_first[sf]; i < aim->texel_first[sf + 1]; i++)
                aim->edge_d2[i] = -1.0f;
        aim->seams_used[sf] = jobs[j].seams_used;
    }
    int nomem = 0;
    write_texels(aim, jobs, ok, n_max, edges_max, &nomem);
    if (nomem) {
        ok = 0;
        rc = lm_fail(err, LM_ERR_NOMEM, "AIM: no memory for N = %u lookups", n_max);
    }
    owe_across_seams(aim, s, su, ps, jobs, ok);
    for (int j = 0; j < ok; j++) {
        int sf = jobs[j].surface;
        if (jobs[j].hits.count == 0 && !aim->direct)
            clear_texels(aim, a, aim->texel_first[sf], aim->texel_first[sf + 1]);
        lm_photon_store_reset_delta_f(ps, sf);
        aim->owed[sf] = 0.0;
        aim->refresh_count[sf]++;
        if (st) {
            st->surfaces_refreshed++;
            st->texels_written += aim->texel_first[sf + 1] - aim->texel_first[sf];
            st->hits_used += jobs[j].hits.count;
            st->surfaces_binned += jobs[j].binned != NULL;
        }
    }
    for (int j = 0; j < count; j++)
        free_surface(&jobs[j]);
    free(jobs);
    if (ok > 0) {
        lm_atlas_dilated_rgba(a, aim->rgb, aim->dilated);
        if (aim->rest)
            lm_atlas_dilated_rgba(a, aim->rest, aim->rest_dilated);
    }
    return rc;
}

static lm_status check_inputs(const lm_aim *aim, const lm_surfaces *su, const lm_atlas *a,
                              const lm_photon_store *ps, lm_error *err)
{
    if (ps->surface_count != aim->surface_count || su->surface_count != aim->surface_count ||
        a->width != aim->width || a->height != aim->height)
        return lm_fail(err, LM_ERR_INVALID,
                       "AIM: built for %d surfaces and a %dx%d atlas, given %d/%d surfaces and %dx%d", aim->surface_count,
                       aim->width, aim->height, ps->surface_count, su->surface_count, a->width, a->height);
    return check_settings(&aim->set, err);
}

lm_status lm_aim_refresh_surface(lm_aim *aim, const lm_scene *s, const lm_surfaces *su, const lm_atlas *a,
                                 lm_photon_store *ps, int surface, lm_aim_stats *stats, lm_error *err)
{
    lm_status rc = check_inputs(aim, su, a, ps, err);
    if (rc != LM_OK)
        return rc;
    if (surface < 0 || surface >= aim->surface_count)
        return lm_fail(err, LM_ERR_INVALID, "AIM: surface %d out of range (0..%d)", surface, aim->surface_count - 1);
    return refresh_surfaces(aim, s, su, a, ps, &surface, 1, stats, err);
}

/* Mean luminance of the stored hits (0 when there are none): the unit of the refresh threshold. */
static double mean_hit_energy(const lm_photon_store *ps)
{
    double sum = 0.0;
    uint64_t n = 0;
    for (int i = 0; i < ps->surface_count; i++) {
        n += ps->surfaces[i].count;
        sum += ps->surfaces[i].energy;
    }
    return n ? sum / (double)n : 0.0;
}

typedef struct {
    double key; /* delta_f / area */
    int surface;
} candidate;

static int by_priority(const void *pa, const void *pb)
{
    const candidate *a = pa, *b = pb;
    if (a->key != b->key)
        return a->key < b->key ? 1 : -1;
    return (a->surface > b->surface) - (a->surface < b->surface);
}

static lm_status run_schedule(lm_aim *aim, const lm_scene *s, const lm_surfaces *su, const lm_atlas *a,
                              lm_photon_store *ps, int budget, int everything, lm_aim_stats *st, lm_error *err)
{
    double mean = mean_hit_energy(ps), threshold = everything ? -1.0 : aim->set.delta_threshold * mean;
    aim->mean_hit_energy = (float)mean;
    candidate *c = malloc(sizeof *c * (size_t)(aim->surface_count ? aim->surface_count : 1));
    if (!c)
        return lm_fail(err, LM_ERR_NOMEM, "AIM: no memory to schedule %d surfaces", aim->surface_count);
    int count = 0;
    for (int i = 0; i < aim->surface_count; i++) {
        double df = ps->surfaces[i].delta_f + aim->owed[i];
        if (everything || (df > threshold && df > 0.0))
            c[count++] = (candidate){df / fmax((double)su->surfaces[i].area, 1e-12), i};
    }
    qsort(c, (size_t)count, sizeof *c, by_priority);
    int todo = budget < 0 || budget > count ? count : budget;
    uint64_t hits = 0;
    for (int i = 0; i < todo && budget >= 0 && aim->set.max_hits; i++) {
        hits += ps->surfaces[c[i].surface].count;
        if (i > 0 && hits > aim->set.max_hits)
            todo = i; /* never past it, never skipping it: the next refresh starts with it */
    }
    int *chosen = malloc(sizeof *chosen * (size_t)(todo ? todo : 1));
    lm_status rc = chosen ? LM_OK : lm_fail(err, LM_ERR_NOMEM, "AIM: no memory to schedule %d surfaces", todo);
    for (int i = 0; chosen && i < todo; i++)
        chosen[i] = c[i].surface;
    if (rc == LM_OK)
        rc = refresh_surfaces(aim, s, su, a, ps, chosen, todo, st, err);
    st->surfaces_pending = count - todo;
    free(chosen);
    free(c);
    return rc;
}

/* One scheduled refresh: up to `budget` changed surfaces (budget < 0: no limit), or every one; or, with a
 * list, the `count` surfaces it names. */
static lm_status refresh(lm_aim *aim, const lm_scene *s, const lm_surfaces *su, const lm_atlas *a,
                         lm_photon_store *ps, int budget, int all, const int *list, int count, lm_aim_stats *stats,
                         lm_error *err)
{
    lm_aim_stats local;
    lm_aim_stats *st = stats ? stats : &local;
    memset(st, 0, sizeof *st);
    double t0 = lm_now();
    lm_status rc = check_inputs(aim, su, a, ps, err);
    if (rc == LM_OK)
        rc = list ? refresh_surfaces(aim, s, su, a, ps, list, count, st, err)
                  : run_schedule(aim, s, su, a, ps, budget, all, st, err);
    int owed = 0;
    for (int k = 0; budget < 0 && !all && !list && k < aim->surface_count; k++)
        owed |= aim->owed[k] > 0.0;
    if (rc == LM_OK && owed) /* without a budget, what the refreshed surfaces owe across seams too (its
                              * counts add to st's; nothing is left pending without a budget) */
        rc = run_schedule(aim, s, su, a, ps, budget, 0, st, err);
    st->seconds = lm_now() - t0;
    return rc;
}

void lm_aim_stats_add(lm_aim_stats *to, const lm_aim_stats *from)
{
    to->surfaces_refreshed += from->surfaces_refreshed;
    to->surfaces_pending = from->surfaces_pending;
    to->texels_written += from->texels_written;
    to->hits_used += from->hits_used;
    to->surfaces_binned += from->surfaces_binned;
    to->seconds += from->seconds;
}

lm_status lm_aim_refresh_listed(lm_aim *aim, const lm_scene *s, const lm_surfaces *su, const lm_atlas *a,
                                lm_photon_store *ps, const int *surfaces, int count, lm_aim_stats *stats,
                                lm_error *err)
{
    return refresh(aim, s, su, a, ps, count, 0, surfaces, count, stats, err);
}

lm_status lm_aim_refresh(lm_aim *aim, const lm_scene *s, const lm_surfaces *su, const lm_atlas *a,
                         lm_photon_store *ps, int budget, lm_aim_stats *stats, lm_error *err)
{
    return refresh(aim, s, su, a, ps, budget, 0, NULL, 0, stats, err);
}

lm_status lm_aim_refresh_all(lm_aim *aim, const lm_scene *s, const lm_surfaces *su, const lm_atlas *a,
                             lm_photon_store *ps, lm_aim_stats *stats, lm_error *err)
{
    return refresh(aim, s, su, a, ps, -1, 1, NULL, 0, stats, err);
}
