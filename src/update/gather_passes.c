#include "gather_passes.h"

#include <stdlib.h>
#include <string.h>

#include "../core/log.h"
#include "../core/timing.h"
#include "bake_checkpoint.h"

/* The first full gather's checkpoint while it runs (bake_checkpoint.h); NULL in gather_run: none. */
typedef struct {
    const char *path;
    uint64_t key;
    uint32_t count;        /* texels in the order */
    lm_checkpoint_range r; /* the passes this gather takes (all, or a shard's) and how many are done */
    double seconds, last;  /* at most one write a `seconds`, the last at `last` */
    float *rgba;           /* the fresh IIM read back */
} checkpointing;

static lm_status checkpoint_save(const lm_gather_job *j, checkpointing *ck, uint32_t done, lm_error *err)
{
    lm_status st = lm_iim_texture_read(j->fresh_tex, j->atlas->width, j->atlas->height, ck->rgba, err);
    ck->r.done = done;
    if (st == LM_OK)
        st = lm_checkpoint_write(ck->path, ck->key, j->atlas, ck->count, &ck->r, ck->rgba, err);
    ck->last = lm_now();
    return st;
}

/* A pass of the gather: its texels together. A pass a time when someone watches or may cancel (the first
 * full gather, a bake: tens of ms a pass, so a cancel is heard within 100 ms), else all at once. */
static uint32_t pass_texels(const lm_gather_job *j, int watched, uint32_t count)
{
    watched |= j->set->progress || j->set->cancel;
    uint32_t pass = watched ? (uint32_t)(j->set->gather.tiles * j->set->gather.tiles) : count;
    return pass ? pass : 1;
}

/* The texels of pass p of the order: [*first, *first + *n). */
static void pass_span(uint32_t p, uint32_t pass, uint32_t count, uint32_t *first, uint32_t *n)
{
    uint64_t at = (uint64_t)p * pass;
    *first = at < count ? (uint32_t)at : count;
    *n = count - *first < pass ? count - *first : pass;
}

/* Pass p of the order (passes of `pass` texels of count) gathered into the fresh IIM; *n its texels. */
static lm_status gather_pass(const lm_gather_job *j, uint32_t p, uint32_t pass, uint32_t count, uint32_t *n, lm_error *err)
{
    uint32_t first;
    pass_span(p, pass, count, &first, n);
    return lm_gather_texels(j->gather, j->scene, j->atlas, j->texels + first, *n, j->fresh_tex, NULL, err);
}

/* Gathers steps [r.done, r.steps) of the passes r names into the fresh IIM, a pass at a time; progress
 * counts the texels of r's passes. */
static lm_status gather_run(const lm_gather_job *j, lm_checkpoint_range r, uint32_t count, checkpointing *ck,
                            lm_error *err)
{
    lm_status st = LM_OK;
    uint32_t texels = 0, done = 0, first, n;
    for (uint32_t s = 0; s < r.steps; s++) {
        pass_span(lm_checkpoint_step_pass(&r, s), r.pass, count, &first, &n);
        texels += n;
        done += s < r.done ? n : 0;
    }
    for (uint32_t s = r.done; st == LM_OK && s < r.steps; s++) {
        if (j->set->cancel && *j->set->cancel) {
            if (ck && (st = checkpoint_save(j, ck, s, err)) != LM_OK)
                return st;
            return lm_fail(err, LM_ERR_CANCELLED, "%s: cancelled after %u of %u texels%s%s", j->scene->path, done,
                           texels, ck ? ", kept in " : "", ck ? ck->path : "");
        }
        st = gather_pass(j, lm_checkpoint_step_pass(&r, s), r.pass, count, &n, err);
        if (st == LM_OK && ck && s + 1 < r.steps && lm_now() - ck->last >= ck->seconds)
            st = checkpoint_save(j, ck, s + 1, err);
        done += n;
        if (j->set->progress && s + 1 == r.steps)
            lm_gl_finish(); /* the last pass's progress says "done" once the GPU has drawn it */
        if (j->set->progress)
            j->set->progress(j->set->progress_user, done, texels);
    }
    return st;
}

/* The passes of the order that set.claim_pass hands this process, gathered into the fresh IIM as they
 * come; ck->r lists them. Progress says how far the handing out has gone: the whole shared bake's. */
static lm_status gather_claimed(const lm_gather_job *j, uint32_t count, checkpointing *ck, lm_error *err)
{
    uint32_t passes = lm_checkpoint_steps(count, ck->r.pass, 0, 0), n, shown = 0;
    ck->r.steps = ck->r.done = 0;
    if (!(ck->r.list = malloc(sizeof *ck->r.list * (passes ? passes : 1))))
        return lm_fail(err, LM_ERR_NOMEM, "no memory for the list of the bake's passes");
    lm_status st = LM_OK;
    while (st == LM_OK) {
        if (j->set->cancel && *j->set->cancel)
            return lm_fail(err, LM_ERR_CANCELLED, "%s: cancelled after %u passes of this process", j->scene->path,
                           ck->r.steps);
        int p = j->set->claim_pass(j->set->claim_user, (int)passes);
        if (p < 0)
            break;
        if ((uint32_t)p >= passes || ck->r.steps == passes)
            return lm_fail(err, LM_ERR_INVALID, "%s: claim_pass gave pass %d of %u (%u taken already)",
                           j->scene->path, p, passes, ck->r.steps);
        st = gather_pass(j, (uint32_t)p, ck->r.pass, count, &n, err);
        ck->r.list[ck->r.steps++] = (uint32_t)p;
        shown = (uint32_t)p * ck->r.pass + n; /* the end of pass p */
        if (j->set->progress)
            j->set->progress(j->set->progress_user, shown, count);
    }
    ck->r.done = ck->r.steps;
    if (st == LM_OK && j->set->progress && shown < count) /* every pass handed out (some may be under way) */
        j->set->progress(j->set->progress_user, count, count);
    return st;
}

/* Gathers the first count scheduled texels, in passes when someone watches. */
lm_status lm_gather_passes(const lm_gather_job *j, uint32_t count, lm_error *err)
{
    uint32_t pass = pass_texels(j, 0, count);
    lm_checkpoint_range all = {pass, lm_checkpoint_steps(count, pass, 0, 0), 0, 0, 0, NULL};
    return gather_run(j, all, count, NULL, err);
}

/* Part p (read into r) checked against the parts before it: of a shared bake's shards, of the same
 * count, a shard no other part is (for dealt parts), passes of this bake's size, finished. */
static lm_status check_part(const lm_gather_job *j, const checkpointing *ck, int p, const lm_checkpoint_range *r,
                            const lm_checkpoint_range *first, const int *have, lm_error *err)
{
    const char *const *parts = j->set->parts;
    if (!r->shards)
        return lm_fail(err, LM_ERR_INVALID, "%s: a whole bake's checkpoint, not a shard's part", parts[p]);
    if (p > 0 && (r->shards != first->shards || !r->list != !first->list))
        return lm_fail(err, LM_ERR_INVALID, "%s: a part of a bake in %u %s; %s's was in %u %s", parts[p], r->shards,
                       r->list ? "processes" : "shards", parts[0], first->shards, first->list ? "processes" : "shards");
    if (have[r->shard] >= 0)
        return lm_fail(err, LM_ERR_INVALID, "%s and %s are both shard %u of %u", parts[have[r->shard]], parts[p],
                       r->shard + 1, r->shards);
    if (r->pass != ck->r.pass) /* the key holds the settings that make the pass */
        return lm_fail(err, LM_ERR_INVALID, "%s: passes of %u texels, this bake's of %u", parts[p], r->pass, ck->r.pass);
    if (r->done != r->steps)
        return lm_fail(err, LM_ERR_INVALID, "%s: an unfinished part (%u of its %u passes gathered); finish its "
                       "shard with --resume", parts[p], r->done, r->steps);
    return LM_OK;
}

/* Part p's passes marked as its own in owner[] (one part a pass) and its texels copied into ck->rgba. */
static lm_status take_part(const lm_gather_job *j, checkpointing *ck, int p, const lm_checkpoint_range *r,
                           const float *part, int *owner, lm_error *err)
{
    for (uint32_t s = 0; s < r->steps; s++) {
        uint32_t pass = lm_checkpoint_step_pass(r, s), first, count;
        if (owner[pass] >= 0)
            return lm_fail(err, LM_ERR_INVALID, "%s and %s both hold pass %u of the gather", j->set->parts[owner[pass]],
                           j->set->parts[p], pass);
        owner[pass] = p;
        pass_span(pass, r->pass, ck->count, &first, &count);
        for (uint32_t i = first; i < first + count; i++) {
            const lm_texel *t = &j->atlas->texels[j->texels[i]];
            size_t at = 4 * ((size_t)t->y * j->atlas->width + t->x);
            memcpy(ck->rgba + at, part + at, 4 * sizeof *part);
        }
    }
    return LM_OK;
}

/* What no part holds, named: a dealt bake's missing shard, or a shared bake's passes in no part. */
static lm_status missing_parts(const lm_gather_job *j, const checkpointing *ck, const lm_checkpoint_range *first,
                               const int *have, const int *owner, lm_error *err)
{
    uint32_t passes = ck->r.steps, lost = 0, at = 0;
    for (uint32_t k = 0; !first->list && k < first->shards; k++)
        if (have[k] < 0)
            return lm_fail(err, LM_ERR_INVALID, "%s: shard %u of %u is missing (%u of the %u passes); merge needs one "
                           "part of each", j->scene->path, k + 1, first->shards,
                           lm_checkpoint_steps(ck->count, ck->r.pass, k, first->shards), passes);
    for (uint32_t q = passes; q-- > 0;)
        if (owner[q] < 0)
            lost++, at = q;
    if (lost)
        return lm_fail(err, LM_ERR_INVALID, "%s: %u of the gather's %u passes (the first: pass %u) are in no part; "
                       "a process of the shared bake is missing", j->scene->path, lost, passes, at);
    return LM_OK;
}

/* The parts of a bake in shards put together into ck->rgba: each part's texels copied from its file, one
 * part of each shard, every pass of the gather in exactly one part. */
static lm_status join_parts(const lm_gather_job *j, checkpointing *ck, lm_error *err)
{
    size_t n = 4 * (size_t)j->atlas->width * (size_t)j->atlas->height;
    uint32_t passes = ck->r.steps;
    float *part = malloc(n * sizeof *part);
    int *have = malloc(sizeof *have * (LM_MAX_SHARDS + 1)), *owner = malloc(sizeof *owner * (passes + 1));
    if (!part || !have || !owner) {
        free(part);
        free(have);
        free(owner);
        return lm_fail(err, LM_ERR_NOMEM, "no memory to join the bake's parts");
    }
    memset(ck->rgba, 0, n * sizeof *ck->rgba);
    for (int k = 0; k <= LM_MAX_SHARDS; k++)
        have[k] = -1;
    for (uint32_t q = 0; q < passes; q++)
        owner[q] = -1;
    lm_status st = LM_OK;
    lm_checkpoint_range first = {0};
    for (int p = 0; p < j->set->part_count && st == LM_OK; p++) {
        lm_checkpoint_range r;
        st = lm_checkpoint_read(j->set->parts[p], ck->key, j->atlas, ck->count, part, &r,
                                "give merge the scene and the options its shards were baked with", err);
        if (st != LM_OK)
            break;
        if (p == 0)
            first = r; /* its list freed at the end */
        st = check_part(j, ck, p, &r, &first, have, err);
        if (st == LM_OK)
            have[r.shard] = p, st = take_part(j, ck, p, &r, part, owner, err);
        if (p > 0)
            free(r.list);
    }
    if (st == LM_OK)
        st = missing_parts(j, ck, &first, have, owner, err);
    free(first.list);
    free(part);
    free(have);
    free(owner);
    return st;
}

lm_status lm_gather_first(const lm_gather_job *j, uint32_t count, const float *aim_dilated, lm_error *err)
{
    lm_status st = LM_OK;
    uint32_t pass = pass_texels(j, 1, count), shard = (uint32_t)j->set->shard, shards = (uint32_t)j->set->shards;
    checkpointing ck = {j->set->checkpoint, 0, count,
                        {pass, lm_checkpoint_steps(count, pass, 0, 0), 0, 0, 0, NULL},
                        j->set->checkpoint_seconds > 0.0 ? j->set->checkpoint_seconds : LM_CHECKPOINT_DEFAULT_SECONDS,
                        lm_now(), malloc(4 * sizeof(float) * (size_t)j->atlas->width * (size_t)j->atlas->height)};
    if (!ck.rgba)
        return lm_fail(err, LM_ERR_NOMEM, "no memory for the bake's checkpoint");
    ck.key = lm_checkpoint_key(j->scene, j->atlas, &j->set->gather, j->texels, count, aim_dilated);
    if (shards > 0)
        ck.r = (lm_checkpoint_range){pass, lm_checkpoint_steps(count, pass, shard, shards), 0, shard, shards, NULL};
    if (j->set->parts) {
        st = join_parts(j, &ck, err);
        ck.r.done = ck.r.steps;
        if (st == LM_OK)
            lm_info("%s: the gather put together from %d parts", j->scene->path, j->set->part_count);
    } else if (j->set->resume) {
        lm_checkpoint_range r = {0};
        st = lm_checkpoint_read(ck.path, ck.key, j->atlas, count, ck.rgba, &r, "bake without --resume to start again",
                                err);
        if (st == LM_OK && r.list)
            st = lm_fail(err, LM_ERR_INVALID, "%s: the part of a process of a shared (MPI) bake: it does not resume",
                         ck.path);
        free(r.list);
        if (st == LM_OK && (r.shard != shard || r.shards != shards || r.pass != pass))
            st = lm_fail(err, LM_ERR_INVALID, "%s: a checkpoint of %s%u of %u, not of this bake's %s%u of %u", ck.path,
                         r.shards ? "shard " : "the whole bake, ", r.shard + !!r.shards, r.shards,
                         shards ? "shard " : "whole bake, ", shard + !!shards, shards);
        ck.r.done = r.done;
        if (st == LM_OK)
            lm_info("%s: resuming the gather at texel %u of %u from %s", j->scene->path,
                    shards ? r.done : r.done * pass < count ? r.done * pass : count, count, ck.path);
    }
    if (st == LM_OK && (j->set->parts || j->set->resume))
        st = lm_iim_texture_write(j->fresh_tex, j->atlas->width, j->atlas->height, ck.rgba, err);
    if (st == LM_OK && j->set->claim_pass && shards > 1)
        st = gather_claimed(j, count, &ck, err);
    else if (st == LM_OK)
        st = gather_run(j, ck.r, count, j->set->checkpoint ? &ck : NULL, err);
    if (st == LM_OK && shards > 0) /* the part: kept by the caller */
        st = checkpoint_save(j, &ck, ck.r.steps, err);
    free(ck.r.list);
    free(ck.rgba);
    return st;
}

