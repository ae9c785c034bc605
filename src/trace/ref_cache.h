/* The reference solver's disk cache (reference.h): keys and files. Internal to src/trace.
 *
 * Key: 64-bit FNV-1a over the scene's vertices, triangles, materials, textures, lights, node world
 * matrices and bounds, then the texel table (or the camera), then every setting that changes the
 * numbers. File: "LMGIREF1", version, kind, key, count, width, height, summary, the arrays, and an
 * FNV-1a checksum of everything before it; written to a temporary name and renamed into place. */
#ifndef LM_REF_CACHE_H
#define LM_REF_CACHE_H

#include <stddef.h>
#include <stdint.h>

#include "reference.h"

enum { LM_REF_KIND_TEXELS = 1, LM_REF_KIND_PIXELS = 2 };

uint64_t lm_ref_key_texels(const lm_scene *s, const lm_atlas *a, const lm_ref_settings *set);
uint64_t lm_ref_key_pixels(const lm_scene *s, const lm_ref_camera *cam, const lm_ref_settings *set);
/* DIR/KIND-KEY.lmref with DIR from the settings, $LMGI_CACHE or build/reference-cache. */
void lm_ref_cache_path(char *buf, size_t size, const lm_ref_settings *set, uint32_t kind, uint64_t key);
/* Fills out (allocating its arrays) from a matching file and returns 1; returns 0 if there is none, and
 * warns and returns 0 if the file does not match or is damaged. */
int lm_ref_cache_load(const char *path, uint32_t kind, uint64_t key, uint32_t count, int width, int height,
                      lm_ref_result *out);
/* Writes r; a failure is a warning (the result stands without a cache). */
void lm_ref_cache_store(const char *path, uint32_t kind, const lm_ref_result *r);

#endif
