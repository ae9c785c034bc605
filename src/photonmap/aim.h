/* Approximated illumination maps (AIMs), Larsen & Christensen section 3.
 *
 * An AIM is a float RGB map over the lightmap atlas holding, per covered texel, the outgoing diffuse
 * radiance reconstructed from the photon hits stored on the texel's surface:
 *
 *     L = rho / pi * sum(Phi_i) / A          (the paper's "total energy of these photons divided by the
 *                                             area that they span"; A = pi r^2 away from the surface's
 *                                             boundary)
 *
 * over the N hits nearest to the texel (r = distance to the N-th), found in a balanced kd-tree built on
 * the surface's hits only ("a structure belonging to the surface that was hit"). Distances are taken in
 * the node's local space (hits and texels both carry node-local positions, so a moved dynamic node
 * lines up), and A is converted to world area with the node's current transform. rho is the material's
 * albedo at the texel's uv. Emission is not included: the gather adds emitters at their own radiance.
 *
 * Hard cases: fewer hits than N use them all; r is clamped to at least min_radius_texels texels, and
 * when the N nearest lie inside that radius every hit within it is counted instead (so coincident hits
 * give a bounded, consistent value); a surface with no hits gets 0; where the disc of radius r crosses
 * the surface's boundary, A is the part of the disc on the surface (computed exactly against the
 * surface's boundary edges, in the texel's tangent plane), so edge and corner texels are not darkened.
 * Gutters and uncovered texels stay 0.
 *
 * Scheduling (section 3): a surface's AIM is refreshed only when its delta_f (energy of hits added or
 * removed since its last refresh, kept by the photon store) exceeds a threshold; surfaces are taken in
 * order of delta_f / area, largest first, at most `budget` per call, and a refreshed surface's delta_f
 * is reset. The surfaces of one call are prepared in parallel and their texels computed in one parallel
 * pass (OpenMP, fixed units of texels); each texel's value depends only on the store's contents, so
 * results are identical for any thread count. */
#ifndef LM_AIM_H
#define LM_AIM_H

#include <stdint.h>

#include "../charts/charts.h"
#include "../core/error.h"
#include "../scene/scene.h"
#include "../trace/direct_irradiance.h"
#include "../trace/photon_store.h"
#include "../trace/rt_scene.h"
#include "kdtree.h"
#include "seams.h"

/* The N at which the smallest radius is min_radius_texels texels (see the settings). */
#define LM_AIM_FLOOR_N 32.0

typedef struct {
    int n_nearest;           /* N hits per estimate (default 32; clamped to the surface's hit count) */
    float min_radius_texels; /* smallest gather radius, in texels of the atlas at N = LM_AIM_FLOOR_N, and
                              * sqrt(N / LM_AIM_FLOOR_N) times that at another N (default 1) */
    float delta_threshold;   /* refresh when delta_f > this x the mean stored hit energy (default 0.01) */
    int front_only;          /* single-sided materials count only hits arriving from the front (default 1) */
    int boundary_correction; /* use the disc's area on the surface near its boundary (default 1) */
    int kernel;              /* 0: box, the paper's sum(Phi) / (pi r^2); 1: Epanechnikov weights
                                w = 1 - d^2 / r^2, sum(w Phi) / (pi r^2 / 2): same mean, far less noise
                                (default 1) */
    int error_estimate;      /* keep each texel's estimate error (lm_aim.error; default 0: off, no cost) */
    int dense;               /* 1 (default): a surface with N hits within every texel's smallest radius is
                              * estimated in one pass over its hits, without a kd-tree (the same hits summed in
                              * another order; a floor lit by 100 lights: 250,000 hits for 144 texels); 0: the
                              * kd-tree always */
    int seams;               /* 1 (default): near its boundary a surface's estimate also uses the hits of the
                              * surfaces that continue it across a seam (seams.h), and the disc's area is taken
                              * on them all; 0: its own hits only, the paper's */
    int direct_parts;        /* with lm_aim_set_direct: the direct light is averaged over direct_parts^2 parts of
                              * each texel, 1 to LM_AIM_DIRECT_PARTS_MAX (default LM_AIM_DIRECT_PARTS; see there) */
    uint64_t max_hits;       /* a refresh with a budget (lm_aim_refresh) stops before a surface that would take its
                              * surfaces' stored hits past this (the first is always refreshed): the hits
                              * bound its cost, and they grow with every light added (default 0: no bound) */
} lm_aim_settings;

typedef struct {
    int surfaces_refreshed;
    int surfaces_pending;    /* over the threshold but left for a later call (budget) */
    uint32_t texels_written;
    uint64_t hits_used;      /* hits put in kd-trees or binned */
    int surfaces_binned;     /* of the surfaces refreshed, those estimated without a kd-tree (set.dense) */
    double seconds;
} lm_aim_stats;
/* to += from: counts and seconds added, surfaces_pending taken from `from` (the later refresh's). */
void lm_aim_stats_add(lm_aim_stats *to, const lm_aim_stats *from);

typedef struct {
    lm_aim_settings set;
    int width, height, surface_count;
    float *rgb;              /* width * height * 3, radiance; 0 in gutters, uncovered texels, unlit surfaces */
    float *dilated;          /* rgb as RGBA (a = 0) with the charts' borders copied into the gutters
                                (lm_aim_dilated_rgba) */
    uint32_t *texel_first;   /* per surface (surface_count + 1 offsets) into texel_list */
    uint32_t *texel_list;    /* atlas texel indices grouped by surface */
    uint32_t *edge_first;    /* per surface (surface_count + 1 offsets) into edges */
    uint32_t *edges;         /* boundary edges, 2 scene vertex ids each, oriented with the surface on the left
                                (collinear runs joined into one edge) */
    uint32_t *refresh_count; /* per surface: how many times it was refreshed */
    float *edge_d2;          /* per texel_list entry: squared distance to its surface's boundary in its
                                tangent plane (-1 until first computed); a smaller disc skips the edges */
    float *error;            /* with set.error_estimate, per atlas texel (width * height * 2): the relative
                                standard error of the texel's radiance (luminance) as a sum of independently
                                placed hits, sqrt(sum (w_i Y_i)^2) / sum(w_i Y_i) with Y_i the luminance of
                                rho / pi Phi_i, over the whole value (direct light computed, not estimated,
                                has none); and the estimate's radius in world units, over which neighbouring
                                texels share hits. 0 and 0 where the AIM is 0. NULL when off */
    lm_seams seams;          /* per surface, the surfaces that continue it (set.seams) */
    uint32_t *seams_used;    /* per surface: which of them its last refresh used, hashed (edge_d2 holds for that set) */
    double *owed;            /* per surface: the delta_f of the continuing surfaces refreshed since its own last
                                refresh; its estimate near the seam reads their hits too, so it is due a refresh
                                as if its own had changed (scheduled by delta_f + owed) */
    float *rest;             /* with lm_aim_keep_rest, rgb less the direct part it computes (lm_aim_set_direct;
                                width * height * 3), for a gather that computes that part where its rays hit;
                                else NULL */
    float *rest_dilated;     /* rest as RGBA, dilated as `dilated` is; NULL without rest */
    float mean_hit_energy;   /* as of the last refresh call */
    const lm_direct_light *direct; /* NULL (default): photons carry all light, the paper's form; else
                                      lm_aim_set_direct */
    const lm_rt *occluders;  /* NULL (default): every hit near a texel counts; else lm_aim_set_occluders */
    float occluder_lift, occluder_cover;
    const float *occluder_cover_by_surface; /* NULL: occluder_cover everywhere (trace/photons.h's cover_by_surface) */
} lm_aim;

void lm_aim_settings_default(lm_aim_settings *o);
/* Sets up per-surface texel and boundary lists for the atlas; the map starts at 0. s, su and a must be
 * the ones the photon store's surfaces refer to; they are read again by the refresh calls. */
lm_status lm_aim_init(lm_aim *aim, const lm_scene *s, const lm_surfaces *su, const lm_atlas *a,
                      const lm_aim_settings *set, lm_error *err);
void lm_aim_free(lm_aim *aim);

/* From the next refresh on, each texel's direct light is computed (trace/direct_irradiance.h: averaged
 * over the texel's parts at their current world positions, geometric normal, both sides for a
 * double-sided material, seeded by the atlas texel index) and the photon hits it covers (lm_direct_covers_hit) are left out of the
 * estimate: L = rho / pi (E_direct + sum(w_i Phi_i) / A_w over the other hits). A surface with no
 * other hits gets its direct light alone. NULL: back to photons for everything. d is borrowed. The
 * caller refreshes every surface after a change (lm_aim_refresh_all) if the maps must agree at once. */
void lm_aim_set_direct(lm_aim *aim, const lm_direct_light *d);
/* From the next refresh on, each texel also keeps its value without the punctual lights' part of the
 * direct light (lm_aim.rest; 0 without lm_aim_set_direct): a ray gather adds that part exactly where each
 * of its rays hits (photonmap/hemicube_rim.h) instead of reading it as the average over the texel it hits,
 * which a sunlit road's 7 m texels blur across every house's shadow (docs/aim.md, "Suns"); and an edit
 * that changes the photons' light alone may scale the rest and keep the computed part
 * (lm_aim_scale_surfaces, docs/tradeoff.md, "Beside a sun"). Costs 7 floats an atlas texel and a second
 * dilation per refresh. Call before the first refresh (the refresh
 * of a surface writes its texels). Errors: out of memory. */
lm_status lm_aim_keep_rest(lm_aim *aim, lm_error *err);
/* rest as RGBA dilated into the gutters, kept up to date by every refresh; NULL without lm_aim_keep_rest. */
const float *lm_aim_rest_dilated_rgba(const lm_aim *aim);
/* From the next refresh on, a hit counts towards a texel's estimate only if the texel sees the vertex its
 * photon left (the emission point, or its previous hit: lm_hit.travelled back along its direction), weighed
 * by 1 / the share of the estimate's disc that sees it (aim_sight.h): a photon that reached the floor
 * beside a box from the far side of it would not have reached the floor at the box's foot, so the contact
 * shadow is not blurred into light (docs/aim.md, "Occluders"). Shadow rays in rt from points lifted `lift`
 * off the surface: N a texel and 8 more for each distinct vertex it sees, 4 to 9 times the estimate's cost.
 * Dense surfaces then take the kd-tree too. A texel whose point has geometry closer than `cover` straight
 * out on a side (the photons' cover distance: under a box on the floor; per surface id where cover_by_surface
 * is given) counts that side's hits untested: it is hidden, not dark. NULL rt: every hit counts (the
 * paper's). rt and cover_by_surface are borrowed. */
void lm_aim_set_occluders(lm_aim *aim, const lm_rt *rt, float lift, float cover, const float *cover_by_surface);
/* The direct light is averaged over this many squared parts of a texel by default (lm_texel_parts; covered
 * parts left out): near a lamp it falls off within a texel, and the centroid's value alone lost energy the
 * hemicube should see (4.8% of the suzanne Cornell box's ceiling, docs/aim.md). More parts cost one more
 * direct-light evaluation each and blur a contact shadow over the texel; a bake asks for more
 * (lm_aim_settings.direct_parts, docs/aim.md "Averaged over the texel"). */
#define LM_AIM_DIRECT_PARTS 2
#define LM_AIM_DIRECT_PARTS_MAX 8

/* For the per-pixel photon gathers (pixel_gather.h, gpu/tiled/photon_gather.h), which sum one constant radius r
 * (world units) with the kernel min(c, 1 - s / r), c = 1/5: per atlas texel, the part of that kernel's
 * weight that lies on the texel's surface, in [1/16, 1] (1 away from its boundary, about 1/2 at an edge,
 * 1/4 in a corner), from the same exact disc-on-surface areas as the AIM's boundary correction, in the
 * texel's tangent plane at its node's current scale. The kernel is the integral of box discs of radius t
 * over t in [(1 - c) r, r], weight 1 / r, taken with 3-point Gauss-Legendre (exact for the full disc).
 * With rt, a texel whose disc leaves its surface also counts the part on the surfaces whose hits the
 * gathers take there (the other facets of a ball, facing within 60 degrees), sampled by 24 rays a Gauss
 * radius; without, its own surface's part alone. out: a->texel_count floats. Cost: O(texels x boundary
 * edges within r), and 72 rays a texel near a boundary with rt. Errors: out of memory. */
lm_status lm_aim_kernel_coverage(const lm_aim *aim, const lm_scene *s, const lm_surfaces *su, const lm_atlas *a,
                                 const lm_rt *rt, float radius, float *out, lm_error *err);

/* Refreshes up to `budget` surfaces (budget < 0: no limit) whose delta_f + owed is over the threshold, in
 * order of (delta_f + owed) / area (ties: lower surface id first), and resets both; the delta_f of each is
 * owed to the surfaces that continue it and were not refreshed with it. stats may be NULL. */
lm_status lm_aim_refresh(lm_aim *aim, const lm_scene *s, const lm_surfaces *su, const lm_atlas *a,
                         lm_photon_store *ps, int budget, lm_aim_stats *stats, lm_error *err);
/* Refreshes every surface (initialisation, or after a settings change) and resets every delta_f. */
lm_status lm_aim_refresh_all(lm_aim *aim, const lm_scene *s, const lm_surfaces *su, const lm_atlas *a,
                             lm_photon_store *ps, lm_aim_stats *stats, lm_error *err);
/* Refreshes the `count` listed surfaces (distinct ids), whatever their delta_f, and resets it: the
 * surfaces a light's power edit scaled (update/photon_stage.c). stats may be NULL. */
lm_status lm_aim_refresh_listed(lm_aim *aim, const lm_scene *s, const lm_surfaces *su, const lm_atlas *a,
                                lm_photon_store *ps, const int *surfaces, int count, lm_aim_stats *stats,
                                lm_error *err);
/* The listed surfaces' texels (rgb, and rest where kept) multiplied by factor[3 k + c] per channel
 * (surface_count x 3), the dilated maps made again; delta_f and owed untouched. A first guess that is
 * exact where every hit of a surface scaled alike (a light's power edit in a scene lit by one, a base
 * colour edit for the surfaces of that material: the AIM multiplies in the albedo), cheap where the
 * refresh it stands in for is not (update/photon_stage.c, under a time budget). Where rest is kept and
 * `computed` is given (surface_count x 3, else NULL), the computed direct part, rgb - rest, is
 * multiplied by computed instead, and rest, the part the photons bring, by factor: a lamp's power edit
 * beside a sun whose direct light the AIM computes scales the photons' part alone. Cost: the listed
 * surfaces' texels and one pass over the atlas. */
void lm_aim_scale_surfaces(lm_aim *aim, const lm_atlas *a, const int *surfaces, int count, const float *factor,
                           const float *computed);
/* Recomputes one surface's texels from its current hits and resets its delta_f. */
lm_status lm_aim_refresh_surface(lm_aim *aim, const lm_scene *s, const lm_surfaces *su, const lm_atlas *a,
                                 lm_photon_store *ps, int surface, lm_aim_stats *stats, lm_error *err);

/* The RGB float map (width * height * 3, row y at offset 3 * (y * width + x)). */
const float *lm_aim_rgb(const lm_aim *aim);
/* The same as RGBA (alpha 0; four floats a texel are what a GPU texture holds and samples fastest) with
 * each chart's border texels copied out into its gutters (lm_atlas_dilate_gutters), what a bilinear lookup
 * near a chart's edge needs; kept up to date by every refresh, so that the frame loop's photon thread, not
 * its rendering thread, pays for it. */
const float *lm_aim_dilated_rgba(const lm_aim *aim);

#endif
