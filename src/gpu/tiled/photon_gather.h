/* Indirect light for the visible picture straight from the photon hits, on the GPU: the tiled deferred
 * photon gather of Mara, McGuire, Nowrouzezahrai & Luebke (2013), with their hash grid and the brute
 * force beside it (docs/tiled.md). Each visible pixel that has a diffuse lobe gets
 *
 *     E(x) = sum_P Phi_P kappa(|Y_P - x|) / (pi c (1 - c + c^2 / 3) r^2)
 *
 * over the photon records (photonmap/photon_records.h) within r of its visible point that lie on its
 * surface or one that continues it (side normals within 60 degrees, within r / 2 of its tangent plane;
 * photonmap/pixel_gather.h) (eq. 1-3, kappa = min(c, 1 - s / r), c = 1/5, one radius r for all: the
 * paper's constant-radius case, in which every gather gives the same picture), and
 * lm_photon_gather_composite adds kd / pi x E / c_x to the frame, c_x the kernel's part on the pixel's
 * surface (the kd texture's alpha holds 1 / c_x: gpu/frame/direct.h lm_direct_set_coverage), in place of the
 * lightmaps' albedo / pi x E_IIM.
 *
 * The gathers, all compute shaders (GL 4.5) over the frame's G-buffer (gpu/frame/direct.h: kd, position and
 * normal from the direct light's first pass):
 *   TILED       tiles of `tile` x `tile` pixels, each bounded by its visible points' depth range; every
 *               record is inserted into the tiles whose frustum its sphere of radius r meets (a count
 *               pass, a prefix sum, a fill pass); a work group per tile loads its records `chunk` at a
 *               time into shared memory and every pixel of the tile reads them there. With stochastic
 *               k > 1 a pixel reads 1/k^2 of them (one class of k^2, turned each frame) and counts them
 *               k^2 times; an edge-aware k x k average follows (the reconstruction).
 *   HASHGRID    records in a hash table of cells of side 2r (count, prefix sum, fill); each pixel reads
 *               the at most 8 cells its sphere reaches.
 *   BRUTEFORCE  each pixel reads every record: O(pixels x records), for small frames.
 * The sums are exact fixed point (glsl/photon_common.glsl), so the three give the same picture (equal
 * terms, added in any order) and a run gives the same picture every time.
 *
 * Cost: records upload as the pages that changed (lm_photon_gather_set_records); lm_photon_gather_run
 * is the whole gather (the caller skips it when the records, the view and the G-buffer are as for the
 * last run: docs/tiled.md). Tiled: O(records x tiles a sphere meets) to insert, O(pixels x the tile's
 * records / k^2) to gather. Memory: 20 bytes a record, 4 bytes a list entry, 8 a tile, 16 a pixel.
 *
 * Limits and errors: a frame larger than the GL's image size, or lists that would pass
 * LM_PHOTON_GATHER_MAX_ENTRIES (a radius that covers much of a large screen with many photons), is
 * refused with a message naming the numbers; nothing is drawn then. Needs a current GL 4.5 context; one
 * object per context, not thread-safe. */
#ifndef LM_PHOTON_GATHER_H
#define LM_PHOTON_GATHER_H

#include <stdint.h>

#include "../../core/error.h"
#include "../../photonmap/photon_records.h"
#include "../../core/camera.h"

typedef enum { LM_PHOTON_GATHER_TILED = 0, LM_PHOTON_GATHER_HASHGRID, LM_PHOTON_GATHER_BRUTEFORCE } lm_photon_gather_kind;

#define LM_PHOTON_GATHER_MAX_ENTRIES (1u << 27) /* list entries (512 MB) */

typedef struct {
    int kind;       /* lm_photon_gather_kind. Default TILED */
    int tile;       /* tiled: tile side in pixels, 4, 8, 16 or 32. Default 16 */
    int chunk;      /* tiled: records per shared-memory load, 64 to 512 (3 vec3 a record: 18 KB). Default 256 */
    int stochastic; /* tiled: k, each pixel reads 1/k^2 of its tile's records (1: all), 1 to 4. Default 1 */
} lm_photon_gather_settings;

void lm_photon_gather_settings_default(lm_photon_gather_settings *s);
/* 0 and a message naming the setting when s is out of range. */
int lm_photon_gather_settings_check(const lm_photon_gather_settings *s, lm_error *err);

typedef struct {
    uint32_t records, records_live;  /* records held, and those that are not empty */
    uint32_t pages_uploaded;         /* record pages (LM_RECORD_PAGE) sent by the last set_records */
    uint64_t entries;                /* tile or cell list entries of the last run */
    int tiles, tiles_lit;            /* tiled: tiles, and tiles with a visible point that takes light */
    double t_upload, t_insert, t_gather; /* seconds: set_records; bounds, count, scan and fill; gather */
    double t_wait;                   /* seconds the run first waited for the GL's earlier work (the frame's
                                      * direct light), not in t_insert */
} lm_photon_gather_stats;

typedef struct lm_photon_gather lm_photon_gather;

lm_status lm_photon_gather_create(const lm_photon_gather_settings *s, lm_photon_gather **out, lm_error *err);
void lm_photon_gather_free(lm_photon_gather *g);
/* Sends the records' dirty pages (all of them the first time or when their count changed). */
lm_status lm_photon_gather_set_records(lm_photon_gather *g, const lm_photon_records *r, lm_photon_gather_stats *st,
                                       lm_error *err);
/* The gather for view at w x h over the G-buffer textures kd_tex and g_tex (lm_direct_kd_texture,
 * lm_direct_gbuffer_texture, drawn for this view), kernel radius r > 0, `frame` turning the stochastic
 * classes; E goes to the object's w x h texture. */
lm_status lm_photon_gather_run(lm_photon_gather *g, const lm_view *view, int w, int h, unsigned kd_tex,
                               unsigned g_tex, float radius, unsigned frame, lm_photon_gather_stats *st, lm_error *err);
/* radiance_tex (w x h RGBA32F, the frame's: lm_direct_radiance_texture) += kd / pi x E / c_x of the last
 * run (reconstructed when stochastic), over the same G-buffer (kd_tex's alpha: 1 / c_x). */
lm_status lm_photon_gather_composite(lm_photon_gather *g, unsigned radiance_tex, unsigned kd_tex, unsigned g_tex,
                                     lm_error *err);
/* The last run's E (3 floats a pixel, row 0 at the top; before any reconstruction), for tests. */
lm_status lm_photon_gather_read(lm_photon_gather *g, float *rgb, lm_error *err);
/* The last run's size (0 x 0 before the first). */
void lm_photon_gather_size(const lm_photon_gather *g, int *w, int *h);

#endif
