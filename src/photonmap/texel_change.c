/* Texel-level change estimates for the IIM's regathering order (texel_change.h). */
#include "texel_change.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../core/top_k.h"
#include "../core/vecmath.h"
#include "delta_i.h"

#define BLOCK 4 /* atlas texels per side of an AIM emitter block */
#define LOCAL 4.0 /* a texel goes ahead only when its change passes this many times the atlas's median */
#define TYPICAL_SAMPLES 8192 /* texels the median is taken over (every stride-th), bounding its cost */

static const float *aim_at(const lm_atlas *a, const float *aim_rgb, uint32_t i)
{
    return aim_rgb + 3 * ((size_t)a->texels[i].y * a->width + a->texels[i].x);
}

/* pi x the AIM's area-weighted mean radiance: the scene's mean irradiance, the unit of the estimates. */
static double mean_irradiance(const lm_atlas *a, const float *aim_rgb)
{
    double sum = 0.0, area = 0.0;
    for (uint32_t i = 0; i < a->texel_count; i++) {
        sum += lm_luminance(aim_at(a, aim_rgb, i)) * a->texels[i].area;
        area += a->texels[i].area;
    }
    return area > 0.0 ? M_PI * sum / area : 0.0;
}

/* Per node, the sphere around its vertices in its local space (centre of their box, radius to the
 * farthest): its place in the world follows the node's matrix. */
static void node_spheres(lm_texel_change *tc, const lm_scene *s)
{
    float *lo = malloc(sizeof(float) * 6 * (size_t)(s->node_count ? s->node_count : 1));
    if (!lo) {
        for (int n = 0; n < s->node_count; n++)
            tc->node_sphere[4 * n + 3] = -1.0f;
        return;
    }
    for (int n = 0; n < s->node_count; n++)
        for (int k = 0; k < 3; k++)
            lo[6 * n + k] = INFINITY, lo[6 * n + 3 + k] = -INFINITY;
    for (uint32_t v = 0; v < s->vertex_count; v++)
        for (int k = 0; k < 3; k++) {
            float *b = lo + 6 * (size_t)s->vertex_node[v], x = s->positions[3 * (size_t)v + k];
            b[k] = fminf(b[k], x), b[3 + k] = fmaxf(b[3 + k], x);
        }
    for (int n = 0; n < s->node_count; n++) {
        float *sp = tc->node_sphere + 4 * n, *b = lo + 6 * n;
        sp[3] = -1.0f;
        if (!(b[0] <= b[3]))
            continue;
        for (int k = 0; k < 3; k++)
            sp[k] = 0.5f * (b[k] + b[3 + k]);
    }
    for (uint32_t v = 0; v < s->vertex_count; v++) {
        float *sp = tc->node_sphere + 4 * (size_t)s->vertex_node[v];
        const float *x = s->positions + 3 * (size_t)v;
        sp[3] = fmaxf(sp[3], lm_length(lm_sub(lm_v3_load(x), lm_v3_load(sp))));
    }
    free(lo);
}

lm_status lm_texel_change_init(lm_texel_change *tc, const lm_scene *s, const lm_atlas *a, const float *aim_rgb,
                               float threshold, lm_error *err)
{
    memset(tc, 0, sizeof *tc);
    size_t T = a->texel_count ? a->texel_count : 1, N = (size_t)(s->node_count ? s->node_count : 1);
    tc->texel_count = a->texel_count;
    tc->threshold = threshold;
    tc->node_count = s->node_count;
    tc->change = calloc(T, sizeof *tc->change);
    tc->lit = calloc(T, sizeof *tc->lit);
    tc->unsettled = calloc(T, sizeof *tc->unsettled);
    tc->doubt = calloc(T, sizeof *tc->doubt);
    tc->pos = malloc(3 * T * sizeof *tc->pos);
    tc->nrm = malloc(3 * T * sizeof *tc->nrm);
    tc->aim_seen = malloc(3 * T * sizeof *tc->aim_seen);
    tc->texel_node = malloc(T * sizeof *tc->texel_node);
    tc->node_world = malloc(16 * N * sizeof *tc->node_world);
    tc->node_sphere = malloc(4 * N * sizeof *tc->node_sphere);
    if (!tc->change || !tc->lit || !tc->unsettled || !tc->doubt || !tc->pos || !tc->nrm || !tc->aim_seen ||
        !tc->texel_node || !tc->node_world || !tc->node_sphere) {
        lm_texel_change_free(tc);
        return lm_fail(err, LM_ERR_NOMEM, "IIM: no memory for the texels' change estimates (%u texels)",
                       a->texel_count);
    }
    for (uint32_t i = 0; i < a->texel_count; i++) {
        lm_texel_world(s, &a->texels[i], tc->pos + 3 * (size_t)i, tc->nrm + 3 * (size_t)i);
        memcpy(tc->aim_seen + 3 * (size_t)i, aim_at(a, aim_rgb, i), 3 * sizeof(float));
        tc->texel_node[i] = (int)s->tri_node[a->texels[i].tri];
    }
    for (int n = 0; n < s->node_count; n++)
        memcpy(tc->node_world + 16 * n, s->nodes[n].world, 16 * sizeof(float));
    node_spheres(tc, s);
    tc->mean_e = mean_irradiance(a, aim_rgb);
    return LM_OK;
}

void lm_texel_change_free(lm_texel_change *tc)
{
    free(tc->change);
    free(tc->lit);
    free(tc->unsettled);
    free(tc->doubt);
    free(tc->pos);
    free(tc->nrm);
    free(tc->aim_seen);
    free(tc->texel_node);
    free(tc->node_world);
    free(tc->node_sphere);
    memset(tc, 0, sizeof *tc);
}

/* The node's sphere in the world under matrix m: centre and radius (times the largest axis scale). */
static void world_sphere(const float *sp, const float m[16], float out[4])
{
    lm_v3_store(out, lm_mat4_point(m, lm_v3_load(sp)));
    float scale = 0.0f;
    for (int c = 0; c < 3; c++)
        scale = fmaxf(scale, sqrtf(m[4 * c] * m[4 * c] + m[4 * c + 1] * m[4 * c + 1] + m[4 * c + 2] * m[4 * c + 2]));
    out[3] = sp[3] * scale;
}

/* Form factor from a point (position p, normal n) to a sphere, widened near the horizon (header). */
static float sphere_factor(const float *p, const float *n, const float sph[4])
{
    lm_vec3 d = lm_sub(lm_v3_load(sph), lm_v3_load(p));
    float dist = lm_length(d);
    if (dist <= sph[3])
        return 1.0f;
    float sin_a = sph[3] / dist, c = lm_dot(lm_v3_load(n), d) / dist + sin_a;
    return fminf(1.0f, sin_a * sin_a) * fminf(1.0f, fmaxf(0.0f, c));
}

float lm_texel_change_node_near(const lm_texel_change *tc, const lm_scene *s, uint32_t texel)
{
    float most = 0.0f, at[4];
    for (int n = 0; n < tc->node_count && n < s->node_count; n++) {
        if (tc->node_sphere[4 * n + 3] < 0.0f || tc->texel_node[texel] == n || !lm_node_moves(&s->nodes[n]))
            continue;
        world_sphere(tc->node_sphere + 4 * n, tc->node_world + 16 * n, at);
        most = fmaxf(most, sphere_factor(tc->pos + 3 * (size_t)texel, tc->nrm + 3 * (size_t)texel, at));
    }
    return most;
}

/* Node n moved from matrix old to its current one: every other texel sees its sphere at both places;
 * its own texels' hemispheres shifted with them (their positions and normals brought up to date). */
static void add_moved_node(lm_texel_change *tc, const lm_scene *s, const lm_atlas *a, int n, const float old[16],
                           int settled)
{
    float was[4], now[4];
    world_sphere(tc->node_sphere + 4 * n, old, was);
    world_sphere(tc->node_sphere + 4 * n, s->nodes[n].world, now);
    /* the share of the sphere's disc that moved off itself: what a texel sees changes by about that part
     * of the sphere's form factor (a small step changes little even right under the object) */
    float step = lm_length(lm_sub(lm_v3_load(now), lm_v3_load(was)));
    float moved = fminf(1.0f, step / fmaxf(now[3], 1e-20f) + fabsf(now[3] - was[3]) / fmaxf(now[3], 1e-20f));
    float *unsettled = settled ? NULL : tc->unsettled;
    tc->any_unsettled |= !settled;
    for (uint32_t i = 0; i < a->texel_count; i++) {
        float *p = tc->pos + 3 * (size_t)i, *nr = tc->nrm + 3 * (size_t)i;
        if (tc->texel_node[i] != n) {
            float c = moved * (sphere_factor(p, nr, was) + sphere_factor(p, nr, now));
            tc->change[i] += c;
            if (unsettled)
                unsettled[i] += c;
            continue;
        }
        float q[3], m[3];
        lm_texel_world(s, &a->texels[i], q, m);
        float dx = lm_length(lm_sub(lm_v3_load(q), lm_v3_load(p)));
        float turn = 1.0f - lm_dot(lm_v3_load(m), lm_v3_load(nr));
        float c = fminf(1.0f, dx / fmaxf(now[3], 1e-20f) + turn);
        tc->change[i] += c;
        if (unsettled)
            unsettled[i] += c;
        memcpy(p, q, sizeof q);
        memcpy(nr, m, sizeof m);
    }
}

int lm_texel_change_moved(lm_texel_change *tc, const lm_scene *s, const lm_atlas *a, int settled)
{
    int moved = 0;
    for (int n = 0; n < s->node_count && n < tc->node_count; n++) {
        float *seen = tc->node_world + 16 * n;
        if (!memcmp(seen, s->nodes[n].world, 16 * sizeof(float)))
            continue;
        if (tc->node_sphere[4 * n + 3] >= 0.0f)
            add_moved_node(tc, s, a, n, seen, settled);
        memcpy(seen, s->nodes[n].world, 16 * sizeof(float));
        moved++;
    }
    return moved;
}

/* An emitter of changed radiance: area-weighted centre and normal, area, and summed dL x area (signed:
 * the photon noise of a refreshed AIM cancels within a block and over time, a moved shadow does not). */
typedef struct {
    double c[3], n[3], area, power;
    int surface;
} emitter;

static void emitter_add(emitter *e, const float *p, const float *n, double area, double dl, int surface)
{
    for (int k = 0; k < 3; k++)
        e->c[k] += p[k] * area, e->n[k] += n[k] * area;
    e->area += area;
    e->power += dl * area;
    e->surface = surface;
}

/* The emitters of the refreshed surfaces' changed texels since aim_seen, one per block or (coarse) one per
 * surface. Returns how many (list sized for the worst case by the caller; slot: `cells` of scratch). */
static int gather_emitters(lm_texel_change *tc, const lm_atlas *a, const float *aim_rgb, const uint8_t *refreshed,
                           int coarse, emitter *list, int *slot, size_t cells)
{
    int count = 0;
    for (size_t k = 0; k < cells; k++)
        slot[k] = -1;
    int bw = (a->width + BLOCK - 1) / BLOCK;
    for (uint32_t i = 0; i < a->texel_count; i++) {
        const lm_texel *t = &a->texels[i];
        if (!refreshed[t->surface])
            continue;
        double dl = lm_luminance(aim_at(a, aim_rgb, i)) - lm_luminance(tc->aim_seen + 3 * (size_t)i);
        if (dl == 0.0)
            continue;
        /* a block is keyed by its cell and surface; slot[] remembers the emitter of the last key seen
         * per cell (texels of one surface in a block are consecutive enough in atlas order for this) */
        int cell = coarse ? t->surface : (t->y / BLOCK) * bw + t->x / BLOCK;
        int e = slot[cell];
        if (e < 0 || list[e].surface != t->surface) {
            e = slot[cell] = count++;
            memset(&list[e], 0, sizeof list[e]);
        }
        emitter_add(&list[e], tc->pos + 3 * (size_t)i, tc->nrm + 3 * (size_t)i, t->area, dl, t->surface);
    }
    return count;
}

/* Which surfaces see emitter surface b (lm_delta_i_sees), asked once per surface while b stays the same. */
typedef struct {
    const lm_iim_sched *sched;
    const lm_scene *scene;
    const lm_rt *rt;
    int b;
    int8_t *seen; /* per surface: -1 not asked yet, else whether it sees b */
} viewers;

static int sees_emitter(viewers *v, const lm_atlas *a, int surface, int b)
{
    if (v->b != b) {
        memset(v->seen, -1, (size_t)(a->surface_count ? a->surface_count : 1));
        v->b = b;
    }
    if (v->seen[surface] < 0)
        v->seen[surface] = (int8_t)lm_delta_i_sees(v->sched, v->scene, a, v->rt, surface, b);
    return v->seen[surface];
}

/* dE / E_mean, signed, at every texel of the surfaces that see the emitter's: dL A cos_t cos_e / (d^2 +
 * A / pi). */
static void add_emitter(lm_texel_change *tc, const lm_atlas *a, const emitter *e, double inv_e, viewers *v)
{
    float c[3], n[3];
    double nl = sqrt(e->n[0] * e->n[0] + e->n[1] * e->n[1] + e->n[2] * e->n[2]);
    for (int k = 0; k < 3; k++)
        c[k] = (float)(e->c[k] / e->area), n[k] = nl > 0.0 ? (float)(e->n[k] / nl) : 0.0f;
    /* a curved emitter's normals cancel: nl / area below 1 widens it towards facing every way */
    float spread = (float)(1.0 - nl / e->area);
    float scale = (float)(e->power * inv_e), disc = (float)(e->area / M_PI);
    for (uint32_t i = 0; i < a->texel_count; i++) {
        if (a->texels[i].surface == e->surface)
            continue;
        const float *p = tc->pos + 3 * (size_t)i, *np = tc->nrm + 3 * (size_t)i;
        lm_vec3 d = lm_sub(lm_v3_load(c), lm_v3_load(p));
        float d2 = lm_dot(d, d), dl = sqrtf(d2);
        if (!(dl > 0.0f))
            continue;
        float ct = lm_dot(lm_v3_load(np), d) / dl;
        float ce = -lm_dot(lm_v3_load(n), d) / dl;
        ce = fmaxf(ce, 0.0f) + spread;
        if (ct <= 0.0f || ce <= 0.0f || !sees_emitter(v, a, a->texels[i].surface, e->surface))
            continue;
        tc->lit[i] += scale * ct * fminf(ce, 1.0f) / (d2 + disc);
    }
}

void lm_texel_change_aim(lm_texel_change *tc, const lm_iim_sched *sched, const lm_scene *s, const lm_atlas *a,
                         const lm_rt *rt, const float *aim_rgb, const uint8_t *refreshed)
{
    int bw = (a->width + BLOCK - 1) / BLOCK, bh = (a->height + BLOCK - 1) / BLOCK;
    size_t cells = (size_t)bw * bh > (size_t)a->surface_count ? (size_t)bw * bh : (size_t)a->surface_count;
    emitter *list = malloc(sizeof *list * (a->texel_count ? a->texel_count : 1));
    int *slot = malloc(sizeof *slot * (cells ? cells : 1));
    double e_mean = mean_irradiance(a, aim_rgb);
    tc->mean_e = e_mean > 0.0 ? e_mean : tc->mean_e;
    viewers v = {sched, s, rt, -1, malloc((size_t)(a->surface_count ? a->surface_count : 1))};
    if (list && slot && v.seen && tc->mean_e > 0.0) { /* else (no memory, no light) the surface order alone */
        /* blocks first; the same texels coarsened to surfaces when that is too much work */
        int count = gather_emitters(tc, a, aim_rgb, refreshed, 0, list, slot, cells);
        if ((double)count * a->texel_count > LM_TEXEL_CHANGE_WORK)
            count = gather_emitters(tc, a, aim_rgb, refreshed, 1, list, slot, cells);
        if ((double)count * a->texel_count <= LM_TEXEL_CHANGE_WORK)
            for (int e = 0; e < count; e++)
                add_emitter(tc, a, &list[e], 1.0 / tc->mean_e, &v);
    }
    for (uint32_t i = 0; i < a->texel_count; i++) /* what was seen: the changes are counted */
        if (refreshed[a->texels[i].surface])
            memcpy(tc->aim_seen + 3 * (size_t)i, aim_at(a, aim_rgb, i), 3 * sizeof(float));
    free(v.seen);
    free(list);
    free(slot);
}

/* The k-th smallest of v[0..n) (k < n), v reordered (quickselect, Hoare's partition): linear, where
 * core/stats.h's lm_quantile sorts, and this runs at every update's pick. */
static float kth_smallest(float *v, uint32_t n, uint32_t k)
{
    uint32_t lo = 0, hi = n - 1;
    while (lo < hi) {
        float pivot = v[lo + (hi - lo) / 2];
        uint32_t i = lo, j = hi;
        while (i <= j) {
            while (v[i] < pivot)
                i++;
            while (v[j] > pivot)
                j--;
            if (i <= j) {
                float t = v[i];
                v[i] = v[j], v[j] = t;
                i++;
                if (j == 0)
                    break;
                j--;
            }
        }
        if (k <= j)
            hi = j;
        else if (k >= i)
            lo = i;
        else
            return v[k];
    }
    return v[k];
}

/* The median change of the texels not on surfaces switched off, over at most TYPICAL_SAMPLES of them (every
 * stride-th, so the same texels each time). What reached every texel alike (a light dimmed) moves it; a
 * local change (a node moved) leaves most texels, and with them the median, at about nothing. */
static float typical_change(const lm_texel_change *tc, const lm_atlas *a, const uint8_t *off)
{
    uint32_t stride = tc->texel_count / TYPICAL_SAMPLES + 1, n = 0;
    float *v = malloc(sizeof *v * (tc->texel_count / stride + 1));
    if (!v)
        return 0.0f; /* no bar above the threshold: every changed texel may go ahead */
    for (uint32_t i = 0; i < tc->texel_count; i += stride)
        if (!off[a->texels[i].surface])
            v[n++] = tc->change[i] + fabsf(tc->lit[i]);
    float m = n ? kth_smallest(v, n, n / 2) : 0.0f;
    free(v);
    return m;
}

void lm_texel_change_doubt(lm_texel_change *tc, const float *doubt)
{
    for (uint32_t i = 0; i < tc->texel_count; i++) /* two standard errors: how far off it may well be */
        tc->doubt[i] += isfinite(doubt[i]) && doubt[i] > 0.0f ? 2.0f * doubt[i] : 0.0f;
}

uint32_t lm_texel_change_pick(lm_texel_change *tc, const lm_atlas *a, const uint8_t *off, uint32_t budget,
                              int all, uint32_t *out)
{
    uint32_t k = budget < tc->texel_count ? budget : tc->texel_count, n = 0;
    lm_ranked *h = k ? malloc(sizeof *h * k) : NULL;
    if (!h)
        return 0;
    /* a change that reached everything alike (a light dimmed) is the surfaces' order's to follow: a texel
     * goes ahead only when it changed more than LOCAL times the atlas's median (with 2, texels re-flagged as
     * the AIMs caught up over many updates took the budget, and the Cornell box's halved light was not
     * within 5% in 120 updates; 101 with whole surfaces only, 102 with 4). The median, not the mean: a
     * moved cube's own faces and the floor under it lifted the mean's bar over the walls beside its new
     * place, whose light changed by 17%, and they waited 11 updates for their surfaces' turn. */
    float floor = all ? tc->threshold : fmaxf(tc->threshold, (float)LOCAL * typical_change(tc, a, off));
    /* a doubted factor is this texel's own error, not a change that reached everything alike: it goes
     * ahead past the threshold alone */
    for (uint32_t i = 0; i < tc->texel_count; i++) {
        float p = lm_texel_change_of(tc, i);
        if ((p - tc->doubt[i] > floor || tc->doubt[i] > tc->threshold) && p > tc->threshold &&
            !off[a->texels[i].surface])
            lm_top_k_offer(h, &n, k, (lm_ranked){p, i});
    }
    qsort(h, n, sizeof *h, lm_ranked_order); /* most changed first */
    for (uint32_t j = 0; j < n; j++) {
        out[j] = h[j].id;
        tc->change[h[j].id] = tc->lit[h[j].id] = tc->doubt[h[j].id] = 0.0f;
    }
    free(h);
    return n;
}

uint32_t lm_texel_change_waiting(const lm_texel_change *tc, const lm_atlas *a, const uint8_t *off, uint32_t *out)
{
    uint32_t n = 0;
    for (uint32_t i = 0; i < tc->texel_count; i++)
        if (lm_texel_change_of(tc, i) > tc->threshold && !off[a->texels[i].surface])
            out[n++] = i;
    return n;
}

void lm_texel_change_gathered(lm_texel_change *tc, const uint32_t *texels, uint32_t count)
{
    for (uint32_t j = 0; j < count; j++)
        tc->change[texels[j]] = tc->lit[texels[j]] = tc->doubt[texels[j]] = 0.0f;
}

float lm_texel_change_of(const lm_texel_change *tc, uint32_t texel)
{
    return tc->change[texel] + fabsf(tc->lit[texel]) + tc->doubt[texel];
}

uint32_t lm_texel_change_settle(lm_texel_change *tc)
{
    uint32_t n = 0;
    for (uint32_t i = 0; tc->any_unsettled && i < tc->texel_count; i++)
        if (tc->unsettled[i] > 0.0f)
            tc->change[i] += tc->unsettled[i], tc->unsettled[i] = 0.0f, n++;
    tc->any_unsettled = 0;
    return n;
}

void lm_texel_change_save(const lm_texel_change *tc, float *saved)
{
    memcpy(saved, tc->change, sizeof *saved * tc->texel_count);
    memcpy(saved + tc->texel_count, tc->lit, sizeof *saved * tc->texel_count);
    memcpy(saved + 2 * (size_t)tc->texel_count, tc->unsettled, sizeof *saved * tc->texel_count);
    memcpy(saved + 3 * (size_t)tc->texel_count, tc->doubt, sizeof *saved * tc->texel_count);
}

void lm_texel_change_restore(lm_texel_change *tc, const float *saved)
{
    memcpy(tc->change, saved, sizeof *saved * tc->texel_count);
    memcpy(tc->lit, saved + tc->texel_count, sizeof *saved * tc->texel_count);
    memcpy(tc->unsettled, saved + 2 * (size_t)tc->texel_count, sizeof *saved * tc->texel_count);
    memcpy(tc->doubt, saved + 3 * (size_t)tc->texel_count, sizeof *saved * tc->texel_count);
    tc->any_unsettled = 1;
}

void lm_texel_change_scale(lm_texel_change *tc, const lm_atlas *a, const float *factor)
{
    for (uint32_t i = 0; i < tc->texel_count; i++)
        for (int c = 0; c < 3; c++)
            tc->aim_seen[3 * (size_t)i + c] *= factor[3 * a->texels[i].surface + c];
}

void lm_texel_change_first_guess(lm_texel_change *tc, const float *factor, const float *add)
{
    for (uint32_t i = 0; i < tc->texel_count; i++) {
        float c = 0.0f;
        for (int k = 0; k < 3; k++)
            c = fmaxf(c, fabsf(factor[3 * (size_t)i + k] - 1.0f) +
                             (tc->mean_e > 0.0 ? fabsf(add[3 * (size_t)i + k]) / (float)tc->mean_e : 0.0f));
        tc->change[i] += isfinite(c) ? c : 0.0f;
    }
}
