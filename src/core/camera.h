/* The pinhole camera every picture of lmgi is taken with, the one camera type inside the library: the
 * rasteriser's matrices (the frame's passes, the surface pictures, a cube map's faces) and, for the ray
 * casters (the reference solver's eye rays, the CPU G-buffer of the per-pixel photon gathers), the same
 * pinhole as an eye and a frame. The public lmgi_camera (include/lmgi.h) is turned into one at the API's
 * edge (api/lmgi_camera.h); the file's cameras (lm_camera, scene.h) become one through
 * lm_view_for_scene (scene/scene_view.h).
 *
 * Layout and invariants: view and proj are column-major with GL conventions (view space looks down -z,
 * proj maps to GL clip space); eye is where view space's origin lies in the world. The pinhole part
 * (forward .. znear) is what rays are cast through: lm_view_pinhole derives it from the matrices, so that
 * the rays' pixels are the rasterised frame's; a caster with no matrices (a test) may set it alone. A view
 * from lm_view_from_matrices or lm_view_for_scene has it zeroed until lm_view_pinhole is called.
 * Plain data: copy it, share it read-only between threads. */
#ifndef LM_CAMERA_H
#define LM_CAMERA_H

#include "error.h"

/* A view's name: as long as a scene's names (LM_NAME_MAX, scene.h, which checks that they agree). */
#define LM_VIEW_NAME_MAX 64

typedef struct {
    float view[16], proj[16];
    float eye[3];
    int from_file;         /* 1 if the scene's camera was used */
    char name[LM_VIEW_NAME_MAX];
    /* The pinhole: unit forward and up (up need not be orthogonal to forward), vertical field of view in
     * radians, picture size; the aspect ratio is width / height. znear is the near clipping plane's
     * distance along forward (0: none): eye rays start on it and points nearer are not seen, as in the
     * rasterised frame, so a camera placed on a wall or in a corner sees the room, not the wall's back. */
    float forward[3], up[3];
    float yfov;
    int width, height;
    float znear;
} lm_view;

/* Whether any of the box lo..hi can be in v's picture: 0 when all its corners lie outside one clip plane
 * (beyond the far plane, nearer than the near one, or off to one side), the picture then the background
 * alone. */
int lm_view_sees_box(const lm_view *v, const float lo[3], const float hi[3]);

/* The part of box lo..hi inside v's frustum, no deeper than max_depth in front of the eye (<= 0: to the
 * far plane), as the vertices of that convex part: the box's faces clipped by the cut frustum's planes and
 * the cut frustum's faces clipped by the box's (a far plane at infinity is cut at the box's farthest
 * corner). Writes at most LM_VIEW_BOX_POINTS points to pts and returns how many: 0 when the view sees
 * none of the box. Cost: a few thousand flops. */
#define LM_VIEW_BOX_POINTS 128
/* How deep in front of v's eye the box lo..hi reaches: its farthest corner's depth, or the far plane's
 * where that is nearer. */
float lm_view_box_reach(const lm_view *v, const float lo[3], const float hi[3]);
int lm_view_box_part(const lm_view *v, const float lo[3], const float hi[3], float max_depth, float pts[][3]);

/* A view from an application's matrices (column-major, GL conventions: the camera looks down -z of view
 * space, proj maps to GL clip space). Returns 0 (out untouched) when view is not an invertible affine map. */
int lm_view_from_matrices(const float view[16], const float proj[16], lm_view *out);

/* Face f (0..5: +X, -X, +Y, -Y, +Z, -Z) of a cube map at eye: a 90-degree square view whose framebuffer
 * pixel (x, y) is the face's texel (s, t) as GL samples a cube map (right and up of each face as the GL
 * specification's major-axis table has them: +X looks with up -Y, right -Z, and so on). */
void lm_view_cube_face(const float eye[3], int face, float znear, float zfar, lm_view *out);

/* Fills v's pinhole for a width x height picture from its matrices (right, up and -forward are the view
 * matrix's rows), so that the rays' pixels are the frame's. Fails (v untouched) for an orthographic view,
 * which no ray caster takes. */
lm_status lm_view_pinhole(lm_view *v, int width, int height, lm_error *err);

#endif
