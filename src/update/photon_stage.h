/* The photon stage of the frame loop (Larsen & Christensen sections 2-3 and 5): play the scene's
 * animations, move instances, notice moved or changed lights, re-trace photons round robin and invalid
 * groups under their budget, refresh the AIMs of the surfaces that changed most, under theirs, and keep
 * the caustic photons current (trace/caustics.h). */
#ifndef LM_PHOTON_STAGE_H
#define LM_PHOTON_STAGE_H

#include "../photonmap/aim.h"
#include "../trace/caustics.h"
#include "../trace/lights.h"
#include "../trace/photons.h"
#include "world.h"

/* Photon-box pairs an update's animated nodes may test (photon_stage.c, animated_room): re-tracing the paths
 * that cross where a moving node was and is (lm_photons_retrace_boxes) costs a pass over every stored path
 * a box. The animated Cornell box (46,080 photons, six boxes) tests 276,480; a level of a million photons
 * leaves its animated nodes to the round robin. */
#define LM_ANIMATED_BOX_WORK (1u << 19)

typedef struct {
    lm_photon_settings photons; /* cover_distance 0 (default) is the atlas's texel size here; < 0: off */
    lm_aim_settings aim;
    int surfaces_per_frame;  /* AIM refreshes per frame, largest delta_f/area first (default 8; < 0 all) */
    int trace;               /* 0: no photon is traced and no AIM filled, at setup or after (a run without
                              * indirect light: the stage keeps only the emitters and the animations) */
    int aims;                /* 0: photons traced, no AIM filled (an indirect path that gathers from the
                              * photons themselves) */
    int exact_direct;        /* AIM texels compute direct light (trace/direct_irradiance.h), photons bring the
                              * rest (LM_EXACT_*) */
    int direct_at_hits;      /* 1: the AIM also keeps its texels without the direct part it computes
                              * (lm_aim_keep_rest), for a ray gather that computes that part at its hits
                              * (lm_gather_set_direct_at_hits); 0 (default): kept only where the punctual
                              * lights' part is all the AIM computes (no emissive triangles'), for the first
                              * guess of other lights' edits under a budget (photon_stage.c, by_rest) */
    int occluders;           /* 1: an AIM texel counts only the hits whose photon came from where it sees
                              * (lm_aim_set_occluders); 0 (default): every hit near it, the paper's */
    int caustics;            /* 1: caustic photons towards the mirror and glass nodes (none exist without
                              * them: no work at all). Default 0; the frame loop follows the scene's effects */
    lm_caustic_settings caustic;
    lm_photon_split split;   /* full traces shared among processes (photons.h); zero: none */
    int find_portals;        /* 1 (default): suns' and the sky's portals found (trace/portal_finder.h) at setup
                              * and at every converge, where the file tags none; 0: only the file's */
} lm_photon_stage_settings;

typedef struct {
    int frame;
    float time;              /* animation time, seconds */
    int emitters_moved;      /* emitters whose placement changed this frame, that were added, or lit from
                              * dark: their photons are traced again */
    int emitters_scaled;     /* lights changed in power alone this frame (or emitters of one material in their
                              * emission), their light scaled at once
                              * (lm_photon_stage_take_scale): their hits scaled, not traced again, or, turned
                              * dark, traced again to go */
    int emitters_lit;        /* of emitters_moved, those lit where they gave no light (added, or switched on
                              * from dark) and traced at once this frame, not queued (not in a bake, which
                              * traces every photon) */
    int materials_changed;   /* materials whose colour or emission an edit changed since last frame */
    int aim_at_once;         /* of aim.surfaces_refreshed, those refreshed at once for this frame's light,
                              * emission or colour edits, or for a node or light placed after a still frame
                              * (lm_photon_stage_animate) */
    int placed;              /* this frame caught up with placements: a node or light placed after a still
                              * frame, or those placed by edits in a row, at the first frame without edits
                              * after them (docs/photons.md, "Caught up in one update") */
    lm_photon_frame_stats caught_up; /* the invalid groups that catch-up re-traced at once (none where the
                              * group budget had already taken them); apart from photons, which are the
                              * round robin's and the group budget's */
    lm_photon_frame_stats photons;
    lm_aim_stats aim;
    lm_caustic_frame_stats caustics; /* its seconds are t_caustics */
    double t_animate, t_photons, t_aim, t_caustics, t_total; /* seconds */
} lm_photon_stage_frame;

typedef struct lm_photon_stage lm_photon_stage;

/* exact_direct: which direct light the AIM texels compute. NONE: photons bring all of it (the paper's form);
 * EMITTERS: emissive triangles' (where their closed form suits the scene); ALL: theirs and every punctual
 * light's; SUNS (the default): directional lights' alone. */
enum { LM_EXACT_NONE = 0, LM_EXACT_EMITTERS = 1, LM_EXACT_ALL = 2, LM_EXACT_SUNS = 3 };

void lm_photon_stage_settings_default(lm_photon_stage_settings *s);
/* exact_direct for lmgi.h's lmgi_aim_direct value v (1 suns, 2 emitters, 3 all, 4 photons; 0, the scene's
 * choice, is SUNS here: lmgi_updater_create makes it EMITTERS where emissive triangles alone light the
 * scene). */
static inline int lm_exact_direct_of(int v)
{
    return v == 4 ? LM_EXACT_NONE : v == 2 ? LM_EXACT_EMITTERS : v == 3 ? LM_EXACT_ALL : LM_EXACT_SUNS;
}
/* Builds emitters, traces every photon and fills every AIM (the first frame's state). `setup` (may be
 * NULL) gets the time of that full trace and refresh. The world (update/world.h) is borrowed and must
 * outlive the stage; the stage moves the BVH's instances as animations play. */
lm_status lm_photon_stage_create(const lm_world *w, const lm_photon_stage_settings *set, lm_photon_stage **out,
                                 lm_photon_stage_frame *setup, lm_error *err);
void lm_photon_stage_free(lm_photon_stage *ps);
/* One frame at animation time t (every animation evaluated; t is clamped to each one's range):
 * lm_photon_stage_animate, then lm_photon_stage_update. */
lm_status lm_photon_stage_step(lm_photon_stage *ps, float t, lm_photon_stage_frame *out, lm_error *err);
/* The first half: animations, node transforms (scene and BVH), emitters and the groups of moved lights
 * marked invalid. */
lm_status lm_photon_stage_animate(lm_photon_stage *ps, float t, lm_photon_stage_frame *out, lm_error *err);
/* The second half: photons re-traced and AIMs refreshed (out: the frame lm_photon_stage_animate began).
 * It reads the scene and BVH and writes only the stage's photons, store and AIM, so it may run on
 * another thread beside rendering that only reads the scene (the frame loop's overlap). */
lm_status lm_photon_stage_update(lm_photon_stage *ps, lm_photon_stage_frame *out, lm_error *err);

/* A full refresh at time t, for a bake: animate, then every photon re-traced (a path that did not change
 * changes nothing in the store) and the AIM of every surface whose photons changed refreshed. With
 * fresh_plan, photons whose plan a fresh stage would make otherwise (lights changed in power or number
 * since creation: lm_photons_plan_outdated) are planned again as it would, traced, and every AIM
 * refreshed (each counts as refreshed); on a failure there the old photons stay. With fresh_plan the
 * trace also replaces every path that differs in any bit (lm_photons_trace_all_exact), so that the store
 * is a fresh stage's. */
lm_status lm_photon_stage_converge(lm_photon_stage *ps, float t, int fresh_plan, lm_photon_stage_frame *out,
                                   lm_error *err);
/* Per surface, 1 if its AIM was refreshed since the last call (by updates or a converge) for a change of
 * at least a thousandth of the energy stored in hits, into out
 * (surface_count bytes); clears the record. Returns how many. Not while an update runs on another
 * thread. */
int lm_photon_stage_take_refreshed(lm_photon_stage *ps, uint8_t *out);

/* Per surface and channel (surface_count x 3 floats into out), what the lights and emitters changed in
 * power alone since the last call multiplied its hits' light by (docs/tradeoff.md, "Light edits at
 * once"); 1 where nothing changed. Those edits and material edits refreshed the AIMs they reach in the
 * update that saw them; *aim_before is the dilated AIM before, and *emissive_before each material's
 * emission before (material_count x 3), from which the IIM's own factors follow (update/light_scale.h):
 * both malloc'd, the caller's to free, NULL when nothing changed or memory ran out. Resets them. Returns
 * 0 when nothing changed, 2 when a light was lit where it gave no light (added or switched on: its light
 * falls where there may have been none, light_scale.h's `adds`), else 1. Not while an update runs on
 * another thread. */
int lm_photon_stage_take_scale(lm_photon_stage *ps, float *out, float **aim_before, float **emissive_before);
/* Whether the scaling lm_photon_stage_take_scale would hand on includes a material's edit: its first guess
 * is right to first order only (a light's power is exact in its own light), so the texels it moved most are
 * regathered first (photonmap/texel_change.h, lm_texel_change_first_guess). */
int lm_photon_stage_scale_recoloured(const lm_photon_stage *ps);
/* Whether a scaling waits for lm_photon_stage_take_scale (the plan of the update that takes it). */
int lm_photon_stage_scale_waiting(const lm_photon_stage *ps);

/* What a time budget allows the next updates (update/budget_plan.h): invalid photon groups re-traced, the
 * AIM refresh's bound on stored hits (then any number of surfaces within it; its first surface always),
 * caustic photons traced; each 0: the settings' own count. Not while an update runs on another thread. */
typedef struct {
    uint32_t groups;
    uint64_t aim_hits;
    uint32_t caustic_photons;
} lm_photon_stage_limits;
void lm_photon_stage_limit(lm_photon_stage *ps, const lm_photon_stage_limits *l);
/* Whether this update runs under a time budget, set before its animate: an edit's work at once is then
 * the cheap first guess, and no placement is caught up (catch_up). Before, the last update's limits
 * said so, and the first update given a budget (or the first without one) still followed the one before. */
void lm_photon_stage_set_budgeted(lm_photon_stage *ps, int budgeted);
/* The work waiting: invalid photon groups queued, the caustic photons the next update would trace
 * (lm_caustics_wanted). */
void lm_photon_stage_waiting(const lm_photon_stage *ps, uint32_t *groups, uint32_t *caustic_photons);
/* Whether the stage has caught up: no invalid photon group queued, and the last AIM refresh left no surface
 * over its threshold for later. Not while an update runs on another thread. */
int lm_photon_stage_settled(const lm_photon_stage *ps);

const lm_photons *lm_photon_stage_photons(const lm_photon_stage *ps);
/* The photon store, writable: the IIM scheduler resets a surface's delta_i once it is regathered. */
lm_photon_store *lm_photon_stage_store(lm_photon_stage *ps);
const lm_aim *lm_photon_stage_aim(const lm_photon_stage *ps);
/* The direct light the AIM texels compute (exact_direct), NULL when they compute none. */
const lm_direct_light *lm_photon_stage_direct(const lm_photon_stage *ps);
/* Every punctual light's direct light at a point, for a gather that takes it at its rays' hits: the AIMs'
 * direct light with every punctual light on and no emissive triangle (a bounce pass's map holds their
 * light unless it sets them back, lightmap_path.c), or, where the AIMs compute none, one made for the
 * purpose. */
lm_direct_light lm_photon_stage_punctual_light(const lm_photon_stage *ps);
const lm_emitters *lm_photon_stage_emitters(const lm_photon_stage *ps);
/* The caustic photons; NULL when the settings have none. A class or switch edit (lm_scene.pass_version), an
 * added light or an edited material makes them again at the next update (a full trace). */
const lm_caustics *lm_photon_stage_caustics(const lm_photon_stage *ps);
/* A counter that moves whenever the caustic photons changed, across their being made again (which
 * lm_caustics_version alone does not see: a new set counts from 0 again). */
uint64_t lm_photon_stage_caustics_version(const lm_photon_stage *ps);

#endif
