/* View and projection matrices for a picture of the scene: the file's first camera, or an automatic one
 * that frames the scene's bounds from the front and a little above. */
#ifndef LM_CAMERA_H
#define LM_CAMERA_H

#include "../scene/scene.h"
#include "../reference/reference.h"

typedef struct {
    float view[16], proj[16];
    float eye[3];
    int from_file;         /* 1 if the scene's camera was used */
    char name[LM_NAME_MAX];
} lm_view;

/* camera: index into s->cameras, or -1 for the first one if any, else automatic. */
void lm_view_for_scene(const lm_scene *s, int camera, int width, int height, lm_view *out);
/* Whether any of the box lo..hi can be in v's picture: 0 when all its corners lie outside one clip plane
 * (beyond the far plane, nearer than the near one, or off to one side), the picture then the background
 * alone. */
int lm_view_sees_box(const lm_view *v, const float lo[3], const float hi[3]);

/* A view from an application's matrices (column-major, GL conventions: the camera looks down -z of view
 * space, proj maps to GL clip space). Returns 0 (out untouched) when view is not an invertible affine map. */
int lm_view_from_matrices(const float view[16], const float proj[16], lm_view *out);

/* Face f (0..5: +X, -X, +Y, -Y, +Z, -Z) of a cube map at eye: a 90-degree square view whose framebuffer
 * pixel (x, y) is the face's texel (s, t) as GL samples a cube map (right and up of each face as the GL
 * specification's major-axis table has them: +X looks with up -Y, right -Z, and so on). */
void lm_view_cube_face(const float eye[3], int face, float znear, float zfar, lm_view *out);

/* The reference solver's camera for the same picture (right, up and -forward are the view matrix's rows),
 * so that its pixels are the frame's. Fails for an orthographic view, which the solver does not take. */
lm_status lm_view_ref_camera(const lm_view *v, int width, int height, lm_ref_camera *cam, lm_error *err);

#endif
