/* The whole frame loop (Larsen & Christensen sections 2-7; docs/architecture.md "The frame loop").
 *
 * One frame at animation time t:
 *   1. photon stage (photon_stage.h): animations, photons re-traced, AIMs refreshed;
 *   2. IIMs (gpu/gather/iim.h, gpu/gather/hemicube.h): up to texels_per_frame texels scheduled by delta_i, gathered
 *      over the current AIMs and node transforms into the fresh IIM, then blended into the display IIM;
 *   3. composite in linear HDR, the paper's Eq. 6, L = L_indirect + L_caustics + L_specular + sum L_direct
 *      shadow: the indirect term kd / pi E_IIM premultiplied over the atlas (gpu/frame/composite.h) and added by
 *      the direct light's first pass at each visible surface's lightmap uv, the direct light per pixel
 *      with shadows (gpu/frame/direct.h), the caustics filtered on screen over its depth (gpu/frame/caustic_pass.h),
 *      then what mirror, glass and glossy nodes reflect of their environment maps (gpu/frame/reflections.h).
 *
 * With `overlap` (the default), step 1's tracing and AIM refresh run on a second thread while the calling
 * thread does steps 2 and 3 over the previous frame's AIMs (docs/architecture.md). A loop that draws no
 * frame (width 0: the application renders) lets that thread run on past the step until the next one
 * (lm_frame_loop_sync), so the photon work hides behind the application's own frame.
 *
 * Initial state (lm_frame_loop_create): a full photon trace, every AIM, and a full gather of every texel
 * shown at once, so the first frame is already converged. The loop owns its GL context (current on the
 * creating thread). */
#ifndef LM_FRAME_LOOP_H
#define LM_FRAME_LOOP_H

#include "../core/camera.h"
#include "frame_settings.h"

typedef struct lm_frame_loop lm_frame_loop;

/* Frames over which the IIM of a loop that gathers texels_per_frame texels a frame is refreshed in full,
 * at the lightmap density 'lmgi run' derives when given no texel size: 3 s at 30 fps. The paper's box had
 * 140 texels for 20 a frame (7 frames); at the 64k-texel default of a bake, 20 texels a frame take
 * 3,300 frames, so indirect light could not follow anything that moves (docs/gather.md, "Atlas
 * density"). */
#define LM_FRAME_LOOP_REFRESH_FRAMES 90
/* The atlas texels to aim at for that: texels_per_frame x LM_FRAME_LOOP_REFRESH_FRAMES, at least 256. */
int lm_frame_loop_atlas_texels(int texels_per_frame);

/* The photon paths' kernel radius in use (0 before their first frame, on the lightmap path, or with no
 * photon to gather). */
float lm_frame_loop_photon_radius(const lm_frame_loop *fl);
/* The initial state. The world (update/world.h) is borrowed and must outlive the loop. setup (may be
 * NULL) gets the photon stage's setup times; t_setup_gather (may be NULL) the full gather's. */
lm_status lm_frame_loop_create(const lm_world *w, const lm_frame_loop_settings *set, lm_frame_loop **out,
                               lm_photon_stage_frame *setup, double *t_setup_gather, lm_error *err);
void lm_frame_loop_free(lm_frame_loop *fl);
/* One frame at animation time t; the picture is then in lm_frame_loop_image. */
lm_status lm_frame_loop_step(lm_frame_loop *fl, float t, lm_frame_stats *out, lm_error *err);

/* Waits for photon work a step left running (a loop that draws no frame of its own, with overlap, lets
 * the stage's tracing and AIM refresh run on past the step, beside whatever the caller does next). Call
 * it before anything that writes the scene or BVH (a commit of edits, which the loop's own steps make
 * after it) or reads the AIM or photons. */
lm_status lm_frame_loop_sync(lm_frame_loop *fl, lm_error *err);
/* lm_frame_loop_sync, then what must be taken of the scene as it is before a change (the waiting texels'
 * ray bases: lm_lightmap_path_before_change). Call it before anything writes the scene's nodes, lights,
 * materials or sky (an edit, an animation's time); the loop's own steps call it before their commits. */
lm_status lm_frame_loop_before_change(lm_frame_loop *fl, lm_error *err);
/* 1 while that photon work runs (a staged edit leaves it running: update/edits.h). */
int lm_frame_loop_busy(const lm_frame_loop *fl);
/* What a bake did: photon paths that changed (of all, re-traced), AIM surfaces refreshed, IIM texels
 * regathered, surfaces whose displayed lightmap changed. */
typedef struct {
    uint32_t photons_traced, photons_changed;
    int aim_surfaces_refreshed;
    uint32_t texels_gathered;
    int surfaces_seeing;   /* of the surfaces regathered, those only because they see a refreshed AIM */
    int surfaces_changed;
    double t_photons, t_gather;
} lm_bake_stats;
/* Brings the lightmaps to the converged state of the scene as it is now (animation time t): every photon
 * re-traced, the AIM of every surface whose photons changed refreshed, every texel of every surface whose
 * light changed regathered, and shown at once (no blend). What the scene's edits did not touch costs
 * only the photons' re-trace. progress (may be NULL) hears fractions 0 to 1 and the stage ("photons",
 * "gather"); *cancel (may be NULL) set non-zero stops it between gather passes with LM_ERR_CANCELLED,
 * nothing of the unfinished gather shown and those surfaces left to the next bake or step. */
lm_status lm_frame_loop_bake(lm_frame_loop *fl, float t, int fresh_plan, lm_bake_progress progress, void *user,
                             const volatile int *cancel, lm_bake_stats *out, lm_error *err);

/* The time the next steps may take, in ms, shared by every stage (budget_plan.h: photon groups, AIM
 * hits, caustic photons, environment map faces and texels, each from its cost model learnt from the
 * steps); 0 (the default): the settings' fixed counts (iim.texels_per_frame, the photons' group_budget,
 * ...). lm_frame_stats says what each step was allowed and which stage took its time. */
void lm_frame_loop_set_budget(lm_frame_loop *fl, float budget_ms);
/* Renders the composited frame from `view` at width x height into rgb (width*height*3 linear floats, top
 * row first) with the lighting of the last step: lmgi_render's camera, beside the step's own frame. When
 * the steps draw no frame (width 0), the environment maps' faces due are refreshed here, and the caustics
 * are the newest photons' (the photon work the last step left running is waited for); else both are as
 * the step's own frame showed them. */
lm_status lm_frame_loop_render(lm_frame_loop *fl, const lm_view *view, int width, int height, float *rgb,
                               lm_error *err);
/* Per surface, how many steps changed what the displayed IIM holds for it (the first full gather is 1):
 * an engine uploads a surface's lightmap again only when this moved. */
const uint32_t *lm_frame_loop_surface_versions(const lm_frame_loop *fl);

/* The caustic irradiance E of the last picture drawn (a step's own frame or lm_frame_loop_render's), its
 * size from lm_frame_loop_caustics_size (0 x 0 before any), width*height*3 linear floats, top row first; 0
 * where no caustic photon's filter reached, and everywhere without caustics: the picture added kd / pi x E. */
void lm_frame_loop_caustics_size(const lm_frame_loop *fl, int *width, int *height);
lm_status lm_frame_loop_read_caustics(lm_frame_loop *fl, float *rgb, lm_error *err);
/* What the caustics added to that picture, kd / pi x E (radiance, the same layout). */
lm_status lm_frame_loop_read_caustic_radiance(lm_frame_loop *fl, float *rgb, lm_error *err);
/* The last frame, composited (width*height*3 linear floats, top row first); the only read-back of a frame. */
const float *lm_frame_loop_image(const lm_frame_loop *fl);
const lm_photon_stage *lm_frame_loop_stage(const lm_frame_loop *fl);
/* The displayed IIM read back (atlas-sized RGBA floats, a = back-face fraction); caller frees. */
lm_status lm_frame_loop_read_iim(const lm_frame_loop *fl, float **rgba, lm_error *err);
/* The same for the atlas window win = {x, y, w, h} alone (w*h RGBA floats); caller frees. */
lm_status lm_frame_loop_read_iim_window(const lm_frame_loop *fl, const int win[4], float **rgba, lm_error *err);
/* The IIMs behind the displayed lightmap (tools and tests: test_bad_values writes a NaN into them to see
 * lmgi_update name the stage). */
lm_iim *lm_frame_loop_iim(lm_frame_loop *fl);
/* Per atlas pixel (width*height floats, 0 outside texels), how far the displayed IIM may be from the
 * lighting as it is now, relative to the texel's irradiance: the larger of
 *   - what the display has still to blend in: |fresh - displayed| / max(|fresh|, floor), fresh being
 *     the latest gathered value (a refresh under way, or a committed one still fading in), luminance,
 *     floor 1% of the mean displayed luminance of valid texels;
 *   - what is not gathered yet: the surface's delta_i (photon energy added or removed since its IIM was
 *     last refreshed, the scheduler's own measure) over its stored IIM energy, an upper bound of the
 *     relative change of the light its photons bring.
 * 0 everywhere once every refresh is complete and blended and no photon changed since. `shown` is the
 * displayed IIM as lm_frame_loop_read_iim gives it. Joins photon work under way first. */
lm_status lm_frame_loop_iim_error(lm_frame_loop *fl, const float *shown, float *error, lm_error *err);
/* The lightmaps' estimate of their own accuracy (gpu/gather/gather_error.h), atlas-sized RGBA: the IIM's relative
 * standard error from the AIMs' photon noise, the AIM texel's own, the hemicube's back-face fraction, 0;
 * with LM_GATHER_ERROR_RAYS rays a texel. `shown` as for lm_frame_loop_iim_error. Needs the AIMs' error
 * (stage.aim.error_estimate), else LM_ERR_INVALID. Joins photon work under way first. */
lm_status lm_frame_loop_accuracy(lm_frame_loop *fl, const float *shown, float *out, lm_error *err);
const lm_frame_loop_settings *lm_frame_loop_get_settings(const lm_frame_loop *fl);
/* The view the frames are drawn from. */
const lm_view *lm_frame_loop_view(const lm_frame_loop *fl);

#endif
