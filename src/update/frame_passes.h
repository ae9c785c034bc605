/* The passes that draw a frame (Larsen & Christensen section 7, Eq. 6: L = L_indirect + L_caustics +
 * L_specular + sum L_direct): the composite's indirect term (gpu/frame/composite.h: kd / pi E_IIM premultiplied
 * over the atlas), the direct light with its shadow maps, which owns the frame's targets (gpu/frame/direct.h),
 * the photon paths' indirect light (photon_path.h) where they are taken, the screen-space caustics
 * (gpu/frame/caustic_pass.h) and the reflections of mirror, glass and glossy nodes (gpu/frame/reflections.h).
 *
 * Each pass decides here whether its inputs changed:
 *   - the composite's surfaces and the reflecting nodes follow lm_scene.pass_version (a material's class,
 *     a node's effect switches); the reflection maps are made again when it moved;
 *   - the caustic photons are sent to the pass when the stage's caustics version moved, the pass made
 *     when the first ones land;
 *   - a picture's caustics (splat, queries, filter) are run again only when the photons, the view, the
 *     size or a node moved since that slot's last run; else its composite alone is drawn again;
 *   - the environment maps' faces are re-rendered where what they see changed (the lightmaps' surface
 *     versions, the emitters and materials, the caustics).
 *
 * The GL passes are made by lm_frame_passes_setup (with a loop that draws frames, at once; else at its
 * first lm_frame_loop_render). Reads the stage's emitters and caustics: only while its worker is quiet.
 * GL calls: on the thread whose context is current. */
#ifndef LM_FRAME_PASSES_H
#define LM_FRAME_PASSES_H

#include "../core/camera.h"
#include "frame_settings.h"
#include "photon_path.h"
#include "world.h"

typedef struct lm_frame_passes lm_frame_passes;

/* Where a frame's indirect light comes from: the lightmap path's IIM, or the photon path, or neither. */
typedef struct {
    const lm_iim *iim;       /* the lightmap path's (NULL: none) */
    lm_photon_path *photons; /* the photon path (NULL: none) */
} lm_frame_indirect;

/* No GL work yet. w, stage and set are the loop's, borrowed. */
lm_status lm_frame_passes_create(const lm_world *w, const lm_photon_stage *stage, const lm_frame_loop_settings *set,
                                 lm_frame_passes **out, lm_error *err);
void lm_frame_passes_free(lm_frame_passes *fp);
/* The composite, direct light and reflections, when not made yet. */
lm_status lm_frame_passes_setup(lm_frame_passes *fp, lm_error *err);
/* After edits that change which passes a node takes part in (lm_scene.pass_version). */
lm_status lm_frame_passes_follow(lm_frame_passes *fp, lm_error *err);
/* The stage's caustic photons into the caustic pass when they changed; with the lightmap path and
 * set->caustic_thin, the thin ones' light into the composite instead (photonmap/caustic_split.h), from
 * the stage's AIM as it is now. */
lm_status lm_frame_passes_upload_caustics(lm_frame_passes *fp, lm_error *err);
/* Whether the scene has caustic generators now (mirror or glass nodes with caustics on), or the caustic
 * pass holds photons: a loop that draws no frame of its own takes the newest caustic photons. */
int lm_frame_passes_want_caustics(lm_frame_passes *fp);
/* A picture from view at w x h into rgb (w*h*3 linear floats, top row first): the indirect term, the
 * environment maps' faces due (when `step`), the direct light, the photon paths' indirect light, the
 * caustics, the reflections; one read-back. `own`: the step's own frame (its caustics kept for
 * lm_frame_passes_read_caustics), else another view. Fills o's pass times and counts. */
lm_status lm_frame_passes_draw(lm_frame_passes *fp, const lm_frame_indirect *ind, const lm_view *view, int w,
                               int h, float *rgb, int own, int step, lm_frame_stats *o, lm_error *err);
/* The step's own frame: lm_frame_passes_draw with the shadow maps' budget of an update (set->direct's
 * maps_per_update) and their counts in o. */
lm_status lm_frame_passes_draw_step(lm_frame_passes *fp, const lm_frame_indirect *ind, const lm_view *view, int w,
                                    int h, float *rgb, lm_frame_stats *o, lm_error *err);
/* The environment maps' faces (all of them: a step marks what changed as it renders), and the most the
 * next steps render (lm_reflections_limit_faces). */
int lm_frame_passes_faces(const lm_frame_passes *fp);
void lm_frame_passes_limit_faces(lm_frame_passes *fp, int most);
/* The caustic irradiance of the last picture drawn (lm_frame_loop_read_caustics says what): the screen
 * pass's plus the thin light the lightmaps carry at each pixel. */
void lm_frame_passes_caustics_size(const lm_frame_passes *fp, int *width, int *height);
lm_status lm_frame_passes_read_caustics(const lm_frame_passes *fp, float *rgb, lm_error *err);
/* What the caustics added to that picture: kd / pi x E at each pixel (radiance, the same layout). */
lm_status lm_frame_passes_read_caustic_radiance(const lm_frame_passes *fp, float *rgb, lm_error *err);

#endif
