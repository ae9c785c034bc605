/* The sky's radiance by direction (lm_scene.sky*): one function every pass asks, so that photons, rays, the
 * gather and the reference see the same sky.
 *
 *   uniform   L(d) = sky
 *   gradient  L(d) = horizon + (sky - horizon) max(d.y, 0): the zenith's radiance overhead, the horizon's
 *             at and below the horizon (an overcast or clear sky over a ground the scene does not model)
 *   image     L(d) = sky x the equirectangular image at d (bilinear; row 0 at the zenith, the middle column
 *             towards -z, +x three quarters across, column 0 towards +z): an HDR capture (.hdr, .exr), or a
 *             glTF's EXT_lights_image_based cube resampled (lm_sky_set_cube)
 *
 * d is a unit direction towards the sky (away from the scene), +y up. lm_sky_mean is L's mean over the
 * sphere (its power's share: flux = 4 pi x mean x pi R^2 through the scene's disk); for the image it is the
 * solid-angle-weighted mean of its pixels, made once as the image is loaded (the photon stage and the
 * frame ask for it every frame). lm_sky_hash extends an FNV-1a hash by everything the sky is (the
 * reference's cache and the bake's checkpoint key on it). Reads only: thread-safe. */
#ifndef LM_SKY_H
#define LM_SKY_H

#include <stdint.h>

#include "scene.h"

void lm_sky_radiance(const lm_scene *s, const float d[3], float out[3]);
void lm_sky_mean(const lm_scene *s, float out[3]);
uint64_t lm_sky_hash(uint64_t h, const lm_scene *s);
/* An image sky's directions, drawn by brightness (a sun in an HDR capture gets the photons its light
 * needs, at about equal flux each, and the rays gather's own sky rays; used where lm_sky_by_brightness,
 * the other skies' photons go uniformly on the sphere): lm_sky_sample gives d towards the sky from
 * (u0, u1) in [0, 1] (nearby values give nearby directions, so QMC strata stay strata);
 * lm_sky_radiance_pdf gives, for any d, lm_sky_radiance and the density per steradian with which
 * lm_sky_sample picks it (1 / 4 pi for the other skies), in one lookup. The density follows the lookup's
 * brightest channel exactly, bilinear between pixel centres, times the solid angle, with 1/100 of the mean
 * added (sky.c says how), so every direction the sky lights keeps one. */
int lm_sky_by_brightness(const lm_scene *s); /* an image sky, not all black */
void lm_sky_sample(const lm_scene *s, float u0, float u1, float d[3]);
void lm_sky_radiance_pdf(const lm_scene *s, const float d[3], float out[3], double *pdf);
/* 1 when the sky looks the same every way (a uniform one): the hemicube may clear to it. */
int lm_sky_is_uniform(const lm_scene *s);
/* Reads an equirectangular HDR image (Radiance .hdr through stb_image, OpenEXR .exr through tinyexr) as the
 * scene's sky image, times scale: rgb finite and >= 0 everywhere, at most LM_SKY_MAX_PIXELS. On failure
 * nothing of s changes; LM_ERR_IO (cannot read), LM_ERR_FORMAT (not an HDR image lmgi reads),
 * LM_ERR_INVALID (a negative or non-finite pixel, too large, a bad scale), naming the file. */
#define LM_SKY_MAX_PIXELS (1 << 24)
lm_status lm_sky_load_image(lm_scene *s, const char *path, const float scale[3], lm_error *err);
/* The sky image from a cube map (EXT_lights_image_based's mip 0), times intensity: six faces of n x n 8-bit
 * RGBA (+X, -X, +Y, -Y, +Z, -Z), each RGBD (lm_decode_rgbd; an LDR face's alpha of 255 makes it its colour
 * to the power 2.2), laid out as Babylon.js, the extension's reference, reads them: OpenGL's cube map
 * faces stored upside down, a scene direction d seen in the cube at R(rotation)^T (-d.x, d.y, d.z),
 * rotation a unit quaternion (x, y, z, w). Resampled into an equirectangular image of 4n x 2n (within
 * LM_SKY_CUBE_MIN/MAX_WIDTH, k x k lookups a pixel where the faces are finer), the kind
 * lm_sky_load_image reads. Errors name `what`: LM_ERR_INVALID (a bad size or intensity), LM_ERR_NOMEM; on
 * failure nothing of s changes. */
#define LM_SKY_CUBE_MIN_WIDTH 64
#define LM_SKY_CUBE_MAX_WIDTH 2048
lm_status lm_sky_set_cube(lm_scene *s, const uint8_t *const rgbd[6], int n, const float rotation[4], float intensity,
                          const char *what, lm_error *err);

#endif
