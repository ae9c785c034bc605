/* The viewer's camera (lmgi view, docs/viewer.md): an orbit around a target that the mouse turns, pans and
 * zooms, and that the keys fly through the scene, made into the lmgi_camera lmgi_render draws from.
 *
 * State: the target, the distance to it, yaw and pitch (radians; pitch kept within +-89 degrees), the
 * vertical field of view and the near and far planes, all in the file's world (+y up, as glTF). It starts
 * from the scene's camera (lm_view_camera_from): its eye, its looking direction and its field of view,
 * the target where that direction passes nearest the middle of the scene's bounds. Pure arithmetic: no
 * allocation, no errors, deterministic. */
#ifndef LM_CLI_VIEW_CAMERA_H
#define LM_CLI_VIEW_CAMERA_H

#include <lmgi.h>

typedef struct {
    float target[3];
    float distance;       /* eye to target, > 0 */
    float yaw, pitch;     /* the eye's direction from the target: yaw about +y from +z, pitch above the horizon */
    float fovy;           /* vertical field of view, radians */
    float near_plane, far_plane;
    float scene_size;     /* the bounds' diagonal: the scale of pans, zooms and flights */
} lm_view_camera;

/* From the scene's camera cam (lmgi_scene_camera) and the scene's bounds. */
void lm_view_camera_from(lm_view_camera *c, const lmgi_camera *cam, const float lo[3], const float hi[3]);
/* The eye's world position. */
void lm_view_camera_eye(const lm_view_camera *c, float eye[3]);
/* The lmgi_camera for a width x height picture. */
void lm_view_camera_get(const lm_view_camera *c, int width, int height, lmgi_camera *out);
/* Mouse: turn by (dx, dy) pixels of a window h pixels high (a full height turns by 180 degrees); pan the
 * target across the view by that much of the view's height at the target's distance; zoom by a wheel's
 * steps (each 15% nearer or farther). */
void lm_view_camera_orbit(lm_view_camera *c, double dx, double dy, int h);
void lm_view_camera_pan(lm_view_camera *c, double dx, double dy, int h);
void lm_view_camera_zoom(lm_view_camera *c, double steps);
/* Keys: fly the eye and the target together along the view (forward > 0), across it (right > 0) and up
 * (up > 0), by `seconds` at a speed of a quarter of the scene's size a second. */
void lm_view_camera_fly(lm_view_camera *c, float forward, float right, float up, float seconds);

#endif
