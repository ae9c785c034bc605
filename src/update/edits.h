/* Edits staged until a commit (Embree's rtcCommitScene is the model). An edit is validated when it is
 * made and kept here; the scene model, the BVH and what the scene calls for (lm_effects) change only at
 * the commit, all at once: every staged light, material, sky and switch edit applied in the order made,
 * one BVH update (one instance update per dynamic node and one top-level commit however many nodes moved;
 * one rebuild when a node was switched dynamic or static), and the effects decided once. So an edit never
 * waits for the photon work that reads the scene: the commit does, once for the whole batch.
 *
 * Node placements and the animation time are the exception: they change the scene model at once (after
 * waiting for that photon work, lmgi_scene.c) and the BVH follows at the commit, since a node's place is
 * read back at once by the next edit of a node under it.
 *
 * What the commit changed is recorded, per light and per material (only those whose values differ from
 * the scene's), and for the sky and for moved nodes: the list the photon stage takes once per step
 * (lm_edits_changes) instead of comparing every light and material with a copy of its own.
 *
 * The commit is made at the start of the frame loop's next step, bake or picture (frame_loop.c) before
 * anything traces a ray, and by the API before its own rays or reads of the scene (lmgi_intersect, the
 * reference solver, an updater made on the scene, exports) or when the caller asks (lmgi_commit). The
 * caller of lm_edits_commit has waited for the photon work when lm_edits_pending says there is work.
 *
 * Layout: small arrays of staged edits: each light and material at most once (a later edit of the same
 * one replaces its staged value), the effect and dynamic switches in the order made (each covers a node's
 * subtree, so a later one may cover part of an earlier one's), so a batch costs its edits, not the
 * scene's size; the change list is one byte per light and material, grown as lights are added.
 *
 * Not thread-safe: staging, reading staged values and the commit run on the thread that owns the world
 * (the API refuses an edit while another thread is inside a call on the updater's context). Errors: the
 * BVH's at the commit (Embree's out of memory), with the batch kept for the next commit; out of memory
 * while staging, with nothing staged. */
#ifndef LM_EDITS_H
#define LM_EDITS_H

#include <stdint.h>

#include "../core/error.h"
#include "../scene/scene.h"
#include "effects.h"

struct lm_world;

typedef struct {
    int id;          /* a light of the scene, or one added by this batch (id >= lm_scene.light_count) */
    lm_light value;  /* what it becomes: colour, intensity, range, cones, on/off, removed, an added one's place */
} lm_staged_light;

typedef struct {
    int id;
    lm_material value; /* a class unlike the scene's changes the passes' switches at the commit */
} lm_staged_material;

typedef struct {
    int node;        /* the node and everything under it take these switches */
    int shadows, indirect, reflections, caustics;
} lm_staged_effects;

typedef struct {
    int node, dynamic; /* the node and everything under it made dynamic (1) or static (0) */
} lm_staged_dynamic;

typedef struct {
    int staged;           /* a sky edit waits for the commit */
    lm_sky_kind kind;
    float sky[3], horizon[3];
    float *image;         /* LM_SKY_IMAGE: owned until the commit hands it to the scene */
    int width, height;
    float image_mean[3];
} lm_staged_sky;

/* What the commits since the photon stage last looked changed (lm_edits_take_changes). */
typedef struct {
    uint8_t *lights;      /* per light id (light_cap of them): placement, power, on/off or removal changed, or
                           * it was added */
    uint8_t *materials;   /* per material: colour, emission or class changed */
    int light_cap, material_cap;
    int lights_changed;   /* how many are set in each */
    int materials_changed;
    int sky;              /* the sky was given or changed */
    int moved;            /* nodes were placed by edits or the animation time, or switched dynamic or static */
} lm_edit_changes;

typedef struct lm_edit_batch {
    uint32_t moved;       /* node placements changed in the scene model since the BVH's last commit */
    lm_staged_light *lights;
    int light_count, light_room, lights_added; /* staged lights; of them, added ones */
    lm_staged_material *materials;
    int material_count, material_room;
    lm_staged_effects *effects;
    int effect_count, effect_room;
    lm_staged_dynamic *dynamic;
    int dynamic_count, dynamic_room;
    lm_staged_sky sky;
    lm_edit_changes changes;
    lm_effects *decided;  /* decided again by a commit that changes what the scene calls for; may be NULL */
} lm_edit_batch;

/* Everything staged and recorded given back (the batch is zeroed). */
void lm_edits_free(lm_edit_batch *b);
/* 1 when a commit has work: staged edits or placements the BVH does not have yet. */
int lm_edits_pending(const lm_edit_batch *b);

/* The scene model brought to every staged edit, the BVH to the model's placements, the effects decided,
 * and the changes recorded; nothing when nothing is staged. */
lm_status lm_edits_commit(const struct lm_world *w, lm_error *err);

/* Staging (each checked by the caller; LM_ERR_NOMEM leaves the batch as it was). A light edit's value is
 * the light as it will be: lm_edits_light gives what to start it from. */
lm_status lm_edits_stage_light(lm_edit_batch *b, const lm_scene *s, int id, const lm_light *value, lm_error *err);
/* A new light (its id is lm_edits_light_count before the call, returned in *id). */
lm_status lm_edits_add_light(lm_edit_batch *b, const lm_scene *s, const lm_light *value, int *id, lm_error *err);
lm_status lm_edits_stage_material(lm_edit_batch *b, const lm_scene *s, int id, const lm_material *value,
                                  lm_error *err);
lm_status lm_edits_stage_effects(lm_edit_batch *b, const lm_staged_effects *e, lm_error *err);
lm_status lm_edits_stage_dynamic(lm_edit_batch *b, int node, int dynamic, lm_error *err);
/* The sky as sky says (its image, if any, taken: the batch frees it). */
void lm_edits_stage_sky(lm_edit_batch *b, const lm_staged_sky *sky);

/* What the scene will be after the commit: the staged value where one is staged, else the scene's. */
int lm_edits_light_count(const lm_edit_batch *b, const lm_scene *s);
const lm_light *lm_edits_light(const lm_edit_batch *b, const lm_scene *s, int id);
const lm_material *lm_edits_material(const lm_edit_batch *b, const lm_scene *s, int id);
void lm_edits_node_effects(const lm_edit_batch *b, const lm_scene *s, int node, int out[4]);
int lm_edits_node_dynamic(const lm_edit_batch *b, const lm_scene *s, int node);
/* The sky's kind and colours (NULL: none staged). */
const lm_staged_sky *lm_edits_sky(const lm_edit_batch *b);

/* Placements the BVH does not have yet: a node moved or the animation time set in the scene model. */
void lm_edits_note_moved(lm_edit_batch *b);

/* The changes the commits recorded since the last lm_edits_clear_changes (b may be NULL: none). A light or
 * material id past an array's end was not changed. */
const lm_edit_changes *lm_edits_changes(const lm_edit_batch *b);
void lm_edits_clear_changes(lm_edit_batch *b);
static inline int lm_edit_changed_light(const lm_edit_changes *c, int id)
{
    return id >= 0 && id < c->light_cap && c->lights[id];
}

#endif
