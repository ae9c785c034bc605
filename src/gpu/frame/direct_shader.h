/* GLSL of the direct-light passes (direct.c): the light program (one additive pass per light; pass_kind 0
 * still draws emission) and a small emission program for the pass that lays down depth and the emitted
 * radiance. Both vertex shaders compute gl_Position with the same invariant expression, so their depths
 * match exactly. */
#ifndef LM_DIRECT_SHADER_H
#define LM_DIRECT_SHADER_H

extern const char *const lm_direct_vs;
/* The light fragment shader without its first lines: "#version 450 core", then KIND (0 point, 1 spot,
 * 2 directional) and PCF (the radius) defined, go before it (direct.c compiles one per kind). */
extern const char *const lm_direct_fs_body;
extern const char *const lm_direct_emission_vs;
extern const char *const lm_direct_emission_fs;
/* GLSL of the material's lobes per pixel, for other passes over lm_direct_vs's outputs: declares
 * `vec3 albedo`, `look_up_albedo()` (call first in main(), in uniform control flow; needs uniforms
 * has_tex and base_tex) and `lobes(out vec3 kd, out vec3 ks)`. */
extern const char *const lm_direct_lobes_glsl;
/* GLSL that unpacks the G-buffer's a (lm_direct_gbuffer_texture): `bool gbuffer_normal(float a, out vec3 n)`,
 * false where the pixel has no visible front. */
extern const char *const lm_direct_gbuffer_glsl;

#endif
