/* The inside of the public lmgi_scene handle (shared by the files that implement include/lmgi.h). */
#ifndef LM_LMGI_SCENE_H
#define LM_LMGI_SCENE_H

#include <lmgi.h>

#include "../charts/charts.h"
#include "api_error.h"
#include "../trace/rt_scene.h"
#include "../update/effects.h"
#include "../update/frame_loop.h"
#include "../update/world.h"

struct lmgi_scene {
    lmgi_options options;
    lm_scene *scene;
    lm_surfaces surfaces;
    lm_atlas atlas;
    int have_surfaces, have_atlas;
    int *surface_rects;     /* 4 a surface: its texels' bounding box in the atlas (x, y, w, h; 0 x 0 where none) */
    lm_rt *rt;
    lm_world world;         /* the four above and the edits, for the runtime (set once they are built) */
    lm_edit_batch edits;    /* edits staged for the next commit (update/edits.h) */
    lm_effects effects;
    lmgi_timings timings;
    lmgi_updater *updater;  /* the one updater working on it (it moves nodes and the BVH), or NULL; */
    lm_frame_loop *loop;    /* its frame loop and context, which an edit waits for and claims first */
    lmgi_context *ctx;      /* (lm_scene_quiet) */
};

/* Before an edit changes what the scene's updater reads (the scene, its BVH, lights, materials, sky):
 * the photon work the last update left running is waited for; with staged edits waiting, as
 * lm_scene_before_change, since a commit follows wherever it is called. Refused (LMGI_ERR_INVALID naming
 * fn) while another thread is inside a call on the updater's context. LMGI_OK at once without an updater. */
lmgi_status lm_scene_quiet(const lmgi_scene *sc, const char *fn, lmgi_error *err);
/* As lm_scene_quiet, before an edit that writes the scene at once (a node's transform, an animation's
 * time): the updater takes what it must of the scene as it is (lm_frame_loop_before_change). */
lmgi_status lm_scene_before_change(const lmgi_scene *sc, const char *fn, lmgi_error *err);
/* The staged edits committed (update/edits.h), after waiting for the photon work when any are staged:
 * before the API traces rays of its own or reads the scene model (exports, reports). */
lmgi_status lm_scene_commit(const lmgi_scene *sc, lmgi_error *err);
/* An edit checked by its caller staged for the next commit (refused, naming fn, while another thread is
 * inside a call on the updater's context). id -1 adds a light. */
lmgi_status lm_scene_stage_light(lmgi_scene *sc, const char *fn, int id, const lm_light *l, lmgi_error *err);
lmgi_status lm_scene_stage_material(lmgi_scene *sc, const char *fn, int id, const lm_material *m, lmgi_error *err);
lmgi_status lm_scene_stage_sky(lmgi_scene *sc, const char *fn, const lm_staged_sky *sky, lmgi_error *err);

#endif
