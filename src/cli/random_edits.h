/* Random edits through the public API, as an editor or a game makes them: the soak's load (`lmgi bench
 * --soak N --random-edits L`, docs/bench.md, "Soak") and what the soak test plays.
 *
 * Each lm_random_edit makes one edit drawn from a fixed mix: a dynamic node moved (a random walk around
 * where it was at load, within a tenth of the scene's size), a light dimmed, brightened or recoloured, a
 * material recoloured, or a light added or removed. Lights are added (point and spot lights placed at
 * random inside the scene's bounds, of the file's lights' mean intensity) while fewer than max_lights
 * are on, and removed (only added ones) once max_lights are, so the light count climbs to max_lights
 * and then holds there while lights come and go. Deterministic for a seed: the same scene and seed make
 * the same edits. Not thread-safe: one state per thread; the scene's edit rules (lmgi.h) apply. */
#ifndef LM_CLI_RANDOM_EDITS_H
#define LM_CLI_RANDOM_EDITS_H

#include <lmgi.h>
#include <stdint.h>

typedef enum { LM_EDIT_NODE, LM_EDIT_LIGHT, LM_EDIT_MATERIAL, LM_EDIT_ADD_LIGHT, LM_EDIT_REMOVE_LIGHT,
               LM_EDIT_KINDS } lm_edit_kind;

#define LM_RANDOM_EDITS_MAX_NODES 64 /* dynamic nodes walked (the first ones) */

typedef struct {
    uint64_t rng;
    int max_lights;
    float lo[3], hi[3];              /* the scene's bounds at the start */
    float mean_intensity;            /* of the file's lights (1 when it has none) */
    int nodes, node[LM_RANDOM_EDITS_MAX_NODES];
    float home[LM_RANDOM_EDITS_MAX_NODES][16]; /* each walked node's world matrix at the start */
    int *added, added_count;         /* live added lights' ids */
    long made[LM_EDIT_KINDS];        /* edits made of each kind */
} lm_random_edits;

/* The state for `sc` (its bounds, dynamic nodes and lights as they are now). 0, or -1 without memory. */
int lm_random_edits_init(lm_random_edits *r, const lmgi_scene *sc, int max_lights, uint64_t seed);
void lm_random_edits_free(lm_random_edits *r);
/* Makes one edit; *kind (may be NULL) says which. The API's status: LMGI_OK, or its error in err. */
lmgi_status lm_random_edit(lm_random_edits *r, lmgi_scene *sc, lm_edit_kind *kind, lmgi_error *err);
/* The lights that are on now (not removed). */
int lm_random_edits_lights(const lmgi_scene *sc);
const char *lm_edit_kind_name(lm_edit_kind k);

#endif
