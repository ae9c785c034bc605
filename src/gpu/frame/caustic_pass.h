/* The screen-space caustic pass (Larsen & Christensen 2004, section 5 and Fig. 3; docs/caustics.md): the
 * caustic photons (trace/caustics.h) drawn as points over the frame's depth, the screen tiles that hold
 * some found by one occlusion query each, and the paper's cone filter (Eq. 4) run on those tiles alone;
 * then each visible surface adds kd / pi x the caustic irradiance E.
 *
 *   splat    one point per photon (with `merge`, the default, one per pixel, receiver triangle and side,
 *            carrying the photons there: their mean position, summed Phi and count n), at the centre of the
 *            pixel it projects into, additively into two RGBA32F textures: (Phi / A_pix, 1) and (Phi, n),
 *            A_pix the world area of that pixel's footprint on the photon's receiver (d^2 Omega_pix / cos,
 *            from its normal); and +1 into the stencil. Depth: the photon lies on a surface, so a hardware
 *            depth test would fight with it;
 *            the vertex shader compares its view depth with the frame's depth at that pixel instead,
 *            within the depth the receiver spans across a pixel (1 + 2 tan of its view angle, capped, pixel
 *            footprints) and drops photons behind, behind the camera, off screen, or on the side of
 *            the receiver the camera does not see. Float throughout: no 8-bit count limit, coloured light.
 *   tiles    the screen in tile x tile squares; per square that a photon projects into (found on the CPU
 *            with the frustum culling), an occlusion query (GL_SAMPLES_PASSED) around a quad drawn where
 *            the stencil is not 0: a tile is lit when the query counts any pixel (a photon behind the depth
 *            leaves its tile unlit); squares no photon projects into are unlit without a query.
 *   filter   over every lit tile grown by the filter's reach (clamped to the screen), with blending off, so
 *            that pixels two grown tiles share get the same value twice, never twice the light; the reach
 *            is k pixels for the fixed filter, and for the density-sized one the tiles within k 2^levels
 *            pixels of a lit tile, each drawn once:
 *              screen (the paper's): E(x) = sum_ij t(x + i, y + j) w_ij / sum_ij w_ij,
 *                w_ij = sqrt(1 + 2 k^2) - sqrt(i^2 + j^2), t the splat's Phi / A_pix: each photon's power
 *                spread over the (2k + 1)^2 pixels around it, over the world area they cover (A_pix at the
 *                photon): E integrates back to the photons' power where A_pix varies little over a filter;
 *              world (the paper's suggestion): every pixel's view position from the depth; a cone kernel of
 *                world radius R = k pixel footprints at x, E(x) = sum_j Phi_j max(0, 1 - |P_j - P_x| / R)
 *                / (pi R^2 / 3): photons on another surface than x's (a depth step) do not leak.
 *            Sized by density (filter_photons > 0): where the (2k + 1)^2 pixels around x hold fewer than
 *            filter_photons photons (counted from the splat's mipmaps), the same (2k + 1)^2 taps lie s
 *            pixels apart, each reading the splat's mean over about 2s pixels (its mipmaps), s up to
 *            2^LM_CAUSTIC_FILTER_LEVELS chosen so the filter holds about filter_photons: thin light is
 *            spread over more pixels instead of showing each photon. Where it holds more and the light
 *            changes across it by more than photon noise (its four quadrants' photon counts differ by
 *            over three standard deviations: an edge, a focal spot), the screen filter's taps close in,
 *            down to 1/16 pixel apart, until it holds about filter_photons: the spot as sharp as its
 *            photons allow, while an even patch keeps the whole filter and its low noise.
 *            Elsewhere E is 0. The receiver mask (splat.a: kd > 0) and the mipmaps are made only over
 *            the tiles the filter may read, those within its reach and its density window's of a tile a
 *            photon projects into, widened to whole texels of the coarsest level read: a few lit tiles
 *            pay for their neighbourhood, not for the screen.
 *   composite  one quad over the box of the grown tiles, each pixel adding kd / pi x E (kd the diffuse
 *            lobe the direct light's first pass wrote there: frame_targets.h).
 *
 * Four slots of targets, each re-made when its size changes: the frame's (LM_CAUSTIC_SLOT_FRAME), the
 * environment maps' faces (_PROBE, composited into the frame targets' probe picture), other views an
 * application renders (_VIEW) and a flat reflector's mirrored view (_MIRROR, into the mirror picture).
 * A view no photon projects into (an environment map face that sees no focal spot) costs no GL work.
 * Cost: one point per photon in the view (fewer where they crowd into pixels), one query quad per tile a photon projects into, (2k + 1)^2 texture reads
 * per filtered pixel (and up to LM_CAUSTIC_FILTER_LEVELS + 5 to size it, four of them the structure test,
 * plus the splat's mipmaps there once a run), two per pixel of the lit tiles' box (docs/bench.md has the figures). Needs a
 * current GL context; not thread-safe. */
#ifndef LM_CAUSTIC_PASS_H
#define LM_CAUSTIC_PASS_H

#include <stdint.h>

#include "../../core/error.h"
#include "../../trace/caustics.h"
#include "../../core/camera.h"
#include "direct.h"

typedef struct {
    int filter_k;          /* k of the (2k + 1)^2 filter, 0 to 8 (default 2; the paper's 7 x 7 is 3) */
    int tile;              /* tile side in pixels, 4 to 256 (default 32) */
    int world_space;       /* 1: filter by world distance (default 0: the paper's screen-space cone) */
    int filter_photons;    /* photons a filter should hold: where the (2k + 1)^2 pixels hold fewer, the filter
                              widens (its taps further apart over the splat's mipmaps) until about that many,
                              up to LM_CAUSTIC_FILTER_LEVELS doublings, and where they hold more and the light
                              has structure it narrows to that many (default 32; 0: the paper's fixed filter) */
    int widen_levels;      /* the density-sized filter widens up to 2^this times, 0 to LM_CAUSTIC_FILTER_LEVELS
                              (default LM_CAUSTIC_FILTER_LEVELS; fewer where thin light is the lightmaps' and the
                              screen holds concentrated photons: lm_caustic_pass_set_widening) */
    int merge;             /* 1: a run draws the photons that fall in one pixel on one receiver triangle and side
                              as one point with their summed flux and their count (default 1; 0: a point a
                              photon, so that a query counts photons) */
} lm_caustic_pass_settings;

/* The density-sized filter widens up to 2^this times. */
#define LM_CAUSTIC_FILTER_LEVELS 3
/* How far from a pixel the density-sized filter of k reads light, in pixels: at its widest (s = 2^levels)
 * its outer taps lie k s away, each reading the mip level whose texels span 2s pixels bilinearly, so
 * from texels up to 2s further whose pixels reach s beyond their centre (40 pixels at k = 2). */
#define LM_CAUSTIC_FILTER_REACH(k) LM_CAUSTIC_FILTER_REACH_AT(k, LM_CAUSTIC_FILTER_LEVELS)
/* The same for a filter that widens up to 2^levels times (lm_caustic_pass_settings.widen_levels). */
#define LM_CAUSTIC_FILTER_REACH_AT(k, levels) (((k) + 3) << (levels))

void lm_caustic_pass_settings_default(lm_caustic_pass_settings *s);

typedef struct {
    uint32_t photons;      /* photons drawn (in the view's frustum) */
    uint32_t points;       /* the points they were drawn as (settings.merge) */
    uint64_t splatted;     /* of those points, the ones that landed on a visible pixel (a query around the
                            * splat): photons when merge is 0 */
    int tiles, tiles_lit;  /* tiles of the screen, and those whose query found photons */
    uint64_t pixels_filtered; /* pixels of the grown lit tiles (shared pixels counted once per tile) */
    double t_splat, t_query, t_filter, t_composite; /* seconds (each ends with the GPU's work done) */
    double t_wait;         /* seconds waited first for the GPU work before the pass (the frame's direct
                            * light, which runs asynchronously): not the pass's own */
} lm_caustic_pass_stats;

typedef struct lm_caustic_pass lm_caustic_pass;
enum {
    LM_CAUSTIC_SLOT_FRAME = 0,
    LM_CAUSTIC_SLOT_PROBE = 1,
    LM_CAUSTIC_SLOT_VIEW = 2,
    LM_CAUSTIC_SLOT_MIRROR = 3,
    LM_CAUSTIC_SLOTS = 4
};

lm_status lm_caustic_pass_create(const lm_caustic_pass_settings *set, lm_caustic_pass **out, lm_error *err);
void lm_caustic_pass_free(lm_caustic_pass *cp);
/* Uploads the landed photons of hits[0 .. count) (slots with zero flux skipped). */
lm_status lm_caustic_pass_set_photons(lm_caustic_pass *cp, const lm_caustic_hit *hits, uint32_t count, lm_error *err);
uint32_t lm_caustic_pass_photon_count(const lm_caustic_pass *cp);
/* From the next run on, the density-sized filter widens up to 2^levels times (clamped to 0 ..
 * LM_CAUSTIC_FILTER_LEVELS): the photons' set decides it, not the pass's life (update/frame_passes.c). */
void lm_caustic_pass_set_widening(lm_caustic_pass *cp, int levels);
/* The runs after this one leave out the photons with dot(plane, (p, 1)) < 0 (a flat reflector's far side,
 * which its mirrored view would otherwise show in front of it); NULL: none left out. */
void lm_caustic_pass_set_clip(lm_caustic_pass *cp, const float plane[4]);
/* Splat, tiles and filter for `view` over the depth texture `depth` (width x height, lm_direct_depth_texture)
 * into slot `slot`'s irradiance; then, unless d is NULL, the composite into d's probe target (the probe
 * slot), mirror picture (the mirror slot) or frame's (the others), whose first pass drew the same view.
 * Nothing at all is drawn without photons. stats may be NULL. */
lm_status lm_caustic_pass_run(lm_caustic_pass *cp, int slot, const lm_view *view, unsigned depth, int width,
                              int height, const lm_direct *d, lm_caustic_pass_stats *stats, lm_error *err);
/* The composite alone, over slot's irradiance as its last run left it: for a picture whose photons, view
 * and depth are those of that run (nothing moved), which need no splat, query or filter again. */
lm_status lm_caustic_pass_composite(lm_caustic_pass *cp, int slot, const lm_direct *d, lm_caustic_pass_stats *stats,
                                    lm_error *err);
/* After a run of slot: the irradiance E (RGBA32F texture, rgb), the tiles whose queries found photons
 * (tiles_x x tiles_y flags, row 0 at the bottom as GL's), and the splat read back (width x height x 4
 * floats, GL rows bottom-up: rgb = sum Phi / A_pix, a = photons) for tests. */
unsigned lm_caustic_pass_irradiance(const lm_caustic_pass *cp, int slot);
const uint8_t *lm_caustic_pass_tiles(const lm_caustic_pass *cp, int slot, int *tiles_x, int *tiles_y);
lm_status lm_caustic_pass_read_splat(const lm_caustic_pass *cp, int slot, float *rgba, lm_error *err);
/* The irradiance read back (width x height x 3 floats, row 0 at the top, as lm_direct_read's picture). */
lm_status lm_caustic_pass_read_irradiance(const lm_caustic_pass *cp, int slot, float *rgb, lm_error *err);

#endif
