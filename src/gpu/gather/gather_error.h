/* The gather's estimate of its own error (docs/gather.md, "Error estimate"; issue 15).
 *
 * An IIM texel is E = integral of L(w) cos(theta) dw over what its hemicube sees, with L the AIMs. Each
 * AIM texel is a kernel estimate from photon hits (photonmap/aim.h, lm_aim.error): relative standard
 * error s and radius r, and texels closer than r share hits, so the AIM's noise is a field whose values
 * are correlated over the kernel's footprint. For a kernel k, the noise integrated over an area much
 * larger than r has the variance of white noise of the same per-point variance over a correlation area
 * A_c = (integral k)^2 / integral k^2: pi r^2 for the box, 3/4 pi r^2 for Epanechnikov. Carried through
 * E's integral (the hit at distance d, its surface at cos_h to the ray):
 *
 *     Var(E) = integral (s L)^2 A_c cos^2(theta) cos_h / d^2 dw
 *
 * estimated with K cosine-weighted rays (a stratified grid shifted per texel by its index, so the same
 * every call): Var(E) = pi / K sum (s_j L_j)^2 A_c cos(theta_j) cos_h,j / d_j^2, and at most the fully
 * correlated (pi / K sum s_j L_j)^2 (a surface closer than r is one estimate, not many). Luminance
 * throughout. What it is not: the estimate of the AIM's bias (its radius blurs shadows and corners) or of
 * the single plane's and the rim's (docs/gather.md); those it does not see.
 *
 * Cost: K rays and AIM lookups per texel on the calling thread's OpenMP team (64 rays: about 10 us a
 * texel here, docs/gather.md). Deterministic for any thread count. Thread-safe (Embree queries and
 * reads only). */
#ifndef LM_GATHER_ERROR_H
#define LM_GATHER_ERROR_H

#include <stdint.h>

#include "../../charts/charts.h"
#include "../../trace/rt_scene.h"
#include "hemicube.h"

/* K of the frame loop's estimate, as the rim's default (photonmap/hemicube_rim.h). */
#define LM_GATHER_ERROR_RAYS 64

/* The AIM's noise as the gather looks it up: per atlas texel RGBA = (s Y, r, Y, 0) with Y the AIM's
 * luminance, s its relative standard error and r the estimate's radius (world units), from lm_aim.rgb
 * and lm_aim.error, gutters dilated like the AIM the hemicube samples. out: width x height x 4 floats. */
void lm_gather_error_source(const lm_atlas *a, const float *aim_rgb, const float *aim_error, float *out);

/* Per atlas texel, RGBA: the IIM's relative standard error from the AIM's noise (the above, over the
 * IIM texel's own luminance Y(E), iim_rgba's rgb), the AIM texel's own relative standard error, the
 * hemicube's back-face fraction (iim_rgba's alpha: the share of the texel's view on the inside of
 * geometry, whose light is unknown), and 0; 0 outside the atlas's texels. source: lm_gather_error_source;
 * aim_error: lm_aim.error; kernel as lm_aim_settings.kernel; samples: K, rounded down to a square (>= 1);
 * rt describes the scene as the IIM was gathered. */
void lm_gather_error(const lm_hemicube_settings *set, const lm_scene *s, const lm_atlas *a, const lm_rt *rt,
                     const float *source, const float *aim_error, int kernel, const float *iim_rgba, int samples,
                     float *out);

#endif
