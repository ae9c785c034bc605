#include "frame_loop.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/memory.h"
#include "../core/timing.h"
#include "../scene/scene_view.h"
#include "budget_plan.h"
#include "frame_passes.h"
#include "light_scale.h"
#include "lightmap_path.h"
#include "ray_estimate.h"
#include "photon_path.h"
#include "stage_worker.h"

/* The conductor: the photon stage (on its worker with overlap), the indirect path the settings take and
 * the frame's passes, each owning its state; the loop keeps the order of their work and the threads. */
struct lm_frame_loop {
    lm_frame_loop_settings set;
    lm_world world;
    lm_gl_context *gl;
    int own_gl;              /* gl made here (else borrowed from the settings) */
    lm_photon_stage *stage;
    lm_stage_worker *worker; /* with settings.overlap: runs the stage's update beside the GL work */
    lm_photon_stage_frame pending; /* detached: the stage's job begun by the last step, not yet joined */
    int pending_busy;
    int pending_joined;            /* a sync joined it: its counts wait for the next step's report */
    lm_lightmap_path *lightmaps;   /* on every loop; every surface off unless on the lightmap path */
    lm_photon_path *photons;       /* on a photon path only */
    lm_frame_passes *passes;
    float *image;
    lm_view view;
    float budget_ms;             /* lm_frame_loop_set_budget's (0: the settings' fixed counts) */
    lm_budget budget;            /* each stage's cost per unit (budget_plan.h) */
    int steps;                   /* steps done */
    double t_before_change;      /* the seconds the last enter spent on lm_frame_loop_before_change */
};

int lm_frame_loop_atlas_texels(int texels_per_frame)
{
    long n = (long)texels_per_frame * LM_FRAME_LOOP_REFRESH_FRAMES;
    return n < 256 ? 256 : n > 1L << 28 ? 1 << 28 : (int)n;
}

/* Where the frames' indirect light comes from. */
static lm_frame_indirect indirect_of(const lm_frame_loop *fl)
{
    return (lm_frame_indirect){lm_frame_lightmap_path(&fl->set) ? lm_lightmap_path_iim_const(fl->lightmaps) : NULL,
                               fl->photons};
}

/* After edits, what follows lm_scene.pass_version and the lights: the lightmap path's switches and
 * light, the frame's passes. */
static lm_status follow_edits(lm_frame_loop *fl, lm_error *err)
{
    lm_status st = lm_lightmap_path_follow(fl->lightmaps, err);
    return st == LM_OK ? lm_frame_passes_follow(fl->passes, err) : st;
}

/* The start of a step, a bake or a picture: the GL context current, and the edits staged since the last
 * one committed (update/edits.h), after the photon work that reads the scene is waited for (a detached
 * step's, still running; none is when nothing is staged). */
static lm_status enter(lm_frame_loop *fl, lm_error *err)
{
    lm_status st = lm_gl_make_current(fl->gl, err);
    double t0 = lm_now();
    if (st == LM_OK && lm_edits_pending(fl->world.edits))
        st = lm_frame_loop_before_change(fl, err);
    fl->t_before_change = lm_now() - t0;
    return st == LM_OK ? lm_edits_commit(&fl->world, err) : st;
}

/* The settings' GL context made current, or one of the loop's own. */
static lm_status setup_gl(lm_frame_loop *fl, lm_error *err)
{
    if (fl->set.gl) {
        fl->gl = fl->set.gl;
        return lm_gl_make_current(fl->gl, err);
    }
    lm_status st = lm_gl_context_create(&fl->gl, err);
    fl->own_gl = st == LM_OK;
    return st;
}

/* GL context, the indirect paths and the frame's passes; then every texel gathered and shown at once. */
static lm_status setup_gpu(lm_frame_loop *fl, double *t_gather, lm_error *err)
{
    lm_status st = setup_gl(fl, err);
    if (st == LM_OK)
        st = lm_lightmap_path_create(&fl->world, fl->stage, &fl->set, &fl->lightmaps, err);
    if (st == LM_OK && lm_frame_photon_path(&fl->set))
        st = lm_photon_path_create(&fl->world, fl->stage, &fl->set, &fl->photons, err);
    if (st == LM_OK)
        st = lm_frame_passes_create(&fl->world, fl->stage, &fl->set, &fl->passes, err);
    if (st == LM_OK && fl->set.width > 0)
        st = lm_frame_passes_setup(fl->passes, err);
    double t = 0.0;
    if (st == LM_OK)
        st = lm_lightmap_path_first(fl->lightmaps, &t, err);
    if (t_gather)
        *t_gather = t;
    return st;
}

/* The budget's first guesses: the setup's full trace, AIM fill, caustic trace and gather per unit (small
 * per-step batches cost more per unit; the models correct themselves from the second step on), and a
 * cube face at half a millisecond until one is measured. */
static void seed_budget(lm_frame_loop *fl, const lm_photon_stage_frame *setup, double t_gather)
{
    const lm_photons *ph = lm_photon_stage_photons(fl->stage);
    uint32_t groups = ph ? lm_photons_group_count(ph) : 0, texels = fl->world.atlas->texel_count;
    double ms[LM_STAGE_PLANNED] = {
        [LM_STAGE_PHOTONS] = groups ? 1e3 * setup->t_photons / groups : 0.0,
        [LM_STAGE_AIM] = setup->aim.hits_used ? 1e3 * setup->t_aim / (double)setup->aim.hits_used : 0.0,
        [LM_STAGE_CAUSTICS] = setup->caustics.cast ? 1e3 * setup->t_caustics / setup->caustics.cast : 0.0,
        [LM_STAGE_REFLECTIONS] = 0.5,
        [LM_STAGE_GATHER] = texels ? 1e3 * t_gather / texels : 0.01,
    };
    lm_budget_seed(&fl->budget, ms);
}

/* What the frame loop adds per atlas texel to what lmgi_load holds (AIM, IIM double buffer, gather
 * tables, their GL textures): about 250 bytes, measured from 66k to 1M texels (peak RSS of lmgi run). */
#define FRAME_LOOP_BYTES_PER_TEXEL 250.0

lm_status lm_frame_loop_create(const lm_world *w, const lm_frame_loop_settings *set, lm_frame_loop **out,
                               lm_photon_stage_frame *setup, double *t_setup_gather, lm_error *err)
{
    *out = NULL;
    const lm_atlas *a = w->atlas;
    lm_frame_loop *fl = calloc(1, sizeof *fl);
    if (!fl)
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for the frame loop", w->scene->path);
    fl->set = *set;
    fl->set.stage.trace = fl->set.stage.trace && fl->set.indirect;
    fl->set.stage.caustics = fl->set.caustics;
    fl->set.stage.aims = fl->set.stage.aims && lm_frame_lightmap_path(&fl->set);
    fl->set.stage.direct_at_hits = fl->set.stage.aims && fl->set.gather.scheme == LM_GATHER_RAYS &&
                                   fl->set.gather.direct_at_hits; /* the rest is for the lightmap path's gather */
    fl->world = *w;
    char what[128];
    snprintf(what, sizeof what, "the lightmaps of %u texels (AIM, IIM, gather)", a->texel_count);
    lm_status st = lm_memory_plan(what, (double)a->texel_count * FRAME_LOOP_BYTES_PER_TEXEL, "a larger texel "
                                  "size (--texel-size) or fewer texels (--texels) makes it smaller", err);
    if (st == LM_OK) /* the edits' placements in the BVH the photons are traced in */
        st = lm_edits_commit(w, err);
    size_t n = 3 * (size_t)fl->set.width * fl->set.height;
    if (st == LM_OK && !(fl->image = malloc((n ? n : 1) * sizeof(float))))
        st = lm_fail(err, LM_ERR_NOMEM, "%s: no memory for the frame loop", w->scene->path);
    lm_photon_stage_frame first;
    memset(&first, 0, sizeof first);
    double t_gather = 0.0;
    if (st == LM_OK)
        st = lm_photon_stage_create(w, &fl->set.stage, &fl->stage, &first, err);
    if (st == LM_OK)
        st = setup_gpu(fl, &t_gather, err);
    if (st == LM_OK)
        seed_budget(fl, &first, t_gather);
    if (setup)
        *setup = first;
    if (t_setup_gather)
        *t_setup_gather = t_gather;
    if (st == LM_OK && fl->set.overlap)
        st = lm_stage_worker_start(fl->stage, &fl->worker, err);
    if (st != LM_OK) {
        lm_frame_loop_free(fl);
        return st;
    }
    *out = fl;
    return LM_OK;
}

void lm_frame_loop_free(lm_frame_loop *fl)
{
    if (!fl)
        return;
    lm_frame_loop_sync(fl, NULL);
    lm_stage_worker_stop(fl->worker);
    lm_frame_passes_free(fl->passes);
    lm_photon_path_free(fl->photons);
    lm_lightmap_path_free(fl->lightmaps);
    if (fl->own_gl)
        lm_gl_context_destroy(fl->gl);
    lm_photon_stage_free(fl->stage);
    free(fl->image);
    free(fl);
}

float lm_frame_loop_photon_radius(const lm_frame_loop *fl) { return fl->photons ? lm_photon_path_radius(fl->photons) : 0.0f; }

/* The step's own frame's view, its caustic photons, and on the photon paths their records, made while the
 * store is quiet (before the stage's worker starts: the frame shows the photons as the last stage left
 * them). */
static lm_status prepare_frame(lm_frame_loop *fl, lm_frame_stats *o, lm_error *err)
{
    int w = fl->set.width, h = fl->set.height;
    if (w <= 0)
        return LM_OK;
    lm_status st = lm_frame_passes_upload_caustics(fl->passes, err);
    if (st != LM_OK)
        return st;
    lm_view_for_scene(fl->world.scene, fl->set.camera, w, h, &fl->view);
    return fl->photons ? lm_photon_path_records(fl->photons, &o->photon_gather, err) : LM_OK;
}

/* The step's frame from the settings' camera (fl->view: prepare_frame's), when the loop draws frames. */
static lm_status render(lm_frame_loop *fl, lm_frame_stats *o, lm_error *err)
{
    if (fl->set.width <= 0)
        return LM_OK;
    lm_frame_indirect ind = indirect_of(fl);
    lm_status st = follow_edits(fl, err);
    return st == LM_OK ? lm_frame_passes_draw_step(fl->passes, &ind, &fl->view, fl->set.width, fl->set.height,
                                                   fl->image, o, err)
                       : st;
}

lm_status lm_frame_loop_render(lm_frame_loop *fl, const lm_view *view, int width, int height, float *rgb,
                               lm_error *err)
{
    lm_status st = enter(fl, err);
    if (st == LM_OK)
        st = lm_frame_passes_setup(fl->passes, err);
    /* the photon gather and the caustic photons read what the worker writes. A loop that draws frames of
     * its own shows the caustic photons its last frame showed (the step's lighting); one that draws none
     * takes the newest, waiting for the work that traces them */
    int newest = fl->set.width <= 0 && lm_frame_passes_want_caustics(fl->passes);
    if (st == LM_OK && (fl->photons || newest))
        st = lm_frame_loop_sync(fl, err);
    if (st == LM_OK && newest)
        st = lm_frame_passes_upload_caustics(fl->passes, err);
    lm_frame_stats o;
    memset(&o, 0, sizeof o);
    if (st == LM_OK && fl->photons)
        st = lm_photon_path_records(fl->photons, &o.photon_gather, err);
    if (st == LM_OK)
        st = follow_edits(fl, err);
    lm_frame_indirect ind = indirect_of(fl);
    /* the environment maps' faces due are refreshed by the steps' own frames; without those, here */
    int refresh = fl->set.width <= 0;
    return st == LM_OK ? lm_frame_passes_draw(fl->passes, &ind, view, width, height, rgb, 0, refresh, &o, err) : st;
}

/* The IIM's blend, timed into o. */
static lm_status blend(lm_frame_loop *fl, lm_frame_stats *o, lm_error *err)
{
    double t0 = lm_now();
    lm_status st = lm_lightmap_path_blend(fl->lightmaps, 0, err);
    o->t_blend = lm_now() - t0;
    return st;
}

/* Blend, then render. */
static lm_status blend_and_render(lm_frame_loop *fl, lm_frame_stats *o, lm_error *err)
{
    lm_status st = blend(fl, o, err);
    return st == LM_OK ? render(fl, o, err) : st;
}

/* The step's counts (budget_plan.h) for the work waiting once the animations played (moved lights queue
 * their groups), before the stage's update and the schedule: with a budget each stage's from its cost
 * model, without it the settings' own. */
static void plan(lm_frame_loop *fl, lm_frame_stats *o)
{
    lm_budget_plan *p = &o->plan;
    if (fl->budget_ms > 0.0f) {
        lm_budget_work w = {.faces = lm_frame_passes_faces(fl->passes), .texels = (int)fl->world.atlas->texel_count};
        lm_photon_stage_waiting(fl->stage, &w.groups, &w.caustic_photons);
        w.scale_edit = lm_photon_stage_scale_waiting(fl->stage);
        w.scale_rays = w.scale_edit ? LM_LIGHT_SCALE_WORK : lm_lightmap_path_scale_waiting(fl->lightmaps);
        w.ms_spent = 1e3 * o->t_waited;
        w.estimates_per_texel = lm_lightmap_path_has_rays(fl->lightmaps) ? LM_RAY_ESTIMATE_PER_TEXEL : 0;
        lm_budget_plan_step(&fl->budget, fl->budget_ms, &w, p);
    } else {
        memset(p, 0, sizeof *p);
        p->texels = fl->set.iim.texels_per_frame;
        p->estimates = LM_RAY_ESTIMATE_PER_TEXEL * (uint32_t)(p->texels > 0 ? p->texels : 0);
    }
    lm_photon_stage_limits l = {p->groups, p->aim_hits, p->caustic_photons};
    lm_photon_stage_limit(fl->stage, &l);
    lm_frame_passes_limit_faces(fl->passes, p->faces);
    lm_lightmap_path_set_texels_per_frame(fl->lightmaps, p->texels);
    lm_lightmap_path_set_ray_budget(fl->lightmaps, p->estimates);
    lm_lightmap_path_set_scale_rays(fl->lightmaps, p->scale_rays, p->ms[LM_STAGE_LIGHT_SCALE]);
}

/* Before the stage evaluates the scene's animations, which may move its nodes (no photon work runs). */
static lm_status before_animation(lm_frame_loop *fl, lm_error *err)
{
    return fl->world.scene->animation_count > 0 ? lm_lightmap_path_before_change(fl->lightmaps, err) : LM_OK;
}

/* Animations and the scene bounds that follow from them: written here, on the calling thread, before
 * anything that reads them (the photon thread's update among them) starts; then the step's plan. */
static lm_status animate(lm_frame_loop *fl, float t, lm_frame_stats *o, lm_error *err)
{
    double t0 = lm_now();
    lm_photon_stage_set_budgeted(fl->stage, fl->budget_ms > 0.0f);
    lm_status st = before_animation(fl, err);
    if (st == LM_OK)
        st = lm_photon_stage_animate(fl->stage, t, &o->stage, err);
    const lm_photon_stage_frame *f = &o->stage; /* an edit's own work, done at once */
    if (f->emitters_lit > 0 || f->emitters_scaled > 0 || f->materials_changed > 0 || f->aim_at_once > 0 ||
        f->placed)
        o->t_edits = lm_now() - t0;
    if (f->placed) /* a placement's catch-up: its AIMs reach this step's gather */
        lm_lightmap_path_caught_up(fl->lightmaps);
    lm_scene_update_bounds(fl->world.scene);
    plan(fl, o);
    return st;
}

/* The seconds of the photon stage's job (its tracing, AIM refreshes and caustic photons) in f so far. */
static double job_seconds(const lm_photon_stage_frame *f) { return f->t_photons + f->t_aim + f->t_caustics; }

/* The seconds a plan gave the photon stage's job; negative without a budget (no plan). */
static double job_planned(const lm_frame_loop *fl, const lm_budget_plan *p)
{
    return fl->budget_ms > 0.0f ? 1e-3 * (p->ms[LM_STAGE_PHOTONS] + p->ms[LM_STAGE_AIM] + p->ms[LM_STAGE_CAUSTICS])
                                : -1.0;
}

/* How far a job of `job` seconds ran past the `planned` it was given, at most the `waited` seconds the
 * step waited for it (lm_frame_stats.t_overrun). */
static double overrun(double planned, double job, double waited)
{
    double x = planned < 0.0 ? 0.0 : job - planned;
    x = x < waited ? x : waited;
    return x > 0.0 ? x : 0.0;
}

/* The stage's work of this step (or of the last one, overlapped) refreshed AIMs: the gather's are stale. */
static void note_stage(lm_frame_loop *fl, const lm_photon_stage_frame *f)
{
    if (f->aim.surfaces_refreshed > 0)
        lm_lightmap_path_aim_changed(fl->lightmaps);
}

/* The step's texels scheduled (lm_lightmap_path_schedule) and the waiting texels' estimates counted; *te
 * (may be NULL) gets the estimates' seconds, the gather's time wherever the step times its schedule. */
static lm_status schedule(lm_frame_loop *fl, lm_frame_stats *o, double *te, lm_error *err)
{
    lm_status st = lm_lightmap_path_schedule(fl->lightmaps, &o->texels_gathered, err);
    o->texels_estimated = lm_lightmap_path_estimated(fl->lightmaps, te, &o->t_estimates);
    return st;
}

/* The paper's order: photon stage, then the gather over its fresh AIMs, blend, render. */
static lm_status step_in_order(lm_frame_loop *fl, float t, lm_frame_stats *o, lm_error *err)
{
    double t0 = lm_now();
    lm_status st = animate(fl, t, o, err);
    double job = job_seconds(&o->stage), tu = lm_now();
    if (st == LM_OK)
        st = lm_photon_stage_update(fl->stage, &o->stage, err);
    o->t_overrun = overrun(job_planned(fl, &o->plan), job_seconds(&o->stage) - job, lm_now() - tu);
    note_stage(fl, &o->stage);
    if (st == LM_OK)
        st = prepare_frame(fl, o, err);
    double t1 = lm_now();
    if (st == LM_OK)
        st = schedule(fl, o, NULL, err);
    if (st == LM_OK)
        st = lm_lightmap_path_gather(fl->lightmaps, o->texels_gathered, err);
    o->t_photons = t1 - t0;
    o->t_gather = lm_now() - t1;
    return st == LM_OK ? blend_and_render(fl, o, err) : st;
}

/* Overlapped: animate, schedule and upload what the gather needs, gather and blend, then the photon
 * stage's tracing and AIM refresh run on the worker while this thread renders. The gather therefore
 * sees the AIMs and delta_i of the previous frame's stage (one frame later than in order; the IIM blends
 * over several frames anyway). Every result depends only on that fixed order, not on timing. The gather
 * runs before the worker starts: its CPU work (the emitter light's shadow rays, llvmpipe's vertex work
 * for one view per texel) is on the frame's critical path and slows down sharing the cores with the
 * stage, while the direct light, whose second rasterizer thread gains little, hides the stage as well
 * alone (docs/bench.md has the figures). So does the blend: its few small compute dispatches each wait for
 * a core, which the stage's threads hold (on two cores about 1 ms of the frame). */
static lm_status step_overlapped(lm_frame_loop *fl, float t, lm_frame_stats *o, lm_error *err)
{
    double t0 = lm_now();
    lm_status st = animate(fl, t, o, err);
    double te = 0.0; /* the ray estimates in the schedule: the gather's time, not the stage's */
    if (st == LM_OK)
        st = schedule(fl, o, &te, err);
    double t1 = lm_now();
    if (st == LM_OK)
        st = prepare_frame(fl, o, err);
    if (st != LM_OK)
        return st;
    st = lm_lightmap_path_gather(fl->lightmaps, o->texels_gathered, err);
    o->t_gather = lm_now() - t1 + te;
    if (st == LM_OK)
        st = blend(fl, o, err);
    double job = job_seconds(&o->stage);
    lm_stage_worker_begin(fl->worker, &o->stage);
    if (st == LM_OK)
        st = render(fl, o, err);
    double t4 = lm_now();
    lm_error worker_err;
    lm_status ws = lm_stage_worker_end(fl->worker, &worker_err);
    o->t_overrun = overrun(job_planned(fl, &o->plan), job_seconds(&o->stage) - job, lm_now() - t4);
    if (ws != LM_OK && st == LM_OK) {
        st = ws;
        if (err)
            *err = worker_err;
    }
    note_stage(fl, &o->stage);
    o->t_photons = (t1 - t0 - te) + (lm_now() - t4); /* what the frame spent on or waiting for the stage */
    return st;
}

/* Waits for the stage's job a detached step left running; `done` (may be NULL) gets its counts, or, when
 * a sync joined it before (lm_frame_loop_sync), that job's counts, which the step reports. */
static lm_status join_stage(lm_frame_loop *fl, lm_photon_stage_frame *done, lm_error *err)
{
    if (!fl->pending_busy) {
        if (done && fl->pending_joined)
            *done = fl->pending;
        fl->pending_joined = fl->pending_joined && !done;
        return LM_OK;
    }
    lm_status st = lm_stage_worker_end(fl->worker, err);
    fl->pending_busy = 0;
    fl->pending_joined = !done;
    note_stage(fl, &fl->pending);
    if (done)
        *done = fl->pending;
    return st;
}

lm_status lm_frame_loop_sync(lm_frame_loop *fl, lm_error *err) { return join_stage(fl, NULL, err); }

lm_status lm_frame_loop_before_change(lm_frame_loop *fl, lm_error *err)
{
    lm_status st = join_stage(fl, NULL, err);
    return st == LM_OK ? lm_lightmap_path_before_change(fl->lightmaps, err) : st;
}

int lm_frame_loop_busy(const lm_frame_loop *fl) { return fl->pending_busy; }

/* Detached (overlap without a frame of its own: a game draws between steps): the stage's job begun by
 * the last step is joined first, then animate, schedule, gather and blend as overlapped, and the next
 * job begins last and runs until the next step, the caller's own frame hiding it. The gather sees the
 * same AIMs and delta_i as overlapped (the previous step's stage), so the lightmaps are the same. */
static lm_status step_detached(lm_frame_loop *fl, float t, lm_frame_stats *o, lm_error *err)
{
    double t0 = lm_now();
    lm_photon_stage_frame done;
    memset(&done, 0, sizeof done);
    lm_status st = join_stage(fl, &done, err);
    o->t_waited = lm_now() - t0; /* before the plan: it knows what is left */
    if (st == LM_OK)
        st = animate(fl, t, o, err);
    /* the counts and times of the stage's work that finished in this step (begun by the last one), with
     * the AIM refreshes this step's edits made at once (animate) */
    o->stage.photons = done.photons;
    lm_aim_stats_add(&o->stage.aim, &done.aim);
    o->stage.caustics = done.caustics;
    o->stage.t_photons = done.t_photons;
    o->stage.t_aim += done.t_aim;
    o->stage.t_caustics = done.t_caustics;
    double te = 0.0; /* as in step_overlapped */
    if (st == LM_OK)
        st = schedule(fl, o, &te, err);
    double t1 = lm_now();
    o->t_photons = t1 - t0 - te;
    if (st == LM_OK)
        st = lm_lightmap_path_gather(fl->lightmaps, o->texels_gathered, err);
    o->t_gather = lm_now() - t1 + te;
    if (st == LM_OK)
        st = blend_and_render(fl, o, err); /* no frame: the blend alone */
    if (st == LM_OK) {
        fl->pending = o->stage;
        memset(&fl->pending.aim, 0, sizeof fl->pending.aim); /* the job counts its own refreshes */
        fl->pending.t_aim = 0.0;
        fl->pending_busy = 1;
        lm_stage_worker_begin(fl->worker, &fl->pending);
    }
    return st;
}

/* The photon stage's work in groups: those re-traced, and the animated boxes' photons (re-traced one by
 * one, lm_photons_retrace_boxes) as the groups of the mean size they make. */
static uint64_t photon_units(const lm_frame_loop *fl, const lm_photon_frame_stats *p)
{
    const lm_photons *ph = lm_photon_stage_photons(fl->stage);
    uint32_t photons = ph ? lm_photons_count(ph) : 0;
    return p->groups_retraced + (photons ? (uint64_t)llround((double)p->box_photons * lm_photons_group_count(ph) /
                                                            photons)
                                         : 0);
}

/* The stages' costs of a step, each over the units it did (the first step, which uploads everything,
 * is left out by the caller). */
static void learn(lm_frame_loop *fl, const lm_frame_stats *o)
{
    const lm_photon_stage_frame *f = &o->stage;
    const double ms[LM_STAGE_PLANNED] = {1e3 * f->t_photons,     1e3 * f->t_aim,
                                         1e3 * f->t_caustics,    1e3 * o->t_reflections,
                                         1e3 * (o->t_gather - o->t_estimates), 1e3 * o->t_light_scale,
                                         1e3 * o->t_estimates};
    const uint64_t units[LM_STAGE_PLANNED] = {photon_units(fl, &f->photons), f->aim.hits_used, f->caustics.cast,
                                              (uint64_t)o->cube_faces, o->texels_gathered, o->scale_rays,
                                              o->texels_estimated};
    lm_budget_learn(&fl->budget, ms, units, 1e3 * o->t_total, 1e3 * (o->t_edits + o->t_waited + o->t_overrun));
}

/* What the step's plan was, in words, for the why of its busiest stage. */
static void plan_words(const lm_frame_loop *fl, const lm_frame_stats *o, lm_stage s, char *out, size_t size)
{
    if (fl->budget_ms > 0.0f)
        snprintf(out, size, "budget %g ms, %.2f ms planned", (double)fl->budget_ms, o->plan.ms[s]);
    else
        snprintf(out, size, "fixed counts");
}

/* The stage that took the step's longest time, and why (lm_frame_stats.busiest, why). */
static void report(const lm_frame_loop *fl, lm_frame_stats *o)
{
    const lm_photon_stage_frame *f = &o->stage;
    const double t[LM_STAGE_COUNT] = {f->t_photons, f->t_aim, f->t_caustics, o->t_reflections,
                                      o->t_gather - o->t_estimates, o->t_light_scale, o->t_estimates,
                                      o->t_blend + o->t_direct + o->t_caustics + o->t_composite};
    lm_stage b = LM_STAGE_PHOTONS;
    for (int s = 1; s < LM_STAGE_COUNT; s++)
        b = t[s] > t[b] ? (lm_stage)s : b;
    o->busiest = b;
    char plan[64];
    plan_words(fl, o, b < LM_STAGE_PLANNED ? b : LM_STAGE_GATHER, plan, sizeof plan);
    char *w = o->why;
    size_t n = sizeof o->why;
    switch (b) {
    case LM_STAGE_PHOTONS:
        snprintf(w, n, "%u invalid photon groups re-traced, %u still waiting (%s)", f->photons.groups_retraced,
                 f->photons.pending_groups, plan);
        break;
    case LM_STAGE_AIM:
        snprintf(w, n, "%d AIM surfaces refreshed (%llu hits), %d still over their threshold (%s)",
                 f->aim.surfaces_refreshed, (unsigned long long)f->aim.hits_used, f->aim.surfaces_pending, plan);
        break;
    case LM_STAGE_CAUSTICS:
        snprintf(w, n, "%u caustic photons traced, %u pairs whole as their generator or light moved (%s)",
                 f->caustics.traced, f->caustics.pairs_moved, plan);
        break;
    case LM_STAGE_REFLECTIONS:
        snprintf(w, n, "%d environment map faces rendered (%s)", o->cube_faces, plan);
        break;
    case LM_STAGE_GATHER:
        snprintf(w, n, "%u texels gathered (%s)", o->texels_gathered, plan);
        break;
    case LM_STAGE_LIGHT_SCALE:
        snprintf(w, n, "a light edit's texel factors: %llu rays, %u still to cast (%s)",
                 (unsigned long long)o->scale_rays, lm_lightmap_path_scale_waiting(fl->lightmaps), plan);
        break;
    case LM_STAGE_ESTIMATES:
        snprintf(w, n, "%u waiting texels' ray estimates brought up to date (%s)", o->texels_estimated, plan);
        break;
    default:
        snprintf(w, n, "the frame's passes: blend %.2f ms, direct light %.2f ms, caustics %.2f ms, composite %.2f ms",
                 1e3 * o->t_blend, 1e3 * o->t_direct, 1e3 * o->t_caustics, 1e3 * o->t_composite);
    }
}

lm_status lm_frame_loop_step(lm_frame_loop *fl, float t, lm_frame_stats *out, lm_error *err)
{
    lm_frame_stats o;
    memset(&o, 0, sizeof o);
    double t0 = lm_now();
    lm_status st = enter(fl, err);
    if (st == LM_OK)
        st = follow_edits(fl, err);
    if (st == LM_OK)
        st = !fl->worker ? step_in_order(fl, t, &o, err)
             : fl->set.width > 0 ? step_overlapped(fl, t, &o, err) : step_detached(fl, t, &o, err);
    o.t_total = lm_now() - t0;
    o.t_edits += fl->t_before_change; /* a still level's first edit: the rays' bases (lightmap_path.h) */
    o.texels_based = lm_lightmap_path_take_based(fl->lightmaps);
    double scale_ms = 0.0;
    o.scale_rays = lm_lightmap_path_take_scale_work(fl->lightmaps, &scale_ms);
    o.t_light_scale = 1e-3 * scale_ms;
    if (st == LM_OK && fl->steps++ > 0)
        learn(fl, &o);
    report(fl, &o);
    if (out)
        *out = o;
    return st;
}

lm_status lm_frame_loop_bake(lm_frame_loop *fl, float t, int fresh_plan, lm_bake_progress progress, void *user,
                             const volatile int *cancel, lm_bake_stats *out, lm_error *err)
{
    memset(out, 0, sizeof *out);
    lm_status st = lm_frame_loop_sync(fl, err);
    if (st == LM_OK)
        st = enter(fl, err);
    if (st == LM_OK)
        st = follow_edits(fl, err);
    if (st != LM_OK)
        return st;
    if (progress)
        progress(user, 0.0, "photons");
    double t0 = lm_now();
    lm_photon_stage_frame f;
    memset(&f, 0, sizeof f);
    st = before_animation(fl, err);
    if (st == LM_OK)
        st = lm_photon_stage_converge(fl->stage, t, fresh_plan, &f, err);
    lm_scene_update_bounds(fl->world.scene);
    out->photons_traced = f.photons.group_photons;
    out->photons_changed = f.photons.photons_updated;
    out->aim_surfaces_refreshed = f.aim.surfaces_refreshed;
    note_stage(fl, &f);
    if (st == LM_OK) /* before a cancel can stop the bake: a later one must still regather them */
        out->surfaces_seeing = lm_lightmap_path_widen(fl->lightmaps);
    double t1 = lm_now();
    out->t_photons = t1 - t0;
    if (st == LM_OK && cancel && *cancel)
        st = lm_fail(err, LM_ERR_CANCELLED, "%s: cancelled after the photons", fl->world.scene->path);
    if (st == LM_OK) {
        if (progress)
            progress(user, 0.3, "gather");
        st = lm_lightmap_path_bake(fl->lightmaps, progress, user, cancel, &out->texels_gathered,
                                   &out->surfaces_changed, err);
    }
    lm_gl_finish(); /* the gather's time holds the GPU's work still queued */
    out->t_gather = lm_now() - t1;
    if (st == LM_OK && progress)
        progress(user, 1.0, "done");
    return st;
}

const float *lm_frame_loop_image(const lm_frame_loop *fl) { return fl->image; }
const uint32_t *lm_frame_loop_surface_versions(const lm_frame_loop *fl)
{
    return lm_lightmap_path_iim_const(fl->lightmaps)->version;
}
void lm_frame_loop_set_budget(lm_frame_loop *fl, float budget_ms) { fl->budget_ms = budget_ms > 0.0f ? budget_ms : 0.0f; }
const lm_photon_stage *lm_frame_loop_stage(const lm_frame_loop *fl) { return fl->stage; }
const lm_frame_loop_settings *lm_frame_loop_get_settings(const lm_frame_loop *fl) { return &fl->set; }
const lm_view *lm_frame_loop_view(const lm_frame_loop *fl) { return &fl->view; }
lm_iim *lm_frame_loop_iim(lm_frame_loop *fl) { return lm_lightmap_path_iim(fl->lightmaps); }

lm_status lm_frame_loop_read_iim_window(const lm_frame_loop *fl, const int win[4], float **rgba, lm_error *err)
{
    *rgba = NULL;
    lm_status st = lm_gl_make_current(fl->gl, err);
    return st == LM_OK ? lm_lightmap_path_read_window(fl->lightmaps, win, rgba, err) : st;
}

lm_status lm_frame_loop_read_iim(const lm_frame_loop *fl, float **rgba, lm_error *err)
{
    const int whole[4] = {0, 0, fl->world.atlas->width, fl->world.atlas->height};
    return lm_frame_loop_read_iim_window(fl, whole, rgba, err);
}

lm_status lm_frame_loop_iim_error(lm_frame_loop *fl, const float *shown, float *error, lm_error *err)
{
    lm_status st = lm_frame_loop_sync(fl, err);
    return st == LM_OK ? lm_lightmap_path_staleness(fl->lightmaps, shown, error, err) : st;
}

lm_status lm_frame_loop_accuracy(lm_frame_loop *fl, const float *shown, float *out, lm_error *err)
{
    lm_status st = lm_frame_loop_sync(fl, err); /* the AIM and its error are the photon work's */
    return st == LM_OK ? lm_lightmap_path_accuracy(fl->lightmaps, shown, out, err) : st;
}

void lm_frame_loop_caustics_size(const lm_frame_loop *fl, int *width, int *height)
{
    lm_frame_passes_caustics_size(fl->passes, width, height);
}

lm_status lm_frame_loop_read_caustics(lm_frame_loop *fl, float *rgb, lm_error *err)
{
    lm_status st = lm_gl_make_current(fl->gl, err);
    return st == LM_OK ? lm_frame_passes_read_caustics(fl->passes, rgb, err) : st;
}

lm_status lm_frame_loop_read_caustic_radiance(lm_frame_loop *fl, float *rgb, lm_error *err)
{
    lm_status st = lm_gl_make_current(fl->gl, err);
    return st == LM_OK ? lm_frame_passes_read_caustic_radiance(fl->passes, rgb, err) : st;
}
