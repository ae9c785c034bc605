/* The reference solver's estimators: one path-traced sample of a texel's irradiance or of a pixel's
 * radiance (reference.h says what they estimate). Internal to src/trace. */
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

void lm_ref_texel_frame(const lm_ref_ctx *c, const lm_texel *t, lm_ref_frame *f);
/* One sample of E_full and E_iim at a texel. */
void lm_ref_texel_sample(const lm_ref_ctx *c, const lm_ref_frame *f, lm_ref_rng *r, float full[3], float iim[3]);
/* One sample of the radiance through pixel (x, y), jittered inside the pixel. */
void lm_ref_pixel_sample(const lm_ref_ctx *c, const lm_ref_camera *cam, int x, int y, lm_ref_rng *r, float out[3]);

#endif
