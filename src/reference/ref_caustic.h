/* The reference solver's caustic part: light arriving at a receiver after one or more mirror or glass
 * bounces straight from an emitter (L S+ D), estimated by light tracing, for every kind of emitter
 * (docs/reference.md, "Which part carries which light"). The path tracer cannot find these paths from
 * point, spot and directional lights at all and finds them from small emitters only rarely; it drops
 * its own estimate of them, so nothing counts twice. Internal to src/reference.
 *
 * Generators: every node with mirror or glass triangles, whatever its "caustics" switch (the reference
 * is the physics, not what the runtime was asked to show), each bounded by the sphere around its
 * specular triangles' world bounds (trace/caustics.h's rule); nodes whose specular triangles have no
 * extent are left out. Pairs: every emitter with every generator, `caustic_photons` photons each.
 * Photon k of pair p draws its numbers from lm_ref_rng seeded by (seed, LM_REF_CAUSTIC_STREAM + p, k):
 * four for lm_caustic_emit (aimed into the cone around the generator's sphere, flux for a set of
 * caustic_photons), one per specular bounce for lm_caustic_follow (at most LM_REF_CAUSTIC_DEPTH bounces; the first
 * hit must be a specular triangle of the pair's own node, so a direction in two cones counts once).
 *
 * Where a photon of flux P lands at point p of a non-specular triangle, arriving along wi:
 *   texels  the texel whose atlas pixel p's lightmap UV falls in, when that texel belongs to the
 *           triangle's surface, gets E += P / area (the texel's world area on its surface); the back of
 *           a single-sided triangle gets nothing;
 *   pixels  when p is seen from the eye (in front of its side, inside the picture, unoccluded), the
 *           pixel it projects into gets L += P f(wi, wo) |cos(ns, wo)| / (d^2 A cos^3 a): wo towards the
 *           eye, d the distance, A the pixel's area on the image plane at distance 1, a the angle
 *           between the eye ray and the camera's forward. The pixel's mean radiance, unbiased.
 *
 * Determinism: photons are traced in parallel into one slot each, then added up in photon order, so the
 * result is bit-identical for any thread count. Cost: pairs x caustic_photons photons, a few rays each
 * (the emission ray, the specular bounces, for pixels a re-intersection and a shadow ray to the eye); a
 * scene without mirror or glass pays nothing. Reads the scene, BVH and emitters only. Errors: no memory. */
#ifndef LM_REF_CAUSTIC_H
#define LM_REF_CAUSTIC_H

#include <stdint.h>

#include "ref_paths.h"

/* Random-number streams of the caustic pairs: above every texel and pixel index. */
#define LM_REF_CAUSTIC_STREAM (1ull << 40)

/* Caustic irradiance per texel of atlas a into out (3 per texel, overwritten); *photons gets how many
 * were traced. */
lm_status lm_ref_caustic_texels(const lm_ref_ctx *c, const lm_atlas *a, const lm_ref_settings *set, float *out,
                                uint64_t *photons, lm_error *err);
/* Caustic radiance per pixel of cam into out (3 per pixel, row 0 at the top, overwritten). */
lm_status lm_ref_caustic_pixels(const lm_ref_ctx *c, const lm_view *cam, const lm_ref_settings *set,
                                float *out, uint64_t *photons, lm_error *err);

#endif
