/* Loading a benchmark's scene (dev_scene.h). */
#include "dev_scene.h"

#include <unistd.h>

lmgi_scene *lm_dev_load(const char *path, int target_texels)
{
    lmgi_options o;
    lmgi_options_init(&o);
    o.target_texels = target_texels;
    lmgi_scene *sc = NULL;
    lmgi_error e;
    return access(path, R_OK) == 0 && lmgi_load(path, &o, &sc, &e) == LMGI_OK ? sc : NULL;
}
