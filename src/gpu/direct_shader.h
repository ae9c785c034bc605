/* GLSL of the direct-light pass (direct.c). One program draws both the emission pass (pass 0: depth
 * and emitted radiance) and one additive pass per light (pass 1), so the depths match exactly. */
#ifndef LM_DIRECT_SHADER_H
#define LM_DIRECT_SHADER_H

extern const char *const lm_direct_vs;
extern const char *const lm_direct_fs;

#endif
