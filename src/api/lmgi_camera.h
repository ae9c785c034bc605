/* The public lmgi_camera (the file's world, GL matrices) turned into the renderer's and the reference's
 * view (lmgi's origin-relative world, core/camera.h). */
#ifndef LM_LMGI_CAMERA_H
#define LM_LMGI_CAMERA_H

#include <lmgi.h>

#include "../core/camera.h"

/* The view of cam in sc's world. Non-finite entries or a view matrix that is not invertible:
 * LMGI_ERR_INVALID with a message starting with fn (the public call's name). */
lmgi_status lm_api_view(const lmgi_scene *sc, const lmgi_camera *cam, const char *fn, lm_view *out, lmgi_error *err);

#endif
