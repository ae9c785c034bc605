#include "lightmap_path.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../charts/atlas_dilate.h"
#include "../core/log.h"
#include "../core/timing.h"
#include "../core/vecmath.h"
#include "../gpu/gather/gather_error.h"
#include "../photonmap/delta_i.h"
#include "../photonmap/texel_change.h"
#include "../scene/sky.h"
#include "../trace/emitter_light.h"
#include "gather_passes.h"
#include "light_scale.h"
#include "ray_estimate.h"

struct lm_lightmap_path {
    lm_frame_loop_settings *set; /* the loop's, borrowed */
    lm_scene *scene;
    const lm_surfaces *surfaces;
    const lm_atlas *atlas;
    lm_rt *rt;
    lm_photon_stage *stage;
    lm_gather *gather;
    lm_iim iim;
    int have_iim;
    lm_emitter_light emitters; /* with have_emitters: the gather's closed-form emitter light */
    int have_emitters;
    uint32_t *texels;          /* scratch: the scheduled texels (atlas texel_count) */
    uint8_t *refreshed;        /* scratch: per surface, its AIM refreshed since the last schedule (before that,
                                * in follow_scale, whether its texels were scaled) */
    float *scale;              /* scratch: per surface x 3, what power edits scaled (lm_photon_stage_take_scale) */
    lm_light_scale scaling;    /* the last power edit's texel factors, refined within the budget */
    uint32_t scale_rays;       /* the rays its gathers may cast an update (0: no bound) */
    double scale_ms_plan;      /* and the milliseconds its refinement may take (0: no bound) */
    double scale_ms;           /* since lm_lightmap_path_take_scale_work: its time and rays */
    uint64_t scale_cast;
    lm_texel_change change;    /* with have_change (from the first gather on): texels ahead of surfaces */
    int have_change;
    lm_ray_estimate rays;      /* with have_rays (from the first change of the scene on, where waiting texels
                                * show an estimate): their own, from a few rays (ray_estimate.h) */
    int have_rays;
    uint32_t *ray_list;        /* scratch: the texels whose ray estimate an update brought up to date */
    uint32_t ray_budget;       /* at most this many an update (lm_lightmap_path_set_ray_budget) */
    uint32_t based;            /* the texels whose ray bases were taken since lm_lightmap_path_take_based */
    uint32_t estimated;        /* how many the last schedule did */
    double estimate_seconds;   /* and the seconds the ray estimates took in it, bases included */
    double update_seconds;     /* of those, the seconds of the waiting texels' estimates alone */
    int aim_stale;             /* the AIM changed since the gather last uploaded it */
    int caught_up;             /* the stage caught up with this step's placements before its gather */
    int placed_now;            /* and this step's widen saw them move, or saw moves since the last catch-up
                                * (a drag released): its gather catches up too (schedule) */
    int moved_uncaught;        /* widen saw nodes move since the stage last caught up */
    uint32_t switch_version;   /* the scene's pass_version the scheduler's switches follow */
    struct {                   /* whether the scene gives any light (follow_light): none, no gather */
        int unlit, emissive;   /* emissive: it has emissive triangles, as of the scene's emissive_version */
        uint32_t emissive_version;
    } light;
};

/* The photon store's delta_i is the IIM scheduler's input, reset once a surface is regathered. */
static lm_photon_store *store_of(lm_lightmap_path *lp) { return lm_photon_stage_store(lp->stage); }

static lm_gather_job job_of(const lm_lightmap_path *lp)
{
    return (lm_gather_job){lp->gather, lp->scene, lp->atlas, lp->texels, lp->iim.fresh_tex, lp->set};
}

/* The AIM as the gather reads it: without the direct part it computes when the gather computes that part
 * at its rays' hits (lm_gather_direct_at_hits), else whole. */
static const float *gather_aim(const lm_lightmap_path *lp)
{
    const lm_aim *aim = lm_photon_stage_aim(lp->stage);
    return lm_gather_direct_at_hits(lp->gather) ? lm_aim_rest_dilated_rgba(aim) : lm_aim_dilated_rgba(aim);
}

/* Uploads the current scene and, when they changed since the last upload, the AIMs: all the gather reads
 * of the photon stage, so that the stage may run again once this returns. */
static lm_status gather_prepare(lm_lightmap_path *lp, lm_error *err)
{
    lm_status st = lm_gather_set_scene(lp->gather, lp->scene, lp->atlas, err);
    if (lp->scene->has_sky) { /* a hemicube clears to one colour: a sky that is not uniform wants the rays scheme */
        float mean[3];
        lm_sky_mean(lp->scene, mean);
        lm_gather_set_sky(lp->gather, mean);
    }
    if (st == LM_OK && lp->aim_stale) {
        st = lm_gather_set_aim_dilated(lp->gather, lp->atlas, gather_aim(lp), err);
        /* the far hits' map, where only the near ones take the emitters' light (docs/gather.md, "Near and far
         * hits"); punctual lights alone are taken at every hit */
        const lm_direct_light *d = lm_photon_stage_direct(lp->stage);
        int far_map = lm_gather_direct_at_hits(lp->gather) && d && d->area;
        if (st == LM_OK)
            st = lm_gather_set_aim_whole(lp->gather, lp->atlas,
                                         far_map ? lm_aim_dilated_rgba(lm_photon_stage_aim(lp->stage)) : NULL, err);
    }
    if (st == LM_OK)
        lp->aim_stale = 0;
    return st;
}

lm_status lm_lightmap_path_gather(lm_lightmap_path *lp, uint32_t count, lm_error *err)
{
    lm_gather_job j = job_of(lp);
    return lm_gather_passes(&j, count, err);
}

/* The scene and AIM uploaded, then the first count scheduled texels gathered. */
static lm_status gather(lm_lightmap_path *lp, uint32_t count, lm_error *err)
{
    if (count == 0)
        return LM_OK;
    lm_status st = gather_prepare(lp, err);
    return st == LM_OK ? lm_lightmap_path_gather(lp, count, err) : st;
}

/* The first full gather of every texel (or of a shard's passes), checkpointed, resumed or put together
 * from parts when the settings name a checkpoint or parts. */
static lm_status first_gather(lm_lightmap_path *lp, lm_error *err)
{
    uint32_t count = lm_iim_sched_pick_all(&lp->iim.sched, store_of(lp), lp->texels);
    if ((!lp->set->checkpoint && !lp->set->parts) || count == 0)
        return gather(lp, count, err);
    lm_status st = gather_prepare(lp, err);
    if (st != LM_OK)
        return st;
    lm_gather_job j = job_of(lp);
    return lm_gather_first(&j, count, gather_aim(lp), err);
}

/* The closed-form emitter light when the settings (or, on auto, the scene) call for it; the gather's
 * coverage samples when on auto: none needed with it, else as the scene's emitters need. */
static lm_status setup_emitters(lm_lightmap_path *lp, lm_error *err)
{
    lm_frame_loop_settings *set = lp->set;
    int closed_form = set->emitter_light < 0 ? lm_emitter_light_suits(lp->scene) : set->emitter_light;
    closed_form = closed_form && lm_emissive_triangle_count(lp->scene) > 0;
    if (set->gather.coverage_samples == 0)
        set->gather.coverage_samples =
            set->gather.scheme == LM_GATHER_LAYERED ? 1 : lm_gather_coverage_for(lp->scene, closed_form);
    set->emitter_light = closed_form;
    if (!closed_form || !lm_frame_lightmap_path(set)) /* the gather's alone */
        return LM_OK;
    lm_status st = lm_emitter_light_init(&lp->emitters, lp->scene, lp->rt, set->emitter_rays, err);
    lp->have_emitters = st == LM_OK;
    return st;
}

/* Per surface, whether its node takes indirect light (extras "indirect", lmgi_set_node_effects): the
 * scheduler gathers only those (one switched on again is regathered in full). */
static void sync_gather_switches(lm_lightmap_path *lp)
{
    for (int k = 0; k < lp->surfaces->surface_count; k++) {
        int off = !lm_frame_lightmap_path(lp->set) || lp->light.unlit ||
                  !lp->scene->nodes[lp->surfaces->surfaces[k].node].settings.indirect;
        if (off != lp->iim.sched.off[k])
            lm_iim_sched_set_off(&lp->iim.sched, store_of(lp), k, off);
    }
}

/* Lights that shine: not removed or switched off. */
static uint32_t lights_on(const lm_scene *s)
{
    uint32_t n = 0;
    for (int i = 0; i < s->light_count; i++)
        n += !s->lights[i].removed && !s->lights[i].off;
    return n;
}

/* A scene without any light (no light on, no emissive triangle, no sky) has no indirect light: nothing is
 * gathered (lmgi info's "indirect: off"), and the IIM is cleared when the last light goes; the gather
 * starts again, every surface in full, when a light, an emissive material or a sky comes. Looked at each
 * frame: the lights and the sky at once, the emissive triangles when a class changed (pass_version). */
static lm_status follow_light(lm_lightmap_path *lp, lm_error *err)
{
    const lm_scene *s = lp->scene;
    if (lp->light.emissive_version != s->pass_version || !lp->have_iim) {
        lp->light.emissive = lm_emissive_triangle_count(s) > 0;
        lp->light.emissive_version = s->pass_version;
    }
    uint32_t lights = lights_on(s);
    int unlit = lights == 0 && !lp->light.emissive && !s->has_sky;
    if (unlit == lp->light.unlit && lp->have_iim)
        return LM_OK;
    lp->light.unlit = unlit;
    if (unlit)
        lm_log(LM_LOG_INFO, "%s: no light (no light on, no emissive material, no sky): the gather is skipped until "
               "one comes", s->path);
    if (!lp->have_iim)
        return LM_OK;
    sync_gather_switches(lp);
    if (unlit && lp->have_rays) /* what the texels saw is gone with the light; their regathers see anew */
        lm_ray_estimate_forget(&lp->rays);
    return unlit ? lm_iim_clear(&lp->iim, lp->atlas, err) : LM_OK;
}

lm_status lm_lightmap_path_follow(lm_lightmap_path *lp, lm_error *err)
{
    lm_status st = follow_light(lp, err);
    if (st == LM_OK && lp->switch_version != lp->scene->pass_version) {
        sync_gather_switches(lp);
        lp->switch_version = lp->scene->pass_version;
    }
    return st;
}

lm_status lm_lightmap_path_create(const lm_world *w, lm_photon_stage *stage, lm_frame_loop_settings *set,
                                  lm_lightmap_path **out, lm_error *err)
{
    *out = NULL;
    lm_lightmap_path *lp = calloc(1, sizeof *lp);
    if (!lp)
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for the lightmap path", w->scene->path);
    lp->set = set;
    lp->scene = w->scene;
    lp->surfaces = w->surfaces;
    lp->atlas = w->atlas;
    lp->rt = w->rt;
    lp->stage = stage;
    lm_light_scale_init(&lp->scaling);
    lp->texels = malloc(sizeof(uint32_t) * (w->atlas->texel_count ? w->atlas->texel_count : 1));
    lp->refreshed = malloc((size_t)w->atlas->surface_count + 1);
    lp->scale = malloc(sizeof *lp->scale * 3 * ((size_t)w->atlas->surface_count + 1));
    lm_status st = lp->texels && lp->refreshed && lp->scale ? LM_OK
                                               : lm_fail(err, LM_ERR_NOMEM, "%s: no memory for the frame loop",
                                                         w->scene->path);
    if (st == LM_OK)
        st = setup_emitters(lp, err);
    if (st == LM_OK)
        st = lm_gather_create(&set->gather, &lp->gather, err);
    if (st == LM_OK && lp->have_emitters)
        lm_gather_set_emitter_light(lp->gather, &lp->emitters);
    if (st == LM_OK) /* the rim outside the plane traced, not extrapolated (photonmap/hemicube_rim.h) */
        lm_gather_set_tracer(lp->gather, lp->rt);
    if (st == LM_OK && set->stage.direct_at_hits && lm_aim_rest_dilated_rgba(lm_photon_stage_aim(stage)))
        lm_gather_set_direct_at_hits(lp->gather, lm_photon_stage_direct(stage));
    if (st == LM_OK)
        st = follow_light(lp, err); /* before the IIM: a scene without light gathers nothing */
    set->iim.backface_limit = set->gather.backface_limit;
    if (st == LM_OK && (st = lm_iim_init(&lp->iim, lp->atlas, &set->iim, 1, err)) == LM_OK) {
        lp->have_iim = 1;
        lm_gather_set_turn(lp->gather, lp->iim.turn_tex); /* the footprint texels' turns, where there are any */
        sync_gather_switches(lp); /* nodes without indirect light are not gathered at all */
        lp->switch_version = lp->scene->pass_version;
    }
    if (st != LM_OK) {
        lm_lightmap_path_free(lp);
        return st;
    }
    *out = lp;
    return LM_OK;
}

void lm_lightmap_path_free(lm_lightmap_path *lp)
{
    if (!lp)
        return;
    if (lp->have_iim)
        lm_iim_free(&lp->iim);
    lm_gather_free(lp->gather);
    if (lp->have_emitters)
        lm_emitter_light_free(&lp->emitters);
    if (lp->have_change)
        lm_texel_change_free(&lp->change);
    if (lp->have_rays)
        lm_ray_estimate_free(&lp->rays);
    free(lp->ray_list);
    free(lp->texels);
    free(lp->refreshed);
    free(lp->scale);
    lm_light_scale_free(&lp->scaling);
    free(lp);
}

/* The bounced light as the next pass reads it: rho / pi times the IIM just gathered, per texel, dilated
 * into the gutters (out: RGBA, atlas-sized; rgb: atlas-sized scratch). The IIM holds everything but the
 * punctual lights' direct light (the sky seen, the emitters' light, the bounces), and the passes take
 * every punctual light at their hits: what the first pass reads from the AIMs and its hits, with the
 * photons' noise gathered once more. With whole (NULL: not wanted) the passes take the emitters' light at
 * their near hits too, as the first did ("Near and far hits"): out then leaves out what the gather added of
 * it at each texel (lm_gather_emitted_at), and whole is the map with it, for the far hits. Texels inside
 * geometry read the AIM the first pass read (aim, and aim_whole for whole). */
static lm_status bounce_map(lm_lightmap_path *lp, const float *aim, const float *aim_whole, float *rgb, float *out,
                            float *whole, lm_error *err)
{
    const lm_atlas *a = lp->atlas;
    float *iim;
    lm_status st = lm_lightmap_path_read_window(lp, (const int[4]){0, 0, a->width, a->height}, &iim, err);
    if (st != LM_OK)
        return st;
    size_t cells = (size_t)a->width * a->height;
    float limit = lp->set->gather.backface_limit;
    for (int map = whole ? 1 : 0; map >= 0; map--) { /* the whole map first, then the rest */
        memset(rgb, 0, sizeof *rgb * 3 * cells);
        const float *inside = map ? aim_whole : aim;
#pragma omp parallel for schedule(dynamic, 256) if (whole)
        for (int64_t i = 0; i < (int64_t)a->texel_count; i++) {
            const lm_texel *t = &a->texels[i];
            size_t at = (size_t)t->y * a->width + t->x;
            float kd[3], emitted[3] = {0.0f, 0.0f, 0.0f};
            lm_texel_kd(lp->scene, t, kd);
            int valid = iim[4 * at + 3] <= limit; /* else the gather saw back faces: it is inside geometry */
            if (valid && whole && !map)
                lm_gather_emitted_at(lp->gather, lp->scene, a, (uint32_t)i, emitted);
            for (int c = 0; c < 3; c++)
                rgb[3 * at + c] = valid ? kd[c] / LM_PI * (iim[4 * at + c] - emitted[c]) : inside[4 * at + c];
        }
        lm_atlas_dilated_rgba(a, rgb, map ? whole : out);
    }
    free(iim);
    return LM_OK;
}

/* Bounce passes (docs/gather.md, "Bounce passes"): every texel gathered again, as many times as the
 * settings say, each pass reading its bounced light from the last pass's IIM instead of the AIMs. A
 * photon estimate's noise (a few heavy photons that came in through a window) then reaches the lightmap
 * only through that many more gathers, each of which multiplies it by an albedo and spreads it over the
 * hemisphere. Only where the gather takes the punctual lights' direct light at its own hits (the rays
 * scheme): a hemicube reads it from the map, which the IIM does not hold. A shard holds part of the
 * first gather, and is refused them (lmgi_updater.c). The AIM is uploaded again for the next gather. */
static lm_status bounce_passes(lm_lightmap_path *lp, lm_error *err)
{
    const lm_atlas *a = lp->atlas;
    if (lp->set->bounce_passes <= 0 || a->texel_count == 0)
        return LM_OK;
    if (lp->set->gather.scheme != LM_GATHER_RAYS) {
        /* said, not warned: lmgi bake asks for one whatever the scheme resolves to */
        lm_log(LM_LOG_INFO, "%s: no bounce pass: they need the rays gather, which takes the punctual light at its "
               "hits (a hemicube reads that light from the map, which an IIM does not hold)", lp->scene->path);
        return LM_OK;
    }
    /* the map holds no punctual light: each is taken at the hits, the suns as before and the others too; where
     * the first pass took the emitters' light at its hits, so do the passes (their map then without it) */
    const lm_direct_light *d = lm_gather_direct_at_hits(lp->gather) ? lm_photon_stage_direct(lp->stage) : NULL;
    const float *aim = gather_aim(lp); /* what the first pass read, for the texels inside geometry */
    int emitters = d && d->area && lp->have_emitters;
    lm_direct_light every = lm_photon_stage_punctual_light(lp->stage);
    every.area = emitters ? d->area : NULL;
    lm_gather_set_direct_at_hits(lp->gather, &every);
    size_t cells = (size_t)a->width * a->height;
    float *rgb = malloc(sizeof *rgb * 3 * cells), *map = malloc(sizeof *map * 4 * cells);
    float *whole = emitters ? malloc(sizeof *whole * 4 * cells) : NULL;
    lm_status st = rgb && map && (whole || !emitters)
                       ? LM_OK
                       : lm_fail(err, LM_ERR_NOMEM, "%s: no memory for a bounce pass", lp->scene->path);
    for (int p = 0; st == LM_OK && p < lp->set->bounce_passes; p++) {
        lm_log(LM_LOG_INFO, "bounce pass %d of %d", p + 1, lp->set->bounce_passes);
        st = bounce_map(lp, aim, lm_aim_dilated_rgba(lm_photon_stage_aim(lp->stage)), rgb, map, whole, err);
        if (st == LM_OK)
            st = lm_gather_set_aim_dilated(lp->gather, a, map, err);
        if (st == LM_OK) /* NULL without the emitters at the hits: every hit takes the punctual lights */
            st = lm_gather_set_aim_whole(lp->gather, a, whole, err);
        if (st == LM_OK)
            st = lm_lightmap_path_gather(lp, lm_iim_sched_pick_all(&lp->iim.sched, store_of(lp), lp->texels), err);
        if (st == LM_OK)
            st = lm_iim_blend(&lp->iim, 1, err);
    }
    lm_gather_set_direct_at_hits(lp->gather, d);
    lp->aim_stale = 1;
    free(rgb);
    free(map);
    free(whole);
    return st;
}

/* Whether texels that wait show an estimate (iim.h, progressive refinement). */
static int shows_estimates(const lm_lightmap_path *lp)
{
    return lp->change.threshold >= 0.0f && lp->iim.set.spread > 0;
}

/* Whether the scene is made to change: a node that may move, or an animation. A level without either may
 * still be edited (its lights, materials, sky), but most are baked and shown as they are. */
static int may_change(const lm_scene *s)
{
    return lm_scene_any_node_moves(s) || s->animation_count > 0;
}

/* The texels' ray estimates begun (ray_estimate.h): every texel's base over the AIM the gathers so far read,
 * the scene still as they saw it (lm_lightmap_path_before_change). */
static lm_status start_rays(lm_lightmap_path *lp, lm_error *err)
{
    const lm_atlas *a = lp->atlas;
    lm_status st = lm_ray_estimate_init(&lp->rays, a->texel_count, lp->set->iim.estimate_rays, err);
    if (st != LM_OK)
        return st;
    if (!(lp->ray_list = malloc(sizeof *lp->ray_list * (a->texel_count ? a->texel_count : 1)))) {
        lm_ray_estimate_free(&lp->rays);
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for the texels' ray estimates", lp->scene->path);
    }
    lp->have_rays = 1;
    lm_ray_estimate_emitters(&lp->rays, lp->have_emitters ? lp->gather : NULL);
    lm_ray_estimate_nodes(&lp->rays, &lp->change);
    lm_light_scale_world w = {lp->scene, a, lp->rt, &lp->set->gather};
    for (uint32_t i = 0; i < a->texel_count; i++)
        lp->ray_list[i] = i;
    lm_ray_estimate_gathered(&lp->rays, &w, lm_aim_dilated_rgba(lm_photon_stage_aim(lp->stage)), lp->ray_list,
                             a->texel_count);
    lp->based += a->texel_count;
    return LM_OK;
}

/* The ray estimates of this update (ray_estimate.h): the bases of the `count` texels gathered now, over the
 * AIM they are gathered from, and of the `waiting` ones after them in lp->texels, some brought up to date and
 * shown. */
static void ray_estimates(lm_lightmap_path *lp, uint32_t count, uint32_t waiting, uint32_t budget)
{
    lp->estimated = 0;
    lp->estimate_seconds = lp->update_seconds = 0.0;
    if (!lp->have_rays)
        return;
    double t0 = lm_now();
    lm_light_scale_world w = {lp->scene, lp->atlas, lp->rt, &lp->set->gather};
    const float *aim = lm_aim_dilated_rgba(lm_photon_stage_aim(lp->stage));
    lm_iim_sight_gathered(&lp->iim, lp->atlas, lp->texels, count);
    lm_ray_estimate_gathered(&lp->rays, &w, aim, lp->texels, count);
    lp->based += count;
    double t1 = lm_now();
    const uint32_t *wait = lp->texels + count;
    float *change = malloc(sizeof *change * (waiting ? waiting : 1));
    for (uint32_t k = 0; change && k < waiting; k++)
        change[k] = lm_texel_change_of(&lp->change, wait[k]);
    /* the change is a share of the scene's mean irradiance (luminance): the rays' light sums the channels */
    float unit = 3.0f * (float)lp->change.mean_e;
    uint32_t m = change ? lm_ray_estimate_update(&lp->rays, &w, aim, wait, change, unit, waiting, budget, lp->ray_list)
                        : 0;
    free(change);
    lm_iim_set_sight(&lp->iim, lp->atlas, lp->ray_list, lp->rays.delta, lp->rays.base, lp->rays.fine,
                     LM_RAY_ESTIMATE_NEAR_RAYS, m);
    lp->estimated = m;
    double t2 = lm_now();
    lp->estimate_seconds = t2 - t0;
    lp->update_seconds = t2 - t1;
}

lm_status lm_lightmap_path_first(lm_lightmap_path *lp, double *t_gather, lm_error *err)
{
    double t0 = lm_now();
    lp->aim_stale = 1;
    lm_status st = first_gather(lp, err);
    lp->set->checkpoint = NULL; /* it holds the first gather; bounce passes are made again from it */
    if (st == LM_OK)
        st = lm_iim_blend(&lp->iim, 1, err);
    if (st == LM_OK) /* shown and cancellable as the first gather is */
        st = bounce_passes(lp, err);
    lp->set->progress = NULL; /* per-frame gathers are small */
    lp->set->cancel = NULL;
    if (st == LM_OK && !lp->have_change) { /* from here on every texel holds what it saw now */
        st = lm_texel_change_init(&lp->change, lp->scene, lp->atlas, lm_photon_stage_aim(lp->stage)->rgb,
                                  lp->set->iim.texel_change, err);
        lp->have_change = st == LM_OK;
    }
    if (st == LM_OK && may_change(lp->scene)) /* taken now, not in the first edit's update: a drag's first step */
        st = lm_lightmap_path_before_change(lp, err);
    lp->based = 0; /* the setup's own work, not an update's */
    lm_gl_finish(); /* the time holds the GPU's work too: the budget's first guess starts from it */
    if (t_gather)
        *t_gather = lm_now() - t0;
    return st;
}

lm_status lm_lightmap_path_before_change(lm_lightmap_path *lp, lm_error *err)
{
    if (!lp || !lp->have_change || lp->have_rays || !shows_estimates(lp) || lp->set->iim.estimate_rays <= 0)
        return LM_OK;
    return start_rays(lp, err);
}

void lm_lightmap_path_aim_changed(lm_lightmap_path *lp) { lp->aim_stale = 1; }

void lm_lightmap_path_caught_up(lm_lightmap_path *lp)
{
    lp->aim_stale = 1;
    lp->caught_up = 1;
}

/* The IIM's texels multiplied by factor and add added (texel_count x 3 each), surfaces with one changed
 * set in scaled. */
static void scale_iim(lm_lightmap_path *lp, const float *factor, const float *add, uint8_t *scaled)
{
    if (lp->have_rays)
        lm_ray_estimate_scale(&lp->rays, factor, add);
    lm_error e;
    if (lm_iim_scale(&lp->iim, lp->atlas, factor, add, scaled, &e) != LM_OK)
        lm_log(LM_LOG_WARN, "%s", e.msg); /* the regathers the scaled hits call for still come */
}

/* Per texel, 1 where every map the IIM blends (fresh, old, new, shown) is black: a light edit's factor
 * changes nothing there (NULL: no memory, or the maps could not be read; a warning says which). */
static uint8_t *black_texels(const lm_lightmap_path *lp)
{
    const lm_atlas *a = lp->atlas;
    size_t cells = (size_t)a->width * a->height;
    float *rgba = malloc(sizeof *rgba * 4 * cells);
    uint8_t *black = rgba ? malloc(a->texel_count ? a->texel_count : 1) : NULL;
    const unsigned tex[4] = {lp->iim.fresh_tex, lp->iim.old_tex, lp->iim.new_tex, lp->iim.display_tex};
    lm_error e;
    if (black)
        memset(black, 1, a->texel_count);
    for (int k = 0; black && k < 4; k++) {
        if (lm_iim_texture_read(tex[k], a->width, a->height, rgba, &e) != LM_OK) {
            lm_log(LM_LOG_WARN, "%s", e.msg);
            free(black);
            black = NULL;
            break;
        }
        for (uint32_t i = 0; i < a->texel_count; i++) {
            const float *v = rgba + 4 * ((size_t)a->texels[i].y * a->width + a->texels[i].x);
            black[i] &= v[0] == 0.0f && v[1] == 0.0f && v[2] == 0.0f;
        }
    }
    free(rgba);
    return black;
}

/* Lights or emitters changed in power alone, or materials edited, since the last call: each IIM texel
 * scaled by its own factor (light_scale.h; its surface's where that cannot be had), shown at the next
 * blend, and the AIM uploaded again before the next gather. Else the last such edit's factors refined,
 * a few surfaces an update, within the rays the plan gives them. */
static void follow_scale(lm_lightmap_path *lp)
{
    float *before = NULL, *emissive = NULL;
    int recoloured = lm_photon_stage_scale_recoloured(lp->stage);
    int edit = lm_photon_stage_take_scale(lp->stage, lp->scale, &before, &emissive);
    if (!edit && !lp->scaling.active)
        return;
    double t0 = lm_now();
    lm_light_scale_world w = {lp->scene, lp->atlas, lp->rt, &lp->set->gather};
    const float *after = lm_aim_dilated_rgba(lm_photon_stage_aim(lp->stage));
    size_t T = lp->atlas->texel_count;
    float *texel = lp->have_iim ? malloc(sizeof *texel * 7 * (T + 1)) : NULL, *add = texel ? texel + 3 * T : NULL;
    float *doubt = texel ? texel + 6 * T : NULL;
    uint8_t *scaled = lp->refreshed; /* scratch until lm_lightmap_path_widen takes the refreshed surfaces */
    if (!edit) {
        int corrected = 0;
        lp->scale_cast +=
            texel ? lm_light_scale_refine(&lp->scaling, &w, after, lp->scale_rays, lp->scale_ms_plan, texel, add,
                                          doubt, &corrected)
                  : 0;
        if (corrected)
            scale_iim(lp, texel, add, scaled);
        if (corrected && lp->have_change)
            lm_texel_change_doubt(&lp->change, doubt);
        free(texel);
        lp->scale_ms += 1e3 * (lm_now() - t0);
        return;
    }
    lp->aim_stale = 1;
    if (lp->have_change)
        lm_texel_change_scale(&lp->change, lp->atlas, lp->scale);
    if (texel) {
        uint32_t rays = lp->scale_rays && lp->scale_rays < LM_LIGHT_SCALE_LEAST ? LM_LIGHT_SCALE_LEAST : lp->scale_rays;
        lp->scale_cast += lm_light_scale_begin(&lp->scaling, &w, before, emissive, black_texels(lp), after, lp->scale,
                                               edit == 2, rays, texel, add, doubt);
        scale_iim(lp, texel, add, scaled);
        if (lp->have_change && recoloured)
            lm_texel_change_first_guess(&lp->change, texel, add);
        if (lp->have_change)
            lm_texel_change_doubt(&lp->change, doubt);
    } else {
        free(before);
        free(emissive);
        if (lp->have_iim)
            lm_log(LM_LOG_WARN, "%s: no memory to scale the lightmap after a light's edit: it follows by regathers",
                   lp->scene->path);
    }
    for (int k = 0; texel && k < lp->surfaces->surface_count; k++) /* scaled texels are regathered in the end */
        if (scaled[k] && !(store_of(lp)->surfaces[k].delta_i > lp->iim.sched.delta_threshold))
            lm_iim_sched_raise(&lp->iim.sched, store_of(lp), k);
    free(texel);
    lp->scale_ms += 1e3 * (lm_now() - t0);
}

int lm_lightmap_path_widen(lm_lightmap_path *lp)
{
    follow_scale(lp);
    int caught_up = lp->caught_up && lm_photon_stage_settled(lp->stage);
    lp->caught_up = 0;
    if (lp->have_change && caught_up) /* earlier moves' texels, gathered from AIMs the stage now caught up */
        lm_texel_change_settle(&lp->change);
    int moved = lp->have_change ? lm_texel_change_moved(&lp->change, lp->scene, lp->atlas, caught_up) : 0;
    lp->placed_now = (moved || lp->moved_uncaught) && caught_up;
    lp->moved_uncaught = (lp->moved_uncaught || moved) && !caught_up;
    /* not in the call that saw a move: the stage has yet to see it (its groups are queued by its update) */
    if (lp->have_change && !moved && lm_photon_stage_settled(lp->stage))
        lm_texel_change_settle(&lp->change);
    if (!lm_photon_stage_take_refreshed(lp->stage, lp->refreshed))
        return 0;
    if (lp->have_change)
        lm_texel_change_aim(&lp->change, &lp->iim.sched, lp->scene, lp->atlas, lp->rt,
                            lm_photon_stage_aim(lp->stage)->rgb, lp->refreshed);
    return lm_delta_i_widen_to_viewers(&lp->iim.sched, store_of(lp), lp->refreshed, lp->scene, lp->atlas, lp->rt);
}

static int by_index(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return x < y ? -1 : x > y;
}

/* Of the texels a surface's refresh hands out, those still waiting for a change of their own (over the
 * threshold) are committed on their own as those picked ahead are: held back for their surface's whole
 * refresh, their change cleared, they dropped the estimate they showed while waiting and went back to the
 * light from before the change for as long as the refresh lasted (a floor texel beside a moved cube's old
 * place, 65% dark, for the 65 updates the floor's 324 texels take at 5 an update). */
static void commit_waiting(lm_lightmap_path *lp, const uint32_t *texels, uint32_t n)
{
    if (!(lp->change.threshold >= 0.0f))
        return;
    uint32_t *list = malloc(sizeof *list * (n ? n : 1)), m = 0;
    if (!list) /* they wait for their surface's commit, as in the paper */
        return;
    for (uint32_t i = 0; i < n; i++)
        if (lm_texel_change_of(&lp->change, texels[i]) > lp->change.threshold)
            list[m++] = texels[i];
    lm_iim_commit_texels(&lp->iim, lp->atlas, list, m);
    free(list);
}

/* Texels into lp->texels: first at most `ahead` of those whose hemisphere changed most (texel_change.h),
 * committed on their own, then the surfaces' refreshes (iim_schedule.h: the budget left, or with `whole`,
 * a bake's, every candidate surface in full), which skip the texels picked ahead: no texel is listed
 * twice, so the atlas's texel_count holds them all. Those still over the threshold wait, shown with the
 * estimate of progressive refinement until gathered (iim.h). */
static uint32_t pick(lm_lightmap_path *lp, uint32_t budget, uint32_t ahead, int whole)
{
    uint32_t n = 0;
    if (lp->have_change && lp->change.threshold >= 0.0f) {
        n = lm_texel_change_pick(&lp->change, lp->atlas, lp->iim.sched.off, ahead < budget ? ahead : budget, whole,
                                 lp->texels);
        lm_iim_commit_texels(&lp->iim, lp->atlas, lp->texels, n);
        lm_iim_sched_gathered(&lp->iim.sched, lp->texels, n, 1);
    }
    uint32_t room = whole ? lp->atlas->texel_count : budget; /* a bake: every surface under way, whole */
    room = room < lp->atlas->texel_count ? room : lp->atlas->texel_count;
    uint32_t count = n + lm_iim_sched_pick_up_to(&lp->iim.sched, store_of(lp), room - n, lp->texels + n);
    uint32_t waiting = 0; /* after the list: none of them is in it (their change was zeroed) */
    if (lp->have_change) {
        if (!whole) /* a bake shows every surface it gathers at once */
            commit_waiting(lp, lp->texels + n, count - n);
        lm_texel_change_gathered(&lp->change, lp->texels + n, count - n);
        if (shows_estimates(lp)) /* else nothing shows them */
            waiting = lm_texel_change_waiting(&lp->change, lp->atlas, lp->iim.sched.off, lp->texels + count);
    }
    lm_iim_set_pending(&lp->iim, lp->atlas, lp->texels + count, waiting);
    if (!whole) /* a bake's texels take their bases once it is through (lm_lightmap_path_bake) */
        ray_estimates(lp, count, waiting, lp->ray_budget);
    lm_light_scale_regathered(&lp->scaling, lp->texels, count); /* fresh: a refined factor would spoil them */
    if (whole) /* a bake: in atlas order, so that where a texel lands in the gather's passes (and its
                * rounding) depends on which texels are gathered, not on how they were picked */
        qsort(lp->texels, count, sizeof *lp->texels, by_index);
    return count;
}

lm_status lm_lightmap_path_schedule(lm_lightmap_path *lp, uint32_t *count, lm_error *err)
{
    lm_lightmap_path_widen(lp);
    uint32_t budget = lp->iim.sched.texels_per_frame > 0 ? (uint32_t)lp->iim.sched.texels_per_frame : 0;
    uint32_t ahead = budget - budget / 4; /* a quarter left to the surfaces' refreshes */
    if (lp->placed_now) /* the move's texels caught up with its photons, shown at once (LM_CATCH_UP_UPDATES) */
        ahead *= LM_CATCH_UP_UPDATES, budget = ahead + budget / 4;
    *count = pick(lp, budget, ahead, 0);
    return *count > 0 ? gather_prepare(lp, err) : LM_OK;
}

lm_status lm_lightmap_path_blend(lm_lightmap_path *lp, int instant, lm_error *err)
{
    return lm_iim_blend(&lp->iim, instant || lp->placed_now, err);
}

/* The bake's gather reports through the settings' progress hook as a fraction of the whole bake. */
typedef struct {
    lm_bake_progress fn;
    void *user;
} bake_watch;

static void bake_gather_progress(void *user, uint32_t done, uint32_t total)
{
    const bake_watch *w = user;
    w->fn(w->user, 0.3 + 0.7 * (double)done / (total ? total : 1), "gather");
}

lm_status lm_lightmap_path_bake(lm_lightmap_path *lp, lm_bake_progress progress, void *user,
                                const volatile int *cancel, uint32_t *texels, int *surfaces_changed,
                                lm_error *err)
{
    lm_photon_store *ps = store_of(lp);
    int S = lp->iim.sched.surface_count;
    double *saved = malloc(sizeof *saved * (size_t)(S ? S : 1));
    size_t saved_floats = LM_TEXEL_CHANGE_SAVED * (size_t)lp->atlas->texel_count + 1;
    float *change = lp->have_change ? malloc(sizeof *change * saved_floats) : NULL;
    if (change) /* a cancelled bake gives back what it took, as delta_i */
        lm_texel_change_save(&lp->change, change);
    if (!saved || (lp->have_change && !change)) {
        free(saved);
        free(change);
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for the bake", lp->scene->path);
    }
    lm_iim_sched_restart(&lp->iim.sched, ps);
    lm_delta_i_save(&lp->iim.sched, ps, saved);
    if (lp->have_change) /* the bake's photons and AIMs have caught up with every move, this call's too */
        lm_texel_change_settle(&lp->change);
    uint32_t n = pick(lp, lp->atlas->texel_count, lp->atlas->texel_count, 1);
    bake_watch w = {progress, user};
    lp->set->progress = progress ? bake_gather_progress : NULL;
    lp->set->progress_user = &w;
    lp->set->cancel = cancel;
    lm_status st = gather(lp, n, err);
    lp->set->progress = NULL;
    lp->set->cancel = NULL;
    if (st != LM_OK) {
        lm_delta_i_restore(&lp->iim.sched, ps, saved);
        lm_iim_sched_gathered(&lp->iim.sched, lp->texels, n, 0);
        if (change)
            lm_texel_change_restore(&lp->change, change);
        lp->iim.list_count = 0;
    } else {
        uint32_t before = 0, after = 0;
        for (int s = 0; s < S; s++)
            before += lp->iim.version[s];
        ray_estimates(lp, n, 0, 0); /* what the bake's texels see now, their estimates' bases */
        st = lm_iim_blend(&lp->iim, 1, err);
        for (int s = 0; s < S; s++)
            after += lp->iim.version[s];
        *texels = n;
        *surfaces_changed = (int)(after - before);
        lm_light_scale_free(&lp->scaling); /* every texel a light edit's factors reached is regathered */
    }
    free(saved);
    free(change);
    return st;
}

lm_iim *lm_lightmap_path_iim(lm_lightmap_path *lp) { return &lp->iim; }
const lm_iim *lm_lightmap_path_iim_const(const lm_lightmap_path *lp) { return &lp->iim; }

void lm_lightmap_path_set_ray_budget(lm_lightmap_path *lp, uint32_t texels) { lp->ray_budget = texels; }
int lm_lightmap_path_has_rays(const lm_lightmap_path *lp) { return lp->have_rays; }

uint32_t lm_lightmap_path_take_based(lm_lightmap_path *lp)
{
    uint32_t n = lp->based;
    lp->based = 0;
    return n;
}

uint32_t lm_lightmap_path_estimated(const lm_lightmap_path *lp, double *seconds, double *waiting_seconds)
{
    if (seconds)
        *seconds = lp->estimate_seconds;
    if (waiting_seconds)
        *waiting_seconds = lp->update_seconds;
    return lp->estimated;
}

void lm_lightmap_path_set_texels_per_frame(lm_lightmap_path *lp, int texels)
{
    lp->iim.sched.texels_per_frame = texels > 0 ? texels : 0;
}

void lm_lightmap_path_set_scale_rays(lm_lightmap_path *lp, uint32_t rays, double ms)
{
    lp->scale_rays = rays;
    lp->scale_ms_plan = ms;
}

uint32_t lm_lightmap_path_scale_waiting(const lm_lightmap_path *lp)
{
    return lm_light_scale_waiting(&lp->scaling, lp->atlas);
}

uint64_t lm_lightmap_path_take_scale_work(lm_lightmap_path *lp, double *ms)
{
    uint64_t n = lp->scale_cast;
    *ms = lp->scale_ms;
    lp->scale_cast = 0;
    lp->scale_ms = 0.0;
    return n;
}

lm_status lm_lightmap_path_read_window(const lm_lightmap_path *lp, const int win[4], float **rgba, lm_error *err)
{
    size_t n = 4 * (size_t)win[2] * win[3];
    *rgba = malloc(n * sizeof(float));
    if (!*rgba)
        return lm_fail(err, LM_ERR_NOMEM, "no memory for the IIM read-back");
    lm_status st = lm_iim_texture_read_window(lp->iim.display_tex, win, *rgba, err);
    if (st != LM_OK) {
        free(*rgba);
        *rgba = NULL;
    }
    return st;
}

lm_status lm_lightmap_path_staleness(const lm_lightmap_path *lp, const float *shown, float *error, lm_error *err)
{
    const lm_atlas *a = lp->atlas;
    size_t n = (size_t)a->width * a->height;
    float *fresh = malloc(4 * n * sizeof *fresh);
    double *pending = calloc((size_t)(a->surface_count > 0 ? a->surface_count : 1), sizeof *pending);
    lm_status st = fresh && pending ? LM_OK : lm_fail(err, LM_ERR_NOMEM, "no memory for the error atlas");
    if (st == LM_OK)
        st = lm_iim_texture_read(lp->iim.fresh_tex, a->width, a->height, fresh, err);
    if (st == LM_OK) {
        const lm_photon_store *ps = lm_photons_store(lm_photon_stage_photons(lp->stage));
        for (int s = 0; s < a->surface_count; s++)
            pending[s] = lm_delta_i_pending(ps, s);
        float limit = lp->set->gather.backface_limit;
        double sum = 0.0;
        uint32_t valid = 0;
        for (uint32_t i = 0; i < a->texel_count; i++) {
            const float *p = shown + 4 * ((size_t)a->texels[i].y * a->width + a->texels[i].x);
            if (!(p[3] > limit))
                sum += lm_luminance(p), valid++;
        }
        double floor = 0.01 * (valid ? sum / valid : 0.0) + 1e-30;
        memset(error, 0, n * sizeof *error);
        for (uint32_t i = 0; i < a->texel_count; i++) {
            size_t at = (size_t)a->texels[i].y * a->width + a->texels[i].x;
            double f = lm_luminance(fresh + 4 * at), blend = fabs(f - lm_luminance(shown + 4 * at)) / fmax(fabs(f), floor);
            int k = a->texels[i].surface;
            double v = lp->iim.sched.off[k] ? 0.0 : fmax(blend, pending[k]); /* off: nothing to show */
            error[at] = isfinite(v) && v < 1e30 ? (float)v : 1.0f; /* past what can be said: all of it stale */
        }
    }
    free(fresh);
    free(pending);
    return st;
}

lm_status lm_lightmap_path_accuracy(const lm_lightmap_path *lp, const float *shown, float *out, lm_error *err)
{
    const lm_atlas *a = lp->atlas;
    const lm_aim *aim = lm_photon_stage_aim(lp->stage);
    if (!aim->error)
        return lm_fail(err, LM_ERR_INVALID, "the error estimate needs the AIMs' own (stage.aim.error_estimate)");
    float *source = malloc(4 * (size_t)a->width * a->height * sizeof *source);
    if (!source)
        return lm_fail(err, LM_ERR_NOMEM, "no memory for the error estimate");
    lm_gather_error_source(a, aim->rgb, aim->error, source);
    lm_gather_error(&lp->set->gather, lp->scene, a, lp->rt, source, aim->error, aim->set.kernel, shown,
                    LM_GATHER_ERROR_RAYS, out);
    free(source);
    return LM_OK;
}
