/* The viewer's edits (lmgi view, docs/viewer.md): the node under the cursor (a ray from the window's camera
 * through lmgi_intersect), a node moved on the horizontal plane through the point grabbed or turned about
 * the vertical through its origin, lights edited, added and removed, materials recoloured or made brighter,
 * a node's effects switched; each as a step that undo and redo replay through the same public calls
 * (lmgi_set_node_transform, lmgi_set_light, lmgi_add_light, lmgi_remove_light, lmgi_set_material,
 * lmgi_set_node_effects). A removed light's id is never given again, so undoing a removal (or redoing an
 * addition) adds the light anew and the step keeps its new id.
 * Memory: one step of about 400 bytes an edit, kept until the viewer closes. Not thread-safe. */
#ifndef LM_CLI_VIEW_EDIT_H
#define LM_CLI_VIEW_EDIT_H

#include <lmgi.h>
#include <stddef.h>

typedef enum {
    LM_VIEW_NODE, LM_VIEW_LIGHT, LM_VIEW_LIGHT_ADDED, LM_VIEW_LIGHT_REMOVED, LM_VIEW_MATERIAL, LM_VIEW_EFFECTS
} lm_view_step_kind;

typedef struct {
    lm_view_step_kind kind;
    int id;                          /* the node, material, or the light as it is now */
    float before[16], after[16];     /* LM_VIEW_NODE: world matrices */
    lmgi_light light_before, light_after;
    lmgi_material material_before, material_after;
    lmgi_node_effects effects_before, effects_after; /* LM_VIEW_EFFECTS: the node's switches */
} lm_view_step;

typedef struct {
    lm_view_step *steps;
    int count, done, cap;            /* steps [0, done) are in effect, [done, count) undone (redo) */
} lm_view_history;

/* Records a step made (the steps undone are dropped: a new edit ends their redo). 0: no memory. */
int lm_view_history_push(lm_view_history *h, const lm_view_step *s);
/* Undoes the last step in effect / redoes the next undone one; 0 when there is none or the scene refused
 * (err says why); what it did in what (n bytes). */
int lm_view_undo(lm_view_history *h, lmgi_scene *sc, char *what, size_t n, lmgi_error *err);
int lm_view_redo(lm_view_history *h, lmgi_scene *sc, char *what, size_t n, lmgi_error *err);
void lm_view_history_free(lm_view_history *h);

/* The world ray through window pixel (x, y) (pixels from the top left, of a w x h window) from cam. */
void lm_view_ray(const lmgi_camera *cam, double x, double y, int w, int h, float org[3], float dir[3]);
/* Where that ray meets the horizontal plane at height y (0: behind the eye or parallel). */
int lm_view_ray_plane(const float org[3], const float dir[3], float y, float out[3]);
/* Where the ray comes closest to the line through p along unit axis a: the distance s along a (0 when the
 * ray runs along the line: nothing to move by). */
float lm_view_ray_axis(const float org[3], const float dir[3], const float p[3], const float a[3]);
/* m turned by angle (radians) about the vertical through its translation. */
void lm_view_turn(const float m[16], float angle, float out[16]);

#endif
