/* Inside the photon stage (photons.h), shared by photons.c, photon_trace.c and photon_paths.c. */
#ifndef LM_PHOTONS_INTERNAL_H
/* A photon ends after this many mirror or glass vertices in a row: light caught by total internal
 * reflection in a glass ball never leaves it (the angle of incidence is the same at every bounce), and a
 * lamp placed inside one sent each photon through all max_bounces vertices (900 a photon, 16 groups in
 * 0.9 s instead of 10 ms). Partial reflection lets out at least 4% a bounce, so a run this long of light
 * that could still leave carries less than 1e-40 of it. */
#define PH_SPECULAR_RUN 64u
#define LM_PHOTONS_INTERNAL_H
#define PH_EMIT_DIMS 4u /* QMC dimensions of a photon's emission (ph_group.emit_u) */

#include "photons.h"

/* A group's photons m = 0..M-1 are emitter photons j = index + m G, ids first_id + m G. Their paths
 * lie back to back in one slab: photon m's vertices are verts[offsets[m] .. offsets[m + 1]). */
typedef struct {
    int emitter;
    uint32_t index, photons, first_id;
    uint32_t rr_next;          /* next photon to check, round robin */
    int invalid;               /* queued for re-trace */
    uint32_t invalidations, retraces; /* counters for reports (lm_photon_group_info) */
    uint32_t *offsets;         /* photons + 1 */
    float *emit_u;             /* photons x 4: photon m's emission numbers (QMC dims 0-3), fixed for
                                * its life, so a re-trace does not recompute them */
    lm_path_vertex *verts;
    uint32_t vert_cap;
} ph_group;

/* A freshly traced path vertex, before it is compared and stored. */
typedef struct {
    int32_t node;
    uint32_t tri;
    int32_t surface;           /* -1: nothing stored here (specular, or no surface) */
    uint16_t bounce;
    uint8_t caustic;           /* every vertex before it was mirror or glass (L S+ D: lm_hit.caustic) */
    float pos[3], local[3], dir[3], flux[3];
    float travelled;           /* lm_hit.travelled */
} ph_vertex;

/* Per-thread growable vertex buffer. */
typedef struct {
    ph_vertex *v;
    size_t len, cap;
} ph_buffer;

/* One photon to trace and where its vertices landed. */
typedef struct {
    uint32_t group, m;
    uint32_t buffer;           /* thread buffer that holds its vertices */
    uint32_t first, count;
    uint32_t rays;             /* rays cast for it (a final miss included) */
    uint32_t stored;           /* of its vertices, those that store a hit */
} ph_job;

/* On a cache line of its own: the calling thread fills one batch (count++ per photon) while the
 * team reads the other's jobs and buffers. */
typedef struct {
    _Alignas(64) ph_job *jobs;
    uint32_t count, cap;
    ph_buffer *buffers;
    int buffer_count;
    uint64_t rays;             /* rays cast by the last ph_trace_batch */
    /* A trace shared among processes (photon_split.c): with shares > 1, ph_trace_batch traces only the
     * jobs i whose first_photon + i is share modulo shares, and leaves the others empty for the exchange
     * to fill. shares 0 or 1: every job. */
    uint32_t share, shares;
    uint64_t first_photon;
} ph_batch;

struct lm_photons {
    const lm_scene *scene;
    const lm_surfaces *surfaces;
    const lm_rt *rt;
    const lm_emitters *em;
    lm_photon_settings set;
    uint32_t frame_groups;     /* lm_photons_limit_groups's (0: set.group_budget) */
    uint32_t box_groups;       /* the groups' worth of photons lm_photons_retrace_boxes traced since the last
                                * frame: a time budget's groups (frame_groups) pay for them */
    float epsilon;             /* resolved settings.epsilon */
    int exact;                 /* while lm_photons_trace_all_exact runs: a path is unchanged only when every
                                * number of it and of its hits is the same to the bit (ph_path_changed) */
    float ray_offset;          /* origin offset along the normal when leaving a surface */
    uint32_t G, emitter_count, group_count, photon_count;
    uint32_t *emitter_first;   /* first photon id of each emitter, emitter_count + 1 entries */
    double per_luminance;      /* photons per unit of emitter weight at creation (lights added later) */
    double weight_floor;       /* the least weight of a lit emitter (emitter_weight), fixed at creation */
    ph_group *groups;          /* emitter e's group g is groups[e G + g] */
    uint32_t *queue;           /* invalid groups, FIFO ring of group_count slots */
    uint32_t queue_head, queue_len;
    /* The store and live_hits change with every applied hit while the other threads trace and read
     * the fields around them: each on cache lines of its own (they shared one with halton_base, read
     * for every QMC number, and the tracing threads kept losing it). */
    _Alignas(64) lm_photon_store store;
    _Alignas(64) uint32_t live_hits;
    _Alignas(64) uint64_t halton_base; /* seed x photon_count: the seed's stretch of the sequence */
    ph_batch batches[2];       /* a re-trace traces one while the other's results are applied */
    /* Area emitters' triangles placed once per traced batch (lm_emitter_place): emitter e's are
     * emit_tris[emit_tri_first[e] ..]. emit_placed is emit_tris while a batch is traced with them,
     * NULL when the batch is too small to be worth it (each photon then places its own triangle). */
    uint32_t *emit_tri_first;  /* emitter_count + 1 */
    lm_emit_tri *emit_tris;
    const lm_emit_tri *emit_placed;
    /* Scratch for rebuilding one group's slab (ph_group_apply) and for lists of groups. */
    lm_path_vertex *tmp_verts;
    uint32_t tmp_cap, max_group_photons;
    uint32_t *tmp_offsets;     /* max_group_photons + 1 */
    uint8_t *tmp_changed;      /* max_group_photons */
    uint32_t *tmp_groups;      /* group_count */
    lm_photon_split split;     /* shares 0 or 1: the process traces every photon itself */
};

/* photon_trace.c: the 4 emission numbers of photon id (QMC dims 0-3), as ph_group.emit_u keeps them.
 * The tracer reads the QMC tables unchecked: lm_qmc_init must have run (lm_photons_create's setup). */
void ph_emission_samples(const lm_photons *ph, uint32_t id, float u[4]);
/* Traces job j's photon (group, m), appends its vertices to buf and fills j's count,
 * rays and stored. Returns 0 when memory ran out. Reads only ph's settings, photon numbering, scene,
 * BVH and emitters (never what applying writes): safe from several threads, and beside an apply. */
int ph_trace_photon(const lm_photons *ph, ph_job *j, ph_buffer *buf);
/* Traces every job of batch b in parallel (OpenMP; on the calling thread for fewer than 1024 jobs).
 * Applies nothing (the round robin compares the paths itself). Fails only when memory runs out. */
lm_status ph_trace_batch(lm_photons *ph, ph_batch *b, lm_error *err);
/* Traces and applies the whole groups list[0 .. n) in batches of whole groups (ph_fill_batch), all
 * in one parallel region: batch k + 1 is traced by the team while the master first applies batch k,
 * batches applied in list order (the store changes exactly as if each were traced and applied in
 * turn). One region instead of one per batch: waking a thread team per batch cost milliseconds on a
 * loaded machine. */
lm_status ph_trace_groups(lm_photons *ph, const uint32_t *list, uint32_t n, lm_photon_frame_stats *st,
                          lm_error *err);
void ph_batch_clear(ph_batch *b);
int ph_batch_push(ph_batch *b, uint32_t group, uint32_t m);
/* ph_batch_push of the group's photons m = 0 .. photons - 1, growing the list once (the calling
 * thread fills a re-trace's batches on its own, between applying and tracing). */
int ph_batch_push_group(ph_batch *b, uint32_t group, uint32_t photons);
void ph_batch_free(ph_batch *b);

/* photon_split.c: ph_trace_groups for a trace shared among processes (lm_photons_set_split): each
 * batch's photons dealt out in turn, each process tracing its own, the paths exchanged and applied by
 * every process in batch order, so every process's store is the one-process trace's. */
lm_status ph_trace_groups_split(lm_photons *ph, const uint32_t *list, uint32_t n, lm_photon_frame_stats *st,
                                lm_error *err);

/* photons.c: fills b with whole groups from list[*i ...] (at least one group, up to a batch's photon
 * bound); empty when the list is used up. Counts the groups' re-traces in g and st. */
lm_status ph_fill_batch(lm_photons *ph, ph_batch *b, const uint32_t *list, uint32_t n, uint32_t *i,
                        lm_photon_frame_stats *st, lm_error *err);

/* photon_paths.c: path storage, comparison and store updates. */
const ph_vertex *ph_job_vertices(const ph_batch *b, const ph_job *j);
/* 1 if the traced path differs from photon m's stored one (photons.h: (node, tri) sequence, a vertex
 * that moved more than epsilon in world or node-local space, or flux changed; with ph->exact, any bit of
 * a vertex or a hit). */
int ph_path_changed(const lm_photons *ph, const ph_group *g, uint32_t m, const ph_vertex *v, uint32_t n);
/* 1 if photon m's stored path, from its emission point (as the emitter places it now) through its
 * vertices, crosses one of the n boxes (6 floats each: min x, y, z, max x, y, z). The part after the last
 * vertex (a photon that left the scene, or was absorbed) is not stored and not tested. */
int ph_path_meets_boxes(const lm_photons *ph, const ph_group *g, uint32_t m, const float *boxes, int n);
/* Rebuilds a group's slab from the jobs [first, first + M) of batch b (one per photon, in order):
 * photons whose path changed get their old hits removed and new ones added; the others keep theirs. */
lm_status ph_group_apply(lm_photons *ph, ph_group *g, const ph_batch *b, const ph_job *jobs,
                         lm_photon_frame_stats *st, lm_error *err);
/* ph_group_apply for some of a group's photons: jobs[0 .. n), in increasing m, each re-traced; the changed
 * ones get their old hits removed and new ones added, the group's other photons keep their paths. */
lm_status ph_group_apply_some(lm_photons *ph, ph_group *g, const ph_batch *b, const ph_job *jobs, uint32_t n,
                              lm_photon_frame_stats *st, lm_error *err);
/* ph_group_apply for every group of a traced batch of whole groups, in batch order. */
lm_status ph_apply_batch(lm_photons *ph, const ph_batch *b, lm_photon_frame_stats *st, lm_error *err);
void ph_group_free(ph_group *g);
size_t ph_group_bytes(const ph_group *g);

#endif
