/* The photon paths of indirect light (Mara et al. 2013; docs/tiled.md): no AIM, no IIM; every visible
 * pixel gathers the photon store's hits on the GPU (tiled, hash grid or brute force: gpu/tiled/photon_gather.h)
 * and the frame adds kd / pi x E / c, c the kernel's part on the pixel's surface (the coverage the direct
 * pass writes beside kd).
 *
 * It owns the hits packed as GPU records (photonmap/photon_records.h), the gather, the kernel radius and
 * what its last picture and coverage were made for, and decides itself whether they changed:
 *   - the records are packed again when the store's version moved, and only the pages that changed are
 *     sent;
 *   - the radius (derived: the disc that holds LM_PIXEL_GATHER_HITS hits on average) is kept until the
 *     live hits change by a tenth, so the kernel does not change every frame with each re-traced photon;
 *   - the coverage is made again when the radius or a node's scale changed;
 *   - the gather runs again only when the records, the view, the size, the radius or the scene (node
 *     matrices, materials, effect switches) changed since its last picture; else that picture is added
 *     again.
 *
 * Reads the photon store: lm_photon_path_records only while the stage's worker is quiet. GL calls: on the
 * thread whose context is current. Made by the frame loop only on a photon path. */
#ifndef LM_PHOTON_PATH_H
#define LM_PHOTON_PATH_H

#include "frame_settings.h"
#include "world.h"

typedef struct lm_photon_path lm_photon_path;

/* Nothing on the GPU yet (the gather is made at the first records). w, stage and set are the loop's,
 * borrowed. */
lm_status lm_photon_path_create(const lm_world *w, const lm_photon_stage *stage, const lm_frame_loop_settings *set,
                                lm_photon_path **out, lm_error *err);
void lm_photon_path_free(lm_photon_path *pp);
/* The store's hits as records, the pages that changed sent (stats, may be NULL, hears the upload), and
 * the kernel radius for them. */
lm_status lm_photon_path_records(lm_photon_path *pp, lm_photon_gather_stats *stats, lm_error *err);
/* The kernel radius in use (0 before the first records, or with no photon to gather). */
float lm_photon_path_radius(const lm_photon_path *pp);
/* The kernel coverage per texel handed to the direct pass, made again when it changed. */
lm_status lm_photon_path_coverage(lm_photon_path *pp, lm_direct *direct, lm_error *err);
/* The indirect light added to the picture lm_direct_draw drew for view (w x h); *gathers counts the
 * gathers run, stats hears the gather's work. */
lm_status lm_photon_path_draw(lm_photon_path *pp, lm_direct *direct, const lm_view *view, int w, int h,
                              lm_photon_gather_stats *stats, int *gathers, lm_error *err);

#endif
