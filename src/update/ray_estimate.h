/* A waiting texel's first estimate from a few rays (issue 32, items 3 and 6; docs/gather.md, "Rays for
 * the texels that wait"): what its hemisphere sees now against what it saw at its last gather, through
 * the same rays.
 *
 * A texel regathered ahead of its surface (photonmap/texel_change.h) waits its turn while nodes keep
 * moving: in the animated Cornell box at `run`'s 1,800 texels nearly every texel waits, and 20 gathers an
 * update reach each about once in 90 updates. The neighbours' loans (iim.h, progressive refinement) do not
 * reach a texel gathered while a cube stood beside it: none of its neighbours changed after it. Here each
 * gather also keeps its texel's small ray gather over the same AIM and scene the hemicube saw (its base,
 * E_0), and each update brings some of the waiting texels' ray gathers up to date (E_t); the texel then
 * shows its gathered value plus
 *
 *     E_t - E_0   (rgb; the same K rays, the same seed: lm_gather_texel_seed)
 *
 * the change of what it sees since its gather. Both sums meet the same points where nothing moved, so the
 * difference holds only what changed: the moved nodes where their rays now meet them or no longer do, and
 * the AIMs' new light; its noise is the changed part's alone. Nothing is added where nothing changed.
 *
 * The ray gather is the rays scheme's estimator (photonmap/hemicube_rim.h with enlargement 0), K strata
 * over the whole hemisphere, each ray's AIM averaged over its footprint, emitters' emission where met (or,
 * where the gather takes it in closed form, its emitter light: lm_ray_estimate_emitters), the sky's mean
 * where nothing is; it reads the whole dilated AIM (its direct part included, as a hemicube
 * does), so bases and updates stay alike whatever the gather scheme.
 *
 * Which texels: those the caller lists as waiting, at most `budget` an update, a third by each of three
 * keys in turn: their estimated change (texel_change.h) times the updates since each was last brought up
 * to date, so that a moving cube's own faces, whose light changes every update, go every update or two;
 * how far each estimate is likely off by now as a share of its light (the rate its rays' change went at
 * between its last two estimates, over its light or LM_RAY_ESTIMATE_DIM of the waiting texels' mean, the
 * largest of its own and its surface's texels' within LM_RAY_ESTIMATE_REACH, times the updates since; or
 * where none has a rate, its estimated change over its light), so that a texel a shadow is sweeping onto
 * goes before one whose light holds; then those updates alone, so that the rest go in turn. (In
 * turns alone, each of the animated box's 1,800 waiting texels once in 6 updates at 320 an update, the
 * cube's faces trailed their light by 6 updates; by change times wait alone, the floor's texels, whose
 * summed change is a hundredth of the cube's faces', waited behind them: over 90 updates a floor block
 * stayed 10% off for 24, against 18 with the halves. Over 120 updates, seeds 0 to 4, halves of the first
 * and third keys: the trail 9 / 9 / 12 / 9 / 12 updates, the moving nodes' own 18 / 12 / 9 / 15 / 9;
 * thirds, each texel's own rate alone: 9 / 6 / 15 / 6 / 9 and 9 / 6 / 6 / 6 / 9; with its neighbours' rates:
 * 9 / 6 / 9 / 6 / 9 and 6 / 6 / 3 / 6 / 6; halves of the second and third, own rates: 9 / 12 / 15 / 9 / 12
 * and 9 / 9 / 3 / 9 / 6.) A texel with no base (never gathered since the estimator began) is skipped.
 *
 * K rays misjudge some texels' change badly and for long: what a texel sees through them is fixed until its
 * next gather, so their error is too. In the animated box, a floor texel in the corner took its base while
 * the mirror sphere stood near: 36 rays read 7.98 where 1,600 read 5.30 (the gather 5.6), and over the next
 * 70 updates, the sphere gone, its estimate showed a quarter of its light's 54% rise. Over 12 seeds 6 x 6
 * strata read 6.0 +- 1.4 there and 12 x 12 6.1 +- 0.6, or 5.75 +- 0.5 with each footprint read at its ray
 * alone: noise, and a bias of the coarse strata. So each base is also taken with LM_RAY_ESTIMATE_FINE x K
 * rays, and a texel whose two differ by more than LM_RAY_ESTIMATE_SPLIT of its light takes those, base and
 * updates alike, until its next gather (`fine`): about a third of the animated box's bases, through the
 * caustics its mirror and glass balls sweep over the walls; few where the light is smooth. The judge is
 * made at the gather only, and a node that comes later is what K rays misjudge most: held with the mirror
 * sphere by that corner, 7 of 8 texels on K rays read it 12-59% too bright after every AIM caught up
 * (docs/tradeoff.md, "Nodes that keep moving", the whole loop). So a texel that a moving node stands beside
 * (the form factor of its bounding sphere over LM_RAY_ESTIMATE_NEAR: lm_texel_change_node_near) takes the
 * near rays, LM_RAY_ESTIMATE_NEAR_FINE x K read each at its own hit (a footprint of one: hemicube_rim.h),
 * at its gather, or from the update the node comes on, against the near rays' base that every gather also
 * takes while nodes move (near_base); its rate starts again then. The near rays stay until its next gather.
 * One gathered while nothing moved (a node made dynamic since: lmgi_set_node_dynamic) has no near base, and
 * keeps its rays until then.
 *
 * Layout: per texel its base and its near rays' base (rgb each), three flags (a base; which rays; a rate),
 * the update it was last brought up to date and the rate its change went at; the deltas an update computes,
 * by texel index, for the caller to show (what is shown is the IIM's, iim.h, which a light edit scales
 * there). Memory: 50 bytes a texel, and 20 a waiting texel while choosing.
 * Cost: (1 + LM_RAY_ESTIMATE_FINE) K rays and footprints of AIM lookups per texel gathered (its base), and
 * while a node moves LM_RAY_ESTIMATE_NEAR_FINE x K rays and lookups more; K, LM_RAY_ESTIMATE_FINE x K or
 * the near rays per texel brought up to date, and a pass over the nodes, on every OpenMP thread; choosing them
 * O(waiting x (2 LM_RAY_ESTIMATE_REACH + 1)^2 + waiting log budget) (core/top_k.h). Deterministic (each
 * texel's rays are seeded by its index). Not thread-safe; the scene and AIM must not change meanwhile.
 * Errors: none but memory at init. */
#ifndef LM_RAY_ESTIMATE_H
#define LM_RAY_ESTIMATE_H

#include <stdint.h>

#include "../gpu/gather/hemicube.h"
#include "../photonmap/texel_change.h"
#include "light_scale.h"

/* Rays a texel's two gathers take by default: 6 x 6 strata. At 16 a texel's change mottles (one move in a
 * held drag: the worst step between neighbours 0.52 of the mean texel against 0.44, and the animated box's
 * trail 24 updates against 12); 64 cost more and did no better (0.46). */
#define LM_RAY_ESTIMATE_RAYS 36

/* Waiting texels brought up to date an update for each texel the update gathers. */
#define LM_RAY_ESTIMATE_PER_TEXEL 16

/* The least light a texel's expected staleness is a share of, as a share of the waiting texels' mean: a
 * black texel's small change is not its whole light. */
#define LM_RAY_ESTIMATE_DIM 0.1
/* Texels either side, on the same surface, whose rate a texel's expected staleness takes where it is larger
 * than its own (header). Over 120 updates of the animated box, seeds 0 to 4: blocks over 10% 0.72 / 0.57 /
 * 0.50 / 0.60 / 0.57 with its own rate alone, 0.57 / 0.45 / 0.38 / 0.50 / 0.42 within 1; the trail's longest
 * run 9 / 6 / 15 / 6 / 9 and 9 / 6 / 9 / 6 / 9. Within 2 did worse (in a probe, 0.55 and 15 at seed 2). */
#define LM_RAY_ESTIMATE_REACH 1

/* A texel whose base through K rays differs from one through LM_RAY_ESTIMATE_FINE x K by more than
 * LM_RAY_ESTIMATE_SPLIT of its light takes the latter (header). Over 120 updates of the animated box, three
 * seeds, 4 x 4 blocks over 10% off a fresh bake 1.82 / 1.30 / 1.82 -> 0.97 / 0.97 / 0.95 at a split of
 * 0.1 (a third of the bases fine; `lmgi run`'s gather, which holds the estimates, 13.5 -> 23.2 ms an update,
 * the update 67 -> 74 ms); 0.2 (a sixth fine) -> 1.05 on the first seed. Two K-ray bases turned apart as
 * the judge, which sees noise but not the strata's bias: 1.38 / 1.23 / 1.20. */
#define LM_RAY_ESTIMATE_FINE 4
#define LM_RAY_ESTIMATE_SPLIT 0.1

/* A texel that a moving node's bounding sphere fills more than LM_RAY_ESTIMATE_NEAR of (its form factor)
 * takes LM_RAY_ESTIMATE_NEAR_FINE x K rays, each read at its hit (header). Over the animated box's whole loop
 * (240 updates, photon seeds 0 to 4): the trail 18 / 6 / 15 / 6 / 9 updates -> 6 / 9 / 12 / 9 / 6, blocks
 * over 10% 0.47 / 0.36 / 0.61 / 0.35 / 0.34 -> 0.12 / 0.23 / 0.23 / 0.20 / 0.21; `lmgi run`'s gather 23 ->
 * 31 ms an update. At 16 x K: 6 / 6 / 15 / 6 / 6, and 39 ms. With 4 x 4 footprints, as the K rays read
 * theirs: 16 x K at a bar of 0.05 took 84 ms. Bars of 0.1 and 0.15 left seed 0 at 18, one of 0.02 cost more
 * and did no better (seed 2: 12). */
#define LM_RAY_ESTIMATE_NEAR 0.05
#define LM_RAY_ESTIMATE_NEAR_FINE 9
#define LM_RAY_ESTIMATE_NEAR_RAYS 2 /* fine: the near rays */
#define LM_RAY_ESTIMATE_NEW_NEAR 3  /* fine: the near rays, taken at this update (no rate from it) */
#define LM_RAY_ESTIMATE_NEAR_BASED 2 /* has: the near rays' base too (taken while some node moved) */

typedef struct {
    uint32_t texel_count;
    int K;          /* rays a texel */
    float *base;    /* per texel, 3: the ray gather at its last gather */
    uint8_t *has;   /* per texel: base holds one (1), and near_base too (LM_RAY_ESTIMATE_NEAR_BASED) */
    float *delta;   /* per texel, 3: E_t - E_0, written by lm_ray_estimate_update for the texels it lists */
    uint32_t *stamp; /* per texel: the update its base or delta was last computed */
    uint32_t frame;  /* updates so far (lm_ray_estimate_update calls) */
    uint8_t *fine;   /* per texel: its base and updates take K rays (0), LM_RAY_ESTIMATE_FINE x K (1), or
                      * LM_RAY_ESTIMATE_NEAR_FINE x K (LM_RAY_ESTIMATE_NEAR_RAYS) (header) */
    float *near_base; /* per texel, 3: its near rays' gather at its last gather while nodes moved (header) */
    float *rate;     /* per texel: |its change's change| an update (channels summed), at its last update */
    uint8_t *rated;  /* per texel: rate holds one (brought up to date since its gather or a light's edit) */
    const lm_gather *emitted; /* NULL: the rays add the emission of the emitters they meet; else the gather
                               * whose closed-form emitter light a texel's two gathers take instead
                               * (lm_ray_estimate_emitters) */
    const lm_texel_change *nodes; /* NULL: no node is near any texel; else where the nodes are (header) */
} lm_ray_estimate;

/* K rays a texel (rounded down to a square by the rim); no base yet. */
lm_status lm_ray_estimate_init(lm_ray_estimate *re, uint32_t texel_count, int K, lm_error *err);
void lm_ray_estimate_free(lm_ray_estimate *re);
/* Texels[0 .. n) are gathered over aim (the dilated AIM, whole) and the scene as they are: their bases. */
void lm_ray_estimate_gathered(lm_ray_estimate *re, const lm_light_scale_world *w, const float *aim,
                              const uint32_t *texels, uint32_t n);
/* Of the n waiting texels (change: each one's estimated change, texel_change.h, in units of change_unit
 * of the rays' light, the channels summed), at most budget with a base, chosen as the header says, brought
 * up to date over aim: their indices into out (room for budget) and their deltas in re->delta. Returns how
 * many. */
uint32_t lm_ray_estimate_update(lm_ray_estimate *re, const lm_light_scale_world *w, const float *aim,
                                const uint32_t *waiting, const float *change, float change_unit, uint32_t n,
                                uint32_t budget, uint32_t *out);
/* A light's edit moved every IIM texel to factor x IIM + add (light_scale.h): the bases follow,
 * so that a later update counts only what came after it. */
void lm_ray_estimate_scale(lm_ray_estimate *re, const float *factor, const float *add);
/* With g (borrowed; NULL: none, as after init), each texel's gathers take the emissive triangles' light as
 * g's gather adds it to the texel (lm_gather_emitted_at: closed form, shadow rays, the texel's seed) and
 * the rays leave the emission they meet out, as the gather's hemicube draws the emitters black. The few
 * rays meet a small emitter with a few strata or none: a blocker's shadow of a 0.3 m emitting square moved
 * 0.3 m changed 46 of a floor's 121 texels by over 10%, and the rays' estimate was over 10% off at 37 of
 * them (test_gather's test_ray_estimate_emitter_shadow). The gather's own light is the same on both sides
 * of E_t - E_0 where nothing moved, to the bit, and exact where a shadow moved. Call before the first base. */
void lm_ray_estimate_emitters(lm_ray_estimate *re, const lm_gather *g);
/* With tc (borrowed; NULL: none, as after init), where the nodes are: a texel that a moving node stands
 * beside takes the near rays (header). */
void lm_ray_estimate_nodes(lm_ray_estimate *re, const lm_texel_change *tc);
/* Every base forgotten (the IIM cleared: lm_iim_clear). */
void lm_ray_estimate_forget(lm_ray_estimate *re);

#endif
