/* The public API's updater: the frame loop (update/frame_loop.h, which turns the time budget into work:
 * update/budget.h) behind include/lmgi.h, with per-surface change counters and the lightmaps read
 * back. */
#include <lmgi_tools.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../charts/atlas_dilate.h"
#include "../scene/scene_view.h"
#include "../scene/sky.h"
#include "../trace/emitter_light.h"
#include "../update/bake_checkpoint.h"
#include "../update/frame_loop.h"
#include "../update/ray_estimate.h"
#include "lmgi_camera.h"
#include "lmgi_context.h"
#include "lmgi_scene.h"
#include "lmgi_updater.h"
#include "updater_knobs.h"

struct lmgi_updater {
    lmgi_context *ctx;
    lmgi_scene *sc;
    lm_frame_loop *loop;
    int frames;                 /* updates done */
    uint32_t *seen;             /* per surface: lmgi_surface_version at the end of the last update */
    lm_photon_stage_frame setup;
    double t_setup_gather;
    lm_lightmap_texture *texture; /* lmgi_get_lightmap_texture's, once asked for */
    lmgi_updater_desc knobs;    /* the desc it was made from, resolved (lmgi_get_updater_info) */
};

/* What the frame loop's gather schemes and indirect paths are called in the desc. */
static const int INDIRECT_PATHS[4] = {LM_INDIRECT_LIGHTMAP, LM_INDIRECT_BRUTEFORCE, LM_INDIRECT_TILED,
                                      LM_INDIRECT_HASHGRID};

/* The frame's size and camera, the fields beside the knobs that have rules of their own. */
static lm_status check_frame_desc(const lm_scene *scene, const lmgi_frame_knobs *f, lm_error *err)
{
    if (f->width < 0 || f->height < 0 || f->width > 16384 || f->height > 16384 || (f->width == 0) != (f->height == 0))
        return lm_fail(err, LM_ERR_INVALID, "lmgi_updater_create: frame %d x %d must be 0 x 0 (none) or sides in "
                       "1..16384", f->width, f->height);
    if (f->camera < -1 || (f->camera > 0 && f->camera >= scene->camera_count))
        return lm_fail(err, LM_ERR_INVALID, "lmgi_updater_create: camera %d: the scene has %d", f->camera,
                       scene->camera_count);
    if (f->width > 0) { /* a camera that shows only the background would give black frames and exit 0 */
        lm_view v;
        lm_view_for_scene(scene, f->camera, f->width, f->height, &v);
        if (!lm_view_sees_box(&v, scene->bounds_min, scene->bounds_max))
            return lm_fail(err, LM_ERR_INVALID, "%s: camera '%s' sees none of the scene (the scene's bounds lie "
                           "wholly outside its view: behind it, off to a side, or beyond its far plane); its frames "
                           "would show only the background", scene->path, v.name);
    }
    return LM_OK;
}

/* The rest beside the table: effects, the indirect path, the tiled gather's combinations and a radius
 * relative to the scene. */
static lm_status check_modes(const lm_scene *scene, const lmgi_updater_desc *d, lm_error *err)
{
    const unsigned all = LMGI_EFFECT_SHADOWS | LMGI_EFFECT_INDIRECT | LMGI_EFFECT_REFLECTIONS | LMGI_EFFECT_CAUSTICS;
    if (d->effects_off & ~all)
        return lm_fail(err, LM_ERR_INVALID, "lmgi_updater_create: effects_off 0x%x has bits other than "
                       "LMGI_EFFECT_SHADOWS, _INDIRECT, _REFLECTIONS and _CAUSTICS", d->effects_off);
    if ((int)d->indirect < LMGI_INDIRECT_LIGHTMAP || (int)d->indirect > LMGI_INDIRECT_HASHGRID)
        return lm_fail(err, LM_ERR_INVALID, "lmgi_updater_create: indirect %d is not an indirect path "
                       "(LMGI_INDIRECT_LIGHTMAP, _BRUTEFORCE, _TILED, _HASHGRID)", (int)d->indirect);
    /* a kernel of 1e-30 divided by its area into infinity, every pixel NaN */
    float size = lm_scene_size(scene), lo = 1e-6f * size, hi = 1e6f * size;
    if (!(d->tiled.radius == 0.0f || (d->tiled.radius >= lo && d->tiled.radius <= hi)))
        return lm_fail(err, LM_ERR_INVALID, "lmgi_updater_create: tiled.radius %g must be 0 (from aim.nearest) or "
                       "within 1e-6 to 1e6 times the scene's size %g", (double)d->tiled.radius, (double)size);
    return LM_OK;
}

/* The frame loop's settings from a desc whose knobs are checked and resolved (r), stage by stage. */
static void photon_settings(const lmgi_updater_desc *r, lm_frame_loop_settings *s)
{
    lm_photon_settings *ph = &s->stage.photons;
    if (r->photons.count)
        ph->total_photons = r->photons.count;
    ph->groups = r->photons.groups;
    if (r->photons.per_group) {
        ph->per_group = r->photons.per_group;
        ph->min_total = 0; /* photons per group as asked, without the scene's floor */
    }
    ph->retrace_per_group = r->photons.retrace_per_group;
    ph->group_budget = r->photons.group_budget == LMGI_OFF ? 0 : (uint32_t)r->photons.group_budget; /* 0: all */
    ph->seed = r->photons.seed;
    s->stage.find_portals = r->photons.find_portals == LMGI_ON;
    s->stage.aim.n_nearest = r->aim.nearest;
    s->stage.aim.min_radius_texels = r->aim.min_radius;
    s->stage.surfaces_per_frame = r->aim.surfaces_per_frame; /* LMGI_OFF: -1, all that changed */
    s->stage.exact_direct = lm_exact_direct_of(r->aim.direct);
    /* lmgi_knobs.h's aim.direct_parts: its default and its most are the AIM's own */
    _Static_assert(LM_AIM_DIRECT_PARTS == 2 && LM_AIM_DIRECT_PARTS_MAX == 8, "aim.direct_parts' table line");
    s->stage.aim.direct_parts = r->aim.direct_parts;
    s->stage.aim.error_estimate = r->aim.error_estimate == LMGI_ON;
    s->stage.occluders = r->aim.occluders == LMGI_ON;
    s->stage.caustic.photons = r->caustics.photons;
    s->stage.caustic.retrace = r->caustics.retrace;
}

static void gather_settings(const lmgi_updater_desc *r, lm_frame_loop_settings *s)
{
    const lmgi_gather_knobs *g = &r->gather;
    s->iim.texels_per_frame = g->texels_per_frame;
    s->iim.blend_frames = g->blend_frames == LMGI_OFF ? 0 : g->blend_frames;
    s->iim.texel_change = g->texel_change == LMGI_OFF ? -1.0f : g->texel_change;
    s->iim.spread = g->spread == LMGI_OFF ? 0 : g->spread;
    /* lmgi_knobs.h's gather.estimate_rays: its default is the estimator's own */
    _Static_assert(LM_RAY_ESTIMATE_RAYS == 36, "gather.estimate_rays' table line");
    s->iim.estimate_rays = g->estimate_rays == LMGI_OFF ? 0 : g->estimate_rays;
    s->gather.resolution = g->resolution;
    s->gather.enlargement = g->enlargement;
    s->gather.samples = g->samples;
    s->gather.coverage_samples = g->coverage; /* 0: chosen per scene */
    s->gather.rim_samples = g->rim_samples == LMGI_OFF ? 0 : g->rim_samples;
    if (g->scheme != LMGI_GATHER_DEFAULT)
        s->gather.scheme = (lm_gather_scheme)(g->scheme - 1);
    s->emitter_light = g->emitter_light == LMGI_EMITTERS_CLOSED_FORM ? 1
                       : g->emitter_light == LMGI_EMITTERS_DRAWN  ? 0
                                                                  : -1; /* chosen per scene */
    s->emitter_rays = g->emitter_rays;
    s->bounce_passes = g->bounce_passes == LMGI_OFF ? 0 : g->bounce_passes;
    s->gather.direct_near = g->direct_near == LMGI_OFF ? 0.0f : g->direct_near;
    s->gather.adapt = g->adapt == LMGI_OFF ? 0.0f : g->adapt;
    s->gather.ray_samples = g->rays;
    s->gather.seed = r->photons.seed; /* the gather's patterns, and a light edit's factors', follow the photons'
                                       * seed */
}

static void frame_settings(const lmgi_updater_desc *r, lm_frame_loop_settings *s)
{
    const lmgi_frame_knobs *f = &r->frame;
    s->width = f->width;
    s->height = f->height;
    s->camera = f->camera;
    s->direct.maps_per_update = f->shadow_maps_per_update; /* LMGI_OFF: -1, every stale one */
    int no_reflections = f->reflection_size == LMGI_OFF || (r->effects_off & LMGI_EFFECT_REFLECTIONS);
    s->reflection_size = no_reflections ? 0 : f->reflection_size;
    s->reflection_faces = f->reflection_faces;
    s->direct.probe_lod = f->reflection_lod == LMGI_OFF ? 0.0f : f->reflection_lod;
    s->caustic_pass.filter_k = r->caustics.filter == LMGI_OFF ? 0 : r->caustics.filter;
    s->caustic_pass.filter_photons = r->caustics.filter_photons == LMGI_OFF ? 0 : r->caustics.filter_photons;
    s->caustic_pass.tile = r->caustics.tile;
    s->caustic_thin = r->caustics.thin == LMGI_OFF ? 0.0f : r->caustics.thin;
    s->caustic_pass.world_space = r->caustics.world_filter == LMGI_ON;
    s->photon_gather.tile = r->tiled.tile;
    s->photon_gather.chunk = r->tiled.chunk;
    s->photon_gather.stochastic = r->tiled.stochastic;
    s->photon_radius = r->tiled.radius;
    s->indirect_path = INDIRECT_PATHS[r->indirect];
    s->overlap = !r->in_order;
    s->direct.shadows = !(r->effects_off & LMGI_EFFECT_SHADOWS);
    s->indirect = !(r->effects_off & LMGI_EFFECT_INDIRECT);
    s->caustics = !(r->effects_off & LMGI_EFFECT_CAUSTICS);
    s->cancel = r->cancel;
}

/* A scene lit by its emissive triangles alone, in closed form: no punctual or directional light, no sky,
 * emitters not drawn into hemicubes. */
static int lit_by_emitters_alone(const lm_scene *scene, const lm_frame_loop_settings *s)
{
    return scene->light_count == 0 && !scene->has_sky && s->emitter_light != 0 && lm_emitter_light_suits(scene);
}

/* The gather scheme and the AIMs' direct light on auto. Rays where the GL rasterizes in software and the
 * level is large (a software hemicube costs what the gather proxy's triangles cost, rays the log of the
 * level's: docs/gather.md, "Rays"), under any sky that is not uniform (a hemicube clears to one colour), and
 * where emissive triangles alone light the scene: there the rays take their light at each near hit (the
 * AIMs' direct light EMITTERS), which keeps the contact shadows a texel's mean blurs, for about twice the
 * hemicube's time (docs/gather.md, "Near and far hits"). Elsewhere the AIMs compute the suns' light. */
static lm_status choose_gather(const lm_scene *scene, const lmgi_updater_desc *d, const lm_gl_context *gl,
                               lm_frame_loop_settings *s, lm_error *err)
{
    int emitters_alone = d->aim.direct == LMGI_AIM_DIRECT_DEFAULT && lit_by_emitters_alone(scene, s);
    if (d->gather.scheme == LMGI_GATHER_DEFAULT &&
        ((scene->tri_count > LMGI_RAYS_ABOVE_TRIANGLES && lm_gl_context_is_software(gl)) ||
         !lm_sky_is_uniform(scene) || emitters_alone))
        s->gather.scheme = LM_GATHER_RAYS;
    if (s->gather.scheme != LM_GATHER_RAYS && !lm_sky_is_uniform(scene))
        return lm_fail(err, LM_ERR_INVALID, "%s: a gradient or image sky needs the rays gather (--gather-scheme rays), "
                       "not hemicubes (%s)", scene->path, lm_gather_scheme_name(s->gather.scheme));
    if (emitters_alone && s->gather.scheme == LM_GATHER_RAYS)
        s->stage.exact_direct = LM_EXACT_EMITTERS;
    return LM_OK;
}

/* The frame loop's settings from a desc: its knobs checked against their table and resolved, the rest
 * checked here. */
lm_status lm_updater_settings(const lm_scene *scene, const lmgi_updater_desc *d, lm_gl_context *gl,
                              lm_frame_loop_settings *s, lm_error *err)
{
    lm_frame_loop_settings_default(s);
    lm_status st = lm_updater_knobs_check(d, "lmgi_updater_create", err);
    if (st == LM_OK)
        st = check_frame_desc(scene, &d->frame, err);
    if (st == LM_OK)
        st = check_modes(scene, d, err);
    if (st != LM_OK)
        return st;
    lmgi_updater_desc r;
    lm_updater_knobs_resolve(d, &r);
    photon_settings(&r, s);
    gather_settings(&r, s);
    frame_settings(&r, s);
    s->gl = gl;
    st = choose_gather(scene, d, gl, s, err);
    if (st != LM_OK)
        return st;
    lm_error why;
    if (!lm_photon_gather_settings_check(&s->photon_gather, &why))
        return lm_fail(err, LM_ERR_INVALID, "lmgi_updater_create: %s (tiled.tile, tiled.chunk, tiled.stochastic; "
                       "0: the defaults)", why.msg);
    return LM_OK;
}

int lmgi_atlas_texels_for(int texels_per_frame)
{
    return lm_frame_loop_atlas_texels(texels_per_frame > 0 ? texels_per_frame : LM_IIM_DEFAULT_TEXELS_PER_FRAME);
}

/* The frame loop's progress (texels of the first gather) as the public one (a fraction and a stage). */
static void gather_progress(void *user, uint32_t done, uint32_t total)
{
    const lmgi_updater_desc *d = user;
    d->progress(d->progress_user, total ? (float)done / (float)total : 1.0f, "gather");
}

/* The desc's shard or parts (a bake in shards), each field checked. */
static lm_status check_shards(const lmgi_updater_desc *d, lm_error *err)
{
    static const char fn[] = "lmgi_updater_create";
    if (d->shards < 0 || d->shards > LM_MAX_SHARDS || (d->shards > 0 && (d->shard < 0 || d->shard >= d->shards)) ||
        (d->shards == 0 && d->shard != 0))
        return lm_fail(err, LM_ERR_INVALID, "%s: shard %d of %d: shards must be 1 to %d (0: none) and shard 0 to "
                       "shards - 1", fn, d->shard, d->shards, LM_MAX_SHARDS);
    if (d->shards > 0 && !d->checkpoint)
        return lm_fail(err, LM_ERR_INVALID, "%s: a shard needs a checkpoint file to hold its part", fn);
    if (!d->parts != !d->part_count || d->part_count < 0)
        return lm_fail(err, LM_ERR_INVALID, "%s: parts %s with part_count %d", fn, d->parts ? "given" : "NULL",
                       d->part_count);
    for (int p = 0; p < d->part_count; p++)
        if (!d->parts[p])
            return lm_fail(err, LM_ERR_INVALID, "%s: parts[%d] is NULL", fn, p);
    if (d->shards > 0 && d->gather.bounce_passes > 0)
        return lm_fail(err, LM_ERR_INVALID, "%s: bounce_passes %d in a shard: each pass reads the whole last "
                       "gather, which a shard does not hold; give them to the merge of the parts", fn,
                       d->gather.bounce_passes);
    if (d->parts && (d->shards > 0 || d->resume))
        return lm_fail(err, LM_ERR_INVALID, "%s: parts are put together into a whole bake: not with %s", fn,
                       d->shards > 0 ? "a shard" : "resume");
    if ((d->photon_exchange || d->claim_pass) && (d->shards < 2 || d->resume))
        return lm_fail(err, LM_ERR_INVALID, "%s: %s connects the processes of a shared bake: it needs shards > 1 "
                       "(here %d) and no resume", fn, d->photon_exchange ? "photon_exchange" : "claim_pass", d->shards);
    return LM_OK;
}

static lmgi_status updater_create_owned(lmgi_context *ctx, lmgi_scene *sc, const lmgi_updater_desc *desc,
                                        lmgi_updater **out, lmgi_error *err)
{
    if (!out)
        return lm_api_refuse(err, "lmgi_updater_create: out is NULL");
    *out = NULL;
    if (!ctx || !sc)
        return lm_api_refuse(err, "lmgi_updater_create: %s is NULL", ctx ? "scene" : "context");
    if (sc->scene->tri_count == 0)
        return lm_api_refuse(err, "%s: the scene has no triangles to light", sc->scene->path);
    if (sc->updater)
        return lm_api_refuse(err, "%s: the scene already has an updater (it moves the scene's nodes: one at a time)",
                       sc->scene->path);
    lmgi_updater_desc d;
    memset(&d, 0, sizeof d);
    if (desc)
        d = *desc;
    lm_log_target saved = lm_api_enter(ctx);
    lm_error e;
    lm_frame_loop_settings set;
    lm_status st = lm_updater_settings(sc->scene, &d, ctx->gl, &set, &e);
    if (d.progress) {
        set.progress = gather_progress;
        set.progress_user = &d;
    }
    set.checkpoint = d.checkpoint;
    set.checkpoint_seconds = d.checkpoint_seconds;
    set.resume = d.resume;
    if (st == LM_OK && (!(d.checkpoint_seconds >= 0.0) || (d.resume && !d.checkpoint)))
        st = lm_fail(&e, LM_ERR_INVALID, "lmgi_updater_create: %s", d.resume ? "resume without a checkpoint file"
                                                                               : "checkpoint_seconds is negative or NaN");
    if (st == LM_OK)
        st = check_shards(&d, &e);
    set.shard = d.shard, set.shards = d.shards, set.parts = d.parts, set.part_count = d.part_count;
    set.claim_pass = d.claim_pass, set.claim_user = d.share_user;
    if (d.photon_exchange)
        set.stage.split = (lm_photon_split){(uint32_t)d.shard, (uint32_t)d.shards, d.photon_exchange, d.share_user};
    lmgi_updater *u = st == LM_OK ? calloc(1, sizeof *u) : NULL;
    if (st == LM_OK && !u)
        st = lm_fail(&e, LM_ERR_NOMEM, "no memory for an updater");
    if (st == LM_OK) {
        u->ctx = ctx;
        u->sc = sc;
        lm_updater_knobs_resolve(&d, &u->knobs);
        u->seen = calloc((size_t)(sc->atlas.surface_count > 0 ? sc->atlas.surface_count : 1), sizeof *u->seen);
        st = u->seen ? lm_frame_loop_create(&sc->world, &set, &u->loop, &u->setup,
                                            &u->t_setup_gather, &e)
                     : lm_fail(&e, LM_ERR_NOMEM, "no memory for an updater");
    }
    if (st == LM_OK)
        lm_info("%s: updater ready: %u photons, %u texels gathered in %.0f ms", sc->scene->path,
                lm_photons_count(lm_photon_stage_photons(lm_frame_loop_stage(u->loop))), sc->atlas.texel_count,
                1e3 * u->t_setup_gather);
    lm_api_leave(saved);
    if (st != LM_OK) {
        if (u)
            free(u->seen);
        free(u);
        return lm_export_error(err, &e);
    }
    const uint32_t *ver = lm_frame_loop_surface_versions(u->loop);
    memcpy(u->seen, ver, sizeof *u->seen * (size_t)sc->atlas.surface_count);
    ctx->updaters++;
    sc->updater = u;
    sc->loop = u->loop;
    sc->ctx = ctx;
    *out = u;
    return LMGI_OK;
}

lmgi_status lmgi_updater_create(lmgi_context *ctx, lmgi_scene *sc, const lmgi_updater_desc *desc, lmgi_updater **out,
                                lmgi_error *err)
{
    if (out)
        *out = NULL;
    if (!ctx)
        return lm_api_refuse(err, "lmgi_updater_create: context is NULL");
    lmgi_status st = lm_api_claim(ctx, "lmgi_updater_create", err);
    if (st != LMGI_OK)
        return st;
    if (sc) /* its settings follow the scene with the edits made so far */
        st = lm_scene_commit(sc, err);
    if (st == LMGI_OK)
        st = updater_create_owned(ctx, sc, desc, out, err);
    lm_api_release(ctx);
    return st;
}

const lmgi_scene *lm_updater_scene(const lmgi_updater *u) { return u->sc; }

lmgi_context *lm_updater_context(const lmgi_updater *u) { return u->ctx; }
lm_frame_loop *lm_updater_loop(const lmgi_updater *u) { return u->loop; }

void lmgi_updater_free(lmgi_updater *u)
{
    if (!u)
        return;
    lmgi_error e;
    if (lm_api_claim(u->ctx, "lmgi_updater_free", &e) != LMGI_OK) { /* kept: freed under the other thread's feet
                                                                        * it would crash there */
        lm_log(LM_LOG_ERROR, "%s; the updater is not freed", e.message);
        return;
    }
    lmgi_context *ctx = u->ctx;
    lm_log_target saved = lm_api_enter(u->ctx);
    lm_gl_make_current(u->ctx->gl, NULL); /* the loop's GL objects are deleted in its context */
    lm_lightmap_texture_free(u->texture);
    lm_frame_loop_free(u->loop);
    lm_api_leave(saved);
    u->ctx->updaters--;
    u->sc->updater = NULL;
    u->sc->loop = NULL;
    u->sc->ctx = NULL;
    free(u->seen);
    free(u);
    lm_api_release(ctx);
}

lm_lightmap_texture **lm_updater_texture(lmgi_updater *u) { return &u->texture; }


/* The photons of the largest group of any light (a light's P_e photons in G groups: ceil(P_e / G)). */
static uint32_t largest_group(const lm_photons *ph)
{
    uint32_t g = lm_photons_groups_per_emitter(ph), most = 0;
    for (int e = 0; g && (uint32_t)e < lm_photons_group_count(ph) / g; e++) {
        uint32_t m = (lm_photons_emitter_photons(ph, e) + g - 1) / g;
        most = m > most ? m : most;
    }
    return most;
}

/* The lmgi_aim_direct value of exact_direct (lm_exact_direct_of's inverse). */
static lmgi_aim_direct aim_direct_of(int exact)
{
    return exact == LM_EXACT_NONE        ? LMGI_AIM_DIRECT_PHOTONS
           : exact == LM_EXACT_EMITTERS ? LMGI_AIM_DIRECT_EMITTERS
           : exact == LM_EXACT_ALL      ? LMGI_AIM_DIRECT_ALL
                                        : LMGI_AIM_DIRECT_SUNS;
}

void lmgi_get_updater_info(const lmgi_updater *u, lmgi_updater_info *info)
{
    if (!info)
        return;
    memset(info, 0, sizeof *info);
    if (!u)
        return;
    /* the knobs as resolved from the desc, then what the scene chose where the desc left it */
    const lmgi_updater_desc *k = &u->knobs;
    info->photons = k->photons, info->aim = k->aim, info->gather = k->gather;
    info->caustics = k->caustics, info->frame = k->frame, info->tiled = k->tiled;
    const lm_frame_loop_settings *s = lm_frame_loop_get_settings(u->loop);
    info->gather.coverage = s->gather.coverage_samples;
    info->gather.scheme = (lmgi_gather_scheme)(s->gather.scheme + 1);
    info->aim.direct = aim_direct_of(s->stage.exact_direct);
    info->gather.emitter_light = s->emitter_light ? LMGI_EMITTERS_CLOSED_FORM : LMGI_EMITTERS_DRAWN;
    info->tiled.radius = lm_frame_loop_photon_radius(u->loop);
    info->gather_scheme = lm_gather_scheme_name(s->gather.scheme);
    info->emissive_triangles = lm_emissive_triangle_count(u->sc->scene);
    info->emitters_closed_form = s->emitter_light;
    info->stored_photons = s->indirect /* else one untraced photon a light */
                               ? lm_photons_count(lm_photon_stage_photons(lm_frame_loop_stage(u->loop))) : 0;
    if (!info->photons.count) /* chosen from the groups and the scene's floor */
        info->photons.count = info->stored_photons;
    if (!info->photons.per_group && s->indirect) /* the count's split: the largest group's photons */
        info->photons.per_group = largest_group(lm_photon_stage_photons(lm_frame_loop_stage(u->loop)));
    info->ms_setup_trace = 1e3 * u->setup.t_photons;
    info->ms_setup_aim = 1e3 * u->setup.t_aim;
    info->ms_setup_gather = 1e3 * u->t_setup_gather;
    static const char *const paths[4] = {"lightmap", "bruteforce", "tiled", "hashgrid"};
    info->indirect = s->indirect_path >= 0 && s->indirect_path < 4 ? paths[s->indirect_path] : "lightmap";
    const lm_emitters *em = lm_photon_stage_emitters(lm_frame_loop_stage(u->loop));
    for (int e = 0; em && e < em->count; e++)
        info->portals_found += em->e[e].portals ? (int)em->e[e].portals->found / 2 : 0;
}

static int count_changed(lmgi_updater *u)
{
    const uint32_t *ver = lm_frame_loop_surface_versions(u->loop);
    int changed = 0;
    for (int s = 0; s < u->sc->atlas.surface_count; s++) {
        changed += ver[s] != u->seen[s];
        u->seen[s] = ver[s];
    }
    return changed;
}

static void export_stats(const lm_frame_stats *fs, int changed, lmgi_update_stats *o)
{
    const lm_photon_stage_frame *st = &fs->stage;
    memset(o, 0, sizeof *o);
    o->frame = st->frame;
    o->time = st->time;
    o->photons_retraced = st->photons.rr_photons + st->photons.group_photons + st->photons.box_photons +
                          st->caught_up.group_photons;
    o->groups_invalidated = st->photons.groups_invalidated;
    o->groups_retraced = st->photons.groups_retraced + st->caught_up.groups_retraced;
    o->groups_at_once = st->caught_up.groups_retraced;
    o->placements_caught_up = st->placed;
    o->lights_scaled = st->emitters_scaled;
    o->lights_lit = st->emitters_lit;
    o->aim_surfaces_refreshed = st->aim.surfaces_refreshed;
    o->aim_surfaces_at_once = st->aim_at_once;
    o->texels_gathered = fs->texels_gathered;
    o->texels_estimated = fs->texels_estimated;
    o->texels_based = fs->texels_based;
    o->texels_budget = fs->plan.texels;
    o->surfaces_changed = changed;
    o->caustic_photons_retraced = st->caustics.traced;
    o->caustic_tiles = fs->caustic.tiles;
    o->caustic_tiles_lit = fs->caustic.tiles_lit;
    o->caustic_pixels_filtered = fs->caustic.pixels_filtered;
    o->caustic_photons_landed = fs->caustic_landed;
    o->caustic_photons_thin = fs->caustic_thin;
    o->cube_faces_rendered = fs->cube_faces;
    o->planar_maps_rendered = fs->plane_maps;
    o->shadow_maps_rendered = fs->shadow_maps;
    o->shadow_maps_stale = fs->shadow_maps_stale;
    o->photon_gathers = fs->photon_gathers;
    o->photon_entries = fs->photon_gathers ? fs->photon_gather.entries : 0;
    o->photon_pages_uploaded = fs->photon_gather.pages_uploaded;
    o->ms_animate = 1e3 * st->t_animate;
    o->ms_trace = 1e3 * st->t_photons;
    o->ms_aim = 1e3 * st->t_aim;
    o->ms_caustic_trace = 1e3 * st->t_caustics;
    o->ms_photons = 1e3 * fs->t_photons;
    o->ms_gather = 1e3 * fs->t_gather;
    o->ms_blend = 1e3 * fs->t_blend;
    o->ms_direct = 1e3 * fs->t_direct;
    o->ms_caustics = 1e3 * fs->t_caustics;
    o->ms_reflections = 1e3 * fs->t_reflections;
    o->ms_composite = 1e3 * fs->t_composite;
    o->ms_total = 1e3 * fs->t_total;
    o->ms_light_scale = 1e3 * fs->t_light_scale;
    o->ms_estimates = 1e3 * fs->t_estimates;
    o->light_scale_rays = fs->scale_rays > UINT32_MAX ? UINT32_MAX : (uint32_t)fs->scale_rays;
    o->busiest_stage = lm_stage_name(fs->busiest);
    snprintf(o->why, sizeof o->why, "%s", fs->why);
}

static void bake_progress(void *user, double fraction, const char *stage)
{
    const lmgi_bake_desc *d = user;
    d->progress(d->progress_user, (float)fraction, stage);
}

static lmgi_status bake_owned(lmgi_updater *u, const lmgi_bake_desc *desc, lmgi_bake_report *report, lmgi_error *err)
{
    lmgi_bake_desc d;
    memset(&d, 0, sizeof d);
    if (desc)
        d = *desc;
    if (report)
        memset(report, 0, sizeof *report);
    if (!u)
        return lm_api_refuse(err, "lmgi_bake: updater is NULL");
    if (!isfinite(d.time))
        return lm_api_refuse(err, "lmgi_bake: time %g is not a finite number", (double)d.time);
    lm_log_target saved = lm_api_enter(u->ctx);
    lm_bake_stats bs;
    lm_error e;
    lm_status st = lm_frame_loop_bake(u->loop, d.time, d.fresh_plan != 0, d.progress ? bake_progress : NULL, &d,
                                      d.cancel, &bs, &e);
    if (st == LM_OK)
        lm_info("%s: bake: %u of %u photon paths changed, %d AIM surfaces, %u texels (%d surfaces for what they "
                "see), %d surfaces changed", u->sc->scene->path, bs.photons_changed, bs.photons_traced,
                bs.aim_surfaces_refreshed, bs.texels_gathered, bs.surfaces_seeing, bs.surfaces_changed);
    lm_api_leave(saved);
    count_changed(u); /* the bake's changes are not the next update's */
    if (report) {
        report->photons_traced = bs.photons_traced;
        report->photons_changed = bs.photons_changed;
        report->aim_surfaces_refreshed = bs.aim_surfaces_refreshed;
        report->texels_gathered = bs.texels_gathered;
        report->surfaces_seeing = bs.surfaces_seeing;
        report->surfaces_changed = bs.surfaces_changed;
        report->ms_photons = 1e3 * bs.t_photons;
        report->ms_gather = 1e3 * bs.t_gather;
        report->ms_total = report->ms_photons + report->ms_gather;
    }
    return st == LM_OK ? LMGI_OK : lm_export_error(err, &e);
}

lmgi_status lmgi_bake(lmgi_updater *u, const lmgi_bake_desc *desc, lmgi_bake_report *report, lmgi_error *err)
{
    if (!u)
        return lm_api_refuse(err, "lmgi_bake: the updater is NULL");
    lmgi_status st = lm_api_claim(u->ctx, "lmgi_bake", err);
    if (st != LMGI_OK)
        return st;
    st = bake_owned(u, desc, report, err);
    lm_api_release(u->ctx);
    return st;
}

static lmgi_status get_caustics_owned(lmgi_updater *u, float *rgb, size_t floats, int *width, int *height,
                                      lmgi_error *err);
static lmgi_status get_lightmap_owned(lmgi_updater *u, const char *fn, lmgi_lightmap kind, const int rect[4],
                                      float *rgba, size_t floats, lmgi_error *err);

static size_t count_not_finite(const float *v, size_t n)
{
    size_t bad = 0;
    for (size_t i = 0; i < n; i++)
        bad += !isfinite(v[i]);
    return bad;
}

/* Which stage made a frame's NaN or infinity: the lightmaps and caustics it composited are read back
 * and counted (only on failure: a frame is scanned each update, the rest never otherwise). */
static void name_the_stage(lmgi_updater *u, char *out, size_t size)
{
    lmgi_info in;
    lmgi_get_info(u->sc, &in);
    size_t n = 4 * (size_t)in.atlas_width * in.atlas_height;
    int w, h;
    lmgi_frame(u, &w, &h);
    size_t nc = 3 * (size_t)w * (size_t)h;
    float *buf = malloc((n > nc ? n : nc) * sizeof *buf);
    static const struct { lmgi_lightmap kind; const char *what; } maps[2] = {
        {LMGI_LIGHTMAP_AIM, "the AIMs (photon estimate)"}, {LMGI_LIGHTMAP_IIM, "the IIM lightmap (the gather)"}};
    snprintf(out, size, "none of the lightmaps or caustics has one: the direct light, reflections or composite "
             "made them");
    for (int k = 0; buf && k < 3; k++) {
        lmgi_error e;
        lmgi_status got = k < 2 ? get_lightmap_owned(u, "lmgi_update", maps[k].kind, NULL, buf, n, &e)
                                : get_caustics_owned(u, buf, nc, NULL, NULL, &e);
        size_t bad = got == LMGI_OK ? count_not_finite(buf, k < 2 ? n : nc) : 0;
        if (bad) { /* the earliest stage that has them: the later ones only carry them on */
            snprintf(out, size, "the first stage that has them: %s, %zu values", k < 2 ? maps[k].what : "the caustic pass",
                     bad);
            break;
        }
    }
    free(buf);
}

/* An update whose frame holds a NaN or infinity fails, naming the stage, rather than pass it on. */
static lmgi_status check_frame(lmgi_updater *u, float time, lmgi_error *err)
{
    int w, h;
    const float *img = lmgi_frame(u, &w, &h);
    size_t bad = img ? count_not_finite(img, 3 * (size_t)w * (size_t)h) : 0;
    if (!bad)
        return LMGI_OK;
    char stage[200];
    name_the_stage(u, stage, sizeof stage);
    lm_error e;
    lm_fail(&e, LM_ERR_BACKEND, "%s: update at t = %g: %zu of the frame's values are not finite numbers (NaN or "
            "infinity); %s", u->sc->scene->path, (double)time, bad, stage);
    return lm_export_error(err, &e);
}

static lmgi_status update_owned(lmgi_updater *u, float time, float budget_ms, lmgi_update_stats *stats, lmgi_error *err)
{
    if (!u)
        return lm_api_refuse(err, "lmgi_update: updater is NULL");
    if (!isfinite(time))
        return lm_api_refuse(err, "lmgi_update: time %g is not a finite number", (double)time);
    if (!(budget_ms >= 0.0f) || !isfinite(budget_ms))
        return lm_api_refuse(err, "lmgi_update: budget %g ms must be a finite number >= 0 (0: texels_per_frame)",
                       (double)budget_ms);
    lm_frame_loop_set_budget(u->loop, budget_ms);
    lm_log_target saved = lm_api_enter(u->ctx);
    lm_frame_stats fs;
    lm_error e;
    lm_status st = lm_frame_loop_step(u->loop, time, &fs, &e);
    lm_api_leave(saved);
    if (st != LM_OK)
        return lm_export_error(err, &e);
    u->frames++;
    if (stats)
        export_stats(&fs, count_changed(u), stats);
    else
        count_changed(u);
    return check_frame(u, time, err);
}

lmgi_status lmgi_update(lmgi_updater *u, float time, float budget_ms, lmgi_update_stats *stats, lmgi_error *err)
{
    if (!u)
        return lm_api_refuse(err, "lmgi_update: the updater is NULL");
    lmgi_status st = lm_api_claim(u->ctx, "lmgi_update", err);
    if (st != LMGI_OK)
        return st;
    st = update_owned(u, time, budget_ms, stats, err);
    lm_api_release(u->ctx);
    return st;
}

const float *lmgi_frame(const lmgi_updater *u, int *width, int *height)
{
    int w = 0, h = 0;
    const float *img = NULL;
    if (u && u->frames > 0 && lm_frame_loop_get_settings(u->loop)->width > 0) { /* a frame composited */
        w = lm_frame_loop_get_settings(u->loop)->width;
        h = lm_frame_loop_get_settings(u->loop)->height;
        img = lm_frame_loop_image(u->loop);
    }
    if (width)
        *width = w;
    if (height)
        *height = h;
    return img;
}

static lmgi_status get_caustics_owned(lmgi_updater *u, float *rgb, size_t floats, int *width, int *height, lmgi_error *err)
{
    int w = 0, h = 0;
    if (u)
        lm_frame_loop_caustics_size(u->loop, &w, &h);
    if (width)
        *width = w;
    if (height)
        *height = h;
    if (!u || !rgb)
        return lm_api_refuse(err, "lmgi_get_caustics: %s is NULL", !u ? "updater" : "rgb");
    size_t need = 3 * (size_t)w * (size_t)h;
    if (!w)
        return lm_api_refuse(err, "lmgi_get_caustics: the updater has drawn no picture yet");
    if (floats < need)
        return lm_api_refuse(err, "lmgi_get_caustics: %zu floats given, the %d x %d picture's caustics need %zu",
                             floats, w, h, need);
    lm_log_target saved = lm_api_enter(u->ctx);
    lm_error e;
    lm_status st = lm_frame_loop_read_caustics(u->loop, rgb, &e);
    lm_api_leave(saved);
    return st == LM_OK ? LMGI_OK : lm_export_error(err, &e);
}

lmgi_status lmgi_get_caustics(lmgi_updater *u, float *rgb, size_t floats, int *width, int *height, lmgi_error *err)
{
    if (!u)
        return lm_api_refuse(err, "lmgi_get_caustics: the updater is NULL");
    lmgi_status st = lm_api_claim(u->ctx, "lmgi_get_caustics", err);
    if (st != LMGI_OK)
        return st;
    st = get_caustics_owned(u, rgb, floats, width, height, err);
    lm_api_release(u->ctx);
    return st;
}

static lmgi_status render_owned(lmgi_updater *u, const lmgi_camera *cam, int width, int height, float *rgb, lmgi_error *err)
{
    if (!u || !cam || !rgb)
        return lm_api_refuse(err, "lmgi_render: %s is NULL", !u ? "updater" : !cam ? "cam" : "rgb");
    if (width < 1 || height < 1 || width > 16384 || height > 16384)
        return lm_api_refuse(err, "lmgi_render: picture %d x %d must have sides in 1..16384", width, height);
    lm_view v;
    if (lm_api_view(u->sc, cam, "lmgi_render", &v, err) != LMGI_OK)
        return LMGI_ERR_INVALID;
    lm_log_target saved = lm_api_enter(u->ctx);
    lm_error e;
    lm_status st = lm_updater_render(u, &v, width, height, rgb, &e);
    lm_api_leave(saved);
    return st == LM_OK ? LMGI_OK : lm_export_error(err, &e);
}

lmgi_status lmgi_render(lmgi_updater *u, const lmgi_camera *cam, int width, int height, float *rgb, lmgi_error *err)
{
    if (!u)
        return lm_api_refuse(err, "lmgi_render: the updater is NULL");
    lmgi_status st = lm_api_claim(u->ctx, "lmgi_render", err);
    if (st != LMGI_OK)
        return st;
    st = render_owned(u, cam, width, height, rgb, err);
    lm_api_release(u->ctx);
    return st;
}

lm_status lm_updater_render(lmgi_updater *u, const lm_view *v, int width, int height, float *rgb, lm_error *err)
{
    return lm_frame_loop_render(u->loop, v, width, height, rgb, err);
}

/* ---- the lightmaps, whole or a rectangle (lmgi_get_lightmap, lmgi_get_lightmap_rect) ---- */

static void whole_atlas(const lm_atlas *at, int r[4]) { r[0] = r[1] = 0, r[2] = at->width, r[3] = at->height; }

/* r grown by m texels on each side, clipped to the atlas. */
static void grow_clip(const lm_atlas *at, const int r[4], int m, int out[4])
{
    int x0 = r[0] - m > 0 ? r[0] - m : 0, y0 = r[1] - m > 0 ? r[1] - m : 0;
    int x1 = r[0] + r[2] + m < at->width ? r[0] + r[2] + m : at->width;
    int y1 = r[1] + r[3] + m < at->height ? r[1] + r[3] + m : at->height;
    out[0] = x0, out[1] = y0, out[2] = x1 - x0, out[3] = y1 - y0;
}

static void unite(int a[4], const int b[4])
{
    int x0 = a[0] < b[0] ? a[0] : b[0], y0 = a[1] < b[1] ? a[1] : b[1];
    int x1 = a[0] + a[2] > b[0] + b[2] ? a[0] + a[2] : b[0] + b[2];
    int y1 = a[1] + a[3] > b[1] + b[3] ? a[1] + a[3] : b[1] + b[3];
    a[0] = x0, a[1] = y0, a[2] = x1 - x0, a[3] = y1 - y0;
}

/* The window whose texels decide rect's values: the rect grown by the dilation's reach (a gutter texel
 * takes its value from texels that near), then every surface with a texel there, whole (an invalid
 * texel is filled from its own surface's texels, however far). */
static void window_for(const lmgi_scene *sc, const int rect[4], int win[4])
{
    const lm_atlas *at = &sc->atlas;
    int grown[4], last = -1;
    grow_clip(at, rect, lm_atlas_dilate_reach(at), grown);
    memcpy(win, grown, sizeof grown);
    for (int y = grown[1]; y < grown[1] + grown[3]; y++)
        for (int x = grown[0]; x < grown[0] + grown[2]; x++) {
            int i = at->texel_index[(size_t)y * at->width + x];
            if (i >= 0 && at->texels[i].surface != last)
                unite(win, sc->surface_rects + 4 * (last = at->texels[i].surface));
        }
}

/* Copies the rect's part of a window-sized image (channels floats a texel) into rgba's rgb. */
static void crop_rgb(const int win[4], const float *img, int channels, const int rect[4], float *rgba)
{
    for (int y = 0; y < rect[3]; y++)
        for (int x = 0; x < rect[2]; x++) {
            const float *v = img + channels * ((size_t)(rect[1] - win[1] + y) * win[2] + (rect[0] - win[0] + x));
            float *o = rgba + 4 * ((size_t)y * rect[2] + x);
            for (int c = 0; c < 3; c++)
                o[c] = v[channels == 1 ? 0 : c];
        }
}

/* The rect's validity as rgba's alpha, from the window's raw IIM: 1 on valid texels, 0 on gutters and on
 * texels inside or under geometry (back-face fraction over the limit: filled from their neighbours for
 * filtering, but not light anyone sees). */
static void rect_validity(const lmgi_updater *u, const int win[4], const float *raw, const int rect[4], float *rgba)
{
    const lm_atlas *at = &u->sc->atlas;
    float limit = lm_frame_loop_get_settings(u->loop)->gather.backface_limit;
    for (int y = 0; y < rect[3]; y++)
        for (int x = 0; x < rect[2]; x++) {
            int ax = rect[0] + x, ay = rect[1] + y;
            float a = raw[4 * ((size_t)(ay - win[1]) * win[2] + (ax - win[0])) + 3];
            rgba[4 * ((size_t)y * rect[2] + x) + 3] = at->texel_index[(size_t)ay * at->width + ax] >= 0 && !(a > limit);
        }
}

/* The displayed IIM in rect, invalid texels filled and gutters dilated, with validity as alpha. */
static lm_status read_iim_rect(const lmgi_updater *u, const int rect[4], float *rgba, lm_error *err)
{
    int win[4];
    window_for(u->sc, rect, win);
    float *raw = NULL;
    lm_status st = lm_frame_loop_read_iim_window(u->loop, win, &raw, err);
    if (st != LM_OK)
        return st;
    rect_validity(u, win, raw, rect, rgba);
    lm_iim_fill_invalid_window(&u->sc->atlas, raw, lm_frame_loop_get_settings(u->loop)->gather.backface_limit, win);
    crop_rgb(win, raw, 4, rect, rgba);
    free(raw);
    return LM_OK;
}

/* The AIM's radiance in rect, gutters dilated, with the IIM's validity as alpha: its texels under geometry
 * hold only the N-nearest estimate's spill from around them. */
static lm_status read_aim_rect(const lmgi_updater *u, const int rect[4], float *rgba, lm_error *err)
{
    const lm_atlas *at = &u->sc->atlas;
    int win[4];
    grow_clip(at, rect, lm_atlas_dilate_reach(at), win); /* no fill: the dilation's reach alone */
    float *rgb = malloc(3 * sizeof(float) * (size_t)win[2] * win[3]), *raw = NULL;
    if (!rgb)
        return lm_fail(err, LM_ERR_NOMEM, "no memory for the AIM read-back");
    lm_status st = lm_frame_loop_sync(u->loop, err); /* the AIM is the photon work's */
    if (st == LM_OK)
        st = lm_frame_loop_read_iim_window(u->loop, rect, &raw, err); /* for the validity alone */
    if (st == LM_OK) {
        rect_validity(u, rect, raw, rect, rgba);
        const float *aim = lm_aim_rgb(lm_photon_stage_aim(lm_frame_loop_stage(u->loop)));
        for (int y = 0; y < win[3]; y++)
            memcpy(rgb + 3 * (size_t)y * win[2], aim + 3 * ((size_t)(win[1] + y) * at->width + win[0]),
                   3 * sizeof(float) * (size_t)win[2]);
        lm_atlas_dilate_window(at, rgb, 3, lm_atlas_dilate_reach(at), win);
        crop_rgb(win, rgb, 3, rect, rgba);
    }
    free(raw);
    free(rgb);
    return st;
}

/* The displayed IIM read back into *raw (the caller frees it), and each texel's validity into rgba's
 * alpha, over the whole atlas: for the error and accuracy estimates, which compare against it. */
static lm_status read_raw_iim(const lmgi_updater *u, float **raw, float *rgba, lm_error *err)
{
    int whole[4];
    whole_atlas(&u->sc->atlas, whole);
    lm_status st = lm_frame_loop_read_iim_window(u->loop, whole, raw, err);
    if (st == LM_OK)
        rect_validity(u, whole, *raw, whole, rgba);
    return st;
}

/* The error estimate (lm_frame_loop_iim_error) in rgb, gutters dilated, with the IIM's validity as alpha. */
static lm_status read_error(const lmgi_updater *u, float *rgba, lm_error *err)
{
    const lm_atlas *at = &u->sc->atlas;
    size_t n = (size_t)at->width * at->height;
    float *e = malloc(n * sizeof *e), *raw = NULL;
    if (!e)
        return lm_fail(err, LM_ERR_NOMEM, "no memory for the error atlas");
    lm_status st = read_raw_iim(u, &raw, rgba, err); /* the validity, and what the estimate compares */
    if (st == LM_OK)
        st = lm_frame_loop_iim_error(u->loop, raw, e, err);
    if (st == LM_OK) {
        lm_atlas_dilate_gutters(at, e, 1);
        for (size_t i = 0; i < n; i++)
            rgba[4 * i] = rgba[4 * i + 1] = rgba[4 * i + 2] = e[i];
    }
    free(raw);
    free(e);
    return st;
}

/* The accuracy estimate (lm_frame_loop_accuracy), gutters dilated, with the IIM's validity as alpha. */
static lm_status read_accuracy(const lmgi_updater *u, float *rgba, lm_error *err)
{
    const lm_atlas *at = &u->sc->atlas;
    size_t n = (size_t)at->width * at->height;
    float *raw = NULL, *est = malloc(4 * n * sizeof *est);
    if (!est)
        return lm_fail(err, LM_ERR_NOMEM, "no memory for the accuracy estimate");
    lm_status st = read_raw_iim(u, &raw, rgba, err); /* the validity, and the IIM the estimate is relative to */
    if (st == LM_OK)
        st = lm_frame_loop_accuracy(u->loop, raw, est, err);
    if (st == LM_OK) {
        lm_atlas_dilate_gutters(at, est, 4);
        for (size_t i = 0; i < n; i++)
            memcpy(rgba + 4 * i, est + 4 * i, 3 * sizeof *rgba);
    }
    free(raw);
    free(est);
    return st;
}

/* The error and accuracy estimates are made over the whole atlas: read whole, then cut. */
static lm_status read_whole_rect(lmgi_updater *u, lmgi_lightmap kind, const int rect[4], float *rgba, lm_error *err)
{
    const lm_atlas *at = &u->sc->atlas;
    float *all = malloc(4 * sizeof(float) * (size_t)at->width * at->height);
    if (!all)
        return lm_fail(err, LM_ERR_NOMEM, "no memory for the %d x %d lightmap", at->width, at->height);
    lm_status st = kind == LMGI_LIGHTMAP_ERROR ? read_error(u, all, err) : read_accuracy(u, all, err);
    for (int y = 0; st == LM_OK && y < rect[3]; y++)
        memcpy(rgba + 4 * (size_t)y * rect[2], all + 4 * ((size_t)(rect[1] + y) * at->width + rect[0]),
               4 * sizeof(float) * (size_t)rect[2]);
    free(all);
    return st;
}

/* The lightmap of `kind` in rect (NULL: the whole atlas) into rgba, as `fn`, on a claimed context, its
 * arguments checked; values that are not finite are handed back as they are (name_the_stage counts them). */
static lmgi_status get_lightmap_owned(lmgi_updater *u, const char *fn, lmgi_lightmap kind, const int rect[4],
                                      float *rgba, size_t floats, lmgi_error *err)
{
    if (!rgba)
        return lm_api_refuse(err, "%s: rgba is NULL", fn);
    const lm_atlas *at = &u->sc->atlas;
    int r[4];
    whole_atlas(at, r);
    if (rect) {
        if (rect[0] < 0 || rect[1] < 0 || rect[2] < 1 || rect[3] < 1 || rect[2] > at->width - rect[0] ||
            rect[3] > at->height - rect[1])
            return lm_api_refuse(err, "%s: rectangle (%d, %d) %d x %d is not inside the %d x %d atlas", fn, rect[0],
                                 rect[1], rect[2], rect[3], at->width, at->height);
        memcpy(r, rect, sizeof r);
    }
    size_t need = 4 * (size_t)r[2] * r[3];
    if (floats < need)
        return lm_api_refuse(err, "%s: the buffer holds %zu floats; the %d x %d %s needs %zu", fn, floats, r[2], r[3],
                             rect ? "rectangle" : "atlas", need);
    if (kind < LMGI_LIGHTMAP_IIM || kind > LMGI_LIGHTMAP_ACCURACY)
        return lm_api_refuse(err, "%s: %d is not a lightmap kind", fn, (int)kind);
    if (kind == LMGI_LIGHTMAP_ACCURACY && !lm_photon_stage_aim(lm_frame_loop_stage(u->loop))->error)
        return lm_api_refuse(err, "%s: the accuracy estimate needs the updater made with desc.aim.error_estimate "
                             "LMGI_ON", fn);
    lm_log_target saved = lm_api_enter(u->ctx);
    lm_error e;
    lm_status st = kind == LMGI_LIGHTMAP_IIM     ? read_iim_rect(u, r, rgba, &e)
                   : kind == LMGI_LIGHTMAP_AIM   ? read_aim_rect(u, r, rgba, &e)
                   : rect                        ? read_whole_rect(u, kind, r, rgba, &e)
                   : kind == LMGI_LIGHTMAP_ERROR ? read_error(u, rgba, &e)
                                                 : read_accuracy(u, rgba, &e);
    lm_api_leave(saved);
    return st == LM_OK ? LMGI_OK : lm_export_error(err, &e);
}

/* lmgi_get_lightmap and lmgi_get_lightmap_rect: a lightmap is never handed on with a NaN or infinity in it. */
static lmgi_status get_lightmap(lmgi_updater *u, const char *fn, lmgi_lightmap kind, const int rect[4], float *rgba,
                                size_t floats, lmgi_error *err)
{
    lmgi_status st = lm_api_claim(u->ctx, fn, err);
    if (st != LMGI_OK)
        return st;
    st = get_lightmap_owned(u, fn, kind, rect, rgba, floats, err);
    lm_api_release(u->ctx);
    static const char *const stage[] = {"the IIM lightmap (the gather)", "the AIMs (the photon estimate)",
                                        "the error estimate", "the accuracy estimate"};
    size_t n = rect ? 4 * (size_t)rect[2] * rect[3] : 4 * (size_t)u->sc->atlas.width * u->sc->atlas.height;
    size_t bad = st == LMGI_OK ? count_not_finite(rgba, n) : 0;
    if (bad) {
        lm_error e;
        lm_fail(&e, LM_ERR_BACKEND, "%s: %zu values of %s are not finite numbers (NaN or infinity)",
                u->sc->scene->path, bad, stage[kind]);
        return lm_export_error(err, &e);
    }
    return st;
}

lmgi_status lmgi_get_lightmap(lmgi_updater *u, lmgi_lightmap kind, float *rgba, size_t floats, lmgi_error *err)
{
    if (!u)
        return lm_api_refuse(err, "lmgi_get_lightmap: the updater is NULL");
    return get_lightmap(u, "lmgi_get_lightmap", kind, NULL, rgba, floats, err);
}

lmgi_status lmgi_get_lightmap_rect(lmgi_updater *u, lmgi_lightmap kind, const int rect[4], float *rgba, size_t floats,
                                   lmgi_error *err)
{
    if (!u || !rect)
        return lm_api_refuse(err, "lmgi_get_lightmap_rect: %s is NULL", u ? "rect" : "the updater");
    return get_lightmap(u, "lmgi_get_lightmap_rect", kind, rect, rgba, floats, err);
}

int lmgi_surface_lightmap_rect(const lmgi_scene *sc, int surface, int rect[4])
{
    if (!lmgi_surface_rect(sc, surface, rect))
        return 0;
    int grown[4];
    grow_clip(&sc->atlas, rect, lm_atlas_dilate_reach(&sc->atlas), grown);
    memcpy(rect, grown, sizeof grown);
    return 1;
}

int lmgi_surface_count(const lmgi_scene *sc) { return sc ? sc->atlas.surface_count : 0; }

int lmgi_surface_rect(const lmgi_scene *sc, int surface, int rect[4])
{
    if (!rect)
        return 0;
    memset(rect, 0, 4 * sizeof *rect);
    if (!sc || surface < 0 || surface >= sc->atlas.surface_count || sc->surface_rects[4 * surface + 2] == 0)
        return 0;
    memcpy(rect, sc->surface_rects + 4 * surface, 4 * sizeof *rect);
    return 1;
}

uint32_t lmgi_surface_version(const lmgi_updater *u, int surface)
{
    if (!u || surface < 0 || surface >= u->sc->atlas.surface_count)
        return 0;
    return lm_frame_loop_surface_versions(u->loop)[surface];
}
