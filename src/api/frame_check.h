/* A frame of the frame loop against the reference solver, the way a user meets the lighting: `lmgi run`'s
 * composited picture next to the path-traced radiance of the same pixels (reference/reference.h), per visible
 * surface and over the whole frame (docs/reference.md, "Frame against reference").
 *
 * What is compared: every pixel whose centre and four neighbours' centres see one surface
 * (gpu/frame/surface_view.h's index picture, drawn from the frame's own view): along an edge the reference's
 * pixel, an average over its area, and the frame's, a sample at its centre, see different things, which
 * is aliasing, not lighting. Mirror and glass pixels (no lightmap; their reflections are another pass)
 * and the background are left out. The frame figures (`lit`, `rel_rmse`) leave out emissive surfaces
 * too: their pixels are mostly their own emission, which both sides get exactly and which would hide
 * the error of everything they light; each emitter still has its own row.
 *
 * Cost: the frame loop's set-up and `frames` frames, plus the reference's pixels (seconds to minutes:
 * the reference's target error and the picture size decide). Deterministic for a given scene and
 * settings (the frame loop's and the reference's own determinism). Not thread-safe: it creates and makes
 * current its own GL context on the calling thread. Errors: those of the frame loop and the reference,
 * and LM_ERR_NOMEM. */
#ifndef LM_FRAME_CHECK_H
#define LM_FRAME_CHECK_H

#include "../reference/reference.h"
#include "../update/frame_loop.h"
#include "lmgi_scene.h"

/* Sums over a set of pixels: how many, and the frame's and the reference's radiance per channel. */
typedef struct {
    uint32_t pixels;
    double frame[3], ref[3];
} lm_check_sum;

typedef struct {
    int width, height;
    float *frame, *ref;    /* 3 floats per pixel, linear radiance, row 0 at the top */
    float *ref_indirect;   /* the reference's indirect part (reference/reference.h: the iim-like rest, shaded) */
    float *caustic, *ref_caustic; /* the caustic part (L S+ D): what the frame's caustic pass added (kd / pi x
                                   * E; 0 where the frame's was not read), and the reference's */
    int32_t *surface_at;   /* per pixel: surface index, -1 specular, -2 nothing */
    uint8_t *compared;     /* per pixel: 1 where it counts in `surface` (an interior pixel of a surface) */
    int surface_count;
    lm_check_sum *surface; /* per surface */
    lm_check_sum lit;      /* every compared pixel of a non-emissive surface */
    double rel_rmse;       /* relative RMSE of the frame over those pixels (lm_ref_relative_rmse) */
    lm_check_sum caustic_lit; /* the caustic parts over the same pixels */
    double caustic_rel_rmse; /* relative RMSE of the frame's caustic part against the reference's there */
    double ref_rel_se;     /* the reference's mean relative standard error per pixel (its own noise) */
    double ref_seconds;    /* time the reference took (its first computation when it came from the cache) */
} lm_frame_check;

/* frame / reference of one channel (1 when both are 0, INFINITY when only the reference is). */
double lm_check_ratio(const lm_check_sum *c, int channel);

/* Runs the frame loop on sc (loaded as the caller wants: `lmgi run` derives its atlas from the texel
 * budget, lm_frame_loop_atlas_texels) for `frames` frames (at least 1, 30 per second of animation), and
 * compares the last with the reference's pixels at the frame's size. */
lm_status lm_frame_check_run(lmgi_scene *sc, const lm_frame_loop_settings *loop, const lm_ref_settings *ref,
                             int frames, lm_frame_check *out, lm_error *err);
void lm_frame_check_free(lm_frame_check *c);
/* The same comparison for a picture already drawn: rgb (width x height x 3, top row first) from `view` of sc
 * as its nodes, lights and materials are now, and what its caustic pass added (caustic, the same layout;
 * NULL: none), against the reference's pixels of that view (the cache keys on all of those). The surface
 * index picture is drawn on the current GL context. */
lm_status lm_frame_check_picture(const lmgi_scene *sc, const lm_view *view, const float *rgb, const float *caustic,
                                 int width, int height, const lm_ref_settings *ref, lm_frame_check *out,
                                 lm_error *err);
/* The frame alone (what lm_frame_check_run compares): the loop's picture after `frames` frames into rgb
 * (loop->width x loop->height x 3 floats). */
lm_status lm_frame_check_frame(lmgi_scene *sc, const lm_frame_loop_settings *loop, int frames, float *rgb,
                               lm_error *err);

#endif
