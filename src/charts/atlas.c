/* lm_atlas_build: charts (unwrapped or from the file's TEXCOORD_1), packing, then the texel table. */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/log.h"
#include "../core/memory.h"
#include "../core/timing.h"
#include "../core/vecmath.h"
#include "charts_internal.h"

void lm_atlas_options_default(lm_atlas_options *o)
{
    o->texel_size = 0.0f;
    o->target_texels = LM_ATLAS_DEFAULT_TEXELS;
    o->gutter = 0;
    o->use_file_uv1 = 0;
    o->max_size = 8192;
    o->wall_texels = 0;
    o->bend_deg = 0.0f;
    o->need = o->sky = NULL;
    o->open_need = 0.0f;
}

float lm_atlas_default_texel_size(const lm_scene *s, const lm_surfaces *su, int target)
{
    double area = 0.0;
    for (int i = 0; i < su->surface_count; i++)
        area += su->surfaces[i].area;
    if (area > 0.0 && isfinite(area))
        return (float)sqrt(area / (target > 0 ? target : LM_ATLAS_DEFAULT_TEXELS));
    float size = 0.0f;
    float *pos = s && s->vertex_count ? lmc_world_positions(s, &size) : NULL;
    free(pos);
    return size > 0.0f ? size / 512.0f : 1.0f;
}

/* One chart per surface: its TEXCOORD_1 coordinates, shifted to the origin and scaled so that uv area
 * matches world area (texel density then follows texel_size like unwrapped charts). */
static lm_status uv1_chart(const lm_scene *s, const lm_surface *f, int sid, const float *pos, lmc_chart *ch,
                           double *tri_uv, lm_error *err)
{
    double lo[2] = {DBL_MAX, DBL_MAX}, uv_area = 0.0, world = 0.0, n[3];
    for (uint32_t i = 0; i < f->tri_count; i++) {
        const uint32_t *v = s->tris + 3 * (size_t)f->tris[i];
        const float *a = s->uv1 + 2 * (size_t)v[0], *b = s->uv1 + 2 * (size_t)v[1], *c = s->uv1 + 2 * (size_t)v[2];
        uv_area += 0.5 * fabs(((double)b[0] - a[0]) * ((double)c[1] - a[1]) - ((double)c[0] - a[0]) * ((double)b[1] - a[1]));
        world += lmc_tri_area(s, pos, f->tris[i], n);
        for (int k = 0; k < 3; k++)
            for (int x = 0; x < 2; x++)
                lo[x] = fmin(lo[x], s->uv1[2 * (size_t)v[k] + x]);
    }
    if (!(uv_area > 0.0) || !isfinite(uv_area))
        return lm_fail(err, LM_ERR_INVALID, "charts: node '%s' has no usable TEXCOORD_1 area (surface %d)",
                       s->nodes[f->node].name, sid);
    double scale = sqrt(world / uv_area);
    ch->surface = sid;
    ch->tri_count = f->tri_count;
    ch->tris = malloc(((size_t)f->tri_count + 1) * sizeof *ch->tris);
    if (!ch->tris)
        return lm_fail(err, LM_ERR_NOMEM, "charts: out of memory");
    memcpy(ch->tris, f->tris, (size_t)f->tri_count * sizeof *ch->tris);
    ch->ext[0] = ch->ext[1] = 0.0;
    for (uint32_t i = 0; i < f->tri_count; i++)
        for (int k = 0; k < 3; k++)
            for (int x = 0; x < 2; x++) {
                uint32_t v = s->tris[3 * (size_t)f->tris[i] + k];
                double u = ((double)s->uv1[2 * (size_t)v + x] - lo[x]) * scale;
                tri_uv[6 * (size_t)f->tris[i] + 2 * k + x] = u;
                ch->ext[x] = fmax(ch->ext[x], u);
            }
    return LM_OK;
}

lm_status lmc_charts_from_uv1(const lm_scene *s, const lm_surfaces *su, const float *pos, lmc_charts *out,
                              lm_error *err)
{
    memset(out, 0, sizeof *out);
    if (!s->uv1)
        return lm_fail(err, LM_ERR_INVALID, "charts: use_file_uv1 is set but '%s' has no TEXCOORD_1", s->path);
    out->tri_uv = malloc(6 * (size_t)s->tri_count * sizeof *out->tri_uv + 1);
    out->charts = calloc((size_t)su->surface_count + 1, sizeof *out->charts);
    if (!out->tri_uv || !out->charts) {
        lmc_charts_free(out);
        return lm_fail(err, LM_ERR_NOMEM, "charts: out of memory");
    }
    for (int i = 0; i < su->surface_count; i++) {
        lm_status st = uv1_chart(s, &su->surfaces[i], i, pos, &out->charts[i], out->tri_uv, err);
        out->count += st == LM_OK;
        if (st != LM_OK) {
            lmc_charts_free(out);
            return st;
        }
    }
    return LM_OK;
}

static lm_status check_options(const lm_scene *s, const lm_surfaces *su, const lm_atlas_options *o, lm_error *err)
{
    lm_status st = lmc_check_scene(s, err);
    if (st != LM_OK)
        return st;
    if (!su || (su->surface_count && (!su->surfaces || !su->tri_surface || !su->tri_adj || !su->vertex_weld)))
        return lm_fail(err, LM_ERR_INVALID, "charts: surfaces missing (call lm_surfaces_build first)");
    if (!isfinite(o->texel_size) || o->gutter < 0 || o->gutter > 64)
        return lm_fail(err, LM_ERR_INVALID, "charts: texel_size %g must be finite and gutter %d in [0, 64]",
                       (double)o->texel_size, o->gutter);
    if (o->target_texels < 0)
        return lm_fail(err, LM_ERR_INVALID, "charts: target_texels %d must be >= 0 (0: %d)", o->target_texels,
                       LM_ATLAS_DEFAULT_TEXELS);
    if (o->wall_texels < 0 || o->wall_texels > 65536)
        return lm_fail(err, LM_ERR_INVALID, "charts: wall_texels %d must be in [0, 65536]", o->wall_texels);
    if (!(o->bend_deg >= 0.0f && o->bend_deg <= 180.0f))
        return lm_fail(err, LM_ERR_INVALID, "charts: bend_deg %g must be in [0, 180]", (double)o->bend_deg);
    if (!(o->open_need >= 0.0f && o->open_need <= 1.0f))
        return lm_fail(err, LM_ERR_INVALID, "charts: open_need %g must be in [0, 1]", (double)o->open_need);
    if (o->max_size < 4 * (o->gutter + 1) || o->max_size > 65536)
        return lm_fail(err, LM_ERR_INVALID, "charts: max_size %d must be in [%d, 65536]", o->max_size,
                       4 * (o->gutter + 1));
    return LM_OK;
}

/* Records each surface's chart range (charts are ordered by surface). */
static lm_status link_surfaces(const lm_surfaces *su, lm_atlas *a, lm_error *err)
{
    size_t n = (size_t)su->surface_count + 1;
    a->surface_count = su->surface_count;
    a->surface_first_chart = malloc(n * sizeof(int));
    a->surface_chart_count = calloc(n, sizeof(int));
    a->surface_texel_size = malloc(n * sizeof(float));
    if (!a->surface_first_chart || !a->surface_chart_count || !a->surface_texel_size)
        return lm_fail(err, LM_ERR_NOMEM, "charts: out of memory");
    for (int i = 0; i < su->surface_count; i++)
        a->surface_first_chart[i] = -1, a->surface_texel_size[i] = a->texel_size;
    for (int c = 0; c < a->chart_count; c++) {
        int f = a->charts[c].surface;
        if (a->surface_chart_count[f]++ == 0)
            a->surface_first_chart[f] = c, a->surface_texel_size[f] = a->charts[c].texel_size;
    }
    return LM_OK;
}

static lm_status copy_chart_tris(const lmc_charts *c, lm_atlas *a, lm_error *err)
{
    for (int i = 0; i < c->count; i++) {
        lm_chart *r = &a->charts[i];
        r->tri_count = c->charts[i].tri_count;
        r->tris = malloc(((size_t)r->tri_count + 1) * sizeof *r->tris);
        if (!r->tris)
            return lm_fail(err, LM_ERR_NOMEM, "charts: out of memory");
        memcpy(r->tris, c->charts[i].tris, (size_t)r->tri_count * sizeof *r->tris);
    }
    return LM_OK;
}

/* The texel table, its rasterisation and what lmgi_load keeps per atlas texel: about 110 bytes per atlas
 * texel, measured on the generated Cornell box from 66k to 4M texels (peak RSS of lmgi info). */
#define ATLAS_BYTES_PER_TEXEL 110.0

static lm_status plan_memory(const lm_atlas *a, lm_error *err)
{
    char what[128];
    double texels = (double)a->width * a->height;
    snprintf(what, sizeof what, "the lightmap atlas of %d x %d texels (texel %g units)", a->width, a->height,
             (double)a->texel_size);
    return lm_memory_plan(what, texels * ATLAS_BYTES_PER_TEXEL, "a larger texel size (--texel-size) or fewer "
                          "texels (--texels) makes it smaller", err);
}

/* A texel budget (target_texels) is met within LM_BUDGET_WARN: a count farther off is packed again, in
 * at most LM_BUDGET_PASSES passes, until within LM_BUDGET_SLACK (each step aiming LM_BUDGET_AIM inside
 * the budget on the side it came from); a count still beyond LM_BUDGET_WARN is warned about. */
#define LM_BUDGET_SLACK 0.1
#define LM_BUDGET_AIM 0.05 /* where in the band a step aims */
#define LM_BUDGET_WARN 0.15
#define LM_BUDGET_PASSES 6

/* A chart extent that takes one texel at texel size ts (as lmc_pack rounds). */
static int one_texel(const lmc_chart *ch, float ts)
{
    return lmc_chart_texels(ch, 0, ts) + 0.01 < 1.0 && lmc_chart_texels(ch, 1, ts) + 0.01 < 1.0;
}

/* A surface's texel size over the atlas's ts: 1, or less where a wall-sized surface would get fewer than
 * wall_texels texels (lm_atlas_options.wall_texels). */
static double texel_scale(const lm_surface *f, float ts, int wall_texels)
{
    if (wall_texels <= 0 || !(f->area >= LM_WALL_AREA))
        return 1.0;
    double own = sqrt((double)f->area / wall_texels);
    return own < ts ? own / ts : 1.0;
}

/* Per surface: how fast its shading normals turn, radians per world unit: over its triangles, the
 * area-weighted mean of the fastest turn along an edge (the angle between the edge's two vertex normals
 * over its length). An area weighting, not the largest: a sliver's short edge must not set it. pos: the
 * world positions (lmc_world_positions). */
static double *surface_bends(const lm_scene *s, const lm_surfaces *su, const float *pos)
{
    float *nrm = lmc_world_normals(s);
    double *bend = calloc((size_t)su->surface_count + 1, sizeof *bend);
    if (!nrm || !bend) {
        free(nrm), free(bend);
        return NULL;
    }
    for (int f = 0; f < su->surface_count; f++) {
        const lm_surface *sf = &su->surfaces[f];
        double sum = 0.0, area = 0.0;
        for (uint32_t i = 0; i < sf->tri_count; i++) {
            const uint32_t *v = s->tris + 3 * (size_t)sf->tris[i];
            lm_vec3 p0 = lm_v3_load(pos + 3 * (size_t)v[0]), p1 = lm_v3_load(pos + 3 * (size_t)v[1]),
                    p2 = lm_v3_load(pos + 3 * (size_t)v[2]);
            double fastest = 0.0, a = 0.5 * (double)lm_length(lm_cross(lm_sub(p1, p0), lm_sub(p2, p0)));
            for (int e = 0; e < 3; e++) {
                const float *pa = pos + 3 * (size_t)v[e], *pb = pos + 3 * (size_t)v[(e + 1) % 3];
                const float *na = nrm + 3 * (size_t)v[e], *nb = nrm + 3 * (size_t)v[(e + 1) % 3];
                double len = 0.0, c = 0.0;
                for (int k = 0; k < 3; k++)
                    len += ((double)pa[k] - pb[k]) * (pa[k] - pb[k]), c += (double)na[k] * nb[k];
                len = sqrt(len);
                if (len > 0.0)
                    fastest = fmax(fastest, acos(fmax(-1.0, fmin(1.0, c))) / len);
            }
            if (a > 0.0)
                sum += a * fastest, area += a;
        }
        bend[f] = area > 0.0 ? sum / area : 0.0;
    }
    free(nrm);
    return bend;
}

/* A bending surface's texel size over the atlas's ts: 1, or less where its normals would turn more than
 * bend_deg (> 0) a texel, where 1 / LM_BEND_REFINE is fine enough. */
static double bend_scale(double bend, float ts, float bend_deg)
{
    double most = bend_deg * LM_PI / 180.0;
    if (!(bend * ts > most) || bend * ts > most * LM_BEND_REFINE)
        return 1.0;
    return most / (bend * ts);
}

/* Per surface, its texel size over the atlas's for what its texels are worth (lm_atlas_options.open_need):
 * 1, or where it is open and its need per area is q < open_need times the level's, sqrt(open_need / q) (its texel density
 * then follows its need, meeting the rest's at q = open_need), at most LM_OPEN_COARSEN. All 1 where the level
 * needs nothing (a lone floor under the sky). NULL: out of memory. */
static double *open_scales(const lm_surfaces *su, const lm_atlas_options *o)
{
    double *scale = malloc(((size_t)su->surface_count + 1) * sizeof *scale), need = 0.0, area = 0.0;
    if (!scale)
        return NULL;
    for (int f = 0; f < su->surface_count; f++) {
        scale[f] = 1.0;
        if (isfinite(o->need[f]) && o->need[f] >= 0.0)
            need += o->need[f], area += su->surfaces[f].area;
    }
    for (int f = 0; need > 0.0 && area > 0.0 && f < su->surface_count; f++) {
        double q = o->need[f] / (su->surfaces[f].area * (need / area)), limit = o->open_need;
        if (su->surfaces[f].area > 0.0f && o->sky[f] >= LM_OPEN_SKY && q >= 0.0 && q < limit)
            scale[f] = q > 0.0 ? fmin(sqrt(limit / q), LM_OPEN_COARSEN) : LM_OPEN_COARSEN;
    }
    return scale;
}

static int cmp_u32(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return (x > y) - (x < y);
}

/* Frees what collapse_small made (its tri_uv is c's). */
static void free_view(lmc_charts *v)
{
    for (int i = 0; v->charts && i < v->count; i++)
        free(v->charts[i].tris);
    free(v->charts);
    memset(v, 0, sizeof *v);
}

/* The charts of c at texel size ts, each surface whose charts would all take one texel made one chart:
 * a small object unwrapped into several charts (a sphere's caps and sides) needs no more than one texel
 * when it is smaller than one, and a level of thousands of them could otherwise never meet a small
 * budget. The one chart's triangles overlap inside its texel, which then holds their summed area. */
static lm_status collapse_small(const lmc_charts *c, const lm_surfaces *su, const double *bend, const double *open,
                                float ts, const lm_atlas_options *o, lmc_charts *v, lm_error *err)
{
    memset(v, 0, sizeof *v);
    v->tri_uv = c->tri_uv;
    v->charts = calloc((size_t)c->count + 1, sizeof *v->charts);
    if (!v->charts)
        return lm_fail(err, LM_ERR_NOMEM, "charts: out of memory");
    for (int i = 0, end; i < c->count; i = end) {
        int small = 1, f = c->charts[i].surface;
        uint32_t tris = 0;
        /* an open surface's coarser size is its own, which the wall and bend rules refine from */
        double coarse = open ? open[f] : 1.0, wall_scale = texel_scale(&su->surfaces[f], (float)(ts * coarse), o->wall_texels);
        double scale = coarse * wall_scale;
        /* a wall's finer texels come on top of the budget, a bending surface's count against it */
        int wall = wall_scale < 1.0;
        for (end = i; end < c->count && c->charts[end].surface == f; end++) {
            lmc_chart probe = c->charts[end];
            probe.texel_scale = scale;
            small &= one_texel(&probe, ts) && !wall; /* a wall keeps its texels */
            tris += c->charts[end].tri_count;
        }
        if (bend && !small && su->surfaces[f].area >= LM_BEND_MIN_TEXELS * ts * ts * coarse * coarse)
            scale = fmin(scale, coarse * bend_scale(bend[f], (float)(ts * coarse), o->bend_deg));
        for (int k = i; k < end; k += small ? end - i : 1) {
            lmc_chart *d = &v->charts[v->count++];
            *d = c->charts[k];
            d->texel_scale = scale;
            d->on_top = wall;
            d->tri_count = small ? tris : c->charts[k].tri_count;
            d->tris = malloc(((size_t)d->tri_count + 1) * sizeof *d->tris);
            if (!d->tris) {
                free_view(v);
                return lm_fail(err, LM_ERR_NOMEM, "charts: out of memory");
            }
            uint32_t n = 0;
            for (int m = k; m < (small ? end : k + 1); m++) {
                memcpy(d->tris + n, c->charts[m].tris, (size_t)c->charts[m].tri_count * sizeof *d->tris);
                n += c->charts[m].tri_count;
                d->ext[0] = fmax(d->ext[0], c->charts[m].ext[0]);
                d->ext[1] = fmax(d->ext[1], c->charts[m].ext[1]);
            }
            if (small)
                qsort(d->tris, n, sizeof *d->tris, cmp_u32);
        }
    }
    return LM_OK;
}

/* The charts packed at texel size ts, their triangles copied and their texels made, into out. */
static lm_status lay_out(const lm_scene *s, const lm_surfaces *su, const lmc_charts *all, const float *pos,
                         const double *bend, const double *open, float ts, const lm_atlas_options *o, lm_atlas *out,
                         double *budgeted, lm_error *err)
{
    lmc_charts c;
    lm_status st = collapse_small(all, su, bend, open, ts, o, &c, err);
    if (st != LM_OK)
        return st;
    st = lmc_pack(&c, su, ts, o->gutter, o->max_size, out, err);
    if (st == LM_OK)
        st = plan_memory(out, err);
    if (st == LM_OK)
        st = copy_chart_tris(&c, out, err);
    if (st == LM_OK)
        st = lmc_texels(s, &c, pos, out, err);
    for (int i = 0; st == LM_OK && i < c.count; i++) { /* a surface's charts are consecutive */
        int first = i == 0 || c.charts[i - 1].surface != c.charts[i].surface, f = c.charts[i].surface;
        double coarse = open ? open[f] : 1.0;
        out->bent_surfaces += first && c.charts[i].texel_scale < coarse && !c.charts[i].on_top;
        out->open_surfaces += first && coarse > 1.0;
    }
    /* what counts against the budget: the walls' extra texels come on top of it */
    *budgeted = out->texel_count;
    for (uint32_t i = 0; st == LM_OK && i < out->texel_count; i++)
        *budgeted -= c.charts[out->tri_chart[out->texels[i].tri]].on_top;
    free_view(&c);
    return st;
}

lm_status lm_atlas_build(const lm_scene *s, const lm_surfaces *su, const lm_atlas_options *o, lm_atlas *out,
                         lm_error *err)
{
    lm_atlas_options def;
    if (!o) {
        lm_atlas_options_default(&def);
        o = &def;
    }
    memset(out, 0, sizeof *out);
    lm_status st = check_options(s, su, o, err);
    if (st != LM_OK)
        return st;
    float ts = o->texel_size > 0.0f ? o->texel_size : lm_atlas_default_texel_size(s, su, o->target_texels), size;
    double t0 = lm_now();
    float *pos = lmc_world_positions(s, &size);
    if (!pos)
        return lm_fail(err, LM_ERR_NOMEM, "charts: out of memory");
    double *bend = o->bend_deg > 0.0f ? surface_bends(s, su, pos) : NULL; /* NULL: the rule is off */
    int open_rule = o->need && o->sky && o->open_need > 0.0f && !o->use_file_uv1 && o->texel_size <= 0.0f;
    double *open = open_rule ? open_scales(su, o) : NULL;
    if ((o->bend_deg > 0.0f && !bend) || (open_rule && !open)) {
        free(pos), free(bend), free(open);
        return lm_fail(err, LM_ERR_NOMEM, "charts: out of memory");
    }
    lmc_charts c;
    st = o->use_file_uv1 ? lmc_charts_from_uv1(s, su, pos, &c, err) : lmc_unwrap(s, su, pos, &c, err);
    double t1 = lm_now(), t2 = t1;
    if (st == LM_OK) {
        double count = 0.0;
        st = lay_out(s, su, &c, pos, bend, open, ts, o, out, &count, err);
        t2 = lm_now();
        /* A texel budget is met by the texel size, but charts round up to whole texels: a level of many small
         * charts got 10x the texels it asked for (scenes/many_rooms.glb at 2,000). The texel size is scaled
         * by the square root of what came over what was asked; a budget below what the charts need at their
         * smallest stays over it (warned). */
        double target = o->target_texels > 0 ? o->target_texels : LM_ATLAS_DEFAULT_TEXELS;
        double ratio = count / target, best = fabs(ratio - 1.0);
        float best_ts = ts, last_ts = ts;
        /* the texel sizes known too fine (over the budget) and too coarse: the count is not 1 / ts^2 where
         * surfaces cross the wall or open rules' limits as ts moves (truck-town's town counts only once its
         * surfaces hold more than wall_texels), and a step that jumps past the budget is bisected */
        double too_fine = ratio > 1.0 ? ts : 0.0, too_coarse = ratio > 1.0 ? INFINITY : ts;
        /* ratio 0: every texel is a wall's, on top of the budget (a level in centimetres makes every surface
         * a wall), and the texel size has nothing to meet: scaling it by 0 made it 0 and the packing wrote
         * outside the atlas */
        for (int pass = 0; st == LM_OK && o->texel_size <= 0.0f && pass < LM_BUDGET_PASSES && ratio > 0.0 &&
                           best > (pass ? LM_BUDGET_SLACK : LM_BUDGET_WARN);
             pass++) {
            /* towards the near edge of the band, not its middle: the texel size moves no further than
             * the budget needs (the shared Cornell box's small box, 6 texels a face at run's 1,800, read
             * +1% at the area's texel size and +6.5% a step further at 5 texels) */
            double step = best_ts * sqrt(ratio / (ratio > 1.0 ? 1.0 + LM_BUDGET_AIM : 1.0 - LM_BUDGET_AIM));
            if (!(step > too_fine && step < too_coarse)) /* between the two, or halfway in scale past the one known */
                step = too_fine > 0.0 && isfinite(too_coarse) ? sqrt(too_fine * too_coarse)
                     : too_fine > 0.0                         ? 2.0 * too_fine
                                                              : 0.5 * too_coarse;
            last_ts = (float)step;
            lm_atlas_free(out);
            st = lay_out(s, su, &c, pos, bend, open, last_ts, o, out, &count, err);
            double r = count / target;
            lm_debug("charts: texel size %g: %u texels, %.0f counted (budget %.0f)", (double)last_ts, out->texel_count,
                     count, target);
            /* stop where the count answered a coarser texel size less than a quarter as much as the area says
             * (1 / ratio): charts already at their fewest texels would otherwise take texels of hundreds of
             * metres for a few texels fewer (truck-town at run's 1,800) */
            if (st != LM_OK || (ratio > 1.0 && r > 1.0 && last_ts > best_ts && r > 0.75 * ratio + 0.25))
                break;
            if (r > 1.0)
                too_fine = fmax(too_fine, last_ts);
            else
                too_coarse = fmin(too_coarse, last_ts);
            if (fabs(r - 1.0) < best - 0.01)
                best = fabs(r - 1.0), best_ts = last_ts, ratio = r;
        }
        if (st == LM_OK && last_ts != best_ts) {
            lm_atlas_free(out);
            st = lay_out(s, su, &c, pos, bend, open, best_ts, o, out, &count, err);
        }
        if (st == LM_OK && o->texel_size <= 0.0f && best > LM_BUDGET_WARN && c.count > 0 && count > 0.0)
            lm_warn("%s: %d charts need %.0f texels at the least; the budget of %.0f texels cannot be met "
                    "(docs/levels.md, \"Atlas\")", s->path, c.count, count, target);
        lmc_charts_free(&c);
    }
    free(pos), free(bend), free(open);
    if (st == LM_OK)
        st = link_surfaces(su, out, err);
    if (st != LM_OK) {
        lm_atlas_free(out);
        return st;
    }
    out->time_unwrap = t1 - t0;
    out->time_pack = t2 - t1;
    out->time_texels = lm_now() - t2;
    lm_debug("charts: %d charts, atlas %dx%d (%d pages of %dx%d), %u texels (%.1f%% of the pages); unwrap %.3f s, "
             "pack %.3f s, texels %.3f s", out->chart_count, out->width, out->height, out->page_count, out->page_width,
             out->page_height, out->texel_count, 100.0 * out->page_utilization,
             out->time_unwrap, out->time_pack, out->time_texels);
    return LM_OK;
}

void lm_atlas_free(lm_atlas *a)
{
    if (!a)
        return;
    for (int i = 0; a->charts && i < a->chart_count; i++)
        free(a->charts[i].tris);
    free(a->charts);
    free(a->corner_uv);
    free(a->coverage_uv);
    free(a->chart_owner);
    free(a->tri_chart);
    free(a->texels);
    free(a->texel_index);
    free(a->footprint_first);
    free(a->footprints);
    free(a->surface_first_chart);
    free(a->surface_chart_count);
    free(a->surface_texel_size);
    memset(a, 0, sizeof *a);
}
