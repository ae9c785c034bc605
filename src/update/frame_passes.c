#include "frame_passes.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../core/hash.h"
#include "../core/timing.h"
#include "../gpu/frame/composite.h"
#include "../gpu/frame/lightmap_view.h"
#include "../gpu/frame/reflections.h"
#include "../photonmap/caustic_split.h"

struct lm_frame_passes {
    const lm_frame_loop_settings *set; /* the loop's, borrowed */
    const lm_world *w;                 /* the loop's, borrowed */
    const lm_photon_stage *stage;
    lm_composite *comp;
    lm_direct *direct;           /* persistent: program, buffers, the frame's targets and shadow maps */
    lm_reflections *reflections; /* NULL: no mirror or glossy node, or switched off */
    uint32_t reflect_version;    /* the scene's pass_version the reflection maps were made for */
    uint32_t coverage_version;   /* the scene's pass_version the composite's surfaces follow */
    lm_caustic_pass *caustic_pass; /* made when the first caustic photons land */
    uint64_t caustic_version;    /* the stage's caustic photons the pass holds (lm_photon_stage_caustics_version) */
    int caustic_slot, caustic_w, caustic_h; /* the last picture drawn: its caustics' slot and size (w 0: none yet) */
    uint64_t caustic_key[LM_CAUSTIC_SLOTS]; /* what each slot's last run was made for (draw_caustics) */
    int caustic_keyed[LM_CAUSTIC_SLOTS];
    lm_caustic_split split;      /* the photons' split between the lightmaps and the screen (caustic_split.h) */
    int thin;                    /* the composite holds thin caustic light (split made with the lightmaps) */
    double split_seconds;        /* the splits since the last step's frame: its caustics' time */
    lm_view caustic_view;        /* the last picture's view (for the thin light at its pixels) */
    int generators;              /* the scene has caustic generators (mirror or glass nodes, caustics on) ... */
    uint32_t generators_version; /* ... as of this pass_version (+1: 0 is never a count yet) */
};

lm_status lm_frame_passes_create(const lm_world *w, const lm_photon_stage *stage, const lm_frame_loop_settings *set,
                                 lm_frame_passes **out, lm_error *err)
{
    *out = calloc(1, sizeof **out);
    if (!*out)
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for the frame's passes", w->scene->path);
    (*out)->set = set;
    (*out)->w = w;
    (*out)->stage = stage;
    return LM_OK;
}

void lm_frame_passes_free(lm_frame_passes *fp)
{
    if (!fp)
        return;
    lm_direct_free(fp->direct);
    lm_composite_free(fp->comp);
    lm_reflections_free(fp->reflections);
    lm_caustic_pass_free(fp->caustic_pass);
    lm_caustic_split_free(&fp->split);
    free(fp);
}

lm_status lm_frame_passes_setup(lm_frame_passes *fp, lm_error *err)
{
    if (fp->direct)
        return LM_OK;
    const lm_frame_loop_settings *set = fp->set;
    lm_status st = lm_composite_create(fp->w->scene, fp->w->atlas, set->gather.backface_limit, &fp->comp, err);
    if (st == LM_OK)
        st = lm_direct_create(fp->w->scene, fp->w->atlas, &set->direct, &fp->direct, err);
    if (st == LM_OK && set->reflection_size > 0)
        st = lm_reflections_create(fp->w->scene, set->reflection_size, set->reflection_faces, &fp->reflections, err);
    fp->reflect_version = fp->coverage_version = fp->w->scene->pass_version;
    return st;
}

lm_status lm_frame_passes_follow(lm_frame_passes *fp, lm_error *err)
{
    uint32_t v = fp->w->scene->pass_version;
    lm_status st = LM_OK;
    if (fp->comp && fp->coverage_version != v)
        st = lm_composite_update_coverage(fp->comp, fp->w->scene, fp->w->atlas, err);
    fp->coverage_version = v;
    if (st != LM_OK || fp->reflect_version == v || fp->set->reflection_size <= 0 || !fp->direct)
        return st;
    lm_reflections_free(fp->reflections);
    fp->reflections = NULL;
    fp->reflect_version = v;
    return lm_reflections_create(fp->w->scene, fp->set->reflection_size, fp->set->reflection_faces, &fp->reflections,
                                 err);
}

/* Whether the scene has caustic generators now (from the scene, which the stage's worker does not write:
 * its caustic photons may be made again on the worker meanwhile). */
static int has_generators(lm_frame_passes *fp)
{
    if (!fp->set->caustics)
        return 0;
    if (fp->generators_version != fp->w->scene->pass_version + 1) {
        lm_caustic_generator *g = NULL;
        lm_error err;
        int n = 1; /* out of memory: taken as there being some (a sync too many, never one too few) */
        if (lm_caustic_generators(fp->w->scene, &g, &n, &err) == LM_OK)
            free(g);
        fp->generators = n > 0;
        fp->generators_version = fp->w->scene->pass_version + 1;
    }
    return fp->generators;
}

/* The caustic pass when it holds photons to draw, else NULL. */
static lm_caustic_pass *drawn_caustics(const lm_frame_passes *fp)
{
    return fp->caustic_pass && lm_caustic_pass_photon_count(fp->caustic_pass) ? fp->caustic_pass : NULL;
}

int lm_frame_passes_want_caustics(lm_frame_passes *fp) { return has_generators(fp) || drawn_caustics(fp); }

/* Whether the caustic photons are split between the lightmaps and the screen: set->caustic_thin, and a
 * frame whose indirect term is the lightmaps' composite. */
static int split_on(const lm_frame_passes *fp)
{
    return fp->set->caustic_thin > 0.0f && fp->comp && lm_frame_lightmap_path(fp->set);
}

/* The photons for the screen pass (*hits): all of them, or when split_on, those where caustics are
 * concentrated, the thin light's texels into the composite. */
static lm_status split_caustics(lm_frame_passes *fp, const lm_caustics *c, const lm_caustic_hit **hits, lm_error *err)
{
    *hits = lm_caustics_hits(c);
    int split = split_on(fp);
    lm_status st = LM_OK;
    double t0 = lm_now();
    if (split)
        st = lm_caustic_split_make(fp->w->scene, fp->w->atlas, lm_aim_rgb(lm_photon_stage_aim(fp->stage)), *hits,
                                   lm_caustics_photon_count(c), fp->set->caustic_thin, &fp->split, err);
    else {
        lm_caustic_split_free(&fp->split);
        fp->split.landed = lm_caustics_landed(c); /* all of them the screen's */
    }
    if (st == LM_OK && split)
        *hits = fp->split.screen;
    fp->thin = st == LM_OK && split && fp->split.thin_photons > 0;
    fp->split_seconds += lm_now() - t0;
    if (st == LM_OK && fp->comp)
        st = lm_composite_set_caustics(fp->comp, fp->thin ? fp->split.thin : NULL, err);
    return st;
}

lm_status lm_frame_passes_upload_caustics(lm_frame_passes *fp, lm_error *err)
{
    const lm_caustics *c = lm_photon_stage_caustics(fp->stage);
    uint64_t version = lm_photon_stage_caustics_version(fp->stage);
    if (!c || version == fp->caustic_version || (!fp->caustic_pass && !lm_caustics_landed(c) && !fp->thin))
        return LM_OK;
    const lm_caustic_hit *hits = NULL;
    lm_status st = split_caustics(fp, c, &hits, err);
    if (st == LM_OK && !fp->caustic_pass)
        st = lm_caustic_pass_create(&fp->set->caustic_pass, &fp->caustic_pass, err);
    if (st == LM_OK) { /* with the thin light in the lightmaps the screen holds concentrated photons: no
                        * thin light for its filter to widen over */
        int levels = fp->set->caustic_pass.widen_levels;
        lm_caustic_pass_set_widening(fp->caustic_pass, fp->thin && levels > LM_CAUSTIC_SPLIT_WIDEN ? LM_CAUSTIC_SPLIT_WIDEN
                                                                                               : levels);
        st = lm_caustic_pass_set_photons(fp->caustic_pass, hits, lm_caustics_photon_count(c), err);
    }
    if (st == LM_OK)
        fp->caustic_version = version;
    return st;
}

/* The photons of the last upload that landed, and of those the ones the lightmaps carry. */
static void caustic_split_counts(const lm_frame_passes *fp, uint32_t *landed, uint32_t *thin)
{
    *landed = fp->split.landed;
    *thin = fp->thin ? fp->split.thin_photons : 0;
}

/* What lights the scene besides the lightmaps, as the environment maps' dirty tracking compares it: the
 * emitters' placement and power, the materials' edits, the caustic photons. */
static uint64_t lighting_hash(const lm_frame_passes *fp)
{
    const lm_emitters *em = lm_photon_stage_emitters(fp->stage);
    uint64_t h = LM_HASH_SEED;
    for (int e = 0; e < em->count; e++) {
        const lm_emitter *x = &em->e[e];
        const float *parts[4] = {x->pos, x->dir, x->radiant, x->power};
        for (int k = 0; k < 4; k++)
            h = lm_hash_bytes(h, parts[k], 3 * sizeof(float));
    }
    h = lm_hash_bytes(h, &fp->w->scene->material_version, sizeof fp->w->scene->material_version);
    return lm_hash_bytes(h, &fp->caustic_version, sizeof fp->caustic_version);
}

/* The caustics of a picture drawn by lm_direct_draw (the step's own frame keeps its caustics apart, for
 * lm_frame_passes_read_caustics). The splat, queries and filter are skipped, the composite alone drawn
 * again, when the photons, the view and every node are as for the slot's last run: nothing it depends on
 * changed. */
static lm_status draw_caustics(lm_frame_passes *fp, lm_caustic_pass *cp, int own, const lm_view *view, int w, int h,
                               lm_frame_stats *o, lm_error *err)
{
    int slot = own ? LM_CAUSTIC_SLOT_FRAME : LM_CAUSTIC_SLOT_VIEW;
    uint64_t key = lm_scene_world_hash(fp->w->scene);
    key = lm_hash_bytes(key, view->view, sizeof view->view);
    key = lm_hash_bytes(key, view->proj, sizeof view->proj);
    key = lm_hash_bytes(key, &fp->caustic_version, sizeof fp->caustic_version);
    const int size[2] = {w, h};
    key = lm_hash_bytes(key, size, sizeof size);
    if (fp->caustic_key[slot] == key && fp->caustic_keyed[slot])
        return lm_caustic_pass_composite(cp, slot, fp->direct, &o->caustic, err);
    lm_status st = lm_caustic_pass_run(cp, slot, view, lm_direct_depth_texture(fp->direct, 0), w, h, fp->direct,
                                       &o->caustic, err);
    fp->caustic_key[slot] = key;
    fp->caustic_keyed[slot] = st == LM_OK;
    return st;
}

lm_status lm_frame_passes_draw(lm_frame_passes *fp, const lm_frame_indirect *ind, const lm_view *view, int w,
                               int h, float *rgb, int own, int step, lm_frame_stats *o, lm_error *err)
{
    double t0 = lm_now();
    unsigned lit = 0;
    lm_status st = LM_OK;
    if (ind->iim) /* else the first pass adds none */
        st = lm_composite_indirect(fp->comp, ind->iim->display_tex, &lit, err);
    double t1 = lm_now();
    lm_direct_set_indirect(fp->direct, lit, ind->iim ? ind->iim->turn_tex : NULL);
    lm_direct_write_gbuffer(fp->direct, ind->photons != NULL); /* the photon gathers read it, nothing else */
    if (st == LM_OK && ind->photons)
        st = lm_photon_path_coverage(ind->photons, fp->direct, err);
    const lm_emitters *em = lm_photon_stage_emitters(fp->stage);
    lm_caustic_pass *caustics = drawn_caustics(fp);
    lm_reflection_inputs in = {fp->w->surfaces, ind->iim ? ind->iim->version : NULL, lighting_hash(fp), caustics};
    if (st == LM_OK && step) /* the faces due this step; an extra view shows the maps as they are */
        st = lm_reflections_update(fp->reflections, fp->direct, fp->w->scene, em, &in, &o->cube_faces, err);
    double t2 = lm_now();
    /* a flat reflector's picture is a direct pass of the view's own (mirrored), drawn whenever what it
     * shows changed: a cost of the view like the direct pass, counted in it, not a stage the budget plans */
    if (st == LM_OK)
        st = lm_reflections_draw_planes(fp->reflections, fp->direct, fp->w->scene, em, &in, view, w, h,
                                        &o->plane_maps, err);
    if (st == LM_OK)
        st = lm_direct_draw(fp->direct, fp->w->scene, em, view, w, h, err);
    double t3 = lm_now();
    o->photon_gather.t_wait = 0.0;
    if (st == LM_OK && ind->photons)
        st = lm_photon_path_draw(ind->photons, fp->direct, view, w, h, &o->photon_gather, &o->photon_gathers, err);
    double t3p = lm_now();
    if (st == LM_OK && caustics)
        st = draw_caustics(fp, caustics, own, view, w, h, o, err);
    fp->caustic_slot = own ? LM_CAUSTIC_SLOT_FRAME : LM_CAUSTIC_SLOT_VIEW;
    fp->caustic_w = w, fp->caustic_h = h;
    fp->caustic_view = *view;
    double t4 = lm_now();
    if (st == LM_OK)
        st = lm_reflections_draw(fp->reflections, fp->direct, fp->w->scene, view, err);
    double t5 = lm_now();
    if (st == LM_OK)
        st = lm_direct_read(fp->direct, rgb, err);
    o->t_composite = t1 - t0;
    /* the caustic pass and the photon gather first wait for the direct light's GPU work: that wait is
     * the direct light's */
    o->t_caustics = t4 - t3p - o->caustic.t_wait + (own ? fp->split_seconds : 0.0);
    fp->split_seconds = own ? 0.0 : fp->split_seconds;
    caustic_split_counts(fp, &o->caustic_landed, &o->caustic_thin);
    o->t_gather += t3p - t3 - o->photon_gather.t_wait;
    o->t_reflections = (t2 - t1) + (t5 - t4);
    o->t_direct = (t3 - t2) + o->caustic.t_wait + o->photon_gather.t_wait + (lm_now() - t5);
    return st;
}

lm_status lm_frame_passes_draw_step(lm_frame_passes *fp, const lm_frame_indirect *ind, const lm_view *view, int w,
                                    int h, float *rgb, lm_frame_stats *o, lm_error *err)
{
    long before = lm_direct_shadow_maps_rendered(fp->direct);
    lm_direct_begin_update(fp->direct, fp->set->direct.maps_per_update);
    lm_status st = lm_frame_passes_draw(fp, ind, view, w, h, rgb, 1, 1, o, err);
    lm_direct_end_update(fp->direct);
    o->shadow_maps = (int)(lm_direct_shadow_maps_rendered(fp->direct) - before);
    o->shadow_maps_stale = lm_direct_stale_maps(fp->direct);
    return st;
}

void lm_frame_passes_caustics_size(const lm_frame_passes *fp, int *width, int *height)
{
    *width = fp->caustic_w;
    *height = fp->caustic_h;
}

lm_status lm_frame_passes_read_caustics(const lm_frame_passes *fp, float *rgb, lm_error *err)
{
    size_t n = 3 * (size_t)fp->caustic_w * (size_t)fp->caustic_h;
    lm_status st = LM_OK;
    if (drawn_caustics(fp))
        st = lm_caustic_pass_read_irradiance(fp->caustic_pass, fp->caustic_slot, rgb, err);
    else /* none drawn on screen */
        memset(rgb, 0, n * sizeof *rgb);
    if (st == LM_OK && fp->thin && fp->caustic_w > 0) /* and what the lightmaps carry */
        st = lm_render_atlas_irradiance(fp->w->scene, fp->w->atlas, lm_composite_caustics_texture(fp->comp),
                                        &fp->caustic_view, fp->caustic_w, fp->caustic_h, rgb, err);
    return st;
}

lm_status lm_frame_passes_read_caustic_radiance(const lm_frame_passes *fp, float *rgb, lm_error *err)
{
    lm_status st = lm_frame_passes_read_caustics(fp, rgb, err);
    if (st != LM_OK || (!drawn_caustics(fp) && !fp->thin))
        return st;
    size_t n = 3 * (size_t)fp->caustic_w * (size_t)fp->caustic_h;
    float *kd = malloc((n ? n : 1) * sizeof *kd);
    if (!kd)
        return lm_fail(err, LM_ERR_NOMEM, "no memory to read the caustics' kd");
    st = lm_frame_targets_read_kd(lm_direct_targets(fp->direct), kd, err);
    for (size_t i = 0; st == LM_OK && i < n; i++) /* what the composite added (caustic_composite_fs.glsl) */
        rgb[i] *= kd[i] / (float)M_PI;
    free(kd);
    return st;
}

int lm_frame_passes_faces(const lm_frame_passes *fp) { return lm_reflections_face_count(fp->reflections); }
void lm_frame_passes_limit_faces(lm_frame_passes *fp, int most) { lm_reflections_limit_faces(fp->reflections, most); }
