/* Edits staged until a commit (Embree's rtcCommitScene is the model): an edit changes the scene model at
 * once (after waiting for the photon work that reads it), and the BVH follows at the commit, once for a
 * whole batch of edits: one instance update per dynamic node and one top-level commit, however many nodes
 * were moved.
 *
 * The commit is made at the start of the frame loop's next step, bake or picture (frame_loop.c), before
 * anything traces a ray, and by the API before its own rays (lmgi_intersect, the reference solver, an
 * updater made on the scene) or when the caller asks (lmgi_commit). Between an edit and the commit the
 * BVH still holds the placements of the last commit; nothing traces it meanwhile.
 *
 * Not thread-safe: the commit runs on the thread that owns the world, with no photon work running (edits
 * join it before they change the scene, and no step has started one since). Errors: the BVH's (Embree's
 * out of memory), with the batch kept for the next commit. */
#ifndef LM_EDITS_H
#define LM_EDITS_H

#include <stdint.h>

#include "../core/error.h"

struct lm_world;

typedef struct lm_edit_batch {
    uint32_t moved; /* node placements changed in the scene model since the BVH's last commit */
} lm_edit_batch;

/* The BVH brought to the scene model's placements when a batch is staged; nothing otherwise. */
lm_status lm_edits_commit(const struct lm_world *w, lm_error *err);

#endif
