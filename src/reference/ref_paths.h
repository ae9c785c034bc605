/* The reference solver's estimators: one path-traced sample of a texel's irradiance or of a pixel's
 * radiance, split by light path into the parts reference.h and docs/reference.md ("Which part carries
 * which light") define. Internal to src/reference. */
#ifndef LM_REF_PATHS_H
#define LM_REF_PATHS_H

#include <stdint.h>

#include "reference.h"

/* Counter-based random numbers: splitmix64 steps from a state hashed from (seed, entry, sample). */
typedef struct {
    uint64_t state;
} lm_ref_rng;

void lm_ref_rng_seed(lm_ref_rng *r, uint32_t seed, uint64_t entry, uint64_t sample);
float lm_ref_rng_float(lm_ref_rng *r);

typedef struct {
    const lm_scene *s;
    const lm_rt *rt;
    const lm_emitters *em;
    int max_depth, rr_depth;
    float eps;             /* ray offset: 1e-5 x scene size */
    int *tri_emitter;      /* area emitter per scene triangle, -1 if none */
} lm_ref_ctx;

lm_status lm_ref_ctx_init(lm_ref_ctx *c, const lm_scene *s, const lm_rt *rt, const lm_emitters *em,
                          const lm_ref_settings *set, lm_error *err);
void lm_ref_ctx_free(lm_ref_ctx *c);

/* Where and about what a texel gathers: origin lifted off the surface, shading normal n, and the
 * triangle's geometric normal turned to n's side; albedo at the texel. */
typedef struct {
    float org[3], n[3], ng[3];
    float albedo[3];
} lm_ref_frame;

/* The parts the backward tracer estimates (the caustic part is the light tracer's, ref_caustic.h). A
 * texel sample fills DIRECT, INDIRECT (E_iim) and LOST; a pixel sample any of them. */
enum {
    LM_REF_EMISSION = 0,   /* the receiver's own emission towards the eye (pixels) */
    LM_REF_DIRECT,         /* point, spot and directional lights straight at the receiver */
    LM_REF_INDIRECT,       /* emitters seen directly, and all light whose first vertex past the receiver is
                            * not specular: E_iim for texels */
    LM_REF_REFLECTIONS,    /* all light along a camera ray whose first hit is mirror or glass (pixels) */
    LM_REF_LOST,           /* light gathered past a specular chain that leaves the receiver (L..D S+ receiver) */
    LM_REF_BACKWARD_PARTS
};

/* One sample. full is every contribution the path tracer keeps, summed in path order (in a scene
 * without mirror or glass bit for bit what the solver gave before the split); the parts add up to it
 * to float rounding. */
typedef struct {
    float full[3];
    float part[LM_REF_BACKWARD_PARTS][3];
    int cut; /* the path was still going at max_depth */
} lm_ref_sample;

void lm_ref_texel_frame(const lm_ref_ctx *c, const lm_texel *t, lm_ref_frame *f);
/* One sample of a texel's irradiance. */
void lm_ref_texel_sample(const lm_ref_ctx *c, const lm_ref_frame *f, lm_ref_rng *r, lm_ref_sample *out);
/* One sample of the radiance through pixel (x, y), jittered inside the pixel. */
void lm_ref_pixel_sample(const lm_ref_ctx *c, const lm_view *cam, int x, int y, lm_ref_rng *r,
                         lm_ref_sample *out);

#endif
