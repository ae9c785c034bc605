/* The reference solver: brute-force Monte Carlo path tracing (Embree), the ground truth for every
 * error figure lmgi reports (docs/reference.md). Its own module, the lab's, above the runtime's
 * (docs/architecture.md): it traces with core to trace, and only api (and the tests) include it.
 *
 * The light at a receiver is split by the path it came along, so that every pass of the runtime is
 * checked against its own part (docs/reference.md, "Which part carries which light"). A vertex is
 * specular when its material is mirror or glass. The receiver is the texel's point, or for a pixel the
 * first non-specular vertex the eye ray reaches with no specular vertex before it.
 *   direct       point, spot and directional lights straight at the receiver;
 *   caustic      light that left an emitter (any kind), met only specular vertices and reached the
 *                receiver (L S+ D); estimated only by light tracing (ref_caustic.h), the path tracer
 *                drops these paths;
 *   lost         light that reaches the receiver through one or more specular vertices whose chain
 *                starts at a non-specular vertex v: everything gathered at v and beyond (v's own
 *                emission is the caustic part's). The runtime carries it in no pass (its hemicubes draw
 *                mirror and glass black); reported so that its size is known;
 *   iim          (texels) the rest: emitters seen straight from the receiver, and all light whose first
 *                vertex past the receiver is not specular, however it got there;
 *   pixels       emission (the receiver's own, towards the eye), direct and indirect (the iim-like rest)
 *                times the receiver's BSDF, caustic, lost, and reflections: all the light along an eye
 *                ray whose first hit is specular (path-traced; a point light's caustic seen in a mirror
 *                is a path of probability 0 both ways and is missing).
 * Per texel: E_full = direct + iim + caustic + lost (W/m^2 in the scene's linear units), E_iim = the iim
 * part (what an indirect illumination map holds), L = albedo / pi x E_full (what an AIM approximates).
 * Per pixel: full = the sum of its six parts (radiance).
 *
 * Estimator: from the texel's position lifted along its geometric normal by 1e-5 x the scene size,
 * over the hemisphere of its shading normal: next-event estimation to every emitter (the punctual ones
 * exactly, emissive surfaces with one light sample each, combined with BSDF sampling by multiple
 * importance sampling, power heuristic), then one cosine-weighted ray continued as a path with NEE
 * and MIS at every non-specular vertex, specular bounces through mirror and glass, and Russian
 * roulette from bounce `rr_depth` on (survival lm_bsdf_survival; at mirror and glass, certain until
 * bounce LM_REF_SPECULAR_RR_DEPTH, then the path's throughput), so paths end by roulette alone: a
 * closed room of albedo 0.999 keeps its light for thousands of bounces and the estimate still has all
 * of it (a fixed depth of 64 left out 47% of it at albedo 0.99). max_depth only guards against a path
 * that never ends (albedo 1); the paths it cuts are counted (paths_cut) and reported. Each contribution goes to the part the
 * path's route says; the route draws no numbers, so in a scene without mirror or glass every path and
 * E_full, E_iim and the pixels are bit for bit what the solver gave before the split. The caustic part:
 * `caustic_photons` photons per (emitter, specular node) pair, traced forward (ref_caustic.h).
 *
 * Adaptive sampling: passes of `samples` paths per active texel (pixel); per entry a running mean and
 * variance (Welford) of the luminance; an entry stops when its relative standard error sqrt(v / n) is at
 * most `target_error` (for texels: for E_full and E_iim both), v the larger of its own relative variance
 * var / max(mean, floor)^2 and its neighbours' mean (pixels: 5 x 5; texels: 25 in atlas order), so that
 * one that has not met a rare bright path its neighbours met keeps sampling, with
 * floor = 1% of the mean luminance over all entries (so black texels stop too), after at least
 * `min_samples`, or at `max_samples`. The rule reads the path tracer's part of E_full (the caustic
 * part has a fixed photon count and is added after).
 *
 * Determinism: the random numbers of sample k of entry i come from a counter-based generator seeded by
 * (seed, i, k), those of caustic photon k of pair p by (seed, LM_REF_CAUSTIC_STREAM + p, k); each entry
 * is summed by one thread in sample order, photons are added up in photon order, and the stopping rule
 * reads sums in a fixed order, so results are bit-identical whatever the thread count.
 *
 * Cache: results are stored in `cache_dir` (default $LMGI_CACHE, else build/reference-cache) under a
 * 64-bit FNV-1a key of the scene's geometry, materials, textures, lights and node matrices, the texel
 * table (or the camera), and every setting. A file that does not match (key, kind, sizes, checksum) is
 * ignored with a warning and recomputed. */
#ifndef LM_REFERENCE_H
#define LM_REFERENCE_H

#include <stddef.h>
#include <stdint.h>

#include "../charts/charts.h"
#include "../core/camera.h"
#include "../core/error.h"
#include "../scene/scene.h"
#include "../trace/lights.h"
#include "../trace/rt_scene.h"

typedef struct {
    float target_error;    /* relative standard error per texel/pixel to stop at (default 0.02) */
    int samples;           /* paths per entry per pass (default 64) */
    int min_samples;       /* never stop an entry before this many (default 2 x samples) */
    int max_samples;       /* cap per entry (default 65536) */
    uint32_t seed;         /* default 1 */
    int max_depth;         /* bounces at most: a guard, not how paths end (default LM_REF_MAX_DEPTH) */
    int rr_depth;          /* Russian roulette from this bounce on (default 3) */
    uint32_t caustic_photons; /* light-traced photons per (emitter, specular node) pair, 1 to 2^24
                               * (default LM_REF_CAUSTIC_PHOTONS) */
    const char *cache_dir; /* NULL: $LMGI_CACHE, else "build/reference-cache" */
    int use_cache;         /* read and write the cache (default 1) */
    int progress;          /* log progress through lm_info every few seconds (default 1) */
} lm_ref_settings;

#define LM_REF_MAX_DEPTH 65536
#define LM_REF_SPECULAR_RR_DEPTH 256
/* A caustic photon's specular bounces at most (ref_caustic.h): an L S+ D chain that long carries nothing. */
#define LM_REF_CAUSTIC_DEPTH 64

/* The caustic part's default photons per pair: scenes/cornell.glb's one pair in about a second on two
 * cores, its texels' caustic within a few percent (docs/reference.md, "Settings and their cost"). */
#define LM_REF_CAUSTIC_PHOTONS (1u << 20)

void lm_ref_settings_default(lm_ref_settings *s);

typedef struct {
    uint32_t count;        /* entries: texels (the atlas's texel order) or pixels (row 0 at the top) */
    int width, height;     /* atlas or picture size */
    /* 3 floats per entry each; texels irradiance, pixels radiance. NULL where the kind has no such part. */
    float *full;           /* everything: the sum of the parts below (E_full for texels) */
    float *iim;            /* texels: E_iim, the iim part; pixels: NULL */
    float *radiance;       /* texels: albedo / pi x E_full; pixels: NULL */
    float *direct;         /* punctual lights straight at the receiver (pixels: times its BSDF) */
    float *caustic;        /* L S+ D, light-traced */
    float *lost;           /* past a specular chain that starts at a non-specular vertex */
    float *emission;       /* pixels: the receiver's own emission; texels: NULL */
    float *indirect;       /* pixels: the iim-like rest times the BSDF; texels: NULL (iim is it) */
    float *reflections;    /* pixels: all light along eye rays whose first hit is mirror or glass; texels: NULL */
    uint32_t *samples;     /* paths per entry */
    float *rel_se;         /* achieved relative standard error per entry (the larger of full and iim) */
    uint64_t total_samples;
    double mean_rel_se, max_rel_se;
    uint32_t converged;    /* entries that reached target_error (the others hit max_samples) */
    uint64_t paths_cut;    /* paths still going at max_depth bounces: what they would have carried on is
                            * missing (0 in any scene that loses light at its bounces) */
    double seconds;        /* time spent computing, caustic part included (the original run's when cached) */
    uint64_t caustic_photons; /* photons the caustic part traced (pairs x caustic_photons; 0 without pairs) */
    double caustic_seconds;   /* its share of `seconds` */
    int from_cache;
    uint64_t key;          /* the cache key */
} lm_ref_result;

/* Texel references for every texel of `atlas` (built from s). */
lm_status lm_reference_texels(const lm_scene *s, const lm_atlas *atlas, const lm_rt *rt, const lm_emitters *em,
                              const lm_ref_settings *set, lm_ref_result *out, lm_error *err);
/* Pixel radiance for a camera: the rays go through its pinhole (forward .. znear, core/camera.h). */
lm_status lm_reference_pixels(const lm_scene *s, const lm_rt *rt, const lm_emitters *em, const lm_view *cam,
                              const lm_ref_settings *set, lm_ref_result *out, lm_error *err);
void lm_ref_result_free(lm_ref_result *r);

/* Spreads per-texel RGB values (3 per texel) into an atlas-sized RGB image (0 outside texels). */
void lm_ref_texels_to_image(const lm_atlas *a, const float *values, float *rgb);

/* Relative RMSE of est against ref over `count` entries of `channels` floats, where mask (NULL: all)
 * is non-zero: sqrt(sum (est - ref)^2) / sqrt(sum ref^2). 0 when both are all zero (or nothing is
 * selected), INFINITY when only ref is. */
double lm_ref_relative_rmse(const float *est, const float *ref, const uint8_t *mask, size_t count, int channels);

#endif
