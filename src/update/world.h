/* What the runtime works on: the scene and what was built from it at load, handed to the photon stage
 * and the frame loop as one (a loaded lmgi_scene holds one, pointing into itself).
 *
 * All are borrowed and must outlive the stage or loop made from them. The scene and the BVH change as
 * animations and edits move nodes (the stage and loop do that themselves, on their thread; an edit's
 * placements reach the BVH at the next commit, edits.h); the surfaces and the atlas never change after
 * load. */
#ifndef LM_WORLD_H
#define LM_WORLD_H

#include "../charts/charts.h"
#include "../scene/scene.h"
#include "../trace/rt_scene.h"
#include "edits.h"

typedef struct lm_world {
    lm_scene *scene;
    const lm_surfaces *surfaces;
    const lm_atlas *atlas;
    lm_rt *rt;
    lm_edit_batch *edits; /* edits staged for the BVH's next commit (edits.h); NULL: every change committed */
} lm_world;

#endif
