#include "frame_loop.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/hash.h"
#include "../core/memory.h"
#include "../core/timing.h"
#include "../core/log.h"
#include "../core/vecmath.h"
#include "../gpu/frame/composite.h"
#include "../gpu/gather/gather_error.h"
#include "../photonmap/pixel_gather.h"
#include "../gpu/frame/reflections.h"
#include "../gpu/gl/gl_context.h"
#include "../scene/sky.h"
#include "../trace/emitter_light.h"
#include "bake_checkpoint.h"
#include "stage_worker.h"

struct lm_frame_loop {
    lm_frame_loop_settings set;
    lm_scene *scene;
    const lm_atlas *atlas;
    lm_gl_context *gl;
    int own_gl;              /* gl made here (else borrowed from the settings) */
    lm_photon_stage *stage;
    lm_stage_worker *worker; /* with settings.overlap: runs the stage's update beside the GL work */
    lm_photon_stage_frame pending; /* detached: the stage's job begun by the last step, not yet joined */
    int pending_busy;
    int pending_joined;            /* a sync joined it: its counts wait for the next step's report */
    lm_gather *gather;
    lm_composite *comp;
    lm_reflections *reflections; /* NULL: no mirror or glossy node, or switched off */
    lm_caustic_pass *caustic_pass; /* made when the first caustic photons land */
    uint64_t caustic_version;    /* the stage's caustic photons the pass holds (lm_photon_stage_caustics_version) */
    int caustic_slot, caustic_w, caustic_h; /* the last picture drawn: its caustics' slot and size (w 0: none yet) */
    uint64_t caustic_key[LM_CAUSTIC_SLOTS]; /* what each slot's last run was made for (draw_caustics) */
    int caustic_keyed[LM_CAUSTIC_SLOTS];
    int generators;              /* the scene has caustic generators (mirror or glass nodes, caustics on) ... */
    uint32_t generators_version; /* ... as of this pass_version (+1: 0 is never a count yet) */
    uint32_t reflect_version;    /* the scene's pass_version the reflection maps were made for */
    uint32_t switch_version;     /* the scene's pass_version the gather's and composite's switches follow */
    struct {                     /* whether the scene gives any light (follow_light): none, no gather */
        int unlit, emissive;     /* emissive: it has emissive triangles, as of the scene's emissive_version */
        uint32_t emissive_version;
    } light;
    /* the photon paths: the store's hits as GPU records, the gather, and what its picture was made for */
    lm_photon_records records;
    lm_photon_gather *photon_gather;
    float photon_radius;         /* the kernel radius for the records held */
    uint32_t radius_live;        /* the live records it was derived from */
    uint64_t photon_key;         /* a hash of the records, view, size, radius and scene the last gather saw */
    int photon_keyed;
    unsigned photon_runs;        /* gathers run: turns the stochastic gather's classes */
    uint64_t coverage_key;       /* the radius and node scales the direct pass's kernel coverage is for (0: none) */
    const lm_surfaces *surfaces;
    lm_direct *direct_light; /* persistent: program, buffers, target and shadow maps */
    lm_iim iim;
    int have_iim;
    lm_rt *rt;
    lm_emitter_light emitters; /* with have_emitters: the gather's closed-form emitter light */
    int have_emitters;
    uint32_t *texels;      /* scratch: this frame's scheduled texels (atlas texel_count) */
    uint8_t *refreshed;    /* scratch: per surface, its AIM refreshed since the last schedule */
    float *image;
    int aim_stale;         /* the AIM changed since the gather last uploaded it */
    lm_view view;
};

int lm_frame_loop_atlas_texels(int texels_per_frame)
{
    long n = (long)texels_per_frame * LM_FRAME_LOOP_REFRESH_FRAMES;
    return n < 256 ? 256 : n > 1L << 28 ? 1 << 28 : (int)n;
}

void lm_frame_loop_settings_default(lm_frame_loop_settings *s)
{
    memset(s, 0, sizeof *s); /* a field added later is 0, NULL, off, not stack garbage */
    lm_photon_stage_settings_default(&s->stage);
    lm_hemicube_settings_default(&s->gather);
    s->gather.coverage_samples = 0; /* chosen per scene */
    s->emitter_light = -1;
    s->overlap = 1;
    s->emitter_rays = LM_EMITTER_LIGHT_DEFAULT_RAYS;
    lm_iim_settings_default(&s->iim);
    lm_direct_settings_default(&s->direct);
    s->width = 512;
    s->height = 512;
    s->camera = -1;
    s->reflection_size = 128;
    s->reflection_faces = 1;
    s->caustics = 1;
    lm_caustic_pass_settings_default(&s->caustic_pass);
    s->indirect = 1;
    s->indirect_path = LM_INDIRECT_LIGHTMAP;
    lm_photon_gather_settings_default(&s->photon_gather);
}

/* Which indirect path the frames take, if any: the lightmaps (AIMs, gather, IIM) or the photon gather at
 * the pixels. */
static int lightmap_path(const lm_frame_loop *fl)
{
    return fl->set.indirect && fl->set.indirect_path == LM_INDIRECT_LIGHTMAP;
}
static int photon_path(const lm_frame_loop *fl)
{
    return fl->set.indirect && fl->set.indirect_path != LM_INDIRECT_LIGHTMAP;
}

/* The photon store's delta_i is the IIM scheduler's input, reset once a surface is regathered. */
static lm_photon_store *store_of(lm_frame_loop *fl) { return lm_photon_stage_store(fl->stage); }

/* A texel's position now (its node may have moved since load) and its triangle's geometric normal now
 * (the side its light leaves from). */
static lm_vec3 texel_now(const lm_frame_loop *fl, uint32_t texel, lm_vec3 *normal)
{
    const lm_texel *t = &fl->atlas->texels[texel];
    const float *w = fl->scene->nodes[fl->scene->tri_node[t->tri]].world;
    lm_vec3 c[3];
    for (int k = 0; k < 3; k++) {
        float v[3];
        lm_scene_vertex_world(fl->scene, fl->scene->tris[3 * (size_t)t->tri + (size_t)k], v);
        c[k] = lm_v3_load(v);
    }
    *normal = lm_normalize(lm_cross(lm_sub(c[1], c[0]), lm_sub(c[2], c[0])));
    return lm_mat4_point(w, lm_v3_load(t->local));
}

#define SEE_PAIRS 16 /* texel pairs tried between two surfaces */

/* Whether surface a sees surface b: one of SEE_PAIRS texel pairs, spread over both, that face each other
 * and are joined by an unoccluded segment (each end lifted off its surface along its normal). False
 * negatives are possible for surfaces that see each other through a gap narrower than the pairs'
 * spacing. */
static int sees(const lm_frame_loop *fl, int a, int b, float lift)
{
    const lm_iim_sched *iim = &fl->iim.sched;
    uint32_t na = iim->surf_first[a + 1] - iim->surf_first[a], nb = iim->surf_first[b + 1] - iim->surf_first[b];
    if (!na || !nb)
        return 0;
    for (uint32_t k = 0; k < SEE_PAIRS; k++) {
        uint32_t ta = iim->surf_texels[iim->surf_first[a] + (uint32_t)((uint64_t)k * na / SEE_PAIRS)];
        uint32_t tb = iim->surf_texels[iim->surf_first[b] + (uint32_t)((uint64_t)((k * 7 + 3) % SEE_PAIRS) * nb / SEE_PAIRS)];
        lm_vec3 na3, nb3;
        lm_vec3 p = texel_now(fl, ta, &na3), q = texel_now(fl, tb, &nb3);
        p = lm_add(p, lm_scale(na3, lift));
        q = lm_add(q, lm_scale(nb3, lift));
        lm_vec3 d = lm_sub(q, p);
        float len = lm_length(d);
        if (!(len > lift))
            continue;
        d = lm_scale(d, 1.0f / len);
        if (!(lm_dot(na3, d) > 0.01f && lm_dot(nb3, d) < -0.01f)) /* not facing each other */
            continue;
        float org[3], dir[3];
        lm_v3_store(org, p);
        lm_v3_store(dir, d);
        if (!lm_rt_occluded(fl->rt, org, dir, 0.0f, len))
            return 1;
    }
    return 0;
}

/* A surface whose own photons did not change may still see one whose AIM was refreshed (the cube beside
 * a recoloured wall that no changed photon reached): its hemicube would show the old light, so it is
 * regathered too. Marks those surfaces' delta_i; returns how many. Called when the stage's work is done
 * (not running on the worker), before the IIM schedule. */
static int widen_to_viewers(lm_frame_loop *fl, lm_photon_store *ps)
{
    uint8_t *refreshed = fl->refreshed;
    if (!lm_photon_stage_take_refreshed(fl->stage, refreshed))
        return 0;
    int S = fl->iim.sched.surface_count, n = 0;
    float lift = 1e-3f * lm_scene_size(fl->scene);
    for (int a = 0; a < S; a++) {
        if (ps->surfaces[a].delta_i > fl->iim.sched.delta_threshold)
            continue;
        for (int b = 0; b < S; b++)
            if (b != a && refreshed[b] && sees(fl, a, b, lift)) {
                /* just over the threshold, whatever its size (a fixed 1e-30 vanishes beside 1; nextafter's
                 * denormal beside 0 reads as 0 on the threads that trace, which flush denormals) */
                double th = fl->iim.sched.delta_threshold;
                ps->surfaces[a].delta_i = th + fmax(1e-30, 1e-9 * th);
                n++;
                break;
            }
    }
    return n;
}

/* Uploads the current scene and, when they changed since the last upload, the AIMs: all the gather reads
 * of the photon stage, so that the stage may run again once this returns. */
static lm_status gather_prepare(lm_frame_loop *fl, lm_error *err)
{
    lm_status st = lm_gather_set_scene(fl->gather, fl->scene, fl->atlas, err);
    if (fl->scene->has_sky) { /* a hemicube clears to one colour: a sky that is not uniform wants the rays scheme */
        float mean[3];
        lm_sky_mean(fl->scene, mean);
        lm_gather_set_sky(fl->gather, mean);
    }
    if (st == LM_OK && fl->aim_stale)
        st = lm_gather_set_aim_dilated(fl->gather, fl->atlas, lm_aim_dilated_rgba(lm_photon_stage_aim(fl->stage)), err);
    if (st == LM_OK)
        fl->aim_stale = 0;
    return st;
}

/* The first full gather's checkpoint while it runs (bake_checkpoint.h); NULL in gather_run: none. */
typedef struct {
    const char *path;
    uint64_t key;
    uint32_t count;        /* texels in the order */
    lm_checkpoint_range r; /* the passes this gather takes (all, or a shard's) and how many are done */
    double seconds, last;  /* at most one write a `seconds`, the last at `last` */
    float *rgba;           /* the fresh IIM read back */
} checkpointing;

static lm_status checkpoint_save(lm_frame_loop *fl, checkpointing *ck, uint32_t done, lm_error *err)
{
    lm_status st = lm_iim_texture_read(fl->iim.fresh_tex, fl->atlas->width, fl->atlas->height, ck->rgba, err);
    ck->r.done = done;
    if (st == LM_OK)
        st = lm_checkpoint_write(ck->path, ck->key, fl->atlas, ck->count, &ck->r, ck->rgba, err);
    ck->last = lm_now();
    return st;
}

/* A pass of the gather: its texels together. A pass a time when someone watches or may cancel (the first
 * full gather, a bake: tens of ms a pass, so a cancel is heard within 100 ms), else all at once. */
static uint32_t pass_texels(const lm_frame_loop *fl, int watched, uint32_t count)
{
    watched |= fl->set.progress || fl->set.cancel;
    uint32_t pass = watched ? (uint32_t)(fl->set.gather.tiles * fl->set.gather.tiles) : count;
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
static lm_status gather_pass(lm_frame_loop *fl, uint32_t p, uint32_t pass, uint32_t count, uint32_t *n, lm_error *err)
{
    uint32_t first;
    pass_span(p, pass, count, &first, n);
    return lm_gather_texels(fl->gather, fl->scene, fl->atlas, fl->texels + first, *n, fl->iim.fresh_tex, NULL, err);
}

/* Gathers steps [r.done, r.steps) of the passes r names into the fresh IIM, a pass at a time; progress
 * counts the texels of r's passes. */
static lm_status gather_run(lm_frame_loop *fl, lm_checkpoint_range r, uint32_t count, checkpointing *ck,
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
        if (fl->set.cancel && *fl->set.cancel) {
            if (ck && (st = checkpoint_save(fl, ck, s, err)) != LM_OK)
                return st;
            return lm_fail(err, LM_ERR_CANCELLED, "%s: cancelled after %u of %u texels%s%s", fl->scene->path, done,
                           texels, ck ? ", kept in " : "", ck ? ck->path : "");
        }
        st = gather_pass(fl, lm_checkpoint_step_pass(&r, s), r.pass, count, &n, err);
        if (st == LM_OK && ck && s + 1 < r.steps && lm_now() - ck->last >= ck->seconds)
            st = checkpoint_save(fl, ck, s + 1, err);
        done += n;
        if (fl->set.progress)
            fl->set.progress(fl->set.progress_user, done, texels);
    }
    return st;
}

/* The passes of the order that set.claim_pass hands this process, gathered into the fresh IIM as they
 * come; ck->r lists them. Progress says how far the handing out has gone: the whole shared bake's. */
static lm_status gather_claimed(lm_frame_loop *fl, uint32_t count, checkpointing *ck, lm_error *err)
{
    uint32_t passes = lm_checkpoint_steps(count, ck->r.pass, 0, 0), n, shown = 0;
    ck->r.steps = ck->r.done = 0;
    if (!(ck->r.list = malloc(sizeof *ck->r.list * (passes ? passes : 1))))
        return lm_fail(err, LM_ERR_NOMEM, "no memory for the list of the bake's passes");
    lm_status st = LM_OK;
    while (st == LM_OK) {
        if (fl->set.cancel && *fl->set.cancel)
            return lm_fail(err, LM_ERR_CANCELLED, "%s: cancelled after %u passes of this process", fl->scene->path,
                           ck->r.steps);
        int p = fl->set.claim_pass(fl->set.claim_user, (int)passes);
        if (p < 0)
            break;
        if ((uint32_t)p >= passes || ck->r.steps == passes)
            return lm_fail(err, LM_ERR_INVALID, "%s: claim_pass gave pass %d of %u (%u taken already)",
                           fl->scene->path, p, passes, ck->r.steps);
        st = gather_pass(fl, (uint32_t)p, ck->r.pass, count, &n, err);
        ck->r.list[ck->r.steps++] = (uint32_t)p;
        shown = (uint32_t)p * ck->r.pass + n; /* the end of pass p */
        if (fl->set.progress)
            fl->set.progress(fl->set.progress_user, shown, count);
    }
    ck->r.done = ck->r.steps;
    if (st == LM_OK && fl->set.progress && shown < count) /* every pass handed out (some may be under way) */
        fl->set.progress(fl->set.progress_user, count, count);
    return st;
}

/* Gathers the first count scheduled texels, in passes when someone watches. */
static lm_status gather_texels(lm_frame_loop *fl, uint32_t count, lm_error *err)
{
    uint32_t pass = pass_texels(fl, 0, count);
    lm_checkpoint_range all = {pass, lm_checkpoint_steps(count, pass, 0, 0), 0, 0, 0, NULL};
    return gather_run(fl, all, count, NULL, err);
}

static lm_status gather(lm_frame_loop *fl, uint32_t count, lm_error *err)
{
    if (count == 0)
        return LM_OK;
    lm_status st = gather_prepare(fl, err);
    return st == LM_OK ? gather_texels(fl, count, err) : st;
}

/* Part p (read into r) checked against the parts before it: of a shared bake's shards, of the same
 * count, a shard no other part is (for dealt parts), passes of this bake's size, finished. */
static lm_status check_part(const lm_frame_loop *fl, const checkpointing *ck, int p, const lm_checkpoint_range *r,
                            const lm_checkpoint_range *first, const int *have, lm_error *err)
{
    const char *const *parts = fl->set.parts;
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
static lm_status take_part(lm_frame_loop *fl, checkpointing *ck, int p, const lm_checkpoint_range *r,
                           const float *part, int *owner, lm_error *err)
{
    for (uint32_t s = 0; s < r->steps; s++) {
        uint32_t pass = lm_checkpoint_step_pass(r, s), first, count;
        if (owner[pass] >= 0)
            return lm_fail(err, LM_ERR_INVALID, "%s and %s both hold pass %u of the gather", fl->set.parts[owner[pass]],
                           fl->set.parts[p], pass);
        owner[pass] = p;
        pass_span(pass, r->pass, ck->count, &first, &count);
        for (uint32_t i = first; i < first + count; i++) {
            const lm_texel *t = &fl->atlas->texels[fl->texels[i]];
            size_t at = 4 * ((size_t)t->y * fl->atlas->width + t->x);
            memcpy(ck->rgba + at, part + at, 4 * sizeof *part);
        }
    }
    return LM_OK;
}

/* What no part holds, named: a dealt bake's missing shard, or a shared bake's passes in no part. */
static lm_status missing_parts(const lm_frame_loop *fl, const checkpointing *ck, const lm_checkpoint_range *first,
                               const int *have, const int *owner, lm_error *err)
{
    uint32_t passes = ck->r.steps, lost = 0, at = 0;
    for (uint32_t k = 0; !first->list && k < first->shards; k++)
        if (have[k] < 0)
            return lm_fail(err, LM_ERR_INVALID, "%s: shard %u of %u is missing (%u of the %u passes); merge needs one "
                           "part of each", fl->scene->path, k + 1, first->shards,
                           lm_checkpoint_steps(ck->count, ck->r.pass, k, first->shards), passes);
    for (uint32_t q = passes; q-- > 0;)
        if (owner[q] < 0)
            lost++, at = q;
    if (lost)
        return lm_fail(err, LM_ERR_INVALID, "%s: %u of the gather's %u passes (the first: pass %u) are in no part; "
                       "a process of the shared bake is missing", fl->scene->path, lost, passes, at);
    return LM_OK;
}

/* The parts of a bake in shards put together into ck->rgba: each part's texels copied from its file, one
 * part of each shard, every pass of the gather in exactly one part. */
static lm_status join_parts(lm_frame_loop *fl, checkpointing *ck, lm_error *err)
{
    size_t n = 4 * (size_t)fl->atlas->width * (size_t)fl->atlas->height;
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
    for (int p = 0; p < fl->set.part_count && st == LM_OK; p++) {
        lm_checkpoint_range r;
        st = lm_checkpoint_read(fl->set.parts[p], ck->key, fl->atlas, ck->count, part, &r,
                                "give merge the scene and the options its shards were baked with", err);
        if (st != LM_OK)
            break;
        if (p == 0)
            first = r; /* its list freed at the end */
        st = check_part(fl, ck, p, &r, &first, have, err);
        if (st == LM_OK)
            have[r.shard] = p, st = take_part(fl, ck, p, &r, part, owner, err);
        if (p > 0)
            free(r.list);
    }
    if (st == LM_OK)
        st = missing_parts(fl, ck, &first, have, owner, err);
    free(first.list);
    free(part);
    free(have);
    free(owner);
    return st;
}

/* The first full gather of every texel (or of a shard's passes), checkpointed to set.checkpoint when one
 * is named (and resumed from it when set.resume says so), or put together from set.parts. */
static lm_status first_gather(lm_frame_loop *fl, lm_error *err)
{
    uint32_t count = lm_iim_sched_pick_all(&fl->iim.sched, store_of(fl), fl->texels);
    if ((!fl->set.checkpoint && !fl->set.parts) || count == 0)
        return gather(fl, count, err);
    lm_status st = gather_prepare(fl, err);
    if (st != LM_OK)
        return st;
    uint32_t pass = pass_texels(fl, 1, count), shard = (uint32_t)fl->set.shard, shards = (uint32_t)fl->set.shards;
    checkpointing ck = {fl->set.checkpoint, 0, count,
                        {pass, lm_checkpoint_steps(count, pass, 0, 0), 0, 0, 0, NULL},
                        fl->set.checkpoint_seconds > 0.0 ? fl->set.checkpoint_seconds : LM_CHECKPOINT_DEFAULT_SECONDS,
                        lm_now(), malloc(4 * sizeof(float) * (size_t)fl->atlas->width * (size_t)fl->atlas->height)};
    if (!ck.rgba)
        return lm_fail(err, LM_ERR_NOMEM, "no memory for the bake's checkpoint");
    ck.key = lm_checkpoint_key(fl->scene, fl->atlas, &fl->set.gather, fl->texels, count,
                               lm_aim_dilated_rgba(lm_photon_stage_aim(fl->stage)));
    if (shards > 0)
        ck.r = (lm_checkpoint_range){pass, lm_checkpoint_steps(count, pass, shard, shards), 0, shard, shards, NULL};
    if (fl->set.parts) {
        st = join_parts(fl, &ck, err);
        ck.r.done = ck.r.steps;
        if (st == LM_OK)
            lm_info("%s: the gather put together from %d parts", fl->scene->path, fl->set.part_count);
    } else if (fl->set.resume) {
        lm_checkpoint_range r = {0};
        st = lm_checkpoint_read(ck.path, ck.key, fl->atlas, count, ck.rgba, &r, "bake without --resume to start again",
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
            lm_info("%s: resuming the gather at texel %u of %u from %s", fl->scene->path,
                    shards ? r.done : r.done * pass < count ? r.done * pass : count, count, ck.path);
    }
    if (st == LM_OK && (fl->set.parts || fl->set.resume))
        st = lm_iim_texture_write(fl->iim.fresh_tex, fl->atlas->width, fl->atlas->height, ck.rgba, err);
    if (st == LM_OK && fl->set.claim_pass && shards > 1)
        st = gather_claimed(fl, count, &ck, err);
    else if (st == LM_OK)
        st = gather_run(fl, ck.r, count, fl->set.checkpoint ? &ck : NULL, err);
    if (st == LM_OK && shards > 0) /* the part: kept by the caller */
        st = checkpoint_save(fl, &ck, ck.r.steps, err);
    free(ck.r.list);
    free(ck.rgba);
    return st;
}

static lm_status alloc_buffers(lm_frame_loop *fl, lm_error *err)
{
    size_t n = 3 * (size_t)fl->set.width * fl->set.height;
    fl->texels = malloc(sizeof(uint32_t) * (fl->atlas->texel_count ? fl->atlas->texel_count : 1));
    fl->image = malloc((n ? n : 1) * sizeof(float));
    fl->refreshed = malloc((size_t)fl->atlas->surface_count + 1);
    if (!fl->texels || !fl->image || !fl->refreshed)
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for the frame loop", fl->scene->path);
    return LM_OK;
}

/* The closed-form emitter light when the settings (or, on auto, the scene) call for it; the gather's
 * coverage samples when on auto: none needed with it, else as the scene's emitters need. */
static lm_status setup_emitters(lm_frame_loop *fl, lm_error *err)
{
    int closed_form = fl->set.emitter_light < 0 ? lm_emitter_light_suits(fl->scene) : fl->set.emitter_light;
    closed_form = closed_form && lm_emissive_triangle_count(fl->scene) > 0;
    if (fl->set.gather.coverage_samples == 0)
        fl->set.gather.coverage_samples =
            fl->set.gather.scheme == LM_GATHER_LAYERED ? 1 : lm_gather_coverage_for(fl->scene, closed_form);
    fl->set.emitter_light = closed_form;
    if (!closed_form || !lightmap_path(fl)) /* the gather's alone */
        return LM_OK;
    lm_status st = lm_emitter_light_init(&fl->emitters, fl->scene, fl->rt, fl->set.emitter_rays, err);
    fl->have_emitters = st == LM_OK;
    return st;
}

/* The passes that draw a frame (composite, direct light, reflections), made with the loop when it draws
 * frames, else at the first lm_frame_loop_render. */
static lm_status setup_render(lm_frame_loop *fl, lm_error *err)
{
    if (fl->direct_light)
        return LM_OK;
    lm_status st = lm_composite_create(fl->scene, fl->atlas, fl->set.gather.backface_limit, &fl->comp, err);
    if (st == LM_OK)
        st = lm_direct_create(fl->scene, fl->atlas, &fl->set.direct, &fl->direct_light, err);
    if (st == LM_OK && fl->set.reflection_size > 0)
        st = lm_reflections_create(fl->scene, fl->set.reflection_size, fl->set.reflection_faces, &fl->reflections,
                                   err);
    fl->reflect_version = fl->scene->pass_version;
    return st;
}

/* Per surface, whether its node takes indirect light (extras "indirect", lmgi_set_node_effects): the
 * scheduler gathers only those (one switched on again is regathered in full). */
static void sync_gather_switches(lm_frame_loop *fl)
{
    for (int k = 0; k < fl->surfaces->surface_count; k++) {
        int off = !lightmap_path(fl) || fl->light.unlit ||
                  !fl->scene->nodes[fl->surfaces->surfaces[k].node].settings.indirect;
        if (off != fl->iim.sched.off[k])
            lm_iim_sched_set_off(&fl->iim.sched, store_of(fl), k, off);
    }
}

/* Lights that shine: not removed or switched off. */
static uint32_t lights_on(const lm_scene *s)
{
    uint32_t n = 0;
    for (int i = 0; i < s->light_count; i++)
        n += !s->lights[i].removed && !s->lights[i].off;
    return n;
}

/* A scene without any light (no light on, no emissive triangle, no sky) has no indirect light: nothing is
 * gathered (lmgi info's "indirect: off"), and the IIM is cleared when the last light goes; the gather
 * starts again, every surface in full, when a light, an emissive material or a sky comes. Looked at each
 * frame: the lights and the sky at once, the emissive triangles when a class changed (pass_version). */
static lm_status follow_light(lm_frame_loop *fl, lm_error *err)
{
    const lm_scene *s = fl->scene;
    if (fl->light.emissive_version != s->pass_version || !fl->have_iim) {
        fl->light.emissive = lm_emissive_triangle_count(s) > 0;
        fl->light.emissive_version = s->pass_version;
    }
    uint32_t lights = lights_on(s);
    int unlit = lights == 0 && !fl->light.emissive && !s->has_sky;
    if (unlit == fl->light.unlit && fl->have_iim)
        return LM_OK;
    fl->light.unlit = unlit;
    if (unlit)
        lm_log(LM_LOG_INFO, "%s: no light (no light on, no emissive material, no sky): the gather is skipped until "
               "one comes", s->path);
    if (!fl->have_iim)
        return LM_OK;
    sync_gather_switches(fl);
    return unlit ? lm_iim_clear(&fl->iim, err) : LM_OK;
}

/* After edits that change which passes a node takes part in (lm_scene.pass_version: a material's class,
 * a node's effect switches): the gather's and the composite's surfaces, and the nodes that reflect,
 * whose maps are made again. */
static lm_status follow_pass_edits(lm_frame_loop *fl, lm_error *err)
{
    uint32_t v = fl->scene->pass_version;
    lm_status st = follow_light(fl, err);
    if (st == LM_OK && fl->switch_version != v) {
        sync_gather_switches(fl);
        if (fl->comp)
            st = lm_composite_update_coverage(fl->comp, fl->scene, fl->atlas, err);
        fl->switch_version = v;
    }
    if (st != LM_OK || fl->reflect_version == v || fl->set.reflection_size <= 0 || !fl->direct_light)
        return st;
    lm_reflections_free(fl->reflections);
    fl->reflections = NULL;
    fl->reflect_version = v;
    return lm_reflections_create(fl->scene, fl->set.reflection_size, fl->set.reflection_faces, &fl->reflections, err);
}

/* The settings' GL context made current, or one of the loop's own. */
static lm_status setup_gl(lm_frame_loop *fl, lm_error *err)
{
    if (fl->set.gl) {
        fl->gl = fl->set.gl;
        return lm_gl_make_current(fl->gl, err);
    }
    lm_status st = lm_gl_context_create(&fl->gl, err);
    fl->own_gl = st == LM_OK;
    return st;
}

/* GL context, gather, IIMs and the render passes; then every texel gathered and shown at once. */
static lm_status setup_gpu(lm_frame_loop *fl, double *t_gather, lm_error *err)
{
    lm_status st = setup_gl(fl, err);
    if (st == LM_OK)
        st = setup_emitters(fl, err);
    if (st == LM_OK)
        st = lm_gather_create(&fl->set.gather, &fl->gather, err);
    if (st == LM_OK && fl->have_emitters)
        lm_gather_set_emitter_light(fl->gather, &fl->emitters);
    if (st == LM_OK) /* the rim outside the plane traced, not extrapolated (gpu/hemicube_rim.h) */
        lm_gather_set_tracer(fl->gather, fl->rt);
    if (st == LM_OK)
        st = follow_light(fl, err); /* before the IIM: a scene without light gathers nothing */
    if (st == LM_OK && (st = lm_iim_init(&fl->iim, fl->atlas, &fl->set.iim, 1, err)) == LM_OK) {
        fl->have_iim = 1;
        sync_gather_switches(fl); /* nodes without indirect light are not gathered at all */
        fl->switch_version = fl->scene->pass_version;
    }
    if (st == LM_OK && fl->set.width > 0)
        st = setup_render(fl, err);
    double t0 = lm_now();
    fl->aim_stale = 1;
    if (st == LM_OK)
        st = first_gather(fl, err);
    fl->set.progress = NULL; /* per-frame gathers are small */
    fl->set.cancel = NULL;
    fl->set.checkpoint = NULL;
    if (st == LM_OK)
        st = lm_iim_blend(&fl->iim, 1, err);
    if (t_gather)
        *t_gather = lm_now() - t0;
    return st;
}

/* What the frame loop adds per atlas texel to what lmgi_load holds (AIM, IIM double buffer, gather
 * tables, their GL textures): about 250 bytes, measured from 66k to 1M texels (peak RSS of lmgi run). */
#define FRAME_LOOP_BYTES_PER_TEXEL 250.0

lm_status lm_frame_loop_create(const lm_world *w, const lm_frame_loop_settings *set, lm_frame_loop **out,
                               lm_photon_stage_frame *setup, double *t_setup_gather, lm_error *err)
{
    *out = NULL;
    const lm_atlas *a = w->atlas;
    lm_frame_loop *fl = calloc(1, sizeof *fl);
    if (!fl)
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for the frame loop", w->scene->path);
    fl->set = *set;
    fl->set.stage.trace = fl->set.stage.trace && fl->set.indirect;
    fl->set.stage.caustics = fl->set.caustics;
    fl->set.stage.aims = fl->set.stage.aims && lightmap_path(fl);
    fl->scene = w->scene;
    fl->surfaces = w->surfaces;
    fl->atlas = a;
    fl->rt = w->rt;
    char what[128];
    snprintf(what, sizeof what, "the lightmaps of %u texels (AIM, IIM, gather)", a->texel_count);
    lm_status st = lm_memory_plan(what, (double)a->texel_count * FRAME_LOOP_BYTES_PER_TEXEL, "a larger texel "
                                  "size (--texel-size) or fewer texels (--texels) makes it smaller", err);
    if (st == LM_OK)
        st = alloc_buffers(fl, err);
    if (st == LM_OK)
        st = lm_photon_stage_create(w, &fl->set.stage, &fl->stage, setup, err);
    if (st == LM_OK)
        st = setup_gpu(fl, t_setup_gather, err);
    if (st == LM_OK && fl->set.overlap)
        st = lm_stage_worker_start(fl->stage, &fl->worker, err);
    if (st != LM_OK) {
        lm_frame_loop_free(fl);
        return st;
    }
    *out = fl;
    return LM_OK;
}

void lm_frame_loop_free(lm_frame_loop *fl)
{
    if (!fl)
        return;
    lm_frame_loop_sync(fl, NULL);
    lm_stage_worker_stop(fl->worker);
    lm_direct_free(fl->direct_light);
    lm_composite_free(fl->comp);
    lm_reflections_free(fl->reflections);
    lm_caustic_pass_free(fl->caustic_pass);
    lm_photon_gather_free(fl->photon_gather);
    lm_photon_records_free(&fl->records);
    if (fl->have_iim)
        lm_iim_free(&fl->iim);
    lm_gather_free(fl->gather);
    if (fl->have_emitters)
        lm_emitter_light_free(&fl->emitters);
    if (fl->own_gl)
        lm_gl_context_destroy(fl->gl);
    lm_photon_stage_free(fl->stage);
    free(fl->texels);
    free(fl->image);
    free(fl->refreshed);
    free(fl);
}

/* The photon paths' records: the store's hits packed, the pages that changed sent to the GPU, and the
 * kernel radius for them. Reads the photon store: never while the stage's worker runs (the steps call it
 * before they start it). */
static lm_status photon_records(lm_frame_loop *fl, lm_frame_stats *o, lm_error *err)
{
    const lm_photon_store *ps = lm_photons_store(lm_photon_stage_photons(fl->stage));
    lm_status st = LM_OK;
    if (!fl->photon_gather) {
        lm_photon_gather_settings set = fl->set.photon_gather;
        set.kind = fl->set.indirect_path == LM_INDIRECT_HASHGRID     ? LM_PHOTON_GATHER_HASHGRID
                   : fl->set.indirect_path == LM_INDIRECT_BRUTEFORCE ? LM_PHOTON_GATHER_BRUTEFORCE
                                                                     : LM_PHOTON_GATHER_TILED;
        st = lm_photon_gather_create(&set, &fl->photon_gather, err);
    }
    int fresh = !fl->records.rec || fl->records.store_version != ps->version;
    if (st == LM_OK && fresh)
        st = lm_photon_records_update(&fl->records, ps, fl->scene, err);
    if (st == LM_OK && fresh)
        st = lm_photon_gather_set_records(fl->photon_gather, &fl->records, o ? &o->photon_gather : NULL, err);
    /* The derived radius is kept until the gathered hits change by a tenth (its square root: 5%): a radius
     * that followed every re-traced photon would change the kernel, and so the picture and the coverage
     * atlas, every frame. */
    uint32_t live = fl->records.live, was = fl->radius_live;
    int drifted = live > was + was / 10 || was > live + live / 10;
    if (st == LM_OK && (!(fl->photon_radius > 0.0f) || (fresh && drifted))) {
        fl->photon_radius = fl->set.photon_radius > 0.0f
                                ? fl->set.photon_radius
                                : lm_pixel_gather_radius(ps, fl->surfaces, LM_PIXEL_GATHER_HITS);
        fl->radius_live = live;
    }
    return st;
}

float lm_frame_loop_photon_radius(const lm_frame_loop *fl) { return photon_path(fl) ? fl->photon_radius : 0.0f; }

/* The photon paths' kernel coverage (lm_aim_kernel_coverage) for the direct pass to write beside kd: made
 * again when the radius or a node's scale (its matrix's column lengths) changed. */
static lm_status update_coverage(lm_frame_loop *fl, lm_error *err)
{
    uint64_t key = lm_hash_bytes(0x9e3779b97f4a7c15ull, &fl->photon_radius, sizeof fl->photon_radius);
    for (int i = 0; i < fl->scene->node_count; i++) {
        const float *m = fl->scene->nodes[i].world;
        float len2[3];
        for (int c = 0; c < 3; c++)
            len2[c] = m[4 * c] * m[4 * c] + m[4 * c + 1] * m[4 * c + 1] + m[4 * c + 2] * m[4 * c + 2];
        key = lm_hash_bytes(key, len2, sizeof len2);
    }
    if (key == fl->coverage_key || !(fl->photon_radius > 0.0f))
        return LM_OK;
    float *c = malloc((size_t)(fl->atlas->texel_count ? fl->atlas->texel_count : 1) * sizeof *c);
    if (!c)
        return lm_fail(err, LM_ERR_NOMEM, "no memory for the coverage of %u texels", fl->atlas->texel_count);
    lm_status st = lm_aim_kernel_coverage(lm_photon_stage_aim(fl->stage), fl->scene, fl->surfaces, fl->atlas,
                                          fl->photon_radius, c, err);
    if (st == LM_OK)
        st = lm_direct_set_coverage(fl->direct_light, c, err);
    free(c);
    fl->coverage_key = st == LM_OK ? key : 0;
    return st;
}

/* The photon paths' indirect light added to the picture lm_direct_draw drew for view: the gather runs
 * again only when its records, the view, the size, the radius or the scene (node matrices, materials,
 * effect switches) changed since its last picture; else that picture is added again. */
static lm_status draw_photon_indirect(lm_frame_loop *fl, const lm_view *view, int w, int h, lm_frame_stats *o,
                                      lm_error *err)
{
    if (!(fl->photon_radius > 0.0f)) /* no photon the gather takes: no indirect light */
        return LM_OK;
    uint64_t key = lm_scene_world_hash(fl->scene);
    key = lm_hash_bytes(key, view->view, sizeof view->view);
    key = lm_hash_bytes(key, view->proj, sizeof view->proj);
    const int size[2] = {w, h};
    key = lm_hash_bytes(key, size, sizeof size);
    key = lm_hash_bytes(key, &fl->records.store_version, sizeof fl->records.store_version);
    key = lm_hash_bytes(key, &fl->photon_radius, sizeof fl->photon_radius);
    key = lm_hash_bytes(key, &fl->scene->material_version, sizeof fl->scene->material_version);
    key = lm_hash_bytes(key, &fl->scene->pass_version, sizeof fl->scene->pass_version);
    unsigned kd = lm_direct_kd_texture(fl->direct_light, 0), gbuf = lm_direct_gbuffer_texture(fl->direct_light);
    lm_status st = LM_OK;
    if (!fl->photon_keyed || key != fl->photon_key) {
        st = lm_photon_gather_run(fl->photon_gather, view, w, h, kd, gbuf, fl->photon_radius, fl->photon_runs++,
                                  &o->photon_gather, err);
        o->photon_gathers++;
        fl->photon_key = key;
        fl->photon_keyed = st == LM_OK;
    }
    if (st == LM_OK)
        st = lm_photon_gather_composite(fl->photon_gather, lm_direct_radiance_texture(fl->direct_light), kd, gbuf, err);
    return st;
}

/* Whether the scene has caustic generators now (from the scene, which the stage's worker does not write:
 * its caustic photons may be made again on the worker meanwhile). */
static int has_generators(lm_frame_loop *fl)
{
    if (!fl->set.caustics)
        return 0;
    if (fl->generators_version != fl->scene->pass_version + 1) {
        lm_caustic_generator *g = NULL;
        lm_error err;
        int n = 1; /* out of memory: taken as there being some (a sync too many, never one too few) */
        if (lm_caustic_generators(fl->scene, &g, &n, &err) == LM_OK)
            free(g);
        fl->generators = n > 0;
        fl->generators_version = fl->scene->pass_version + 1;
    }
    return fl->generators;
}

/* The stage's caustic photons into the caustic pass when they changed since, the pass made when the first
 * ones land. Reads the stage's photons: while its worker is quiet. */
static lm_status upload_caustics(lm_frame_loop *fl, lm_error *err)
{
    const lm_caustics *c = lm_photon_stage_caustics(fl->stage);
    uint64_t version = lm_photon_stage_caustics_version(fl->stage);
    if (!c || version == fl->caustic_version || (!fl->caustic_pass && !lm_caustics_landed(c)))
        return LM_OK;
    lm_status st = fl->caustic_pass ? LM_OK : lm_caustic_pass_create(&fl->set.caustic_pass, &fl->caustic_pass, err);
    if (st == LM_OK)
        st = lm_caustic_pass_set_photons(fl->caustic_pass, lm_caustics_hits(c), lm_caustics_photon_count(c), err);
    if (st == LM_OK)
        fl->caustic_version = version;
    return st;
}

/* The step's own frame's view, its caustic photons, and on the photon paths their records, made while the
 * store is quiet (before the stage's worker starts: the frame shows the photons as the last stage left
 * them). */
static lm_status prepare_frame(lm_frame_loop *fl, lm_frame_stats *o, lm_error *err)
{
    int w = fl->set.width, h = fl->set.height;
    if (w <= 0)
        return LM_OK;
    lm_status st = upload_caustics(fl, err);
    if (st != LM_OK)
        return st;
    lm_view_for_scene(fl->scene, fl->set.camera, w, h, &fl->view);
    return photon_path(fl) ? photon_records(fl, o, err) : LM_OK;
}

/* What lights the scene besides the lightmaps, as the environment maps' dirty tracking compares it: the
 * emitters' placement and power, the materials' edits, the caustic photons. */
static uint64_t lighting_hash(const lm_frame_loop *fl)
{
    const lm_emitters *em = lm_photon_stage_emitters(fl->stage);
    uint64_t h = LM_HASH_SEED;
    for (int e = 0; e < em->count; e++) {
        const lm_emitter *x = &em->e[e];
        const float *parts[4] = {x->pos, x->dir, x->radiant, x->power};
        for (int k = 0; k < 4; k++)
            h = lm_hash_bytes(h, parts[k], 3 * sizeof(float));
    }
    h = lm_hash_bytes(h, &fl->scene->material_version, sizeof fl->scene->material_version);
    return lm_hash_bytes(h, &fl->caustic_version, sizeof fl->caustic_version);
}

/* The caustics of a picture drawn by lm_direct_draw (the step's own frame keeps its caustics apart, for
 * lm_frame_loop_read_caustics). The splat, queries and filter are skipped, the composite alone drawn
 * again, when the photons, the view and every node are as for the slot's last run: nothing it depends on
 * changed. */
static lm_status draw_caustics(lm_frame_loop *fl, lm_caustic_pass *cp, int own, const lm_view *view, int w, int h,
                               lm_frame_stats *o, lm_error *err)
{
    int slot = own ? LM_CAUSTIC_SLOT_FRAME : LM_CAUSTIC_SLOT_VIEW;
    uint64_t key = lm_scene_world_hash(fl->scene);
    key = lm_hash_bytes(key, view->view, sizeof view->view);
    key = lm_hash_bytes(key, view->proj, sizeof view->proj);
    key = lm_hash_bytes(key, &fl->caustic_version, sizeof fl->caustic_version);
    const int size[2] = {w, h};
    key = lm_hash_bytes(key, size, sizeof size);
    if (fl->caustic_key[slot] == key && fl->caustic_keyed[slot])
        return lm_caustic_pass_composite(cp, slot, fl->direct_light, &o->caustic, err);
    lm_status st = lm_caustic_pass_run(cp, slot, view, lm_direct_depth_texture(fl->direct_light, 0), w, h,
                                       fl->direct_light, &o->caustic, err);
    fl->caustic_key[slot] = key;
    fl->caustic_keyed[slot] = st == LM_OK;
    return st;
}

/* The composite's indirect term (E_IIM / pi, premultiplied over the atlas), the environment map faces
 * due this frame (when `step`), then the direct light, whose first pass adds kd x that term at each
 * visible surface's lightmap uv (shadow maps re-rendered only when stale), the caustics over its depth,
 * the reflections over it: one frame-sized read-back. `own`: the step's own frame (its caustics are kept
 * for lm_frame_loop_read_caustics), else another view. */
static lm_status render_view(lm_frame_loop *fl, const lm_view *view, int w, int h, float *rgb, int own, int step,
                             lm_frame_stats *o, lm_error *err)
{
    double t0 = lm_now();
    unsigned lit = 0;
    lm_status st = follow_pass_edits(fl, err);
    if (st == LM_OK && lightmap_path(fl))
        st = lm_composite_indirect(fl->comp, fl->iim.display_tex, &lit, err); /* else the first pass adds none */
    double t1 = lm_now();
    lm_direct_set_indirect(fl->direct_light, lit);
    if (st == LM_OK && photon_path(fl))
        st = update_coverage(fl, err);
    const lm_emitters *em = lm_photon_stage_emitters(fl->stage);
    lm_caustic_pass *caustics = fl->caustic_pass && lm_caustic_pass_photon_count(fl->caustic_pass) ? fl->caustic_pass
                                                                                                  : NULL;
    if (st == LM_OK && step) { /* the faces due this step; an extra view shows the maps as they are */
        lm_reflection_inputs in = {fl->surfaces, lightmap_path(fl) ? fl->iim.version : NULL, lighting_hash(fl),
                                   caustics};
        st = lm_reflections_update(fl->reflections, fl->direct_light, fl->scene, em, &in, &o->cube_faces, err);
    }
    double t2 = lm_now();
    if (st == LM_OK)
        st = lm_direct_draw(fl->direct_light, fl->scene, em, view, w, h, err);
    double t3 = lm_now();
    o->photon_gather.t_wait = 0.0;
    if (st == LM_OK && photon_path(fl))
        st = draw_photon_indirect(fl, view, w, h, o, err);
    double t3p = lm_now();
    if (st == LM_OK && caustics)
        st = draw_caustics(fl, caustics, own, view, w, h, o, err);
    fl->caustic_slot = own ? LM_CAUSTIC_SLOT_FRAME : LM_CAUSTIC_SLOT_VIEW;
    fl->caustic_w = w, fl->caustic_h = h;
    double t4 = lm_now();
    if (st == LM_OK)
        st = lm_reflections_draw(fl->reflections, fl->direct_light, fl->scene, view, err);
    double t5 = lm_now();
    if (st == LM_OK)
        st = lm_direct_read(fl->direct_light, rgb, err);
    o->t_composite = t1 - t0;
    /* the caustic pass and the photon gather first wait for the direct light's GPU work: that wait is
     * the direct light's */
    o->t_caustics = t4 - t3p - o->caustic.t_wait;
    o->t_gather += t3p - t3 - o->photon_gather.t_wait;
    o->t_reflections = (t2 - t1) + (t5 - t4);
    o->t_direct = (t3 - t2) + o->caustic.t_wait + o->photon_gather.t_wait + (lm_now() - t5);
    return st;
}

/* The step's frame from the settings' camera, when the loop draws frames. */
static lm_status render(lm_frame_loop *fl, lm_frame_stats *o, lm_error *err)
{
    int w = fl->set.width, h = fl->set.height;
    if (w <= 0)
        return LM_OK;
    long before = lm_direct_shadow_maps_rendered(fl->direct_light);
    lm_direct_begin_update(fl->direct_light, fl->set.direct.maps_per_update);
    lm_status st = render_view(fl, &fl->view, w, h, fl->image, 1, 1, o, err); /* fl->view: prepare_frame's */
    lm_direct_end_update(fl->direct_light);
    o->shadow_maps = (int)(lm_direct_shadow_maps_rendered(fl->direct_light) - before);
    o->shadow_maps_stale = lm_direct_stale_maps(fl->direct_light);
    return st;
}

lm_status lm_frame_loop_render(lm_frame_loop *fl, const lm_view *view, int width, int height, float *rgb,
                               lm_error *err)
{
    lm_status st = lm_gl_make_current(fl->gl, err);
    if (st == LM_OK)
        st = setup_render(fl, err);
    /* the photon gather and the caustic photons read what the worker writes. A loop that draws frames of
     * its own shows the caustic photons its last frame showed (the step's lighting); one that draws none
     * takes the newest, waiting for the work that traces them */
    int newest = fl->set.width <= 0 && (has_generators(fl) || (fl->caustic_pass &&
                                                                  lm_caustic_pass_photon_count(fl->caustic_pass)));
    if (st == LM_OK && (photon_path(fl) || newest))
        st = lm_frame_loop_sync(fl, err);
    if (st == LM_OK && newest)
        st = upload_caustics(fl, err);
    lm_frame_stats o;
    memset(&o, 0, sizeof o);
    if (st == LM_OK && photon_path(fl))
        st = photon_records(fl, &o, err);
    /* the environment maps' faces due are refreshed by the steps' own frames; without those, here */
    int refresh = fl->set.width <= 0;
    return st == LM_OK ? render_view(fl, view, width, height, rgb, 0, refresh, &o, err) : st;
}

/* This frame's texels (after adding the viewers of refreshed AIMs), and the uploads the gather needs. */
static lm_status schedule(lm_frame_loop *fl, lm_frame_stats *o, lm_error *err)
{
    widen_to_viewers(fl, store_of(fl));
    o->texels_gathered = lm_iim_sched_pick(&fl->iim.sched, store_of(fl), fl->texels);
    return o->texels_gathered > 0 ? gather_prepare(fl, err) : LM_OK;
}

/* Blend (timed into o), then render. */
static lm_status blend_and_render(lm_frame_loop *fl, lm_frame_stats *o, lm_error *err)
{
    double t0 = lm_now();
    lm_status st = lm_iim_blend(&fl->iim, 0, err);
    o->t_blend = lm_now() - t0;
    return st == LM_OK ? render(fl, o, err) : st;
}

/* Animations and the scene bounds that follow from them: written here, on the calling thread, before
 * anything that reads them (the photon thread's update among them) starts. */
static lm_status animate(lm_frame_loop *fl, float t, lm_frame_stats *o, lm_error *err)
{
    lm_status st = lm_photon_stage_animate(fl->stage, t, &o->stage, err);
    lm_scene_update_bounds(fl->scene);
    return st;
}

/* The paper's order: photon stage, then the gather over its fresh AIMs, blend, render. */
static lm_status step_in_order(lm_frame_loop *fl, float t, lm_frame_stats *o, lm_error *err)
{
    double t0 = lm_now();
    lm_status st = animate(fl, t, o, err);
    if (st == LM_OK)
        st = lm_photon_stage_update(fl->stage, &o->stage, err);
    if (o->stage.aim.surfaces_refreshed > 0)
        fl->aim_stale = 1;
    if (st == LM_OK)
        st = prepare_frame(fl, o, err);
    double t1 = lm_now();
    if (st == LM_OK)
        st = schedule(fl, o, err);
    if (st == LM_OK)
        st = gather_texels(fl, o->texels_gathered, err);
    o->t_photons = t1 - t0;
    o->t_gather = lm_now() - t1;
    return st == LM_OK ? blend_and_render(fl, o, err) : st;
}

/* Overlapped: animate, schedule and upload what the gather needs, gather, then the photon stage's
 * tracing and AIM refresh run on the worker while this thread blends and renders. The gather therefore
 * sees the AIMs and delta_i of the previous frame's stage (one frame later than in order; the IIM blends
 * over several frames anyway). Every result depends only on that fixed order, not on timing. The gather
 * runs before the worker starts: its CPU work (the emitter light's shadow rays, llvmpipe's vertex work
 * for one view per texel) is on the frame's critical path and slows down sharing the cores with the
 * stage, while the direct light, whose second rasterizer thread gains little, hides the stage as well
 * alone (docs/bench.md has the figures). */
static lm_status step_overlapped(lm_frame_loop *fl, float t, lm_frame_stats *o, lm_error *err)
{
    double t0 = lm_now();
    lm_status st = animate(fl, t, o, err);
    if (st == LM_OK)
        st = schedule(fl, o, err);
    double t1 = lm_now();
    if (st == LM_OK)
        st = prepare_frame(fl, o, err);
    if (st != LM_OK)
        return st;
    st = gather_texels(fl, o->texels_gathered, err);
    o->t_gather = lm_now() - t1;
    lm_stage_worker_begin(fl->worker, &o->stage);
    if (st == LM_OK)
        st = blend_and_render(fl, o, err);
    double t4 = lm_now();
    lm_error worker_err;
    lm_status ws = lm_stage_worker_end(fl->worker, &worker_err);
    if (ws != LM_OK && st == LM_OK) {
        st = ws;
        if (err)
            *err = worker_err;
    }
    if (o->stage.aim.surfaces_refreshed > 0)
        fl->aim_stale = 1;
    o->t_photons = (t1 - t0) + (lm_now() - t4); /* what the frame spent on or waiting for the stage */
    return st;
}

/* Waits for the stage's job a detached step left running; `done` (may be NULL) gets its counts, or, when
 * a sync joined it before (lm_frame_loop_sync), that job's counts, which the step reports. */
static lm_status join_stage(lm_frame_loop *fl, lm_photon_stage_frame *done, lm_error *err)
{
    if (!fl->pending_busy) {
        if (done && fl->pending_joined)
            *done = fl->pending;
        fl->pending_joined = fl->pending_joined && !done;
        return LM_OK;
    }
    lm_status st = lm_stage_worker_end(fl->worker, err);
    fl->pending_busy = 0;
    fl->pending_joined = !done;
    if (fl->pending.aim.surfaces_refreshed > 0)
        fl->aim_stale = 1;
    if (done)
        *done = fl->pending;
    return st;
}

lm_status lm_frame_loop_sync(lm_frame_loop *fl, lm_error *err) { return join_stage(fl, NULL, err); }

/* Detached (overlap without a frame of its own: a game draws between steps): the stage's job begun by
 * the last step is joined first, then animate, schedule, gather and blend as overlapped, and the next
 * job begins last and runs until the next step, the caller's own frame hiding it. The gather sees the
 * same AIMs and delta_i as overlapped (the previous step's stage), so the lightmaps are the same. */
static lm_status step_detached(lm_frame_loop *fl, float t, lm_frame_stats *o, lm_error *err)
{
    double t0 = lm_now();
    lm_photon_stage_frame done;
    memset(&done, 0, sizeof done);
    lm_status st = join_stage(fl, &done, err);
    if (st == LM_OK)
        st = animate(fl, t, o, err);
    /* the counts and times of the stage's work that finished in this step (begun by the last one) */
    o->stage.photons = done.photons;
    o->stage.aim = done.aim;
    o->stage.caustics = done.caustics;
    o->stage.t_photons = done.t_photons;
    o->stage.t_aim = done.t_aim;
    o->stage.t_caustics = done.t_caustics;
    if (st == LM_OK)
        st = schedule(fl, o, err);
    double t1 = lm_now();
    o->t_photons = t1 - t0;
    if (st == LM_OK)
        st = gather_texels(fl, o->texels_gathered, err);
    o->t_gather = lm_now() - t1;
    if (st == LM_OK)
        st = blend_and_render(fl, o, err); /* no frame: the blend alone */
    if (st == LM_OK) {
        fl->pending = o->stage;
        fl->pending_busy = 1;
        lm_stage_worker_begin(fl->worker, &fl->pending);
    }
    return st;
}

lm_status lm_frame_loop_step(lm_frame_loop *fl, float t, lm_frame_stats *out, lm_error *err)
{
    lm_frame_stats o;
    memset(&o, 0, sizeof o);
    double t0 = lm_now();
    lm_status st = lm_gl_make_current(fl->gl, err);
    if (st == LM_OK)
        st = follow_pass_edits(fl, err);
    if (st == LM_OK)
        st = !fl->worker ? step_in_order(fl, t, &o, err)
             : fl->set.width > 0 ? step_overlapped(fl, t, &o, err) : step_detached(fl, t, &o, err);
    o.t_total = lm_now() - t0;
    if (out)
        *out = o;
    return st;
}

/* The bake's gather reports through the loop's progress hook as a fraction of the whole bake. */
typedef struct {
    lm_bake_progress fn;
    void *user;
} bake_watch;

static void bake_gather_progress(void *user, uint32_t done, uint32_t total)
{
    const bake_watch *w = user;
    w->fn(w->user, 0.3 + 0.7 * (double)done / (total ? total : 1), "gather");
}

/* Schedules every texel of every surface whose light changed (the whole atlas as the budget), gathers
 * them a pass at a time and commits them at once. On a cancel the scheduled surfaces get their delta_i
 * back and stay uncommitted, so what shows is the last complete state and a later bake or step redoes
 * them. */
static lm_status bake_gather(lm_frame_loop *fl, lm_bake_progress progress, void *user, const volatile int *cancel,
                             lm_bake_stats *out, lm_error *err)
{
    lm_photon_store *ps = store_of(fl);
    int S = fl->iim.sched.surface_count;
    double *saved = malloc(sizeof *saved * (size_t)(S ? S : 1));
    if (!saved)
        return lm_fail(err, LM_ERR_NOMEM, "%s: no memory for the bake", fl->scene->path);
    for (int s = 0; s < S; s++)
        saved[s] = ps->surfaces[s].delta_i;
    uint32_t n = lm_iim_sched_pick_up_to(&fl->iim.sched, ps, fl->atlas->texel_count, fl->texels);
    bake_watch w = {progress, user};
    fl->set.progress = progress ? bake_gather_progress : NULL;
    fl->set.progress_user = &w;
    fl->set.cancel = cancel;
    lm_status st = gather(fl, n, err);
    fl->set.progress = NULL;
    fl->set.cancel = NULL;
    if (st != LM_OK) {
        for (int s = 0; s < S; s++)
            if (fl->iim.sched.commit[s])
                fl->iim.sched.commit[s] = 0, ps->surfaces[s].delta_i = saved[s];
    } else {
        uint32_t before = 0, after = 0;
        for (int s = 0; s < S; s++)
            before += fl->iim.version[s];
        st = lm_iim_blend(&fl->iim, 1, err);
        for (int s = 0; s < S; s++)
            after += fl->iim.version[s];
        out->texels_gathered = n;
        out->surfaces_changed = (int)(after - before);
    }
    free(saved);
    return st;
}

lm_status lm_frame_loop_bake(lm_frame_loop *fl, float t, lm_bake_progress progress, void *user,
                             const volatile int *cancel, lm_bake_stats *out, lm_error *err)
{
    memset(out, 0, sizeof *out);
    lm_status st = lm_frame_loop_sync(fl, err);
    if (st == LM_OK)
        st = lm_gl_make_current(fl->gl, err);
    if (st == LM_OK)
        st = follow_pass_edits(fl, err);
    if (st != LM_OK)
        return st;
    if (progress)
        progress(user, 0.0, "photons");
    double t0 = lm_now();
    lm_photon_stage_frame f;
    st = lm_photon_stage_converge(fl->stage, t, &f, err);
    lm_scene_update_bounds(fl->scene);
    out->photons_traced = f.photons.group_photons;
    out->photons_changed = f.photons.photons_updated;
    out->aim_surfaces_refreshed = f.aim.surfaces_refreshed;
    if (f.aim.surfaces_refreshed > 0)
        fl->aim_stale = 1;
    if (st == LM_OK) /* before a cancel can stop the bake: a later one must still regather them */
        out->surfaces_seeing = widen_to_viewers(fl, store_of(fl));
    double t1 = lm_now();
    out->t_photons = t1 - t0;
    if (st == LM_OK && cancel && *cancel)
        st = lm_fail(err, LM_ERR_CANCELLED, "%s: cancelled after the photons", fl->scene->path);
    if (st == LM_OK) {
        if (progress)
            progress(user, 0.3, "gather");
        st = bake_gather(fl, progress, user, cancel, out, err);
    }
    out->t_gather = lm_now() - t1;
    if (st == LM_OK && progress)
        progress(user, 1.0, "done");
    return st;
}

const float *lm_frame_loop_image(const lm_frame_loop *fl) { return fl->image; }
const uint32_t *lm_frame_loop_surface_versions(const lm_frame_loop *fl) { return fl->iim.version; }

void lm_frame_loop_set_texels_per_frame(lm_frame_loop *fl, int texels)
{
    fl->iim.sched.texels_per_frame = texels > 0 ? texels : 0;
}
const lm_photon_stage *lm_frame_loop_stage(const lm_frame_loop *fl) { return fl->stage; }
const lm_frame_loop_settings *lm_frame_loop_get_settings(const lm_frame_loop *fl) { return &fl->set; }
const lm_view *lm_frame_loop_view(const lm_frame_loop *fl) { return &fl->view; }

lm_iim *lm_frame_loop_iim(lm_frame_loop *fl) { return &fl->iim; }

lm_status lm_frame_loop_read_iim_window(const lm_frame_loop *fl, const int win[4], float **rgba, lm_error *err)
{
    size_t n = 4 * (size_t)win[2] * win[3];
    *rgba = NULL;
    lm_status st = lm_gl_make_current(fl->gl, err);
    if (st != LM_OK)
        return st;
    *rgba = malloc(n * sizeof(float));
    if (!*rgba)
        return lm_fail(err, LM_ERR_NOMEM, "no memory for the IIM read-back");
    st = lm_iim_texture_read_window(fl->iim.display_tex, win, *rgba, err);
    if (st != LM_OK) {
        free(*rgba);
        *rgba = NULL;
    }
    return st;
}

lm_status lm_frame_loop_read_iim(const lm_frame_loop *fl, float **rgba, lm_error *err)
{
    const int whole[4] = {0, 0, fl->atlas->width, fl->atlas->height};
    return lm_frame_loop_read_iim_window(fl, whole, rgba, err);
}

lm_status lm_frame_loop_iim_error(lm_frame_loop *fl, const float *shown, float *error, lm_error *err)
{
    const lm_atlas *a = fl->atlas;
    size_t n = (size_t)a->width * a->height;
    float *fresh = malloc(4 * n * sizeof *fresh);
    double *pending = calloc((size_t)(a->surface_count > 0 ? a->surface_count : 1), sizeof *pending);
    lm_status st = fresh && pending ? lm_frame_loop_sync(fl, err) : lm_fail(err, LM_ERR_NOMEM, "no memory for the error atlas");
    if (st == LM_OK)
        st = lm_iim_texture_read(fl->iim.fresh_tex, a->width, a->height, fresh, err);
    if (st == LM_OK) {
        const lm_photon_store *ps = lm_photons_store(lm_photon_stage_photons(fl->stage));
        for (int s = 0; s < a->surface_count; s++) {
            double e = lm_photon_store_iim_energy(ps, s), d = ps->surfaces[s].delta_i;
            pending[s] = !(d > 0.0) ? 0.0 : e > 0.0 && isfinite(d / e) ? d / e : 1.0;
        }
        float limit = fl->set.gather.backface_limit;
        double sum = 0.0;
        uint32_t valid = 0;
        for (uint32_t i = 0; i < a->texel_count; i++) {
            const float *p = shown + 4 * ((size_t)a->texels[i].y * a->width + a->texels[i].x);
            if (!(p[3] > limit))
                sum += lm_luminance(p), valid++;
        }
        double floor = 0.01 * (valid ? sum / valid : 0.0) + 1e-30;
        memset(error, 0, n * sizeof *error);
        for (uint32_t i = 0; i < a->texel_count; i++) {
            size_t at = (size_t)a->texels[i].y * a->width + a->texels[i].x;
            double f = lm_luminance(fresh + 4 * at), blend = fabs(f - lm_luminance(shown + 4 * at)) / fmax(fabs(f), floor);
            int k = a->texels[i].surface;
            double v = fl->iim.sched.off[k] ? 0.0 : fmax(blend, pending[k]); /* off: nothing to show */
            error[at] = isfinite(v) && v < 1e30 ? (float)v : 1.0f; /* past what can be said: all of it stale */
        }
    }
    free(fresh);
    free(pending);
    return st;
}

lm_status lm_frame_loop_accuracy(lm_frame_loop *fl, const float *shown, float *out, lm_error *err)
{
    const lm_atlas *a = fl->atlas;
    lm_status st = lm_frame_loop_sync(fl, err); /* the AIM and its error are the photon work's */
    const lm_aim *aim = lm_photon_stage_aim(fl->stage);
    if (st == LM_OK && !aim->error)
        st = lm_fail(err, LM_ERR_INVALID, "the error estimate needs the AIMs' own (stage.aim.error_estimate)");
    float *source = st == LM_OK ? malloc(4 * (size_t)a->width * a->height * sizeof *source) : NULL;
    if (st == LM_OK && !source)
        st = lm_fail(err, LM_ERR_NOMEM, "no memory for the error estimate");
    if (st == LM_OK) {
        lm_gather_error_source(a, aim->rgb, aim->error, source);
        lm_gather_error(&fl->set.gather, fl->scene, a, fl->rt, source, aim->error, aim->set.kernel, shown,
                        LM_GATHER_ERROR_RAYS, out);
    }
    free(source);
    return st;
}

void lm_frame_loop_caustics_size(const lm_frame_loop *fl, int *width, int *height)
{
    *width = fl->caustic_w;
    *height = fl->caustic_h;
}

lm_status lm_frame_loop_read_caustics(lm_frame_loop *fl, float *rgb, lm_error *err)
{
    size_t n = 3 * (size_t)fl->caustic_w * (size_t)fl->caustic_h;
    lm_status st = lm_gl_make_current(fl->gl, err);
    if (st != LM_OK)
        return st;
    if (!fl->caustic_pass || !lm_caustic_pass_photon_count(fl->caustic_pass)) { /* none drawn: none */
        memset(rgb, 0, n * sizeof *rgb);
        return LM_OK;
    }
    return lm_caustic_pass_read_irradiance(fl->caustic_pass, fl->caustic_slot, rgb, err);
}
