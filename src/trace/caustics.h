/* Caustic photons (Larsen & Christensen 2004, section 5; DESIGN.md step 5; docs/caustics.md): light
 * whose last bounces before a diffuse receiver were specular (L S+ D), traced on the CPU only towards
 * the scene's caustic generators and stored where it lands.
 *
 * Generators: every node with mirror or glass triangles whose "caustics" switch is on (extras, or
 * lmgi_set_node_effects). Each is bounded by the sphere around its specular triangles' world bounds.
 * Pairs: every emitter (point, spot, directional, area; not a removed light) with every generator; pair p owns `photons`
 * photons with fixed QMC (Halton) numbers, so an unchanged scene re-traces the identical paths:
 *   point, spot   a direction uniform in the cone from the light around the generator's sphere (the
 *                 whole sphere of directions when the light is inside it), flux I att(w) Omega / N,
 *                 Omega = 2 pi (1 - cos a) the cone's solid angle (so the flux the generator receives is
 *                 exact, not a share of the light's whole power);
 *   directional   an origin uniform on the disk of the sphere's radius across the light's direction,
 *                 started outside the scene's bounding sphere, flux E pi r^2 / N;
 *   area          a point on the emitter (lm_emitter_area_point) and a direction uniform in the cone
 *                 from that point around the sphere, flux (Le / pdf_A) cos Omega / N.
 * A photon counts only when its first hit is a specular triangle of its own generator: a direction in
 * the cones of two generators belongs to the one it meets first, so no light is counted twice, and one
 * that meets something else first is direct light (the direct pass's) and is dropped.
 *
 * A photon follows mirror and glass bounces (bsdf.h: tinted mirror, Fresnel-chosen reflection or
 * refraction, total internal reflection, the glass tint), one Halton number per bounce, and is stored
 * where it first lands on a surface that stores photon hits (diffuse, glossy, emitter), with the flux
 * it carries there. A photon still bouncing after `max_bounces` specular bounces (light caught between
 * two mirrors, total internal reflection inside a glass block) is dropped and counted.
 *
 * Updates (lm_caustics_frame): a pair whose generator or light moved or changed is re-traced whole in the
 * frame that sees it; after any other node moved, every pair is re-traced round robin, `retrace` of its
 * photons a frame, until one full turn has passed with nothing moving. A still scene traces nothing. A
 * frame traces at most what the pairs at creation took when all moved at once with the round robin on
 * (pairs x photons x (1 + retrace)): with lights added since, whole re-traces go first and spread over
 * frames, and the round robin gets what is left.
 * Results are per photon slot, so they do not depend on the thread count.
 *
 * The scene, BVH and emitters are borrowed and must stay current (as for lm_photons). Not thread-safe;
 * lm_caustics_frame traces with OpenMP inside. Errors: bad settings, no memory. */
#ifndef LM_CAUSTICS_H
#define LM_CAUSTICS_H

#include <stdint.h>

#include "../core/error.h"
#include "../scene/scene.h"
#include "lights.h"
#include "rt_scene.h"

typedef struct {
    uint32_t photons;      /* per (emitter, generator) pair (default 16384) */
    float retrace;         /* fraction of each pair's photons re-traced a frame while something moves
                            * (default 0.25: every photon at least every 4 frames) */
    uint32_t max_bounces;  /* specular bounces before a photon is dropped (default 32) */
    uint32_t seed;         /* selects another stretch of the Halton sequence (default 0) */
} lm_caustic_settings;

void lm_caustic_settings_default(lm_caustic_settings *s);

/* A caustic photon where it landed. */
typedef struct {
    float pos[3];          /* world position */
    float ng[3];           /* receiver's unit geometric normal, turned to the side the photon arrived at */
    float flux[3];         /* RGB flux; all 0 for a slot without a landed photon */
    float dir[3];          /* unit direction it travelled, towards the receiver */
    int32_t node;          /* receiver's node and triangle */
    uint32_t tri;
    float bary[2];         /* where on tri: pos = (1 - u - v) v0 + u v1 + v v2 (lm_rt_hit's u, v), at the node's
                            * placement when it landed */
    uint16_t bounces;      /* specular bounces before landing (1 = straight off the generator) */
    uint16_t emitter;      /* emitter index */
} lm_caustic_hit;

/* A generator's bounding sphere: the emitters aim at it. */
typedef struct {
    int node;
    float centre[3], radius;
} lm_caustic_generator;

/* Sampling a caustic photon of emitter e towards a generator's sphere: origin, unit direction and the
 * photon's flux for a set of `count` (see the file comment). u: 4 numbers in [0, 1), u[0], u[1] the
 * direction (or the disk point), u[2], u[3] the point on an area emitter. tris: lm_emitter_place's
 * triangles of e or NULL. Returns 0 when the sample carries nothing (outside a spot's cone, the back of
 * an area emitter, an empty sphere). Shared with the reference solver, which draws u at random. */
int lm_caustic_emit(const lm_emitters *em, const lm_scene *s, int e, const lm_emit_tri *tris,
                    const lm_caustic_generator *g, const float u[4], uint32_t count, float org[3], float dir[3],
                    float flux[3]);

/* Why a traced caustic photon stored nothing, or that it did. */
typedef enum {
    LM_CAUSTIC_LANDED = 0,
    LM_CAUSTIC_MISSED,     /* its first hit was not its generator (direct light, or another generator's) */
    LM_CAUSTIC_ESCAPED,    /* left the scene after the generator */
    LM_CAUSTIC_ABSORBED,   /* ended inside the generator (a sample below a surface, a non-finite flux) */
    LM_CAUSTIC_CAPPED      /* still bouncing after max_bounces */
} lm_caustic_fate;

/* Follows a photon from org along dir: its first hit must be a specular triangle of node `generator`
 * (-1: any specular triangle), then specular bounces with the numbers next(user, bounce) gives (one per
 * bounce: glass's reflect-or-refract), until it lands (hit filled, flux included) or ends. *rays
 * (may be NULL) gets the rays cast. source: the emitter (its range windows the flux at the first hit,
 * lm_emitter_range_window). Reads the scene and BVH only: thread-safe. */
typedef float (*lm_caustic_numbers)(void *user, uint32_t bounce);
lm_caustic_fate lm_caustic_follow(const lm_scene *s, const lm_rt *rt, const lm_emitter *source, int generator,
                                  const float org[3], const float dir[3], const float flux[3], uint32_t max_bounces,
                                  lm_caustic_numbers next, void *user, lm_caustic_hit *hit, uint32_t *rays);

/* The generators of s as they are now (world bounds of their specular triangles), nodes whose switch is
 * off left out, as do nodes whose specular triangles have no extent. *out (caller frees) may be NULL
 * when there are none. Fails only when memory runs out. */
lm_status lm_caustic_generators(const lm_scene *s, lm_caustic_generator **out, int *count, lm_error *err);

/* What one lm_caustics_frame (or the first trace) did. */
typedef struct {
    uint32_t traced;       /* photons traced */
    uint32_t cast;         /* of those, the ones that cast a ray (a dark light's cost nothing: what a time
                            * budget's price per photon learns from, update/budget_plan.h) */
    uint32_t landed, missed, escaped, absorbed, capped; /* their fates */
    uint32_t pairs_moved;  /* pairs re-traced whole because their generator or emitter changed */
    uint64_t rays;
    double seconds;
} lm_caustic_frame_stats;

typedef struct lm_caustics lm_caustics;

/* Finds the generators and pairs and traces every photon once. *out is a valid object (with no pairs)
 * when the scene has no generator or no emitter: such a scene pays nothing. stats may be NULL. */
lm_status lm_caustics_create(const lm_scene *s, const lm_rt *rt, const lm_emitters *em,
                             const lm_caustic_settings *set, lm_caustics **out, lm_caustic_frame_stats *stats,
                             lm_error *err);
void lm_caustics_free(lm_caustics *c);
/* One frame's update (see the file comment). stats may be NULL. Fails only when memory runs out. */
lm_status lm_caustics_frame(lm_caustics *c, lm_caustic_frame_stats *stats, lm_error *err);
/* Re-traces every photon (a bake). */
lm_status lm_caustics_trace_all(lm_caustics *c, lm_caustic_frame_stats *stats, lm_error *err);
/* Queues every pair for a whole re-trace by the next frames (after a change the frames cannot see: a
 * material recoloured). */
void lm_caustics_retrace_all_later(lm_caustics *c);
/* Photons of whole re-traces still queued (0 once the frames have caught up). */
uint32_t lm_caustics_pending(const lm_caustics *c);
/* What the next frame would trace while things move: the queued whole re-traces and a round-robin turn of
 * every pair, within the frame cap. */
uint32_t lm_caustics_wanted(const lm_caustics *c);
/* The photons the next frames trace at most, in place of the frame cap (a time budget's count,
 * update/budget_plan.h); 0: the frame cap again. */
void lm_caustics_limit_frame(lm_caustics *c, uint32_t most);
/* Follows the emitter list's changes since c's pairs were laid out: the pairs of emitters appended (a
 * light added) are queued whole, those of removed lights dropped with their photon slots (a soak adding
 * and removing lights kept 3.2 MB of slots a removed light in the Cornell box), the others keep their
 * photons. Fails only when memory runs out (c unchanged). */
lm_status lm_caustics_follow_emitters(lm_caustics *c, lm_error *err);

int lm_caustics_pair_count(const lm_caustics *c);
int lm_caustics_generator_count(const lm_caustics *c);
const lm_caustic_generator *lm_caustics_generator(const lm_caustics *c, int i);
uint32_t lm_caustics_photon_count(const lm_caustics *c); /* slots: pairs x photons */
/* Traces the photon of one slot again ray by ray (lm_caustic_follow's way) into *hit, leaving c as it is:
 * what the packets of a frame's trace (16 photons of one cell of their Halton numbers together, one
 * Embree packet a bounce) must give it. For tests. */
lm_caustic_fate lm_caustics_trace_one(const lm_caustics *c, uint32_t slot, lm_caustic_hit *hit);
/* Every slot, pair by pair (a slot whose flux is 0 holds no photon). */
const lm_caustic_hit *lm_caustics_hits(const lm_caustics *c);
/* Landed photons now, and a counter of changes to the slots: it moves when a trace changed a slot (a copy
 * compares it to know it is stale; a round robin that finds every path as it was leaves it). */
uint32_t lm_caustics_landed(const lm_caustics *c);
uint64_t lm_caustics_version(const lm_caustics *c);
/* The total flux stored per channel (doubles), and the flux the generators received from the emitters,
 * sum over photons of their emitted flux (what a lossless mirror would store). */
void lm_caustics_flux(const lm_caustics *c, double stored[3], double emitted[3]);

#endif
