/* The whole frame loop (Larsen & Christensen sections 2-7; docs/architecture.md "The frame loop").
 *
 * One frame at animation time t:
 *   1. photon stage (photon_stage.h): animations, photons re-traced, AIMs refreshed;
 *   2. IIMs (gpu/iim.h, gpu/hemicube.h): up to texels_per_frame texels scheduled by delta_i, gathered
 *      over the current AIMs and node transforms into the fresh IIM, then blended into the display IIM;
 *   3. composite in linear HDR, the paper's Eq. 6, L = L_indirect + L_caustics + L_specular + sum L_direct
 *      shadow: the indirect term kd / pi E_IIM premultiplied over the atlas (gpu/composite.h) and added by
 *      the direct light's first pass at each visible surface's lightmap uv, the direct light per pixel
 *      with shadows (gpu/direct.h), the caustics filtered on screen over its depth (gpu/caustic_pass.h),
 *      then what mirror, glass and glossy nodes reflect of their environment maps (gpu/reflections.h).
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

#include "../gpu/camera.h"
#include "../gpu/frame/caustic_pass.h"
#include "../gpu/frame/direct.h"
#include "../gpu/gl/gl_context.h"
#include "../gpu/gather/hemicube.h"
#include "../gpu/gather/iim.h"
#include "../gpu/tiled/photon_gather.h"
#include "photon_stage.h"

enum { LM_INDIRECT_LIGHTMAP = 0, LM_INDIRECT_BRUTEFORCE = 1, LM_INDIRECT_TILED = 2, LM_INDIRECT_HASHGRID = 3 };

typedef struct {
    lm_photon_stage_settings stage;
    lm_hemicube_settings gather; /* coverage_samples 0 (the default here): 1 with the closed-form emitter
                                  * light, else lm_gather_coverage_for the scene */
    int emitter_light;     /* emitters' light in the gather (trace/emitter_light.h): 1 closed form with sampled
                            * visibility, 0 drawn into the hemicubes, -1 (default) closed form when
                            * lm_emitter_light_suits the scene */
    int emitter_rays;      /* shadow rays per emissive triangle and texel (default 32) */
    int overlap;           /* 1 (default): the photon stage's tracing and AIM refresh run on a second thread
                            * beside the render, after the gather, which then sees the previous frame's
                            * AIMs and delta_i; 0: the paper's order, all on the calling thread */
    lm_iim_settings iim;
    lm_direct_settings direct;
    int width, height;     /* frame size (default 512 x 512; 0 x 0: lm_frame_loop_step composites no frame, and
                            * the render passes are made at the first lm_frame_loop_render) */
    int camera;            /* lm_view_for_scene's camera (default -1) */
    int reflection_size;   /* texels per side of a mirror or glossy node's environment map (gpu/reflections.h;
                            * default 128; 0: no reflections) */
    int reflection_faces;  /* environment map faces re-rendered a frame, round robin, after all of them at the
                            * first frame (default 1: a map refreshed in 6 frames) */
    int caustics;          /* 1 (default): caustic photons (stage.caustic) and the screen-space caustic pass, which
                            * cost nothing while no mirror or glass node has its caustics switched on; 0: none */
    lm_caustic_pass_settings caustic_pass;
    int indirect;          /* 0: no indirect light at all (no photon, AIM or gather work; the frame shows direct
                            * light, emission and reflections); default 1. stage.trace follows it */
    int indirect_path;     /* how the frame gets its indirect light: LM_INDIRECT_LIGHTMAP (default: AIMs, the
                            * hemicube gather into the IIM, the composite) or LM_INDIRECT_TILED, _HASHGRID or
                            * _BRUTEFORCE (straight from the photon hits at the visible pixels on the GPU,
                            * gpu/photon_gather.h: no AIM, no IIM; the lightmaps stay 0 and environment maps
                            * hold direct light only) */
    lm_photon_gather_settings photon_gather; /* those three paths' tile, chunk and stochastic k (the kind
                                              * follows indirect_path) */
    float photon_radius;   /* their kernel radius (0, the default: the disc that holds LM_PIXEL_GATHER_HITS
                            * hits on average, lm_pixel_gather_radius) */
    /* called during the first full gather (seconds on big atlases) with texels done and total; NULL: none */
    void (*progress)(void *user, uint32_t done, uint32_t total);
    void *progress_user;
    const volatile int *cancel; /* non-zero stops the first full gather between passes: LM_ERR_CANCELLED */
    /* the first full gather's checkpoint file (bake_checkpoint.h; NULL: none): written at most every
     * checkpoint_seconds (0: LM_CHECKPOINT_DEFAULT_SECONDS) between passes and on a cancel; resume
     * non-zero: the gather starts from it (it must exist and match, else LM_ERR_INVALID) */
    const char *checkpoint;
    double checkpoint_seconds;
    int resume;
    /* a bake spread over processes (docs/levels.md, "A bake in shards"): shards > 0 gathers only share
     * `shard` (0-based) of the first full gather's order, cut at pass boundaries, into the checkpoint (which
     * it needs), written at the end too; parts (part_count checkpoint files of every share) instead start
     * the first gather from their texels put together, which must be all of them (LM_ERR_INVALID naming a
     * part of another bake, two parts holding the same texels, or the share no part holds) */
    int shard, shards;
    /* with shards > 1: the passes handed out as the processes finish them (lmgi_updater_desc.claim_pass;
     * NULL: every shards-th pass from shard); the part lists the passes it took */
    int (*claim_pass)(void *user, int passes);
    void *claim_user;
    const char *const *parts;
    int part_count;
    lm_gl_context *gl;     /* borrowed, made current at each call: the context to render with (NULL, the
                            * default: the loop makes its own) */
} lm_frame_loop_settings;

typedef struct {
    lm_photon_stage_frame stage;
    uint32_t texels_gathered;
    lm_caustic_pass_stats caustic; /* the frame's caustic pass */
    int cube_faces;        /* environment map faces rendered */
    int shadow_maps;       /* shadow maps re-rendered by the frame's draws */
    int shadow_maps_stale; /* stale ones left for later updates (lm_direct_begin_update) */
    lm_photon_gather_stats photon_gather; /* the photon paths' gather (its times are in t_gather) */
    int photon_gathers;    /* gathers run: 0 when the records, view and G-buffer were as for the last one */
    /* seconds per stage: photon stage (animate + photons + AIMs + caustic photons), IIM gather (schedule,
     * scene and AIM upload, hemicubes), blend, direct light (emission and indirect, lights, shadow maps,
     * the frame's read-back), caustics (the screen-space pass), reflections (map faces and their pass),
     * composite (the indirect term's atlas pass); and the whole frame */
    double t_photons, t_gather, t_blend, t_direct, t_caustics, t_reflections, t_composite, t_total;
} lm_frame_stats;

typedef struct lm_frame_loop lm_frame_loop;

/* Frames over which the IIM of a loop that gathers texels_per_frame texels a frame is refreshed in full,
 * at the lightmap density 'lmgi run' derives when given no texel size: 3 s at 30 fps. The paper's box had
 * 140 texels for 20 a frame (7 frames); at the 64k-texel default of a bake, 20 texels a frame take
 * 3,300 frames, so indirect light could not follow anything that moves (docs/gather.md, "Atlas
 * density"). */
#define LM_FRAME_LOOP_REFRESH_FRAMES 90
/* The atlas texels to aim at for that: texels_per_frame x LM_FRAME_LOOP_REFRESH_FRAMES, at least 256. */
int lm_frame_loop_atlas_texels(int texels_per_frame);

void lm_frame_loop_settings_default(lm_frame_loop_settings *s);
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
 * it before anything that writes the scene or BVH (an edit) or reads the AIM or photons. */
lm_status lm_frame_loop_sync(lm_frame_loop *fl, lm_error *err);
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
typedef void (*lm_bake_progress)(void *user, double fraction, const char *stage);
/* Brings the lightmaps to the converged state of the scene as it is now (animation time t): every photon
 * re-traced, the AIM of every surface whose photons changed refreshed, every texel of every surface whose
 * light changed regathered, and shown at once (no blend). What the scene's edits did not touch costs
 * only the photons' re-trace. progress (may be NULL) hears fractions 0 to 1 and the stage ("photons",
 * "gather"); *cancel (may be NULL) set non-zero stops it between gather passes with LM_ERR_CANCELLED,
 * nothing of the unfinished gather shown and those surfaces left to the next bake or step. */
lm_status lm_frame_loop_bake(lm_frame_loop *fl, float t, lm_bake_progress progress, void *user,
                             const volatile int *cancel, lm_bake_stats *out, lm_error *err);

/* The texels the next steps gather (at least 0; the settings' iim.texels_per_frame until set): the public
 * updater's time budget turns into this. */
void lm_frame_loop_set_texels_per_frame(lm_frame_loop *fl, int texels);
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
/* The lightmaps' estimate of their own accuracy (gpu/gather_error.h), atlas-sized RGBA: the IIM's relative
 * standard error from the AIMs' photon noise, the AIM texel's own, the hemicube's back-face fraction, 0;
 * with LM_GATHER_ERROR_RAYS rays a texel. `shown` as for lm_frame_loop_iim_error. Needs the AIMs' error
 * (stage.aim.error_estimate), else LM_ERR_INVALID. Joins photon work under way first. */
lm_status lm_frame_loop_accuracy(lm_frame_loop *fl, const float *shown, float *out, lm_error *err);
const lm_frame_loop_settings *lm_frame_loop_get_settings(const lm_frame_loop *fl);
/* The view the frames are drawn from. */
const lm_view *lm_frame_loop_view(const lm_frame_loop *fl);

#endif
