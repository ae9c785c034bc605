/* The public API's scene: a loaded glTF scene with its surfaces, lightmap atlas, texel table and
 * ray-tracing BVHs, plus the effects it calls for. */
#include <lmgi.h>

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../charts/charts.h"
#include "../core/hash.h"
#include "../core/log.h"
#include "../core/timing.h"
#include "../core/vecmath.h"
#include "../trace/rt_scene.h"
#include "../trace/surface_need.h"
#include "../update/effects.h"
#include "lmgi_context.h"
#include "lmgi_scene.h"

void lmgi_options_init(lmgi_options *o)
{
    if (!o)
        return;
    lm_surface_options so;
    lm_atlas_options ao;
    lm_surface_options_default(&so);
    lm_atlas_options_default(&ao);
    memset(o, 0, sizeof *o);
    o->texel_size = ao.texel_size;
    o->target_texels = 0; /* LM_ATLAS_DEFAULT_TEXELS, unless a caller (lmgi run) knows better */
    o->gutter = ao.gutter;
    o->use_file_uv1 = ao.use_file_uv1;
    o->strict = so.strict;
    o->surface_cone_deg = so.cone_deg;
    o->max_atlas_size = ao.max_size;
    o->bend_deg = LM_BEND_DEFAULT_DEG;
    o->open_need = 0.0f; /* off, unless a caller (lmgi run) asks for it */
}

/* lm_scene_quiet, and with `changes` what the updater takes of the scene before it changes
 * (lm_frame_loop_before_change). */
static lmgi_status quiet(const lmgi_scene *sc, const char *fn, int changes, lmgi_error *err)
{
    if (!sc->loop)
        return LMGI_OK;
    lmgi_status st = lm_api_claim(sc->ctx, fn, err); /* an edit while another thread updates: refused */
    if (st != LMGI_OK)
        return st;
    lm_log_target saved = lm_api_enter(sc->ctx);
    lm_error e;
    lm_status s = changes ? lm_frame_loop_before_change(sc->loop, &e) : lm_frame_loop_sync(sc->loop, &e);
    if (s != LM_OK) /* reported again by the next update's own work */
        lm_log(LM_LOG_ERROR, "%s", e.msg);
    lm_api_leave(saved);
    lm_api_release(sc->ctx);
    return LMGI_OK;
}

lmgi_status lm_scene_quiet(const lmgi_scene *sc, const char *fn, lmgi_error *err)
{
    return quiet(sc, fn, lm_edits_pending(&sc->edits), err); /* staged edits: a commit follows */
}

lmgi_status lm_scene_before_change(const lmgi_scene *sc, const char *fn, lmgi_error *err)
{
    return quiet(sc, fn, 1, err);
}

lmgi_status lm_scene_commit(const lmgi_scene *sc, lmgi_error *err)
{
    if (!lm_edits_pending(&sc->edits))
        return LMGI_OK;
    lmgi_status st = lm_scene_quiet(sc, "the commit of the edits", err); /* the photon work reads the scene */
    if (st != LMGI_OK)
        return st;
    lm_error e;
    return lm_edits_commit(&sc->world, &e) == LM_OK ? LMGI_OK : lm_export_error(err, &e);
}

/* Staging an edit: refused (naming fn) while another thread is inside a call on the updater's context,
 * which may be committing the batch; stage_end releases the context and reports what staging said. */
static lmgi_status stage_begin(lmgi_scene *sc, const char *fn, lmgi_error *err)
{
    return sc->loop ? lm_api_claim(sc->ctx, fn, err) : LMGI_OK;
}

static lmgi_status stage_end(lmgi_scene *sc, lm_status st, const lm_error *e, lmgi_error *err)
{
    if (sc->loop)
        lm_api_release(sc->ctx);
    return st == LM_OK ? LMGI_OK : lm_export_error(err, e);
}

lmgi_status lm_scene_stage_light(lmgi_scene *sc, const char *fn, int id, const lm_light *l, lmgi_error *err)
{
    lmgi_status claimed = stage_begin(sc, fn, err);
    if (claimed != LMGI_OK)
        return claimed;
    lm_error e;
    int added;
    lm_status st = id < 0 ? lm_edits_add_light(&sc->edits, sc->scene, l, &added, &e)
                          : lm_edits_stage_light(&sc->edits, sc->scene, id, l, &e);
    return stage_end(sc, st, &e, err);
}

lmgi_status lm_scene_stage_material(lmgi_scene *sc, const char *fn, int id, const lm_material *m, lmgi_error *err)
{
    lmgi_status claimed = stage_begin(sc, fn, err);
    if (claimed != LMGI_OK)
        return claimed;
    lm_error e;
    return stage_end(sc, lm_edits_stage_material(&sc->edits, sc->scene, id, m, &e), &e, err);
}

lmgi_status lm_scene_stage_sky(lmgi_scene *sc, const char *fn, const lm_staged_sky *sky, lmgi_error *err)
{
    lmgi_status claimed = stage_begin(sc, fn, err);
    if (claimed != LMGI_OK)
        return claimed;
    lm_edits_stage_sky(&sc->edits, sky);
    return stage_end(sc, LM_OK, NULL, err);
}

lmgi_status lmgi_commit(lmgi_scene *sc, lmgi_error *err)
{
    if (!sc)
        return lm_api_refuse(err, "lmgi_commit: the scene is NULL");
    return lm_scene_commit(sc, err);
}

/* o with each 0 made its default: 0 means the default in every field, so a zeroed lmgi_options (or
 * none) is the defaults, as lmgi_options_init gives them. */
static void resolve_options(const lmgi_options *o, lmgi_options *out)
{
    lmgi_options_init(out);
    if (!o)
        return;
    lmgi_options def = *out;
    *out = *o;
    if (o->surface_cone_deg == 0.0f)
        out->surface_cone_deg = def.surface_cone_deg;
    if (o->max_atlas_size == 0)
        out->max_atlas_size = def.max_atlas_size;
    if (o->bend_deg == 0.0f)
        out->bend_deg = def.bend_deg;
}

static lm_status check_options(const char *path, const lmgi_options *o, lm_error *err)
{
    if (!(o->texel_size >= 0.0f) || !isfinite(o->texel_size))
        return lm_fail(err, LM_ERR_INVALID, "%s: texel size %g must be a finite number >= 0 (0 = automatic)",
                       path, (double)o->texel_size);
    if (o->target_texels < 0)
        return lm_fail(err, LM_ERR_INVALID, "%s: target texel count %d must be >= 0 (0 = %d)", path,
                       o->target_texels, LM_ATLAS_DEFAULT_TEXELS);
    if (o->gutter < 0 || o->gutter > 64)
        return lm_fail(err, LM_ERR_INVALID, "%s: gutter %d must be between 0 and 64 texels", path, o->gutter);
    if (!(o->surface_cone_deg > 0.0f && o->surface_cone_deg < 90.0f))
        return lm_fail(err, LM_ERR_INVALID, "%s: surface cone %g must be in (0, 90) degrees", path,
                       (double)o->surface_cone_deg);
    if (o->wall_texels < 0 || o->wall_texels > 65536)
        return lm_fail(err, LM_ERR_INVALID, "%s: wall_texels %d must be in [0, 65536]", path, o->wall_texels);
    if (o->bend_deg != (float)LMGI_OFF && !(o->bend_deg > 0.0f && o->bend_deg <= 180.0f))
        return lm_fail(err, LM_ERR_INVALID, "%s: bend_deg %g must be in (0, 180] degrees, or LMGI_OFF", path,
                       (double)o->bend_deg);
    if (o->open_need != (float)LMGI_OFF && !(o->open_need >= 0.0f && o->open_need <= 1.0f))
        return lm_fail(err, LM_ERR_INVALID, "%s: open_need %g must be in (0, 1], 0 or LMGI_OFF", path,
                       (double)o->open_need);
    if (o->max_atlas_size < 64 || o->max_atlas_size > 32768)
        return lm_fail(err, LM_ERR_INVALID, "%s: max_atlas_size (a lightmap page's side) %d must be in [64, 32768]",
                       path, o->max_atlas_size);
    return LM_OK;
}

/* Each surface's texels' bounding box, once: lmgi_surface_rect and the lightmap's window reads. */
static lm_status find_surface_rects(lmgi_scene *sc, lm_error *err)
{
    const lm_atlas *at = &sc->atlas;
    int n = at->surface_count > 0 ? at->surface_count : 1;
    int *lo = malloc(2 * sizeof(int) * (size_t)n), *r = calloc(4 * (size_t)n, sizeof(int));
    if (!lo || !r) {
        free(lo);
        free(r);
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for the surfaces' rectangles", sc->scene->path);
    }
    for (int i = 0; i < at->surface_count; i++) /* r holds the far corner + 1 until the end */
        lo[2 * i] = at->width, lo[2 * i + 1] = at->height;
    for (uint32_t i = 0; i < at->texel_count; i++) {
        const lm_texel *t = &at->texels[i];
        int *l = lo + 2 * t->surface, *h = r + 4 * t->surface;
        l[0] = t->x < l[0] ? t->x : l[0], l[1] = t->y < l[1] ? t->y : l[1];
        h[2] = t->x + 1 > h[2] ? t->x + 1 : h[2], h[3] = t->y + 1 > h[3] ? t->y + 1 : h[3];
    }
    for (int i = 0; i < at->surface_count; i++) {
        int *h = r + 4 * i;
        if (h[2] > 0)
            h[0] = lo[2 * i], h[1] = lo[2 * i + 1], h[2] -= h[0], h[3] -= h[1];
    }
    free(lo);
    sc->surface_rects = r;
    return LM_OK;
}

/* Each surface's need and its rays' share that see the sky (trace/surface_need.h), where the open-surface rule
 * applies (a derived texel size, lmgi_options.open_need in (0, 1]): *need (malloc'd, surface_count entries of
 * each, the sky's after the need's; NULL where the rule does not apply). R is clamped at the texel the budget
 * would give by area alone: nearer than that no texel resolves, and a level's contact lines would otherwise
 * raise its mean need until its rooms' walls looked open. */
static lm_status surface_needs(const lmgi_scene *sc, const lmgi_options *o, double **need, lm_error *err)
{
    *need = NULL;
    size_t n = (size_t)sc->surfaces.surface_count;
    if (o->texel_size > 0.0f || o->use_file_uv1 || !(o->open_need > 0.0f) || !n)
        return LM_OK;
    float ts = lm_atlas_default_texel_size(sc->scene, &sc->surfaces, o->target_texels);
    if (!(*need = malloc(2 * n * sizeof **need)))
        return lm_fail(err, LM_ERR_NOMEM, "%s: out of memory", sc->scene->path);
    lm_status st = lm_surface_need(sc->rt, sc->scene, &sc->surfaces, ts, *need, *need + n, err);
    if (st != LM_OK)
        free(*need), *need = NULL;
    return st;
}

static lm_status build(lmgi_scene *sc, const char *path, const void *data, size_t size, const lmgi_options *o,
                       lm_error *err)
{
    double t0 = lm_now();
    lm_load_options lo = {.strict = o->strict, .data = data, .size = size, .untrusted = o->untrusted};
    lm_status st = lm_scene_load_gltf(path, &lo, &sc->scene, err);
    if (st != LM_OK)
        return st;
    double t1 = lm_now();

    lm_surface_options so;
    lm_surface_options_default(&so);
    so.cone_deg = o->surface_cone_deg;
    so.strict = o->strict;
    st = lm_surfaces_build(sc->scene, &so, &sc->surfaces, err);
    if (st == LM_OK && o->texel_size <= 0.0f && !o->use_file_uv1 &&
        (so.min_surface_area = lm_surface_area_for_budget(&sc->surfaces, o->target_texels)) > 0.0f) {
        if (o->wall_texels > 0) /* walls keep their own texels (lm_atlas_options.wall_texels) */
            so.min_surface_area = fminf(so.min_surface_area, LM_WALL_AREA);
        lm_surfaces_free(&sc->surfaces); /* the small surfaces merged, so that the budget can be met */
        st = lm_surfaces_build(sc->scene, &so, &sc->surfaces, err);
    }
    if (st != LM_OK)
        return st;
    sc->have_surfaces = 1;
    double t2 = lm_now();

    /* the BVH before the atlas: what each surface sees sets its texels (lm_atlas_options.open_need) */
    st = lm_rt_build(sc->scene, &sc->surfaces, &sc->rt, err);
    if (st != LM_OK)
        return st;
    double t3 = lm_now();
    double *need = NULL;
    if ((st = surface_needs(sc, o, &need, err)) != LM_OK)
        return st;

    lm_atlas_options ao;
    lm_atlas_options_default(&ao);
    ao.texel_size = o->texel_size;
    ao.target_texels = o->target_texels;
    ao.wall_texels = o->texel_size <= 0.0f ? o->wall_texels : 0;
    ao.bend_deg = o->texel_size <= 0.0f && o->bend_deg > 0.0f ? o->bend_deg : 0.0f;
    ao.gutter = o->gutter;
    ao.use_file_uv1 = o->use_file_uv1;
    ao.max_size = o->max_atlas_size;
    ao.need = need;
    ao.sky = need ? need + sc->surfaces.surface_count : NULL;
    ao.open_need = need ? o->open_need : 0.0f;
    st = lm_atlas_build(sc->scene, &sc->surfaces, &ao, &sc->atlas, err);
    free(need);
    if (st != LM_OK)
        return st;
    sc->have_atlas = 1;
    if ((st = find_surface_rects(sc, err)) != LM_OK)
        return st;
    double t4 = lm_now();

    sc->world = (lm_world){sc->scene, &sc->surfaces, &sc->atlas, sc->rt, &sc->edits};
    sc->edits.decided = &sc->effects;
    lm_effects_decide(sc->scene, &sc->effects);
    sc->timings.load = t1 - t0;
    sc->timings.surfaces = t2 - t1;
    sc->timings.unwrap = sc->atlas.time_unwrap;
    sc->timings.pack = sc->atlas.time_pack;
    sc->timings.texels = sc->atlas.time_texels;
    sc->timings.atlas = t4 - t3;
    sc->timings.bvh = t3 - t2;
    sc->timings.total = t4 - t0;
    return LM_OK;
}

/* lmgi_load and lmgi_load_memory: the file's bytes from disk, or data (when non-NULL) named `path`. */
static lmgi_status load(const char *path, const void *data, size_t size, const lmgi_options *o, lmgi_scene **out,
                        lmgi_error *err)
{
    lm_error e;
    lm_error_clear(&e);
    if (!out) {
        lm_fail(&e, LM_ERR_INVALID, "lmgi_load: out is NULL (where the scene would go)");
        return lm_export_error(err, &e);
    }
    *out = NULL;
    lmgi_options resolved;
    resolve_options(o, &resolved);
    o = &resolved;
    if (!path) {
        lm_fail(&e, LM_ERR_INVALID, "no scene file given");
        return lm_export_error(err, &e);
    }
    lmgi_scene *sc = calloc(1, sizeof *sc);
    if (!sc) {
        lm_fail(&e, LM_ERR_NOMEM, "%s: no memory", path);
        return lm_export_error(err, &e);
    }
    sc->options = *o;
    lm_status st = check_options(path, o, &e);
    if (st == LM_OK)
        st = build(sc, path, data, size, o, &e);
    if (st != LM_OK) {
        lmgi_free(sc);
        return lm_export_error(err, &e);
    }
    *out = sc;
    return LMGI_OK;
}

lmgi_status lmgi_load(const char *path, const lmgi_options *o, lmgi_scene **out, lmgi_error *err)
{
    return load(path, NULL, 0, o, out, err);
}

lmgi_status lmgi_load_memory(const void *data, size_t size, const char *name, const lmgi_options *o,
                             lmgi_scene **out, lmgi_error *err)
{
    if (!data || size == 0) {
        if (out)
            *out = NULL;
        return lm_api_refuse(err, "lmgi_load_memory: %s", data ? "size is 0" : "data is NULL");
    }
    return load(name ? name : "(memory)", data, size, o, out, err);
}

void lmgi_free(lmgi_scene *sc)
{
    if (!sc)
        return;
    if (sc->updater) { /* its updater reads it: leak it rather than crash later */
        lm_log(LM_LOG_ERROR, "lmgi_free: %s still has an updater; free that first (scene kept)", sc->scene->path);
        return;
    }
    lm_edits_free(&sc->edits);
    lm_rt_free(sc->rt);
    if (sc->have_atlas)
        lm_atlas_free(&sc->atlas);
    free(sc->surface_rects);
    if (sc->have_surfaces)
        lm_surfaces_free(&sc->surfaces);
    lm_scene_free(sc->scene);
    free(sc);
}

int lmgi_node_count(const lmgi_scene *sc) { return sc ? sc->scene->node_count : 0; }

uint64_t lmgi_geometry_hash(const lmgi_scene *sc)
{
    if (!sc)
        return 0;
    const lm_scene *s = sc->scene;
    /* the nodes that hold triangles, by name, in order; each triangle's node by its rank among them, so a
     * node without triangles (a lamp, a camera) added or removed anywhere changes nothing */
    int *rank = malloc(sizeof *rank * (size_t)(s->node_count > 0 ? s->node_count : 1));
    if (!rank)
        return 0;
    for (int n = 0; n < s->node_count; n++)
        rank[n] = -1;
    for (uint32_t t = 0; t < s->tri_count; t++)
        rank[s->tri_node[t]] = 0;
    uint64_t h = LM_HASH_SEED;
    int held = 0;
    for (int n = 0; n < s->node_count; n++)
        if (rank[n] == 0) {
            rank[n] = held++;
            h = lm_hash_bytes(h, s->nodes[n].name, strlen(s->nodes[n].name) + 1);
        }
    h = lm_hash_bytes(h, &s->vertex_count, sizeof s->vertex_count);
    h = lm_hash_bytes(h, s->positions, 3 * sizeof *s->positions * (size_t)s->vertex_count);
    h = lm_hash_bytes(h, &s->tri_count, sizeof s->tri_count);
    h = lm_hash_bytes(h, s->tris, 3 * sizeof *s->tris * (size_t)s->tri_count);
    for (uint32_t t = 0; t < s->tri_count; t++)
        h = lm_hash_bytes(h, &rank[s->tri_node[t]], sizeof *rank);
    free(rank);
    return lm_hash_bytes(h, s->tri_material, sizeof *s->tri_material * (size_t)s->tri_count);
}

int lmgi_find_node(const lmgi_scene *sc, const char *name)
{
    for (int n = 0; sc && name && n < sc->scene->node_count; n++)
        if (strcmp(sc->scene->nodes[n].name, name) == 0)
            return n;
    return -1;
}

const char *lmgi_node_name(const lmgi_scene *sc, int node)
{
    return sc && node >= 0 && node < sc->scene->node_count ? sc->scene->nodes[node].name : NULL;
}

int lmgi_node_is_dynamic(const lmgi_scene *sc, int node)
{
    return sc && node >= 0 && node < sc->scene->node_count && lm_edits_node_dynamic(&sc->edits, sc->scene, node);
}

/* Whether a node or one under it has triangles (a static one of those is in the static BVH, which does not
 * move; a light's or camera's node without any may move freely). */
static int carries_triangles(const lm_scene *s, int node)
{
    for (int i = 0; i < s->node_count; i++)
        if (s->nodes[i].tri_count > 0 && lm_node_under(s, i, node))
            return 1;
    return 0;
}

lmgi_status lmgi_get_node_effects(const lmgi_scene *sc, int node, lmgi_node_effects *out, lmgi_error *err)
{
    if (out)
        memset(out, 0, sizeof *out);
    if (!sc || !out)
        return lm_api_refuse(err, "lmgi_get_node_effects: %s is NULL", sc ? "out" : "the scene");
    if (node < 0 || node >= sc->scene->node_count)
        return lm_api_refuse(err, "node id %d is out of range (scene has %d nodes)", node, sc->scene->node_count);
    int v[4];
    lm_edits_node_effects(&sc->edits, sc->scene, node, v);
    out->shadows = v[0], out->indirect = v[1], out->reflections = v[2], out->caustics = v[3];
    return LMGI_OK;
}

lmgi_status lmgi_set_node_effects(lmgi_scene *sc, int node, const lmgi_node_effects *in, lmgi_error *err)
{
    if (!sc || !in)
        return lm_api_refuse(err, "lmgi_set_node_effects: %s is NULL", sc ? "the effects" : "the scene");
    lm_scene *s = sc->scene;
    if (node < 0 || node >= s->node_count)
        return lm_api_refuse(err, "node id %d is out of range (scene has %d nodes)", node, s->node_count);
    const int v[4] = {in->shadows, in->indirect, in->reflections, in->caustics};
    static const char *const names[4] = {"shadows", "indirect", "reflections", "caustics"};
    for (int k = 0; k < 4; k++)
        if (v[k] != 0 && v[k] != 1)
            return lm_api_refuse(err, "node '%s': %s is 0 or 1, not %d", s->nodes[node].name, names[k], v[k]);
    lmgi_status claimed = stage_begin(sc, "lmgi_set_node_effects", err);
    if (claimed != LMGI_OK)
        return claimed;
    const lm_staged_effects fx = {node, in->shadows, in->indirect, in->reflections, in->caustics};
    lm_error e;
    return stage_end(sc, lm_edits_stage_effects(&sc->edits, &fx, &e), &e, err);
}

lmgi_status lmgi_set_node_dynamic(lmgi_scene *sc, int node, int dynamic, lmgi_error *err)
{
    if (!sc)
        return lm_api_refuse(err, "lmgi_set_node_dynamic: the scene is NULL");
    lm_scene *s = sc->scene;
    if (node < 0 || node >= s->node_count)
        return lm_api_refuse(err, "node id %d is out of range (scene has %d nodes)", node, s->node_count);
    const lm_node *n = &s->nodes[node];
    if (dynamic != 0 && dynamic != 1)
        return lm_api_refuse(err, "node '%s': dynamic is 0 or 1, not %d", n->name, dynamic);
    int same = 1;
    for (int i = 0; i < s->node_count; i++)
        same &= !lm_node_under(s, i, node) || lm_edits_node_dynamic(&sc->edits, s, i) == dynamic;
    if (same)
        return LMGI_OK; /* nothing to rebuild */
    if (!dynamic && n->parent >= 0 && lm_edits_node_dynamic(&sc->edits, s, n->parent))
        return lm_api_refuse(err, "node '%s' lies under dynamic node '%s', which moves it: it stays dynamic", n->name,
                             s->nodes[n->parent].name);
    if (!dynamic && lm_node_animated_under(s, node))
        return lm_api_refuse(err, "node '%s' (or a node under it) is animated: it stays dynamic", n->name);
    /* the BVH is rebuilt at the commit, once for every switch staged by then */
    lmgi_status claimed = stage_begin(sc, "lmgi_set_node_dynamic", err);
    if (claimed != LMGI_OK)
        return claimed;
    lm_error e;
    return stage_end(sc, lm_edits_stage_dynamic(&sc->edits, node, dynamic, &e), &e, err);
}

lmgi_status lmgi_set_node_transform(lmgi_scene *sc, int node, const float world[16], lmgi_error *err)
{
    lm_error e;
    lm_error_clear(&e);
    if (!sc || !world) {
        lm_fail(&e, LM_ERR_INVALID, "lmgi_set_node_transform: %s is NULL", sc ? "the matrix" : "the scene");
        return lm_export_error(err, &e);
    }
    const lm_node *n = node >= 0 && node < sc->scene->node_count ? &sc->scene->nodes[node] : NULL;
    /* its winding was set at load by the sign it had then (lm_node.mirrored): the rays would follow a
     * change (rt_scene.c), the rasterised sides and surfaces would not */
    if (n && lm_mat4_finite(world) && !lm_mat4_singular(world) && lm_mat4_mirrors(world) != n->mirrored) {
        lm_fail(&e, LM_ERR_INVALID, "node '%s': transform %s the node, which it %s at load; a node's sides are "
                "decided at load, so an edit keeps the sign of its determinant", n->name,
                n->mirrored ? "no longer mirrors" : "mirrors", n->mirrored ? "was mirrored" : "was not mirrored");
        return lm_export_error(err, &e);
    }
    float m[16]; /* from the file's world to lmgi's (lm_scene.origin) */
    memcpy(m, world, sizeof m);
    for (int k = 0; k < 3; k++)
        m[12 + k] -= sc->scene->origin[k];
    if (!n) {
        lm_fail(&e, LM_ERR_INVALID, "node id %d is out of range (scene has %d nodes)", node, sc->scene->node_count);
        return lm_export_error(err, &e);
    }
    if (!lm_edits_node_dynamic(&sc->edits, sc->scene, node) && carries_triangles(sc->scene, node)) {
        lm_fail(&e, LM_ERR_INVALID, "node '%s' is static and cannot be moved; mark it dynamic with extras "
                "{\"lmgi\": {\"dynamic\": true}}", n->name);
        return lm_export_error(err, &e);
    }
    if (!lm_mat4_finite(m) || lm_mat4_singular(m)) {
        lm_fail(&e, LM_ERR_INVALID, "node '%s': transform %s", n->name, lm_mat4_finite(m) ? "is singular (a zero "
                "scale flattens the node)" : "has NaN or Inf entries");
        return lm_export_error(err, &e);
    }
    /* The scene model now (children follow through their local matrices), the rays at the commit
     * (update/edits.h); on a failure the node's earlier placement comes back. */
    if (lm_scene_before_change(sc, "lmgi_set_node_transform", err) != LMGI_OK) /* its photon work may still be reading the scene and BVH */
        return LMGI_ERR_INVALID;
    lm_node saved = *n;
    lm_status st = lm_scene_set_node_world(sc->scene, node, m)
                       ? lm_scene_check_extent(sc->scene, node, &e)
                       : lm_fail(&e, LM_ERR_INVALID, "node '%s': its parent's transform has no inverse", n->name);
    if (st != LM_OK) {
        sc->scene->nodes[node] = saved;
        lm_scene_update_world(sc->scene);
        return lm_export_error(err, &e);
    }
    lm_edits_note_moved(&sc->edits); /* the BVH follows at the commit */
    return LMGI_OK;
}

int lmgi_get_node_transform(const lmgi_scene *sc, int node, float world[16])
{
    if (!sc || !world || node < 0 || node >= sc->scene->node_count)
        return 0;
    memcpy(world, sc->scene->nodes[node].world, 16 * sizeof *world);
    for (int k = 0; k < 3; k++) /* lmgi's world to the file's */
        world[12 + k] += sc->scene->origin[k];
    return 1;
}

lmgi_status lmgi_node_resume_animation(lmgi_scene *sc, int node, lmgi_error *err)
{
    lm_error e;
    if (!sc || node < 0 || node >= sc->scene->node_count) {
        lm_fail(&e, LM_ERR_INVALID, "lmgi_node_resume_animation: %s", sc ? "node id out of range" : "the scene is NULL");
        return lm_export_error(err, &e);
    }
    if (lm_scene_before_change(sc, "lmgi_node_resume_animation", err) != LMGI_OK)
        return LMGI_ERR_INVALID;
    lm_scene_release_node(sc->scene, node);
    return LMGI_OK;
}

lmgi_status lmgi_set_time(lmgi_scene *sc, float t, lmgi_error *err)
{
    lm_error e;
    lm_error_clear(&e);
    if (!sc) {
        lm_fail(&e, LM_ERR_INVALID, "lmgi_set_time: the scene is NULL");
        return lm_export_error(err, &e);
    }
    if (!isfinite(t)) {
        lm_fail(&e, LM_ERR_INVALID, "%s: animation time is not a finite number", sc->scene->path);
        return lm_export_error(err, &e);
    }
    if ((sc->scene->animation_count > 0 ? lm_scene_before_change(sc, "lmgi_set_time", err)
                                             : lm_scene_quiet(sc, "lmgi_set_time", err)) != LMGI_OK)
        return LMGI_ERR_INVALID;
    lm_scene_eval_animation(sc->scene, -1, t);
    lm_edits_note_moved(&sc->edits); /* the BVH follows at the commit */
    return LMGI_OK;
}

void lmgi_intersect(const lmgi_scene *sc, const float org[3], const float dir[3], float tmax, lmgi_hit *hit)
{
    if (!hit)
        return;
    lm_rt_hit h;
    memset(hit, 0, sizeof *hit);
    hit->node = hit->surface = hit->material = -1;
    if (!sc || !org || !dir || lm_scene_commit(sc, NULL) != LMGI_OK) /* the BVH unusable: nothing hit */
        return;
    const float *o = sc->scene->origin;
    const float local[3] = {org[0] - o[0], org[1] - o[1], org[2] - o[2]};
    if (!lm_rt_intersect(sc->rt, local, dir, 0.0f, tmax, &h))
        return;
    hit->hit = 1;
    hit->t = h.t;
    hit->node = h.node;
    hit->surface = h.surface;
    hit->triangle = h.tri;
    hit->material = sc->scene->tri_material[h.tri];
    hit->uv[0] = h.u, hit->uv[1] = h.v;
    memcpy(hit->normal, h.ng, sizeof hit->normal);
}

uint32_t lmgi_texel_count(const lmgi_scene *sc) { return sc ? sc->atlas.texel_count : 0; }

void lmgi_get_texel(const lmgi_scene *sc, uint32_t i, lmgi_texel *out)
{
    if (!out)
        return;
    memset(out, 0, sizeof *out);
    if (!sc || i >= sc->atlas.texel_count) {
        out->surface = -1;
        return;
    }
    const lm_texel *t = &sc->atlas.texels[i];
    for (int k = 0; k < 3; k++)
        out->position[k] = t->pos[k] + sc->scene->origin[k];
    memcpy(out->normal, t->normal, sizeof out->normal);
    out->x = t->x;
    out->y = t->y;
    out->surface = t->surface;
    out->triangle = t->tri;
    out->area = t->area;
    out->page = lm_atlas_page_of(&sc->atlas, t->x, t->y, &out->page_x, &out->page_y);
}

int lmgi_triangle_lightmap_uv(const lmgi_scene *sc, uint32_t tri, float uv[6])
{
    if (!sc || !uv || tri >= sc->scene->tri_count || sc->atlas.tri_chart[tri] < 0)
        return 0;
    memcpy(uv, sc->atlas.corner_uv + 6 * (size_t)tri, 6 * sizeof(float));
    return 1;
}

const char *lmgi_status_name(lmgi_status s) { return lm_status_name((lm_status)s); }

void lmgi_set_verbosity(int level)
{
    lm_log_set_level(level <= 0 ? LM_LOG_ERROR : level == 1 ? LM_LOG_WARN : level == 2 ? LM_LOG_INFO : LM_LOG_DEBUG);
}
