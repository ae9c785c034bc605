/* Which nodes an edit placed elsewhere since the last look, and where they were and are now: the boxes
 * the photon stage queues the paths of at once (trace/photons.h, lm_photons_invalidate_boxes), where the
 * paper's round robin alone finds a moved object's changed paths one photon a group an update.
 *
 * A node counts when its world matrix changed. One an animation drives (a channel on it or on a node above
 * it that is not itself placed by an edit, lm_node.edited) counts only within the caller's room for them:
 * animated nodes move a little every frame, and the paper leaves them to the round robin, which finds
 * their changed paths one photon a group an update; a moving cube's own faces then read the floor's AIM
 * from where the cube stood seconds ago (docs/photons.md, "Animated nodes"). Its box is its triangles' box in its local space
 * (lm_scene_node_local_boxes) placed by the old and the new matrix (lm_box_placed), so a child that follows
 * an edited parent counts too.
 *
 * Layout: per node the world matrix last seen (16 floats) and its local box (6 floats; min > max: no
 * triangles). Memory: 88 bytes a node. Cost: O(nodes) a call, O(channels x depth) for a moved node.
 * Deterministic. Not thread-safe: the scene must not change meanwhile. Errors: no memory at init. */
#ifndef LM_MOVED_NODES_H
#define LM_MOVED_NODES_H

#include "../core/error.h"
#include "scene.h"

typedef struct {
    int node_count;
    float *world;     /* per node, 16 */
    float *local_box; /* per node, 6: min x, y, z, max x, y, z */
} lm_moved_nodes;

lm_status lm_moved_nodes_init(lm_moved_nodes *m, const lm_scene *s, lm_error *err);
void lm_moved_nodes_free(lm_moved_nodes *m);
/* Into out (room for 12 x node_count floats, LM_MOVED_NODE_BOXES a node): for every node with triangles that
 * moved since the last call (or the init), its world box where it was, then where it is, those of animated
 * nodes only while animated_room (boxes) lasts; every node's matrix noted. Returns how many boxes (two a
 * moved node). */
#define LM_MOVED_NODE_BOXES 12
int lm_moved_nodes_boxes(lm_moved_nodes *m, const lm_scene *s, float *out, int animated_room);

#endif
