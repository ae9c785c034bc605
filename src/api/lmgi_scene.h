/* The inside of the public lmgi_scene handle (shared by the files that implement include/lmgi.h). */
#ifndef LM_LMGI_SCENE_H
#define LM_LMGI_SCENE_H

#include <lmgi.h>

#include "../charts/charts.h"
#include "../trace/rt_scene.h"
#include "../update/effects.h"
#include "../update/world.h"

struct lmgi_scene {
    lmgi_options options;
    lm_scene *scene;
    lm_surfaces surfaces;
    lm_atlas atlas;
    int have_surfaces, have_atlas;
    int *surface_rects;     /* 4 a surface: its texels' bounding box in the atlas (x, y, w, h; 0 x 0 where none) */
    lm_rt *rt;
    lm_world world;         /* the four above, for the runtime (set once they are built) */
    lm_effects effects;
    lmgi_timings timings;
    lmgi_updater *updater;  /* the one updater working on it (it moves nodes and the BVH), or NULL */
};

/* Copies an internal error into the public one and returns its status. */
lmgi_status lm_export_error(lmgi_error *out, const lm_error *in);
/* Fills err with LMGI_ERR_INVALID and the formatted message, and returns LMGI_ERR_INVALID. */
lmgi_status lm_api_refuse(lmgi_error *err, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

#endif
