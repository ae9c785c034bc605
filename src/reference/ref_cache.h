/* The reference solver's disk cache (reference.h): keys and files. Internal to src/reference.
 *
 * Key: 64-bit FNV-1a over the file version, the scene's vertices, triangles, materials, textures,
 * lights, node world matrices and bounds, then the texel table (or the camera), then every setting that
 * changes the numbers (caustic_photons included). File: "LMGIREF1", version (2: the split by light
 * path), kind, key, count, width, height, summary (the caustic part's photons and time included), the
 * float arrays in lm_ref_result_arrays' order, samples, rel_se, and an FNV-1a checksum of everything
 * before it; written to a temporary name and renamed into place. A file of another version is ignored
 * with a warning and recomputed. */
#ifndef LM_REF_CACHE_H
#define LM_REF_CACHE_H

#include <stddef.h>
#include <stdint.h>

#include "reference.h"

enum { LM_REF_KIND_TEXELS = 1, LM_REF_KIND_PIXELS = 2 };

/* The float arrays (3 per entry) a result of the kind holds, as pointers to r's fields, in a fixed order
 * (the file's): full, direct, caustic, lost, then iim, radiance (texels) or emission, indirect,
 * reflections (pixels). Returns how many. Shared by the solver (reference.c) and the cache. */
#define LM_REF_MAX_ARRAYS 8
int lm_ref_result_arrays(lm_ref_result *r, int texels, float **arrays[LM_REF_MAX_ARRAYS]);
/* Allocates those arrays, samples and rel_se for count entries into a zeroed r; 0 when memory ran out
 * (what was allocated stays for lm_ref_result_free). */
int lm_ref_result_alloc(lm_ref_result *r, uint32_t count, int texels);

uint64_t lm_ref_key_texels(const lm_scene *s, const lm_atlas *a, const lm_ref_settings *set);
uint64_t lm_ref_key_pixels(const lm_scene *s, const lm_view *cam, const lm_ref_settings *set);
/* DIR/KIND-KEY.lmref with DIR from the settings, $LMGI_CACHE or build/reference-cache. */
void lm_ref_cache_path(char *buf, size_t size, const lm_ref_settings *set, uint32_t kind, uint64_t key);
/* Fills out (allocating its arrays) from a matching file and returns 1; returns 0 if there is none, and
 * warns and returns 0 if the file does not match or is damaged. */
int lm_ref_cache_load(const char *path, uint32_t kind, uint64_t key, uint32_t count, int width, int height,
                      lm_ref_result *out);
/* Writes r; a failure is a warning (the result stands without a cache). */
void lm_ref_cache_store(const char *path, uint32_t kind, const lm_ref_result *r);

#endif
