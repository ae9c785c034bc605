/* Loading the command's scene, with the command's message on failure. */
#ifndef LM_CLI_SCENE_LOAD_H
#define LM_CLI_SCENE_LOAD_H

#include <lmgi.h>

/* Loads path into *sc; prints "lmgi: error: ..." and returns 0 on failure. With lit = 1 a scene without
 * triangles is refused too (nothing to light: 'run', 'photons' and 'reference' would only write black
 * pictures), naming the file; 'info' and 'charts' take it. */
int lm_cli_load_scene(const char *path, const lmgi_options *o, int lit, lmgi_scene **sc);
/* --sky: every scene lm_cli_load_scene loads from now on gets this sky (lmgi_set_environment and its
 * gradient and image forms; the arrays are copied, the image's path kept). */
typedef enum { LM_CLI_SKY_NONE = 0, LM_CLI_SKY_UNIFORM, LM_CLI_SKY_GRADIENT, LM_CLI_SKY_IMAGE } lm_cli_sky;
void lm_cli_set_sky(lm_cli_sky kind, const float zenith[3], const float horizon[3], const char *image);
/* 1 when nothing lights the scene: no light, no emissive material, no sky (its pictures are black). */
int lm_cli_scene_unlit(const lmgi_scene *sc);
/* The --sky image's path, NULL when the sky is not an image. */
const char *lm_cli_sky_image(void);

#endif
