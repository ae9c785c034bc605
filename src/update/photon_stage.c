#include "photon_stage.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../core/timing.h"
#include "../scene/moved_nodes.h"
#include "../trace/portal_finder.h"
#include "../trace/sealed_lights.h"

/* Shadow rays per emissive triangle and point (trace/emitter_light.h): an AIM texel takes 4 points (its
 * 2 x 2 parts), 16 rays in all; only penumbrae are sampled. */
#define AIM_EMITTER_RAYS 4

/* Where an emitter was and what it emitted when its photons were last traced: its node's world matrix,
 * its place and its power. An emitter's placement follows from more than edits name (its node's parents,
 * the scene's bounds for a sun, a light sealed in a closed object by a node that moved), so whether a
 * re-placed emitter moved is decided against this. */
typedef struct {
    float world[16];
    float pos[3], dir[3], power[3];
    float shape[12];  /* a sun's rectangle, a light's range and cones: the rest its photons' paths follow */
} emitter_snapshot;

struct lm_photon_stage {
    lm_photon_stage_settings set;
    lm_scene *scene;
    const lm_surfaces *surfaces;
    const lm_atlas *atlas;
    lm_rt *rt;
    lm_edit_batch *edits;        /* the edits' change list (update/edits.h); NULL: only animations change */
    lm_emitters emitters;
    emitter_snapshot *snap;
    float bounds[6];             /* the scene's bounds when the emitters were last placed (a sun's follow) */
    uint8_t *refreshed;          /* per surface: its AIM refreshed since lm_photon_stage_take_refreshed */
    int aim_pending;             /* AIM surfaces over their threshold that the last refresh left for later */
    lm_moved_nodes moves;        /* the nodes edits moved, whose paths are queued at once (moved_nodes.h) */
    int edited_before;           /* the last update saw edits of any kind (catch_up) */
    int uncaught;                /* a placement since then was not caught up: the next still update does it */
    int budgeted;                /* this update runs under a time budget (lm_photon_stage_set_budgeted) */
    float *move_boxes;           /* LM_MOVED_NODE_BOXES floats a node: this frame's, between animate and update */
    int animated_boxes;          /* of them, those the update half re-traces photon by photon (an animation's
                                  * moves alone; an edit's are queued in animate for its catch-up) */
    double *delta_before;        /* scratch: per surface, delta_f + owed before a refresh (aim.h) */
    uint32_t *count_before;      /* scratch: per surface, its refresh count before it */
    lm_photons *photons;
    lm_aim aim;
    lm_emitter_light area;       /* with have_area: the emissive triangles' closed form, for the AIMs */
    lm_direct_light direct;      /* the AIMs' direct light (set.exact_direct) */
    lm_caustics *caustics;       /* with set.caustics */
    uint32_t caustic_version;    /* the scene's pass_version they were made for */
    int caustic_emitters;        /* the emitters they were made for */
    int caustics_stale;          /* a material was edited: made again at the next update */
    uint64_t caustic_made;       /* times they were made (lm_photon_stage_caustics_version) */
    float *light_scale;          /* per surface x 3: what light edits scaled its light by since
                                  * lm_photon_stage_take_scale (1: nothing) */
    int scaled;                  /* light_scale holds something other than 1 */
    int scaled_lit;              /* and a light was lit where it gave no light (light_now) */
    int scaled_materials;        /* and a material was edited (lm_photon_stage_scale_recoloured) */
    int scaled_computed;         /* and one of those lights' direct light is computed by the AIM (its first
                                  * hits are left out of the estimate, lm_direct_covers_emitter) */
    float *aim_before;           /* with scaled: the dilated AIM before the first of those scalings (or NULL:
                                  * no memory for it), lm_photon_stage_take_scale's to hand on */
    float *emissive_before;      /* with scaled: per material, the emission the photons saw before them */
    double *flux_before, *flux_after, *flux_of; /* scratch: per surface x 3 (note_scale); flux_of also the
                                                 * flux of the hits the AIM's direct part covers (own_flux) */
    int *touched;                /* scratch: per surface, the surfaces it scaled (apply_scale) */
    uint8_t *reached;            /* scratch: per surface, reweighted photons reach it (follow_materials) */
    lm_material *materials;      /* the scene's materials as the photons last saw them (material_count) */
    float *ratio;                /* scratch: per material x 3, a recolour's ratio (follow_materials) */
    float *aim_factor;           /* scratch: per surface x 3, what an edit scales its AIM by (under a budget) */
    float *computed_factor;      /* scratch: per surface x 3, and the part of it the AIM computes (by_rest) */
    int material_count;
    int have_emitters, have_aim, have_area;
    int frame;
    uint64_t hit_bound;          /* worst_refresh at creation: the AIM refresh's bound without a budget */
    lm_photon_stage_limits limit; /* a time budget's counts (lm_photon_stage_limit); zeros: the settings' */
};

void lm_photon_stage_settings_default(lm_photon_stage_settings *s)
{
    memset(s, 0, sizeof *s);
    lm_photon_settings_default(&s->photons);
    lm_aim_settings_default(&s->aim);
    s->surfaces_per_frame = 8; /* lmgi_knobs.h's aim.surfaces_per_frame (docs/aim.md, "How many an update") */
    s->trace = 1;
    s->aims = 1;
    s->find_portals = 1;
    s->exact_direct = LM_EXACT_SUNS; /* lmgi_aim_direct's default */
    lm_caustic_settings_default(&s->caustic);
}

static int has_sun(const lm_emitters *em)
{
    for (int k = 0; k < em->count; k++)
        if (em->e[k].kind == LM_EMIT_DIRECTIONAL)
            return 1;
    return 0;
}

/* The AIMs take direct light from trace/direct_irradiance.h as exact_direct says (LM_EXACT_*); nothing
 * where the photons' cover distance hides a side. */
static lm_status setup_direct(lm_photon_stage *ps, const lm_photon_settings *ph, lm_error *err)
{
    int suns = ps->set.exact_direct == LM_EXACT_SUNS, all = ps->set.exact_direct == LM_EXACT_ALL;
    if (suns ? !has_sun(&ps->emitters) : !all && !lm_emitter_light_suits(ps->scene))
        return LM_OK; /* nothing to compute: photons bring all light, as in the paper */
    if (!suns && lm_emitter_light_suits(ps->scene)) {
        lm_status st = lm_emitter_light_init(&ps->area, ps->scene, ps->rt, AIM_EMITTER_RAYS, err);
        if (st != LM_OK)
            return st;
        ps->have_area = 1;
    }
    ps->direct = (lm_direct_light){ps->scene, ps->rt, &ps->emitters, ps->have_area ? &ps->area : NULL,
                                   all ? LM_DIRECT_PUNCTUAL : suns ? LM_DIRECT_SUNS : LM_DIRECT_NONE,
                                   lm_scene_ray_lift(ps->scene), ph->cover_distance, ph->cover_by_surface};
    lm_aim_set_direct(&ps->aim, &ps->direct);
    /* rest: for a ray gather that adds the computed part at its hits, and, where the punctual lights' part is
     * all the AIM computes (no emissive triangles'), for the first guess of other lights' edits (by_rest) */
    return ps->set.direct_at_hits || !ps->have_area ? lm_aim_keep_rest(&ps->aim, err) : LM_OK;
}

static void take_snapshot(const lm_photon_stage *ps, int e, emitter_snapshot *out)
{
    const lm_emitter *em = &ps->emitters.e[e];
    memset(out, 0, sizeof *out);
    if (em->node >= 0 && em->node < ps->scene->node_count)
        memcpy(out->world, ps->scene->nodes[em->node].world, sizeof out->world);
    if (em->punctual) {
        memcpy(out->pos, em->pos, sizeof out->pos);
        memcpy(out->dir, em->dir, sizeof out->dir);
    }
    memcpy(out->power, em->power, sizeof out->power);
    memcpy(out->shape, em->rect, sizeof em->rect);
    if (em->light >= 0 && em->light < ps->scene->light_count) {
        const lm_light *l = &ps->scene->lights[em->light];
        out->shape[9] = l->range, out->shape[10] = l->inner_cone, out->shape[11] = l->outer_cone;
    }
}

/* Scene light `light` (-1: the sky), come after the emitter list was built, joins it last and the photons,
 * which queue its groups for tracing; *added counts it. */
static lm_status join_emitter(lm_photon_stage *ps, int light, int *added, lm_error *err)
{
    emitter_snapshot *snap = realloc(ps->snap, sizeof *snap * ((size_t)ps->emitters.count + 2));
    if (!snap && light < 0)
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for the sky", ps->scene->path);
    if (!snap)
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for light '%s'", ps->scene->path, ps->scene->lights[light].name);
    ps->snap = snap;
    lm_status st = light < 0 ? lm_emitters_add_sky(&ps->emitters, ps->scene, err)
                             : lm_emitters_add_light(&ps->emitters, ps->scene, light, err);
    if (st == LM_OK)
        st = lm_photons_add_emitter(ps->photons, err);
    if (st != LM_OK)
        return st;
    take_snapshot(ps, ps->emitters.count - 1, &ps->snap[ps->emitters.count - 1]);
    ++*added;
    return LM_OK;
}

/* Lights added to the scene since the emitter list was built (they come last, in id order), and a sky
 * given to it since, join the emitters as join_emitter says. Returns how many. */
static lm_status take_new_emitters(lm_photon_stage *ps, int *added, lm_error *err)
{
    *added = 0;
    lm_status st = LM_OK;
    for (int l = lm_emitters_light_count(&ps->emitters); st == LM_OK && l < ps->scene->light_count; l++)
        st = join_emitter(ps, l, added, err);
    if (st == LM_OK && ps->scene->has_sky && lm_emitters_sky(&ps->emitters) < 0)
        st = join_emitter(ps, -1, added, err);
    return st;
}

/* Keeps the dilated AIM as it is before the first change this frame shows at once (light power edits,
 * material edits), for the IIM's factors (lm_photon_stage_take_scale): at most once between takes. */
static void keep_aim_before(lm_photon_stage *ps)
{
    if (ps->scaled)
        return;
    ps->scaled = 1;
    size_t cells = 4 * (size_t)ps->atlas->width * ps->atlas->height;
    if ((ps->aim_before = malloc(sizeof *ps->aim_before * cells)) != NULL)
        memcpy(ps->aim_before, lm_aim_dilated_rgba(&ps->aim), sizeof *ps->aim_before * cells);
    int M = ps->scene->material_count; /* the emissions the photons last saw, for the gathers before */
    if ((ps->emissive_before = malloc(sizeof *ps->emissive_before * 3 * (size_t)(M ? M : 1))) == NULL)
        return;
    for (int m = 0; m < M; m++)
        memcpy(ps->emissive_before + 3 * m, (m < ps->material_count ? ps->materials : ps->scene->materials)[m].emissive,
               3 * sizeof *ps->emissive_before);
}

/* Whether material `now` differs from `was` in its base colour alone (rgb), both diffuse and `was` lit
 * in every channel: the BSDF weight of a diffuse bounce is the albedo, base colour x texture, so the photons
 * that bounced off it may be reweighted by now / was (lm_photons_scale_materials) into r. */
static int recoloured(const lm_material *was, const lm_material *now, float r[3])
{
    if (was->cls != LM_MAT_DIFFUSE || now->cls != LM_MAT_DIFFUSE || was->base_color[3] != now->base_color[3] ||
        was->base_color_tex != now->base_color_tex || was->metallic != now->metallic ||
        was->roughness != now->roughness || was->emissive_tex != now->emissive_tex ||
        memcmp(was->emissive, now->emissive, sizeof now->emissive) || was->transmission != now->transmission)
        return 0;
    for (int c = 0; c < 3; c++) {
        if (!(was->base_color[c] > 0.0f))
            return 0;
        r[c] = now->base_color[c] / was->base_color[c];
        if (!isfinite(r[c]) || r[c] < 0.0f)
            return 0;
    }
    return 1;
}

/* An AIM refresh's counts and time added to the frame's (out->aim, out->t_aim): a frame may refresh for
 * its edits (animate) and for its photons (update), and both are AIM work that the budget's cost model
 * learns and lmgi_update's stats report. */
static void add_aim_stats(lm_photon_stage_frame *out, const lm_aim_stats *st)
{
    lm_aim_stats_add(&out->aim, st);
    out->t_aim += st->seconds;
}

/* The AIMs of the listed surfaces refreshed at once for this frame's edits, counted in out beside the
 * budgeted refreshes (aim_at_once); refresh_at_once: the first `count` of ps->touched. */
static lm_status refresh_listed_at_once(lm_photon_stage *ps, const int *surfaces, int count,
                                        lm_photon_stage_frame *out, lm_error *err)
{
    lm_aim_stats st;
    lm_status rc = lm_aim_refresh_listed(&ps->aim, ps->scene, ps->surfaces, ps->atlas,
                                         lm_photons_store_mutable(ps->photons), surfaces, count, &st, err);
    add_aim_stats(out, &st);
    out->aim_at_once += st.surfaces_refreshed;
    return rc;
}

static lm_status refresh_at_once(lm_photon_stage *ps, int count, lm_photon_stage_frame *out, lm_error *err)
{
    return refresh_listed_at_once(ps, ps->touched, count, out, err);
}

/* How much a surface's hits' flux changed in a channel, from `before` to `after`: 1 where it had none. */
static float flux_ratio(double before, double after)
{
    return before > 0.0 ? (float)fmax(after / before, 0.0) : 1.0f;
}

/* Whether the frame loop gives this update a time budget (lm_photon_stage_set_budgeted): then an edit's
 * AIM work at once is the cheap first guess, the refreshes left to the budgeted ones. */
static int budgeted(const lm_photon_stage *ps) { return ps->budgeted; }

/* Whether, where the AIM computes direct light, an edit's first guess may still scale it: its rest (the
 * part the photons bring) is kept apart from the punctual lights' direct part, which is then all it
 * computes (no emissive triangles'), so the direct part keeps its value and rest alone scales, by how much
 * the flux of the hits the estimate sums changed (own_flux). The shared room's lamp dimmed beside its sun
 * refreshed 468 AIMs at once, 25 ms of a 8 ms budget. Flux of the covered hits into ps->flux_of. */
static int by_rest(lm_photon_stage *ps)
{
    if (!ps->aim.direct || !ps->aim.rest || ps->direct.area)
        return 0;
    lm_direct_covered_flux(&ps->direct, lm_photons_store(ps->photons), ps->flux_of);
    return 1;
}

/* A surface's flux `f` in channel c less that of its hits the AIM's direct part covers (by_rest), the
 * flux its estimate sums: 0 where the two differ by rounding alone. */
static double own_flux(const lm_photon_stage *ps, double f, int k, int c)
{
    double own = f - ps->flux_of[3 * k + c];
    return own > 1e-6 * f ? own : 0.0;
}

/* Under a budget, the AIMs after material edits (follow_materials), each scaled at once: a recoloured
 * material's surfaces by its ratio, exact while their hits are as they were (the AIM multiplies in the
 * albedo); the surfaces the reweighted photons reach (reweighted: flux_before and flux_after hold their
 * hits' flux) by how much that flux changed, a first guess of their second bounce's change that the
 * budgeted refreshes their hits' delta_f asks for refine; where the AIM computes direct light, which no
 * reweighted photon's first hit moves, that of its rest alone (by_rest). The surfaces of materials
 * changed otherwise, and the reached ones where the AIM computes direct light not kept apart (the hits'
 * flux's change is then not the AIM's), are refreshed at once. */
static lm_status recolour_aims(lm_photon_stage *ps, const uint8_t *changed, int reweighted,
                               lm_photon_stage_frame *out, lm_error *err)
{
    int S = ps->surfaces->surface_count, scaled = 0, other = 0;
    int rest = reweighted && by_rest(ps); /* a bounce off a material moves no first hit: direct kept */
    int scalable = !ps->aim.direct || rest;
    for (int k = 0; k < S; k++) {
        int m = ps->surfaces->surfaces[k].material, by = 0;
        float *f = ps->aim_factor + 3 * k, *g = ps->computed_factor + 3 * k;
        f[0] = f[1] = f[2] = g[0] = g[1] = g[2] = 1.0f;
        for (int c = 0; c < 3 && reweighted && ps->reached[k] && scalable; c++) {
            double b = ps->flux_before[3 * k + c], a = ps->flux_after[3 * k + c];
            f[c] = rest ? flux_ratio(own_flux(ps, b, k, c), own_flux(ps, a, k, c)) : flux_ratio(b, a);
            by |= f[c] != 1.0f;
        }
        const float *r = ps->ratio + 3 * m;
        int recoloured = changed[m] && (r[0] != 1.0f || r[1] != 1.0f || r[2] != 1.0f);
        double moved = 0.0;
        for (int c = 0; c < 3 && recoloured; c++) /* the albedo multiplies the direct part too */
            f[c] *= r[c], g[c] = r[c], moved = fmax(moved, fabs((double)r[c] - 1.0));
        /* owed a refresh as if its hits had changed that much: the budgeted refreshes and a bake make it
         * again from its hits, so that it ends as a fresh updater's (the scaled one is so to rounding) */
        ps->aim.owed[k] += moved * lm_photons_store(ps->photons)->surfaces[k].energy;
        if ((changed[m] && !recoloured) || (reweighted && ps->reached[k] && !scalable))
            ps->touched[S - 1 - other++] = k; /* from the end: the two lists share the scratch */
        else if (by || recoloured)
            ps->touched[scaled++] = k;
    }
    lm_aim_scale_surfaces(&ps->aim, ps->atlas, ps->touched, scaled, ps->aim_factor, ps->computed_factor);
    return other > 0 ? refresh_listed_at_once(ps, ps->touched + S - other, other, out, err) : LM_OK;
}

/* The materials the edits changed (colour, emission, class; ch) reach the photons that touch them, which
 * are re-traced under the group budget. At once, the photons that bounced off a diffuse material
 * recoloured alone are reweighted (lm_photons_scale_materials), and the AIMs of the surfaces of the
 * changed materials and of those the reweighted photons reach are refreshed: the changed light at every
 * bounce shows at the next update (issue 32, item 2), that of other material edits to first order (the
 * AIM multiplies in the new albedo), and the IIM texels that see them follow (update/light_scale.h).
 * *count: how many materials changed. */
static lm_status follow_materials(lm_photon_stage *ps, const lm_edit_changes *ch, lm_photon_stage_frame *out,
                                  lm_error *err)
{
    int *count = &out->materials_changed;
    *count = 0;
    if (!ch->materials_changed)
        return LM_OK;
    const uint8_t *changed = ch->materials; /* material_cap >= material_count once any is set */
    ps->caustics_stale = 1;
    lm_photons_invalidate_materials(ps->photons, changed);
    *count = ch->materials_changed;
    int S = ps->surfaces->surface_count, M = ps->material_count, any = 0;
    if (ps->have_aim) /* before the snapshot below takes the new emissions */
        keep_aim_before(ps);
    ps->scaled_materials = 1;
    for (int m = 0; m < M; m++) {
        float *r = ps->ratio + 3 * m;
        r[0] = r[1] = r[2] = 1.0f;
        if (changed[m] && !recoloured(&ps->materials[m], &ps->scene->materials[m], r))
            r[0] = r[1] = r[2] = 1.0f;
        any |= r[0] != 1.0f || r[1] != 1.0f || r[2] != 1.0f;
        if (changed[m])
            ps->materials[m] = ps->scene->materials[m];
    }
    memset(ps->reached, 0, (size_t)S);
    int first_guess = ps->have_aim && budgeted(ps);
    if (any && first_guess) /* the reached surfaces' flux before and after, for their AIM's first guess */
        lm_photon_store_surface_flux(lm_photons_store(ps->photons), ps->flux_before);
    if (any)
        lm_photons_scale_materials(ps->photons, ps->ratio, M, ps->reached);
    if (any && first_guess)
        lm_photon_store_surface_flux(lm_photons_store(ps->photons), ps->flux_after);
    if (first_guess)
        return recolour_aims(ps, changed, any, out, err);
    int n = 0;
    for (int k = 0; k < S; k++)
        if (ps->reached[k] || changed[ps->surfaces->surfaces[k].material])
            ps->touched[n++] = k;
    return ps->have_aim && n > 0 ? refresh_at_once(ps, n, out, err) : LM_OK;
}

/* Whether anything an emitter's placement or power follows from may have changed since they were last
 * placed: an added emitter, an animation, an edit's light, material, sky or placement (ch), or the
 * scene's bounds (set after the last frame's animations). Otherwise placing them again would find them
 * where they were. */
static int emitters_touched(lm_photon_stage *ps, const lm_edit_changes *ch, int added)
{
    const lm_scene *s = ps->scene;
    float b[6] = {s->bounds_min[0], s->bounds_min[1], s->bounds_min[2],
                  s->bounds_max[0], s->bounds_max[1], s->bounds_max[2]};
    int bounds = memcmp(b, ps->bounds, sizeof b) != 0;
    memcpy(ps->bounds, b, sizeof b);
    return added || bounds || s->animation_count > 0 || ch->moved || ch->lights_changed || ch->sky ||
           ch->materials_changed;
}

/* Whether an area emitter's triangles share one material: then an edit of its emission scales every
 * triangle's alike, and the choice of triangle by flux, so every path, stays. */
static int one_material(const lm_scene *sc, const lm_emitter *em)
{
    if (em->kind != LM_EMIT_AREA || em->tri_count == 0)
        return 0;
    for (uint32_t i = 1; i < em->tri_count; i++)
        if (sc->tri_material[em->tris[i]] != sc->tri_material[em->tris[0]])
            return 0;
    return 1;
}

/* Whether a power, or a surface's hits' flux, is lit in some channel. */
static int any_lit(const float p[3]) { return p[0] > 0.0f || p[1] > 0.0f || p[2] > 0.0f; }
static int any_flux(const double f[3]) { return f[0] > 0.0 || f[1] > 0.0 || f[2] > 0.0; }

/* Whether an emitter stays where and as it was from `was` to `now` (its paths' start and shape). */
static int same_place(const emitter_snapshot *was, const emitter_snapshot *now)
{
    return !memcmp(was->world, now->world, sizeof now->world) && !memcmp(was->pos, now->pos, sizeof now->pos) &&
           !memcmp(was->dir, now->dir, sizeof now->dir) && !memcmp(was->shape, now->shape, sizeof now->shape);
}

/* Whether a punctual light's change from `was` to `now` is in power alone (its colour, intensity or
 * switch: the same place and shape), or an area emitter's of one material in its emission alone, and by
 * how much, per channel, into s. A channel that was dark and is lit is not a scale: its photons carry
 * nothing to scale (their paths are traced again). */
static int power_alone(const lm_scene *sc, const lm_emitter *em, const emitter_snapshot *was,
                       const emitter_snapshot *now, float s[3])
{
    if (!(em->punctual || one_material(sc, em)) || !same_place(was, now))
        return 0;
    for (int c = 0; c < 3; c++) {
        if (!(was->power[c] > 0.0f))
            return 0; /* dark, or not a number */
        s[c] = now->power[c] / was->power[c];
        if (!isfinite(s[c]) || s[c] < 0.0f)
            return 0;
    }
    return 1;
}

/* Emitter e's share of each surface's hits' flux (flux_of) added, times w, to their totals after this
 * frame's edits (flux_after), which start from the totals before any of them (flux_before, taken at the
 * first). */
static void note_flux(lm_photon_stage *ps, int e, const float w[3], int first)
{
    size_t n = 3 * (size_t)ps->surfaces->surface_count;
    if (first) {
        lm_photon_store_surface_flux(lm_photons_store(ps->photons), ps->flux_before);
        memcpy(ps->flux_after, ps->flux_before, sizeof *ps->flux_after * n);
        ps->scaled_computed = 0;
    }
    ps->scaled_computed |= ps->aim.direct && lm_direct_covers_emitter(&ps->direct, &ps->emitters.e[e]);
    memset(ps->flux_of, 0, sizeof *ps->flux_of * n);
    lm_photons_emitter_flux(ps->photons, e, ps->flux_of);
    for (size_t i = 0; i < n; i++)
        ps->flux_after[i] += (double)w[i % 3] * ps->flux_of[i];
}

/* Emitter e's light scaled by s (power_alone): its hits' flux moves by s - 1 times what it was. */
static void note_scale(lm_photon_stage *ps, int e, const float s[3], int first)
{
    note_flux(ps, e, (const float[3]){s[0] - 1.0f, s[1] - 1.0f, s[2] - 1.0f}, first);
}

/* Whether the stage shows a newly lit emitter at once (light_now): it traces photons and holds AIMs. */
static int lights_at_once(const lm_photon_stage *ps) { return ps->have_aim && ps->set.trace; }

/* Emitter e lit where it gave no light (added, or switched on from dark in the same place): its groups
 * are traced now and taken off the re-trace queue, rather than traced over the updates the queue takes
 * (the shared room's added lamp read 67% off the converged lightmap for 108 updates), and its hits' flux,
 * all new (a dark light stores none), moves the surfaces' totals, so that apply_scale refreshes the AIMs
 * it reaches (under a budget: scales those that had hits, and refreshes those it alone lights) and the
 * IIM takes its factors from them as after a power edit (update/light_scale.h): a first guess where the
 * new light falls elsewhere than the light there was, which the regathers of those surfaces refine. The trace is paid in the edit's update
 * whatever its budget, as a power edit's first guess is (LM_LIGHT_SCALE_LEAST): 20-24 ms for the shared
 * room's lamp of 15,912 photons on 2 cores. */
static lm_status light_now(lm_photon_stage *ps, int e, int first, lm_photon_stage_frame *out, lm_error *err)
{
    note_flux(ps, e, (const float[3]){-1.0f, -1.0f, -1.0f}, first);
    lm_status st = lm_photons_retrace_emitter(ps->photons, e, err);
    note_flux(ps, e, (const float[3]){1.0f, 1.0f, 1.0f}, 0);
    out->emitters_lit++;
    ps->scaled_lit = 1;
    return st;
}

/* The light of this frame's scaled emitters shown at once (issue 32, item 2; docs/tradeoff.md, "Light
 * edits at once"): their hits are what a re-trace would store (scaled, or gone for a light turned dark),
 * so the AIMs of the surfaces whose hits' flux changed are refreshed from them at once, exact whatever
 * mix of lights they hold. Each surface's factor, how much the flux of its hits changed per channel (one
 * that no hit reaches: 1, or the whole scene's where its AIM computes the lights' direct light), waits
 * for the IIM (lm_photon_stage_take_scale) with the AIM from before. */
static lm_status apply_scale(lm_photon_stage *ps, lm_photon_stage_frame *out, lm_error *err)
{
    int S = ps->surfaces->surface_count, moved = 0, dark = 0;
    int computed = ps->set.exact_direct == LM_EXACT_ALL || ps->set.exact_direct == LM_EXACT_SUNS; /* lights' direct */
    int rest = budgeted(ps) && !ps->scaled_computed && by_rest(ps);
    int first_guess = budgeted(ps) && (!ps->aim.direct || rest); /* the AIMs scaled, not refreshed (below) */
    double all_before[3] = {0, 0, 0}, all_after[3] = {0, 0, 0};
    for (int k = 0; k < S; k++)
        for (int c = 0; c < 3; c++)
            all_before[c] += ps->flux_before[3 * k + c], all_after[c] += ps->flux_after[3 * k + c];
    for (int k = 0; k < S; k++) {
        int changed = 0;
        double own_before[3], own_after[3]; /* the flux of the hits its estimate sums */
        for (int c = 0; c < 3; c++) {
            double b = ps->flux_before[3 * k + c], a = ps->flux_after[3 * k + c];
            own_before[c] = rest ? own_flux(ps, b, k, c) : b, own_after[c] = rest ? own_flux(ps, a, k, c) : a;
            if (!(b > 0.0) && computed) /* its AIM may hold the lights' direct light alone */
                b = all_before[c], a = all_after[c];
            float f = flux_ratio(b, a);
            ps->light_scale[3 * k + c] *= f;
            ps->aim_factor[3 * k + c] = rest ? flux_ratio(own_before[c], own_after[c]) : f;
            ps->computed_factor[3 * k + c] = 1.0f; /* no light whose direct part it computes changed */
            changed |= f != 1.0f || ps->aim_factor[3 * k + c] != 1.0f ||
                       (!(b > 0.0) && a > 0.0); /* lit by a new light's photons alone */
        }
        int lit_now = !any_flux(own_before) && any_flux(own_after);
        if (changed && first_guess && lit_now) /* by a new light's hits alone */
            ps->touched[S - 1 - dark++] = k; /* from the end: the two lists share the scratch */
        else if (changed)
            ps->touched[moved++] = k;
    }
    keep_aim_before(ps);
    /* scaled as their hits were, refreshed as those hits' delta_f asks, within the budget; where the AIM
     * computes direct light, its rest alone (by_rest), and not at all where that is not kept apart or an
     * edited light's direct part is computed; nor where a new light's hits are all it has (no factor
     * lights a dark surface) */
    if (first_guess) {
        lm_aim_scale_surfaces(&ps->aim, ps->atlas, ps->touched, moved, ps->aim_factor, ps->computed_factor);
        return dark ? refresh_listed_at_once(ps, ps->touched + S - dark, dark, out, err) : LM_OK;
    }
    return refresh_at_once(ps, moved, out, err);
}

/* Whether an emitter dark in every channel (was) is lit now in the same place and shape: switched on. */
static int switched_on(const emitter_snapshot *was, const emitter_snapshot *now)
{
    return !any_lit(was->power) && any_lit(now->power) && same_place(was, now);
}

/* Invalidates the groups of every emitter whose placement or power changed since its last snapshot; a
 * light changed in power alone keeps its photons, whose hits are scaled (lm_photons_scale_emitter), or,
 * turned dark, are traced again to go; either way its light is scaled at once (apply_scale). *scaled
 * counts those. With at_once, the `added` emitters (the list's last) and those switched on are traced
 * now (light_now) and counted as moved. */
static lm_status check_emitters(lm_photon_stage *ps, int added, int at_once, lm_photon_stage_frame *out,
                                lm_error *err)
{
    int *moved = &out->emitters_moved, *scaled = &out->emitters_scaled;
    *moved = *scaled = 0;
    int noted = 0;
    for (int e = 0; e < ps->emitters.count; e++) {
        emitter_snapshot now;
        take_snapshot(ps, e, &now);
        int is_new = e >= ps->emitters.count - added;
        int lit = at_once && any_lit(now.power);
        if (is_new && lit) { /* placed now, after its snapshot as it joined */
            ps->snap[e] = now;
            lm_status st = light_now(ps, e, !noted++, out, err);
            if (st != LM_OK)
                return st;
            continue;
        }
        if (!memcmp(&now, &ps->snap[e], sizeof now))
            continue;
        float s[3];
        int by_power = power_alone(ps->scene, &ps->emitters.e[e], &ps->snap[e], &now, s);
        int on_now = !by_power && lit && switched_on(&ps->snap[e], &now);
        ps->snap[e] = now;
        if (by_power && ps->have_aim)
            note_scale(ps, e, s, !noted++);
        *scaled += by_power;
        *moved += !by_power;
        lm_status st = on_now                               ? light_now(ps, e, !noted++, out, err)
                       : !by_power                          ? lm_photons_invalidate_emitter(ps->photons, e, err)
                       : ps->emitters.e[e].luminance > 0.0f ? lm_photons_scale_emitter(ps->photons, e, s, err)
                                                            : lm_photons_retrace_emitter(ps->photons, e, err);
        if (st != LM_OK)
            return st;
    }
    return noted ? apply_scale(ps, out, err) : LM_OK;
}

/* The caustic photons for the scene as it is now (made again after edits that change the generators or
 * the emitters: every photon traced). */
static lm_status make_caustics(lm_photon_stage *ps, lm_caustic_frame_stats *st, lm_error *err)
{
    lm_caustics_free(ps->caustics);
    ps->caustics = NULL;
    ps->caustic_version = ps->scene->pass_version;
    ps->caustic_emitters = ps->emitters.count;
    ps->caustics_stale = 0;
    ps->caustic_made++;
    lm_status rc = lm_caustics_create(ps->scene, ps->rt, &ps->emitters, &ps->set.caustic, &ps->caustics, st, err);
    if (ps->caustics) /* a budget's count holds for the new set's frames too */
        lm_caustics_limit_frame(ps->caustics, ps->limit.caustic_photons);
    return rc;
}

/* Whether edits changed what the caustic photons are made of: a class or switch (pass_version), an added
 * light, an edited material. */
static int caustics_outdated(const lm_photon_stage *ps)
{
    return ps->caustics_stale || ps->caustic_version != ps->scene->pass_version ||
           ps->caustic_emitters != ps->emitters.count;
}

/* One frame of the caustic photons: made again after edits that change the generators (a class or a
 * switch); an added light's pairs and a recoloured material's re-traces queued and spread over the frames
 * under the caustics' frame cap (caustics.h); then their round robin and the pairs that moved. */
static lm_status update_caustics(lm_photon_stage *ps, lm_photon_stage_frame *out, lm_error *err)
{
    if (!ps->set.caustics)
        return LM_OK;
    double t0 = lm_now();
    lm_status st = LM_OK;
    if (ps->caustics && ps->caustic_version == ps->scene->pass_version) {
        st = lm_caustics_follow_emitters(ps->caustics, err);
        ps->caustic_emitters = st == LM_OK ? ps->emitters.count : ps->caustic_emitters;
        if (ps->caustics_stale)
            lm_caustics_retrace_all_later(ps->caustics);
        ps->caustics_stale = 0;
    }
    if (st == LM_OK)
        st = caustics_outdated(ps) ? make_caustics(ps, &out->caustics, err)
                                   : lm_caustics_frame(ps->caustics, &out->caustics, err);
    out->t_caustics = lm_now() - t0;
    return st;
}

static int by_count_down(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return (x < y) - (x > y);
}

/* The AIM refreshes' bound on stored hits (lm_aim_settings.max_hits): the most an update's refresh could
 * take with the lights the scene had at creation (its surfaces_per_frame fullest surfaces), so that the
 * lights added later spread their surfaces' refreshes over updates instead of making each dearer (a soak
 * with 20 lights added to the Cornell box took 230 ms for 4 AIMs). 0 (no bound) without a budget. */
static uint64_t worst_refresh(const lm_photon_stage *ps)
{
    int S = ps->surfaces->surface_count, k = ps->set.surfaces_per_frame;
    if (k < 0 || S == 0)
        return 0;
    uint32_t *count = malloc(sizeof *count * (size_t)S);
    if (!count)
        return 0;
    const lm_photon_store *store = lm_photons_store(ps->photons);
    for (int i = 0; i < S; i++)
        count[i] = store->surfaces[i].count;
    qsort(count, (size_t)S, sizeof *count, by_count_down);
    uint64_t most = 0;
    for (int i = 0; i < k && i < S; i++)
        most += count[i];
    free(count);
    return most;
}

/* Each sun's and the sky's portals found again (trace/portal_finder.h: the openings, or the file's, and the
 * places outside that light through them); an emitter whose portals changed has its groups queued (its
 * photons go elsewhere now: the full trace that follows at setup and converge takes them). */
static lm_status find_portals(lm_photon_stage *ps, lm_error *err)
{
    if (!ps->set.trace || !ps->set.find_portals)
        return LM_OK;
    for (int e = 0; e < ps->emitters.count; e++) {
        if (!lm_portals_guide(&ps->emitters.e[e]))
            continue;
        lm_portals *found = NULL;
        lm_status st = lm_portals_find(ps->scene, ps->surfaces, ps->rt, &ps->emitters.e[e], &found, err);
        if (st == LM_OK && lm_portals_same(found, ps->emitters.e[e].portals)) {
            lm_portals_free(found);
            continue;
        }
        if (st == LM_OK) {
            lm_emitter_set_portals(&ps->emitters, e, found);
            st = lm_photons_invalidate_emitter(ps->photons, e, err);
        }
        if (st != LM_OK)
            return st;
    }
    return LM_OK;
}

/* Each sun's guide made again (trace/sun_guide.h) where the level has open surfaces and the sun no usable
 * portals; a sun whose guide changed has its photons invalidated (the full trace that follows at setup and
 * converge takes them). */
static lm_status guide_suns(lm_photon_stage *ps, lm_error *err)
{
    if (!ps->set.trace || !ps->atlas || ps->atlas->open_surfaces <= 0)
        return LM_OK;
    for (int e = 0; e < ps->emitters.count; e++) {
        lm_emitter *em = &ps->emitters.e[e];
        if (em->kind != LM_EMIT_DIRECTIONAL || (em->portals && em->portals->usable))
            continue;
        lm_sun_guide *g = NULL;
        lm_status st = lm_sun_guide_make(ps->rt, ps->scene, ps->atlas, (const float(*)[3])em->rect, em->dir, &g, err);
        if (st == LM_OK && lm_sun_guide_same(g, em->guide)) {
            lm_sun_guide_free(g);
            continue;
        }
        if (st == LM_OK) {
            lm_emitter_set_guide(&ps->emitters, e, g);
            st = lm_photons_invalidate_emitter(ps->photons, e, err);
        }
        if (st != LM_OK)
            return st;
    }
    return LM_OK;
}

/* The photon settings of the stage's photons: the settings given, with the defaults the stage chooses. */
static lm_photon_settings photon_settings(const lm_photon_stage *ps)
{
    lm_photon_settings photons = ps->set.photons;
    if (photons.cover_distance == 0.0f && ps->atlas) { /* light closer under something than a texel is hidden */
        photons.cover_distance = ps->atlas->texel_size;
        photons.cover_by_surface = ps->atlas->surface_texel_size; /* each surface's own texel */
    }
    if (!ps->set.trace) /* one photon a light, never traced: the emitters' bookkeeping without the cost */
        photons.total_photons = 0, photons.groups = 1, photons.per_group = 1;
    return photons;
}

/* The photons planned for the emitters as they are, nothing traced, into *out. */
static lm_status make_photons(lm_photon_stage *ps, lm_photons **out, lm_error *err)
{
    lm_photon_settings photons = photon_settings(ps);
    lm_status st = lm_photons_create(ps->scene, ps->surfaces, ps->rt, &ps->emitters, &photons, out, err);
    if (st == LM_OK) {
        lm_photons_set_split(*out, &ps->set.split);
        lm_photons_limit_groups(*out, ps->limit.groups);
    }
    return st;
}

/* A bake with fresh_plan after lights were added, removed or changed in power (lm_photons_plan_outdated):
 * the photons planned again as a fresh updater plans them, so that the bake gives its lightmap and not
 * one made with the shares of creation (photon noise apart: up to 15% a texel at 2,000 texels). Nothing
 * traced yet. The store's version goes on from the old one's, for whoever keeps copies by version. On
 * a failure the old photons stay. */
static lm_status plan_photons_again(lm_photon_stage *ps, lm_error *err)
{
    lm_photons *fresh = NULL;
    lm_status st = make_photons(ps, &fresh, err);
    if (st != LM_OK)
        return st;
    lm_photons_store_mutable(fresh)->version += lm_photons_store(ps->photons)->version + 1;
    lm_photons_free(ps->photons);
    ps->photons = fresh;
    return LM_OK;
}

static lm_status setup(lm_photon_stage *ps, lm_photon_stage_frame *first, lm_error *err)
{
    double t0 = lm_now();
    lm_status st = lm_emitters_build(ps->scene, &ps->emitters, err);
    if (st != LM_OK)
        return st;
    ps->have_emitters = 1;
    lm_emitters_seal(&ps->emitters, ps->scene, ps->rt);
    ps->snap = calloc((size_t)ps->emitters.count + 1, sizeof *ps->snap);
    if (!ps->snap)
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for the photon stage", ps->scene->path);
    for (int e = 0; e < ps->emitters.count; e++)
        take_snapshot(ps, e, &ps->snap[e]);
    emitters_touched(ps, lm_edits_changes(NULL), 0); /* the bounds they were placed in */
    size_t S = (size_t)ps->surfaces->surface_count + 1;
    ps->refreshed = calloc(S, 1);
    ps->delta_before = calloc(S, sizeof *ps->delta_before);
    ps->count_before = calloc(S, sizeof *ps->count_before);
    ps->light_scale = malloc(3 * S * sizeof *ps->light_scale);
    ps->flux_before = malloc(3 * S * sizeof *ps->flux_before);
    ps->aim_factor = malloc(3 * S * sizeof *ps->aim_factor);
    ps->computed_factor = malloc(3 * S * sizeof *ps->computed_factor);
    ps->flux_after = malloc(3 * S * sizeof *ps->flux_after);
    ps->flux_of = malloc(3 * S * sizeof *ps->flux_of);
    ps->touched = malloc(S * sizeof *ps->touched);
    ps->reached = malloc(S);
    ps->material_count = ps->scene->material_count;
    size_t M = (size_t)ps->material_count + 1;
    ps->materials = malloc(M * sizeof *ps->materials);
    ps->ratio = malloc(3 * M * sizeof *ps->ratio);
    if (ps->materials)
        memcpy(ps->materials, ps->scene->materials, (M - 1) * sizeof *ps->materials);
    for (size_t i = 0; ps->light_scale && i < 3 * S; i++)
        ps->light_scale[i] = 1.0f;
    if (!ps->refreshed || !ps->delta_before || !ps->count_before || !ps->light_scale || !ps->flux_before ||
        !ps->flux_after || !ps->aim_factor || !ps->computed_factor || !ps->flux_of || !ps->touched || !ps->reached ||
        !ps->materials || !ps->ratio)
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for the photon stage", ps->scene->path);
    st = make_photons(ps, &ps->photons, err);
    if (st == LM_OK)
        st = lm_moved_nodes_init(&ps->moves, ps->scene, err);
    if (st == LM_OK && !(ps->move_boxes = malloc(sizeof *ps->move_boxes * LM_MOVED_NODE_BOXES *
                                                 (size_t)(ps->scene->node_count ? ps->scene->node_count : 1))))
        st = lm_fail(err, LM_ERR_NOMEM, "%s: no memory for the photon stage", ps->scene->path);
    if (st == LM_OK)
        st = find_portals(ps, err);
    if (st == LM_OK)
        st = guide_suns(ps, err);
    if (st == LM_OK && ps->set.trace)
        st = lm_photons_trace_all(ps->photons, &first->photons, err);
    double t1 = lm_now();
    if (st == LM_OK)
        st = lm_aim_init(&ps->aim, ps->scene, ps->surfaces, ps->atlas, &ps->set.aim, err);
    ps->have_aim = st == LM_OK;
    lm_photon_settings ph = photon_settings(ps);
    if (st == LM_OK && ps->set.exact_direct != LM_EXACT_NONE)
        st = setup_direct(ps, &ph, err);
    if (st == LM_OK && ps->set.occluders) { /* lifted off surfaces as far as the gather's texels are */
        float size = lm_scene_size(ps->scene);
        lm_aim_set_occluders(&ps->aim, ps->rt, 1e-4f * (size > 0.0f && isfinite(size) ? size : 1.0f),
                             ph.cover_distance, ph.cover_by_surface);
    }
    if (st == LM_OK && ps->set.trace && ps->set.aims)
        st = lm_aim_refresh_all(&ps->aim, ps->scene, ps->surfaces, ps->atlas,
                                lm_photons_store_mutable(ps->photons), &first->aim, err);
    if (st == LM_OK)
        ps->hit_bound = worst_refresh(ps);
    double t2 = lm_now();
    if (st == LM_OK && ps->set.caustics)
        st = make_caustics(ps, &first->caustics, err);
    first->t_photons = t1 - t0;
    first->t_aim = t2 - t1;
    first->t_caustics = lm_now() - t2;
    first->t_total = lm_now() - t0;
    return st;
}

lm_status lm_photon_stage_create(const lm_world *w, const lm_photon_stage_settings *set, lm_photon_stage **out,
                                 lm_photon_stage_frame *first, lm_error *err)
{
    *out = NULL;
    lm_photon_stage *ps = calloc(1, sizeof *ps);
    if (!ps)
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for the photon stage", w->scene->path);
    if (set)
        ps->set = *set;
    else
        lm_photon_stage_settings_default(&ps->set);
    ps->scene = w->scene;
    ps->surfaces = w->surfaces;
    ps->atlas = w->atlas;
    ps->rt = w->rt;
    ps->edits = w->edits;
    lm_photon_stage_frame scratch;
    memset(&scratch, 0, sizeof scratch);
    lm_status st = setup(ps, first ? first : &scratch, err);
    if (st != LM_OK) {
        lm_photon_stage_free(ps);
        return st;
    }
    *out = ps;
    return LM_OK;
}

void lm_photon_stage_free(lm_photon_stage *ps)
{
    if (!ps)
        return;
    lm_caustics_free(ps->caustics);
    if (ps->have_aim)
        lm_aim_free(&ps->aim);
    if (ps->have_area)
        lm_emitter_light_free(&ps->area);
    lm_photons_free(ps->photons);
    if (ps->have_emitters)
        lm_emitters_free(&ps->emitters);
    free(ps->snap);
    free(ps->refreshed);
    free(ps->delta_before);
    free(ps->count_before);
    free(ps->light_scale);
    free(ps->flux_before);
    free(ps->flux_after);
    free(ps->aim_factor);
    free(ps->computed_factor);
    free(ps->flux_of);
    free(ps->touched);
    free(ps->reached);
    free(ps->materials);
    free(ps->ratio);
    lm_moved_nodes_free(&ps->moves);
    free(ps->move_boxes);
    free(ps->aim_before);
    free(ps->emissive_before);
    free(ps);
}

static lm_status refresh_aims(lm_photon_stage *ps, int budget, lm_aim_stats *out, lm_error *err);

/* A node or a light placed or reshaped by an edit after an update without edits (an artist's drag
 * committed on release, a door set open) is caught up as the edit's own work, as a light lit is
 * (light_now): every group it queued is re-traced and every AIM over its threshold refreshed now, rather
 * than 16 groups and 4 AIMs an update. The lightmaps' regathers wait on those: the moved cube's faces and
 * the floor around it took 24 updates to come within 10% of a fresh bake. Edits made update after update
 * (a drag committed every frame, an engine driving a node, a soak of random edits) stay with the fixed
 * counts while they last: caught up each time, the two rooms' soak ran its median update 40% longer and
 * its resident memory 20 MB higher. Their placements are caught up at the first update without edits
 * after them (the drag released). Everything under a time budget keeps to its plan (update/budget_plan.h). */
static lm_status catch_up(lm_photon_stage *ps, lm_photon_stage_frame *out, lm_error *err)
{
    out->placed = 1;
    lm_status st = lm_photons_drain_all(ps->photons, &out->caught_up, err);
    if (st != LM_OK || !ps->set.aims)
        return st;
    lm_aim_stats as;
    st = refresh_aims(ps, -1, &as, err); /* every surface over its threshold, no bound on hits (as a bake) */
    add_aim_stats(out, &as);
    out->aim_at_once += as.surfaces_refreshed;
    return st;
}

/* The boxes the animated nodes' moves may queue paths with this frame (moved_nodes.h): each costs a test
 * of every stored photon's path (lm_photons_invalidate_boxes), so past LM_ANIMATED_BOX_WORK photons a box
 * the round robin alone finds their changed paths, as in the paper. */
static int animated_room(const lm_photon_stage *ps)
{
    uint32_t photons = lm_photons_count(ps->photons);
    uint32_t room = photons ? LM_ANIMATED_BOX_WORK / photons : LM_MOVED_NODE_BOXES;
    return room > (uint32_t)(2 * ps->scene->node_count) ? 2 * ps->scene->node_count : (int)room;
}

/* lm_photon_stage_animate; `bake`: a full trace follows, which traces newly lit emitters with the rest
 * (and counts their paths as changed), so they are not traced at once here. */
static lm_status animate(lm_photon_stage *ps, float t, int bake, lm_photon_stage_frame *out, lm_error *err)
{
    memset(out, 0, sizeof *out);
    out->frame = ps->frame++;
    out->time = t;
    double t0 = lm_now();
    if (ps->scene->animation_count > 0) {
        lm_scene_eval_animation(ps->scene, -1, t);
        lm_status st = lm_rt_sync_transforms(ps->rt, ps->scene, err);
        if (st != LM_OK)
            return st;
    }
    /* what the edits committed since the last frame changed (update/edits.h), taken once */
    const lm_edit_changes *ch = lm_edits_changes(ps->edits);
    int moved = ch->moved && ps->photons && ps->set.trace;
    int room = ps->scene->animation_count > 0 && ps->photons && ps->set.trace ? animated_room(ps) : 0;
    ps->animated_boxes = 0;
    if (moved || room > 0) { /* an edit's move, or an animation's: their paths found now (moved_nodes.h) */
        int boxes = lm_moved_nodes_boxes(&ps->moves, ps->scene, ps->move_boxes, room);
        if (moved || bake) /* queued: the edit's catch-up, or the bake's full trace, takes them */
            lm_photons_invalidate_boxes(ps->photons, ps->move_boxes, boxes);
        else /* re-traced photon by photon in the update half, off the calling thread */
            ps->animated_boxes = boxes;
    }
    int added = 0;
    lm_status st = take_new_emitters(ps, &added, err);
    if (emitters_touched(ps, ch, added)) {
        lm_emitters_update(&ps->emitters, ps->scene);
        lm_emitters_seal(&ps->emitters, ps->scene, ps->rt);
        if (st == LM_OK)
            st = check_emitters(ps, added, !bake && lights_at_once(ps), out, err);
    }
    int placed = (moved || (ch->lights_changed && out->emitters_moved > 0)) && ps->photons && ps->set.trace;
    int edited = ch->moved || ch->lights_changed || ch->materials_changed || ch->sky || added;
    int caught = st == LM_OK && !bake && !budgeted(ps) && (placed ? !ps->edited_before : ps->uncaught && !edited);
    if (caught)
        st = catch_up(ps, out, err);
    ps->uncaught = !caught && !bake && (ps->uncaught || placed);
    ps->edited_before = edited;
    out->emitters_moved += added;
    lm_status sm = follow_materials(ps, ch, out, st == LM_OK ? err : NULL);
    st = st == LM_OK ? sm : st;
    lm_edits_clear_changes(ps->edits);
    out->t_total = lm_now() - t0;
    out->t_animate = out->t_total - out->t_aim; /* the edits' AIM refreshes are AIM time */
    return st;
}

lm_status lm_photon_stage_animate(lm_photon_stage *ps, float t, lm_photon_stage_frame *out, lm_error *err)
{
    return animate(ps, t, 0, out, err);
}

/* A refreshed AIM whose change is at least this fraction of all the energy stored in hits counts for the
 * surfaces that see it (lm_photon_stage_take_refreshed); smaller changes, such as the few photons that
 * reach the edges of a closed door from the far room, are not worth regathering everything that sees
 * them. */
#define SEEN_CHANGE 1e-3

/* lm_aim_refresh, noting which surfaces it refreshed (their delta_f went to 0) by a change worth seeing. */
static lm_status refresh_aims(lm_photon_stage *ps, int budget, lm_aim_stats *out, lm_error *err)
{
    lm_photon_store *store = lm_photons_store_mutable(ps->photons);
    int S = ps->surfaces->surface_count;
    uint64_t hits = 0;
    for (int k = 0; k < S; k++) { /* the change each would be refreshed for, and whether it was (its count) */
        ps->delta_before[k] = store->surfaces[k].delta_f + ps->aim.owed[k];
        ps->count_before[k] = ps->aim.refresh_count[k];
        hits += store->surfaces[k].count;
    }
    lm_status st = lm_aim_refresh(&ps->aim, ps->scene, ps->surfaces, ps->atlas, store, budget, out, err);
    ps->aim_pending = st == LM_OK ? out->surfaces_pending : ps->aim_pending;
    double seen = SEEN_CHANGE * ps->aim.mean_hit_energy * (double)hits;
    for (int k = 0; k < S; k++)
        ps->refreshed[k] |= ps->delta_before[k] > seen && ps->aim.refresh_count[k] != ps->count_before[k];
    return st;
}

/* Every surface's AIM made again from a new photon set (lm_aim_refresh_all): each counts as refreshed,
 * since photons all over have changed. */
static lm_status refresh_all_aims(lm_photon_stage *ps, lm_aim_stats *out, lm_error *err)
{
    lm_status st = lm_aim_refresh_all(&ps->aim, ps->scene, ps->surfaces, ps->atlas,
                                      lm_photons_store_mutable(ps->photons), out, err);
    memset(ps->refreshed, 1, (size_t)ps->surfaces->surface_count);
    ps->aim_pending = st == LM_OK ? 0 : ps->aim_pending;
    return st;
}

/* The photons of lights removed for good given back once their removal's re-trace has emptied them: a
 * soak that adds and removes lights held every removed light's paths (lmgi_remove_light). */
static void release_removed(lm_photon_stage *ps)
{
    for (int e = 0; e < ps->emitters.count; e++)
        if (lm_emitter_removed(ps->scene, &ps->emitters.e[e]))
            lm_photons_release_emitter(ps->photons, e);
}

/* A frame's photon stats with the animated boxes' photons (lm_photons_retrace_boxes) added. */
static void add_box_stats(lm_photon_frame_stats *to, const lm_photon_frame_stats *b)
{
    to->box_photons += b->box_photons;
    to->photons_updated += b->photons_updated;
    to->hits_added += b->hits_added;
    to->hits_removed += b->hits_removed;
    to->rays += b->rays;
    to->seconds += b->seconds;
}

lm_status lm_photon_stage_update(lm_photon_stage *ps, lm_photon_stage_frame *out, lm_error *err)
{
    double t1 = lm_now();
    lm_photon_frame_stats boxed;
    memset(&boxed, 0, sizeof boxed);
    lm_status st = ps->set.trace && ps->animated_boxes > 0
                       ? lm_photons_retrace_boxes(ps->photons, ps->move_boxes, ps->animated_boxes, &boxed, err)
                       : LM_OK;
    ps->animated_boxes = 0;
    if (st == LM_OK && ps->set.trace)
        st = lm_photons_frame(ps->photons, lm_scene_any_node_moves(ps->scene), &out->photons, err);
    add_box_stats(&out->photons, &boxed);
    if (st == LM_OK && ps->set.trace)
        release_removed(ps);
    double t2 = lm_now();
    if (st == LM_OK && ps->set.trace && ps->set.aims) {
        /* a budget's bound on hits takes any number of surfaces within it */
        ps->aim.set.max_hits = ps->limit.aim_hits ? ps->limit.aim_hits : ps->hit_bound;
        lm_aim_stats as;
        st = refresh_aims(ps, ps->limit.aim_hits ? ps->surfaces->surface_count : ps->set.surfaces_per_frame, &as,
                          err);
        add_aim_stats(out, &as);
    }
    if (st == LM_OK)
        st = update_caustics(ps, out, err);
    out->t_photons = t2 - t1;
    out->t_total += lm_now() - t1;
    return st;
}

lm_status lm_photon_stage_step(lm_photon_stage *ps, float t, lm_photon_stage_frame *out, lm_error *err)
{
    lm_status st = lm_photon_stage_animate(ps, t, out, err);
    return st == LM_OK ? lm_photon_stage_update(ps, out, err) : st;
}

lm_status lm_photon_stage_converge(lm_photon_stage *ps, float t, int fresh_plan, lm_photon_stage_frame *out,
                                   lm_error *err)
{
    lm_status st = animate(ps, t, 1, out, err);
    if (st == LM_OK && ps->set.caustics) { /* every caustic photon traced again */
        double t0 = lm_now();
        st = caustics_outdated(ps) ? make_caustics(ps, &out->caustics, err)
                                   : lm_caustics_trace_all(ps->caustics, &out->caustics, err);
        out->t_caustics = lm_now() - t0;
    }
    if (st != LM_OK || !ps->set.trace)
        return st;
    double t1 = lm_now();
    int replan = fresh_plan && lm_photons_plan_outdated(ps->photons);
    if (st == LM_OK)
        st = find_portals(ps, err);
    if (st == LM_OK)
        st = guide_suns(ps, err);
    if (st == LM_OK && replan)
        st = plan_photons_again(ps, err);
    if (st == LM_OK) /* with fresh_plan, what a fresh trace stores, to the bit */
        st = fresh_plan ? lm_photons_trace_all_exact(ps->photons, &out->photons, err)
                        : lm_photons_trace_all(ps->photons, &out->photons, err);
    double t2 = lm_now();
    lm_aim_stats as;
    memset(&as, 0, sizeof as);
    if (st == LM_OK && ps->set.aims && replan) {
        st = refresh_all_aims(ps, &as, err);
    } else if (st == LM_OK && ps->set.aims) {
        float threshold = ps->aim.set.delta_threshold; /* a bake refreshes every surface whose photons changed */
        ps->aim.set.delta_threshold = 0.0f;
        st = refresh_aims(ps, -1, &as, err);
        ps->aim.set.delta_threshold = threshold;
    }
    add_aim_stats(out, &as);
    out->t_photons = t2 - t1;
    out->t_total = out->t_animate + out->t_photons + out->t_aim + out->t_caustics;
    return st;
}

int lm_photon_stage_take_refreshed(lm_photon_stage *ps, uint8_t *out)
{
    int n = 0;
    for (int k = 0; k < ps->surfaces->surface_count; k++) {
        n += out[k] = ps->refreshed[k];
        ps->refreshed[k] = 0;
    }
    return n;
}

int lm_photon_stage_take_scale(lm_photon_stage *ps, float *out, float **aim_before, float **emissive_before)
{
    int S = ps->surfaces->surface_count, any = ps->scaled ? 1 + ps->scaled_lit : 0;
    for (int i = 0; i < 3 * S; i++) {
        out[i] = ps->light_scale[i];
        ps->light_scale[i] = 1.0f;
    }
    *aim_before = ps->aim_before;
    *emissive_before = ps->emissive_before;
    ps->aim_before = ps->emissive_before = NULL;
    ps->scaled = ps->scaled_lit = ps->scaled_materials = 0;
    return any;
}

int lm_photon_stage_scale_recoloured(const lm_photon_stage *ps) { return ps->scaled_materials; }

int lm_photon_stage_scale_waiting(const lm_photon_stage *ps) { return ps->scaled; }
const lm_photons *lm_photon_stage_photons(const lm_photon_stage *ps) { return ps->photons; }
lm_photon_store *lm_photon_stage_store(lm_photon_stage *ps) { return lm_photons_store_mutable(ps->photons); }
const lm_aim *lm_photon_stage_aim(const lm_photon_stage *ps) { return &ps->aim; }
const lm_direct_light *lm_photon_stage_direct(const lm_photon_stage *ps) { return ps->aim.direct; }
lm_direct_light lm_photon_stage_punctual_light(const lm_photon_stage *ps)
{
    lm_direct_light d = ps->aim.direct ? *ps->aim.direct
                                       : (lm_direct_light){ps->scene, ps->rt, &ps->emitters, NULL, LM_DIRECT_NONE,
                                                           lm_scene_ray_lift(ps->scene), 0.0f, NULL};
    d.punctual = LM_DIRECT_PUNCTUAL;
    d.area = NULL; /* a bounce pass's map holds the emitters' light */
    return d;
}
const lm_emitters *lm_photon_stage_emitters(const lm_photon_stage *ps) { return &ps->emitters; }
const lm_caustics *lm_photon_stage_caustics(const lm_photon_stage *ps) { return ps->caustics; }

void lm_photon_stage_set_budgeted(lm_photon_stage *ps, int on) { ps->budgeted = on; }

void lm_photon_stage_limit(lm_photon_stage *ps, const lm_photon_stage_limits *l)
{
    ps->limit = *l;
    if (ps->photons)
        lm_photons_limit_groups(ps->photons, l->groups);
    if (ps->caustics)
        lm_caustics_limit_frame(ps->caustics, l->caustic_photons);
}

void lm_photon_stage_waiting(const lm_photon_stage *ps, uint32_t *groups, uint32_t *caustic_photons)
{
    *groups = ps->photons && ps->set.trace ? lm_photons_pending_groups(ps->photons) : 0;
    *caustic_photons = ps->caustics ? lm_caustics_wanted(ps->caustics) : 0;
}

int lm_photon_stage_settled(const lm_photon_stage *ps)
{
    return !(ps->photons && ps->set.trace && lm_photons_pending_groups(ps->photons)) && !ps->aim_pending;
}

uint64_t lm_photon_stage_caustics_version(const lm_photon_stage *ps)
{
    return ps->caustic_made << 40 | (ps->caustics ? lm_caustics_version(ps->caustics) : 0);
}
