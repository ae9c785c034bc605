/* View and projection matrices for a picture of the scene: the file's first camera, or an automatic one
 * that frames the scene's bounds from the front and a little above. */
#ifndef LM_CAMERA_H
#define LM_CAMERA_H

#include "../scene/scene.h"

typedef struct {
    float view[16], proj[16];
    float eye[3];
    int from_file;         /* 1 if the scene's camera was used */
    char name[LM_NAME_MAX];
} lm_view;

/* camera: index into s->cameras, or -1 for the first one if any, else automatic. */
void lm_view_for_scene(const lm_scene *s, int camera, int width, int height, lm_view *out);

#endif
