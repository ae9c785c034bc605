#ifndef LM_DEV_SCENE_H
#define LM_DEV_SCENE_H
#include <lmgi_tools.h>
/* path loaded at about target_texels atlas texels (0: lmgi_load's default; lmgi_atlas_texels_for(0): the
 * density `lmgi run` loads at), or NULL when the file is missing or does not load (the benchmark then says
 * it skipped it). Free with lmgi_free. */
lmgi_scene *lm_dev_load(const char *path, int target_texels);
#endif
