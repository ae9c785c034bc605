/* What a frame loop is made with (frame_loop.h), the one default of each, and what a step reports;
 * shared by the loop and the parts it conducts (lightmap_path.h, photon_path.h, frame_passes.h), which
 * read the fields of their own stage. The loop keeps its copy: the parts it makes resolve the fields
 * left to the scene (gather.coverage_samples, emitter_light) in it, so that lm_frame_loop_get_settings
 * says what runs. */
#ifndef LM_FRAME_SETTINGS_H
#define LM_FRAME_SETTINGS_H

#include "../gpu/frame/caustic_pass.h"
#include "../gpu/frame/direct.h"
#include "../gpu/gl/gl_context.h"
#include "../gpu/gather/hemicube.h"
#include "../gpu/gather/iim.h"
#include "../gpu/tiled/photon_gather.h"
#include "../photonmap/caustic_split.h"
#include "budget_plan.h"
#include "photon_stage.h"

enum { LM_INDIRECT_LIGHTMAP = 0, LM_INDIRECT_BRUTEFORCE = 1, LM_INDIRECT_TILED = 2, LM_INDIRECT_HASHGRID = 3 };

typedef struct {
    lm_photon_stage_settings stage;
    lm_hemicube_settings gather; /* coverage_samples 0 (the default here): 1 with the closed-form emitter
                                  * light, else lm_gather_coverage_for the scene */
    int bounce_passes;     /* after the first full gather, this many more, each reading the bounced light as
                            * rho / pi times the last one's IIM instead of the photons' AIM (rays scheme with
                            * the punctual light at its hits only; lightmap_path.c); 0: none */
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
    int reflection_size;   /* texels per side of a mirror or glossy node's environment map (gpu/frame/reflections.h;
                            * default 128; 0: no reflections) */
    int reflection_faces;  /* environment map faces re-rendered a frame, round robin, after all of them at the
                            * first frame (default 1: a map refreshed in 6 frames) */
    int caustics;          /* 1 (default): caustic photons (stage.caustic) and the screen-space caustic pass, which
                            * cost nothing while no mirror or glass node has its caustics switched on; 0: none */
    lm_caustic_pass_settings caustic_pass;
    float caustic_thin;    /* with the lightmap path: caustic light under this x a texel's other light is carried
                            * by the lightmaps, the rest by the screen pass (photonmap/caustic_split.h;
                            * default LM_CAUSTIC_THIN_DEFAULT; 0: every photon on screen, the paper's) */
    int indirect;          /* 0: no indirect light at all (no photon, AIM or gather work; the frame shows direct
                            * light, emission and reflections); default 1. stage.trace follows it */
    int indirect_path;     /* how the frame gets its indirect light: LM_INDIRECT_LIGHTMAP (default: AIMs, the
                            * hemicube gather into the IIM, the composite) or LM_INDIRECT_TILED, _HASHGRID or
                            * _BRUTEFORCE (straight from the photon hits at the visible pixels on the GPU,
                            * gpu/tiled/photon_gather.h: no AIM, no IIM; the lightmaps stay 0 and environment maps
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

void lm_frame_loop_settings_default(lm_frame_loop_settings *s);

/* What a step did (lm_frame_loop_step). */
typedef struct {
    lm_photon_stage_frame stage;
    uint32_t texels_gathered;
    uint32_t texels_estimated; /* waiting texels whose ray estimate was brought up to date (ray_estimate.h) */
    uint32_t texels_based;     /* texels whose ray estimate's base was taken since the last step (lightmap_path.h,
                                * lm_lightmap_path_before_change) */
    lm_caustic_pass_stats caustic; /* the frame's caustic pass */
    uint32_t caustic_landed, caustic_thin; /* the caustic photons the frame showed, and of those the ones its
                                            * lightmaps carried (photonmap/caustic_split.h) */
    int cube_faces;        /* environment map faces rendered */
    int plane_maps;        /* flat reflectors' mirrored pictures drawn (reflections.h) */
    int shadow_maps;       /* shadow maps re-rendered by the frame's draws */
    int shadow_maps_stale; /* stale ones left for later updates (lm_direct_begin_update) */
    lm_photon_gather_stats photon_gather; /* the photon paths' gather (its times are in t_gather) */
    int photon_gathers;    /* gathers run: 0 when the records, view and G-buffer were as for the last one */
    /* seconds per stage: photon stage (animate + photons + AIMs + caustic photons), IIM gather (schedule,
     * scene and AIM upload, hemicubes), blend, direct light (emission and indirect, lights, shadow maps,
     * the frame's read-back), caustics (the split of the photons between the lightmaps and the screen, and
     * the screen-space pass), reflections (map faces and their pass),
     * composite (the indirect term's atlas pass); and the whole frame */
    double t_photons, t_gather, t_blend, t_direct, t_caustics, t_reflections, t_composite, t_total;
    /* of t_photons or t_gather (where the step schedules), a light edit's texel factors (update/light_scale.h):
     * their seconds and the rays of one of their gathers */
    double t_light_scale;
    uint64_t scale_rays;
    /* of t_gather, the waiting texels' ray estimates brought up to date (the gathered texels' bases are the
     * gather's own): a stage of the budget's */
    double t_estimates;
    /* of t_photons, the edits' work the photon stage did at once (a lit light's photons traced, AIMs
     * refreshed for a light or colour edit: lm_photon_stage_animate), which the budget's model of the
     * gather's rest leaves out like the texel factors (budget_plan.h); and, before t_photons, the rays'
     * bases a level without dynamic nodes takes at its first edit (lm_lightmap_path_before_change) */
    double t_edits;
    /* of t_photons, how far the photon stage's job that finished in this step ran past what its plan gave
     * it, at most what the step waited for it (in order and overlapped): a price its stages' models learn
     * from this step on, which the gather's rest leaves out too; detached, the wait for the job the last
     * step began, at the step's start, which the plan takes off the budget instead (budget_plan.h) */
    double t_overrun, t_waited;
    /* the time budget (budget_plan.h): the counts the step was allowed (zeros but texels without a budget:
     * the settings'), the stage that took the most time and why, in words */
    lm_budget_plan plan;
    lm_stage busiest;
    char why[160];
} lm_frame_stats;

/* A bake's progress: fractions 0 to 1 and the stage ("photons", "gather", "done"). */
typedef void (*lm_bake_progress)(void *user, double fraction, const char *stage);

/* Which indirect path the frames take, if any: the lightmaps (AIMs, gather, IIM) or the photon gather at
 * the pixels. */
static inline int lm_frame_lightmap_path(const lm_frame_loop_settings *s)
{
    return s->indirect && s->indirect_path == LM_INDIRECT_LIGHTMAP;
}
static inline int lm_frame_photon_path(const lm_frame_loop_settings *s)
{
    return s->indirect && s->indirect_path != LM_INDIRECT_LIGHTMAP;
}

#endif
