/* GLSL of the per-pixel photon gathers (photon_gather.c). Each compute shader is a body; the program is
 * "#version 450 core", the defines photon_gather.c puts first (TILE, CHUNK, LIMIT), lm_pg_common_glsl and
 * the body, in that order. */
#ifndef LM_PHOTON_GATHER_SHADERS_H
#define LM_PHOTON_GATHER_SHADERS_H

/* Records (binding 0), the kernel, the fixed-point sums and the G-buffer lookup every gather shares. */
extern const char *const lm_pg_common_glsl;
/* Per tile, the visible points' depth range (binding 1). */
extern const char *const lm_pg_tile_bounds_cs;
/* Per record, the tiles (tiled) or the cell (hash grid) it reaches: counted (fill 0) or listed (fill 1). */
extern const char *const lm_pg_insert_tiles_cs;
extern const char *const lm_pg_insert_cells_cs;
/* Exclusive prefix sum of the counts into the offsets, one work group. */
extern const char *const lm_pg_scan_cs;
/* The gathers: per tile from shared memory, per pixel from its cells, per pixel over every record. */
extern const char *const lm_pg_gather_tiles_cs;
extern const char *const lm_pg_gather_cells_cs;
extern const char *const lm_pg_gather_all_cs;
/* The gathers' sums (carried over their windows) made into E. */
extern const char *const lm_pg_finish_cs;
/* The edge-aware reconstruction (stochastic gathers) and kd / pi x E added to the frame's radiance. */
extern const char *const lm_pg_resolve_cs;

#endif
