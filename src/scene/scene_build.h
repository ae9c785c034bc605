/* Internal helpers for building an lm_scene from a file (used by gltf_loader.cpp). Not public API:
 * the file-format-independent part of loading lives here, in C, so the C++ wrapper stays thin. */
#ifndef LM_SCENE_BUILD_H
#define LM_SCENE_BUILD_H

#include <stddef.h>
#include <stdint.h>

#include "scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/* glTF accessor component types (the GL enums). */
enum {
    LM_COMP_BYTE = 5120,
    LM_COMP_UNSIGNED_BYTE = 5121,
    LM_COMP_SHORT = 5122,
    LM_COMP_UNSIGNED_SHORT = 5123,
    LM_COMP_UNSIGNED_INT = 5125,
    LM_COMP_FLOAT = 5126
};

/* Size in bytes of one component, 0 for an unknown type. */
size_t lm_component_size(int comp_type);
/* 1 if `count` elements of `elem` bytes, `stride` apart, starting at `offset`, fit in `avail` bytes
 * (overflow-safe). */
int lm_span_fits(uint64_t offset, uint64_t count, uint64_t stride, uint64_t elem, uint64_t avail);
/* Decodes count elements of ncomp components into floats (normalised integers mapped to [0,1] or
 * [-1,1] as glTF defines when `normalized`). */
void lm_decode_floats(const uint8_t *src, size_t count, size_t stride, int comp_type, int ncomp,
                      int normalized, float *out);
/* Decodes unsigned integer indices (u8/u16/u32); returns 0 for another component type. */
int lm_decode_indices(const uint8_t *src, size_t count, size_t stride, int comp_type, uint32_t *out);

/* Appends triangles from a primitive's index list in glTF `mode` (4 list, 5 strip, 6 fan), offset by
 * `base`; out must hold lm_prim_tri_count(mode, n) * 3 entries. */
uint32_t lm_prim_tri_count(int mode, uint32_t index_count);
void lm_prim_triangles(int mode, const uint32_t *idx, uint32_t n, uint32_t base, uint32_t *out);

/* Area-weighted vertex normals from the faces, for vertices [first_vertex, first_vertex+vcount) used by
 * the given triangles. Vertices no face touches get +Z. */
void lm_generate_normals(float *normals, const float *positions, const uint32_t *tris, uint32_t tri_count,
                         uint32_t first_vertex, uint32_t vcount);
/* Number of triangles in [first, first+count) whose local-space area is zero (or negligible against
 * their longest edge, see LM_DEGENERATE_REL). */
uint32_t lm_count_degenerate(const lm_scene *s, uint32_t first, uint32_t count);
/* Index of the first non-finite float among n, or -1. */
long lm_first_nonfinite(const float *v, size_t n);

/* Converts 8-bit RGBA pixels to a linear float texture (sRGB transfer removed from RGB if srgb). */
int lm_texture_from_rgba8(lm_texture *t, const uint8_t *px, int w, int h, int srgb);

/* After nodes (parent, has_matrix, TRS or matrix) are filled: rejects parent cycles, decomposes given
 * matrices into TRS, resolves settings inheritance, computes world matrices and bounds. `animated[i]`
 * says node i is targeted by an animation (may be NULL). */
lm_status lm_scene_finish_nodes(lm_scene *s, const unsigned char *animated, lm_error *err);

/* Safe bounded name copy. */
void lm_copy_name(char *dst, const char *src);

#ifdef __cplusplus
}
#endif

#endif
