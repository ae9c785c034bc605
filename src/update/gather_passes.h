/* The IIM gather in passes: a long gather that can be watched, cancelled, checkpointed, resumed, split
 * into shards or handed out to processes, and put together from their parts (docs/levels.md, "Long
 * bakes" and "A bake in shards"; the checkpoint file is bake_checkpoint.h).
 *
 * A pass is gather.tiles^2 texels of the order (tens of ms: a cancel is heard within 100 ms) when someone
 * watches (set->progress or set->cancel) or the gather is checkpointed; else the whole order is one pass.
 * Pass p holds the texels [p x pass, (p + 1) x pass) of the order, so a checkpoint or part names passes,
 * never texels, and two processes with the same scene and settings cut the same passes.
 *
 * Everything is gathered into the fresh IIM texture (gpu/gather/iim.h); committing and blending it is the
 * caller's (lightmap_path.h). The job's fields are borrowed for the call; the scene and the AIM must
 * have been uploaded to the gather already. Runs on the thread whose GL context is current. */
#ifndef LM_GATHER_PASSES_H
#define LM_GATHER_PASSES_H

#include "frame_settings.h"

typedef struct {
    lm_gather *gather;
    const lm_scene *scene;
    const lm_atlas *atlas;
    const uint32_t *texels;            /* the order: atlas texel indices */
    unsigned fresh_tex;                /* the IIM texture gathered into */
    const lm_frame_loop_settings *set; /* gather.tiles, progress, cancel, checkpoint, resume, shards, parts */
} lm_gather_job;

/* The first count texels of the order, in passes when someone watches (progress in texels of count). A
 * cancel returns LM_ERR_CANCELLED naming how far it got. */
lm_status lm_gather_passes(const lm_gather_job *j, uint32_t count, lm_error *err);

/* The first full gather of a loop whose settings name a checkpoint or parts: resumed from the checkpoint
 * when set->resume says so (it must match this scene, atlas, gather settings, order and AIM:
 * LM_ERR_INVALID otherwise), a shard's passes or those set->claim_pass hands out, or put together from
 * set->parts; the checkpoint written at most every set->checkpoint_seconds, on a cancel, and at the end
 * of a shard (its part). aim_dilated is the AIM the gather reads, part of the checkpoint's key. */
lm_status lm_gather_first(const lm_gather_job *j, uint32_t count, const float *aim_dilated, lm_error *err);

#endif
