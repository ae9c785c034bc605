/* Cameras across the public API: the scene's own, and the application's turned into lmgi's view. */
#include "lmgi_camera.h"

#include <math.h>
#include <string.h>

#include "../core/vecmath.h"
#include "../scene/scene_view.h"
#include "lmgi_scene.h"

/* The translation by sign x the scene's origin (lm_scene.origin: where lmgi's world origin lies in the
 * file's): +1 takes lmgi's positions to the file's, -1 the file's to lmgi's. */
static void origin_shift(const lm_scene *s, float sign, float m[16])
{
    lm_mat4_identity(m);
    for (int k = 0; k < 3; k++)
        m[12 + k] = sign * s->origin[k];
}

lmgi_status lmgi_scene_camera(const lmgi_scene *sc, int index, int width, int height, lmgi_camera *cam,
                              lmgi_error *err)
{
    if (!sc || !cam)
        return lm_api_refuse(err, "lmgi_scene_camera: %s is NULL", sc ? "cam" : "scene");
    if (index < -1 || index >= sc->scene->camera_count)
        return lm_api_refuse(err, "lmgi_scene_camera: camera %d: the scene has %d", index, sc->scene->camera_count);
    if (width < 1 || height < 1 || width > 16384 || height > 16384)
        return lm_api_refuse(err, "lmgi_scene_camera: picture %d x %d must have sides in 1..16384", width, height);
    lm_view v;
    lm_view_for_scene(sc->scene, index, width, height, &v);
    float to_file[16]; /* lmgi's world to the file's: the view matrix takes file positions */
    origin_shift(sc->scene, -1.0f, to_file);
    lm_mat4_mul(cam->view, v.view, to_file);
    memcpy(cam->proj, v.proj, sizeof cam->proj);
    return LMGI_OK;
}

lmgi_status lm_api_view(const lmgi_scene *sc, const lmgi_camera *cam, const char *fn, lm_view *out, lmgi_error *err)
{
    for (int i = 0; i < 16; i++)
        if (!isfinite(cam->view[i]) || !isfinite(cam->proj[i]))
            return lm_api_refuse(err, "%s: camera matrix entry %d is not a finite number", fn, i);
    float from_file[16], view[16]; /* the camera takes file positions; lmgi's are origin-relative */
    origin_shift(sc->scene, 1.0f, from_file);
    lm_mat4_mul(view, cam->view, from_file);
    if (!lm_view_from_matrices(view, cam->proj, out))
        return lm_api_refuse(err, "%s: the view matrix is not invertible", fn);
    return LMGI_OK;
}
