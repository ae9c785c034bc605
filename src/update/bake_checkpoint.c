/* The first full gather's checkpoint file (bake_checkpoint.h). */
#include "bake_checkpoint.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/hash.h"
#include "../core/image.h"
#include "../scene/sky.h"

static const char k_magic[8] = {'L', 'M', 'G', 'I', 'C', 'K', 'P', '3'};

uint64_t lm_checkpoint_key(const lm_scene *s, const lm_atlas *a, const lm_hemicube_settings *gather,
                           const uint32_t *order, uint32_t count, const float *aim_dilated_rgba)
{
    uint64_t h = LM_HASH_SEED;
    h = lm_hash_bytes(h, s->positions, 3 * sizeof(float) * s->vertex_count);
    h = lm_hash_bytes(h, s->tris, 3 * sizeof(uint32_t) * s->tri_count);
    h = lm_hash_bytes(h, s->materials, sizeof *s->materials * (size_t)s->material_count);
    h = lm_sky_hash(h, s);
    for (int n = 0; n < s->node_count; n++)
        h = lm_hash_bytes(h, s->nodes[n].world, sizeof s->nodes[n].world);
    h = lm_hash_bytes(h, &a->width, sizeof a->width);
    h = lm_hash_bytes(h, &a->height, sizeof a->height);
    h = lm_hash_bytes(h, a->texels, sizeof *a->texels * a->texel_count);
    h = lm_hash_bytes(h, gather, sizeof *gather);
    h = lm_hash_bytes(h, &count, sizeof count);
    h = lm_hash_bytes(h, order, sizeof *order * count);
    return lm_hash_bytes(h, aim_dilated_rgba, 4 * sizeof(float) * (size_t)a->width * (size_t)a->height);
}

uint32_t lm_checkpoint_step_pass(const lm_checkpoint_range *r, uint32_t s)
{
    return r->list ? r->list[s] : r->shards ? r->shard + s * r->shards : s;
}

uint32_t lm_checkpoint_steps(uint32_t count, uint32_t pass, uint32_t shard, uint32_t shards)
{
    uint32_t passes = pass ? (uint32_t)(((uint64_t)count + pass - 1) / pass) : 0;
    if (!shards)
        return passes;
    return passes > shard ? (passes - shard + shards - 1) / shards : 0;
}

typedef struct {
    char magic[8];
    uint64_t key;
    uint32_t count, pass, steps, done, shard, shards, listed;
    int32_t width, height;
} header;

lm_status lm_checkpoint_write(const char *path, uint64_t key, const lm_atlas *a, uint32_t count,
                              const lm_checkpoint_range *range, const float *rgba, lm_error *err)
{
    header hd;
    memset(&hd, 0, sizeof hd);
    memcpy(hd.magic, k_magic, sizeof hd.magic);
    hd.key = key, hd.count = count, hd.width = a->width, hd.height = a->height;
    hd.pass = range->pass, hd.steps = range->steps, hd.done = range->done;
    hd.shard = range->shard, hd.shards = range->shards, hd.listed = range->list != NULL;
    size_t n = 4 * sizeof(float) * (size_t)a->width * (size_t)a->height;
    size_t list = hd.listed ? sizeof(uint32_t) * range->steps : 0, body = sizeof hd + n + list;
    unsigned char *file = malloc(body + sizeof(uint64_t));
    if (!file)
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for the bake's checkpoint", path);
    memcpy(file, &hd, sizeof hd);
    memcpy(file + sizeof hd, rgba, n);
    if (list)
        memcpy(file + sizeof hd + n, range->list, list);
    uint64_t sum = lm_hash_bytes(LM_HASH_SEED, file, body);
    memcpy(file + body, &sum, sizeof sum);
    lm_status st = lm_write_file(path, file, body + sizeof sum, err); /* whole or not at all */
    free(file);
    return st;
}

lm_status lm_checkpoint_read(const char *path, uint64_t key, const lm_atlas *a, uint32_t count, float *rgba,
                             lm_checkpoint_range *range, const char *advice, lm_error *err)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return lm_fail(err, errno == ENOENT ? LM_ERR_INVALID : LM_ERR_IO, "%s: no checkpoint to resume: %s", path,
                       strerror(errno));
    header hd;
    size_t n = 4 * sizeof(float) * (size_t)a->width * (size_t)a->height;
    uint64_t sum = 0;
    int ok = fread(&hd, sizeof hd, 1, f) == 1 && memcmp(hd.magic, k_magic, sizeof hd.magic) == 0;
    if (ok && (hd.key != key || hd.count != count || hd.width != a->width || hd.height != a->height)) {
        fclose(f);
        return lm_fail(err, LM_ERR_INVALID,
                       "%s: a checkpoint of another scene or other settings (its key %016llx, this bake's %016llx); "
                       "%s", path, (unsigned long long)hd.key, (unsigned long long)key, advice);
    }
    uint32_t passes = ok && hd.pass > 0 ? lm_checkpoint_steps(count, hd.pass, 0, 0) : 0, *list = NULL;
    ok = ok && hd.pass > 0 && hd.done <= hd.steps && hd.listed <= 1 && hd.shards <= LM_MAX_SHARDS &&
         (hd.listed ? hd.steps <= passes && hd.shards > 1 : hd.steps == lm_checkpoint_steps(count, hd.pass, hd.shard, hd.shards)) &&
         (hd.shards ? hd.shard < hd.shards : hd.shard == 0) && fread(rgba, 1, n, f) == n;
    size_t list_bytes = hd.listed ? sizeof *list * hd.steps : 0;
    if (ok && hd.listed && (!(list = malloc(list_bytes ? list_bytes : 1)) || fread(list, 1, list_bytes, f) != list_bytes))
        ok = 0;
    ok = ok && fread(&sum, sizeof sum, 1, f) == 1 && fgetc(f) == EOF &&
         sum == lm_hash_bytes(lm_hash_bytes(lm_hash_bytes(LM_HASH_SEED, &hd, sizeof hd), rgba, n), list, list_bytes);
    for (uint32_t s = 0; ok && list && s < hd.steps; s++)
        ok = list[s] < passes;
    fclose(f);
    if (!ok) {
        free(list);
        return lm_fail(err, LM_ERR_INVALID, "%s: not an lmgi bake checkpoint, or damaged", path);
    }
    *range = (lm_checkpoint_range){hd.pass, hd.steps, hd.done, hd.shard, hd.shards, list};
    return LM_OK;
}
