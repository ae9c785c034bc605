/* The first full gather's checkpoint: what a bake had gathered when it was cancelled, failed or killed,
 * so that a resumed bake gathers only the rest and ends with the same bits as one that never stopped.
 *
 * Why it can: the gather writes each texel from the AIMs and the scene alone, and the first full gather
 * takes the texels in a fixed order in passes of a fixed size; a checkpoint is written only between passes.
 * So the fresh IIM after `done` passes, plus the passes from there on, is the uninterrupted gather. The
 * same holds for any set of its passes: a shard of a bake spread over processes takes every shards-th
 * pass (passes shard, shard + shards, ...: a level's dear texels, which cluster in the order, are dealt
 * out to every shard), and the parts' texels put together are the one-process gather's.
 *
 * File (little-endian, as the machine writes it): "LMGICKP3", key (u64), texel count (u32), texels a pass
 * (u32), the gather's passes and those done (u32: a whole bake's passes are all the order's in turn, a
 * shard's its own), shard and shards (u32; 0 and 0 for a whole bake), listed (u32: 1 when the
 * passes are a list), atlas width, height (i32), width x height x 4 floats (the fresh IIM as the passes left it,
 * 0 outside what they gathered), the list (steps u32) when listed, and an FNV-1a checksum of all before it. Written whole or not at all (lm_write_file: NAME.partial renamed over NAME),
 * so a kill leaves the previous checkpoint or the new one, never half of one.
 *
 * Key: FNV-1a over the scene's vertices, triangles, materials and node matrices, the texel table, the
 * order the texels are gathered in, the gather's settings and the dilated AIM it reads (which carries
 * the photons, lights and estimate settings). A checkpoint of another scene or other settings does not
 * match and is refused, naming the file.
 *
 * Cost: one read-back of the IIM (16 bytes a texel) and its write per checkpoint; the key hashes about
 * 50 bytes a texel and a triangle once. Errors: LM_ERR_IO (cannot read or write, naming the file),
 * LM_ERR_INVALID (no checkpoint to resume, another bake's, or damaged). Not thread-safe. */
#ifndef LM_BAKE_CHECKPOINT_H
#define LM_BAKE_CHECKPOINT_H

#include <stdint.h>

#include "../charts/charts.h"
#include "../core/error.h"
#include "../gpu/gather/hemicube.h"
#include "../scene/scene.h"

#define LM_CHECKPOINT_DEFAULT_SECONDS 10.0
#define LM_MAX_SHARDS 4096 /* a bake in at most this many shards */

uint64_t lm_checkpoint_key(const lm_scene *s, const lm_atlas *a, const lm_hemicube_settings *gather,
                           const uint32_t *order, uint32_t count, const float *aim_dilated_rgba);

/* What of the order a checkpoint holds: `done` of the `steps` passes of `pass` texels its gather takes,
 * which are every pass of the order (shards 0), shard `shard`'s (0-based) of `shards` (passes shard,
 * shard + shards, ...), or, with a list, list[0 .. steps): the passes a process of a shared bake was
 * handed as it went (lmgi_updater_desc.claim_pass). */
typedef struct {
    uint32_t pass, steps, done, shard, shards;
    uint32_t *list;
} lm_checkpoint_range;
/* The order's pass that step s of a gather takes (lm_checkpoint_range), and how many steps it has. */
uint32_t lm_checkpoint_step_pass(const lm_checkpoint_range *r, uint32_t s);
uint32_t lm_checkpoint_steps(uint32_t count, uint32_t pass, uint32_t shard, uint32_t shards);

/* Reads the checkpoint at path into rgba (width x height x 4 floats of a) and *range (its list, when it
 * has one, malloc'ed: the caller frees it); LM_ERR_INVALID when there is none, or it is of another key or
 * atlas (the message then ends with `advice`), or damaged. */
lm_status lm_checkpoint_read(const char *path, uint64_t key, const lm_atlas *a, uint32_t count, float *rgba,
                             lm_checkpoint_range *range, const char *advice, lm_error *err);
lm_status lm_checkpoint_write(const char *path, uint64_t key, const lm_atlas *a, uint32_t count,
                              const lm_checkpoint_range *range, const float *rgba, lm_error *err);

#endif
