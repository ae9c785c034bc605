/* View and projection matrices for a picture of the scene: the file's first camera, or an automatic one
 * that frames the scene's bounds from the front and a little above (core/camera.h's lm_view). */
#ifndef LM_SCENE_VIEW_H
#define LM_SCENE_VIEW_H

#include "../core/camera.h"
#include "scene.h"

/* camera: index into s->cameras, or -1 for the first one if any, else automatic. */
void lm_view_for_scene(const lm_scene *s, int camera, int width, int height, lm_view *out);

#endif
