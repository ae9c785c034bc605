/* What the public updater shares with the rest of the API: its desc turned into frame loop settings. */
#ifndef LM_LMGI_UPDATER_H
#define LM_LMGI_UPDATER_H

#include <lmgi.h>

#include "../update/frame_loop.h"

/* The frame loop's settings for a desc (its zeros the defaults), each field checked: LM_ERR_INVALID naming
 * the field and its range. The gather scheme and the AIMs' direct light on auto are chosen for the scene
 * and the GL context gl (s->gl), so that an updater and lmgi_check's run gather alike. s->progress is the
 * caller's to set. */
lm_status lm_updater_settings(const lm_scene *scene, const lmgi_updater_desc *d, lm_gl_context *gl,
                              lm_frame_loop_settings *s, lm_error *err);

/* The scene u works on, and the context it was made on. */
const lmgi_scene *lm_updater_scene(const lmgi_updater *u);
lmgi_context *lm_updater_context(const lmgi_updater *u);
lm_frame_loop *lm_updater_loop(const lmgi_updater *u); /* tools and tests */
/* lmgi_render's picture from a view already checked, inside the caller's lm_api_enter. */
lm_status lm_updater_render(lmgi_updater *u, const lm_view *v, int width, int height, float *rgb, lm_error *err);

/* The updater's lightmap texture (lmgi_texture.c): NULL until lmgi_get_lightmap_texture first asks for it;
 * freed by lmgi_updater_free with the updater's GL context current. */
typedef struct lm_lightmap_texture lm_lightmap_texture;
lm_lightmap_texture **lm_updater_texture(lmgi_updater *u);
void lm_lightmap_texture_free(lm_lightmap_texture *t);

#endif
